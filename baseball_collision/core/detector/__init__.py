"""The stream detector: samples in, impact and near-miss events out."""

from .config import (
    DEFAULTS, DetectorConfig, Kind, NODE_NAME, PARAMETERS, ParameterSpec, Range, SPECS,
    unit_vector, validate_parameters)
from .detector import (
    Detector, DetectorStats, DROP_REASONS, Event, FAR_AHEAD_NS, Impact, MPS_TO_MPH, NearMiss,
    Prediction, PREDICTION_CHORD_FACTOR, PREDICTION_DEGREE, PredictionCleared, SPARSE_SAMPLES,
    StateReset, StreamGap)

__all__ = [
    'DROP_REASONS', 'FAR_AHEAD_NS', 'MPS_TO_MPH', 'DetectorConfig', 'Impact', 'NearMiss',
    'Prediction', 'PredictionCleared', 'StreamGap', 'StateReset', 'Event', 'DetectorStats',
    'Detector', 'PREDICTION_CHORD_FACTOR', 'PREDICTION_DEGREE', 'SPARSE_SAMPLES',
    # the parameter table (config.py)
    'NODE_NAME', 'Kind', 'Range', 'ParameterSpec', 'PARAMETERS', 'SPECS', 'DEFAULTS',
    'validate_parameters', 'unit_vector',
]
