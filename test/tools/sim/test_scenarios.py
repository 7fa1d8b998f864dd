"""Tests for baseball_collision.tools.sim scenarios: every kind is what it says, reproducibly."""

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.errors import ToolError
from baseball_collision.tools.sim import make_scenario, Scenario
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
