"""
Scenarios: a pitch and a swing aimed at each other so that one kind of event happens.

``make_scenario`` draws a swing of a family (``families``: today's right-handed fixed-plane
swing by default) and a 76-94 mph pitch that make a 'barrel', 'end_cap', 'handle', 'graze',
'miss_over' or 'miss_under' (:data:`KINDS`), or one of the closest calls (:data:`CLOSE_KINDS`),
each checked against its computed :class:`~.truth.Truth` and drawn again if the kind does not
hold. A scenario runs over ``[0, t_end]`` seconds of scenario time.
"""

from dataclasses import dataclass, replace
import math
from typing import Optional, Tuple

import numpy as np

from .common import as_times, check_number, SQRT_TWO_PI, TimeLike, unit, Vector
from .families import check_family, draw_extras, Extras, mirrored
from .pitches import BALL_RADIUS, GRAVITY, MPH, Pitch, RPM
from .swings import Swing
from .truth import compute_truth, segment_gaps, Truth
from ..choices import KINDS  # the command line's options read them without the simulator
from ...core.bat import BatProfile, PoseBatGeometry, SWEET_SPOT_FROM_TIP, WOOD_BAT_34
from ...errors import ToolError

CLOSE_KINDS = ('tick', 'shave')
"""The closest calls ``make_scenario`` also builds: a contact 0.1-1 mm deep, a miss by 0.1-2 mm."""


@dataclass(frozen=True)
class Scenario:
    """
    A swing against a pitch over [0, t_end] seconds, with its truth.

    ``truth`` is computed on construction when not given (``compute_truth``).

    :ivar name: a label.
    :ivar kind: one of ``KINDS``, or ``'custom'``.
    :ivar swing: the bat's motion.
    :ivar pitch: the ball's flight (covering [0, t_end]).
    :ivar t_end: duration (s).
    :ivar profile: the bat's radius profile.
    :ivar ball_radius: ball radius (m).
    :ivar truth: what happened.
    """

    name: str
    kind: str
    swing: Swing
    pitch: Pitch
    t_end: float
    profile: BatProfile = WOOD_BAT_34
    ball_radius: float = BALL_RADIUS
    truth: Optional[Truth] = None

    def __post_init__(self) -> None:
        """
        Check the kind and compute the truth when not given.

        :raises ToolError: an unknown kind, or as ``compute_truth``.
        """
        if self.kind not in KINDS + CLOSE_KINDS + ('custom',):
            raise ToolError(f'scenario kind must be one of {KINDS + CLOSE_KINDS + ("custom",)}, '
                            f'got {self.kind!r}')
        if self.truth is None:
            object.__setattr__(self, 'truth', compute_truth(
                self.swing, self.pitch, self.t_end, self.profile, self.ball_radius))

    def gap(self, t: TimeLike) -> np.ndarray:
        """Return the signed ball-bat gap in metres at time(s) t (s); negative is overlap."""
        times, shape = as_times(t)
        knob, tip = self.swing.knob_tip(times)
        gaps = segment_gaps(self.pitch.position(times), knob, tip, self.profile,
                            self.ball_radius)
        return gaps.min(axis=0).reshape(shape)


def _kind_holds(kind: str, truth: Truth) -> bool:
    """Return whether a truth is an instance of a scenario kind."""
    if kind == 'shave':
        return not truth.contact and 1e-4 <= truth.min_gap_m <= 2e-3
    if kind in ('miss_over', 'miss_under'):
        upward = truth.min_gap_vector[2] > 0.0
        return (not truth.contact and 0.02 <= truth.min_gap_m <= 0.15
                and upward == (kind == 'miss_over'))
    if not truth.contact or truth.time_s is None:
        return False
    if kind == 'barrel':
        return truth.feature == 'side' and 0.05 <= truth.distance_from_tip_m <= 0.25
    if kind == 'end_cap':
        return truth.feature == 'tip_end'
    if kind == 'handle':
        return truth.feature == 'side' and 0.2 <= truth.distance_from_knob_m <= 0.4
    if kind == 'tick':
        return -1e-3 <= truth.min_gap_m <= -1e-4
    return -0.010 <= truth.min_gap_m <= -0.001  # graze


def _draw_swing(rng: np.random.Generator, contact_time: float, geometry: PoseBatGeometry,
                family: str = 'plane') -> Tuple[Swing, Extras]:
    """
    Draw a swing of a family, its reference at the contact time, sweet spot 28-34.5 m/s.

    The fixed-plane draws come first and in today's order, so ``'plane'`` swings are unchanged;
    a family's extras (``families.draw_extras``) follow, and are returned with the swing.
    """
    azimuth = math.radians(rng.uniform(-20.0, 15.0))  # of the bat from +x toward +y
    elevation = math.radians(rng.uniform(-30.0, 5.0))  # barrel below the hands when < 0
    direction = np.array([math.cos(elevation) * math.cos(azimuth),
                          math.cos(elevation) * math.sin(azimuth), math.sin(elevation)])
    attack = math.radians(rng.uniform(0.0, 15.0))  # the barrel's upward path at contact
    path = np.array([-math.sin(azimuth) * math.cos(attack),
                     math.cos(azimuth) * math.cos(attack), math.sin(attack)])
    path = unit('path', path - direction * float(path @ direction))
    normal = np.cross(direction, path)
    hands = np.array([rng.uniform(-0.6, -0.45), rng.uniform(0.05, 0.4), rng.uniform(0.85, 1.1)])
    hands_width = rng.uniform(0.035, 0.05)
    hands_lag = rng.uniform(0.02, 0.05)  # the hands' speed peaks before contact
    hands_dir = unit('hands', np.array([rng.uniform(0.0, 0.4), 1.0, rng.uniform(-0.2, 0.1)]))
    hands_peak = hands_dir * rng.uniform(5.0, 8.0)
    hands_accel = np.array([rng.uniform(-12.0, -4.0), rng.uniform(-4.0, 4.0),
                            rng.uniform(-4.0, 4.0)])
    grip = rng.uniform(0.08, 0.12)
    target = rng.uniform(28.0, 34.5)
    lead = rng.uniform(0.15, 0.5)  # peak angular speed after contact, in widths
    turn = rng.uniform(4.6, 5.6)  # total rotation < 2 pi
    roll_rate = rng.uniform(-4.0, 4.0)
    extras = draw_extras(family, rng, normal)
    length = float(np.linalg.norm(np.subtract(geometry.tip_offset, geometry.knob_offset)))
    hands_velocity = hands_peak * math.exp(-0.5 * (hands_lag / hands_width) ** 2)
    # angular speed at contact for the drawn sweet-spot speed
    lever = length - SWEET_SPOT_FROM_TIP - grip
    if extras.tilt_rate:  # the tilting plane moves the sweet spot too
        hands_velocity = hands_velocity + lever * extras.tilt_rate * np.cross(
            extras.tilt_axis, direction)
    across = np.cross(normal, direction)
    along = float(hands_velocity @ across)
    square = along * along - float(hands_velocity @ hands_velocity) + target * target
    omega_contact = (-along + math.sqrt(max(square, 0.0))) / lever
    peak = omega_contact * math.exp(0.5 * lead * lead) / (1.0 - extras.skew * lead)
    width = turn / (peak * SQRT_TWO_PI)
    swing = Swing(
        reference_time=contact_time, hands=tuple(hands), direction=tuple(direction),
        plane_normal=tuple(normal), peak_angular_speed=peak,
        peak_time=contact_time + lead * width, angular_width=width,
        hands_peak_velocity=tuple(hands_peak), hands_peak_time=contact_time - hands_lag,
        hands_width=hands_width, hands_acceleration=tuple(hands_accel), grip_from_knob=grip,
        roll_rate=roll_rate, geometry=geometry, tilt_axis=extras.tilt_axis,
        tilt_rate=extras.tilt_rate, tilt_acceleration=extras.tilt_acceleration,
        angular_skew=extras.skew, hands_jerk=extras.hands_jerk,
        brake_fraction=extras.brake_fraction, brake_duration=extras.brake_duration)
    return (mirrored(swing) if extras.left else swing), extras


def _draw_ball_velocity(rng: np.random.Generator, contact: np.ndarray, drag_constant: float,
                        release_y: float) -> np.ndarray:
    """Draw the ball's velocity at contact for a 76-94 mph release about 1.4-2.0 m high."""
    release_speed = rng.uniform(76.0, 94.0) * MPH
    travel = release_y - float(contact[1])
    speed = release_speed * math.exp(-drag_constant * travel)
    flight = travel / (0.5 * (speed + release_speed))
    release_height = rng.uniform(1.5, 1.8)  # the drag-free aim lands ~0.1 m higher
    release_x = rng.uniform(-0.6, 0.6)
    down = (release_height - float(contact[2]) + 0.5 * GRAVITY * flight * flight) / (
        speed * flight)
    across = (float(contact[0]) - release_x) / (speed * flight)
    down = min(max(down, 0.0), 0.3)
    across = min(max(across, -0.1), 0.1)
    along = math.sqrt(1.0 - down * down - across * across)
    return speed * np.array([across, -along, -down])


def _draw_spin(rng: np.random.Generator, velocity: np.ndarray) -> Vector:
    """
    Draw a pitch's spin (rad/s): 1,500-2,800 rpm about an axis at any angle across the flight.

    The axis's part across the velocity (the spin that lifts or breaks the ball: its
    "efficiency") is 0.3-1.0 of the spin, pointing any way around the flight; the rest is gyro
    spin along it (a slider's). So the Magnus acceleration is 1-7 m/s^2 in any direction
    across the flight: a fastball's rise, a curveball's drop, a slider's or sinker's sideways
    break (MLB pitches spin at 1,500-3,000 rpm).
    """
    rate = rng.uniform(1500.0, 2800.0) * RPM
    efficiency = rng.uniform(0.3, 1.0)
    angle = rng.uniform(0.0, 2.0 * math.pi)
    along = unit('velocity', velocity)
    side = unit('side', np.cross(along, (0.0, 0.0, 1.0)))
    up = np.cross(side, along)
    across = math.cos(angle) * side + math.sin(angle) * up
    axis = efficiency * across + math.sqrt(1.0 - efficiency * efficiency) * along
    return tuple((rate * axis).tolist())


def _draw_scenario(kind: str, rng: np.random.Generator, lead_s: float, trail_s: float,
                   profile: BatProfile, ball_radius: float, geometry: PoseBatGeometry,
                   family: str = 'plane', spin: bool = False) -> Optional[Scenario]:
    """
    Draw one candidate scenario of a kind; None when the draw is implausible.

    :raises ToolError: a degenerate draw (the caller draws again).
    """
    contact_time = lead_s + rng.uniform(-0.005, 0.005)
    t_end = lead_s + trail_s
    swing, extras = _draw_swing(rng, contact_time, geometry, family)
    length = swing.length
    segments = profile.segments()
    if kind == 'barrel':
        fraction = 1.0 - rng.uniform(0.07, 0.22) / length
    elif kind == 'handle':
        fraction = rng.uniform(0.23, 0.37) / length
    elif kind == 'end_cap':
        fraction = segments[-1][1]
    elif kind in ('graze',) + CLOSE_KINDS:
        fraction = 1.0 - rng.uniform(0.06, 0.3) / length
    else:
        fraction = 1.0 - rng.uniform(0.06, 0.35) / length
    spot = swing.point(contact_time, fraction)
    reach = ball_radius + profile.radius_at(fraction)
    release_y = rng.uniform(16.5, 17.0)
    drag_constant = Pitch((0.0, 0.0, 0.0), (0.0, -1.0, 0.0), duration=1e-3).drag_constant
    velocity = _draw_ball_velocity(rng, spot, drag_constant, release_y)
    # the frame of the encounter: axis d, the ball's motion across it, and "up" across both
    axis = swing.knob_tip(contact_time)
    axis = unit('axis', axis[1] - axis[0])
    relative = velocity - swing.point_velocity(contact_time, fraction)
    across = relative - axis * float(relative @ axis)
    incoming = unit('relative velocity', across)
    up = unit('up', np.cross(axis, incoming))
    if up[2] < 0.0:
        up = -up
    if kind in ('barrel', 'handle'):
        angle = math.radians(rng.uniform(-55.0, 55.0))
        centre = spot + reach * (-math.cos(angle) * incoming + math.sin(angle) * up)
    elif kind == 'end_cap':
        angle = math.radians(rng.uniform(-35.0, 35.0))
        tilt = math.radians(rng.uniform(25.0, 60.0))
        side = -math.cos(angle) * incoming + math.sin(angle) * up
        centre = spot + reach * (math.cos(tilt) * side + math.sin(tilt) * axis)
    elif kind == 'graze':
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        centre = spot + sign * (reach - rng.uniform(0.002, 0.008)) * up
    elif kind in CLOSE_KINDS:
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        clearance = -rng.uniform(1e-4, 1e-3) if kind == 'tick' else rng.uniform(1e-4, 2e-3)
        centre = spot + sign * (reach + clearance) * up
    else:
        sign = 1.0 if kind == 'miss_over' else -1.0
        centre = spot + sign * (reach + rng.uniform(0.03, 0.12)) * up
    pitch = Pitch.through(centre, velocity, contact_time, release_y=release_y,
                          end_time=t_end + 0.01)
    release_speed = math.hypot(*pitch.release_velocity) / MPH
    if not (74.0 <= release_speed <= 96.0 and 1.0 <= pitch.release_position[2] <= 2.6):
        return None
    if spin:  # through the same contact: released wherever the spin bends its flight back to
        pitch = Pitch.through(centre, velocity, contact_time, release_y=release_y,
                              end_time=t_end + 0.01, spin=_draw_spin(rng.spawn(1)[0], velocity))
    name = f'{kind}-{int(rng.integers(0, 2 ** 32)):08x}'
    scenario = Scenario(name=name, kind=kind, swing=swing, pitch=pitch, t_end=t_end,
                        profile=profile, ball_radius=ball_radius)
    if kind in CLOSE_KINDS:
        scenario = _settle_clearance(scenario, clearance, velocity, contact_time, release_y)
    return rebounded(_braked(scenario), extras.restitution, extras.mass_share)


def _settle_clearance(scenario: Scenario, clearance: float, velocity: np.ndarray,
                      contact_time: float, release_y: float) -> Scenario:
    """
    Return the scenario with the ball moved until its smallest gap is ``clearance`` (m).

    The smallest gap changes about one for one with a shift of the ball along the normal at
    the closest approach: a few such steps bring it within a micrometre.
    """
    for _ in range(4):
        truth = scenario.truth
        error = clearance - truth.min_gap_m
        if abs(error) < 1e-6:
            break
        normal = np.asarray(truth.min_gap_vector) / truth.min_gap_m
        centre = scenario.pitch.position(contact_time) + error * normal
        pitch = Pitch.through(centre, velocity, contact_time, release_y=release_y,
                              end_time=scenario.t_end + 0.01, spin=scenario.pitch.spin)
        scenario = replace(scenario, pitch=pitch, truth=None)
    return scenario


def _braked(scenario: Scenario) -> Scenario:
    """
    Return the scenario with its swing braking from the first contact on (if it brakes).

    The swing's drawn ``brake_fraction`` is what a square hit at the sweet spot takes away; the
    contact's own takes that times its ``impulse_share`` (a tick or an end-cap hit hardly
    slows a bat). The first contact is before the brake, so the truth stays as it is.
    """
    truth, swing = scenario.truth, scenario.swing
    if not truth.contact or not swing.brake_fraction:
        return scenario
    fraction = swing.brake_fraction * impulse_share(scenario)
    return replace(scenario, swing=replace(swing, brake_time=truth.time_s,
                                           brake_fraction=fraction), truth=truth)


def rebounded(scenario: Scenario, restitution: float, mass_share: float) -> Scenario:
    """
    Return the scenario with its ball pushed off the bat from the first contact on.

    The push is along the contact normal (no friction): the ball's speed into the bat's
    surface, ``u`` (m/s, from ``surface_motion``), changes by ``-(1 + restitution) *
    mass_share * u``, over ``Pitch.rebound_duration`` from the contact instant. The first
    contact is before the push, so the truth stays as it is. Unchanged without a contact or
    with ``restitution`` 0.

    :param restitution: the coefficient of restitution (0-1).
    :param mass_share: the bat's effective mass at the spot over the sum of it and the ball's
        (0-1).
    """
    truth = scenario.truth
    if not truth.contact or not restitution:
        return scenario
    relative, normal = surface_motion(scenario)
    into = float(relative @ normal)  # < 0: the ball moves into the bat
    change = -(1.0 + restitution) * mass_share * min(into, 0.0) * normal
    pitch = replace(scenario.pitch, rebound_time=truth.time_s,
                    rebound_change=tuple(change.tolist()))
    return replace(scenario, pitch=pitch, truth=truth)


def surface_motion(scenario: Scenario) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return the ball's velocity relative to the bat's surface point it first touches (m/s).

    With the unit contact normal (from the bat's axis toward the ball) at the first contact.

    :raises ToolError: a scenario without a contact.
    """
    truth, swing = scenario.truth, scenario.swing
    if not truth.contact:
        raise ToolError(f'scenario {scenario.name!r} has no contact')
    t = truth.time_s
    point, normal = np.asarray(truth.point), np.asarray(truth.normal)
    on_axis = swing.point(t, truth.bat_fraction)
    surface_velocity = swing.point_velocity(t, truth.bat_fraction) + np.cross(
        swing.angular_velocity(t), point - on_axis)
    return scenario.pitch.velocity(t) - surface_velocity, normal


def impulse_share(scenario: Scenario) -> float:
    """
    Return how much of a square sweet-spot hit's swing-slowing impulse the first contact has.

    A ball slows the swing by its angular impulse about the hands along the swing's angular
    velocity: the impulse along the contact normal, which grows with the normal part of the
    ball's speed relative to the bat's surface point there (a graze or a tick meets the bat
    almost tangentially), times its lever about the hands across the normal (an end-cap hit
    pushes along the bat: almost no lever). The share is ``(closing / relative speed) *
    (lever / the sweet spot's lever)``, clipped to [0, 1]: 1 for a square hit at (or beyond)
    the sweet spot, about 0.1 for a tick 0.3 mm deep, near 0 for the end cap.

    :returns: 0 for a scenario without a contact.
    """
    truth, swing = scenario.truth, scenario.swing
    if not truth.contact:
        return 0.0
    t = truth.time_s
    point = np.asarray(truth.point)
    omega = swing.angular_velocity(t)
    relative, normal = surface_motion(scenario)
    closing = -float(relative @ normal)  # > 0: the ball moves into the bat
    lever = float(np.cross(point - swing.hands_position(t), normal) @ omega) / float(
        np.linalg.norm(omega))
    sweet_lever = swing.sweet_spot_fraction() * swing.length - swing.grip_from_knob
    share = (closing / float(np.linalg.norm(relative))) * (lever / sweet_lever)
    return min(max(share, 0.0), 1.0)


def make_scenario(kind: str, rng: np.random.Generator, *, lead_s: float = 0.15,
                  trail_s: float = 0.10, profile: BatProfile = WOOD_BAT_34,
                  ball_radius: float = BALL_RADIUS,
                  geometry: PoseBatGeometry = PoseBatGeometry(),
                  max_attempts: int = 50, family: str = 'plane', spin: bool = False) -> Scenario:
    """
    Build a plausible pitch and swing aimed so that one kind of event happens.

    A swing of ``family`` (``families.FAMILIES``: today's right-handed fixed-plane swing by
    default; sweet spot at 28-34.5 m/s at contact, the hands leading) and a
    76-94 mph pitch released 16.5-17 m away about 1.4-2.0 m high. The contact instant (about
    ``lead_s`` after the start) and spot on the bat are chosen first; the ball is placed there at
    that instant, offset along the contact normal, and the flight integrated backward to the
    release. Kinds:

    * ``'barrel'``: the side of the barrel, 0.05-0.25 m from the tip (along the axis);
    * ``'end_cap'``: the rounded barrel end;
    * ``'handle'``: the side of the bat 0.2-0.4 m from the knob;
    * ``'graze'``: a foul tip: a contact whose deepest overlap is 1-10 mm;
    * ``'miss_over'`` / ``'miss_under'``: no contact, the ball passing 2-15 cm over / under the
      bat (smallest gap, with its vertical component of that sign);
    * ``'tick'`` and ``'shave'`` (:data:`CLOSE_KINDS`, not in ``KINDS``): the closest calls, a
      contact 0.1-1 mm deep and a miss by 0.1-2 mm.

    Each draw is checked against its computed truth and redrawn if the kind does not hold.

    :param kind: one of ``KINDS``.
    :param rng: the random source (the result is a function of its state).
    :param lead_s: seconds from the start to (about) the contact or closest approach.
    :param trail_s: seconds after that to the end.
    :param profile: the bat's radius profile.
    :param ball_radius: ball radius (m).
    :param geometry: where knob and tip sit in the bat body frame of the swing's pose.
    :param max_attempts: draws before giving up.
    :param family: the swing family.
    :param spin: a spinning pitch (``_draw_spin``: the Magnus force bends its flight by 1-7
        m/s^2 across it), its spin drawn from a generator ``rng`` spawns: ``rng``'s own draws
        are those without spin, so the scenario is the one without spin (the same swing and
        contact, the pitch as plausible) with the ball's flight before the contact bent, and
        released where the bent flight comes from (unless the bent flight changes what the kind
        needs, a miss's gap, and the draw is made again); else none.

    :returns: The scenario, running over [0, lead_s + trail_s].

    :raises ToolError: an unknown kind or family, bad durations, or no draw of the kind within
        ``max_attempts``.
    """
    if kind not in KINDS + CLOSE_KINDS:
        raise ToolError(f'scenario kind must be one of {KINDS + CLOSE_KINDS}, got {kind!r}')
    check_family(family)
    lead_s = check_number('lead_s', lead_s, minimum=0.05)
    trail_s = check_number('trail_s', trail_s, minimum=0.02)
    failure = None
    for _ in range(max(1, int(max_attempts))):
        try:
            scenario = _draw_scenario(kind, rng, lead_s, trail_s, profile, ball_radius, geometry,
                                      family, spin)
        except ToolError as error:
            failure = error
            continue
        if scenario is not None and _kind_holds(kind, scenario.truth):
            return scenario
    raise ToolError(f'no {kind!r} scenario in {max_attempts} draws') from failure
