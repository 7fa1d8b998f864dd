"""
The cheap far test: ball and bat clearly apart over a union interval, from the raw samples.

Most intervals of a session have the ball metres from the bat. This decides them without
building a path: each body's path lies in a sphere around its chord's middle, grown by a bound
on how far the motion model lets it bulge (none for chords; for a rigid turn, the sagitta is
at most half the chord of the rotating part; for the spline, ``bulge_bounds``).
"""

import math
from typing import Callable, List, Sequence

from .streams import Stream
from ..geometry import sub, Vector
from ..motion import BatSample

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


def clearly_apart(ball: Stream, bat: Stream, ball_k: int, bat_k: int, margin: float,
                  model: str, max_gap: float) -> bool:
    """
    Return whether ball and bat stay more than ``margin`` (m) apart over both sample intervals.

    :param ball_k, bat_k: the streams' sample intervals (``Stream.interval``) in play.
    :param model: the motion model between samples.
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
    if model == 'rigid':
        turning = max(math.dist(k0, k1), math.dist(e0, e1))
        if s0.position is not None:
            reference = math.dist(s0.position, s1.position)
        else:
            # knob moves on its chord, the length changes linearly: both count in full
            reference = math.dist(k0, k1) + 2.0 * abs(math.dist(k0, e0) - math.dist(k1, e1))
        bat_radius += 0.5 * (turning + reference)
    elif model == 'spline':
        # the knob's cubic, then the knob-to-tip vector r turning on an arc (at most
        # (pi / 4) |D r| from its chord) by an angle whose cubic overshoots uniform speed by at
        # most pi times r's own bulge bound (angle <= (pi / 2) chord / length), and the
        # length changing linearly
        ball_radius += bulge_bounds(ball, ball_k, (_same,), max_gap)[0]
        knob_bulge, axis_bulge = bulge_bounds(bat, bat_k, (_knob_of, _axis_of), max_gap)
        bat_radius += (knob_bulge + 0.25 * math.pi * math.dist(sub(e0, k0), sub(e1, k1))
                       + math.pi * axis_bulge + abs(math.dist(k0, e0) - math.dist(k1, e1)))
    return math.dist(ball_centre, bat_centre) - ball_radius - bat_radius > margin
