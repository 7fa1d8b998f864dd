"""
A prediction's 1-sigma uncertainties: its instant and where on the bat it comes.

Python and numpy (no ROS). Times in s, positions in m. With a commanded bat plan the bat's path
is what the arm will do, so a prediction is as good as the ball's forecast at the predicted
instant and the plan's interpolation there; an extrapolated bat adds its swing's change over the
lead. Three sources, each a spread of the ball's centre relative to the bat at that instant
(m):

* **The tracker's noise** (``tracker_noise``, told or the ball's estimate under auto). The
  forecast's position at t0 + lead is linear in the window's samples: the parabola's value and
  rate at t0 carried on at rate, plus half the lead squared times the lift's acceleration (the
  parabola over the ``lift_window``). Its spread per coordinate is the noise times the norm of
  those weights (``ball_spread``): 1 mm of noise at 90 Hz spreads it by about 1 mm at 20 ms
  ahead and 4 mm at 200 ms (the velocity's error carried on, and the lift's).
* **What the forecast may still miss.** It holds its acceleration over the lead; what that
  misses as the drag eases and the lift grows and turns is corrected (``flight_miss``,
  ``flight_corrected``: every prediction's), and a third of the lift's part is carried as its
  doubt (the lift's power of the speed, 1.5 +- 0.5). Where the flight is too short for its
  lift (fewer than the kernel's ``LIFT_MIN_SAMPLES`` or ``LIFT_MIN_SPAN``, or ``lift_window``
  0) the lift left out is a pitch's spin's: ``LIFT_PRIOR`` across the flight, carried on as
  half the lead squared.
* **The bat's path.** A plan's interpolation: between its poses the bat moves by LERP and
  SLERP; the contact point's planned position at the instant against the quadratic through the
  three poses nearest it (``plan_sag``): what a smoother path through the same poses would put
  there. An extrapolated bat's change over the lead (``swing_variance``): the forecast holds
  its angular and its pivot's accelerations, so it misses what the swing does next, and the
  newest frame's own noise is carried on. What the samples show is its recent misses: the
  forecasts from frames ``BACKTEST_LEADS`` before the forecast's newest, at that frame
  (``recent_misses``), scaled to the lead as the lead over theirs (a velocity's miss) up to it
  and its cube beyond (a held acceleration's). What they cannot show is the swing's coming
  change: its angular acceleration gives out as the bat nears its peak speed, near the
  contact, which a forecast from before holds on (it predicts early, by 0.3-0.7 ms 10-15 ms
  ahead at 90 Hz, by 1-4 ms 20-50 ms ahead). That is carried as a prior: the swing's angular
  and its hands' accelerations may change at their speed over ``SWING_TIME_SCALE`` squared
  (``swing_change``).

Along the contact's normal the spread moves the instant: the ball's forecast is moved by it,
toward the bat and away, and searched again (``contact_of``), so a graze the shift takes away
or a contact whose normal speed is small counts by what the search finds, not a slope; the
half difference of the two instants is the instant's sigma (the one found, one-sided), that of
the two distances from the tip part of where on the bat; where neither meets the bat (a
spread wider than the contact), the spread over the ball's closing speed there. Across the
normal, the spread along the bat's axis moves the spot itself (``prediction_uncertainty``).

A prediction takes copies of what its error bars are measured from (``PendingPrediction``), so
they are the same to the bit measured at once (``analyze``) or later (the node: after sending
``~/predicted_impact``, with its report).
"""

from bisect import bisect_right
from dataclasses import dataclass, replace
import math
from typing import Any, Callable, List, Optional, Sequence, Tuple

import numpy as np

from .bat_window import STEP_ROWS
from .events import Prediction
from .streams import Stream
from ..geometry import advance, cross, dot, lerp, norm, scale, sub, Vector
from ..prediction import bat_window_numbers, contact_of, states_of
from ..toi import _kernel

LIFT_PRIOR = 3.0
"""m/s^2, 1 sigma a coordinate across the flight: the lift a pitch's spin may give that its
flight is too short to show. Pitches spin at 1,500-3,000 rpm and the Magnus force is then 1-7
m/s^2 across the flight in any direction around it (4.4 m/s^2 rms over a uniform spread of its
size: 3.1 a coordinate of the two)."""


def ball_spread(times: Sequence[float], first: int, end: int, lift_first: int, t0: float,
                lead: float) -> Tuple[float, bool]:
    """
    Return the forecast's spread at t0 + lead per metre of noise, and whether it has its lift.

    The forecast (``prediction.ball_numbers``): the parabola of samples [first, end) at t0,
    its value and rate carried on ``lead`` s, and the lift of the parabola of samples
    [lift_first, end) (when the kernel takes one: at least ``LIFT_MIN_SAMPLES`` samples over
    ``LIFT_MIN_SPAN`` s) times lead^2 / 2. That position is a weighted sum of the samples; for
    noise of 1 sigma per coordinate, independent from sample to sample, its sigma per
    coordinate is the norm of the weights (both fits' weights on the samples they share added
    first: ``_quadratic_form``). The lift's gain and the drag's dependence on the velocity are
    left out (the gain is at most 1; the drag moves the lead's 0.2 s by under 3 %).

    :param times: the ball stream's times (s), before t0; the windows within them, ``end -
        first >= 3``; ``lift_first == end``: no lift.
    :returns: (spread, dimensionless: m per m of noise; whether the lift was fitted).
    """
    start = min(first, lift_first)
    span = max(t0 - times[start], 1e-9)  # (one scale for both fits: well conditioned)
    x = (np.asarray(times[end - 1:start - 1 if start else None:-1], dtype=float) - t0) / span
    x2 = x * x  # (newest first: the power sums of every window ending at ``end``, cumulated)
    sums = np.stack((np.ones_like(x), x, x2, x2 * x, x2 * x2), axis=1).cumsum(axis=0)
    forecast = (1.0, lead / span, 0.0)  # (the parabola's c0, c1, c2 in the scaled time)
    square = _quadratic_form(sums[end - 1 - first], forecast, forecast)  # (a well-posed
    # forecast: the kernel fitted it, at least 3 samples at distinct times)
    lifted = bool(end - lift_first >= _kernel.LIFT_MIN_SAMPLES and (
        times[end - 1] - times[lift_first] >= _kernel.LIFT_MIN_SPAN))
    if lifted:  # (the parabola's acceleration is twice its square term)
        lift = (0.0, 0.0, (lead / span) ** 2)
        square += _quadratic_form(sums[end - 1 - lift_first], lift, lift) + 2.0 * (
            _quadratic_form(sums[-1], forecast, lift))  # (the larger fit's: the cross term)
    return math.sqrt(max(square, 0.0)), lifted


def _quadratic_form(sums: np.ndarray, row: Tuple[float, ...], column: Tuple[float, ...]) -> float:
    """
    Return ``row . G^-1 column``, G a parabola fit's normal matrix from its power sums.

    ``sums``: the sums of the scaled times' powers 0-4 over the fit's samples. With the
    weights on the samples ``X G^-1 r`` (X the fit's design), two weight vectors' dot product
    is ``r . G^-1 X^T X' G'^-1 r'``; where one fit's samples are among the other's (the
    forecast's among its lift's, on one time scale) ``X^T X'`` is the smaller fit's G, so the
    cross term is ``r . G'^-1 r'`` of the larger fit: the weights are never made.
    """
    s0, s1, s2, s3, s4 = sums.tolist()
    # G = [[s0, s1, s2], [s1, s2, s3], [s2, s3, s4]]: symmetric, so its adjugate is too
    a00, a01, a02 = s2 * s4 - s3 * s3, s2 * s3 - s1 * s4, s1 * s3 - s2 * s2
    a11, a12, a22 = s0 * s4 - s2 * s2, s1 * s2 - s0 * s3, s0 * s2 - s1 * s1
    adjugate = ((a00, a01, a02), (a01, a11, a12), (a02, a12, a22))
    determinant = s0 * a00 + s1 * a01 + s2 * a02
    return sum(r * sum(a * c for a, c in zip(line, column))
               for r, line in zip(row, adjugate)) / determinant


LIFT_SPEED_POWER = 1.5
"""A pitch's lift goes as its speed to this power (``flight_miss``): the Magnus force is
``0.5 rho A C_L v^2`` and C_L grows as the spin factor ``S = r omega / v`` does, as
``S^0.3-0.6`` over a pitch's S of 0.1-0.4 (Nathan's ``S / (2.32 S + 0.4)``; other fits lie
within), so the lift as ``v^1.4-1.7``; 1 to 2 bound every fit, carried as ``LIFT_POWER_SIGMA``."""

LIFT_POWER_SIGMA = 0.5
"""1 sigma of ``LIFT_SPEED_POWER``."""


def flight_miss(ball: Sequence[float], gravity: Vector, drag: float, lead: float,
                lift_span: float) -> Tuple[Vector, Vector]:
    """
    Return how far (m vectors) the forecast misses the flight ``lead`` s on, and its doubt.

    The forecast (``ball``: the kernel's 10 numbers) holds its acceleration: gravity, the drag
    at t0's speed and the lift of its flight's last ``lift_span`` s (at that window's middle).
    As the ball slows, the drag deceleration changes at ``j = -k (|v| a + v (v . a) / |v|)``
    (k ``drag`` in 1/m), so the flight leaves the forecast by ``j lead^3 / 6``: 4-5 mm at 200
    ms for a 40 m/s pitch (0.1 ms). The lift, ``w x v`` times ``|v|^(p - 1)`` for a spin
    axis w across the flight that holds (``w = v x lift / |v|^2``; p ``LIFT_SPEED_POWER``),
    changes at ``p (v . a) / |v|^2`` of itself as the ball slows, and at ``w x a_across`` as
    its flight turns (a_across: the acceleration across v), from the window's middle on,
    ``lift_span / 2`` before t0: by ``rate (lead^3 / 6 + lift_span lead^2 / 4)``, 1-2 cm at
    250 ms for 5 m/s^2 of lift.

    :returns: (the miss, both changes; the lift's change over ``LIFT_SPEED_POWER`` times
        ``LIFT_POWER_SIGMA``: 1 sigma of the miss, along it).
    """
    velocity, acceleration = ball[4:7], ball[7:10]
    speed = math.sqrt(dot(velocity, velocity))
    if speed == 0.0:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    slowing = dot(velocity, acceleration) / speed  # m/s^2: the speed's rate
    held_drag = drag * lead ** 3 / 6.0  # (the jerk's -k factor, times lead^3 / 6)
    held = lead ** 3 / 6.0 + lift_span * lead * lead / 4.0
    lift = [a - g + drag * speed * v for a, g, v in zip(acceleration, gravity, velocity)]
    spin = scale(cross(velocity, lift), 1.0 / (speed * speed))  # (w x v = lift, w across v)
    across = [a - v * slowing / speed for a, v in zip(acceleration, velocity)]
    growth = LIFT_SPEED_POWER * slowing / speed * held
    lift_change = [growth * f + held * r for f, r in zip(lift, cross(spin, across))]
    miss = tuple(-held_drag * (speed * a + v * slowing) + c
                 for a, v, c in zip(acceleration, velocity, lift_change))
    return miss, scale(lift_change, LIFT_POWER_SIGMA / LIFT_SPEED_POWER)


def plan_sag(ball: Sequence[float], plan: tuple, times: Sequence[float], t: float,
             bat_fraction: float, here: Vector) -> List[Vector]:
    """
    Return the contact point's planned place at t less quadratics through its poses (m, 3).

    The point ``bat_fraction`` of the way from knob to tip, ``here`` at t on the plan (LERP and
    SLERP between its poses), less the quadratic through the plan's poses i - 1, i, i + 1 and
    the one through i, i + 1, i + 2, t within [times[i], times[i + 1]] (``times``, s: the
    plan's): where the plan's motion changes within a step (a bat braking) the two part, so the
    third vector is the one less the other. A quadratic a plan has not the poses for (at its
    ends) is the other; none for a plan of fewer than three poses.
    """
    count = len(times)
    if count < 3:
        return []
    i = min(max(bisect_right(times, t) - 1, 0), count - 2)  # t in [times[i], times[i + 1]]
    places = {k: _point(ball, plan, times[k], bat_fraction)
              for k in range(max(i - 1, 0), min(i + 3, count))}
    sags = []
    for start in (min(max(i - 1, 0), count - 3), min(i, count - 3)):
        at = times[start:start + 3]
        weights = [math.prod((t - at[m]) / (at[k] - at[m]) for m in range(3) if m != k)
                   for k in range(3)]
        sags.append(tuple(h - sum(w * places[start + k][c] for k, w in enumerate(weights))
                          for c, h in enumerate(here)))
    sags.append(sub(sags[1], sags[0]))
    return sags


def _point(ball: Sequence[float], plan: tuple, t: float, bat_fraction: float) -> Vector:
    """Return the axis point ``bat_fraction`` of the way from knob to tip at t on the plan."""
    _, _, knob, tip = states_of(ball, plan, t)
    return lerp(knob, tip, bat_fraction)


NEAR = 0.005
"""s: a search again for a contact moved by millimetres (``flight_corrected``) covers this on
either side of the contact found (within the horizon): they move it by under 1 ms."""

SLOW_CLOSING = 10.0
"""m/s: the sigma's forecasts, the ball moved by its spread along the normal, are searched
within ``NEAR`` and the time a ball closing on the bat this slowly takes over that spread."""


CLOSING_STEP = 1e-4
"""s: the step either side of the contact over which ``prediction_uncertainty`` takes the bat's
motion there (central differences) where neither forecast moved by the spread meets the bat (a
spread wider than the contact's reach)."""


def search_near(ball: Tuple[float, ...], bat: tuple, t0: float, t: float, search: tuple,
                near: float = NEAR) -> Optional[Tuple[float, Any]]:
    """
    Return the first contact of the forecasts within ``near`` s of t (s), or None.

    ``search``: (horizon s from t0, ball radius m, bat profile, chord tolerance m): the
    prediction's horizon, with a finer tolerance than its own search's (``contact_of``).
    """
    horizon, *rest = search
    start = max(t0, t - near)
    end = min(t0 + horizon, t + near)
    return contact_of(ball, bat, start, end - start, *rest) if end > start else None


def flight_corrected(ball: Tuple[float, ...], bat: tuple, t0: float, found: Tuple[float, Any],
                     miss: Vector, search: tuple
                     ) -> Tuple[Tuple[float, Any], Tuple[float, ...]]:
    """
    Return the contact ``found`` (t, hit) searched again with the flight's changes, that ball.

    The ball's forecast (the kernel's 10 numbers) moved by ``miss`` (``flight_miss`` at the
    contact's lead: the whole path by the same vector, which at the contact instant is the
    flight as the drag's and the lift's changes have it, to first order) and searched again
    near t (``search_near``; ``search``: horizon s, ball radius m, bat profile, chord tolerance
    m). Where the moved forecast meets nothing there (a graze the millimetres take away),
    ``found`` and ``ball`` unchanged.
    """
    moved = (ball[0], *(p + m for p, m in zip(ball[1:4], miss)), *ball[4:])
    again = search_near(moved, bat, t0, found[0], search)
    return (found, ball) if again is None else (again, moved)


def plan_variance(sags: List[Vector]) -> Callable[[Vector], float]:
    """Return a plan's spread along a unit direction (m^2): the largest of ``plan_sag``'s."""
    def variance(direction: Vector) -> float:
        return max((dot(v, direction) ** 2 for v in sags), default=0.0)
    return variance


SWING_TIME_SCALE = 0.03
"""s: an extrapolated bat's prior (``swing_change``): a swing's angular acceleration may change
by its angular speed over this squared each second, its hands' by their speed over it squared.
A swing builds its bat speed over 0.1-0.2 s and passes its peak at about the contact, so its
angular acceleration falls from its largest to none over tens of milliseconds, where the
extrapolation holds it. Of 30, 40, 50 and 70 ms tried on the six swing families (whose speed
peaks are 35-50 ms wide), 30 ms is the one whose error bars cover the errors
(BENCHMARKS.md, "An extrapolated bat's error bars")."""

BACKTEST_LEADS = (0.015, 0.035)
"""s: an extrapolated bat's recent misses are those of the forecasts from frames this far before
the forecast's newest (``backtest_frames``): long enough that a held acceleration's miss shows
over a millimetre of noise, short enough to be the swing of now."""

BACKTEST_MOST = 2
"""Recent misses at most: the first and last frame of ``BACKTEST_LEADS`` (a third between them
changed no coverage by a point on the scratch set: "An extrapolated bat's error bars")."""


def backtest_frames(times: Sequence[float], breaks: Sequence[bool], newest: int) -> List[int]:
    """
    Return the frames whose forecasts' misses at frame ``newest`` an extrapolated bat carries.

    Frames of ``newest``'s segment (no break after them up to it) ``BACKTEST_LEADS`` s before
    it, oldest first, at most ``BACKTEST_MOST`` (the first and last); where none is (a
    rate under about 30 Hz, a segment begun since), the one nearest the span's middle within
    twice its end; none in a segment that short. ``times`` (s) and ``breaks``: a bat stream's.
    """
    low, high = BACKTEST_LEADS
    newest_time = times[newest]
    inside, near = [], []
    i = newest
    while i > 0 and not breaks[i]:
        i -= 1
        back = newest_time - times[i]
        if back > 2.0 * high:
            break
        (inside if low <= back <= high else near).append(i)
    if not inside:
        middle = 0.5 * (low + high)
        return [min(near, key=lambda k: abs(newest_time - times[k] - middle))] if near else []
    return sorted({inside[0], inside[-1]} if len(inside) > BACKTEST_MOST else inside)


def recent_misses(bat: Stream, forecast: Sequence[float], bat_fraction: float,
                  window: float, degree: int) -> List[Tuple[float, Vector]]:
    """
    Return an extrapolated bat's recent misses: (their lead s, the miss m) at its newest frame.

    The forecasts (``prediction.bat_window_numbers`` of ``degree``, each from its frame's own
    ``window`` s of frames, ``Stream.history``) from the frames ``backtest_frames`` names before
    the forecast's newest frame (its start, ``forecast[0]``: the kernel's 21 numbers), less
    ``forecast`` there, at the axis point ``bat_fraction`` of the way from knob to tip; a
    rank-deficient fit, or a window of fewer than 3 frames, is left out. ``bat``: the stream,
    or an excerpt of it holding those windows (``streams.excerpt``: the same bits).
    """
    start = forecast[0]
    times = bat.times
    newest = bisect_right(times, start) - 1
    _, _, knob_now, tip_now = states_of(None, forecast, start)
    here = lerp(knob_now, tip_now, bat_fraction)
    rows = bat.aligned.setdefault(STEP_ROWS, [])
    misses = []
    for k in backtest_frames(times, bat.breaks, newest):
        frames = bat.history(times[k], window)
        before = bat_window_numbers(times, bat.values, rows, frames[0], k + 1, degree) \
            if len(frames) >= 3 else None
        if before is not None:
            _, _, knob, tip = states_of(None, before, start)
            misses.append((start - times[k], sub(lerp(knob, tip, bat_fraction), here)))
    return misses


def swing_change(bat: Sequence[float], bat_fraction: float, lead: float) -> Tuple[Vector, Vector]:
    """
    Return what an extrapolated bat's held accelerations may miss ``lead`` s on (m, 1 sigma).

    The forecast (``bat``: the kernel's 21 numbers) turns about a fixed axis at its angular
    speed and acceleration and moves its pivot at its velocity and acceleration. A swing's
    angular acceleration changing at ``|w| / SWING_TIME_SCALE^2`` moves the axis point
    ``bat_fraction`` of the way from knob to tip by ``|w| lead^3 / (6 tau^2)`` times its arm,
    along its motion (``w x r``); the hands' at ``|v| / tau^2`` move the pivot by
    ``|v| lead^3 / (6 tau^2)`` along its velocity.

    :returns: (the turn's vector, the pivot's).
    """
    held = lead ** 3 / (6.0 * SWING_TIME_SCALE ** 2)
    axis, rate = bat[16:19], bat[19]
    knob_arm, tip_arm = bat[10:13], bat[13:16]
    arm = lerp(knob_arm, tip_arm, bat_fraction)
    arm = sub(arm, scale(axis, dot(axis, arm)))
    return scale(cross(axis, arm), abs(rate) * held), scale(bat[4:7], held)


def swing_variance(misses: Sequence[Tuple[float, Vector]], lead: float, changes: Sequence[Vector],
                   noise: float) -> Callable[[Vector], float]:
    """
    Return an extrapolated bat's spread along a unit direction (m^2), ``lead`` s on.

    ``misses``: (their lead s, the miss m) of the forecasts from earlier frames at the
    forecast's newest (``backtest_frames``), each scaled to ``lead`` as ``lead / theirs`` up to
    theirs and its cube beyond, averaged; plus ``changes`` (``swing_change``) and the newest
    frame's ``noise`` (m, 1 sigma a coordinate).
    """
    vectors = list(changes)
    if misses:
        share = 1.0 / math.sqrt(len(misses))
        for back, miss in misses:
            ratio = lead / back
            vectors.append(scale(miss, share * (ratio if ratio < 1.0 else ratio ** 3)))
    floor = noise * noise

    def variance(direction: Vector) -> float:
        return floor + sum(dot(v, direction) ** 2 for v in vectors)
    return variance


def prediction_uncertainty(ball: Tuple[float, ...], bat: tuple, t0: float,
                           found: Tuple[float, Any], at: Tuple[Vector, Vector, Vector],
                           spread: float, lifted: bool, doubt: Vector,
                           bat_variance: Callable[[Vector], float],
                           search: tuple) -> Tuple[Optional[float], float]:
    """
    Return a prediction's 1-sigma time (s) and distance from the tip (m) uncertainty.

    The module's docstring. ``ball``: the forecast (the kernel's 10 numbers, as
    ``flight_corrected`` moved it) that found the contact ``found`` (t, hit) on the bat's
    (``bat``: a plan's or the extrapolated kernel numbers); ``at``: the ball's velocity (m/s),
    the knob and the tip (m) at t (``states_of``'s); ``spread``: the noise's spread of the
    ball's centre at t, m a coordinate (``ball_spread`` times the noise); ``lifted``: whether
    the forecast has its lift (else ``LIFT_PRIOR``'s); ``doubt``: 1 sigma of the flight's
    correction (``flight_miss``'s second vector, m); ``bat_variance``: the bat's spread at t
    along a unit direction (m^2: ``plan_variance``, ``swing_variance``); ``search``: (horizon
    s, ball radius m, bat profile, chord tolerance m) of the prediction's own search
    (``contact_of``).

    :returns: (time sigma, distance sigma). Where neither shifted forecast meets the bat (a
        spread wider than the contact: an extrapolated bat far ahead), the time sigma is the
        spread along the normal over the ball's closing speed on the bat there (None where it
        does not close).
    """
    t, hit = found
    lead = t - t0
    n = hit.normal
    velocity, knob, tip = at
    length = math.dist(knob, tip)
    axis = scale(sub(tip, knob), 1.0 / length) if length > 0.0 else (0.0, 0.0, 0.0)
    flight = scale(velocity, 1.0 / max(norm(velocity), 1e-12))
    prior = 0.0 if lifted else 0.5 * LIFT_PRIOR * lead * lead

    def variance(direction: Vector) -> float:
        """Return the relative place's variance along a unit direction (m^2)."""
        return spread * spread + bat_variance(direction) + prior * prior * (
            1.0 - dot(direction, flight) ** 2) + dot(doubt, direction) ** 2

    along = math.sqrt(variance(n))
    near = NEAR + along / SLOW_CLOSING
    shifted = []
    for sign in (-1.0, 1.0):
        moved = (ball[0], *advance(ball[1:4], n, sign * along), *ball[4:])
        again = search_near(moved, bat, t0, t, search, near)
        if again is not None:
            when, moved_hit = again
            _, _, knob_at, tip_at = states_of(moved, bat, when)
            shifted.append((when, (1.0 - moved_hit.bat_fraction) * math.dist(knob_at, tip_at)))
    spot_variance = variance(axis) * (1.0 - dot(axis, n) ** 2)
    if not shifted:  # (a spread wider than the contact: at the instant's closing speed)
        _, _, knob_a, tip_a = states_of(ball, bat, t - CLOSING_STEP)
        _, _, knob_b, tip_b = states_of(ball, bat, t + CLOSING_STEP)
        moved_by = sub(lerp(knob_b, tip_b, hit.bat_fraction),
                       lerp(knob_a, tip_a, hit.bat_fraction))
        closing = abs(dot(velocity, n) - 0.5 * dot(moved_by, n) / CLOSING_STEP)
        return (along / closing if closing > 0.0 else None), math.sqrt(spot_variance)
    if len(shifted) == 1:  # (one-sided: the other shift loses the contact)
        shifted.append((t, (1.0 - hit.bat_fraction) * length))
        half = 1.0
    else:
        half = 0.5
    (t_a, d_a), (t_b, d_b) = shifted
    return half * abs(t_b - t_a), math.sqrt((half * (d_b - d_a)) ** 2 + spot_variance)


BACKTEST_SPAN = 2.0 * BACKTEST_LEADS[1]
"""s: how far before an extrapolated bat's newest frame its pending prediction keeps the frames
(``backtest_frames``' reach), and a ``velocity_window`` more for their fits."""


@dataclass(frozen=True)
class PendingPrediction:
    """
    A prediction whose error bars are yet to be measured, with copies of what they are from.

    Taken when the prediction is made (``Predictor.predict``), so ``measure`` gives the same
    error bars to the bit whenever it runs, whatever the detector took or cleared since: the
    node publishes ``~/predicted_impact`` first and measures them with the reports, after the
    drain (``Detector`` with ``deferred_uncertainty``); ``analyze`` measures them at once.

    :ivar prediction: the prediction, its uncertainties None.
    :ivar ball: the ball's forecast (the kernel's 10 numbers, as ``flight_corrected`` moved it).
    :ivar bat: the bat's (a plan's kernel numbers, or the extrapolated 21).
    :ivar plan_times: the plan's pose times (s), None for an extrapolated bat.
    :ivar t0: the instant predicted from (s); ``found``: (t, hit) of the contact.
    :ivar at: the ball's velocity (m/s), the knob and the tip (m) at t.
    :ivar doubt: ``flight_miss``'s doubt (m).
    :ivar search: (horizon s, ball radius m, bat profile, chord tolerance m).
    :ivar ball_times: the ball's sample times (s) the forecast and its lift read;
        ``ball_window``: (first, end, lift_first) among them; ``ball_noise``: its noise (m).
    :ivar bat_frames: an excerpt of the bat stream holding ``recent_misses``' windows (None
        with a plan); ``bat_noise``: its noise (m); ``window``, ``degree``: the fits'.
    """

    prediction: Prediction
    ball: Tuple[float, ...]
    bat: tuple
    plan_times: Optional[Sequence[float]]
    t0: float
    found: Tuple[float, Any]
    at: Tuple[Vector, Vector, Vector]
    doubt: Vector
    search: tuple
    ball_times: Sequence[float]
    ball_window: Tuple[int, int, int]
    ball_noise: float
    bat_frames: Optional[Stream] = None
    bat_noise: float = 0.0
    window: float = 0.0
    degree: int = 0

    def measure(self) -> Prediction:
        """Return the prediction with its 1-sigma uncertainties (``prediction_uncertainty``)."""
        t, hit = self.found
        first, end, lift_first = self.ball_window
        gain, lifted = ball_spread(self.ball_times, first, end, lift_first, self.t0, t - self.t0)
        _, knob, tip = self.at
        fraction = hit.bat_fraction
        if self.plan_times is not None:
            bat_variance = plan_variance(plan_sag(self.ball, self.bat, self.plan_times, t,
                                                  fraction, lerp(knob, tip, fraction)))
        else:
            lead = t - self.bat[0]
            bat_variance = swing_variance(
                recent_misses(self.bat_frames, self.bat, fraction, self.window, self.degree),
                lead, swing_change(self.bat, fraction, lead), self.bat_noise)
        time_sigma, spot_sigma = prediction_uncertainty(
            self.ball, self.bat, self.t0, self.found, self.at, gain * self.ball_noise, lifted,
            self.doubt, bat_variance, self.search)
        return replace(self.prediction, time_uncertainty_s=time_sigma,
                       distance_from_tip_uncertainty_m=spot_sigma)
