"""Tests for the sweep's second far test over arrays: path_margins."""

import math

from baseball_collision.core.detector.broadphase import path_margins
from baseball_collision.core.detector.departure import leaves_flight
from hypothesis import given, settings, strategies as st
import numpy as np
from support import examples
from support.far import MOTIONS, turning_swing


@settings(max_examples=examples(200), deadline=None)
@given(k=st.integers(0, 2), **MOTIONS)
def test_vectorised_path_test_is_the_sweeps(model: str, offset, ball_moves, hand_moves, turns,
                                            steps, k: int) -> None:
    """
    ``path_margins`` is the gap of the spheres of the paths the sweep builds (to rounding).

    Where the ball keeps its free flight: where it leaves it the sweep takes another path,
    which ``plans`` allows for (``departure``).
    """
    hands = np.cumsum(hand_moves, axis=0)
    balls = np.array(offset) + np.cumsum(ball_moves, axis=0)
    detector = turning_swing(model, [tuple(b) for b in balls], [tuple(h) for h in hands],
                             turns, steps)
    ball, bat = detector._ball, detector._bat
    gap = detector._config.max_gap
    if leaves_flight(ball, k, 0.0, gap) or (model == 'spline' and k + 1 < len(ball.times) - 1
                                            and leaves_flight(ball, k + 1, 0.0, gap)):
        return  # the sweep takes the free flight there (``departure``): plans allow for it
    ball_path, bat_path = detector._sweep.paths(k, k)
    expected = (math.dist(ball_path.centre, bat_path.centre) - ball_path.radius
                - bat_path.radius)
    one = np.array([k])
    before, after = np.array([k - 1 if k else -1]), np.array([k + 2 if k < 2 else -1])
    lever = max(math.dist(o, (0.0, 0.0, 0.0)) for o in detector._offsets)
    found = path_margins(
        np.array(ball.values), np.array([s.knob for s in bat.values]),
        np.array([s.tip for s in bat.values]), np.array([s.quaternion for s in bat.values]),
        one, one, before, after, before, after, np.array(ball.times), np.array(bat.times),
        model, lever)[0]
    assert abs(found - expected) <= 1e-9 * (1.0 + abs(expected))
