"""The not-a-knot slopes (``motion.splines``): the system solved; a cubic reproduced."""

from typing import List

from baseball_collision.core.motion import not_a_knot_slopes
from hypothesis import given, settings, strategies as st
import numpy as np
from support import examples


def _system(times: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Return the slopes by LAPACK on the dense not-a-knot system (the independent reference)."""
    n = len(times)
    h = np.diff(times)
    d = np.diff(values, axis=0) / h[:, None]
    matrix, rhs = np.zeros((n, n)), np.zeros_like(values)
    for i in range(1, n - 1):
        matrix[i, i - 1:i + 2] = h[i], 2.0 * (h[i - 1] + h[i]), h[i - 1]
        rhs[i] = 3.0 * (h[i] * d[i - 1] + h[i - 1] * d[i])
    matrix[0, :2] = h[1], h[0] + h[1]
    rhs[0] = ((h[0] + 2.0 * (h[0] + h[1])) * h[1] * d[0] + h[0] ** 2 * d[1]) / (h[0] + h[1])
    matrix[-1, -2:] = h[-1] + h[-2], h[-2]
    rhs[-1] = (h[-1] ** 2 * d[-2] + (2.0 * (h[-2] + h[-1]) + h[-1]) * h[-2] * d[-1]) / (
        h[-2] + h[-1])
    return np.linalg.solve(matrix, rhs)


@settings(max_examples=examples(200), deadline=None)
@given(steps=st.lists(st.floats(1.0, 3.0), min_size=3, max_size=31),
       scale=st.floats(1e-4, 1e-1), columns=st.integers(1, 7), seed=st.integers(0, 2**32 - 1))
def test_slopes_solve_the_not_a_knot_system(steps: List[float], scale: float, columns: int,
                                            seed: int) -> None:
    """The tridiagonal solve gives LAPACK's dense solution to rounding, on uneven steps."""
    times = 5.0 + np.concatenate(([0.0], np.cumsum(steps))) * scale
    values = np.random.default_rng(seed).normal(size=(len(times), columns))
    expected = _system(times, values)
    assert np.allclose(not_a_knot_slopes(times, values), expected, rtol=1e-10,
                       atol=1e-10 * np.abs(expected).max())


@settings(max_examples=examples(100), deadline=None)
@given(steps=st.lists(st.floats(0.5, 2.0), min_size=3, max_size=20),
       coefficients=st.lists(st.floats(-5.0, 5.0), min_size=4, max_size=4))
def test_a_cubic_is_reproduced_exactly(steps: List[float], coefficients: List[float]) -> None:
    """Not-a-knot reproduces any cubic: its slopes are the cubic's derivative at the knots."""
    times = np.concatenate(([0.0], np.cumsum(steps))) * 0.01
    a, b, c, d = coefficients
    values = (a + b * times + c * times ** 2 + d * times ** 3)[:, None]
    slopes = not_a_knot_slopes(times, values)[:, 0]
    assert np.allclose(slopes, b + 2 * c * times + 3 * d * times ** 2, rtol=1e-7, atol=1e-7)


def _quintic_reference(times: np.ndarray, values: np.ndarray,
                       at: np.ndarray) -> List[np.ndarray]:
    """
    Return the not-a-knot quintic's value, slope and second derivative at ``at`` (dense).

    The independent reference: the spline in the truncated power basis (the quintic in
    t - t[0], plus (t - knot)_+^5 per interior knot, the stamps t[3] .. t[n - 4]), its n
    coefficients from the n interpolation conditions by LAPACK; no B-splines.
    """
    origin, knots = times[0], times[3:-3]

    def basis(t: np.ndarray, derivative: int) -> np.ndarray:
        columns = []
        for power in range(6):
            factor = np.prod(np.arange(power, power - derivative, -1)) if derivative else 1.0
            columns.append(factor * (t - origin) ** max(power - derivative, 0)
                           if power >= derivative else np.zeros_like(t))
        factor = np.prod(np.arange(5, 5 - derivative, -1)) if derivative else 1.0
        for knot in knots:
            columns.append(factor * np.maximum(t - knot, 0.0) ** (5 - derivative))
        return np.stack(columns, axis=1)
    coefficients = np.linalg.solve(basis(times, 0), values)
    return [basis(at, derivative) @ coefficients for derivative in range(3)]


@settings(max_examples=examples(200), deadline=None)
@given(steps=st.lists(st.floats(1.0, 2.0), min_size=5, max_size=15),
       scale=st.floats(1e-3, 1e-1), columns=st.integers(1, 7), seed=st.integers(0, 2**32 - 1),
       start=st.integers(0, 20))
def test_the_quintic_is_the_dense_not_a_knot_quintic(steps: List[float], scale: float,
                                                     columns: int, seed: int,
                                                     start: int) -> None:
    """The collocation's slopes and second derivatives are the power basis' dense solution's."""
    from baseball_collision.core.motion.splines import not_a_knot_quintic_rows
    times = np.concatenate(([0.0], np.cumsum(steps))) * scale
    start = min(start, len(times) - 1)
    values = np.random.default_rng(seed).normal(size=(len(times), columns))
    _, slopes, seconds = _quintic_reference(times, values, times[start:])
    found_slopes, found_seconds = (np.array(rows) for rows in not_a_knot_quintic_rows(
        times, values, start))
    assert found_slopes.shape == found_seconds.shape == (len(times) - start, columns)
    assert np.allclose(found_slopes, slopes, rtol=1e-7, atol=1e-7 * np.abs(slopes).max())
    assert np.allclose(found_seconds, seconds, rtol=1e-7, atol=1e-7 * np.abs(seconds).max())
    # lists in, the same numbers as the arrays' (read as they lie)
    rows = not_a_knot_quintic_rows(times.tolist(), values.tolist(), start)
    assert [list(map(list, part)) for part in rows] == [part.tolist() for part in (
        found_slopes, found_seconds)]


@settings(max_examples=examples(100), deadline=None)
@given(steps=st.lists(st.floats(1.0, 2.0), min_size=5, max_size=12),
       coefficients=st.lists(st.floats(-2.0, 2.0), min_size=6, max_size=6))
def test_a_quintic_is_reproduced_exactly(steps: List[float], coefficients: List[float]) -> None:
    """A quintic polynomial's samples give back its own slopes and second derivatives."""
    from baseball_collision.core.motion.splines import not_a_knot_quintic_rows
    times = np.concatenate(([0.0], np.cumsum(steps))) / 10.0
    values = np.polyval(coefficients, times)[:, None]
    slopes, seconds = not_a_knot_quintic_rows(times, values, 0)
    assert np.allclose(np.array(slopes)[:, 0], np.polyval(np.polyder(coefficients), times),
                       atol=1e-9)
    assert np.allclose(np.array(seconds)[:, 0], np.polyval(np.polyder(coefficients, 2), times),
                       atol=1e-8)


def test_the_quintic_refuses_too_few_samples_and_bad_starts() -> None:
    """Fewer than six samples, a start outside them, rows of other lengths: ValueError."""
    import pytest
    from baseball_collision.core.motion.splines import not_a_knot_quintic_rows
    times = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]
    with pytest.raises(ValueError):
        not_a_knot_quintic_rows(times[:5], [[0.0]] * 5)
    with pytest.raises(ValueError):
        not_a_knot_quintic_rows(times, [[0.0]] * 6, 6)
    with pytest.raises(ValueError):
        not_a_knot_quintic_rows(times, [[0.0]] * 5 + [[0.0, 1.0]])


def test_the_quintic_window_rule() -> None:
    """Six samples or more, one after the interval, steps within the ratio: else the cubic."""
    from baseball_collision.core.motion.splines import QUINTIC_STEP_RATIO, quintic_window
    even = [0.01 * i for i in range(8)]
    assert quintic_window(even, 5) and not quintic_window(even, 6)
    assert not quintic_window(even[:5], 2)
    uneven = even[:-1] + [even[-2] + 0.01 * (QUINTIC_STEP_RATIO + 0.01)]
    assert not quintic_window(uneven, 3)
    assert quintic_window(even[:-1] + [even[-2] + 0.0099 * QUINTIC_STEP_RATIO], 3)


def test_the_quintic_window_rule_holds_the_ratio_itself_whatever_the_rounding() -> None:
    """
    Steps of 2 and 4 ms on a millisecond grid are within the factor 2, however they round.

    Integer-nanosecond stamps 4.001 s on, in seconds: the 4 ms step comes out a rounding
    above twice a 2 ms one (0.004000000000000448 against 0.0019999999999997797), which the
    plain comparison refused; a step 2e-5 longer than the factor is still refused.
    """
    from baseball_collision.core.motion.splines import quintic_window
    grid_ms = (4001, 4003, 4007, 4009, 4012, 4014, 4017, 4020)
    times = [ms * 1_000_000 * 1e-9 for ms in grid_ms]
    steps = [b - a for a, b in zip(times, times[1:])]
    assert max(steps) > 2.0 * min(steps)  # the rounding this test is about
    assert quintic_window(times, 4)
    longer = times[:2] + [t + 2e-8 for t in times[2:]]  # the 4 ms step 20 ns longer
    assert not quintic_window(longer, 4)
