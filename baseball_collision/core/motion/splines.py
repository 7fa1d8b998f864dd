"""
Cubic splines through samples on uneven stamps: the slopes at the knots, numpy only.

A cubic spline is a piecewise cubic Hermite: its values and its slopes at the knots fix it.
``not_a_knot_slopes`` returns the slopes of the C2 interpolating spline whose third
derivative is continuous at the second and the second-to-last knots (not-a-knot), so the end
pieces are as accurate as the inner ones: for a function with a bounded fourth derivative the
error is O(h^4) in value and O(h^3) in slope on every piece, also on uneven stamps (de Boor, A
Practical Guide to Splines, ch. IV). Two samples give the chord, three the parabola.
"""

from typing import Sequence, Tuple

import numpy as np


def not_a_knot_slopes(times: Sequence[float], values: np.ndarray) -> np.ndarray:
    """
    Return the slopes at the knots of the not-a-knot cubic spline through (times, values).

    :param times: (n,) strictly increasing (s), n >= 2.
    :param values: (n, columns): each column is fitted on its own.
    :returns: (n, columns) slopes (value units per second).
    """
    t = np.asarray(times, dtype=float)
    y = np.asarray(values, dtype=float)
    h = np.diff(t)
    d = np.diff(y, axis=0) / h[:, None]
    n = len(t)
    if n == 2:
        return np.vstack([d, d])
    if n == 3:  # the parabola through the three samples
        curvature = (d[1] - d[0]) / (h[0] + h[1])
        return np.vstack([d[0] - curvature * h[0], d[0] + curvature * h[0],
                          d[1] + curvature * h[1]])
    matrix = np.zeros((n, n))
    rhs = np.empty_like(y)
    inner = np.arange(1, n - 1)
    matrix[inner, inner - 1] = h[1:]
    matrix[inner, inner] = 2.0 * (h[:-1] + h[1:])
    matrix[inner, inner + 1] = h[:-1]
    rhs[1:-1] = 3.0 * (h[1:, None] * d[:-1] + h[:-1, None] * d[1:])
    matrix[0, :2] = (h[1], h[0] + h[1])
    rhs[0] = ((h[0] + 2.0 * (h[0] + h[1])) * h[1] * d[0] + h[0] ** 2 * d[1]) / (h[0] + h[1])
    matrix[-1, -2:] = (h[-1] + h[-2], h[-2])
    rhs[-1] = (h[-1] ** 2 * d[-2] + (2.0 * (h[-2] + h[-1]) + h[-1]) * h[-2] * d[-1]) / (
        h[-2] + h[-1])
    return np.linalg.solve(matrix, rhs)


def end_state(times: Sequence[float], values: np.ndarray,
              t: float) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return the values and rates at t of the not-a-knot spline through (times, values).

    From its last piece: for t after the last sample the last cubic is extrapolated, so the
    state at an instant up to a step after the last sample comes from samples up to it only.

    :param times: (n,) strictly increasing (s), n >= 2; ``values``: (n, columns).
    :returns: ((columns,) values, (columns,) rates per second).
    """
    y = np.asarray(values, dtype=float)
    slopes = not_a_knot_slopes(times, y)
    t0, t1 = float(times[-2]), float(times[-1])
    h = t1 - t0
    s = (t - t0) / h
    # the cubic Hermite y0 + m0 s + c s^2 + d s^3 (s in steps) with end slopes m0, m1
    m0, m1 = slopes[-2] * h, slopes[-1] * h
    chord = y[-1] - y[-2]
    c = 3.0 * chord - 2.0 * m0 - m1
    d = m0 + m1 - 2.0 * chord
    return y[-2] + s * (m0 + s * (c + s * d)), (m0 + s * (2.0 * c + 3.0 * s * d)) / h
