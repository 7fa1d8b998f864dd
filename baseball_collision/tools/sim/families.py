"""
Families of swings: today's fixed-plane swing and the ways real swings differ from it.

A family says what ``scenarios.make_scenario`` adds to the drawn swing (:data:`FAMILIES`):

* ``'plane'``: today's swings, turning in a fixed plane (the default: the bundled bags and
  every recording made before families existed come out unchanged);
* ``'tilted'``: the swing plane tilts, the rotation axis moving at 1-3 rad/s (either way, with
  up to 20 rad/s^2 of change);
* ``'jerky'``: tilted, with hands that keep accelerating (a jerk of up to 150 m/s^3) and an
  angular-speed profile skewed by up to 0.3 (its angular acceleration changes faster on one
  side of the peak: angular jerk);
* ``'lefty'``: jerky, batting left-handed (the mirror image of a right-handed swing through the
  plane x = 0);
* ``'braking'``: jerky, either side, and after a contact the bat loses angular speed over 1-3
  ms, as a real bat does when it hits a ball: 10-35 % for a square hit at the sweet spot, any
  other contact that times its share of such a hit's angular impulse about the hands
  (``scenarios.impulse_share``: a tick or a hit on the end cap hardly slows it; misses do not
  brake);
* ``'rebound'``: a real hit, both ways: the braking family's swings, and the ball leaves the
  bat. At the contact the bat pushes the ball along the contact normal over 0.6 ms
  (``scenarios.rebounded``): its speed into the bat reverses to a coefficient of restitution
  of 0.45-0.55 against a bat whose effective mass at the spot takes 60-80 % of the exchange
  (a 0.145 kg ball against a swinging bat), so a square hit leaves at about the bat's speed
  plus half the pitch's, and a tick is hardly deflected. The frames after a contact then
  show the ball going away from the bat, as every real hit does.

The extras are drawn after everything a ``'plane'`` swing draws, so they never change it.
"""

from dataclasses import dataclass, replace
from typing import Tuple

import numpy as np

from .swings import Swing
from ..choices import FAMILIES  # the command line's options read them without the simulator
from ...errors import ToolError


def check_family(family: str) -> str:
    """
    Return ``family`` if it names a swing family.

    :raises ToolError: any other name.
    """
    if family not in FAMILIES:
        raise ToolError(f"swing family must be one of {', '.join(FAMILIES)}, got {family!r}")
    return family


@dataclass(frozen=True)
class Extras:
    """
    What a family adds to a right-handed fixed-plane swing (all zero for ``'plane'``).

    :ivar tilt_rate: rad/s; ``tilt_acceleration``: rad/s^2; ``tilt_axis``: across the plane's
        normal (unit).
    :ivar skew: the angular-speed profile's skew.
    :ivar hands_jerk: m/s^3.
    :ivar left: bat left-handed (mirror the swing).
    :ivar brake_fraction, brake_duration: the brake after a contact (0: none), seconds.
    :ivar restitution: the ball's coefficient of restitution off the bat (0: no rebound, the
        ball flies on through the bat as if nothing were there); ``mass_share``: the bat's
        effective mass at the spot over the sum of it and the ball's.
    """

    tilt_rate: float = 0.0
    tilt_acceleration: float = 0.0
    tilt_axis: Tuple[float, float, float] = (0.0, 0.0, 1.0)
    skew: float = 0.0
    hands_jerk: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    left: bool = False
    brake_fraction: float = 0.0
    brake_duration: float = 0.002
    restitution: float = 0.0
    mass_share: float = 0.0


def draw_extras(family: str, rng: np.random.Generator, normal: np.ndarray) -> Extras:
    """
    Draw what ``family`` adds to a swing turning about ``normal`` (draws nothing for 'plane').

    :raises ToolError: an unknown family.
    """
    if check_family(family) == 'plane':
        return Extras()
    sign = 1.0 if rng.uniform() < 0.5 else -1.0
    rate = sign * rng.uniform(1.0, 3.0)
    change = rng.uniform(-20.0, 20.0)
    # an axis across the normal, so the normal itself moves at the tilt rate
    helper = rng.normal(size=3)
    axis = helper - normal * float(helper @ normal)
    axis = axis / float(np.linalg.norm(axis))
    extras = Extras(tilt_rate=rate, tilt_acceleration=change, tilt_axis=tuple(axis.tolist()))
    if family == 'tilted':
        return extras
    skew = rng.uniform(-0.3, 0.3)
    jerk = rng.uniform(-150.0, 150.0, size=3)
    hits = family in ('braking', 'rebound')
    left = family == 'lefty' or (hits and rng.uniform() < 0.5)
    fraction = rng.uniform(0.10, 0.35) if hits else 0.0
    duration = rng.uniform(0.001, 0.003)
    extras = replace(extras, skew=skew, hands_jerk=tuple(jerk.tolist()), left=left,
                     brake_fraction=fraction, brake_duration=duration)
    if family == 'rebound':
        extras = replace(extras, restitution=rng.uniform(0.45, 0.55),
                         mass_share=rng.uniform(0.6, 0.8))
    return extras


_MIRROR = np.array([-1.0, 1.0, 1.0])


def mirrored(swing: Swing) -> Swing:
    """
    Return the mirror image of a swing through the plane x = 0: a left-handed batter.

    Points and velocities flip their x; rotation axes (the plane normal, the tilt axis) are
    axial vectors and flip the other two components; the roll turns the other way.
    """
    def flip(vector) -> Tuple[float, float, float]:
        return tuple((np.asarray(vector) * _MIRROR).tolist())

    def flip_axis(vector) -> Tuple[float, float, float]:
        return tuple((-np.asarray(vector) * _MIRROR).tolist())

    return replace(swing, hands=flip(swing.hands), direction=flip(swing.direction),
                   plane_normal=flip_axis(swing.plane_normal),
                   hands_peak_velocity=flip(swing.hands_peak_velocity),
                   hands_acceleration=flip(swing.hands_acceleration),
                   hands_jerk=flip(swing.hands_jerk), tilt_axis=flip_axis(swing.tilt_axis),
                   roll_rate=-swing.roll_rate)
