"""
The scalar far test the node's sweep runs: ball and bat clearly apart over one union interval.

Each body's path lies in a sphere around its chord's middle (and within the hull of its end
samples, for the finer bound ``hull_separation``), grown by a bound on how far the motion
model lets it bulge (none for chords; for a rigid turn, the sagitta is at most half the chord
of the rotating part; for the spline, ``bulge_bounds``; for ``c2``, the bounds of ``.c2``).
"""

import math
from typing import Callable, List, Sequence

from .c2 import c2_bat_growth, c2_clearly_apart
from ..departure import departure_reach
from ..fitting import c2_window
from ..streams import Stream
from ...geometry import sub, Vector
from ...motion import BatSample, PointPath
from ...toi import _kernel

Pick = Callable[[object], Vector]
"""Picks the point followed from a sample value (the ball itself, the knob, the axis)."""


def _same(point: Vector) -> Vector:
    return point


def _knob_of(sample: BatSample) -> Vector:
    return sample.knob


def _axis_of(sample: BatSample) -> Vector:
    return sub(sample.tip, sample.knob)


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


NOISE_REACH = 20.0
"""How far (in the streams' 1-sigma noise, ball's plus bat's) the ``c2`` paths smoothed under
noise may leave the raw samples' spline that the hull bound holds for. Measured, paths at 9
instants of every interval with paths (``analyze`` on a noisy session at 1 mm, the noisy
worst cases at 1 and 2 mm, the bundled 240 Hz noisy bag): p99 3.8-4.2 sigma, at most 6.1
(the ball's free flight at a hit, which the margin's ``departure_reach`` covers, aside)."""


def clearly_apart(ball: Stream, bat: Stream, ball_k: int, bat_k: int, margin: float,
                  model: str, max_gap: float, look_ahead: int = 0, size: int = 8,
                  noise: float = 0.0) -> bool:
    """
    Return whether ball and bat stay more than ``margin`` (m) apart over both sample intervals.

    Two lower bounds on the distance between any point of the ball's path and any point of the
    bat's axis over the intervals: the bounding spheres' gap, then the hulls' separation along
    one direction (:func:`hull_separation`), each less how far the paths may leave them.

    :param ball_k, bat_k: the streams' sample intervals (``Stream.interval``) in play.
    :param model: the motion model between samples.
    :param look_ahead, size: the ``c2`` model's look-ahead and window (samples).
    :param noise: the ball's plus the bat's tracking noise (m, 1 sigma): ``c2`` smooths the
        samples under noise, and its paths may leave the samples' hulls by ``NOISE_REACH``
        times it more.

    The ball's bounds hold for the free flight's path too, which the sweep takes where the
    ball's closing sample has left it (a hit): the margin grows by ``departure_reach``.
    """
    margin += departure_reach(ball, ball_k, max_gap)
    b0, b1 = ball.values[ball_k], ball.values[ball_k + 1]
    s0, s1 = bat.values[bat_k], bat.values[bat_k + 1]
    k0, e0, k1, e1 = s0.knob, s0.tip, s1.knob, s1.tip
    # the ball chord's middle and half its length, the bat's four end points' mean and their
    # largest distance from it (math.dist), and hull_separation: the kernel's, in this order
    ball_centre, ball_radius, bat_centre, bat_radius, hull = _kernel.far_spheres(
        b0, b1, k0, e0, k1, e1)
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
        return c2_clearly_apart(ball, bat, ball_k, bat_k, (ball_centre, ball_radius, bat_centre,
                                                           bat_radius), margin, max_gap,
                                look_ahead, size, hull - NOISE_REACH * noise)
    return (math.dist(ball_centre, bat_centre) - ball_radius - bat_radius > margin
            or hull - ball_bulge - bat_growth > margin)


def c2_path_apart(ball_path: PointPath, ball: Stream, bat: Stream, ball_k: int, bat_k: int,
                  margin: float, max_gap: float, look_ahead: int, size: int,
                  bat_noise: float) -> bool:
    """
    Return whether the ``c2`` bat stays more than ``margin`` (m) from the ball's own path.

    Under noise ``c2`` fits the ball (its flight fit, or its smoothed window) and the sweep
    takes that path, which leaves the chord of its own two ends by at most its ``bulge``;
    ``clearly_apart``'s bounds are the samples' spline's, whose bulge carries the noise times
    the window's weights (70-120 mm at 1 mm of noise, against micrometres for a flight fit).
    Here the hulls' separation of the path's two ends and the bat's four end points, less the
    path's bulge, the bat's growth (``c2_bat_growth``) and ``NOISE_REACH`` times the bat's
    noise (m, 1 sigma: its path is smoothed too); the margin grows by the ball's
    ``departure_reach`` as in ``clearly_apart``.

    :param ball_path: the sweep's path of the ball over its sample interval ``ball_k``.
    """
    s0, s1 = bat.values[bat_k], bat.values[bat_k + 1]
    apart = (hull_separation(ball_path.a, ball_path.end, s0.knob, s0.tip, s1.knob, s1.tip)
             - ball_path.bulge)
    margin += departure_reach(ball, ball_k, max_gap)
    if not apart - NOISE_REACH * bat_noise > margin:
        return False  # (nor with the growth, >= 0, taken off too: rounding is monotone)
    growth = c2_bat_growth(bat, bat_k, c2_window(bat, bat_k, max_gap, look_ahead, size))
    return growth is not None and apart - growth - NOISE_REACH * bat_noise > margin


def hull_separation(b0: Vector, b1: Vector, k0: Vector, e0: Vector, k1: Vector,
                    e1: Vector) -> float:
    """
    Return a lower bound (m) on the distance between the hulls of (b0, b1) and (k0, e0, k1, e1).

    For any unit vector n, every x in the first hull and y in the second are at least
    min(n.b) - max(n.p) apart (n.(x - y) <= |x - y|). Here n points from the closest point of
    the bat's middle segment (the knobs' middle to the tips' middle) to the ball chord's middle:
    nearly the hulls' own separating direction when the ball is beside the bat. A ball chord
    crossing that segment gives a negative number (no bound); so does a direction of zero length.
    The kernel's (``toi._kernel.hull_separation``; the plan's far test over arrays takes the
    same function).
    """
    return _kernel.hull_separation(b0, b1, k0, e0, k1, e1)
