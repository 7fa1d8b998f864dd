"""
Tests for baseball_collision.core.detector.plans: a chunk's plan computed on arrays.

Its array steps against the scalar code they stand for: the poses' knob and tip points
(``geometry.pose_point``, to the bit) and the trims after each step (``Stream.trim``). The plan
as a whole is tested by feeding chunks (test_chunks.py): the same as one sample at a time.
"""

from typing import List, Tuple

from baseball_collision.core.detector import DetectorConfig
from baseball_collision.core.detector.plans import (
    _closed, _continuous, _first_reaching, _next_greater, _order_checks, _pose_points, _trims,
    _value_checks, Items, SLACK, TRIM_FROM, TRIM_KEEP)
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.geometry import pose_point
from baseball_collision.core.toi import _kernel
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples

FINITE = st.floats(-10.0, 10.0, allow_nan=False)


@settings(max_examples=examples(200), deadline=None)
@given(jumps=st.lists(st.integers(1, 6), min_size=0, max_size=40), start=st.integers(0, 45))
def test_chain_marks_walks_the_chain(jumps: List[int], start: int) -> None:
    """The kernel's ``chain_marks`` marks start, following[start], ... below n, as a walk."""
    n = len(jumps)
    following = np.arange(n, dtype=np.int64) + np.array(jumps, dtype=np.int64)
    expected = np.zeros(n, bool)
    j = start
    while j < n:
        expected[j] = True
        j = int(following[j])
    marks = np.zeros(n, bool)
    _kernel.chain_marks(following, start, marks)
    assert np.array_equal(marks, expected)


def test_chain_marks_refuses_what_would_not_end_or_is_not_its_arrays() -> None:
    """An entry not after its index, or buffers of other types or sizes: ValueError."""
    marks = np.zeros(3, bool)
    with pytest.raises(ValueError, match='not after its index'):
        _kernel.chain_marks(np.array([1, 1, 3], np.int64), 0, marks)
    for following, out in ((np.array([1, 2, 3], np.int32), marks),
                           (np.array([1, 2, 3], np.int64), np.zeros(3, np.int64)),
                           (np.array([1, 2], np.int64), marks)):
        with pytest.raises(ValueError, match='int64'):
            _kernel.chain_marks(following, 0, out)


@settings(max_examples=examples(200), deadline=None)
@given(rows=st.lists(st.tuples(*[FINITE] * 7), min_size=1, max_size=20),
       offset=st.tuples(*[FINITE] * 3))
def test_pose_points_are_pose_point_to_the_bit(rows: List[Tuple[float, ...]],
                                               offset: Tuple[float, float, float]) -> None:
    """``_pose_points`` over rows gives ``pose_point`` of each row, bit for bit."""
    values = np.array(rows)
    quaternion = values[:, 3:]
    magnitude = np.sqrt((quaternion * quaternion).sum(1))
    quaternion = quaternion / np.where(magnitude > 0.0, magnitude, 1.0)[:, None]
    points = _pose_points(values[:, :3], quaternion, offset)
    for row, position, q in zip(points.tolist(), values[:, :3].tolist(), quaternion.tolist()):
        assert tuple(row) == pose_point(tuple(position), tuple(q), offset)


@settings(max_examples=examples(200), deadline=None)
@given(steps=st.lists(st.tuples(st.integers(0, 3), st.floats(0.0, 0.02)), min_size=1,
                      max_size=300))
def test_trims_are_the_stream_trim_after_each_step(steps: List[Tuple[int, float]]) -> None:
    """
    ``_trims``: each step's first kept sample and length before its trim, as ``Stream.trim``.

    A stream gets some samples per step, 1 ms apart, then is trimmed before a cursor that
    moves on by a random amount (behind its newest sample), with no history window.
    """
    stream = Stream('ball')
    counts, cuts, starts, lengths = [], [], [], []
    total, cursor = 0, 0.0
    for added, advance in steps:
        for _ in range(added):
            stream.append(total * 1e-3, total + 1, (0.0, 0.0, 0.0), False)
            total += 1
        cursor = min(cursor + advance, (total - 1) * 1e-3) if total else 0.0
        counts.append(total)
        times = np.arange(total) * 1e-3
        cuts.append(int(np.searchsorted(times, cursor, 'right')) - TRIM_KEEP)
        lengths.append(len(stream.times))
        if total:
            stream.trim(cursor, 0.0)
        starts.append(total - len(stream.times))
    after, before = _trims(np.array(counts), np.array(cuts))
    assert after.tolist() == starts
    assert before.tolist() == lengths


def _trimmed_one_at_a_time(counts: List[int], cuts: List[int]) -> Tuple[List[int], List[int]]:
    """After each sample: a stream of TRIM_FROM or more drops what is before a later cut."""
    start, after, lengths = 0, [], []
    for count, cut in zip(counts, cuts):
        lengths.append(count - start)
        if count - start >= TRIM_FROM and cut > start:
            start = cut
        after.append(start)
    return after, lengths


@settings(max_examples=examples(300), deadline=None)
@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 40)), min_size=1, max_size=600),
       st.integers(0, 200), st.integers(0, 2 * TRIM_FROM))
def test_trims_are_the_rule_applied_sample_by_sample(
        steps: List[Tuple[int, int]], first: int, lag: int) -> None:
    """
    ``_trims`` against the trim rule applied sample by sample.

    Histories shorter and longer than ``TRIM_FROM`` (then every sample trims), so a stream's
    length reaches ``TRIM_FROM`` exactly.
    """
    counts = np.cumsum([step for step, _ in steps]) + first
    cuts = np.maximum.accumulate(counts - lag - np.array([jitter for _, jitter in steps]))
    after, lengths = _trims(counts, cuts)
    expected_after, expected_lengths = _trimmed_one_at_a_time(counts.tolist(), cuts.tolist())
    assert after.tolist() == expected_after
    assert lengths.tolist() == expected_lengths


@settings(max_examples=examples(200), deadline=None)
@given(st.lists(st.integers(0, 3), max_size=300), st.integers(-5, 5))
def test_next_greater_is_the_search_for_one_more(steps: List[int], first: int) -> None:
    """``_next_greater`` of nondecreasing integers: ``searchsorted(values, values + 1)``."""
    values = np.cumsum(np.array(steps, dtype=np.int64)) + first
    assert _next_greater(values).tolist() == np.searchsorted(values, values + 1, 'left').tolist()


SPECIAL = st.sampled_from([0.0, -0.0, 1.0, 0.5, 1.0005, 0.9995, np.nan, np.inf, -np.inf])


@settings(max_examples=examples(200), deadline=None)
@given(st.lists(st.tuples(st.booleans(), st.lists(st.one_of(FINITE, SPECIAL), min_size=7,
                                                  max_size=7)), min_size=1, max_size=40),
       st.booleans())
def test_value_checks_are_the_row_reductions(rows: List[Tuple[bool, List[float]]],
                                             unit: bool) -> None:
    """
    ``_value_checks`` on columns in turn: the row reductions it stands for, sample by sample.

    Points and poses with NaN, infinities, zeros and quaternions at the tolerance's edges.
    """
    values = np.array([v for _, v in rows])
    if unit:  # quaternions near unit length, where the magnitude's last bit can matter
        q = values[:, 3:7]
        values[:, 3:7] = q / np.where(np.isfinite(q).all(1) & ((q * q).sum(1) > 0),
                                      np.sqrt((q * q).sum(1)), 1.0)[:, None]
    is_ball = np.array([ball for ball, _ in rows])
    ok = _value_checks(DetectorConfig(), values, is_ball, ~is_ball)
    finite = np.isfinite(values)
    q = values[:, 3:7]
    with np.errstate(all='ignore'):
        pose = (~is_ball & finite.all(1)
                & (np.abs(np.sqrt((q * q).sum(1)) - 1.0) < 1e-3 * (1.0 - SLACK))
                & ~(values[:, :3] == 0.0).all(1))
    assert ok.tolist() == ((is_ball & finite[:, :3].all(1)) | pose).tolist()


def test_order_checks_need_three_kept_samples() -> None:
    """``_order_checks`` compares each new sample with the three before: fewer is an error."""
    stamps = np.arange(1, 6, dtype=np.int64) * 10_000_000
    times = stamps * 1e-9
    with pytest.raises(ValueError, match='3 kept samples'):
        _order_checks(DetectorConfig(), stamps, times, [np.zeros((5, 3))], 2)
    ok, gap = _order_checks(DetectorConfig(), stamps, times, [np.zeros((5, 3))], 3)
    assert ok.tolist() == [True, True] and gap.tolist() == [False, False]


@settings(max_examples=examples(200), deadline=None)
@given(st.lists(st.integers(0, 2), max_size=200), st.integers(-5, 5),
       st.lists(st.integers(-10, 250), max_size=60))
def test_first_reaching_is_the_search(steps: List[int], first: int, targets: List[int]) -> None:
    """``_first_reaching``: ``searchsorted(counts, targets)``, counts rising by one or more."""
    counts = np.cumsum(np.array(steps, dtype=np.int64)) + first
    wanted = np.array(targets, dtype=np.int64)
    assert _first_reaching(counts, wanted).tolist() == np.searchsorted(
        counts, wanted, 'left').tolist()


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


@pytest.mark.parametrize('values', [[3, -1, 2**40], [0.5, -0.0, 1e300], [True, False], []])
def test_items_read_as_the_list(values: list) -> None:
    """``Items``: each value as ``tolist()`` gives it (the same type), negative j, the length."""
    array = np.array(values)
    items = Items(array)
    listed = array.tolist()
    assert len(items) == len(listed)
    assert [(items[j], type(items[j])) for j in range(len(listed))] == [
        (v, type(v)) for v in listed]
    if listed:
        assert items[-1] == listed[-1] and type(items[-1]) is type(listed[-1])
    with pytest.raises(IndexError):
        items[len(listed)]
