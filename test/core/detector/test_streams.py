"""Tests for the detector's sample buffer: intervals, segments, history, trimming, turns."""

import math
from typing import Callable, List, Optional, Set, Tuple

from baseball_collision.core.detector.streams import MAX_HISTORY, reversed_excerpt, Stream
from baseball_collision.core.motion import BatSample
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples


def _filled(times, breaks=()) -> Stream:
    stream = Stream('ball')
    for i, t in enumerate(times):
        stream.append(t, 1000 + i, (t, 0.0, 0.0), i in breaks)
    return stream


def test_intervals_and_continuity() -> None:
    """Find the sample interval of a time; a break or a long step is not continuous."""
    stream = _filled([0.0, 0.01, 0.02, 0.1, 0.11], breaks={4})
    assert stream.interval(-1.0) == -1 and stream.interval(0.015) == 1
    assert stream.interval(0.02) == 2 and stream.newest() == 1004
    assert stream.breaks == [True, False, False, False, True]
    assert stream.continuous(1, 0.05) and not stream.continuous(2, 0.05)
    assert not stream.continuous(3, 0.05)  # the break
    assert stream.neighbours(1, 0.05) == (0, 3 if stream.continuous(2, 0.05) else None)
    assert stream.neighbours(0, 0.05) == (None, 2)


def test_history_stays_in_the_segment_and_the_window() -> None:
    """The window back from t, at least two samples, never across a segment break."""
    stream = _filled([0.01 * i for i in range(10)], breaks={5})
    assert list(stream.history(0.085, 0.025)) == [6, 7, 8]  # back from the last sample, 0.08
    assert list(stream.history(0.085, 0.05)) == [5, 6, 7, 8]  # not across the break at 5
    assert list(stream.history(0.055, 1.0)) == [5]
    assert list(stream.history(0.045, 0.0)) == [3, 4]  # at least two
    assert list(stream.history(-0.5, 1.0)) == []
    long = _filled([0.001 * i for i in range(200)])
    assert len(long.history(0.199, 10.0)) == MAX_HISTORY


def test_trim_keeps_what_the_fits_need() -> None:
    """Samples older than the history and a few before the cursor go; the path cache too."""
    stream = _filled([0.001 * i for i in range(100)])
    stream.path_key = (1, 2)
    stream.trim(0.0995, 0.01)
    # the last sample at or before 0.0995 - 0.01 is 0.089; four more are kept before it
    assert stream.times[0] == pytest.approx(0.085, abs=1e-12)
    assert stream.path_key is None
    short = _filled([0.0, 0.01])
    short.trim(1.0, 0.0)
    assert len(short.times) == 2  # short buffers are left alone


def test_a_removed_sample_is_as_if_it_never_came() -> None:
    """
    ``remove``: the sample's neighbours join; per-sample facts lose its entry, the rest is cut.

    The kept parabolas and the far test's numbers, each made from a few samples about its own,
    are cut back to the one before it and made again on demand; the noise estimate after each
    sample (a fact) keeps the others' entries where they were; a segment it started starts at
    the next sample; the path cache goes.
    """
    stream = _filled([0.01 * i for i in range(8)], breaks={5})
    stream.aligned['noise'] = [0.1 * i for i in range(8)]
    stream.aligned['parabolas'] = list(range(8))
    stream.path_key = (1, 2)
    stream.remove(3, ('noise',))
    assert stream.stamps == [1000, 1001, 1002, 1004, 1005, 1006, 1007]
    assert stream.times[3] == pytest.approx(0.04) and stream.values[3] == (0.04, 0.0, 0.0)
    assert stream.aligned['noise'] == pytest.approx([0.0, 0.1, 0.2, 0.4, 0.5, 0.6, 0.7])
    assert stream.aligned['parabolas'] == [0, 1]
    assert stream.path_key is None
    assert stream.breaks == [True, False, False, False, True, False, False]
    stream.remove(4, ('noise',))  # the sample that started the second segment: the next does
    assert stream.stamps[4] == 1006 and stream.breaks == [True, False, False, False, True, False]
    assert len(stream.aligned['noise']) == 6 and stream.aligned['parabolas'] == [0, 1]


def test_an_inserted_sample_joins_its_neighbours() -> None:
    """
    ``insert``: a sample put back in stamp order starts a segment only after a long gap.

    The sample after it continues it (the segment break a forgotten glitch left there goes)
    unless a gap parts them; per-sample facts take the entry before it, the rest is cut back
    as ``remove`` cuts it; the path cache goes.
    """
    stream = _filled([0.0, 0.01, 0.02, 0.2, 0.22, 0.23], breaks={3})
    stream.aligned['noise'] = [0.1 * i for i in range(6)]
    stream.aligned['parabolas'] = list(range(6))
    stream.path_key = (1, 2)
    assert stream.insert(0.21, 7, (0.21, 0.0, 0.0), 0.05, ('noise',)) == 4
    assert stream.stamps == [1000, 1001, 1002, 1003, 7, 1004, 1005]
    assert stream.breaks == [True, False, False, True, False, False, False]
    assert stream.aligned['noise'] == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.3, 0.4, 0.5])
    assert stream.aligned['parabolas'] == [0, 1, 2] and stream.path_key is None
    stream.remove(3, ('noise',))  # a glitch that started the segment: its next starts it
    assert stream.breaks == [True, False, False, True, False, False]
    assert stream.insert(0.15, 8, (0.15, 0.0, 0.0), 0.05, ('noise',)) == 3
    assert stream.breaks == [True, False, False, True, True, False, False]  # gaps both sides
    assert stream.insert(0.5, 9, (0.5, 0.0, 0.0), 0.05) == 7 and stream.breaks[7]


def test_cumulative_turn_of_bat_samples() -> None:
    """A bat turning 0.1 rad per sample about z sums to k * 0.1 about z; a break restarts."""
    stream = Stream('bat')
    for k in range(6):
        angle = 0.1 * k
        stream.append(0.01 * k, k + 1, BatSample((0.0, 0.0, 0.0),
                                                 (math.cos(angle), math.sin(angle), 0.0)),
                      k == 4)
    assert stream.turn(3) == pytest.approx((0.0, 0.0, 0.3, 0.0))
    assert stream.turn(4) == (0.0, 0.0, 0.0, 0.0)
    assert stream.turn(5) == pytest.approx((0.0, 0.0, 0.1, 0.0))


def test_a_removed_bat_samples_turns_after_it_are_summed_again() -> None:
    """
    ``remove`` on a bat: the turns after the sample were summed through it; they are again.

    A frame tipped 0.5 rad out of the swing's plane (a glitch) removed: the turn after it is
    the swing's own 0.4 rad about z, not the sum of the two steps through the glitch.
    """
    stream = Stream('bat')
    for k in range(6):
        angle, lift = 0.1 * k, (0.5 if k == 3 else 0.0)
        stream.append(0.01 * k, k + 1, BatSample((0.0, 0.0, 0.0), (
            math.cos(angle) * math.cos(lift), math.sin(angle) * math.cos(lift),
            math.sin(lift))), k == 0)
    through = stream.turn(5)
    assert math.dist(through[:3], (0.0, 0.0, 0.5)) > 1e-3
    stream.remove(3)
    assert stream.turns[3:] == [None, None]
    assert stream.turn(3) == pytest.approx((0.0, 0.0, 0.4, 0.0))
    assert stream.turn(4) == pytest.approx((0.0, 0.0, 0.5, 0.0))


def test_trim_beside_a_silent_stream_keeps_own_history() -> None:
    """Beside a live stream: behind the cursor; beside a silent or empty one: own newest."""
    times = [0.001 * i for i in range(3000)]
    live = _filled(times)
    live.trim_beside(_filled([2.99, 2.999]), 1.0, 0.1)
    assert live.times[0] == pytest.approx(0.895, abs=0.002)  # the cursor's history
    alone = _filled(times)
    alone.trim_beside(_filled([0.0, 0.01]), 0.01, 0.1)  # silent since 10 ms
    assert alone.times[0] == pytest.approx(2.895, abs=0.002)
    empty = _filled(times)
    empty.trim_beside(Stream('bat'), None, 0.1)
    assert empty.times[0] == pytest.approx(2.895, abs=0.002)
    assert empty.times[-1] == 2.999


@settings(max_examples=examples(200), deadline=None)
@given(steps=st.lists(st.floats(1e-3, 0.05), min_size=1, max_size=90),
       breaks=st.sets(st.integers(1, 89), max_size=4), t=st.floats(-0.1, 3.0),
       window=st.floats(0.0, 2.0))
def test_history_is_the_segment_window_rule(steps: List[float], breaks: Set[int], t: float,
                                            window: float) -> None:
    """Sample by sample: the samples at or before t, in its segment, ``window`` back, 2-64."""
    stream = Stream('ball')
    times = np.concatenate(([0.0], np.cumsum(steps))).tolist()
    for i, time in enumerate(times):
        stream.append(time, i, (0.0, 0.0, 0.0), i == 0 or i in breaks)
    k = max((i for i, time in enumerate(times) if time <= t), default=-1)
    if k < 0:
        assert list(stream.history(t, window)) == []
        return
    start = max(i for i in range(k + 1) if i == 0 or i in breaks)
    inside = [i for i in range(start, k + 1) if times[i] > times[k] - window - 1e-9][
        -MAX_HISTORY:]
    if len(inside) < 2 and k > start:  # at least the last two of the segment
        inside = [k - 1, k]
    assert list(stream.history(t, window)) == inside


def _python_sums(turns: List[Optional[Tuple[float, ...]]], k: int, first_kept: int,
                 step: Callable[[int], Tuple[Tuple[float, float, float], float]]
                 ) -> Tuple[float, ...]:
    """
    Fill ``turns[k]`` and the missing turns before it as plain Python sums them (the reference).

    The steps (``step(i)``: the turn from sample i - 1 to i) from the last known turn at or
    before k, in order; where none is known from ``first_kept`` on, ``turns[first_kept]`` is
    the zero reference.
    """
    first = k
    while turns[first] is None:
        if first == first_kept:
            turns[first] = (0.0, 0.0, 0.0, 0.0)
            break
        first -= 1
    for i in range(first + 1, k + 1):
        swing, roll = step(i)
        last = turns[i - 1]
        turns[i] = (last[0] + swing[0], last[1] + swing[1], last[2] + swing[2],
                    last[3] + roll)
    return turns[k]


@settings(max_examples=examples(60), deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(1, 80), posed=st.booleans(),
       breaks=st.sets(st.integers(1, 79), max_size=4), known=st.sets(st.integers(0, 79),
                                                                     max_size=5),
       first_kept=st.integers(0, 79), asks=st.lists(st.integers(0, 79), min_size=1,
                                                    max_size=6))
def test_the_kernels_turns_are_the_python_sums(seed: int, n: int, posed: bool,
                                               breaks: Set[int], known: Set[int],
                                               first_kept: int, asks: List[int]) -> None:
    """
    ``Stream.turn`` (the kernel's ``fill_turns``) fills the turns as plain Python sums them.

    Random poses (or knob-tip samples), segment starts and turns already known anywhere; the
    same tuples, to the bit, whichever samples are asked for in whatever order, and with a
    zero reference where none is known from ``first_kept`` on.
    """
    from baseball_collision.core.motion import turn_between
    from baseball_collision.core.toi import _kernel
    rng = np.random.default_rng(seed)
    stream = Stream('bat')
    for i in range(n):
        knob = tuple(rng.normal(size=3).tolist())
        tip = tuple((np.asarray(knob) + rng.normal(size=3)).tolist())
        q = rng.normal(size=4)
        quaternion = tuple((q / np.linalg.norm(q)).tolist()) if posed else None
        stream.append(0.01 * i, i, BatSample(knob, tip, knob if posed else None,
                                             quaternion), i in breaks)
    for i in known:
        if i < n:
            stream.turns[i] = tuple(rng.normal(size=4).tolist())
    mine, theirs = list(stream.turns), list(stream.turns)
    values = stream.values
    for k in asks:
        if k < n:
            start = min(first_kept, k)
            assert _kernel.fill_turns(values, mine, start, k) == _python_sums(
                theirs, k, start, lambda i: turn_between(values[i - 1], values[i]))
            assert mine == theirs
    with pytest.raises(IndexError):
        _kernel.fill_turns(values, mine, 0, n)
    with pytest.raises(TypeError):
        _kernel.fill_turns(tuple(values), mine, 0, 0)


def test_a_reversed_excerpt_runs_the_samples_backwards() -> None:
    """Samples last..first, the latest first, times and stamps negated, one segment."""
    stream = Stream('ball')
    for i in range(6):
        stream.append(0.01 * i, 1_000 * i, (float(i), 0.0, 0.0), i == 3)
    backwards = reversed_excerpt(stream, 1, 4)
    assert backwards.times == [-0.04, -0.03, -0.02, -0.01]
    assert backwards.stamps == [-4_000, -3_000, -2_000, -1_000]
    assert [value[0] for value in backwards.values] == [4.0, 3.0, 2.0, 1.0]
    assert backwards.breaks == [True, False, False, False]
    assert stream.times[1:5] == [0.01, 0.02, 0.03, 0.04]  # (the stream as it was)
