"""
Cubic smoothing splines over a window of noisy samples on uneven stamps: numpy only.

A smoothing spline is the cubic spline ``f`` through smoothed values ``f = (I + lam P)^-1 y``
at the knots, ``P`` a roughness penalty (symmetric, positive semi-definite) and ``lam`` its
weight. Three penalties (``PENALTIES``), each linear in the values:

* ``natural``: Reinsch (1967), the integral of f''^2, ``P = Q R^-1 Q^T``: the natural cubic
  smoothing spline (f'' = 0 at both ends). Its straight lines cost nothing; at a window's end
  it pulls the curvature to zero, a bias where the motion accelerates.
* ``not-a-knot``: the squared jumps of f''' at the inner knots of the not-a-knot interpolant
  of ``f`` (the knots 2 .. n - 3; at 1 and n - 2 not-a-knot makes them 0), each scaled to the
  mean step. Every cubic costs nothing, so a cubic motion comes through unbiased at the ends
  too; 4 samples or fewer are interpolated.
* ``jerk``: the constant-jerk motion model of a Kalman/RTS smoother (state position, velocity,
  acceleration and jerk; the jerk a random walk: white noise in its derivative, the snap) as
  a prior on the values at the knots, its initial state unknown (diffuse): ``P`` is the
  precision of the knot values under that model (:func:`jerk_precision`), so ``(I + lam P)^-1 y``
  is the RTS smoother's smoothed position with the snap's intensity ``sigma^2 / lam`` (Wahba
  1978: the smoothing spline of degree 7 at its knots), and its slopes the smoothed state's
  velocities (:func:`jerk_slopes`). Every cubic costs nothing, as above.

The weight is chosen from the noise (``variances``, per column, the square of the 1-sigma noise
of each coordinate; the columns of one call share one weight): with ``target='samples'``
Reinsch's rule, the weighted residual sum ``sum (y - f)^2 / variance`` equals the number of
values (what ``tools.reference`` uses over a whole stream); with ``target='dof'`` it equals
its expectation for that weight, the number of values less the smoother's degrees of freedom
(trace of ``(I + lam P)^-1``) per column. When even the stiffest fit (the penalty's null
space: a least-squares line or cubic) leaves less than that, it is taken. With
``target='likelihood'`` the weight of largest marginal likelihood when the penalty is read as
a Gaussian prior (the smoother is then the Kalman/RTS smoother of that prior, as a cubic
smoothing spline is that of an integrated white-noise acceleration: Wahba 1978); it stays put
where the residual rules are flat, and can be the stiffest fit too (searched on a grid of
log10 weights 0.1 apart by the compiled kernel, ``toi._kernel.likeliest``). A column of zero
variance is interpolated. Values are smoothed per column, so ``slopes`` are those of the
interpolating spline (natural or not-a-knot) through the smoothed values.
"""

import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .splines import not_a_knot_slope_rows, not_a_knot_slopes
from ..toi import _kernel

PENALTIES = ('natural', 'not-a-knot', 'jerk')
"""The roughness penalties ``smooth`` knows."""

TARGETS = ('samples', 'dof', 'likelihood')
"""How ``smooth`` picks the weight: Reinsch's rule, or the residuals' expectation."""

LOG_WEIGHTS = (-12.0, 12.0)
"""The range (log10) the dimensionless weight is searched in by bisection."""


def natural_parts(h: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Return Reinsch's Q (n x n-2, 1/s) and R (n-2 x n-2, s) for steps h."""
    n = len(h) + 1
    q = np.zeros((n, n - 2))
    r = np.zeros((n - 2, n - 2))
    for j in range(1, n - 1):
        q[j - 1:j + 2, j - 1] = (1.0 / h[j - 1], -1.0 / h[j - 1] - 1.0 / h[j], 1.0 / h[j])
        r[j - 1, j - 1] = (h[j - 1] + h[j]) / 3.0
        if j < n - 2:
            r[j - 1, j] = r[j, j - 1] = h[j] / 6.0
    return q, r


def natural_slopes(times: Sequence[float], values: np.ndarray) -> np.ndarray:
    """
    Return the slopes at the knots of the natural cubic spline through (times, values).

    :param times: (n,) strictly increasing (s), n >= 2; ``values``: (n, columns).
    """
    t = np.asarray(times, dtype=float)
    y = np.asarray(values, dtype=float)
    h = np.diff(t)
    if len(t) == 2:
        d = (y[1] - y[0]) / h[0]
        return np.vstack([d, d])
    q, r = natural_parts(h)
    moments = np.zeros_like(y)
    moments[1:-1] = np.linalg.solve(r, q.T @ y)
    chords = np.diff(y, axis=0) / h[:, None]
    slopes = np.empty_like(y)
    slopes[:-1] = chords - h[:, None] * (2.0 * moments[:-1] + moments[1:]) / 6.0
    slopes[-1] = chords[-1] + h[-1] * (moments[-2] + 2.0 * moments[-1]) / 6.0
    return slopes


def penalty(times: Sequence[float], kind: str) -> np.ndarray:
    """
    Return the roughness penalty matrix P (n x n, dimensionless) of a window's stamps.

    :param kind: one of ``PENALTIES``.
    :raises ValueError: an unknown kind.
    """
    t = np.asarray(times, dtype=float)
    n = len(t)
    if kind == 'not-a-knot':  # (the third jumps scaled by the mean step cubed, J^T J)
        return np.frombuffer(_kernel.not_a_knot_penalty(t.tolist())).reshape(n, n)
    h = np.diff(t)
    mean = float(np.mean(h))
    if kind == 'natural':
        if n < 3:
            return np.zeros((n, n))
        q, r = natural_parts(h)
        return q @ np.linalg.solve(r, q.T) * mean ** 3
    if kind == 'jerk':
        return jerk_precision(t / mean)
    raise ValueError(f"penalty must be one of {', '.join(PENALTIES)}, got {kind!r}")


def jerk_steps(h: float) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return (F, Q): the constant-jerk model's transition and process noise over a step h.

    The state (position, velocity, acceleration, jerk) moves by ``F`` over ``h`` and gains
    noise of covariance ``Q`` (the snap white with unit intensity: Q's entry (i, j) is
    ``h^(7 - i - j) / ((3 - i)! (3 - j)! (7 - i - j))``), in the unit of time of ``h``.
    """
    powers = h ** np.arange(8)
    factorials = np.array([1.0, 1.0, 2.0, 6.0])
    i = np.arange(4)
    transition = np.where(i[None, :] >= i[:, None],
                          powers[np.abs(i[None, :] - i[:, None])]
                          / factorials[np.abs(i[None, :] - i[:, None])], 0.0)
    order = 7 - i[:, None] - i[None, :]
    noise = powers[order] / (factorials[3 - i][:, None] * factorials[3 - i][None, :] * order)
    return transition, noise


def jerk_precision(times: Sequence[float]) -> np.ndarray:
    """
    Return the precision (n x n) of the values at ``times`` under the constant-jerk model.

    The knots' states are a Gauss-Markov chain (:func:`jerk_steps`), the first one diffuse, so
    their joint precision is the sum of each step's ``[-F, I]^T Q^-1 [-F, I]``; the values'
    precision is its Schur complement on the positions (the velocities, accelerations and
    jerks marginalised). Its null space is the cubics (projected out of the rounding of that
    subtraction). None below 5 knots: zeros.

    :param times: (n,) strictly increasing, in a unit of time near the steps (e.g. the mean
        step) for conditioning.
    """
    t = np.asarray(times, dtype=float)
    n = len(t)
    if n < 5:
        return np.zeros((n, n))
    joint, positions, rest = _jerk_joint(t)
    across = joint[np.ix_(positions, rest)]
    precision = joint[np.ix_(positions, positions)] - across @ np.linalg.solve(
        joint[np.ix_(rest, rest)], across.T)
    # the subtraction leaves rounding of the joint's large entries in the cubics' directions:
    # projected out (the exact precision is zero on them), the null space is the cubics' to
    # the last bits
    cubics, _ = np.linalg.qr(np.vander(t - t.mean(), 4, increasing=True))
    outside = np.eye(n) - cubics @ cubics.T
    precision = outside @ precision @ outside
    return 0.5 * (precision + precision.T)


def jerk_slopes(times: Sequence[float], values: np.ndarray) -> np.ndarray:
    """
    Return the constant-jerk model's velocities at the knots given its positions there.

    The states that cost least under the model with the positions held (the smoothed state's
    velocities once the positions are the smoothed ones): the interpolant of the model's
    prior, a spline of degree 7. Fewer than 5 knots: the not-a-knot slopes (one cubic).

    :param times: (n,) strictly increasing (s); ``values``: (n, columns). Slopes per second.
    """
    t = np.asarray(times, dtype=float)
    y = np.asarray(values, dtype=float)
    if len(t) < 5:
        return not_a_knot_slopes(t, y)
    unit = float(np.mean(np.diff(t)))
    joint, positions, rest = _jerk_joint(t / unit)
    states = -np.linalg.solve(joint[np.ix_(rest, rest)], joint[np.ix_(rest, positions)] @ y)
    return states[0::3] / unit  # (rest holds velocity, acceleration, jerk at each knot)


def _jerk_joint(t: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the knots' states' joint precision (4n x 4n), the positions' and the others' rows."""
    n = len(t)
    joint = np.zeros((4 * n, 4 * n))
    identity = np.eye(4)
    for k, h in enumerate(np.diff(t)):
        transition, noise = jerk_steps(float(h))
        link = np.hstack([-transition, identity])
        joint[4 * k:4 * k + 8, 4 * k:4 * k + 8] += link.T @ np.linalg.solve(noise, link)
    positions = np.arange(0, 4 * n, 4)
    return joint, positions, np.setdiff1d(np.arange(4 * n), positions)


def third_jumps(times: Sequence[float]) -> np.ndarray:
    """
    Return J: ``J @ values`` are the not-a-knot interpolant's third-derivative jumps (per s^3).

    One row per inner knot 2 .. n - 3 (none for n < 5: the interpolant is one cubic).

    :param times: (n,) strictly increasing (s).
    """
    n = len(times)
    if n < 5:
        return np.zeros((0, n))
    # each unit value's not-a-knot slopes (the spline is linear in its values), each piece's
    # third derivative 6 (s0 + s1 - 2 chord) / h^2 and its jumps, in the compiled kernel
    return np.frombuffer(_kernel.third_jumps(
        times.tolist() if isinstance(times, np.ndarray) else times)).reshape(n - 4, n)


def smoothing_weight(p: np.ndarray, z: np.ndarray, variances: np.ndarray,
                     target: str) -> float:
    """
    Return the weight lam (dimensionless, inf for the stiffest fit) for eigen-coordinates z.

    :param p: (n,) the penalty's eigenvalues; ``z``: (n, columns) the values in its
        eigenvectors; ``variances``: (columns,) > 0.
    """
    if target == 'likelihood':
        return _likeliest(p, z, variances, ((0, len(variances)),))[0]
    n = len(p)
    scaled = (z * z / variances[None, :]).sum(axis=1)
    columns = len(variances)
    rough = p > NULL_EIGENVALUE * max(float(np.max(p)), 1e-300) if n else np.zeros(0, bool)

    def excess(lam: float) -> float:
        shrink = lam * p / (1.0 + lam * p)
        free = n - float(np.sum(1.0 / (1.0 + lam * p))) if target == 'dof' else n
        return float(np.sum(shrink * shrink * scaled)) - columns * free

    stiffest = float(np.sum(scaled[rough])) - columns * (
        n - float(np.sum(~rough)) if target == 'dof' else n)
    if stiffest <= 0.0:
        return np.inf
    low, high = LOG_WEIGHTS
    if excess(10.0 ** low) >= 0.0:
        return 10.0 ** low
    for _ in range(48):
        middle = 0.5 * (low + high)
        if excess(10.0 ** middle) > 0.0:
            high = middle
        else:
            low = middle
    return 10.0 ** low


NULL_EIGENVALUE = 1e-9
"""A penalty's eigenvalue at most this times the largest is its null space's (``penalty_eigen``
makes it zero; the weight search leaves it out)."""


LIKELIHOOD_GRID = np.arange(LOG_WEIGHTS[0], LOG_WEIGHTS[1] + 1e-9, 0.1)
"""The log10 weights ``target='likelihood'`` searches (``LOG_WEIGHTS`` in steps of 0.1)."""


def _likeliest(p: np.ndarray, z: np.ndarray, variances: np.ndarray,
               bounds: Sequence[Tuple[int, int]]) -> Tuple[float, ...]:
    """
    Return the weight of largest marginal likelihood for each group of columns.

    The penalty as a Gaussian prior of precision lam P / sigma^2 on the values: each rough
    eigen-coordinate z_i is then normal with variance sigma^2 (1 + 1 / (lam p_i)) (the null
    space drops out, as in REML). Searched on ``LIKELIHOOD_GRID`` by the compiled kernel
    (``toi._kernel.likeliest``: the cost it minimises is in its comment; every 16th weight
    first, then only the stretches between whose lower bound may hold a cheaper one: the
    weight the whole grid gives, to the bit). Per group (``bounds``: column ranges): the
    weight, inf when that is the stiffest fit, NaN when no column of the group is noisy
    (variance > 0) or the penalty is zero.
    """
    return _kernel.likeliest(np.ascontiguousarray(p, dtype=float),
                             np.ascontiguousarray(z, dtype=float),
                             np.ascontiguousarray(variances, dtype=float), bounds,
                             LIKELIHOOD_GRID, NULL_EIGENVALUE)


def penalty_eigen(times: Sequence[float], kind: str) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return the eigenvalues (>= 0) and eigenvectors of a window's ``penalty`` (read-only).

    A penalty depends on the window's steps only, not on where the window starts. Taken to
    the nanosecond (the detector's stamps are whole nanoseconds), the steps are the key: one
    window's stamps are smoothed again and again (the ball's and the bat's windows of an
    interval share them; an impact's velocities and uncertainty fit its windows again), and a
    tracker on a steady clock gives every window of a swing one of a few step patterns. The
    answer is the penalty of stamps rebuilt from those steps, so a pure function of the key;
    the last ``_EIGEN_KEPT`` answers are kept and the same arrays given again. Stamps less than
    a nanosecond apart are kept by their own values instead.

    :raises ValueError: an unknown kind (``penalty``).
    """
    steps = _kernel.step_key(times.tolist() if isinstance(times, np.ndarray) else times)
    whole = steps is not None
    key = (steps if whole else tuple(np.asarray(times, dtype=float).tolist()), whole, kind)
    found = _EIGEN.get(key)
    if found is None:
        rebuilt = (np.concatenate(([0.0], np.cumsum(np.frombuffer(steps)) * 1e-9)) if whole
                   else np.asarray(times, dtype=float))
        p, u = _eigen_beside_null(penalty(rebuilt, kind), rebuilt, NULL_DEGREE[kind])
        p.setflags(write=False)
        u.setflags(write=False)
        if len(_EIGEN) >= _EIGEN_KEPT:
            _EIGEN.clear()
        found = _EIGEN[key] = (p, u)
    return found


def _eigen_beside_null(matrix: np.ndarray, times: np.ndarray,
                       degree: int) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return a penalty's eigenvalues and eigenvectors with its null space exact.

    The null space is the polynomials of ``degree`` at the stamps (``NULL_DEGREE``). Decomposed
    as it is, its eigenvalues are rounding, not zero (with a weight of 1e12 that took up to
    0.2 % off a window's cubic motion, a millimetre of a swing), and the eigenvectors beside it
    leave it by rounding times the penalty's scale over the smallest rough eigenvalue (2e-8 on
    uneven steps). So the null space's eigenvalues are made zero and its eigenvectors an
    orthonormal basis of the polynomials (the kernel's ``polynomial_basis``), and the others
    are projected off it.
    """
    p, u = np.linalg.eigh(matrix)  # (ascending: the null space's first)
    p, u = np.ascontiguousarray(p), np.ascontiguousarray(u)
    null = min(degree + 1, len(times))
    # the kernel's: the basis in the first columns, the others less their parts c_i in it, the
    # null eigenvalues (and any rounding below zero) zero; orthonormal columns less their
    # parts are off orthonormal by c_i . c_j, at most the largest |c_i|^2, which it returns
    if _kernel.beside_null(p, u, times.tolist(), null, NULL_EIGENVALUE) > 1e-13:
        # (an ill-conditioned penalty, steps of very different lengths: what the projection
        # took off was more than rounding) orthonormal again, in the eigenvalues' order
        u[:, null:] = np.linalg.qr(u[:, null:])[0]
    return p, u


NULL_DEGREE = {'natural': 1, 'not-a-knot': 3, 'jerk': 3}
"""The degree of the polynomials each penalty leaves alone (its null space): lines under the
natural spline's, cubics under the others."""

_EIGEN: dict = {}
"""``penalty_eigen``'s answers: (the steps in ns as bytes, or the stamps; whether steps; kind) ->
the eigenvalues and vectors."""

_EIGEN_KEPT = 128
"""Most answers ``_EIGEN`` holds (then it starts again): a few pitches' windows."""


def smoother_matrix(times: Sequence[float], values: np.ndarray, variances: Sequence[float],
                    kind: str = 'not-a-knot', target: str = 'likelihood',
                    eigen: Optional[Tuple[np.ndarray, np.ndarray]] = None) -> np.ndarray:
    """
    Return A (n x n): the smoothed values are ``A @ values`` (the weight chosen on values).

    :param times: (n,) strictly increasing (s); ``values``: (n, columns) (units of each
        column); ``variances``: (columns,) noise variance of each column (its unit squared);
        ``eigen``: ``penalty_eigen(times, kind)`` when the caller has it (columns fitted in
        groups over one window share it).
    :raises ValueError: an unknown penalty or target, or shapes that do not match.
    """
    y, v = _checked(times, values, variances, target)
    p, u = eigen if eigen is not None else penalty_eigen(times, kind)
    lam = _weights(p, u.T @ y, v, target, ((0, len(v)),))[0]
    return np.eye(len(times)) if math.isnan(lam) else (u * _factors(p, lam)[None, :]) @ u.T


def smoother_weights(times: Sequence[float], values: np.ndarray, variances: Sequence[float],
                     kind: str = 'not-a-knot', target: str = 'likelihood',
                     eigen: Optional[Tuple[np.ndarray, np.ndarray]] = None,
                     groups: Sequence[slice] = (slice(None),)) -> List[float]:
    """
    Return each group's smoothing weight, as ``smooth`` chooses it (NaN: not smoothed).

    inf is the stiffest fit. For ``smoother_rows`` and ``smoother_shifts`` of one window (their
    ``weights``): the search made once. Arguments and errors as for ``smooth``.
    """
    y, v = _checked(times, values, variances, target)
    p, u = eigen if eigen is not None else penalty_eigen(times, kind)
    return list(_weights(p, u.T @ y, v, target, _bounds(groups, len(v))))


def smoother_rows(times: Sequence[float], rows: np.ndarray, values: np.ndarray,
                  variances: Sequence[float], kind: str = 'not-a-knot',
                  target: str = 'likelihood',
                  eigen: Optional[Tuple[np.ndarray, np.ndarray]] = None,
                  groups: Sequence[slice] = (slice(None),),
                  weights: Optional[Sequence[float]] = None) -> np.ndarray:
    """
    Return (groups, rows, n): each row through each group's ``smoother_matrix``, turned into U.

    Row r and group g give ``(r @ A_g) @ U``, A_g the smoother of g's columns of ``values``
    (their weight chosen on them, as ``smooth`` with ``groups`` does). A_g is ``U diag(f) U^T``
    with U the penalty's orthonormal eigenvectors, so that is ``(r @ U) f``: no matrix formed,
    and the norms and dot products of the rows are those of ``r @ A_g`` (to rounding). A group
    with no noisy column is interpolated: ``r @ U``.

    :param times: (n,) strictly increasing (s); ``rows``: (r, n) weights of the n values (e.g. a
        spline's value at t: ``fitting.piece_weights``); ``values``, ``variances``, ``kind``,
        ``target``, ``eigen``, ``groups``: as for ``smooth``; ``weights``: the groups'
        ``smoother_weights`` when the caller has them (else searched here).
    :raises ValueError: an unknown penalty or target, or shapes that do not match.
    """
    y, v = _checked(times, values, variances, target)
    p, u = eigen if eigen is not None else penalty_eigen(times, kind)
    if weights is None:
        weights = _weights(p, u.T @ y, v, target, _bounds(groups, len(v)))
    along = np.asarray(rows, dtype=float) @ u
    return np.array([along if math.isnan(lam) else along * _factors(p, lam)
                     for lam in weights])


def smoother_shifts(times: Sequence[float], rows: np.ndarray, values: np.ndarray,
                    variances: Sequence[float], kind: str = 'not-a-knot',
                    target: str = 'likelihood',
                    eigen: Optional[Tuple[np.ndarray, np.ndarray]] = None,
                    groups: Sequence[slice] = (slice(None),),
                    reference: Optional[np.ndarray] = None,
                    weights: Optional[Sequence[float]] = None) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return how far each group's smoothing moves each row's value, and that move's weights.

    (shifts (groups, rows, columns), deviations (groups, rows, n)): row r and group g give
    ``r @ A_g @ values - s @ values``, the row through the smoothed values less the reference
    row s through the values themselves (``reference``, (rows, n); the rows themselves by
    default: the smoothed spline's value at t less the interpolant's, for a
    ``fitting.piece_weights`` row; only g's own columns are smoothed by A_g), and
    ``(r @ A_g - s) @ U``, its weights turned into U as ``smoother_rows``' (their norm times a
    column's noise is the shift's spread from that noise alone). A group with no noisy column
    is not smoothed: its shifts and deviations are zero. Arguments (``weights`` too) and errors
    as for ``smoother_rows``.
    """
    y, v = _checked(times, values, variances, target)
    p, u = eigen if eigen is not None else penalty_eigen(times, kind)
    along = np.asarray(rows, dtype=float) @ u
    against = along if reference is None else np.asarray(reference, dtype=float) @ u
    z = u.T @ y
    if weights is None:
        weights = _weights(p, z, v, target, _bounds(groups, len(v)))
    deviations = np.array([np.zeros_like(along) if math.isnan(lam)
                           else along * _factors(p, lam) - against for lam in weights])
    return deviations @ z, deviations


def smoother_norms(times: Sequence[float], rows: np.ndarray, values: np.ndarray,
                   variances: Sequence[float], kind: str = 'not-a-knot',
                   target: str = 'likelihood',
                   eigen: Optional[Tuple[np.ndarray, np.ndarray]] = None,
                   groups: Sequence[slice] = (slice(None),)) -> np.ndarray:
    """
    Return (groups, rows): the norm of each row through each group's ``smoother_matrix``.

    Row r and group g give ``|r @ A_g|`` (``smoother_rows``' norms). Arguments and errors as
    for ``smoother_rows``.
    """
    return np.linalg.norm(smoother_rows(times, rows, values, variances, kind, target, eigen,
                                        groups), axis=2)


def smooth(times: Sequence[float], values: np.ndarray, variances: Sequence[float],
           kind: str = 'not-a-knot', target: str = 'likelihood',
           eigen: Optional[Tuple[np.ndarray, np.ndarray]] = None,
           groups: Sequence[slice] = (slice(None),), start: int = 0
           ) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return (smoothed values, slopes per second) at the knots: see the module docstring.

    Columns of zero variance come back as given (interpolated). Each group of columns has its
    own weight: ``smooth(..., groups=(a, b))`` is ``smooth`` of columns ``a`` and of columns
    ``b`` in turn, in one pass (the eigenvectors applied once, the slopes solved once).

    :param times: (n,) strictly increasing (s), n >= 2; ``values``: (n, columns);
        ``variances``: (columns,) the noise variance of each column; ``eigen``: as for
        ``smoother_matrix``; ``groups``: contiguous slices of the columns, each smoothed
        with one weight (the kernel's ``toi._kernel.smoothed`` applies them).
    :param start: the slopes of knots ``start`` .. n - 1 only (rows n - ``start``; the values
        are all n): a window's interval is near its end (``not-a-knot`` solves only those;
        another penalty solves all and keeps those).
    :raises ValueError: an unknown penalty or target, or shapes that do not match.
    """
    y, v = _checked(times, values, variances, target)
    p, u = eigen if eigen is not None else penalty_eigen(times, kind)
    z = u.T @ y
    bounds = _bounds(groups, len(v))
    y = np.ascontiguousarray(y)
    fitted = np.frombuffer(_kernel.smoothed(p, u, z, y, v, bounds,
                                            _weights(p, z, v, target, bounds),
                                            NULL_EIGENVALUE)).reshape(y.shape)
    if start and kind == 'not-a-knot':
        return fitted, np.array(not_a_knot_slope_rows(times, fitted, start))
    slopes = {'natural': natural_slopes, 'jerk': jerk_slopes}.get(kind, not_a_knot_slopes)(
        times, fitted)
    return fitted, slopes[start:]


def _checked(times: Sequence[float], values: np.ndarray, variances: Sequence[float],
             target: str) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return values (n, columns) and variances (columns,) as float arrays.

    :raises ValueError: an unknown target, or shapes that do not match.
    """
    y = np.asarray(values, dtype=float)
    v = np.asarray(variances, dtype=float)
    if target not in TARGETS:
        raise ValueError(f"target must be one of {', '.join(TARGETS)}, got {target!r}")
    if y.ndim != 2 or y.shape[0] != len(times) or v.shape != (y.shape[1],):
        raise ValueError(f'values {y.shape} and variances {v.shape} do not match '
                         f'{len(times)} stamps')
    return y, v


def _bounds(groups: Sequence[slice], columns: int) -> List[Tuple[int, int]]:
    """
    Return each group's (start, stop) columns.

    :raises ValueError: a group that is not a contiguous slice.
    """
    bounds = []
    for group in groups:
        start, stop, step = group.indices(columns)
        if step != 1:
            raise ValueError(f'a group of columns must be contiguous, got {group!r}')
        bounds.append((start, stop))
    return bounds


def _weights(p: np.ndarray, z: np.ndarray, v: np.ndarray, target: str,
             bounds: Sequence[Tuple[int, int]]) -> List[float]:
    """
    Return each group's weight (``bounds``: its columns) on the noisy columns of z.

    z: the values in the eigenvectors. NaN where the group has no noisy column or the penalty
    is zero (nothing smoothed); inf for the stiffest fit.
    """
    if target == 'likelihood':
        return list(_likeliest(p, z, v, bounds))
    if not np.any(p > 0.0):
        return [math.nan] * len(bounds)
    weights = []
    for start, stop in bounds:
        noisy = v[start:stop] > 0.0
        weights.append(smoothing_weight(p, z[:, start:stop][:, noisy], v[start:stop][noisy],
                                        target) if np.any(noisy) else math.nan)
    return weights


def _factors(p: np.ndarray, lam: float) -> np.ndarray:
    """
    Return the smoother's factor on each eigen-coordinate: 1 / (1 + lam p).

    At lam = inf (the stiffest fit) 1 on the null space and 0 off it: its projection. (The
    kernel's ``smoothed`` applies the same factors to a window's values; this is for
    ``smoother_matrix``.)
    """
    return 1.0 / (1.0 + lam * p) if math.isfinite(lam) else (
        p <= NULL_EIGENVALUE * float(np.max(p))).astype(float)
