"""
Predicted impact: where and when the ball will meet the bat's coming path.

Python and numpy (no ROS). Times are float seconds on the detector's clock,
positions metres. The detector builds the two forecasts from its latest samples and calls
``first_contact``; this module only extrapolates and searches.

* ``BallForecast``: a ballistic path from the ball's state now: constant acceleration (gravity
  plus the drag deceleration at the current speed). Over the 0-300 ms of a prediction the drag
  changes little (a 40 m/s pitch loses ~4% of its speed in 300 ms); the position error of
  holding it constant is (1/6) d(drag)/dt tau^3, under 1 cm at 300 ms and 0.1 mm at 50 ms.
* ``BatForecast``: the bat as a rigid body from its state now: a pivot (the least-accelerating
  axis point, near the hands) moving with constant acceleration, and the bat turning about a
  fixed axis with constant angular acceleration. Or, for a robot arm, a commanded trajectory of
  bat poses (``PlannedBat``), interpolated like the rigid model (position LERP, SLERP).
* ``first_contact``: the exact linear solver on sub-steps of the horizon short enough for the
  chord error tolerance, skipping every stretch where the ball cannot reach the bat (that test
  for all the horizon's coarse steps at once, in numpy: ``positions``, ``speeds``, ``pivots``,
  ``pivot_travels`` evaluate the forecasts at many instants).
"""

from bisect import bisect_left, bisect_right
from dataclasses import dataclass
import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .bat import BatProfile
from .geometry import (
    add, dot, interpolate_pose, lerp, norm, pose_point, Quaternion, quaternion_angle, scale,
    sub, turn_about, Vector)
from .toi import ImpactResult, profile_contact


@dataclass(frozen=True)
class BallForecast:
    """
    The ball from time ``t0`` on, with constant acceleration.

    :ivar t0: start (s); ``position`` (m), ``velocity`` (m/s), ``acceleration`` (m/s^2) at t0.
    """

    t0: float
    position: Vector
    velocity: Vector
    acceleration: Vector

    @classmethod
    def ballistic(cls, t0: float, position: Vector, velocity: Vector, gravity: Vector,
                  drag: float) -> 'BallForecast':
        """
        Return a forecast under gravity (m/s^2 vector) and quadratic drag ``drag`` (1/m).

        The drag deceleration is ``drag * |v| * v``, ``drag = rho Cd A / (2 m)``: about 0.006
        per metre for a baseball.
        """
        speed = norm(velocity)
        acceleration = sub(gravity, scale(velocity, drag * speed))
        return cls(t0=t0, position=position, velocity=velocity, acceleration=acceleration)

    def at(self, t: float) -> Vector:
        """Return the ball centre (m) at time t (s)."""
        tau = t - self.t0
        return add(self.position, add(scale(self.velocity, tau),
                                      scale(self.acceleration, 0.5 * tau * tau)))

    def velocity_at(self, t: float) -> Vector:
        """Return the ball velocity (m/s) at time t (s)."""
        return add(self.velocity, scale(self.acceleration, t - self.t0))

    def positions(self, times: np.ndarray) -> np.ndarray:
        """Return the ball centres (m, one row each) at the times (s): ``at`` for many."""
        tau = (times - self.t0)[:, None]
        return np.asarray(self.position) + (np.asarray(self.velocity) * tau + np.asarray(
            self.acceleration) * (0.5 * tau * tau))

    def speeds(self, times: np.ndarray) -> np.ndarray:
        """Return how fast (m/s) the ball flies at each of the times (s)."""
        velocities = np.asarray(self.velocity) + np.asarray(self.acceleration) * (
            times - self.t0)[:, None]
        return np.sqrt((velocities * velocities).sum(axis=1))


@dataclass(frozen=True)
class BatForecast:
    """
    The bat from time ``t0`` on: a pivot with constant acceleration, turning about a fixed axis.

    :ivar t0: start (s).
    :ivar pivot: pivot point at t0 (m); ``pivot_velocity`` (m/s), ``pivot_acceleration``.
    :ivar knob_arm, tip_arm: knob and tip relative to the pivot at t0 (m).
    :ivar axis: unit axis of the turn; ``rate`` (rad/s) and ``rate_change`` (rad/s^2) about it.
    """

    t0: float
    pivot: Vector
    pivot_velocity: Vector
    pivot_acceleration: Vector
    knob_arm: Vector
    tip_arm: Vector
    axis: Vector
    rate: float
    rate_change: float

    def angle(self, t: float) -> float:
        """Return how far (rad) the bat has turned at time t (s)."""
        tau = t - self.t0
        return self.rate * tau + 0.5 * self.rate_change * tau * tau

    def at(self, t: float) -> Tuple[Vector, Vector]:
        """Return (knob, tip) in metres at time t (s)."""
        pivot = self.pivot_at(t)
        angle = self.angle(t)
        return (add(pivot, turn_about(self.knob_arm, self.axis, angle)),
                add(pivot, turn_about(self.tip_arm, self.axis, angle)))

    def reach(self) -> float:
        """Return the farthest any bat axis point is from the pivot (m)."""
        return max(norm(self.knob_arm), norm(self.tip_arm))

    def pivot_at(self, t: float) -> Vector:
        """Return the pivot (m) at time t (s)."""
        tau = t - self.t0
        return add(self.pivot, add(scale(self.pivot_velocity, tau),
                                   scale(self.pivot_acceleration, 0.5 * tau * tau)))

    def turn_rate_bound(self, ta: float, tb: float) -> float:
        """Return the largest turning rate (rad/s) over [ta, tb]."""
        return max(abs(self.rate + self.rate_change * (t - self.t0)) for t in (ta, tb))

    def pivot_travel(self, ta: float, tb: float) -> float:
        """Return a bound (m) on how far the pivot moves from where it is at ta, up to tb."""
        h = tb - ta
        speed = norm(add(self.pivot_velocity, scale(self.pivot_acceleration, ta - self.t0)))
        return speed * h + 0.5 * norm(self.pivot_acceleration) * h * h

    def pivots(self, times: np.ndarray) -> np.ndarray:
        """Return the pivot (m, one row each) at the times (s): ``pivot_at`` for many."""
        tau = (times - self.t0)[:, None]
        return np.asarray(self.pivot) + (np.asarray(self.pivot_velocity) * tau + np.asarray(
            self.pivot_acceleration) * (0.5 * tau * tau))

    def pivot_travels(self, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """Return ``pivot_travel`` (m) for each pair of start and end times (s)."""
        h = ends - starts
        velocities = np.asarray(self.pivot_velocity) + np.asarray(self.pivot_acceleration) * (
            starts - self.t0)[:, None]
        speeds = np.sqrt((velocities * velocities).sum(axis=1))
        return speeds * h + 0.5 * norm(self.pivot_acceleration) * h * h


@dataclass(frozen=True)
class PlannedBat:
    """
    A commanded bat trajectory: poses at increasing times (a robot arm's plan).

    :ivar times: seconds on the detector's clock, increasing.
    :ivar positions: pose origins (m); ``quaternions``: unit (x, y, z, w).
    :ivar knob_offset, tip_offset: knob and tip in the bat body frame (m).
    """

    times: Tuple[float, ...]
    positions: Tuple[Vector, ...]
    quaternions: Tuple[Quaternion, ...]
    knob_offset: Vector
    tip_offset: Vector

    def covers(self, t: float) -> bool:
        """Return whether the plan has a pose at or around time t (s)."""
        return bool(self.times) and self.times[0] <= t <= self.times[-1]

    def at(self, t: float) -> Tuple[Vector, Vector]:
        """Return (knob, tip) in metres at time t (s), within the plan."""
        times = self.times
        k = max(0, min(len(times) - 2, _index(times, t)))
        if len(times) == 1:
            origin, q = self.positions[0], self.quaternions[0]
        else:
            origin, q = interpolate_pose(self.positions[k], self.quaternions[k],
                                         self.positions[k + 1], self.quaternions[k + 1],
                                         (t - times[k]) / (times[k + 1] - times[k]))
        return pose_point(origin, q, self.knob_offset), pose_point(origin, q, self.tip_offset)

    def reach(self) -> float:
        """Return the farthest any bat axis point is from the pose origin (m)."""
        return max(norm(self.knob_offset), norm(self.tip_offset))

    def pivot_at(self, t: float) -> Vector:
        """Return the pose origin (m) at time t (s), within the plan."""
        times = self.times
        if len(times) == 1:
            return self.positions[0]
        k = max(0, min(len(times) - 2, _index(times, t)))
        return lerp(self.positions[k], self.positions[k + 1],
                    (t - times[k]) / (times[k + 1] - times[k]))

    def pivot_travel(self, ta: float, tb: float) -> float:
        """Return the length (m) of the pose origin's path from ta to tb (it moves on chords)."""
        times = self.times
        first, end = bisect_right(times, ta), bisect_left(times, tb)  # poses inside (ta, tb)
        points = [self.pivot_at(ta)]
        points += self.positions[first:max(first, end)]
        points.append(self.pivot_at(tb))
        return sum(math.dist(a, b) for a, b in zip(points[:-1], points[1:]))

    def pivots(self, times: np.ndarray) -> np.ndarray:
        """Return the pose origin (m, one row each) at the times (s), within the plan."""
        return np.array([self.pivot_at(t) for t in times.tolist()]).reshape(-1, 3)

    def pivot_travels(self, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """Return ``pivot_travel`` (m) for each pair of start and end times (s)."""
        return np.array([self.pivot_travel(a, b) for a, b in zip(starts.tolist(),
                                                                 ends.tolist())])

    def turn_rate_bound(self, ta: float, tb: float) -> float:
        """Return the largest turning rate (rad/s) between plan poses overlapping [ta, tb]."""
        worst = 0.0
        times = self.times
        for k in range(max(0, _index(times, ta)), min(len(times) - 1, _index(times, tb) + 1)):
            angle = quaternion_angle(self.quaternions[k], self.quaternions[k + 1])
            worst = max(worst, angle / (times[k + 1] - times[k]))
        return worst


def _index(times: Sequence[float], t: float) -> int:
    """Return k with times[k] <= t < times[k + 1] (-1 before the first)."""
    return bisect_right(times, t) - 1


def first_contact(ball: BallForecast, bat, t_start: float, horizon: float, ball_radius: float,
                  profile: BatProfile, tolerance: float,
                  coarse_step: float = 0.01) -> Optional[Tuple[float, ImpactResult]]:
    """
    Return the first contact of the forecasts within [t_start, t_start + horizon], or None.

    The horizon is scanned in coarse steps; a step is skipped when the ball stays farther from
    the bat's pivot than the bat reaches (plus the radii and what both can travel in the step).
    Other steps are cut into sub-steps whose chord error is below ``tolerance`` (m): the ball's
    parabola leaves its chord by |a| h^2 / 8, a turn of rate w by reach (w h)^2 / 8. Each
    sub-step is solved exactly. For a plan, only the part it covers is searched.

    :param bat: a ``BatForecast`` or a ``PlannedBat``.
    :returns: (contact time in seconds, the solver's result for the sub-step), or None.
    """
    end = t_start + horizon
    if isinstance(bat, PlannedBat):
        if not bat.times:
            return None
        t_start, end = max(t_start, bat.times[0]), min(end, bat.times[-1])
    reach = bat.reach() + ball_radius + profile.max_radius
    ball_accel = norm(ball.acceleration)
    starts, ends = _coarse_steps(t_start, end, coarse_step)
    if not starts:
        return None
    ta_all, tb_all = np.array(starts), np.array(ends)
    h_all = tb_all - ta_all
    # largest distance either body can move from its position at ta within each step
    travel = (ball.speeds(ta_all) * h_all + 0.5 * ball_accel * h_all * h_all
              + bat.pivot_travels(ta_all, tb_all) + 1e-9)
    gap = ball.positions(ta_all) - bat.pivots(ta_all)
    far = np.sqrt((gap * gap).sum(axis=1)) > reach + travel
    for k in np.flatnonzero(~far).tolist():
        found = _first_in_step(ball, bat, starts[k], ends[k], ball_radius, profile, tolerance,
                               ball_accel)
        if found is not None:
            return found
    return None


def _coarse_steps(t_start: float, end: float,
                  coarse_step: float) -> Tuple[List[float], List[float]]:
    """Return the starts and ends (s) of the coarse steps from t_start to end."""
    starts: List[float] = []
    ends: List[float] = []
    ta = t_start
    while ta < end:
        tb = min(end, ta + coarse_step)
        starts.append(ta)
        ends.append(tb)
        ta = tb
    return starts, ends


def _first_in_step(ball: BallForecast, bat, ta: float, tb: float, ball_radius: float,
                   profile: BatProfile, tolerance: float,
                   ball_accel: float) -> Optional[Tuple[float, ImpactResult]]:
    """Return the first contact in the coarse step [ta, tb], solved on chord sub-steps."""
    h = tb - ta
    rate = bat.turn_rate_bound(ta, tb)
    per_step = math.sqrt(8.0 * tolerance / max(ball_accel, 1e-12))
    if rate > 0.0:
        per_step = min(per_step, math.sqrt(8.0 * tolerance / bat.reach()) / rate)
    n = max(1, int(math.ceil(h / per_step)))
    previous_t = ta
    previous_ball = ball.at(ta)
    previous_knob, previous_tip = bat.at(ta)
    for j in range(1, n + 1):
        t = tb if j == n else ta + h * j / n
        ball_t = ball.at(t)
        knob_t, tip_t = bat.at(t)
        hit = profile_contact(previous_ball, ball_t, previous_tip, tip_t, previous_knob,
                              knob_t, ball_radius, profile, t - previous_t)
        if hit is not None:
            return previous_t + hit.time, hit
        previous_t, previous_ball, previous_knob, previous_tip = t, ball_t, knob_t, tip_t
    return None


def prediction_due(last_ns: Optional[int], now_ns: int, period: float) -> bool:
    """
    Return whether a frame stamped ``now_ns`` predicts, the last that did being ``last_ns``.

    Due with no earlier prediction, on a stamp before the last (the clock went back), or at
    least ``period`` (s, rounded to ns) after it; always with a period of 0.
    """
    return last_ns is None or now_ns < last_ns or now_ns - last_ns >= round(period * 1e9)


def in_force_after(period: float) -> int:
    """Return for how long (ns) a prediction stays in force: ``period``, at least 1 ns."""
    return max(int(round(period * 1e9)), 1)


def turn_axis_and_rates(rate_vector: Sequence[float],
                        change_vector: Sequence[float]) -> Tuple[Vector, float, float]:
    """
    Return (unit axis, rate rad/s, rate change rad/s^2) of a turn about one fixed axis.

    The axis is the angular velocity's direction; the angular acceleration is taken along it
    (its part across the axis would tilt the swing plane, which a fixed axis cannot follow).
    """
    rate = norm(rate_vector)
    if rate == 0.0:
        return (0.0, 0.0, 1.0), 0.0, 0.0
    axis = scale(rate_vector, 1.0 / rate)
    return axis, rate, dot(change_vector, axis)


MAX_PLAN_POSES = 10_000
"""Poses a commanded bat plan may hold: 10 s at 1 kHz; a plan is the coming swing, re-sent as
the arm re-plans, not a whole session."""


def check_plan_size(count: int) -> None:
    """
    Refuse a plan of more than ``MAX_PLAN_POSES`` poses.

    :raises ValueError: saying the limit and why.
    """
    if count > MAX_PLAN_POSES:
        raise ValueError(f'a bat plan of {count} poses is more than the {MAX_PLAN_POSES} a '
                         'plan may hold: send the coming swing (seconds), not a session')


def planned_bat(times: Sequence[float], positions: Sequence[Sequence[float]],
                quaternions: Sequence[Sequence[float]], knob_offset: Vector,
                tip_offset: Vector) -> PlannedBat:
    """
    Return a plan from parallel lists, normalising the quaternions.

    :raises ValueError: more than ``MAX_PLAN_POSES`` poses, lists of different lengths, times
        not increasing, or a quaternion that is not unit length within 1e-3.
    """
    check_plan_size(len(times))
    if not len(times) == len(positions) == len(quaternions):
        raise ValueError('a bat plan needs as many times, positions and quaternions')
    if any(b <= a for a, b in zip(times[:-1], times[1:])):
        raise ValueError('bat plan times must increase')
    unit: List[Quaternion] = []
    for q in quaternions:
        length = math.sqrt(sum(float(x) * float(x) for x in q))
        if not math.isfinite(length) or abs(length - 1.0) > 1e-3:
            raise ValueError(f'bat plan quaternion {tuple(q)!r} is not unit length')
        unit.append(tuple(float(x) / length for x in q))
    return PlannedBat(times=tuple(float(t) for t in times),
                      positions=tuple(tuple(float(x) for x in p) for p in positions),
                      quaternions=tuple(unit), knob_offset=knob_offset, tip_offset=tip_offset)
