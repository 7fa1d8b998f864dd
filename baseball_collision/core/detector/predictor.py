"""
Predictions: the coming impact, from the detector's latest samples and a commanded bat plan.

After every processed frame (when ``prediction_horizon`` > 0 and the detector is armed; with
``prediction_period`` > 0 only on a frame at least that long after the last one that did) the
ball's latest samples give a ballistic forecast, and the bat's either its commanded plan (a
robot arm's, when it covers the instant) or a rigid-body extrapolation of its latest motion;
``prediction.contact_of`` (``first_contact`` on the kernel's numbers) searches them for the
first contact within the horizon.

The forecasts do not start from a newest sample off its stream's motion that the sweep has not
judged yet: a ball sample off the free flight of the samples before it
(``departure.leaves_flight``, the sweep's own rule: a tracker's glitch, dropped as
``ball_glitch`` once the next sample has come, or the ball leaving the bat), or a bat frame a
glitch's distance off the forecast of the frames before it, the frame before on it
(``Predictor._bat_off``: a glitch or a frame stamped milliseconds off, which the sweep
judges only once the ball is near the bat). Where a contact is found or a prediction is in
force (for the bat: where the frame would change what is shown), such a frame predicts
nothing: the prediction in force stays, and the next frame predicts, so a glitch neither shows
a contact the pitch does not have, nor moves or withdraws one. A newest bat frame off the
forecast through the frame before it and on the one without that frame (a frame stamped
milliseconds off, its pose right, bends the forecasts through it without being a glitch's
distance off) predicts from its forecast without the frame before (``Predictor._bat_off``:
``BEFORE``), where it would change what is shown or the stamps about that frame break their
cadence; the sweep still reads the frame.

A newest bat frame after a hole (frames lost right before it) is judged so against the
hole's own floor, the window's one-step miss times how much farther the forecast reaches across
the hole on the same noise (``Predictor._across_floor``: the hole, not the frame, may put a
swing's frame centimetres off): one off it predicts from the forecast of the frames before it,
neither held nor bending the prediction, and the frame after it says which it was: on the
forecast through it, the swing's own (used from then on); off it, left out till the sweep's
rule for it judges it (``Predictor._followed``, ``_late_verdict``).

A glitch further back in the bat's forecast window would bend the fit of every forecast after it
until the sweep judged it near the ball (tens of milliseconds at 90 Hz). So a frame that would
change what is shown (a contact found, withdrawn or moved) first judges the window's newest bat
frames by the sweep's rule, the oldest first, and drops a glitch as the sweep does
(``bat_glitch``, counted; forgotten): ``Predictor._bat_glitch_dropped``. The prediction and the
detection path read the same frames. A newest bat frame that held the prediction (off the swing,
above) is judged so by the next forecast whatever it shows (``Predictor.suspect``): a glitch
that bends the forecasts after it away from the ball would otherwise stay in them, showing
nothing, until the sweep judged it near the ball. So is a newest bat frame off the swing whose
forecast finds nothing with nothing in force (nothing shown either way, so nothing was judged;
the glitch then bent the forecasts after it), after a hole (``_after_step``) or off the line
through the two frames before it (``_off_line``, a screen no fit reads): on a regular step it
is held as above; after a hole the frame after it says which it was; it makes no prediction
from the forecast without it (that gave misses false ones). A chunk's plan stops at such a frame
(``plan_prediction``: its newest frame after a long step or off that line, over the least
glitch floor off the fit). Where that rule cannot judge
the suspect (a segment's first frames, a frame beside a hole over ``bat_glitches.LOST_HOLE``),
the sweep's rule for it does once the frames after it that it reads have come
(``Predictor._late_verdict``: ``early_glitch``, ``first_frame_glitch``, ``hole_glitch``); till
then, or once judged a glitch, the bat is forecast without it (the sweep drops it when a contact
hangs on it).
"""

from bisect import bisect_left
from dataclasses import replace
import math
from statistics import median
from typing import Callable, List, Optional, Sequence, Tuple, Union

from .bat_glitch_edges import late_rule, segment_first
from .bat_glitches import BAT_GLITCH_FLOOR, first_glitch, glitch_floor, REGULAR_STEP
from .bat_window import newest_miss, noise_gain, PREDICTION_DEGREE, STEP_ROWS
from .config import DetectorConfig
from .departure import judging_noise, leaves_flight
from .events import Prediction, PredictionCleared
from .fitting import c2_window, stream_noise
from .gap_flight import GAP_FLIGHT_BIAS, GAP_FLIGHT_JERK
from .gate import Clock, integer_stamp
from .kinematics import fit_polynomial
from .streams import Stream
from ..geometry import lerp, scale, Vector
from ..prediction import (
    ball_numbers, BallForecast, bat_window_numbers, BatForecast, check_plan_size, contact_of,
    frozen, planned_bat, PlannedBat, prediction_due, states_of)
from ..toi import _kernel, ImpactResult
from ...errors import CoreError

PREDICTION_CHORD_FACTOR = 4.0
"""A prediction's sub-steps may leave the forecast paths by this many ``max_chord_error``."""

BAT_CHECK_MOVE = 0.002
"""s: a prediction in force whose instant a frame moves by less than this is not checked for a
bat frame off the swing (``Predictor._bat_off``, 9 us at 1 kHz): consecutive predictions
10 ms apart move by a median 0.4-0.7 ms on a tracked swing at 360 Hz with 1 mm of noise."""

BEFORE_OFF = 1.5
"""How many times nearer the forecast without the frame before it than the one through it a
bat frame off the latter lands where that frame before is taken as off (``Predictor._bat_off``;
``bench_prediction.py --faults``: 2 lost 20 ms ahead that the pitch without the frame keeps,
of 252 hits at 90 Hz with 1 mm of noise, against 7 at 2 times and 15 at 3)."""

NEWEST, BEFORE, ACROSS = 'newest', 'before', 'across'
"""``Predictor._bat_off``'s verdicts: the newest bat frame is off the swing, the one before, or
the newest after a step over ``REGULAR_STEP`` times the one before (a frame lost between)."""

NOT_LATE = 'not late'
"""``Predictor._late_verdict``'s answer for a frame the window's judgment (``first_glitch``)
judges."""


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


class Predictor:
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
                 '_ball_window', '_bat_window', '_instant', 'drop_bat', 'suspect', '_left_out')

    def __init__(self, config: DetectorConfig, clock: Clock, ball: Stream, bat: Stream,
                 offsets: Tuple[Vector, Vector]) -> None:
        self.config, self.clock, self.ball, self.bat, self.offsets = (
            config, clock, ball, bat, offsets)
        self.max_radius = config.profile.max_radius
        # the commanded plan: (its first stamp, the plan timed in s from it); on this clock
        self.plan: Optional[Tuple[int, PlannedBat]] = None
        self.plan_on_clock: Optional[PlannedBat] = None
        self.predicting = False
        self.last_ns: Optional[int] = None  # the stamp of the last frame that predicted
        self._ball_window = (0, 0)  # the last ball forecast's samples [first, end)
        self._bat_window = (0, 0)  # the last extrapolated bat's frames [first, end); (0, 0): plan
        self._instant = 0.0  # the instant (s) of the prediction in force
        # drops and forgets bat frame j, a glitch judged from the samples up to a last one
        # (the sweep's ``_bat_glitch``); None: the forecast's frames are not judged
        self.drop_bat: Optional[Callable[[int, int], None]] = None
        # the time (s) of a newest bat frame that held a prediction (``_bat_off``), not
        # judged yet: the frames after it judge it whatever they show (``_bat_glitch_dropped``)
        self.suspect: Optional[float] = None
        # the suspect's frame where the sweep's rule for it (a segment's first frames, beside a
        # long hole: ``_late_verdict``) awaits later frames or judged it a glitch: the bat is
        # forecast without it
        self._left_out: Optional[int] = None

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
        a contact is found or a prediction is in force and the ball's forecast starts from a
        sample off its free flight (``_ball_departed``), or the frame would change what is
        shown (``_shown_changes``) and the bat's starts from a frame off the swing
        (``_bat_off``: ``NEWEST``, that frame is then ``suspect``); the next frame is then due.
        Where the frame before the bat's newest is off instead (``BEFORE``), the bat is
        forecast again without it. Where nothing is found and none is in force, a newest bat
        frame after a hole (``_after_step``) or off the line through the two frames before it
        (``_off_line``) is judged all the same (nothing is shown either way): off the swing it
        is ``suspect`` (held where ``NEWEST``; after a hole, ``ACROSS``, the frame after it
        says which it was), and nothing is forecast without it. The bat's turns are summed over
        the forecast's own window (``_bat_forecast``), whose frames are judged first where the
        frame would change what is shown or a frame is suspect (``_bat_glitch_dropped``: a
        glitch dropped, the bat forecast again without it); a suspect whose rule awaits later
        frames, or that its rule judged a glitch (``_left_out``), is left out of the bat's
        forecast, and the newest frames are not checked meanwhile.
        """
        config = self._config
        now_ns = self.clock.stamp(t0)
        last_ns = self.last_ns
        if not prediction_due(last_ns, now_ns, config.prediction_period):
            return
        self.last_ns = now_ns
        found = None
        if armed and self._may_reach():
            ball = self._ball_forecast(t0)
            forecast = None if ball is None else self._bat_forecast(t0)
            while forecast is not None:
                planned = forecast.__class__ is PlannedBat
                bat_args = forecast.kernel_args if planned else forecast
                found = contact_of(ball, bat_args, t0, config.prediction_horizon,
                                   config.ball_radius, config.profile, self._tolerance)
                if planned or not self._bat_glitch_dropped(found):
                    break
                found, forecast = None, self._bat_forecast(t0)  # (its frames judged again)
            left_out = None if forecast is None or planned else self._left_out
            if left_out is not None:  # (a suspect the sweep's rule judges later: without it)
                without = self._bat_numbers(*self._bat_window, left_out)
                if without is not None:
                    bat_args, found = without, contact_of(
                        ball, without, t0, config.prediction_horizon, config.ball_radius,
                        config.profile, self._tolerance)
            if forecast is None:
                self.suspect = self._left_out = None  # (nothing forecast: none awaits a verdict)
            elif found is not None or self.predicting or not planned and left_out is None and (
                    self._after_step(self._bat_window[1]) or self._off_line(self._bat_window[1])):
                # (nothing found, nothing in force: a newest bat frame after a hole, or off the
                # line through the two before it, is judged)
                shown = found is not None or self.predicting
                held = shown and self._ball_departed()
                off = None if held or planned or left_out is not None else self._bat_off(found)
                if off is NEWEST:
                    held, self.suspect = True, self.bat.times[self._bat_window[1] - 1]
                elif off is not None and not shown:  # (no prediction from a frame left out)
                    if off is ACROSS:  # (the newest: judged by the frame after it)
                        self.suspect = self.bat.times[self._bat_window[1] - 1]
                elif off is not None:  # BEFORE, ACROSS: forecast without that frame
                    first, end = self._bat_window
                    if off is ACROSS:  # (the newest: judged by the frame after it)
                        self.suspect = self.bat.times[end - 1]
                    without = self._bat_numbers(first, end, end - 2) if off is BEFORE else \
                        self._bat_numbers(first, end - 1)
                    if without is not None:
                        bat_args, found = without, contact_of(
                            ball, without, t0, config.prediction_horizon, config.ball_radius,
                            config.profile, self._tolerance)
                if held:
                    self.last_ns = last_ns  # (no frame that predicted: the next one is due)
                    return
        else:
            self.suspect = self._left_out = None
        if found is None:
            if self.predicting:
                self.predicting = False
                events.append(PredictionCleared(made_at_ns=now_ns))
            return
        t, hit = found
        ball_position, ball_velocity, knob, tip = states_of(ball, bat_args, t)
        self.predicting, self._instant = True, t
        events.append(frozen(  # the frozen __init__ would set its ten fields one by one
            Prediction, stamp_ns=self.clock.stamp(t), made_at_ns=now_ns, lead_s=t - t0,
            point=tuple(hit.point), normal=tuple(hit.normal), bat_fraction=hit.bat_fraction,
            distance_from_tip_m=(1.0 - hit.bat_fraction) * math.dist(knob, tip),
            ball_position=ball_position, ball_velocity=ball_velocity, planned=planned))

    def _bat_glitch_dropped(self, found: Optional[Tuple[float, ImpactResult]]) -> bool:
        """
        Judge the extrapolated bat's frames as the sweep does; True: a glitch was dropped.

        Where the frame would change what is shown (``_shown_changes``; ``found``:
        ``contact_of``'s result, a contact or one in force), or a newest frame held the
        prediction since the last judgment (``suspect``, forgotten once a judgment reads its
        next frame or it left the window, or at a due frame that forecasts nothing: the ball
        out of reach, disarmed, too few samples): the forecast window's frames with
        their next frame in it that the sweep judges for an interval closing at its newest
        (``fitting.c2_window``: up to ``spline_window`` frames), the oldest first, by the
        sweep's rule (``bat_glitches.first_glitch`` from the window's samples, the verdicts
        kept with the sweep's), and the first glitch is dropped and forgotten (``drop_bat``:
        the sweep's ``bat_glitch`` drop), so that the prediction reads the frames the detection
        path reads; the sweep judges a frame only once an interval near the ball reads it. A
        frame's first verdict costs a smoothed continuation with noise
        (``bat_glitches.departure``), hence only where the frame would change what is shown.

        A suspect that rule cannot judge (a segment's first frames, a frame beside a hole over
        ``bat_glitches.LOST_HOLE``) is judged by the sweep's rule for it once the frames after it
        that the rule reads have come (``_late_verdict``): a frame judged no glitch is forgotten
        as a suspect, and so is one after a hole (``_bat_off``: ``ACROSS``) whose next frame goes
        on from it (``_followed``) meanwhile; till then, or judged a glitch (``_left_out``), and
        while it is in the forecast's window, the bat is forecast without it (``predict``). Not
        dropped here: the sweep drops it where a contact hangs on it, and a drop here, at
        another frame than the sweep's, made the chunk path's impacts differ from one sample at
        a time's (``bench_prediction.py --faults --chunks``: 7 of 288 runs, 90 Hz, 1 mm).
        """
        first, end = self._bat_window
        suspect = self.suspect
        self._left_out = None
        if self.drop_bat is None or (suspect is None and (
                (found is None and not self.predicting) or not self._shown_changes(found))):
            return False
        bat, config = self.bat, self._config
        gap, size, last = config.max_gap, config.spline_window, end - 1
        times, noise = bat.times, stream_noise(bat, config)
        if suspect is not None and first <= (j := bisect_left(times, suspect, first, end)) < last \
                and times[j] == suspect:
            verdict = self._late_verdict(j)
            if verdict is None and self._across_hole(j) and self._followed(j):
                verdict = False  # (its next frame goes on from it: the swing's own)
            if verdict is None or verdict is True:  # (waits, or a glitch: forecast without it)
                self._left_out = j
            elif verdict is not NOT_LATE:
                self.suspect = None  # (judged no glitch by the sweep's rule)
        first = max(first, c2_window(bat, last - 1, gap, 0, size).start)
        if suspect is not None and self._left_out is None and (
                times[first] > suspect or suspect < times[last]):
            self.suspect = None  # judged now (its next frame in), or out of the window
        glitch = first_glitch(bat, first, last, gap, size, noise)
        if glitch is None:
            return False
        if glitch == self._left_out:
            return False  # (left out already, till the sweep's rule for it can judge it)
        self.drop_bat(glitch, last)
        self.suspect = self._left_out = None
        return True

    def _late_verdict(self, j: int) -> Union[None, bool, str]:
        """
        Return the sweep's verdict on bat frame j where ``first_glitch`` cannot judge it.

        A segment's 2nd to 8th frame (``bat_glitch_edges.early``: ``early_glitch``), its first
        (``segment_first``: ``first_frame_glitch``), a frame beside a hole over ``LOST_HOLE``
        (``beside_hole``: ``hole_glitch``), picked as the sweep picks them
        (``bat_glitch_edges.late_rule``): True, a glitch; False, none; None, the frames after it
        that the rule reads have not all come. ``NOT_LATE``: none of those (``first_glitch``
        judges it).
        """
        bat, config = self.bat, self._config
        rule = late_rule(bat, j, config.max_gap)
        if rule is None:
            return NOT_LATE
        return rule[0](bat, j, config.max_gap, config.spline_window, stream_noise(bat, config))

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

    def _shown_changes(self, found: Optional[Tuple[float, ImpactResult]]) -> bool:
        """
        Return whether a frame's search result changes what is shown by more than a little.

        A contact where none is in force, none where one is, or an instant ``BAT_CHECK_MOVE``
        or more from the one in force (``found``: ``contact_of``'s result).
        """
        return found is None or not self.predicting or \
            abs(found[0] - self._instant) >= BAT_CHECK_MOVE

    def _bat_off(self, found: Optional[Tuple[float, ImpactResult]]) -> Optional[str]:
        """
        Return which of the extrapolated bat's newest frames is off the swing, if one is.

        ``NEWEST``: the newest frame, and not the one before, left the swing: it is more than a
        bat glitch's least distance (``bat_glitches.glitch_floor`` of the stream's noise: 5 cm
        or more) from the bat forecast from the frames before it (the forecast's own fit, one
        frame shorter; knob or tip), and no nearer the forecast without the frame before
        (below). A swing's own frames land within 2.8 cm of it at 90 Hz and 3.6 cm at 360 Hz
        with 1 mm of noise, a frame turned 10 cm at the tip 8.3 cm or more away. Not where the
        frame before left it too: the fit through that one misses the newest (the sweep judges
        a bat frame only near the ball, so a glitch may stay in the window for tens of
        milliseconds). Only after a step at most ``bat_glitches.REGULAR_STEP`` times the step
        before it. Judged only where the frame would change what is shown (``_shown_changes``;
        ``found``: ``contact_of``'s result; a frame after a hole, or off the line through the
        two before it, that finds nothing with nothing in force is judged so too, ``predict``).

        ``ACROSS``: as ``NEWEST``, but the newest frame comes after a hole (``_across_hole``:
        frames lost or dropped right before it), where the forecast reaches over two steps or
        more and a swing's own frame lands centimetres off it: more than the hole's floor off
        (``_across_floor``, from the window's own one-step miss and the fit's noise gain), and
        not ``BEFORE_OFF`` times nearer the forecast without the frame before it (a frame
        stamped off before the hole bent the forecast: ``BEFORE``'s case; after a genuine frame
        dropped beside it a hit lost its prediction). The frame predicts from the forecast of
        the frames before it (not held, not bent) and is ``suspect``: the frame after it says
        which it was (``_bat_glitch_dropped``: ``_followed``).

        ``BEFORE``: the frame before the newest is off, the newest not: the newest is that far
        from the forecast through it, and ``BEFORE_OFF`` times nearer the forecast from the
        frames before them both (a frame stamped milliseconds off, its pose right, or a glitch
        not judged yet, bends the first and not the second). Judged where the frame would
        change what is shown, or where one of the two steps about the frame before is more than
        ``REGULAR_STEP`` times the other (a stamp off the stream's cadence), with 6 frames or
        more in the window.

        None: neither (or fewer than 5 frames; 4 where they begin their segment among regular
        steps, ``_segment_start``: a glitch among a segment's first frames, which the window's
        judgment cannot judge, is held so and then left out, ``_bat_glitch_dropped``).
        """
        first, end = self._bat_window
        times = self.bat.times
        if end - first < 4 or end - first == 4 and not self._segment_start(first, end):
            return None
        before, after = times[end - 2] - times[end - 3], times[end - 1] - times[end - 2]
        shown = self._shown_changes(found)
        if not shown and max(before, after) <= REGULAR_STEP * min(before, after):
            return None
        miss = self._bat_miss(first, end)
        if miss <= glitch_floor(stream_noise(self.bat, self._config)):
            return None
        if end - first >= 6 and BEFORE_OFF * self._bat_miss(first, end, end - 2) < miss:
            return BEFORE
        if not shown or self._bat_leaves(first, end - 1):
            return None
        if after <= REGULAR_STEP * before:
            return NEWEST
        if not self._across_hole(end - 1) or miss <= self._across_floor(first, end):
            return None
        # (not where the frame before the hole bent the forecast: one stamped off, ``BEFORE``;
        # with 6 frames or more its test above said so already)
        return None if end - first < 6 and BEFORE_OFF * self._bat_miss(
            first, end, end - 2) < miss else ACROSS

    def _across_floor(self, first: int, end: int) -> float:
        """
        Return the distance (m) bat frame end - 1, after a hole, is off the swing beyond.

        ``glitch_floor`` of the stream's noise, or the frame before it off the forecast of the
        frames before that (``_bat_miss``: the window's one-step miss, its noise and the swing's
        own turn) times how much more the forecast of frames [first, end - 1) carries at frame
        end - 1's stamp on the same noise (``noise_gain``, from the stamps and the fit's degree:
        across one frame lost at 90 Hz 6.1 times; a still bat with 1 mm of noise: 35 mm at
        the median, 67 mm p99), if more: across a hole the forecast, not the frame, may be that
        far off.
        """
        times = self.bat.times
        degree = min(self._config.velocity_degree, PREDICTION_DEGREE)
        ratio = noise_gain(times[first:end - 1], times[end - 1], degree) / noise_gain(
            times[first:end - 2], times[end - 2], degree)
        return max(glitch_floor(stream_noise(self.bat, self._config)),
                   ratio * self._bat_miss(first, end - 1))

    def _after_step(self, end: int) -> bool:
        """
        Return whether bat frame end - 1's step is over ``REGULAR_STEP`` times the one before.

        Of ``_across_hole``'s tests the one from three stamps (a frame lost or dropped before
        it, or one stamped early: ``_bat_off`` tells which); False with fewer than 3 frames.
        """
        times = self.bat.times
        return end >= 3 and times[end - 1] - times[end - 2] > REGULAR_STEP * (
            times[end - 2] - times[end - 3])

    def _off_line(self, end: int) -> bool:
        """
        Return whether bat frame end - 1 is off the line through the two frames before it.

        Knob or tip more than ``glitch_floor`` of the stream's noise (m) from where the step
        from frame end - 3 to end - 2, scaled by the ratio of their steps (s), carries frame
        end - 2: a screen no fit reads (a swing's own frames between the ball's forecasts land
        within it; a frame turned 10 cm or more off a slow bat does not). False with fewer
        than 3 frames; True where the two frames before are stamped alike.
        """
        times, values = self.bat.times, self.bat.values
        if end < 3:
            return False
        before = times[end - 2] - times[end - 3]
        if before <= 0.0:
            return True
        ratio = (times[end - 1] - times[end - 2]) / before
        oldest, middle, newest = values[end - 3], values[end - 2], values[end - 1]
        off = 0.0
        for (ax, ay, az), (bx, by, bz), c in ((oldest.knob, middle.knob, newest.knob),
                                              (oldest.tip, middle.tip, newest.tip)):
            off = max(off, math.dist(c, (bx + (bx - ax) * ratio, by + (by - ay) * ratio,
                                         bz + (bz - az) * ratio)))
        # (the least floor first: the stream's noise only where it may matter)
        return off > BAT_GLITCH_FLOOR and off > glitch_floor(stream_noise(self.bat, self._config))

    def _across_hole(self, j: int) -> bool:
        """
        Return whether bat frame j comes after a hole: frames lost (or dropped) right before it.

        Its step over ``REGULAR_STEP`` times the step before it and the median step of the
        frames before it in its forecast's window (``velocity_window`` back from it): not the
        frame after one stamped early (``BEFORE``'s case), whose step is long only beside it.
        """
        bat = self.bat
        times, start = bat.times, bat.history(bat.times[j], self._config.velocity_window)[0]
        if j - start < 3:
            return False
        step = times[j] - times[j - 1]
        return step > REGULAR_STEP * max(times[j - 1] - times[j - 2], median(
            [b - a for a, b in zip(times[start:j - 1], times[start + 1:j])]))

    def _followed(self, j: int) -> bool:
        """
        Return whether bat frame j + 1 goes on from frame j: on the forecast through it.

        Frame j + 1 within ``glitch_floor`` of the forecast of frame j's window (the frames
        ``_bat_off`` judged it with, ``velocity_window`` back from it) and frame j, extrapolated
        from frame j itself (``_bat_leaves``): a glitch puts that forecast about its own
        distance off the swing, a swing's own frame does not. The window is frame j's, so every
        forecast that judges it reads the same verdict.
        """
        bat = self.bat
        if j + 1 >= len(bat.times):
            return False
        start = bat.history(bat.times[j], self._config.velocity_window)[0]
        return not self._bat_leaves(start, j + 2)

    def _segment_start(self, first: int, end: int) -> bool:
        """
        Return whether bat frames [first, end) begin their segment, among regular steps.

        Frame ``first`` its segment's first (``bat_glitch_edges.segment_first``: the tracker
        re-acquired the bat), each step at most ``REGULAR_STEP`` times another: a window short
        for the segment's sake, not across frames lost.
        """
        times = self.bat.times
        steps = [b - a for a, b in zip(times[first:end - 1], times[first + 1:end])]
        return segment_first(self.bat, first, self._config.max_gap) and \
            max(steps) <= REGULAR_STEP * min(steps)

    def _bat_leaves(self, first: int, end: int) -> bool:
        """Return whether bat frame end - 1 left the forecast of frames [first, end - 1)."""
        return self._bat_miss(first, end) > glitch_floor(stream_noise(self.bat, self._config))

    def _bat_miss(self, first: int, end: int, without: Optional[int] = None) -> float:
        """
        Return how far (m) bat frame end - 1 is from the forecast of frames [first, end - 1).

        The larger of the knob's and the tip's distances; ``without``: the forecast of those
        frames but that one (``_bat_numbers``). 0 where the fit is rank deficient or would read
        fewer than 3 frames.
        """
        bat = self.bat
        if without is None:
            return newest_miss(bat.times, bat.values, bat.aligned.setdefault(STEP_ROWS, []),
                               first, end, min(self._config.velocity_degree, PREDICTION_DEGREE))
        if end - 2 - first < 3:
            return 0.0
        before = self._bat_numbers(first, end - 1, without)
        if before is None:
            return 0.0
        knob, tip = states_of(None, before, bat.times[end - 1])[2:]
        newest = bat.values[end - 1]
        return max(math.dist(knob, newest.knob), math.dist(tip, newest.tip))

    def _bat_numbers(self, first: int, end: int,
                     without: Optional[int] = None) -> Optional[Tuple[float, ...]]:
        """
        Return the bat forecast from frames [first, end), but frame ``without`` if given.

        As the kernel's 21 numbers (``prediction.bat_window_numbers``; the frames but one
        fitted from lists of their own, their steps made afresh); None: a rank-deficient fit.
        """
        bat = self.bat
        degree = min(self._config.velocity_degree, PREDICTION_DEGREE)
        if without is None:
            return bat_window_numbers(bat.times, bat.values, bat.aligned[STEP_ROWS], first, end,
                                      degree)
        kept = [i for i in range(first, end) if i != without]
        return bat_window_numbers([bat.times[i] for i in kept], [bat.values[i] for i in kept],
                                  [], 0, len(kept), degree)

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
        kernel call on the window (``prediction.ball_numbers``); a rank-deficient fit by
        LAPACK's least squares (``fit_polynomial``). None with fewer than 3 samples.
        """
        ball = self.ball
        config = self._config
        indices = ball.history(t0, config.prediction_window)
        if len(indices) < 3:
            return None
        first, end = indices[0], indices[-1] + 1  # the history is contiguous
        self._ball_window = (first, end)
        self._bat_window = (0, 0)
        forecast = ball_numbers(ball.times, ball.values, first, end, t0, self._gravity,
                                config.ball_drag)
        if forecast is None:
            position, velocity, _ = fit_polynomial(ball.times[first:end],
                                                   ball.values[first:end], t0, 2)
            forecast = BallForecast.ballistic(t0, position, velocity, self._gravity,
                                              config.ball_drag).kernel_args
        return forecast

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
