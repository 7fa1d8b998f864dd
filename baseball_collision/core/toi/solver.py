"""
Exact time of impact between a ball (sphere) and a bat (capsule or a profile of capsules).

Pure Python + numpy; no ROS imports. Units: metres and seconds.

Model: over one interval of ``dt`` seconds the ball centre ``B``, the bat tip (barrel end) ``E``
and the knob ``S`` each move linearly from their ``*0`` to their ``*1`` positions. The bat is the
segment S-E thickened by ``bat_radius`` (a capsule: rounded ends); the ball has ``ball_radius``.
With ``R = ball_radius + bat_radius``, ``u = E - S`` and ``w = B - S`` (both degree 1 in time):

* side of the bat (the projection ``lambda = w.u / u.u`` in [0, 1]):
  ``|w x u|^2 - R^2 |u|^2 = 0``, the seed derivation's quartic (its Eq. 15f);
* knob end (lambda < 0): ``|w|^2 - R^2 = 0``; tip end (lambda > 1): ``|w - u|^2 - R^2 = 0``.

The gap is continuous in time, so first contact is the earliest time in [0, dt] at which one of
these three polynomials enters <= 0 while its region condition holds (0 if touching at the start).
Each polynomial is solved on its monotone pieces found by the derivative chain (roots of P'' in
closed form bound the monotone pieces of P'; their roots are the critical points of P), so a
tangential touch (a double root, which ``numpy.roots`` returns as a complex pair) is never lost:
at every local minimum the gap itself is compared with ``TOUCH_TOLERANCE``. Roots are refined by
safeguarded Newton in the scalar path and by bisection to full precision in the batch path.
Coordinates are shifted to the knob's start and scaled to the interval's extent, and time is
normalised to [0, 1], before any coefficient is formed.

Precision: contact times are exact to a few ulps of dt wherever the bodies have volume. With
both radii zero (a point against a segment) contact is a double root of a squared distance and
its time is only good to about sqrt(machine epsilon) of the interval's scale.
"""

from dataclasses import dataclass
import math
from typing import Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from ..bat import BatProfile
from ..geometry import advance, cross, dot, lerp, scale, sub, Vector
from ...errors import CoreError

TOUCH_TOLERANCE = 1e-9
"""A gap (metres) at or below which ball and bat count as touching."""

ArrayLike = Union[Sequence[float], np.ndarray]

_DEGENERATE_AXIS = 1e-24  # |u|^2 in scaled units below which the bat has no axis (a sphere)
_ROOT_SLACK = 1e-10  # scaled gap allowed at a side root for rounding (0.1 nm on a 1 m scale)


@dataclass(frozen=True)
class ImpactResult:
    """
    First contact between ball and bat within one interval.

    :ivar time: seconds from the interval start to first contact (0.0 when touching at the start).
    :ivar point: contact point on the bat surface, world frame (metres).
    :ivar normal: unit vector from the bat axis towards the ball centre at contact.
    :ivar bat_fraction: where along the bat axis, 0 at the knob and 1 at the tip.
    :ivar initially_overlapping: ball and bat were already touching or overlapping at time 0.
    :ivar gap: signed surface gap at ``time`` (metres): ~0 at a fresh contact, negative when
        overlapping at the start, within (0, TOUCH_TOLERANCE] for a graze.
    :ivar feature: ``'side'``, ``'knob_end'`` or ``'tip_end'``: the part of the bat that was hit.
    """

    time: float
    point: Vector
    normal: Vector
    bat_fraction: float
    initially_overlapping: bool
    gap: float
    feature: str


# ----------------------------------------------------------------------------------------------
# Input checking


def _point(name: str, value: ArrayLike) -> Vector:
    try:
        x, y, z = (float(v) for v in value)
    except (TypeError, ValueError) as error:
        raise CoreError(f'{name} must be 3 numbers (metres), got {value!r}') from error
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
        raise CoreError(f'{name} must be finite, got {value!r}')
    return (x, y, z)


def _non_negative(name: str, value: float) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError) as error:
        raise CoreError(f'{name} must be a number, got {value!r}') from error
    if not (math.isfinite(number) and number >= 0.0):
        raise CoreError(f'{name} must be finite and >= 0, got {value!r}')
    return number


def _interval(dt: float) -> float:
    number = _non_negative('dt', dt)
    if number <= 0.0:
        raise CoreError(f'dt must be > 0 seconds, got {dt!r}')
    return number


# ----------------------------------------------------------------------------------------------
# Polynomials on [0, 1], coefficients lowest power first (c0, c1, c2, c3, c4)


def _eval(c: Sequence[float], x: float) -> float:
    return c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * c[4])))


def _eval_d1(c: Sequence[float], x: float) -> float:
    return c[1] + x * (2.0 * c[2] + x * (3.0 * c[3] + x * 4.0 * c[4]))


def _eval_d2(c: Sequence[float], x: float) -> float:
    return 2.0 * c[2] + x * (6.0 * c[3] + x * 12.0 * c[4])


def _quadratic_roots(a: float, b: float, c: float) -> List[float]:
    """Real roots of a x^2 + b x + c in ascending order (numerically stable form)."""
    if a == 0.0:
        return [] if b == 0.0 else [-c / b]
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return []
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    if q == 0.0:
        return [0.0, 0.0]
    r1, r2 = q / a, c / q
    return [r1, r2] if r1 <= r2 else [r2, r1]


def _bracketed_root(f, df, lo: float, hi: float, f_lo: float) -> float:
    """
    Root of f, monotone on [lo, hi] and changing sign there, to double precision.

    Newton steps safeguarded by bisection: a step leaving the bracket is replaced by halving.
    ``f_lo`` is f(lo) (not zero); the bracket keeps f(lo) on that side of zero.
    """
    positive = f_lo > 0.0
    x = 0.5 * (lo + hi)
    for _ in range(200):
        fx = f(x)
        if fx == 0.0:
            return x
        if (fx > 0.0) == positive:
            lo = x
        else:
            hi = x
        slope = df(x)
        step = fx / slope if slope != 0.0 else math.inf
        candidate = x - step
        if not lo < candidate < hi:
            candidate = 0.5 * (lo + hi)
        if abs(candidate - x) <= 1e-16 or hi - lo <= 2e-16:
            return candidate
        x = candidate
    return x


def _critical_points(c: Sequence[float]) -> List[float]:
    """
    Points in (0, 1) where the quartic c changes direction, ascending (derivative chain).

    The roots of c'' (closed form) split [0, 1] into pieces on which c' is monotone; a sign
    change of c' over a piece brackets its single root there. A zero of c' exactly at an
    inflection is a stationary inflection, where c keeps its direction, so it is skipped.
    """
    inflections = [x for x in _quadratic_roots(12.0 * c[4], 6.0 * c[3], 2.0 * c[2])
                   if 0.0 < x < 1.0]
    bounds = [0.0] + inflections + [1.0]
    critical = []
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        d_lo, d_hi = _eval_d1(c, lo), _eval_d1(c, hi)
        if (d_lo < 0.0 and d_hi > 0.0) or (d_lo > 0.0 and d_hi < 0.0):
            critical.append(_bracketed_root(
                lambda x: _eval_d1(c, x), lambda x: _eval_d2(c, x), lo, hi, d_lo))
    return critical


def _touch_candidates(c: Sequence[float], slack) -> Iterator[float]:
    """
    Yield the times in [0, 1] at which a gap polynomial starts to count as contact, in order.

    ``c`` is a quartic whose sign is the sign of (distance^2 - R^2) for one feature; ``slack(x)``
    is the value of c that corresponds to a gap of TOUCH_TOLERANCE at x. Yields 0 when touching
    at the start, each root where c enters <= 0, and each local minimum at which c stays within
    ``slack`` without crossing (a graze).
    """
    a = 0.0
    f_a = _eval(c, 0.0)
    if f_a <= slack(0.0):
        yield 0.0
    for b in _critical_points(c) + [1.0]:
        f_b = _eval(c, b)
        if f_a > 0.0 and f_b <= 0.0:
            yield _bracketed_root(lambda x: _eval(c, x), lambda x: _eval_d1(c, x), a, b, f_a)
        elif 0.0 < f_b < f_a and f_b <= slack(b):
            yield b
        a, f_a = b, f_b


# ----------------------------------------------------------------------------------------------
# The scalar solver


@dataclass(frozen=True)
class _Scaled:
    """One interval in scaled coordinates: w = B - S and u = E - S as w0 + w1 tau, u0 + u1 tau."""

    w0: Vector
    w1: Vector
    u0: Vector
    u1: Vector
    scale: float


def _quadratic_entry(a: float, b: float, c: float, slack: float) -> Optional[float]:
    """
    First tau in [0, 1] at which a tau^2 + b tau + c (a >= 0) counts as contact, or None.

    Contact: the value is <= 0, or a local minimum stays within ``slack`` (a graze). This is
    ``_touch_candidates`` in closed form for the end caps' quadratics.
    """
    if c <= slack:
        return 0.0
    if a > 0.0:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0 and b < 0.0:
            q = -0.5 * (b - math.sqrt(disc))
            root = min(q / a, c / q)
            if root <= 1.0:
                return root
        vertex = min(1.0, -0.5 * b / a)
    else:
        vertex = 1.0 if b < 0.0 else 0.0
    if vertex > 0.0 and a * vertex * vertex + b * vertex + c <= slack:
        return vertex
    return None


def _scaled(ball0: Vector, ball1: Vector, tip0: Vector, tip1: Vector, knob0: Vector,
            knob1: Vector, radius: float) -> _Scaled:
    w0 = sub(ball0, knob0)
    w_end = sub(ball1, knob1)
    u0 = sub(tip0, knob0)
    u_end = sub(tip1, knob1)
    extent = max(abs(v) for v in w0 + w_end + u0 + u_end + (radius,))
    if extent == 0.0:
        extent = 1.0
    inv = 1.0 / extent
    w0s, wes, u0s, ues = scale(w0, inv), scale(w_end, inv), scale(u0, inv), scale(u_end, inv)
    return _Scaled(w0s, sub(wes, w0s), u0s, sub(ues, u0s), extent)


def _side_quartic(s: _Scaled, rr: float) -> Tuple[Tuple[float, ...], Tuple[float, ...]]:
    """Coefficients of |w x u|^2 - rr |u|^2 (the seed's Eq. 15f) and of |u|^2."""
    c0 = cross(s.w0, s.u0)
    c1 = sub(cross(s.w0, s.u1), cross(s.u0, s.w1))
    c2 = cross(s.w1, s.u1)
    uu = (dot(s.u0, s.u0), 2.0 * dot(s.u0, s.u1), dot(s.u1, s.u1), 0.0, 0.0)
    quartic = (
        dot(c0, c0) - rr * uu[0],
        2.0 * dot(c0, c1) - rr * uu[1],
        dot(c1, c1) + 2.0 * dot(c0, c2) - rr * uu[2],
        2.0 * dot(c1, c2),
        dot(c2, c2),
    )
    return quartic, uu


def _first_contact_tau(s: _Scaled, radius: float) -> Optional[float]:
    """Earliest tau in [0, 1] of contact (gap <= TOUCH_TOLERANCE) with the capsule, or None."""
    r = radius / s.scale
    rr = r * r
    tol = TOUCH_TOLERANCE / s.scale
    cap_slack = (r + tol) * (r + tol) - rr  # products overflow to inf; ** would raise
    best = None
    v0, v1 = sub(s.w0, s.u0), sub(s.w1, s.u1)
    for p0, p1 in ((s.w0, s.w1), (v0, v1)):
        tau = _quadratic_entry(dot(p1, p1), 2.0 * dot(p0, p1), dot(p0, p0) - rr, cap_slack)
        if tau is not None and (best is None or tau < best):
            best = tau
    if best:
        best = _polish(s, best, r)
    quartic, uu = _side_quartic(s, rr)
    if max(uu[0], abs(uu[1]), uu[2]) <= _DEGENERATE_AXIS:
        return best  # zero-length bat: a sphere, the end caps say it all
    wu = (dot(s.w0, s.u0), dot(s.w0, s.u1) + dot(s.w1, s.u0), dot(s.w1, s.u1), 0.0, 0.0)
    for tau in _touch_candidates(quartic, lambda x: cap_slack * _eval(uu, x)):
        if best is not None and tau >= best:
            break
        axis2 = _eval(uu, tau)
        along = _eval(wu, tau)
        if axis2 <= _DEGENERATE_AXIS or not 0.0 <= along <= axis2:
            continue
        # The quartic also vanishes where the bat's length passes through zero; the gap itself,
        # at the polished root, confirms a root is a touch of the side.
        polished = _polish(s, tau, r) if tau > 0.0 else tau
        if _scaled_gap(s, polished, r)[0] <= tol + _ROOT_SLACK:
            return polished if best is None else min(best, polished)
    return best


def _scaled_gap(s: _Scaled, tau: float, r: float) -> Tuple[float, float]:
    """Gap between ball and capsule at tau, and its rate d(gap)/d(tau), in scaled units."""
    w = advance(s.w0, s.w1, tau)
    u = advance(s.u0, s.u1, tau)
    fraction, closest = _closest_on_axis(w, (0.0, 0.0, 0.0), u)
    offset = sub(w, closest)
    length = math.sqrt(dot(offset, offset))
    if length == 0.0:
        return -r, 0.0
    # the closest point slides along the axis, but offset is normal to it: only the motion of
    # the ball relative to the bat point at that fraction changes the gap to first order
    rate = dot(offset, sub(s.w1, scale(s.u1, fraction))) / length
    return length - r, rate


def _polish(s: _Scaled, tau: float, r: float) -> float:
    """
    Refine a crossing root with Newton steps on the gap itself (well conditioned).

    The polynomial root is exact up to the conditioning of its coefficients, which degrades
    when the bodies shrink towards one point; two Newton steps on the gap restore full
    precision. A step that is large (a graze, where the rate vanishes) or that does not reduce
    the gap is not taken.
    """
    gap, rate = _scaled_gap(s, tau, r)
    for _ in range(2):
        if rate == 0.0 or gap == 0.0:
            break
        step = gap / rate
        if abs(step) > 1e-6 or not 0.0 <= tau - step <= 1.0:
            break
        new_gap, new_rate = _scaled_gap(s, tau - step, r)
        if abs(new_gap) >= abs(gap):
            break
        tau, gap, rate = tau - step, new_gap, new_rate
    return tau


def _closest_on_axis(ball: Vector, knob: Vector, tip: Vector) -> Tuple[float, Vector]:
    """Fraction along knob-tip (clipped to [0, 1]) and the closest axis point to the ball."""
    axis = sub(tip, knob)
    axis2 = dot(axis, axis)
    fraction = 0.0 if axis2 == 0.0 else min(1.0, max(0.0, dot(sub(ball, knob), axis) / axis2))
    return fraction, lerp(knob, tip, fraction)


def _unit_normal(offset: Vector, axis: Vector, relative_velocity: Vector) -> Vector:
    """Return offset as a unit vector; for a ball centre on the axis, a perpendicular to it."""
    length = math.sqrt(dot(offset, offset))
    if 1e-12 < length < math.inf:
        return scale(offset, 1.0 / length)
    # Ball centre on the bat axis: push the ball back against its approach, across the axis.
    axis2 = dot(axis, axis)
    for candidate in (scale(relative_velocity, -1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)):
        if axis2 > 0.0:
            along = dot(candidate, axis) / axis2
            candidate = sub(candidate, scale(axis, along))
        length = math.sqrt(dot(candidate, candidate))
        if 1e-12 < length < math.inf:
            return scale(candidate, 1.0 / length)
    return (0.0, 0.0, 1.0)


def _contact_at(tau: float, dt: float, ball0: Vector, ball1: Vector, tip0: Vector, tip1: Vector,
                knob0: Vector, knob1: Vector, ball_radius: float, bat_radius: float,
                fraction_range: Tuple[float, float] = (0.0, 1.0),
                ends: Tuple[bool, bool] = (True, True)) -> ImpactResult:
    """
    Build the result for contact at normalised time tau on a capsule piece.

    ``fraction_range`` maps the piece onto the whole knob-tip axis; ``ends`` says whether the
    piece's knob and tip caps are the bat's own ends.
    """
    ball, tip, knob = lerp(ball0, ball1, tau), lerp(tip0, tip1, tau), lerp(knob0, knob1, tau)
    local, centre = _closest_on_axis(ball, knob, tip)
    bat_motion = lerp(sub(knob1, knob0), sub(tip1, tip0), local)
    rel_velocity = scale(sub(sub(ball1, ball0), bat_motion), 1.0 / dt)
    normal = _unit_normal(sub(ball, centre), sub(tip, knob), rel_velocity)
    offset = sub(ball, centre)
    gap = math.sqrt(dot(offset, offset)) - ball_radius - bat_radius
    f0, f1 = fraction_range
    fraction = f0 + (f1 - f0) * local
    feature = 'side'
    if local <= 0.0 and ends[0]:
        feature = 'knob_end'
    elif local >= 1.0 and ends[1]:
        feature = 'tip_end'
    point = tuple(centre[i] + normal[i] * bat_radius for i in range(3))
    return ImpactResult(time=tau * dt, point=point, normal=normal, bat_fraction=fraction,
                        initially_overlapping=tau == 0.0, gap=gap, feature=feature)


def _capsule_tau(ball0: Vector, ball1: Vector, tip0: Vector, tip1: Vector, knob0: Vector,
                 knob1: Vector, radius: float) -> Optional[float]:
    if not _may_touch(ball0, ball1, tip0, tip1, knob0, knob1, radius):
        return None
    return _first_contact_tau(_scaled(ball0, ball1, tip0, tip1, knob0, knob1, radius), radius)


def closest_offset(ball0: Vector, ball1: Vector, tip0: Vector, tip1: Vector, knob0: Vector,
                   knob1: Vector) -> Vector:
    """
    Return the ball's offset (m) from the bat's midpoint at their closest, all moving on chords.

    The offset moves linearly over the interval, so its smallest value is in closed form.
    """
    m0 = sub(ball0, lerp(knob0, tip0, 0.5))
    m1 = sub(sub(ball1, lerp(knob1, tip1, 0.5)), m0)
    m11 = dot(m1, m1)
    s = 0.0 if m11 == 0.0 else min(1.0, max(0.0, -dot(m0, m1) / m11))
    return advance(m0, m1, s)


def _may_touch(ball0: Vector, ball1: Vector, tip0: Vector, tip1: Vector, knob0: Vector,
               knob1: Vector, radius: float) -> bool:
    """
    Conservative broad phase: False only when the ball certainly stays clear of the bat.

    The ball's closest approach to the bat's midpoint minus the largest half-length of the bat
    bounds the gap from below.
    """
    closest = closest_offset(ball0, ball1, tip0, tip1, knob0, knob1)
    half = 0.5 * max(math.sqrt(dot(sub(tip0, knob0), sub(tip0, knob0))),
                     math.sqrt(dot(sub(tip1, knob1), sub(tip1, knob1))))
    reach = half + radius + TOUCH_TOLERANCE
    margin = 1e-9 * (1.0 + reach)
    return dot(closest, closest) <= (reach + margin) * (reach + margin)


def time_of_impact(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
                   knob0: ArrayLike, knob1: ArrayLike, ball_radius: float, bat_radius: float,
                   dt: float = 1.0) -> Optional[ImpactResult]:
    """
    First contact between a ball and a capsule bat over one interval, or None.

    :param ball0, ball1: ball centre at the start and end of the interval (metres).
    :param tip0, tip1: bat tip (barrel end) at the start and end (metres).
    :param knob0, knob1: bat knob at the start and end (metres).
    :param ball_radius: ball radius (metres, >= 0).
    :param bat_radius: bat radius (metres, >= 0); the bat is the knob-tip segment thickened by it.
    :param dt: interval length (seconds, > 0). Every point moves linearly over it.

    :returns: The first contact (gap <= TOUCH_TOLERANCE), exact under the linear model, or None.

    :raises CoreError: (a ValueError) a point that is not 3 finite numbers, a negative or
        non-finite radius, or dt not > 0; the message names the argument.
    """
    b0, b1 = _point('ball0', ball0), _point('ball1', ball1)
    e0, e1 = _point('tip0', tip0), _point('tip1', tip1)
    s0, s1 = _point('knob0', knob0), _point('knob1', knob1)
    rb = _non_negative('ball_radius', ball_radius)
    rt = _non_negative('bat_radius', bat_radius)
    seconds = _interval(dt)
    tau = _capsule_tau(b0, b1, e0, e1, s0, s1, rb + rt)
    if tau is None:
        return None
    return _contact_at(tau, seconds, b0, b1, e0, e1, s0, s1, rb, rt)


def time_of_impact_profile(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
                           knob0: ArrayLike, knob1: ArrayLike, ball_radius: float,
                           profile: BatProfile, dt: float = 1.0) -> Optional[ImpactResult]:
    """
    First contact between a ball and a bat given by a radius profile, or None.

    The profile is a union of capsules on sub-segments of knob-tip (see ``bat.BatProfile``);
    each piece's ends are fixed fractions of knob-tip, so they move linearly and each piece is
    solved exactly. ``bat_fraction`` in the result is along the whole knob-tip axis.

    :param ball0, ball1, tip0, tip1, knob0, knob1, ball_radius, dt: as for ``time_of_impact``.
    :param profile: the bat's radius profile, scaled to the measured knob-tip distance.

    :raises CoreError: as for ``time_of_impact``.
    """
    b0, b1 = _point('ball0', ball0), _point('ball1', ball1)
    e0, e1 = _point('tip0', tip0), _point('tip1', tip1)
    s0, s1 = _point('knob0', knob0), _point('knob1', knob1)
    rb = _non_negative('ball_radius', ball_radius)
    seconds = _interval(dt)
    return _profile_contact(b0, b1, e0, e1, s0, s1, rb, profile, seconds)


def _profile_contact(b0: Vector, b1: Vector, e0: Vector, e1: Vector, s0: Vector, s1: Vector,
                     ball_radius: float, profile: BatProfile,
                     dt: float) -> Optional[ImpactResult]:
    """Profile solve on checked inputs (the detector's hot path calls this directly)."""
    segments = profile.segments()
    if len(segments) > 1 and not _may_touch(b0, b1, e0, e1, s0, s1,
                                            ball_radius + profile.max_radius):
        return None
    best_tau, best_piece = None, None
    for index, (f0, f1, radius) in enumerate(segments):
        k0, k1 = lerp(s0, e0, f0), lerp(s1, e1, f0)
        t0, t1 = lerp(s0, e0, f1), lerp(s1, e1, f1)
        tau = _capsule_tau(b0, b1, t0, t1, k0, k1, ball_radius + radius)
        if tau is not None and (best_tau is None or tau < best_tau):
            best_tau, best_piece = tau, (index, f0, f1, radius, k0, k1, t0, t1)
    if best_tau is None:
        return None
    index, f0, f1, radius, k0, k1, t0, t1 = best_piece
    ends = (index == 0, index == len(segments) - 1)
    return _contact_at(best_tau, dt, b0, b1, t0, t1, k0, k1, ball_radius, radius, (f0, f1), ends)


def profile_gap(ball: Vector, knob: Vector, tip: Vector, ball_radius: float,
                profile: BatProfile) -> Tuple[float, Vector, float]:
    """
    Return the gap between a ball and a profiled bat at one instant (no input checking).

    :param ball: ball centre (metres); ``knob``, ``tip``: the bat's ends (metres).
    :param ball_radius: metres.
    :param profile: the bat's radius profile, scaled to the knob-tip distance.
    :returns: (gap in metres, negative when overlapping; unit normal from the bat axis to the
        ball centre; fraction along knob-tip of the closest axis point).
    """
    axis = sub(tip, knob)
    offset = sub(ball, knob)
    uu = dot(axis, axis)
    wu = dot(offset, axis)
    ww = dot(offset, offset)
    along = wu / uu if uu > 0.0 else 0.0
    best_gap, best_fraction = math.inf, 0.0
    for f0, f1, radius in profile.segments():
        fraction = f0 if along < f0 else (f1 if along > f1 else along)
        # |offset - fraction * axis|, without building the vector
        gap = math.sqrt(max(0.0, ww - fraction * (2.0 * wu - fraction * uu))) - radius
        if gap < best_gap:
            best_gap, best_fraction = gap, fraction
    closest = sub(offset, scale(axis, best_fraction))
    length = math.sqrt(dot(closest, closest))
    normal = scale(closest, 1.0 / length) if length > 0.0 else _unit_normal(
        closest, axis, (0.0, 0.0, 0.0))
    return best_gap - ball_radius, normal, best_fraction


# ----------------------------------------------------------------------------------------------
# Objective 1: the gap as a function of time (vectorised over t)


def _positions_at(t: ArrayLike, dt: float, *pairs: ArrayLike) -> List[np.ndarray]:
    times = np.asarray(t, dtype=float)[..., None] / float(dt)
    out = []
    for start, end in zip(pairs[::2], pairs[1::2]):
        p0 = np.asarray(start, dtype=float)
        p1 = np.asarray(end, dtype=float)
        out.append(p0 + (p1 - p0) * times)
    return out


def line_distance(t: ArrayLike, ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike,
                  tip1: ArrayLike, knob0: ArrayLike, knob1: ArrayLike, ball_radius: float,
                  bat_radius: float, dt: float) -> np.ndarray:
    """
    Seed Eq. (6): gap between the ball and the INFINITE line through knob and tip.

    ``d(t) = |(B - E) x (B - S)| / |S - E| - r_bat - r_ball`` with every point linear in t.

    :param t: times in seconds from the interval start (any shape).
    :param ball0 ... dt: as for ``time_of_impact``.

    :returns: Gap in metres, same shape as t (NaN where knob and tip coincide).
    """
    ball, tip, knob = _positions_at(t, dt, ball0, ball1, tip0, tip1, knob0, knob1)
    numerator = np.linalg.norm(np.cross(ball - tip, ball - knob), axis=-1)
    denominator = np.linalg.norm(knob - tip, axis=-1)
    with np.errstate(divide='ignore', invalid='ignore'):
        return numerator / denominator - bat_radius - ball_radius


def distance(t: ArrayLike, ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
             knob0: ArrayLike, knob1: ArrayLike, ball_radius: float, bat_radius: float,
             dt: float) -> np.ndarray:
    """
    Signed gap between the ball and the capsule bat (segment knob-tip, rounded ends).

    Objective 1 for a finite bat: the distance from the ball centre to the nearest point of the
    segment, minus both radii. Negative means overlap.

    :param t: times in seconds from the interval start (any shape).
    :param ball0 ... dt: as for ``time_of_impact``.

    :returns: Gap in metres, same shape as t.
    """
    ball, tip, knob = _positions_at(t, dt, ball0, ball1, tip0, tip1, knob0, knob1)
    axis = tip - knob
    axis2 = np.einsum('...i,...i->...', axis, axis)
    along = np.einsum('...i,...i->...', ball - knob, axis)
    with np.errstate(divide='ignore', invalid='ignore'):
        fraction = np.where(axis2 > 0.0, np.clip(along / axis2, 0.0, 1.0), 0.0)
    closest = knob + axis * fraction[..., None]
    return np.linalg.norm(ball - closest, axis=-1) - bat_radius - ball_radius


# ----------------------------------------------------------------------------------------------
# The seed's own method, kept for comparison


def seed_time_of_impact(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
                        knob0: ArrayLike, knob1: ArrayLike, ball_radius: float,
                        bat_radius: float, dt: float = 1.0) -> Optional[float]:
    """
    Run the seed derivation's method: first real root in [0, dt] of its quartic (Eq. 15f).

    Kept to compare against; do not use it to find impacts. Its known failures:

    * the bat is an infinite line, so it reports hits past the tip and behind the knob;
    * a ball already in contact at t = 0 with no crossing in the interval is missed (it looks
      for roots, not for the sign at the start);
    * a tangential touch is a double root, which ``numpy.roots`` returns with a small imaginary
      part, so grazes are lost;
    * coefficients are formed in raw seconds and metres, so they are badly scaled.

    :param ball0 ... dt: as for ``time_of_impact``.

    :returns: Seconds from the interval start of the smallest real root in [0, dt], or None.
    """
    b0, b1 = np.asarray(ball0, float), np.asarray(ball1, float)
    e0, e1 = np.asarray(tip0, float), np.asarray(tip1, float)
    s0, s1 = np.asarray(knob0, float), np.asarray(knob1, float)
    # Eqs. (4)-(5): B - E = a t + b, B - S = c t + d, S - E = e t + f
    a = (b1 - b0 - e1 + e0) / dt
    b = b0 - e0
    c = (b1 - b0 - s1 + s0) / dt
    d = b0 - s0
    e = (s1 - s0 - e1 + e0) / dt
    f = s0 - e0
    r = ball_radius + bat_radius
    alpha = np.array([0.0, 0.0, e @ e, 2.0 * (e @ f), f @ f])  # Eq. (13)
    x = np.stack([np.cross(a, c), np.cross(b, c) + np.cross(a, d), np.cross(b, d)], axis=1)
    beta = np.array([  # Eq. (12)
        np.sum(x[:, 0] ** 2),
        np.sum(2.0 * x[:, 0] * x[:, 1]),
        np.sum(x[:, 1] ** 2 + 2.0 * x[:, 0] * x[:, 2]),
        np.sum(2.0 * x[:, 1] * x[:, 2]),
        np.sum(x[:, 2] ** 2),
    ])
    coefficients = beta - r * r * alpha  # Eq. (15f)
    nonzero = np.flatnonzero(coefficients)
    if nonzero.size == 0:
        return None
    roots = np.roots(coefficients[nonzero[0]:])
    real = roots[np.isreal(roots)].real
    in_range = real[(real >= 0.0) & (real <= dt)]
    return float(in_range.min()) if in_range.size else None


# ----------------------------------------------------------------------------------------------
# The batch solver: N intervals at once, no Python loop over N


_BISECTIONS = 56  # halvings of a sub-interval of [0, 1]: below double precision


def _b_dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum('...i,...i->...', a, b)


def _b_eval(c: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Evaluate quartics c (N, 5) at x (N,) or (N, K)."""
    if x.ndim == 1:
        return c[:, 0] + x * (c[:, 1] + x * (c[:, 2] + x * (c[:, 3] + x * c[:, 4])))
    return c[:, :1] + x * (c[:, 1:2] + x * (c[:, 2:3] + x * (c[:, 3:4] + x * c[:, 4:5])))


def _b_eval_d1(c: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Evaluate the derivatives of quartics c (N, 5) at x (N,) or (N, K)."""
    if x.ndim == 1:
        return c[:, 1] + x * (2.0 * c[:, 2] + x * (3.0 * c[:, 3] + x * 4.0 * c[:, 4]))
    return c[:, 1:2] + x * (2.0 * c[:, 2:3] + x * (3.0 * c[:, 3:4] + x * 4.0 * c[:, 4:5]))


def _b_quadratic_roots_in_unit(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Roots of a x^2 + b x + c strictly inside (0, 1) as (N, 2), NaN where absent."""
    with np.errstate(divide='ignore', invalid='ignore', over='ignore'):
        disc = b * b - 4.0 * a * c
        sq = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        q = -0.5 * (b + np.copysign(sq, b))
        quad = np.stack([q / a, c / q], axis=1)
        linear = np.stack([-c / b, np.full_like(b, np.nan)], axis=1)
        roots = np.where((a == 0.0)[:, None], linear, quad)
    inside = (roots > 0.0) & (roots < 1.0)
    return np.where(inside, roots, np.nan)


def _b_bisect(f, c: np.ndarray, lo: np.ndarray, hi: np.ndarray,
              lo_positive: np.ndarray) -> np.ndarray:
    """
    Locate sign changes of f(c, x) on brackets [lo, hi] (all (M,)) by bisection.

    Returns the side of each bracket past the change, to double precision.
    """
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        same = (f(c, mid) > 0.0) == lo_positive
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    return hi


def _b_solve_pieces(f, c: np.ndarray, lo: np.ndarray, hi: np.ndarray, change: np.ndarray,
                    lo_positive: np.ndarray) -> np.ndarray:
    """Bisect only the (row, piece) brackets marked in ``change``; NaN elsewhere."""
    out = np.full(lo.shape, np.nan)
    rows, pieces = np.nonzero(change)
    if rows.size:
        out[rows, pieces] = _b_bisect(f, c[rows], lo[rows, pieces], hi[rows, pieces],
                                      lo_positive[rows, pieces])
    return out


def _b_monotone_bounds(c: np.ndarray) -> np.ndarray:
    """Boundaries of the monotone pieces of quartics c on [0, 1]: (N, 5) sorted, 1.0-padded."""
    n = c.shape[0]
    inflections = _b_quadratic_roots_in_unit(12.0 * c[:, 4], 6.0 * c[:, 3], 2.0 * c[:, 2])
    zeros = np.zeros((n, 1))
    ones = np.ones((n, 1))
    knots = np.concatenate([zeros, inflections, ones], axis=1)
    knots = np.sort(np.where(np.isnan(knots), 1.0, knots), axis=1)
    lo, hi = knots[:, :-1], knots[:, 1:]
    d_lo, d_hi = _b_eval_d1(c, lo), _b_eval_d1(c, hi)
    change = (((d_lo > 0.0) & (d_hi < 0.0)) | ((d_lo < 0.0) & (d_hi > 0.0))) & (hi > lo)
    critical = _b_solve_pieces(_b_eval_d1, c, lo, hi, change, d_lo > 0.0)
    bounds = np.concatenate([zeros, critical, ones], axis=1)
    return np.sort(np.where(np.isnan(bounds), 1.0, bounds), axis=1)


def _b_candidates(c: np.ndarray, slack) -> np.ndarray:
    """Batch ``_touch_candidates``: (N, 5) candidate times, NaN where none."""
    bounds = _b_monotone_bounds(c)
    values = _b_eval(c, bounds)
    lo, hi = bounds[:, :-1], bounds[:, 1:]
    f_lo, f_hi = values[:, :-1], values[:, 1:]
    crossing = (f_lo > 0.0) & (f_hi <= 0.0) & (hi > lo)
    roots = _b_solve_pieces(_b_eval, c, lo, hi, crossing, np.ones(lo.shape, dtype=bool))
    graze = ~crossing & (f_hi > 0.0) & (f_hi < f_lo) & (f_hi <= slack(hi))
    pieces = np.where(crossing, roots, np.where(graze, hi, np.nan))
    start = np.where(values[:, :1] <= slack(bounds[:, :1]), 0.0, np.nan)
    return np.concatenate([start, pieces], axis=1)


def _b_quadratic_entry(a: np.ndarray, b: np.ndarray, c: np.ndarray,
                       slack: np.ndarray) -> np.ndarray:
    """Batch ``_quadratic_entry``: (N,) first contact tau, inf where none."""
    with np.errstate(divide='ignore', invalid='ignore'):
        disc = b * b - 4.0 * a * c
        q = -0.5 * (b - np.sqrt(np.maximum(disc, 0.0)))
        root = np.minimum(q / a, c / q)
        crossing = (a > 0.0) & (disc >= 0.0) & (b < 0.0) & (root <= 1.0)
        vertex = np.where(a > 0.0, np.minimum(1.0, -0.5 * b / a), np.where(b < 0.0, 1.0, 0.0))
    graze = (vertex > 0.0) & (a * vertex * vertex + b * vertex + c <= slack)
    return np.where(c <= slack, 0.0, np.where(crossing, root, np.where(graze, vertex, np.inf)))


def _as_points(name: str, value: ArrayLike) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.ndim != 2 or array.shape[1] != 3:
        raise CoreError(f'{name} must have shape (N, 3), got {array.shape}')
    return array


def _as_column(name: str, value: Union[float, ArrayLike], n: int) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return np.full(n, float(array))
    if array.shape != (n,):
        raise CoreError(f'{name} must be a scalar or have shape ({n},), got {array.shape}')
    return array


def time_of_impact_batch(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
                         knob0: ArrayLike, knob1: ArrayLike, ball_radius: Union[float, ArrayLike],
                         bat_radius: Union[float, ArrayLike],
                         dt: Union[float, ArrayLike] = 1.0) -> np.ndarray:
    """
    ``time_of_impact`` for N intervals at once, fully vectorised.

    :param ball0, ball1, tip0, tip1, knob0, knob1: arrays of shape (N, 3) (metres).
    :param ball_radius, bat_radius: scalars or (N,) (metres, >= 0).
    :param dt: scalar or (N,) (seconds, > 0).

    :returns: (N,) float64 seconds from each interval's start to first contact; NaN where there is
        no contact, and NaN for rows with non-finite values, negative radii or dt <= 0.

    :raises CoreError: arrays of the wrong shape (rows are not checked by raising).
    """
    points = [_as_points(name, value) for name, value in (
        ('ball0', ball0), ('ball1', ball1), ('tip0', tip0), ('tip1', tip1),
        ('knob0', knob0), ('knob1', knob1))]
    n = points[0].shape[0]
    for name, array in zip(('ball1', 'tip0', 'tip1', 'knob0', 'knob1'), points[1:]):
        if array.shape[0] != n:
            raise CoreError(f'{name} has {array.shape[0]} rows but ball0 has {n}')
    rb = _as_column('ball_radius', ball_radius, n)
    rt = _as_column('bat_radius', bat_radius, n)
    seconds = _as_column('dt', dt, n)
    b0, b1, e0, e1, s0, s1 = points
    radius = rb + rt
    with np.errstate(invalid='ignore'):
        good = (np.all(np.isfinite(np.concatenate(points, axis=1)), axis=1)
                & np.isfinite(radius) & (rb >= 0.0) & (rt >= 0.0)
                & np.isfinite(seconds) & (seconds > 0.0))
    result = np.full(n, np.nan)
    rows = np.flatnonzero(good)
    if rows.size == 0:
        return result
    # broad phase (as _may_touch): drop rows that certainly stay clear
    b0, b1, e0, e1, s0, s1 = (p[rows] for p in points)
    radius = radius[rows]
    m0 = b0 - 0.5 * (s0 + e0)
    m1 = (b1 - 0.5 * (s1 + e1)) - m0
    m11 = _b_dot(m1, m1)
    with np.errstate(divide='ignore', invalid='ignore'):
        s = np.where(m11 > 0.0, np.clip(-_b_dot(m0, m1) / m11, 0.0, 1.0), 0.0)
    closest = m0 + m1 * s[:, None]
    half = 0.5 * np.maximum(np.linalg.norm(e0 - s0, axis=1), np.linalg.norm(e1 - s1, axis=1))
    reach = half + radius + TOUCH_TOLERANCE
    near = _b_dot(closest, closest) <= (reach + 1e-9 * (1.0 + reach)) ** 2
    rows, b0, b1, e0, e1, s0, s1, radius = (
        x[near] for x in (rows, b0, b1, e0, e1, s0, s1, radius))
    if rows.size == 0:
        return result
    tau = _b_first_contact_tau(b0, b1, e0, e1, s0, s1, radius)
    result[rows] = tau * seconds[rows]
    return result


def _b_first_contact_tau(b0: np.ndarray, b1: np.ndarray, e0: np.ndarray, e1: np.ndarray,
                         s0: np.ndarray, s1: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Batch ``_first_contact_tau`` on checked rows: (N,) tau in [0, 1] or NaN."""
    w0 = b0 - s0
    u0 = e0 - s0
    w_end = b1 - s1
    u_end = e1 - s1
    extent = np.max(np.abs(np.concatenate([w0, w_end, u0, u_end, radius[:, None]], axis=1)),
                    axis=1)
    extent = np.where(extent > 0.0, extent, 1.0)[:, None]
    w0, w_end, u0, u_end = w0 / extent, w_end / extent, u0 / extent, u_end / extent
    w1, u1 = w_end - w0, u_end - u0
    r = radius / extent[:, 0]
    rr = r * r
    cap_slack = ((r + TOUCH_TOLERANCE / extent[:, 0]) ** 2 - rr)[:, None]
    zeros = np.zeros_like(rr)
    best = np.full(rr.shape, np.inf)
    for p0, p1 in ((w0, w1), (w0 - u0, w1 - u1)):
        best = np.minimum(best, _b_quadratic_entry(
            _b_dot(p1, p1), 2.0 * _b_dot(p0, p1), _b_dot(p0, p0) - rr, cap_slack[:, 0]))
    c0, c2 = np.cross(w0, u0), np.cross(w1, u1)
    c1 = np.cross(w0, u1) - np.cross(u0, w1)
    uu = np.stack([_b_dot(u0, u0), 2.0 * _b_dot(u0, u1), _b_dot(u1, u1), zeros, zeros], axis=1)
    wu = np.stack([_b_dot(w0, u0), _b_dot(w0, u1) + _b_dot(w1, u0), _b_dot(w1, u1),
                   zeros, zeros], axis=1)
    quartic = np.stack([
        _b_dot(c0, c0) - rr * uu[:, 0],
        2.0 * _b_dot(c0, c1) - rr * uu[:, 1],
        _b_dot(c1, c1) + 2.0 * _b_dot(c0, c2) - rr * uu[:, 2],
        2.0 * _b_dot(c1, c2),
        _b_dot(c2, c2),
    ], axis=1)
    candidates = _b_candidates(quartic, lambda x: cap_slack * _b_eval(uu, x))
    safe = np.where(np.isnan(candidates), 0.0, candidates)
    axis2 = _b_eval(uu, safe)
    along = _b_eval(wu, safe)
    in_range = ~np.isnan(candidates) & (axis2 > _DEGENERATE_AXIS) & (along >= 0.0) & (
        along <= axis2)
    # confirm with the gap at the polished root (the quartic also vanishes where the bat's
    # length does)
    rows, cols = np.nonzero(in_range)
    picked = [x[rows] for x in (w0, w1, u0, u1, r)]
    polished = _b_polish(candidates[rows, cols], *picked)
    gap = _b_gap_and_rate(polished, *picked)[0]
    accepted = gap <= TOUCH_TOLERANCE / extent[rows, 0] + _ROOT_SLACK
    side_times = np.full(candidates.shape, np.inf)
    side_times[rows[accepted], cols[accepted]] = polished[accepted]
    side = np.min(side_times, axis=1)
    caps = _b_polish(np.where(np.isfinite(best), best, np.nan), w0, w1, u0, u1, r)
    best = np.fmin(caps, side)
    return np.where(np.isfinite(best), best, np.nan)


def _b_gap_and_rate(x: np.ndarray, w0: np.ndarray, w1: np.ndarray, u0: np.ndarray,
                    u1: np.ndarray, r: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Batch ``_scaled_gap``: gap and d(gap)/d(tau) at x (N,) in scaled units."""
    w = w0 + w1 * x[:, None]
    u = u0 + u1 * x[:, None]
    axis2 = _b_dot(u, u)
    with np.errstate(divide='ignore', invalid='ignore'):
        fraction = np.where(axis2 > 0.0, np.clip(_b_dot(w, u) / axis2, 0.0, 1.0), 0.0)
        offset = w - u * fraction[:, None]
        length = np.linalg.norm(offset, axis=1)
        rate = np.where(length > 0.0, _b_dot(offset, w1 - u1 * fraction[:, None]) / length, 0.0)
    return length - r, rate


def _b_polish(tau: np.ndarray, w0: np.ndarray, w1: np.ndarray, u0: np.ndarray, u1: np.ndarray,
              r: np.ndarray) -> np.ndarray:
    """Batch ``_polish``: two guarded Newton steps on the gap at each contact tau > 0."""
    active = np.isfinite(tau) & (tau > 0.0)
    x = np.where(active, tau, 0.5)
    gap, rate = _b_gap_and_rate(x, w0, w1, u0, u1, r)
    for _ in range(2):
        with np.errstate(divide='ignore', invalid='ignore'):
            step = gap / rate
        trial = x - step
        ok = active & np.isfinite(step) & (np.abs(step) <= 1e-6) & (trial >= 0.0) & (trial <= 1.0)
        new_gap, new_rate = _b_gap_and_rate(np.where(ok, trial, x), w0, w1, u0, u1, r)
        ok &= np.abs(new_gap) < np.abs(gap)
        x = np.where(ok, trial, x)
        gap = np.where(ok, new_gap, gap)
        rate = np.where(ok, new_rate, rate)
    return np.where(active, x, tau)
