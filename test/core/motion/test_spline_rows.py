"""The c2 fits' float paths: the same bits as the array forms they stand in for."""

import math

from baseball_collision.core.detector.fitting import chart_swing
from baseball_collision.core.geometry import cross, dot, norm
from baseball_collision.core.motion import BatSample, C2BatPath, rotate, unit_axis
from baseball_collision.core.motion import c2 as c2_model
from baseball_collision.core.motion.splines import (
    end_state, not_a_knot_slope_rows, not_a_knot_slopes)
from baseball_collision.core.toi import _kernel
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples


@settings(max_examples=examples(300), deadline=None)
@given(n=st.integers(2, 34), columns=st.integers(1, 8), seed=st.integers(0, 2**32 - 1),
       identity=st.booleans())
def test_rows_from_any_knot_are_the_slopes(n: int, columns: int, seed: int,
                                           identity: bool) -> None:
    """``not_a_knot_slope_rows(start)`` gives the slopes' rows from ``start``, bit for bit."""
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.001, 0.004, n)).tolist()
    values = np.eye(n) if identity else rng.normal(size=(n, columns)) * 10 ** rng.uniform(-3, 2)
    slopes = not_a_knot_slopes(times, values)
    rows = [tuple(row) for row in values.tolist()]
    for start in {0, max(n - 2, 0), int(rng.integers(0, n))}:
        found = not_a_knot_slope_rows(times, rows, start)
        assert np.array(found).tobytes() == slopes[start:].tobytes()


def _array_end_state(times, values, t):
    """Return ``end_state`` by numpy on the slopes' arrays (its former form)."""
    y = np.asarray(values, dtype=float)
    slopes = not_a_knot_slopes(times, y)
    t0, t1 = float(times[-2]), float(times[-1])
    h = t1 - t0
    s = (t - t0) / h
    m0, m1 = slopes[-2] * h, slopes[-1] * h
    chord = y[-1] - y[-2]
    c = 3.0 * chord - 2.0 * m0 - m1
    d = m0 + m1 - 2.0 * chord
    return y[-2] + s * (m0 + s * (c + s * d)), (m0 + s * (2.0 * c + 3.0 * s * d)) / h


@settings(max_examples=examples(300), deadline=None)
@given(n=st.integers(2, 12), columns=st.integers(1, 7), seed=st.integers(0, 2**32 - 1),
       after=st.floats(-1.0, 1.0))
def test_end_state_on_floats_is_the_array_form(n: int, columns: int, seed: int,
                                               after: float) -> None:
    """The last piece's value and rate at t: the same bits as the array arithmetic."""
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.001, 0.004, n)).tolist()
    values = rng.normal(size=(n, columns)) * 10 ** rng.uniform(-3, 2)
    t = times[-1] + after * (times[-1] - times[-2])
    for found, expected in zip(end_state(times, values, t), _array_end_state(times, values, t)):
        assert found.tobytes() == expected.tobytes()


def _array_chart_swing(reference, turn, turn_rate):
    """Return ``chart_swing`` by numpy on 3-vectors (1e-4 rad along the rate)."""
    speed = np.linalg.norm(turn_rate)
    if speed == 0.0:
        return (0.0, 0.0, 0.0)
    step = 1e-4 / speed
    ahead = np.array(rotate(reference, tuple(turn + step * turn_rate)))
    behind = np.array(rotate(reference, tuple(turn - step * turn_rate)))
    direction = np.array(rotate(reference, tuple(turn)))
    return tuple(np.cross(direction, (ahead - behind) / (2.0 * step)).tolist())


def test_chart_swing_and_rotation_to_are_their_former_forms() -> None:
    """Random charts: ``chart_swing`` and ``rotation_to`` give the numpy forms' bits."""
    rng = np.random.default_rng(8)
    for i in range(3000):
        reference = rng.normal(size=3)
        reference = tuple((reference / np.linalg.norm(reference)).tolist())
        turn = rng.normal(size=3) * rng.uniform(0.0, 2.0) * (i % 11 != 0)
        rate = rng.normal(size=3) * 10 ** rng.uniform(-2, 2) * (i % 7 != 0)
        assert chart_swing(reference, turn, rate) == _array_chart_swing(reference, turn, rate)
        direction = tuple(rotate(reference, tuple(turn.tolist())))
        turned = cross(reference, direction)
        sine = norm(turned)
        expected = (0.0, 0.0, 0.0) if sine < 1e-15 else tuple(
            x * (math.atan2(sine, dot(reference, direction)) / sine) for x in turned)
        assert c2_model.rotation_to(reference, direction) == expected


def test_kept_axes_and_deviation_are_the_computed_ones() -> None:
    """A sample's kept direction and length, and a path's kept deviation, as computed."""
    rng = np.random.default_rng(9)
    samples = []
    for _ in range(c2_model._AXES_KEPT + 50):  # past the store's size: it starts again
        knob = tuple(rng.normal(size=3).tolist())
        samples.append(BatSample(knob, tuple((np.array(knob) + rng.normal(size=3)).tolist())))
    for sample in samples[:100] + samples[-100:]:
        axis = np.subtract(sample.tip, sample.knob)
        size = norm(tuple(axis.tolist()))
        assert unit_axis(sample) == tuple((axis / size).tolist())
        assert c2_model.axis_and_length(sample)[1] == math.dist(sample.tip, sample.knob)
    for sample, after in zip(samples[:50], samples[1:51]):
        path = C2BatPath(0.0, 0.01, sample, after, ((1.0, 2.0, 3.0), (2.0, 1.0, 0.0)),
                         ((5.0, 1.0, 0.0), (4.0, 2.0, 1.0)), (0.1, -0.2))
        assert path.deviation(0.0, 0.01) == path._deviation(0.0, 0.01)
        assert path.deviation(0.0, 0.005) == path._deviation(0.0, 0.005)


def test_chart_rows_are_each_samples_knob_turn_and_length() -> None:
    """
    The kernel's chart: per sample its knob, ``rotation_to`` from sample j's axis, its length.

    Swings turning up to a radian a frame: a sample before j turned more than
    ``MAX_CHART_ANGLE`` from sample j starts the window after it, one after j + 1 ends it.
    """
    rng = np.random.default_rng(12)
    cut_before = cut_after = 0
    for _ in range(400):
        n = int(rng.integers(2, 14))
        turns = np.cumsum(rng.uniform(0.0, 1.0, n)) + rng.uniform(-3.0, 3.0)
        samples = []
        for angle, lift in zip(turns, rng.uniform(-0.3, 0.3, n)):
            knob = tuple(rng.normal(size=3).tolist())
            axis = (math.cos(angle) * math.cos(lift), math.sin(angle) * math.cos(lift),
                    math.sin(lift))
            length = float(rng.uniform(0.8, 0.9))
            samples.append(BatSample(knob, tuple(k + length * a for k, a in zip(knob, axis))))
        j = int(rng.integers(0, n - 1))
        c2_model._LAST_ROWS[0] = None
        first, rows = c2_model.c2_rows(samples, j)
        reference = unit_axis(samples[j])
        expected, expected_first = [], 0
        for i, sample in enumerate(samples):
            turn = c2_model.rotation_to(reference, unit_axis(sample))
            if norm(turn) > c2_model.MAX_CHART_ANGLE and i < j:
                expected, expected_first = [], i + 1
                continue
            if norm(turn) > c2_model.MAX_CHART_ANGLE and i > j + 1:
                break
            expected.append((*sample.knob, *turn, c2_model.axis_and_length(sample)[1]))
        assert (first, rows) == (expected_first, expected)
        cut_before += first > 0
        cut_after += first + len(rows) < n
    assert cut_before > 20 and cut_after > 20  # both ends' cuts were taken


def test_kernel_not_a_knot_refuses_short_or_uneven_windows() -> None:
    """Fewer than four knots, rows of other lengths, a start outside: ValueError."""
    times = [0.0, 0.01, 0.02, 0.03]
    with pytest.raises(ValueError):
        _kernel.not_a_knot(times[:3], [(1.0,)] * 3, 0)
    with pytest.raises(ValueError):
        _kernel.not_a_knot(times, [(1.0,), (2.0,), (3.0, 4.0), (5.0,)], 0)
    with pytest.raises(ValueError):
        _kernel.not_a_knot(times, [(1.0,)] * 4, 4)
    assert _kernel.not_a_knot(times, [(1.0,), (2.0,), (3.0,), (4.0,)], 2) == [
        (pytest.approx(100.0),), (pytest.approx(100.0),)]


@settings(max_examples=examples(100), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(4, 34), m=st.integers(1, 9),
       start=st.integers(0, 33))
def test_kernel_reads_an_array_as_its_rows(seed: int, n: int, m: int, start: int) -> None:
    """The kernel's ``not_a_knot`` on an array: the same tuples as on its rows, strided too."""
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.001, 0.01, n)).tolist()
    values = rng.normal(size=(n, 2 * m))
    start = min(start, n - 1)
    rows = [tuple(row) for row in values[:, :m].tolist()]
    assert _kernel.not_a_knot(times, np.ascontiguousarray(values[:, :m]), start) == \
        _kernel.not_a_knot(times, rows, start)
    assert _kernel.not_a_knot(times, values[:, :m], start) == _kernel.not_a_knot(times, rows,
                                                                                 start)
