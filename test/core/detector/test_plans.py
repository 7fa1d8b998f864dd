"""
Tests for baseball_collision.core.detector.plans: a chunk's plan computed on arrays.

Its array steps against the scalar code they stand for: the chunk's rows (``gate.unit_pose``
and ``geometry.pose_point``, to the bit), the value checks, the trims after each step
(``Stream.trim``). The order checks and held samples: test_plan_order.py; the far tests:
test_plan_far.py; the forecasts' windows: test_plan_prediction.py. The plan as a whole is
tested by feeding chunks (test_chunks.py): the same as one sample at a time.
"""

import math
from typing import List, Tuple

from baseball_collision.core.detector.gate import FAR_AHEAD_NS, unit_pose
from baseball_collision.core.detector.plans import (
    _trims, BALL, BAT_POSE, items, SLACK, TRIM_FROM, TRIM_KEEP)
from baseball_collision.core.detector.streams import Stream, TRIM_LEAVES
from baseball_collision.core.geometry import pose_point
from baseball_collision.core.toi import _kernel
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples

FINITE = st.floats(-10.0, 10.0, allow_nan=False)


def test_trims_refuses_what_is_not_its_arrays() -> None:
    """The kernel's ``trims``: buffers of other types or sizes, read-only outputs: errors."""
    counts = np.arange(3, dtype=np.int64)
    out = np.zeros(3, np.int64)
    for arguments in ((counts.astype(np.int32), counts, out, out),
                      (counts, counts[:2], out, out), (counts, counts, np.zeros(3), out)):
        with pytest.raises(ValueError):
            _kernel.trims(arguments[0], arguments[1], TRIM_FROM, *arguments[2:])
    frozen = np.zeros(3, np.int64)
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match='read-only'):
        _kernel.trims(counts, counts, TRIM_FROM, frozen, out)


@settings(max_examples=examples(200), deadline=None)
@given(steps=st.lists(st.tuples(st.integers(0, 3), st.floats(0.0, 0.02)), min_size=1,
                      max_size=300))
def test_trims_are_the_stream_trim_after_each_step(steps: List[Tuple[int, float]]) -> None:
    """
    ``_trims``: each step's first kept sample and length before its trim, as ``Stream.trim``.

    A stream gets some samples per step, 1 ms apart, then is trimmed before a cursor that
    moves on by a random amount (behind its newest sample), with no history window: where the
    cursor is near the newest sample, the trim's floor (``TRIM_LEAVES``) decides the cut.
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
        # (as ``plans._trim_starts`` makes them: at most TRIM_LEAVES from the newest)
        cuts.append(min(int(np.searchsorted(times, cursor, 'right')) - TRIM_KEEP,
                        total - TRIM_LEAVES))
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


SPECIAL = st.sampled_from([0.0, -0.0, 1.0, 0.5, 1.0005, 0.9995, np.nan, np.inf, -np.inf])


def _plan_rows(roles: np.ndarray, stamps: np.ndarray, values: np.ndarray, origin: int,
               offsets: Tuple[Tuple[float, ...], Tuple[float, ...]], pre: Tuple[int, int]
               ) -> Tuple[np.ndarray, ...]:
    """Return the kernel's ``plan_rows`` outputs for a chunk after ``pre`` kept rows (zeros)."""
    m_ball, m_bat = pre[0] + int((roles == BALL).sum()), pre[1] + int((roles == BAT_POSE).sum())
    outputs = (np.zeros(m_ball), np.zeros(m_ball, np.int64), np.zeros((m_ball, 3)),
               np.zeros(m_bat), np.zeros(m_bat, np.int64), np.zeros((m_bat, 3)),
               np.zeros((m_bat, 3)), np.zeros((m_bat, 3)), np.zeros((m_bat, 4)))
    ok = np.zeros(len(roles), bool)
    _kernel.plan_rows(roles, stamps, values, origin, (BALL, BAT_POSE), offsets,
                      (1e-3 * (1.0 - SLACK), FAR_AHEAD_NS), *outputs, pre, ok)
    return (*outputs, ok)


@settings(max_examples=examples(200), deadline=None)
@given(rows=st.lists(st.tuples(st.integers(0, 3), st.integers(-2, 3 * 10 ** 15),
                               st.lists(st.one_of(FINITE, SPECIAL), min_size=7, max_size=7)),
                     min_size=1, max_size=40),
       offsets=st.tuples(st.tuples(*[FINITE] * 3), st.tuples(*[FINITE] * 3)),
       pre=st.tuples(st.integers(0, 3), st.integers(0, 3)), unit=st.booleans(),
       origin=st.integers(0, 10 ** 15))
def test_plan_rows_are_the_per_sample_path_to_the_bit(rows: List[Tuple[int, int, List[float]]],
                                                      offsets, pre: Tuple[int, int],
                                                      unit: bool, origin: int) -> None:
    """
    ``plan_rows``: each sample's row as the per-sample path makes it, bit for bit, and checks.

    Times ``(stamp - origin) * 1e-9``; a pose's quaternion as ``gate.unit_pose`` makes it unit,
    its knob and tip ``geometry.pose_point``. The value checks are the row reductions they
    stand for, with room to spare (NaN, infinities, zeros, quaternions at the tolerance's
    edges), and the stamp after 0 and at most ``FAR_AHEAD_NS`` after the origin.
    """
    roles = np.array([role for role, _, _ in rows], np.int8)
    stamps = np.array([stamp for _, stamp, _ in rows], np.int64)
    values = np.array([v for _, _, v in rows])
    if unit:  # quaternions near unit length, where the magnitude's last bit can matter
        q = values[:, 3:7]
        with np.errstate(all='ignore'):
            values[:, 3:7] = q / np.where(np.isfinite(q).all(1) & ((q * q).sum(1) > 0),
                                          np.sqrt((q * q).sum(1)), 1.0)[:, None]
    (ball_times, ball_stamps, ball, bat_times, bat_stamps, knobs, tips, positions, quaternions,
     ok) = _plan_rows(roles, stamps, values, origin, offsets, pre)
    b, t = pre
    for role, stamp, row, passes in zip(roles.tolist(), stamps.tolist(), values.tolist(),
                                        ok.tolist()):
        time = (stamp - origin) * 1e-9
        finite = [x * 0.0 == 0.0 for x in row]
        in_time = stamp > 0 and stamp - origin <= FAR_AHEAD_NS
        if role == BALL:
            assert (ball_times[b], ball_stamps[b]) == (time, stamp)
            assert ball[b].tobytes() == np.array(row[:3]).tobytes()
            assert passes == (all(finite[:3]) and in_time)
            b += 1
        elif role == BAT_POSE:
            assert (bat_times[t], bat_stamps[t]) == (time, stamp)
            assert positions[t].tobytes() == np.array(row[:3]).tobytes()
            magnitude = math.sqrt(sum(x * x for x in row[3:]) if all(finite) else math.nan)
            pose = unit_pose((row[:3], row[3:]))
            if isinstance(pose, tuple):
                position, quaternion = pose
                assert tuple(quaternions[t].tolist()) == quaternion
                assert tuple(knobs[t].tolist()) == pose_point(position, quaternion, offsets[0])
                assert tuple(tips[t].tolist()) == pose_point(position, quaternion, offsets[1])
            assert passes == (all(finite) and abs(magnitude - 1.0) < 1e-3 * (1.0 - SLACK)
                              and row[:3] != [0.0, 0.0, 0.0] and in_time)
            t += 1
        else:
            assert not passes
    assert (b, t) == (len(ball_times), len(bat_times))


def test_plan_rows_refuses_outputs_that_do_not_hold_the_chunk() -> None:
    """Outputs of another length than the kept rows and the chunk's, roles not int8: errors."""
    roles = np.array([BALL, BAT_POSE, BAT_POSE], np.int8)
    stamps = np.array([1, 2, 3], np.int64)
    values = np.tile([0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], (3, 1))
    with pytest.raises(ValueError, match='do not hold'):
        _kernel.plan_rows(roles, stamps, values, 0, (BALL, BAT_POSE), ((0, 0, 0), (1, 0, 0)),
                          (1e-3, 10), np.zeros(1), np.zeros(1, np.int64), np.zeros((1, 3)),
                          np.zeros(1), np.zeros(1, np.int64), np.zeros((1, 3)),
                          np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 4)), (0, 0),
                          np.zeros(3, bool))
    with pytest.raises(ValueError, match='roles'):
        _plan_rows(roles.astype(np.int64), stamps, values, 0, ((0.0, 0.0, 0.0),) * 2, (0, 0))


@pytest.mark.parametrize('values', [[3, -1, 2**40], [0.5, -0.0, 1e300], [True, False], []])
def test_items_read_as_the_list(values: list) -> None:
    """``items``: each value as ``tolist()`` gives it (the same type), negative j, the length."""
    array = np.array(values)
    read = items(array)
    listed = array.tolist()
    assert len(read) == len(listed)
    assert [(read[j], type(read[j])) for j in range(len(listed))] == [
        (v, type(v)) for v in listed]
    if listed:
        assert read[-1] == listed[-1] and type(read[-1]) is type(listed[-1])
        assert items(np.array(values)[::-1])[0] == listed[-1]  # (a strided view, made contiguous)
    with pytest.raises(IndexError):
        read[len(listed)]
