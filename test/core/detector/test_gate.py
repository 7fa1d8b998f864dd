"""Tests for the detector's gate: value, stamp, speed and length checks, and the clock."""

import math

from baseball_collision.core.detector.events import DropReason, ResetReason
from baseball_collision.core.detector.gate import (
    Clock, FAR_AHEAD_NS, finite_point, frame_check, LengthCheck, speed_check, stamp_check,
    unit_pose)
from baseball_collision.core.detector.streams import Stream
import pytest


def test_points_must_be_three_finite_numbers() -> None:
    """Numbers become floats; inf and NaN give None; non-numbers raise (dropped as such)."""
    assert finite_point((1, 2.5, '3')) == (1.0, 2.5, 3.0)
    assert finite_point((0.0, math.inf, 0.0)) is None
    assert finite_point((math.nan, 0.0, 0.0)) is None
    with pytest.raises(ValueError):
        finite_point((1.0, 2.0))
    with pytest.raises(ValueError):
        finite_point(('x', 0.0, 0.0))


def test_poses_need_a_unit_quaternion() -> None:
    """A quaternion within 1e-3 of unit is normalised; further off, or non-finite, dropped."""
    position, quaternion = unit_pose(((1, 2, 3), (0.0, 0.0, 0.0, 1.0005)))
    assert position == (1.0, 2.0, 3.0) and quaternion == pytest.approx((0, 0, 0, 1), abs=1e-15)
    assert unit_pose(((0, 0, 0), (0.0, 0.0, 0.0, 1.01))) is DropReason.BAD_QUATERNION
    assert unit_pose(((0, 0, math.nan), (0.0, 0.0, 0.0, 1.0))) is DropReason.NON_FINITE


def test_frames_other_than_the_tracking_one_are_dropped() -> None:
    """An empty frame, or no tracking frame yet, passes."""
    assert frame_check('world', 'world') is None
    assert frame_check('', 'world') is None and frame_check('camera', None) is None
    assert frame_check('camera', 'world') is DropReason.WRONG_FRAME


def test_stamp_order_and_jumps() -> None:
    """In order passes; equal or a little behind drops; far behind or far ahead resets."""
    second = 1_000_000_000
    assert stamp_check(None, 5, None, 1.0) is None
    assert stamp_check(10 * second, 11 * second, 0, 1.0) is None
    assert stamp_check(10 * second, 10 * second, 0, 1.0) is DropReason.DUPLICATE_STAMP
    assert stamp_check(10 * second, 9 * second, 0, 1.0) is DropReason.OUT_OF_ORDER
    assert stamp_check(10 * second, 8 * second, 0, 1.0) is ResetReason.TIME_JUMP_BACKWARDS
    assert stamp_check(None, FAR_AHEAD_NS + 1, 0, 1.0) is ResetReason.TIME_JUMP_FORWARD
    assert stamp_check(None, FAR_AHEAD_NS, 0, 1.0) is None


def test_clock_keeps_nanoseconds_from_its_origin() -> None:
    """Times are seconds after the first stamp; stamps come back to the nanosecond."""
    clock = Clock()
    base = 1_700_000_000_123_456_789
    clock.origin = base
    assert clock.time(base + 1_500_000_001) == pytest.approx(1.500000001, abs=1e-15)
    assert clock.stamp(clock.time(base + 987_654_321)) == base + 987_654_321


def test_speed_bound_drops_jumps_until_the_third_in_a_row() -> None:
    """A point faster than max_speed is dropped twice; the third starts a new segment."""
    stream = Stream('ball')
    assert speed_check(stream, 0.0, [(0.0, 0.0, 0.0)], [], 0.05, 150.0) == (True, True)
    stream.append(0.0, 1, (0.0, 0.0, 0.0), True)
    assert speed_check(stream, 0.01, [(1.0, 0.0, 0.0)], [(0.0, 0.0, 0.0)], 0.05, 150.0) == (
        True, False)
    far = [(5.0, 0.0, 0.0)]
    assert speed_check(stream, 0.01, far, [(0.0, 0.0, 0.0)], 0.05, 150.0) == (False, False)
    assert speed_check(stream, 0.01, far, [(0.0, 0.0, 0.0)], 0.05, 150.0) == (False, False)
    assert speed_check(stream, 0.01, far, [(0.0, 0.0, 0.0)], 0.05, 150.0) == (True, True)
    assert stream.speed_drops == 0
    # after a gap longer than max_gap anything goes, as a new segment
    assert speed_check(stream, 1.0, [(900.0, 0.0, 0.0)], [(0.0, 0.0, 0.0)], 0.05, 150.0) == (
        True, True)


def test_bat_length_against_the_recent_median() -> None:
    """Zero length and jumps are dropped; three jumps in a row are a new bat."""
    check = LengthCheck()
    knob = (0.0, 0.0, 0.0)
    assert check.check(knob, (0.0005, 0.0, 0.0), 0.05) is DropReason.ZERO_LENGTH_BAT
    for length in (0.86, 0.87, 0.85):
        assert check.check(knob, (length, 0.0, 0.0), 0.05) is None
    assert check.check(knob, (1.2, 0.0, 0.0), 0.05) is DropReason.BAT_LENGTH_JUMP
    assert check.check(knob, (1.2, 0.0, 0.0), 0.05) is DropReason.BAT_LENGTH_JUMP
    assert check.check(knob, (1.2, 0.0, 0.0), 0.05) is None  # re-calibrated
    assert check.lengths == [1.2]
    for _ in range(20):
        check.check(knob, (1.2, 0.0, 0.0), 0.05)
    assert len(check.lengths) == 15
