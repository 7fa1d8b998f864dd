"""Tests for baseball_collision.tools.sim truth: first contact on any grid, contact spot."""

import math

from baseball_collision.core.toi import profile_gap
from baseball_collision.tools.sim import compute_truth
import numpy as np
import pytest


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


def test_contact_spot_is_on_both_surfaces(scenarios: dict) -> None:
    """At first contact the spot is on the bat surface and the ball's, the normal between."""
    for kind in ('barrel', 'end_cap', 'handle'):
        for scenario in scenarios[kind][:5]:
            truth = scenario.truth
            knob, tip = scenario.swing.knob_tip(truth.time_s)
            ball = scenario.pitch.position(truth.time_s)
            gap, normal, fraction = profile_gap(tuple(ball), tuple(knob), tuple(tip),
                                                scenario.ball_radius, scenario.profile)
            assert abs(gap) < 1e-9 and fraction == pytest.approx(truth.bat_fraction, abs=1e-12)
            assert np.asarray(truth.normal) == pytest.approx(normal, abs=1e-12)
            spot = np.asarray(truth.point)
            assert np.linalg.norm(ball - spot) == pytest.approx(scenario.ball_radius, abs=1e-9)
            assert (ball - spot) @ np.asarray(truth.normal) > 0.0
