"""The stream detector: samples in, impact and near-miss events out."""

from .bat_window import PREDICTION_DEGREE
from .config import (
    AUTO_NOISE, DEFAULTS, DetectorConfig, Kind, node_fqn, NODE_NAME, PARAMETERS, ParameterSpec,
    Range, section_applies, SPECS, unit_vector, unknown_parameters, validate_parameters)
from .detector import Detector
from .events import (
    DetectorStats, DROP_REASONS, DropReason, Event, Impact, MPS_TO_MPH, NearMiss, Prediction,
    PredictionCleared, ResetReason, Role, StateReset, StreamGap)
from .gate import FAR_AHEAD_NS
from .kinematics import SPARSE_SAMPLES
from .prediction_spread import PendingPrediction
from .predictor import PREDICTION_CHORD_FACTOR
from .uncertainty import PendingUncertainty
from ..toi import Feature

__all__ = [
    'DROP_REASONS', 'FAR_AHEAD_NS', 'MPS_TO_MPH', 'DetectorConfig', 'Impact', 'NearMiss',
    'Prediction', 'PredictionCleared', 'StreamGap', 'StateReset', 'Event', 'DetectorStats',
    'Detector', 'PREDICTION_CHORD_FACTOR', 'PREDICTION_DEGREE', 'SPARSE_SAMPLES', 'DropReason',
    'Feature', 'ResetReason', 'Role', 'PendingUncertainty', 'PendingPrediction',
    # the parameter table (config.py)
    'AUTO_NOISE', 'NODE_NAME', 'Kind', 'Range', 'ParameterSpec', 'PARAMETERS', 'SPECS', 'DEFAULTS',
    'validate_parameters', 'unknown_parameters', 'unit_vector', 'section_applies', 'node_fqn',
]
