"""Motion between samples: how the bodies move between two frames."""

from .paths import (
    BatPath, BatSample, check_model, hermite_tangent, MODELS, PointPath, Quaternion,
    quaternion_angle, rotate, slerp_quaternions, slerp_vectors, substeps_for, swing_rotation)

__all__ = [
    'Quaternion', 'MODELS', 'BatSample', 'check_model', 'slerp_vectors', 'slerp_quaternions',
    'quaternion_angle', 'rotate', 'swing_rotation', 'hermite_tangent', 'substeps_for', 'PointPath',
    'BatPath',
]
