"""
Predictions: the coming impact, from the detector's latest samples and a commanded bat plan.

After every processed frame (when ``prediction_horizon`` > 0 and the detector is armed; with
``prediction_period`` > 0 only on a frame at least that long after the last one that did) the
ball's latest samples give a ballistic forecast, and the bat's either its commanded plan (a
robot arm's, when it covers the instant) or a rigid-body extrapolation of its latest motion;
``prediction.contact_of`` (``first_contact`` on the kernel's numbers) searches them for the
first contact within the horizon. The contact found is searched again near its instant, the
ball moved by what its held acceleration misses over the lead and with finer chords
(``prediction_spread.flight_corrected``); the prediction carries its 1-sigma error bars
(``prediction_spread.PendingPrediction``: the plan's, or the extrapolated swing's change),
measured at once or, for the node, after its message is sent (``defer``).

The forecasts do not start from a newest sample off its stream's motion that the sweep has not
judged yet. A ball sample off the free flight of the samples before it
(``departure.leaves_flight``, the sweep's own rule: a tracker's glitch, dropped as
``ball_glitch`` once the next sample has come, or the ball leaving the bat;
``Predictor._ball_departed``) predicts nothing where a contact is found or a prediction is in
force: the prediction in force stays, and the next frame predicts. The bat frames a forecast
reads are judged first by the predictor's base, ``bat_judgment.BatJudgment`` (a glitch, a
frame stamped off, a frame after frames lost: held, forecast without, or dropped as the sweep
drops it), so a tracker's fault neither shows a contact the pitch does not have, nor moves or
withdraws one (docs/faults.md, "With prediction on").
"""

from bisect import bisect_left, bisect_right
from dataclasses import replace
import math
from typing import Any, Callable, List, Optional, Sequence, Tuple, Union

import numpy as np

from .bat_judgment import BatJudgment, Found, NEWEST
from .bat_window import PREDICTION_DEGREE, STEP_ROWS
from .config import DetectorConfig
from .departure import judging_noise, leaves_flight
from .events import Prediction, PredictionCleared
from .fitting import stream_noise
from .gap_flight import GAP_FLIGHT_BIAS, GAP_FLIGHT_JERK
from .gate import Clock, integer_stamp
from .kinematics import fit_polynomial
from .prediction_spread import (
    BACKTEST_SPAN, flight_corrected, flight_miss, PendingPrediction)
from .streams import excerpt, Stream
from ..geometry import lerp, scale, Vector
from ..prediction import (
    ball_numbers, BallForecast, bat_window_numbers, BatForecast, check_plan_size, contact_of,
    frozen, LIFT_MOST_SAMPLES, planned_bat, PlannedBat, prediction_due, states_of)
from ..toi import _kernel
from ...errors import CoreError

PREDICTION_CHORD_FACTOR = 4.0
"""A prediction's sub-steps may leave the forecast paths by this many ``max_chord_error``."""

REFINED_CHORD = 0.1
"""The contact a prediction found is searched again near its instant with chords this many
``max_chord_error`` (``prediction_spread.flight_corrected``): the search's own chords place it
up to 2 mm off (30-40 us at a tip end), these 0.05 mm (1-2 us)."""


def kept_flight_span(window: float) -> float:
    """
    Return how long (s) after a ball's last sample the parabola of its last ``window`` s holds.

    How long a pitch's flight may go unseen (its tracker paused, or lost it) with the forecast
    from its samples before the silence still good: till the flight, its acceleration changing
    by ``gap_flight.GAP_FLIGHT_JERK`` the whole time, may have drifted from that parabola by
    ``GAP_FLIGHT_BIAS`` (a ball's radius: the sweep's bound on a flight kept across a tracking
    gap). The parabola a least-squares fit over the window's span W (samples spread evenly):
    it misses the cubic ``jerk u^3 / 6`` (u from the last sample, -W to 0) by
    ``jerk W^3 P3(1 + 2u / W) / 120`` (P3 the Legendre polynomial ``(5 y^3 - 3 y) / 2``: the
    cubic's part no parabola fits), at u = s continued past the last sample. 0.215 s for the
    0.1 s ``prediction_window`` (0.19 s for a 0.15 s flight, as ``gap_flight`` says; 0.263 s,
    the bare cubic's, as W goes to 0); 0 where the fit misses by that at its last sample.

    :param window: s, the span of the latest ball samples a forecast fits (> 0).
    """
    size = 120.0 * GAP_FLIGHT_BIAS / (GAP_FLIGHT_JERK * window ** 3)  # P3(y) at the bound
    if size <= 1.0:  # (P3(1) = 1: missed by that at the last sample already)
        return 0.0
    # the real root of 5 y^3 - 3 y - 2 size = 0 (Cardano; one, since size > 1 / sqrt(5))
    half, root = 0.2 * size, math.sqrt(0.04 * size * size - 0.008)
    y = math.copysign(abs(half + root) ** (1 / 3), half + root) + math.copysign(
        abs(half - root) ** (1 / 3), half - root)
    return 0.5 * (y - 1.0) * window


class Predictor(BatJudgment):
    """
    Forecasts from the ball and bat streams; the commanded plan; whether a contact is predicted.

    The forecasts go from the kernel's fits to its search as the kernel's numbers
    (``prediction.ball_numbers``, ``bat_window_numbers``, ``contact_of``): no forecast object
    is made.

    :param config: the detector's configuration (``DetectorConfig``).
    :param clock: the detector's clock; ``ball``, ``bat``: its streams.
    :param offsets: (knob, tip) in the bat's body frame (m), for a plan's poses.
    """

    __slots__ = ('_config', 'clock', 'ball', 'bat', 'offsets', 'max_radius', 'plan',
                 'plan_on_clock', 'predicting', 'last_ns', '_gravity', '_tolerance',
                 '_ball_window', '_lift_first', '_bat_window', '_instant', 'defer')

    def __init__(self, config: DetectorConfig, clock: Clock, ball: Stream, bat: Stream,
                 offsets: Tuple[Vector, Vector]) -> None:
        super().__init__()  # (the judgment's state: ``drop_bat``, ``suspect``)
        self.config, self.clock, self.ball, self.bat, self.offsets = (
            config, clock, ball, bat, offsets)
        self.max_radius = config.profile.max_radius
        # the commanded plan: (its first stamp, the plan timed in s from it); on this clock
        self.plan: Optional[Tuple[int, PlannedBat]] = None
        self.plan_on_clock: Optional[PlannedBat] = None
        self.predicting = False
        self.last_ns: Optional[int] = None  # the stamp of the last frame that predicted
        self._ball_window = (0, 0)  # the last ball forecast's samples [first, end)
        self._lift_first = 0  # and the first of its lift's
        self._bat_window = (0, 0)  # the last extrapolated bat's frames [first, end); (0, 0): plan
        self._instant = 0.0  # the instant (s) of the prediction in force
        # None: each prediction comes with its error bars; else it takes what measures them
        # (``PendingPrediction``), and the prediction comes without (the node's, deferred)
        self.defer: Optional[Callable[[PendingPrediction], None]] = None

    @property
    def config(self) -> DetectorConfig:
        """Return the configuration in force."""
        return self._config

    @config.setter
    def config(self, config: DetectorConfig) -> None:
        """Set the configuration, and what every prediction derives from it (made once)."""
        self._config = config
        self._gravity = scale(config.up_axis, -config.gravity)  # m/s^2
        # a forecast is good to millimetres at best: a coarser chord tolerance than for
        # impacts costs it nothing
        self._tolerance = PREDICTION_CHORD_FACTOR * config.max_chord_error

    def set_plan(self, stamps_ns: Sequence[int], positions: Sequence[Sequence[float]],
                 quaternions: Sequence[Sequence[float]]) -> None:
        """
        Set (or, with no stamps, clear) a commanded bat trajectory.

        :raises CoreError: more than ``MAX_PLAN_POSES`` poses, lists of different lengths,
            stamps not integer nanoseconds or not increasing, a position not 3 finite numbers,
            a quaternion not 4 or not unit length (at once: not at a later sample's forecast).
        """
        self.plan_on_clock = None
        try:
            count = len(stamps_ns)
            check_plan_size(count)  # before any work on a huge plan
            stamps = [integer_stamp(s, 'a plan stamp') for s in stamps_ns]
        except (TypeError, ValueError) as error:
            raise CoreError(f'bad bat plan: {error}') from error
        if not count:
            self.plan = None
            return
        first = stamps[0]
        self.plan = (first, planned_bat([(s - first) * 1e-9 for s in stamps], positions,
                                        quaternions, *self.offsets))

    def predict(self, t0: float, armed: Optional[bool], events: List) -> None:
        """
        Append a ``Prediction`` from time t0 (s) on, or ``PredictionCleared`` if one ended.

        Nothing at all, the last prediction staying in force, when t0 is less than
        ``prediction_period`` after the last frame that predicted (``prediction_due``), or when
        the frame holds the prediction (``_search``: a newest sample off its stream's motion);
        the next frame is then due. Disarmed or the ball out of reach (``_may_reach``), nothing
        is forecast, and no bat frame awaits a verdict.
        """
        now_ns = self.clock.stamp(t0)
        last_ns = self.last_ns
        if not prediction_due(last_ns, now_ns, self._config.prediction_period):
            return
        self.last_ns = now_ns
        found = None
        if armed and self._may_reach():
            searched = self._search(t0)
            if searched is None:
                self.last_ns = last_ns  # (no frame that predicted: the next one is due)
                return
            found, ball, bat_args, planned = searched
        else:
            self.suspect = self._left_out = None
        if found is None:
            if self.predicting:
                self.predicting = False
                events.append(PredictionCleared(made_at_ns=now_ns))
            return
        config = self._config
        search = (config.prediction_horizon, config.ball_radius, config.profile,
                  REFINED_CHORD * config.max_chord_error)
        lift_first, end = self._lift_first, self._ball_window[1]
        lift_span = t0 - self.ball.times[lift_first] if lift_first < end else 0.0  # (0: none)
        miss, doubt = flight_miss(ball, self._gravity, config.ball_drag, found[0] - t0,
                                  lift_span)
        found, ball = flight_corrected(ball, bat_args, t0, found, miss, search)
        t, hit = found
        ball_position, ball_velocity, knob, tip = states_of(ball, bat_args, t)
        self.predicting, self._instant = True, t
        prediction = frozen(  # the frozen __init__ would set its fields one by one
            Prediction, stamp_ns=self.clock.stamp(t), made_at_ns=now_ns, lead_s=t - t0,
            point=tuple(hit.point), normal=tuple(hit.normal), bat_fraction=hit.bat_fraction,
            distance_from_tip_m=(1.0 - hit.bat_fraction) * math.dist(knob, tip),
            ball_position=ball_position, ball_velocity=ball_velocity, planned=planned,
            time_uncertainty_s=None, distance_from_tip_uncertainty_m=None)
        pending = self._pending(prediction, ball, bat_args, planned, t0, found,
                                (ball_velocity, knob, tip), doubt, search)
        if self.defer is None:
            events.append(pending.measure())
        else:  # (the node: the prediction first, its error bars with the reports)
            self.defer(pending)
            events.append(prediction)

    def _pending(self, prediction: Prediction, ball: Tuple[float, ...], bat: Tuple[Any, ...],
                 planned: bool, t0: float, found: Tuple[float, Any],
                 at: Tuple[Vector, Vector, Vector], doubt: Any,
                 search: Tuple[Any, ...]) -> PendingPrediction:
        """
        Return what a prediction's error bars are measured from, copied now.

        The ball's forecast window and its lift's (their times) and noise (the ball's, told or
        estimated); the bat's forecast ``bat`` (the plan in force where ``planned``, with its
        pose times; else the extrapolated kernel numbers, with an excerpt of the bat's frames
        ``BACKTEST_SPAN`` and a ``velocity_window`` before its newest, for ``recent_misses``);
        from t0 to the contact ``found`` (``at``: the ball's velocity, the knob and the tip
        there, as ``predict`` has them).
        """
        first, end = self._ball_window
        lift_first = self._lift_first
        start = min(first, lift_first)
        config = self._config
        common = (prediction, ball, bat)
        rest = (t0, found, at, doubt, search, self.ball.times[start:end],
                (first - start, end - start, lift_first - start),
                stream_noise(self.ball, config))
        if planned:
            return PendingPrediction(*common, self.plan_on_clock.times, *rest)
        frames = self.bat
        newest = bisect_right(frames.times, bat[0]) - 1
        oldest = bisect_left(frames.times, bat[0] - BACKTEST_SPAN - config.velocity_window,
                             0, newest)
        return PendingPrediction(*common, None, *rest, excerpt(frames, oldest, newest),
                                 stream_noise(frames, config), config.velocity_window,
                                 min(config.velocity_degree, PREDICTION_DEGREE))

    def _search(self, t0: float) -> Optional[Tuple[Found, Optional[Tuple[float, ...]],
                                                   Optional[Tuple[float, ...]], bool]]:
        """
        Return the first contact the frame's forecasts from t0 (s) find, with those forecasts.

        (``contact_of``'s result, None for none; the ball's and the bat's forecasts as the
        kernel's numbers; whether the bat's is the commanded plan). None where the frame holds
        the prediction: a contact is found or one is in force and the ball's forecast starts
        from a sample off its free flight (``_ball_departed``), or the bat's from a frame off
        the swing (``_newest_judged``: ``NEWEST``). The bat's frames are judged first where the
        frame would change what is shown or a frame is suspect (``_bat_glitch_dropped``: a
        glitch dropped, the bat forecast again without it); a suspect left out
        (``_left_out``) is forecast without, and the newest frames are not checked meanwhile;
        else the newest frame is judged where a contact is found or one is in force, or after
        a hole (``_after_step``) or off the line through the two frames before it
        (``_off_line``), and a frame off (``BEFORE``, ``ACROSS``) is forecast without where
        something is shown. Nothing forecast (too few samples): no frame awaits a verdict.
        """
        ball = self._ball_forecast(t0)
        forecast = None if ball is None else self._bat_forecast(t0)
        found = None
        while forecast is not None:
            planned = forecast.__class__ is PlannedBat
            bat_args = forecast.kernel_args if planned else forecast
            found = self._contact(ball, bat_args, t0)
            if planned or not self._bat_glitch_dropped(found):
                break
            found, forecast = None, self._bat_forecast(t0)  # (its frames judged again)
        if forecast is None:
            self.suspect = self._left_out = None  # (nothing forecast: none awaits a verdict)
            return None, ball, None, False
        left_out = None if planned else self._left_out
        if left_out is not None:  # (a suspect the sweep's rule judges later: without it)
            without = self._bat_numbers(*self._bat_window, left_out)
            if without is not None:
                bat_args, found = without, self._contact(ball, without, t0)
        shown, end = found is not None or self.predicting, self._bat_window[1]
        if shown or not planned and left_out is None and (
                self._after_step(end) or self._off_line(end)):
            if shown and self._ball_departed():
                return None
            off = None if planned or left_out is not None else self._newest_judged(found)
            if off is NEWEST:
                return None
            if off is not None and shown:  # BEFORE, ACROSS, SECOND: forecast without it
                without = self._numbers_without(off)
                if without is not None:
                    bat_args, found = without, self._contact(ball, without, t0)
        return found, ball, bat_args, planned

    def _contact(self, ball: Tuple[float, ...], bat_args: Tuple[float, ...], t0: float) -> Found:
        """Return the first contact of the forecasts (the kernel's numbers) from t0 (s) on."""
        config = self._config
        return contact_of(ball, bat_args, t0, config.prediction_horizon, config.ball_radius,
                          config.profile, self._tolerance)

    def _ball_departed(self) -> bool:
        """
        Return whether the last ball forecast's newest sample left the ball's free flight.

        The sweep's test (``departure.leaves_flight``: off the parabola through the three
        samples before it, beyond the noise it judges with and the scatter of the intervals
        before), which the sweep makes only once the next sample has come: a glitch then is
        dropped. No swing family's pitch leaves it before the contact (90 and 360 Hz, exact
        and 1 mm of noise); a sample moved 10 cm or more does. False with fewer than four
        samples in the window (the sweep judges a segment's first samples otherwise).
        """
        first, end = self._ball_window
        return end - first >= 4 and leaves_flight(
            self.ball, end - 2, judging_noise(self._config), self._config.max_gap) is not None

    def _may_reach(self) -> bool:
        """
        Return whether the ball could reach the bat within the prediction horizon.

        From the newest samples alone: the distance from the ball to the bat's middle against
        the bat's half length, the radii and what both can travel over the horizon at twice
        their speed over the last sample step (a plan may move the bat anywhere: always True).
        """
        if self.plan is not None:
            return True
        ball, bat = self.ball, self.bat
        if len(ball.times) < 2 or len(bat.times) < 2:
            return False
        b0, b1 = ball.values[-2], ball.values[-1]
        s0, s1 = bat.values[-2], bat.values[-1]
        ball_speed = math.dist(b0, b1) / (ball.times[-1] - ball.times[-2])
        bat_speed = max(math.dist(s0.knob, s1.knob), math.dist(s0.tip, s1.tip)) / (
            bat.times[-1] - bat.times[-2])
        middle = lerp(s1.knob, s1.tip, 0.5)
        config = self._config
        reach = (0.5 * math.dist(s1.knob, s1.tip) + config.ball_radius + self.max_radius
                 + 2.0 * (ball_speed + bat_speed) * config.prediction_horizon)
        return math.dist(b1, middle) <= reach

    def _ball_forecast(self, t0: float) -> Optional[Tuple[float, ...]]:
        """
        Return the ball's ballistic forecast from a parabola fitted to its latest samples.

        As the kernel's 10 numbers (``BallForecast.kernel_args``): fit and forecast in one
        kernel call on the window (``prediction.ball_numbers``), with the lift of the flight's
        last ``lift_window`` (its spin); a rank-deficient fit by LAPACK's least squares
        (``fit_polynomial``), its lift too (``_lift``). None with fewer than 3 samples.
        """
        ball = self.ball
        config = self._config
        indices = ball.history(t0, config.prediction_window)
        if len(indices) < 3:
            return None
        first, end = indices[0], indices[-1] + 1  # the history is contiguous
        self._ball_window = (first, end)
        self._bat_window = (0, 0)
        lift_first = ball.history(t0, config.lift_window, LIFT_MOST_SAMPLES)[0] \
            if config.lift_window > 0.0 else end
        self._lift_first = lift_first
        forecast = ball_numbers(ball.times, ball.values, first, end, t0, self._gravity,
                                config.ball_drag, lift_first)
        if forecast is None:
            position, velocity, _ = fit_polynomial(ball.times[first:end],
                                                   ball.values[first:end], t0, 2)
            forecast = BallForecast.ballistic(t0, position, velocity, self._gravity,
                                              config.ball_drag).kernel_args
            lift = self._lift(lift_first, end, t0)
            forecast = forecast[:7] + tuple(a + m for a, m in zip(forecast[7:], lift))
        return forecast

    def _lift(self, first: int, end: int, t0: float) -> Vector:
        """
        Return the ball's lift (m/s^2) from samples [first, end): the kernel's ``add_lift``.

        Where the kernel refused the forecast's window (rank deficient), so without the
        kernel's glitch pass (``without_ball_glitch``): its parabola's acceleration (numpy's
        QR) less gravity and the drag at the velocity it has at the samples' middle instant,
        times the gain ``max(0, 1 - 3 var / |lift|^2)`` of the acceleration's variance from the
        samples' scatter about the parabola; zero over less than ``LIFT_MIN_SPAN`` s or
        ``LIFT_MIN_SAMPLES`` samples, or a rank-deficient fit.
        """
        times, n = self.ball.times, end - first
        if n < _kernel.LIFT_MIN_SAMPLES or \
                times[end - 1] - times[first] < _kernel.LIFT_MIN_SPAN:
            return (0.0, 0.0, 0.0)
        span = max(t0 - times[first], 1e-9)
        x = (np.array(times[first:end]) - t0) / span
        q, r = np.linalg.qr(np.vander(x, 3, increasing=True))
        if not abs(r[2, 2]) > 0.0:
            return (0.0, 0.0, 0.0)
        values = np.array(self.ball.values[first:end], dtype=float)
        coefficients = np.linalg.solve(r, q.T @ values)
        scatter = float(np.sum((values - q @ (q.T @ values)) ** 2))
        variance = scatter / (3.0 * (n - 3)) * 4.0 / (r[2, 2] ** 2 * span ** 4)
        acceleration = 2.0 * coefficients[2] / span ** 2
        velocity = coefficients[1] / span + acceleration * 0.5 * (x[0] + x[-1]) * span
        drag = self._config.ball_drag * float(np.linalg.norm(velocity))
        lift = acceleration - (np.array(self._gravity) - velocity * drag)
        size = float(lift @ lift)
        gain = max(0.0, 1.0 - 3.0 * variance / size) if size > 0.0 else 0.0
        return tuple((gain * lift).tolist())

    def _bat_forecast(self, t0: float) -> Union[Tuple[float, ...], PlannedBat, None]:
        """
        Return the bat's forecast: the commanded plan when it covers t0, else extrapolated.

        Extrapolated from the newest bat sample itself (a fit lags an accelerating swing), with
        the rates of the same knob + tip + turn fit as an impact's velocities
        (``kinematics.bat_rates``), its turn summed from the window's first sample (each
        sample's step kept in ``aligned[STEP_ROWS]``), fitted and turned into the forecast in
        one kernel call (``prediction.bat_window_numbers``: the kernel's 21 numbers,
        ``BatForecast.kernel_args``; a chunk's plan computes the same from arrays,
        ``prediction.forecast_outcomes``); a rank-deficient fit by LAPACK's least squares.
        None with fewer than 3 samples.
        """
        if self.plan is not None:
            if self.plan_on_clock is None:  # once: the clock's origin stays until a reset
                first, plan = self.plan
                shift = self.clock.time(first)
                self.plan_on_clock = replace(plan, times=tuple(t + shift for t in plan.times))
            if self.plan_on_clock.times[-1] > t0:
                return self.plan_on_clock
        bat = self.bat
        config = self._config
        degree = min(config.velocity_degree, PREDICTION_DEGREE)  # <= 3: bat_rates' shared fit
        indices = bat.history(t0, config.velocity_window)
        if len(indices) < 3:
            return None
        first, end = indices[0], indices[-1] + 1  # the history is contiguous
        self._bat_window = (first, end)
        steps = bat.aligned.setdefault(STEP_ROWS, [])
        forecast = bat_window_numbers(bat.times, bat.values, steps, first, end, degree)
        if forecast is None:
            start, latest = bat.times[end - 1], bat.values[end - 1]
            rows = _kernel.bat_window_rows(bat.values, steps, first, end)
            _, rates, changes = fit_polynomial(bat.times[first:end], rows, start, degree)
            forecast = BatForecast.from_rates(start, rates, changes, latest.knob,
                                              latest.tip).kernel_args
        return forecast
