"""Tests for the plain per-coordinate cubic spline every model is compared with."""

from baseball_collision.tools.reference import reference_result, smoothing_spline
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np


def test_reference_finds_the_contact_of_a_densely_sampled_swing() -> None:
    """At 360 Hz without noise the reference's contact is within microseconds of the truth."""
    scenario = make_scenario('barrel', np.random.default_rng(3), family='tilted')
    samples = sample(scenario, 360.0, np.random.default_rng(0))
    result = reference_result(scenario, samples)
    assert result.detected and result.false_impacts == 0
    assert abs(result.time_error_s) < 5e-6
    assert abs(result.location_error_m) < 1e-3
    assert abs(result.sweet_spot_speed_error) < 1e-3


def test_smoothing_spline_leaves_residuals_the_size_of_the_noise() -> None:
    """Reinsch's spline with the known sigma: sum of squared residuals / sigma^2 ~ n."""
    rng = np.random.default_rng(1)
    times = np.cumsum(rng.uniform(0.004, 0.006, 60))
    truth = np.stack([np.sin(20.0 * times), times ** 2], axis=1)
    noisy = truth + rng.normal(0.0, 1e-3, truth.shape)
    fitted, _ = smoothing_spline(times, noisy, 1e-3)
    ratio = np.sum((noisy - fitted) ** 2, axis=0) / (1e-6 * len(times))
    assert np.allclose(ratio, 1.0, atol=0.05)
    assert np.sqrt(np.mean((fitted - truth) ** 2)) < 1e-3
