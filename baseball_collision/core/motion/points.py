"""
Paths of one point (the ball) and of one angle over a sample interval: chords, cubics, quintics.

* ``PointPath``: a point on its chord (linear, rigid) or on a cubic Hermite through its
  neighbours (spline): tangents from the three-point rule, exact for a quadratic, also on uneven
  stamps; or (``c2``'s quintic windows) a quintic Hermite, its end accelerations given too. A
  curve leaves its chord by at most max|p''| h^2 / 8.
* ``AngleCubic``: the same for a scalar, the spline bat's turning angle and ``c2``'s length.

A piece is the polynomial a + b s + c s^2 + d s^3 (+ e s^4 + f s^5 for a quintic; e and f are
None otherwise) in s = (t - t0) / h over its interval.
"""

import math
from typing import Optional, Sequence, Tuple

from .base import hermite_slope, hermite_tangent, Neighbour
from ..geometry import norm, Vector
from ..toi import _kernel


def quintic_coefficients(chord: float, b: float, c: float, slope1: float,
                         bend1: float) -> Tuple[float, float, float]:
    """
    Return a quintic Hermite's power coefficients d, e, f (of s^3, s^4, s^5) given the rest.

    The kernel's (``toi._kernel``'s ``quintic_hermite``, the same operations): chord = p1 - p0,
    b = h m0, c = h^2 g0 / 2, slope1 = h m1 and bend1 = h^2 g1 (m the end rates, g the end
    second derivatives), from d + e + f = chord - b - c, 3 d + 4 e + 5 f = slope1 - b - 2 c and
    6 d + 12 e + 20 f = bend1 - 2 c.
    """
    value, slope, bend = chord - b - c, slope1 - b - 2.0 * c, bend1 - 2.0 * c
    return (10.0 * value - 4.0 * slope + 0.5 * bend, -15.0 * value + 7.0 * slope - bend,
            6.0 * value - 3.0 * slope + 0.5 * bend)


SPAN_BULGE = (0.25, 0.38491, 0.4725, 0.535)
"""The largest |s^k - s| over [0, 1] for k = 2 .. 5, rounded up (a piece's bulge per
coefficient): 1/4, then k^(-k/(k-1)) - k^(-1/(k-1)) in size."""


def quintic_bend_bound(c: Sequence[float], d: Sequence[float], e: Sequence[float],
                       f: Sequence[float], sa: float, sb: float) -> float:
    """
    Return a bound on max |p''| h^2 over [sa, sb] (in steps) of a quintic's coordinates.

    p'' h^2 = 2 c + 6 d s + 12 e s^2 + 20 f s^3, by Taylor's theorem about sa:
    |p''(sa)| + |p^(3)(sa)| (sb - sa) + max |p^(4)| (sb - sa)^2 / 2, p^(4) h^4 = 24 e + 120 f s
    linear, so at an end (the kernel's ``quintic_bend_bound``).
    """
    span = sb - sa
    bend = jerk = snap_a = snap_b = 0.0
    for ci, di, ei, fi in zip(c, d, e, f):
        second = 2.0 * ci + sa * (6.0 * di + sa * (12.0 * ei + sa * 20.0 * fi))
        third = 6.0 * di + sa * (24.0 * ei + sa * 60.0 * fi)
        fourth_a, fourth_b = 24.0 * ei + 120.0 * fi * sa, 24.0 * ei + 120.0 * fi * sb
        bend += second * second
        jerk += third * third
        snap_a += fourth_a * fourth_a
        snap_b += fourth_b * fourth_b
    return (math.sqrt(bend) + math.sqrt(jerk) * span
            + max(math.sqrt(snap_a), math.sqrt(snap_b)) * span * span * 0.5)


class PointPath:
    """
    A point moving over one sample interval [t0, t1]: linear, or Hermite (cubic, quintic).

    ``centre`` and ``radius`` (metres) bound the whole path by a sphere (a ``MotionPath``).

    :param t0, t1: interval ends (seconds), t1 > t0.
    :param p0, p1: positions at the ends (metres).
    :param m0, m1: velocities at the ends (m/s) for a cubic; both None for the chord.
    :param g0, g1: accelerations at the ends (m/s^2) too for a quintic.
    """

    __slots__ = ('t0', 't1', 'h', 'a', 'b', 'c', 'd', 'e', 'f', 'curved', 'end', 'centre',
                 'radius', 'accel0', 'accel_rate', 'bulge')

    def __init__(self, t0: float, t1: float, p0: Vector, p1: Vector,
                 m0: Optional[Vector] = None, m1: Optional[Vector] = None,
                 g0: Optional[Vector] = None, g1: Optional[Vector] = None) -> None:
        # in the kernel (``toi._kernel.point_path_init``, the same operations in this order):
        # the power basis in s = (t - t0) / h, p = a + b s + c s^2 + d s^3 with b = h m0,
        # h m1 as m, c = 3 chord - 2 b - m, d = b + m - 2 chord; p''(t) = accel0 + accel_rate s
        # with accel0 = 2 c / h^2, accel_rate = 6 d / h^2; p(s) - chord(s) = c (s^2 - s) +
        # d (s^3 - s), |s^2 - s| <= 1/4 and |s^3 - s| <= 0.3849002, so bulge = 0.25 |c| +
        # 0.38491 |d|; a chord: b = the chord, c = d = 0, bulge 0; centre: the chord's middle,
        # radius: half the chord plus the bulge; e = f = None. A quintic (g0, g1 given too):
        # c = h^2 g0 / 2, d, e, f from ``quintic_coefficients``, accel0 = g0, accel_rate =
        # 6 d / h^2 (p'' = accel0 + accel_rate s + ...), bulge: ``SPAN_BULGE`` times |c| .. |f|
        if g0 is None or g1 is None:
            _kernel.point_path_init(self, t0, t1, p0, p1, m0, m1)
        else:
            _kernel.point_path_init(self, t0, t1, p0, p1, m0, m1, g0, g1)

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
        a, b, c, d, e = self.a, self.b, self.c, self.d, self.e
        if e is not None:
            f = self.f
            return (a[0] + s * (b[0] + s * (c[0] + s * (d[0] + s * (e[0] + s * f[0])))),
                    a[1] + s * (b[1] + s * (c[1] + s * (d[1] + s * (e[1] + s * f[1])))),
                    a[2] + s * (b[2] + s * (c[2] + s * (d[2] + s * (e[2] + s * f[2])))))
        return (a[0] + s * (b[0] + s * (c[0] + s * d[0])),
                a[1] + s * (b[1] + s * (c[1] + s * d[1])),
                a[2] + s * (b[2] + s * (c[2] + s * d[2])))

    def velocity(self, t: float) -> Vector:
        """Return the time derivative of the position (m/s) at time t (seconds)."""
        s = (t - self.t0) / self.h
        b, c, d, e, f = self.b, self.c, self.d, self.e, self.f
        if e is not None:
            return tuple((b[i] + s * (2.0 * c[i] + s * (3.0 * d[i] + s * (
                4.0 * e[i] + 5.0 * s * f[i])))) / self.h for i in range(3))
        return tuple((b[i] + s * (2.0 * c[i] + 3.0 * s * d[i])) / self.h for i in range(3))

    def max_acceleration(self, ta: float, tb: float) -> float:
        """
        Return the largest |p''| (m/s^2) over [ta, tb]: at an end, p'' being linear in t.

        A quintic's: ``quintic_bend_bound`` over h^2 (a bound, not the largest).
        """
        if not self.curved:
            return 0.0
        if self.e is not None:
            return quintic_bend_bound(self.c, self.d, self.e, self.f, (ta - self.t0) / self.h,
                                      (tb - self.t0) / self.h) / (self.h * self.h)
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
    An angle (rad) over one sample interval [t0, t1]: linear, or Hermite (cubic, quintic).

    (Also any scalar of a path: ``c2``'s bat length, in metres.)

    :param t0, t1: interval ends (seconds), t1 > t0.
    :param v0, v1: angles at the ends (rad).
    :param m0, m1: rates at the ends (rad/s) for a cubic; both None for a uniform turn.
    :param g0, g1: their rates too (rad/s^2) for a quintic.
    :ivar bulge: a bound (rad) on how far the angle leaves uniform speed over the interval.
    """

    __slots__ = ('t0', 't1', 'h', 'a', 'b', 'c', 'd', 'e', 'f', 'curved', 'end', 'accel0',
                 'accel_rate', 'bulge')

    def __init__(self, t0: float, t1: float, v0: float, v1: float,
                 m0: Optional[float] = None, m1: Optional[float] = None,
                 g0: Optional[float] = None, g1: Optional[float] = None) -> None:
        # (the kernel's ``fill_angle_cubic`` makes the same slots by the same operations)
        self.t0, self.t1 = t0, t1
        h = self.h = t1 - t0
        self.a = v0
        self.end = v1
        self.curved = m0 is not None and m1 is not None
        self.e = self.f = None
        chord = v1 - v0
        if self.curved and g0 is not None and g1 is not None:
            h2 = h * h
            b = self.b = h * m0
            c = self.c = 0.5 * h2 * g0
            d, e, f = self.d, self.e, self.f = quintic_coefficients(chord, b, c, h * m1, h2 * g1)
            self.accel0, self.accel_rate = g0, 6.0 * d / h2
            self.bulge = sum(w * abs(x) for w, x in zip(SPAN_BULGE, (c, d, e, f)))
        elif self.curved:
            b = self.b = h * m0
            e = h * m1
            c = self.c = 3.0 * chord - 2.0 * b - e
            d = self.d = b + e - 2.0 * chord
            h2 = h * h
            self.accel0 = 2.0 * c / h2
            self.accel_rate = 6.0 * d / h2
            self.bulge = 0.25 * abs(c) + 0.38491 * abs(d)
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
        if self.e is not None:
            return self.a + s * (self.b + s * (self.c + s * (self.d + s * (self.e + s * self.f))))
        return self.a + s * (self.b + s * (self.c + s * self.d))

    def velocity(self, t: float) -> float:
        """Return the rate (rad/s) at time t (seconds)."""
        s = (t - self.t0) / self.h
        if self.e is not None:
            return (self.b + s * (2.0 * self.c + s * (3.0 * self.d + s * (
                4.0 * self.e + 5.0 * s * self.f)))) / self.h
        return (self.b + s * (2.0 * self.c + 3.0 * s * self.d)) / self.h

    def deviation(self, ta: float, tb: float) -> float:
        """Return a bound (rad) on how far the angle leaves uniform speed over [ta, tb]."""
        if not self.curved:
            return 0.0
        if self.e is not None:
            return quintic_bend_bound((self.c,), (self.d,), (self.e,), (self.f,),
                                      (ta - self.t0) / self.h,
                                      (tb - self.t0) / self.h) / (self.h * self.h) * (
                tb - ta) ** 2 / 8.0
        worst = 0.0
        for t in (ta, tb):
            s = (t - self.t0) / self.h
            worst = max(worst, abs(self.accel0 + self.accel_rate * s))
        return worst * (tb - ta) ** 2 / 8.0
