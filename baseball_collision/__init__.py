"""
baseball_collision: the exact instant a tracked bat hits a tracked ball.

The public API is the pure core (Python + numpy, no ROS): the exact time-of-impact solver, the
bat's geometry and the stream detector. The ROS 2 node is ``baseball_collision.ros``, the bag
tools ``baseball_collision.bags`` and ``baseball_collision.tools``.
"""

from .core.bat import BatProfile, WOOD_BAT_34
from .core.detector import (
    Detector, DetectorConfig, Impact, NearMiss, Prediction, PredictionCleared, StateReset,
    StreamGap)
from .core.toi import time_of_impact, time_of_impact_batch, time_of_impact_profile
from .errors import BagError, BaseballCollisionError, CoreError, RosError, ToolError

__version__ = '0.1.0'
"""The package version (as in package.xml and setup.py)."""

__all__ = [
    '__version__', 'BagError', 'BaseballCollisionError', 'BatProfile', 'CoreError', 'Detector',
    'DetectorConfig', 'Impact', 'NearMiss', 'Prediction', 'PredictionCleared', 'RosError',
    'StateReset', 'StreamGap', 'time_of_impact', 'time_of_impact_batch',
    'time_of_impact_profile', 'ToolError', 'WOOD_BAT_34',
]
