"""Tests for ``tracker_noise: auto``: each stream's noise estimated from its own samples."""

import math

from baseball_collision.core.detector import AUTO_NOISE, Detector, DetectorConfig
from baseball_collision.core.detector.noise import (
    divided_difference_weights, MIN_RESIDUALS, NoiseEstimate)
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample
from baseball_collision.tools.sim import FAMILIES, make_scenario, sample
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples


def _session(bat_input: str, rate: float, noise_m: float, seed: int) -> Detector:
    """Return a detector (auto noise) after one pitch of each swing family, 1 s apart."""
    detector = Detector(DetectorConfig(bat_input=bat_input, model='c2',
                                       tracker_noise=AUTO_NOISE))
    for i, family in enumerate(FAMILIES):
        scenario = make_scenario('barrel', np.random.default_rng(seed + i), family=family)
        samples = sample(scenario, rate, np.random.default_rng(seed + i), jitter_s=2e-4,
                         grid_s=1e-3, noise_m=noise_m, marker_spread_m=0.3 if noise_m else None)
        for stamp, role, values in samples.messages(bat_input):
            detector.add(role, stamp + i * 1_000_000_000, values)
    detector.finish()
    return detector


@pytest.mark.parametrize('noise_mm', [0.5, 1.0, 2.0])
@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_auto_recovers_the_noise_of_knob_tip_swings(rate: float, noise_mm: float) -> None:
    """
    Five pitches (one per family) at 90 and 360 Hz: ball and bat within 25 % of the noise.

    (The estimate is a median over 100-384 residuals, whose spread is about 1.25 / sqrt(n):
    8-13 % 1-sigma; 25 % is 2-3 sigma.)
    """
    detector = _session('points', rate, noise_mm * 1e-3, 30)
    for stream in (detector._ball, detector._bat):
        assert stream.noise == pytest.approx(noise_mm * 1e-3, rel=0.25), stream.name


@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_auto_finds_no_noise_on_clean_swings(rate: float) -> None:
    """Exact samples: the ball's and the knob-tip bat's estimates are below 1 um."""
    detector = _session('points', rate, 0.0, 40)
    assert detector._ball.noise < 1e-6 and detector._bat.noise < 1e-6


def test_auto_from_poses_is_close_at_360_hz_and_biased_up_by_the_swing_at_90() -> None:
    """
    A pose's position: within 25 % at 360 Hz with 1 mm, clean under 0.05 mm.

    At 90 Hz the swing's own fourth differences show as 0.1-0.4 mm (the module docstring).
    """
    assert _session('pose', 360.0, 1e-3, 50)._bat.noise == pytest.approx(1e-3, rel=0.25)
    assert _session('pose', 360.0, 0.0, 50)._bat.noise < 5e-5
    assert 5e-5 < _session('pose', 90.0, 0.0, 50)._bat.noise < 5e-4


def test_no_estimate_until_enough_residuals_and_none_across_a_break() -> None:
    """Fewer than MIN_RESIDUALS residuals: 0; a new segment restarts the five samples."""
    rng = np.random.default_rng(1)
    stream, estimate = Stream('ball'), NoiseEstimate('point')
    for i in range(4 + MIN_RESIDUALS // 3):
        stream.append(i * 0.01, i, tuple(rng.normal(0.0, 1e-3, 3)), i == 0)
        found = estimate.update(stream)
        assert (found > 0.0) == (3 * max(0, i - 3) >= MIN_RESIDUALS)
    stream.append(1.0, 99, (0.0, 0.0, 0.0), True)
    before = len(estimate.residuals)
    estimate.update(stream)
    assert len(estimate.residuals) == before


def test_length_residuals_are_half_the_length_change() -> None:
    """A knob-tip bat: the residual is half the change of its length, whatever it moved."""
    stream, estimate = Stream('bat'), NoiseEstimate('length')
    stream.append(0.0, 1, BatSample((0.0, 0.0, 0.0), (0.8, 0.0, 0.0)), True)
    stream.append(0.01, 2, BatSample((1.0, 2.0, 0.0), (1.0, 2.0, 0.802)), False)
    estimate.update(stream)
    assert list(estimate.residuals) == [pytest.approx(0.001)]


@settings(max_examples=examples(60), deadline=None)
@given(steps=st.lists(st.floats(0.001, 0.02), min_size=4, max_size=4),
       coefficients=st.lists(st.floats(-100.0, 100.0), min_size=4, max_size=4))
def test_fourth_differences_vanish_on_cubics_and_have_unit_noise_gain(steps,
                                                                      coefficients) -> None:
    """On uneven stamps the weights kill any cubic; normalised, noise keeps its variance."""
    times = np.concatenate([[0.0], np.cumsum(steps)])
    weights = divided_difference_weights(times)
    cubic = np.polyval(coefficients, times)
    gain = math.sqrt(float(weights @ weights))
    assert abs(weights @ cubic) / gain <= 1e-9 * (1.0 + np.abs(cubic).max())
    rng = np.random.default_rng(3)
    noise = rng.normal(0.0, 1.0, (20000, 5))
    assert np.std(noise @ weights / gain) == pytest.approx(1.0, rel=0.03)
