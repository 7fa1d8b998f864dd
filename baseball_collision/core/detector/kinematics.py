"""
How the bodies move at an instant, from their samples up to it: least-squares fits.

Velocities at an impact come from samples up to the impact only (a real hit decelerates the
bat in the next frames, so an interpolant spanning the impact would under-read the speed). The
bat is a rigid body: a pivot near the hands (the axis point that accelerates least) moving with
its own velocity, turning with an angular velocity fitted to the cumulative turn of its samples.
With too few samples before the impact, the chords of the spanning interval stand in. With exact
bat samples at a high rate the bat's knob velocity and swing come from the quintic spline
through its samples up to the impact instead, where they pass its check (``fit_velocities``,
``quintic_bat_rates``).

Under the ``c2`` model (``c2_velocities``) the velocities come from samples before the impact
only: with exact samples at a high rate the splines through the samples up to the impact,
extrapolated by their last piece: the knob's velocity and the swing angular velocity u x u' of
the direction chart from the quintic spline (O(h^5)) where the samples show that it pays
(``quintic_bat_rates``), else from the cubic (O(h^3)), the ball's centre its velocity from the
cubic; with exact samples at a low rate the least-squares fits above (half the error of the
splines' extrapolation there); with noise the rates of the window fits that end at the impact
interval's opening frame, smoothed, extrapolated to the impact. A bat braking right after the
contact does not reach them. Each body by its own noise: an exact bat beside a noisy ball (a
robot's own kinematics beside a camera-tracked ball) keeps the exact samples' rates.
"""

from dataclasses import dataclass, replace
import math
from typing import Any, Callable, List, Optional, Sequence, Tuple

import numpy as np

from .fitting import (
    c2_bat_path, c2_point_path, c2_window, chart_swing, stream_noise, swing_rate)
from .noise import NOISE_FLOOR
from .streams import Stream, Turn
from ..geometry import add, lerp, scale, Vector
from ..motion import (
    BatPath, BatSample, c2_rows, C2BatPath, end_state, MotionPath, PointPath, turn_between,
    unit_axis)
from ..motion.broken import broken_fit
from ..toi import _kernel

SPARSE_SAMPLES = 6
"""At most this many samples in the velocity window (a low rate): the pivot's fit uses the full
``velocity_degree``, interpolating, since the impact can be a whole step after the last sample;
with more samples (a high rate) at most degree 3, which averages tracking noise at little bias
(the hands' path is smooth; the bat's turn is not, so its fit keeps the full degree)."""

Rates = Tuple[float, Vector, Vector]
"""A pivot's fraction along knob-tip, its velocity (m/s) and acceleration (m/s^2)."""

TurnRates = Tuple[Vector, float, Vector]
"""Swing angular velocity (rad/s), roll rate (rad/s), swing angular acceleration (rad/s^2)."""


def fit_coefficients(times: Sequence[float], values: Any, t: float,
                     degree: int) -> Tuple[np.ndarray, float]:
    """
    Return the coefficients (one column per component) and span (s) of a least-squares fit.

    The polynomial is in x = (time - t) / span, span = t - times[0] (at least 1 ns), so the
    fit is well conditioned; the degree drops to the number of samples minus one (then it
    interpolates). Solved by the compiled kernel (Householder QR, ``_kernel.polyfit``); a fit
    it finds rank deficient by LAPACK's minimum-norm ``lstsq``.

    :param times: sample times (s), oldest first, at or before t.
    :param values: one row of components per sample (a sequence of rows or an array).
    """
    coefficients, span = _fit(times, values, t, degree)
    return np.asarray(coefficients), span


def _fit(times: Sequence[float], values: Any, t: float,
         degree: int) -> Tuple[Any, float]:
    """Return ``fit_coefficients``, the coefficients as the kernel's lists when it solved it."""
    fitted = _kernel.polyfit(times, values, t, degree)
    if fitted is not NotImplemented:
        return fitted
    degree = min(degree, len(times) - 1)
    span = max(t - times[0], 1e-9)
    x = (np.asarray(times, dtype=float) - t) / span
    vandermonde = np.vander(x, degree + 1, increasing=True)
    coefficients, *_ = np.linalg.lstsq(vandermonde, np.asarray(values, dtype=float), rcond=None)
    return coefficients, span


def derivatives(coefficients: Any, span: float,
                x: float = 0.0) -> Tuple[List[float], List[float], List[float]]:
    """
    Return value, first and second time derivatives of ``fit_coefficients``' fit at x.

    :param coefficients: an array, or lists, one row of components per power.
    :param x: where, in the fit's scaled time ((time - t) / span); 0 is the fit's own t.
    """
    if x != 0.0:
        coefficients = np.asarray(coefficients, dtype=float)
        powers = x ** np.arange(len(coefficients))
        k = np.arange(len(coefficients), dtype=float)
        value = powers @ coefficients
        first = (k[1:] * powers[:-1]) @ coefficients[1:] / span
        second = (k[2:] * (k[2:] - 1.0) * powers[:-2]) @ coefficients[2:] / span ** 2
        return value.tolist(), first.tolist(), second.tolist()
    # at x = 0 the powers are 0 but one: the coefficients scaled, as lists (small rows: numpy
    # would cost more in calls than it saves; the same operations, so the same bits)
    if isinstance(coefficients, np.ndarray):
        coefficients = coefficients.tolist()
    first = [c / span for c in coefficients[1]] if len(coefficients) > 1 else [
        0.0 * c for c in coefficients[0]]
    squared = span ** 2
    second = [2.0 * c / squared for c in coefficients[2]] if len(coefficients) > 2 else [
        0.0 * c for c in coefficients[0]]
    return list(coefficients[0]), first, second


def fit_polynomial(times: Sequence[float], values: Any, t: float,
                   degree: int) -> Tuple[List[float], List[float], List[float]]:
    """
    Return value, first and second time derivatives at t of a least-squares polynomial.

    The degree drops to the number of samples minus one (then it interpolates). Time is
    centred on t and scaled by the span, so the fit is well conditioned.

    :param times: sample times (s), oldest first, at or before t.
    :param values: one row of components per sample.
    """
    return derivatives(*_fit(times, values, t, degree))


def fit_rates(times: Sequence[float], values: Any, t: float,
              degree: int) -> Tuple[List[float], List[float]]:
    """Return first and second time derivatives at t of ``fit_polynomial``."""
    return fit_polynomial(times, values, t, degree)[1:]


def point_velocity(stream: Stream, t: float, pick: Callable[[object], Vector], window: float,
                   degree: int) -> Optional[Vector]:
    """
    Return the velocity (m/s) at t of a point, from the samples up to t only.

    A least-squares polynomial of ``degree`` through the samples of the last ``window`` s of
    the segment, differentiated at t; None with fewer than two samples.
    """
    indices = stream.history(t, window)
    if len(indices) < 2:
        return None
    return tuple(fit_rates([stream.times[i] for i in indices],
                           [pick(stream.values[i]) for i in indices], t, degree)[0])


def pivot_degree(samples: int, degree: int) -> int:
    """Return the degree of the bat pivot's velocity fit for a window of ``samples``."""
    return degree if samples <= SPARSE_SAMPLES else min(degree, 3)


def least_accelerating(knob: Sequence[float], tip: Sequence[float]) -> float:
    """
    Return the fraction along knob-tip of the axis point with the smallest acceleration.

    Every axis point's acceleration is linear in the fraction between the knob's and the
    tip's (m/s^2); the smallest is taken, within [-0.5, 1] (0 when both are equal). The
    compiled kernel's (the prediction's bat forecast uses the same function).

    :raises TypeError: knob or tip not 3 numbers.
    """
    return _kernel.least_accelerating(knob, tip)


def pivot_fraction(stream: Stream, t: float, window: float, degree: int) -> float:
    """
    Return the fraction along knob-tip of the bat point that accelerates least before t.

    A swinging bat turns about the hands: the axis point nearest them moves on the smoothest
    path, so its velocity is the best one to extrapolate (the knob circles the hands). Knob
    and tip are fitted (so noise is averaged) and ``least_accelerating`` picks the point at
    the last sample before t.
    """
    indices = stream.history(t, window)
    if len(indices) < 3:
        return 0.0
    return bat_rates(stream, t, window, degree)[0][0]


def bat_rates(stream: Stream, t: float, window: float, degree: int,
              turn_degree: Optional[int] = None,
              indices: Optional[Sequence[int]] = None) -> Tuple[Optional[Rates],
                                                                Optional[TurnRates]]:
    """
    Return the bat's ``pivot_rates`` and (with ``turn_degree``) ``turn_rates`` at t.

    From one least-squares fit of knob and tip (``pivot_degree``): least squares is linear in
    the data, so the pivot's rates are those of knob and tip interpolated at its fraction;
    the fraction is the least-accelerating point at the last sample (the same polynomial
    evaluated there). The turn shares that fit when its degree is the same. (None, None) with
    fewer than two samples.

    :param indices: ``stream.history(t, window)`` when the caller has it already.
    """
    if indices is None:
        indices = stream.history(t, window)
    if len(indices) < 2:
        return None, None
    first, end = indices[0], indices[-1] + 1  # the history is contiguous
    sample_times = stream.times[first:end]
    fit_degree = pivot_degree(len(indices), degree)
    shared = turn_degree is not None and min(turn_degree, len(indices) - 1) == min(
        fit_degree, len(indices) - 1)
    if shared:
        rows = turn_rows(stream, first, end)[first:end]
    else:
        rows = [value.knob + value.tip for value in stream.values[first:end]]
    coefficients, span = _fit(sample_times, rows, t, fit_degree)
    _, first, second = derivatives(coefficients, span)
    fraction = 0.0
    if len(indices) >= 3:
        x = (sample_times[-1] - t) / span
        at_last = second if x == 0.0 else derivatives(coefficients, span, x)[2]
        fraction = least_accelerating(at_last[:3], at_last[3:6])
    pivot = (fraction, lerp(first[:3], first[3:6], fraction),
             lerp(second[:3], second[3:6], fraction))
    if turn_degree is None:
        return pivot, None
    if shared:
        rate, change = first[6:], second[6:]
    else:
        rate, change = fit_rates(sample_times, window_turns(stream, indices[0], end), t,
                                 turn_degree)
    return pivot, ((rate[0], rate[1], rate[2]), rate[3], (change[0], change[1], change[2]))


def window_turns(stream: Stream, first: int, end: int) -> List[Turn]:
    """
    Return the cumulative turns of bat samples [first, end) of one segment (``Stream.turn``).

    The newest first: one kernel call sums every step missing up to it, in the order a call
    per sample would (the same numbers), and the rest are then known.
    """
    stream.turn(end - 1)
    turns = stream.turns[first:end]
    if None in turns:  # (not within one segment: each from its own reference)
        turns = [stream.turn(i) for i in range(first, end)]
    return turns


def turn_rows(stream: Stream, first: int, end: int) -> List[Optional[Tuple[float, ...]]]:
    """
    Return the rows knob + tip + cumulative turn of a bat stream, filled for samples [first, end).

    Fills every turn of the segment up to sample end - 1 (``Stream.turn``). Each row is made
    once and kept in ``stream.aligned`` (a sample and its turn never change), aligned with the
    samples; rows outside [first, end) may be None.
    """
    stream.turn(end - 1)
    rows = stream.aligned.setdefault('turn_rows', [])
    if len(rows) < end:
        rows.extend([None] * (end - len(rows)))
    values, turns = stream.values, stream.turns
    last = end - 1
    while last >= first and rows[last] is None:  # the newest samples: what is usually missing
        rows[last] = values[last].knob + values[last].tip + turns[last]
        last -= 1
    if None in rows[first:last + 1]:
        for i in range(first, last + 1):
            if rows[i] is None:
                rows[i] = values[i].knob + values[i].tip + turns[i]
    return rows


def pivot_rates(stream: Stream, t: float, window: float, degree: int) -> Optional[Rates]:
    """
    Return the bat pivot's fraction along knob-tip, velocity (m/s) and acceleration at t.

    The pivot is ``pivot_fraction``'s axis point; its samples up to t are fitted with
    ``pivot_degree`` (``bat_rates``). None with fewer than two samples.
    """
    return bat_rates(stream, t, window, degree)[0]


def turn_rates(stream: Stream, t: float, window: float, degree: int) -> Optional[TurnRates]:
    """
    Return the bat's swing angular velocity, roll rate and swing angular acceleration at t.

    From the samples up to t only: the rotations between consecutive samples are summed into a
    cumulative rotation (exact for a turn about a fixed axis, and close when the axis moves
    slowly), fitted like a point (``point_velocity``). None with fewer than two samples.

    :param window: how far back (s) from t: within the history every stream keeps behind the
        detector's cursor (``fitting.kept_history``), so that the node, whatever the order its
        streams' samples arrive in, and ``analyze`` fit the same samples.
    """
    indices = stream.history(t, window)
    if len(indices) < 2:
        return None
    first, end = indices[0], indices[-1] + 1  # the history is contiguous
    rate, change = fit_rates(stream.times[first:end], window_turns(stream, first, end), t,
                             degree)
    return (rate[0], rate[1], rate[2]), rate[3], (change[0], change[1], change[2])


def _point(value: Vector) -> Vector:
    return value


def _knob(ends: Tuple[Vector, Vector]) -> Vector:
    return ends[0]


def chord_velocity(path: MotionPath, pick: Callable[[object], Vector] = _point) -> Vector:
    """Return the mean velocity (m/s) of a path's (picked) point over its whole interval."""
    a, b = pick(path.at(path.t0)), pick(path.at(path.t0 + path.h))
    return tuple((q - p) / path.h for p, q in zip(a, b))


def chord_turn_rates(bat_path: BatPath) -> Tuple[Vector, float]:
    """Return the mean swing angular velocity and roll rate (rad/s) over a bat path."""
    knob0, tip0 = bat_path.at(bat_path.t0)
    knob1, tip1 = bat_path.at(bat_path.t0 + bat_path.h)
    swing, roll = turn_between(BatSample(knob0, tip0, None, bat_path.sample0.quaternion),
                               BatSample(knob1, tip1, None, bat_path.sample1.quaternion))
    return scale(swing, 1.0 / bat_path.h), roll / bat_path.h


@dataclass(frozen=True)
class ImpactVelocities:
    """
    How ball and bat moved at an impact.

    :ivar ball: ball velocity (m/s).
    :ivar pivot_fraction: the bat pivot's fraction along knob-tip.
    :ivar pivot: the pivot's velocity (m/s).
    :ivar swing: swing angular velocity (rad/s, across the bat); ``roll``: about its axis.
    :ivar from_history: False when the spanning interval's chords stood in for the fits.
    """

    ball: Vector
    pivot_fraction: float
    pivot: Vector
    swing: Vector
    roll: float
    from_history: bool


def knot_bat_rates(bat: Stream, window: range, t: float) -> Tuple[Vector, Vector]:
    """
    Return the bat's knob velocity (m/s) and swing angular velocity (rad/s) at t (s).

    From exact samples before t only: the ``c2`` chart rows (knob, rotation vector from the
    second-newest sample's direction, length) of the window's samples, all at or before t,
    fitted by the not-a-knot spline with a knot at t (``motion.broken.broken_fit`` broken
    after its last sample): the value at t is the one that keeps the whole window's third-
    derivative jumps least, not the last cubic's continuation; the rates are its left limits.

    :param window: the samples' indices in the stream (at least two, all at or before t).
    """
    samples = bat.values[window.start:window.stop]
    first, rows = c2_rows(samples, len(samples) - 2)
    times = bat.times[window.start + first:window.start + first + len(rows)]
    _, fitted, slopes = broken_fit(times, rows, [0.0] * len(rows[0]), t)  # exact: one call
    state, rates = fitted[-1], slopes[-1]
    return (tuple(rates[:3].tolist()),
            chart_swing(unit_axis(samples[-2]), state[3:6], rates[3:6]))


POLY_SAMPLES = 8
"""Samples (the newest of the window) ``poly_bat_rates`` interpolates: degree 7."""


def poly_bat_rates(bat: Stream, window: range, t: float) -> Tuple[Vector, Vector]:
    """
    Return the bat's knob velocity (m/s) and swing angular velocity (rad/s) at t (s).

    From exact samples before t only: the ``c2`` chart rows (as ``knot_bat_rates``) of the
    window's newest ``POLY_SAMPLES`` samples interpolated by one polynomial of degree
    (samples - 1), differentiated at t: a higher-order extrapolation than the spline's last
    cubic (measured, not chosen: BENCHMARKS.md, "Higher-order fits before the contact").

    :param window: the samples' indices in the stream (at least two, all at or before t).
    """
    window = range(max(window.start, window.stop - POLY_SAMPLES), window.stop)
    samples = bat.values[window.start:window.stop]
    first, rows = c2_rows(samples, len(samples) - 2)
    times = np.asarray(bat.times[window.start + first:window.start + first + len(rows)])
    scale = times[-1] - times[0]  # s: the powers in units of the window's span
    powers = np.vander((times - t) / scale, len(times), increasing=True)
    coefficients = np.linalg.solve(powers, np.asarray(rows, dtype=float))
    state, rates = coefficients[0], coefficients[1] / scale
    return (tuple(rates[:3].tolist()),
            chart_swing(unit_axis(samples[-2]), state[3:6], rates[3:6]))


QUINTIC_CHECK_RATIO = 0.5
"""``quintic_bat_rates`` takes the quintic spline where, continued from the samples before the
newest, it misses the newest by at most this times the cubic spline's continuation's miss.
Measured at the impacts of bench_accuracy's families (exact samples, 0.2 ms jitter; 1st to 99th
percentile): 0.17-0.44 at 120 Hz, 0.03-0.16 at 240 and 360 Hz; with 0.1 mm of noise or more 0.5
and up at 90 Hz, 1.5 and up above (the quintic's end amplifies noise; BENCHMARKS.md, "The
sweet-spot speed of exact samples from the quintic spline")."""


def quintic_check(times: Sequence[float], samples: Sequence[BatSample]) -> Optional[bool]:
    """
    Return whether the bat's samples follow the quintic spline closely: exact, not noisy.

    The quintic spline of the ``c2`` chart rows through all but the newest sample, continued to
    the newest, misses it (the larger of knob and tip) by at most ``QUINTIC_CHECK_RATIO`` times
    the cubic spline's continuation does, or by at most ``noise.NOISE_FLOOR``: noise the
    detector was not told of fails it (the quintic's end weights amplify it). None where no
    quintic is fitted (``splines.quintic_window``: seven samples or more here, steps within a
    factor 2).

    :param times, samples: the window (s, bat samples), oldest first.
    """
    newest = len(samples) - 1
    if newest < 6:
        return None
    shorter = C2BatPath.fitted(times[:-1], samples[:-1], newest - 2, True)
    if shorter.knob.e is None:
        return None
    cubic = C2BatPath.fitted(times[:-1], samples[:-1], newest - 2)
    misses = [max(map(math.dist, fit.at(times[-1]), (samples[-1].knob, samples[-1].tip)))
              for fit in (shorter, cubic)]
    return misses[0] <= max(QUINTIC_CHECK_RATIO * misses[1], NOISE_FLOOR)


def quintic_bat_rates(times: Sequence[float], samples: Sequence[BatSample],
                      t: float) -> Optional[Tuple[Vector, Vector]]:
    """
    Return the bat's knob velocity (m/s) and swing angular velocity (rad/s) at t (s), or None.

    From exact samples before t only: the quintic spline of the ``c2`` chart rows through them
    (``C2BatPath.fitted``, continued), its last piece continued to t (its rates' error falls as
    h^5 where the cubic's falls as h^3), where the samples show that it pays: the same spline
    through all but the newest sample, continued to the newest, misses it (the larger of knob
    and tip) by at most ``QUINTIC_CHECK_RATIO`` times the cubic spline's continuation does, or
    by at most ``noise.NOISE_FLOOR`` (both exact to within rounding: a bat turning steadily
    about a fixed axis). Noise the detector was not told of fails that check (the quintic's end
    weights amplify it: ``quintic_check``). None where the check fails, or where either window
    takes no quintic (``splines.quintic_window``: six samples or more, so seven here, steps
    within a factor 2).

    :param times, samples: the window (s, bat samples), oldest first, all at or before t.
    """
    if not quintic_check(times, samples):
        return None  # (the check first: noisy samples, the common refusal, fit no more)
    path = C2BatPath.fitted(times, samples, len(samples) - 2, True)
    if path.knob.e is None:
        return None
    return path.knob.velocity(t), swing_rate(path, t)


def spline_velocities(ball: Stream, bat: Stream, t: float, size: int,
                      window: float) -> Optional[ImpactVelocities]:
    """
    Return the ``c2`` velocities at t (s) from the last ``size`` samples up to t of each stream.

    The bat pivots about its knob (fraction 0): its rates from the quintic spline where
    ``quintic_bat_rates`` takes it, else the cubic's last piece extrapolated (``end_state``);
    the ball's from the cubic's. The roll rate comes from the turns of poses over ``window``
    (s) up to t (``turn_rates``, 0 for points). None with fewer than two samples of a body.
    """
    ball_indices = ball.history(t, 1.0)[-size:]
    bat_indices = bat.history(t, 1.0)[-size:]
    if len(ball_indices) < 2 or len(bat_indices) < 2:
        return None
    ball_velocity = end_state([ball.times[i] for i in ball_indices],
                              [ball.values[i] for i in ball_indices], t)[1]
    samples = [bat.values[i] for i in bat_indices]
    times = [bat.times[i] for i in bat_indices]
    found = quintic_bat_rates(times, samples, t)
    if found is None:
        first, rows = c2_rows(samples, len(samples) - 2)
        state, rates = end_state(times[first:], rows, t)
        found = (tuple(rates[:3].tolist()),
                 chart_swing(unit_axis(samples[-2]), state[3:6], rates[3:6]))
    roll = 0.0
    if samples[-1].quaternion is not None:
        rates_of_turn = turn_rates(bat, t, window, 3)
        roll = rates_of_turn[1] if rates_of_turn is not None else 0.0
    return ImpactVelocities(tuple(ball_velocity.tolist()), 0.0, found[0], found[1], roll, True)


def spline_window_for(bat: Stream, t: float, config: Any) -> int:
    """
    Return the ``c2`` splines' window for the velocities at t, or 0 for the least-squares fits.

    Chosen by measurement (benchmarks/bench_accuracy.py): without tracking noise the splines
    when the velocity window holds more than ``SPARSE_SAMPLES`` samples (a high rate: their
    error falls as h^3, the quintic's as h^5), the fits at a low rate (where the quintic's
    extrapolation is worse than the fits too); with noise (``tracker_noise`` > 0) the other
    way round: at a high rate the fits average the noise, at a low rate they interpolate it
    and the spline's extrapolation is the smaller error.
    """
    many = len(bat.history(t, config.velocity_window)) > SPARSE_SAMPLES
    return config.spline_window if many == (stream_noise(bat, config) == 0.0) else 0


def rigid_bat(velocities: ImpactVelocities, knob: Vector, tip: Vector,
              sweet_spot_from_tip: float) -> Tuple[Vector, Vector, Vector]:
    """
    Return the bat's (angular velocity (rad/s), pivot point, sweet spot (m)) at an impact.

    The angular velocity is the swing's plus the roll about the bat's own axis; a point p of
    the bat then moves at ``rigid_point_velocity(velocities.pivot, omega, pivot, p)``. The
    sweet spot is the axis point ``sweet_spot_from_tip`` (m) from the tip (the knob on a
    shorter bat).
    """
    length = math.dist(knob, tip)
    direction = tuple((e - k) / length for k, e in zip(knob, tip))
    omega = add(velocities.swing, scale(direction, velocities.roll))
    sweet = max(0.0, length - sweet_spot_from_tip)
    sweet_point = add(knob, tuple(sweet * d for d in direction))
    return omega, lerp(knob, tip, velocities.pivot_fraction), sweet_point


def velocity_interval(stream: Stream, k: int, max_gap: float) -> int:
    """
    Return the interval whose window fits give ``c2``'s velocities for an impact in interval k.

    The one before it, whose window (without look-ahead) ends at k's opening frame, so no
    sample after the impact enters; k itself at a segment's start, where nothing comes before.
    """
    return k - 1 if k >= 1 and stream.continuous(k - 1, max_gap) else k


def velocity_path(ball: Stream, ball_path: PointPath, config: Any, before: bool) -> PointPath:
    """
    Return the ball's path whose rates give ``c2``'s ball velocity at an impact on ``ball_path``.

    ``before``: the window fit of the interval before (``velocity_interval``), else the
    impact interval's own without look-ahead (``ball_path`` itself without a look-ahead).
    """
    gap = config.max_gap
    k = ball.interval(ball_path.t0)
    j = velocity_interval(ball, k, gap) if before else k
    if j != k or config.look_ahead:
        return c2_point_path(ball, j, c2_window(ball, j, gap, 0, config.spline_window),
                             stream_noise(ball, config), config)
    return ball_path


VELOCITIES = 'auto'
"""c2's impact velocities: 'auto' (below: each body's as 'fits' where its samples are exact, else
as 'before'), 'before' (the
window fits ending at the interval's opening frame, extrapolated to t), 'knot' (as 'before',
but with exact bat samples the bat's window fitted with a knot at t: ``knot_bat_rates``;
measured, not chosen: BENCHMARKS.md, "Contact-aware fits"), 'poly' (as 'knot', with
``poly_bat_rates``: one interpolating polynomial; measured, not chosen: "Higher-order fits
before the contact"), 'window' (the look-ahead-0 window fits' rates at t: they reach the
closing frame, after the contact) or 'fits' (``spline_window_for``: with exact samples the
splines up to t at a high rate, the least-squares fits at a low rate; with noise the other way
round); the others are kept for bench_accuracy's comparison (BENCHMARKS.md, "Exact samples at a
low rate: the least-squares fits again")."""


def c2_velocities(ball: Stream, bat: Stream, t: float, ball_path: PointPath,
                  bat_path: C2BatPath, config: Any,
                  mode: Optional[str] = None) -> ImpactVelocities:
    """
    Return the ``c2`` velocities at an impact at t (s), from samples before the impact only.

    ``mode``: a rule of ``VELOCITIES`` (None: ``VELOCITIES``'s). Under 'auto', exact bat
    samples ('fits'): at a high rate (more than ``SPARSE_SAMPLES`` in ``velocity_window``) the
    splines through the last samples up to t, extrapolated by their last piece
    (``spline_velocities``), at a low rate the least-squares fits of the samples up to t
    (``impact_velocities``: ``velocity_degree`` over ``velocity_window``); the ball's the same
    way where its samples are exact too, else its 'before' rule below (an exact bat beside a
    noisy ball: the bat's sweet-spot speed p99 at 90 Hz 0.75-1.92 % as with an exact ball,
    against 1.62-2.84 % by 'before', BENCHMARKS.md). Noisy bat samples
    ('before'): the window fits of the interval before the impact's
    (smoothed with ``tracker_noise``), which end at the impact interval's opening frame,
    differentiated at t: the ball's centre (with noise its flight fit where the guard passes,
    ``fitting.ball_flight``, as the sweep's paths), the bat's knob (the pivot, fraction 0) and its
    swing u x u' (``fitting.swing_rate``). Neither reaches the interval's closing frame, which
    a bat braking right after the contact has already slowed (benchmarks/bench_accuracy.py
    compares the choices). At a segment's first interval, where nothing comes before, the
    interval's own fits without look-ahead stand in. The roll rate comes from the turns of
    poses over ``velocity_window`` (``turn_rates``, 0 for points).
    """
    mode = VELOCITIES if mode is None else mode
    exact = stream_noise(bat, config) == 0.0
    if mode == 'auto':
        mode = 'fits' if exact else 'before'
        if exact and stream_noise(ball, config) > 0.0:
            fits = impact_velocities(ball, bat, t, config.velocity_window,
                                     config.velocity_degree, ball_path, bat_path,
                                     spline_window_for(bat, t, config))
            if not fits.from_history:  # the chords of the interval stood in for both
                return fits
            return replace(fits, ball=velocity_path(ball, ball_path, config, True).velocity(t))
    if mode == 'fits':
        return impact_velocities(ball, bat, t, config.velocity_window, config.velocity_degree,
                                 ball_path, bat_path, spline_window_for(bat, t, config))
    gap, size = config.max_gap, config.spline_window
    before = mode in ('before', 'knot', 'poly')
    ball_path = velocity_path(ball, ball_path, config, before)
    k = bat.interval(bat_path.t0)
    j = velocity_interval(bat, k, gap) if before else k
    if mode in ('knot', 'poly') and exact and j != k:
        rates = knot_bat_rates if mode == 'knot' else poly_bat_rates
        knob_rate, swing = rates(bat, c2_window(bat, j, gap, 0, size), t)
    else:
        if j != k or config.look_ahead:
            bat_path = c2_bat_path(bat, j, c2_window(bat, j, gap, 0, size),
                                   stream_noise(bat, config))
        knob_rate, swing = bat_path.knob.velocity(t), swing_rate(bat_path, t)
    roll = 0.0
    if bat.values[k].quaternion is not None:
        rates_of_turn = turn_rates(bat, t, config.velocity_window, 3)
        roll = rates_of_turn[1] if rates_of_turn is not None else 0.0
    return ImpactVelocities(ball_path.velocity(t), 0.0, knob_rate, swing, roll, True)


def fit_velocities(ball: Stream, bat: Stream, t: float, ball_path: MotionPath,
                   bat_path: BatPath, config: Any, quintic: bool = True) -> ImpactVelocities:
    """
    Return the velocities at an impact at t (s) under ``linear``, ``rigid`` and ``spline``.

    The least-squares fits of the samples up to t (``impact_velocities``: ``velocity_degree``
    over ``velocity_window``). With exact bat samples (``tracker_noise`` 0, or estimated 0) at
    a high rate (more than ``SPARSE_SAMPLES`` in ``velocity_window``) the bat's knob velocity
    and swing come from the quintic spline through its last ``spline_window`` samples up to t
    instead, where its check passes (``quintic_bat_rates``, as ``c2``'s): the fits' bias on an
    accelerating swing does not fall with the rate (sweet-spot speed p99 about 1 % from 240 Hz
    to 1 kHz), the quintic's does (BENCHMARKS.md, "The sweet-spot speed of exact samples from
    the quintic spline"). Noise fails the check, and the fits average it as before.
    ``quintic`` False: the fits alone.
    """
    velocities = impact_velocities(ball, bat, t, config.velocity_window, config.velocity_degree,
                                   ball_path, bat_path)
    if (not quintic or not velocities.from_history or stream_noise(bat, config) > 0.0
            or len(bat.history(t, config.velocity_window)) <= SPARSE_SAMPLES):
        return velocities
    indices = bat.history(t, 1.0)[-config.spline_window:]
    found = quintic_bat_rates([bat.times[i] for i in indices], [bat.values[i] for i in indices],
                              t)
    if found is None:
        return velocities
    return ImpactVelocities(velocities.ball, 0.0, found[0], found[1], velocities.roll, True)


def impact_velocities(ball: Stream, bat: Stream, t: float, window: float, degree: int,
                      ball_path: MotionPath, bat_path: BatPath,
                      spline_window: int = 0) -> ImpactVelocities:
    """
    Return the velocities at an impact at t (s), from the samples up to t.

    The ball's fit is at most a parabola; the bat's pivot and turn use ``degree``. With fewer
    than two samples of a body before t, its part comes from the paths' chords instead.
    ``spline_window`` > 0: the ``c2`` splines' rates instead (``spline_velocities``).
    """
    if spline_window:
        found = spline_velocities(ball, bat, t, spline_window, window)
        if found is not None:
            return found
    ball_velocity = point_velocity(ball, t, _point, window, min(2, degree))
    rates, turn = bat_rates(bat, t, window, degree, degree)
    fraction, pivot_velocity = (rates[0], rates[1]) if rates else (0.0, None)
    omega = None if turn is None else (turn[0], turn[1])
    if ball_velocity is not None and pivot_velocity is not None and omega is not None:
        return ImpactVelocities(ball_velocity, fraction, pivot_velocity, omega[0], omega[1], True)
    # not enough history before the impact: fall back to the spanning interval
    ball_velocity = ball_velocity or chord_velocity(ball_path)
    pivot_velocity = pivot_velocity or chord_velocity(bat_path, _knob)
    swing, roll = omega or chord_turn_rates(bat_path)
    return ImpactVelocities(ball_velocity, 0.0, pivot_velocity, swing, roll, False)
