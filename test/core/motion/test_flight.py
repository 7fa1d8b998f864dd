"""Tests for the ball's flight fit: the polynomials, their spread, the chi-square guard."""

from baseball_collision.core.motion.flight import (
    chi_square_bound, fit_flight, flight_or_none)
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples


def _pitch(times: np.ndarray) -> np.ndarray:
    """Return a ball under gravity with a slowly changing drag and spin (m): not a polynomial."""
    t = np.asarray(times, dtype=float)
    return np.stack([0.3 + 1.5 * t + 0.4 * np.sin(0.5 * t), 16.0 - 38.0 * t + 4.0 * t * t
                     - 0.8 * t ** 3, 1.8 - 1.0 * t - 4.9 * t * t], axis=1)


def _stamps(rate: float, count: int, seed: int) -> np.ndarray:
    """Return uneven stamps (s) near a rate."""
    return np.cumsum(np.random.default_rng(seed).uniform(0.8, 1.2, count)) / rate


@pytest.mark.parametrize('dof, quantile', [(10, 29.588), (30, 59.703), (100, 149.449)])
def test_chi_square_bound_against_tables(dof: int, quantile: float) -> None:
    """Wilson-Hilferty's bound is the tabled 0.999 quantile within 1.5 %."""
    assert chi_square_bound(dof) == pytest.approx(quantile, rel=0.015)


def test_polynomials_are_reproduced_exactly() -> None:
    """A parabola through degree 2, a cubic through degree 3: values and rates to rounding."""
    t = _stamps(90.0, 14, 1)
    parabola = np.stack([2.0 - 30.0 * t + 3.0 * t * t, 0.5 * t, 1.0 - 4.9 * t * t], axis=1)
    cubic = parabola + np.stack([0.0 * t, 7.0 * t ** 3, -2.0 * t ** 3], axis=1)
    for values, degree in ((parabola, 2), (cubic, 3)):
        fit = fit_flight(t, values, 1e-3, degree)
        assert fit.chi_square < 1e-12 and fit.free and fit.excess == 1.0
        exact = np.polyfit(t, values, degree)
        late = t[-1] + 0.011
        assert np.allclose(fit.at(late), [np.polyval(exact[:, c], late) for c in range(3)],
                           atol=1e-9)
        slope = [np.polyval(np.polyder(exact[:, c]), late) for c in range(3)]
        assert np.allclose(fit.velocity(late), slope, atol=1e-7)
        value, rate = fit.weights(late)
        assert np.allclose(value @ values, fit.at(late), atol=1e-9)
        assert np.allclose(rate @ values, fit.velocity(late), atol=1e-7)


@pytest.mark.parametrize('degree', [2, 3])
def test_spread_is_what_the_weights_say(degree: int) -> None:
    """Over 400 noisy draws the errors at the window's end have the weights' sigma (+-10 %)."""
    t = _stamps(360.0, 54, 2)
    sigma = 1e-3
    truth = t * 0.0 + 1.0  # a ball at rest is in free flight too
    rng = np.random.default_rng(3)
    errors, rates = [], []
    for _ in range(400):
        values = np.stack([truth] * 3, axis=1) + rng.normal(0.0, sigma, (len(t), 3))
        fit = fit_flight(t, values, sigma, degree)
        errors.append(fit.at(t[-1])[0] - 1.0)
        rates.append(fit.velocity(t[-1])[0])
    value, rate = fit.weights(t[-1])
    assert np.std(errors) == pytest.approx(sigma * np.linalg.norm(value), rel=0.1)
    assert np.std(rates) == pytest.approx(sigma * np.linalg.norm(rate), rel=0.1)


def test_the_guard_passes_flight_and_fails_a_bounce() -> None:
    """0.15 s of a pitch at 1 mm passes in about 99.9 % of draws; a bounce or a hand fail."""
    t = _stamps(120.0, 18, 4)
    sigma = 1e-3
    rng = np.random.default_rng(5)
    passed = [fit_flight(t, _pitch(t) + rng.normal(0.0, sigma, (len(t), 3)), sigma).free
              for _ in range(300)]
    assert np.mean(passed) >= 0.98
    bounced = _pitch(t)
    after = t > t[12]
    bounced[after, 1] = bounced[12, 1] + 20.0 * (t[after] - t[12])  # back toward the pitcher
    held = np.stack([0.02 * np.sin(25.0 * t), 0.0 * t, 1.0 + 0.02 * np.cos(25.0 * t)], axis=1)
    for values in (bounced, held):
        noisy = values + rng.normal(0.0, sigma, values.shape)
        assert not fit_flight(t, noisy, sigma).free
        assert flight_or_none(t, noisy, sigma, 2, 8) is None
    assert flight_or_none(t, _pitch(t), sigma, 2, 8) is not None
    assert flight_or_none(t[:7], _pitch(t[:7]), sigma, 2, 8) is None  # too few samples


def test_an_untold_noise_fails_the_guard() -> None:
    """Told 0.2 mm when the samples carry 1 mm, the residuals are far too large."""
    t = _stamps(90.0, 13, 6)
    noisy = _pitch(t) + np.random.default_rng(7).normal(0.0, 1e-3, (len(t), 3))
    assert not fit_flight(t, noisy, 2e-4).free


def test_a_noise_too_small_to_square_fails_the_guard_without_a_crash() -> None:
    """Told 1e-300 m (its square is 0): the guard turns the fit away, dividing by nothing."""
    t = _stamps(90.0, 13, 6)
    assert flight_or_none(t, _pitch(t), 1e-300, 2, 5) is None
    assert flight_or_none(t, _pitch(t), 1e-3, 2, 5) is not None  # (the same pitch, told 1 mm)


@pytest.mark.parametrize('times, values, sigma, degree', [
    ([0.0, 0.1, 0.2], np.zeros((3, 3)), 1e-3, 2),
    ([0.0, 0.1, 0.2, 0.3], np.zeros((4, 2)), 1e-3, 2),
    ([0.0, 0.1, 0.2, 0.3], np.zeros((4, 3)), 0.0, 2),
    ([0.0, 0.1, 0.1, 0.3], np.zeros((4, 3)), 1e-3, 2),
])
def test_bad_input_raises(times, values, sigma: float, degree: int) -> None:
    """Too few samples, a wrong shape, no noise or stamps that do not increase raise."""
    with pytest.raises(ValueError):
        fit_flight(times, values, sigma, degree)
    with pytest.raises(ValueError):
        chi_square_bound(0)


def test_tolerance_admits_a_noise_estimated_somewhat_low() -> None:
    """Told 0.8 mm for 1 mm over 54 samples, the exact bound fails and a 1.25 tolerance passes."""
    t = _stamps(360.0, 54, 8)
    noisy = _pitch(t) + np.random.default_rng(9).normal(0.0, 1e-3, (len(t), 3))
    fit = fit_flight(t, noisy, 8e-4)
    assert not fit.free and fit.passes(1.25)
    assert flight_or_none(t, noisy, 8e-4, 2, 8) is None
    assert flight_or_none(t, noisy, 8e-4, 2, 8, 1.25) is not None
    assert fit.excess == pytest.approx(np.sqrt(fit.chi_square / fit.dof))


@settings(max_examples=examples(100), deadline=None)
@given(count=st.integers(4, 60), degree=st.integers(2, 3), seed=st.integers(0, 2 ** 32 - 1),
       start=st.floats(0.0, 2e9))
def test_fit_is_numpys_least_squares(count: int, degree: int, seed: int, start: float) -> None:
    """Coefficients, residuals and the operator are numpy's least squares (SVD) to rounding."""
    rng = np.random.default_rng(seed)
    t = start + _stamps(rng.uniform(90.0, 360.0), count, seed)
    if count < degree + 2 or not np.all(np.diff(t) > 0.0):
        return
    values = rng.normal(0.0, 1.0, (count, 3))
    fit = fit_flight(t.tolist(), [tuple(row) for row in values.tolist()], 0.5, degree)
    tau = (t - 0.5 * (t[0] + t[-1])) / (0.5 * (t[-1] - t[0]))
    expected, residuals, _, _ = np.linalg.lstsq(tau[:, None] ** np.arange(degree + 1), values,
                                                rcond=None)
    assert np.allclose(fit.coefficients, expected, rtol=1e-9, atol=1e-9)
    assert fit.chi_square * 0.25 == pytest.approx(float(np.sum(residuals)), rel=1e-9, abs=1e-12)
    assert np.allclose(fit.solve @ values, expected, rtol=1e-8, atol=1e-8)
    assert fit.dof == 3 * (count - degree - 1)


def test_bunched_stamps_are_no_fit() -> None:
    """Stamps bunched to a rounding's width are rank deficient: fit_flight raises, no fit."""
    t = [1.0, 1.0 + 1e-15, 1.0 + 2e-15, 1.0 + 3e-15, 2.0]
    values = np.zeros((5, 3))
    with pytest.raises(ValueError, match='bunched'):
        fit_flight(t, values, 1e-3, 3)
    assert flight_or_none(t, values, 1e-3, 3, 4) is None


def test_a_sample_that_is_not_a_number_gives_no_fit() -> None:
    """A NaN coordinate makes the residuals NaN: the guard fails (no fit), nothing raises."""
    t = _stamps(360.0, 20, 4)
    values = _pitch(t)
    values[7, 1] = np.nan
    assert flight_or_none(t, values, 1e-3, 2, 8) is None
    assert not fit_flight(t, values, 1e-3).free


@settings(max_examples=examples(100), deadline=None)
@given(count=st.integers(5, 60), degree=st.integers(0, 5), seed=st.integers(0, 2 ** 32 - 1),
       at=st.floats(-0.5, 1.5))
def test_the_state_is_the_basis_row_combined_in_order(count: int, degree: int, seed: int,
                                                      at: float) -> None:
    """
    ``state`` (the kernel's) is the basis row and its rate combined as Python's sum, to the bit.

    Written out: ``_rows``' row at t, each coordinate's coefficients multiplied in order from
    the lowest power and summed from 0; ``at`` and ``velocity`` are its two halves.
    """
    rng = np.random.default_rng(seed)
    t = _stamps(rng.uniform(90.0, 360.0), count, seed)
    if count < degree + 2 or not np.all(np.diff(t) > 0.0):
        return
    fit = fit_flight(t.tolist(), rng.normal(0.0, 5.0, (count, 3)), 1e-3, degree)
    when = float(t[0] + at * (t[-1] - t[0]))
    value, rate = fit._rows(when)
    columns = fit.coefficients.T.tolist()
    expected = (tuple(sum(v * c for v, c in zip(value, column)) for column in columns),
                tuple(sum(r * c for r, c in zip(rate, column)) for column in columns))
    assert fit.state(when) == expected
    assert (fit.at(when), fit.velocity(when)) == expected


def test_a_state_of_columns_that_do_not_match_raises() -> None:
    """The kernel's ``flight_state``: 3 columns of one count of numbers, else a TypeError."""
    from baseball_collision.core.toi import _kernel
    with pytest.raises(TypeError):
        _kernel.flight_state([[1.0, 2.0], [1.0, 2.0]], 0.0, 1.0, 0.5)
    with pytest.raises(TypeError):
        _kernel.flight_state([[1.0, 2.0], [1.0], [1.0, 2.0]], 0.0, 1.0, 0.5)
    with pytest.raises(TypeError):
        _kernel.flight_state([[1.0, 'a'], [1.0, 2.0], [1.0, 2.0]], 0.0, 1.0, 0.5)
    with pytest.raises(TypeError):
        _kernel.flight_state([[]] * 3, 0.0, 1.0, 0.5)
    constant = _kernel.flight_state([[1.0], [2.0], [3.0]], 0.0, 1.0, 0.5)
    assert constant == ((1.0, 2.0, 3.0), (0.0, 0.0, 0.0))
