"""
Cubic and quintic splines through samples on uneven stamps: their derivatives at the knots.

A cubic spline is a piecewise cubic Hermite: its values and its slopes at the knots fix it.
``not_a_knot_slopes`` returns the slopes of the C2 interpolating spline whose third
derivative is continuous at the second and the second-to-last knots (not-a-knot), so the end
pieces are as accurate as the inner ones: for a function with a bounded fourth derivative the
error is O(h^4) in value and O(h^3) in slope on every piece, also on uneven stamps (de Boor, A
Practical Guide to Splines, ch. IV). Two samples give the chord, three the parabola.
``not_a_knot_quintic_rows`` gives the same of the not-a-knot quintic spline, and its second
derivatives: a piecewise quintic Hermite, O(h^6) in value (``c2``'s exact windows with a sample
after the interval, or whose last piece the caller takes: ``quintic_window``).
"""

from typing import List, Sequence, Tuple, Union

import numpy as np

from ..toi import _kernel


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

    Solved by the compiled kernel (``toi._kernel.not_a_knot``: the tridiagonal system
    eliminated by Thomas' forward sweep without pivoting, the not-a-knot system's first
    elimination leaving ``h0 + h1`` on the diagonal and its inner rows diagonally dominant;
    then each column in turn), in plain doubles in a fixed order, so the slopes are the same
    bits on every machine (LAPACK's solve, which this replaced, rounds as the BLAS kernels a
    CPU is given: ``c2``'s answers moved by 1 ns on an AVX-512 machine).

    :param start: the first knot whose slopes are wanted (0 <= start < n): the rows of knots
        ``start`` .. n - 1 are returned; the back-substitution stops there (a window's interval
        is at its end: two rows instead of n).
    :raises ValueError: rows of unequal lengths, or ``start`` outside the knots.
    """
    if len(times) <= 3:
        return [tuple(row) for row in _short_slopes(
            np.asarray(times, dtype=float), np.asarray(values, dtype=float)).tolist()[start:]]
    if isinstance(times, np.ndarray):
        times = times.tolist()
    # (an array's rows as they lie in it, float64: the same numbers as its rows' floats)
    return _kernel.not_a_knot(times, np.ascontiguousarray(values, dtype=float)
                              if isinstance(values, np.ndarray) else values, start)


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


QUINTIC_STEP_RATIO = 2.0
"""``c2`` takes the quintic for a window only where its longest step is at most this times its
shortest (the far test's cardinal weights for the quintic are measured within it), to within
``STEP_RATIO_TOLERANCE``."""

STEP_RATIO_TOLERANCE = 1e-6
"""Relative slack on ``QUINTIC_STEP_RATIO``: stamps on a millisecond grid (integer nanoseconds)
become seconds from the clock's origin with rounding, which puts a 4 ms step a few 1e-16 s above
or below twice a 2 ms one; at the ratio itself the rule would follow the rounding."""


def not_a_knot_quintic_rows(times: Sequence[float],
                            values: Union[np.ndarray, Sequence[Sequence[float]]],
                            start: int = 0) -> Tuple[List[Tuple[float, ...]],
                                                     List[Tuple[float, ...]]]:
    """
    Return the slopes and second derivatives of the not-a-knot quintic spline, as rows.

    The degree-5 spline through (times, values) whose knots are the stamps but the second,
    third, third-to-last and second-to-last (de Boor's not-a-knot choice for an odd degree: the
    end pieces as accurate as the inner ones), so for a function with a bounded sixth
    derivative O(h^6) off in value, O(h^5) in slope and O(h^4) in second derivative, on uneven
    stamps too; six samples give the one quintic through them. Solved by the compiled kernel
    (``toi._kernel.not_a_knot_quintic``: B-spline collocation by de Boor's recurrence, the
    totally positive system eliminated without pivoting, in a fixed order: the same bits on
    every machine).

    :param times: (n,) strictly increasing (s), n >= 6.
    :param values: (n, columns) floats, an array or rows: each column is fitted on its own.
    :param start: the first knot whose derivatives are wanted (0 <= start < n).
    :returns: (slopes, second derivatives) of knots ``start`` .. n - 1, a tuple per knot
        (value units per second and per second squared).
    :raises ValueError: fewer than 6 samples, rows of unequal lengths, ``start`` outside.
    """
    if isinstance(times, np.ndarray):
        times = times.tolist()
    return _kernel.not_a_knot_quintic(times, np.ascontiguousarray(values, dtype=float)
                                      if isinstance(values, np.ndarray) else values, start)


def quintic_window(times: Sequence[float], j: int, continued: bool = False) -> bool:
    """
    Return whether ``c2`` fits interval j of an exact window by the quintic spline.

    Six samples or more, at least one after the interval unless ``continued`` (a window's last
    piece, and so the velocities extrapolated from it, is left to the cubic by default: the
    quintic's end weights amplify whatever noise the samples carry), and steps within
    ``QUINTIC_STEP_RATIO`` of each other (to within ``STEP_RATIO_TOLERANCE``).

    :param continued: the last piece may be quintic: the bat's own path over an interval that
        ends its window (look-ahead 0, ``detector.sweep.Sweep.paths``; 6x nearer in time p99
        on exact 90 Hz tilting swings than the cubic), or a piece continued past the window's
        end (a hit's bat carried on from before its interval, ``detector.fitting.c2_bat_ahead``,
        which its rule takes only from samples that follow their own continuation).
    """
    if len(times) < 6 or j + (1 if continued else 2) >= len(times):
        return False
    steps = [b - a for a, b in zip(times, times[1:])]
    return max(steps) <= QUINTIC_STEP_RATIO * (1.0 + STEP_RATIO_TOLERANCE) * min(steps)
