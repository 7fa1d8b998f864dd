"""Tests for the window smoothing splines: Reinsch's rule, the not-a-knot and jerk penalties."""

import math

from baseball_collision.core.motion import smoothing
from baseball_collision.core.motion.smoothing import (
    jerk_slopes, jerk_steps, natural_slopes, penalty, penalty_eigen, smooth, smoother_matrix,
    smoother_norms, smoother_rows, smoother_shifts, smoother_weights, smoothing_weight,
    third_jumps)
from baseball_collision.core.toi import _kernel
from baseball_collision.tools.reference import smoothing_spline
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples

steps = st.lists(st.floats(0.002, 0.012), min_size=5, max_size=16)


def _times(steps) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(steps)])


def test_natural_rule_matches_the_reference_reinsch_spline() -> None:
    """Per column, the natural penalty with Reinsch's rule is the reference's smoothing spline."""
    rng = np.random.default_rng(4)
    times = np.cumsum(rng.uniform(0.008, 0.014, 24))
    values = np.c_[np.sin(9.0 * times), 30.0 * times ** 3] + rng.normal(0.0, 1e-3, (24, 2))
    expected, expected_slopes = smoothing_spline(times, values, 1e-3)
    for column in range(2):
        fitted, slopes = smooth(times, values[:, [column]], [1e-6], 'natural', 'samples')
        assert np.allclose(fitted[:, 0], expected[:, column], atol=1e-9)
        assert np.allclose(slopes[:, 0], expected_slopes[:, column], atol=1e-6)


@settings(max_examples=examples(60), deadline=None)
@given(steps=steps, coefficients=st.lists(st.floats(-50.0, 50.0), min_size=4, max_size=4),
       weight=st.floats(-6.0, 6.0), kind=st.sampled_from(('not-a-knot', 'jerk')))
def test_the_penalties_leave_every_cubic_alone(steps, coefficients, weight, kind) -> None:
    """
    Every cubic costs nothing: whatever the weight, a cubic's samples come back unchanged.

    The penalty matrix takes a cubic to zero, to its rounding; the smoother, through the
    penalty's eigenvectors with the null space exact (``penalty_eigen``, what every smoothing
    call uses), gives it back to 1e-7 whatever the weight (the eigenvectors beside the null
    space are off it by rounding, 2e-8 on uneven steps). Solved densely, ``I + w P``, the
    matrix's rounding would come back multiplied by w over its smallest rough eigenvalue (2e-6
    at w = 1e6 on uneven steps): why the smoother does not solve it so.
    """
    times = _times(steps)
    a, b, c, d = coefficients
    cubic = a + b * times + c * times ** 2 + d * times ** 3
    matrix = penalty(times, kind)
    scale = 1.0 + np.abs(cubic).max()
    assert np.allclose(matrix @ cubic, 0.0, atol=1e-7 * scale * max(1.0, np.abs(matrix).max()))
    p, u = penalty_eigen(times, kind)
    smoothed = u @ ((u.T @ cubic) / (1.0 + 10.0 ** weight * p))
    assert np.allclose(smoothed, cubic, rtol=0.0, atol=1e-7 * scale)
    _, slopes = smooth(times, cubic[:, None], [1e-6], kind)  # and its slopes are the cubic's
    derivative = b + 2.0 * c * times + 3.0 * d * times ** 2
    unit = float(np.mean(steps))  # (rounding of values of this scale, per this time)
    assert np.allclose(slopes[:, 0], derivative,
                       atol=1e-6 * (1.0 + np.abs(derivative).max()) + 1e-8 * scale / unit)


def _rts_states(times: np.ndarray, values: np.ndarray, noise_variance: float,
                snap_intensity: float, diffuse: float = 1e7) -> np.ndarray:
    """
    Brute force: the states of a Kalman filter and RTS smoother, constant-jerk model.

    Written out step by step (predict, update in Joseph's form, then the backward pass), the
    first state's covariance ``diffuse`` times the identity in place of an unknown one.
    """
    state, covariance = np.array([values[0], 0.0, 0.0, 0.0]), np.eye(4) * diffuse
    read = np.array([1.0, 0.0, 0.0, 0.0])
    filtered, predicted, transitions = [], [], []
    for k, (t, y) in enumerate(zip(times, values)):
        if k:
            transition, noise = jerk_steps(t - times[k - 1])
            state = transition @ state
            covariance = transition @ covariance @ transition.T + snap_intensity * noise
            transitions.append(transition)
        predicted.append((state, covariance))
        gain = covariance @ read / (read @ covariance @ read + noise_variance)
        state = state + gain * (y - read @ state)
        kept = np.eye(4) - np.outer(gain, read)  # (Joseph's form: the diffuse start's rounding)
        covariance = kept @ covariance @ kept.T + noise_variance * np.outer(gain, gain)
        filtered.append((state, covariance))
    smoothed = [filtered[-1][0]]
    for k in range(len(times) - 2, -1, -1):
        state, covariance = filtered[k]
        ahead, ahead_covariance = predicted[k + 1]
        gain = covariance @ transitions[k].T @ np.linalg.inv(ahead_covariance)
        smoothed.append(state + gain @ (smoothed[-1] - ahead))
    return np.array(smoothed[::-1])


@settings(max_examples=examples(40), deadline=None)
@given(steps=steps, log_intensity=st.floats(-3.0, 3.0))
def test_jerk_penalty_is_the_rts_smoother_of_the_constant_jerk_model(
        steps, log_intensity) -> None:
    """
    (I + lam P)^-1 y is the RTS smoother's position, lam the noise over the snap's intensity.

    And the slopes through those positions (``jerk_slopes``) are its velocities.
    """
    times = _times(steps)
    unit = float(np.mean(np.diff(times)))  # penalty's time unit: the mean step
    rng = np.random.default_rng(len(steps))
    values = np.sin(40.0 * times) + rng.normal(0.0, 1e-2, len(times))
    noise_variance, intensity = 1e-4, 10.0 ** log_intensity
    mine = np.linalg.solve(np.eye(len(times)) + noise_variance / intensity
                           * penalty(times, 'jerk'), values)
    expected = _rts_states(times / unit, values, noise_variance, intensity)
    # the reference's finite start leaves an error that falls as 1 / diffuse: twice what a
    # start 10 times less diffuse adds to it bounds it (near the first samples, after a long
    # step: a 2.4e-4 slope there, 2e-6 from a start of 1e9, whose rounding is worse elsewhere);
    # its rounding leaves up to a few 1e-5 (measured over 300 windows, 1.4e-5 and 5.4e-5); a
    # wrong model or step is off by 1e-2 and more
    start = np.abs(expected - _rts_states(times / unit, values, noise_variance, intensity,
                                          diffuse=1e6)) / 4.5
    assert np.all(np.abs(mine - expected[:, 0]) <= 1e-4 + start[:, 0])
    slopes = jerk_slopes(times, mine[:, None])[:, 0] * unit  # per mean step, as the states
    assert np.all(np.abs(slopes - expected[:, 1])
                  <= 2e-4 * max(1.0, np.abs(slopes).max()) + start[:, 1])


@pytest.mark.parametrize('step', [0.3, 1.0, 2.5])
def test_jerk_steps_are_the_integrated_model(step: float) -> None:
    """
    Brute force: F is exp(A h) and Q the integral of exp(A s) b b^T exp(A s)^T over [0, h].

    A shifts each state into the one before it (position' = velocity, ...), b drives the
    jerk with unit white noise; the integral by Simpson's rule on a fine grid.
    """
    shift = np.eye(4, k=1)

    def propagate(s: float) -> np.ndarray:  # exp(A s): A is nilpotent, its series ends
        return sum(np.linalg.matrix_power(shift * s, k) / np.prod(range(1, k + 1))
                   for k in range(4))
    grid = np.linspace(0.0, step, 2001)
    drive = np.array([propagate(s)[:, 3] for s in grid])  # exp(A s) b
    integrand = drive[:, :, None] * drive[:, None, :]
    weights = np.ones(len(grid))
    weights[1:-1:2], weights[2:-1:2] = 4.0, 2.0
    integral = np.tensordot(weights, integrand, axes=1) * (grid[1] - grid[0]) / 3.0
    transition, noise = jerk_steps(step)
    assert np.allclose(transition, propagate(step), rtol=1e-12, atol=1e-12)
    assert np.allclose(noise, integral, rtol=1e-9, atol=1e-12)


@settings(max_examples=examples(40), deadline=None)
@given(steps=steps)
def test_not_a_knot_penalty_is_the_squared_third_derivative_jumps(steps) -> None:
    """
    Brute force: y^T P y is the sum of squared f''' jumps at knots 2..n-3 (times mean step^3).

    The jumps are measured on the not-a-knot interpolant by finite differences of its pieces
    (numpy's polyfit through four dense points of each piece), not from the slopes.
    """
    times = _times(steps)
    rng = np.random.default_rng(len(steps))
    y = rng.normal(0.0, 1.0, len(times))
    from baseball_collision.core.motion import not_a_knot_slopes
    slopes = not_a_knot_slopes(times, y[:, None])[:, 0]
    thirds = []
    for i in range(len(times) - 1):
        h = times[i + 1] - times[i]
        s = np.linspace(0.0, 1.0, 4)
        hermite = ((2 * s ** 3 - 3 * s ** 2 + 1) * y[i] + (s ** 3 - 2 * s ** 2 + s) * h * slopes[i]
                   + (3 * s ** 2 - 2 * s ** 3) * y[i + 1] + (s ** 3 - s ** 2) * h * slopes[i + 1])
        thirds.append(6.0 * np.polyfit(s * h, hermite, 3)[0])
    jumps = np.diff(thirds)[1:-1] * np.mean(np.diff(times)) ** 3
    assert y @ penalty(times, 'not-a-knot') @ y == pytest.approx(np.sum(jumps ** 2), rel=1e-6)


def test_natural_slopes_are_a_natural_spline() -> None:
    """The natural spline's slopes: exact for a line, and zero curvature at both ends."""
    times = np.array([0.0, 0.3, 0.5, 1.1, 1.4])
    line = (2.0 - 3.0 * times)[:, None]
    assert np.allclose(natural_slopes(times, line)[:, 0], -3.0)
    y = np.array([[0.0], [1.0], [0.5], [2.0], [1.0]])
    m = natural_slopes(times, y)[:, 0]
    h = np.diff(times)
    # curvature at the ends of a cubic Hermite piece from its end values and slopes
    start = (6.0 * (y[1, 0] - y[0, 0]) / h[0] - 4.0 * m[0] - 2.0 * m[1]) / h[0]
    end = (-6.0 * (y[-1, 0] - y[-2, 0]) / h[-1] + 2.0 * m[-2] + 4.0 * m[-1]) / h[-1]
    assert abs(start) < 1e-9 and abs(end) < 1e-9


@pytest.mark.parametrize('kind', ['natural', 'not-a-knot', 'jerk'])
def test_the_weight_meets_its_rule(kind: str) -> None:
    """
    The chosen weight makes the weighted residuals what the rule asks (samples or dof).

    Unless even the stiffest fit leaves less: then it is taken (a projection onto the
    penalty's null space, here under not-a-knot with Reinsch's rule).
    """
    rng = np.random.default_rng(8)
    times = np.cumsum(rng.uniform(0.002, 0.004, 40))
    clean = np.c_[np.sin(20.0 * times), np.cos(15.0 * times), times]
    noisy = clean + rng.normal(0.0, 2e-3, clean.shape)
    variances = np.full(3, 4e-6)
    for target in ('samples', 'dof'):
        matrix = smoother_matrix(times, noisy, variances, kind, target)
        residual = np.sum((noisy - matrix @ noisy) ** 2 / variances)
        goal = 3 * (len(times) - (np.trace(matrix) if target == 'dof' else 0.0))
        if np.allclose(matrix @ matrix, matrix, atol=1e-9):
            assert residual < goal and kind != 'natural' and target == 'samples'
        else:
            assert residual == pytest.approx(goal, rel=1e-6)


def test_likeliest_weight_matches_a_dense_marginal_likelihood() -> None:
    """
    Brute force: the weight maximising the Gaussian marginal likelihood, computed densely.

    With the prior values ~ N(null-space, sigma^2 / lam P^+), the samples' covariance on the
    penalty's range is sigma^2 (I + (lam P)^+); its log-likelihood over a fine grid of lam
    peaks within the search's step (0.1 in log10) of the chosen weight.
    """
    rng = np.random.default_rng(5)
    times = np.cumsum(rng.uniform(0.002, 0.004, 24))
    values = np.c_[np.sin(40.0 * times), times ** 4 * 1e4] + rng.normal(0.0, 1e-3, (24, 2))
    matrix = penalty(times, 'not-a-knot')
    p, u = np.linalg.eigh(matrix)
    rough = p > 1e-9 * p.max()
    basis = u[:, rough]
    chosen = smoothing_weight(p, u.T @ values, np.full(2, 1e-6), 'likelihood')
    best, best_log = -np.inf, None
    for log in np.arange(-6.0, 6.0, 0.01):
        covariance = 1e-6 * (np.eye(rough.sum()) + np.linalg.pinv(
            basis.T @ (10.0 ** log * matrix) @ basis))
        _, logdet = np.linalg.slogdet(covariance)
        projected = basis.T @ values
        score = -sum(logdet + c @ np.linalg.solve(covariance, c) for c in projected.T)
        if score > best:
            best, best_log = score, log
    assert abs(np.log10(chosen) - best_log) <= 0.11


def test_smoothing_brings_noisy_samples_closer_to_the_truth() -> None:
    """Over many noisy windows the smoothed values' error is well below the noise."""
    rng = np.random.default_rng(2)
    errors, raw = [], []
    for _ in range(40):
        times = np.cumsum(rng.uniform(0.002, 0.0035, 24))
        clean = np.c_[0.5 * np.sin(12.0 * times), 3.0 * times ** 2, np.cos(7.0 * times)]
        noisy = clean + rng.normal(0.0, 1e-3, clean.shape)
        fitted, _ = smooth(times, noisy, [1e-6] * 3)
        errors.append(fitted[4:-4] - clean[4:-4])
        raw.append(noisy[4:-4] - clean[4:-4])
    assert np.std(errors) < 0.6 * np.std(raw)


def test_zero_variance_and_short_windows_interpolate() -> None:
    """A column without noise, and four samples under the not-a-knot penalty, are kept."""
    times = np.array([0.0, 0.01, 0.02, 0.035, 0.05, 0.06])
    values = np.c_[np.sin(30.0 * times), np.cos(30.0 * times)]
    fitted, _ = smooth(times, values + [[1e-3, 0.0]] * np.array([[1], [-1]] * 3),
                       [1e-6, 0.0])
    assert np.array_equal(fitted[:, 1], values[:, 1])
    assert np.array_equal(smooth(times[:4], values[:4], [1e-6, 1e-6])[0], values[:4])


def test_mismatched_shapes_and_unknown_choices_are_refused() -> None:
    """Variances that do not match the columns, an unknown penalty or rule: ValueError."""
    times = np.linspace(0.0, 0.1, 8)
    values = np.zeros((8, 2))
    with pytest.raises(ValueError, match='do not match'):
        smooth(times, values, [1e-6])
    with pytest.raises(ValueError, match='penalty'):
        smooth(times, values, [1e-6, 1e-6], kind='quintic')
    with pytest.raises(ValueError, match='target'):
        smooth(times, values, [1e-6, 1e-6], target='gcv')


def _is_the_eigen_of(eigen, matrix: np.ndarray, times: np.ndarray, kind: str,
                     orthonormal: float = 1e-12) -> None:
    """Assert: orthonormal vectors that rebuild ``matrix``, the null space its polynomials."""
    p, u = eigen
    nulls = 2 if kind == 'natural' else 4  # (lines cost nothing under it, cubics under the rest)
    assert np.all(p[:nulls] == 0.0) and np.all(p[nulls:] >= 0.0)
    assert np.allclose(u.T @ u, np.eye(len(p)), rtol=0.0, atol=orthonormal)
    scale = np.abs(matrix).max()
    assert np.allclose((u * p) @ u.T, matrix, rtol=0.0, atol=1e-9 * scale)
    polynomials = np.vander(times - times.mean(), nulls, increasing=True)
    inside = u[:, :nulls] @ (u[:, :nulls].T @ polynomials)  # (projected on the null space)
    assert np.allclose(inside, polynomials, rtol=0.0, atol=1e-12 * np.abs(polynomials).max())


@settings(max_examples=examples(40), deadline=None)
@given(steps=st.lists(st.integers(1_000_000, 12_000_000), min_size=4, max_size=31),
       start=st.integers(0, 10 ** 12), kind=st.sampled_from(('not-a-knot', 'natural', 'jerk')))
def test_penalty_eigen_kept_by_steps_is_the_computed_answer(steps, start, kind) -> None:
    """
    The answer is the penalty's of the window's steps (ns), wherever the window starts.

    The eigen of the penalty of stamps rebuilt from the steps, its null space (the
    polynomials it leaves alone) exact; a window with the same steps elsewhere gets the same
    arrays; a step a nanosecond longer, another.
    """
    stamps = start + np.concatenate([[0], np.cumsum(steps)])  # ns
    times = (stamps - 10 ** 11) * 1e-9  # s, as the detector's clock has them
    smoothing._EIGEN.clear()
    first = penalty_eigen(times, kind)
    rebuilt = np.concatenate([[0.0], np.cumsum(np.array(steps, dtype=float)) * 1e-9])
    _is_the_eigen_of(first, penalty(rebuilt, kind), rebuilt, kind)
    assert not first[0].flags.writeable and not first[1].flags.writeable
    elsewhere = penalty_eigen(list(times + 3.25), kind)  # the same steps, later
    assert elsewhere[0] is first[0] and elsewhere[1] is first[1]
    longer = stamps.copy()
    longer[-1] += 1  # its last step a nanosecond longer: another window
    other = penalty_eigen((longer - 10 ** 11) * 1e-9, kind)
    assert other[1] is not first[1]


@settings(max_examples=examples(40), deadline=None)
@given(steps=steps, kind=st.sampled_from(('not-a-knot', 'natural', 'jerk')))
def test_penalty_eigen_leaves_the_null_space_exact(steps, kind) -> None:
    """On any steps (not whole nanoseconds), the polynomials are the null space to rounding."""
    times = _times(steps)
    smoothing._EIGEN.clear()
    eigen = penalty_eigen(times, kind)
    rebuilt = np.concatenate([[0.0], np.cumsum(np.rint(np.diff(times) * 1e9)) * 1e-9])
    _is_the_eigen_of(eigen, penalty(rebuilt, kind), rebuilt, kind)


def test_penalty_eigen_of_stamps_closer_than_a_nanosecond() -> None:
    """Steps under a nanosecond are no key: such a window is kept by its own stamps."""
    smoothing._EIGEN.clear()
    times = np.array([0.0, 1e-10, 0.002, 0.004, 0.006, 0.008])
    eigen = penalty_eigen(times, 'not-a-knot')
    # (a step of 0.1 ns among 2 ms ones: the penalty's scale is 1e16, and its eigenvectors are
    # orthogonal to a few 1e-6)
    _is_the_eigen_of(eigen, penalty(times, 'not-a-knot'), times, 'not-a-knot', 1e-5)
    assert penalty_eigen(times, 'not-a-knot') is eigen


def test_penalty_eigen_keeps_a_bounded_number() -> None:
    """The kept answers never pass ``_EIGEN_KEPT``."""
    smoothing._EIGEN.clear()
    for k in range(smoothing._EIGEN_KEPT + 5):
        penalty_eigen(_times([0.01 + 1e-6 * k] * 6), 'not-a-knot')
        assert len(smoothing._EIGEN) <= smoothing._EIGEN_KEPT


GROUPS = (slice(0, 3), slice(3, 6), slice(6, 7))
"""A bat row's groups of columns (knob, rotation vector, length), as ``fitting.BAT_GROUPS``."""

seven_columns = given(
    steps=st.lists(st.floats(0.002, 0.012), min_size=5, max_size=31),
    sigmas=st.lists(st.sampled_from((0.0, 1e-4, 1e-3, 1e-2)), min_size=7, max_size=7),
    seed=st.integers(0, 2 ** 16))
"""Windows of 6-32 stamps and seven noisy columns (``_seven_columns``), some exact."""


def _seven_columns(steps, sigmas, seed):  # type: ignore[no-untyped-def]
    """Return (times, values (n, 7), variances, rng): smooth motions with the given noise."""
    times = _times(steps)
    rng = np.random.default_rng(seed)
    values = np.c_[np.sin(20.0 * times[:, None] + rng.uniform(0, 6, 7)) * rng.uniform(0.1, 2, 7)]
    values = values + rng.normal(0.0, 1.0, values.shape) * np.array(sigmas)
    return times, values, np.array(sigmas) ** 2, rng


@settings(max_examples=examples(40), deadline=None)
@seven_columns
def test_groups_smooth_as_each_group_alone(steps, sigmas, seed) -> None:
    """One call with groups is each group's own call: its weight, values and slopes."""
    times, values, variances, _ = _seven_columns(steps, sigmas, seed)
    groups = GROUPS
    smoothing._EIGEN.clear()
    fitted, slopes = smooth(times, values, variances, groups=groups)
    for group in groups:
        alone, alone_slopes = smooth(times, values[:, group], variances[group])
        scale = 1.0 + np.abs(values[:, group]).max()
        assert np.allclose(fitted[:, group], alone, rtol=0.0, atol=1e-12 * scale)
        assert np.allclose(slopes[:, group], alone_slopes, rtol=0.0,
                           atol=1e-9 * scale / float(np.min(steps)))
        matrix = smoother_matrix(times, values[:, group], variances[group])
        noisy = variances[group] > 0.0  # (the matrix smooths every column; smooth keeps exact
        assert np.allclose((matrix @ values[:, group])[:, noisy], alone[:, noisy], rtol=0.0,
                           atol=1e-12 * scale)  # ones as given)


@settings(max_examples=examples(40), deadline=None)
@seven_columns
def test_smoother_norms_are_the_norms_through_each_groups_matrix(steps, sigmas, seed) -> None:
    """``smoother_norms``: each row's norm through its group's ``smoother_matrix`` (1e-12)."""
    times, values, variances, rng = _seven_columns(steps, sigmas, seed)
    rows = rng.normal(0.0, 1.0, (2, len(times)))
    norms = smoother_norms(times, rows, values, variances, groups=GROUPS)
    assert norms.shape == (3, 2)
    for group, found in zip(GROUPS, norms):
        matrix = smoother_matrix(times, values[:, group], variances[group])
        expected = np.linalg.norm(rows @ matrix, axis=1)
        assert np.allclose(found, expected, rtol=1e-12, atol=0.0), (found, expected)
        if not np.any(variances[group] > 0.0):  # (interpolated: the rows' own norms)
            assert np.allclose(found, np.linalg.norm(rows, axis=1), rtol=1e-12, atol=0.0)


@settings(max_examples=examples(40), deadline=None)
@seven_columns
def test_smoother_rows_keep_the_products_through_the_groups(steps, sigmas, seed) -> None:
    """
    ``smoother_rows``: in the eigenbasis, the dot products of rows through two groups' smoothers.

    (r A_g) . (s A_h), A_g each group's ``smoother_matrix``, to 1e-12 of the norms' product:
    what ``fitting.bat_gains`` correlates the knob's and the direction's errors by.
    """
    times, values, variances, rng = _seven_columns(steps, sigmas, seed)
    rows = rng.normal(0.0, 1.0, (2, len(times)))
    through = smoother_rows(times, rows, values, variances, groups=GROUPS)
    assert through.shape == (3, 2, len(times))
    matrices = [smoother_matrix(times, values[:, group], variances[group]) for group in GROUPS]
    for g, h in ((0, 1), (0, 2), (1, 2), (1, 1)):
        expected = (rows @ matrices[g]) @ (rows @ matrices[h]).T
        scale = np.outer(np.linalg.norm(rows @ matrices[g], axis=1),
                         np.linalg.norm(rows @ matrices[h], axis=1))
        assert np.allclose(through[g] @ through[h].T, expected, rtol=0.0, atol=1e-12 * scale.max())


@settings(max_examples=examples(40), deadline=None)
@seven_columns
def test_smoother_shifts_are_the_smoothed_values_less_the_values(steps, sigmas, seed) -> None:
    """
    ``smoother_shifts``: each row through its group's smoothed values less through the values.

    ``r @ (A_g - I) @ values`` on g's own columns and the norms of ``r @ (A_g - I)``, A_g each
    group's ``smoother_matrix``, to 1e-12 of the values' and the rows' scales; zero for a group
    with no noisy column (not smoothed); against ``reference`` rows s, ``(r @ A_g - s)``.
    """
    times, values, variances, rng = _seven_columns(steps, sigmas, seed)
    rows = rng.normal(0.0, 1.0, (2, len(times)))
    shifts, deviations = smoother_shifts(times, rows, values, variances, groups=GROUPS)
    assert shifts.shape == (3, 2, values.shape[1]) and deviations.shape == (3, 2, len(times))
    scale = float(np.abs(rows).sum(axis=1).max() * (1.0 + np.abs(values).max()))
    for group, moved, apart in zip(GROUPS, shifts, deviations):
        if not np.any(variances[group] > 0.0):
            assert not moved.any() and not apart.any()
            continue
        change = smoother_matrix(times, values[:, group], variances[group]) - np.eye(len(times))
        assert np.allclose(moved[:, group], rows @ change @ values[:, group], rtol=0.0,
                           atol=1e-12 * scale)
        assert np.allclose(np.linalg.norm(apart, axis=1), np.linalg.norm(rows @ change, axis=1),
                           rtol=0.0, atol=1e-12 * float(np.abs(rows).sum(axis=1).max()))
    reference = rng.normal(0.0, 1.0, rows.shape)  # against other rows: r A_g y - s y
    shifts, deviations = smoother_shifts(times, rows, values, variances, groups=GROUPS,
                                         reference=reference)
    scale = float((np.abs(rows).sum(axis=1).max() + np.abs(reference).sum(axis=1).max())
                  * (1.0 + np.abs(values).max()))
    for group, moved, apart in zip(GROUPS, shifts, deviations):
        if np.any(variances[group] > 0.0):
            matrix = smoother_matrix(times, values[:, group], variances[group])
            assert np.allclose(moved[:, group], (rows @ matrix - reference) @ values[:, group],
                               rtol=0.0, atol=1e-12 * scale)
            assert np.allclose(np.linalg.norm(apart, axis=1),
                               np.linalg.norm(rows @ matrix - reference, axis=1), rtol=0.0,
                               atol=1e-12 * scale)


@settings(max_examples=examples(40), deadline=None)
@given(steps=st.lists(st.floats(0.002, 0.012), min_size=4, max_size=31), data=st.data())
def test_slopes_from_a_knot_are_those_knots_slopes(steps, data) -> None:
    """
    ``start`` gives the same slopes of knots start.. (to the bit) and all the values.

    Under every penalty: ``not-a-knot`` solves only those rows, the others all of them.
    """
    times = _times(steps)
    start = data.draw(st.integers(0, len(times) - 2))
    values = np.c_[np.sin(25.0 * times), times ** 2] + np.array([[1e-3, -1e-3]] * len(times))
    for kind in ('not-a-knot', 'natural', 'jerk'):
        fitted, slopes = smooth(times, values, [1e-6, 0.0], kind)
        fitted_from, slopes_from = smooth(times, values, [1e-6, 0.0], kind, start=start)
        assert np.array_equal(fitted_from, fitted)
        assert np.array_equal(slopes_from, slopes[start:])
        assert slopes_from.shape == (len(times) - start, 2)


def _grid_costs(p: np.ndarray, z: np.ndarray, variances: np.ndarray,
                grid: np.ndarray = smoothing.LIKELIHOOD_GRID) -> np.ndarray:
    """Return the likelihood's costs on the grid, written out in numpy: a sum of logs each."""
    rough = p > smoothing.NULL_EIGENVALUE * max(float(np.max(p)), 1e-300)
    scaled = (z * z / variances[None, :]).sum(axis=1)[rough]
    costs = []
    for log in grid:
        spread = 1.0 + 1.0 / (10.0 ** log * p[rough])
        costs.append(len(variances) * np.sum(np.log(spread)) + np.sum(scaled / spread))
    return np.array(costs)


@settings(max_examples=examples(60), deadline=None)
@given(steps=steps, seed=st.integers(0, 2 ** 16), scale=st.floats(1e-4, 1e2))
def test_the_kernels_weight_search_is_the_grid_search(steps, seed, scale) -> None:
    """
    ``_kernel.likeliest`` picks the grid weight a plain sum of logs picks, group by group.

    Its costs are a product's log (one division a term), not a sum of logs: another weight
    only where the two weights' costs tie to rounding.
    """
    times = _times(steps)
    p, u = penalty_eigen(times, 'not-a-knot')
    rng = np.random.default_rng(seed)
    values = np.c_[np.sin(15.0 * times), times ** 3, np.cos(30.0 * times), times]
    values = scale * values + rng.normal(0.0, 1e-3, values.shape)
    variances = np.array([1e-6, 4e-6, 0.0, 1e-6])
    z = u.T @ values
    groups = ((0, 2), (2, 3), (1, 4), (0, 4))
    found = _kernel.likeliest(p, z, variances, groups, smoothing.LIKELIHOOD_GRID,
                              smoothing.NULL_EIGENVALUE)
    assert np.isnan(found[1])  # no noisy column: nothing to smooth
    grid = smoothing.LIKELIHOOD_GRID
    for (start, stop), weight in zip(groups, found):
        noisy = variances[start:stop] > 0.0
        if not noisy.any():
            continue
        costs = _grid_costs(p, z[:, start:stop][:, noisy], variances[start:stop][noisy])
        chosen = len(grid) - 1 if weight == np.inf else int(np.argmin(np.abs(
            10.0 ** grid - weight)))
        assert weight == np.inf or weight == 10.0 ** grid[chosen]
        best = int(np.argmin(costs))
        assert costs[chosen] - costs[best] <= 1e-12 * (abs(costs[best]) + 1.0)
        assert smoothing_weight(p, z[:, start:stop][:, noisy], variances[start:stop][noisy],
                                'likelihood') == weight


@settings(max_examples=examples(60), deadline=None)
@given(steps=steps, seed=st.integers(0, 2 ** 16),
       grid=st.lists(st.floats(-6.0, 6.0), min_size=1, max_size=9, unique=True))
def test_the_kernels_weight_search_on_grids_of_any_length(steps, seed, grid) -> None:
    """
    On a grid of 1-9 weights (the kernel takes them four at a time) the weight is the cheapest.

    The grid's last weight is the stiffest fit (inf); a tie to rounding may pick either.
    """
    times = _times(steps)
    p, u = penalty_eigen(times, 'not-a-knot')
    rng = np.random.default_rng(seed)
    values = np.c_[np.sin(15.0 * times), times ** 3] + rng.normal(0.0, 1e-3, (len(times), 2))
    variances = np.array([1e-6, 4e-6])
    z = u.T @ values
    grid = np.array(sorted(grid))
    weight, = _kernel.likeliest(p, z, variances, ((0, 2),), grid, smoothing.NULL_EIGENVALUE)
    costs = _grid_costs(p, z, variances, grid)
    chosen = len(grid) - 1 if weight == np.inf else int(np.argmin(np.abs(10.0 ** grid - weight)))
    assert weight == np.inf or weight == 10.0 ** grid[chosen]
    best = int(np.argmin(costs))
    assert costs[chosen] - costs[best] <= 1e-12 * (abs(costs[best]) + 1.0)


def _whole_grid_pick(p, z, variances, bounds, grid) -> list:  # type: ignore[no-untyped-def]
    """
    ``_kernel.likeliest`` written out over every grid weight, its operations in its order.

    Per weight: the product of 1 + lam p_i kept in range by ``frexp`` and its log less the
    logs of lam and of p; per group the sum of s_i lam p_i / (1 + lam p_i); the first smallest
    cost (a NaN first), as ``numpy.argmin``.
    """
    largest = max([1e-300] + [float(x) for x in p])
    rough = [float(x) for x in p if x > smoothing.NULL_EIGENVALUE * largest]
    rows = [i for i, x in enumerate(p) if x > smoothing.NULL_EIGENVALUE * largest]
    logs_of_p = 0.0
    for x in rough:
        logs_of_p += math.log(x)
    picks = []
    for start, stop in bounds:
        columns = [j for j in range(start, stop) if variances[j] > 0.0]
        scaled = []
        for i in rows:
            total = 0.0
            for j in columns:
                total += z[i, j] * z[i, j] / variances[j]
            scaled.append(total)
        best, best_cost = -1, 0.0
        for g, power in enumerate(grid):
            lam = 10.0 ** power
            product, exponent = 1.0, 0
            for x in rough:
                product *= 1.0 + lam * x
                if not product < 1e150:
                    product, e = math.frexp(product)
                    exponent += e
            logs = (math.log(product) + exponent * 0.69314718055994530942
                    - len(rough) * power * 2.30258509299404568402 - logs_of_p)
            total = 0.0
            for x, s in zip(rough, scaled):
                total += lam * x / (1.0 + lam * x) * s
            cost = len(columns) * logs + total
            if best >= 0 and math.isnan(best_cost):
                break
            if best < 0 or math.isnan(cost) or cost < best_cost:
                best, best_cost = g, cost
        picks.append(math.nan if not columns or not rough else
                     math.inf if best == len(grid) - 1 else 10.0 ** grid[best])
    return picks


@settings(max_examples=examples(40), deadline=None)
@given(steps=steps, seed=st.integers(0, 2 ** 16), scale=st.floats(1e-4, 1e3),
       points=st.sampled_from((0, 1, 2, 16, 17, 33, 120, 300)))
def test_the_weight_search_by_bounds_is_the_whole_grids(steps, seed, scale, points) -> None:
    """
    The kernel's search by bounds picks what costing every grid weight picks, to the bit.

    It costs every 16th weight and only the stretches between whose bound may hold a cheaper
    one; written out over the whole grid (its numbers by the same operations), the same
    weights, for the smoother's grid (``points`` 0) and grids of 1-300 weights.
    """
    times = _times(steps)
    p, u = penalty_eigen(times, 'not-a-knot')
    rng = np.random.default_rng(seed)
    values = np.c_[np.sin(15.0 * times), times ** 3, np.cos(30.0 * times), times]
    values = scale * values + rng.normal(0.0, 1e-3, values.shape)
    variances = np.array([1e-6, 4e-6, 0.0, 1e-6]) * rng.uniform(0.1, 10.0)
    z = np.ascontiguousarray(u.T @ values)
    grid = (smoothing.LIKELIHOOD_GRID if points == 0
            else np.sort(rng.uniform(-12.0, 12.0, points)))
    groups = ((0, 2), (2, 3), (1, 4), (0, 4), (3, 4))
    found = _kernel.likeliest(p, z, variances, groups, grid, smoothing.NULL_EIGENVALUE)
    expected = _whole_grid_pick(p, z, variances, groups, grid)
    assert [x if x == x else 'nan' for x in found] == [x if x == x else 'nan' for x in expected]


def test_the_kernels_weight_search_refuses_bad_input() -> None:
    """Wrong shapes or types and bounds outside the columns raise; no penalty gives NaN."""
    p, z, v = np.ones(5), np.ones((5, 2)), np.ones(2)
    grid = smoothing.LIKELIHOOD_GRID
    for args in ((p, np.ones((4, 2)), v, ((0, 2),)), (p, z, v, ((0, 3),)),
                 (p, z, v, ((1, 0),)), (p, z, v, ('ab',)), (p.astype(np.float32), z, v, ())):
        with pytest.raises(ValueError):
            _kernel.likeliest(*args, grid, smoothing.NULL_EIGENVALUE)
    assert np.isnan(_kernel.likeliest(np.zeros(5), z, v, ((0, 2),), grid, 1e-9)[0])


@settings(max_examples=examples(60), deadline=None)
@given(steps=st.lists(st.floats(0.001, 0.02), min_size=4, max_size=40),
       offset=st.floats(0.0, 1e4), seed=st.integers(0, 2 ** 16))
def test_third_jumps_are_the_interpolants_third_derivative_jumps(steps, offset, seed) -> None:
    """
    Brute force: J @ values are the jumps of the not-a-knot spline's third derivative.

    The spline through random values from its slopes (``not_a_knot_slopes``), each piece's
    third derivative from its Hermite form, their differences at knots 2 .. n - 3; zero on a
    cubic; none below 5 stamps.
    """
    times = offset + _times(steps)
    n = len(times)
    jumps = smoothing.third_jumps(times)
    assert jumps.shape == (max(n - 4, 0), n)
    if n < 5:
        return
    assert np.array_equal(smoothing.third_jumps(list(times)), jumps)
    values = np.random.default_rng(seed).normal(0.0, 1.0, n)
    slopes = smoothing.not_a_knot_slopes(times, values[:, None])[:, 0]
    h = np.diff(times)
    third = [6.0 * (slopes[i] + slopes[i + 1] - 2.0 * (values[i + 1] - values[i]) / h[i])
             / h[i] ** 2 for i in range(n - 1)]
    expected = [third[i] - third[i - 1] for i in range(2, n - 2)]
    size = np.abs(third).max()
    assert np.allclose(jumps @ values, expected, rtol=0.0, atol=1e-9 * size)
    cubic = 1.0 + 2.0 * (times - offset) - 3.0 * (times - offset) ** 3
    assert np.allclose(jumps @ cubic, 0.0, atol=1e-7 * np.abs(jumps).max())


@settings(max_examples=examples(60), deadline=None)
@given(steps=st.lists(st.floats(1e-4, 0.02), min_size=1, max_size=40),
       offset=st.floats(-1e3, 1e3), count=st.integers(1, 5))
def test_the_kernels_polynomial_basis(steps, offset, count) -> None:
    """Orthonormal columns spanning the polynomials of degree < count; out-of-range refused."""
    times = offset + _times(steps)
    n = len(times)
    if count > n:
        with pytest.raises(ValueError, match='count'):
            _kernel.polynomial_basis(times.tolist(), count)
        return
    basis = np.frombuffer(_kernel.polynomial_basis(times.tolist(), count)).reshape(n, count)
    assert np.allclose(basis.T @ basis, np.eye(count), rtol=0.0, atol=1e-12)
    scaled = (times - times.mean()) / np.abs(times - times.mean()).max()
    powers = np.vander(scaled, count, increasing=True)
    assert np.allclose(basis @ (basis.T @ powers), powers, rtol=0.0, atol=1e-9)


@settings(max_examples=examples(40), deadline=None)
@given(steps=steps, seed=st.integers(0, 2 ** 16), log_weight=st.floats(-12.0, 12.0))
def test_the_kernels_smoothed_values_are_the_eigenvectors_products(steps, seed,
                                                                   log_weight) -> None:
    """``_kernel.smoothed`` is u (f z) per group (numpy's), y where NaN or zero variance."""
    times = _times(steps)
    p, u = penalty_eigen(times, 'not-a-knot')
    rng = np.random.default_rng(seed)
    y = rng.normal(0.0, 1.0, (len(times), 5))
    variances = np.array([1e-6, 0.0, 1e-6, 1e-6, 1e-6])
    z = u.T @ y
    bounds = ((0, 2), (2, 3), (3, 5))
    weights = (10.0 ** log_weight, np.inf, np.nan)
    fitted = np.frombuffer(_kernel.smoothed(p, u, z, y, variances, bounds, weights,
                                            smoothing.NULL_EIGENVALUE)).reshape(y.shape)
    factors = 1.0 / (1.0 + weights[0] * p)
    assert np.allclose(fitted[:, 0], u @ (factors * z[:, 0]), rtol=1e-12, atol=1e-12)
    assert np.array_equal(fitted[:, 1], y[:, 1])  # zero variance: as given
    null = (p <= smoothing.NULL_EIGENVALUE * p.max()).astype(float)
    assert np.allclose(fitted[:, 2], u @ (null * z[:, 2]), rtol=1e-12, atol=1e-12)
    assert np.array_equal(fitted[:, 3:], y[:, 3:])  # NaN: nothing smoothed


def test_the_kernels_smoothed_values_refuse_bad_input() -> None:
    """Shapes that do not match, bounds outside the columns, a weight short: ValueErrors."""
    p, u, y, v = np.ones(4), np.eye(4), np.ones((4, 2)), np.ones(2)
    for args in ((p, np.eye(3), y, y, v, ((0, 2),), (1.0,)),
                 (p, u, y, np.ones((4, 3)), v, ((0, 2),), (1.0,)),
                 (p, u, y, y, v, ((0, 3),), (1.0,)),
                 (p, u, y, y, v, ((0, 2),), ()),
                 (p, u, y.astype(np.float32), y, v, ((0, 2),), (1.0,))):
        with pytest.raises(ValueError):
            _kernel.smoothed(*args, smoothing.NULL_EIGENVALUE)


@settings(max_examples=examples(60), deadline=None)
@given(steps=steps, start=st.floats(0.0, 2e9))
def test_the_kernels_step_key_is_numpys_rounded_steps(steps, start) -> None:
    """``_kernel.step_key`` is ``rint(diff(t) * 1e9)`` to the bit; None under 1 ns or 2 stamps."""
    times = start + _times(steps)
    expected = np.rint(np.diff(times) * 1e9)
    found = _kernel.step_key(times.tolist())
    if expected.min() >= 1.0:
        assert found == expected.tobytes()
    else:
        assert found is None
    assert _kernel.step_key([1.0]) is None
    assert _kernel.step_key([1.0, 1.0 + 1e-10]) is None


@settings(max_examples=examples(60), deadline=None)
@given(steps=steps)
def test_the_kernels_penalty_is_the_scaled_third_jumps_product(steps) -> None:
    """``penalty(..., 'not-a-knot')`` is (m^3 J)^T (m^3 J), J the third jumps, m the mean step."""
    times = _times(steps)
    jumps = third_jumps(times) * float(np.mean(np.diff(times))) ** 3
    expected = jumps.T @ jumps
    found = penalty(times, 'not-a-knot')
    assert np.array_equal(found, found.T)
    assert np.allclose(found, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    assert np.array_equal(penalty(times[:4], 'not-a-knot'), np.zeros((4, 4)))


@settings(max_examples=examples(60), deadline=None)
@given(steps=steps, degree=st.sampled_from([1, 3]))
def test_the_kernels_null_space_is_the_projection_written_out(steps, degree) -> None:
    """``_kernel.beside_null``: the basis in front, the rest less its parts, the leak returned."""
    times = _times(steps)
    p, u = np.linalg.eigh(penalty(times, 'not-a-knot'))
    count = degree + 1
    basis = np.frombuffer(_kernel.polynomial_basis(times.tolist(), count)).reshape(-1, count)
    parts = basis.T @ u[:, count:]
    rough = u[:, count:] - basis @ parts
    expected_p = p.copy()
    expected_p[:count] = 0.0
    expected_p[expected_p <= smoothing.NULL_EIGENVALUE * expected_p[-1]] = 0.0
    leak = _kernel.beside_null(p, u, times.tolist(), count, smoothing.NULL_EIGENVALUE)
    assert leak == pytest.approx(float((parts * parts).sum(axis=0).max()), rel=1e-9, abs=1e-20)
    assert np.array_equal(u[:, :count], basis)
    assert np.allclose(u[:, count:], rough, atol=1e-13)
    assert np.array_equal(p, expected_p)
    with pytest.raises(ValueError):
        _kernel.beside_null(p, u[:-1], times.tolist(), count, 1e-9)


@settings(max_examples=examples(30), deadline=None)
@seven_columns
def test_smoother_weights_given_are_the_weights_searched(steps, sigmas, seed) -> None:
    """
    ``smoother_weights``: given to the rows and shifts, their answers to the bit.

    One weight per group, NaN where no column is noisy; ``smoother_rows`` and
    ``smoother_shifts`` given them answer as with their own search.
    """
    times, values, variances, rng = _seven_columns(steps, sigmas, seed)
    rows = rng.normal(0.0, 1.0, (2, len(times)))
    weights = smoother_weights(times, values, variances, groups=GROUPS)
    assert len(weights) == len(GROUPS)
    for group, weight in zip(GROUPS, weights):
        assert math.isnan(weight) == (not np.any(variances[group] > 0.0))
    assert np.array_equal(smoother_rows(times, rows, values, variances, groups=GROUPS),
                          smoother_rows(times, rows, values, variances, groups=GROUPS,
                                        weights=weights))
    reference = rng.normal(0.0, 1.0, rows.shape)
    for searched, handed in zip(
            smoother_shifts(times, rows, values, variances, groups=GROUPS, reference=reference),
            smoother_shifts(times, rows, values, variances, groups=GROUPS, reference=reference,
                            weights=weights)):
        assert np.array_equal(searched, handed)
