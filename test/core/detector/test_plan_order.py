"""
Tests for baseball_collision.core.detector.plan_order: a chunk's order rules on arrays.

The order checks against the bounds written out and the intake's own hold rule; where a plan
ends and its held samples against the scan they stand for.
"""

from typing import List

from baseball_collision.core.detector import DetectorConfig
from baseball_collision.core.detector.broadphase.arrays import SLACK
from baseball_collision.core.detector.gate import HOLD_FACTOR
from baseball_collision.core.detector.plan_order import held_gaps, order_checks
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples


def test_order_checks_need_three_kept_samples() -> None:
    """``order_checks`` compares each new sample with the three before: fewer is an error."""
    stamps = np.arange(1, 6, dtype=np.int64) * 10_000_000
    times = stamps * 1e-9
    with pytest.raises(ValueError, match='3 kept samples'):
        order_checks(DetectorConfig(), stamps, times, (np.zeros((5, 3)), None), 2)
    ok, gap = order_checks(DetectorConfig(), stamps, times, (np.zeros((5, 3)), None), 3)
    assert ok.tolist() == [True, True] and gap.tolist() == [False, False]


@settings(max_examples=examples(200), deadline=None)
@given(steps=st.lists(st.sampled_from([1, 2_000_000, 2_777_778, 5_000_000, 6_944_444, 7_000_000,
                                       20_000_000, 60_000_000, 3 * 10 ** 9, -5, 0]),
                      min_size=4, max_size=40),
       moves=st.lists(st.floats(0.0, 0.4), min_size=41, max_size=41), pre=st.integers(3, 4),
       two=st.booleans())
def test_order_checks_are_the_bounds_written_out(steps: List[int], moves: List[float], pre: int,
                                                 two: bool) -> None:
    """
    ``order_checks`` (the kernel's): the stamp, gap and speed bounds in numpy, sample by sample.

    Steps on the bounds' edges (the hold factor, ``max_gap``, the reset), back and repeated
    stamps, points moving near the speed bound; a step past the two before judged by the
    median of the last eight, as ``gate.hold_ahead`` judges it.
    """
    config = DetectorConfig()
    stamps = np.cumsum(np.array([10 ** 9] + steps, dtype=np.int64))
    m = len(stamps)
    times = (stamps - stamps[0]) * 1e-9
    rng = np.random.default_rng(len(steps))
    first = np.cumsum(np.array(moves[:m])[:, None] * rng.normal(size=(m, 3)), axis=0)
    second = first + 0.8 if two else None
    ok, gap = order_checks(config, stamps, times, (first, second), pre)
    step = (stamps[pre:] - stamps[pre - 1:-1]).astype(float)
    step1 = (stamps[pre - 1:-1] - stamps[pre - 2:-2]).astype(float)
    step2 = (stamps[pre - 2:-2] - stamps[pre - 3:-3]).astype(float)
    reset = round(config.time_jump_reset * 1e9)
    dt = times[pre:] - times[pre - 1:-1]
    speed = config.max_speed * dt * (1.0 - SLACK)
    moved = np.linalg.norm(first[pre:] - first[pre - 1:-1], axis=1)
    factor = HOLD_FACTOR * (1.0 - SLACK)
    unheld = (step < factor * step1) & (step < factor * step2)
    for i, k in enumerate(range(pre, m)):  # else from the fifth sample: the last eight's median
        if not unheld[i] and k >= 4:
            recent = stamps[max(0, k - 9):k]
            unheld[i] = step[i] < factor * sorted(np.diff(recent).tolist())[(len(recent) - 1) // 2]
    expected = ((step > 0) & (step <= reset) & unheld
                & (dt <= config.max_gap * (1.0 - SLACK)) & (moved < speed))
    if two:
        expected &= np.linalg.norm(second[pre:] - second[pre - 1:-1], axis=1) < speed
    assert ok.tolist() == expected.tolist()
    assert gap.tolist() == ((step > 0) & (step <= reset * (1.0 - SLACK))
                            & (dt > config.max_gap * (1.0 + SLACK))
                            & (step > HOLD_FACTOR * (1.0 + SLACK) * step1)).tolist()


@settings(max_examples=examples(300), deadline=None)
@given(steps=st.lists(st.integers(1, 6), min_size=4, max_size=30), pre=st.integers(3, 9))
def test_a_sample_the_order_checks_pass_is_not_held(steps: List[int], pre: int) -> None:
    """
    A sample ``order_checks`` passes is one ``gate.hold_ahead`` takes at once (not held).

    Jittered clocks on a millisecond grid (steps of 1-6 ms, so a long step after a short one
    is common): every sample passed is not held by the intake's own rule.
    """
    from baseball_collision.core.detector.gate import hold_ahead
    config = DetectorConfig()
    stamps = np.cumsum(np.array([10 ** 9] + [step * 1_000_000 for step in steps], np.int64))
    if len(stamps) <= pre:
        return
    times = (stamps - stamps[0]) * 1e-9
    ok, _ = order_checks(config, stamps, times, (np.zeros((len(stamps), 3)), None), pre)
    reset = round(config.time_jump_reset * 1e9)
    for k in range(pre, len(stamps)):
        if ok[k - pre]:
            assert not hold_ahead(stamps[:k].tolist(), int(stamps[k]), reset), k


def _held_gaps_written_out(ok, gap, is_ball, is_bat, stamps, newest):  # type: ignore
    """``plan_order.held_gaps`` as its Python was (the samples before each one scanned again)."""
    n = len(ok)
    failing = np.flatnonzero(~ok).tolist()
    if not failing:
        return n, []
    following = np.full(n, n)
    for mine in (is_ball, is_bat):
        own = np.flatnonzero(mine)
        following[own[:-1]] = own[1:]
    waiting = np.zeros(n, bool)
    held = []
    for x in failing:
        y = int(following[x])
        if not gap[x] or y >= n or not ok[y]:
            return x + 1, held
        before = stamps[:x][~waiting[:x]]
        if stamps[x] <= max(newest, int(before.max()) if len(before) else newest):
            return x + 1, held
        held.append((x, y))
        waiting[x] = True
    return n, held


@settings(max_examples=examples(300), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(1, 60), failing=st.floats(0.0, 0.5),
       ahead=st.integers(-3, 3))
def test_held_gaps_are_the_scan_written_out(seed: int, n: int, failing: float,
                                            ahead: int) -> None:
    """
    Where a plan ends and its held samples: the same as scanning the samples before each.

    Random checks failed and passed, gap starts among the failures, the two streams' samples
    mixed, stamps out of order among them and about the streams' newest.
    """
    rng = np.random.default_rng(seed)
    ok = rng.random(n) >= failing
    gap = ~ok & (rng.random(n) < 0.8)
    is_ball = rng.random(n) < 0.5
    stamps = (np.cumsum(rng.integers(-2, 5, n)) + 100).astype(np.int64)
    newest = max(100 + ahead, 99)
    assert held_gaps(ok, gap, is_ball, ~is_ball, stamps, newest) == _held_gaps_written_out(
        ok, gap, is_ball, ~is_ball, stamps, newest)
