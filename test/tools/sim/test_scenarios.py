"""Tests for baseball_collision.tools.sim scenarios: every kind is what it says, reproducibly."""

from dataclasses import replace

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.geometry import quaternion_to_matrix
from baseball_collision.errors import ToolError
from baseball_collision.tools.sim import CLOSE_KINDS, KINDS, make_scenario, Scenario
from baseball_collision.tools.sim.scenarios import impulse_share, surface_motion
import numpy as np
import pytest


def _scenario(kind: str, seed: int) -> Scenario:
    return make_scenario(kind, np.random.default_rng(seed))


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


def test_make_scenario_is_reproducible_and_refuses_unknown_kinds() -> None:
    """The same seed gives the same scenario; an unknown kind raises."""
    a, b = _scenario('barrel', 7), _scenario('barrel', 7)
    assert a.name == b.name and a.truth == b.truth
    with pytest.raises(ToolError):
        make_scenario('homer', np.random.default_rng(0))


def _share_by_differences(scenario: Scenario) -> float:
    """impulse_share from finite differences: the gap's rate, the pose's and the ball's motion."""
    truth, swing, step = scenario.truth, scenario.swing, 1e-6
    t, point, normal = truth.time_s, np.asarray(truth.point), np.asarray(truth.normal)
    closing = -float(scenario.gap(t + step) - scenario.gap(t - step)) / (2.0 * step)
    position, quaternion = swing.pose(t)
    body = np.array(quaternion_to_matrix(tuple(quaternion))).T @ (point - position)

    def surface(time: float) -> np.ndarray:
        where, turn = swing.pose(time)
        return where + np.array(quaternion_to_matrix(tuple(turn))) @ body

    relative = (scenario.pitch.position(t + step) - scenario.pitch.position(t - step)
                - surface(t + step) + surface(t - step)) / (2.0 * step)
    omega = swing.angular_velocity(t)
    lever = np.cross(point - swing.hands_position(t), normal) @ omega / np.linalg.norm(omega)
    sweet_lever = swing.sweet_spot_fraction() * swing.length - swing.grip_from_knob
    return float(np.clip(closing / np.linalg.norm(relative) * lever / sweet_lever, 0.0, 1.0))


def test_a_braking_bat_slows_with_the_contacts_impulse() -> None:
    """
    The braking family's brake is the drawn 10-35 % times the contact's ``impulse_share``.

    The share agrees with one from finite differences (the gap's rate at the contact for the
    closing speed, the pose's motion for the bat's surface point); a tick hardly brakes (its
    ball meets the bat almost tangentially), a handle hit less than a barrel hit (its lever
    about the hands is short), and misses do not brake.
    """
    rng = np.random.default_rng(5)
    shares = {}
    for kind in KINDS + CLOSE_KINDS:
        for _ in range(4):
            scenario = make_scenario(kind, rng, family='braking')
            swing = scenario.swing
            if not scenario.truth.contact:
                assert swing.brake_time is None and impulse_share(scenario) == 0.0
                continue
            share = impulse_share(scenario)
            assert 0.0 <= share <= 1.0
            assert share == pytest.approx(_share_by_differences(scenario), abs=1e-4)
            assert swing.brake_time == scenario.truth.time_s
            assert 0.10 * share - 1e-12 <= swing.brake_fraction <= 0.35 * share + 1e-12
            shares.setdefault(kind, []).append(share)
    assert max(shares['tick']) < 0.05
    assert max(shares['handle']) < 0.5 < float(np.median(shares['barrel']))


def test_a_rebounding_ball_leaves_the_bat_as_from_a_hit() -> None:
    """
    The rebound family: the ball's speed into the bat's surface reverses at the contact.

    It changes by -(1 + e) q times itself along the normal (e 0.45-0.55, q 0.6-0.8: a
    square hit leaves at 30-50 m/s), not across it, after ``rebound_duration``; the truth is
    the flight's before the push, and the swing brakes as the braking family's does.
    """
    rng = np.random.default_rng(9)
    for kind in ('barrel', 'handle', 'tick', 'miss_over'):
        scenario = make_scenario(kind, rng, family='rebound')
        pitch = scenario.pitch
        if not scenario.truth.contact:
            assert pitch.rebound_time is None
            continue
        t = scenario.truth.time_s
        assert pitch.rebound_time == t
        relative, normal = surface_motion(scenario)
        into = float(relative @ normal)
        gained = pitch.velocity(t + pitch.rebound_duration) - pitch.velocity(t)
        free = replace(pitch, rebound_time=None)
        gained = gained - (free.velocity(t + pitch.rebound_duration) - free.velocity(t))
        ratio = float(gained @ normal) / -into
        assert 0.45 * 1.6 - 1e-9 <= ratio <= 1.55 * 0.8 + 1e-9
        assert np.linalg.norm(gained - (gained @ normal) * normal) < 1e-9
        if kind == 'barrel':
            assert 30.0 < np.linalg.norm(pitch.velocity(t + 0.002)) < 55.0
        assert scenario.swing.brake_time == t
