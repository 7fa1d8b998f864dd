"""Motion between samples: how the bodies move between two frames."""

from .paths import (
    BatPath, BatSample, check_model, hermite_tangent, MODELS, PointPath, substeps_for)

__all__ = [
    'MODELS', 'BatSample', 'check_model', 'hermite_tangent', 'substeps_for', 'PointPath',
    'BatPath',
]
