"""
Exact time of impact on plain floats: one ball against a capsule or a profile of round cones.

Thin wrappers of the compiled kernel (``_kernel.c``, the one implementation of the solver),
which solves one interval in which every point moves linearly: coordinates are shifted to the
knob's start and scaled to the interval's extent, and time is normalised to [0, 1], before any
coefficient is formed. The end caps' quadratics are solved in closed form; the side's quartic
on its monotone pieces, each crossing refined by safeguarded Newton and then by two Newton
steps on the gap itself. The kernel also checks its input (finite points, radii >= 0, dt > 0);
only input it refuses comes back here, to be converted or refused with a ``CoreError`` that
names the argument.

Precision: contact times are exact to a few ulps of dt wherever the bodies have volume. With
both radii zero (a point against a segment) contact is a double root of a squared distance and
its time is only good to about sqrt(machine epsilon) of the interval's scale.
"""

import math
from typing import Optional, Tuple

from . import _kernel
from .result import ArrayLike, Feature, ImpactResult
from ..bat import BatProfile
from ..geometry import finite_vector, Vector
from ...errors import CoreError

# the kernel makes ImpactResults itself: these are its fields, as the kernel orders its values
_kernel.bind(ImpactResult, ('time', 'point', 'normal', 'bat_fraction', 'initially_overlapping',
                            'gap', 'feature'), (Feature.SIDE, Feature.KNOB_END, Feature.TIP_END))

# ----------------------------------------------------------------------------------------------
# Input checking (the kernel's refusals, explained)


def _non_negative(name: str, value: float) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError) as error:
        raise CoreError(f'{name} must be a number, got {value!r}') from error
    if not (math.isfinite(number) and number >= 0.0):
        raise CoreError(f'{name} must be finite and >= 0, got {value!r}')
    return number


def _interval(dt: float) -> float:
    try:
        number = float(dt)
    except (TypeError, ValueError) as error:
        raise CoreError(f'dt must be a number, got {dt!r}') from error
    if not (math.isfinite(number) and number > 0.0):
        raise CoreError(f'dt must be finite and > 0 seconds, got {dt!r}')
    return number


def _checked(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
             knob0: ArrayLike, knob1: ArrayLike) -> Tuple[Vector, ...]:
    """Return the six points as 3-tuples of floats, in the order given."""
    return tuple(finite_vector(name, value, ' (metres)') for name, value in (
        ('ball0', ball0), ('ball1', ball1), ('tip0', tip0), ('tip1', tip1), ('knob0', knob0),
        ('knob1', knob1)))


# ----------------------------------------------------------------------------------------------
# The public calls


def closest_offset(ball0: Vector, ball1: Vector, tip0: Vector, tip1: Vector, knob0: Vector,
                   knob1: Vector) -> Vector:
    """
    Return the ball's offset (m) from the bat's midpoint at their closest, all moving on chords.

    The offset moves linearly over the interval, so its smallest value is in closed form (the
    kernel's broad phase, which bounds the gap from below with it).

    :raises CoreError: a point that is not 3 finite numbers.
    """
    try:
        return _kernel.closest_offset(ball0, ball1, tip0, tip1, knob0, knob1)
    except TypeError as error:
        raise CoreError(f'closest_offset: {error}') from error


def profile_gap(ball: Vector, knob: Vector, tip: Vector, ball_radius: float,
                profile: BatProfile) -> Tuple[float, Vector, float]:
    """
    Return the gap between a ball and a profiled bat at one instant (no input checking).

    The package's one scalar point-to-profile distance (its round cones), the kernel's (the
    batch solver has its numpy sibling, for one capsule): it runs per sub-step of the detector.

    :param ball: ball centre (metres); ``knob``, ``tip``: the bat's ends (metres).
    :param ball_radius: metres.
    :param profile: the bat's radius profile (a ``BatProfile``), scaled to knob-tip.
    :returns: (gap in metres, negative when overlapping; unit normal from the bat axis to the
        ball centre; fraction along knob-tip of the nearest bat point: its place along the
        axis, within the first and last station).
    :raises CoreError: a point that is not 3 numbers, a radius that is not a number, a
        ``profile`` that is not a ``BatProfile``.
    """
    try:
        return _kernel.profile_gap(ball, knob, tip, ball_radius, profile)
    except (TypeError, ValueError, AttributeError) as error:
        raise CoreError(f'profile_gap: {error}') from error


def lowest_gap_place(ball0: Vector, ball1: Vector, knob0: Vector, knob1: Vector, tip0: Vector,
                     tip1: Vector, ball_radius: float, profile: BatProfile) -> float:
    """
    Return where (0-1) on a linear sub-step the gap of ball and bat is smallest.

    Each body moves on its chord (from its first point to its second). A golden-section search
    of ``profile_gap`` (40 steps) against both ends; of equal gaps, the earlier place.

    :raises CoreError: as ``profile_gap``.
    """
    try:
        return _kernel.lowest_gap(ball0, ball1, knob0, knob1, tip0, tip1, ball_radius, profile)
    except (TypeError, ValueError, AttributeError) as error:
        raise CoreError(f'lowest_gap_place: {error}') from error


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
    hit = _kernel.capsule(ball0, ball1, tip0, tip1, knob0, knob1, ball_radius, bat_radius, dt)
    if hit is NotImplemented:
        points = _checked(ball0, ball1, tip0, tip1, knob0, knob1)
        hit = _kernel.capsule(*points, _non_negative('ball_radius', ball_radius),
                              _non_negative('bat_radius', bat_radius), _interval(dt))
    return hit


def time_of_impact_profile(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
                           knob0: ArrayLike, knob1: ArrayLike, ball_radius: float,
                           profile: BatProfile, dt: float = 1.0) -> Optional[ImpactResult]:
    """
    First contact between a ball and a bat given by a radius profile, or None.

    The profile is a union of round cones on sub-segments of knob-tip (see ``bat.BatProfile``);
    each piece's ends are fixed fractions of knob-tip, so they move linearly and each piece is
    solved exactly. ``bat_fraction`` in the result is along the whole knob-tip axis.

    :param ball0, ball1, tip0, tip1, knob0, knob1, ball_radius, dt: as for ``time_of_impact``.
    :param profile: the bat's radius profile, scaled to the measured knob-tip distance.

    :raises CoreError: as for ``time_of_impact``; a ``profile`` that is not a ``BatProfile``.
    """
    if not isinstance(profile, BatProfile):
        raise CoreError(f'profile must be a BatProfile (e.g. WOOD_BAT_34), not '
                        f'{type(profile).__name__}')
    hit = _kernel.profile(ball0, ball1, tip0, tip1, knob0, knob1, ball_radius, profile, dt)
    if hit is NotImplemented:
        points = _checked(ball0, ball1, tip0, tip1, knob0, knob1)
        hit = _kernel.profile(*points, _non_negative('ball_radius', ball_radius), profile,
                              _interval(dt))
    return hit


def profile_contact(b0: Vector, b1: Vector, e0: Vector, e1: Vector, s0: Vector, s1: Vector,
                    ball_radius: float, profile: BatProfile,
                    dt: float) -> Optional[ImpactResult]:
    """
    Return ``time_of_impact_profile`` on checked inputs, or None.

    For the hot paths (the detector's sub-steps, the prediction's search): every point must be
    a tuple of three finite floats, ``ball_radius`` >= 0 and ``dt`` > 0.

    :raises CoreError: input that breaks the contract (as ``time_of_impact_profile``).
    """
    hit = _kernel.profile(b0, b1, e0, e1, s0, s1, ball_radius, profile, dt)
    if hit is NotImplemented:
        return time_of_impact_profile(b0, b1, e0, e1, s0, s1, ball_radius, profile, dt)
    return hit
