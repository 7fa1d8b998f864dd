"""
The package's errors: one root, one subclass per layer, each raised ``from`` its cause.

Catch :class:`BaseballCollisionError` for anything this package refuses; catch a layer's
error to handle just that layer:

* :class:`CoreError` (also a ``ValueError``): input or configuration the pure core cannot use:
  a non-finite point given to the solver, a bat profile that describes no bat, an unknown motion
  model, a detector parameter out of its range.
* :class:`BagError`: a bag that cannot be read or written (missing, empty, corrupt, truncated,
  without the needed topics, or with topics of the wrong type: :class:`TopicError` for a topic
  asked for).
* :class:`RosError`: a node parameter ROS cannot take, a replay that cannot start.
* :class:`ToolError`: command-line tools: analysis inputs and outputs, truth files,
  simulations, recordings, the demo.
"""


class BaseballCollisionError(Exception):
    """Anything ``baseball_collision`` refuses: the root of the package's errors."""


class CoreError(BaseballCollisionError, ValueError):
    """Input or configuration that the core (solver, bat, motion, detector) cannot use."""


class BagError(BaseballCollisionError):
    """A bag that cannot be read or written as asked."""


class TopicError(BagError):
    """
    A topic asked for (by a flag, a parameter file) that a bag lacks or has of another type.

    :ivar role: the role it was asked for (``ball``, ``bat_pose``, ``knob``, ``tip``).
    """

    def __init__(self, message: str, role: str) -> None:
        super().__init__(message)
        self.role = role


class RosError(BaseballCollisionError):
    """A node parameter or a replay that ROS cannot take."""


class ToolError(BaseballCollisionError):
    """Bad input to a command-line tool (analysis, truth files, simulation, the demo)."""
