"""Tests for the far test over arrays: apart_margins and hull_separations."""

from baseball_collision.core.detector import Detector
from baseball_collision.core.detector.broadphase import (
    apart_margins, hull_separation, hull_separations)
from hypothesis import given, settings, strategies as st
import numpy as np
from support import examples
from support.far import closest_distance, MOTIONS, turning_swing


def _vectorised_bound(detector: Detector, model: str) -> float:
    """Return ``apart_margins`` over interval 1 of the detector's streams (m)."""
    ball, bat = detector._ball, detector._bat
    one = np.array([1])
    return float(apart_margins(
        np.array(ball.values), np.array([s.knob for s in bat.values]),
        np.array([s.tip for s in bat.values]), np.array([s.position for s in bat.values]),
        one, one, one - 1, one + 2, one - 1, one + 2, np.array(ball.times),
        np.array(bat.times), model)[0])


@settings(max_examples=examples(200), deadline=None)
@given(**MOTIONS)
def test_vectorised_far_bound_never_exceeds_the_paths_distance(model: str, offset, ball_moves,
                                                               hand_moves, turns,
                                                               steps) -> None:
    """
    ``apart_margins`` (spheres and hulls) is a lower bound on the paths' least distance.

    Ball and bat within a metre, moving up to 0.15 m a sample, so many cases are close. Fails
    when the growth terms are left out (hulls' separation alone), and when either bound is raised
    by 1 mm.
    """
    hands = np.cumsum(hand_moves, axis=0)
    balls = np.array(offset) + np.cumsum(ball_moves, axis=0)
    detector = turning_swing(model, [tuple(b) for b in balls], [tuple(h) for h in hands],
                             turns, steps)
    assert _vectorised_bound(detector, model) <= closest_distance(detector) + 1e-9


def test_the_hulls_without_the_growth_overshoot_a_turning_bat() -> None:
    """
    Need the growth terms: without them a turning bat's bound overshoots.

    A bat turning fast bows out of its end samples' hull, and the hulls' separation alone
    then exceeds the true distance (the property above fails when they are left out); with
    them, the bound holds.
    """
    for model in ('rigid', 'spline'):
        # the bat turns 1.2 rad a step about the tilted axis; the ball waits just outside the
        # hull of the middle interval's end samples, on the side the arc bows to
        probe = turning_swing(model, [(5.0, 5.0, 5.0)] * 4, [(0.0, 0.0, 0.0)] * 4,
                              [-1.2, 0.0, 1.2, 2.4], [0.005] * 3)
        s0, s1 = probe._bat.values[1], probe._bat.values[2]
        bow = np.array(s0.tip) + np.array(s1.tip) - np.array(s0.knob) - np.array(s1.knob)
        ball = tuple(0.5 * (np.array(s0.tip) + np.array(s1.tip)) + 0.05 * bow / np.linalg.norm(
            bow))
        detector = turning_swing(model, [ball] * 4, [(0.0, 0.0, 0.0)] * 4,
                                 [-1.2, 0.0, 1.2, 2.4], [0.005] * 3)
        closest = closest_distance(detector)
        b0, b1 = (np.array([v]) for v in detector._ball.values[1:3])
        k0, k1 = (np.array([s.knob]) for s in detector._bat.values[1:3])
        e0, e1 = (np.array([s.tip]) for s in detector._bat.values[1:3])
        assert hull_separations(b0, b1, k0, e0, k1, e1)[0] > closest + 0.01
        assert _vectorised_bound(detector, model) <= closest + 1e-9


@settings(max_examples=examples(100), deadline=None)
@given(points=st.lists(st.tuples(*[st.floats(-3.0, 3.0)] * 3), min_size=6, max_size=6))
def test_hull_separation_scalar_and_arrays_agree(points) -> None:
    """``hull_separation`` and ``hull_separations`` give one number (to rounding)."""
    scalar = hull_separation(*points)
    array = hull_separations(*(np.array([p], dtype=float) for p in points))[0]
    assert scalar == array or abs(scalar - array) <= 1e-9 * (1.0 + abs(scalar))
