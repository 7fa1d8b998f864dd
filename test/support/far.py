"""
The broad phase's shared scenes: four samples of a bat turning, and the paths' least distance.

For the far tests' properties (test/core/detector/broadphase/): the bound each test gives must
never exceed :func:`closest_distance`, found by brute force on the paths the sweep builds.
"""

import math
from typing import Optional, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig
from hypothesis import strategies as st
import numpy as np
from support.scenes import BASE_NS


def turning_swing(model: str, balls, hands, turns, steps) -> Detector:
    """Return a detector holding four ball and four bat-pose samples (a bat turning)."""
    detector = Detector(DetectorConfig(model=model, bat_input='pose', max_speed=1e4,
                                       drop_lost_body=False))
    times = np.concatenate([[0.0], np.cumsum(steps)])
    axis = np.array([1.0, 1.0, 0.3]) / np.linalg.norm([1.0, 1.0, 0.3])
    for t, ball, hand, turn in zip(times, balls, hands, turns):
        stamp = BASE_NS + int(round(t * 1e9))
        detector.add_bat_pose(stamp, hand, tuple(axis * math.sin(0.5 * turn))
                              + (math.cos(0.5 * turn),))
        detector.add_ball(stamp, ball)
    assert len(detector._ball.times) == 4 and len(detector._bat.times) == 4
    return detector


def tilting_bat(t: float, spin: float, tilt: float, rng: Optional[np.random.Generator] = None,
                noise: float = 0.0) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return knob and tip (m) at t (s) of a bat turning ever faster in a tilting plane.

    The angle is ``spin * t + 100 t^2`` (rad) in a plane whose normal tilts at ``tilt`` rad/s;
    the knob drifts 0.2 m/s along x at 1 m height; the bat is 0.86 m long. With ``rng``, each
    point gets Gaussian noise of ``noise`` m per coordinate (the knob's drawn first).
    """
    angle = spin * t + 100.0 * t * t
    axis = np.array([math.sin(tilt * t), 0.0, math.cos(tilt * t)])
    radial = np.array([math.cos(angle), math.sin(angle), 0.0])
    direction = radial - axis * (radial @ axis)
    knob = np.array([0.2 * t, 0.0, 1.0])
    if rng is None:
        return knob, knob + 0.86 * direction / np.linalg.norm(direction)
    knob = knob + rng.normal(0.0, noise, 3)
    return knob, knob + 0.86 * direction / np.linalg.norm(direction) + rng.normal(0.0, noise, 3)


def closest_distance(detector: Detector) -> float:
    """
    Return the least distance (m) between the ball's and the bat axis' paths, brute force.

    Over sample interval 1, any instant of the one against any instant of the other.
    """
    ball_path, bat_path = detector._sweep.paths(1, 1)
    times = np.linspace(detector._ball.times[1], detector._ball.times[2], 41)
    balls = np.array([ball_path.at(t) for t in times])  # (41, 3)
    ends = [(np.array(knob), np.array(tip)) for knob, tip in map(bat_path.at, times)]
    least = math.inf
    for knob, tip in ends:
        axis = tip - knob
        along = np.clip((balls - knob) @ axis / (axis @ axis), 0.0, 1.0)
        least = min(least, float(np.linalg.norm(balls - knob - along[:, None] * axis,
                                                axis=1).min()))
    return least


small = st.tuples(*[st.floats(-0.15, 0.15)] * 3)
MOTIONS = {'model': st.sampled_from(['linear', 'rigid', 'spline']),
           'offset': st.tuples(*[st.floats(-1.0, 1.0)] * 3),
           'ball_moves': st.lists(small, min_size=4, max_size=4),
           'hand_moves': st.lists(small, min_size=4, max_size=4),
           'turns': st.lists(st.floats(-1.5, 1.5), min_size=4, max_size=4),
           'steps': st.lists(st.floats(0.002, 0.012), min_size=3, max_size=3)}
"""Four samples of ball and bat (pose) moving and turning freely: the far tests' properties."""
