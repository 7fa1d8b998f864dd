"""
Motion between samples: how the bodies move between two frames.

Every path covers ONE sample interval of one stream, ``[t0, t1]``, and answers two questions
(the ``MotionPath`` protocol): where is it at time t, and how far it leaves its chord over
``[ta, tb]``, so that ``substeps_for`` can cut ``[ta, tb]`` into equal sub-steps on which
moving linearly stays within a chord error tolerance. The detector then runs the exact linear
solver on each sub-step.

* ``base``: model names, ``BatSample``, the protocol, ``PathKind``, tangents, sub-steps;
* ``points``: ``PointPath`` (the ball: chord or cubic Hermite) and ``AngleCubic`` (an angle);
* ``bat_paths``: one class per model for the bat (``LinearBatPath``, ``RigidPosePath`` and
  ``RigidAxisPath``, ``SplineBatPath``), built by ``BatPath.build``.
"""

from typing import Tuple

from .base import (
    BatSample, check_model, hermite_slope, hermite_tangent, MODELS, MotionPath, PathKind,
    SAMPLES_AHEAD, samples_ahead, substeps_for, swing_between, turn_between)
from .bat_paths import (
    BatPath, LinearBatPath, RigidAxisPath, RigidBatPath, RigidPosePath, SplineBatPath)
from .c2 import c2_rows, C2BatPath, MAX_CHART_ANGLE, rotate, unit_axis
from .points import AngleCubic, PointPath
from .splines import end_state, not_a_knot_slopes

Paths = Tuple[PointPath, BatPath]
"""The ball's and the bat's paths over one interval."""

__all__ = [
    'MODELS', 'BatSample', 'check_model', 'hermite_tangent', 'substeps_for', 'PointPath',
    'BatPath', 'AngleCubic', 'LinearBatPath', 'MotionPath', 'PathKind', 'RigidAxisPath',
    'RigidBatPath', 'RigidPosePath', 'SAMPLES_AHEAD', 'SplineBatPath', 'hermite_slope',
    'swing_between', 'turn_between', 'samples_ahead', 'C2BatPath', 'c2_rows', 'unit_axis',
    'MAX_CHART_ANGLE',
    'not_a_knot_slopes', 'end_state', 'rotate', 'Paths',
]
