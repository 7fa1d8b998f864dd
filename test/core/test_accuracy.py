"""
Accuracy of the detector against continuous-time truth (simulated swings and pitches).

Each motion model runs on the same scenarios (every kind: barrel, end-cap and handle hits,
grazes, misses over and under), sampled like a tracker: timestamp jitter and a millisecond stamp
grid (uneven steps). The bounds are the goals of the package, so a regression fails here; the
full table over many more scenarios is ``benchmarks/bench_accuracy.py`` (see BENCHMARKS.md).
"""

from baseball_collision.core.detector import DetectorConfig
from baseball_collision.tools.accuracy import run_scenario, summarize
from baseball_collision.tools.sim import KINDS, make_scenario
import numpy as np
import pytest


@pytest.fixture(scope='module')
def scenarios() -> list:
    """Return five scenarios of every kind (fixed seed)."""
    rng = np.random.default_rng(2024)
    return [make_scenario(kind, rng) for kind in KINDS for _ in range(5)]


def _summary(scenarios: list, model: str, rate_hz: float, noise_m: float = 0.0,
             bat_input: str = 'pose') -> dict:
    config = DetectorConfig(model=model, bat_input=bat_input)
    results = [run_scenario(scenario, rate_hz, config, np.random.default_rng(index),
                            jitter_s=2e-4, grid_s=1e-3, noise_m=noise_m)[1]
               for index, scenario in enumerate(scenarios)]
    return summarize(results)


def test_spline_meets_the_goals_at_90_hz(scenarios: list) -> None:
    """Best model at 90 Hz: recall and precision 1, p99 time <= 50 us, spot 5 mm, speed 1%."""
    summary = _summary(scenarios, 'spline', 90.0)
    assert summary['contacts'] == 20
    assert summary['recall'] == 1.0 and summary['precision'] == 1.0
    assert summary['time_error_us_p99'] <= 50.0
    assert summary['location_error_mm_p99'] <= 5.0
    assert summary['sweet_spot_speed_error_pct_p99'] <= 1.0


@pytest.mark.parametrize('bat_input', ['pose', 'points'])
def test_rigid_at_360_hz_is_close_to_exact(scenarios: list, bat_input: str) -> None:
    """The live default at 360 Hz, from poses or knob/tip: microseconds and sub-millimetre."""
    summary = _summary(scenarios, 'rigid', 360.0, bat_input=bat_input)
    assert summary['recall'] == 1.0 and summary['precision'] == 1.0
    assert summary['time_error_us_p99'] <= 20.0
    assert summary['location_error_mm_p99'] <= 1.0
    assert summary['sweet_spot_speed_error_pct_p99'] <= 1.5


def test_the_seed_chord_model_is_worse_at_90_hz(scenarios: list) -> None:
    """The seed's linear chord model places contacts late and centimetres off at 90 Hz."""
    linear = _summary(scenarios, 'linear', 90.0)
    spline = _summary(scenarios, 'spline', 90.0)
    assert linear['location_error_mm_p99'] > 5.0 * max(spline['location_error_mm_p99'], 1.0)
    assert linear['time_error_us_p99'] > 100.0
    assert linear['precision'] == 1.0  # worse, but it does not invent contacts


def test_tracking_noise_degrades_gracefully(scenarios: list) -> None:
    """With 1 mm position noise at 360 Hz every contact is still found, spot within 1 cm."""
    summary = _summary(scenarios, 'spline', 360.0, noise_m=1e-3)
    assert summary['recall'] == 1.0 and summary['precision'] == 1.0
    assert summary['time_error_us_p99'] <= 300.0
    assert summary['location_error_mm_p99'] <= 10.0
    assert summary['sweet_spot_speed_error_pct_p99'] <= 3.0


def test_look_ahead_does_not_bend_a_braking_impact_late() -> None:
    """
    Issue 11's braking check: the c2 look-ahead fit is no later than the re-fit would be.

    On swings whose bat brakes within 1-3 ms after contact (the ``braking`` family, 90 Hz,
    points), a re-fit from the samples up to the interval's closing frame is the look-ahead-0
    fit itself; the fits with 1 and 2 frames of look-ahead must be biased late by no more than
    10 us beyond it (measured here +35, +41, +40 us; over bench_accuracy's 64 braking
    scenarios +23 for look-ahead 0 and +21 for 2), every bias within 0.1 ms: the late bias
    comes from the braked closing frame, which every fit of the interval holds, not from the
    look-ahead.
    """
    rng = np.random.default_rng(11)
    scenarios = [make_scenario(kind, rng, family='braking')
                 for kind in ('barrel', 'end_cap', 'handle') for _ in range(4)]
    bias = {}
    for look_ahead in (0, 1, 2):
        config = DetectorConfig(model='c2', bat_input='points', look_ahead=look_ahead)
        results = [run_scenario(scenario, 90.0, config, np.random.default_rng(index),
                                jitter_s=2e-4, grid_s=1e-3)[1]
                   for index, scenario in enumerate(scenarios)]
        summary = summarize(results)
        assert summary['contacts'] == 12 and summary['recall'] == 1.0
        bias[look_ahead] = summary['time_error_us_mean']
    assert all(abs(value) <= 100.0 for value in bias.values()), bias
    assert bias[0] > 0.0  # the braked closing frame makes every fit a little late
    assert bias[1] <= bias[0] + 10.0 and bias[2] <= bias[0] + 10.0, bias
