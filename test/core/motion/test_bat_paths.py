"""Tests for baseball_collision.core.motion.bat_paths: one bat path class per model."""

import math

from baseball_collision.core.motion import (
    BatPath, BatSample, LinearBatPath, PathKind, RigidAxisPath, RigidPosePath, SplineBatPath)
from baseball_collision.errors import CoreError
import numpy as np
import pytest


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


def test_build_picks_one_class_per_model() -> None:
    """The factory's class and kind for each model and bat input; unknown models refused."""
    half = math.sqrt(0.5)
    s0 = BatSample((0, 0, 0), (0, 0, 0.8), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    s1 = BatSample((1, 0, 0), (1.8, 0, 0), (1.0, 0.0, 0.0), (0.0, half, 0.0, half))
    offsets = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.8))
    cases = [('linear', offsets, LinearBatPath, PathKind.POINTS),
             ('rigid', offsets, RigidPosePath, PathKind.POSE),
             ('rigid', None, RigidAxisPath, PathKind.AXIS),
             ('spline', offsets, SplineBatPath, PathKind.TURNING)]
    for model, given_offsets, kind_class, kind in cases:
        path = BatPath.build(model, 0.0, 1.0, s0, s1, offsets=given_offsets)
        assert type(path) is kind_class and path.kind == kind
        assert path.at(0.0) == (s0.knob, s0.tip) and path.at(1.0) == (s1.knob, s1.tip)
    with pytest.raises(CoreError, match='linear, rigid, spline'):
        BatPath.build('cubic', 0.0, 1.0, s0, s1)


def test_bounding_spheres_hold_every_axis_point() -> None:
    """The bounding sphere holds the knob, the tip and the middle all through the interval."""
    def bat(t: float) -> BatSample:
        angle = 20.0 * t * t
        knob = (0.3 * t, 0.1 * t * t, 1.0)
        return BatSample(knob, (knob[0] + 0.86 * math.cos(angle),
                                knob[1] + 0.86 * math.sin(angle), 1.0))
    for model in ('linear', 'rigid', 'spline'):
        path = BatPath.build(model, 0.1, 0.15, bat(0.1), bat(0.15), (0.05, bat(0.05)),
                             (0.2, bat(0.2)))
        for t in np.linspace(0.1, 0.15, 51):
            knob, tip = path.at(t)
            for f in (0.0, 0.5, 1.0):
                inside = np.array(knob) + f * (np.array(tip) - np.array(knob))
                assert np.linalg.norm(inside - path.centre) <= path.radius + 1e-12
