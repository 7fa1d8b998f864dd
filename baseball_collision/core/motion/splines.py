"""
Cubic splines through samples on uneven stamps: the slopes at the knots, numpy only.

A cubic spline is a piecewise cubic Hermite: its values and its slopes at the knots fix it.
``not_a_knot_slopes`` returns the slopes of the C2 interpolating spline whose third
derivative is continuous at the second and the second-to-last knots (not-a-knot), so the end
pieces are as accurate as the inner ones: for a function with a bounded fourth derivative the
error is O(h^4) in value and O(h^3) in slope on every piece, also on uneven stamps (de Boor, A
Practical Guide to Splines, ch. IV). Two samples give the chord, three the parabola.
"""

from typing import Iterable, List, Sequence, Tuple, Union

import numpy as np


def not_a_knot_slopes(times: Sequence[float],
                      values: Union[np.ndarray, Sequence[Sequence[float]]]) -> np.ndarray:
    """
    Return the slopes at the knots of the not-a-knot cubic spline through (times, values).

    :param times: (n,) strictly increasing (s), n >= 2.
    :param values: (n, columns) floats, an array or rows (sequences): each column is fitted on
        its own.
    :returns: (n, columns) slopes (value units per second).
    """
    if len(times) <= 3:
        return _short_slopes(np.asarray(times, dtype=float), np.asarray(values, dtype=float))
    return np.array(not_a_knot_slope_rows(times, values))


def not_a_knot_slope_rows(times: Sequence[float],
                          values: Union[np.ndarray, Sequence[Sequence[float]]],
                          start: int = 0) -> List[Tuple[float, ...]]:
    """
    Return ``not_a_knot_slopes`` as rows of floats (one tuple per knot): the same numbers.

    Plain floats (numpy's per-call cost dominates at these sizes): the system's matrix depends
    on the steps only, so it is eliminated once (``_eliminated``, kept for the next call on the
    same stamps: a ball's and a bat's windows of one interval usually share them) and each
    column is solved in turn (``_solve_columns``).

    :param start: the first knot whose slopes are wanted (0 <= start < n): the rows of knots
        ``start`` .. n - 1 are returned; the back-substitution stops there (a window's interval
        is at its end: two rows instead of n).
    """
    if len(times) <= 3:
        return [tuple(row) for row in _short_slopes(
            np.asarray(times, dtype=float), np.asarray(values, dtype=float)).tolist()[start:]]
    key = tuple(times)
    last = _LAST_SYSTEM[0]
    if last is not None and last[0] == key:
        system = last[1]
    else:
        system = _eliminated(key)
        _LAST_SYSTEM[0] = (key, system)
    columns = values.T.tolist() if isinstance(values, np.ndarray) else zip(*values)
    return list(zip(*_solve_columns(system, columns, start)))


_LAST_SYSTEM: list = [None]
"""The last ``_eliminated`` system and its stamps (a tuple): (stamps, system)."""

System = Tuple[List[float], List[float], List[float], List[float], Tuple[float, ...]]
"""The not-a-knot system eliminated (``_eliminated``): steps (s), elimination factors, the
diagonal after elimination, the upper diagonal, and the end rows' coefficients."""


def _eliminated(times: Sequence[float]) -> System:
    """
    Return the not-a-knot system's matrix on these knots, eliminated (Thomas' forward sweep).

    The tridiagonal matrix (row i: ``below``, ``diagonal``, ``above``) depends on the steps
    only. No pivoting: the not-a-knot system's first elimination leaves ``h0 + h1`` on the
    diagonal and the inner rows are diagonally dominant (checked against LAPACK: 1.2e-15
    relative over 3,000 random windows of 4-32 uneven steps).
    """
    n = len(times)
    t = [float(x) for x in times]
    h = [b - a for a, b in zip(t, t[1:])]
    h0, h1, hm, hl = h[0], h[1], h[-2], h[-1]
    # inner row i: below h[i], diagonal 2 (h[i - 1] + h[i]), above h[i - 1]
    diagonal = [h1] + [2.0 * (hb + ha) for hb, ha in zip(h, h[1:])] + [hm]
    above = [h0 + h1] + h[:-1]
    below = [0.0] + h[1:] + [hl + hm]
    factors = [0.0] * n
    for i in range(1, n):
        factor = below[i] / diagonal[i - 1]
        diagonal[i] -= factor * above[i - 1]
        factors[i] = factor
    ends = ((h0 + 2.0 * (h0 + h1)) * h1, h0 ** 2, h0 + h1,
            hl ** 2, (2.0 * (hm + hl) + hl) * hm, hm + hl)
    return h, factors, diagonal, above, ends


def _solve_columns(system: System, columns: Iterable[Sequence[float]],
                   start: int = 0) -> List[List[float]]:
    """
    Return the slopes of each column of values through an ``_eliminated`` system.

    In plain floats, so the slopes are the same bits on every machine: LAPACK's solve, which
    this replaced, rounds as the BLAS kernels a CPU is given (``c2``'s answers moved by 1 ns
    on an AVX-512 machine; with this solve they are the same under either kernel, measured).

    :param columns: each the values (n,) at the knots.
    :param start: the first knot wanted: the slopes of knots ``start`` .. n - 1, per column.
    """
    h, factors, diagonal, above, (first, h0_squared, span0, hl_squared, last, span1) = system
    inner = list(zip(h[1:], h, factors[1:]))
    last_factor, last_pivot = factors[-1], diagonal[-1]
    back = range(len(h) - 1, start - 1, -1)
    solved = []
    for y in columns:
        d = [(b - a) / step for a, b, step in zip(y, y[1:], h)]
        r = (first * d[0] + h0_squared * d[1]) / span0
        # forward: each inner row's right-hand side, less its factor times the row above's
        rhs = [r]
        rhs += [r := 3.0 * (ha * x + hb * z) - f * r for (ha, hb, f), x, z in zip(inner, d, d[1:])]
        s = ((hl_squared * d[-2] + last * d[-1]) / span1 - last_factor * r) / last_pivot
        slopes = [s]  # back from the last knot
        for i in back:
            s = (rhs[i] - above[i] * s) / diagonal[i]
            slopes.append(s)
        slopes.reverse()
        solved.append(slopes)
    return solved


def _short_slopes(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Return the slopes through two samples (the chord) or three (the parabola)."""
    h = np.diff(t)
    d = np.diff(y, axis=0) / h[:, None]
    if len(t) == 2:
        return np.vstack([d, d])
    curvature = (d[1] - d[0]) / (h[0] + h[1])
    return np.vstack([d[0] - curvature * h[0], d[0] + curvature * h[0],
                      d[1] + curvature * h[1]])


def end_state(times: Sequence[float], values: np.ndarray,
              t: float) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return the values and rates at t of the not-a-knot spline through (times, values).

    From its last piece: for t after the last sample the last cubic is extrapolated, so the
    state at an instant up to a step after the last sample comes from samples up to it only.

    :param times: (n,) strictly increasing (s), n >= 2; ``values``: (n, columns).
    :returns: ((columns,) values, (columns,) rates per second).
    """
    rows = values.tolist() if isinstance(values, np.ndarray) else values
    start = len(times) - 2
    m0_rows, m1_rows = not_a_knot_slope_rows(times, rows, start)
    t0, t1 = float(times[-2]), float(times[-1])
    h = t1 - t0
    s = (t - t0) / h
    at, rates = [], []
    # per column, the cubic Hermite y0 + m0 s + c s^2 + d s^3 (s in steps) with end slopes
    # m0, m1 (plain floats: the same operations as on the arrays of the columns)
    for y0, y1, slope0, slope1 in zip(rows[-2], rows[-1], m0_rows, m1_rows):
        y0, y1 = float(y0), float(y1)
        m0, m1 = slope0 * h, slope1 * h
        chord = y1 - y0
        c = 3.0 * chord - 2.0 * m0 - m1
        d = m0 + m1 - 2.0 * chord
        at.append(y0 + s * (m0 + s * (c + s * d)))
        rates.append((m0 + s * (2.0 * c + 3.0 * s * d)) / h)
    return np.array(at), np.array(rates)
