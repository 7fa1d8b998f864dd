"""
Tests for baseball_collision.core.detector.plan_far: which intervals of a plan are far.

The stream rule on arrays (``Stream.continuous``), the samples whose walk visits an interval
against the scan they stand for, the kernel's search of ascending keys against numpy's. The
far tests themselves against the scalar ones (``apart_margins``, ``clearly_apart``) and the
plan as a whole (the same events as one sample at a time): test_chunks.py.
"""

from typing import List, Tuple

from baseball_collision.core.detector.plan_far import (
    _closed, _continuous, _visiting, search_right)
from baseball_collision.core.toi import _kernel
from hypothesis import given, settings, strategies as st
import numpy as np
from support import examples


@settings(max_examples=examples(200), deadline=None)
@given(st.lists(st.tuples(st.floats(0.0, 0.05), st.booleans()), min_size=1, max_size=60),
       st.lists(st.integers(-3, 64), max_size=40), st.floats(0.0, 0.05))
def test_continuous_is_the_stream_rule(samples: List[Tuple[float, bool]], ks: List[int],
                                       max_gap: float) -> None:
    """``_continuous`` from ``_closed``: k and k + 1 in range, no break at k + 1, a short step."""
    times = np.cumsum([step for step, _ in samples])
    breaks = np.array([cut for _, cut in samples])
    k = np.array(ks, dtype=np.int64)
    got = _continuous(_closed(times, breaks, max_gap), k).tolist()
    assert got == [0 <= j and j + 1 < len(times) and not breaks[j + 1]
                   and bool(times[j + 1] - times[j] <= max_gap) for j in ks]


@settings(max_examples=examples(200), deadline=None)
@given(steps=st.lists(st.integers(0, 3), min_size=1, max_size=40),
       marks=st.lists(st.integers(0, 50), max_size=20))
def test_visiting_is_the_first_sample_past_each_interval(steps: List[int],
                                                         marks: List[int]) -> None:
    """
    ``_visiting``: for each interval m, the first sample whose walk reaches past it, if any.

    ``visited``: how many union times the cursor has reached after each sample (from 1, not
    decreasing); interval m ends at the m-th union time after the cursor's.
    """
    visited = 1 + np.cumsum(steps)
    intervals = np.array(sorted(marks), dtype=np.int64)
    n = len(visited)
    wanted = [next(j for j in range(n) if visited[j] > m) for m in intervals.tolist()
              if visited[-1] > m]
    assert _visiting(visited, intervals, n).tolist() == wanted
    assert _visiting(visited, intervals, n - 1).tolist() == [j for j in wanted if j < n - 1]


@settings(max_examples=examples(200), deadline=None)
@given(array=st.lists(st.floats(-3.0, 3.0), max_size=40),
       keys=st.lists(st.floats(-4.0, 4.0), max_size=40))
def test_search_right_is_numpys_searchsorted(array: List[float], keys: List[float]) -> None:
    """``search_right`` for ascending times and keys: ``np.searchsorted`` right, as int64."""
    times, wanted = np.sort(np.array(array, dtype=float)), np.sort(np.array(keys, dtype=float))
    found = search_right(times, wanted)
    assert found.dtype == np.int64
    assert found.tolist() == np.searchsorted(times, wanted, 'right').tolist()


@settings(max_examples=examples(300), deadline=None)
@given(array=st.lists(st.one_of(st.floats(-3.0, 3.0), st.sampled_from(
    [0.0, 1.0, np.inf, -np.inf, np.nan])), max_size=40),
       keys=st.lists(st.one_of(st.floats(-4.0, 4.0), st.sampled_from(
           [0.0, 1.0, np.inf, -np.inf, np.nan])), max_size=40),
       ascending=st.booleans(), right=st.booleans())
def test_sorted_search_is_numpys_searchsorted(array: List[float], keys: List[float],
                                              ascending: bool, right: bool) -> None:
    """
    The kernel's ``sorted_search``: ``np.searchsorted`` (NaN last), keys ascending or not.

    Equal entries, infinities and NaN in both.
    """
    values = np.sort(np.array(array, dtype=float))
    wanted = np.array(keys, dtype=float)
    if ascending:
        wanted = np.sort(wanted)
    found = np.empty(len(wanted), np.int64)
    _kernel.sorted_search(values, wanted, right, found)
    assert found.tolist() == np.searchsorted(values, wanted, 'right' if right else 'left').tolist()
