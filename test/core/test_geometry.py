"""Tests for baseball_collision.core.geometry: rotations, poses, rigid bodies."""

import math

from baseball_collision.core.geometry import (
    interpolate_pose, pose_point, quaternion_angle, quaternion_to_matrix, rigid_point_velocity,
    rotate, rotation_between, slerp_quaternions, slerp_vectors, swing_rotation, turn_about)
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples
from support.scenes import point

unit = st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: 0.1 < math.hypot(*q))


def _normalised(q):
    length = math.hypot(*q)
    return tuple(x / length for x in q)


@settings(max_examples=examples(200), deadline=None)
@given(q=unit, v=st.tuples(*[st.floats(-2, 2)] * 3))
def test_rotate_matches_the_rotation_matrix(q, v) -> None:
    """Quaternion rotation equals the matrix of the same quaternion."""
    q = _normalised(q)
    assert rotate(q, v) == pytest.approx(quaternion_to_matrix(q) @ np.array(v), abs=1e-12)


@settings(max_examples=examples(200), deadline=None)
@given(q0=unit, q1=unit, s=st.floats(0, 1))
def test_slerp_quaternions_turns_at_a_constant_rate(q0, q1, s: float) -> None:
    """The interpolated rotation is a fraction s of the way, along the shorter arc."""
    q0, q1 = _normalised(q0), _normalised(q1)
    q = slerp_quaternions(q0, q1, s)
    total = quaternion_angle(q0, q1)
    assert math.hypot(*q) == pytest.approx(1.0)
    assert quaternion_angle(q0, q) == pytest.approx(s * total, abs=1e-6)
    assert quaternion_angle(q, q1) == pytest.approx((1 - s) * total, abs=1e-6)


def test_slerp_vectors_keeps_unit_length_on_the_great_circle() -> None:
    """Halfway between x and y is the unit diagonal; ends are exact."""
    x, y = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    half = math.sqrt(0.5)
    assert slerp_vectors(x, y, 0.5) == pytest.approx((half, half, 0.0))
    assert slerp_vectors(x, y, 0.0) == pytest.approx(x)
    assert slerp_vectors(x, y, 1.0) == pytest.approx(y)
    assert slerp_vectors(x, x, 0.3) == pytest.approx(x)


@settings(max_examples=examples(200), deadline=None)
@given(v=point, axis=point, angle=st.floats(-4.0, 4.0))
def test_turn_about_is_the_quaternion_rotation(v, axis, angle: float) -> None:
    """Rodrigues' formula about a unit axis equals rotating by that axis-angle quaternion."""
    length = math.hypot(*axis)
    if length < 0.1:
        return
    axis = tuple(a / length for a in axis)
    q = tuple(a * math.sin(0.5 * angle) for a in axis) + (math.cos(0.5 * angle),)
    assert turn_about(v, axis, angle) == pytest.approx(rotate(q, v), abs=1e-12)
    assert turn_about(v, axis, 0.0) is v


@settings(max_examples=examples(200), deadline=None)
@given(q0=unit, q1=unit)
def test_rotation_between_turns_q0_into_q1(q0, q1) -> None:
    """The rotation vector from q0 to q1, applied after q0, gives q1's rotation."""
    q0, q1 = _normalised(q0), _normalised(q1)
    turn = rotation_between(q0, q1)
    if turn is None:
        assert quaternion_angle(q0, q1) < 1e-6
        return
    angle = math.hypot(*turn)
    # quaternion_angle's acos is good to about sqrt(epsilon) near 0; the atan2 here is exact
    assert angle == pytest.approx(quaternion_angle(q0, q1), abs=1e-7)
    if angle < 1e-6:
        return
    v = (0.3, -0.2, 0.9)
    assert turn_about(rotate(q0, v), tuple(t / angle for t in turn), angle) == pytest.approx(
        rotate(q1, v), abs=1e-9)
    assert rotation_between(q0, q0) is None


def test_swing_rotation_turns_one_direction_onto_the_other() -> None:
    """Turning x onto y is a quarter turn about +z; parallel directions do not turn."""
    assert swing_rotation((1.0, 0.0, 0.0), (0.0, 2.0, 0.0)) == pytest.approx((0, 0, math.pi / 2))
    assert swing_rotation((1.0, 0.0, 0.0), (3.0, 0.0, 0.0)) == (0.0, 0.0, 0.0)


def test_pose_points_and_interpolation() -> None:
    """A body point goes with the pose; halfway between poses is LERP plus SLERP."""
    half = math.sqrt(0.5)
    quarter = (0.0, 0.0, half, half)  # a quarter turn about +z
    assert pose_point((1.0, 2.0, 3.0), quarter, (1.0, 0.0, 0.0)) == pytest.approx((1, 3, 3))
    position, q = interpolate_pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), (2.0, 0.0, 0.0),
                                   quarter, 0.5)
    assert position == (1.0, 0.0, 0.0)
    assert quaternion_angle(q, (0.0, 0.0, 0.0, 1.0)) == pytest.approx(math.pi / 4)


def test_rigid_point_velocity_adds_the_turn() -> None:
    """A point 1 m out along x on a body turning at 2 rad/s about z moves at 2 m/s along y."""
    assert rigid_point_velocity((0.5, 0.0, 0.0), (0.0, 0.0, 2.0), (1.0, 1.0, 0.0),
                                (2.0, 1.0, 0.0)) == (0.5, 2.0, 0.0)
