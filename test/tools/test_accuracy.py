"""The accuracy evaluation: per simulated pitch against its truth, and summaries."""

from dataclasses import replace
import math

from baseball_collision.core.detector import DetectorConfig, Impact, NearMiss
from baseball_collision.tools.accuracy import compare_pitch, run_scenario, summarize
from baseball_collision.tools.sim import make_scenario
import numpy as np
import pytest


def _impact(stamp_ns: int, from_tip: float, speed: float) -> Impact:
    zero = (0.0, 0.0, 0.0)
    return Impact(
        stamp_ns=stamp_ns, point=zero, normal=(0.0, 0.0, 1.0), bat_fraction=0.9,
        distance_from_knob_m=0.8, distance_from_tip_m=from_tip, feature='side',
        bat_velocity=zero, bat_angular_velocity=zero, sweet_spot_velocity=zero,
        sweet_spot_speed_mps=speed, bat_speed_at_contact_mps=speed, ball_velocity=zero,
        ball_speed_mps=40.0, relative_normal_speed_mps=70.0, attack_angle_deg=5.0,
        ball_position=zero, knob=zero, tip=zero, model='spline', interval_start_ns=0,
        interval_end_ns=1, velocities_from_history=True, initially_overlapping=False)


HIT = {'name': 'p1', 'kind': 'barrel', 'contact': True, 'stamp_ns': 1_000_000,
       'distance_from_tip_m': 0.15, 'sweet_spot_speed_mps': 30.0, 'min_gap_m': -0.02}
MISS = {'name': 'p2', 'kind': 'miss_over', 'contact': False, 'min_gap_m': 0.05}


def test_compare_pitch_measures_the_first_impact() -> None:
    """Errors are detected minus true, from the first impact; later ones are false."""
    result = compare_pitch(HIT, [_impact(1_000_020, 0.152, 30.3), _impact(1_500_000, 0.1, 1.0)])
    assert result.detected and result.false_impacts == 1
    assert result.time_error_s == pytest.approx(20e-9)
    assert result.location_error_m == pytest.approx(0.002)
    assert result.sweet_spot_speed_error == pytest.approx(0.01)
    assert result.ball_speed_error is None  # the truth gives no ball speed
    with_ball = compare_pitch(dict(HIT, ball_speed_mps=50.0), [_impact(1_000_020, 0.15, 30.0)])
    assert with_ball.ball_speed_error == pytest.approx(40.0 / 50.0 - 1.0)
    assert summarize([with_ball])['ball_speed_error_pct_p99'] == pytest.approx(20.0)
    assert compare_pitch(HIT, []).detected is False


def test_compare_pitch_on_a_miss() -> None:
    """On a miss every impact is false; a near miss's gap is compared with the truth."""
    assert compare_pitch(MISS, [_impact(1, 0.1, 30.0)]).false_impacts == 1
    miss = NearMiss(stamp_ns=5, gap_m=0.051, gap_vector=(0.0, 0.0, 0.051),
                    ball_position=(0.0, 0.0, 0.0), bat_fraction=0.8, distance_from_tip_m=0.1)
    result = compare_pitch(MISS, [], [miss])
    assert not result.detected and result.near_miss_gap_error_m == pytest.approx(0.001)


def test_summarize_counts_only_clear_cut_pitches() -> None:
    """Recall and precision skip pitches within the clearance; errors are absolute values."""
    unclear = dict(HIT, min_gap_m=-5e-5)
    results = [compare_pitch(HIT, [_impact(1_000_010, 0.15, 30.0)]),
               compare_pitch(HIT, []),
               compare_pitch(unclear, []),
               compare_pitch(MISS, [_impact(7, 0.1, 30.0)])]
    summary = summarize(results)
    assert summary['contacts'] == 2 and summary['recall'] == 0.5
    assert summary['precision'] == 0.5 and summary['false_impacts'] == 1
    assert summary['time_error_us_max'] == pytest.approx(0.01)
    assert math.isnan(summarize([])['recall'])


def test_summarize_counts_errors_within_the_reported_sigmas() -> None:
    """Coverage compares each error with its own sigma; the spot's is from the knob."""
    truth = dict(HIT, distance_from_knob_m=0.79)
    sigmas = {'time_uncertainty_s': 15e-9, 'distance_from_knob_uncertainty_m': 0.004,
              'sweet_spot_speed_uncertainty_mps': 0.2}
    inside = replace(_impact(1_000_010, 0.15, 30.1), **sigmas)  # 0.67, 2.5, 0.5 sigma
    outside = replace(_impact(1_000_025, 0.15, 30.5), **sigmas)  # 1.67, 2.5, 2.5 sigma
    results = [compare_pitch(truth, [inside]), compare_pitch(truth, [outside])]
    assert results[0].knob_distance_error_m == pytest.approx(0.01)
    summary = summarize(results)
    assert summary['time_within_1_sigma'] == 0.5 and summary['time_within_2_sigma'] == 1.0
    assert summary['location_within_1_sigma'] == 0.0
    assert summary['location_within_2_sigma'] == 0.0
    assert summary['speed_within_1_sigma'] == 0.5 and summary['speed_within_2_sigma'] == 0.5
    assert math.isnan(summarize([compare_pitch(HIT, [inside])])['location_within_1_sigma'])


def test_run_scenario_finds_a_barrel_hit() -> None:
    """A simulated barrel hit at 360 Hz is found within microseconds of the truth."""
    scenario = make_scenario('barrel', np.random.default_rng(3))
    events, result = run_scenario(scenario, 360.0, DetectorConfig(model='spline'),
                                  np.random.default_rng(4), jitter_s=2e-4, grid_s=1e-3)
    assert result.detected and result.false_impacts == 0
    assert abs(result.time_error_s) < 20e-6
    assert any(isinstance(e, Impact) for e in events)
