"""Tests for the detector's gate: value, stamp, speed and length checks, and the clock."""

import math

from baseball_collision.core.detector.events import DropReason, ResetReason
from baseball_collision.core.detector.gate import (
    Clock, FAR_AHEAD_NS, finite_point, frame_check, FrameVote, hold_ahead, HOLD_FACTOR,
    JUMP_CONFIRM, JumpWatch, LengthCheck, lost_body, speed_check, stamp_check, unit_pose)
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


def test_bad_frames_are_refused_before_any_comparison() -> None:
    """Control characters (an embedded NUL) and U+FFFD (bytes that were not UTF-8) are bad."""
    for frame in ('wor\x00ld', 'w\ufffdrld', 'world\n', '\x7f'):
        assert frame_check(frame, None) is DropReason.BAD_FRAME
        assert frame_check(frame, 'world') is DropReason.BAD_FRAME
    assert frame_check('wörld', None) is None and frame_check('a b', 'a b') is None


def test_the_frame_vote_needs_every_role() -> None:
    """The first frame is provisional; a frame is agreed once every role sent it."""
    vote = FrameVote('', ('ball', 'bat_pose'))
    assert vote.frame is None and vote.vote('ball', 'camera') is None
    assert vote.provisional == 'camera'
    assert vote.vote('ball', 'world') is None and vote.vote('ball', '') is None
    assert vote.vote('bat_pose', 'world') == 'world'
    assert vote.candidate() == 'world'  # two votes to one
    assert FrameVote('world', ('ball',)).frame == 'world'


def test_a_frame_is_a_candidate_only_if_every_stream_sending_one_sent_it() -> None:
    """
    Without agreement, the most common frame is adopted only where no stream never sent it.

    A stream silent so far (or sending only empty frames) does not count; streams in frames
    that differ leave no candidate, and the disagreement names each stream's frames.
    """
    vote = FrameVote('', ('ball', 'knob', 'tip'))
    assert vote.candidate() is None and vote.disagreement() is None  # nothing sent
    for _ in range(5):
        vote.vote('knob', 'a')
    vote.vote('knob', 'b')
    vote.vote('tip', 'b')
    vote.vote('ball', '')
    assert vote.candidate() == 'b'  # 'a' is the most common, but the tip never sent it
    assert vote.disagreement() is None
    vote.vote('ball', 'world')
    assert vote.candidate() is None
    assert vote.disagreement() == "ball sends 'world', knob sends 'a' and 'b', tip sends 'b'"
    vote.frame = 'b'  # (adopted: no disagreement any more)
    assert vote.disagreement() is None


def test_a_lost_body_is_exactly_the_identity_at_the_origin() -> None:
    """Origin and identity; a pose a hair away from either is a real pose."""
    assert lost_body((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    assert lost_body((-0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    assert not lost_body((0.0, 0.0, 1e-9), (0.0, 0.0, 0.0, 1.0))
    assert not lost_body((0.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0))


def test_a_step_far_beyond_the_usual_waits() -> None:
    """Hold when the step is over HOLD_FACTOR typical steps or over the jump threshold."""
    ms = 1_000_000
    stamps = [i * 3 * ms for i in range(10)]
    newest, reset = stamps[-1], 1000 * ms
    assert not hold_ahead(stamps, newest + 3 * ms, reset)
    assert not hold_ahead(stamps, newest + int(HOLD_FACTOR * 3 * ms), reset)
    assert hold_ahead(stamps, newest + int(HOLD_FACTOR * 3 * ms) + 1, reset)
    assert not hold_ahead(stamps[:3], newest + 30 * ms, reset)  # too few steps to know
    assert hold_ahead(stamps[:2], newest + reset + 1, reset)  # beyond a jump: always
    jittered = stamps[:-1] + [stamps[-1] + 5 * ms]  # one long step does not set the usual
    assert hold_ahead(jittered, jittered[-1] + 9 * ms, reset)


def test_the_jump_watch_confirms_only_samples_in_a_row_that_agree() -> None:
    """JUMP_CONFIRM agreeing samples confirm; one far from the others starts again."""
    watch, second = JumpWatch(), 1_000_000_000
    for k in range(JUMP_CONFIRM - 1):
        assert watch.behind(k, 5 * second + k, second) == (False, [])
    confirmed, abandoned = watch.behind('other', 50 * second, second)  # another clock
    assert not confirmed and abandoned == list(range(JUMP_CONFIRM - 1))
    for k in range(JUMP_CONFIRM - 2):
        assert not watch.behind(k, 50 * second + k, second)[0]
    assert watch.behind('last', 50 * second - 1, second) == (True, [])
    assert len(watch.take()) == JUMP_CONFIRM and watch.candidates == []
