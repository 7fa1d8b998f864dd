"""Tests for baseball_collision.core.toi's seed method and its infinite-line gap."""

from baseball_collision.core.toi import (
    distance, line_distance, seed_time_of_impact, time_of_impact)
import numpy as np
import pytest
from support.scenes import vector_args, VECTORS


def test_line_distance_is_the_seed_equation_6() -> None:
    """line_distance equals |(B-E)x(B-S)|/|S-E| - r at sample times, and ignores the ends."""
    ball0, ball1 = np.array([3.0, 0.5, 0.0]), np.array([3.0, -0.5, 0.0])
    knob, tip = np.zeros(3), np.array([1.0, 0.0, 0.0])
    t = np.array([0.0, 0.25, 0.5])
    got = line_distance(t, ball0, ball1, tip, tip, knob, knob, 0.03, 0.02, 1.0)
    assert got == pytest.approx([0.5 - 0.05, 0.25 - 0.05, -0.05])
    capsule = distance(t, ball0, ball1, tip, tip, knob, knob, 0.03, 0.02, 1.0)
    assert capsule[2] == pytest.approx(2.0 - 0.05)


def test_seed_reports_a_hit_past_the_tip() -> None:
    """The seed's infinite line reports a contact the real (finite) bat never makes."""
    pass_beyond = ([1.17, 1.0, 0], [1.17, -1.0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 0])
    seed = seed_time_of_impact(*pass_beyond, 0.037, 0.033, 0.01)
    assert seed is not None and seed == pytest.approx(0.01 * (1.0 - 0.07) / 2.0)
    assert time_of_impact(*pass_beyond, 0.037, 0.033, 0.01) is None


def test_seed_misses_a_ball_that_starts_in_contact() -> None:
    """Overlapping throughout: the seed finds no root; the exact solver reports time 0."""
    inside = ([0.5, 0.01, 0], [0.5, -0.01, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 0])
    assert seed_time_of_impact(*inside, 0.037, 0.033, 0.01) is None
    assert time_of_impact(*inside, 0.037, 0.033, 0.01).time == 0.0


def test_seed_agrees_on_a_clean_side_hit() -> None:
    """Where its assumptions hold (a transversal side hit) the seed finds the same time."""
    case = next(c for c in VECTORS if c['family'] == 'real_barrel' and c['time_of_impact'])
    expected = case['time_of_impact']
    assert seed_time_of_impact(*vector_args(case)) == pytest.approx(expected, rel=1e-6)
