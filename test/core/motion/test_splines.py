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
