"""
The bat over one sample interval, one class per motion model (``MotionPath`` of (knob, tip)).

* ``LinearBatPath`` (``linear``, the seed's model): knob and tip each on their chord; exact for
  the linear solver, so one sub-step.
* ``RigidBatPath`` (``rigid``): the bat keeps its shape. ``RigidPosePath`` from poses: the
  position moves linearly and the rotation by SLERP (constant angular velocity over the
  interval); ``RigidAxisPath`` from knob and tip points: the knob moves linearly, the
  knob-to-tip direction by SLERP and the length linearly. A point at lever arm rho turning by
  theta leaves its chord by rho * (1 - cos(theta / 2)) ~ rho theta^2 / 8, so n sub-steps bound
  the error by rho theta^2 / (8 n^2).
* ``SplineBatPath`` (``spline``): the bat stays rigid; its knob is a cubic through the
  neighbouring knobs, and its knob-to-tip direction turns about the interval's axis by an angle
  that is a cubic in time (rates from the neighbouring turns), so it sweeps arcs at a changing
  angular speed, as a swing does. It needs the next sample after the interval: one frame of
  latency live.

``BatPath.build`` picks the class for a model; every class answers ``at(t)`` (knob, tip) and
``deviation(ta, tb)``, a bound on how far any bat point leaves its chord over [ta, tb].
"""

import math
from typing import Optional, Tuple

from .base import BatSample, check_model, PathKind, swing_between
from .points import AngleCubic, PointPath
from ..geometry import (
    cross, dot, interpolate_pose, lerp, norm, pose_point, quaternion_angle, scale,
    slerp_vectors, sub, Vector)

Ends = Tuple[Vector, Vector]
"""(knob, tip) in metres."""

BatNeighbour = Optional[Tuple[float, BatSample]]
"""A bat sample (time in seconds, sample) next to an interval, or None."""


class BatPath:
    """
    The bat over one sample interval [t0, t1] under a motion model: the common part.

    Build one with ``BatPath.build``. ``centre`` and ``radius`` (metres) bound every axis point
    over the whole interval by a sphere: the hull of the four sample ends, grown by how far the
    model lets the bat leave its chords.
    """

    __slots__ = ('t0', 't1', 'h', 'sample0', 'sample1', 'centre', 'radius', 'angle', 'lever')
    kind: PathKind

    def __init__(self, t0: float, t1: float, sample0: BatSample, sample1: BatSample) -> None:
        self.t0, self.t1, self.h = t0, t1, t1 - t0
        self.sample0, self.sample1 = sample0, sample1
        k0, e0, k1, e1 = sample0.knob, sample0.tip, sample1.knob, sample1.tip
        centre = self.centre = (0.25 * (k0[0] + e0[0] + k1[0] + e1[0]),
                                0.25 * (k0[1] + e0[1] + k1[1] + e1[1]),
                                0.25 * (k0[2] + e0[2] + k1[2] + e1[2]))
        self.radius = max(math.dist(k0, centre), math.dist(e0, centre), math.dist(k1, centre),
                          math.dist(e1, centre))

    @staticmethod
    def build(model: str, t0: float, t1: float, sample0: BatSample, sample1: BatSample,
              before: BatNeighbour = None, after: BatNeighbour = None,
              offsets: Optional[Ends] = None) -> 'BatPath':
        """
        Return the bat's path between two samples.

        :param model: ``'linear'``, ``'rigid'`` or ``'spline'``.
        :param t0, t1: sample times (seconds), t1 > t0.
        :param sample0, sample1: the samples at t0 and t1.
        :param before: (time, sample) before t0, for spline tangents (None if absent).
        :param after: (time, sample) after t1, for spline tangents (None if absent).
        :param offsets: (knob_offset, tip_offset) in the body frame, for the rigid model from
            poses (both samples must carry a quaternion; else it turns knob-to-tip).
        :raises CoreError: an unknown model.
        """
        check_model(model)
        if model == 'rigid':
            if offsets is not None and sample0.quaternion is not None \
                    and sample1.quaternion is not None:
                return RigidPosePath(t0, t1, sample0, sample1, offsets)
            return RigidAxisPath(t0, t1, sample0, sample1)
        if model == 'spline':
            return SplineBatPath(t0, t1, sample0, sample1, before, after)
        return LinearBatPath(t0, t1, sample0, sample1)

    def at(self, t: float) -> Ends:
        """Return (knob, tip) in metres at time t (seconds)."""
        if t == self.t0:
            return self.sample0.knob, self.sample0.tip
        if t == self.t1:
            return self.sample1.knob, self.sample1.tip
        return self._inside(t)

    def _inside(self, t: float) -> Ends:
        """Return (knob, tip) at a time t strictly inside the interval."""
        raise NotImplementedError

    def deviation(self, ta: float, tb: float) -> float:
        """Return a bound (metres) on how far any bat point leaves its chord over [ta, tb]."""
        raise NotImplementedError


class LinearBatPath(BatPath):
    """``linear``: knob and tip each on their chord."""

    __slots__ = ('knob', 'tip')
    kind = PathKind.POINTS

    def __init__(self, t0: float, t1: float, sample0: BatSample, sample1: BatSample) -> None:
        super().__init__(t0, t1, sample0, sample1)
        self.knob = PointPath(t0, t1, sample0.knob, sample1.knob)
        self.tip = PointPath(t0, t1, sample0.tip, sample1.tip)

    def _inside(self, t: float) -> Ends:
        return self.knob.at(t), self.tip.at(t)

    def deviation(self, ta: float, tb: float) -> float:
        """Return 0: the chords are the path."""
        return 0.0


class RigidBatPath(BatPath):
    """``rigid``: a turn at constant angular velocity by ``angle`` (rad) on a ``lever`` (m)."""

    __slots__ = ()

    def _grow(self) -> None:
        """Grow the bounding sphere by the deviation over the whole interval."""
        self.radius += self.deviation(self.t0, self.t1)

    def deviation(self, ta: float, tb: float) -> float:
        """Return the sagitta bound lever * theta^2 / 8 of the angle theta turned over [ta, tb]."""
        theta = self.angle * (tb - ta) / self.h
        return self.lever * theta * theta / 8.0


class RigidPosePath(RigidBatPath):
    """``rigid`` from poses: position LERP and orientation SLERP, the body offsets carried."""

    __slots__ = ('knob_offset', 'tip_offset')
    kind = PathKind.POSE

    def __init__(self, t0: float, t1: float, sample0: BatSample, sample1: BatSample,
                 offsets: Ends) -> None:
        super().__init__(t0, t1, sample0, sample1)
        self.knob_offset, self.tip_offset = offsets
        self.angle = quaternion_angle(sample0.quaternion, sample1.quaternion)
        self.lever = max(norm(offsets[0]), norm(offsets[1]))
        self._grow()

    def _inside(self, t: float) -> Ends:
        s0, s1 = self.sample0, self.sample1
        origin, q = interpolate_pose(s0.position, s0.quaternion, s1.position, s1.quaternion,
                                     (t - self.t0) / self.h)
        return pose_point(origin, q, self.knob_offset), pose_point(origin, q, self.tip_offset)


class RigidAxisPath(RigidBatPath):
    """``rigid`` from knob and tip: knob LERP, knob-to-tip direction SLERP, length LERP."""

    __slots__ = ('direction0', 'direction1', 'length0', 'length1')
    kind = PathKind.AXIS

    def __init__(self, t0: float, t1: float, sample0: BatSample, sample1: BatSample) -> None:
        super().__init__(t0, t1, sample0, sample1)
        axis0 = sub(sample0.tip, sample0.knob)
        axis1 = sub(sample1.tip, sample1.knob)
        self.length0, self.length1 = norm(axis0), norm(axis1)
        self.direction0 = tuple(x / self.length0 for x in axis0)
        self.direction1 = tuple(x / self.length1 for x in axis1)
        cosine = dot(self.direction0, self.direction1)
        self.angle = math.acos(max(-1.0, min(1.0, cosine)))
        self.lever = max(self.length0, self.length1)
        self._grow()

    def _inside(self, t: float) -> Ends:
        s = (t - self.t0) / self.h
        knob = lerp(self.sample0.knob, self.sample1.knob, s)
        direction = slerp_vectors(self.direction0, self.direction1, s)
        length = self.length0 + (self.length1 - self.length0) * s
        return knob, (knob[0] + length * direction[0], knob[1] + length * direction[1],
                      knob[2] + length * direction[2])


class SplineBatPath(BatPath):
    """
    ``spline``: a rigid bat with a cubic knob, a cubic turning angle and a linear length.

    The knob follows a cubic Hermite through the neighbouring knobs. The knob-to-tip direction
    turns about the interval's own axis (d0 x d1) by an angle that is a cubic Hermite in time,
    its rates at the ends taken from the neighbouring turns (projected on that axis) by the
    three-point rule: the bat keeps its shape and sweeps arcs, and its angular speed may change
    within the interval, as a swing's does.
    """

    __slots__ = ('knob', 'turn', 'across', 'direction0', 'direction1', 'length0', 'length1')
    kind = PathKind.TURNING

    def __init__(self, t0: float, t1: float, sample0: BatSample, sample1: BatSample,
                 before: BatNeighbour = None, after: BatNeighbour = None) -> None:
        super().__init__(t0, t1, sample0, sample1)
        self.knob = PointPath.build(
            'spline', t0, t1, sample0.knob, sample1.knob,
            before=(before[0], before[1].knob) if before else None,
            after=(after[0], after[1].knob) if after else None)
        axis0, axis1 = sub(sample0.tip, sample0.knob), sub(sample1.tip, sample1.knob)
        self.length0, self.length1 = norm(axis0), norm(axis1)
        self.lever = max(self.length0, self.length1)
        d0 = self.direction0 = scale(axis0, 1.0 / self.length0)
        d1 = self.direction1 = scale(axis1, 1.0 / self.length1)
        self.turn, self.across = self._turning(d0, d1, before, after)
        bulge = self.turn.bulge
        self.radius = self.radius + self.knob.bulge + self.lever * (
            (self.angle + 2.0 * bulge) ** 2 / 8.0 + 2.0 * bulge)

    def _turning(self, d0: Vector, d1: Vector, before: BatNeighbour,
                 after: BatNeighbour) -> Tuple[AngleCubic, Vector]:
        """Return the turning angle's cubic and the direction across (d0 turned a right angle)."""
        t0, t1 = self.t0, self.t1
        turn = cross(d0, d1)
        sine = norm(turn)
        self.angle = math.atan2(sine, dot(d0, d1))
        if sine < 1e-12:  # no turn to speak of: the direction stays put
            return AngleCubic(t0, t1, 0.0, self.angle), (0.0, 0.0, 0.0)
        axis = scale(turn, 1.0 / sine)
        s0, s1 = self.sample0, self.sample1
        # the neighbours' turns about this interval's axis (rad)
        previous = (before[0], -dot(swing_between(before[1], s0), axis)) if before else None
        following = (after[0], self.angle + dot(swing_between(s1, after[1]), axis)) if after \
            else None
        return (AngleCubic.through(t0, t1, 0.0, self.angle, previous, following),
                cross(axis, d0))

    def _inside(self, t: float) -> Ends:
        s = (t - self.t0) / self.h
        knob = self.knob.at(t)
        angle = self.turn.at(t)
        length = self.length0 + (self.length1 - self.length0) * s
        c, n = math.cos(angle) * length, math.sin(angle) * length
        d0, across = self.direction0, self.across
        return knob, (knob[0] + c * d0[0] + n * across[0], knob[1] + c * d0[1] + n * across[1],
                      knob[2] + c * d0[2] + n * across[2])

    def deviation(self, ta: float, tb: float) -> float:
        """
        Return the bound over [ta, tb].

        The arc's sagitta over the angle swept, plus the angle's own departure from uniform
        speed (a cubic in time), on the bat's lever; plus the knob's and the length's.
        """
        sweep = abs(self.turn.at(tb) - self.turn.at(ta))
        uneven = self.turn.deviation(ta, tb)
        length_change = abs(self.length1 - self.length0)
        return (self.knob.deviation(ta, tb) + self.lever * (sweep * sweep / 8.0 + uneven)
                + length_change)
