"""
Exact time of impact for N intervals at once (numpy, no Python loop over N); the gap over time.

The batch sibling of ``scalar``: the same model and coefficients (``capsule``), the same
derivative chain (``polynomials``, batch half), refined by bisection to full precision and
polished by the same two guarded Newton steps on the gap.
"""

from typing import List, Tuple, Union

import numpy as np

from .capsule import BATCH, cap_quadratics, side_quartic
from .polynomials import evaluate_batch, quadratic_entry_batch, touch_candidates_batch
from .result import ArrayLike, DEGENERATE_AXIS, ROOT_SLACK, TOUCH_TOLERANCE
from ...errors import CoreError

_dot = BATCH.dot


def _as_points(name: str, value: ArrayLike) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.ndim != 2 or array.shape[1] != 3:
        raise CoreError(f'{name} must have shape (N, 3), got {array.shape}')
    return array


def _as_column(name: str, value: Union[float, ArrayLike], n: int) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return np.full(n, float(array))
    if array.shape != (n,):
        raise CoreError(f'{name} must be a scalar or have shape ({n},), got {array.shape}')
    return array


def time_of_impact_batch(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
                         knob0: ArrayLike, knob1: ArrayLike, ball_radius: Union[float, ArrayLike],
                         bat_radius: Union[float, ArrayLike],
                         dt: Union[float, ArrayLike] = 1.0) -> np.ndarray:
    """
    ``time_of_impact`` for N intervals at once, fully vectorised.

    :param ball0, ball1, tip0, tip1, knob0, knob1: arrays of shape (N, 3) (metres).
    :param ball_radius, bat_radius: scalars or (N,) (metres, >= 0).
    :param dt: scalar or (N,) (seconds, > 0).

    :returns: (N,) float64 seconds from each interval's start to first contact; NaN where there is
        no contact, and NaN for rows with non-finite values, negative radii or dt <= 0.

    :raises CoreError: arrays of the wrong shape (rows are not checked by raising).
    """
    points = [_as_points(name, value) for name, value in (
        ('ball0', ball0), ('ball1', ball1), ('tip0', tip0), ('tip1', tip1),
        ('knob0', knob0), ('knob1', knob1))]
    n = points[0].shape[0]
    for name, array in zip(('ball1', 'tip0', 'tip1', 'knob0', 'knob1'), points[1:]):
        if array.shape[0] != n:
            raise CoreError(f'{name} has {array.shape[0]} rows but ball0 has {n}')
    rb = _as_column('ball_radius', ball_radius, n)
    rt = _as_column('bat_radius', bat_radius, n)
    seconds = _as_column('dt', dt, n)
    radius = rb + rt
    with np.errstate(invalid='ignore'):
        good = (np.all(np.isfinite(np.concatenate(points, axis=1)), axis=1)
                & np.isfinite(radius) & (rb >= 0.0) & (rt >= 0.0)
                & np.isfinite(seconds) & (seconds > 0.0))
    result = np.full(n, np.nan)
    rows = np.flatnonzero(good)
    if rows.size == 0:
        return result
    b0, b1, e0, e1, s0, s1 = (p[rows] for p in points)
    near = _may_touch(b0, b1, e0, e1, s0, s1, radius[rows])
    rows, b0, b1, e0, e1, s0, s1, radius = (
        x[near] for x in (rows, b0, b1, e0, e1, s0, s1, radius[rows]))
    if rows.size == 0:
        return result
    tau = _first_contact_tau(b0, b1, e0, e1, s0, s1, radius)
    result[rows] = tau * seconds[rows]
    return result


def _may_touch(b0: np.ndarray, b1: np.ndarray, e0: np.ndarray, e1: np.ndarray, s0: np.ndarray,
               s1: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Batch broad phase (as the scalar one): False for rows that certainly stay clear."""
    m0 = b0 - 0.5 * (s0 + e0)
    m1 = (b1 - 0.5 * (s1 + e1)) - m0
    m11 = _dot(m1, m1)
    with np.errstate(divide='ignore', invalid='ignore'):
        s = np.where(m11 > 0.0, np.clip(-_dot(m0, m1) / m11, 0.0, 1.0), 0.0)
    closest = m0 + m1 * s[:, None]
    half = 0.5 * np.maximum(np.linalg.norm(e0 - s0, axis=1), np.linalg.norm(e1 - s1, axis=1))
    reach = half + radius + TOUCH_TOLERANCE
    return _dot(closest, closest) <= (reach + 1e-9 * (1.0 + reach)) ** 2


def _first_contact_tau(b0: np.ndarray, b1: np.ndarray, e0: np.ndarray, e1: np.ndarray,
                       s0: np.ndarray, s1: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Batch first contact on checked rows: (N,) tau in [0, 1] or NaN."""
    w0 = b0 - s0
    u0 = e0 - s0
    w_end = b1 - s1
    u_end = e1 - s1
    extent = np.max(np.abs(np.concatenate([w0, w_end, u0, u_end, radius[:, None]], axis=1)),
                    axis=1)
    extent = np.where(extent > 0.0, extent, 1.0)[:, None]
    w0, w_end, u0, u_end = w0 / extent, w_end / extent, u0 / extent, u_end / extent
    w1, u1 = w_end - w0, u_end - u0
    r = radius / extent[:, 0]
    rr = r * r
    cap_slack = ((r + TOUCH_TOLERANCE / extent[:, 0]) ** 2 - rr)[:, None]
    zeros = np.zeros_like(rr)
    best = np.full(rr.shape, np.inf)
    for a, b, c in cap_quadratics(w0, w1, u0, u1, rr, BATCH):
        best = np.minimum(best, quadratic_entry_batch(a, b, c, cap_slack[:, 0]))
    quartic, axis, along_axis = side_quartic(w0, w1, u0, u1, rr, BATCH)
    uu = np.stack(list(axis) + [zeros, zeros], axis=1)
    wu = np.stack(list(along_axis) + [zeros, zeros], axis=1)
    candidates = touch_candidates_batch(np.stack(quartic, axis=1),
                                        lambda x: cap_slack * evaluate_batch(uu, x))
    safe = np.where(np.isnan(candidates), 0.0, candidates)
    axis2 = evaluate_batch(uu, safe)
    along = evaluate_batch(wu, safe)
    in_range = ~np.isnan(candidates) & (axis2 > DEGENERATE_AXIS) & (along >= 0.0) & (
        along <= axis2)
    # confirm with the gap at the polished root (the quartic also vanishes where the bat's
    # length does)
    rows, cols = np.nonzero(in_range)
    picked = [x[rows] for x in (w0, w1, u0, u1, r)]
    polished = _polish(candidates[rows, cols], *picked)
    gap = _gap_and_rate(polished, *picked)[0]
    accepted = gap <= TOUCH_TOLERANCE / extent[rows, 0] + ROOT_SLACK
    side_times = np.full(candidates.shape, np.inf)
    side_times[rows[accepted], cols[accepted]] = polished[accepted]
    side = np.min(side_times, axis=1)
    caps = _polish(np.where(np.isfinite(best), best, np.nan), w0, w1, u0, u1, r)
    best = np.fmin(caps, side)
    return np.where(np.isfinite(best), best, np.nan)


def _segment_offsets(point: np.ndarray, start: np.ndarray,
                     axis: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return the fraction along each segment (clipped to [0, 1]) and the offset from it.

    The numpy sibling of ``geometry.closest_on_segment``: rows of (..., 3) arrays, a segment
    from ``start`` along ``axis``; a zero-length segment is its start.
    """
    axis2 = _dot(axis, axis)
    with np.errstate(divide='ignore', invalid='ignore'):
        fraction = np.where(axis2 > 0.0, np.clip(_dot(point - start, axis) / axis2, 0.0, 1.0),
                            0.0)
    return fraction, point - (start + axis * fraction[..., None])


def _gap_and_rate(x: np.ndarray, w0: np.ndarray, w1: np.ndarray, u0: np.ndarray,
                  u1: np.ndarray, r: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Return the gap and d(gap)/d(tau) at x (N,) in scaled units (scalar ``_scaled_gap``)."""
    w = w0 + w1 * x[:, None]
    u = u0 + u1 * x[:, None]
    fraction, offset = _segment_offsets(w, 0.0, u)
    length = np.linalg.norm(offset, axis=1)
    with np.errstate(divide='ignore', invalid='ignore'):
        rate = np.where(length > 0.0, _dot(offset, w1 - u1 * fraction[:, None]) / length, 0.0)
    return length - r, rate


def _polish(tau: np.ndarray, w0: np.ndarray, w1: np.ndarray, u0: np.ndarray, u1: np.ndarray,
            r: np.ndarray) -> np.ndarray:
    """Batch polish: two guarded Newton steps on the gap at each contact tau > 0."""
    active = np.isfinite(tau) & (tau > 0.0)
    x = np.where(active, tau, 0.5)
    gap, rate = _gap_and_rate(x, w0, w1, u0, u1, r)
    for _ in range(2):
        with np.errstate(divide='ignore', invalid='ignore'):
            step = gap / rate
        trial = x - step
        ok = active & np.isfinite(step) & (np.abs(step) <= 1e-6) & (trial >= 0.0) & (trial <= 1.0)
        new_gap, new_rate = _gap_and_rate(np.where(ok, trial, x), w0, w1, u0, u1, r)
        ok &= np.abs(new_gap) < np.abs(gap)
        x = np.where(ok, trial, x)
        gap = np.where(ok, new_gap, gap)
        rate = np.where(ok, new_rate, rate)
    return np.where(active, x, tau)


# ----------------------------------------------------------------------------------------------
# Objective 1: the gap as a function of time (vectorised over t)


def positions_at(t: ArrayLike, dt: float, *pairs: ArrayLike) -> List[np.ndarray]:
    """Return each (start, end) pair of points moved linearly to times t (s) of dt: (..., 3)."""
    times = np.asarray(t, dtype=float)[..., None] / float(dt)
    out = []
    for start, end in zip(pairs[::2], pairs[1::2]):
        p0 = np.asarray(start, dtype=float)
        p1 = np.asarray(end, dtype=float)
        out.append(p0 + (p1 - p0) * times)
    return out


def distance(t: ArrayLike, ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
             knob0: ArrayLike, knob1: ArrayLike, ball_radius: float, bat_radius: float,
             dt: float) -> np.ndarray:
    """
    Signed gap between the ball and the capsule bat (segment knob-tip, rounded ends).

    Objective 1 for a finite bat: the distance from the ball centre to the nearest point of the
    segment, minus both radii. Negative means overlap.

    :param t: times in seconds from the interval start (any shape).
    :param ball0 ... dt: as for ``time_of_impact``.

    :returns: Gap in metres, same shape as t.
    """
    ball, tip, knob = positions_at(t, dt, ball0, ball1, tip0, tip1, knob0, knob1)
    _, offset = _segment_offsets(ball, knob, tip - knob)
    return np.linalg.norm(offset, axis=-1) - bat_radius - ball_radius
