"""Tests for the plain per-coordinate cubic spline every model is compared with."""

from dataclasses import replace
from typing import Optional, Tuple

from baseball_collision.tools.reference import (
    reference_result, reference_truth, reference_within_rules, smoothing_spline,
    speeds_before)
from baseball_collision.tools.sim import make_scenario, sample, Samples
import numpy as np
import pytest


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


def _held_after(samples: Samples, ends_ns: Tuple[int, int], inclusive: bool) -> Samples:
    """Return the samples with each stream's from its end on (or after it) held still."""
    def held(stamps: np.ndarray, values: np.ndarray, end_ns: int) -> np.ndarray:
        first = int(np.searchsorted(stamps, end_ns, side='left' if inclusive else 'right'))
        out = values.copy()
        out[first:] = values[first - 1]
        return out
    return replace(
        samples, ball_positions=held(samples.ball_stamps_ns, samples.ball_positions, ends_ns[0]),
        knobs=held(samples.bat_stamps_ns, samples.knobs, ends_ns[1]),
        tips=held(samples.bat_stamps_ns, samples.tips, ends_ns[1]))


@pytest.mark.parametrize('family, rate_hz, ball_rate_hz',
                         [('plane', 90.0, None), ('braking', 90.0, None), ('plane', 360.0, 60.0)])
def test_the_reference_within_rules_reads_no_sample_after_the_contact(
        family: str, rate_hz: float, ball_rate_hz: Optional[float]) -> None:
    """Time and spot read nothing after a closing frame; the speeds nothing from the contact."""
    scenario = make_scenario('barrel', np.random.default_rng(5), family=family)
    samples = sample(scenario, rate_hz, np.random.default_rng(0), jitter_s=2e-4,
                     ball_rate_hz=ball_rate_hz)
    found = reference_within_rules(scenario, samples)
    assert found.contact
    contact_ns = samples.start_ns + int(np.ceil(found.time_s * 1e9))
    closing_ns = tuple(int(stamps[np.searchsorted(stamps, contact_ns)])
                       for stamps in (samples.ball_stamps_ns, samples.bat_stamps_ns))
    after_closing = reference_within_rules(scenario, _held_after(samples, closing_ns, False))
    assert after_closing.time_s == found.time_s
    assert after_closing.distance_from_tip_m == found.distance_from_tip_m
    speeds = speeds_before(samples, found.time_s, found.bat_fraction)
    assert speeds == (found.sweet_spot_speed_mps, found.bat_speed_at_contact_mps,
                      found.ball_speed_mps)
    held = _held_after(samples, (contact_ns, contact_ns), True)
    assert speeds_before(held, found.time_s, found.bat_fraction) == speeds
    whole = reference_truth(scenario, samples)
    assert whole.sweet_spot_speed_mps != found.sweet_spot_speed_mps


def test_the_reference_within_rules_converges_as_a_cubic() -> None:
    """Exact samples: its speed error falls about 8x per halving of the step (third order)."""
    scenario = make_scenario('barrel', np.random.default_rng(3), family='tilted')
    errors = []
    for rate in (180.0, 360.0, 720.0):
        result = reference_result(scenario, sample(scenario, rate, np.random.default_rng(0),
                                                   jitter_s=0.0), within_rules=True)
        assert result.detected and result.false_impacts == 0
        errors.append(abs(result.sweet_spot_speed_error))
    assert errors[2] < errors[1] / 4.0 < errors[0] / 16.0
    assert abs(result.time_error_s) < 1e-6


def test_the_reference_within_rules_ends_a_cycle_of_cuts_on_the_contact() -> None:
    """A noisy end-cap graze: cut at its closing frame no contact, a frame later one before it."""
    scenario = make_scenario('end_cap', np.random.default_rng(1002), family='tilted')
    samples = sample(scenario, 90.0, np.random.default_rng(2), jitter_s=2e-4, grid_s=1e-3,
                     noise_m=1e-3)
    found = reference_within_rules(scenario, samples, 1e-3)
    assert found.contact
    assert abs(found.time_s - scenario.truth.time_s) < 1e-4
