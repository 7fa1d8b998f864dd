"""
baseball_collision: the exact instant a tracked bat hits a tracked ball.

The public API is the pure core (Python + numpy, no ROS): the exact time-of-impact solver, the
bat's geometry and the stream detector. The ROS 2 node is ``baseball_collision.ros``, the bag
tools ``baseball_collision.bags`` and ``baseball_collision.tools``.

The names below are imported on first use (PEP 562), so that ``import baseball_collision``
alone loads neither numpy nor the core: the console scripts (``entry_points``) set up numpy's
BLAS before anything imports it.
"""

import importlib
from typing import Any, List, TYPE_CHECKING

if TYPE_CHECKING:  # what a type checker and an IDE see; at run time ``__getattr__`` imports
    from .core.bat import BatProfile, WOOD_BAT_34  # noqa: F401
    from .core.detector import (  # noqa: F401
        Detector, DetectorConfig, Impact, NearMiss, Prediction, PredictionCleared, StateReset,
        StreamGap)
    from .core.toi import (  # noqa: F401
        time_of_impact, time_of_impact_batch, time_of_impact_profile)
    from .errors import (  # noqa: F401
        BagError, BaseballCollisionError, CoreError, RosError, ToolError)

__version__ = '0.1.0'
"""The package version (as in package.xml and setup.py)."""

_WHERE = {
    'BatProfile': 'core.bat', 'WOOD_BAT_34': 'core.bat',
    'Detector': 'core.detector', 'DetectorConfig': 'core.detector', 'Impact': 'core.detector',
    'NearMiss': 'core.detector', 'Prediction': 'core.detector',
    'PredictionCleared': 'core.detector', 'StateReset': 'core.detector',
    'StreamGap': 'core.detector',
    'time_of_impact': 'core.toi', 'time_of_impact_batch': 'core.toi',
    'time_of_impact_profile': 'core.toi',
    'BagError': 'errors', 'BaseballCollisionError': 'errors', 'CoreError': 'errors',
    'RosError': 'errors', 'ToolError': 'errors',
}
"""Each public name's module, relative to this package."""

__all__ = ['__version__', *sorted(_WHERE, key=str.lower)]


def __getattr__(name: str) -> Any:
    """
    Return a public name, importing its module on first use.

    :raises AttributeError: ``name`` is not one of ``__all__``.
    """
    if name not in _WHERE:
        raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
    value = getattr(importlib.import_module(f'.{_WHERE[name]}', __name__), name)
    globals()[name] = value
    return value


def __dir__() -> List[str]:
    """Return the module's names, the lazily imported ones included."""
    return sorted(set(globals()) | set(__all__))
