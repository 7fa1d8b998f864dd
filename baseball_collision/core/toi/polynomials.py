"""
Polynomials on [0, 1]: evaluation, the derivative chain, bracketed roots; scalar and batch.

Coefficients are lowest power first, ``(c0, c1, c2, c3, c4)``: a quartic (a quadratic or a
line is a quartic with zero top coefficients). Each building block comes in two siblings: the
scalar one on floats (Newton steps safeguarded by bisection) for the scalar solver, and the
batch one on numpy rows (``(N, 5)`` coefficients, plain bisection, no Python loop over N) for
``time_of_impact_batch``.

The derivative chain finds every monotone piece of a quartic: the roots of P'' (closed form)
split [0, 1] into pieces on which P' is monotone, so a sign change of P' over a piece brackets
its single root; those roots (the critical points of P) split [0, 1] into pieces on which P is
monotone. A tangential touch (a double root, which ``numpy.roots`` returns as a complex pair)
is then never lost: at every local minimum the value itself is compared with a slack.
"""

import math
from typing import Callable, Iterator, List, Optional, Sequence

import numpy as np

Slack = Callable[[float], float]
"""The value of a gap polynomial that corresponds to a gap of TOUCH_TOLERANCE, at a tau."""

BISECTIONS = 56
"""Halvings of a sub-interval of [0, 1] in the batch path: below double precision."""


# ----------------------------------------------------------------------------------------------
# scalar


def evaluate(c: Sequence[float], x: float) -> float:
    """Return the quartic c at x (Horner)."""
    return c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * c[4])))


def evaluate_d1(c: Sequence[float], x: float) -> float:
    """Return the first derivative of the quartic c at x."""
    return c[1] + x * (2.0 * c[2] + x * (3.0 * c[3] + x * 4.0 * c[4]))


def evaluate_d2(c: Sequence[float], x: float) -> float:
    """Return the second derivative of the quartic c at x."""
    return 2.0 * c[2] + x * (6.0 * c[3] + x * 12.0 * c[4])


def quadratic_roots(a: float, b: float, c: float) -> List[float]:
    """Return the real roots of a x^2 + b x + c in ascending order (numerically stable form)."""
    if a == 0.0:
        return [] if b == 0.0 else [-c / b]
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return []
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    if q == 0.0:
        return [0.0, 0.0]
    r1, r2 = q / a, c / q
    return [r1, r2] if r1 <= r2 else [r2, r1]


def bracketed_root(f: Callable[[float], float], df: Callable[[float], float], lo: float,
                   hi: float, f_lo: float) -> float:
    """
    Return the root of f, monotone on [lo, hi] and changing sign there, to double precision.

    Newton steps safeguarded by bisection: a step leaving the bracket is replaced by halving.
    ``f_lo`` is f(lo) (not zero); the bracket keeps f(lo) on that side of zero.
    """
    positive = f_lo > 0.0
    x = 0.5 * (lo + hi)
    for _ in range(200):
        fx = f(x)
        if fx == 0.0:
            return x
        if (fx > 0.0) == positive:
            lo = x
        else:
            hi = x
        slope = df(x)
        step = fx / slope if slope != 0.0 else math.inf
        candidate = x - step
        if not lo < candidate < hi:
            candidate = 0.5 * (lo + hi)
        if abs(candidate - x) <= 1e-16 or hi - lo <= 2e-16:
            return candidate
        x = candidate
    return x


def critical_points(c: Sequence[float]) -> List[float]:
    """
    Return the points in (0, 1) where the quartic c changes direction, ascending.

    A zero of c' exactly at an inflection is a stationary inflection, where c keeps its
    direction, so it is skipped.
    """
    inflections = [x for x in quadratic_roots(12.0 * c[4], 6.0 * c[3], 2.0 * c[2])
                   if 0.0 < x < 1.0]
    bounds = [0.0] + inflections + [1.0]
    critical = []
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        d_lo, d_hi = evaluate_d1(c, lo), evaluate_d1(c, hi)
        if (d_lo < 0.0 and d_hi > 0.0) or (d_lo > 0.0 and d_hi < 0.0):
            critical.append(bracketed_root(
                lambda x: evaluate_d1(c, x), lambda x: evaluate_d2(c, x), lo, hi, d_lo))
    return critical


def touch_candidates(c: Sequence[float], slack: Slack) -> Iterator[float]:
    """
    Yield the times in [0, 1] at which a gap polynomial starts to count as contact, in order.

    ``c`` is a quartic whose sign is the sign of (distance^2 - R^2) for one feature; ``slack(x)``
    is the value of c that corresponds to a gap of TOUCH_TOLERANCE at x. Yields 0 when touching
    at the start, each root where c enters <= 0, and each local minimum at which c stays within
    ``slack`` without crossing (a graze).
    """
    a = 0.0
    f_a = evaluate(c, 0.0)
    if f_a <= slack(0.0):
        yield 0.0
    for b in critical_points(c) + [1.0]:
        f_b = evaluate(c, b)
        if f_a > 0.0 and f_b <= 0.0:
            yield bracketed_root(lambda x: evaluate(c, x), lambda x: evaluate_d1(c, x), a, b, f_a)
        elif 0.0 < f_b < f_a and f_b <= slack(b):
            yield b
        a, f_a = b, f_b


def quadratic_entry(a: float, b: float, c: float, slack: float) -> Optional[float]:
    """
    Return the first tau in [0, 1] at which a tau^2 + b tau + c (a >= 0) counts as contact.

    Contact: the value is <= 0, or a local minimum stays within ``slack`` (a graze). This is
    ``touch_candidates`` in closed form for the end caps' quadratics. None: no contact.
    """
    if c <= slack:
        return 0.0
    if a > 0.0:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0 and b < 0.0:
            q = -0.5 * (b - math.sqrt(disc))
            root = min(q / a, c / q)
            if root <= 1.0:
                return root
        vertex = min(1.0, -0.5 * b / a)
    else:
        vertex = 1.0 if b < 0.0 else 0.0
    if vertex > 0.0 and a * vertex * vertex + b * vertex + c <= slack:
        return vertex
    return None


# ----------------------------------------------------------------------------------------------
# batch: N polynomials at once


def evaluate_batch(c: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Evaluate quartics c (N, 5) at x (N,) or (N, K)."""
    if x.ndim == 1:
        return c[:, 0] + x * (c[:, 1] + x * (c[:, 2] + x * (c[:, 3] + x * c[:, 4])))
    return c[:, :1] + x * (c[:, 1:2] + x * (c[:, 2:3] + x * (c[:, 3:4] + x * c[:, 4:5])))


def evaluate_d1_batch(c: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Evaluate the derivatives of quartics c (N, 5) at x (N,) or (N, K)."""
    if x.ndim == 1:
        return c[:, 1] + x * (2.0 * c[:, 2] + x * (3.0 * c[:, 3] + x * 4.0 * c[:, 4]))
    return c[:, 1:2] + x * (2.0 * c[:, 2:3] + x * (3.0 * c[:, 3:4] + x * 4.0 * c[:, 4:5]))


def quadratic_roots_in_unit_batch(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Return the roots of a x^2 + b x + c strictly inside (0, 1) as (N, 2), NaN where absent."""
    with np.errstate(divide='ignore', invalid='ignore', over='ignore'):
        disc = b * b - 4.0 * a * c
        sq = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        q = -0.5 * (b + np.copysign(sq, b))
        quad = np.stack([q / a, c / q], axis=1)
        linear = np.stack([-c / b, np.full_like(b, np.nan)], axis=1)
        roots = np.where((a == 0.0)[:, None], linear, quad)
    inside = (roots > 0.0) & (roots < 1.0)
    return np.where(inside, roots, np.nan)


def bisect_batch(f: Callable[[np.ndarray, np.ndarray], np.ndarray], c: np.ndarray,
                 lo: np.ndarray, hi: np.ndarray, lo_positive: np.ndarray) -> np.ndarray:
    """
    Locate sign changes of f(c, x) on brackets [lo, hi] (all (M,)) by bisection.

    Returns the side of each bracket past the change, to double precision.
    """
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        same = (f(c, mid) > 0.0) == lo_positive
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    return hi


def _solve_pieces_batch(f: Callable[[np.ndarray, np.ndarray], np.ndarray], c: np.ndarray,
                        lo: np.ndarray, hi: np.ndarray, change: np.ndarray,
                        lo_positive: np.ndarray) -> np.ndarray:
    """Bisect only the (row, piece) brackets marked in ``change``; NaN elsewhere."""
    out = np.full(lo.shape, np.nan)
    rows, pieces = np.nonzero(change)
    if rows.size:
        out[rows, pieces] = bisect_batch(f, c[rows], lo[rows, pieces], hi[rows, pieces],
                                         lo_positive[rows, pieces])
    return out


def monotone_bounds_batch(c: np.ndarray) -> np.ndarray:
    """Return the bounds of the monotone pieces of quartics c on [0, 1]: (N, 5), 1.0-padded."""
    n = c.shape[0]
    inflections = quadratic_roots_in_unit_batch(12.0 * c[:, 4], 6.0 * c[:, 3], 2.0 * c[:, 2])
    zeros = np.zeros((n, 1))
    ones = np.ones((n, 1))
    knots = np.concatenate([zeros, inflections, ones], axis=1)
    knots = np.sort(np.where(np.isnan(knots), 1.0, knots), axis=1)
    lo, hi = knots[:, :-1], knots[:, 1:]
    d_lo, d_hi = evaluate_d1_batch(c, lo), evaluate_d1_batch(c, hi)
    change = (((d_lo > 0.0) & (d_hi < 0.0)) | ((d_lo < 0.0) & (d_hi > 0.0))) & (hi > lo)
    critical = _solve_pieces_batch(evaluate_d1_batch, c, lo, hi, change, d_lo > 0.0)
    bounds = np.concatenate([zeros, critical, ones], axis=1)
    return np.sort(np.where(np.isnan(bounds), 1.0, bounds), axis=1)


def touch_candidates_batch(c: np.ndarray,
                           slack: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Batch ``touch_candidates``: (N, 5) candidate times, NaN where none."""
    bounds = monotone_bounds_batch(c)
    values = evaluate_batch(c, bounds)
    lo, hi = bounds[:, :-1], bounds[:, 1:]
    f_lo, f_hi = values[:, :-1], values[:, 1:]
    crossing = (f_lo > 0.0) & (f_hi <= 0.0) & (hi > lo)
    roots = _solve_pieces_batch(evaluate_batch, c, lo, hi, crossing,
                                np.ones(lo.shape, dtype=bool))
    graze = ~crossing & (f_hi > 0.0) & (f_hi < f_lo) & (f_hi <= slack(hi))
    pieces = np.where(crossing, roots, np.where(graze, hi, np.nan))
    start = np.where(values[:, :1] <= slack(bounds[:, :1]), 0.0, np.nan)
    return np.concatenate([start, pieces], axis=1)


def quadratic_entry_batch(a: np.ndarray, b: np.ndarray, c: np.ndarray,
                          slack: np.ndarray) -> np.ndarray:
    """Batch ``quadratic_entry``: (N,) first contact tau, inf where none."""
    with np.errstate(divide='ignore', invalid='ignore'):
        disc = b * b - 4.0 * a * c
        q = -0.5 * (b - np.sqrt(np.maximum(disc, 0.0)))
        root = np.minimum(q / a, c / q)
        crossing = (a > 0.0) & (disc >= 0.0) & (b < 0.0) & (root <= 1.0)
        vertex = np.where(a > 0.0, np.minimum(1.0, -0.5 * b / a), np.where(b < 0.0, 1.0, 0.0))
    graze = (vertex > 0.0) & (a * vertex * vertex + b * vertex + c <= slack)
    return np.where(c <= slack, 0.0, np.where(crossing, root, np.where(graze, vertex, np.inf)))
