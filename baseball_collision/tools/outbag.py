"""
``analyze --out-bag``: a bag Foxglove (or RViz through a replay) opens and shows the session.

:class:`FoxgloveCopy` is a sample and event sink of the analyze loop
(:func:`.analyze.run_detector`). It writes, in log-time order:

- every topic of the input bag, as recorded (CDR bytes copied, ROS 1 converted), with the QoS
  profiles its publishers offered (a topic the analysis writes too, e.g. ``/diagnostics`` of a
  live session, under :data:`RECORDED_PREFIX`); a type ROS 2 Jazzy does not define is written
  with the ``.msg`` definition the input bag holds for it (one held as IDL only, or none, and
  the topic is left out with a note);
- what the node would have published, on the node's topics (:func:`.parameters.output_topics`),
  with the node's QoS: ``~/impact``, ``~/impact_velocity``, ``~/near_miss``,
  ``~/predicted_impact``; ``~/impact_report`` (the JSON record of each impact, near miss and
  prediction, :func:`baseball_collision.core.records.event_record`); ``~/markers`` (the live bat
  and ball at ``marker_rate`` of log time, each impact's bat, ball, contact, normal and label,
  a DELETEALL at a state reset: :mod:`baseball_collision.core.scene`); ``/diagnostics`` (the
  node's status every ``diagnostics_period`` of log time: :mod:`baseball_collision.core.health`).

The bag's log time plays the node's clock: a derived message is logged at the log time of the
sample that produced it. Messages are stamped with the sample's header stamp, as the node does.
"""

from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

from .parameters import output_topics, Remapping
from ..bags import (
    BagWriter, DIAGNOSTIC_ARRAY, health_message, MARKER_ARRAY, qos_profile, RawBag, RawMessage,
    scene_message, STRING, text_message)
from ..bags.names import POINT_STAMPED, TWIST_STAMPED, VECTOR3_STAMPED
from ..core.detector import DEFAULTS, Detector, Impact, NearMiss, Prediction, StateReset
from ..core.health import health_status, NS_PER_S, silent_streams, take_snapshot, Tally
from ..core.records import event_record, record_text
from ..core.scene import bat_ends, impact_scene, live_scene, Scene
from ..errors import BagError

EVENTS_QOS = qos_profile(depth=100)
"""The node's event topics: reliable, volatile, 100 deep."""

VIEWS_QOS = qos_profile(depth=10)
"""The node's markers and diagnostics: reliable, volatile, 10 deep."""

MAX_STATUSES_PER_GAP = 100
"""Most diagnostics statuses written for one gap between samples (the last ones are kept)."""

RECORDED_PREFIX = '/recorded'
"""An input topic the analysis writes too (``/diagnostics``, the node's outputs recorded live)
is copied under this prefix: ``/recorded/diagnostics``."""

SETTINGS = ('marker_rate', 'marker_lifetime', 'publish_markers', 'diagnostics_period',
            'stale_timeout', 'qos')
"""The node's own parameters the copy uses (from ``--params``, else their defaults)."""


def derived_topics(node: Union[str, Remapping]) -> Dict[str, Tuple[str, str]]:
    """
    Return the node's output topics and types the copy writes: ``{name: (topic, type)}``.

    For the node named (with its namespace), or as a ``Remapping``'s node has them.
    """
    topics = output_topics(node)
    types = {'impact': POINT_STAMPED, 'impact_velocity': TWIST_STAMPED,
             'near_miss': VECTOR3_STAMPED, 'predicted_impact': POINT_STAMPED,
             'impact_report': STRING, 'markers': MARKER_ARRAY, 'diagnostics': DIAGNOSTIC_ARRAY}
    return {name: (topics[name], msgtype) for name, msgtype in types.items()}


class FoxgloveCopy:
    """
    Writes the output bag of ``analyze --out-bag`` (see the module), streaming.

    Use: :meth:`open` before the loop, as a sink during it, :meth:`close` after it (writes the
    input messages after the last sample and a last status).

    :param writer: an open output bag.
    :param input_path: the bag analysed (read a second time, raw, for every topic).
    :param detector: the detector the loop feeds (its state and counters make the status).
    :param streams: the selected topic of each stream (``ball``, ``bat_pose`` or knob/tip).
    :param parameters: flat node parameters (``--params``): the settings in :data:`SETTINGS`.
    :param node_name: the node whose topics are written (with its namespace), or a
        ``Remapping`` (``analyze --remap``): its node, its topics as it remaps them.
    :param frame_id: the configured frame ('' : the samples' frame).
    :raises BagError: from :meth:`open` and the sink methods, when reading or writing fails.
    """

    def __init__(self, writer: BagWriter, input_path: Any, detector: Detector,
                 streams: Mapping[str, str], parameters: Mapping[str, Any],
                 node_name: Union[str, Remapping], frame_id: str = '') -> None:
        self.writer = writer
        self.detector = detector
        self.config = detector.config
        self.streams = dict(streams)
        name = node_name if isinstance(node_name, str) else node_name.node_name
        self.node_name = name.strip('/').rsplit('/', 1)[-1]  # as the node's get_name()
        self.frame_id = frame_id
        self.settings = {name: parameters.get(name, DEFAULTS[name]) for name in SETTINGS}
        self.settings.update(model=self.config.model, bat_input=self.config.bat_input,
                             tracker_noise=self.config.tracker_noise)
        self.topics = derived_topics(node_name)
        self._raw = RawBag(input_path)
        self._pending: Iterator[RawMessage] = iter(())
        self._next: Optional[RawMessage] = None
        self._tally: Optional[Tally] = None
        self._last_values: Dict[str, Tuple[Any, ...]] = {}
        self._candidate: Optional[Tuple[str, Tuple[Any, ...]]] = None
        self._stamp_ns = 0
        self._frame = ''
        self._next_marker_ns: Optional[int] = None
        self._next_status_ns: Optional[int] = None
        self._log_time_ns = 0
        self.skipped: Dict[str, str] = {}
        """Input topics not copied, with why (several types, a type Jazzy does not define)."""
        self.renamed: Dict[str, str] = {}
        """Input topics the analysis also writes (a bag of a live node), and their new names."""

    # ---- set-up and end ----------------------------------------------------------------------

    def open(self) -> None:  # noqa: A003 - as the bag readers and writers
        """
        Open the input again, declare every topic with its QoS (input topics first).

        :raises BagError: the input cannot be read, or a topic cannot be declared.
        """
        self._raw.open()
        self.skipped = dict(self._raw.skipped)
        written = {topic for name, (topic, _) in self.topics.items()
                   if name != 'markers' or self.settings['publish_markers']}
        kept = []
        for topic in self._raw.topics.values():
            if topic.msgtype not in self.writer.typestore.types:
                why = self._define(topic.name, topic.msgtype)
                if why:
                    self.skipped[topic.name] = why
                    continue
            if topic.name in written:  # recorded from a live node: kept beside the analysis
                self.renamed[topic.name] = RECORDED_PREFIX + topic.name
            self.writer.add_topic(self.renamed.get(topic.name, topic.name), topic.msgtype,
                                  topic.qos_profiles)
            kept.append(topic.name)
        for name, (topic, msgtype) in self.topics.items():
            if name == 'markers' and not self.settings['publish_markers']:
                continue
            qos = VIEWS_QOS if name in ('markers', 'diagnostics') else EVENTS_QOS
            self.writer.add_topic(topic, msgtype, (qos,))
        self._pending = self._raw.messages(kept)
        self._next = next(self._pending, None)

    def _define(self, topic: str, msgtype: str) -> str:
        """
        Give the writer the input's own definition of a type Jazzy does not define.

        :returns: '' when the type can now be written; else why the topic is not copied.
        """
        kind, text = self._raw.definition(topic)
        if kind != 'msg':
            held = 'in the bag only as IDL' if kind == 'idl' else 'not in the bag'
            return f'{msgtype} is not a ROS 2 Jazzy type and its definition is {held}'
        try:
            self.writer.register_definition(msgtype, text)
        except BagError as error:
            return f'{msgtype} is not a ROS 2 Jazzy type and its definition in the bag ' \
                f'cannot be used: {error}'
        return ''

    def close(self) -> None:
        """
        Write the input messages left and a last status; close the input (idempotent).

        :raises BagError: a read or write failure.
        """
        try:
            self._accept_previous()
            self._copy_until(None)
            self._write_status(self._log_time_ns)
            self._tally = None
        finally:
            self.release()

    def release(self) -> None:
        """Close the input without writing anything more (idempotent)."""
        self._next = None
        self._raw.close()

    def notes(self) -> List[str]:
        """Return what the reader of the output bag should know (topics skipped or renamed)."""
        return ([f'--out-bag: {topic} not copied ({why})'
                 for topic, why in sorted(self.skipped.items())]
                + [f'--out-bag: the recorded {topic} is copied as {renamed} (the analysis writes '
                   f'{topic})' for topic, renamed in sorted(self.renamed.items())])

    # ---- the sink ------------------------------------------------------------------------------

    def on_sample(self, role: str, stamp_ns: int, frame_id: str, values: Sequence[float],
                  log_time_ns: int) -> None:
        """Copy the input up to this sample's log time; then live markers and status when due."""
        self._accept_previous()
        now_s = log_time_ns / NS_PER_S
        if self._tally is None:
            self._tally = Tally(started=now_s)
            self._next_status_ns = log_time_ns + self._period_ns('diagnostics_period')
            self._next_marker_ns = log_time_ns
        self._statuses_until(log_time_ns)
        self._copy_until(log_time_ns)
        self._tally.arrived(role, now_s)
        self._tally.period.record(0.0)
        self._log_time_ns = log_time_ns
        self._stamp_ns = stamp_ns
        self._frame = self.frame_id or self.detector.frame_id or frame_id
        self._candidate = (role, (tuple(values[:3]), tuple(values[3:])))
        if self.settings['publish_markers'] and self.settings['marker_rate'] > 0.0 \
                and log_time_ns >= self._next_marker_ns:
            self._write_live_markers(log_time_ns)
            self._next_marker_ns = log_time_ns + int(NS_PER_S / self.settings['marker_rate'])

    def on_events(self, events: Sequence[Any], log_time_ns: int, frame_id: str) -> None:
        """Write each event's messages as the node publishes them."""
        self._accept_previous()
        frame = self.frame_id or frame_id or self.detector.frame_id or self._frame
        for event in events:
            if isinstance(event, Impact):
                self._write_impact(event, frame, log_time_ns)
            elif isinstance(event, NearMiss):
                self._write_stamped('near_miss', event.stamp_ns, frame, event.gap_vector,
                                    log_time_ns)
            elif isinstance(event, Prediction):
                self._write_stamped('predicted_impact', event.stamp_ns, frame, event.point,
                                    log_time_ns)
            elif isinstance(event, StateReset) and self.settings['publish_markers']:
                self._last_values.clear()
                self._write_scene(Scene(event.stamp_ns, frame, (), delete_all=True),
                                  log_time_ns)
            if isinstance(event, (Impact, NearMiss, Prediction)):
                self._write_report(event, frame, log_time_ns)

    # ---- the pieces ----------------------------------------------------------------------------

    def _period_ns(self, name: str) -> int:
        return max(1, int(self.settings[name] * NS_PER_S))

    def _statuses_until(self, log_time_ns: int) -> None:
        """
        Write the statuses due up to ``log_time_ns``, each at its time on the period's grid.

        As the node's timer does, also while no sample arrives (a gap longer than
        :data:`MAX_STATUSES_PER_GAP` periods gets the last ones only).
        """
        period = self._period_ns('diagnostics_period')
        due = (log_time_ns - self._next_status_ns) // period
        if due > MAX_STATUSES_PER_GAP:
            self._next_status_ns += (due - MAX_STATUSES_PER_GAP) * period
        while self._next_status_ns <= log_time_ns:
            self._copy_until(self._next_status_ns)
            self._write_status(self._next_status_ns)
            self._next_status_ns += period

    def _accept_previous(self) -> None:
        """Keep the previous sample's values as the live ones unless the detector dropped it."""
        if self._candidate is not None:
            role, (position, rest) = self._candidate
            if self.detector.stats.last_drop_reason is None:
                self._last_values[role] = (position, rest) if role == 'bat_pose' else (position,)
            self._candidate = None

    def _copy_until(self, log_time_ns: Optional[int]) -> None:
        """Write the input messages logged at or before ``log_time_ns`` (None: all left)."""
        message = self._next
        while message is not None and (log_time_ns is None
                                       or message.log_time_ns <= log_time_ns):
            self.writer.write_serialized(self.renamed.get(message.topic, message.topic),
                                         message.msgtype, message.log_time_ns, message.data)
            message = next(self._pending, None)
        self._next = message

    def _write_stamped(self, name: str, stamp_ns: int, frame: str, values: Sequence[float],
                       log_time_ns: int) -> None:
        topic, msgtype = self.topics[name]
        write = {POINT_STAMPED: self.writer.write_point,
                 VECTOR3_STAMPED: self.writer.write_vector3}[msgtype]
        write(topic, stamp_ns, frame, values, log_time_ns)

    def _write_impact(self, impact: Impact, frame: str, log_time_ns: int) -> None:
        if self._tally is not None:
            self._tally.last_impact_ns = impact.stamp_ns
        self._write_stamped('impact', impact.stamp_ns, frame, impact.point, log_time_ns)
        self.writer.write_twist(self.topics['impact_velocity'][0], impact.stamp_ns, frame,
                                impact.bat_velocity, impact.bat_angular_velocity, log_time_ns)
        if self.settings['publish_markers']:
            self._write_scene(impact_scene(impact, frame, self.config,
                                           self.settings['marker_lifetime']), log_time_ns)

    def _write_report(self, event: Any, frame: str, log_time_ns: int) -> None:
        text = record_text(event_record(event, frame, self.config))
        self.writer.write_message(self.topics['impact_report'][0],
                                  text_message(text, self.writer.typestore), log_time_ns)

    def _write_scene(self, scene: Scene, log_time_ns: int) -> None:
        self.writer.write_message(self.topics['markers'][0],
                                  scene_message(scene, self.writer.typestore), log_time_ns)

    def _write_live_markers(self, log_time_ns: int) -> None:
        ball = self._last_values.get('ball')
        ends = bat_ends(self._last_values, self.config)
        if ball is None and ends is None:
            return
        lifetime = 2.0 / self.settings['marker_rate']
        self._write_scene(live_scene(self._stamp_ns, self._frame, ball and ball[0], ends,
                                     self.config, lifetime), log_time_ns)

    def _write_status(self, log_time_ns: int) -> None:
        if self._tally is None:
            return
        detector = self.detector
        snapshot = take_snapshot(
            log_time_ns / NS_PER_S, self.node_name, tuple(self.streams), self.streams,
            self._tally, detector.stats, detector.watermark_ns, detector.frame_id,
            self.settings, detector.noise)
        problems = dict.fromkeys(silent_streams(snapshot), 'no message in the bag then')
        status = health_status(snapshot, problems)
        self.writer.write_message(self.topics['diagnostics'][0],
                                  health_message(status, self._stamp_ns, self.writer.typestore),
                                  log_time_ns)
