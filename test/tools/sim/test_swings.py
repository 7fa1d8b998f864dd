"""Tests for baseball_collision.tools.sim swings: rigid kinematics, poses, exact derivatives."""

import math

from baseball_collision.core.bat import PoseBatGeometry
from baseball_collision.core.geometry import matrix_to_quaternion, quaternion_to_matrix
from baseball_collision.errors import ToolError
from baseball_collision.tools.sim import KINDS, Swing
import numpy as np
import pytest


def _swings(scenarios: dict) -> list:
    swings = [scenarios['barrel'][0].swing, scenarios['handle'][1].swing]
    base = scenarios['end_cap'][2].swing
    odd = PoseBatGeometry(knob_offset=(0.01, 0.02, -0.05), tip_offset=(0.8, 0.1, 0.3))
    fields = {name: getattr(base, name) for name in (
        'reference_time', 'hands', 'direction', 'plane_normal', 'peak_angular_speed',
        'peak_time', 'angular_width', 'hands_peak_velocity', 'hands_peak_time', 'hands_width',
        'hands_acceleration', 'grip_from_knob')}
    swings.append(Swing(**fields, roll_rate=7.0, geometry=odd))
    return swings


def test_pose_reproduces_knob_and_tip(scenarios: dict) -> None:
    """geometry.knob_and_tip(pose(t)) is knob_tip(t), scalar and vectorised, any geometry."""
    t = np.linspace(0.0, 0.25, 41)
    for swing in _swings(scenarios):
        knobs, tips = swing.knob_tip(t)
        positions, quaternions = swing.pose(t)
        assert knobs.shape == tips.shape == positions.shape == (41, 3)
        assert np.allclose(np.linalg.norm(quaternions, axis=1), 1.0, atol=1e-14)
        for i, time in enumerate(t):
            knob, tip = swing.geometry.knob_and_tip(positions[i], quaternions[i])
            assert np.abs(knob - knobs[i]).max() < 1e-12
            assert np.abs(tip - tips[i]).max() < 1e-12
            one_knob, one_tip = swing.knob_tip(float(time))
            assert one_knob.shape == (3,) and np.abs(one_tip - tips[i]).max() < 1e-15
        # rigid: constant length; the quaternion never flips sign between close samples
        assert np.abs(np.linalg.norm(tips - knobs, axis=1) - swing.length).max() < 1e-12
        assert np.all(np.sum(quaternions[1:] * quaternions[:-1], axis=1) > 0.0)


def test_point_velocity_and_angular_velocity_are_exact_derivatives(scenarios: dict) -> None:
    """point_velocity matches central differences of positions, angular_velocity of rotations."""
    h = 1e-6
    for swing in _swings(scenarios):
        for time in (0.02, 0.12, 0.15, 0.2, 0.24):
            for fraction in (0.0, 0.3, 0.82, 1.0):
                numeric = (swing.point(time + h, fraction) - swing.point(time - h, fraction)) / (
                    2.0 * h)
                exact = swing.point_velocity(time, fraction)
                assert np.abs(numeric - exact).max() < 1e-5, (time, fraction)
            r0 = quaternion_to_matrix(swing.pose(time - h)[1])
            r1 = quaternion_to_matrix(swing.pose(time + h)[1])
            skew = (r1 - r0) / (2.0 * h) @ quaternion_to_matrix(swing.pose(time)[1]).T
            omega = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
            assert np.abs(omega - swing.angular_velocity(time)).max() < 1e-4


def test_swing_turns_less_than_a_revolution(scenarios: dict) -> None:
    """The Gaussian speed profile bounds the whole swing below 2 pi (one pass of the ball)."""
    for kind in KINDS:
        for scenario in scenarios[kind]:
            swing = scenario.swing
            assert swing.total_rotation < 2.0 * math.pi
            sweep = float(swing.angle(scenario.t_end) - swing.angle(0.0))
            assert 3.0 < sweep < swing.total_rotation
            assert swing.angular_speed(0.0) < 0.05 * swing.peak_angular_speed  # from rest


def test_swing_refuses_bad_input() -> None:
    """Degenerate planes, widths and grips raise ToolError."""
    good = {'reference_time': 0.15, 'hands': (-0.5, 0.2, 1.0), 'direction': (1.0, 0.0, 0.0),
            'plane_normal': (0.0, 0.0, 1.0), 'peak_angular_speed': 50.0, 'peak_time': 0.16,
            'angular_width': 0.04}
    Swing(**good)
    for change in ({'plane_normal': (2.0, 0.0, 0.0)}, {'angular_width': 0.0},
                   {'grip_from_knob': 2.0}, {'hands': (0.0, math.inf, 0.0)}):
        with pytest.raises(ToolError):
            Swing(**{**good, **change})


def test_matrix_to_quaternion_inverts_quaternion_to_matrix() -> None:
    """The swing's reference orientation comes back from its matrix, every Shepperd branch."""
    rng = np.random.default_rng(4)
    quaternions = list(rng.normal(size=(200, 4))) + [
        np.array(q) for q in ((0, 0, 0, 1), (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0))]
    for quaternion in quaternions:
        quaternion = quaternion / np.linalg.norm(quaternion)
        back = matrix_to_quaternion(quaternion_to_matrix(quaternion))
        assert abs(float(back @ quaternion)) == pytest.approx(1.0, abs=1e-12)
