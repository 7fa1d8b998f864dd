"""
The sample checks: what a sample must pass before it is buffered, and why it is dropped.

Pure functions and two small state holders (the clock's origin, the bat's recent lengths).
The facade runs them in order (frame, values, stamp, clock, physical bounds); a bad sample is
dropped for one ``DropReason`` and never processed. Two stamp outcomes are not drops but
resets (``ResetReason``): a stamp far behind its stream, and one far after the clock's origin.
"""

import math
from typing import List, Optional, Sequence, Tuple, Union

from .events import DropReason, ResetReason
from .streams import Stream
from ..geometry import Quaternion, Vector

FAR_AHEAD_NS = 10 ** 15
"""A stamp this far (ns, about 11.6 days) after the detector's time origin starts a new one:
float seconds keep nanosecond resolution up to about 10^6 s."""

SPEED_DROPS_TO_JUMP = 3
"""Samples in a row over the speed bound after which the body really moved (a new segment)."""

LENGTH_DROPS_TO_CHANGE = 3
"""Bat samples in a row off the usual length after which the bat really changed."""

LENGTHS_KEPT = 15
"""Recent bat lengths whose median is the reference."""


class Clock:
    """
    The detector's time origin: float seconds inside, integer nanosecond stamps outside.

    Absolute epoch nanoseconds do not fit a float, so times are seconds after ``origin``, the
    first accepted stamp (ns; None before any).
    """

    __slots__ = ('origin',)

    def __init__(self) -> None:
        self.origin: Optional[int] = None

    def time(self, stamp: int) -> float:
        """Return a stamp in nanoseconds as seconds on the detector's clock."""
        return (stamp - self.origin) * 1e-9

    def stamp(self, t: float) -> int:
        """Return seconds on the detector's clock as a stamp, to the nearest nanosecond."""
        return self.origin + int(round(t * 1e9))


def frame_check(frame_id: str, frame: Optional[str]) -> Optional[DropReason]:
    """Return ``WRONG_FRAME`` for a frame other than the tracking one (an empty one passes)."""
    if not frame_id or frame is None or frame_id == frame:
        return None
    return DropReason.WRONG_FRAME


def finite_point(value: Sequence[float]) -> Optional[Vector]:
    """
    Return three numbers as a tuple of floats; None when one is infinite or NaN.

    :raises TypeError, ValueError: not three numbers (the facade drops those as non-finite).
    """
    x, y, z = value
    x, y, z = float(x), float(y), float(z)
    if x * 0.0 + y * 0.0 + z * 0.0 != 0.0:  # inf or NaN
        return None
    return (x, y, z)


def unit_pose(pose: Tuple[Sequence[float], Sequence[float]]) -> Union[
        DropReason, Tuple[Vector, Quaternion]]:
    """
    Return a pose (position, quaternion x y z w) with a normalised quaternion, or why not.

    :raises TypeError, ValueError: not 3 and 4 numbers.
    """
    position, quaternion = pose
    px, py, pz = position
    qx, qy, qz, qw = quaternion
    px, py, pz = float(px), float(py), float(pz)
    qx, qy, qz, qw = float(qx), float(qy), float(qz), float(qw)
    # each product is 0.0 for a finite number and NaN for inf or NaN (and cannot overflow)
    if px * 0.0 + py * 0.0 + pz * 0.0 + qx * 0.0 + qy * 0.0 + qz * 0.0 + qw * 0.0 != 0.0:
        return DropReason.NON_FINITE
    magnitude = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    if abs(magnitude - 1.0) > 1e-3:
        return DropReason.BAD_QUATERNION
    return (px, py, pz), (qx / magnitude, qy / magnitude, qz / magnitude, qw / magnitude)


def stamp_check(newest: Optional[int], stamp: int, origin: Optional[int],
                time_jump_reset: float) -> Union[DropReason, ResetReason, None]:
    """
    Return what a stamp (ns) means after its stream's ``newest`` and the clock's ``origin``.

    :returns: None (take it), ``DUPLICATE_STAMP`` or ``OUT_OF_ORDER`` (a little behind: drop
        it), ``TIME_JUMP_BACKWARDS`` (more than ``time_jump_reset`` s behind) or
        ``TIME_JUMP_FORWARD`` (more than ``FAR_AHEAD_NS`` after the origin): reset, then take
        it.
    """
    if newest is not None and stamp <= newest:
        if stamp == newest:
            return DropReason.DUPLICATE_STAMP
        if (newest - stamp) * 1e-9 > time_jump_reset:
            return ResetReason.TIME_JUMP_BACKWARDS
        return DropReason.OUT_OF_ORDER
    if origin is not None and stamp - origin > FAR_AHEAD_NS:
        # a new session (or a wild clock): a new origin keeps float times at ns resolution
        return ResetReason.TIME_JUMP_FORWARD
    return None


def speed_check(stream: Stream, t: float, points: Sequence[Vector],
                previous_points: Sequence[Vector], max_gap: float,
                max_speed: float) -> Tuple[bool, bool]:
    """
    Return (accept, new_segment) for a sample at t (s) after the physical speed bound.

    A sample whose points moved faster than ``max_speed`` (m/s) from the stream's last is
    dropped, unless it is the ``SPEED_DROPS_TO_JUMP``-th in a row: then the body really moved
    and it starts a new segment (as does a sample after a gap longer than ``max_gap``).
    """
    if not stream.times:
        return True, True
    dt = t - stream.times[-1]
    if dt > max_gap:
        stream.speed_drops = 0
        return True, True
    limit = max_speed * dt
    for p, q in zip(points, previous_points):
        if math.dist(p, q) > limit:  # math.dist does not overflow (1e300 m is fine)
            stream.speed_drops += 1
            if stream.speed_drops >= SPEED_DROPS_TO_JUMP:
                stream.speed_drops = 0
                return True, True
            return False, False
    stream.speed_drops = 0
    return True, False


class LengthCheck:
    """The knob-tip length of bat points against the median of the recent ones."""

    __slots__ = ('lengths', 'drops')

    def __init__(self) -> None:
        self.lengths: List[float] = []
        self.drops = 0

    def check(self, knob: Vector, tip: Vector, tolerance: float) -> Optional[DropReason]:
        """
        Return why a bat of these ends is dropped, or None (its length is then kept).

        ``ZERO_LENGTH_BAT`` under 1 mm; ``BAT_LENGTH_JUMP`` more than ``tolerance`` (m) off the
        median, unless it is the ``LENGTH_DROPS_TO_CHANGE``-th in a row (a re-calibration:
        the history starts again).
        """
        length = math.dist(knob, tip)
        if length < 1e-3:
            return DropReason.ZERO_LENGTH_BAT
        lengths = self.lengths
        if lengths:
            reference = sorted(lengths)[len(lengths) // 2]
            if abs(length - reference) > tolerance:
                self.drops += 1
                if self.drops < LENGTH_DROPS_TO_CHANGE:
                    return DropReason.BAT_LENGTH_JUMP
                lengths.clear()  # the bat really changed (re-calibration)
        self.drops = 0
        lengths.append(length)
        if len(lengths) > LENGTHS_KEPT:
            del lengths[0]
        return None
