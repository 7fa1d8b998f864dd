"""
The exact truth of a scenario: first contact, contact spot and speeds, smallest gap.

The first contact of the continuous motion is found by dense evaluation of the gap on a 20 us
grid, local minima refined so a shallow graze is not lost, and bisection to 1e-12 s, against the
same geometry the package uses: the ball sphere against the union of the round cones of
``profile.segments()`` placed on knob-tip by fraction (each piece's nearest sphere in closed
form over the grid, :func:`segment_gaps`, written here apart from the solver's;
``core.toi.profile_gap`` at the instants found).
"""

from dataclasses import dataclass
import math
from typing import Callable, Dict, Optional, Tuple

import numpy as np

from .common import check_number, Vector
from .pitches import BALL_RADIUS, Pitch
from .swings import Swing
from ...core.bat import BatProfile, WOOD_BAT_34
from ...core.toi import profile_gap
from ...errors import ToolError

TRUTH_GRID_S = 2e-5
"""Step (s) of the dense gap evaluation behind ``Truth``."""

TRUTH_TIME_TOLERANCE_S = 1e-12
"""Width (s) of the final bisection bracket of the first-contact time."""

_REFINE_POINTS = 65  # points per pass of the crossing and minimum refinements


@dataclass(frozen=True)
class Truth:
    """
    What really happened in a scenario, from the continuous motion.

    Contact fields are None for a miss.

    :ivar contact: the ball touched the bat (gap <= 0) within the scenario.
    :ivar time_s: first-contact instant (s, scenario time), to 1e-12 s.
    :ivar point: contact point on the bat surface (m).
    :ivar normal: unit normal at contact, from the bat axis toward the ball centre.
    :ivar bat_fraction: contact position along knob-tip (0 knob, 1 tip), as the solver reports
        it (the contact point's place along the axis; on an end cap, that end's station).
    :ivar distance_from_knob_m: ``bat_fraction * length`` (m).
    :ivar distance_from_tip_m: ``(1 - bat_fraction) * length`` (m).
    :ivar feature: ``'side'``, ``'knob_end'`` or ``'tip_end'``: the part of the bat touched.
    :ivar sweet_spot_speed_mps: speed of the axis point 0.1524 m from the tip at contact (m/s).
    :ivar ball_speed_mps: ball speed at contact (m/s).
    :ivar bat_speed_at_contact_mps: speed of the axis point at ``bat_fraction`` at contact (m/s).
    :ivar min_gap_m: smallest gap over the scenario (m); negative is the deepest overlap.
    :ivar min_gap_time_s: when it happens (s).
    :ivar min_gap_vector: ``min_gap_m`` times the unit normal from the bat axis toward the ball
        centre at that instant: from the bat surface to the ball surface for a miss (m).
    :ivar min_gap_fraction: fraction along knob-tip of the nearest bat point at that instant
        (``core.toi.profile_gap``'s).
    """

    contact: bool
    time_s: Optional[float]
    point: Optional[Vector]
    normal: Optional[Vector]
    bat_fraction: Optional[float]
    distance_from_knob_m: Optional[float]
    distance_from_tip_m: Optional[float]
    feature: Optional[str]
    sweet_spot_speed_mps: Optional[float]
    ball_speed_mps: Optional[float]
    bat_speed_at_contact_mps: Optional[float]
    min_gap_m: float
    min_gap_time_s: float
    min_gap_vector: Vector
    min_gap_fraction: float


def segment_gaps(ball: np.ndarray, knob: np.ndarray, tip: np.ndarray, profile: BatProfile,
                 ball_radius: float) -> np.ndarray:
    """
    Return the gap (m) of the ball to every piece of the profile: (S, N) for (N, 3) input.

    A piece is the union of the spheres along its axis whose radius grows linearly from its
    start's to its end's; the gap is the least over them of the distance to the sphere, a
    convex function of the axis fraction f, least at ``dr d / (L sqrt(L^2 - dr^2))`` past the
    foot of the ball centre's perpendicular (d its distance from the axis, L the piece's
    length, dr its radius growth), then clipped to the piece.
    """
    axis = tip - knob
    rows = []
    for f0, f1, r0, r1 in profile.segments():
        start = knob + f0 * axis
        piece = (f1 - f0) * axis
        offset = ball - start
        length2 = np.einsum('ij,ij->i', piece, piece)
        growth = r1 - r0
        with np.errstate(invalid='ignore', divide='ignore'):
            along = np.where(length2 > 0.0, np.einsum('ij,ij->i', offset, piece) / length2, 0.0)
            across = np.linalg.norm(offset - along[:, None] * piece, axis=1)
            slide = growth * across / np.sqrt(length2 * (length2 - growth * growth))
        fraction = np.clip(np.where(length2 > growth * growth, along + slide,
                                    1.0 if growth > 0.0 else 0.0), 0.0, 1.0)
        rows.append(np.linalg.norm(offset - fraction[:, None] * piece, axis=1)
                    - (r0 + fraction * growth) - ball_radius)
    return np.array(rows)


@dataclass(frozen=True)
class _Closest:
    """The closest piece of a profile to the ball at one instant."""

    gap: float
    point: np.ndarray
    normal: np.ndarray
    fraction: float
    feature: str


def _closest(ball: np.ndarray, knob: np.ndarray, tip: np.ndarray, profile: BatProfile,
             ball_radius: float) -> _Closest:
    """Return the gap, surface point, normal, fraction and feature of the nearest capsule."""
    gap, normal, fraction = profile_gap(tuple(ball.tolist()), tuple(knob.tolist()),
                                        tuple(tip.tolist()), ball_radius, profile)
    segments = profile.segments()
    feature = 'side'
    if fraction <= segments[0][0]:
        feature = 'knob_end'
    elif fraction >= segments[-1][1]:
        feature = 'tip_end'
    unit_normal = np.array(normal)
    # the bat surface point facing the ball: the ball centre less the ball radius and the gap
    point = ball - (gap + ball_radius) * unit_normal
    return _Closest(gap=gap, point=point, normal=unit_normal, fraction=fraction,
                    feature=feature)


def _refine_crossing(gaps_at: Callable[[np.ndarray], np.ndarray], lo: float, hi: float,
                     tolerance: float) -> float:
    """
    Return the end of a bracket, at most ``tolerance`` wide, past the first sign change.

    The gap is > 0 at ``lo`` and <= 0 at ``hi``; each pass evaluates it on ``_REFINE_POINTS``
    points across the bracket and keeps the grid cell of the first point with gap <= 0.
    """
    while hi - lo > tolerance:
        times = np.linspace(lo, hi, _REFINE_POINTS)
        touching = np.flatnonzero(gaps_at(times[1:]) <= 0.0)
        index = int(touching[0]) + 1 if touching.size else _REFINE_POINTS - 1
        new_lo, new_hi = float(times[index - 1]), float(times[index])
        if (new_lo, new_hi) == (lo, hi) or not new_lo < new_hi:
            break
        lo, hi = new_lo, new_hi
    return hi


def _refine_minimum(gaps_at: Callable[[np.ndarray], np.ndarray], lo: float, hi: float,
                    tolerance: float) -> Tuple[float, float]:
    """
    Return (time, gap) of the minimum of a gap unimodal on [lo, hi] to within ``tolerance`` s.

    Each pass evaluates ``_REFINE_POINTS`` points and keeps the two cells around the smallest.
    """
    best_time, best_gap = lo, math.inf
    while True:
        times = np.linspace(lo, hi, _REFINE_POINTS)
        values = gaps_at(times)
        index = int(np.argmin(values))
        if values[index] <= best_gap:
            best_time, best_gap = float(times[index]), float(values[index])
        new_lo = float(times[max(index - 1, 0)])
        new_hi = float(times[min(index + 1, _REFINE_POINTS - 1)])
        if hi - lo <= tolerance or (new_lo, new_hi) == (lo, hi):
            return best_time, best_gap
        lo, hi = new_lo, new_hi


GapFunction = Callable[[np.ndarray], np.ndarray]


def _first_contact(gaps_at: GapFunction, grid: np.ndarray, values: np.ndarray
                   ) -> Tuple[Optional[float], Dict[int, Tuple[float, float]]]:
    """
    Return the first-contact time (None for none) and the grid minima refined on the way.

    The first grid sign change, or an earlier local minimum that dips <= 0, narrowed to
    ``TRUTH_TIME_TOLERANCE_S``; refined minima as ``{grid index: (time, gap)}``.
    """
    count = grid.size
    minima = np.flatnonzero((values[1:-1] <= values[:-2]) & (values[1:-1] <= values[2:])) + 1
    # between grid points the gap can dip below a grid value by at most its largest change per
    # step (a Lipschitz bound from the grid itself), doubled for safety
    near = 2.0 * float(np.max(np.abs(np.diff(values)))) if count > 1 else math.inf
    first = None
    crossings = np.flatnonzero(values <= 0.0)
    if crossings.size and crossings[0] == 0:
        first = 0.0
    elif crossings.size:
        i = int(crossings[0])
        first = _refine_crossing(gaps_at, float(grid[i - 1]), float(grid[i]),
                                 TRUTH_TIME_TOLERANCE_S)
    refined = {}
    for j in minima:
        if first is not None and grid[j] >= first:
            break
        if values[j] > near:
            continue
        t_min, g_min = _refine_minimum(gaps_at, float(grid[j - 1]), float(grid[j + 1]), 1e-12)
        refined[int(j)] = (t_min, g_min)
        if g_min <= 0.0:
            first = _refine_crossing(gaps_at, float(grid[j - 1]), t_min,
                                     TRUTH_TIME_TOLERANCE_S)
            break
    return first, refined


def _smallest_gap(gaps_at: GapFunction, grid: np.ndarray, values: np.ndarray,
                  refined: Dict[int, Tuple[float, float]]) -> Tuple[float, float]:
    """Return (time, gap) of the smallest gap: refined around the smallest grid value."""
    count = grid.size
    k = int(np.argmin(values))
    if k in refined:
        min_time, min_gap = refined[k]
    elif 0 < k < count - 1:
        min_time, min_gap = _refine_minimum(gaps_at, float(grid[k - 1]), float(grid[k + 1]),
                                            1e-12)
    else:
        min_time, min_gap = float(grid[k]), float(values[k])
    for t_min, g_min in refined.values():
        if g_min < min_gap:
            min_time, min_gap = t_min, g_min
    return min_time, min_gap


def compute_truth(swing: Swing, pitch: Pitch, t_end: float, profile: BatProfile = WOOD_BAT_34,
                  ball_radius: float = BALL_RADIUS, grid_s: float = TRUTH_GRID_S) -> Truth:
    """
    Return the exact truth of a swing against a pitch over [0, t_end] seconds.

    The gap (ball sphere against the union of the profile's round cones on knob-tip) of the
    continuous motion is evaluated on a grid of ``grid_s``; every grid local minimum within twice
    the largest grid-to-grid change of zero is refined (nested sub-grids), so a touch shorter than
    the grid step is not lost, and the first sign change is narrowed to
    ``TRUTH_TIME_TOLERANCE_S``. ``time_s`` is the end of that bracket at which the gap is <= 0
    (0.0 when touching at the start). The smallest gap is refined around the smallest grid
    value (and any refined local minimum below it).

    :param swing: the bat's motion.
    :param pitch: the ball's flight; it must cover [0, t_end].
    :param t_end: scenario duration (s, > 0).
    :param profile: the bat's radius profile (scaled to the swing's bat length by fraction).
    :param ball_radius: ball radius (m, >= 0).
    :param grid_s: step (s) of the dense evaluation.

    :returns: The truth.

    :raises ToolError: bad parameters or a pitch not covering [0, t_end].
    """
    t_end = check_number('t_end', t_end, positive=True)
    ball_radius = check_number('ball_radius', ball_radius, minimum=0.0)
    grid_s = check_number('grid_s', grid_s, positive=True)
    if pitch.release_time > 0.0 or pitch.end_time < t_end:
        raise ToolError(
            f'the pitch covers [{pitch.release_time}, {pitch.end_time}] s, not [0, {t_end}] s')

    def gaps_at(times: np.ndarray) -> np.ndarray:
        knob, tip = swing.knob_tip(times)
        return segment_gaps(pitch.position(times), knob, tip, profile, ball_radius).min(axis=0)

    count = int(math.ceil(t_end / grid_s)) + 1
    grid = np.linspace(0.0, t_end, count)
    values = gaps_at(grid)
    first, refined = _first_contact(gaps_at, grid, values)
    min_time, min_gap = _smallest_gap(gaps_at, grid, values, refined)
    knob, tip = swing.knob_tip(min_time)
    closest = _closest(pitch.position(min_time), knob, tip, profile, ball_radius)
    min_fields = {'min_gap_m': float(min_gap), 'min_gap_time_s': float(min_time),
                  'min_gap_vector': tuple(float(v) for v in closest.normal * min_gap),
                  'min_gap_fraction': float(closest.fraction)}
    if first is None:
        return Truth(contact=False, time_s=None, point=None, normal=None, bat_fraction=None,
                     distance_from_knob_m=None, distance_from_tip_m=None, feature=None,
                     sweet_spot_speed_mps=None, ball_speed_mps=None,
                     bat_speed_at_contact_mps=None, **min_fields)
    knob, tip = swing.knob_tip(first)
    touch = _closest(pitch.position(first), knob, tip, profile, ball_radius)
    length = swing.length
    sweet = swing.point_velocity(first, swing.sweet_spot_fraction())
    return Truth(
        contact=True, time_s=float(first), point=tuple(float(v) for v in touch.point),
        normal=tuple(float(v) for v in touch.normal), bat_fraction=float(touch.fraction),
        distance_from_knob_m=float(touch.fraction * length),
        distance_from_tip_m=float((1.0 - touch.fraction) * length), feature=touch.feature,
        sweet_spot_speed_mps=float(np.linalg.norm(sweet)),
        ball_speed_mps=float(np.linalg.norm(pitch.velocity(first))),
        bat_speed_at_contact_mps=float(np.linalg.norm(swing.point_velocity(first,
                                                                           touch.fraction))),
        **min_fields)
