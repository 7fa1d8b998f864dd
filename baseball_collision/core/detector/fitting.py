"""
The ``c2`` model on the streams: each interval's window of samples, and its fitted paths.

An interval [times[k], times[k + 1]] is fitted over a window of its stream's segment: up to
``look_ahead`` samples after its closing frame (fewer where the segment or the stream ends),
back to ``spline_window`` samples in all (fewer at the segment's start). Nothing crosses a
segment break or a gap longer than ``max_gap``.

With tracking noise (``noise`` > 0, m, 1 sigma per coordinate) the window's coordinates are
smoothed first (``motion.smoothing``, penalty and weight rule ``SMOOTHER``, chosen by
measurement: benchmarks/bench_accuracy.py) and the path is the interpolating spline's piece
through the smoothed values: the ball's centre (each coordinate sigma); the bat's knob (sigma),
its direction in the rotation-vector chart (sigma * sqrt(2) / length rad across the bat from
knob and tip points, sigma / ``MARKER_SPREAD_M`` from a pose) and its length (sigma * sqrt(2)
from points; exact from a pose). The smoothed direction at the interval's opening frame is the
path's new chart origin: the rotation vectors' rates are carried over to it numerically.

The ball's centre under noise comes first from its flight fit (``FLIGHT``, ``motion.flight``):
one parabola per coordinate through its samples of the last 0.15 s up to the interval's closing
frame (its segment only, no gap longer than ``max_gap``, no further back than the streams keep
samples: ``kept_history``), the path the fit's piece over the interval. A chi-square test of
the residuals against the noise guards it: where it fails (a ball held, bounced off the bat by
the closing frame, deflected), the fit ending at the opening frame, then the smoother. Without
noise nothing changes.
"""

import math
from typing import Any, Callable, List, Optional, Sequence, Tuple

import numpy as np

from .streams import Stream
from ..geometry import cross, dot, sub, Vector
from ..motion import BatSample, c2_rows, C2BatPath, PointPath, rotate, unit_axis
from ..motion.flight import fit_flight, flight_or_none, FlightFit
from ..motion.points import quintic_coefficients
from ..motion.smoothing import (
    penalty_eigen, smooth, smoother_norms, smoother_rows, smoother_shifts, smoother_weights)
from ..motion.splines import not_a_knot_quintic_rows, not_a_knot_slope_rows, quintic_window
from ..toi import _kernel

SMOOTHER = ('not-a-knot', 'likelihood')
"""The smoothing penalty and weight rule (``smoothing.PENALTIES``, ``smoothing.TARGETS``)."""

BAT_GROUPS = (slice(0, 3), slice(3, 6), slice(6, 7))
"""A bat chart row's columns (``c2_rows``: knob, rotation vector, length) that share a
smoothing weight (``bat_variances``: one noise per group)."""

MARKER_SPREAD_M = 0.3
"""The spread of a bat's markers (m): a pose's orientation noise is sigma / this (rad)."""

NOISE_SPAN = 0.09
"""s: with noise a window reaches at least this far back from its newest sample (within its
segment, at most ``MAX_WINDOW`` samples), so the smoother has samples to average at 360 Hz
as at 90 Hz (chosen by measurement)."""

MAX_WINDOW = 32
"""Most samples in a smoothed window (``spline_window``'s largest value)."""

FLIGHT: Optional[Tuple[int, float, str]] = (2, 0.15, 'closing')
"""With noise, the ball's flight fit (``motion.flight``): (polynomial degree, span in s, where
its window ends: ``'closing'``, the interval's window's newest sample, and where that fails the
guard (a ball that bounced off the bat by then) its opening frame; ``'opening'``, the opening
frame only; from the opening frame the path is carried over the interval), or None for the
window smoother alone. A parabola over 0.15 s (the streams' default trim history) ending at the
closing frame, chosen by measurement (BENCHMARKS.md, "The ball's flight fit")."""

FLIGHT_MIN_SAMPLES = 8
"""Fewest samples a flight fit takes (fewer: the smoother)."""

AUTO_NOISE_TOLERANCE = 1.25
"""Under ``tracker_noise: auto`` the flight fit's guard allows the estimated noise to be this
factor below the true one (the estimate's documented accuracy: within 25 %; measured 7 % low on
the simulator's 360 Hz pitches, where an exact bound turned a quarter of the fits away)."""

_STEP = 1e-4
"""rad: the step along a rotation vector's rate when its chart changes (numeric derivative)."""


def stream_noise(stream: Stream, config: Any) -> float:
    """Return a stream's noise (m, 1 sigma): ``tracker_noise``, or its estimate under auto."""
    return stream.noise if config.tracker_noise < 0.0 else config.tracker_noise


def c2_window(stream: Stream, k: int, max_gap: float, look_ahead: int, size: int) -> range:
    """
    Return the indices of the samples fitted for interval k (both of its ends included).

    Up to ``look_ahead`` samples after its closing frame, back to ``size`` in all, none across
    a break or a step longer than ``max_gap`` (s): the kernel's (``toi._kernel.c2_window``).
    """
    return _kernel.c2_window(stream.times, stream.breaks, k, max_gap, look_ahead, size)


def widened(stream: Stream, window: range) -> range:
    """
    Return a window reaching ``NOISE_SPAN`` back from its newest sample, in its segment.

    At most ``MAX_WINDOW`` samples (the kernel's ``toi._kernel.reach_back``).
    """
    return range(_kernel.reach_back(stream.times, stream.breaks, window.start, window.stop,
                                    math.inf, NOISE_SPAN, MAX_WINDOW), window.stop)


def kept_history(config: Any) -> float:
    """
    Return how far (s) behind the detector's cursor every stream keeps its samples.

    The scheduler's and the chunk path's trim (``1.5 max(velocity_window, prediction_window)``,
    plus a few samples): a fit reaching no further back sees the same samples in the node and
    in ``analyze`` whenever it is made.
    """
    return 1.5 * max(config.velocity_window, config.prediction_window)


def flight_window(stream: Stream, last: int, max_gap: float, span: float) -> range:
    """
    Return the samples up to ``last`` within ``span`` s of it, in its segment, no long gap.

    No step longer than ``max_gap`` (s); the kernel's ``toi._kernel.reach_back``.
    """
    return range(_kernel.reach_back(stream.times, stream.breaks, last, last + 1, max_gap, span,
                                    last + 2), last + 1)


def ball_flight(stream: Stream, k: int, window: range, noise: float,
                config: Any) -> Optional[FlightFit]:
    """
    Return the ball's flight fit for interval k (``FLIGHT``), or None for the smoother.

    None without noise or a config, when ``FLIGHT`` is None, with too few samples, or when the
    residuals fail the chi-square guard (the ball not in free flight: held, bounced, deflected)
    for each window tried (``FLIGHT``'s end).

    :param window: the interval's ``c2_window`` (its newest sample ends a ``'closing'`` fit).
    """
    found = _ball_flight(stream, k, window, noise, config)
    return None if found is None else found[0]


def _ball_flight(stream: Stream, k: int, window: range, noise: float,
                 config: Any) -> Optional[Tuple[FlightFit, List[Any]]]:
    """Return ``ball_flight``'s fit and the samples it fitted, or None."""
    if FLIGHT is None or config is None or not noise > 0.0:
        return None
    degree, span, end = FLIGHT
    span = min(span, kept_history(config))
    tolerance = AUTO_NOISE_TOLERANCE if config.tracker_noise < 0.0 else 1.0
    for last in ((window.stop - 1, k) if end == 'closing' else (k,)):
        found = flight_window(stream, last, config.max_gap, span)
        times = stream.times[found.start:found.stop]
        values = stream.values[found.start:found.stop]
        fit = _kept(('flight', noise, degree, FLIGHT_MIN_SAMPLES, tolerance, tuple(times)),
                    values, lambda: flight_or_none(
                        times, values, noise, degree, FLIGHT_MIN_SAMPLES, tolerance))
        if fit is not None:
            return fit, values
    return None


def _kept(key: Tuple[Any, ...], samples: List[Any], fit: Callable[[], Any]) -> Any:
    """
    Return ``fit()`` for a window's samples, kept: a window fitted again gets the same object.

    An impact fits its windows again under noise (its velocities, then its uncertainty's
    gains and its re-solve without look-ahead: ``uncertainty``), each fit a smoother or a
    least-squares solve. A fit reads only its stamps and samples (never changed once taken:
    ``Stream``) and the settings in ``key``, so the answer is kept by the stamps (in ``key``)
    and the samples' identities; the entry holds the samples, so no other object can take
    their ids while it is kept (at most ``_FITS_KEPT`` entries, then it starts again).

    :param key: what else the fit depends on (noise, settings), and the stamps (s).
    """
    key = (*key, *map(id, samples))
    found = _FITS.get(key)
    if found is None:
        if len(_FITS) >= _FITS_KEPT:
            _FITS.clear()
        found = _FITS[key] = (samples, fit())
    return found[1]


_FITS: dict = {}
"""``_kept``'s answers: key -> (the samples, the fit)."""

_FITS_KEPT = 64
"""Most fits ``_FITS`` holds."""


def c2_point_path(stream: Stream, k: int, window: range, noise: float = 0.0,
                  config: Any = None) -> PointPath:
    """
    Return the ball's ``c2`` path over interval k: its window spline's piece (smoothed).

    Exact, the quintic spline's piece where ``quintic_window`` takes the window, else the
    cubic's (as the bat's: ``motion.c2``).

    With noise and a ``config`` (its ``max_gap`` and trim history), the flight fit instead where
    ``ball_flight`` finds one (``flight_point_path``).
    """
    fit = ball_flight(stream, k, window, noise, config)
    if fit is not None:
        return flight_point_path(stream, k, fit)
    if noise > 0.0:
        window = widened(stream, window)
    times = stream.times[window.start:window.stop]
    j = k - window.start
    if noise > 0.0:
        values, slopes = smooth(times, np.asarray(stream.values[window.start:window.stop]),
                                [noise * noise] * 3, *SMOOTHER, start=j)
        (v0, v1), (s0, s1) = values[j:j + 2].tolist(), slopes[:2].tolist()  # (floats at once)
        return PointPath(times[j], times[j + 1], tuple(v0), tuple(v1), tuple(s0), tuple(s1))
    values = stream.values[window.start:window.stop]
    if quintic_window(times, j):
        slopes, bends = not_a_knot_quintic_rows(times, values, j)
        return PointPath(times[j], times[j + 1], stream.values[k], stream.values[k + 1],
                         slopes[0], slopes[1], bends[0], bends[1])
    slopes = not_a_knot_slope_rows(times, values, j)
    return PointPath(times[j], times[j + 1], stream.values[k], stream.values[k + 1], slopes[0],
                     slopes[1])


def flight_point_path(stream: Stream, k: int, fit: FlightFit) -> PointPath:
    """Return the ball's path over interval k on its flight fit (``ball_flight``'s)."""
    t0, t1 = stream.times[k], stream.times[k + 1]
    (p0, v0), (p1, v1) = fit.state(t0), fit.state(t1)
    return PointPath(t0, t1, p0, p1, v0, v1)


def bat_variances(sample: BatSample, noise: float) -> List[float]:
    """
    Return the noise variance of each of a bat sample's ``c2_rows`` columns.

    Knob (m^2), rotation vector (rad^2: the direction's noise across the bat, split over the
    axes by how far each is from the bat), length (m^2). A pose's knob also moves with its
    orientation's noise (``noise / MARKER_SPREAD_M`` rad per axis) by its offset o from the
    pose's origin: ``across * (|o|^2 - o_e^2)`` more on axis e (none with the origin at the knob).
    """
    axis = unit_axis(sample)
    if sample.quaternion is None:
        length = math.dist(sample.tip, sample.knob)
        across, along = 2.0 * (noise / length) ** 2, 2.0 * noise * noise
        knob = [noise * noise] * 3
    else:
        across, along = (noise / MARKER_SPREAD_M) ** 2, 0.0
        offset = sub(sample.knob, sample.position)
        reach = dot(offset, offset)
        knob = [noise * noise + across * (reach - o * o) for o in offset]
    return knob + [across * (1.0 - a * a) for a in axis] + [along]


def _recharted(reference: Vector, origin: Vector, turn: Sequence[float],
               rate: Sequence[float]) -> Tuple[Vector, Vector]:
    """
    Return a rotation vector and its rate (rad, rad/s) moved from one chart to another.

    :param reference: the old chart's origin direction, in which ``turn`` and ``rate`` are;
        ``origin``: the new chart's. The rate by central differences ``_STEP`` rad along it
        (the kernel's ``toi._kernel.recharted``).
    """
    return _kernel.recharted(reference, origin, turn, rate, _STEP)


def smoothed_bat_path(times: Sequence[float], samples: Sequence[BatSample], k: int,
                      noise: float) -> C2BatPath:
    """
    Return the bat's ``c2`` path over [times[k], times[k + 1]] through smoothed samples.

    :param times, samples: the window (s, bat samples); k: the interval in it; ``noise``: m.
    """
    first, rows = c2_rows(samples, k)
    window = times[first:first + len(rows)]
    variances = bat_variances(samples[k], noise)
    fitted, slopes = smooth(window, np.asarray(rows, dtype=float), variances, *SMOOTHER,
                            penalty_eigen(window, SMOOTHER[0]), BAT_GROUPS, k - first)
    reference = unit_axis(samples[k])
    # the interval's two rows and the slopes at its knots (its own two first), read as Python
    # floats once (the same numbers: numpy's small reads cost more inside the detector's loop)
    rows0, rows1 = fitted[k - first:k + 2 - first].tolist()
    s0, s1 = slopes[:2].tolist()
    ends = []
    for i, row in ((k - first, rows0), (k + 1 - first, rows1)):
        knob = tuple(row[:3])
        direction = rotate(reference, tuple(row[3:6]))
        length = row[6]
        tip = tuple(p + length * d for p, d in zip(knob, direction))
        original = samples[first + i]
        ends.append(BatSample(knob, tip, original.position, original.quaternion))
    origin = unit_axis(ends[0])
    turns = [_recharted(reference, origin, row[3:6], slope[3:6])[1]
             for row, slope in ((rows0, s0), (rows1, s1))]
    return C2BatPath(times[k], times[k + 1], ends[0], ends[1], (tuple(s0[:3]), tuple(s1[:3])),
                     (turns[0], turns[1]), (s0[6], s1[6]))


def c2_bat_path(stream: Stream, k: int, window: range, noise: float = 0.0,
                continued: bool = False) -> C2BatPath:
    """
    Return the bat's ``c2`` path over interval k: knob, direction and length splines.

    :param continued: exact, the window's last piece may be quintic (``C2BatPath.fitted``):
        interval k ends the window (``Sweep.paths``), or the path is continued past its end.
    """
    if noise > 0.0:
        window = widened(stream, window)
    times = stream.times[window.start:window.stop]
    samples = stream.values[window.start:window.stop]
    if noise > 0.0:  # (kept: ``_kept``)
        j = k - window.start
        return _kept(('bat', noise, j, SMOOTHER, MARKER_SPREAD_M, tuple(times)), samples,
                     lambda: smoothed_bat_path(times, samples, j, noise))
    return C2BatPath.fitted(times, samples, k - window.start, continued)


def c2_bat_ahead(stream: Stream, k: int, max_gap: float, size: int,
                 noise: float = 0.0, quintic: bool = False) -> Optional[C2BatPath]:
    """
    Return the bat's ``c2`` path over interval k continued from before it, or None.

    The window spline of interval k - 1 (no look-ahead: up to interval k's opening frame), its
    last piece continued to interval k's closing stamp: where the bat would have gone had
    nothing slowed it, for an interval whose closing frame is after a hit (the bat brakes in
    the 1-3 ms after it). Exact, that piece is the quintic spline's where its window takes one
    (``splines.quintic_window``, continued). The chart is moved onto interval k's opening
    direction, as its own path's. None without two samples before k in its segment. With
    ``noise`` (m, 1 sigma per coordinate) the window is smoothed (``c2_bat_path``) and the path
    starts on it, not on the opening sample. ``quintic``: None too where the continued piece is
    not a quintic.
    """
    continued = c2_bat_continued(stream, k, max_gap, size, noise, quintic)
    if continued is None:
        return None
    before, at = continued
    t0, t1 = stream.times[k], stream.times[k + 1]
    length = before.length
    opening = at(t0) if noise > 0.0 else stream.values[k]
    origin = unit_axis(opening)
    turn0, turn1 = (_recharted(before.reference, origin, before.turn.at(t),
                               before.turn.velocity(t))[1] for t in (t0, t1))
    return C2BatPath(t0, t1, opening, at(t1),
                     (before.knob.velocity(t0), before.knob.velocity(t1)), (turn0, turn1),
                     (length.velocity(t0), length.velocity(t1)))


def c2_bat_continued(stream: Stream, k: int, max_gap: float, size: int, noise: float = 0.0,
                     quintic: bool = False
                     ) -> Optional[Tuple[C2BatPath, Callable[[float], BatSample]]]:
    """
    Return the window spline of bat interval k - 1 and the bat on it continued, or None.

    The window up to sample k (no look-ahead; ``c2_bat_path``, smoothed with ``noise``), its
    last piece continued: a function of t (s) giving the knob and the tip (m) there (the
    direction's rotation vector and the length continued with it). None without two samples
    before k in its segment, or with ``quintic`` where the continued piece is not a quintic.
    (``c2_bat_ahead``'s path over interval k; ``bat_glitches.departure`` at one stamp.)
    """
    window = c2_window(stream, k - 1, max_gap, 0, size)
    if k < 2 or window.start > k - 2 or window.stop - 1 != k:
        return None
    before = c2_bat_path(stream, k - 1, window, noise, True)  # in sample k - 1's chart
    if quintic and before.knob.e is None:
        return None
    length = before.length

    def at(t: float) -> BatSample:  # the continued bat at t (s)
        knob = before.knob.at(t)
        direction = rotate(before.reference, before.turn.at(t))
        return BatSample(knob, tuple(x + length.at(t) * u for x, u in zip(knob, direction)))

    return before, at


def chart_swing(reference: Vector, turn: Sequence[float], rate: Sequence[float]) -> Vector:
    """
    Return the swing angular velocity u x u' (rad/s) of a direction chart's rotation vector.

    u = ``rotate(reference, turn)``; u' by central differences ``_STEP`` rad along the rate
    (the map's curvature makes their error about 1e-9 of the rate).

    :param reference: the chart's origin direction (unit); ``turn``: the rotation vector
        (rad) turning it onto the bat's direction u; ``rate``: its rate (rad/s).
    """
    turn, rate = np.asarray(turn, dtype=float), np.asarray(rate, dtype=float)
    speed = float(np.linalg.norm(rate))
    direction = rotate(reference, tuple(turn.tolist()))
    if speed == 0.0:
        return (0.0, 0.0, 0.0)
    step = _STEP / speed
    ahead = np.array(rotate(reference, tuple((turn + step * rate).tolist())))
    behind = np.array(rotate(reference, tuple((turn - step * rate).tolist())))
    return cross(direction, tuple(((ahead - behind) / (2.0 * step)).tolist()))


def swing_rate(path: C2BatPath, t: float) -> Vector:
    """Return the swing angular velocity (rad/s) of a ``c2`` bat path at t (s): u x u'."""
    return chart_swing(path.reference, path.turn.at(t), path.turn.velocity(t))


def piece_weights(times: Sequence[float], j: int, t: float) -> np.ndarray:
    """
    Return the weights (2, n) of a window's samples in its spline's value and rate at t (s).

    The spline is the not-a-knot interpolant through the n samples, evaluated on its piece j
    (t in [times[j], times[j + 1]]): value = ``weights[0] @ values``, rate (per s) =
    ``weights[1] @ values``; both linear. Through smoothed values ``A @ values``, they are
    ``weights @ A``.
    """
    n = len(times)
    # (each unit sample's slopes at knots j and j + 1: the kernel's back-substitution stops
    # there, the same numbers as the whole solve's)
    slopes = np.array(not_a_knot_slope_rows(times, np.eye(n), j)[:2])
    h = times[j + 1] - times[j]
    s = (t - times[j]) / h
    weights = np.zeros((2, n))
    weights[0, j], weights[0, j + 1] = 2 * s ** 3 - 3 * s ** 2 + 1, 3 * s ** 2 - 2 * s ** 3
    weights[0] += h * ((s ** 3 - 2 * s ** 2 + s) * slopes[0] + (s ** 3 - s ** 2) * slopes[1])
    weights[1, j], weights[1, j + 1] = (6 * s ** 2 - 6 * s) / h, (6 * s - 6 * s ** 2) / h
    weights[1] += (3 * s ** 2 - 4 * s + 1) * slopes[0] + (3 * s ** 2 - 2 * s) * slopes[1]
    return weights


def quintic_piece_weights(times: Sequence[float], j: int, t: float) -> np.ndarray:
    """
    Return the weights (n,) of a window's samples in its quintic spline's value at t (s).

    The not-a-knot quintic interpolant through the n >= 6 samples (``splines``' de Boor
    spline, the exact windows' ``C2BatPath.fitted``), evaluated on its piece j (t in
    [times[j], times[j + 1]]): the piece's quintic Hermite (``points.quintic_coefficients``,
    linear in its ends, so it takes the weight rows as they are) of its ends' values, slopes
    and second derivatives. value = ``weights @ values``.
    """
    n = len(times)
    slopes, bends = (np.array(rows) for rows in not_a_knot_quintic_rows(times, np.eye(n), j))
    h = times[j + 1] - times[j]
    s = (t - times[j]) / h
    start, end = np.eye(n)[j], np.eye(n)[j + 1]
    b, c = h * slopes[0], 0.5 * h * h * bends[0]
    d, e, f = quintic_coefficients(end - start, b, c, h * slopes[1], h * h * bends[1])
    return start + s * (b + s * (c + s * (d + s * (e + s * f))))


def point_gains(stream: Stream, window: range, k: int, t: float, noise: float,
                config: Any = None) -> Tuple[float, float]:
    """
    Return the root sum of squares of the samples' weights in a ``c2`` point's value and rate.

    Times the noise (m, per coordinate) they are the 1-sigma errors its noise makes in each
    coordinate of the ball's position (m) and velocity (m/s) at t (s) on interval k. A flight
    fit's (``ball_flight``, as ``c2_point_path`` takes it) are scaled by its residuals' excess
    over the noise (``FlightFit.excess``), so a misfit the guard lets through widens them.
    """
    fit = ball_flight(stream, k, window, noise, config)
    if fit is not None:
        value, rate = fit.weights(t)
        return (fit.excess * float(np.linalg.norm(value)),
                fit.excess * float(np.linalg.norm(rate)))
    if noise > 0.0:
        window = widened(stream, window)
    times = [stream.times[i] for i in window]
    weights = piece_weights(times, k - window.start, t)
    if noise > 0.0:
        values = np.asarray(stream.values[window.start:window.stop], dtype=float)
        value, rate = smoother_norms(times, weights, values, [noise * noise] * 3, *SMOOTHER)[0]
    else:
        value, rate = np.linalg.norm(weights, axis=1)
    return float(value), float(rate)


def _bat_rows(stream: Stream, window: range, k: int, t: float,
              noise: float) -> Tuple[List[float], np.ndarray, List[float], np.ndarray, np.ndarray,
                                     int]:
    """
    Return what a ``c2`` bat's gains at t (s) on interval k are taken from.

    (times (s), chart rows (n, 7), their noise variances, the per-group sigmas (knob m,
    direction across the bat rad, length m), the interpolant's value and rate weights (2, n),
    the interval's piece in the window).
    """
    if noise > 0.0:
        window = widened(stream, window)
    samples = stream.values[window.start:window.stop]
    j = k - window.start
    first, rows = c2_rows(samples, j)
    times = [stream.times[i] for i in window][first:first + len(rows)]
    variances = bat_variances(samples[j], noise)
    sigmas = np.array((noise, math.sqrt(variances[3] + variances[4] + variances[5])
                       / math.sqrt(2.0), math.sqrt(variances[6])))
    return (times, np.asarray(rows, dtype=float), variances, sigmas,
            piece_weights(times, j - first, t), j - first)


def _correlation(knob: np.ndarray, direction: np.ndarray) -> float:
    """Return (a . b) / (|a| |b|) of two weight rows (0 when either is zero)."""
    scale = float(np.linalg.norm(knob) * np.linalg.norm(direction))
    return float(knob @ direction) / scale if scale > 0.0 else 0.0


def point_shifts(stream: Stream, window: range, k: int, t: float, noise: float,
                 config: Any = None) -> Tuple[np.ndarray, float]:
    """
    Return how far a ``c2`` point's fit is from the next richer one at t, and the noise in it.

    :returns: (shift (3,) m, spread m per coordinate): where its path (``point_gains``') takes
        a flight fit, the flight fit of one degree more on the same samples less it (none when
        that fit is rank deficient); where it takes the smoother, the smoothed window's value
        less the interpolant's (``smoothing.smoother_shifts``); and the 1-sigma spread the
        noise alone gives that difference (the flight fit's scaled by its residuals' excess, as
        its gains are). Zero without noise.
    """
    if not noise > 0.0:
        return np.zeros(3), 0.0
    found = _ball_flight(stream, k, window, noise, config)
    if found is not None:
        fit, values = found
        try:
            richer = fit_flight(fit.times, values, noise, fit.degree + 1)
        except ValueError:
            return np.zeros(3), 0.0
        moved = np.subtract(richer.at(t), fit.at(t))
        return moved, fit.excess * noise * float(np.linalg.norm(richer.weights(t)[0]
                                                                - fit.weights(t)[0]))
    window = widened(stream, window)
    times = [stream.times[i] for i in window]
    values = np.asarray(stream.values[window.start:window.stop], dtype=float)
    shifts, deviations = smoother_shifts(times, piece_weights(times, k - window.start, t)[:1],
                                         values, [noise * noise] * 3, *SMOOTHER)
    return shifts[0, 0], noise * float(np.linalg.norm(deviations[0, 0]))


BatErrors = Tuple[np.ndarray, np.ndarray, float]
"""``bat_gains``' and ``bat_shifts``' answers: two per-group arrays and a correlation."""


def bat_gains(stream: Stream, window: range, k: int, t: float, noise: float) -> BatErrors:
    """
    Return the 1-sigma errors the noise makes in a ``c2`` bat's knob, direction and length.

    :returns: (value errors, rate errors, correlation): the errors (knob per coordinate in m,
        direction across the bat in rad, length in m; per second for the rates) at t (s) on
        interval k, and the correlation of the knob's smoother row for the value with the
        direction's, (a_knob . a_direction) / (|a_knob| |a_direction|): the samples' noise
        reaches both through them (from knob and tip points, a knob marker's noise moves the
        knob and turns the direction: ``uncertainty.propagated`` takes it).
    """
    return _bat_gains(_bat_rows(stream, window, k, t, noise), noise)


def bat_shifts(stream: Stream, window: range, k: int, t: float, noise: float) -> BatErrors:
    """
    Return how far the smoothing moves a ``c2`` bat from its interpolant at t, and its noise.

    The interpolant is the quintic spline where the window takes one (``quintic_window``,
    continued; ``quintic_piece_weights``: the exact samples' own fit, whose end error is far
    below the cubic's; the smoothed path is a cubic spline, and a cubic interpolant would
    share its end error), else the cubic.

    :returns: (shifts, spreads, correlation): the smoothed window's value at t (s) on interval
        k less the interpolant's (``smoothing.smoother_shifts``; (7,): the knob's m, the
        rotation vector's rad in the chart of ``c2_rows``, the length's m), the 1-sigma
        spread the noise alone gives that difference (knob per coordinate in m, direction
        across the bat in rad, length in m) and the correlation of its knob and direction
        rows (as ``bat_gains``'). All zero without noise.
    """
    if not noise > 0.0:
        return np.zeros(7), np.zeros(3), 0.0
    return _bat_shifts(_bat_rows(stream, window, k, t, noise), t)


def bat_errors(stream: Stream, window: range, k: int, t: float,
               noise: float) -> Tuple[BatErrors, BatErrors]:
    """
    Return ``bat_gains`` and ``bat_shifts`` of one window at t (s) at once, the same to the bit.

    The window's rows are gathered, and its groups' smoothing weights searched, once for both.
    """
    if not noise > 0.0:
        return bat_gains(stream, window, k, t, noise), bat_shifts(stream, window, k, t, noise)
    rows = _bat_rows(stream, window, k, t, noise)
    times, values, variances = rows[:3]
    weights = smoother_weights(times, values, variances, *SMOOTHER, groups=BAT_GROUPS)
    return _bat_gains(rows, noise, weights), _bat_shifts(rows, t, weights)


def _bat_gains(rows: Tuple[Any, ...], noise: float,
               weights: Optional[List[float]] = None) -> BatErrors:
    """Return ``bat_gains`` from a window's ``_bat_rows`` (its groups' weights, when known)."""
    times, values, variances, sigmas, piece, _ = rows
    if noise > 0.0:
        through = smoother_rows(times, piece, values, variances, *SMOOTHER, groups=BAT_GROUPS,
                                weights=weights)
    else:
        through = np.array([piece] * len(BAT_GROUPS))
    norms = np.linalg.norm(through, axis=2)
    correlation = _correlation(through[0, 0], through[1, 0])
    return sigmas * norms[:, 0], sigmas * norms[:, 1], correlation


def _bat_shifts(rows: Tuple[Any, ...], t: float,
                weights: Optional[List[float]] = None) -> BatErrors:
    """Return a noisy window's ``bat_shifts`` at t (s) from its ``_bat_rows`` (and weights)."""
    times, values, variances, sigmas, piece, j = rows
    reference = (quintic_piece_weights(times, j, t)[None, :]
                 if quintic_window(times, j, True) else None)
    shifts, deviations = smoother_shifts(times, piece[:1], values, variances, *SMOOTHER,
                                         groups=BAT_GROUPS, reference=reference,
                                         weights=weights)
    moved = np.concatenate([shifts[g, 0, group] for g, group in enumerate(BAT_GROUPS)])
    norms = np.linalg.norm(deviations, axis=2)
    return moved, sigmas * norms[:, 0], _correlation(deviations[0, 0], deviations[1, 0])
