"""
Predicted impact: where and when the ball will meet the bat's coming path.

Python and numpy (no ROS). Times are float seconds on the detector's clock,
positions metres. The detector builds the two forecasts from its latest samples and calls
``first_contact``; this module only extrapolates and searches.

* ``BallForecast``: a ballistic path from the ball's state now: constant acceleration (gravity
  plus the drag deceleration at the current speed, plus the lift of its spin). Over the 0-300
  ms of a prediction the drag changes little (a 40 m/s pitch loses ~4% of its speed in 300 ms);
  the position error of holding it constant is (1/6) d(drag)/dt tau^3, under 1 cm at 300 ms and
  0.1 mm at 50 ms (the detector's predictor moves the forecast by it, and by the lift's change,
  at the contact it found and searches again: ``detector.prediction_spread.flight_miss``). A
  pitch spins (1,500-3,000 rpm), and the Magnus force lifts, drops or breaks it by 1-7 m/s^2
  across its flight: 12 cm over 200 ms left out. So the forecast adds the
  ball's lift, what its flight over the last ``lift_window`` (a detector parameter: 0.25 s, a
  pitch's spin changes little over it) accelerates by beyond gravity and drag (the kernel's
  ``add_lift``: a parabola's acceleration over at least 0.05 s and 6 samples of the flight,
  less gravity and the drag at the window's middle, scaled down where the samples' scatter
  could have made it: 1 mm of noise over 0.25 s at 90 Hz scatters it by about 0.1 m/s^2, 0.2
  cm over 200 ms, over 0.1 s by 0.85 m/s^2). Up to two samples off the flight a window (a
  tracker's glitch: 5 times the others' scatter and 1 cm off their parabola) are left out of
  both fits (the kernel's ``without_ball_glitch``).
* ``BatForecast``: the bat as a rigid body from its state now: a pivot (the least-accelerating
  axis point, near the hands) moving with constant acceleration, and the bat turning about a
  fixed axis with constant angular acceleration. Or, for a robot arm, a commanded trajectory of
  bat poses (``PlannedBat``), interpolated like the rigid model (position LERP, SLERP).
* ``first_contact``: the exact linear solver on sub-steps of the horizon short enough for the
  chord error tolerance, skipping every stretch where the ball cannot reach the bat. The
  forecasts' paths, that reach test and the search are the compiled kernel's (``toi/_kernel.c``,
  one implementation); the classes here hold the forecasts and ask the kernel (``at``,
  ``pivot_travel``, ...). The detector's predictions skip the objects: ``ball_numbers`` and
  ``bat_window_numbers`` give the kernel's numbers of a fitted forecast, ``contact_of`` and
  ``states_of`` search and evaluate them, and ``forecast_outcomes`` does all three for many
  frames of arrays at once (a chunk's plan).
"""

from dataclasses import dataclass
import math
from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np

from .bat import BatProfile
from .geometry import Quaternion, Vector
from .toi import _kernel, ImpactResult
from ..errors import CoreError


def frozen(cls: type, **values: object) -> object:
    """
    Return an instance of the frozen dataclass ``cls`` holding ``values`` (every field).

    Its ``__dict__`` filled at once: a forecast or a prediction is made on every prediction, and
    the frozen ``__init__`` sets each field through ``object.__setattr__`` (twice the time).
    Extra keys (``_kernel_args``, the numbers the kernel gave) are kept beside the fields.
    ``cls`` must not have ``__slots__``.
    """
    instance = object.__new__(cls)
    instance.__dict__.update(values)
    return instance


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
        return cls.from_kernel_args(_kernel.ballistic(t0, position, velocity, gravity, drag))

    @classmethod
    def fitted(cls, times: List[float], points: List[Vector], first: int, end: int, t0: float,
               gravity: Vector, drag: float,
               lift_first: Optional[int] = None) -> Optional['BallForecast']:
        """
        Return ``ballistic`` from the parabola fitted to samples [first, end) at t0, in one call.

        The compiled kernel reads the window from the stream's lists (times in s, points in m)
        into contiguous arrays, fits the least-squares parabola in (time - t0) / span
        (``kinematics.fit_polynomial``'s fit, to the bit) and takes its value and rate at t0;
        its acceleration gains the lift of samples [lift_first, end) (none by default; the
        module's docstring).

        :returns: the forecast, or None when the fit is rank deficient (the caller's
            ``fit_polynomial`` solves it with LAPACK, then ``ballistic``).
        :raises TypeError, IndexError: lists that are not the stream's, or a window outside.
        """
        args = ball_numbers(times, points, first, end, t0, gravity, drag,
                            end if lift_first is None else lift_first)
        return None if args is None else cls.from_kernel_args(args)

    @classmethod
    def from_kernel_args(cls, args: Tuple[float, ...]) -> 'BallForecast':
        """Return the forecast of the kernel's 10 numbers (``kernel_args``), keeping them."""
        return frozen(cls, t0=args[0], position=args[1:4], velocity=args[4:7],
                      acceleration=args[7:10], _kernel_args=args)

    @property
    def kernel_args(self) -> Tuple[float, ...]:
        """Return the forecast as the kernel takes it: t0, position, velocity, acceleration."""
        args = self.__dict__.get('_kernel_args')
        if args is None:
            args = (self.t0, *self.position, *self.velocity, *self.acceleration)
            self.__dict__['_kernel_args'] = args
        return args

    def at(self, t: float) -> Vector:
        """Return the ball centre (m) at time t (s)."""
        return _kernel.forecast(self.kernel_args, None, t)[0]

    def velocity_at(self, t: float) -> Vector:
        """Return the ball velocity (m/s) at time t (s)."""
        return _kernel.forecast(self.kernel_args, None, t)[1]


class _BatPath:
    """What both bat forecasts answer, from the kernel (``kernel_args`` says which bat)."""

    kernel_args: tuple

    def at(self, t: float) -> Tuple[Vector, Vector]:
        """Return (knob, tip) in metres at time t (s)."""
        return _kernel.forecast(None, self.kernel_args, t)[2:4]

    def pivot_at(self, t: float) -> Vector:
        """Return the pivot (a plan's pose origin, m) at time t (s)."""
        return _kernel.forecast(None, self.kernel_args, t)[4]

    def reach(self) -> float:
        """Return the farthest any bat axis point is from the pivot (m)."""
        return _kernel.bat_bounds(self.kernel_args, 0.0, 0.0)[2]

    def pivot_travel(self, ta: float, tb: float) -> float:
        """
        Return a bound (m) on how far the pivot moves from where it is at ta, up to tb.

        Its speed and acceleration for an extrapolated bat; a plan's pose origin moves on
        chords between its poses: the length of that path.
        """
        return _kernel.bat_bounds(self.kernel_args, ta, tb)[0]

    def turn_rate_bound(self, ta: float, tb: float) -> float:
        """Return the largest turning rate (rad/s) over [ta, tb] (a plan's: between poses)."""
        return _kernel.bat_bounds(self.kernel_args, ta, tb)[1]


@dataclass(frozen=True)
class BatForecast(_BatPath):
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

    @classmethod
    def fitted(cls, times: List[float], rows: List[Sequence[float]], first: int,
               end: int, degree: int) -> Optional['BatForecast']:
        """
        Return the bat extrapolated from its samples [first, end) (at least 3), in one call.

        The compiled kernel reads the window from the stream's lists (times in s; rows: knob
        and tip in m and the cumulative turn in rad, 10 floats each, ``kinematics.turn_rows``)
        into contiguous arrays and fits them with one least-squares polynomial of ``degree``
        in (time - t) / span at the newest sample's time t (``kinematics.bat_rates``' shared
        fit, to the bit); ``from_rates`` makes the forecast from its rates.

        :returns: the forecast from t, or None when the fit is rank deficient (the caller's
            ``fit_polynomial`` solves it with LAPACK, then ``from_rates``).
        :raises TypeError, IndexError, ValueError: lists that are not the stream's, a window
            outside them or of fewer than 3 samples.
        """
        args = bat_numbers(times, rows, first, end, degree)
        return None if args is None else cls.from_kernel_args(args)

    @classmethod
    def from_rates(cls, t0: float, first: Sequence[float], second: Sequence[float],
                   knob: Vector, tip: Vector) -> 'BatForecast':
        """
        Return the bat from t0 (s) on, from its fit's rates and its knob and tip (m) at t0.

        ``first`` and ``second``: the first and second time derivatives of the knob, tip and
        cumulative turn fit (10 each). The pivot is the axis point that accelerates least
        (``kinematics.least_accelerating``), moving with the rates interpolated there; the
        turn is about the angular velocity's axis, at its rate and the angular acceleration
        along it (a fixed axis cannot follow the part across). The compiled kernel's;
        ``fitted`` does the fit and this in one call.
        """
        return cls.from_kernel_args(_kernel.bat_from_rates(t0, first, second, knob, tip))

    @classmethod
    def from_kernel_args(cls, args: Tuple[float, ...]) -> 'BatForecast':
        """Return the forecast of the kernel's 21 numbers (``kernel_args``), keeping them."""
        return frozen(cls, t0=args[0], pivot=args[1:4], pivot_velocity=args[4:7],
                      pivot_acceleration=args[7:10], knob_arm=args[10:13], tip_arm=args[13:16],
                      axis=args[16:19], rate=args[19], rate_change=args[20], _kernel_args=args)

    @property
    def kernel_args(self) -> Tuple[float, ...]:
        """Return the forecast as the kernel takes it: its 21 numbers in field order."""
        args = self.__dict__.get('_kernel_args')
        if args is None:
            args = (self.t0, *self.pivot, *self.pivot_velocity, *self.pivot_acceleration,
                    *self.knob_arm, *self.tip_arm, *self.axis, self.rate, self.rate_change)
            self.__dict__['_kernel_args'] = args
        return args


@dataclass(frozen=True)
class PlannedBat(_BatPath):
    """
    A commanded bat trajectory: poses at increasing times (a robot arm's plan).

    Between poses the bat moves as the rigid model does (position LERP, orientation SLERP);
    before the first and after the last pose the nearest segment is extended.

    :ivar times: seconds on the detector's clock, increasing.
    :ivar positions: pose origins (m); ``quaternions``: unit (x, y, z, w).
    :ivar knob_offset, tip_offset: knob and tip in the bat body frame (m).
    """

    times: Tuple[float, ...]
    positions: Tuple[Vector, ...]
    quaternions: Tuple[Quaternion, ...]
    knob_offset: Vector
    tip_offset: Vector

    @property
    def kernel_args(self) -> Tuple[np.ndarray, np.ndarray, np.ndarray, Vector, Vector]:
        """
        Return the plan as the kernel takes it: times, positions and quaternions as arrays.

        Made once per plan and kept in the instance (the plan is frozen; functools'
        cached_property would take a lock on every read).
        """
        args = self.__dict__.get('_kernel_args')
        if args is None:
            args = (np.array(self.times, dtype=float),
                    np.array(self.positions, dtype=float).reshape(-1, 3),
                    np.array(self.quaternions, dtype=float).reshape(-1, 4),
                    self.knob_offset, self.tip_offset)
            self.__dict__['_kernel_args'] = args
        return args

    def covers(self, t: float) -> bool:
        """Return whether the plan has a pose at or around time t (s)."""
        return bool(self.times) and self.times[0] <= t <= self.times[-1]


def ball_numbers(times: List[float], points: List[Vector], first: int, end: int, t0: float,
                 gravity: Vector, drag: float, lift_first: int) -> Optional[Tuple[float, ...]]:
    """
    Return ``BallForecast.fitted``'s forecast as the kernel's 10 numbers (``kernel_args``).

    No forecast object is made: a prediction hands the numbers straight to ``contact_of``.
    The lift is that of samples [lift_first, end) (``lift_first`` <= ``end``; none for fewer
    than the kernel's ``LIFT_MIN_SAMPLES``).

    :returns: the numbers, or None when the fit is rank deficient.
    :raises TypeError, IndexError: lists that are not the stream's, or a window outside.
    """
    args = _kernel.ball_forecast(times, points, first, end, t0, 2, gravity, drag, lift_first)
    return None if args is NotImplemented else args


def bat_numbers(times: List[float], rows: List[Sequence[float]], first: int, end: int,
                degree: int) -> Optional[Tuple[float, ...]]:
    """
    Return ``BatForecast.fitted``'s forecast as the kernel's 21 numbers (``kernel_args``).

    :returns: the numbers, or None when the fit is rank deficient.
    :raises TypeError, IndexError, ValueError: as ``BatForecast.fitted``.
    """
    args = _kernel.bat_forecast(times, rows, first, end, degree)
    return None if args is NotImplemented else args


def bat_window_numbers(times: List[float], values: List[Any], rows: List[Any], first: int,
                       end: int, degree: int) -> Optional[Tuple[float, ...]]:
    """
    Return a bat stream's forecast from its samples [first, end) as the kernel's 21 numbers.

    What ``bat_numbers`` gives of the rows knob + tip + the turn since sample ``first`` (the
    window's own, so that any window of the same samples gives the same bits, however the
    stream was trimmed or its cumulative turns summed): each sample's turn from the one before
    is made once into ``rows`` (the stream's ``aligned['step_rows']``, extended to ``end``:
    knob + tip + that turn; ``bat_window_rows`` gives the window's summed rows).

    :param times: the stream's times (s); ``values``: its ``BatSample`` list.
    :returns: the numbers, or None when the fit is rank deficient.
    :raises TypeError, IndexError, ValueError: lists that are not a bat stream's, a window
        outside them or of fewer than 3 samples, a degree outside 0-15.
    """
    args = _kernel.bat_window_forecast(times, values, rows, first, end, degree)
    return None if args is NotImplemented else args


LIFT_MOST_SAMPLES = 256
"""Samples at most whose flight gives a forecast's lift: 0.25 s (``lift_window``'s default) of a
ball tracked at 1 kHz. The lift's span is also within what the stream keeps
(``fitting.kept_history``: 0.15 s and a few samples behind the cursor once it holds 64 samples,
so from about 180 Hz up that long)."""

COARSE_STEP = 0.01
"""``first_contact``'s coarse step (s) unless told another: the stretch of the horizon whose
reach is tested before it is solved."""

FOUND, UNDECIDED = 1, 2
"""``forecast_outcomes``' codes of a frame whose forecasts meet, and of one the kernel leaves to
the predictor (a rank-deficient fit, or forecasts that leave finite numbers); 0: none."""


def forecast_outcomes(ball: Tuple[np.ndarray, np.ndarray], bat: Tuple[np.ndarray, ...],
                      windows: np.ndarray, t0s: np.ndarray, gravity: Vector, drag: float,
                      degree: int, horizon: float, ball_radius: float, profile: BatProfile,
                      tolerance: float) -> np.ndarray:
    """
    Return what a prediction from each of many frames of two streams held as arrays finds.

    Frame k forecasts from time ``t0s[k]`` (s) with the ball's samples
    ``windows[k, 0]:windows[k, 1]`` (its lift from ``windows[k, 4]`` on) and the bat's
    ``windows[k, 2]:windows[k, 3]``, as the
    detector's predictor does from its streams (``ball_numbers`` of degree 2, the bat's
    ``bat_window_numbers``, ``contact_of`` over ``horizon``), the same bits, all in one
    kernel call.

    :param ball: times (m,) and points (m, 3); ``bat``: times (m,), knobs and tips (m, 3),
        unit quaternions (m, 4) (float64, C-contiguous).
    :param windows: (frames, 5) int64; a window of fewer than 3 samples finds nothing.
    :returns: int8 per frame: ``FOUND``, 0 (none), or ``UNDECIDED``.
    :raises CoreError: arrays of the wrong types or shapes, or windows outside them.
    """
    out = np.zeros(len(t0s), np.int8)
    try:
        _kernel.forecast_outcomes(*ball, *bat, windows, t0s, out, gravity, drag, degree,
                                  horizon, ball_radius, profile, tolerance, COARSE_STEP)
    except (TypeError, ValueError, IndexError) as error:
        raise CoreError(f'cannot forecast the frames: {error}') from error
    return out


def first_contact(ball: BallForecast, bat: Union[BatForecast, PlannedBat], t_start: float,
                  horizon: float, ball_radius: float, profile: BatProfile, tolerance: float,
                  coarse_step: float = COARSE_STEP) -> Optional[Tuple[float, ImpactResult]]:
    """
    Return the first contact of the forecasts within [t_start, t_start + horizon], or None.

    In the compiled kernel (``toi/_kernel.c``). The horizon is scanned in coarse steps; a step
    is skipped when the ball stays farther from the bat's pivot than the bat reaches (plus the
    radii and what both can travel in the step). Other steps are cut into sub-steps whose chord
    error is below ``tolerance`` (m): the ball's parabola leaves its chord by |a| h^2 / 8, a turn
    of rate w by reach (w h)^2 / 8. Each sub-step is solved exactly. For a plan, only the part
    it covers is searched.

    :param bat: a ``BatForecast`` or a ``PlannedBat``.
    :param t_start, horizon: seconds; ``ball_radius`` (m, >= 0); ``tolerance`` (m, > 0);
        ``coarse_step`` (s, > 0).
    :returns: (contact time in seconds, the solver's result for the sub-step), or None.
    :raises CoreError: forecasts that leave finite numbers over the horizon, or arguments out
        of range.
    """
    return contact_of(ball.kernel_args, bat.kernel_args, t_start, horizon, ball_radius, profile,
                      tolerance, coarse_step)


def contact_of(ball: Tuple[float, ...], bat: tuple, t_start: float, horizon: float,
               ball_radius: float, profile: BatProfile, tolerance: float,
               coarse_step: float = COARSE_STEP) -> Optional[Tuple[float, ImpactResult]]:
    """
    Return ``first_contact`` of the forecasts given as the kernel's numbers (``kernel_args``).

    :raises CoreError: as ``first_contact``.
    """
    try:
        found = _kernel.first_contact(ball, bat, t_start, horizon, ball_radius, profile,
                                      tolerance, coarse_step)
    except (TypeError, ValueError) as error:
        raise CoreError(f'cannot search the forecasts: {error}') from error
    if found is NotImplemented:
        raise CoreError('the forecasts leave finite numbers (or a sub-step has no length) '
                        f'within {horizon} s of {t_start} s')
    return found


def states_of(ball: Tuple[float, ...], bat: tuple,
              t: float) -> Tuple[Vector, Vector, Vector, Vector]:
    """
    Return the ball centre (m), ball velocity (m/s), knob and tip (m) of the forecasts at t (s).

    The forecasts given as the kernel's numbers (``kernel_args``): one kernel call for what
    ``at``, ``velocity_at`` and the bat's ``at`` give one by one.
    """
    return _kernel.forecast(ball, bat, t)[:4]


def prediction_due(last_ns: Optional[int], now_ns: int, period: float) -> bool:
    """
    Return whether a frame stamped ``now_ns`` predicts, the last that did being ``last_ns``.

    Due with no earlier prediction, on a stamp before the last (the clock went back), or at
    least ``period`` (s, rounded to ns) after it; always with a period of 0.
    """
    return last_ns is None or now_ns < last_ns or now_ns - last_ns >= round(period * 1e9)


MAX_PLAN_POSES = 10_000
"""Poses a commanded bat plan may hold: 10 s at 1 kHz; a plan is the coming swing, re-sent as
the arm re-plans, not a whole session."""


def check_plan_size(count: int) -> None:
    """
    Refuse a plan of more than ``MAX_PLAN_POSES`` poses.

    :raises CoreError: saying the limit and why.
    """
    if count > MAX_PLAN_POSES:
        raise CoreError(f'a bat plan of {count} poses is more than the {MAX_PLAN_POSES} a '
                        'plan may hold: send the coming swing (seconds), not a session')


def planned_bat(times: Sequence[float], positions: Sequence[Sequence[float]],
                quaternions: Sequence[Sequence[float]], knob_offset: Vector,
                tip_offset: Vector) -> PlannedBat:
    """
    Return a plan from parallel lists, normalising the quaternions.

    :param times: seconds, increasing; ``positions``: the pose origins (m); ``quaternions``:
        their orientations (x, y, z, w); ``knob_offset``, ``tip_offset``: knob and tip in the
        bat body frame (m).
    :raises CoreError: more than ``MAX_PLAN_POSES`` poses, lists of different lengths (or not
        lists), times not increasing numbers, a position not 3 finite numbers, a quaternion not
        4 numbers or not unit length within 1e-3.
    """
    try:
        check_plan_size(len(times))
        if not len(times) == len(positions) == len(quaternions):
            raise ValueError(f'{len(times)} times, {len(positions)} positions and '
                             f'{len(quaternions)} quaternions: a plan needs as many of each')
        plan_times = tuple(float(t) for t in times)
        if any(b <= a for a, b in zip(plan_times[:-1], plan_times[1:])):
            raise ValueError('bat plan times must increase')
        plan_positions: List[Vector] = []
        unit: List[Quaternion] = []
        for position, quaternion in zip(positions, quaternions):
            point, q = tuple(float(x) for x in position), tuple(float(x) for x in quaternion)
            if len(point) != 3 or len(q) != 4 or not all(map(math.isfinite, point)):
                raise ValueError('every position must be 3 finite numbers (m) and every '
                                 'quaternion 4 (x, y, z, w)')
            length = math.sqrt(sum(x * x for x in q))
            if not math.isfinite(length) or abs(length - 1.0) > 1e-3:
                raise ValueError(f'bat plan quaternion {q!r} is not unit length')
            plan_positions.append(point)
            unit.append(tuple(x / length for x in q))
    except (TypeError, ValueError) as error:
        raise CoreError(f'bad bat plan: {error}') from error
    return PlannedBat(times=plan_times, positions=tuple(plan_positions), quaternions=tuple(unit),
                      knob_offset=knob_offset, tip_offset=tip_offset)
