"""
The sample checks: what a sample must pass before it is buffered, and why it is dropped.

Pure functions and small state holders (the clock's origin, the bat's recent lengths, the
frame vote, the watch on samples far behind). The facade checks values first, then
``intake`` orders the rest (frame, stamp, clock, physical bounds); a bad sample is dropped for
one ``DropReason`` and never processed. Two stamp outcomes are not drops but resets
(``ResetReason``): stamps far behind their streams once enough of them agree (a jump back),
and one far after the clock's origin.
"""

from collections import Counter
import math
import numbers
from typing import Any, Collection, Dict, List, Optional, Sequence, Set, Tuple, Union

from .events import DropReason, ResetReason
from .streams import Stream
from ..geometry import Quaternion, Vector
from ...errors import CoreError

FAR_AHEAD_NS = 10 ** 15
"""A stamp this far (ns, about 11.6 days) after the detector's time origin starts a new one:
float seconds keep nanosecond resolution up to about 10^6 s."""

SPEED_DROPS_TO_JUMP = 3
"""Samples in a row over the speed bound after which the body really moved (a new segment)."""

LENGTH_DROPS_TO_CHANGE = 3
"""Bat samples in a row off the usual length after which the bat really changed."""

LENGTHS_KEPT = 15
"""Recent bat lengths whose median is the reference."""

JUMP_CONFIRM = 10
"""Samples in a row far behind the clock (and agreeing with each other) that make a jump back;
fewer, interleaved with samples on the current clock, are another publisher's clock."""

HOLD_FACTOR = 2.5
"""A sample this many typical steps after its stream's newest waits for the next one."""

FRAME_PENDING_MAX = 32
"""Samples kept waiting for the streams to agree on a frame; then the most common that every
stream sending a frame has sent is taken (``FrameVote.candidate``), and where there is none the
oldest waiting sample is dropped (``no_common_frame``) and the wait goes on."""


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
    """
    Return why a sample's ``frame_id`` is refused against the tracking ``frame``, or None.

    ``BAD_FRAME``: control characters (an embedded NUL) or U+FFFD (bytes that were not UTF-8,
    as rclpy decodes them); ``WRONG_FRAME``: another frame than the tracking one. An empty
    frame passes, as does any frame while there is no tracking frame yet.
    """
    if not frame_id or frame_id == frame:  # (the tracking frame was checked when adopted)
        return None
    if not frame_id.isprintable() or '\ufffd' in frame_id:
        return DropReason.BAD_FRAME
    return None if frame is None else DropReason.WRONG_FRAME


class FrameVote:
    """
    The tracking frame: configured, or adopted once every input stream has sent it.

    :param configured: the ``frame_id`` parameter ('' : vote).
    :param roles: the input roles that must agree (``ball`` and ``bat_pose``, or ``ball``,
        ``knob`` and ``tip``), in the order :meth:`disagreement` names them.
    :ivar frame: the tracking frame (None before agreement).
    :ivar provisional: the first frame voted for (None before any).
    :ivar seen: the roles that sent each frame (frames in the order first seen).
    :ivar blank: the roles that sent an empty frame (taken as in any frame: ``Intake.offer``
        notes them before agreement).
    """

    __slots__ = ('frame', 'provisional', 'roles', 'order', 'seen', 'counts', 'blank')

    def __init__(self, configured: str, roles: Collection[str]) -> None:
        self.frame: Optional[str] = configured or None
        self.provisional: Optional[str] = None
        self.roles = frozenset(roles)
        self.order = tuple(roles)
        self.seen: Dict[str, Set[str]] = {}
        self.counts: Counter = Counter()
        self.blank: Set[str] = set()

    def vote(self, role: str, frame_id: str) -> Optional[str]:
        """Count a sample's (non-empty) frame; return the frame every role has sent, or None."""
        if not frame_id:
            return None
        if self.provisional is None:
            self.provisional = frame_id
        roles = self.seen.setdefault(frame_id, set())
        roles.add(role)
        self.counts[frame_id] += 1
        return frame_id if roles >= self.roles else None

    def candidate(self) -> Optional[str]:
        """
        Return the frame to adopt without agreement: the most common one every stream sent.

        Every stream that has sent a (non-empty) frame must have sent it; a stream silent so
        far, or one that has sent an empty frame (taken as in any frame: a stray frame on it
        holds nothing up), does not count. The first seen among equals; None where no frame
        qualifies (``disagreement``) or none was sent.
        """
        framing = set().union(*self.seen.values()) - self.blank
        for frame, _ in self.counts.most_common():
            if self.seen[frame] >= framing:
                return frame
        return None

    def disagreement(self) -> Optional[str]:
        """
        Return each stream's frames while no frame can be adopted, None otherwise.

        ``"ball sends 'world', bat_pose sends 'arm_base'"``: streams in the roles' order, each
        with the frames it sent in the order first seen (a stream that sent none left out).
        """
        if self.frame is not None or not self.seen or self.candidate() is not None:
            return None
        parts = []
        for role in self.order:
            frames = [frame for frame, roles in self.seen.items() if role in roles]
            if frames:
                parts.append(f"{role} sends {' and '.join(repr(f) for f in frames)}")
        return ', '.join(parts)


def integer_stamp(stamp_ns: Any, what: str = 'stamp_ns') -> int:
    """
    Return a stamp given as an integer number of nanoseconds (a Python or numpy integer).

    :raises CoreError: anything else (a float: seconds, or epoch nanoseconds a double cannot
        hold to the nanosecond; a bool; a string). A programming error, never data to drop: it
        was truncated before and every sample dropped as a duplicate or a bad stamp.
    """
    if stamp_ns.__class__ is int or (isinstance(stamp_ns, numbers.Integral)
                                     and not isinstance(stamp_ns, bool)):
        return int(stamp_ns)
    raise CoreError(f'{what} must be an integer number of nanoseconds, not '
                    f'{type(stamp_ns).__name__} {stamp_ns!r} (seconds? int(round(s * 1e9)))')


def frame_text(frame_id: Any) -> str:
    """
    Return a sample's ``frame_id`` as given (a str), '' for None.

    :raises CoreError: anything else (bytes, a number): a programming error, as a float stamp
        is, not data to drop.
    """
    if frame_id is None:
        return ''
    if isinstance(frame_id, str):
        return str(frame_id)
    raise CoreError(f'frame_id must be a str, not {type(frame_id).__name__} {frame_id!r}')


def finite_point(value: Sequence[float]) -> Optional[Vector]:
    """
    Return three numbers as a tuple of floats; None when one is infinite or NaN.

    :raises TypeError, ValueError: not three numbers (the facade raises ``CoreError`` for
        those: :func:`values_error`).
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

    :raises TypeError, ValueError: not 3 and 4 numbers (the facade raises ``CoreError`` for
        those: :func:`values_error`).
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


POINT_VALUES = '3 numbers (x, y, z) in m'
"""What a ball, knob or tip sample's values are."""

POSE_VALUES = '7 numbers (px, py, pz) in m and a unit quaternion (qx, qy, qz, qw)'
"""What a bat pose's values are, given to ``Detector.add`` in one sequence."""


def values_error(role: str, value: Any, parts: bool = False) -> str:
    """
    Return why a sample's values are refused: not the numbers of its role (for ``CoreError``).

    A programming error, as a float stamp is (the node's messages fix the shapes): values of
    another length or that are not numbers were dropped as ``non_finite`` before, which sent
    the caller looking for NaNs.

    :param role: the sample's role.
    :param value: the values as given.
    :param parts: ``value`` is ``add_bat_pose``'s (position, quaternion).
    """
    if parts:
        position, quaternion = value
        return ('a bat pose is a position of 3 numbers (m) and a unit quaternion of 4 (x, y, '
                f'z, w), got {_described(position, 3)} and {_described(quaternion, 4)}')
    pose = role == 'bat_pose'
    return (f'{role} values must be {POSE_VALUES if pose else POINT_VALUES}, got '
            f'{_described(value, 7 if pose else 3)}')


def _described(value: Any, count: int) -> str:
    """Return what a value given for ``count`` numbers is: its shape or type, and itself."""
    text = ' '.join(repr(value).split())
    text = text if len(text) <= 60 else text[:57] + '...'
    shape = getattr(value, 'shape', None)
    if isinstance(shape, tuple):  # a numpy array
        return f'an array of shape {shape}: {text}'
    if isinstance(value, (str, bytes)) or not hasattr(value, '__len__'):
        return f'{type(value).__name__} {text}'
    if len(value) != count:
        return f'{len(value)} values: {text}'
    try:
        [float(each) for each in value]
    except (TypeError, ValueError):
        return f'{count} values, not all numbers: {text}'
    return f'{count} numbers: {text}'


def lost_body(position: Vector, quaternion: Quaternion) -> bool:
    """Return whether a pose is exactly the origin with the identity orientation."""
    return position == (0.0, 0.0, 0.0) and quaternion == (0.0, 0.0, 0.0, 1.0)


def stamp_check(newest: Optional[int], stamp: int, origin: Optional[int],
                time_jump_reset: float) -> Union[DropReason, ResetReason, None]:
    """
    Return what a stamp (ns) means after its stream's ``newest`` and the clock's ``origin``.

    :returns: None (take it), ``DUPLICATE_STAMP`` or ``OUT_OF_ORDER`` (a little behind: drop
        it), ``TIME_JUMP_BACKWARDS`` (more than ``time_jump_reset`` s behind: a jump back, or
        another clock; ``JumpWatch`` tells which) or ``TIME_JUMP_FORWARD`` (more than
        ``FAR_AHEAD_NS`` after the origin): reset, then take it.
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
    if not within_speed(dt, points, previous_points, max_speed):
        stream.speed_drops += 1
        if stream.speed_drops >= SPEED_DROPS_TO_JUMP:
            stream.speed_drops = 0
            return True, True
        return False, False
    stream.speed_drops = 0
    return True, False


def within_speed(dt: float, points: Sequence[Vector], previous_points: Sequence[Vector],
                 max_speed: float) -> bool:
    """Return whether no point moved faster than ``max_speed`` (m/s) over dt (s) from before."""
    limit = max_speed * dt
    for p, q in zip(points, previous_points):
        if math.dist(p, q) > limit:  # math.dist does not overflow (1e300 m is fine)
            return False
    return True


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


class JumpWatch:
    """
    Samples far behind the clock, kept until they make a jump back or prove another clock.

    A jump back (a looped bag, a restarted clock) moves every stream: ``JUMP_CONFIRM`` samples
    in a row arrive far behind, each within ``time_jump_reset`` of the previous ones. A stale
    second publisher sends its samples between the current clock's: a sample on the current
    clock abandons the candidates (they are dropped as ``STALE_STAMP``).

    :ivar candidates: the samples waiting, in arrival order.
    :ivar newest: the newest stamp among them (ns).
    """

    __slots__ = ('candidates', 'newest')

    def __init__(self) -> None:
        self.candidates: List[Any] = []
        self.newest = 0

    def behind(self, sample: Any, stamp: int, reset_ns: int) -> Tuple[bool, List[Any]]:
        """
        Keep a sample stamped (ns) far behind the clock.

        :param reset_ns: ``time_jump_reset`` in ns: how far apart samples of one clock may be.
        :returns: (whether the jump is confirmed, the candidates it abandoned: another clock).
        """
        abandoned: List[Any] = []
        if self.candidates and abs(stamp - self.newest) > reset_ns:
            abandoned, self.candidates = self.candidates, []
        if not self.candidates or stamp > self.newest:
            self.newest = stamp
        self.candidates.append(sample)
        return len(self.candidates) >= JUMP_CONFIRM, abandoned

    def take(self) -> List[Any]:
        """Return the candidates and forget them."""
        candidates, self.candidates = self.candidates, []
        return candidates


def hold_ahead(stamps: Sequence[int], stamp: int, reset_ns: int) -> bool:
    """
    Return whether a sample stamped (ns) after its stream's ``stamps`` should wait for the next.

    It waits when its step from the newest is more than ``reset_ns`` or ``HOLD_FACTOR`` times
    the stream's typical step (the median of its last eight): a glitched stamp, or a real gap
    the next sample will confirm.
    """
    step = stamp - stamps[-1]
    if step > reset_ns:
        return True
    if len(stamps) < 4:
        return False
    if step <= HOLD_FACTOR * (stamps[-1] - stamps[-2]) and \
            step <= HOLD_FACTOR * (stamps[-2] - stamps[-3]):
        return False  # the common case: a step like the last two
    recent = stamps[-9:]
    steps = sorted(b - a for a, b in zip(recent[:-1], recent[1:]))
    return step > HOLD_FACTOR * steps[len(steps) // 2]
