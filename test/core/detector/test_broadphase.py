"""Tests for the detector's broad phase: the raw-sample far test and the spline bulge bounds."""

import math

from baseball_collision.core.detector import Detector, DetectorConfig
from baseball_collision.core.detector.broadphase import (
    apart_margins, bulge_bounds, clearly_apart, hull_separation, hull_separations,
    path_margins)
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


def _swing(model: str, balls, hands, turns, steps) -> Detector:
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


def _closest(detector: Detector) -> float:
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


def _vectorised_bound(detector: Detector, model: str) -> float:
    """Return ``apart_margins`` over interval 1 of the detector's streams (m)."""
    ball, bat = detector._ball, detector._bat
    one = np.array([1])
    return float(apart_margins(
        np.array(ball.values), np.array([s.knob for s in bat.values]),
        np.array([s.tip for s in bat.values]), np.array([s.position for s in bat.values]),
        one, one, one - 1, one + 2, one - 1, one + 2, np.array(ball.times),
        np.array(bat.times), model)[0])


small = st.tuples(*[st.floats(-0.15, 0.15)] * 3)
MOTIONS = {'model': st.sampled_from(['linear', 'rigid', 'spline']),
           'offset': st.tuples(*[st.floats(-1.0, 1.0)] * 3),
           'ball_moves': st.lists(small, min_size=4, max_size=4),
           'hand_moves': st.lists(small, min_size=4, max_size=4),
           'turns': st.lists(st.floats(-1.5, 1.5), min_size=4, max_size=4),
           'steps': st.lists(st.floats(0.002, 0.012), min_size=3, max_size=3)}
"""Four samples of ball and bat (pose) moving and turning freely: the far tests' properties."""


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
    detector = _swing(model, [tuple(b) for b in balls], [tuple(h) for h in hands], turns,
                      steps)
    assert _vectorised_bound(detector, model) <= _closest(detector) + 1e-9


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
        probe = _swing(model, [(5.0, 5.0, 5.0)] * 4, [(0.0, 0.0, 0.0)] * 4,
                       [-1.2, 0.0, 1.2, 2.4], [0.005] * 3)
        s0, s1 = probe._bat.values[1], probe._bat.values[2]
        bow = np.array(s0.tip) + np.array(s1.tip) - np.array(s0.knob) - np.array(s1.knob)
        ball = tuple(0.5 * (np.array(s0.tip) + np.array(s1.tip)) + 0.05 * bow / np.linalg.norm(
            bow))
        detector = _swing(model, [ball] * 4, [(0.0, 0.0, 0.0)] * 4, [-1.2, 0.0, 1.2, 2.4],
                          [0.005] * 3)
        closest = _closest(detector)
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


@settings(max_examples=examples(200), deadline=None)
@given(k=st.integers(0, 2), **MOTIONS)
def test_vectorised_path_test_is_the_sweeps(model: str, offset, ball_moves, hand_moves, turns,
                                            steps, k: int) -> None:
    """``path_margins`` is the gap of the spheres of the paths the sweep builds (to rounding)."""
    hands = np.cumsum(hand_moves, axis=0)
    balls = np.array(offset) + np.cumsum(ball_moves, axis=0)
    detector = _swing(model, [tuple(b) for b in balls], [tuple(h) for h in hands], turns,
                      steps)
    ball, bat = detector._ball, detector._bat
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
