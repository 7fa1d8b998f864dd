"""
Motion between samples: the linear, rigid and spline models.

Pure Python (no numpy in the hot path, no ROS). Times are float seconds on the detector's own
clock, positions metres. Every path here covers ONE sample interval of one stream,
``[t0, t1]``, and answers two questions: where is it at time t, and into how many equal
sub-steps must ``[ta, tb]`` be cut so that moving linearly between sub-step ends stays within a
chord error tolerance. The detector then runs the exact linear solver on each sub-step.

* ``linear``: the seed's model. Every point moves on the chord between its samples; exact for
  the linear solver, so one sub-step.
* ``rigid``: the bat keeps its shape. From a pose, the position moves linearly and the rotation
  by SLERP (constant angular velocity over the interval); from knob and tip points, the knob
  moves linearly, the knob-to-tip direction by SLERP and the length linearly. A point at lever
  arm rho turning by theta leaves its chord by rho * (1 - cos(theta / 2)) ~ rho theta^2 / 8, so
  n sub-steps bound the error by rho theta^2 / (8 n^2). The ball moves linearly.
* ``spline``: cubic Hermite interpolation through the neighbouring samples, with the tangent at
  each sample from the parabola through it and its two neighbours (exact for a quadratic, also
  on uneven stamps). The ball's position is a cubic. The bat stays rigid: its knob is a cubic,
  and its knob-to-tip direction turns about the interval's axis by an angle that is a cubic in
  time (rates from the neighbouring turns), so it sweeps arcs at a changing angular speed, as a
  swing does. A curve leaves its chord by at most max|p''| h^2 / 8. It needs the next sample
  after the interval: one frame of latency live.
"""

from dataclasses import dataclass
import math
from typing import Optional, Tuple

from ..geometry import (
    cross, dot, lerp, norm, Quaternion, quaternion_angle, rotate, scale, slerp_quaternions,
    slerp_vectors, sub, swing_rotation, Vector)
from ...errors import CoreError

MODELS = ('linear', 'rigid', 'spline')
"""The motion model names."""


@dataclass(frozen=True)
class BatSample:
    """
    One bat sample: knob and tip (metres), and the pose when the bat came as a pose.

    :ivar knob: knob end, world frame.
    :ivar tip: barrel end, world frame.
    :ivar position: pose origin (pose input only).
    :ivar quaternion: pose orientation, unit, ROS order (x, y, z, w) (pose input only).
    """

    knob: Vector
    tip: Vector
    position: Optional[Vector] = None
    quaternion: Optional[Quaternion] = None


def check_model(model: str) -> str:
    """
    Return ``model`` if it names a motion model.

    :raises CoreError: for any other name.
    """
    if model not in MODELS:
        raise CoreError(f"motion model must be one of {', '.join(MODELS)}, got '{model}'")
    return model


def hermite_tangent(t_prev: Optional[float], p_prev: Optional[Vector], t: float, p: Vector,
                    t_next: Optional[float], p_next: Optional[Vector]) -> Vector:
    """
    Return the velocity at sample (t, p) from its neighbours (metres per second).

    With both neighbours, the derivative at t of the parabola through the three samples
    (second-order accurate on uneven stamps); with one, the chord to it; with none, zero.
    """
    if p_prev is not None and p_next is not None:
        h0, h1 = t - t_prev, t_next - t
        w_prev = h1 / (h0 * (h0 + h1))
        w_next = h0 / (h1 * (h0 + h1))
        w_here = w_prev - w_next
        return (w_next * p_next[0] + w_here * p[0] - w_prev * p_prev[0],
                w_next * p_next[1] + w_here * p[1] - w_prev * p_prev[1],
                w_next * p_next[2] + w_here * p[2] - w_prev * p_prev[2])
    if p_next is not None:
        inverse = 1.0 / (t_next - t)
        return ((p_next[0] - p[0]) * inverse, (p_next[1] - p[1]) * inverse,
                (p_next[2] - p[2]) * inverse)
    if p_prev is not None:
        inverse = 1.0 / (t - t_prev)
        return ((p[0] - p_prev[0]) * inverse, (p[1] - p_prev[1]) * inverse,
                (p[2] - p_prev[2]) * inverse)
    return (0.0, 0.0, 0.0)


def substeps_for(deviation_bound: float, tolerance: float) -> int:
    """Return sub-steps n so that deviation_bound / n^2 <= tolerance (at least 1)."""
    if deviation_bound <= tolerance:
        return 1
    return int(math.ceil(math.sqrt(deviation_bound / tolerance)))


# ----------------------------------------------------------------------------------------------
# point paths


class PointPath:
    """
    A point moving over one sample interval [t0, t1]: linear, or cubic Hermite with tangents.

    ``centre`` and ``radius`` (metres) bound the whole path by a sphere.

    :param t0, t1: interval ends (seconds), t1 > t0.
    :param p0, p1: positions at the ends (metres).
    :param m0, m1: velocities at the ends (m/s) for a cubic; both None for the chord.
    """

    __slots__ = ('t0', 't1', 'h', 'a', 'b', 'c', 'd', 'curved', 'end', 'centre', 'radius',
                 'accel0', 'accel_rate', 'bulge')

    def __init__(self, t0: float, t1: float, p0: Vector, p1: Vector,
                 m0: Optional[Vector] = None, m1: Optional[Vector] = None) -> None:
        self.t0, self.t1 = t0, t1
        h = self.h = t1 - t0
        self.a = p0
        self.end = p1
        self.curved = m0 is not None and m1 is not None
        chord = sub(p1, p0)
        if self.curved:
            # power basis in s = (t - t0) / h: p = a + b s + c s^2 + d s^3
            b = self.b = (h * m0[0], h * m0[1], h * m0[2])
            e = (h * m1[0], h * m1[1], h * m1[2])
            c = self.c = (3.0 * chord[0] - 2.0 * b[0] - e[0], 3.0 * chord[1] - 2.0 * b[1] - e[1],
                          3.0 * chord[2] - 2.0 * b[2] - e[2])
            d = self.d = (b[0] + e[0] - 2.0 * chord[0], b[1] + e[1] - 2.0 * chord[1],
                          b[2] + e[2] - 2.0 * chord[2])
            # p''(t) = accel0 + accel_rate * s (m/s^2)
            h2 = h * h
            self.accel0 = (2.0 * c[0] / h2, 2.0 * c[1] / h2, 2.0 * c[2] / h2)
            self.accel_rate = (6.0 * d[0] / h2, 6.0 * d[1] / h2, 6.0 * d[2] / h2)
            # p(s) - chord(s) = c (s^2 - s) + d (s^3 - s); |s^2 - s| <= 1/4, |s^3 - s| <= 0.385
            self.bulge = 0.25 * norm(c) + 0.3849 * norm(d)
        else:
            self.b = chord
            self.c = self.d = (0.0, 0.0, 0.0)
            self.bulge = 0.0
        self.centre = lerp(p0, p1, 0.5)
        self.radius = 0.5 * norm(chord) + self.bulge

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

    def deviation(self, ta: float, tb: float) -> float:
        """Return a bound (metres) on how far the path leaves its chord over [ta, tb]."""
        if not self.curved:
            return 0.0
        # p'' is linear in t on a cubic: its largest value over [ta, tb] is at an end
        a0, rate = self.accel0, self.accel_rate
        worst = 0.0
        for t in (ta, tb):
            s = (t - self.t0) / self.h
            worst = max(worst, norm((a0[0] + rate[0] * s, a0[1] + rate[1] * s,
                                     a0[2] + rate[2] * s)))
        return worst * (tb - ta) ** 2 / 8.0


# ----------------------------------------------------------------------------------------------
# bat paths


class BatPath:
    """
    The bat over one sample interval [t0, t1] under a motion model.

    Build it with ``BatPath.build``; ``at(t)`` gives (knob, tip) and ``deviation(ta, tb)`` a
    bound on how far any bat point leaves its chord over [ta, tb]. ``centre`` and ``radius``
    (metres) bound every axis point over the whole interval by a sphere: the hull of the four
    sample ends, grown by the deviation.
    """

    __slots__ = ('t0', 't1', 'h', 'kind', 'knob', 'tip', 'sample0', 'sample1', 'direction0',
                 'direction1', 'length0', 'length1', 'angle', 'lever', 'knob_offset',
                 'tip_offset', 'centre', 'radius', 'turn_axis', 'across', 'turn')

    @classmethod
    def build(cls, model: str, t0: float, t1: float, sample0: BatSample, sample1: BatSample,
              before: Optional[Tuple[float, BatSample]] = None,
              after: Optional[Tuple[float, BatSample]] = None,
              offsets: Optional[Tuple[Vector, Vector]] = None) -> 'BatPath':
        """
        Return the bat's path between two samples.

        :param model: ``'linear'``, ``'rigid'`` or ``'spline'``.
        :param t0, t1: sample times (seconds), t1 > t0.
        :param sample0, sample1: the samples at t0 and t1.
        :param before: (time, sample) before t0, for spline tangents (None if absent).
        :param after: (time, sample) after t1, for spline tangents (None if absent).
        :param offsets: (knob_offset, tip_offset) in the body frame, for the rigid model from
            poses (both samples must carry a quaternion).
        :raises CoreError: an unknown model.
        """
        path = cls()
        path.t0, path.t1, path.h = t0, t1, t1 - t0
        path.sample0, path.sample1 = sample0, sample1
        check_model(model)
        k0, e0, k1, e1 = sample0.knob, sample0.tip, sample1.knob, sample1.tip
        centre = path.centre = (0.25 * (k0[0] + e0[0] + k1[0] + e1[0]),
                                0.25 * (k0[1] + e0[1] + k1[1] + e1[1]),
                                0.25 * (k0[2] + e0[2] + k1[2] + e1[2]))
        hull = max(math.dist(k0, centre), math.dist(e0, centre), math.dist(k1, centre),
                   math.dist(e1, centre))
        if model == 'rigid':
            if offsets is not None and sample0.quaternion is not None \
                    and sample1.quaternion is not None:
                path.kind = 'pose'
                path.knob_offset, path.tip_offset = offsets
                path.angle = quaternion_angle(sample0.quaternion, sample1.quaternion)
                path.lever = max(norm(offsets[0]), norm(offsets[1]))
            else:
                path.kind = 'axis'
                axis0 = sub(sample0.tip, sample0.knob)
                axis1 = sub(sample1.tip, sample1.knob)
                path.length0, path.length1 = norm(axis0), norm(axis1)
                path.direction0 = tuple(x / path.length0 for x in axis0)
                path.direction1 = tuple(x / path.length1 for x in axis1)
                cosine = dot(path.direction0, path.direction1)
                path.angle = math.acos(max(-1.0, min(1.0, cosine)))
                path.lever = max(path.length0, path.length1)
            path.radius = hull + path.deviation(t0, t1)
            return path
        if model == 'spline':
            path._build_turning(before, after)
            path.radius = hull + path.knob.bulge + path.lever * (
                (path.angle + 2.0 * path.turn.bulge) ** 2 / 8.0 + 2.0 * path.turn.bulge)
            return path
        path.kind = 'points'
        path.knob = PointPath(t0, t1, k0, k1)
        path.tip = PointPath(t0, t1, e0, e1)
        path.radius = hull
        return path

    def _build_turning(self, before: Optional[Tuple[float, BatSample]],
                       after: Optional[Tuple[float, BatSample]]) -> None:
        """
        Set up the spline of a rigid bat: cubic knob, cubic turning angle, linear length.

        The knob follows a cubic Hermite through the neighbouring knobs. The knob-to-tip
        direction turns about the interval's own axis (d0 x d1) by an angle that is a cubic
        Hermite in time, its rates at the ends taken from the neighbouring turns (projected on
        that axis) by the three-point rule: the bat keeps its shape and sweeps arcs, and its
        angular speed may change within the interval, as a swing's does.
        """
        self.kind = 'turning'
        t0, t1 = self.t0, self.t1
        s0, s1 = self.sample0, self.sample1
        tb = before[0] if before else None
        ta = after[0] if after else None
        self.knob = PointPath(
            t0, t1, s0.knob, s1.knob,
            hermite_tangent(tb, before[1].knob if before else None, t0, s0.knob, t1, s1.knob),
            hermite_tangent(t0, s0.knob, t1, s1.knob, ta, after[1].knob if after else None))
        axis0, axis1 = sub(s0.tip, s0.knob), sub(s1.tip, s1.knob)
        self.length0, self.length1 = norm(axis0), norm(axis1)
        self.lever = max(self.length0, self.length1)
        d0 = self.direction0 = scale(axis0, 1.0 / self.length0)
        d1 = self.direction1 = scale(axis1, 1.0 / self.length1)
        turn = cross(d0, d1)
        sine = norm(turn)
        self.angle = math.atan2(sine, dot(d0, d1))
        if sine < 1e-12:  # no turn to speak of: the direction stays put
            self.turn_axis = (0.0, 0.0, 0.0)
            self.across = (0.0, 0.0, 0.0)
            self.turn = PointPath(t0, t1, (0.0, 0.0, 0.0), (self.angle, 0.0, 0.0))
            return
        axis = self.turn_axis = scale(turn, 1.0 / sine)
        self.across = cross(axis, d0)

        def turned(a: BatSample, b: BatSample) -> float:
            """Return the angle (rad) the bat turned from a to b, about this interval's axis."""
            return dot(swing_rotation(sub(a.tip, a.knob), sub(b.tip, b.knob)), axis)
        previous = (tb, (-turned(before[1], s0), 0.0, 0.0)) if before else (None, None)
        following = (ta, (self.angle + turned(s1, after[1]), 0.0, 0.0)) if after \
            else (None, None)
        start, end = (0.0, 0.0, 0.0), (self.angle, 0.0, 0.0)
        self.turn = PointPath(t0, t1, start, end,
                              hermite_tangent(previous[0], previous[1], t0, start, t1, end),
                              hermite_tangent(t0, start, t1, end, following[0], following[1]))

    def at(self, t: float) -> Tuple[Vector, Vector]:
        """Return (knob, tip) in metres at time t (seconds)."""
        if t == self.t0:
            return self.sample0.knob, self.sample0.tip
        if t == self.t1:
            return self.sample1.knob, self.sample1.tip
        if self.kind == 'points':
            return self.knob.at(t), self.tip.at(t)
        s = (t - self.t0) / self.h
        if self.kind == 'turning':
            knob = self.knob.at(t)
            angle = self.turn.at(t)[0]
            length = self.length0 + (self.length1 - self.length0) * s
            c, n = math.cos(angle) * length, math.sin(angle) * length
            d0, across = self.direction0, self.across
            return knob, (knob[0] + c * d0[0] + n * across[0], knob[1] + c * d0[1] + n * across[1],
                          knob[2] + c * d0[2] + n * across[2])
        if self.kind == 'pose':
            q = slerp_quaternions(self.sample0.quaternion, self.sample1.quaternion, s)
            origin = lerp(self.sample0.position, self.sample1.position, s)
            knob_arm = rotate(q, self.knob_offset)
            tip_arm = rotate(q, self.tip_offset)
            return ((origin[0] + knob_arm[0], origin[1] + knob_arm[1], origin[2] + knob_arm[2]),
                    (origin[0] + tip_arm[0], origin[1] + tip_arm[1], origin[2] + tip_arm[2]))
        knob = lerp(self.sample0.knob, self.sample1.knob, s)
        direction = slerp_vectors(self.direction0, self.direction1, s)
        length = self.length0 + (self.length1 - self.length0) * s
        return knob, (knob[0] + length * direction[0], knob[1] + length * direction[1],
                      knob[2] + length * direction[2])

    def deviation(self, ta: float, tb: float) -> float:
        """Return a bound (metres) on how far any bat point leaves its chord over [ta, tb]."""
        if self.kind == 'points':
            return max(self.knob.deviation(ta, tb), self.tip.deviation(ta, tb))
        if self.kind == 'turning':
            # the arc's sagitta over the angle swept, plus the angle's own departure from
            # uniform speed (a cubic in time), on the bat's lever
            sweep = abs(self.turn.at(tb)[0] - self.turn.at(ta)[0])
            uneven = self.turn.deviation(ta, tb)
            length_change = abs(self.length1 - self.length0)
            return (self.knob.deviation(ta, tb) + self.lever * (sweep * sweep / 8.0 + uneven)
                    + length_change)
        theta = self.angle * (tb - ta) / self.h
        return self.lever * theta * theta / 8.0
