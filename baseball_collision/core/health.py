"""
The detector's health as plain data: counters in, a status (level, message, grouped values) out.

Pure Python (no ROS): the node counts what arrives in a :class:`Tally`; once a period it copies
the tally and the detector's counters into a :class:`Snapshot` and :func:`health_status` turns
them into a :class:`HealthStatus`; ``ros.diagnostics`` converts that into a
``diagnostic_msgs/DiagnosticStatus``, and ``analyze --out-bag`` writes the same statuses into
``/diagnostics`` of its bag. Times are seconds on any monotonic clock passed in (wall time in
the node, the bag's log time offline); why a silent topic is silent (no publisher, another
type) is asked of the ROS graph by the node for the streams :func:`silent_streams` names.
"""

from collections import Counter
from dataclasses import dataclass, field
import enum
import math
from typing import Dict, List, Mapping, Optional, Tuple

from .detector import DetectorStats, DROP_REASONS

HARDWARE_ID = 'baseball_collision'
"""The status's ``hardware_id`` when the settings name none (``hardware_id`` '')."""

RESETS_ERROR = 3
"""State resets within one diagnostics period that make the status ERROR (one makes WARN)."""

LOSS_FACTOR = 1.5
"""A stamp step more than this many typical steps is a gap: messages lost (see StampGaps)."""

LOSS_GAP_MAX_NS = 1_000_000_000
"""A longer stamp step is a pause of the publisher (a stale input), not messages lost."""

OTHER_PUBLISHER_NS = 1_000_000_000
"""A message numbered next on a publisher track but stamped more than this (ns) behind where the
track would be is another publisher's (a stale one 3 s behind) or a jump back: it starts a track
of its own. Ahead is a pause or a glitch: it stays."""

NS_PER_S = 1_000_000_000


class Level(enum.IntEnum):
    """A status level, with the values of ``diagnostic_msgs/DiagnosticStatus``."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


Values = Tuple[Tuple[str, str], ...]
"""Key/value pairs, both text."""


@dataclass(frozen=True)
class HealthStatus:
    """
    One status: what ``/diagnostics`` says about the detector.

    :ivar level: OK, WARN, ERROR (or STALE).
    :ivar name: ``<node name>: impact detector``.
    :ivar message: one line: the state and the problems seen.
    :ivar hardware_id: what the status is about.
    :ivar groups: ``(group name, key/values)`` in order: ``state``, ``inputs``, ``drops``,
        ``events``, ``timing``, ``session``.
    """

    level: Level
    name: str
    message: str
    hardware_id: str
    groups: Tuple[Tuple[str, Values], ...]

    def values(self) -> Values:
        """Return every key/value of every group, in order."""
        return tuple(pair for _, pairs in self.groups for pair in pairs)


def format_stamp(stamp_ns: int) -> str:
    """Return integer nanoseconds as ``seconds.nanoseconds`` text."""
    return f'{stamp_ns // NS_PER_S}.{stamp_ns % NS_PER_S:09d}'


@dataclass
class Period:
    """
    Counters at the start of a diagnostics period, and the callback times inside it.

    :ivar start: monotonic s the period started.
    :ivar arrivals: messages received per stream since start-up, when it started.
    :ivar dropped: samples dropped since start-up, when it started.
    :ivar count, total_s, max_s: message callbacks in the period and their wall times (s).
    :ivar resets: the detector's state resets since start-up, when it started.
    :ivar lost: messages estimated lost per stream since start-up, when it started.
    """

    start: float
    arrivals: Counter
    dropped: int
    resets: int = 0
    lost: Counter = field(default_factory=Counter)
    count: int = 0
    total_s: float = 0.0
    max_s: float = 0.0

    def record(self, elapsed_s: float) -> None:
        """Account the wall time (s) one message took in its callback."""
        self.count += 1
        self.total_s += elapsed_s
        if elapsed_s > self.max_s:
            self.max_s = elapsed_s


class StampGaps:
    """
    Messages of one stream estimated lost from gaps in its header stamps.

    A publisher at a steady rate steps its stamps by about the same amount; a step of more
    than ``LOSS_FACTOR`` typical steps (the median of the last eight) and at most
    ``LOSS_GAP_MAX_NS`` (longer: a pause, reported as stale) means ``round(step / typical) -
    1`` messages did not arrive. A step is counted when the next stamp comes after it: a lone
    stamp glitched ahead (the next one comes before it) is not a gap, and its message counts
    as the one after the stamp before it (its own, misstamped). Stamps at or behind the newest
    (another publisher, a jump back) are ignored until the stream passes them.

    :param confirm: count a gap only when the step after it is a typical one (used where
        sequence numbers say nothing was lost in transport: a glitch, or a pause, right after
        the big step is then not a loss).
    :ivar lost: messages estimated lost so far.
    """

    __slots__ = ('lost', '_newest', '_steps', '_pending', '_confirm')

    def __init__(self, confirm: bool = False) -> None:
        self.lost = 0
        self._confirm = confirm
        self._newest: Optional[int] = None
        self._steps: List[int] = []
        self._pending: Optional[Tuple[int, int]] = None  # (stamp before the step, lost)

    def take(self, stamp_ns: int) -> None:
        """Count in the header stamp (ns) of the next message (see the class)."""
        newest = self._settle(stamp_ns)
        if newest is None or stamp_ns <= newest:
            if newest is None:
                self._newest = stamp_ns
            return
        step = stamp_ns - newest
        steps = self._steps
        typical = self._typical() or None
        if step > LOSS_GAP_MAX_NS or (typical is not None and step > LOSS_FACTOR * typical):
            lost = 0 if typical is None or step > LOSS_GAP_MAX_NS else round(step / typical) - 1
            self._pending = (newest, max(0, lost))  # decided by the next stamp
            self._newest = stamp_ns
            return
        steps.append(step)
        if len(steps) > 8:
            del steps[0]
        self._newest = stamp_ns

    def resume(self, stamp_ns: int) -> None:
        """
        Take the stamp (ns) of a message after messages counted elsewhere: no gap counted.

        The step before it is not a typical step either (:class:`PublisherGaps` counted the
        messages it spans from their sequence numbers).
        """
        newest = self._settle(stamp_ns)
        if newest is None or stamp_ns > newest:
            self._newest = stamp_ns

    def _settle(self, stamp_ns: int) -> Optional[int]:
        """Decide a pending big step by the stamp (ns) after it; return the newest stamp."""
        newest = self._newest
        if self._pending is not None:
            before, lost = self._pending
            self._pending = None
            if stamp_ns < newest:  # the big step was a lone glitch: it took the slot after
                newest = self._newest = before + self._typical()  # before (misstamped)
            elif not self._confirm or stamp_ns - newest <= LOSS_FACTOR * self._typical():
                self.lost += lost
        return newest

    @property
    def typical_ns(self) -> int:
        """Return the typical step between stamps (ns; 0 while unknown)."""
        return self._typical()

    def _typical(self) -> int:
        """Return the typical step (ns): the median of the last eight, 0 before four."""
        steps = self._steps
        return sorted(steps)[len(steps) // 2] if len(steps) >= 4 else 0


class PublisherGaps:
    """
    Messages of one stream lost, counted from each publisher's sequence numbers.

    An RMW that gives a message's publication sequence number (rmw_fastrtps_cpp: the
    writer's, 1, 2, 3 ... per publisher) makes transport losses exact: messages between two
    received numbers of one publisher never arrived, however long the pause between them and
    whatever their stamps said (a queue overflowing in a burst, a lossy link). rclpy gives no
    publisher id with the number, so each message is attributed to a publisher *track* (at
    most ``MAX_TRACKS``). Candidates are the tracks whose last number is below the message's,
    where the stamp is not behind the track's prediction (its last stamp + the numbers between
    x its typical step) by more than ``OTHER_PUBLISHER_NS`` for the next number, or by more
    than two typical steps and a twelfth of the skipped ones past a gap (the skipped messages
    needed that time, less the error of a typical step learnt from jittery stamps; a pause only
    adds to it; judged from the message before the last too, in case the last was a glitch
    ahead). The message joins first a track whose prediction it fits (within two typical
    steps; ``OTHER_PUBLISHER_NS`` while the step is unknown, or the stream's while a new track
    does not know its own), then the one whose stamps' mean pace (pauses included) predicts
    its stamp best (a pause before the next number explains itself). Without a candidate it
    starts a track
    of its own (a stale publisher 3 s behind, one that joined late with larger numbers,
    a jump back); the first message of a track counts nothing before it. Within a track,
    consecutive numbers whose stamps skip steps (a tracker that dropped frames upstream,
    publishing on) are counted from the stamps as in :class:`StampGaps` (steps up to
    ``LOSS_GAP_MAX_NS``, confirmed by a typical step after), so the two never count a message
    twice.

    Ambiguous when publishers share a clock, or when a loss spans a pause and another
    publisher's numbers and stamps happen to predict the message as well: measured, exact on
    the fault benchmark's streams with random bursts lost (10 of 10 runs), 13 of 1,500 random
    three-publisher cases with a 1.5 s pause miscounted (``test_health``).

    :ivar lost: messages lost so far (numbers skipped, and stamps skipped between consecutive
        numbers).
    """

    MAX_TRACKS = 8
    """Publishers tracked at once; the one heard from longest ago makes room for a new one."""

    __slots__ = ('_tracks', '_skipped', '_typical')

    def __init__(self) -> None:
        # [last number, last stamp ns, StampGaps, first number, first stamp, (number, stamp)
        # of the message before the last or None], the one used last first
        self._tracks: List[List] = []
        self._skipped = 0
        self._typical = 0  # the last typical step a track knew: a new track's until it knows

    @property
    def lost(self) -> int:
        """Return the messages lost so far."""
        return self._skipped + sum(track[2].lost for track in self._tracks)

    def take(self, sequence: int, stamp_ns: int) -> None:
        """Count in a message's publication sequence number and header stamp (ns)."""
        tracks = self._tracks
        track = tracks[0] if tracks else None
        if track is None or sequence != track[0] + 1 \
                or abs(stamp_ns - track[1] - track[2].typical_ns) > LOSS_GAP_MAX_NS:
            track = self._attribute(sequence, stamp_ns)
            if track is None:  # a new publisher (or one that restarted)
                gaps = StampGaps(confirm=True)
                gaps.take(stamp_ns)
                tracks.insert(0, [sequence, stamp_ns, gaps, sequence, stamp_ns, None])
                if len(tracks) > self.MAX_TRACKS:
                    self._retire(tracks.pop())
                return
            tracks.remove(track)
            tracks.insert(0, track)
        skipped = sequence - track[0] - 1
        track[5] = (track[0], track[1])  # the message before: a glitched last stamp's check
        track[0], track[1] = sequence, stamp_ns
        if skipped:
            self._skipped += skipped
            track[2].resume(stamp_ns)
        else:
            track[2].take(stamp_ns)

    def _attribute(self, sequence: int, stamp_ns: int) -> Optional[List]:
        """Return the track a message belongs to (see the class), None for a new one."""
        best, best_rank = None, None
        for track in self._tracks:
            last, last_stamp, gaps, first, first_stamp, before = track
            if last >= sequence:
                continue
            typical = gaps.typical_ns
            if typical:
                self._typical = typical
            else:
                typical = self._typical
            steps = sequence - last
            error = stamp_ns - last_stamp - steps * typical
            fit = 2 * typical or OTHER_PUBLISHER_NS
            if steps == 1 and error < -OTHER_PUBLISHER_NS:
                continue  # the next number, but stamped far behind: another publisher
            slack = fit + steps * typical // 12  # the typical step learnt off by jitter
            if steps > 1 and error < -slack and before is not None:  # the last a glitch ahead?
                error = max(error, stamp_ns - before[1] - (sequence - before[0]) * typical)
            if steps > 1 and error < -slack:
                continue  # stamps advanced less than the skipped messages took: another one
            mean = (last_stamp - first_stamp) / (last - first) if last - first >= 8 else typical
            off = stamp_ns - last_stamp - steps * mean  # against its stamps' mean pace
            rank = (abs(error) > fit, 0 if steps == 1 and off > 0 else abs(off), steps)
            if best_rank is None or rank < best_rank:
                best, best_rank = track, rank
        return best

    def _retire(self, track: List) -> None:
        """Forget a track, keeping the messages its stamps counted lost."""
        self._skipped += track[2].lost


@dataclass
class Tally:
    """
    What the node counts for its diagnostics (times: monotonic s).

    :ivar started: when the node started.
    :ivar arrivals: messages received per stream since start-up.
    :ivar last_arrival: when each stream last received a message.
    :ivar period: the diagnostics period running.
    :ivar incompatible: QoS or type incompatibilities seen; ``incompatible_reported``: as many
        as the last status reported.
    :ivar last_impact_ns: the stamp of the last impact published.
    :ivar gaps: each stream's :class:`StampGaps` (messages estimated lost from the stamps of
        messages without a sequence number).
    :ivar publishers: each stream's :class:`PublisherGaps` (messages lost, from the
        publishers' sequence numbers and stamps).
    """

    started: float
    arrivals: Counter = field(default_factory=Counter)
    last_arrival: Dict[str, float] = field(default_factory=dict)
    period: Optional[Period] = None
    incompatible: int = 0
    incompatible_reported: int = 0
    last_impact_ns: Optional[int] = None
    gaps: Dict[str, StampGaps] = field(default_factory=dict)
    publishers: Dict[str, PublisherGaps] = field(default_factory=dict)

    def __post_init__(self) -> None:
        """Start the first period at start-up."""
        if self.period is None:
            self.period = Period(self.started, Counter(), 0)

    def arrived(self, stream: str, now: float) -> None:
        """Count a message on ``stream`` received at ``now``."""
        self.arrivals[stream] += 1
        self.last_arrival[stream] = now

    def stamped(self, stream: str, stamp_ns: int, sequence: Optional[int] = None) -> None:
        """
        Take a message's header stamp (ns) on ``stream``, for the loss estimate.

        :param sequence: its publication sequence number when the RMW gives one (exact
            per-publisher accounting, :class:`PublisherGaps`); None: the stamps alone
            (:class:`StampGaps`).
        """
        if sequence is not None:
            publishers = self.publishers.get(stream)
            if publishers is None:
                publishers = self.publishers[stream] = PublisherGaps()
            publishers.take(sequence, stamp_ns)
            return
        gaps = self.gaps.get(stream)
        if gaps is None:
            gaps = self.gaps[stream] = StampGaps()
        gaps.take(stamp_ns)

    def lost(self) -> Counter:
        """Return the messages estimated lost per stream since start-up."""
        lost = Counter({stream: gaps.lost for stream, gaps in self.gaps.items()})
        lost.update({stream: each.lost for stream, each in self.publishers.items()})
        return lost

    def next_period(self, now: float, dropped: int, resets: int = 0) -> Period:
        """
        Start a new period at ``now``; return the one that ends.

        :param dropped: samples dropped since start-up, now; ``resets``: state resets.
        """
        ended, self.period = self.period, Period(now, Counter(self.arrivals), dropped, resets,
                                                 self.lost())
        return ended


@dataclass(frozen=True)
class Snapshot:
    """
    Everything one status is made of, copied at one instant.

    :ivar now: monotonic s.
    :ivar name: the node's name.
    :ivar streams: the input streams (``ball``, ``bat_pose`` or ``knob`` and ``tip``).
    :ivar topics: each stream's resolved topic.
    :ivar started, arrivals, last_arrival: as in :class:`Tally`.
    :ivar period: the period ending now.
    :ivar dropped: samples dropped by reason since start-up.
    :ivar counts: ``impacts``, ``near_misses``, ``gaps``, ``resets`` since start-up.
    :ivar detector_mean_s, detector_max_s: the detector's wall time per call since start-up.
    :ivar watermark_ns: the detector's watermark (None before any data).
    :ivar last_impact_ns: the last impact's stamp (None before any).
    :ivar frame_id: the tracking frame ('' before the first sample).
    :ivar settings: ``stale_timeout`` (s), ``model``, ``bat_input``, ``qos``.
    :ivar incompatible, incompatible_reported: as in :class:`Tally`.
    :ivar lost: messages estimated lost per stream since start-up (``Tally.lost``).
    """

    now: float
    name: str
    streams: Tuple[str, ...]
    topics: Mapping[str, str]
    started: float
    arrivals: Mapping[str, int]
    last_arrival: Mapping[str, float]
    period: Period
    dropped: Mapping[str, int]
    counts: Mapping[str, int]
    detector_mean_s: float
    detector_max_s: float
    watermark_ns: Optional[int]
    last_impact_ns: Optional[int]
    frame_id: str
    settings: Mapping[str, object]
    incompatible: int
    incompatible_reported: int
    lost: Mapping[str, int] = field(default_factory=dict)


def take_snapshot(now: float, name: str, streams: Tuple[str, ...], topics: Mapping[str, str],
                  tally: Tally, stats: DetectorStats, watermark_ns: Optional[int],
                  frame_id: Optional[str], settings: Mapping[str, object]) -> Snapshot:
    """
    Copy the counters into a snapshot and start the next period of ``tally``.

    :param stats: the detector's counters; ``watermark_ns``, ``frame_id``: its state.
    """
    dropped = dict(stats.dropped)
    return Snapshot(
        now=now, name=name, streams=tuple(streams), topics=dict(topics), started=tally.started,
        arrivals=Counter(tally.arrivals), last_arrival=dict(tally.last_arrival),
        period=tally.next_period(now, sum(dropped.values()), stats.resets), dropped=dropped,
        counts={'impacts': stats.impacts, 'near_misses': stats.near_misses, 'gaps': stats.gaps,
                'resets': stats.resets},
        detector_mean_s=stats.mean_processing_s, detector_max_s=stats.max_processing_s,
        watermark_ns=watermark_ns, last_impact_ns=tally.last_impact_ns,
        frame_id=frame_id or '', settings=settings, incompatible=tally.incompatible,
        incompatible_reported=tally.incompatible_reported, lost=tally.lost())


def silent_streams(snapshot: Snapshot) -> List[str]:
    """Return the streams with no message within ``stale_timeout`` (or none yet)."""
    timeout = snapshot.settings['stale_timeout']
    return [stream for stream in snapshot.streams
            if stream not in snapshot.last_arrival
            or snapshot.now - snapshot.last_arrival[stream] > timeout]


def _inputs(snapshot: Snapshot, problems: Mapping[str, str]) -> Tuple[List[str], List[str]]:
    """Return the stale and the waiting topics, each with why."""
    timeout = snapshot.settings['stale_timeout']
    stale, waiting = [], []
    for stream in snapshot.streams:
        topic = snapshot.topics[stream]
        last = snapshot.last_arrival.get(stream)
        why = f', {problems[stream]}' if problems.get(stream) else ''
        if last is None:
            if snapshot.now - snapshot.started > timeout:
                stale.append(f'{topic} (no data since start{why})')
            else:
                waiting.append(f'{topic}{why}')
        elif snapshot.now - last > timeout:
            stale.append(f'{topic} (silent for {snapshot.now - last:.1f} s{why})')
    return stale, waiting


def health_status(snapshot: Snapshot, problems: Mapping[str, str]) -> HealthStatus:
    """
    Return the detector's status over the period ending at ``snapshot.now``.

    Level: OK; WARN when an input is stale, samples were dropped in the period, messages were
    estimated lost (gaps in an input's stamps), the state was reset in the period or a new QoS
    or type incompatibility was seen; ERROR when every sample of the period was dropped or
    the state was reset ``RESETS_ERROR`` times in it. Every input silent longer than
    ``idle_timeout`` after data came is the state ``idle`` at OK (a session ended).
    Groups and keys: ``state`` (``state``: waiting for data, tracking, stale, idle;
    ``stale_topics``); ``inputs`` (per stream ``<stream>_topic``, ``<stream>_rate_hz``,
    ``<stream>_received``, ``<stream>_lost``: estimated; ``lost_in_period``); ``drops``
    (``dropped_<reason>`` for every reason in ``DROP_REASONS``, ``dropped_total``,
    ``dropped_in_period``); ``events`` (``impacts``, ``near_misses``, ``gaps``, ``resets``,
    ``resets_in_period``); ``timing`` (``messages_in_period``,
    ``processing_mean_ms``, ``processing_max_ms``: whole callback, over the period;
    ``detector_mean_ms``, ``detector_max_ms``: since start); ``session``
    (``watermark_stamp``, ``last_impact_stamp``, ``frame_id``, ``model``, ``bat_input``,
    ``qos``, ``incompatible_qos_events``).

    :param problems: why a silent stream may be silent ('' or missing: nothing known).
    """
    period = snapshot.period
    stale, waiting = _inputs(snapshot, problems)
    state = 'stale' if stale else 'waiting for data' if waiting else 'tracking'
    idle_after = float(snapshot.settings.get('idle_timeout', 0.0) or 0.0)
    if stale and idle_after > 0.0 and snapshot.last_arrival and all(
            snapshot.now - snapshot.last_arrival.get(stream, -math.inf) > idle_after
            for stream in snapshot.streams):
        state, stale = 'idle', []
    dropped_total = sum(snapshot.dropped.values())
    dropped_now = dropped_total - period.dropped
    received_now = sum(snapshot.arrivals.values()) - sum(period.arrivals.values())
    resets_now = snapshot.counts.get('resets', 0) - period.resets
    lost_now = {stream: count - period.lost.get(stream, 0)
                for stream, count in snapshot.lost.items()
                if count > period.lost.get(stream, 0)}

    level, problems_seen = Level.OK, []
    if stale:
        level = Level.WARN
        problems_seen.append('stale: ' + ', '.join(stale))
    if lost_now:
        level = Level.WARN
        problems_seen.append('about ' + ', '.join(
            f'{count} messages lost on {snapshot.topics.get(stream, stream)}'
            for stream, count in sorted(lost_now.items()))
            + " (gaps in the publishers' sequence numbers or stamps)")
    if resets_now:
        level = max(level, Level.ERROR if resets_now >= RESETS_ERROR else Level.WARN)
        problems_seen.append(f'state reset {resets_now} time(s) (see the log)')
    if dropped_now:
        level = Level.WARN
        problems_seen.append(f'dropped {dropped_now} of {received_now} samples')
        if dropped_now >= received_now:
            level = Level.ERROR
            problems_seen[-1] = f'every sample was dropped ({dropped_now})'
    if snapshot.incompatible != snapshot.incompatible_reported:
        level = max(level, Level.WARN)
        problems_seen.append('incompatible QoS or type on a topic (see the log)')
    message = 'waiting for data on ' + ', '.join(waiting) if state == 'waiting for data' \
        else state
    if state == 'idle':
        silent = snapshot.now - max(snapshot.last_arrival.values())
        message = f'idle: no input for {silent:.0f} s (the session ended?)'

    if problems_seen:
        message = '; '.join(problems_seen) if stale else f"{message}; {'; '.join(problems_seen)}"
    return HealthStatus(level=level, name=f'{snapshot.name}: impact detector', message=message,
                        hardware_id=str(snapshot.settings.get('hardware_id') or HARDWARE_ID),
                        groups=_groups(snapshot, state, stale, dropped_now, resets_now,
                                       sum(lost_now.values())))


def _groups(snapshot: Snapshot, state: str, stale: List[str], dropped_now: int,
            resets_now: int, lost_now: int) -> Tuple[Tuple[str, Values], ...]:
    """Return the status's grouped key/values (see health_status)."""
    period = snapshot.period
    elapsed = max(snapshot.now - period.start, 1e-9)
    inputs: List[Tuple[str, str]] = []
    for stream in snapshot.streams:
        rate = (snapshot.arrivals.get(stream, 0) - period.arrivals[stream]) / elapsed
        inputs += [(f'{stream}_topic', snapshot.topics[stream]),
                   (f'{stream}_rate_hz', f'{rate:.1f}'),
                   (f'{stream}_received', str(snapshot.arrivals.get(stream, 0))),
                   (f'{stream}_lost', str(snapshot.lost.get(stream, 0)))]
    inputs.append(('lost_in_period', str(lost_now)))
    drops = [(f'dropped_{reason}', str(snapshot.dropped.get(reason, 0)))
             for reason in DROP_REASONS]
    drops += [('dropped_total', str(sum(snapshot.dropped.values()))),
              ('dropped_in_period', str(dropped_now))]
    mean = period.total_s / period.count if period.count else 0.0
    settings = snapshot.settings
    timing = (
        ('messages_in_period', str(period.count)),
        ('processing_mean_ms', f'{mean * 1e3:.4f}'),
        ('processing_max_ms', f'{period.max_s * 1e3:.4f}'),
        ('detector_mean_ms', f'{snapshot.detector_mean_s * 1e3:.4f}'),
        ('detector_max_ms', f'{snapshot.detector_max_s * 1e3:.4f}'))
    session = (
        ('watermark_stamp', '' if snapshot.watermark_ns is None
         else format_stamp(snapshot.watermark_ns)),
        ('last_impact_stamp', '' if snapshot.last_impact_ns is None
         else format_stamp(snapshot.last_impact_ns)),
        ('frame_id', snapshot.frame_id), ('model', str(settings['model'])),
        ('bat_input', str(settings['bat_input'])), ('qos', str(settings['qos'])),
        ('incompatible_qos_events', str(snapshot.incompatible)))
    return (('state', (('state', state), ('stale_topics', ', '.join(stale)))),
            ('inputs', tuple(inputs)), ('drops', tuple(drops)),
            ('events', tuple((name, str(count)) for name, count in snapshot.counts.items())
             + (('resets_in_period', str(resets_now)),)),
            ('timing', timing), ('session', session))
