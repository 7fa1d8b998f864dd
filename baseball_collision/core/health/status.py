"""
The detector's status over a diagnostics period: a snapshot of the counters in, a status out.

Pure Python (no ROS): :func:`take_snapshot` copies a ``Tally`` and the detector's counters into a
:class:`Snapshot`; :func:`health_status` turns it into a :class:`HealthStatus` (level, message,
grouped key/values), which ``ros.diagnostics`` converts into a
``diagnostic_msgs/DiagnosticStatus`` and ``analyze --out-bag`` writes into its bag.
"""

from collections import Counter
from dataclasses import dataclass, field
import enum
import math
from typing import List, Mapping, Optional, Tuple

from .tally import Period, Tally
from ..detector import DetectorStats, DROP_REASONS

HARDWARE_ID = 'baseball_collision'
"""The status's ``hardware_id`` when the settings name none (``hardware_id`` '')."""

RESETS_ERROR = 3
"""State resets within one diagnostics period that make the status ERROR (one makes WARN)."""

NS_PER_S = 1_000_000_000
"""Nanoseconds per second: the package's one definition (stamps are integer nanoseconds)."""


class Level(enum.IntEnum):
    """A status level, with the values of ``diagnostic_msgs/DiagnosticStatus`` (STALE unused)."""

    OK = 0
    WARN = 1
    ERROR = 2


Values = Tuple[Tuple[str, str], ...]
"""Key/value pairs, both text."""


@dataclass(frozen=True)
class HealthStatus:
    """
    One status: what ``/diagnostics`` says about the detector.

    :ivar level: OK, WARN or ERROR.
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
    :ivar counts: ``impacts``, ``near_misses``, ``gaps``, ``resets``, ``internal_errors`` (the
        node's own failures, ``Tally.failures``) since start-up.
    :ivar detector_mean_s, detector_max_s: the detector's wall time per call since start-up.
    :ivar watermark_ns: the detector's watermark (None before any data).
    :ivar last_impact_ns: the last impact's stamp (None before any).
    :ivar frame_id: the tracking frame ('' before the first sample).
    :ivar settings: ``stale_timeout`` (s), ``model``, ``bat_input``, ``qos``.
    :ivar incompatible, incompatible_reported: as in :class:`Tally`.
    :ivar lost: messages estimated lost per stream since start-up (``Tally.lost``).
    :ivar noise: the ball's and the bat's tracking noise the fits take now (m, 1 sigma per
        coordinate: ``Detector.noise``, told or estimated; 0: exact).
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
    noise: Tuple[float, float] = (0.0, 0.0)


def take_snapshot(now: float, name: str, streams: Tuple[str, ...], topics: Mapping[str, str],
                  tally: Tally, stats: DetectorStats, watermark_ns: Optional[int],
                  frame_id: Optional[str], settings: Mapping[str, object],
                  noise: Tuple[float, float] = (0.0, 0.0)) -> Snapshot:
    """
    Copy the counters into a snapshot and start the next period of ``tally``.

    :param stats: the detector's counters; ``watermark_ns``, ``frame_id``, ``noise``: its
        state (``Detector.noise``: m, the ball's and the bat's).
    """
    dropped = dict(stats.dropped)
    return Snapshot(
        now=now, name=name, streams=tuple(streams), topics=dict(topics), started=tally.started,
        arrivals=Counter(tally.arrivals), last_arrival=dict(tally.last_arrival),
        period=tally.next_period(now, sum(dropped.values()), stats.resets), dropped=dropped,
        counts={'impacts': stats.impacts, 'near_misses': stats.near_misses, 'gaps': stats.gaps,
                'resets': stats.resets, 'internal_errors': tally.failures},
        detector_mean_s=stats.mean_processing_s, detector_max_s=stats.max_processing_s,
        watermark_ns=watermark_ns, last_impact_ns=tally.last_impact_ns,
        frame_id=frame_id or '', settings=settings, incompatible=tally.incompatible,
        incompatible_reported=tally.incompatible_reported, lost=tally.lost(), noise=noise)


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
    or type incompatibility was seen; ERROR when every sample of the period was dropped, the
    state was reset ``RESETS_ERROR`` times in it or the node's own code failed in it (an
    internal error: a bug, logged with its traceback). Every input silent longer than
    ``idle_timeout`` after data came is the state ``idle`` at OK (a session ended).
    Groups and keys: ``state`` (``state``: waiting for data, tracking, stale, idle;
    ``stale_topics``); ``inputs`` (per stream ``<stream>_topic``, ``<stream>_rate_hz``,
    ``<stream>_received``, ``<stream>_lost``: estimated; ``lost_in_period``); ``drops``
    (``dropped_<reason>`` for every reason in ``DROP_REASONS``, ``dropped_total``,
    ``dropped_in_period``); ``events`` (``impacts``, ``near_misses``, ``gaps``, ``resets``,
    ``internal_errors``, ``resets_in_period``); ``timing`` (``messages_in_period``,
    ``processing_mean_ms``, ``processing_max_ms``: whole callback, over the period;
    ``detector_mean_ms``, ``detector_max_ms``: since start); ``session``
    (``watermark_stamp``, ``last_impact_stamp``, ``frame_id``, ``model``, ``bat_input``,
    ``qos``, ``incompatible_qos_events``, ``tracker_noise``: auto or told, ``ball_noise_mm``,
    ``bat_noise_mm``: the noise the fits take now, 0 for exact samples).

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
    failures_now = snapshot.counts.get('internal_errors', 0) - period.failures
    if failures_now:
        level = Level.ERROR
        problems_seen.append(f'{failures_now} internal error(s) (see the log)')
    if dropped_now:
        level = max(level, Level.WARN)
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
        ('incompatible_qos_events', str(snapshot.incompatible)),
        ('tracker_noise', 'auto' if float(settings.get('tracker_noise', -1.0)) < 0.0
         else 'told'),
        ('ball_noise_mm', f'{snapshot.noise[0] * 1e3:.3f}'),
        ('bat_noise_mm', f'{snapshot.noise[1] * 1e3:.3f}'))
    return (('state', (('state', state), ('stale_topics', ', '.join(stale)))),
            ('inputs', tuple(inputs)), ('drops', tuple(drops)),
            ('events', tuple((name, str(count)) for name, count in snapshot.counts.items())
             + (('resets_in_period', str(resets_now)),)),
            ('timing', timing), ('session', session))
