"""
A rigid bat swinging about the hands: exact kinematics, poses and velocities.

A right-handed batter stands on the third-base side (x < 0) facing +x, and the bat turns
counter-clockwise seen from above (angular velocity roughly +z), the barrel moving toward +y
(the pitcher) at contact; a left-handed one is its mirror image (``families``). The bat is
rigid: its knob-to-tip length never changes. The hands (a pivot on the bat axis near the knob)
follow a smooth path and the bat turns about them in a swing plane, with an optional steady
roll about its own axis. The plane is fixed (today's swings) or tilts: it turns about
``tilt_axis`` by ``tilt_rate s + tilt_acceleration s^2 / 2``, so the rotation axis moves at a few
rad/s, as a real swing's does. Quaternions are ``(x, y, z, w)`` (ROS order), unit, rotating the
bat body frame into the world. The swing angle (``profiles.AngleProfile``) has a Gaussian
angular-speed profile, optionally skewed (angular jerk) and braked after a contact, so the bat
turns less than one revolution over all time and passes through the ball's path at most once.
"""

from dataclasses import dataclass, field
import math
from typing import Dict, Optional, Tuple

import numpy as np

from .common import (
    as_times, check_number, check_vector, erf, SQRT_HALF_PI, SQRT_TWO, SQRT_TWO_PI, TimeLike,
    unit, Vector)
from .profiles import AngleProfile
from ...core.bat import PoseBatGeometry, SWEET_SPOT_FROM_TIP
from ...core.geometry import (
    axis_angle_quaternions, matrix_to_quaternion, quaternion_multiply, rotate)
from ...errors import ToolError


def _perpendicular(axis: np.ndarray) -> np.ndarray:
    """Return a unit vector perpendicular to the unit ``axis``."""
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    return unit('perpendicular', helper - axis * float(helper @ axis))


@dataclass(frozen=True)
class Swing:
    """
    A rigid bat turning about the hands in a swing plane that may tilt.

    Kinematics (closed form, exact derivatives), with ``s = t - reference_time``:

    * swing angle ``theta(t)`` about ``plane_normal`` (right-handed), 0 at ``reference_time``,
      with angular speed ``theta'(t) = peak_angular_speed * exp(-z^2 / 2) * (1 + angular_skew
      z)``, ``z = (t - peak_time) / angular_width``: the bat starts from rest, speeds up into
      contact and slows in the follow-through, and turns ``total_rotation`` radians over all
      time (less after a brake: ``brake_time``, ``brake_fraction``, ``brake_duration``);
    * the plane turns about ``tilt_axis`` by ``phi(s) = tilt_rate s + tilt_acceleration s^2 / 2``
      (rotation ``T``); bat direction (knob to tip) ``d(t) = T (cos(theta) direction +
      sin(theta) (n x direction))``;
    * hands ``H(t) = hands + hands_peak_velocity * (integral of a Gaussian of width
      hands_width centred on hands_peak_time) + hands_acceleration s^2 / 2 + hands_jerk s^3 / 6``;
    * knob ``H - grip_from_knob d``, tip ``knob + length d``;
    * roll ``roll_rate * s`` about the bat's own axis (changes the pose, not knob and tip).

    Every method takes a float time (s) or an array of times and raises ``ToolError``
    for non-finite times.

    :ivar reference_time: instant (s) at which the bat points along ``direction`` with the hands
        at ``hands`` (``make_scenario`` uses the contact time).
    :ivar hands: the hands' pivot point on the bat axis at ``reference_time`` (m).
    :ivar direction: knob-to-tip direction at ``reference_time`` (normalised on construction).
    :ivar plane_normal: axis the bat turns about (made perpendicular to ``direction`` and unit).
    :ivar peak_angular_speed: peak swing angular speed (rad/s, > 0).
    :ivar peak_time: instant (s) of the peak angular speed.
    :ivar angular_width: standard deviation (s) of the angular-speed profile.
    :ivar hands_peak_velocity: the hands' peak velocity from the Gaussian term (m/s).
    :ivar hands_peak_time: instant (s) of that peak.
    :ivar hands_width: standard deviation (s) of the hands' speed profile.
    :ivar hands_acceleration: a constant extra acceleration of the hands (m/s^2): curves the
        hands' path.
    :ivar grip_from_knob: distance (m) from the knob to the hands along the axis.
    :ivar roll_rate: spin of the bat about its own axis (rad/s).
    :ivar geometry: where knob and tip sit in the bat body frame of ``pose``.
    :ivar tilt_axis: the axis the swing plane turns about (unit on construction).
    :ivar tilt_rate: rad/s at ``reference_time``; ``tilt_acceleration``: rad/s^2.
    :ivar angular_skew: the angular-speed profile's skew (dimensionless, |skew| < 1).
    :ivar hands_jerk: a constant jerk of the hands (m/s^3).
    :ivar brake_time: when the bat starts to lose angular speed (s; a contact), None for never.
    :ivar brake_fraction: the fraction it loses (0-1); ``brake_duration``: over how long (s).
    """

    reference_time: float
    hands: Vector
    direction: Vector
    plane_normal: Vector
    peak_angular_speed: float
    peak_time: float
    angular_width: float
    hands_peak_velocity: Vector = (0.0, 0.0, 0.0)
    hands_peak_time: float = 0.0
    hands_width: float = 0.05
    hands_acceleration: Vector = (0.0, 0.0, 0.0)
    grip_from_knob: float = 0.1
    roll_rate: float = 0.0
    geometry: PoseBatGeometry = PoseBatGeometry()
    tilt_axis: Vector = (0.0, 0.0, 1.0)
    tilt_rate: float = 0.0
    tilt_acceleration: float = 0.0
    angular_skew: float = 0.0
    hands_jerk: Vector = (0.0, 0.0, 0.0)
    brake_time: Optional[float] = None
    brake_fraction: float = 0.0
    brake_duration: float = 0.002
    _frame: Dict[str, np.ndarray] = field(init=False, repr=False, compare=False)
    _profile: AngleProfile = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """
        Check the parameters, normalise the directions and precompute the frames.

        :raises ToolError: non-finite values, a non-positive width or angular speed, a
            plane normal parallel to the direction, a grip outside the bat, a skew of 1 or
            more, or a brake fraction outside [0, 1].
        """
        setattr_ = object.__setattr__
        for name in ('reference_time', 'peak_time', 'hands_peak_time', 'roll_rate', 'tilt_rate',
                     'tilt_acceleration', 'angular_skew'):
            setattr_(self, name, check_number(name, getattr(self, name)))
        for name in ('peak_angular_speed', 'angular_width', 'hands_width', 'brake_duration'):
            setattr_(self, name, check_number(name, getattr(self, name), positive=True))
        for name in ('hands', 'hands_peak_velocity', 'hands_acceleration', 'hands_jerk'):
            setattr_(self, name, check_vector(name, getattr(self, name)))
        if abs(self.angular_skew) >= 1.0:
            raise ToolError(f'angular_skew must lie in (-1, 1), got {self.angular_skew!r}')
        fraction = check_number('brake_fraction', self.brake_fraction, minimum=0.0)
        if fraction > 1.0:
            raise ToolError(f'brake_fraction must lie in [0, 1], got {fraction!r}')
        setattr_(self, 'brake_fraction', fraction)
        if self.brake_time is not None:
            setattr_(self, 'brake_time', check_number('brake_time', self.brake_time))
        tilt_axis = unit('tilt_axis', np.array(check_vector('tilt_axis', self.tilt_axis)))
        setattr_(self, 'tilt_axis', tuple(float(v) for v in tilt_axis))
        d = unit('direction', np.array(check_vector('direction', self.direction)))
        n = np.array(check_vector('plane_normal', self.plane_normal))
        n = unit('plane_normal (perpendicular to direction)', n - d * float(n @ d))
        setattr_(self, 'direction', tuple(float(v) for v in d))
        setattr_(self, 'plane_normal', tuple(float(v) for v in n))
        knob_b = np.asarray(self.geometry.knob_offset, dtype=float)
        tip_b = np.asarray(self.geometry.tip_offset, dtype=float)
        length = float(np.linalg.norm(tip_b - knob_b))
        grip = check_number('grip_from_knob', self.grip_from_knob, minimum=0.0)
        if grip > length:
            raise ToolError(f'grip_from_knob {grip} m is beyond the bat ({length} m)')
        setattr_(self, 'grip_from_knob', grip)
        axis_b = (tip_b - knob_b) / length
        # body frame (b1, b2, axis_b) onto world frame (n, d x n, d): axis_b -> d
        b1 = _perpendicular(axis_b)
        body = np.stack([b1, np.cross(axis_b, b1), axis_b], axis=1)
        world = np.stack([n, np.cross(d, n), d], axis=1)
        setattr_(self, '_frame', {
            'd': d, 'n': n, 'e2': np.cross(n, d), 'axis_body': axis_b,
            'q_ref': matrix_to_quaternion(world @ body.T),
            'grip_body': knob_b + grip * axis_b, 'length': np.array(length),
            'tilt_axis': tilt_axis,
        })
        setattr_(self, '_profile', AngleProfile(
            peak=self.peak_angular_speed, peak_time=self.peak_time, width=self.angular_width,
            skew=self.angular_skew, reference_time=self.reference_time,
            brake_time=self.brake_time, brake_fraction=self.brake_fraction,
            brake_duration=self.brake_duration))

    @property
    def length(self) -> float:
        """Return the knob-to-tip length in metres, fixed by ``geometry``."""
        return float(self._frame['length'])

    @property
    def total_rotation(self) -> float:
        """Return the angle (rad) the unbraked bat turns in its plane over all time (< 2 pi)."""
        return self.peak_angular_speed * self.angular_width * SQRT_TWO_PI

    @property
    def tilts(self) -> bool:
        """Return whether the swing plane turns."""
        return self.tilt_rate != 0.0 or self.tilt_acceleration != 0.0

    def angle(self, t: TimeLike) -> np.ndarray:
        """Return the swing angle in radians at time(s) t (s), 0 at ``reference_time``."""
        times, shape = as_times(t)
        return self._profile.angle(times).reshape(shape)

    def angular_speed(self, t: TimeLike) -> np.ndarray:
        """Return the swing angular speed d(theta)/dt (rad/s) at time(s) t (s)."""
        times, shape = as_times(t)
        return self._profile.rate(times).reshape(shape)

    def tilt_angle(self, t: TimeLike) -> np.ndarray:
        """Return the angle (rad) the swing plane has turned about ``tilt_axis`` at time(s) t."""
        times, shape = as_times(t)
        s = times - self.reference_time
        return (s * (self.tilt_rate + 0.5 * self.tilt_acceleration * s)).reshape(shape)

    def _tilt(self, times: np.ndarray, vectors: np.ndarray) -> np.ndarray:
        """Return vectors (N, 3) turned about the tilt axis by the tilt angle at times (N,)."""
        if not self.tilts:
            return vectors
        axis = self._frame['tilt_axis']
        phi = self.tilt_angle(times)[:, None]
        c, s = np.cos(phi), np.sin(phi)
        return (c * vectors + s * np.cross(axis[None, :], vectors)
                + (1.0 - c) * (vectors @ axis)[:, None] * axis[None, :])

    def _hands(self, times: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Return the hands' position (N, 3) m and velocity (N, 3) m/s at times (N,) s."""
        peak = np.asarray(self.hands_peak_velocity)
        accel = np.asarray(self.hands_acceleration)
        scale = 1.0 / (self.hands_width * SQRT_TWO)
        origin = math.erf((self.reference_time - self.hands_peak_time) * scale)
        travel = self.hands_width * SQRT_HALF_PI * (
            erf((times - self.hands_peak_time) * scale) - origin)
        s = (times - self.reference_time)[:, None]
        z = (times - self.hands_peak_time) / self.hands_width
        position = (np.asarray(self.hands)[None, :] + travel[:, None] * peak[None, :]
                    + 0.5 * s * s * accel[None, :])
        velocity = np.exp(-0.5 * z * z)[:, None] * peak[None, :] + s * accel[None, :]
        if any(self.hands_jerk):
            jerk = np.asarray(self.hands_jerk)[None, :]
            position = position + (s * s * s / 6.0) * jerk
            velocity = velocity + (0.5 * s * s) * jerk
        return position, velocity

    def _axis(self, times: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return the swing angle (N,), the direction d (N, 3) and n x d (N, 3) at times (N,)."""
        theta = self.angle(times)
        c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
        d, e2 = self._frame['d'][None, :], self._frame['e2'][None, :]
        return theta, self._tilt(times, c * d + s * e2), self._tilt(times, c * e2 - s * d)

    def hands_position(self, t: TimeLike) -> np.ndarray:
        """Return the hands' pivot (m) at time(s) t (s): (3,) or t.shape + (3,)."""
        times, shape = as_times(t)
        return self._hands(times)[0].reshape(shape + (3,))

    def hands_velocity(self, t: TimeLike) -> np.ndarray:
        """Return the hands' velocity (m/s) at time(s) t (s): (3,) or t.shape + (3,)."""
        times, shape = as_times(t)
        return self._hands(times)[1].reshape(shape + (3,))

    def knob_tip(self, t: TimeLike) -> Tuple[np.ndarray, np.ndarray]:
        """
        Return the knob and the tip (barrel end) (m) at time(s) t (s).

        :returns: ``(knob, tip)``, each (3,) for a float t, t.shape + (3,) for an array.
        """
        times, shape = as_times(t)
        hands = self._hands(times)[0]
        direction = self._axis(times)[1]
        knob = hands - self.grip_from_knob * direction
        tip = knob + self.length * direction
        return knob.reshape(shape + (3,)), tip.reshape(shape + (3,))

    def point(self, t: TimeLike, fraction: float) -> np.ndarray:
        """Return the axis point at ``fraction`` (0 knob, 1 tip) (m) at time(s) t (s)."""
        knob, tip = self.knob_tip(t)
        return knob + float(fraction) * (tip - knob)

    def pose(self, t: TimeLike) -> Tuple[np.ndarray, np.ndarray]:
        """
        Return the bat pose at time(s) t (s): body-frame origin (m) and unit quaternion.

        ``geometry.knob_and_tip(*pose(t))`` equals ``knob_tip(t)`` (to ~1e-15 m). The quaternion
        is ``(x, y, z, w)`` and continuous in t (no sign flips).

        :returns: ``(position, quaternion)``: (3,) and (4,) for a float t, t.shape + (3,) and
            t.shape + (4,) for an array.
        """
        times, shape = as_times(t)
        hands = self._hands(times)[0]
        theta = self.angle(times)
        swing = axis_angle_quaternions(self._frame['n'], theta)
        roll = axis_angle_quaternions(self._frame['axis_body'],
                                      self.roll_rate * (times - self.reference_time))
        reference = np.broadcast_to(self._frame['q_ref'], swing.shape)
        quaternion = quaternion_multiply(quaternion_multiply(swing, reference), roll)
        if self.tilts:
            tilt = axis_angle_quaternions(self._frame['tilt_axis'], self.tilt_angle(times))
            quaternion = quaternion_multiply(tilt, quaternion)
        quaternion /= np.linalg.norm(quaternion, axis=1, keepdims=True)
        grip = tuple(self._frame['grip_body'])
        position = hands - np.stack(rotate(tuple(quaternion.T), grip), axis=1)
        return position.reshape(shape + (3,)), quaternion.reshape(shape + (4,))

    def point_velocity(self, t: TimeLike, fraction: float) -> np.ndarray:
        """
        Return the exact velocity (m/s) of the axis point at ``fraction`` (0 knob, 1 tip).

        ``H'(t) + (fraction * length - grip_from_knob) (theta'(t) T n x d(t) + phi'(t) a x
        d(t))``: the roll does not move points on the axis.

        :returns: (3,) for a float t, t.shape + (3,) for an array.
        """
        times, shape = as_times(t)
        hands_velocity = self._hands(times)[1]
        lever = float(fraction) * self.length - self.grip_from_knob
        _, direction, across = self._axis(times)
        velocity = hands_velocity + (self.angular_speed(times) * lever)[:, None] * across
        if self.tilts:
            velocity = velocity + lever * self._tilt_rate(times)[:, None] * np.cross(
                self._frame['tilt_axis'][None, :], direction)
        return velocity.reshape(shape + (3,))

    def _tilt_rate(self, times: np.ndarray) -> np.ndarray:
        """Return phi'(t) (rad/s) at times (N,)."""
        return self.tilt_rate + self.tilt_acceleration * (times - self.reference_time)

    def angular_velocity(self, t: TimeLike) -> np.ndarray:
        """
        Return the bat's angular velocity (rad/s) at time(s) t (s): swing plus roll.

        :returns: (3,) for a float t, t.shape + (3,) for an array.
        """
        times, shape = as_times(t)
        direction = self._axis(times)[1]
        normal = self._tilt(times, np.broadcast_to(self._frame['n'], direction.shape))
        omega = self.angular_speed(times)[:, None] * normal + self.roll_rate * direction
        if self.tilts:
            omega = omega + self._tilt_rate(times)[:, None] * self._frame['tilt_axis'][None, :]
        return omega.reshape(shape + (3,))

    def sweet_spot_fraction(self) -> float:
        """Return the fraction of the sweet spot, 6 in (0.1524 m) from the tip."""
        return 1.0 - SWEET_SPOT_FROM_TIP / self.length
