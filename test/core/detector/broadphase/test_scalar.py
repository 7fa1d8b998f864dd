"""Tests for the scalar far test the sweep runs: clearly_apart and the spline bulge bounds."""

import math

from baseball_collision.core.detector import Detector, DetectorConfig
from baseball_collision.core.detector.broadphase import bulge_bounds, clearly_apart
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import PointPath
from hypothesis import given, settings, strategies as st
import numpy as np
from support import examples
from support.scenes import BASE_NS

point = st.tuples(*[st.floats(-1.5, 1.5)] * 3)


@settings(max_examples=examples(300), deadline=None)
@given(model=st.sampled_from(['linear', 'rigid', 'spline']),
       bat_as=st.sampled_from(['pose', 'points']),
       balls=st.lists(st.tuples(*[st.floats(-3.0, 3.0)] * 3), min_size=4, max_size=4),
       hands=st.lists(point, min_size=4, max_size=4),
       turns=st.lists(st.floats(-1.5, 1.5), min_size=4, max_size=4),
       steps=st.lists(st.floats(0.002, 0.012), min_size=3, max_size=3))
def test_cheap_far_test_never_clears_a_close_pass(model: str, bat_as: str, balls, hands, turns,
                                                  steps) -> None:
    """Whenever the raw-sample test calls an interval clear, the exact paths really are."""
    detector = Detector(DetectorConfig(model=model, bat_input=bat_as, max_speed=1e4,
                                       drop_lost_body=False))  # hands may sit at 0, 0, 0
    times = np.concatenate([[0.0], np.cumsum(steps)])
    for t, ball, hand, turn in zip(times, balls, hands, turns):
        stamp = BASE_NS + int(round(t * 1e9))
        half = 0.5 * turn  # a turn about a tilted axis, the bat along body +z
        axis = np.array([1.0, 1.0, 0.3]) / np.linalg.norm([1.0, 1.0, 0.3])
        quaternion = tuple(axis * math.sin(half)) + (math.cos(half),)
        if bat_as == 'pose':
            detector.add_bat_pose(stamp, hand, quaternion)
        else:
            knob, tip = detector.config.geometry.knob_and_tip(hand, quaternion)
            detector.add_knob(stamp, knob)
            detector.add_tip(stamp, tip)
        detector.add_ball(stamp, ball)
    config = detector.config
    margin = (config.ball_radius + config.profile.max_radius
              + max(config.near_miss_threshold, config.rearm_distance))
    assert len(detector._ball.times) == 4 and len(detector._bat.times) == 4
    if not clearly_apart(detector._ball, detector._bat, 1, 1, margin, model, config.max_gap):
        return
    ball_path, bat_path = detector._sweep.paths(1, 1)
    for t in np.linspace(detector._ball.times[1], detector._ball.times[2], 200):
        knob, tip = (np.array(p) for p in bat_path.at(t))
        ball = np.array(ball_path.at(t))
        along = np.clip((ball - knob) @ (tip - knob) / ((tip - knob) @ (tip - knob)), 0.0, 1.0)
        assert np.linalg.norm(ball - knob - along * (tip - knob)) > margin


@settings(max_examples=examples(200), deadline=None)
@given(points=st.lists(point, min_size=4, max_size=4),
       steps=st.lists(st.floats(0.002, 0.012), min_size=3, max_size=3))
def test_bulge_bound_covers_the_spline(points, steps) -> None:
    """The raw-sample bulge bound is at least the cubic's real distance from its chord."""
    stream = Stream('ball')
    times = np.concatenate([[0.0], np.cumsum(steps)])
    for t, p in zip(times, points):
        stream.append(float(t), int(t * 1e9) + 1, tuple(float(x) for x in p), False)
    bound = bulge_bounds(stream, 1, (lambda p: p,), max_gap=1.0)[0]
    path = PointPath.build('spline', times[1], times[2], stream.values[1], stream.values[2],
                           (times[0], stream.values[0]), (times[3], stream.values[3]))
    chord = np.array(stream.values[2]) - np.array(stream.values[1])
    for s in np.linspace(0.0, 1.0, 101):
        off = np.array(path.at(times[1] + s * (times[2] - times[1]))) - (
            np.array(stream.values[1]) + s * chord)
        assert np.linalg.norm(off) <= bound + 1e-12


def test_a_ball_through_the_bat_is_never_clear() -> None:
    """A ball passing through the bat's middle is not clearly apart under any model."""
    for model in ('linear', 'rigid', 'spline'):
        detector = Detector(DetectorConfig(model=model, bat_input='points'))
        for j, y in enumerate((1.0, 0.5, 0.0, -0.5)):
            stamp = BASE_NS + j * 5_000_000
            detector.add_knob(stamp, (0.0, 0.0, 1.0))
            detector.add_tip(stamp, (0.8, 0.0, 1.0))
            detector.add_ball(stamp, (0.4, y, 1.0))
        assert not clearly_apart(detector._ball, detector._bat, 1, 1, 0.0, model, 0.05)
