"""
Paths of one point (the ball) and of one angle over a sample interval: chords and cubics.

* ``PointPath``: a point on its chord (linear, rigid) or on a cubic Hermite through its
  neighbours (spline): tangents from the three-point rule, exact for a quadratic, also on uneven
  stamps. A curve leaves its chord by at most max|p''| h^2 / 8.
* ``AngleCubic``: the same for a scalar, the spline bat's turning angle.
"""

from typing import Optional

from .base import hermite_slope, hermite_tangent, Neighbour
from ..geometry import norm, Vector
from ..toi import _kernel


class PointPath:
    """
    A point moving over one sample interval [t0, t1]: linear, or cubic Hermite with tangents.

    ``centre`` and ``radius`` (metres) bound the whole path by a sphere (a ``MotionPath``).

    :param t0, t1: interval ends (seconds), t1 > t0.
    :param p0, p1: positions at the ends (metres).
    :param m0, m1: velocities at the ends (m/s) for a cubic; both None for the chord.
    """

    __slots__ = ('t0', 't1', 'h', 'a', 'b', 'c', 'd', 'curved', 'end', 'centre', 'radius',
                 'accel0', 'accel_rate', 'bulge')

    def __init__(self, t0: float, t1: float, p0: Vector, p1: Vector,
                 m0: Optional[Vector] = None, m1: Optional[Vector] = None) -> None:
        # in the kernel (``toi._kernel.point_path_init``, the same operations in this order):
        # the power basis in s = (t - t0) / h, p = a + b s + c s^2 + d s^3 with b = h m0,
        # e = h m1, c = 3 chord - 2 b - e, d = b + e - 2 chord; p''(t) = accel0 + accel_rate s
        # with accel0 = 2 c / h^2, accel_rate = 6 d / h^2; p(s) - chord(s) = c (s^2 - s) +
        # d (s^3 - s), |s^2 - s| <= 1/4 and |s^3 - s| <= 0.385, so bulge = 0.25 |c| +
        # 0.3849 |d|; a chord: b = the chord, c = d = 0, bulge 0; centre: the chord's middle,
        # radius: half the chord plus the bulge
        _kernel.point_path_init(self, t0, t1, p0, p1, m0, m1)

    @classmethod
    def build(cls, model: str, t0: float, t1: float, p0: Vector, p1: Vector,
              before: Neighbour = None, after: Neighbour = None) -> 'PointPath':
        """
        Return a point's path between two samples under a motion model.

        The spline is a cubic with tangents from the neighbours ``before`` and ``after``
        ((time, point) or None); every other model moves a point on its chord.
        """
        if model != 'spline':
            return cls(t0, t1, p0, p1)
        tb, pb = before if before is not None else (None, None)
        ta, pa = after if after is not None else (None, None)
        return cls(t0, t1, p0, p1, hermite_tangent(tb, pb, t0, p0, t1, p1),
                   hermite_tangent(t0, p0, t1, p1, ta, pa))

    def at(self, t: float) -> Vector:
        """Return the position (metres) at time t (seconds)."""
        if t == self.t0:
            return self.a
        if t == self.t1:
            return self.end
        s = (t - self.t0) / self.h
        a, b, c, d = self.a, self.b, self.c, self.d
        return (a[0] + s * (b[0] + s * (c[0] + s * d[0])),
                a[1] + s * (b[1] + s * (c[1] + s * d[1])),
                a[2] + s * (b[2] + s * (c[2] + s * d[2])))

    def velocity(self, t: float) -> Vector:
        """Return the time derivative of the position (m/s) at time t (seconds)."""
        s = (t - self.t0) / self.h
        b, c, d = self.b, self.c, self.d
        return tuple((b[i] + s * (2.0 * c[i] + 3.0 * s * d[i])) / self.h for i in range(3))

    def max_acceleration(self, ta: float, tb: float) -> float:
        """Return the largest |p''| (m/s^2) over [ta, tb]: at an end, p'' being linear in t."""
        if not self.curved:
            return 0.0
        a0, rate = self.accel0, self.accel_rate
        worst = 0.0
        for t in (ta, tb):
            s = (t - self.t0) / self.h
            worst = max(worst, norm((a0[0] + rate[0] * s, a0[1] + rate[1] * s,
                                     a0[2] + rate[2] * s)))
        return worst

    def deviation(self, ta: float, tb: float) -> float:
        """Return a bound (metres) on how far the path leaves its chord over [ta, tb]."""
        return self.max_acceleration(ta, tb) * (tb - ta) ** 2 / 8.0


class AngleCubic:
    """
    An angle (rad) over one sample interval [t0, t1]: linear, or cubic Hermite with rates.

    :param t0, t1: interval ends (seconds), t1 > t0.
    :param v0, v1: angles at the ends (rad).
    :param m0, m1: rates at the ends (rad/s) for a cubic; both None for a uniform turn.
    :ivar bulge: a bound (rad) on how far the angle leaves uniform speed over the interval.
    """

    __slots__ = ('t0', 't1', 'h', 'a', 'b', 'c', 'd', 'curved', 'end', 'accel0', 'accel_rate',
                 'bulge')

    def __init__(self, t0: float, t1: float, v0: float, v1: float,
                 m0: Optional[float] = None, m1: Optional[float] = None) -> None:
        self.t0, self.t1 = t0, t1
        h = self.h = t1 - t0
        self.a = v0
        self.end = v1
        self.curved = m0 is not None and m1 is not None
        chord = v1 - v0
        if self.curved:
            b = self.b = h * m0
            e = h * m1
            c = self.c = 3.0 * chord - 2.0 * b - e
            d = self.d = b + e - 2.0 * chord
            h2 = h * h
            self.accel0 = 2.0 * c / h2
            self.accel_rate = 6.0 * d / h2
            self.bulge = 0.25 * abs(c) + 0.3849 * abs(d)
        else:
            self.b = chord
            self.c = self.d = 0.0
            self.bulge = 0.0

    @classmethod
    def through(cls, t0: float, t1: float, v0: float, v1: float, before: Neighbour = None,
                after: Neighbour = None) -> 'AngleCubic':
        """Return the cubic with rates from the neighbours ((time, angle) or None) at each end."""
        tb, vb = before if before is not None else (None, None)
        ta, va = after if after is not None else (None, None)
        return cls(t0, t1, v0, v1, hermite_slope(tb, vb, t0, v0, t1, v1),
                   hermite_slope(t0, v0, t1, v1, ta, va))

    def at(self, t: float) -> float:
        """Return the angle (rad) at time t (seconds)."""
        if t == self.t0:
            return self.a
        if t == self.t1:
            return self.end
        s = (t - self.t0) / self.h
        return self.a + s * (self.b + s * (self.c + s * self.d))

    def deviation(self, ta: float, tb: float) -> float:
        """Return a bound (rad) on how far the angle leaves uniform speed over [ta, tb]."""
        if not self.curved:
            return 0.0
        worst = 0.0
        for t in (ta, tb):
            s = (t - self.t0) / self.h
            worst = max(worst, abs(self.accel0 + self.accel_rate * s))
        return worst * (tb - ta) ** 2 / 8.0
