"""Tests for baseball_collision.core.motion: SLERP, Hermite tangents, paths and chord bounds."""

import math

from baseball_collision.core.geometry import (
    quaternion_angle, quaternion_to_matrix, rotate, slerp_quaternions, slerp_vectors)
from baseball_collision.core.motion import (
    BatPath, BatSample, check_model, hermite_tangent, PointPath, substeps_for)
from baseball_collision.errors import CoreError
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples

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


def test_hermite_tangent_is_exact_for_a_parabola_on_uneven_steps() -> None:
    """The three-point tangent recovers the derivative of a quadratic on uneven stamps."""
    def p(t: float) -> tuple:
        return (3.0 * t * t - t, 2.0 * t, -4.9 * t * t)
    t_prev, t, t_next = 0.0, 0.002, 0.005
    tangent = hermite_tangent(t_prev, p(t_prev), t, p(t), t_next, p(t_next))
    assert tangent == pytest.approx((6.0 * t - 1.0, 2.0, -9.8 * t))
    assert hermite_tangent(None, None, t, p(t), t_next, p(t_next)) == pytest.approx(
        [(b - a) / (t_next - t) for a, b in zip(p(t), p(t_next))])
    assert hermite_tangent(None, None, t, p(t), None, None) == (0.0, 0.0, 0.0)


def test_cubic_point_path_follows_a_cubic_and_bounds_its_chord_error() -> None:
    """With exact end tangents a cubic is reproduced, and the deviation bound holds."""
    def p(t: float) -> tuple:
        return (t ** 3, 1.0 - t * t, 0.5 * t)

    def v(t: float) -> tuple:
        return (3 * t * t, -2.0 * t, 0.5)
    path = PointPath(0.2, 0.7, p(0.2), p(0.7), v(0.2), v(0.7))
    for t in np.linspace(0.2, 0.7, 11):
        assert path.at(t) == pytest.approx(p(t))
        assert path.velocity(t) == pytest.approx(v(t))
    ta, tb = 0.3, 0.6
    chord = [np.array(path.at(ta)) + (np.array(path.at(tb)) - path.at(ta)) * s
             for s in np.linspace(0, 1, 101)]
    actual = max(np.linalg.norm(np.array(path.at(ta + (tb - ta) * s)) - c)
                 for s, c in zip(np.linspace(0, 1, 101), chord))
    assert actual <= path.deviation(ta, tb) + 1e-12
    assert PointPath(0.0, 1.0, (0, 0, 0), (1, 1, 1)).deviation(0.0, 1.0) == 0.0


def test_rigid_axis_path_keeps_length_and_swings_on_the_arc() -> None:
    """From knob and tip points the rigid model turns the bat about the knob."""
    knob = (0.0, 0.0, 1.0)
    s0 = BatSample(knob=knob, tip=(0.8, 0.0, 1.0))
    s1 = BatSample(knob=knob, tip=(0.0, 0.8, 1.0))
    path = BatPath.build('rigid', 0.0, 0.01, s0, s1)
    knob_mid, tip_mid = path.at(0.005)
    assert math.dist(knob_mid, tip_mid) == pytest.approx(0.8)
    half = 0.8 * math.sqrt(0.5)
    assert tip_mid == pytest.approx((half, half, 1.0))
    # sagitta of a quarter turn on a 0.8 m lever: bound rho theta^2 / 8 is an upper bound
    sagitta = 0.8 * (1 - math.cos(math.pi / 4))
    assert sagitta <= path.deviation(0.0, 0.01) <= 1.3 * sagitta


def test_rigid_pose_path_uses_the_body_offsets() -> None:
    """From poses, knob and tip follow position LERP and quaternion SLERP with their offsets."""
    half = math.sqrt(0.5)
    offsets = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.8))
    s0 = BatSample(knob=(0, 0, 0), tip=(0, 0, 0.8), position=(0.0, 0.0, 0.0),
                   quaternion=(0.0, 0.0, 0.0, 1.0))
    s1 = BatSample(knob=(1, 0, 0), tip=(1.8, 0, 0), position=(1.0, 0.0, 0.0),
                   quaternion=(0.0, half, 0.0, half))
    path = BatPath.build('rigid', 0.0, 1.0, s0, s1, offsets=offsets)
    knob, tip = path.at(1.0)
    assert knob == pytest.approx((1.0, 0.0, 0.0)) and tip == pytest.approx((1.8, 0.0, 0.0))
    knob, tip = path.at(0.5)
    assert knob == pytest.approx((0.5, 0.0, 0.0))
    assert math.dist(knob, tip) == pytest.approx(0.8)


def test_linear_bat_path_moves_the_ends_on_chords() -> None:
    """Linear moves knob and tip on their chords; no sub-steps needed."""
    s1 = BatSample(knob=(1.0, 0.0, 0.0), tip=(1.0, 1.0, 1.0))
    s2 = BatSample(knob=(2.0, 0.0, 0.0), tip=(2.0, 1.0, 4.0))
    linear = BatPath.build('linear', 1.0, 2.0, s1, s2)
    assert linear.at(1.5)[1] == pytest.approx((1.5, 1.0, 2.5))
    assert linear.deviation(1.0, 2.0) == 0.0


def test_spline_bat_path_follows_an_accelerating_turn() -> None:
    """A bat turning about its knob with angle t^2 (+ a cubic knob path) is reproduced."""
    def bat(t: float) -> BatSample:
        knob = (0.1 * t, 0.02 * t * t, 0.0)
        angle = 3.0 * t * t
        return BatSample(knob=knob, tip=(knob[0] + 0.8 * math.cos(angle),
                                         knob[1] + 0.8 * math.sin(angle), 0.0))
    path = BatPath.build('spline', 0.1, 0.2, bat(0.1), bat(0.2), before=(0.0, bat(0.0)),
                         after=(0.3, bat(0.3)))
    for t in np.linspace(0.1, 0.2, 7):
        knob, tip = path.at(t)
        assert knob == pytest.approx(bat(t).knob, abs=1e-12)
        assert tip == pytest.approx(bat(t).tip, abs=1e-12)  # the angle is exactly quadratic
        assert math.dist(knob, tip) == pytest.approx(0.8)
    # the bound covers the true chord error of the whole interval
    mid_true = np.array(bat(0.15).tip)
    chord_mid = 0.5 * (np.array(bat(0.1).tip) + np.array(bat(0.2).tip))
    assert np.linalg.norm(mid_true - chord_mid) <= path.deviation(0.1, 0.2)


def test_substeps_for_meets_the_tolerance() -> None:
    """Enough sub-steps bring a quadratic deviation under the tolerance, and no more."""
    assert substeps_for(0.0, 1e-3) == 1
    assert substeps_for(1e-3, 1e-3) == 1
    n = substeps_for(0.02, 5e-4)
    assert 0.02 / n ** 2 <= 5e-4 < 0.02 / (n - 1) ** 2


def test_unknown_model_is_refused() -> None:
    """Only the three documented models exist."""
    assert check_model('spline') == 'spline'
    with pytest.raises(CoreError, match='linear, rigid, spline'):
        check_model('cubic')
