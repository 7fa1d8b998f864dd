"""
The stream detector: samples in, impact and near-miss events out.

Pure Python + numpy: no rclpy, no rosbags. The ROS node and the bag tools both translate their
messages into calls on one ``Detector`` and its events back into messages, so a bag gives the
same impacts through both.

Stamps at the boundary are integer nanoseconds (``header.stamp``); inside, times are float
seconds relative to the first accepted stamp (absolute epoch nanoseconds do not fit a float).

How samples become events:

* Each stream (ball; bat as poses, or as knob and tip points that are paired by stamp, the
  other point interpolated when their stamps differ) is checked and kept in a short buffer.
  Bad samples are dropped and counted by reason, never processed.
* The detector walks the union of all streams' sample times up to the watermark, the oldest of
  the streams' newest usable stamps (for the spline model, the second newest: it needs the next
  sample). Between two consecutive union times every stream is inside one of its own sample
  intervals, so the motion model (``motion``) gives each body's path exactly by stamps, whatever
  the rates, jitter or uneven steps. An interval inside a stream gap longer than ``max_gap`` is
  not interpolated; a ``StreamGap`` event says so.
* Each union interval is cut into sub-steps small enough for the chord error bound and solved
  exactly (``solver``). The first contact is an ``Impact``; the detector is then disarmed until
  the ball has separated from the bat by ``rearm_distance`` (trackers keep reporting the ball
  inside or beyond the bat for frames after a hit). It also starts disarmed after a start, a
  reset or a gap, until it has seen the ball clear of the bat: a ball already overlapping the
  bat has no known first-contact time, and an invented one is worse than none.
* A pass of the ball within ``near_miss_threshold`` of the bat without contact is a ``NearMiss``
  at the closest approach, reported when the ball moves back out of the threshold.
* Velocities at an impact come from samples up to the impact only (a real hit decelerates the
  bat in the next frames, so an interpolant spanning the impact would under-read the speed).
"""

from bisect import bisect_right
from collections import Counter
from dataclasses import dataclass, field, replace
import math
import time
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from .config import DetectorConfig
from ..geometry import add, cross, dot, lerp, norm, rotate, scale, sub, swing_rotation, Vector
from ..motion import BatPath, BatSample, hermite_tangent, PointPath, substeps_for
from ..prediction import (
    BallForecast, BatForecast, first_contact, planned_bat, PlannedBat, turn_axis_and_rates)
from ..toi import closest_offset, profile_gap
from ..toi import profile_contact as _profile_contact
from ...errors import CoreError

DROP_REASONS = (
    'wrong_frame', 'non_finite', 'bad_stamp', 'duplicate_stamp', 'out_of_order',
    'bad_quaternion', 'zero_length_bat', 'bat_length_jump', 'speed_limit', 'unexpected_input')
"""Every reason a sample can be dropped for (the keys of ``DetectorStats.dropped``)."""

FAR_AHEAD_NS = 10 ** 15
"""A stamp this far (ns, about 11.6 days) after the detector's time origin starts a new one:
float seconds keep nanosecond resolution up to about 10^6 s."""

MPS_TO_MPH = 1.0 / 0.44704
"""Metres per second to miles per hour."""


# ----------------------------------------------------------------------------------------------
# Events


@dataclass(frozen=True)
class Impact:
    """
    First contact of a ball with the bat.

    :ivar stamp_ns: the impact instant (ns, same clock as the input stamps).
    :ivar point: contact point on the bat surface (m); ``normal``: unit, bat to ball.
    :ivar bat_fraction: along knob-tip, 0 at the knob, 1 at the tip.
    :ivar distance_from_knob_m, distance_from_tip_m: along the axis, metres.
    :ivar feature: ``'side'``, ``'knob_end'`` or ``'tip_end'``.
    :ivar bat_velocity: bat surface velocity at the contact point (m/s).
    :ivar bat_angular_velocity: rad/s (world frame; without the roll about the bat's axis when
        the bat came as knob and tip points).
    :ivar sweet_spot_velocity: velocity (m/s) of the axis point ``sweet_spot_from_tip`` from
        the tip; ``sweet_spot_speed_mps`` its norm (Statcast's bat speed).
    :ivar bat_speed_at_contact_mps: speed of the bat surface at the contact point.
    :ivar ball_velocity: m/s; ``ball_speed_mps`` its norm.
    :ivar relative_normal_speed_mps: closing speed along the normal (positive approaching).
    :ivar attack_angle_deg: vertical angle of the sweet spot's velocity (degrees, up > 0).
    :ivar ball_position, knob, tip: where the bodies were at the impact (m).
    :ivar model: motion model used.
    :ivar interval_start_ns, interval_end_ns: the union sample interval the impact fell in.
    :ivar velocities_from_history: False when too few samples before the impact existed and
        the velocities had to come from the interval spanning it.
    :ivar initially_overlapping: the contact was already there at the interval start.
    """

    stamp_ns: int
    point: Vector
    normal: Vector
    bat_fraction: float
    distance_from_knob_m: float
    distance_from_tip_m: float
    feature: str
    bat_velocity: Vector
    bat_angular_velocity: Vector
    sweet_spot_velocity: Vector
    sweet_spot_speed_mps: float
    bat_speed_at_contact_mps: float
    ball_velocity: Vector
    ball_speed_mps: float
    relative_normal_speed_mps: float
    attack_angle_deg: float
    ball_position: Vector
    knob: Vector
    tip: Vector
    model: str
    interval_start_ns: int
    interval_end_ns: int
    velocities_from_history: bool
    initially_overlapping: bool


@dataclass(frozen=True)
class NearMiss:
    """
    A pass of the ball by the bat without contact, at the closest approach.

    :ivar stamp_ns: closest approach (ns).
    :ivar gap_m: smallest surface gap (m, > 0).
    :ivar gap_vector: from the bat surface to the ball surface (m): +z means the bat passed
        under the ball.
    :ivar ball_position: ball centre at closest approach (m).
    :ivar bat_fraction: where along knob-tip the bat came closest.
    :ivar distance_from_tip_m: metres along the axis from the tip to that point.
    """

    stamp_ns: int
    gap_m: float
    gap_vector: Vector
    ball_position: Vector
    bat_fraction: float
    distance_from_tip_m: float


@dataclass(frozen=True)
class Prediction:
    """
    The coming impact, predicted from the samples up to ``made_at_ns``.

    :ivar stamp_ns: predicted impact instant (ns).
    :ivar made_at_ns: the newest processed instant the prediction starts from (ns).
    :ivar lead_s: how far ahead (s): ``(stamp_ns - made_at_ns) * 1e-9``.
    :ivar point: predicted contact point on the bat surface (m); ``normal``: bat to ball.
    :ivar bat_fraction: where along knob-tip; ``distance_from_tip_m``: metres from the tip.
    :ivar ball_position, ball_velocity: the ball's predicted centre (m) and velocity (m/s).
    :ivar planned: the bat's path came from a commanded plan (else extrapolated).
    """

    stamp_ns: int
    made_at_ns: int
    lead_s: float
    point: Vector
    normal: Vector
    bat_fraction: float
    distance_from_tip_m: float
    ball_position: Vector
    ball_velocity: Vector
    planned: bool


@dataclass(frozen=True)
class PredictionCleared:
    """A contact was predicted and no longer is (as of ``made_at_ns``)."""

    made_at_ns: int


@dataclass(frozen=True)
class StreamGap:
    """A stream went longer than ``max_gap`` between samples; that span was not interpolated."""

    stream: str
    start_ns: int
    end_ns: int


@dataclass(frozen=True)
class StateReset:
    """
    The detector dropped its state.

    :ivar reason: ``'time_jump_backwards'`` (a stamp ``time_jump_reset`` behind its stream),
        ``'time_jump_forward'`` (a stamp more than ``FAR_AHEAD_NS`` after the clock's origin:
        a new session) or ``'requested'``.
    """

    stamp_ns: int
    reason: str


Event = Union[Impact, NearMiss, StreamGap, StateReset, Prediction, PredictionCleared]


@dataclass
class DetectorStats:
    """
    Counters for diagnostics.

    :ivar received: samples offered, by stream (ball, bat_pose, knob, tip).
    :ivar dropped: samples dropped, by reason (see ``DROP_REASONS``).
    :ivar impacts, near_misses, gaps, resets: events emitted.
    :ivar intervals: union intervals processed; ``substeps``: exact solves run on them.
    :ivar last_processing_s, total_processing_s, max_processing_s, calls: wall time spent in
        the detector per call.
    :ivar newest_stamp_ns: newest accepted stamp of any stream (None before any).
    :ivar last_drop_reason: why the last sample offered was dropped (None: it was accepted).
    """

    received: Counter = field(default_factory=Counter)
    dropped: Counter = field(default_factory=Counter)
    impacts: int = 0
    near_misses: int = 0
    gaps: int = 0
    resets: int = 0
    intervals: int = 0
    substeps: int = 0
    last_processing_s: float = 0.0
    total_processing_s: float = 0.0
    max_processing_s: float = 0.0
    calls: int = 0
    newest_stamp_ns: Optional[int] = None
    last_drop_reason: Optional[str] = None

    @property
    def mean_processing_s(self) -> float:
        """Mean wall time per call (seconds)."""
        return self.total_processing_s / self.calls if self.calls else 0.0


# ----------------------------------------------------------------------------------------------
# Streams


class _Stream:
    """Accepted samples of one body: times (s, detector clock), stamps (ns), values, breaks."""

    __slots__ = ('name', 'times', 'stamps', 'values', 'breaks', 'speed_drops', 'path_key',
                 'path', 'reported_gap', 'turns')

    def __init__(self, name: str) -> None:
        self.name = name
        self.times: List[float] = []
        self.stamps: List[int] = []
        self.values: List[Any] = []
        self.breaks: List[bool] = []  # True: this sample does not continue the previous one
        # bat only: cumulative (swing x, y, z, roll) turn since the segment's first sample,
        # filled in on demand by ``turn``
        self.turns: List[Optional[Tuple[float, float, float, float]]] = []
        self.speed_drops = 0
        self.path_key: Optional[Tuple[int, int]] = None
        self.path: Any = None
        self.reported_gap: Optional[int] = None

    def newest(self) -> Optional[int]:
        return self.stamps[-1] if self.stamps else None

    def append(self, t: float, stamp: int, value: Any, new_segment: bool) -> None:
        self.times.append(t)
        self.stamps.append(stamp)
        self.values.append(value)
        self.breaks.append(new_segment or len(self.times) == 1)
        if isinstance(value, BatSample):
            self.turns.append((0.0, 0.0, 0.0, 0.0) if self.breaks[-1] else None)

    def trim(self, before: float, history: float, keep: int = 4) -> None:
        """Forget samples more than ``history`` s and ``keep`` samples before time ``before``."""
        if len(self.times) < 64:
            return
        index = min(bisect_right(self.times, before - history),
                    bisect_right(self.times, before)) - 1 - keep
        if index > 0:
            for buffer in (self.times, self.stamps, self.values, self.breaks, self.turns):
                del buffer[:index]
            self.path_key = None

    def turn(self, k: int) -> Tuple[float, float, float, float]:
        """Return the cumulative turn of bat sample k, summing the missing steps once."""
        turns = self.turns
        first = k
        while turns[first] is None:
            if first == 0:  # trimmed past the segment start: a new (zero) reference; only
                turns[0] = (0.0, 0.0, 0.0, 0.0)  # differences of turns are ever used
                break
            first -= 1  # a segment's first sample always has its turn (zero)
        for i in range(first + 1, k + 1):
            swing, roll = _rotation(self.values[i - 1], self.values[i])
            last = turns[i - 1]
            turns[i] = (last[0] + swing[0], last[1] + swing[1], last[2] + swing[2],
                        last[3] + roll)
        return turns[k]

    def interval(self, t: float) -> int:
        """Index k of the sample interval [times[k], times[k+1]] that starts at or before t."""
        return bisect_right(self.times, t) - 1

    def continuous(self, k: int, max_gap: float) -> bool:
        """Return whether samples k and k+1 are one segment no longer than ``max_gap``."""
        return not self.breaks[k + 1] and self.times[k + 1] - self.times[k] <= max_gap


# ----------------------------------------------------------------------------------------------
# The detector


class Detector:
    """
    Stateful impact detector: feed samples with ``add_*``, get events back.

    Every ``add_*`` returns the events that sample made decidable (often none). ``finish()``
    at the end of a recording processes what is left; ``reset()`` drops all state.

    :param config: the detector configuration.
    """

    def __init__(self, config: Optional[DetectorConfig] = None) -> None:
        self.config = config or DetectorConfig()
        self.stats = DetectorStats()
        self._segments = self.config.profile.segments()
        self._max_radius = self.config.profile.max_radius
        self._offsets = (tuple(float(x) for x in self.config.geometry.knob_offset),
                         tuple(float(x) for x in self.config.geometry.tip_offset))
        self._clear()

    @property
    def _history_span(self) -> float:
        """Return how far back (s) from the cursor the fits need samples."""
        config = self.config
        return 1.5 * max(config.velocity_window, config.prediction_window)

    # ---- state ---------------------------------------------------------------------------

    def _clear(self) -> None:
        self._origin: Optional[int] = None
        self._frame: Optional[str] = self.config.frame_id or None
        self._ball = _Stream('ball')
        self._bat = _Stream('bat')
        self._knob = _Stream('knob')
        self._tip = _Stream('tip')
        self._pair_cursor: Optional[float] = None
        self._cursor: Optional[float] = None
        self._armed: Optional[bool] = None  # None: not yet seen clear of the bat
        self._lengths: List[float] = []
        self._length_drops = 0
        self._episode: Optional[Dict[str, Any]] = None  # open near-miss episode
        self._last_gap: Optional[Tuple] = None  # (t, state, gap) last computed
        self._predicting = False
        # commanded bat plan: (first stamp, plan timed in s from it); and on this clock, cached
        self._plan: Optional[Tuple[int, PlannedBat]] = None
        self._plan_on_clock: Optional[PlannedBat] = None
        self._zone_clear = False  # armed and seen outside the near-miss threshold since

    RESTART_FIELDS = ('model', 'bat_input', 'profile', 'geometry', 'frame_id')
    """Config fields that cannot change on a running detector (they shape its buffers)."""

    def reconfigure(self, config: DetectorConfig) -> None:
        """
        Swap in a new configuration that differs only in thresholds.

        :raises CoreError: the new config changes one of ``RESTART_FIELDS``.
        """
        changed = [name for name in self.RESTART_FIELDS
                   if getattr(config, name) != getattr(self.config, name)]
        if changed:
            raise CoreError(f"{', '.join(changed)} cannot change while running: restart")
        self.config = config

    def set_bat_plan(self, stamps_ns: Sequence[int], positions: Sequence[Sequence[float]],
                     quaternions: Sequence[Sequence[float]]) -> None:
        """
        Set a commanded bat trajectory (poses in the bat's body frame, as for pose input).

        Predictions use it instead of extrapolating the bat, over the span it covers. An empty
        plan clears it.

        :raises CoreError: lists of different lengths, stamps not increasing, or a
            quaternion not unit length.
        """
        self._plan_on_clock = None
        if not stamps_ns:
            self._plan = None
            return
        first = int(stamps_ns[0])
        try:
            plan = planned_bat([(int(s) - first) * 1e-9 for s in stamps_ns], positions,
                               quaternions, *self._offsets)
        except (TypeError, ValueError) as error:
            raise CoreError(f'bad bat plan: {error}') from error
        self._plan = (first, plan)

    def reset(self, stamp_ns: int = 0, reason: str = 'requested') -> StateReset:
        """
        Drop every buffered sample and episode; counters are kept.

        :returns: the ``StateReset`` event describing it.
        """
        self._clear()
        self.stats.resets += 1
        return StateReset(stamp_ns=int(stamp_ns), reason=reason)

    @property
    def frame_id(self) -> Optional[str]:
        """Return the tracking frame: the configured one, else the first seen (None before)."""
        return self._frame

    @property
    def watermark_ns(self) -> Optional[int]:
        """Return the newest instant (ns) up to which everything has been processed."""
        if self._cursor is None or self._origin is None:
            return None
        return self._stamp(self._cursor)

    def _time(self, stamp: int) -> float:
        return (stamp - self._origin) * 1e-9

    def _stamp(self, t: float) -> int:
        return self._origin + int(round(t * 1e9))

    # ---- input ---------------------------------------------------------------------------

    def add_ball(self, stamp_ns: int, position: Sequence[float],
                 frame_id: str = '') -> List[Event]:
        """
        Add a ball centre sample (metres) stamped ``stamp_ns`` (header stamp, ns).

        :returns: the events this sample made decidable.
        """
        return self._timed(self._add_ball, 'ball', stamp_ns, position, frame_id)

    def add_bat_pose(self, stamp_ns: int, position: Sequence[float],
                     quaternion: Sequence[float], frame_id: str = '') -> List[Event]:
        """
        Add a bat pose sample: position (m) and unit quaternion (x, y, z, w).

        :returns: the events this sample made decidable.
        """
        return self._timed(self._add_bat_pose, 'bat_pose', stamp_ns, (position, quaternion),
                           frame_id)

    def add_knob(self, stamp_ns: int, position: Sequence[float],
                 frame_id: str = '') -> List[Event]:
        """
        Add a knob sample (metres) when the bat comes as knob and tip points.

        :returns: the events this sample made decidable.
        """
        return self._timed(self._add_end, 'knob', stamp_ns, position, frame_id)

    def add_tip(self, stamp_ns: int, position: Sequence[float],
                frame_id: str = '') -> List[Event]:
        """
        Add a tip (barrel end) sample (metres) when the bat comes as knob and tip points.

        :returns: the events this sample made decidable.
        """
        return self._timed(self._add_end, 'tip', stamp_ns, position, frame_id)

    ROLES = ('ball', 'bat_pose', 'knob', 'tip')
    """Sample roles accepted by ``add``."""

    def add(self, role: str, stamp_ns: int, values: Sequence[float],
            frame_id: str = '') -> List[Event]:
        """
        Add a sample by role: the one entry point for message adapters (node, bag replay).

        :param role: ``'ball'``, ``'knob'`` or ``'tip'`` with values (x, y, z) in metres, or
            ``'bat_pose'`` with values (px, py, pz, qx, qy, qz, qw).
        :param stamp_ns: header stamp (ns).
        :param frame_id: the header's frame.
        :returns: the events this sample made decidable.
        :raises CoreError: an unknown role (a programming error, not bad data).
        """
        if role == 'ball':
            return self.add_ball(stamp_ns, values, frame_id)
        if role == 'bat_pose':  # split inside the guard: unsliceable values are dropped too
            return self._timed(self._add_pose_values, 'bat_pose', stamp_ns, values, frame_id)
        if role == 'knob':
            return self.add_knob(stamp_ns, values, frame_id)
        if role == 'tip':
            return self.add_tip(stamp_ns, values, frame_id)
        raise CoreError(f"role must be one of {', '.join(self.ROLES)}, got '{role}'")

    def finish(self) -> List[Event]:
        """
        Process what is left at the end of a recording and close an open near miss.

        :returns: the remaining events.
        """
        events: List[Event] = []
        if self.config.model == 'spline':
            self._advance(events, final=True)
        self._close_episode(events)
        return events

    def _timed(self, handler, stream: str, stamp_ns: int, value: Any,
               frame_id: str) -> List[Event]:
        start = time.perf_counter()
        self.stats.received[stream] += 1
        events: List[Event] = []
        reason = self._check_frame(frame_id)
        if reason is None:
            try:
                stamp = int(stamp_ns)
                reason = 'bad_stamp' if stamp <= 0 else handler(stream, stamp, value, events)
            except (TypeError, ValueError) as error:
                if isinstance(error, CoreError):
                    raise
                reason = 'non_finite'  # not numbers at all
            if reason is None and self._frame is None and frame_id:
                self._frame = frame_id  # the first accepted sample sets the tracking frame
        stats = self.stats
        stats.last_drop_reason = reason
        if reason is not None:
            stats.dropped[reason] += 1
        elapsed = time.perf_counter() - start
        stats.calls += 1
        stats.last_processing_s = elapsed
        stats.total_processing_s += elapsed
        if elapsed > stats.max_processing_s:
            stats.max_processing_s = elapsed
        return events

    def _check_frame(self, frame_id: str) -> Optional[str]:
        if not frame_id or self._frame is None:
            return None
        return None if frame_id == self._frame else 'wrong_frame'

    def _check_stamp(self, stream: _Stream, stamp: int, events: List[Event]) -> Optional[str]:
        """Return a drop reason for a stamp, resetting on a jump backwards."""
        newest = stream.newest()
        if newest is None:
            return None
        if stamp == newest:
            return 'duplicate_stamp'
        if stamp < newest:
            if (newest - stamp) * 1e-9 > self.config.time_jump_reset:
                events.extend(self._close_and_reset(stamp))
                return None
            return 'out_of_order'
        return None

    def _close_and_reset(self, stamp: int, reason: str = 'time_jump_backwards') -> List[Event]:
        events: List[Event] = []
        self._close_episode(events)
        events.append(self.reset(stamp, reason))
        return events

    def _start_clock(self, stamp: int, events: List[Event]) -> None:
        if self._origin is not None and stamp - self._origin > FAR_AHEAD_NS:
            # a new session (or a wild clock): start a new time origin, so float times keep
            # their nanosecond resolution
            events.extend(self._close_and_reset(stamp, 'time_jump_forward'))
        if self._origin is None:
            self._origin = stamp
        newest = self.stats.newest_stamp_ns
        if newest is None or stamp > newest:
            self.stats.newest_stamp_ns = stamp

    def _speed_ok(self, stream: _Stream, t: float, points: Sequence[Vector],
                  previous_points: Sequence[Vector]) -> Tuple[bool, bool]:
        """Return (accept, new_segment) after the physical speed bound."""
        if not stream.times:
            return True, True
        dt = t - stream.times[-1]
        if dt > self.config.max_gap:
            stream.speed_drops = 0
            return True, True
        limit = self.config.max_speed * dt
        for p, q in zip(points, previous_points):
            if math.dist(p, q) > limit:  # math.dist does not overflow (1e300 m is fine)
                stream.speed_drops += 1
                if stream.speed_drops >= 3:  # the body really moved: start a new segment
                    stream.speed_drops = 0
                    return True, True
                return False, False
        stream.speed_drops = 0
        return True, False

    def _add_ball(self, name: str, stamp: int, value: Sequence[float],
                  events: List[Event]) -> Optional[str]:
        x, y, z = value
        x, y, z = float(x), float(y), float(z)
        if x * 0.0 + y * 0.0 + z * 0.0 != 0.0:  # inf or NaN
            return 'non_finite'
        reason = self._check_stamp(self._ball, stamp, events)
        if reason:
            return reason
        self._start_clock(stamp, events)
        t = self._time(stamp)
        point = (x, y, z)
        previous = [self._ball.values[-1]] if self._ball.values else []
        accept, new_segment = self._speed_ok(self._ball, t, [point], previous)
        if not accept:
            return 'speed_limit'
        self._ball.append(t, stamp, point, new_segment)
        self._advance(events)
        return None

    def _add_pose_values(self, name: str, stamp: int, values: Sequence[float],
                         events: List[Event]) -> Optional[str]:
        return self._add_bat_pose(name, stamp, (values[:3], values[3:]), events)

    def _add_bat_pose(self, name: str, stamp: int, value: Tuple[Sequence[float], Sequence[float]],
                      events: List[Event]) -> Optional[str]:
        if self.config.bat_input != 'pose':
            return 'unexpected_input'
        px, py, pz = value[0]
        qx, qy, qz, qw = value[1]
        px, py, pz = float(px), float(py), float(pz)
        qx, qy, qz, qw = float(qx), float(qy), float(qz), float(qw)
        # each product is 0.0 for a finite number and NaN for inf or NaN (and cannot overflow)
        if px * 0.0 + py * 0.0 + pz * 0.0 + qx * 0.0 + qy * 0.0 + qz * 0.0 + qw * 0.0 != 0.0:
            return 'non_finite'
        magnitude = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
        if abs(magnitude - 1.0) > 1e-3:
            return 'bad_quaternion'
        position = (px, py, pz)
        quaternion = (qx / magnitude, qy / magnitude, qz / magnitude, qw / magnitude)
        reason = self._check_stamp(self._bat, stamp, events)
        if reason:
            return reason
        self._start_clock(stamp, events)
        t = self._time(stamp)
        knob = add(position, rotate(quaternion, self._offsets[0]))
        tip = add(position, rotate(quaternion, self._offsets[1]))
        sample = BatSample(knob=knob, tip=tip, position=position, quaternion=quaternion)
        return self._accept_bat(t, stamp, sample, events, check_length=False)

    def _accept_bat(self, t: float, stamp: int, sample: BatSample, events: List[Event],
                    check_length: bool) -> Optional[str]:
        if check_length:
            length = math.dist(sample.knob, sample.tip)
            if length < 1e-3:
                return 'zero_length_bat'
            if self._lengths:
                reference = sorted(self._lengths)[len(self._lengths) // 2]
                if abs(length - reference) > self.config.bat_length_tolerance:
                    self._length_drops += 1
                    if self._length_drops < 3:
                        return 'bat_length_jump'
                    self._lengths.clear()  # the bat really changed (re-calibration)
            self._length_drops = 0
            self._lengths.append(length)
            if len(self._lengths) > 15:
                del self._lengths[0]
        previous = []
        if self._bat.values:
            previous = [self._bat.values[-1].knob, self._bat.values[-1].tip]
        accept, new_segment = self._speed_ok(self._bat, t, [sample.knob, sample.tip], previous)
        if not accept:
            return 'speed_limit'
        self._bat.append(t, stamp, sample, new_segment)
        self._advance(events)
        return None

    def _add_end(self, name: str, stamp: int, value: Sequence[float],
                 events: List[Event]) -> Optional[str]:
        if self.config.bat_input != 'points':
            return 'unexpected_input'
        x, y, z = value
        x, y, z = float(x), float(y), float(z)
        if x * 0.0 + y * 0.0 + z * 0.0 != 0.0:  # inf or NaN
            return 'non_finite'
        stream = self._knob if name == 'knob' else self._tip
        reason = self._check_stamp(stream, stamp, events)
        if reason:
            return reason
        self._start_clock(stamp, events)
        t = self._time(stamp)
        stream.append(t, stamp, (x, y, z), False)
        return self._pair(events)

    def _pair(self, events: List[Event]) -> Optional[str]:
        """Form bat samples at every knob or tip time both streams now cover."""
        knob, tip = self._knob, self._tip
        if not knob.times or not tip.times:
            return None
        ready = min(knob.times[-1], tip.times[-1])
        start = self._pair_cursor
        times = sorted({t for t in knob.times + tip.times
                        if t <= ready and (start is None or t > start)})
        reason = None
        for t in times:
            self._pair_cursor = t
            ends = []
            for stream in (knob, tip):
                k = stream.interval(t)
                if k < 0:
                    break
                if stream.times[k] == t:
                    ends.append(stream.values[k])
                elif k + 1 < len(stream.times) and \
                        stream.times[k + 1] - stream.times[k] <= self.config.max_gap:
                    s = (t - stream.times[k]) / (stream.times[k + 1] - stream.times[k])
                    a, b = stream.values[k], stream.values[k + 1]
                    ends.append(tuple(p + (q - p) * s for p, q in zip(a, b)))
                else:
                    break
            if len(ends) == 2:
                stamp = self._stamp(t)
                reason = self._accept_bat(t, stamp, BatSample(knob=ends[0], tip=ends[1]),
                                          events, check_length=True) or reason
        knob.trim(self._pair_cursor or 0.0, 0.0)
        tip.trim(self._pair_cursor or 0.0, 0.0)
        return reason

    # ---- processing ----------------------------------------------------------------------

    def _ready(self, stream: _Stream, final: bool) -> Optional[float]:
        if self.config.model == 'spline' and not final:
            return stream.times[-2] if len(stream.times) >= 2 else None
        return stream.times[-1] if stream.times else None

    def _advance(self, events: List[Event], final: bool = False) -> None:
        ball, bat = self._ball, self._bat
        if not ball.times or not bat.times:
            return
        ready_ball, ready_bat = self._ready(ball, final), self._ready(bat, final)
        if ready_ball is None or ready_bat is None:
            return
        watermark = ready_ball if ready_ball < ready_bat else ready_bat
        cursor = self._cursor
        if cursor is None:
            cursor = self._cursor = max(ball.times[0], bat.times[0])
        if watermark <= cursor:
            return
        # walk the union of both streams' sample times in (cursor, watermark]
        ball_times, bat_times = ball.times, bat.times
        i = bisect_right(ball_times, cursor)
        j = bisect_right(bat_times, cursor)
        while True:
            a = ball_times[i] if i < len(ball_times) else math.inf
            b = bat_times[j] if j < len(bat_times) else math.inf
            t = a if a < b else b
            if t > watermark:
                break
            if a == t:
                i += 1
            if b == t:
                j += 1
            self._interval(cursor, t, events)
            cursor = t
        moved = cursor != self._cursor
        self._cursor = cursor
        ball.trim(cursor, self._history_span)
        bat.trim(cursor, self._history_span)
        if moved and self.config.prediction_horizon > 0.0:
            self._predict(events)

    def _locate(self, ta: float, events: List[Event]) -> Optional[Tuple[int, int]]:
        """Return each stream's sample interval index holding ta, or None across a gap."""
        indices = []
        for stream in (self._ball, self._bat):
            k = stream.interval(ta)
            if k < 0 or k + 1 >= len(stream.times):
                return None
            if not stream.continuous(k, self.config.max_gap):
                if stream.reported_gap != stream.stamps[k]:
                    stream.reported_gap = stream.stamps[k]
                    self.stats.gaps += 1
                    events.append(StreamGap(stream=stream.name, start_ns=stream.stamps[k],
                                            end_ns=stream.stamps[k + 1]))
                    self._close_episode(events)
                    self._armed = None
                    self._zone_clear = False
                return None
            indices.append(k)
        return indices[0], indices[1]

    def _neighbours(self, stream: _Stream, k: int) -> Tuple[Optional[int], Optional[int]]:
        """Return the samples before k and after k + 1 in the same segment (or None)."""
        max_gap = self.config.max_gap
        before = k - 1 if k >= 1 and stream.continuous(k - 1, max_gap) else None
        after = k + 2 if k + 2 < len(stream.times) and stream.continuous(k + 1, max_gap) \
            else None
        return before, after

    def _paths(self, ball_k: int, bat_k: int) -> Tuple[Any, Any]:
        """Return (ball path, bat path) over the sample intervals ball_k and bat_k."""
        paths = []
        spline = self.config.model == 'spline'
        for stream, k in ((self._ball, ball_k), (self._bat, bat_k)):
            key = (stream.stamps[k], stream.stamps[k + 1])
            if stream.path_key != key:
                before, after = self._neighbours(stream, k)
                stream.path = self._build_path(stream, k, before, after, spline)
                stream.path_key = key
            paths.append(stream.path)
        return paths[0], paths[1]

    def _bulge_bounds(self, stream: _Stream, k: int, picks: Sequence) -> List[float]:
        """
        Bound (m) how far each picked point's spline over sample interval k leaves its chord.

        With tangents from the three-point rule, p(s) - chord(s) = c (s^2 - s) + d (s^3 - s)
        and |c| / 4 + 0.385 |d| <= 3.04 |D| + 0.885 (h / h_prev) |D_prev| +
        0.635 (h / h_next) |D_next|, D the chords; no path needs to be built for it.
        """
        times, values = stream.times, stream.values
        h = times[k + 1] - times[k]
        before, after = self._neighbours(stream, k)
        weight_before = 0.885 * h / (times[k] - times[before]) if before is not None else 0.0
        weight_after = 0.635 * h / (times[after] - times[k + 1]) if after is not None else 0.0
        here, there = values[k], values[k + 1]
        bounds = []
        for pick in picks:
            bound = 3.04 * math.dist(pick(here), pick(there))
            if before is not None:
                bound += weight_before * math.dist(pick(values[before]), pick(here))
            if after is not None:
                bound += weight_after * math.dist(pick(there), pick(values[after]))
            bounds.append(bound)
        return bounds

    def _clearly_apart(self, ball_k: int, bat_k: int, margin: float) -> bool:
        """
        Return whether ball and bat stay more than ``margin`` apart over both sample intervals.

        Decided from the raw samples (no path built): each body's path lies in a sphere around
        its chord's middle, grown by a bound on the model's curvature: none for chords; for a
        rigid turn, the sagitta is at most half the chord of the rotating part; for the spline,
        ``_bulge_bounds``.
        """
        ball, bat = self._ball, self._bat
        b0, b1 = ball.values[ball_k], ball.values[ball_k + 1]
        s0, s1 = bat.values[bat_k], bat.values[bat_k + 1]
        k0, e0, k1, e1 = s0.knob, s0.tip, s1.knob, s1.tip
        ball_centre = ((b0[0] + b1[0]) * 0.5, (b0[1] + b1[1]) * 0.5, (b0[2] + b1[2]) * 0.5)
        ball_radius = 0.5 * math.dist(b0, b1)
        bat_centre = ((k0[0] + e0[0] + k1[0] + e1[0]) * 0.25,
                      (k0[1] + e0[1] + k1[1] + e1[1]) * 0.25,
                      (k0[2] + e0[2] + k1[2] + e1[2]) * 0.25)
        bat_radius = max(math.dist(k0, bat_centre), math.dist(e0, bat_centre),
                         math.dist(k1, bat_centre), math.dist(e1, bat_centre))
        model = self.config.model
        if model == 'rigid':
            turning = max(math.dist(k0, k1), math.dist(e0, e1))
            if s0.position is not None:
                reference = math.dist(s0.position, s1.position)
            else:
                # knob moves on its chord, the length changes linearly: both count in full
                reference = math.dist(k0, k1) + 2.0 * abs(math.dist(k0, e0) - math.dist(k1, e1))
            bat_radius += 0.5 * (turning + reference)
        elif model == 'spline':
            # the knob's cubic, then the knob-to-tip vector r turning on an arc (at most
            # (pi / 4) |D r| from its chord) by an angle whose cubic overshoots uniform speed by at
            # most pi times r's own bulge bound (angle <= (pi / 2) chord / length), and the
            # length changing linearly
            ball_radius += self._bulge_bounds(ball, ball_k, (_same,))[0]
            knob_bulge, axis_bulge = self._bulge_bounds(bat, bat_k, (_knob_of, _axis_of))
            bat_radius += (knob_bulge + 0.25 * math.pi * math.dist(sub(e0, k0), sub(e1, k1))
                           + math.pi * axis_bulge + abs(math.dist(k0, e0) - math.dist(k1, e1)))
        return math.dist(ball_centre, bat_centre) - ball_radius - bat_radius > margin

    def _build_path(self, stream: _Stream, k: int, before: Optional[int], after: Optional[int],
                    spline: bool) -> Any:
        t0, t1 = stream.times[k], stream.times[k + 1]
        if stream is self._bat:
            return BatPath.build(
                self.config.model, t0, t1, stream.values[k], stream.values[k + 1],
                before=None if before is None else (stream.times[before], stream.values[before]),
                after=None if after is None else (stream.times[after], stream.values[after]),
                offsets=self._offsets)
        p0, p1 = stream.values[k], stream.values[k + 1]
        if not spline:
            return PointPath(t0, t1, p0, p1)
        tb, pb = (stream.times[before], stream.values[before]) if before is not None \
            else (None, None)
        ta, pa = (stream.times[after], stream.values[after]) if after is not None \
            else (None, None)
        return PointPath(t0, t1, p0, p1, hermite_tangent(tb, pb, t0, p0, t1, p1),
                         hermite_tangent(t0, p0, t1, p1, ta, pa))

    def _interval(self, ta: float, tb: float, events: List[Event]) -> None:
        located = self._locate(ta, events)
        if located is None:
            return
        self.stats.intervals += 1
        config = self.config
        margin = (config.ball_radius + self._max_radius + 1e-6
                  + max(config.near_miss_threshold, config.rearm_distance))
        if self._clearly_apart(located[0], located[1], margin):
            self._far(events)
            return
        paths = self._paths(*located)
        ball_path, bat_path = paths
        apart = math.dist(ball_path.centre, bat_path.centre) - ball_path.radius - bat_path.radius
        if apart > margin:
            # the bounding spheres of both whole sample intervals are clear: far apart
            self._far(events)
            return
        ball_a, ball_b = ball_path.at(ta), ball_path.at(tb)
        knob_a, tip_a = bat_path.at(ta)
        knob_b, tip_b = bat_path.at(tb)
        deviation = ball_path.deviation(ta, tb) + bat_path.deviation(ta, tb)
        reach = 0.5 * max(math.dist(knob_a, tip_a), math.dist(knob_b, tip_b)) + deviation + margin
        if norm(closest_offset(ball_a, ball_b, tip_a, tip_b, knob_a, knob_b)) > reach:
            self._far(events)
            return
        n = substeps_for(deviation, config.max_chord_error)
        self.stats.substeps += n
        previous = (ta, ball_a, knob_a, tip_a)
        gap_previous = self._gap_at(previous)
        for j in range(1, n + 1):
            t1 = tb if j == n else ta + (tb - ta) * j / n
            if j == n:
                state = (t1, ball_b, knob_b, tip_b)
            else:
                knob, tip = bat_path.at(t1)
                state = (t1, ball_path.at(t1), knob, tip)
            gap = self._gap_at(state)
            if self._substep(previous, state, gap_previous, gap, (ta, tb), paths, events):
                return
            previous, gap_previous = state, gap

    def _gap_at(self, state: Tuple) -> float:
        """Return the gap (m) at a state (t, ball, knob, tip), reusing the last one computed."""
        cached = self._last_gap
        if cached is not None and cached[0] == state[0] and cached[1] == state[1:]:
            return cached[2]
        gap = profile_gap(state[1], state[2], state[3], self.config.ball_radius,
                          self.config.profile)[0]
        self._last_gap = (state[0], state[1:], gap)
        return gap

    # ---- prediction ----------------------------------------------------------------------

    def _predict(self, events: List[Event]) -> None:
        """Predict the coming impact from the samples up to the cursor (``Prediction``)."""
        config = self.config
        t0 = self._cursor
        found = None
        if self._armed and self._may_reach(t0):
            ball = self._ball_forecast(t0)
            bat = self._bat_forecast(t0)
            if ball is not None and bat is not None:
                # a forecast is good to millimetres at best: a coarser chord tolerance than for
                # impacts costs it nothing
                found = first_contact(ball, bat, t0, config.prediction_horizon,
                                      config.ball_radius, config.profile,
                                      PREDICTION_CHORD_FACTOR * config.max_chord_error)
        if found is None:
            if self._predicting:
                self._predicting = False
                events.append(PredictionCleared(made_at_ns=self._stamp(t0)))
            return
        t, hit = found
        knob, tip = bat.at(t)
        self._predicting = True
        events.append(Prediction(
            stamp_ns=self._stamp(t), made_at_ns=self._stamp(t0), lead_s=t - t0,
            point=tuple(hit.point), normal=tuple(hit.normal), bat_fraction=hit.bat_fraction,
            distance_from_tip_m=(1.0 - hit.bat_fraction) * math.dist(knob, tip),
            ball_position=ball.at(t), ball_velocity=ball.velocity_at(t),
            planned=isinstance(bat, PlannedBat)))

    def _may_reach(self, t0: float) -> bool:
        """
        Return whether the ball could reach the bat within the prediction horizon.

        From the newest samples alone: the distance from the ball to the bat's middle against
        the bat's half length, the radii and what both can travel over the horizon at twice
        their speed over the last sample step (a plan may move the bat anywhere: always True).
        """
        if self._plan is not None:
            return True
        ball, bat = self._ball, self._bat
        if len(ball.times) < 2 or len(bat.times) < 2:
            return False
        b0, b1 = ball.values[-2], ball.values[-1]
        s0, s1 = bat.values[-2], bat.values[-1]
        ball_speed = math.dist(b0, b1) / (ball.times[-1] - ball.times[-2])
        bat_speed = max(math.dist(s0.knob, s1.knob), math.dist(s0.tip, s1.tip)) / (
            bat.times[-1] - bat.times[-2])
        middle = lerp(s1.knob, s1.tip, 0.5)
        reach = (0.5 * math.dist(s1.knob, s1.tip) + self.config.ball_radius + self._max_radius
                 + 2.0 * (ball_speed + bat_speed) * self.config.prediction_horizon)
        return math.dist(b1, middle) <= reach

    def _ball_forecast(self, t0: float) -> Optional[BallForecast]:
        """Return the ball's ballistic forecast from a parabola fitted to its latest samples."""
        indices = _history(self._ball, t0, self.config.prediction_window)
        if len(indices) < 3:
            return None
        times = [self._ball.times[i] for i in indices]
        position, velocity, _ = _fit_polynomial(times, [self._ball.values[i] for i in indices],
                                                t0, 2)
        gravity = scale(self.config.up_axis, -self.config.gravity)
        return BallForecast.ballistic(t0, tuple(position), tuple(velocity), gravity,
                                      self.config.ball_drag)

    def _bat_forecast(self, t0: float):
        """Return the bat's forecast: the commanded plan when it covers t0, else extrapolated."""
        if self._plan is not None:
            if self._plan_on_clock is None:  # once: the clock's origin stays until a reset
                first, plan = self._plan
                shift = self._time(first)
                self._plan_on_clock = replace(plan, times=tuple(t + shift for t in plan.times))
            if self._plan_on_clock.times[-1] > t0:
                return self._plan_on_clock
        bat = self._bat
        config = self.config
        window, degree = config.velocity_window, min(config.velocity_degree, PREDICTION_DEGREE)
        indices = _history(bat, t0, window)
        if len(indices) < 3:
            return None
        # start from the newest bat sample itself (a fit lags an accelerating swing); the same
        # fits as an impact's velocities give the rates (``_impact``)
        start = bat.times[indices[-1]]
        latest = bat.values[indices[-1]]
        fraction, pivot_velocity, pivot_acceleration = _pivot_rates(bat, start, window, degree)
        rate, _, change = _turn_rates(bat, start, window, degree)
        axis, turn, turn_change = turn_axis_and_rates(rate, change)
        pivot = lerp(latest.knob, latest.tip, fraction)
        return BatForecast(t0=start, pivot=pivot, pivot_velocity=pivot_velocity,
                           pivot_acceleration=pivot_acceleration,
                           knob_arm=sub(latest.knob, pivot), tip_arm=sub(latest.tip, pivot),
                           axis=axis, rate=turn, rate_change=turn_change)

    def _far(self, events: List[Event]) -> None:
        """Note an interval with the ball far from the bat all through it."""
        self._armed = True  # separated: re-armed, and clear of the near-miss zone
        self._zone_clear = True
        if self._episode is not None:
            self._close_episode(events)

    def _substep(self, start: Tuple, end: Tuple, gap0: float, gap1: float,
                 interval: Tuple[float, float], paths: Tuple, events: List[Event]) -> bool:
        """Solve one linear sub-step between states (t, ball, knob, tip); True on an impact."""
        t0, ball0, knob0, tip0 = start
        t1, ball1, knob1, tip1 = end
        config = self.config
        if self._armed is None and gap0 > 0.0:
            self._armed = True
        elif self._armed is False and gap0 > config.rearm_distance:
            self._armed = True
        if self._armed:
            hit = _profile_contact(ball0, ball1, tip0, tip1, knob0, knob1, config.ball_radius,
                                   config.profile, t1 - t0)
            if hit is not None:
                self._armed = False
                self._zone_clear = False
                self._episode = None  # the pass ended in contact: no near miss
                events.append(self._impact(t0 + hit.time, hit, interval, paths))
                self.stats.impacts += 1
                return True
        self._track_gap(start, end, gap0, gap1, events)
        return False

    # ---- near misses ---------------------------------------------------------------------

    def _track_gap(self, start: Tuple, end: Tuple, gap0: float, gap1: float,
                   events: List[Event]) -> None:
        """
        Follow the gap over a sub-step for near misses, then re-arm if the ball cleared.

        An open episode keeps the sub-steps on both sides of its smallest end-point gap; the
        closest approach lies in one of them and is refined once, when the episode closes.
        """
        config = self.config
        threshold = config.near_miss_threshold
        # a pass is a near miss only when it came into the threshold from outside it while armed
        # (not the ball leaving after a contact, nor one first seen close to the bat)
        if self._armed and gap0 >= threshold:
            self._zone_clear = True
        episode = self._episode
        if self._zone_clear and (gap0 < threshold or gap1 < threshold) and episode is None:
            episode = self._episode = {'gap': math.inf, 'around': [], 'follow': False}
        if episode is not None:
            if episode['follow']:
                episode['around'].append((start, end))
                episode['follow'] = False
            if gap0 < episode['gap']:
                episode.update(gap=gap0, around=[(start, end)], follow=False)
            if gap1 < episode['gap']:
                episode.update(gap=gap1, around=[(start, end)], follow=True)
            if gap1 >= threshold:
                self._close_episode(events)
        if self._armed is False and gap1 > config.rearm_distance:
            self._armed = True

    def _lowest_gap(self, start: Tuple, end: Tuple) -> Tuple:
        """
        Find the smallest gap over a linear sub-step, by golden-section search.

        :returns: (t, gap, normal, fraction, ball, (knob, tip)) at the smallest gap found.
        """
        config = self.config
        t0, t1 = start[0], end[0]

        def state(s: float) -> Tuple:
            return tuple(tuple(a + (b - a) * s for a, b in zip(p, q))
                         for p, q in zip(start[1:], end[1:]))

        def gap(s: float) -> float:
            return profile_gap(*state(s), config.ball_radius, config.profile)[0]

        ratio = (math.sqrt(5.0) - 1.0) / 2.0
        lo, hi = 0.0, 1.0
        x1, x2 = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
        g1, g2 = gap(x1), gap(x2)
        for _ in range(40):
            if g1 < g2:
                hi, x2, g2 = x2, x1, g1
                x1 = hi - ratio * (hi - lo)
                g1 = gap(x1)
            else:
                lo, x1, g1 = x1, x2, g2
                x2 = lo + ratio * (hi - lo)
                g2 = gap(x2)
        _, s = min((gap(0.0), 0.0), (gap(1.0), 1.0), (min(g1, g2), x1 if g1 < g2 else x2))
        ball, knob, tip = state(s)
        value, normal, fraction = profile_gap(ball, knob, tip, config.ball_radius,
                                              config.profile)
        return (t0 + (t1 - t0) * s, value, normal, fraction, ball, (knob, tip))

    def _close_episode(self, events: List[Event]) -> None:
        episode = self._episode
        self._episode = None
        if episode is None or not episode['around']:
            return
        t, gap, normal, fraction, ball, ends = min(
            (self._lowest_gap(start, end) for start, end in episode['around']),
            key=lambda lowest: lowest[1])
        if gap >= self.config.near_miss_threshold:
            return
        events.append(NearMiss(
            stamp_ns=self._stamp(t), gap_m=gap, gap_vector=scale(normal, gap),
            ball_position=ball, bat_fraction=fraction,
            distance_from_tip_m=(1.0 - fraction) * math.dist(*ends)))
        self.stats.near_misses += 1

    # ---- impact details ------------------------------------------------------------------

    def _impact(self, t: float, hit: Any, interval: Tuple[float, float], paths: Tuple) -> Impact:
        ball_path, bat_path = paths
        knob, tip = bat_path.at(t)
        ball = ball_path.at(t)
        length = math.dist(knob, tip)
        history = True
        window, degree = self.config.velocity_window, self.config.velocity_degree
        ball_velocity = _point_velocity(self._ball, t, _same, window, min(2, degree))
        rates = _pivot_rates(self._bat, t, window, degree)
        pivot, pivot_velocity = (rates[0], rates[1]) if rates else (0.0, None)
        omega = _angular_velocity(self._bat, t, window, degree)
        if ball_velocity is None or pivot_velocity is None or omega is None:
            # not enough history before the impact: fall back to the spanning interval
            history = False
            pivot = 0.0
            ball_velocity = ball_velocity or _chord_velocity(ball_path, t)
            pivot_velocity = pivot_velocity or _chord_velocity(_KnobOf(bat_path), t)
            omega = omega or _chord_omega(bat_path, t)
        sweet = max(0.0, length - self.config.sweet_spot_from_tip)
        direction = tuple((e - k) / length for k, e in zip(knob, tip))
        swing, roll = omega
        omega = add(swing, scale(direction, roll))  # the roll turns about the bat's own axis
        sweet_arm = tuple(sweet * d for d in direction)
        # rigid body: every point moves with the pivot plus the turn about it
        pivot_point = lerp(knob, tip, pivot)
        sweet_velocity = add(pivot_velocity, cross(omega, sub(add(knob, sweet_arm), pivot_point)))
        bat_velocity = add(pivot_velocity, cross(omega, sub(hit.point, pivot_point)))
        sweet_speed = norm(sweet_velocity)
        up = self.config.up_axis
        attack = 0.0
        if sweet_speed > 0.0:
            rise = max(-1.0, min(1.0, dot(sweet_velocity, up) / sweet_speed))
            attack = math.degrees(math.asin(rise))
        closing = dot(tuple(b - v for b, v in zip(bat_velocity, ball_velocity)), hit.normal)
        return Impact(
            stamp_ns=self._stamp(t), point=tuple(hit.point), normal=tuple(hit.normal),
            bat_fraction=hit.bat_fraction, distance_from_knob_m=hit.bat_fraction * length,
            distance_from_tip_m=(1.0 - hit.bat_fraction) * length, feature=hit.feature,
            bat_velocity=bat_velocity, bat_angular_velocity=omega,
            sweet_spot_velocity=sweet_velocity, sweet_spot_speed_mps=sweet_speed,
            bat_speed_at_contact_mps=norm(bat_velocity), ball_velocity=ball_velocity,
            ball_speed_mps=norm(ball_velocity), relative_normal_speed_mps=closing,
            attack_angle_deg=attack, ball_position=ball, knob=knob, tip=tip,
            model=self.config.model, interval_start_ns=self._stamp(interval[0]),
            interval_end_ns=self._stamp(interval[1]), velocities_from_history=history,
            initially_overlapping=hit.initially_overlapping)


# ----------------------------------------------------------------------------------------------
# helpers


def _same(point: Vector) -> Vector:
    return point


def _knob_of(sample: BatSample) -> Vector:
    return sample.knob


def _axis_of(sample: BatSample) -> Vector:
    return sub(sample.tip, sample.knob)


PREDICTION_CHORD_FACTOR = 4.0
"""A prediction's sub-steps may leave the forecast paths by this many ``max_chord_error``."""

PREDICTION_DEGREE = 3
"""Largest degree of the bat fits behind a prediction: it extrapolates tens of milliseconds,
where higher degrees amplify tracking noise (at 90 Hz with 1 mm noise they lose the swing)."""

SPARSE_SAMPLES = 6
"""At most this many samples in the velocity window (a low rate): the pivot's fit uses the full
``velocity_degree``, interpolating, since the impact can be a whole step after the last sample;
with more samples (a high rate) at most degree 3, which averages tracking noise at little bias
(the hands' path is smooth; the bat's turn is not, so its fit keeps the full degree)."""

_MAX_HISTORY = 64  # samples at most in a velocity fit


def _pivot_degree(samples: int, degree: int) -> int:
    """Return the degree of the bat pivot's velocity fit for a window of ``samples``."""
    return degree if samples <= SPARSE_SAMPLES else min(degree, 3)


def _history(stream: _Stream, t: float, window: float) -> List[int]:
    """
    Return indices of samples at or before t in t's segment, ``window`` s back from the last.

    At least the last two samples of the segment (when it has them), at most ``_MAX_HISTORY``.
    """
    k = stream.interval(t)
    if k < 0:
        return []
    times, breaks = stream.times, stream.breaks
    first = max(bisect_right(times, times[k] - window - 1e-9), k - _MAX_HISTORY + 1, 0)
    first = min(first, max(k - 1, 0))
    for i in range(k, first, -1):  # stay within the segment
        if breaks[i]:
            first = i
            break
    return list(range(first, k + 1))


def _fit_polynomial(times: Sequence[float], values: Sequence[Sequence[float]], t: float,
                    degree: int) -> Tuple[List[float], List[float], List[float]]:
    """
    Return value, first and second time derivatives at t of a least-squares polynomial.

    The degree drops to the number of samples minus one (then it interpolates). Time is
    centred on t and scaled by the span, so the fit is well conditioned.

    :param times: sample times (s), oldest first, at or before t.
    :param values: one row of components per sample.
    """
    degree = min(degree, len(times) - 1)
    span = max(t - times[0], 1e-9)
    x = (np.asarray(times, dtype=float) - t) / span
    vandermonde = np.vander(x, degree + 1, increasing=True)
    coefficients, *_ = np.linalg.lstsq(vandermonde, np.asarray(values, dtype=float), rcond=None)
    first = coefficients[1] / span if degree >= 1 else 0.0 * coefficients[0]
    second = 2.0 * coefficients[2] / span ** 2 if degree >= 2 else 0.0 * coefficients[0]
    return coefficients[0].tolist(), first.tolist(), second.tolist()


def _fit_rates(times: Sequence[float], values: Sequence[Sequence[float]], t: float,
               degree: int) -> Tuple[List[float], List[float]]:
    """Return first and second time derivatives at t of ``_fit_polynomial``."""
    return _fit_polynomial(times, values, t, degree)[1:]


def _point_velocity(stream: _Stream, t: float, pick, window: float,
                    degree: int) -> Optional[Vector]:
    """
    Return the velocity (m/s) at t of a point, from the samples up to t only.

    A least-squares polynomial of ``degree`` through the samples of the last ``window`` s of
    the segment, differentiated at t; None with fewer than two samples.
    """
    indices = _history(stream, t, window)
    if len(indices) < 2:
        return None
    return tuple(_fit_rates([stream.times[i] for i in indices],
                            [pick(stream.values[i]) for i in indices], t, degree)[0])


def _rotation(a: BatSample, b: BatSample) -> Tuple[Vector, float]:
    """
    Return how the bat turned from sample a to sample b.

    :returns: (swing rotation vector: axis times angle in radians, world frame, across the
        bat; roll angle about the bat's own axis in radians, 0 for knob/tip points). The swing
        part comes from the knob-to-tip directions, so a roll of the bat cannot leak into it.
    """
    d0 = sub(a.tip, a.knob)
    d1 = sub(b.tip, b.knob)
    swing = swing_rotation(d0, d1)
    if a.quaternion is None or b.quaternion is None:
        return swing, 0.0
    x0, y0, z0, w0 = a.quaternion
    x1, y1, z1, w1 = b.quaternion
    # q = q1 * conj(q0), the world-frame rotation from a to b
    w = w1 * w0 + x1 * x0 + y1 * y0 + z1 * z0
    x = -w1 * x0 + x1 * w0 - y1 * z0 + z1 * y0
    y = -w1 * y0 + y1 * w0 - z1 * x0 + x1 * z0
    z = -w1 * z0 + z1 * w0 - x1 * y0 + y1 * x0
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    vector_part = math.sqrt(x * x + y * y + z * z)
    mean_axis = add(d0, d1)
    length = norm(mean_axis)
    if vector_part == 0.0 or length == 0.0:
        return swing, 0.0
    full = scale((x, y, z), 2.0 * math.atan2(vector_part, w) / vector_part)
    return swing, dot(full, mean_axis) / length


def _pivot_fraction(stream: _Stream, t: float, window: float, degree: int) -> float:
    """
    Return the fraction along knob-tip of the bat point that accelerates least before t.

    A swinging bat turns about the hands: the axis point nearest them moves on the smoothest
    path, so its velocity is the best one to extrapolate (the knob circles the hands). Every
    axis point's acceleration is linear in the fraction between the knob's and the tip's
    (from the same fits as the velocities, so noise is averaged); the smallest is taken,
    within [-0.5, 1].
    """
    indices = _history(stream, t, window)
    if len(indices) < 3:
        return 0.0
    times = [stream.times[i] for i in indices]
    rows = [stream.values[i].knob + stream.values[i].tip for i in indices]
    second = _fit_rates(times, rows, times[-1], _pivot_degree(len(times), degree))[1]
    knob, tip = second[:3], second[3:]
    change = sub(tip, knob)
    size = dot(change, change)
    if size == 0.0:
        return 0.0
    return min(1.0, max(-0.5, -dot(knob, change) / size))


def _pivot_rates(stream: _Stream, t: float, window: float,
                 degree: int) -> Optional[Tuple[float, Vector, Vector]]:
    """
    Return the bat pivot's fraction along knob-tip, velocity (m/s) and acceleration at t.

    The pivot is ``_pivot_fraction``'s axis point; its samples up to t are fitted with
    ``_pivot_degree``. None with fewer than two samples.
    """
    indices = _history(stream, t, window)
    if len(indices) < 2:
        return None
    fraction = _pivot_fraction(stream, t, window, degree)
    rows = [lerp(stream.values[i].knob, stream.values[i].tip, fraction) for i in indices]
    first, second = _fit_rates([stream.times[i] for i in indices], rows, t,
                               _pivot_degree(len(indices), degree))
    return fraction, tuple(first), tuple(second)


def _angular_velocity(stream: _Stream, t: float, window: float,
                      degree: int) -> Optional[Tuple[Vector, float]]:
    """
    Return the bat's swing angular velocity (rad/s) and roll rate (rad/s) at t.

    From the samples up to t only: the rotations between consecutive samples are summed into a
    cumulative rotation (exact for a turn about a fixed axis, and close when the axis moves
    slowly), fitted like a point (``_point_velocity``). None with fewer than two samples.
    """
    turn = _turn_rates(stream, t, window, degree)
    return None if turn is None else (turn[0], turn[1])


def _turn_rates(stream: _Stream, t: float, window: float,
                degree: int) -> Optional[Tuple[Vector, float, Vector]]:
    """Return ``_angular_velocity`` and the swing's angular acceleration (rad/s^2) at t."""
    indices = _history(stream, t, window)
    if len(indices) < 2:
        return None
    cumulative = [stream.turn(i) for i in indices]
    rate, change = _fit_rates([stream.times[i] for i in indices], cumulative, t, degree)
    return (rate[0], rate[1], rate[2]), rate[3], (change[0], change[1], change[2])


class _KnobOf:
    """The knob of a bat path, as a point path (for the chord fallback)."""

    def __init__(self, bat_path: BatPath) -> None:
        self.bat_path = bat_path
        self.t0, self.h = bat_path.t0, bat_path.h

    def at(self, t: float) -> Vector:
        return self.bat_path.at(t)[0]


def _chord_velocity(path: Any, t: float) -> Vector:
    a, b = path.at(path.t0), path.at(path.t0 + path.h)
    return tuple((q - p) / path.h for p, q in zip(a, b))


def _chord_omega(bat_path: BatPath, t: float) -> Tuple[Vector, float]:
    knob0, tip0 = bat_path.at(bat_path.t0)
    knob1, tip1 = bat_path.at(bat_path.t0 + bat_path.h)
    swing, roll = _rotation(BatSample(knob0, tip0, None, bat_path.sample0.quaternion),
                            BatSample(knob1, tip1, None, bat_path.sample1.quaternion))
    return scale(swing, 1.0 / bat_path.h), roll / bat_path.h
