"""
A rigid bat swinging about the hands: exact kinematics, poses and velocities.

The batter is right-handed: stands on the third-base side (x < 0) facing +x, and the bat turns
counter-clockwise seen from above (angular velocity roughly +z), the barrel moving toward +y
(the pitcher) at contact. The bat is rigid: its knob-to-tip length never changes. The hands (a
pivot on the bat axis near the knob) follow a smooth path and the bat turns about them in a
fixed, tilted swing plane, with an optional steady roll about its own axis. Quaternions are
``(x, y, z, w)`` (ROS order), unit, rotating the bat body frame into the world. The swing
angle has a Gaussian angular-speed profile (closed form through ``erf``), so the bat turns less
than one revolution over all time and passes through the ball's path at most once.
"""

from dataclasses import dataclass, field
import math
from typing import Dict, Tuple

import numpy as np

from .common import (
    as_times, check_number, check_vector, erf, SQRT_HALF_PI, SQRT_TWO, SQRT_TWO_PI, TimeLike,
    unit, Vector)
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
    A rigid bat turning about the hands in a fixed swing plane.

    Kinematics (closed form, exact derivatives), with ``s = t - reference_time``:

    * swing angle ``theta(t)`` about ``plane_normal`` (right-handed), 0 at ``reference_time``,
      with angular speed ``theta'(t) = peak_angular_speed * exp(-(t - peak_time)^2 /
      (2 angular_width^2))``: the bat starts from rest, speeds up into contact and slows in the
      follow-through, and turns ``total_rotation`` radians over all time;
    * bat direction (knob to tip) ``d(t) = cos(theta) direction + sin(theta) (n x direction)``;
    * hands ``H(t) = hands + hands_peak_velocity * (integral of a Gaussian of width
      hands_width centred on hands_peak_time) + 0.5 hands_acceleration s^2``;
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
    _frame: Dict[str, np.ndarray] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """
        Check the parameters, normalise the directions and precompute the frames.

        :raises ToolError: non-finite values, a non-positive width or angular speed, a
            plane normal parallel to the direction, or a grip outside the bat.
        """
        setattr_ = object.__setattr__
        for name in ('reference_time', 'peak_time', 'hands_peak_time', 'roll_rate'):
            setattr_(self, name, check_number(name, getattr(self, name)))
        for name in ('peak_angular_speed', 'angular_width', 'hands_width'):
            setattr_(self, name, check_number(name, getattr(self, name), positive=True))
        for name in ('hands', 'hands_peak_velocity', 'hands_acceleration'):
            setattr_(self, name, check_vector(name, getattr(self, name)))
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
        })

    @property
    def length(self) -> float:
        """Return the knob-to-tip length in metres, fixed by ``geometry``."""
        return float(self._frame['length'])

    @property
    def total_rotation(self) -> float:
        """Return the angle (rad) the bat turns in its plane over all time (< 2 pi: one pass)."""
        return self.peak_angular_speed * self.angular_width * SQRT_TWO_PI

    def angle(self, t: TimeLike) -> np.ndarray:
        """Return the swing angle in radians at time(s) t (s), 0 at ``reference_time``."""
        times, shape = as_times(t)
        scale = 1.0 / (self.angular_width * SQRT_TWO)
        amplitude = self.peak_angular_speed * self.angular_width * SQRT_HALF_PI
        origin = math.erf((self.reference_time - self.peak_time) * scale)
        return (amplitude * (erf((times - self.peak_time) * scale) - origin)).reshape(shape)

    def angular_speed(self, t: TimeLike) -> np.ndarray:
        """Return the swing angular speed d(theta)/dt (rad/s) at time(s) t (s)."""
        times, shape = as_times(t)
        z = (times - self.peak_time) / self.angular_width
        return (self.peak_angular_speed * np.exp(-0.5 * z * z)).reshape(shape)

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
        return position, velocity

    def _axis(self, times: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return the swing angle (N,), the direction d (N, 3) and n x d (N, 3) at times (N,)."""
        theta = self.angle(times)
        c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
        d, e2 = self._frame['d'][None, :], self._frame['e2'][None, :]
        return theta, c * d + s * e2, c * e2 - s * d

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
        quaternion /= np.linalg.norm(quaternion, axis=1, keepdims=True)
        grip = tuple(self._frame['grip_body'])
        position = hands - np.stack(rotate(tuple(quaternion.T), grip), axis=1)
        return position.reshape(shape + (3,)), quaternion.reshape(shape + (4,))

    def point_velocity(self, t: TimeLike, fraction: float) -> np.ndarray:
        """
        Return the exact velocity (m/s) of the axis point at ``fraction`` (0 knob, 1 tip).

        ``H'(t) + theta'(t) (fraction * length - grip_from_knob) (n x d(t))``: the roll does not
        move points on the axis.

        :returns: (3,) for a float t, t.shape + (3,) for an array.
        """
        times, shape = as_times(t)
        hands_velocity = self._hands(times)[1]
        lever = float(fraction) * self.length - self.grip_from_knob
        across = self._axis(times)[2]
        velocity = hands_velocity + (self.angular_speed(times) * lever)[:, None] * across
        return velocity.reshape(shape + (3,))

    def angular_velocity(self, t: TimeLike) -> np.ndarray:
        """
        Return the bat's angular velocity (rad/s) at time(s) t (s): swing plus roll.

        :returns: (3,) for a float t, t.shape + (3,) for an array.
        """
        times, shape = as_times(t)
        direction = self._axis(times)[1]
        omega = (self.angular_speed(times)[:, None] * self._frame['n'][None, :]
                 + self.roll_rate * direction)
        return omega.reshape(shape + (3,))

    def sweet_spot_fraction(self) -> float:
        """Return the fraction of the sweet spot, 6 in (0.1524 m) from the tip."""
        return 1.0 - SWEET_SPOT_FROM_TIP / self.length
