"""Tests for baseball_collision.tools.sim.simulation: pitch, swing, scenario truth and sampling."""

import json
import math

from baseball_collision.core.bat import PoseBatGeometry, WOOD_BAT_34
from baseball_collision.core.geometry import quaternion_to_matrix
from baseball_collision.errors import ToolError
from baseball_collision.tools.sim import (
    compute_truth, GRAVITY, KINDS, make_scenario, MPH, Pitch, sample, Scenario, Swing, truth_dict)
import numpy as np
import pytest

SEEDS = range(20)
START_NS = 1_700_000_000_123_456_789


def _scenario(kind: str, seed: int) -> Scenario:
    return make_scenario(kind, np.random.default_rng(seed))


@pytest.fixture(scope='module')
def scenarios() -> dict:
    """Twenty scenarios of every kind (seeds 0-19)."""
    return {kind: [_scenario(kind, seed) for seed in SEEDS] for kind in KINDS}


# ----------------------------------------------------------------------------------------------
# Pitch


def test_pitch_without_drag_is_the_parabola() -> None:
    """With drag off, RK4 + Hermite reproduce the closed form to round-off."""
    p0, v0 = np.array([0.3, 16.8, 1.8]), np.array([-0.5, -40.0, -1.0])
    pitch = Pitch(tuple(p0), tuple(v0), -0.3, duration=0.5, drag=False)
    t = np.random.default_rng(0).uniform(-0.3, 0.2, 500)
    s = (t + 0.3)[:, None]
    g = np.array([0.0, 0.0, -GRAVITY])
    assert np.abs(pitch.position(t) - (p0 + v0 * s + 0.5 * g * s * s)).max() < 1e-11
    assert np.abs(pitch.velocity(t) - (v0 + g * s)).max() < 1e-10
    assert pitch.position(-0.3) == pytest.approx(p0, abs=1e-15)
    assert pitch.position(0.1).shape == (3,)


def test_pitch_matches_a_finer_integration() -> None:
    """The default 1 ms step agrees with a 50 us integration to far below 1e-9 m."""
    args = ((0.3, 16.8, 1.8), (-0.5, -40.0, -1.0), -0.3)
    coarse = Pitch(*args, duration=0.5)
    fine = Pitch(*args, duration=0.5, step=5e-5)
    t = np.random.default_rng(1).uniform(-0.3, 0.2, 500)
    assert np.abs(coarse.position(t) - fine.position(t)).max() < 1e-10
    assert np.abs(coarse.velocity(t) - fine.velocity(t)).max() < 1e-7


def test_drag_slows_a_90_mph_pitch_by_8_to_10_percent_over_17_m() -> None:
    """A 90 mph pitch loses 8-10 % of its speed on the way to the plate; no drag, it gains."""
    for drag, low, high in ((True, 0.08, 0.10), (False, -0.01, 0.0)):
        pitch = Pitch((0.0, 17.0, 1.8), (0.0, -90.0 * MPH, 0.0), drag=drag, duration=0.6)
        t = np.linspace(0.0, 0.6, 60001)
        arrival = t[np.argmax(pitch.position(t)[:, 1] <= 0.0)]
        loss = 1.0 - np.linalg.norm(pitch.velocity(arrival)) / (90.0 * MPH)
        assert low <= loss <= high, (drag, loss)


def test_pitch_through_passes_the_given_state() -> None:
    """A pitch built backward from a state passes it at that instant, released near y=16.8."""
    position, velocity = np.array([0.1, 0.3, 0.8]), np.array([0.2, -37.0, -4.0])
    pitch = Pitch.through(position, velocity, 0.15, release_y=16.8, end_time=0.3)
    assert np.abs(pitch.position(0.15) - position).max() < 1e-11
    assert np.abs(pitch.velocity(0.15) - velocity).max() < 1e-9
    assert 16.8 <= pitch.release_position[1] < 16.9
    assert pitch.release_time < 0.0 and pitch.end_time >= 0.3


def test_pitch_refuses_bad_input() -> None:
    """Times outside the flight, non-finite states and balls flying away raise."""
    pitch = Pitch((0.0, 17.0, 1.8), (0.0, -40.0, 0.0), duration=0.5)
    with pytest.raises(ToolError):
        pitch.position(0.6)
    with pytest.raises(ToolError):
        pitch.velocity(-0.01)
    with pytest.raises(ToolError):
        Pitch((0.0, math.nan, 1.8), (0.0, -40.0, 0.0))
    with pytest.raises(ToolError):
        Pitch((0.0, 17.0, 1.8), (0.0, -40.0, 0.0), step=0.0)
    with pytest.raises(ToolError):
        Pitch.through((0.0, 0.0, 1.0), (0.0, 40.0, 0.0), 0.1)


# ----------------------------------------------------------------------------------------------
# Swing


def _swings(scenarios: dict) -> list:
    swings = [scenarios['barrel'][0].swing, scenarios['handle'][1].swing]
    base = scenarios['end_cap'][2].swing
    odd = PoseBatGeometry(knob_offset=(0.01, 0.02, -0.05), tip_offset=(0.8, 0.1, 0.3))
    fields = {name: getattr(base, name) for name in (
        'reference_time', 'hands', 'direction', 'plane_normal', 'peak_angular_speed',
        'peak_time', 'angular_width', 'hands_peak_velocity', 'hands_peak_time', 'hands_width',
        'hands_acceleration', 'grip_from_knob')}
    swings.append(Swing(**fields, roll_rate=7.0, geometry=odd))
    return swings


def test_pose_reproduces_knob_and_tip(scenarios: dict) -> None:
    """geometry.knob_and_tip(pose(t)) is knob_tip(t), scalar and vectorised, any geometry."""
    t = np.linspace(0.0, 0.25, 41)
    for swing in _swings(scenarios):
        knobs, tips = swing.knob_tip(t)
        positions, quaternions = swing.pose(t)
        assert knobs.shape == tips.shape == positions.shape == (41, 3)
        assert np.allclose(np.linalg.norm(quaternions, axis=1), 1.0, atol=1e-14)
        for i, time in enumerate(t):
            knob, tip = swing.geometry.knob_and_tip(positions[i], quaternions[i])
            assert np.abs(knob - knobs[i]).max() < 1e-12
            assert np.abs(tip - tips[i]).max() < 1e-12
            one_knob, one_tip = swing.knob_tip(float(time))
            assert one_knob.shape == (3,) and np.abs(one_tip - tips[i]).max() < 1e-15
        # rigid: constant length; the quaternion never flips sign between close samples
        assert np.abs(np.linalg.norm(tips - knobs, axis=1) - swing.length).max() < 1e-12
        assert np.all(np.sum(quaternions[1:] * quaternions[:-1], axis=1) > 0.0)


def test_point_velocity_and_angular_velocity_are_exact_derivatives(scenarios: dict) -> None:
    """point_velocity matches central differences of positions, angular_velocity of rotations."""
    h = 1e-6
    for swing in _swings(scenarios):
        for time in (0.02, 0.12, 0.15, 0.2, 0.24):
            for fraction in (0.0, 0.3, 0.82, 1.0):
                numeric = (swing.point(time + h, fraction) - swing.point(time - h, fraction)) / (
                    2.0 * h)
                exact = swing.point_velocity(time, fraction)
                assert np.abs(numeric - exact).max() < 1e-5, (time, fraction)
            r0 = quaternion_to_matrix(swing.pose(time - h)[1])
            r1 = quaternion_to_matrix(swing.pose(time + h)[1])
            skew = (r1 - r0) / (2.0 * h) @ quaternion_to_matrix(swing.pose(time)[1]).T
            omega = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
            assert np.abs(omega - swing.angular_velocity(time)).max() < 1e-4


def test_swing_turns_less_than_a_revolution(scenarios: dict) -> None:
    """The Gaussian speed profile bounds the whole swing below 2 pi (one pass of the ball)."""
    for kind in KINDS:
        for scenario in scenarios[kind]:
            swing = scenario.swing
            assert swing.total_rotation < 2.0 * math.pi
            sweep = float(swing.angle(scenario.t_end) - swing.angle(0.0))
            assert 3.0 < sweep < swing.total_rotation
            assert swing.angular_speed(0.0) < 0.05 * swing.peak_angular_speed  # from rest


def test_swing_refuses_bad_input() -> None:
    """Degenerate planes, widths and grips raise ToolError."""
    good = {'reference_time': 0.15, 'hands': (-0.5, 0.2, 1.0), 'direction': (1.0, 0.0, 0.0),
            'plane_normal': (0.0, 0.0, 1.0), 'peak_angular_speed': 50.0, 'peak_time': 0.16,
            'angular_width': 0.04}
    Swing(**good)
    for change in ({'plane_normal': (2.0, 0.0, 0.0)}, {'angular_width': 0.0},
                   {'grip_from_knob': 2.0}, {'hands': (0.0, math.inf, 0.0)}):
        with pytest.raises(ToolError):
            Swing(**{**good, **change})


# ----------------------------------------------------------------------------------------------
# Scenarios and their truth


def _check_first_contact(scenario: Scenario) -> None:
    """Check the gap is ~0 at time_s, and > 0 just before and on a fine grid before it."""
    truth = scenario.truth
    assert 0.0 < truth.time_s < scenario.t_end
    assert abs(float(scenario.gap(truth.time_s))) < 1e-9
    assert float(scenario.gap(truth.time_s)) <= 0.0
    assert float(scenario.gap(truth.time_s - 2e-12)) > 0.0
    before = np.linspace(0.0, truth.time_s - 1e-9, 4001)
    assert scenario.gap(before).min() > 0.0
    assert truth.min_gap_m < 0.0 and truth.min_gap_time_s > truth.time_s
    assert scenario.gap(truth.min_gap_time_s) == pytest.approx(truth.min_gap_m, abs=1e-12)
    assert 26.8 <= truth.sweet_spot_speed_mps <= 35.8
    assert 30.0 <= truth.ball_speed_mps <= 43.0
    assert truth.distance_from_knob_m + truth.distance_from_tip_m == pytest.approx(
        scenario.swing.length)
    knob, tip = scenario.swing.knob_tip(truth.time_s)
    axis_point = knob + truth.bat_fraction * (tip - knob)
    radius = np.linalg.norm(np.asarray(truth.point) - axis_point)
    assert WOOD_BAT_34.radius_at(0.0) * 0.5 < radius <= WOOD_BAT_34.max_radius + 1e-12
    ball = scenario.pitch.position(truth.time_s)
    assert np.linalg.norm(ball - np.asarray(truth.point)) == pytest.approx(
        scenario.ball_radius, abs=1e-9)
    assert np.asarray(truth.normal) @ (ball - axis_point) > 0.0


@pytest.mark.parametrize('kind', ['barrel', 'end_cap', 'handle', 'graze'])
def test_contact_kinds_hold_over_many_seeds(scenarios: dict, kind: str) -> None:
    """Every contact kind is what it says, and its first contact is exact."""
    for scenario in scenarios[kind]:
        truth = scenario.truth
        assert scenario.kind == kind and truth.contact
        _check_first_contact(scenario)
        if kind == 'barrel':
            assert truth.feature == 'side' and 0.05 <= truth.distance_from_tip_m <= 0.25
        elif kind == 'end_cap':
            assert truth.feature == 'tip_end'
            assert truth.bat_fraction == pytest.approx(WOOD_BAT_34.segments()[-1][1])
        elif kind == 'handle':
            assert truth.feature == 'side' and 0.2 <= truth.distance_from_knob_m <= 0.4
        else:
            assert -0.010 <= truth.min_gap_m <= -0.001


@pytest.mark.parametrize('kind', ['miss_over', 'miss_under'])
def test_miss_kinds_hold_over_many_seeds(scenarios: dict, kind: str) -> None:
    """Misses never touch; the ball passes 2-15 cm over / under the bat."""
    for scenario in scenarios[kind]:
        truth = scenario.truth
        assert not truth.contact and truth.time_s is None and truth.point is None
        assert 0.02 <= truth.min_gap_m <= 0.15
        t = np.linspace(0.0, scenario.t_end, 4001)
        assert scenario.gap(t).min() >= truth.min_gap_m - 1e-12
        assert float(scenario.gap(truth.min_gap_time_s)) == pytest.approx(truth.min_gap_m)
        vector = np.asarray(truth.min_gap_vector)
        assert np.linalg.norm(vector) == pytest.approx(truth.min_gap_m)
        assert (vector[2] > 0.0) == (kind == 'miss_over')


def test_a_touch_shorter_than_the_grid_is_found(scenarios: dict) -> None:
    """A graze is found from grids far coarser than its overlap, at the same instant."""
    scenario = scenarios['graze'][3]
    expected = scenario.truth.time_s
    missed = 0
    for grid in (1.3e-3, 1.7e-3, 2.1e-3, 2.9e-3):
        count = int(math.ceil(scenario.t_end / grid)) + 1
        missed += int(scenario.gap(np.linspace(0.0, scenario.t_end, count)).min() > 0.0)
        truth = compute_truth(scenario.swing, scenario.pitch, scenario.t_end, grid_s=grid)
        assert truth.contact and truth.time_s == pytest.approx(expected, abs=1e-11)
        assert truth.min_gap_m == pytest.approx(scenario.truth.min_gap_m, abs=1e-9)
    assert missed > 0  # at least one grid never saw the overlap


def test_make_scenario_is_reproducible_and_refuses_unknown_kinds() -> None:
    """The same seed gives the same scenario; an unknown kind raises."""
    a, b = _scenario('barrel', 7), _scenario('barrel', 7)
    assert a.name == b.name and a.truth == b.truth
    with pytest.raises(ToolError):
        make_scenario('homer', np.random.default_rng(0))


def test_truth_dict_is_json(scenarios: dict) -> None:
    """truth_dict round-trips through JSON with absolute stamps."""
    hit, miss = scenarios['barrel'][0], scenarios['miss_over'][0]
    record = json.loads(json.dumps(truth_dict(hit, START_NS)))
    assert record['stamp_ns'] == START_NS + round(hit.truth.time_s * 1e9)
    assert record['contact'] and record['kind'] == 'barrel'
    assert record['point'] == list(hit.truth.point)
    record = json.loads(json.dumps(truth_dict(miss, START_NS)))
    assert not record['contact'] and record['stamp_ns'] is None
    assert record['min_gap_stamp_ns'] == START_NS + round(miss.truth.min_gap_time_s * 1e9)


# ----------------------------------------------------------------------------------------------
# Sampling


@pytest.mark.parametrize('rate', [90.0, 120.0, 240.0, 360.0])
def test_samples_are_the_truth_at_the_stamps(scenarios: dict, rate: float) -> None:
    """Without noise, every sample is the truth at its stamp; stamps are int64, increasing."""
    scenario = scenarios['barrel'][1]
    samples = sample(scenario, rate, np.random.default_rng(0), start_ns=START_NS)
    stamps = samples.ball_stamps_ns
    assert stamps.dtype == np.int64 and samples.bat_stamps_ns.dtype == np.int64
    assert np.all(np.diff(stamps) > 0) and stamps[0] == START_NS
    assert np.array_equal(stamps, samples.bat_stamps_ns)
    assert len(stamps) == int(scenario.t_end * rate) + 1
    assert np.all(np.abs(np.diff(stamps) - 1e9 / rate) <= 1.0)
    t = (stamps - START_NS) * 1e-9
    assert np.array_equal(samples.ball_positions, scenario.pitch.position(t))
    knobs, tips = scenario.swing.knob_tip(t)
    assert np.array_equal(samples.knobs, knobs) and np.array_equal(samples.tips, tips)
    for position, quaternion, knob, tip in zip(samples.bat_positions, samples.bat_quaternions,
                                               samples.knobs, samples.tips):
        got_knob, got_tip = scenario.swing.geometry.knob_and_tip(position, quaternion)
        assert np.abs(got_knob - knob).max() < 1e-12 and np.abs(got_tip - tip).max() < 1e-12


def test_360_hz_on_a_millisecond_grid_steps_2_and_3_ms(scenarios: dict) -> None:
    """grid_s=0.001 at 360 Hz stamps on whole milliseconds, in steps of 2 and 3 ms."""
    scenario = scenarios['end_cap'][0]
    samples = sample(scenario, 360.0, np.random.default_rng(0), grid_s=0.001,
                     start_ns=START_NS)
    steps = np.diff(samples.ball_stamps_ns)
    assert set(steps.tolist()) == {2_000_000, 3_000_000}
    assert np.all((samples.ball_stamps_ns - START_NS) % 1_000_000 == 0)
    t = (samples.ball_stamps_ns - START_NS) * 1e-9
    assert np.array_equal(samples.ball_positions, scenario.pitch.position(t))


def test_jitter_noise_and_bat_offset(scenarios: dict) -> None:
    """Jittered stamps still increase; noise is one draw per sample; the bat can be offset."""
    scenario = scenarios['handle'][0]
    samples = sample(scenario, 240.0, np.random.default_rng(5), jitter_s=3e-4, noise_m=0.002,
                     start_ns=START_NS, bat_offset_s=0.0013)
    for stamps in (samples.ball_stamps_ns, samples.bat_stamps_ns):
        assert stamps.dtype == np.int64 and np.all(np.diff(stamps) > 0)
        assert START_NS <= stamps[0] and stamps[-1] <= START_NS + round(scenario.t_end * 1e9)
    assert not np.array_equal(samples.ball_stamps_ns, samples.bat_stamps_ns)
    t_ball = (samples.ball_stamps_ns - START_NS) * 1e-9
    error = samples.ball_positions - scenario.pitch.position(t_ball)
    assert 0.0015 < error.std() < 0.0025
    t_bat = (samples.bat_stamps_ns - START_NS) * 1e-9
    knobs, tips = scenario.swing.knob_tip(t_bat)
    shake = samples.knobs - knobs
    assert np.allclose(samples.tips - tips, shake, atol=1e-12)  # the same draw: still rigid
    assert 0.0015 < shake.std() < 0.0025
    for position, quaternion, knob in zip(samples.bat_positions, samples.bat_quaternions,
                                          samples.knobs):
        got_knob, _ = scenario.swing.geometry.knob_and_tip(position, quaternion)
        assert np.abs(got_knob - knob).max() < 1e-12


def test_sample_refuses_bad_input(scenarios: dict) -> None:
    """Non-positive rates, negative jitter or noise raise ToolError."""
    scenario = scenarios['barrel'][0]
    for kwargs in ({'rate_hz': 0.0}, {'rate_hz': 90.0, 'jitter_s': -1.0},
                   {'rate_hz': 90.0, 'noise_m': -1.0}, {'rate_hz': 90.0, 'grid_s': 0.0}):
        with pytest.raises(ToolError):
            sample(scenario, rng=np.random.default_rng(0), **kwargs)
