"""
What every motion model shares: the model names, bat samples, the path protocol, tangents.

Pure Python (no numpy, no ROS). Times are float seconds on the detector's own clock,
positions metres.
"""

from dataclasses import dataclass
import enum
import math
from typing import Optional, Protocol, Tuple, TypeVar

from ..geometry import Quaternion, sub, swing_rotation, Vector
from ..toi import _kernel
from ...errors import CoreError

MODELS = ('linear', 'rigid', 'spline', 'c2')
"""The motion model names."""

SAMPLES_AHEAD = {'linear': 0, 'rigid': 0, 'spline': 1, 'c2': 0}
"""Samples after an interval's end a model needs before it can move over the interval
(``c2``: its look-ahead on top, ``samples_ahead``)."""


def samples_ahead(model: str, look_ahead: int = 0) -> int:
    """Return the samples after an interval's end the walk waits for under a model."""
    return SAMPLES_AHEAD[model] + (look_ahead if model == 'c2' else 0)


def check_model(model: str) -> str:
    """
    Return ``model`` if it names a motion model.

    :raises CoreError: for any other name.
    """
    if model not in MODELS:
        raise CoreError(f"motion model must be one of {', '.join(MODELS)}, got '{model}'")
    return model


class PathKind(enum.StrEnum):
    """How a bat path moves the bat (``BatPath.kind``; a ``str``)."""

    POINTS = 'points'
    """linear: knob and tip each on their chord."""
    POSE = 'pose'
    """rigid, from poses: position LERP, orientation SLERP, the body offsets carried along."""
    AXIS = 'axis'
    """rigid, from knob and tip: knob LERP, direction SLERP, length LERP."""
    TURNING = 'turning'
    """spline: cubic knob, knob-to-tip turning by a cubic angle, length LERP."""
    C2 = 'c2'
    """c2: knob, unit direction (renormalised) and length, each a windowed not-a-knot spline."""


@dataclass(frozen=True, slots=True)
class BatSample:
    """
    One bat sample: knob and tip (metres), and the pose when the bat came as a pose.

    :ivar knob: knob end, world frame.
    :ivar tip: barrel end, world frame.
    :ivar position: pose origin (pose input only).
    :ivar quaternion: pose orientation, unit, ROS order (x, y, z, w) (pose input only).
    """

    knob: Vector
    tip: Vector
    position: Optional[Vector] = None
    quaternion: Optional[Quaternion] = None


Where = TypeVar('Where', covariant=True)


class MotionPath(Protocol[Where]):
    """
    One body over one sample interval [t0, t1] under a motion model.

    ``Where`` is what ``at`` gives: a point (the ball) or (knob, tip) (the bat). ``centre`` and
    ``radius`` (metres) bound the whole path (every axis point, for the bat) by a sphere.
    """

    t0: float
    t1: float
    h: float
    centre: Vector
    radius: float

    def at(self, t: float) -> Where:
        """Return where the body is at time t (seconds), metres."""

    def deviation(self, ta: float, tb: float) -> float:
        """Return a bound (metres) on how far the body leaves its chord over [ta, tb]."""


Neighbour = Optional[Tuple[float, object]]
"""A sample (time in seconds, value) next to an interval, or None when there is none."""


def _three_point_weights(t_prev: float, t: float, t_next: float) -> Tuple[float, float, float]:
    """Return (w_prev, w_here, w_next): the parabola's slope at t is the weighted sum."""
    h0, h1 = t - t_prev, t_next - t
    w_prev = h1 / (h0 * (h0 + h1))
    w_next = h0 / (h1 * (h0 + h1))
    return w_prev, w_prev - w_next, w_next


def hermite_tangent(t_prev: Optional[float], p_prev: Optional[Vector], t: float, p: Vector,
                    t_next: Optional[float], p_next: Optional[Vector]) -> Vector:
    """
    Return the velocity at sample (t, p) from its neighbours (metres per second).

    With both neighbours, the derivative at t of the parabola through the three samples
    (second-order accurate on uneven stamps); with one, the chord to it; with none, zero.
    """
    if p_prev is not None and p_next is not None:
        w_prev, w_here, w_next = _three_point_weights(t_prev, t, t_next)
        return (w_next * p_next[0] + w_here * p[0] - w_prev * p_prev[0],
                w_next * p_next[1] + w_here * p[1] - w_prev * p_prev[1],
                w_next * p_next[2] + w_here * p[2] - w_prev * p_prev[2])
    if p_next is not None:
        inverse = 1.0 / (t_next - t)
        return ((p_next[0] - p[0]) * inverse, (p_next[1] - p[1]) * inverse,
                (p_next[2] - p[2]) * inverse)
    if p_prev is not None:
        inverse = 1.0 / (t - t_prev)
        return ((p[0] - p_prev[0]) * inverse, (p[1] - p_prev[1]) * inverse,
                (p[2] - p_prev[2]) * inverse)
    return (0.0, 0.0, 0.0)


def hermite_slope(t_prev: Optional[float], v_prev: Optional[float], t: float, v: float,
                  t_next: Optional[float], v_next: Optional[float]) -> float:
    """Return ``hermite_tangent`` of a scalar (an angle: rad/s)."""
    if v_prev is not None and v_next is not None:
        w_prev, w_here, w_next = _three_point_weights(t_prev, t, t_next)
        return w_next * v_next + w_here * v - w_prev * v_prev
    if v_next is not None:
        return (v_next - v) * (1.0 / (t_next - t))
    if v_prev is not None:
        return (v - v_prev) * (1.0 / (t - t_prev))
    return 0.0


def substeps_for(deviation_bound: float, tolerance: float) -> int:
    """Return sub-steps n so that deviation_bound / n^2 <= tolerance (at least 1)."""
    if deviation_bound <= tolerance:
        return 1
    return int(math.ceil(math.sqrt(deviation_bound / tolerance)))


def swing_between(a: BatSample, b: BatSample) -> Vector:
    """Return the rotation (axis times angle, rad) turning a's knob-to-tip onto b's."""
    return swing_rotation(sub(a.tip, a.knob), sub(b.tip, b.knob))


def turn_between(a: BatSample, b: BatSample) -> Tuple[Vector, float]:
    """
    Return how the bat turned from sample a to sample b.

    :returns: (swing rotation vector: axis times angle in radians, world frame, across the
        bat; roll angle about the bat's own axis in radians, 0 for knob/tip points). The swing
        part comes from the knob-to-tip directions, so a roll of the bat cannot leak into it:
        ``geometry.swing_rotation`` of the two knob-to-tip vectors; the roll is the world-frame
        rotation between the quaternions (``geometry.rotation_between``) along the mean of
        those vectors, 0 without both quaternions, for equal ones or a zero mean. Computed by
        the kernel (``toi._kernel.turn_between``: those functions' operations in their order).
    """
    return _kernel.turn_between(a, b)
