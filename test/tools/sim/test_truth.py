"""Tests for baseball_collision.tools.sim truth: first contact on any grid, contact spot."""

import math

from baseball_collision.core.toi import profile_gap
from baseball_collision.tools.sim import compute_truth
from baseball_collision.tools.sim.truth import segment_gaps
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


def test_the_truths_gaps_are_the_kernels(scenarios: dict) -> None:
    """
    ``segment_gaps`` (the truth's grid, its own numpy) and the kernel's gap agree everywhere.

    Two closed forms of the nearest sphere of each round cone, written apart: their least
    over the pieces is the same gap to 1e-12 m, 10 ms either side of each contact.
    """
    for kind in ('barrel', 'handle', 'graze'):
        scenario = scenarios[kind][0]
        times = np.linspace(scenario.truth.time_s - 0.01, scenario.truth.time_s + 0.01, 201)
        knob, tip = scenario.swing.knob_tip(times)
        ball = scenario.pitch.position(times)
        grid = segment_gaps(ball, knob, tip, scenario.profile, scenario.ball_radius).min(axis=0)
        kernel = [profile_gap(tuple(b), tuple(k), tuple(e), scenario.ball_radius,
                              scenario.profile)[0] for b, k, e in zip(ball, knob, tip)]
        assert grid == pytest.approx(kernel, abs=1e-12), kind
