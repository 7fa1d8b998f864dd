"""Tests for the scalar far test the sweep runs: clearly_apart and the spline bulge bounds."""

import math

from baseball_collision.core.detector import Detector, DetectorConfig
from baseball_collision.core.detector.broadphase import bulge_bounds, clearly_apart
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import PointPath
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
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


def _hull_written_out(b0, b1, k0, e0, k1, e1):  # type: ignore[no-untyped-def]
    """``hull_separation`` as its Python was."""
    cx, cy, cz = (b0[0] + b1[0]) * 0.5, (b0[1] + b1[1]) * 0.5, (b0[2] + b1[2]) * 0.5
    mx, my, mz = (k0[0] + k1[0]) * 0.5, (k0[1] + k1[1]) * 0.5, (k0[2] + k1[2]) * 0.5
    ax, ay, az = ((e0[0] + e1[0]) * 0.5 - mx, (e0[1] + e1[1]) * 0.5 - my,
                  (e0[2] + e1[2]) * 0.5 - mz)
    along = ax * ax + ay * ay + az * az
    s = ((cx - mx) * ax + (cy - my) * ay + (cz - mz) * az) / along if along > 0.0 else 0.0
    s = 0.0 if s < 0.0 else 1.0 if s > 1.0 else s
    nx, ny, nz = cx - mx - s * ax, cy - my - s * ay, cz - mz - s * az
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    if not length > 0.0:
        return -math.inf
    nx, ny, nz = nx / length, ny / length, nz / length
    return (min(nx * b0[0] + ny * b0[1] + nz * b0[2], nx * b1[0] + ny * b1[1] + nz * b1[2])
            - max(nx * k0[0] + ny * k0[1] + nz * k0[2], nx * e0[0] + ny * e0[1] + nz * e0[2],
                  nx * k1[0] + ny * k1[1] + nz * k1[2], nx * e1[0] + ny * e1[1] + nz * e1[2]))


@settings(max_examples=examples(300), deadline=None)
@given(points=st.lists(st.tuples(*[st.floats(-3.0, 3.0)] * 3), min_size=6, max_size=6),
       scale=st.sampled_from([1e-3, 1.0, 50.0]))
def test_the_kernels_spheres_and_hull_are_the_python_written_out(points, scale) -> None:
    """
    ``_kernel.far_spheres`` and ``hull_separation`` are the far test's Python, to the bit.

    The ball chord's middle and half its ``math.dist``, the bat ends' mean and their largest
    distance from it, the hulls' separation (-inf where its direction has no length: also a
    ball chord on the bat's middle segment); anything but six points of 3 numbers refused.
    """
    from baseball_collision.core.detector.broadphase import hull_separation
    from baseball_collision.core.toi import _kernel
    b0, b1, k0, e0, k1, e1 = (tuple(x * scale for x in p) for p in points)
    centre = ((k0[0] + e0[0] + k1[0] + e1[0]) * 0.25, (k0[1] + e0[1] + k1[1] + e1[1]) * 0.25,
              (k0[2] + e0[2] + k1[2] + e1[2]) * 0.25)
    expected = (((b0[0] + b1[0]) * 0.5, (b0[1] + b1[1]) * 0.5, (b0[2] + b1[2]) * 0.5),
                0.5 * math.dist(b0, b1), centre,
                max(math.dist(k0, centre), math.dist(e0, centre), math.dist(k1, centre),
                    math.dist(e1, centre)), _hull_written_out(b0, b1, k0, e0, k1, e1))
    assert _kernel.far_spheres(b0, b1, k0, e0, k1, e1) == expected
    assert hull_separation(b0, b1, k0, e0, k1, e1) == expected[4]
    with pytest.raises(TypeError):
        _kernel.far_spheres(b0, b1, k0, e0, k1)
    with pytest.raises(TypeError):
        _kernel.hull_separation(b0, b1, k0, e0, k1, (0.0, 1.0))
