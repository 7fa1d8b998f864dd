"""
Offline analysis of a bag: the one detector over recorded samples, in the bag's order.

No rclpy: this is the ``baseball-collision analyze`` path and runs on rosbags (through
:mod:`baseball_collision.bags`) and the core only.

:func:`analyze_bag` reads a bag with :class:`~baseball_collision.bags.BagReader`, feeds every
sample to the detector in the bag's order, then
:meth:`~baseball_collision.core.detector.Detector.finish`, handing samples and events to sinks:
the :class:`BagAnalysis` files the events; with ``--predict`` the frame stamps are kept to score
the predictions; with ``--out-bag`` every input topic and what the node would publish are
written into an MCAP (:mod:`.outbag`). When only events (and the frame stamps) are wanted the
bag goes a chunk of arrays at a time to ``Detector.add_chunk`` (:func:`run_detector_chunks`);
a sink that needs each sample gets the loop of :meth:`Detector.add
<baseball_collision.core.detector.Detector.add>` per sample (:func:`run_detector`): the same
events either way. The result is compared with the truth file beside the bag when there is one.
"""

from collections import Counter
from dataclasses import dataclass, field
import itertools
import os
from pathlib import Path
import sys
import time
from typing import (
    Any, Callable, Dict, Iterable, Iterator, List, Mapping, Optional, Protocol, Sequence,
    Tuple, TYPE_CHECKING, Union)

import numpy as np

from .events import event_kind
from .parameters import build_config, NODE_NAME, Remapping, TOPIC_PARAMETERS
from .truth import (
    compare_truth, LEADS_S, load_truth, PredictionIndex, silence_clearings, truth_path,
    TruthComparison)
from ..bags import BagReader, PATH, TOPIC_FLAGS, TopicSelection
from ..core.detector import (
    DEFAULTS, Detector, DetectorConfig, DetectorStats, Impact, NearMiss, Prediction,
    PredictionCleared, StateReset, StreamGap, unknown_parameters)
from ..core.detector.chunks import ROLE_CODES
from ..core.detector.predictor import kept_flight_span
from ..errors import BagError, ToolError

if TYPE_CHECKING:  # the writer's modules are imported only when a bag is written
    from ..bags import BagWriter

PROGRESS_MIN_MESSAGES = 100_000
"""Bags with more messages than this get a progress bar (also any bag when stderr is a TTY)."""

CHUNK = 8192
"""Samples read between two progress bar updates, and given to the detector at once."""

ROLE_NAMES = {code: role for role, code in ROLE_CODES.items()}
"""A chunk's role codes' roles (``SampleChunk.roles``)."""

SCORE_WINDOW_NS = 500_000_000
"""Predictions made more than this (ns) before an impact are not its predictions."""


@dataclass
class BagAnalysis:
    """
    What the detector found in one bag.

    :ivar path: the bag.
    :ivar selection: the topics read.
    :ivar config: the detector configuration used.
    :ivar impacts, near_misses, gaps, resets: the detector's events, in order.
    :ivar predictions: predicted impacts (with ``--predict``), in order.
    :ivar cleared: the detector's ``PredictionCleared`` events, in order: a prediction is in
        force until the next one or such a clearing.
    :ivar stats: the detector's counters (``dropped`` by reason).
    :ivar messages: samples read and fed.
    :ivar seconds: wall time of reading and detecting (s).
    :ivar first_stamp_ns: the first sample's header stamp (ns): the table's time origin.
    :ivar truth: the comparison with the truth file beside the bag, if there is one.
    :ivar frame_id: the frame of the events (the configured one, else the first sample's).
    :ivar notes: what the reader should know (a truth file ignored, and why).
    :ivar drops_by_role: dropped samples by ``(role, reason)``.
    :ivar noise: the ball's and the bat's tracking noise at the bag's end (m, 1 sigma per
        coordinate: ``Detector.noise``, told or estimated under auto; 0: exact).
    :ivar stamp_spans: each role's first and last header stamp (ns, the smallest and the
        largest), of every sample read (dropped ones too).
    :ivar first_frames: each role's first sample's ``frame_id``.
    :ivar frame_disagreement: each stream's frames where they have none in common, so none
        was adopted (``Detector.frame_disagreement``); None: no such disagreement.
    :ivar rates: with ``AnalysisOptions.decimate``: the impacts at each lower rate against
        these (``rates.RateCheck``, one per factor).
    """

    path: Path
    selection: TopicSelection
    config: DetectorConfig
    impacts: List[Impact] = field(default_factory=list)
    near_misses: List[NearMiss] = field(default_factory=list)
    gaps: List[StreamGap] = field(default_factory=list)
    resets: List[StateReset] = field(default_factory=list)
    predictions: List[Prediction] = field(default_factory=list)
    cleared: List[PredictionCleared] = field(default_factory=list)
    stats: DetectorStats = field(default_factory=DetectorStats)
    messages: int = 0
    seconds: float = 0.0
    first_stamp_ns: Optional[int] = None
    truth: Optional[TruthComparison] = None
    frame_id: str = ''
    notes: List[str] = field(default_factory=list)
    drops_by_role: Counter = field(default_factory=Counter)
    noise: Tuple[float, float] = (0.0, 0.0)
    stamp_spans: Dict[str, Tuple[int, int]] = field(default_factory=dict)
    first_frames: Dict[str, str] = field(default_factory=dict)
    frame_disagreement: Optional[str] = None
    rates: List[Any] = field(default_factory=list)

    @property
    def throughput(self) -> float:
        """Return samples per second of wall time (0 when nothing was timed)."""
        return self.messages / self.seconds if self.seconds > 0.0 else 0.0

    def relative_s(self, stamp_ns: int) -> float:
        """Return seconds from the first header stamp of the bag to ``stamp_ns``."""
        return (stamp_ns - (self.first_stamp_ns or 0)) * 1e-9

    def on_events(self, events: Iterable[Any], log_time_ns: int, frame_id: str) -> None:
        """File events into their lists by kind (an event sink; other types are not kept)."""
        for event in events:
            kind = event_kind(event)
            if kind is not None:
                getattr(self, kind.collection).append(event)

    def on_sample(self, role: str, stamp_ns: int, frame_id: str, values: Sequence[float],
                  log_time_ns: int) -> None:
        """Note a sample's role's stamp span and first frame (a sample sink)."""
        span = self.stamp_spans.get(role)
        if span is None:
            self.stamp_spans[role] = (stamp_ns, stamp_ns)
            self.first_frames[role] = frame_id
        elif not span[0] <= stamp_ns <= span[1]:
            self.stamp_spans[role] = (min(span[0], stamp_ns), max(span[1], stamp_ns))

    def on_chunk(self, chunk: Any) -> None:
        """Note a chunk's roles' stamp spans and first frames (a chunk sink: no sample loop)."""
        roles, stamps = chunk.roles, chunk.stamps_ns
        for code in np.flatnonzero(np.bincount(roles, minlength=len(ROLE_NAMES))):
            role = ROLE_NAMES[code]
            mine = roles == code
            low, high = int(stamps[mine].min()), int(stamps[mine].max())
            span = self.stamp_spans.get(role)
            if span is None:
                self.first_frames[role] = chunk.frame_ids[int(np.argmax(mine))]
                self.stamp_spans[role] = (low, high)
            elif low < span[0] or high > span[1]:
                self.stamp_spans[role] = (min(span[0], low), max(span[1], high))

    def unsolved_note(self) -> Optional[str]:
        """
        Return why nothing could be solved though the ball and the bat were read (None: solved).

        Their stamps never overlapping (two clocks), or overlapping but with every step of a
        stream longer than ``max_gap`` (a pause in tracking: never interpolated).
        """
        received = self.stats.received
        bat_roles = [role for role in ('bat_pose', 'knob', 'tip') if received.get(role)]
        if self.stats.intervals or not received.get('ball') or not bat_roles:
            return None
        spans = [self.stamp_spans[role] for role in ['ball'] + bat_roles
                 if role in self.stamp_spans]
        if len(spans) > 1 and max(low for low, _ in spans) > min(high for _, high in spans):
            return ('the ball and the bat were never tracked at the same time (their stamps do '
                    'not overlap): nothing could be solved; are both stamped by one clock?')
        pauses = Counter(gap.stream for gap in self.gaps)
        counted = ', '.join(f'{stream} {count}' for stream, count in sorted(pauses.items()))
        topics = ', '.join(f'{role} {topic}' for role, topic in self.selection.topics.items())
        return (f'the ball and the bat were tracked at the same time (their stamps overlap) '
                f'but nothing could be solved: no stretch had both streams stepping within '
                f'max_gap ({self.config.max_gap:g} s; pauses in tracking: {counted or "none"}); '
                f'are these the topics ({topics}), and is a stream that slow? (a larger max_gap '
                'in --params interpolates longer steps)')

    def silenced_topics(self) -> List[str]:
        """
        Return why selected topics had every one of their samples dropped (empty: none had).

        One line per set of reasons: the topics with their counts, the reasons; with a hint
        when the frames disagree (each topic's frame named; with no frame in common, each
        stream's frames as the detector names them) or the header stamps are zero.
        """
        silenced: Dict[Tuple[str, ...], List[str]] = {}
        for role, topic in self.selection.topics.items():
            received = self.stats.received.get(role, 0)
            reasons = tuple((reason, count) for (dropped_role, reason), count
                            in sorted(self.drops_by_role.items()) if dropped_role == role)
            if received and sum(count for _, count in reasons) >= received:
                silenced.setdefault(tuple(reason for reason, _ in reasons), []).append(role)
        lines = []
        for reasons, roles in silenced.items():
            topics = self.selection.topics
            counted = ' and '.join(f'{topics[role]} ({self.stats.received.get(role, 0)})'
                                   for role in roles)
            line = f"every sample of {counted} was dropped ({', '.join(reasons)})"
            if 'wrong_frame' in reasons:
                line += ': ' + self._frames_hint(roles)
            if 'no_common_frame' in reasons and self.frame_disagreement:
                line += (f': {self.frame_disagreement}: no frame every input sends, so none was '
                         "adopted (frame_id ''): set frame_id or transform one stream into the "
                         "other's frame (no TF)")
            if 'bad_stamp' in reasons:
                line += ('; their header stamps are zero (or before 1970): the detector, as the '
                         'node, times every sample by its header stamp and needs real stamps '
                         "(the bag's recording times are not used): stamp the tracker's "
                         'messages')
            lines.append(line)
        return lines

    def _frames_hint(self, dropped: Sequence[str]) -> str:
        """Return each selected topic's frame, against the configured or tracked frame."""
        topics = self.selection.topics

        def framed(roles: Sequence[str]) -> str:
            return ', '.join(f"{topics[role]} in '{self.first_frames[role]}'" for role in roles
                             if role in self.first_frames)

        kept = [role for role in topics if role not in dropped]
        frames = framed(dropped) or ' and '.join(topics[role] for role in dropped) + \
            ' in another frame'
        if self.config.frame_id:
            return (f"frame_id '{self.config.frame_id}' is configured and {frames} (every "
                    'input must be in that frame: no TF)')
        tracked = f"'{self.frame_id}'" if self.frame_id else "the first sample's frame"
        others = framed(kept)
        return (frames + (f', but {others}' if others else '')
                + f" (the tracking frame is {tracked}, the first sample's); every input must "
                "share one frame (no TF: transform one stream into the other's frame)")

    def prediction_scores(self) -> List[Dict[float, Optional[Tuple[float, float]]]]:
        """
        Score the predictions of every impact at the lead times ``LEADS_S``.

        The reference is the true contact when a truth file matched the impact, else the
        detected impact itself; predictions made up to :data:`SCORE_WINDOW_NS` before it
        count. One ``PredictionIndex.errors`` dict per impact; the predictions are indexed once.
        """
        truths = {}
        if self.truth is not None:
            truths = {impact.stamp_ns: truth for truth, impact in self.truth.matched}
        # (a reset ends the prediction in force too: the node turns ~/impact_predicted off;
        # and a ball silent past its flight's span, as the node's does: silence_clearings)
        cleared = [event.made_at_ns for event in self.cleared] + [
            reset.stamp_ns for reset in self.resets]
        index = PredictionIndex(self.predictions, cleared)
        silences = silence_clearings(
            index, [(gap.start_ns, gap.end_ns) for gap in self.gaps if gap.stream == 'ball'],
            self.config.max_gap, kept_flight_span(self.config.prediction_window))
        if silences:
            index = PredictionIndex(self.predictions, cleared + silences)
        scores = []
        for impact in self.impacts:
            truth = truths.get(impact.stamp_ns)
            stamp = int(truth['stamp_ns']) if truth else impact.stamp_ns
            point = truth['point'] if truth else impact.point
            scores.append(index.errors(stamp, point, LEADS_S, SCORE_WINDOW_NS))
        return scores


@dataclass(frozen=True)
class AnalysisOptions:
    """
    How to analyse: topics, parameters and overrides (None: not given).

    :ivar ball_topic, bat_pose_topic, knob_topic, tip_topic: topic flags.
    :ivar parameters: flat node parameters from ``--params`` (empty: none).
    :ivar model: ``--model``.
    :ivar ball_radius: ``--ball-radius`` (m).
    :ivar bat_radius: ``--bat-radius`` (m).
    :ivar prediction_horizon: ``--predict`` horizon (s).
    :ivar node_name: the node whose output topics ``--out-bag`` writes, and whose namespace
        the parameter file's relative topics take (``cage2/impact_node``: ``/cage2/ball``).
    :ivar topic_flags: the caller has the topic flags (``analyze``'s command line): an error
        about a topic from the parameter file names the flag that overrides it; False (the
        demo, which replays a bag's own topics): it does not.
    :ivar bat_plan_topic: ``--bat-plan-topic``: the bag's topic of an arm's bat plans
        (``nav_msgs/Path``), as the node's ``bat_plan_topic`` ('': none, whatever the parameter
        file says; None: the file's).
    :ivar remaps: ``--remap``: the node's remapping rules (``FROM:=TO``, as ``--ros-args -r``
        takes them; ``parameters.Remapping``): the topics the node would subscribe to and
        publish, the node renamed or moved (``__node``, ``__ns``).
    :ivar every, phase: analyse only every ``every``-th sample of each input, from its
        ``phase``-th (0 first): the recording at a lower rate (:func:`decimated_chunks`).
    :ivar decimate: ``--decimate``: factors K at which the bag is analysed again, every K-th
        frame in each of its K phases, and the impacts compared with this analysis's
        (``rates.check_rates``: ``BagAnalysis.rates``).
    """

    ball_topic: Optional[str] = None
    bat_pose_topic: Optional[str] = None
    knob_topic: Optional[str] = None
    tip_topic: Optional[str] = None
    parameters: Mapping[str, Any] = field(default_factory=dict)
    model: Optional[str] = None
    ball_radius: Optional[float] = None
    bat_radius: Optional[float] = None
    prediction_horizon: Optional[float] = None
    node_name: str = NODE_NAME
    topic_flags: bool = True
    bat_plan_topic: Optional[str] = None
    remaps: Tuple[str, ...] = ()
    every: int = 1
    phase: int = 0
    decimate: Tuple[int, ...] = ()

    def __post_init__(self) -> None:
        """
        Refuse parameters that are not a mapping of names to values, and bad remapping rules.

        :raises ToolError: a parameter file's path (``load_parameters`` reads it), a list of
            pairs: each raised AttributeError from inside ``analyze_bag``; a rule
            ``Remapping.parse`` refuses; ``every`` under 1, a ``phase`` outside 0 to ``every``
            - 1, a ``decimate`` factor under 2 (or not an integer).
        """
        for name, value, least in (('every', self.every, 1), ('phase', self.phase, 0),
                                   *(('decimate', k, 2) for k in self.decimate)):
            if isinstance(value, bool) or not isinstance(value, int) or value < least:
                raise ToolError(f'AnalysisOptions({name}=...) takes whole numbers from {least}, '
                                f'not {value!r}')
        if self.phase >= self.every:
            raise ToolError(f'AnalysisOptions(phase={self.phase}) must be under every='
                            f'{self.every}')
        if not isinstance(self.parameters, Mapping):
            raise ToolError('AnalysisOptions(parameters=...) takes node parameters by name (a '
                            f'dict), not {type(self.parameters).__name__} {self.parameters!r:.60}'
                            ' (a parameter file: load_parameters(path))')
        if isinstance(self.remaps, str):
            raise ToolError(f'AnalysisOptions(remaps=...) takes a sequence of rules, not the '
                            f'string {self.remaps!r}')
        self.remapping()

    def remapping(self) -> Remapping:
        """Return the node as ``remaps`` rename it and its topics (``Remapping``)."""
        return Remapping.parse(self.remaps, self.node_name)

    def _remapped(self, parameter: str) -> Tuple[Optional[str], Optional[str]]:
        """
        Return a topic parameter's topic as the node takes it, and the rule that renamed it.

        The parameter file's (``remaps`` applied), else with a rule for it the default's; (None,
        None) for neither, or an empty topic (the plan's default: none).
        """
        name = self.parameters.get(parameter)
        if not name and not self.remaps:
            return None, None
        remapping = self.remapping()
        if not name:
            name = DEFAULTS[parameter]
            if not name:
                return None, None
            topic, rule = remapping.topic(name)
            return (topic, rule) if rule else (None, None)
        return remapping.topic(name)

    def topic(self, role: str) -> Optional[str]:
        """
        Return the topic asked for a role: its flag, else the parameter file's, else None.

        A parameter file's topic is expanded as the node expands it, for ``node_name``
        (``ball`` -> ``/ball``, ``/cage2/ball`` under ``/cage2``: ``resolve_topic``), and
        remapped by ``remaps``, as is the node's default topic where a rule renames it; the
        file's bat topics count only for its ``bat_input`` (``pose`` by default), and none of
        them when a topic flag names a bat topic.
        """
        flags = {'ball': self.ball_topic, 'bat_pose': self.bat_pose_topic,
                 'knob': self.knob_topic, 'tip': self.tip_topic}
        if flags[role] is not None:
            return flags[role]
        if role != 'ball' and any(flags[bat] for bat in ('bat_pose', 'knob', 'tip')):
            return None
        points = self.parameters.get('bat_input') == 'points'
        if (role == 'bat_pose' and points) or (role in ('knob', 'tip') and not points):
            return None
        return self._remapped(TOPIC_PARAMETERS[role])[0]

    def plan_topic(self) -> Optional[str]:
        """
        Return the bat plan topic: ``bat_plan_topic`` given here, else the parameter file's.

        The file's expanded and remapped as the node expands and remaps it (``_remapped``);
        None for none.
        """
        if self.bat_plan_topic is not None:
            return self.bat_plan_topic or None
        return self._remapped(TOPIC_PARAMETERS['bat_plan'])[0]

    def named(self) -> Dict[str, str]:
        """
        Return how the bag's errors name each topic the parameter file or a rule gave, by role.

        By its parameter, where it came from and the flag that overrides it:
        ``ball_topic '/x' (from the parameter file; --ball-topic overrides it)``, ``ball_topic
        '/y' (the default, remapped by --remap ball:=/y; ...)`` (without the
        flag where the caller has none: ``topic_flags``). A topic a flag gave is named by its
        flag, the reader's default.
        """
        named = {}
        for role, flag in TOPIC_FLAGS.items():
            topic = self.topic(role)
            if topic and getattr(self, f'{role}_topic') is None:
                parameter = TOPIC_PARAMETERS[role]
                rule = self._remapped(parameter)[1]
                given = 'from the parameter file' if self.parameters.get(parameter) else \
                    'the default'
                named[role] = f"{parameter} '{topic}' ({given}" + (
                    f', remapped by --remap {rule}' if rule else '') + (
                    f'; {flag} overrides it)' if self.topic_flags else ')')
        return named

    def reader(self, path: os.PathLike) -> BagReader:
        """Return an unopened reader of ``path`` with these topic choices."""
        prefer = 'points' if self.parameters.get('bat_input') == 'points' else 'pose'
        return BagReader(path, ball=self.topic('ball'), bat_pose=self.topic('bat_pose'),
                         knob=self.topic('knob'), tip=self.topic('tip'), prefer_bat=prefer,
                         named=self.named())


# ----------------------------------------------------------------------------------------------
# Sinks: what the loop hands samples and events to


class SampleSink(Protocol):
    """Receives every sample, before the detector sees it."""

    def on_sample(self, role: str, stamp_ns: int, frame_id: str, values: Sequence[float],
                  log_time_ns: int) -> None:
        """Take one sample (as :class:`~baseball_collision.bags.Sample` gives it)."""


class EventSink(Protocol):
    """Receives the detector's events with the log time and frame of the sample that gave them."""

    def on_events(self, events: Sequence[Any], log_time_ns: int, frame_id: str) -> None:
        """Take the events of one sample (or of ``finish()``: the last sample's time, frame)."""


Sink = Union[SampleSink, EventSink]
"""What the loops hand samples and events to: a sample sink, an event sink, or both."""


# ----------------------------------------------------------------------------------------------
# An arm's bat plans, where the samples pass them


class PlanFeed:
    """
    Hand a bag's bat plans to the detector where the samples' log times pass them.

    What the live node does with a plan on its plan topic: takes it when it arrives, before the
    samples that arrive after it (``Detector.take_bat_plan``: the node's rules; a plan refused
    is counted with its reason). A plan goes before every sample logged after it; samples
    logged at its very instant go first.

    :param plans: the bag's plan messages in log-time order (``bags.PlanMessage``).
    :param detector: the detector the analysis feeds.
    """

    def __init__(self, plans: Sequence[Any], detector: Any) -> None:
        self._plans, self._detector, self._next = list(plans), detector, 0
        self.taken = 0
        self.refused: Counter = Counter()  # reasons, counted
        self.next_ns = self._plans[0].log_time_ns if self._plans else None

    def take_before(self, log_time_ns: int) -> None:
        """Take every plan logged before ``log_time_ns`` (ns) not taken yet."""
        plans = self._plans
        while self._next < len(plans) and plans[self._next].log_time_ns < log_time_ns:
            plan = plans[self._next]
            self._next += 1
            reason = plan.refused or self._detector.take_bat_plan(
                plan.stamps_ns, plan.positions, plan.quaternions, plan.frames)
            if reason is None:
                self.taken += 1
            else:
                self.refused[reason] += 1
        self.next_ns = plans[self._next].log_time_ns if self._next < len(plans) else None

    def note(self, topic: str) -> str:
        """Return what the analysis did with the plans, for its notes."""
        refused = sum(self.refused.values())
        why = '; '.join(f'{count} x {reason}' for reason, count in self.refused.most_common())
        return (f"bat plans on '{topic}': {self.taken} taken for the predictions"
                + (f', {refused} refused ({why})' if refused else ''))


def _pieces(chunk: Any, plans: Optional[PlanFeed]) -> Iterable[Any]:
    """Yield a chunk cut where plans fall among its samples, taking each plan between."""
    while plans is not None and plans.next_ns is not None and \
            plans.next_ns < int(chunk.log_times_ns[-1]):
        cut = int(np.searchsorted(chunk.log_times_ns, plans.next_ns, side='right'))
        if cut:  # (every field of a SampleChunk is per sample)
            yield type(chunk)(*(part[:cut] for part in chunk))
            chunk = type(chunk)(*(part[cut:] for part in chunk))
        plans.take_before(int(chunk.log_times_ns[0]))
    if plans is not None:
        plans.take_before(int(chunk.log_times_ns[0]))
    yield chunk


# ----------------------------------------------------------------------------------------------
# The loop


def decimated_chunks(chunks: Iterable[Any], every: int, phase: int) -> Iterator[Any]:
    """
    Yield the chunks' samples at a lower rate: every ``every``-th of each role.

    From each role's ``phase``-th sample (0: its first), as a tracker at 1 / ``every`` of the
    rate would have sent them. Each role is counted on its own (a ball at another rate than
    the bat keeps its own); chunks left empty are not yielded. ``every`` 1 yields the chunks
    as they are.
    """
    if every == 1:
        yield from chunks
        return
    counts = np.zeros(len(ROLE_CODES), np.int64)
    for chunk in chunks:
        index = np.empty(len(chunk.roles), np.int64)
        for code in range(len(ROLE_CODES)):
            mine = chunk.roles == code
            taken = int(np.count_nonzero(mine))
            if taken:
                index[mine] = counts[code] + np.arange(taken)
                counts[code] += taken
        keep = index % every == phase
        if keep.all():
            yield chunk
        elif keep.any():
            frames = [frame for frame, kept in zip(chunk.frame_ids, keep.tolist()) if kept]
            yield type(chunk)(chunk.roles[keep], chunk.stamps_ns[keep], frames,
                              chunk.values[keep], chunk.log_times_ns[keep])


def decimated_samples(samples: Iterable[Any], every: int, phase: int) -> Iterator[Any]:
    """Yield the samples :func:`decimated_chunks` keeps, one at a time (``Sample`` tuples)."""
    counts: Counter = Counter()
    for sample in samples:
        index = counts[sample[0]]
        counts[sample[0]] += 1
        if index % every == phase:
            yield sample


def _fan_out(methods: Sequence[Callable[..., None]]) -> Optional[Callable[..., None]]:
    """Return one callable calling every method in turn (the method itself for one; None)."""
    if not methods:
        return None
    if len(methods) == 1:
        return methods[0]

    def call(*args: Any) -> None:
        for method in methods:
            method(*args)
    return call


def run_detector(samples: Iterable[Sequence[Any]], detector: Any,
                 sinks: Sequence[Sink], bar: Any = None,
                 drops: Optional[Counter] = None,
                 plans: Optional[PlanFeed] = None) -> Tuple[int, Optional[int]]:
    """
    Feed every sample to the detector, then ``finish()``; hand samples and events to sinks.

    The one analyze loop. Per sample: the sample sinks (:class:`SampleSink`), then
    ``detector.add``, then, if it returned events, the event sinks (:class:`EventSink`); the
    events of ``finish()`` go to the event sinks with the last sample's log time and frame.
    With no sample sink the loop does nothing but ``add`` per sample (the fast path).

    :param samples: ``(role, stamp_ns, frame_id, values, log_time_ns)`` tuples
        (:class:`~baseball_collision.bags.Sample`), in the bag's order.
    :param detector: a :class:`~baseball_collision.core.detector.Detector` (or anything with
        its ``add(role, stamp_ns, values, frame_id)`` and ``finish()``).
    :param sinks: objects with ``on_sample`` and/or ``on_events``.
    :param bar: a progress bar (``update(n)``) or None.
    :param drops: counts ``(role, reason)`` of every dropped sample (from the detector's
        ``stats.last_drop_reason`` and ``stats.late_drops``) when given.
    :param plans: the bag's bat plans, each taken before the first sample logged after it.
    :returns: (samples fed, the first sample's stamp in ns or None for none).
    """
    add = detector.add
    plan_ns = None if plans is None else plans.next_ns
    on_sample = _fan_out([sink.on_sample for sink in sinks if hasattr(sink, 'on_sample')])
    on_events = _fan_out([sink.on_events for sink in sinks if hasattr(sink, 'on_events')]) \
        or (lambda events, log_time_ns, frame_id: None)
    stats = detector.stats if drops is not None else None
    iterator = iter(samples)
    first = next(iterator, None)
    head = () if first is None else (first,)
    # the first sample is peeked for its stamp and put back in the first chunk only
    pending = itertools.chain(head, itertools.islice(iterator, CHUNK - len(head)))
    count, log_time, frame = 0, 0, ''
    while True:
        chunk = 0
        for role, stamp, frame, values, log_time in pending:
            if plan_ns is not None and plan_ns < log_time:
                plans.take_before(log_time)
                plan_ns = plans.next_ns
            if on_sample is not None:
                on_sample(role, stamp, frame, values, log_time)
            events = add(role, stamp, values, frame)
            if events:
                on_events(events, log_time, frame)
            if stats is not None:
                if stats.last_drop_reason is not None:
                    drops[role, stats.last_drop_reason] += 1
                for late in stats.late_drops:  # samples that waited, dropped by this call
                    drops[late.role, late.reason] += 1
            chunk += 1
        count += chunk
        if bar is not None:
            bar.update(chunk)
        if chunk < CHUNK:
            break
        pending = itertools.islice(iterator, CHUNK)
    events = detector.finish()
    if stats is not None:
        for late in stats.late_drops:
            drops[late.role, late.reason] += 1
    if events:
        on_events(events, log_time, frame)
    return count, None if first is None else first[1]


def run_detector_chunks(chunks: Iterable[Any], detector: Any, sinks: Sequence[Sink],
                        bar: Any = None, drops: Optional[Counter] = None,
                        plans: Optional[PlanFeed] = None) -> Tuple[int, Optional[int]]:
    """
    :func:`run_detector` a chunk at a time, for event and chunk sinks only (no sample sink).

    A chunk sink's ``on_chunk`` is given each chunk before the detector.

    Each chunk goes to ``detector.add_chunk`` (the common case with numpy, the rest sample by
    sample: the same events as :func:`run_detector`); its events go to the event sinks with
    the chunk's last log time and frame.

    :param chunks: :class:`~baseball_collision.bags.SampleChunk` in the bag's order.
    :param detector: a :class:`~baseball_collision.core.detector.Detector` (or anything with
        its ``add_chunk`` and ``finish()``).
    :param sinks: objects with ``on_events`` and/or ``on_chunk`` (others are ignored).
    :param bar: a progress bar (``update(n)``) or None.
    :param drops: counts ``(role, reason)`` of every dropped sample when given.
    :param plans: the bag's bat plans: a chunk is cut where one falls among its samples, and
        the plan taken between the pieces (``run_detector``'s order).
    :returns: (samples fed, the first sample's stamp in ns or None for none).
    """
    on_events = _fan_out([sink.on_events for sink in sinks if hasattr(sink, 'on_events')]) \
        or (lambda events, log_time_ns, frame_id: None)
    on_chunk = _fan_out([sink.on_chunk for sink in sinks if hasattr(sink, 'on_chunk')])
    count, first, log_time, frame = 0, None, 0, ''
    for whole in chunks:
        for chunk in _pieces(whole, plans):
            n = len(chunk.stamps_ns)
            if first is None:
                first = int(chunk.stamps_ns[0])
            if on_chunk is not None:
                on_chunk(chunk)
            events = detector.add_chunk(chunk.roles, chunk.stamps_ns, chunk.values,
                                        chunk.frame_ids, drops)
            log_time, frame = int(chunk.log_times_ns[-1]), chunk.frame_ids[-1]
            if events:
                on_events(events, log_time, frame)
            count += n
            if bar is not None:
                bar.update(n)
    events = detector.finish()
    if drops is not None:
        for late in detector.stats.late_drops:
            drops[late.role, late.reason] += 1
    if events:
        on_events(events, log_time, frame)
    return count, first


def progress_bar(total: int, label: str) -> Any:
    """Return a tqdm bar on stderr for long bags or a terminal, else None."""
    if total <= PROGRESS_MIN_MESSAGES and not sys.stderr.isatty():
        return None
    from tqdm import tqdm
    return tqdm(total=total, unit='msg', unit_scale=True, desc=label, file=sys.stderr,
                leave=False, dynamic_ncols=True)


def analyze_bag(path: Union[str, os.PathLike], options: AnalysisOptions = AnalysisOptions(), *,
                out_bag: Optional['BagWriter'] = None, progress: bool = True,
                use_truth: bool = True, read_ahead: int = 1) -> BagAnalysis:
    """
    Run the detector over a bag: every selected sample in the bag's order, then ``finish()``.

    :param path: ROS 2 bag directory, ``.mcap``/``.db3`` file or ROS 1 ``.bag`` file.
    :param options: topics, parameters and overrides.
    :param out_bag: an open writer that receives the input samples and the event messages.
    :param progress: show a progress bar on stderr for long bags (see :func:`progress_bar`).
    :param use_truth: compare with the truth file beside the bag when there is one.
    :param read_ahead: an MCAP or sqlite3 bag's file chunks or batches read ahead on a
        background thread while the detector works (``BagReader.chunks``; 0: none): on a
        spare core the reading overlaps the detector, the same events.
    :returns: the analysis.
    :raises ToolError: the bag cannot be read (missing, empty, corrupt, without the needed
        topics or with topics of the wrong type), a bad setting, or a failure writing
        ``out_bag``. A damaged truth file is not an error: it is ignored, with a note
        (``BagAnalysis.notes``). ``options`` that are not ``AnalysisOptions``, a path that is
        not a str or path.
    """
    if not isinstance(options, AnalysisOptions):
        raise ToolError(f'options must be AnalysisOptions, not {type(options).__name__} (node '
                        'parameters as a dict: AnalysisOptions(parameters=values))')
    if not isinstance(path, (str, os.PathLike)):
        raise ToolError(f'path must be a bag path (str or Path), not {type(path).__name__}')
    path = Path(path)
    start = time.perf_counter()
    try:
        with options.reader(path) as bag:
            config = build_config(options.parameters, bat_input=bag.selection.bat_mode,
                                  model=options.model, ball_radius=options.ball_radius,
                                  bat_radius=options.bat_radius,
                                  prediction_horizon=options.prediction_horizon)
            result = BagAnalysis(path=path, selection=bag.selection, config=config,
                                 notes=list(bag.notes))
            sinks: List[Sink] = [result]
            detector = Detector(config)
            plan_topic = options.plan_topic() if config.prediction_horizon > 0.0 else None
            plans = _bag_plans(bag, plan_topic, detector, result.notes)
            copy = None
            if out_bag is not None:
                from .outbag import FoxgloveCopy  # (imported only for an output bag)
                copy = FoxgloveCopy(out_bag, path, detector, bag.selection.topics,
                                    options.parameters, options.remapping(), config.frame_id)
                copy.open()
                sinks.append(copy)
            bar = progress_bar(bag.message_count, path.name) if progress else None
            try:
                if any(hasattr(sink, 'on_sample') and not hasattr(sink, 'on_chunk')
                       for sink in sinks):
                    samples = bag.samples()
                    result.messages, result.first_stamp_ns = run_detector(
                        samples if options.every == 1 else decimated_samples(
                            samples, options.every, options.phase),
                        detector, sinks, bar, result.drops_by_role, plans)
                else:  # events (and the frames' stamps) only: a chunk at a time
                    result.messages, result.first_stamp_ns = run_detector_chunks(
                        decimated_chunks(bag.chunks(CHUNK, read_ahead), options.every,
                                         options.phase), detector, sinks, bar,
                        result.drops_by_role, plans)
                if plans is not None:
                    result.notes.append(plans.note(plan_topic))
                if copy is not None:
                    copy.close()
                    result.notes += copy.notes()
            finally:
                if bar is not None:
                    bar.close()
                if copy is not None:
                    copy.release()
    except BagError as error:
        raise ToolError(str(error)) from error
    result.seconds = time.perf_counter() - start
    result.stats = detector.stats
    result.noise = detector.noise
    result.frame_id = detector.frame_id or config.frame_id or ''
    result.frame_disagreement = detector.frame_disagreement
    unknown = unknown_parameters(options.parameters, options.remapping().node_name)
    if unknown is not None:  # (typos: rclpy would ignore them too)
        result.notes.append(unknown)
    unsolved = result.unsolved_note()
    if unsolved is not None:
        result.notes.append(unsolved)
    if use_truth:  # (--no-truth: never looked for)
        _compare_with_truth(result, path)
    if options.decimate:
        from .rates import check_rates
        result.rates = check_rates(result, options, read_ahead)
    return result


def _bag_plans(bag: BagReader, topic: Optional[str], detector: Detector,
               notes: List[str]) -> Optional[PlanFeed]:
    """
    Return the bag's bat plans on ``topic`` for the detector, or None (a note says why).

    None for no topic (noting a ``nav_msgs/Path`` topic of the bag then, which
    ``--bat-plan-topic`` would take) or one the bag lacks (the predictions then extrapolate
    the bat, as the node's would).

    :raises BagError: the topic is of another type, or cannot be read.
    """
    if topic is None:
        paths = [name for name, kind in bag.topics.items() if kind == PATH]
        if paths and detector.config.prediction_horizon > 0.0:
            notes.append(f"the bag's {PATH} topic {', '.join(repr(p) for p in paths)} was not "
                         'read: --bat-plan-topic TOPIC (bat_plan_topic in --params) predicts '
                         "with an arm's plans on it")
        return None
    plans = bag.plans(topic)
    if plans is None:
        notes.append(f"no bat plan topic '{topic}' in the bag: the predictions extrapolate "
                     'the bat')
        return None
    return PlanFeed(plans, detector)


def _compare_with_truth(result: BagAnalysis, path: Path) -> None:
    """
    Compare ``result`` with the truth file beside the bag at ``path``, where there is one.

    Sets ``result.truth``; a damaged truth file is ignored with a note, and one written for
    another bag's name is compared all the same, with a note.
    """
    truth_file = truth_path(path)
    if not truth_file.is_file():
        return
    try:
        truth = load_truth(truth_file)
        result.truth = compare_truth(result.impacts, result.near_misses, truth, truth_file)
    except ToolError as error:
        result.notes.append(f'{error}; the truth file was ignored')
    else:
        name = Path(os.path.abspath(path)).name  # ('.' is the directory one is in)
        made_for = Path(str(truth.get('bag', name))).name
        if made_for != name:
            result.notes.append(f'{truth_file.name} was written for {made_for}, not '
                                f'{name}: compared all the same (a renamed copy?)')
