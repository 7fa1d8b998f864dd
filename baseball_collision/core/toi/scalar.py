"""
Exact time of impact on plain floats: one ball against a capsule or a profile of capsules.

Each call solves one interval in which every point moves linearly (``capsule`` states the
model). Coordinates are shifted to the knob's start and scaled to the interval's extent, and
time is normalised to [0, 1], before any coefficient is formed. The end caps' quadratics are
solved in closed form; the side's quartic on its monotone pieces (``polynomials``), each
crossing refined by safeguarded Newton and then by two Newton steps on the gap itself.

Precision: contact times are exact to a few ulps of dt wherever the bodies have volume. With
both radii zero (a point against a segment) contact is a double root of a squared distance and
its time is only good to about sqrt(machine epsilon) of the interval's scale.
"""

import math
from typing import NamedTuple, Optional, Tuple

from .capsule import cap_quadratics, SCALAR, side_quartic
from .polynomials import evaluate, quadratic_entry, touch_candidates
from .result import ArrayLike, DEGENERATE_AXIS, Feature, ImpactResult, ROOT_SLACK, TOUCH_TOLERANCE
from ..bat import BatProfile
from ..geometry import (
    advance, closest_on_segment, dot, finite_vector, lerp, scale, sub, unit_normal, Vector)
from ...errors import CoreError

_ORIGIN = (0.0, 0.0, 0.0)


# ----------------------------------------------------------------------------------------------
# Input checking


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


def _checked(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
             knob0: ArrayLike, knob1: ArrayLike) -> Tuple[Vector, ...]:
    """Return the six points as 3-tuples of floats, in the order given."""
    return tuple(finite_vector(name, value, ' (metres)') for name, value in (
        ('ball0', ball0), ('ball1', ball1), ('tip0', tip0), ('tip1', tip1), ('knob0', knob0),
        ('knob1', knob1)))


# ----------------------------------------------------------------------------------------------
# One capsule


class _Scaled(NamedTuple):
    """One interval in scaled coordinates: w = B - S and u = E - S as w0 + w1 tau, u0 + u1 tau."""

    w0: Vector
    w1: Vector
    u0: Vector
    u1: Vector
    scale: float


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


def _first_contact_tau(s: _Scaled, radius: float) -> Optional[float]:
    """Return the earliest tau in [0, 1] of contact (gap <= TOUCH_TOLERANCE), or None."""
    r = radius / s.scale
    rr = r * r
    tol = TOUCH_TOLERANCE / s.scale
    cap_slack = (r + tol) * (r + tol) - rr  # products overflow to inf; ** would raise
    best = None
    for a, b, c in cap_quadratics(s.w0, s.w1, s.u0, s.u1, rr, SCALAR):
        tau = quadratic_entry(a, b, c, cap_slack)
        if tau is not None and (best is None or tau < best):
            best = tau
    if best:
        best = _polish(s, best, r)
    quartic, axis, along_axis = side_quartic(s.w0, s.w1, s.u0, s.u1, rr, SCALAR)
    if max(axis[0], abs(axis[1]), axis[2]) <= DEGENERATE_AXIS:
        return best  # zero-length bat: a sphere, the end caps say it all
    uu = axis + (0.0, 0.0)
    wu = along_axis + (0.0, 0.0)
    for tau in touch_candidates(quartic, lambda x: cap_slack * evaluate(uu, x)):
        if best is not None and tau >= best:
            break
        axis2 = evaluate(uu, tau)
        along = evaluate(wu, tau)
        if axis2 <= DEGENERATE_AXIS or not 0.0 <= along <= axis2:
            continue
        # The quartic also vanishes where the bat's length passes through zero; the gap itself,
        # at the polished root, confirms a root is a touch of the side.
        polished = _polish(s, tau, r) if tau > 0.0 else tau
        if _scaled_gap(s, polished, r)[0] <= tol + ROOT_SLACK:
            return polished if best is None else min(best, polished)
    return best


def _scaled_gap(s: _Scaled, tau: float, r: float) -> Tuple[float, float]:
    """Return the gap between ball and capsule at tau, and d(gap)/d(tau), in scaled units."""
    w = advance(s.w0, s.w1, tau)
    u = advance(s.u0, s.u1, tau)
    fraction, closest = closest_on_segment(w, _ORIGIN, u)
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


def _capsule_tau(ball0: Vector, ball1: Vector, tip0: Vector, tip1: Vector, knob0: Vector,
                 knob1: Vector, radius: float) -> Optional[float]:
    """Return the first contact tau with a capsule of ``radius`` (both radii), or None."""
    if not _may_touch(ball0, ball1, tip0, tip1, knob0, knob1, radius):
        return None
    return _first_contact_tau(_scaled(ball0, ball1, tip0, tip1, knob0, knob1, radius), radius)


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
    local, centre = closest_on_segment(ball, knob, tip)
    bat_motion = lerp(sub(knob1, knob0), sub(tip1, tip0), local)
    rel_velocity = scale(sub(sub(ball1, ball0), bat_motion), 1.0 / dt)
    normal = unit_normal(sub(ball, centre), sub(tip, knob), rel_velocity)
    offset = sub(ball, centre)
    gap = math.sqrt(dot(offset, offset)) - ball_radius - bat_radius
    f0, f1 = fraction_range
    fraction = f0 + (f1 - f0) * local
    feature = Feature.SIDE
    if local <= 0.0 and ends[0]:
        feature = Feature.KNOB_END
    elif local >= 1.0 and ends[1]:
        feature = Feature.TIP_END
    point = tuple(centre[i] + normal[i] * bat_radius for i in range(3))
    return ImpactResult(time=tau * dt, point=point, normal=normal, bat_fraction=fraction,
                        initially_overlapping=tau == 0.0, gap=gap, feature=feature)


# ----------------------------------------------------------------------------------------------
# Broad phase


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


# ----------------------------------------------------------------------------------------------
# The public calls


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
    b0, b1, e0, e1, s0, s1 = _checked(ball0, ball1, tip0, tip1, knob0, knob1)
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
    b0, b1, e0, e1, s0, s1 = _checked(ball0, ball1, tip0, tip1, knob0, knob1)
    rb = _non_negative('ball_radius', ball_radius)
    seconds = _interval(dt)
    return profile_contact(b0, b1, e0, e1, s0, s1, rb, profile, seconds)


def profile_contact(b0: Vector, b1: Vector, e0: Vector, e1: Vector, s0: Vector, s1: Vector,
                    ball_radius: float, profile: BatProfile,
                    dt: float) -> Optional[ImpactResult]:
    """
    Return ``time_of_impact_profile`` on checked inputs (no conversion, no checks), or None.

    For the hot paths (the detector's sub-steps, the prediction's search): every point must be
    a tuple of three finite floats, ``ball_radius`` >= 0 and ``dt`` > 0.
    """
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
