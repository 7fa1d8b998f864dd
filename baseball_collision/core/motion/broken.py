"""
A window's cubic splines with a break at an instant: position shared, velocity free to jump.

For an impact at t* inside a window of samples, the knots are the samples' stamps and t*. Two
not-a-knot cubic splines (``splines.not_a_knot_slopes``) meet at t*: the left one through the
knots up to t*, the right one from t* on. They share their value at t* (the bat does not jump)
and nothing else: the velocity and every higher derivative may jump there (a hit brakes the
bat). The value at t*, which no sample gives, is the one whose two splines are the least rough
together: the sum of both sides' ``smoothing.penalty`` (squared jumps of the third derivative
at their inner knots, both in units of the mean step before t*; a side of four knots or fewer
costs nothing). With noise the sample knots are smoothed too, minimising
``|y - f|^2 + lam (f' P f)`` over all knot values f, the weight lam chosen by
``smoothing.smoothing_weight`` on the samples up to t* alone.

So samples after t* can pin WHERE the motion is at t* (when they are four or more: a side of
four knots or fewer is any cubic) but cannot bend its velocity before t*: the left-limit rate
at t* is that of the left spline, an interpolation between its last sample and t*. A
piecewise cubic with a velocity kink at t* and at least four samples on each side is
reproduced exactly (both sides cost nothing). With fewer samples after t* (or none: a break
after the last sample) the right side is free and the value at t* is the least rough for the
left spline alone: an extrapolation from the samples before t* by the whole window's
smoothness, not only its last cubic's (the continuation, when the left side has four knots or
fewer).

Error order: each side is a not-a-knot spline, O(h^4) in value and O(h^3) in rate for a motion
with a bounded fourth derivative on that side; what a brake spread over a time d after t*
does to the right side (it is not a kink) reaches the value at t* as about the lost speed
times d / 2.
"""

import math
from typing import Optional, Sequence, Tuple

import numpy as np

from .smoothing import penalty_eigen, smoothing_weight, third_jumps
from .splines import end_state, not_a_knot_slopes

SAME_INSTANT = 1e-9
"""s: a break this close after a sample is at the sample (no knot of its own)."""

STIFF = 1e-9
"""Singular values of the stacked jumps below this share of the largest are their null space."""


def broken_knots(times: Sequence[float], t_break: float) -> Tuple[np.ndarray, int, bool]:
    """
    Return (knots, the break's index in them, whether it is a knot of its own).

    :param times: (n,) strictly increasing (s), n >= 2; ``t_break``: at or after times[1]
        (after the last sample: the right side is the break alone).
    :raises ValueError: a break before the second sample (or not finite).
    """
    t = np.asarray(times, dtype=float)
    if not (len(t) >= 2 and math.isfinite(t_break) and t_break >= t[1]):
        raise ValueError(f'break {t_break!r} s must be at or after the second sample, '
                         f'{t[1] if len(t) >= 2 else None!r} s')
    j = int(np.searchsorted(t, t_break, side='right')) - 1  # the last sample at or before
    if t_break - t[j] <= SAME_INSTANT:
        return t, j, False
    return np.insert(t, j + 1, t_break), j + 1, True


def broken_jumps(knots: np.ndarray, star: int, scale: float) -> np.ndarray:
    """
    Return both sides' third-derivative jumps as rows over all knots (dimensionless).

    ``J @ f`` are the jumps of the left spline (knots up to ``star``) and of the right one
    (from ``star``), each times ``scale`` ** 3 (s^3), so ``|J f|^2`` is the penalty.
    """
    m = len(knots)
    left, right = third_jumps(knots[:star + 1]), third_jumps(knots[star:])
    rows = np.zeros((len(left) + len(right), m))
    rows[:len(left), :star + 1] = left
    rows[len(left):, star:] = right
    return rows * scale ** 3


def broken_fit(times: Sequence[float], values: np.ndarray, variances: Sequence[float],
               t_break: float, target: str = 'likelihood'
               ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return the left spline of the fit broken at ``t_break``: its knots, values and slopes.

    Its last knot is ``t_break``: ``values[-1]`` is the fitted value there and ``slopes[-1]``
    the left-limit rate (per s). Columns of one call share one weight; a column of zero
    variance is interpolated (its samples kept, only the value at the break fitted).

    :param times: (n,) strictly increasing (s); ``values``: (n, columns); ``variances``:
        (columns,) noise variance per column; ``target``: ``smoothing``'s weight rule.
    :raises ValueError: a break before times[1], or shapes that do not match.
    """
    y = np.asarray(values, dtype=float)
    v = np.asarray(variances, dtype=float)
    if y.ndim != 2 or y.shape[0] != len(times) or v.shape != (y.shape[1],):
        raise ValueError(f'values {y.shape} and variances {v.shape} do not match '
                         f'{len(times)} stamps')
    knots, star, inserted = broken_knots(times, t_break)
    before = np.asarray(times[:star + 1 - int(inserted)], dtype=float)  # samples up to t*
    scale = float(np.mean(np.diff(before))) if len(before) >= 2 else float(
        np.mean(np.diff(knots)))
    jumps = broken_jumps(knots, star, scale)
    samples = np.delete(np.arange(len(knots)), star) if inserted else np.arange(len(knots))
    pick = np.eye(len(knots))[samples]  # the sample knots' rows
    fitted = pick.T @ y
    free = inserted and not np.any(jumps[:, star])
    noisy = v > 0.0
    if np.any(noisy):
        weight = 0.0
        if len(before) >= 5:
            p, u = penalty_eigen(before, 'not-a-knot')
            weight = smoothing_weight(p, u.T @ y[:len(before)][:, noisy], v[noisy], target)
        fitted[:, noisy] = _smoothed(pick, jumps, y[:, noisy], weight, star if free else None)
    if inserted and not free:
        exact = ~noisy
        others = np.delete(np.arange(len(knots)), star)
        fitted[star, exact] = np.linalg.lstsq(
            jumps[:, [star]], -jumps[:, others] @ fitted[others][:, exact], rcond=None)[0][0]
    if free:  # no side constrains t*: the left spline continued
        fitted[star] = end_state(knots[:star], fitted[:star], knots[star])[0]
    left_knots, left_values = knots[:star + 1], fitted[:star + 1]
    return left_knots, left_values, not_a_knot_slopes(left_knots, left_values)


def _smoothed(pick: np.ndarray, jumps: np.ndarray, y: np.ndarray, weight: float,
              free: Optional[int]) -> np.ndarray:
    """
    Return the knot values minimising ``|y - pick f|^2 + weight |jumps f|^2``.

    Stacked least squares; an infinite weight: the least-squares fit in the jumps' null space.

    :param free: a knot no term constrains (left out, filled by the caller), or None.
    """
    m = pick.shape[1]
    keep = np.arange(m) if free is None else np.delete(np.arange(m), free)
    a, rows = pick[:, keep], jumps[:, keep]
    out = np.zeros((m, y.shape[1]))
    if np.isfinite(weight):
        stacked = np.vstack([a, math.sqrt(weight) * rows])
        rhs = np.vstack([y, np.zeros((len(rows), y.shape[1]))])
        out[keep] = np.linalg.lstsq(stacked, rhs, rcond=None)[0]
        return out
    _, sizes, vt = np.linalg.svd(rows) if len(rows) else (None, np.zeros(0), np.eye(len(keep)))
    rank = int(np.sum(sizes > STIFF * (sizes[0] if len(sizes) else 0.0)))
    null = vt[rank:].T
    out[keep] = null @ np.linalg.lstsq(a @ null, y, rcond=None)[0]
    return out
