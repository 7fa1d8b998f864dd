"""
The cheap far test: ball and bat clearly apart over a union interval, from the raw samples.

Most intervals of a session have the ball metres from the bat. This decides them without
building a path: each body's path lies in a sphere around its chord's middle (and within the
hull of its end samples, for the finer bound ``hull_separation``), grown by a bound
on how far the motion model lets it bulge (none for chords; for a rigid turn, the sagitta is
at most half the chord of the rotating part; for the spline, ``bulge_bounds``; for ``c2``,
first ``c2_jump_bulge`` and ``c2_reach`` from numbers kept per sample, then ``c2_bulge`` and
``c2_bat_growth`` over the interval's window).
"""

import math
from operator import mul
from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np

from .fitting import c2_window
from .streams import Stream
from ..geometry import norm, sub, Vector
from ..motion import BatSample, c2_rows, unit_axis

Pick = Callable[[object], Vector]
"""Picks the point followed from a sample value (the ball itself, the knob, the axis)."""


def _same(point: Vector) -> Vector:
    return point


def _knob_of(sample: BatSample) -> Vector:
    return sample.knob


def _axis_of(sample: BatSample) -> Vector:
    return sub(sample.tip, sample.knob)


C2_WEIGHTS_BEFORE = (4.8, 2.5, 0.67, 0.18, 0.048, 0.013, 0.0034, 0.0009, 0.0002)
"""Bounds of |l_i - chord| over interval k of the window spline's cardinal function l_i, for
samples i = k - 1, k - 2, ... (then 0.0001 each): measured over windows of 2-16 samples with
steps within a factor 4 of each other (test/core/detector/test_broadphase_c2.py re-measures)."""

C2_WEIGHTS_AFTER = (3.4, 1.1)
"""The same for samples k + 2 and k + 3 (look-ahead 1 and 2)."""

C2_SAFETY = 1.25
"""Factor on the weights."""

C2_STEP_RATIO = 4.0
"""Windows whose longest step is more than this times the shortest get no far test."""


_FAR_OFFSET = 40
_WEIGHT_LIST = [C2_SAFETY * (C2_WEIGHTS_BEFORE[-o - 1] if -len(C2_WEIGHTS_BEFORE) <= o < 0
                             else 0.0001 if o < 0 else 0.0 if o < 2 else C2_WEIGHTS_AFTER[o - 2])
                for o in range(-_FAR_OFFSET, 2 + len(C2_WEIGHTS_AFTER))]
"""``C2_SAFETY`` times the cardinal weight of the sample at offset o, at o + ``_FAR_OFFSET``
(a window holds at most 32 + 2 samples)."""


def c2_bulge(times: Sequence[float], points: Sequence[Vector], j: int) -> float:
    """
    Bound (m) how far the ``c2`` spline through (times, points) leaves its chord over interval j.

    The spline is linear in its samples and reproduces lines, so it leaves the chord by at
    most sum_i |r_i| w_i: r_i each sample's distance from the chord's line extended, w_i the
    cardinal bound by its distance from the interval (``C2_WEIGHTS_*``), times
    ``C2_SAFETY``. Valid for steps within ``C2_STEP_RATIO`` of each other (the caller checks).
    """
    t0, h = times[j], times[j + 1] - times[j]
    (x0, y0, z0), p1 = points[j], points[j + 1]
    vx, vy, vz = (p1[0] - x0) / h, (p1[1] - y0) / h, (p1[2] - z0) / h
    bound = 0.0
    weights = _WEIGHT_LIST[_FAR_OFFSET - j:_FAR_OFFSET - j + len(times)]
    for weight, t, p in zip(weights, times, points):
        if weight:
            dt = t - t0
            dx, dy, dz = p[0] - x0 - vx * dt, p[1] - y0 - vy * dt, p[2] - z0 - vz * dt
            bound += weight * math.sqrt(dx * dx + dy * dy + dz * dz)
    return bound


def _scalar_bulge(times: Sequence[float], values: Sequence[float], j: int) -> float:
    """``c2_bulge`` of one number per sample."""
    t0, v0 = times[j], values[j]
    rate = (values[j + 1] - v0) / (times[j + 1] - t0)
    weights = _WEIGHT_LIST[_FAR_OFFSET - j:_FAR_OFFSET - j + len(times)]
    return sum(weight * abs(v - v0 - rate * (t - t0))
               for weight, t, v in zip(weights, times, values) if weight)


def _jump_coefficients() -> Tuple[float, ...]:
    """Return c_a = sum over o > a of W(o) (o - a): W(o) the safe weight o samples before."""
    weights = _WEIGHT_LIST[_FAR_OFFSET - 1::-1]  # W(1), W(2), ... W(_FAR_OFFSET)
    return tuple(sum(weight * (o - a) for o, weight in enumerate(weights, 1) if o > a)
                 for a in range(_FAR_OFFSET))


C2_JUMP_BEFORE = _jump_coefficients()
"""Coefficient of the chord-velocity jump at sample k - a in ``c2_jump_bulge`` (a = 0, 1, ...)."""

_AFTER_ONE, _AFTER_TWO = (C2_SAFETY * weight for weight in C2_WEIGHTS_AFTER)


def _fill_jumps(stream: Stream, last: int, reach: int) -> List[float]:
    """
    Fill the stream's per-sample steps and chord-velocity jumps up to sample ``last``.

    Kept in ``stream.aligned`` (each computed once): ``steps[m]`` = times[m] - times[m - 1]
    (s), ``jumps[m]`` = |v_m+1 - v_m| (m/s) with v_m = (p_m - p_m-1) / steps[m] the chord
    velocity into sample m of the ball, or for the bat that of its knob plus the same of its
    knob-to-tip length (both bulges at once: they are added up in ``c2_reach``); up to
    ``last`` (jumps: ``last`` - 1); index 0 holds 0 (never used); samples more than ``reach``
    before ``last`` not yet filled hold NaN (the window that reads them has not come yet, and
    no later window reaches them: a run the chunk path fast-forwarded).

    :returns: the jumps.
    """
    aligned = stream.aligned
    if 'steps' not in aligned:
        aligned['steps'], aligned['jumps'] = [], []
    steps, jumps = aligned['steps'], aligned['jumps']
    times, values = stream.times, stream.values
    skip = last - reach
    if len(steps) < skip:
        steps += [math.nan] * (skip - len(steps))
    if len(jumps) < skip:
        jumps += [math.nan] * (skip - len(jumps))
    for m in range(len(steps), last + 1):
        steps.append(times[m] - times[m - 1] if m else 0.0)
    bat = values[0].__class__ is BatSample
    for m in range(len(jumps), last):
        if m == 0:
            jumps.append(0.0)
            continue
        h0, h1 = steps[m], steps[m + 1]
        a, b, c = values[m - 1], values[m], values[m + 1]
        stretch = 0.0
        if bat:
            la, lb, lc = (math.dist(a.tip, a.knob), math.dist(b.tip, b.knob),
                          math.dist(c.tip, c.knob))
            stretch = abs((lc - lb) / h1 - (lb - la) / h0)
            a, b, c = a.knob, b.knob, c.knob
        jumps.append(stretch + math.sqrt(((c[0] - b[0]) / h1 - (b[0] - a[0]) / h0) ** 2
                                         + ((c[1] - b[1]) / h1 - (b[1] - a[1]) / h0) ** 2
                                         + ((c[2] - b[2]) / h1 - (b[2] - a[2]) / h0) ** 2))
    return jumps


def c2_jump_bulge(stream: Stream, k: int, look_ahead: int, size: int,
                  max_gap: float) -> Optional[float]:
    """
    Bound (m) how far the ``c2`` spline over interval k leaves its chord, from kept numbers.

    Of the ball; of the bat, its knob's bulge plus its length's (``_fill_jumps``). Never
    below ``c2_bulge``'s bound: a sample i before k is off the chord's line by
    r_i = sum over m = i..k-1 of (v_k - v_m) h_m, so |r_i| <= H sum over p = i..k-1 of
    (p - i + 1) J_p+1 (H the longest step, J_m = |v_m+1 - v_m| the chord-velocity jump at
    sample m); after k + 1, |r_k+2| <= H J_k+1 and |r_k+3| <= H (2 J_k+1 + J_k+2). With the
    weights, the bound is H (sum over a of ``C2_JUMP_BEFORE[a]`` J_k-a + the look-ahead
    terms): numbers kept per sample instead of a pass over the window per interval. Taken
    over the samples a full window could hold (``size`` up to k + 1 + ``look_ahead``): never
    fewer than ``c2_window``'s, so never a smaller bound; where their steps are uneven (a
    segment's start within them), over ``c2_window``'s own.

    :returns: the bound (m), or None: the window's steps are not within ``C2_STEP_RATIO`` of
        each other (no bound).
    """
    first = k + 2 - size
    if first < 0:
        first = 0
    last = k + 1 + look_ahead
    if last >= len(stream.times):
        last = len(stream.times) - 1
    jumps = stream.aligned.get('jumps')
    if jumps is None or len(jumps) < last:
        jumps = _fill_jumps(stream, last, size + look_ahead + 1)
    steps = stream.aligned['steps']
    inside = steps[first + 1:last + 1]
    longest = max(inside)
    if longest > C2_STEP_RATIO * min(inside):
        window = c2_window(stream, k, max_gap, look_ahead, size)
        first, last = window.start, window.stop - 1
        inside = steps[first + 1:last + 1]
        longest = max(inside)
        if longest > C2_STEP_RATIO * min(inside):
            return None
    bound = sum(map(mul, C2_JUMP_BEFORE, jumps[k:first:-1]))
    if last > k + 1:
        bound += _AFTER_ONE * jumps[k + 1]
        if last > k + 2:
            bound += _AFTER_TWO * (2.0 * jumps[k + 1] + jumps[k + 2])
    return longest * bound


def c2_reach(stream: Stream, k: int, look_ahead: int, size: int,
             max_gap: float) -> Optional[Tuple[Vector, float]]:
    """
    Return a sphere (centre, radius in m) holding the whole ``c2`` bat over interval k.

    Cheap (no chart, no window): the knob's spline stays within its bulge B_k of its chord
    and every axis point within the length L(t) <= max(L_k, L_k+1) + B_L of the knob, so the
    sphere about the knob chord's middle of radius |chord| / 2 + B_k + max L + B_L holds the
    bat (B_k + B_L: ``c2_jump_bulge``). None: no bound (uneven steps).
    """
    bulge = c2_jump_bulge(stream, k, look_ahead, size, max_gap)
    if bulge is None:
        return None
    s0, s1 = stream.values[k], stream.values[k + 1]
    k0, k1 = s0.knob, s1.knob
    centre = ((k0[0] + k1[0]) * 0.5, (k0[1] + k1[1]) * 0.5, (k0[2] + k1[2]) * 0.5)
    return centre, (0.5 * math.dist(k0, k1) + bulge
                    + max(math.dist(s0.tip, k0), math.dist(s1.tip, k1)))


def c2_bat_growth(stream: Stream, k: int, window: range) -> Optional[float]:
    """
    Bound (m) how far any axis point of the ``c2`` bat leaves its chord over interval k.

    With the bulges B_k, B_r, B_L of the knob's, the rotation vector's (``c2_rows``) and the
    length's splines, the angle theta between the end directions and the longer end length
    L: the direction (the rotation vector's exponential map, 1-Lipschitz) stays within B_r of
    the great-circle arc, itself within 1 - cos(theta / 2) of the chord, so any axis point
    within B_k + B_L + (L + B_L) (1 - cos(theta / 2) + B_r) + |dL| |du| / 4. None: no bound
    (uneven steps).
    """
    times = stream.times[window.start:window.stop]
    samples = stream.values[window.start:window.stop]
    j = k - window.start
    first, rows = c2_rows(samples, j)
    times = times[first:first + len(rows)]
    if max(b - a for a, b in zip(times, times[1:])) > C2_STEP_RATIO * min(
            b - a for a, b in zip(times, times[1:])):
        return None
    i = j - first
    knob = c2_bulge(times, [row[0:3] for row in rows], i)
    turn = c2_bulge(times, [row[3:6] for row in rows], i)
    stretch = _scalar_bulge(times, [row[6] for row in rows], i)
    half_cos = math.cos(0.5 * norm(rows[i + 1][3:6]))
    length0, length1 = rows[i][6], rows[i + 1][6]
    return (knob + stretch + (max(length0, length1) + stretch) * (1.0 - half_cos + turn)
            + 0.25 * abs(length1 - length0) * math.dist(unit_axis(samples[j]),
                                                        unit_axis(samples[j + 1])))


def bulge_bounds(stream: Stream, k: int, picks: Sequence[Pick], max_gap: float) -> List[float]:
    """
    Bound (m) how far each picked point's spline over sample interval k leaves its chord.

    With tangents from the three-point rule, p(s) - chord(s) = c (s^2 - s) + d (s^3 - s)
    and |c| / 4 + 0.385 |d| <= 3.04 |D| + 0.885 (h / h_prev) |D_prev| +
    0.635 (h / h_next) |D_next|, D the chords; no path needs to be built for it.
    """
    times, values = stream.times, stream.values
    h = times[k + 1] - times[k]
    before, after = stream.neighbours(k, max_gap)
    weight_before = 0.885 * h / (times[k] - times[before]) if before is not None else 0.0
    weight_after = 0.635 * h / (times[after] - times[k + 1]) if after is not None else 0.0
    here, there = values[k], values[k + 1]
    bounds = []
    for pick in picks:
        bound = 3.04 * math.dist(pick(here), pick(there))
        if before is not None:
            bound += weight_before * math.dist(pick(values[before]), pick(here))
        if after is not None:
            bound += weight_after * math.dist(pick(there), pick(values[after]))
        bounds.append(bound)
    return bounds


def clearly_apart(ball: Stream, bat: Stream, ball_k: int, bat_k: int, margin: float,
                  model: str, max_gap: float, look_ahead: int = 0, size: int = 8) -> bool:
    """
    Return whether ball and bat stay more than ``margin`` (m) apart over both sample intervals.

    Two lower bounds on the distance between any point of the ball's path and any point of the
    bat's axis over the intervals: the bounding spheres' gap, then (``linear``, ``rigid``,
    ``spline``) the hulls' separation along one direction (:func:`hull_separation`).

    :param ball_k, bat_k: the streams' sample intervals (``Stream.interval``) in play.
    :param model: the motion model between samples.
    :param look_ahead, size: the ``c2`` model's look-ahead and window (samples).
    """
    b0, b1 = ball.values[ball_k], ball.values[ball_k + 1]
    s0, s1 = bat.values[bat_k], bat.values[bat_k + 1]
    k0, e0, k1, e1 = s0.knob, s0.tip, s1.knob, s1.tip
    ball_centre = ((b0[0] + b1[0]) * 0.5, (b0[1] + b1[1]) * 0.5, (b0[2] + b1[2]) * 0.5)
    ball_radius = 0.5 * math.dist(b0, b1)
    bat_centre = ((k0[0] + e0[0] + k1[0] + e1[0]) * 0.25,
                  (k0[1] + e0[1] + k1[1] + e1[1]) * 0.25,
                  (k0[2] + e0[2] + k1[2] + e1[2]) * 0.25)
    bat_radius = max(math.dist(k0, bat_centre), math.dist(e0, bat_centre),
                     math.dist(k1, bat_centre), math.dist(e1, bat_centre))
    # how far the paths leave the hulls of their end samples: the ball's of its chord, every
    # axis point of the bat's of the four points (where the chords of its ends are)
    ball_bulge = bat_growth = 0.0
    if model == 'rigid':
        turning = max(math.dist(k0, k1), math.dist(e0, e1))
        if s0.position is not None:
            reference = math.dist(s0.position, s1.position)
        else:
            # knob moves on its chord, the length changes linearly: both count in full
            reference = math.dist(k0, k1) + 2.0 * abs(math.dist(k0, e0) - math.dist(k1, e1))
        bat_growth = 0.5 * (turning + reference)
        bat_radius += bat_growth
    elif model == 'spline':
        # the knob's cubic, then the knob-to-tip vector r turning on an arc (at most
        # (pi / 4) |D r| from its chord) by an angle whose cubic overshoots uniform speed by at
        # most pi times r's own bulge bound (angle <= (pi / 2) chord / length), and the
        # length changing linearly
        ball_bulge = bulge_bounds(ball, ball_k, (_same,), max_gap)[0]
        knob_bulge, axis_bulge = bulge_bounds(bat, bat_k, (_knob_of, _axis_of), max_gap)
        turn, stretch = (0.25 * math.pi * math.dist(sub(e0, k0), sub(e1, k1)),
                         abs(math.dist(k0, e0) - math.dist(k1, e1)))
        bat_growth = knob_bulge + turn + math.pi * axis_bulge + stretch
        ball_radius += ball_bulge
        bat_radius += bat_growth
    elif model == 'c2':
        # first from numbers kept per sample (``c2_jump_bulge``), then the exact weights
        quick = c2_jump_bulge(ball, ball_k, look_ahead, size, max_gap)
        reach = None if quick is None else c2_reach(bat, bat_k, look_ahead, size, max_gap)
        if reach is not None and (math.dist(ball_centre, reach[0]) - ball_radius - quick
                                  - reach[1] > margin):
            return True
        window = c2_window(ball, ball_k, max_gap, look_ahead, size)
        times = ball.times[window.start:window.stop]
        steps = [b - a for a, b in zip(times, times[1:])]
        if max(steps) > C2_STEP_RATIO * min(steps):
            return False
        ball_radius += c2_bulge(times, ball.values[window.start:window.stop],
                                ball_k - window.start)
        growth = c2_bat_growth(bat, bat_k, c2_window(bat, bat_k, max_gap, look_ahead, size))
        if growth is None:
            return False
        bat_radius += growth
        return math.dist(ball_centre, bat_centre) - ball_radius - bat_radius > margin
    return (math.dist(ball_centre, bat_centre) - ball_radius - bat_radius > margin
            or hull_separation(b0, b1, k0, e0, k1, e1) - ball_bulge - bat_growth > margin)


def hull_separation(b0: Vector, b1: Vector, k0: Vector, e0: Vector, k1: Vector,
                    e1: Vector) -> float:
    """
    Return a lower bound (m) on the distance between the hulls of (b0, b1) and (k0, e0, k1, e1).

    For any unit vector n, every x in the first hull and y in the second are at least
    min(n.b) - max(n.p) apart (n.(x - y) <= |x - y|). Here n points from the closest point of
    the bat's middle segment (the knobs' middle to the tips' middle) to the ball chord's middle:
    nearly the hulls' own separating direction when the ball is beside the bat. A ball chord
    crossing that segment gives a negative number (no bound); so does a direction of zero length.
    """
    cx, cy, cz = (b0[0] + b1[0]) * 0.5, (b0[1] + b1[1]) * 0.5, (b0[2] + b1[2]) * 0.5
    mx, my, mz = (k0[0] + k1[0]) * 0.5, (k0[1] + k1[1]) * 0.5, (k0[2] + k1[2]) * 0.5
    ax = (e0[0] + e1[0]) * 0.5 - mx
    ay = (e0[1] + e1[1]) * 0.5 - my
    az = (e0[2] + e1[2]) * 0.5 - mz
    along = ax * ax + ay * ay + az * az
    s = ((cx - mx) * ax + (cy - my) * ay + (cz - mz) * az) / along if along > 0.0 else 0.0
    s = 0.0 if s < 0.0 else 1.0 if s > 1.0 else s
    nx, ny, nz = cx - mx - s * ax, cy - my - s * ay, cz - mz - s * az
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    if not length > 0.0:
        return -math.inf
    nx, ny, nz = nx / length, ny / length, nz / length
    return (min(nx * b0[0] + ny * b0[1] + nz * b0[2], nx * b1[0] + ny * b1[1] + nz * b1[2])
            - max(nx * k0[0] + ny * k0[1] + nz * k0[2], nx * e0[0] + ny * e0[1] + nz * e0[2],
                  nx * k1[0] + ny * k1[1] + nz * k1[2], nx * e1[0] + ny * e1[1] + nz * e1[2]))


def apart_margins(ball: np.ndarray, bat_knob: np.ndarray, bat_tip: np.ndarray,
                  bat_position: Optional[np.ndarray], ball_k: np.ndarray,
                  bat_k: np.ndarray, ball_before: np.ndarray, ball_after: np.ndarray,
                  bat_before: np.ndarray, bat_after: np.ndarray, ball_times: np.ndarray,
                  bat_times: np.ndarray, model: str, look_ahead: int = 0,
                  size: int = 8, margin: float = math.inf) -> np.ndarray:
    """
    Return ``clearly_apart``'s clearance (m) for many intervals at once.

    The same bounds as :func:`clearly_apart` for the ``linear``, ``rigid`` and ``spline``
    models, over arrays: the clearance is the larger of its two lower bounds (the bounding
    spheres' gap, the hulls' separation less both growths); ``clearly_apart`` says True where
    it exceeds ``margin``. For ``c2``, the clearance of its first stage (``c2_jump_bulge`` and
    ``c2_reach``) with the jumps and steps of every sample a full window could hold, counted
    from the arrays' first sample: never below the scalar test's bound, as long as the arrays
    start at or before the stream's first kept sample (-inf where the steps are too uneven:
    the scalar test decides). Computed with numpy's own rounding: a caller that must agree
    with the scalar test compares with a tolerance.

    :param ball: ball samples (n_ball, 3); ``bat_knob``, ``bat_tip``: bat samples (n_bat, 3).
    :param bat_position: pose origins (n_bat, 3) for pose input, else None.
    :param ball_k, bat_k: each interval's sample interval in the streams (m,).
    :param ball_before, ball_after, bat_before, bat_after: the neighbour samples of each
        interval in its segment (``Stream.neighbours``), -1 for none (spline only).
    :param ball_times, bat_times: the samples' times (s) (spline only).
    :param model: ``linear``, ``rigid``, ``spline`` or ``c2``.
    :param look_ahead, size: the ``c2`` model's look-ahead and window (samples).
    :param margin: ``c2``: intervals whose first stage clears this (m) skip the second.
    :returns: the clearance of each interval (m,).
    :raises ValueError: an unknown model.
    """
    if model == 'c2':
        return _c2_margins(ball, bat_knob, bat_tip, ball_k, bat_k, ball_times, bat_times,
                           look_ahead, size, margin)
    b0, b1 = ball[ball_k], ball[ball_k + 1]
    k0, k1 = bat_knob[bat_k], bat_knob[bat_k + 1]
    e0, e1 = bat_tip[bat_k], bat_tip[bat_k + 1]
    ball_centre = (b0 + b1) * 0.5
    ball_radius = 0.5 * _dist(b0, b1)
    bat_centre = (k0 + e0 + k1 + e1) * 0.25
    bat_radius = np.maximum(np.maximum(_dist(k0, bat_centre), _dist(e0, bat_centre)),
                            np.maximum(_dist(k1, bat_centre), _dist(e1, bat_centre)))
    ball_bulge = bat_growth = 0.0
    if model == 'rigid':
        turning = np.maximum(_dist(k0, k1), _dist(e0, e1))
        if bat_position is not None:
            reference = _dist(bat_position[bat_k], bat_position[bat_k + 1])
        else:
            reference = _dist(k0, k1) + 2.0 * np.abs(_dist(k0, e0) - _dist(k1, e1))
        bat_growth = 0.5 * (turning + reference)
    elif model == 'spline':
        ball_bulge = _bulges(ball, ball_times, ball_k, ball_before, ball_after)
        axis = bat_tip - bat_knob
        bat_growth = (_bulges(bat_knob, bat_times, bat_k, bat_before, bat_after)
                      + 0.25 * math.pi * _dist(e0 - k0, e1 - k1)
                      + math.pi * _bulges(axis, bat_times, bat_k, bat_before, bat_after)
                      + np.abs(_dist(k0, e0) - _dist(k1, e1)))
    elif model != 'linear':
        raise ValueError(f'no vectorised far test for the {model} model')
    ball_radius = ball_radius + ball_bulge
    bat_radius = bat_radius + bat_growth
    sphere = _dist(ball_centre, bat_centre) - ball_radius - bat_radius
    return np.maximum(sphere, hull_separations(b0, b1, k0, e0, k1, e1) - ball_bulge
                      - bat_growth)


def hull_separations(b0: np.ndarray, b1: np.ndarray, k0: np.ndarray, e0: np.ndarray,
                     k1: np.ndarray, e1: np.ndarray) -> np.ndarray:
    """:func:`hull_separation` over rows of (m, 3) arrays (NaN rounds to no bound: -inf)."""
    centre = (b0 + b1) * 0.5
    middle = (k0 + k1) * 0.5
    axis = (e0 + e1) * 0.5 - middle
    along = np.einsum('ij,ij->i', axis, axis)
    with np.errstate(all='ignore'):
        s = np.where(along > 0.0, np.einsum('ij,ij->i', centre - middle, axis) / along, 0.0)
    s = np.clip(s, 0.0, 1.0)
    n = centre - middle - s[:, None] * axis
    length = np.sqrt(np.einsum('ij,ij->i', n, n))
    with np.errstate(all='ignore'):
        n = n / length[:, None]
        separation = (np.minimum(np.einsum('ij,ij->i', n, b0), np.einsum('ij,ij->i', n, b1))
                      - np.maximum(np.maximum(np.einsum('ij,ij->i', n, k0),
                                              np.einsum('ij,ij->i', n, e0)),
                                   np.maximum(np.einsum('ij,ij->i', n, k1),
                                              np.einsum('ij,ij->i', n, e1))))
    return np.where(length > 0.0, separation, -np.inf)


def _c2_margins(ball: np.ndarray, bat_knob: np.ndarray, bat_tip: np.ndarray,
                ball_k: np.ndarray, bat_k: np.ndarray, ball_times: np.ndarray,
                bat_times: np.ndarray, look_ahead: int, size: int,
                margin: float) -> np.ndarray:
    """
    ``apart_margins`` for ``c2``: the larger clearance of ``clearly_apart``'s two stages.

    The second only where the first is not above ``margin`` (m).

    Each over the samples a full window could hold (``size`` before the interval's closing
    frame, ``look_ahead`` after it): a superset of the scalar test's window and chart, and
    every bound grows with the samples it sums over.
    """
    lengths = _dist(bat_tip, bat_knob)
    quick = _c2_jump_bulges(ball, None, ball_times, ball_k, look_ahead, size)
    bulge = _c2_jump_bulges(bat_knob, lengths, bat_times, bat_k, look_ahead, size)
    b0, b1 = ball[ball_k], ball[ball_k + 1]
    k0, k1 = bat_knob[bat_k], bat_knob[bat_k + 1]
    ball_centre, ball_radius = (b0 + b1) * 0.5, 0.5 * _dist(b0, b1)
    reach = 0.5 * _dist(k0, k1) + bulge + np.maximum(lengths[bat_k], lengths[bat_k + 1])
    first = _dist(ball_centre, (k0 + k1) * 0.5) - ball_radius - quick - reach
    near = np.flatnonzero(~(first > margin))
    if len(near) == len(first):
        return np.fmax(first, _c2_window_margins(ball, bat_knob, bat_tip, lengths, ball_k,
                                                 bat_k, ball_times, bat_times, look_ahead,
                                                 size))
    if len(near):
        first[near] = np.fmax(first[near], _c2_window_margins(
            ball, bat_knob, bat_tip, lengths, ball_k[near], bat_k[near], ball_times, bat_times,
            look_ahead, size))
    return first


def _c2_window_margins(ball: np.ndarray, bat_knob: np.ndarray, bat_tip: np.ndarray,
                       lengths: np.ndarray, ball_k: np.ndarray, bat_k: np.ndarray,
                       ball_times: np.ndarray, bat_times: np.ndarray, look_ahead: int,
                       size: int) -> np.ndarray:
    """Return the clearance (m) of ``clearly_apart``'s second ``c2`` stage over many intervals."""
    ball_k, ball_of = np.unique(ball_k, return_inverse=True)
    bat_k, bat_of = np.unique(bat_k, return_inverse=True)
    # the window's weights (``c2_bulge``, ``c2_bat_growth``), once per sample interval
    ball_window = _Windows(ball_times, ball_k, look_ahead, size)
    ball_bulge = ball_window.bulges(ball[ball_window.index])[ball_of]
    ball_uneven = ball_window.uneven[ball_of]
    bat_window = _Windows(bat_times, bat_k, look_ahead, size)
    index = bat_window.index
    axes = (bat_tip - bat_knob) / lengths[:, None]
    origin = axes[bat_k]
    rotations = _rotations_to(origin[:, None], axes[index])
    knob = bat_window.bulges(bat_knob[index])
    turn = bat_window.bulges(rotations)
    stretch = bat_window.bulges(lengths[index][:, :, None])
    half_cos = np.cos(0.5 * np.sqrt((rotations[:, size - 1] ** 2).sum(1)))
    length0, length1 = lengths[bat_k], lengths[bat_k + 1]
    growth = (knob + stretch + (np.maximum(length0, length1) + stretch) * (1.0 - half_cos + turn)
              + 0.25 * np.abs(length1 - length0) * _dist(origin, axes[bat_k + 1]))[bat_of]
    ball_k, bat_k = ball_k[ball_of], bat_k[bat_of]
    b0, b1 = ball[ball_k], ball[ball_k + 1]
    k0, k1 = bat_knob[bat_k], bat_knob[bat_k + 1]
    e0, e1 = bat_tip[bat_k], bat_tip[bat_k + 1]
    ball_centre, ball_radius = (b0 + b1) * 0.5, 0.5 * _dist(b0, b1)
    bat_centre = (k0 + e0 + k1 + e1) * 0.25
    bat_radius = np.maximum(np.maximum(_dist(k0, bat_centre), _dist(e0, bat_centre)),
                            np.maximum(_dist(k1, bat_centre), _dist(e1, bat_centre)))
    second = _dist(ball_centre, bat_centre) - ball_radius - ball_bulge - bat_radius - growth
    second[ball_uneven | bat_window.uneven[bat_of]] = -np.inf
    return np.nan_to_num(second, nan=-np.inf)


def _rotations_to(reference: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """``c2.rotation_to`` over rows (rad, (..., 3)), the rows broadcast."""
    ax, ay, az = reference[..., 0], reference[..., 1], reference[..., 2]
    bx, by, bz = direction[..., 0], direction[..., 1], direction[..., 2]
    turn = np.stack((ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx), axis=-1)
    sine = np.sqrt((turn * turn).sum(-1))
    cosine = ax * bx + ay * by + az * bz
    with np.errstate(all='ignore'):
        angle = np.where(sine < 1e-15, 0.0, np.arctan2(sine, cosine) / sine)
    return turn * angle[..., None]


class _Windows:
    """
    The samples a full ``c2`` window could hold, for many intervals k of one stream.

    From ``size`` samples before each interval's closing frame (not before the stream's
    first) to ``look_ahead`` after it (not past its last).

    :ivar index: (m, W) the sample k + o of each interval, o from 2 - ``size`` to
        ``look_ahead`` + 1 (clipped into the stream); ``weights``: (m, W) ``C2_SAFETY`` times
        its cardinal weight, 0 outside the window.
    :ivar uneven: where the window's steps are more uneven than ``C2_STEP_RATIO`` (the scalar
        test gives no bound).
    """

    def __init__(self, times: np.ndarray, k: np.ndarray, look_ahead: int, size: int) -> None:
        n = len(times)
        offsets = np.arange(2 - size, look_ahead + 2)
        m = k[:, None] + offsets
        first = np.maximum(k + 2 - size, 0)[:, None]
        inside = (m >= first) & (m <= np.minimum(k + 1 + look_ahead, n - 1)[:, None])
        self.index = np.minimum(np.maximum(m, 0), n - 1)
        self.weights = np.where(inside, np.array(_WEIGHT_LIST)[_FAR_OFFSET + offsets], 0.0)
        self.centre = size - 2  # the column of offset 0
        self.k, self.times = k, times
        steps = np.zeros(n)
        steps[1:] = times[1:] - times[:-1]
        step = steps[self.index]
        within = inside & (m > first)
        longest = np.where(within, step, 0.0).max(1)
        shortest = np.where(within, step, np.inf).min(1)
        self.uneven = longest > C2_STEP_RATIO * shortest

    def bulges(self, values: np.ndarray) -> np.ndarray:
        """
        ``c2_bulge`` over the windows (the values' units).

        :param values: (m, W, c): each interval's window values (``index``).
        """
        c = self.centre
        p0 = values[:, c]
        t0 = self.times[self.k]
        dt = self.times[self.index] - t0[:, None]
        rate = (values[:, c + 1] - p0) / dt[:, c + 1, None]
        d = values - p0[:, None] - rate[:, None] * dt[:, :, None]
        return (self.weights * np.sqrt((d * d).sum(2))).sum(1)


def _c2_jump_bulges(points: np.ndarray, lengths: Optional[np.ndarray], times: np.ndarray,
                    k: np.ndarray, look_ahead: int, size: int) -> np.ndarray:
    """
    ``c2_jump_bulge`` over many intervals k of one stream (m; inf where it gives no bound).

    Over every sample a full window could hold, counted from the arrays' first sample: the
    sum over the jumps is taken for every sample at once (the jumps before the first sample
    are 0, as the first's own), then read at k.

    :param points: the ball's samples or the bat's knobs (n, 3); ``lengths``: the bat's
        knob-to-tip lengths (n,), None for the ball; ``times``: (n,) s.
    """
    n = len(times)
    steps = np.zeros(n)
    steps[1:] = times[1:] - times[:-1]
    jumps = np.zeros(n + look_ahead + 2)
    if n >= 3:
        h0, h1 = steps[1:-1, None], steps[2:, None]
        a, b, c = points[:-2], points[1:-1], points[2:]
        jumps[1:n - 1] = np.sqrt((((c - b) / h1 - (b - a) / h0) ** 2).sum(1))
        if lengths is not None:
            la, lb, lc = lengths[:-2], lengths[1:-1], lengths[2:]
            jumps[1:n - 1] += np.abs((lc - lb) / h1[:, 0] - (lb - la) / h0[:, 0])
    # per sample m: the weighted jumps before it, the longest and shortest step in its window
    padded = np.concatenate((np.zeros(size), jumps[:n]))
    before = np.zeros(n)
    for a in range(size - 2):
        before += C2_JUMP_BEFORE[a] * padded[size - a:size - a + n]
    high = np.concatenate((np.full(size, -np.inf), [-np.inf], steps[1:],
                           np.full(look_ahead + 2, -np.inf)))
    low = np.concatenate((np.full(size, np.inf), [np.inf], steps[1:],
                          np.full(look_ahead + 2, np.inf)))
    longest, shortest = np.full(n, -np.inf), np.full(n, np.inf)
    for o in range(3 - size, look_ahead + 2):
        longest = np.maximum(longest, high[size + o:size + o + n])
        shortest = np.minimum(shortest, low[size + o:size + o + n])
    after = np.minimum(k + 1 + look_ahead, n - 1) - k
    bound = before[k]
    bound = bound + np.where(after > 1, _AFTER_ONE * jumps[k + 1], 0.0)
    bound = bound + np.where(after > 2, _AFTER_TWO * (2.0 * jumps[k + 1] + jumps[k + 2]), 0.0)
    longest, shortest = longest[k], shortest[k]
    return np.where(longest > C2_STEP_RATIO * shortest, np.inf, longest * bound)


def _dist(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the row-wise distances between two (m, 3) arrays."""
    d = a - b
    return np.sqrt(np.einsum('ij,ij->i', d, d))


def _bulges(points: np.ndarray, times: np.ndarray, k: np.ndarray, before: np.ndarray,
            after: np.ndarray) -> np.ndarray:
    """``bulge_bounds`` of one picked point over many intervals k (-1 neighbours: none)."""
    h = times[k + 1] - times[k]
    here, there = points[k], points[k + 1]
    bound = 3.04 * _dist(here, there)
    has = before >= 0
    b = np.where(has, before, k)
    step = np.where(has, times[k] - times[b], 1.0)
    bound = bound + np.where(has, 0.885 * h / step * _dist(points[b], here), 0.0)
    has = after >= 0
    a = np.where(has, after, k + 1)
    step = np.where(has, times[a] - times[k + 1], 1.0)
    return bound + np.where(has, 0.635 * h / step * _dist(there, points[a]), 0.0)


def path_margins(ball: np.ndarray, bat_knob: np.ndarray, bat_tip: np.ndarray,
                 bat_quaternion: np.ndarray, ball_k: np.ndarray, bat_k: np.ndarray,
                 ball_before: np.ndarray, ball_after: np.ndarray, bat_before: np.ndarray,
                 bat_after: np.ndarray, ball_times: np.ndarray, bat_times: np.ndarray,
                 model: str, lever: float) -> np.ndarray:
    """
    Return the sweep's second far test over many intervals: the motion paths' spheres' gap (m).

    ``PointPath.centre``/``radius`` of the ball and ``BatPath.centre``/``radius`` of the bat
    (``rigid`` from poses, ``spline``; ``linear``: the chords, the first test's spheres) as
    ``Sweep.interval`` builds them, over arrays, without building the paths; the sweep calls an
    interval far where this exceeds its margin. Arguments as :func:`apart_margins`, with the
    bat's unit quaternions (n_bat, 4) and, for ``rigid``, ``lever``: the longer body offset
    (m). Computed with numpy's own rounding: compare with a tolerance
    (test/core/detector/test_broadphase.py checks it against the paths).

    :raises ValueError: ``c2`` (its windows are not vectorised).
    """
    b0, b1 = ball[ball_k], ball[ball_k + 1]
    k0, k1 = bat_knob[bat_k], bat_knob[bat_k + 1]
    e0, e1 = bat_tip[bat_k], bat_tip[bat_k + 1]
    bat_centre = 0.25 * (k0 + e0 + k1 + e1)
    bat_radius = np.maximum(np.maximum(_dist(k0, bat_centre), _dist(e0, bat_centre)),
                            np.maximum(_dist(k1, bat_centre), _dist(e1, bat_centre)))
    ball_radius = 0.5 * _dist(b0, b1)
    if model == 'rigid':
        cosine = np.abs(np.einsum('ij,ij->i', bat_quaternion[bat_k], bat_quaternion[bat_k + 1]))
        angle = 2.0 * np.arccos(np.minimum(1.0, cosine))
        bat_radius = bat_radius + lever * angle * angle / 8.0
    elif model == 'spline':
        ball_radius = ball_radius + _cubic_bulges(ball, ball_times, ball_k, ball_before,
                                                  ball_after)
        bat_radius = (bat_radius + _cubic_bulges(bat_knob, bat_times, bat_k, bat_before,
                                                 bat_after)
                      + _turn_growth(bat_knob, bat_tip, bat_times, bat_k, bat_before, bat_after))
    elif model != 'linear':
        raise ValueError(f'no vectorised path test for the {model} model')
    return _dist(b0 + (b1 - b0) * 0.5, bat_centre) - ball_radius - bat_radius


def _slopes(t_prev: np.ndarray, v_prev: np.ndarray, t: np.ndarray, v: np.ndarray,
            t_next: np.ndarray, v_next: np.ndarray, has_prev: np.ndarray,
            has_next: np.ndarray) -> np.ndarray:
    """``motion.base.hermite_tangent`` (and ``hermite_slope``: 1-d values) over rows."""
    h0, h1 = t - t_prev, t_next - t
    if v.ndim == 2:
        h0, h1, t_next, t_prev, t = (x[:, None] for x in (h0, h1, t_next, t_prev, t))
        has_prev, has_next = has_prev[:, None], has_next[:, None]
    with np.errstate(all='ignore'):
        w_prev = h1 / (h0 * (h0 + h1))
        w_next = h0 / (h1 * (h0 + h1))
        both = w_next * v_next + (w_prev - w_next) * v - w_prev * v_prev
        forward = (v_next - v) * (1.0 / (t_next - t))
        backward = (v - v_prev) * (1.0 / (t - t_prev))
    return np.where(has_prev & has_next, both, np.where(
        has_next, forward, np.where(has_prev, backward, 0.0)))


def _hermite_bulge(h: np.ndarray, chord: np.ndarray, m0: np.ndarray,
                   m1: np.ndarray) -> np.ndarray:
    """``PointPath.bulge`` (``AngleCubic.bulge``: 1-d) of cubics with end rates m0, m1."""
    if chord.ndim == 2:
        h = h[:, None]
    b, e = h * m0, h * m1
    c = 3.0 * chord - 2.0 * b - e
    d = b + e - 2.0 * chord
    if chord.ndim == 2:
        return 0.25 * np.sqrt(np.einsum('ij,ij->i', c, c)) + 0.3849 * np.sqrt(
            np.einsum('ij,ij->i', d, d))
    return 0.25 * np.abs(c) + 0.3849 * np.abs(d)


def _cubic_bulges(points: np.ndarray, times: np.ndarray, k: np.ndarray, before: np.ndarray,
                  after: np.ndarray) -> np.ndarray:
    """``PointPath.build('spline', ...).bulge`` over many intervals k (-1 neighbours: none)."""
    has_before, has_after = before >= 0, after >= 0
    b, a = np.where(has_before, before, k), np.where(has_after, after, k + 1)
    t0, t1 = times[k], times[k + 1]
    p0, p1 = points[k], points[k + 1]
    true = np.ones(len(k), bool)
    m0 = _slopes(times[b], points[b], t0, p0, t1, p1, has_before, true)
    m1 = _slopes(t0, p0, t1, p1, times[a], points[a], true, has_after)
    return _hermite_bulge(t1 - t0, p1 - p0, m0, m1)


def _swing_angles(u: np.ndarray, v: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return ``geometry.swing_rotation``'s (cross, sine, angle) over rows."""
    turn = np.cross(u, v)
    sine = np.sqrt(np.einsum('ij,ij->i', turn, turn))
    return turn, sine, np.arctan2(sine, np.einsum('ij,ij->i', u, v))


def _turn_growth(knobs: np.ndarray, tips: np.ndarray, times: np.ndarray, k: np.ndarray,
                 before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """
    ``SplineBatPath``'s growth beyond the knob's bulge over many intervals k (m).

    lever * ((angle + 2 bulge)^2 / 8 + 2 bulge): the turn between the directions and its
    cubic's (``AngleCubic.through``) bulge, the neighbours' swings projected on its axis.
    """
    axes = tips - knobs
    lengths = np.sqrt(np.einsum('ij,ij->i', axes, axes))
    directions = axes / lengths[:, None]
    d0, d1 = directions[k], directions[k + 1]
    turn, sine, angle = _swing_angles(d0, d1)
    turning = sine >= 1e-12
    with np.errstate(all='ignore'):
        axis = turn / sine[:, None]
    has_before, has_after = before >= 0, after >= 0
    b, a = np.where(has_before, before, k), np.where(has_after, after, k + 1)
    ones = np.ones(len(k), bool)

    def projected(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        cross, s, theta = _swing_angles(u, v)
        with np.errstate(all='ignore'):
            rotation = cross * (theta / s)[:, None]
        return np.where(s > 0.0, np.einsum('ij,ij->i', rotation, axis), 0.0)
    previous = -projected(axes[b], axes[k])
    following = angle + projected(axes[k + 1], axes[a])
    t0, t1 = times[k], times[k + 1]
    zero = np.zeros(len(k))
    m0 = _slopes(times[b], previous, t0, zero, t1, angle, has_before, ones)
    m1 = _slopes(t0, zero, t1, angle, times[a], following, ones, has_after)
    bulge = np.where(turning, _hermite_bulge(t1 - t0, angle, m0, m1), 0.0)
    lever = np.maximum(lengths[k], lengths[k + 1])
    return lever * ((angle + 2.0 * bulge) ** 2 / 8.0 + 2.0 * bulge)
