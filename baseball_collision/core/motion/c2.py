"""
The ``c2`` model: a not-a-knot cubic spline per coordinate over a window of each stream.

Over the last W samples of a continuous stream segment up to the interval's closing frame plus
a look-ahead of 0, 1 or 2 frames, each coordinate is interpolated by the not-a-knot cubic
spline (``splines.not_a_knot_slopes``): the ball's centre; the bat's knob, its unit
knob-to-tip direction and its length. The direction's spline is renormalised where it is used,
so the bat turns about whatever axis its samples say, the axis changing within and between
intervals (no fixed axis per interval: a tilting swing plane is followed), and keeps its
length. From poses the knob and tip the pose carries are fitted the same way (a round bat's
roll does not move its axis).

Error order: a spline through samples of a motion with a bounded fourth derivative is O(h^4)
off in position (and the renormalisation keeps that order: the unit direction is a smooth
function) and O(h^3) in velocity, on uneven stamps and in the window's end pieces too
(not-a-knot), so halving the step divides the position error by about 16. With look-ahead 0
the fit ends at the interval's closing frame: frames after it (the bat braking after a
contact) cannot bend the interval. Each path is a ``MotionPath`` over one interval;
``C2BatPath.deviation`` bounds how far any bat axis point leaves its chord from the second
derivative of knob + length * direction.
"""

import math
from typing import Sequence, Tuple

from .base import BatSample, PathKind
from .bat_paths import BatPath, Ends
from .points import AngleCubic, PointPath
from ..geometry import dot, norm, sub, Vector


def _second_bound(path: PointPath, ta: float, tb: float) -> float:
    """Return the largest |p''| (per s^2) of a cubic point path over [ta, tb] (at an end)."""
    if not path.curved:
        return 0.0
    a0, rate = path.accel0, path.accel_rate
    worst = 0.0
    for t in (ta, tb):
        s = (t - path.t0) / path.h
        worst = max(worst, norm((a0[0] + rate[0] * s, a0[1] + rate[1] * s, a0[2] + rate[2] * s)))
    return worst


def _scalar_bounds(cubic: AngleCubic, ta: float, tb: float) -> Tuple[float, float, float]:
    """Return bounds of |v|, |v'| and |v''| of a scalar cubic over [ta, tb]."""
    span = tb - ta
    second = 0.0
    if cubic.curved:
        second = max(abs(cubic.accel0 + cubic.accel_rate * (t - cubic.t0) / cubic.h)
                     for t in (ta, tb))
    s = (ta - cubic.t0) / cubic.h
    first = abs((cubic.b + s * (2.0 * cubic.c + 3.0 * s * cubic.d)) / cubic.h) + second * span
    value = max(abs(cubic.at(ta)), abs(cubic.at(tb))) + second * span * span / 8.0
    return value, first, second


def _least_norm(a: Vector, b: Vector) -> float:
    """Return the smallest length of a point on the segment from a to b."""
    change = sub(b, a)
    size = dot(change, change)
    u = 0.0 if size == 0.0 else min(1.0, max(0.0, -dot(a, change) / size))
    return norm((a[0] + u * change[0], a[1] + u * change[1], a[2] + u * change[2]))


class C2BatPath(BatPath):
    """
    ``c2``: knob, unit direction and length, each a spline piece (cubic Hermite) over [t0, t1].

    :param knob_slopes, direction_slopes: (start, end) velocities (per second) of the knob (m)
        and of the unit knob-to-tip direction, from the window's spline.
    :param length_slopes: (start, end) rates of the knob-to-tip length (m/s).
    """

    __slots__ = ('knob', 'direction', 'length')
    kind = PathKind.C2

    def __init__(self, t0: float, t1: float, sample0: BatSample, sample1: BatSample,
                 knob_slopes: Tuple[Vector, Vector], direction_slopes: Tuple[Vector, Vector],
                 length_slopes: Tuple[float, float]) -> None:
        super().__init__(t0, t1, sample0, sample1)
        self.knob = PointPath(t0, t1, sample0.knob, sample1.knob, *knob_slopes)
        axis0, axis1 = sub(sample0.tip, sample0.knob), sub(sample1.tip, sample1.knob)
        length0, length1 = norm(axis0), norm(axis1)
        self.direction = PointPath(t0, t1, tuple(c / length0 for c in axis0),
                                   tuple(c / length1 for c in axis1), *direction_slopes)
        self.length = AngleCubic(t0, t1, length0, length1, *length_slopes)
        self.lever = max(length0, length1)
        self.angle = math.acos(max(-1.0, min(1.0, dot(self.direction.a, self.direction.end))))
        self.radius += self.deviation(t0, t1)

    @classmethod
    def fitted(cls, times: Sequence[float], samples: Sequence[BatSample], k: int,
               slopes: Sequence[Sequence[float]]) -> 'C2BatPath':
        """
        Return the path over [times[k], times[k + 1]] from the window's spline slopes.

        :param slopes: per window sample, the 7 slopes of (knob x, y, z, direction x, y, z,
            length), from ``splines.not_a_knot_slopes`` over ``c2_rows``.
        """
        s0, s1 = slopes[k], slopes[k + 1]
        return cls(times[k], times[k + 1], samples[k], samples[k + 1],
                   (tuple(s0[:3]), tuple(s1[:3])), (tuple(s0[3:6]), tuple(s1[3:6])),
                   (s0[6], s1[6]))

    def _inside(self, t: float) -> Ends:
        knob = self.knob.at(t)
        d = self.direction.at(t)
        stretch = self.length.at(t) / norm(d)
        return knob, (knob[0] + stretch * d[0], knob[1] + stretch * d[1],
                      knob[2] + stretch * d[2])

    def deviation(self, ta: float, tb: float) -> float:
        """
        Return a bound (m) on how far any axis point leaves its chord over [ta, tb].

        An axis point is p = knob + f L d / |d| (0 <= f <= 1) and leaves its chord by at most
        max |p''| (tb - ta)^2 / 8, with |p''| <= |knob''| + |L''| + 2 |L'| |u'| + L |u''|,
        u = d / |d|: |u'| <= |d'| / |d| and |u''| <= |d''| / |d| + 3 |d'|^2 / |d|^2, |d| at
        least the chord's least length less the cubic's bulge from it.
        """
        span = tb - ta
        direction = self.direction
        second = _second_bound(direction, ta, tb)
        first = norm(direction.velocity(ta)) + second * span
        least = _least_norm(direction.at(ta), direction.at(tb)) - second * span * span / 8.0
        value, rate, change = _scalar_bounds(self.length, ta, tb)
        knob = _second_bound(self.knob, ta, tb) * span * span / 8.0
        if least < 0.25:  # the direction's spline nearly passes through zero: bound crudely
            return knob + 2.0 * value
        turn = first / least
        bend = second / least + 3.0 * turn * turn
        return knob + (change + 2.0 * rate * turn + value * bend) * span * span / 8.0


def c2_rows(samples: Sequence[BatSample]) -> list:
    """Return per bat sample the 7 fitted coordinates: knob, unit direction, length."""
    rows = []
    for sample in samples:
        axis = sub(sample.tip, sample.knob)
        length = norm(axis)
        rows.append((*sample.knob, axis[0] / length, axis[1] / length, axis[2] / length, length))
    return rows
