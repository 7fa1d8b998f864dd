"""
The node's outputs: its publishers, and what each of the detector's events sends out when.

The topics, their message types and QoS are :data:`OUTPUTS` (events reliable and volatile,
``~/impact_predicted`` latched with a liveliness lease, markers and ``/diagnostics`` a short
queue). In a message's executor callback, ``~/impact`` goes out the moment the detector solves
a contact (``_on_contact``, before its velocities are fitted) and the other events' messages as
the detector returns them (``_publish``: a throttled or echoed line at its level, a state
reset's line at debug while it echoes a ROS clock jump of under ``CLOCK_ECHO_S`` ago). What
costs time and no arm waits on comes after the intake's drain (``_complete_events``): an
impact's error bars, INFO line and markers, then every event's ``~/impact_report`` (made only
while the topic has a subscriber), then the bat's newest departures for the glitch judgments to
come (``_departures_ahead``). Markers: an impact's scene, the live bat and ball on a
timer (only when a new sample came), a ``DELETEALL`` on every state reset; all as CDR bytes.

:class:`Outputs` is a mixin base of ``node.ImpactNode``: it uses the node's endpoints,
detector, settings, lock, tally and log lines, and the flag's ``_set_predicting``.
"""

import time
from typing import Any, Callable, Deque, Dict, Optional, Tuple, Union

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PointStamped, TwistStamped, Vector3Stamped
from rclpy.duration import Duration
from rclpy.qos import (
    DurabilityPolicy, HistoryPolicy, LivelinessPolicy, QoSProfile, ReliabilityPolicy)
from std_msgs.msg import Bool, String
from visualization_msgs.msg import MarkerArray

from .markers import latest_scene, scene_cdr
from .messages import describe_impact, event_report, EventOutput, FLAG_CDR, format_stamp
from ..core.detector import (
    DetectorConfig, Event, Impact, PendingPrediction, PendingUncertainty)
from ..core.geometry import Vector
from ..core.scene import impact_scene, Scene


LIVELINESS_LEASE_S = 0.5
"""``~/impact_predicted``'s liveliness lease (s): a subscriber's liveliness event says the node
is gone this long after it died (its process killed or frozen), not Fast DDS's 20 s."""
CLOCK_ECHO_S = 2.0
"""A state reset by the stamps this soon (s) after a ROS clock jump echoes it: logged at debug."""

EVENTS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                    reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
"""The events' QoS (and the reports'): reliable, volatile, the last 100."""
VIEWS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                   reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
"""The markers' and ``/diagnostics``' QoS (and the bat plan's): reliable, volatile, the last 10."""
LATCHED = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                     reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL,
                     liveliness=LivelinessPolicy.AUTOMATIC,
                     liveliness_lease_duration=Duration(seconds=LIVELINESS_LEASE_S))
"""``~/impact_predicted``'s QoS: the last value kept for late subscribers."""
OUTPUTS = (  # output name, message type, topic, QoS
    ('predicted_impact', PointStamped, '~/predicted_impact', EVENTS),
    ('impact_predicted', Bool, '~/impact_predicted', LATCHED),
    ('impact', PointStamped, '~/impact', EVENTS),
    ('impact_velocity', TwistStamped, '~/impact_velocity', EVENTS),
    ('near_miss', Vector3Stamped, '~/near_miss', EVENTS),
    ('impact_report', String, '~/impact_report', EVENTS),
    ('markers', MarkerArray, '~/markers', VIEWS),
    ('diagnostics', DiagnosticArray, '/diagnostics', VIEWS),
)
"""The node's publishers, in the order they are made: name, message type, topic, QoS."""


class Outputs:
    """Publish the detector's events, their completions and the markers (a mixin of the node)."""

    _outputs: Dict[str, Any]  # each output's publisher by name (OUTPUTS)
    _last_values: Dict[str, Tuple[int, Any]]  # each stream's newest accepted stamp and values
    _markers_stamp: Optional[int]  # the newest stamp the live markers showed
    _frame: str  # the frame of the message being taken (``_on_contact``'s)
    _contact_ns: Optional[int]  # a contact solved in the add being taken
    _clock_jump_at: float  # when the ROS clock last jumped back (s, steady clock)
    # (event, frame, config) to complete once the inputs are drained
    _to_complete: Deque[Tuple[Union[Event, PendingUncertainty, PendingPrediction], str,
                              DetectorConfig]]

    def _advertise_outputs(self) -> None:
        """Make the publishers (``OUTPUTS``, mismatches warned about); the flag starts false."""
        self._outputs = {name: self.endpoints.advertise(msg_type, topic, qos)
                         for name, msg_type, topic, qos in OUTPUTS}
        self._outputs['impact_predicted'].publish(FLAG_CDR[False])  # latched

    def _on_contact(self, stamp_ns: int, point: Vector) -> None:
        """
        Publish ``~/impact`` the moment the detector solves a contact (``Detector.on_contact``).

        Inside ``_take``'s ``add``, before the impact's velocities are fitted: its message's
        stamp and point are the impact's; ``~/impact_velocity`` follows once it is returned.
        ``~/impact_predicted`` turns false right after it: the contact came (the detector's
        ``PredictionCleared`` comes only at its next frame that predicts, up to
        ``prediction_period`` later). A prediction the same ``add`` returns that was made before
        the contact does not turn it on again.
        """
        self._outputs['impact'].publish(self._point_cdr(
            stamp_ns, self._frame or self.detector.frame_id or '', point))
        self.tally.last_impact_ns = stamp_ns
        self._contact_ns = stamp_ns
        self._set_predicting(False)

    def _then_reports(self, on_message: Callable[[Any, Any], None]) -> Callable[[Any, Any], None]:
        """
        Return an input's executor callback: ``on_message`` (and the drain), then reports.

        And then the bat's newest departures made ahead (``_departures_ahead``).
        """
        complete = self._guarded(self._complete_events, "completing the impacts' reports")
        ahead = self._guarded(self._departures_ahead, "making the bat's departures ahead")

        def handled(message: Any, info: Any) -> None:
            on_message(message, info)
            complete()
            ahead()
        return handled

    def _departures_ahead(self) -> None:
        """
        Make the newest bat frames' departures after the drain (``Detector.departures_ahead``).

        A frame's first glitch judgment near the ball (the first sweep near it, the first
        prediction) reads a window's departures, a ``c2`` fit each (10 us): made here, after
        the drain, they are off the path of the message that judges them. No output changes.
        """
        with self._lock:
            self.detector.departures_ahead()

    def _complete_events(self) -> None:
        """
        Complete the queued events in order: impacts' error bars, lines, markers; reports.

        An impact's ``~/impact`` and ``~/impact_velocity`` went out as its message was handled;
        here its 1-sigma uncertainties are measured (``PendingUncertainty.measure``: re-solves
        from copies of its samples taken then, 0.3-0.6 ms; the same to the bit as ``analyze``'s),
        its INFO line logged and its markers published. A prediction's ``~/predicted_impact``
        went out too; its error bars (``PendingPrediction.measure``: 0.08-0.09 ms median, 0.4 ms
        at most, measured at 90-1000 Hz) are measured only for its report. Then each event's
        ``~/impact_report``.
        Called after each input's executor callback, once the intake has drained the queues
        (no message waiting, or ``DRAIN_LIMIT`` taken), so the error bars and a record's JSON (a
        third of the message that predicts, with a recorder subscribed) delay no message taken
        in it and no output an arm reads. Records are made only while the topic has a subscriber
        (it is volatile: a record published to nobody reaches nobody).
        """
        queued, publisher = self._to_complete, self._outputs['impact_report']
        subscribed = bool(queued) and publisher.get_subscription_count() > 0
        while queued:
            event, frame, config = queued.popleft()
            kind = event.__class__
            if kind is PendingUncertainty:
                try:
                    event = self._measured(event, frame)
                except Exception as error:  # the error bars' own failure (a bug)
                    self._failed(f'the error bars of the impact at '
                                 f'{format_stamp(event.impact.stamp_ns)} s failed',
                                 'its line, markers and report are left out', error)
                    continue
            elif kind is PendingPrediction:
                if not subscribed:  # (its error bars are for its report alone)
                    continue
                try:
                    event = event.measure()
                except Exception as error:  # the error bars' own failure (a bug)
                    self._failed(f'the error bars of the prediction made at '
                                 f'{format_stamp(event.prediction.made_at_ns)} s failed',
                                 'its report is left out', error)
                    continue
            if subscribed:
                publisher.publish(event_report(event, frame, config))

    def _measured(self, pending: PendingUncertainty, frame: str) -> Impact:
        """Return a pending impact with its error bars; log its line, publish its markers."""
        impact = pending.measure()
        self._lines.info(describe_impact(impact))
        markers = self._markers(impact, frame)
        if markers is not None:
            self._outputs['markers'].publish(markers)
        return impact

    def _markers(self, impact: Impact, frame: str) -> Optional[bytes]:
        """Return an impact's markers (CDR bytes), or None when ``publish_markers`` is off."""
        if not self.settings['publish_markers']:
            return None
        return scene_cdr(impact_scene(impact, frame, self.detector.config,
                                      self.settings['marker_lifetime']))

    def _publish(self, output: EventOutput) -> None:
        """Publish what one event became and log its line."""
        if output.predicting is not None:
            self._set_predicting(output.predicting)
        for name, message in output.messages:
            self._outputs[name].publish(message)
        if output.impact_ns is not None:
            self.tally.last_impact_ns = output.impact_ns
        if not output.log:
            return
        logger = self._lines
        if output.throttled:
            if self._log_throttle.allows('event'):
                logger.info(output.log)
        elif output.echoes_clock_jump and time.monotonic() - self._clock_jump_at < CLOCK_ECHO_S:
            logger.debug(output.log)  # the clock jump already warned
        elif output.level == 'warning':
            logger.warning(output.log)
        else:
            logger.info(output.log)

    def _publish_live_markers(self) -> None:
        """
        Publish the last accepted bat and ball as markers (timer, steady clock).

        Stamped with the newest of their samples' stamps; published only when a new sample
        came since the last array (they expire two periods after input stops).
        """
        if not self.settings['publish_markers']:
            return
        with self._lock:
            last = dict(self._last_values)
            frame = self.detector.frame_id or ''
            config = self.detector.config
        newest = max((stamp for stamp, _ in last.values()), default=None)
        if newest is None or newest == self._markers_stamp:
            return  # nothing new: no republish
        self._markers_stamp = newest
        scene = latest_scene(last, frame, config, 2.0 / self.settings['marker_rate'])
        if scene is not None:
            self._outputs['markers'].publish(scene_cdr(scene))

    def _clear_markers(self, stamp_ns: int, frame: str) -> None:
        """After a state reset: forget the live values, clear the markers (DELETEALL)."""
        self._last_values.clear()
        self._watch.clear()
        self._markers_stamp = None
        if self.settings['publish_markers']:
            self._outputs['markers'].publish(scene_cdr(
                Scene(stamp_ns, frame, (), delete_all=True)))
