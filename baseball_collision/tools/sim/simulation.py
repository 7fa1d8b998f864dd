"""
Continuous-time ground truth for a bat swinging at a pitched ball, and tracker-like samples of it.

Pure Python + numpy; no ROS imports. SI units throughout: metres, seconds, m/s, rad, rad/s.

Conventions:

* World frame: z up (gravity along -z), home plate near the origin, the pitch travels roughly
  toward -y (the pitcher releases at y ~ +16.5..17 m). Looking from the catcher toward the
  pitcher, x points right (toward first base).
* The batter is right-handed: stands on the third-base side (x < 0) facing +x, and the bat turns
  counter-clockwise seen from above (angular velocity roughly +z), the barrel moving toward +y
  (the pitcher) at contact.
* The bat is rigid: its knob-to-tip length never changes. The hands (a pivot on the bat axis near
  the knob) follow a smooth path and the bat turns about them in a fixed, tilted swing plane,
  with an optional steady roll about its own axis.
* Time inside this module is float seconds relative to the scenario start (a scenario runs over
  ``[0, t_end]``); sample stamps are integer nanoseconds, ``start_ns + round(t * 1e9)``.
* Quaternions are ``(x, y, z, w)`` (ROS order), unit, rotating the bat body frame into the world.

Contents:

* ``Pitch``: a ball under gravity and quadratic air drag, integrated by RK4 on a fixed step and
  interpolated by cubic Hermite through the stored positions and velocities (positions good to
  ~1e-12 m; see the tests).
* ``Swing``: the bat's exact kinematics: ``knob_tip``, ``pose``, ``point_velocity``,
  ``angular_velocity``. The swing angle in the plane has a Gaussian angular-speed profile
  (closed form through ``erf``), so the bat turns less than one revolution over all time and
  passes through the ball's path at most once.
* ``Scenario`` / ``make_scenario``: a pitch and a swing aimed at each other so that one kind of
  event happens ('barrel', 'end_cap', 'handle', 'graze', 'miss_over', 'miss_under'), with its
  ``Truth``: the exact first contact of the continuous motion (dense evaluation of the gap on a
  20 us grid, local minima refined so a shallow graze is not lost, bisection to 1e-12 s) against
  the same geometry the package uses: the ball sphere against the union of the capsules of
  ``profile.segments()`` placed on knob-tip by fraction.
* ``sample``: the truth as a tracker reports it (nominal rate, timestamp jitter, a stamp grid,
  position noise); ``truth_dict``: the truth as JSON for a truth file beside a bag.
"""

from dataclasses import dataclass, field
import math
from typing import Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from ...core.bat import BatProfile, PoseBatGeometry, SWEET_SPOT_FROM_TIP, WOOD_BAT_34
from ...core.toi import distance
from ...errors import ToolError

GRAVITY = 9.80665
"""Standard gravity (m/s^2), along -z."""

AIR_DENSITY = 1.2
"""Air density (kg/m^3)."""

DRAG_COEFFICIENT = 0.35
"""Drag coefficient of a pitched baseball (dimensionless)."""

BALL_MASS = 0.145
"""Baseball mass (kg)."""

BALL_RADIUS = 0.0366
"""Baseball radius (m)."""

MPH = 0.44704
"""One mile per hour in m/s."""

KINDS = ('barrel', 'end_cap', 'handle', 'graze', 'miss_over', 'miss_under')
"""Scenario kinds ``make_scenario`` builds (``Scenario`` also accepts ``'custom'``)."""

TRUTH_GRID_S = 2e-5
"""Step (s) of the dense gap evaluation behind ``Truth``."""

TRUTH_TIME_TOLERANCE_S = 1e-12
"""Width (s) of the final bisection bracket of the first-contact time."""

DEFAULT_START_NS = 1_700_000_000_000_000_000
"""Default absolute stamp (ns since the epoch) of the scenario start in ``sample``."""

Vector = Tuple[float, float, float]
TimeLike = Union[float, Sequence[float], np.ndarray]

_SQRT_HALF_PI = math.sqrt(0.5 * math.pi)
_SQRT_TWO = math.sqrt(2.0)
_SQRT_TWO_PI = math.sqrt(2.0 * math.pi)
_REFINE_POINTS = 65  # points per pass of the crossing and minimum refinements


# ----------------------------------------------------------------------------------------------
# Small helpers


def _vector(name: str, value: Sequence[float]) -> Vector:
    """
    Return ``value`` as 3 finite floats.

    :raises ToolError: not 3 finite numbers.
    """
    try:
        x, y, z = (float(v) for v in value)
    except (TypeError, ValueError) as error:
        raise ToolError(f'{name} must be 3 numbers, got {value!r}') from error
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
        raise ToolError(f'{name} must be finite, got {value!r}')
    return (x, y, z)


def _number(name: str, value: float, minimum: Optional[float] = None,
            positive: bool = False) -> float:
    """
    Return ``value`` as a finite float, optionally > 0 or >= ``minimum``.

    :raises ToolError: not a finite number, or out of range.
    """
    try:
        number = float(value)
    except (TypeError, ValueError) as error:
        raise ToolError(f'{name} must be a number, got {value!r}') from error
    if not math.isfinite(number):
        raise ToolError(f'{name} must be finite, got {value!r}')
    if positive and number <= 0.0:
        raise ToolError(f'{name} must be > 0, got {value!r}')
    if minimum is not None and number < minimum:
        raise ToolError(f'{name} must be >= {minimum}, got {value!r}')
    return number


def _unit(name: str, value: np.ndarray) -> np.ndarray:
    """
    Return ``value`` scaled to unit length.

    :raises ToolError: a (near) zero vector.
    """
    norm = float(np.linalg.norm(value))
    if not norm > 1e-12:
        raise ToolError(f'{name} must not be a zero vector, got {value!r}')
    return value / norm


def _times(t: TimeLike) -> Tuple[np.ndarray, Tuple[int, ...]]:
    """
    Return times flattened to (N,) float64 and the input shape.

    :raises ToolError: non-finite times.
    """
    array = np.asarray(t, dtype=float)
    if not np.all(np.isfinite(array)):
        raise ToolError('times must be finite seconds')
    return array.reshape(-1), array.shape


def _erf(x: np.ndarray) -> np.ndarray:
    """Return the error function of every element of x (numpy has none)."""
    return np.fromiter((math.erf(v) for v in x), dtype=float, count=x.size)


def _quaternion_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the Hamilton products a b of quaternions (..., 4) in (x, y, z, w) order."""
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack([
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ], axis=-1)


def _axis_angle_quaternions(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Return quaternions (N, 4) turning by ``angles`` (N,) rad about the unit ``axis`` (3,)."""
    half = 0.5 * angles
    return np.concatenate([np.sin(half)[:, None] * axis[None, :], np.cos(half)[:, None]], axis=1)


def _rotate(quaternions: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """Return ``vector`` (3,) rotated by each unit quaternion of (N, 4): (N, 3)."""
    q = quaternions[:, :3]
    w = quaternions[:, 3:4]
    t = 2.0 * np.cross(q, vector[None, :])
    return vector[None, :] + w * t + np.cross(q, t)


def _matrix_to_quaternion(matrix: np.ndarray) -> np.ndarray:
    """Return the unit quaternion (x, y, z, w) of a rotation matrix (Shepperd's method)."""
    m = matrix
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s]
    quaternion = np.array(q)
    return quaternion / np.linalg.norm(quaternion)


def _perpendicular(axis: np.ndarray) -> np.ndarray:
    """Return a unit vector perpendicular to the unit ``axis``."""
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    return _unit('perpendicular', helper - axis * float(helper @ axis))


# ----------------------------------------------------------------------------------------------
# The pitch


def _rk4_step(state: Tuple[float, ...], h: float, k: float, g: float) -> Tuple[float, ...]:
    """
    Advance ``(x, y, z, vx, vy, vz)`` by one RK4 step of ``h`` seconds (h < 0 goes back).

    Acceleration: ``-k |v| v - g z_hat`` (quadratic drag with ``k = rho Cd A / (2 m)``).
    Pure floats: a pitch takes hundreds of steps and numpy's per-call cost would dominate.
    """
    x, y, z, vx, vy, vz = state
    half = 0.5 * h
    c1 = k * math.sqrt(vx * vx + vy * vy + vz * vz)
    ax1, ay1, az1 = -c1 * vx, -c1 * vy, -c1 * vz - g
    ux, uy, uz = vx + half * ax1, vy + half * ay1, vz + half * az1
    c2 = k * math.sqrt(ux * ux + uy * uy + uz * uz)
    ax2, ay2, az2 = -c2 * ux, -c2 * uy, -c2 * uz - g
    wx, wy, wz = vx + half * ax2, vy + half * ay2, vz + half * az2
    c3 = k * math.sqrt(wx * wx + wy * wy + wz * wz)
    ax3, ay3, az3 = -c3 * wx, -c3 * wy, -c3 * wz - g
    px, py, pz = vx + h * ax3, vy + h * ay3, vz + h * az3
    c4 = k * math.sqrt(px * px + py * py + pz * pz)
    ax4, ay4, az4 = -c4 * px, -c4 * py, -c4 * pz - g
    sixth = h / 6.0
    return (x + sixth * (vx + 2.0 * (ux + wx) + px),
            y + sixth * (vy + 2.0 * (uy + wy) + py),
            z + sixth * (vz + 2.0 * (uz + wz) + pz),
            vx + sixth * (ax1 + 2.0 * (ax2 + ax3) + ax4),
            vy + sixth * (ay1 + 2.0 * (ay2 + ay3) + ay4),
            vz + sixth * (az1 + 2.0 * (az2 + az3) + az4))


@dataclass(frozen=True)
class Pitch:
    """
    A pitched ball under gravity and quadratic air drag (no spin).

    The flight is integrated by RK4 on a fixed ``step`` from the release over ``duration``
    seconds; ``position`` and ``velocity`` interpolate by cubic Hermite through the stored
    positions and velocities. With the default 1 ms step both errors are far below 1e-9 m
    (measured ~4e-14 m against a 20 us integration; RK4 and the Hermite cubic are exact for the
    drag-free parabola).

    :ivar release_position: ball centre at release (m).
    :ivar release_velocity: ball velocity at release (m/s).
    :ivar release_time: release instant (s, scenario time; negative when released before the
        scenario starts).
    :ivar duration: seconds after the release over which the flight is defined.
    :ivar drag: apply air drag ``F = 0.5 rho Cd A v^2`` against the velocity.
    :ivar drag_coefficient: Cd.
    :ivar air_density: rho (kg/m^3).
    :ivar mass: ball mass (kg).
    :ivar radius: ball radius (m); A = pi radius^2.
    :ivar gravity: gravitational acceleration (m/s^2) along -z.
    :ivar step: integration step (s).
    """

    release_position: Vector
    release_velocity: Vector
    release_time: float = 0.0
    duration: float = 1.0
    drag: bool = True
    drag_coefficient: float = DRAG_COEFFICIENT
    air_density: float = AIR_DENSITY
    mass: float = BALL_MASS
    radius: float = BALL_RADIUS
    gravity: float = GRAVITY
    step: float = 1e-3
    _positions: np.ndarray = field(init=False, repr=False, compare=False)
    _velocities: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """
        Check the parameters and integrate the flight.

        :raises ToolError: non-finite or out-of-range parameters.
        """
        setattr_ = object.__setattr__
        setattr_(self, 'release_position', _vector('release_position', self.release_position))
        setattr_(self, 'release_velocity', _vector('release_velocity', self.release_velocity))
        setattr_(self, 'release_time', _number('release_time', self.release_time))
        setattr_(self, 'duration', _number('duration', self.duration, positive=True))
        for name in ('drag_coefficient', 'air_density', 'radius', 'gravity'):
            setattr_(self, name, _number(name, getattr(self, name), minimum=0.0))
        setattr_(self, 'mass', _number('mass', self.mass, positive=True))
        setattr_(self, 'step', _number('step', self.step, positive=True))
        steps = max(1, int(math.ceil(self.duration / self.step - 1e-9)))
        if steps > 10_000_000:
            raise ToolError(f'duration / step is too many steps ({steps})')
        state = self.release_position + self.release_velocity
        k, g = self.drag_constant, self.gravity
        states = [state]
        for _ in range(steps):
            state = _rk4_step(state, self.step, k, g)
            states.append(state)
        array = np.array(states)
        setattr_(self, '_positions', array[:, :3])
        setattr_(self, '_velocities', array[:, 3:])

    @classmethod
    def through(cls, position: Sequence[float], velocity: Sequence[float], time: float, *,
                release_y: float = 16.8, end_time: Optional[float] = None,
                **parameters) -> 'Pitch':
        """
        Build the pitch that passes ``position`` with ``velocity`` at ``time``.

        The state is integrated backward (same RK4 step) until the ball is at ``y >=
        release_y``; that step is the release, so the forward flight passes the given state at
        ``time`` to integration round-off (~1e-12 m).

        :param position: ball centre at ``time`` (m).
        :param velocity: ball velocity at ``time`` (m/s); its y component must be < 0.
        :param time: the instant (s, scenario time).
        :param release_y: y (m) of the release; the pitcher is at +y.
        :param end_time: last instant (s) the pitch must cover (default ``time + 0.5``).
        :param parameters: any other ``Pitch`` field (``drag``, ``step``, ...).

        :returns: The pitch, released at or just beyond ``release_y``.

        :raises ToolError: a ball not travelling toward -y, or bad parameters.
        """
        p = _vector('position', position)
        v = _vector('velocity', velocity)
        t = _number('time', time)
        if not v[1] < 0.0:
            raise ToolError(f'the pitch must travel toward -y, got velocity {v!r}')
        probe = cls(p, v, t, duration=1e-3, **{
            k: value for k, value in parameters.items() if k != 'duration'})
        state = p + v
        steps = 0
        while state[1] < release_y:
            state = _rk4_step(state, -probe.step, probe.drag_constant, probe.gravity)
            steps += 1
            if steps * probe.step > 10.0 or state[4] >= 0.0:
                raise ToolError(
                    f'a pitch through {p!r} at {v!r} m/s does not come from y = {release_y} m')
        release_time = t - steps * probe.step
        end = t + 0.5 if end_time is None else _number('end_time', end_time)
        parameters = dict(parameters)
        parameters['duration'] = max(end - release_time, probe.step)
        return cls(tuple(state[:3]), tuple(state[3:]), release_time, **parameters)

    @property
    def drag_constant(self) -> float:
        """Return ``k = rho Cd pi r^2 / (2 m)`` (1/m); the drag deceleration is ``k v^2``."""
        if not self.drag:
            return 0.0
        area = math.pi * self.radius * self.radius
        return 0.5 * self.air_density * self.drag_coefficient * area / self.mass

    @property
    def end_time(self) -> float:
        """Return the last instant (s) the flight is defined at."""
        return self.release_time + (self._positions.shape[0] - 1) * self.step

    def _hermite(self, t: TimeLike, derivative: bool) -> np.ndarray:
        """
        Return the Hermite position (or its derivative) at times t: shape t.shape + (3,).

        :raises ToolError: a time outside [release_time, end_time].
        """
        times, shape = _times(t)
        u = (times - self.release_time) / self.step
        last = self._positions.shape[0] - 1
        if times.size and (u.min() < -1e-9 or u.max() > last + 1e-9):
            raise ToolError(
                f'pitch times must lie in [{self.release_time}, {self.end_time}] s, got '
                f'[{times.min()}, {times.max()}]')
        index = np.clip(np.floor(u).astype(int), 0, last - 1)
        s = (u - index)[:, None]
        p0, p1 = self._positions[index], self._positions[index + 1]
        m0, m1 = self._velocities[index] * self.step, self._velocities[index + 1] * self.step
        s2 = s * s
        if derivative:
            out = ((6.0 * s2 - 6.0 * s) * (p0 - p1) + (3.0 * s2 - 4.0 * s + 1.0) * m0
                   + (3.0 * s2 - 2.0 * s) * m1) / self.step
        else:
            s3 = s2 * s
            out = ((2.0 * s3 - 3.0 * s2 + 1.0) * p0 + (s3 - 2.0 * s2 + s) * m0
                   + (3.0 * s2 - 2.0 * s3) * p1 + (s3 - s2) * m1)
        return out.reshape(shape + (3,))

    def position(self, t: TimeLike) -> np.ndarray:
        """
        Return the ball centre (m) at time(s) t (s): (3,) for a float, t.shape + (3,) else.

        :raises ToolError: a time outside the integrated flight.
        """
        return self._hermite(t, derivative=False)

    def velocity(self, t: TimeLike) -> np.ndarray:
        """
        Return the ball's velocity in m/s at time(s) t (s), shaped as ``position``.

        :raises ToolError: a time outside the integrated flight.
        """
        return self._hermite(t, derivative=True)


# ----------------------------------------------------------------------------------------------
# The swing


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
            setattr_(self, name, _number(name, getattr(self, name)))
        for name in ('peak_angular_speed', 'angular_width', 'hands_width'):
            setattr_(self, name, _number(name, getattr(self, name), positive=True))
        for name in ('hands', 'hands_peak_velocity', 'hands_acceleration'):
            setattr_(self, name, _vector(name, getattr(self, name)))
        d = _unit('direction', np.array(_vector('direction', self.direction)))
        n = np.array(_vector('plane_normal', self.plane_normal))
        n = _unit('plane_normal (perpendicular to direction)', n - d * float(n @ d))
        setattr_(self, 'direction', tuple(float(v) for v in d))
        setattr_(self, 'plane_normal', tuple(float(v) for v in n))
        knob_b = np.asarray(self.geometry.knob_offset, dtype=float)
        tip_b = np.asarray(self.geometry.tip_offset, dtype=float)
        length = float(np.linalg.norm(tip_b - knob_b))
        grip = _number('grip_from_knob', self.grip_from_knob, minimum=0.0)
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
            'q_ref': _matrix_to_quaternion(world @ body.T),
            'grip_body': knob_b + grip * axis_b, 'length': np.array(length),
        })

    @property
    def length(self) -> float:
        """Return the knob-to-tip length in metres, fixed by ``geometry``."""
        return float(self._frame['length'])

    @property
    def total_rotation(self) -> float:
        """Return the angle (rad) the bat turns in its plane over all time (< 2 pi: one pass)."""
        return self.peak_angular_speed * self.angular_width * _SQRT_TWO_PI

    def angle(self, t: TimeLike) -> np.ndarray:
        """Return the swing angle in radians at time(s) t (s), 0 at ``reference_time``."""
        times, shape = _times(t)
        scale = 1.0 / (self.angular_width * _SQRT_TWO)
        amplitude = self.peak_angular_speed * self.angular_width * _SQRT_HALF_PI
        origin = math.erf((self.reference_time - self.peak_time) * scale)
        return (amplitude * (_erf((times - self.peak_time) * scale) - origin)).reshape(shape)

    def angular_speed(self, t: TimeLike) -> np.ndarray:
        """Return the swing angular speed d(theta)/dt (rad/s) at time(s) t (s)."""
        times, shape = _times(t)
        z = (times - self.peak_time) / self.angular_width
        return (self.peak_angular_speed * np.exp(-0.5 * z * z)).reshape(shape)

    def _hands(self, times: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Return the hands' position (N, 3) m and velocity (N, 3) m/s at times (N,) s."""
        peak = np.asarray(self.hands_peak_velocity)
        accel = np.asarray(self.hands_acceleration)
        scale = 1.0 / (self.hands_width * _SQRT_TWO)
        origin = math.erf((self.reference_time - self.hands_peak_time) * scale)
        travel = self.hands_width * _SQRT_HALF_PI * (
            _erf((times - self.hands_peak_time) * scale) - origin)
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
        times, shape = _times(t)
        return self._hands(times)[0].reshape(shape + (3,))

    def hands_velocity(self, t: TimeLike) -> np.ndarray:
        """Return the hands' velocity (m/s) at time(s) t (s): (3,) or t.shape + (3,)."""
        times, shape = _times(t)
        return self._hands(times)[1].reshape(shape + (3,))

    def knob_tip(self, t: TimeLike) -> Tuple[np.ndarray, np.ndarray]:
        """
        Return the knob and the tip (barrel end) (m) at time(s) t (s).

        :returns: ``(knob, tip)``, each (3,) for a float t, t.shape + (3,) for an array.
        """
        times, shape = _times(t)
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
        times, shape = _times(t)
        hands = self._hands(times)[0]
        theta = self.angle(times)
        swing = _axis_angle_quaternions(self._frame['n'], theta)
        roll = _axis_angle_quaternions(self._frame['axis_body'],
                                       self.roll_rate * (times - self.reference_time))
        reference = np.broadcast_to(self._frame['q_ref'], swing.shape)
        quaternion = _quaternion_multiply(_quaternion_multiply(swing, reference), roll)
        quaternion /= np.linalg.norm(quaternion, axis=1, keepdims=True)
        position = hands - _rotate(quaternion, self._frame['grip_body'])
        return position.reshape(shape + (3,)), quaternion.reshape(shape + (4,))

    def point_velocity(self, t: TimeLike, fraction: float) -> np.ndarray:
        """
        Return the exact velocity (m/s) of the axis point at ``fraction`` (0 knob, 1 tip).

        ``H'(t) + theta'(t) (fraction * length - grip_from_knob) (n x d(t))``: the roll does not
        move points on the axis.

        :returns: (3,) for a float t, t.shape + (3,) for an array.
        """
        times, shape = _times(t)
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
        times, shape = _times(t)
        direction = self._axis(times)[1]
        omega = (self.angular_speed(times)[:, None] * self._frame['n'][None, :]
                 + self.roll_rate * direction)
        return omega.reshape(shape + (3,))

    def sweet_spot_fraction(self) -> float:
        """Return the fraction of the sweet spot, 6 in (0.1524 m) from the tip."""
        return 1.0 - SWEET_SPOT_FROM_TIP / self.length


# ----------------------------------------------------------------------------------------------
# Truth


@dataclass(frozen=True)
class Truth:
    """
    What really happened in a scenario, from the continuous motion.

    Contact fields are None for a miss.

    :ivar contact: the ball touched the bat (gap <= 0) within the scenario.
    :ivar time_s: first-contact instant (s, scenario time), to 1e-12 s.
    :ivar point: contact point on the bat surface (m).
    :ivar normal: unit normal at contact, from the bat axis toward the ball centre.
    :ivar bat_fraction: contact position along knob-tip (0 knob, 1 tip), as the solver reports
        it (the closest axis point of the touching capsule).
    :ivar distance_from_knob_m: ``bat_fraction * length`` (m).
    :ivar distance_from_tip_m: ``(1 - bat_fraction) * length`` (m).
    :ivar feature: ``'side'``, ``'knob_end'`` or ``'tip_end'``: the part of the bat touched.
    :ivar sweet_spot_speed_mps: speed of the axis point 0.1524 m from the tip at contact (m/s).
    :ivar ball_speed_mps: ball speed at contact (m/s).
    :ivar bat_speed_at_contact_mps: speed of the axis point at ``bat_fraction`` at contact (m/s).
    :ivar min_gap_m: smallest gap over the scenario (m); negative is the deepest overlap.
    :ivar min_gap_time_s: when it happens (s).
    :ivar min_gap_vector: ``min_gap_m`` times the unit normal from the bat axis toward the ball
        centre at that instant: from the bat surface to the ball surface for a miss (m).
    :ivar min_gap_fraction: fraction along knob-tip of the closest axis point at that instant.
    """

    contact: bool
    time_s: Optional[float]
    point: Optional[Vector]
    normal: Optional[Vector]
    bat_fraction: Optional[float]
    distance_from_knob_m: Optional[float]
    distance_from_tip_m: Optional[float]
    feature: Optional[str]
    sweet_spot_speed_mps: Optional[float]
    ball_speed_mps: Optional[float]
    bat_speed_at_contact_mps: Optional[float]
    min_gap_m: float
    min_gap_time_s: float
    min_gap_vector: Vector
    min_gap_fraction: float


def _segment_gaps(ball: np.ndarray, knob: np.ndarray, tip: np.ndarray, profile: BatProfile,
                  ball_radius: float) -> np.ndarray:
    """Return the gap (m) of the ball to every capsule of the profile: (S, N) for (N, 3) input."""
    axis = tip - knob
    rows = []
    for f0, f1, radius in profile.segments():
        start = knob + f0 * axis
        end = knob + f1 * axis
        rows.append(distance(0.0, ball, ball, end, end, start, start, ball_radius, radius, 1.0))
    return np.array(rows)


@dataclass(frozen=True)
class _Closest:
    """The closest capsule of a profile to the ball at one instant."""

    gap: float
    point: np.ndarray
    normal: np.ndarray
    fraction: float
    feature: str


def _closest(ball: np.ndarray, knob: np.ndarray, tip: np.ndarray, profile: BatProfile,
             ball_radius: float) -> _Closest:
    """Return the gap, surface point, normal, fraction and feature of the nearest capsule."""
    segments = profile.segments()
    axis = tip - knob
    best = None
    for index, (f0, f1, radius) in enumerate(segments):
        start = knob + f0 * axis
        piece = (f1 - f0) * axis
        piece2 = float(piece @ piece)
        along = float((ball - start) @ piece)
        local = 0.0 if piece2 == 0.0 else min(1.0, max(0.0, along / piece2))
        centre = start + local * piece
        offset = ball - centre
        length = float(np.linalg.norm(offset))
        gap = length - radius - ball_radius
        if best is None or gap < best[0]:
            best = (gap, index, local, centre, offset, length, radius, f0, f1)
    gap, index, local, centre, offset, length, radius, f0, f1 = best
    normal = offset / length if length > 1e-12 else _perpendicular(axis / np.linalg.norm(axis))
    feature = 'side'
    if local <= 0.0 and index == 0:
        feature = 'knob_end'
    elif local >= 1.0 and index == len(segments) - 1:
        feature = 'tip_end'
    return _Closest(gap=gap, point=centre + radius * normal, normal=normal,
                    fraction=f0 + (f1 - f0) * local, feature=feature)


def _refine_crossing(gaps_at: Callable[[np.ndarray], np.ndarray], lo: float, hi: float,
                     tolerance: float) -> float:
    """
    Return the end of a bracket, at most ``tolerance`` wide, past the first sign change.

    The gap is > 0 at ``lo`` and <= 0 at ``hi``; each pass evaluates it on ``_REFINE_POINTS``
    points across the bracket and keeps the grid cell of the first point with gap <= 0.
    """
    while hi - lo > tolerance:
        times = np.linspace(lo, hi, _REFINE_POINTS)
        touching = np.flatnonzero(gaps_at(times[1:]) <= 0.0)
        index = int(touching[0]) + 1 if touching.size else _REFINE_POINTS - 1
        new_lo, new_hi = float(times[index - 1]), float(times[index])
        if (new_lo, new_hi) == (lo, hi) or not new_lo < new_hi:
            break
        lo, hi = new_lo, new_hi
    return hi


def _refine_minimum(gaps_at: Callable[[np.ndarray], np.ndarray], lo: float, hi: float,
                    tolerance: float) -> Tuple[float, float]:
    """
    Return (time, gap) of the minimum of a gap unimodal on [lo, hi] to within ``tolerance`` s.

    Each pass evaluates ``_REFINE_POINTS`` points and keeps the two cells around the smallest.
    """
    best_time, best_gap = lo, math.inf
    while True:
        times = np.linspace(lo, hi, _REFINE_POINTS)
        values = gaps_at(times)
        index = int(np.argmin(values))
        if values[index] <= best_gap:
            best_time, best_gap = float(times[index]), float(values[index])
        new_lo = float(times[max(index - 1, 0)])
        new_hi = float(times[min(index + 1, _REFINE_POINTS - 1)])
        if hi - lo <= tolerance or (new_lo, new_hi) == (lo, hi):
            return best_time, best_gap
        lo, hi = new_lo, new_hi


def compute_truth(swing: Swing, pitch: Pitch, t_end: float, profile: BatProfile = WOOD_BAT_34,
                  ball_radius: float = BALL_RADIUS, grid_s: float = TRUTH_GRID_S) -> Truth:
    """
    Return the exact truth of a swing against a pitch over [0, t_end] seconds.

    The gap (ball sphere against the union of the profile's capsules on knob-tip) of the
    continuous motion is evaluated on a grid of ``grid_s``; every grid local minimum within twice
    the largest grid-to-grid change of zero is refined (nested sub-grids), so a touch shorter than
    the grid step is not lost, and the first sign change is narrowed to
    ``TRUTH_TIME_TOLERANCE_S``. ``time_s`` is the end of that bracket at which the gap is <= 0
    (0.0 when touching at the start). The smallest gap is refined around the smallest grid
    value (and any refined local minimum below it).

    :param swing: the bat's motion.
    :param pitch: the ball's flight; it must cover [0, t_end].
    :param t_end: scenario duration (s, > 0).
    :param profile: the bat's radius profile (scaled to the swing's bat length by fraction).
    :param ball_radius: ball radius (m, >= 0).
    :param grid_s: step (s) of the dense evaluation.

    :returns: The truth.

    :raises ToolError: bad parameters or a pitch not covering [0, t_end].
    """
    t_end = _number('t_end', t_end, positive=True)
    ball_radius = _number('ball_radius', ball_radius, minimum=0.0)
    grid_s = _number('grid_s', grid_s, positive=True)
    if pitch.release_time > 0.0 or pitch.end_time < t_end:
        raise ToolError(
            f'the pitch covers [{pitch.release_time}, {pitch.end_time}] s, not [0, {t_end}] s')

    def gaps_at(times: np.ndarray) -> np.ndarray:
        knob, tip = swing.knob_tip(times)
        return _segment_gaps(pitch.position(times), knob, tip, profile, ball_radius).min(axis=0)

    count = int(math.ceil(t_end / grid_s)) + 1
    grid = np.linspace(0.0, t_end, count)
    values = gaps_at(grid)
    minima = np.flatnonzero((values[1:-1] <= values[:-2]) & (values[1:-1] <= values[2:])) + 1
    # between grid points the gap can dip below a grid value by at most its largest change per
    # step (a Lipschitz bound from the grid itself), doubled for safety
    near = 2.0 * float(np.max(np.abs(np.diff(values)))) if count > 1 else math.inf
    # the first touch: the first grid sign change, or an earlier local minimum that dips <= 0
    first = None
    crossings = np.flatnonzero(values <= 0.0)
    if crossings.size and crossings[0] == 0:
        first = 0.0
    elif crossings.size:
        i = int(crossings[0])
        first = _refine_crossing(gaps_at, float(grid[i - 1]), float(grid[i]),
                                 TRUTH_TIME_TOLERANCE_S)
    refined = {}
    for j in minima:
        if first is not None and grid[j] >= first:
            break
        if values[j] > near:
            continue
        t_min, g_min = _refine_minimum(gaps_at, float(grid[j - 1]), float(grid[j + 1]), 1e-12)
        refined[int(j)] = (t_min, g_min)
        if g_min <= 0.0:
            first = _refine_crossing(gaps_at, float(grid[j - 1]), t_min,
                                     TRUTH_TIME_TOLERANCE_S)
            break
    # the smallest gap over the scenario, refined around the smallest grid value
    k = int(np.argmin(values))
    if k in refined:
        min_time, min_gap = refined[k]
    elif 0 < k < count - 1:
        min_time, min_gap = _refine_minimum(gaps_at, float(grid[k - 1]), float(grid[k + 1]),
                                            1e-12)
    else:
        min_time, min_gap = float(grid[k]), float(values[k])
    for t_min, g_min in refined.values():
        if g_min < min_gap:
            min_time, min_gap = t_min, g_min
    knob, tip = swing.knob_tip(min_time)
    closest = _closest(pitch.position(min_time), knob, tip, profile, ball_radius)
    min_fields = {'min_gap_m': float(min_gap), 'min_gap_time_s': float(min_time),
                  'min_gap_vector': tuple(float(v) for v in closest.normal * min_gap),
                  'min_gap_fraction': float(closest.fraction)}
    if first is None:
        return Truth(contact=False, time_s=None, point=None, normal=None, bat_fraction=None,
                     distance_from_knob_m=None, distance_from_tip_m=None, feature=None,
                     sweet_spot_speed_mps=None, ball_speed_mps=None,
                     bat_speed_at_contact_mps=None, **min_fields)
    knob, tip = swing.knob_tip(first)
    touch = _closest(pitch.position(first), knob, tip, profile, ball_radius)
    length = swing.length
    sweet = swing.point_velocity(first, swing.sweet_spot_fraction())
    return Truth(
        contact=True, time_s=float(first), point=tuple(float(v) for v in touch.point),
        normal=tuple(float(v) for v in touch.normal), bat_fraction=float(touch.fraction),
        distance_from_knob_m=float(touch.fraction * length),
        distance_from_tip_m=float((1.0 - touch.fraction) * length), feature=touch.feature,
        sweet_spot_speed_mps=float(np.linalg.norm(sweet)),
        ball_speed_mps=float(np.linalg.norm(pitch.velocity(first))),
        bat_speed_at_contact_mps=float(np.linalg.norm(swing.point_velocity(first,
                                                                           touch.fraction))),
        **min_fields)


# ----------------------------------------------------------------------------------------------
# Scenarios


@dataclass(frozen=True)
class Scenario:
    """
    A swing against a pitch over [0, t_end] seconds, with its truth.

    ``truth`` is computed on construction when not given (``compute_truth``).

    :ivar name: a label.
    :ivar kind: one of ``KINDS``, or ``'custom'``.
    :ivar swing: the bat's motion.
    :ivar pitch: the ball's flight (covering [0, t_end]).
    :ivar t_end: duration (s).
    :ivar profile: the bat's radius profile.
    :ivar ball_radius: ball radius (m).
    :ivar truth: what happened.
    """

    name: str
    kind: str
    swing: Swing
    pitch: Pitch
    t_end: float
    profile: BatProfile = WOOD_BAT_34
    ball_radius: float = BALL_RADIUS
    truth: Optional[Truth] = None

    def __post_init__(self) -> None:
        """
        Check the kind and compute the truth when not given.

        :raises ToolError: an unknown kind, or as ``compute_truth``.
        """
        if self.kind not in KINDS + ('custom',):
            raise ToolError(f'scenario kind must be one of {KINDS + ("custom",)}, '
                            f'got {self.kind!r}')
        if self.truth is None:
            object.__setattr__(self, 'truth', compute_truth(
                self.swing, self.pitch, self.t_end, self.profile, self.ball_radius))

    def gap(self, t: TimeLike) -> np.ndarray:
        """Return the signed ball-bat gap in metres at time(s) t (s); negative is overlap."""
        times, shape = _times(t)
        knob, tip = self.swing.knob_tip(times)
        gaps = _segment_gaps(self.pitch.position(times), knob, tip, self.profile,
                             self.ball_radius)
        return gaps.min(axis=0).reshape(shape)


def _kind_holds(kind: str, truth: Truth) -> bool:
    """Return whether a truth is an instance of a scenario kind."""
    if kind in ('miss_over', 'miss_under'):
        upward = truth.min_gap_vector[2] > 0.0
        return (not truth.contact and 0.02 <= truth.min_gap_m <= 0.15
                and upward == (kind == 'miss_over'))
    if not truth.contact or truth.time_s is None:
        return False
    if kind == 'barrel':
        return truth.feature == 'side' and 0.05 <= truth.distance_from_tip_m <= 0.25
    if kind == 'end_cap':
        return truth.feature == 'tip_end'
    if kind == 'handle':
        return truth.feature == 'side' and 0.2 <= truth.distance_from_knob_m <= 0.4
    return -0.010 <= truth.min_gap_m <= -0.001  # graze


def _segment_radius(profile: BatProfile, fraction: float) -> float:
    """Return the radius (m) of the profile capsule spanning ``fraction`` (the largest one)."""
    radii = [r for f0, f1, r in profile.segments() if f0 <= fraction <= f1]
    return max(radii) if radii else profile.radius_at(fraction)


def _draw_swing(rng: np.random.Generator, contact_time: float,
                geometry: PoseBatGeometry) -> Swing:
    """Draw a right-handed swing, its reference at the contact time, sweet spot 28-34.5 m/s."""
    azimuth = math.radians(rng.uniform(-20.0, 15.0))  # of the bat from +x toward +y
    elevation = math.radians(rng.uniform(-30.0, 5.0))  # barrel below the hands when < 0
    direction = np.array([math.cos(elevation) * math.cos(azimuth),
                          math.cos(elevation) * math.sin(azimuth), math.sin(elevation)])
    attack = math.radians(rng.uniform(0.0, 15.0))  # the barrel's upward path at contact
    path = np.array([-math.sin(azimuth) * math.cos(attack),
                     math.cos(azimuth) * math.cos(attack), math.sin(attack)])
    path = _unit('path', path - direction * float(path @ direction))
    normal = np.cross(direction, path)
    hands = np.array([rng.uniform(-0.6, -0.45), rng.uniform(0.05, 0.4), rng.uniform(0.85, 1.1)])
    hands_width = rng.uniform(0.035, 0.05)
    hands_lag = rng.uniform(0.02, 0.05)  # the hands' speed peaks before contact
    hands_dir = _unit('hands', np.array([rng.uniform(0.0, 0.4), 1.0, rng.uniform(-0.2, 0.1)]))
    hands_peak = hands_dir * rng.uniform(5.0, 8.0)
    hands_accel = np.array([rng.uniform(-12.0, -4.0), rng.uniform(-4.0, 4.0),
                            rng.uniform(-4.0, 4.0)])
    grip = rng.uniform(0.08, 0.12)
    length = float(np.linalg.norm(np.subtract(geometry.tip_offset, geometry.knob_offset)))
    hands_velocity = hands_peak * math.exp(-0.5 * (hands_lag / hands_width) ** 2)
    # angular speed at contact for the drawn sweet-spot speed
    target = rng.uniform(28.0, 34.5)
    lever = length - SWEET_SPOT_FROM_TIP - grip
    across = np.cross(normal, direction)
    along = float(hands_velocity @ across)
    square = along * along - float(hands_velocity @ hands_velocity) + target * target
    omega_contact = (-along + math.sqrt(max(square, 0.0))) / lever
    lead = rng.uniform(0.15, 0.5)  # peak angular speed after contact, in widths
    peak = omega_contact * math.exp(0.5 * lead * lead)
    width = rng.uniform(4.6, 5.6) / (peak * _SQRT_TWO_PI)  # total rotation < 2 pi
    return Swing(
        reference_time=contact_time, hands=tuple(hands), direction=tuple(direction),
        plane_normal=tuple(normal), peak_angular_speed=peak,
        peak_time=contact_time + lead * width, angular_width=width,
        hands_peak_velocity=tuple(hands_peak), hands_peak_time=contact_time - hands_lag,
        hands_width=hands_width, hands_acceleration=tuple(hands_accel), grip_from_knob=grip,
        roll_rate=rng.uniform(-4.0, 4.0), geometry=geometry)


def _draw_ball_velocity(rng: np.random.Generator, contact: np.ndarray, drag_constant: float,
                        release_y: float) -> np.ndarray:
    """Draw the ball's velocity at contact for a 76-94 mph release about 1.4-2.0 m high."""
    release_speed = rng.uniform(76.0, 94.0) * MPH
    travel = release_y - float(contact[1])
    speed = release_speed * math.exp(-drag_constant * travel)
    flight = travel / (0.5 * (speed + release_speed))
    release_height = rng.uniform(1.5, 1.8)  # the drag-free aim lands ~0.1 m higher
    release_x = rng.uniform(-0.6, 0.6)
    down = (release_height - float(contact[2]) + 0.5 * GRAVITY * flight * flight) / (
        speed * flight)
    across = (float(contact[0]) - release_x) / (speed * flight)
    down = min(max(down, 0.0), 0.3)
    across = min(max(across, -0.1), 0.1)
    along = math.sqrt(1.0 - down * down - across * across)
    return speed * np.array([across, -along, -down])


def _draw_scenario(kind: str, rng: np.random.Generator, lead_s: float, trail_s: float,
                   profile: BatProfile, ball_radius: float,
                   geometry: PoseBatGeometry) -> Optional[Scenario]:
    """
    Draw one candidate scenario of a kind; None when the draw is implausible.

    :raises ToolError: a degenerate draw (the caller draws again).
    """
    contact_time = lead_s + rng.uniform(-0.005, 0.005)
    t_end = lead_s + trail_s
    swing = _draw_swing(rng, contact_time, geometry)
    length = swing.length
    segments = profile.segments()
    if kind == 'barrel':
        fraction = 1.0 - rng.uniform(0.07, 0.22) / length
    elif kind == 'handle':
        fraction = rng.uniform(0.23, 0.37) / length
    elif kind == 'end_cap':
        fraction = segments[-1][1]
    elif kind == 'graze':
        fraction = 1.0 - rng.uniform(0.06, 0.3) / length
    else:
        fraction = 1.0 - rng.uniform(0.06, 0.35) / length
    spot = swing.point(contact_time, fraction)
    reach = ball_radius + _segment_radius(profile, fraction)
    release_y = rng.uniform(16.5, 17.0)
    drag_constant = Pitch((0.0, 0.0, 0.0), (0.0, -1.0, 0.0), duration=1e-3).drag_constant
    velocity = _draw_ball_velocity(rng, spot, drag_constant, release_y)
    # the frame of the encounter: axis d, the ball's motion across it, and "up" across both
    axis = swing.knob_tip(contact_time)
    axis = _unit('axis', axis[1] - axis[0])
    relative = velocity - swing.point_velocity(contact_time, fraction)
    across = relative - axis * float(relative @ axis)
    incoming = _unit('relative velocity', across)
    up = _unit('up', np.cross(axis, incoming))
    if up[2] < 0.0:
        up = -up
    if kind in ('barrel', 'handle'):
        angle = math.radians(rng.uniform(-55.0, 55.0))
        centre = spot + reach * (-math.cos(angle) * incoming + math.sin(angle) * up)
    elif kind == 'end_cap':
        angle = math.radians(rng.uniform(-35.0, 35.0))
        tilt = math.radians(rng.uniform(25.0, 60.0))
        side = -math.cos(angle) * incoming + math.sin(angle) * up
        centre = spot + reach * (math.cos(tilt) * side + math.sin(tilt) * axis)
    elif kind == 'graze':
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        centre = spot + sign * (reach - rng.uniform(0.002, 0.008)) * up
    else:
        sign = 1.0 if kind == 'miss_over' else -1.0
        centre = spot + sign * (reach + rng.uniform(0.03, 0.12)) * up
    pitch = Pitch.through(centre, velocity, contact_time, release_y=release_y,
                          end_time=t_end + 0.01)
    release_speed = math.hypot(*pitch.release_velocity) / MPH
    if not (74.0 <= release_speed <= 96.0 and 1.0 <= pitch.release_position[2] <= 2.6):
        return None
    name = f'{kind}-{int(rng.integers(0, 2 ** 32)):08x}'
    return Scenario(name=name, kind=kind, swing=swing, pitch=pitch, t_end=t_end,
                    profile=profile, ball_radius=ball_radius)


def make_scenario(kind: str, rng: np.random.Generator, *, lead_s: float = 0.15,
                  trail_s: float = 0.10, profile: BatProfile = WOOD_BAT_34,
                  ball_radius: float = BALL_RADIUS,
                  geometry: PoseBatGeometry = PoseBatGeometry(),
                  max_attempts: int = 50) -> Scenario:
    """
    Build a plausible pitch and swing aimed so that one kind of event happens.

    A right-handed swing (sweet spot at 28-34.5 m/s at contact, the hands leading) and a
    76-94 mph pitch released 16.5-17 m away about 1.4-2.0 m high. The contact instant (about
    ``lead_s`` after the start) and spot on the bat are chosen first; the ball is placed there at
    that instant, offset along the contact normal, and the flight integrated backward to the
    release. Kinds:

    * ``'barrel'``: the side of the barrel, 0.05-0.25 m from the tip (along the axis);
    * ``'end_cap'``: the rounded barrel end;
    * ``'handle'``: the side of the bat 0.2-0.4 m from the knob;
    * ``'graze'``: a foul tip: a contact whose deepest overlap is 1-10 mm;
    * ``'miss_over'`` / ``'miss_under'``: no contact, the ball passing 2-15 cm over / under the
      bat (smallest gap, with its vertical component of that sign).

    Each draw is checked against its computed truth and redrawn if the kind does not hold.

    :param kind: one of ``KINDS``.
    :param rng: the random source (the result is a function of its state).
    :param lead_s: seconds from the start to (about) the contact or closest approach.
    :param trail_s: seconds after that to the end.
    :param profile: the bat's radius profile.
    :param ball_radius: ball radius (m).
    :param geometry: where knob and tip sit in the bat body frame of the swing's pose.
    :param max_attempts: draws before giving up.

    :returns: The scenario, running over [0, lead_s + trail_s].

    :raises ToolError: an unknown kind, bad durations, or no draw of the kind within
        ``max_attempts``.
    """
    if kind not in KINDS:
        raise ToolError(f'scenario kind must be one of {KINDS}, got {kind!r}')
    lead_s = _number('lead_s', lead_s, minimum=0.05)
    trail_s = _number('trail_s', trail_s, minimum=0.02)
    failure = None
    for _ in range(max(1, int(max_attempts))):
        try:
            scenario = _draw_scenario(kind, rng, lead_s, trail_s, profile, ball_radius, geometry)
        except ToolError as error:
            failure = error
            continue
        if scenario is not None and _kind_holds(kind, scenario.truth):
            return scenario
    raise ToolError(f'no {kind!r} scenario in {max_attempts} draws') from failure


# ----------------------------------------------------------------------------------------------
# Sampling


@dataclass(frozen=True)
class Samples:
    """
    A scenario as trackers report it.

    Stamps are absolute int64 nanoseconds, strictly increasing; the scenario time of a stamp is
    ``(stamp - start_ns) * 1e-9`` s. Positions are the truth at the stamped instant plus noise.

    :ivar ball_stamps_ns: (N,) int64.
    :ivar ball_positions: (N, 3) ball centres (m).
    :ivar bat_stamps_ns: (M,) int64.
    :ivar bat_positions: (M, 3) bat pose positions (m).
    :ivar bat_quaternions: (M, 4) bat pose orientations, unit (x, y, z, w).
    :ivar knobs: (M, 3) knobs (m), ``geometry.knob_and_tip`` of the (noisy) pose.
    :ivar tips: (M, 3) tips (m), likewise.
    :ivar start_ns: absolute stamp of the scenario start (ns).
    """

    ball_stamps_ns: np.ndarray
    ball_positions: np.ndarray
    bat_stamps_ns: np.ndarray
    bat_positions: np.ndarray
    bat_quaternions: np.ndarray
    knobs: np.ndarray
    tips: np.ndarray
    start_ns: int

    def messages(self, bat: str = 'pose') -> List[Tuple[int, str, Tuple[float, ...]]]:
        """
        Return the samples as a tracker publishes them: ``(stamp_ns, role, values)``.

        In stamp order; at equal stamps the ball comes first, then the bat pose, knob, tip.
        Roles and values are those of ``Detector.add``.

        :param bat: ``'pose'`` (bat poses), ``'points'`` (knob and tip) or ``'both'``.
        :raises ToolError: an unknown ``bat``.
        """
        if bat not in ('pose', 'points', 'both'):
            raise ToolError(f"bat must be 'pose', 'points' or 'both', got '{bat}'")
        rows = [(s, 0, 'ball', tuple(p)) for s, p in zip(self.ball_stamps_ns.tolist(),
                                                         self.ball_positions.tolist())]
        stamps = self.bat_stamps_ns.tolist()
        if bat in ('pose', 'both'):
            rows += [(s, 1, 'bat_pose', tuple(p + q)) for s, p, q in zip(
                stamps, self.bat_positions.tolist(), self.bat_quaternions.tolist())]
        if bat in ('points', 'both'):
            rows += [(s, 2, 'knob', tuple(p)) for s, p in zip(stamps, self.knobs.tolist())]
            rows += [(s, 3, 'tip', tuple(p)) for s, p in zip(stamps, self.tips.tolist())]
        rows.sort(key=lambda row: (row[0], row[1]))
        return [(stamp, role, values) for stamp, _, role, values in rows]


def _stamps(t_end: float, rate_hz: float, rng: np.random.Generator, jitter_s: float,
            grid_s: Optional[float], offset_s: float) -> np.ndarray:
    """Return relative stamps (ns, int64, strictly increasing, within [0, t_end])."""
    count = int(math.floor(t_end * rate_hz)) + 2
    nominal = offset_s + np.arange(count) / rate_hz
    if jitter_s > 0.0:
        nominal = nominal + rng.normal(0.0, jitter_s, count)
    relative = np.rint(nominal * 1e9).astype(np.int64)
    if grid_s is not None:
        step = int(round(grid_s * 1e9))
        relative = np.rint(relative / step).astype(np.int64) * step
    end_ns = int(math.floor(t_end * 1e9))
    relative = relative[(relative >= 0) & (relative <= end_ns)]
    return np.unique(relative)


def sample(scenario: Scenario, rate_hz: float, rng: np.random.Generator, *,
           jitter_s: float = 0.0, grid_s: Optional[float] = None, noise_m: float = 0.0,
           start_ns: int = DEFAULT_START_NS, bat_offset_s: float = 0.0) -> Samples:
    """
    Sample a scenario as a tracker would.

    Sample ``k`` is nominally at ``k / rate_hz`` seconds (plus ``bat_offset_s`` for the bat),
    plus Gaussian jitter of ``jitter_s``, rounded to the nanosecond and then to ``grid_s`` when
    given (``grid_s=0.001`` at 360 Hz gives the 2 and 3 ms steps of real mocap). Stamps outside
    [0, t_end] and repeats are dropped, so stamps strictly increase. Positions are the truth at
    the stamped instant, plus Gaussian noise of ``noise_m`` per axis: one draw per ball sample,
    one per bat sample added to the pose position and so to knob and tip alike (knob and tip
    stay those of the pose). With ``bat_offset_s == 0`` the bat has the ball's stamps.

    :param scenario: what to sample.
    :param rate_hz: nominal sample rate (Hz, > 0).
    :param rng: the random source for jitter and noise (not drawn from when both are 0).
    :param jitter_s: standard deviation of the timestamp jitter (s, >= 0).
    :param grid_s: stamp grid (s, > 0), or None for nanosecond stamps.
    :param noise_m: standard deviation of the position noise per axis (m, >= 0).
    :param start_ns: absolute stamp (ns) of the scenario start.
    :param bat_offset_s: shift (s) of the bat stream's nominal times.

    :returns: The samples.

    :raises ToolError: a rate, jitter, grid or noise out of range.
    """
    rate_hz = _number('rate_hz', rate_hz, positive=True)
    jitter_s = _number('jitter_s', jitter_s, minimum=0.0)
    noise_m = _number('noise_m', noise_m, minimum=0.0)
    bat_offset_s = _number('bat_offset_s', bat_offset_s)
    if grid_s is not None:
        grid_s = _number('grid_s', grid_s, positive=True)
        if round(grid_s * 1e9) < 1:
            raise ToolError(f'grid_s must be at least 1 ns, got {grid_s!r}')
    try:
        start = int(start_ns)
    except (TypeError, ValueError) as error:
        raise ToolError(f'start_ns must be an integer, got {start_ns!r}') from error
    ball_rel = _stamps(scenario.t_end, rate_hz, rng, jitter_s, grid_s, 0.0)
    if bat_offset_s == 0.0:
        bat_rel = ball_rel
    else:
        bat_rel = _stamps(scenario.t_end, rate_hz, rng, jitter_s, grid_s, bat_offset_s)
    ball = scenario.pitch.position(ball_rel * 1e-9)
    bat_times = bat_rel * 1e-9
    position, quaternion = scenario.swing.pose(bat_times)
    knobs, tips = scenario.swing.knob_tip(bat_times)
    if noise_m > 0.0:
        ball = ball + rng.normal(0.0, noise_m, ball.shape)
        shake = rng.normal(0.0, noise_m, position.shape)
        position, knobs, tips = position + shake, knobs + shake, tips + shake
    return Samples(
        ball_stamps_ns=np.int64(start) + ball_rel, ball_positions=ball,
        bat_stamps_ns=np.int64(start) + bat_rel, bat_positions=position,
        bat_quaternions=quaternion, knobs=knobs, tips=tips, start_ns=start)


def truth_dict(scenario: Scenario, start_ns: int = DEFAULT_START_NS) -> Dict[str, object]:
    """
    Return the scenario's truth as a JSON-serialisable dict (for a truth file beside a bag).

    Times are given both as scenario seconds and as absolute stamps
    (``start_ns + round(time_s * 1e9)``); vectors are lists; absent values are None.

    :param scenario: the scenario.
    :param start_ns: absolute stamp (ns) of the scenario start.

    :returns: The dict.
    """
    truth = scenario.truth
    start = int(start_ns)

    def stamp(seconds: Optional[float]) -> Optional[int]:
        return None if seconds is None else start + int(round(seconds * 1e9))

    def listed(vector: Optional[Sequence[float]]) -> Optional[List[float]]:
        return None if vector is None else [float(v) for v in vector]

    return {
        'name': scenario.name,
        'kind': scenario.kind,
        'start_ns': start,
        'end_ns': stamp(scenario.t_end),
        't_end_s': float(scenario.t_end),
        'contact': bool(truth.contact),
        'time_s': truth.time_s,
        'stamp_ns': stamp(truth.time_s),
        'point': listed(truth.point),
        'normal': listed(truth.normal),
        'bat_fraction': truth.bat_fraction,
        'distance_from_knob_m': truth.distance_from_knob_m,
        'distance_from_tip_m': truth.distance_from_tip_m,
        'feature': truth.feature,
        'sweet_spot_speed_mps': truth.sweet_spot_speed_mps,
        'ball_speed_mps': truth.ball_speed_mps,
        'bat_speed_at_contact_mps': truth.bat_speed_at_contact_mps,
        'min_gap_m': truth.min_gap_m,
        'min_gap_time_s': truth.min_gap_time_s,
        'min_gap_stamp_ns': stamp(truth.min_gap_time_s),
        'min_gap_vector': listed(truth.min_gap_vector),
        'min_gap_fraction': truth.min_gap_fraction,
        'ball_radius_m': float(scenario.ball_radius),
        'bat_length_m': scenario.swing.length,
        'bat_profile': {'length_m': scenario.profile.length,
                        'stations': [[d, r] for d, r in scenario.profile.stations]},
        'bat_geometry': {'knob_offset': listed(scenario.swing.geometry.knob_offset),
                         'tip_offset': listed(scenario.swing.geometry.tip_offset)},
    }
