"""Tests for baseball_collision.core.toi's scalar solver: vectors, brute force, edge cases."""

import math

from baseball_collision.core.bat import BatProfile, WOOD_BAT_34
from baseball_collision.core.toi import (
    closest_offset, distance, ImpactResult, lowest_gap_place, profile_gap, time_of_impact,
    time_of_impact_batch, time_of_impact_profile, TOUCH_TOLERANCE)
from baseball_collision.errors import CoreError
from hypothesis import assume, example, given, HealthCheck, settings, strategies as st
import numpy as np
import pytest
from support import examples
from support.scenes import (
    agrees, point, POINT_NAMES, profile_reference, reference_first_contact, sampling_decides,
    swing_interval, vector_args, VECTORS)

# property tests that filter out near-grazes (sampling cannot decide them)
FILTERING = {'deadline': None, 'suppress_health_check': [HealthCheck.filter_too_much]}


# ----------------------------------------------------------------------------------------------
# Shared vectors


@pytest.mark.parametrize('case', VECTORS,
                         ids=[f"{c['family']}-{i}" for i, c in enumerate(VECTORS)])
def test_vectors_scalar(case: dict) -> None:
    """Every shared vector: same contact verdict, time within 1e-9*dt + 1e-12 s."""
    result = time_of_impact(*vector_args(case))
    got = None if result is None else result.time
    assert agrees(case['time_of_impact'], got, case['dt']), (case['time_of_impact'], got)


def test_vectors_cover_contacts_and_misses() -> None:
    """The vectors exercise both verdicts, so agreement above means something."""
    hits = sum(c['time_of_impact'] is not None for c in VECTORS)
    assert 100 < hits < len(VECTORS) - 100


# ----------------------------------------------------------------------------------------------
# Properties against the brute-force reference

radius = st.floats(0.0, 0.12, allow_nan=False)
interval = st.floats(1e-3, 0.1, allow_nan=False)


@settings(max_examples=examples(150), **FILTERING)
@given(points=st.tuples(point, point, point, point, point, point), ball_radius=radius,
       bat_radius=radius, dt=interval)
def test_matches_brute_force(points, ball_radius: float, bat_radius: float, dt: float) -> None:
    """Contact verdict and time agree with dense sampling wherever sampling is decisive."""
    expected, min_gap = reference_first_contact(*points, ball_radius + bat_radius)
    assume(sampling_decides(min_gap, *points, 4001))  # sampling cannot decide a near-graze
    result = time_of_impact(*points, ball_radius, bat_radius, dt)
    if expected is None:
        assert result is None
        return
    assert result is not None
    assert result.time == pytest.approx(expected * dt, abs=1e-9 * dt + 1e-12)
    batch = time_of_impact_batch(*[np.array([p]) for p in points], ball_radius, bat_radius, dt)
    assert batch[0] == pytest.approx(result.time, abs=1e-9 * dt + 1e-12)


@settings(max_examples=examples(150), **FILTERING)
@given(points=swing_interval(), ball_radius=st.floats(0.03, 0.04),
       bat_radius=st.floats(0.01, 0.035))
def test_swings_match_brute_force(points, ball_radius: float, bat_radius: float) -> None:
    """Realistic swings: contact verdict, time, and the contact lies on both surfaces."""
    expected, min_gap = reference_first_contact(*points, ball_radius + bat_radius)
    assume(sampling_decides(min_gap, *points, 4001))
    dt = 1.0 / 90.0
    result = time_of_impact(*points, ball_radius, bat_radius, dt)
    assert (result is None) == (expected is None)
    if result is None:
        return
    assert result.time == pytest.approx(expected * dt, abs=1e-9 * dt + 1e-12)
    assert math.isclose(math.hypot(*result.normal), 1.0, rel_tol=1e-12)
    assert 0.0 <= result.bat_fraction <= 1.0
    if not result.initially_overlapping:
        tau = result.time / dt
        ball = points[0] + (points[1] - points[0]) * tau
        # at a fresh contact the bat surface point is one ball radius from the ball centre
        assert math.dist(ball, result.point) == pytest.approx(ball_radius, abs=1e-7)
        assert abs(result.gap) <= 1e-7


@settings(max_examples=examples(150), **FILTERING)
@given(points=st.one_of(swing_interval(), st.tuples(point, point, point, point, point, point)),
       ball_radius=st.floats(0.001, 0.12), bat_radius=radius, dt=interval)
def test_contact_time_is_first(points, ball_radius: float, bat_radius: float, dt: float) -> None:
    """No sampled instant before the reported contact has the bodies overlapping."""
    result = time_of_impact(*points, ball_radius, bat_radius, dt)
    assume(result is not None and result.time > 0.0)
    before = np.linspace(0.0, result.time, 500, endpoint=False)
    gaps = distance(before, *points, ball_radius, bat_radius, dt)
    assert np.all(gaps > -1e-9)
    assert distance(np.array([result.time]), *points, ball_radius, bat_radius, dt)[0] <= 1e-9


# ----------------------------------------------------------------------------------------------
# Edge cases


def test_initial_overlap_reports_zero() -> None:
    """A ball that starts inside the bat is a contact at time 0, flagged as overlapping."""
    result = time_of_impact([0.5, 0.05, 0], [0.5, 1.0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0],
                            [0, 0, 0], 0.037, 0.033, 0.01)
    assert result is not None and result.time == 0.0 and result.initially_overlapping
    assert result.gap == pytest.approx(0.05 - 0.07)
    assert result.normal == pytest.approx((0.0, 1.0, 0.0))


def test_zero_motion() -> None:
    """Nothing moves: contact iff touching at the start, and never NaN."""
    still = ([0.5, 0.2, 0], [0.5, 0.2, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 0])
    assert time_of_impact(*still, 0.037, 0.033, 0.01) is None
    assert time_of_impact(*still, 0.1, 0.1, 0.01).time == 0.0


def test_parallel_motion_keeps_the_gap() -> None:
    """Ball and bat moving together never meet, and do when they start in contact."""
    shift = np.array([0.3, -0.2, 0.1])
    ball, tip, knob = np.array([0.5, 0.2, 0]), np.array([1.0, 0, 0]), np.zeros(3)
    moving = (ball, ball + shift, tip, tip + shift, knob, knob + shift)
    assert time_of_impact(*moving, 0.037, 0.033, 0.01) is None
    assert time_of_impact(*moving, 0.1, 0.1, 0.01).time == 0.0


def test_ball_on_the_axis_line_hits_the_tip_cap() -> None:
    """A ball travelling along the bat's own axis line meets the rounded tip end."""
    result = time_of_impact([2.0, 0, 0], [0.0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0],
                            [0, 0, 0], 0.05, 0.05, 1.0)
    assert result is not None and result.feature == 'tip_end'
    assert result.time == pytest.approx(0.45, abs=1e-12)  # 1 m minus 0.1 m, over 2 m/s
    assert result.normal == pytest.approx((1.0, 0.0, 0.0))
    assert result.point == pytest.approx((1.05, 0.0, 0.0))


def test_ball_centre_on_axis_at_start_has_a_unit_normal() -> None:
    """Ball centre inside the bat on its axis: a unit normal across the axis, not NaN."""
    result = time_of_impact([0.5, 0, 0], [0.5, 0.1, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0],
                            [0, 0, 0], 0.03, 0.03, 0.01)
    assert result.initially_overlapping
    assert abs(np.dot(result.normal, [1, 0, 0])) < 1e-12
    assert math.isclose(np.linalg.norm(result.normal), 1.0)


def test_zero_length_bat_is_a_sphere() -> None:
    """Knob and tip together: sphere against sphere, first contact at the closing distance."""
    result = time_of_impact([1.0, 0, 0], [-1.0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0],
                            [0, 0, 0], 0.1, 0.1, 1.0)
    assert result.time == pytest.approx(0.4, abs=1e-12)
    assert result.point == pytest.approx((0.1, 0.0, 0.0))


@pytest.mark.parametrize('bat_radius', [1e-4, 3e-4, 5.511880480606291e-4, 1e-3, 1e-2])
def test_a_bat_shrinking_to_the_point_the_ball_meets(bat_radius: float) -> None:
    """
    A bat shrinking to the point the ball meets is hit at the closed form's instant.

    Tip and knob close on the origin as the ball does: the side's quartic has four roots within
    a few 1e-4 of the interval's end, the first found to about 1e-4 of it; polished on the gap
    it is the first contact to the closed form's 1e-9 of dt (hypothesis found it 1.7 us late).

    The gap at s = 1 - tau is 0.75 sqrt(2) s: the ball's nearest bat point, for the ball at
    (0, 0, -s/2), is a quarter of the way from the tip (0, s, 0) to the knob (0, 0, s).
    """
    dt = 0.0625
    ends = ([0.0, 0.0, -0.5], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    expected = (1.0 - bat_radius / (0.75 * math.sqrt(2.0))) * dt
    result = time_of_impact(*ends, 0.0, bat_radius, dt)
    assert result is not None
    assert result.time == pytest.approx(expected, abs=1e-9 * dt)
    assert result.bat_fraction == pytest.approx(0.75, abs=1e-6)
    batch = time_of_impact_batch(*[np.array([p]) for p in ends], 0.0, bat_radius, dt)
    assert batch[0] == result.time


def test_graze_within_tolerance_counts() -> None:
    """A tangential pass with a closest gap of 0.5 nm is contact; 2 nm is not."""
    def graze(gap: float) -> ImpactResult:
        offset = 0.07 + gap
        return time_of_impact([0.5, offset, -1.0], [0.5, offset, 1.0], [1, 0, 0], [1, 0, 0],
                              [0, 0, 0], [0, 0, 0], 0.037, 0.033, 1.0)
    touch = graze(0.5 * TOUCH_TOLERANCE)
    assert touch is not None and touch.time == pytest.approx(0.5, abs=1e-9)
    assert 0.0 < touch.gap <= TOUCH_TOLERANCE
    assert graze(2.0 * TOUCH_TOLERANCE) is None
    exact = graze(0.0)
    assert exact is not None and exact.time == pytest.approx(0.5, abs=1e-6)


def test_ball_passing_beyond_the_tip_is_no_contact() -> None:
    """The finite bat misses a ball passing 10 cm beyond the tip."""
    pass_beyond = ([1.17, 1.0, 0], [1.17, -1.0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 0])
    assert time_of_impact(*pass_beyond, 0.037, 0.033, 0.01) is None


@pytest.mark.parametrize('name, index', [(n, i) for i, n in enumerate(POINT_NAMES)])
def test_non_finite_point_raises_naming_the_argument(name: str, index: int) -> None:
    """A NaN or inf coordinate raises a CoreError that names the argument."""
    args = [[0.5, 0.2, 0], [0.5, 0.2, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 0]]
    args[index] = [0.0, math.nan if index % 2 else math.inf, 0.0]
    with pytest.raises(CoreError, match=name):
        time_of_impact(*args, 0.037, 0.033, 0.01)


@pytest.mark.parametrize('ball_radius, bat_radius, dt, name', [
    (math.nan, 0.03, 0.01, 'ball_radius'), (0.03, -0.01, 0.01, 'bat_radius'),
    (0.03, 0.03, 0.0, 'dt'), (0.03, 0.03, math.inf, 'dt')])
def test_bad_scalars_raise(ball_radius: float, bat_radius: float, dt: float, name: str) -> None:
    """Radii must be finite and >= 0, dt finite and > 0."""
    with pytest.raises(CoreError, match=name):
        time_of_impact([0, 0, 0], [0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 0],
                       ball_radius, bat_radius, dt)


def test_wrong_point_shape_raises() -> None:
    """A point with two coordinates is refused with the argument's name."""
    with pytest.raises(CoreError, match='tip1'):
        time_of_impact([0, 0, 0], [0, 0, 0], [1, 0, 0], [1, 0], [0, 0, 0], [0, 0, 0],
                       0.03, 0.03, 0.01)


# ----------------------------------------------------------------------------------------------
# Bat profiles


def test_constant_profile_equals_the_capsule() -> None:
    """A one-radius profile gives exactly the capsule answer, on every contact vector."""
    for case in VECTORS[:120]:
        capsule = time_of_impact(*vector_args(case))
        profile = BatProfile.constant(case['bat_radius'])
        pieces = time_of_impact_profile(*[case[k] for k in POINT_NAMES], case['ball_radius'],
                                        profile, case['dt'])
        assert (capsule is None) == (pieces is None)
        if capsule is not None:
            assert pieces.time == pytest.approx(capsule.time, abs=1e-12)
            assert pieces.bat_fraction == pytest.approx(capsule.bat_fraction, abs=1e-9)


@settings(max_examples=examples(60), **FILTERING)
@given(points=swing_interval())
def test_profile_matches_brute_force(points) -> None:
    """The default wood bat: first contact of the union of round cones, against dense sampling."""
    _matches_brute_force(points, WOOD_BAT_34)


def _matches_brute_force(points, profile: BatProfile) -> None:
    """
    Check a profile's first contact over an interval against dense sampling.

    The reference takes each piece's nearest sphere by ternary search (``cone_reference_gap``);
    the spot is the contact point's own place along the axis, within the first and last
    station, and a first touch's contact point lies on the ball's surface.
    """
    tau = np.linspace(0.0, 1.0, 2001)
    gaps = profile_reference(tau, points, 0.0366, profile)
    assume(sampling_decides(float(gaps.min()), *points, len(tau)))
    hits = np.flatnonzero(gaps <= 0.0)
    dt = 1.0 / 120.0
    result = time_of_impact_profile(*points, 0.0366, profile, dt)
    assert (result is None) == (hits.size == 0)
    if result is None:
        return
    assert tau[max(hits[0] - 1, 0)] - 1e-12 <= result.time / dt <= tau[hits[0]] + 1e-12
    ball0, ball1, tip0, tip1, knob0, knob1 = points
    s = result.time / dt
    ball, knob, tip = (a + (b - a) * s for a, b in ((ball0, ball1), (knob0, knob1),
                                                    (tip0, tip1)))
    if not result.initially_overlapping:  # (touching: the point on both surfaces)
        assert np.linalg.norm(np.asarray(result.point) - ball) == pytest.approx(0.0366,
                                                                                abs=1e-6)
    axis = tip - knob
    along = float((np.asarray(result.point) - knob) @ axis / (axis @ axis))
    first, last = profile.segments()[0][0], profile.segments()[-1][1]
    assert first - 1e-12 <= result.bat_fraction <= last + 1e-12
    if result.feature.value == 'side':
        assert result.bat_fraction == pytest.approx(min(max(along, first), last), abs=1e-9)


@st.composite
def tapered_profile(draw) -> BatProfile:
    """Draw a profile of 2-5 stations with steep and gentle tapers, thin and thick pieces."""
    count = draw(st.integers(2, 5))
    gaps = draw(st.lists(st.floats(0.02, 0.4), min_size=count - 1, max_size=count - 1))
    start = draw(st.floats(0.0, 0.05))
    distances = start + np.concatenate(([0.0], np.cumsum(gaps)))
    radii = draw(st.lists(st.floats(0.005, 0.06), min_size=count, max_size=count))
    return BatProfile(stations=tuple(zip(distances.tolist(), radii)),
                      length=float(distances[-1]) + draw(st.floats(0.0, 0.05)))


@settings(max_examples=examples(80), **FILTERING)
@given(points=swing_interval(), profile=tapered_profile())
def test_tapered_profiles_match_brute_force(points, profile: BatProfile) -> None:
    """Any profile's round cones, steep tapers too: first contact as dense sampling finds it."""
    _matches_brute_force(points, profile)


def test_profile_spot_follows_the_ball_across_a_station() -> None:
    """
    A ball met across the 10-inch station (handle into taper) is touched where it is.

    The pieces are round cones, so the surface has no step at a station: the spot moves with
    the ball's place along the bat, within the taper's lean (slope times the ball radius, 1 mm
    here), strictly increasing. (Capsules of each piece's mean radius stood 1.65 mm proud at
    the station: a ball up to 12.7 mm before it touched the step's rounded end, the spot
    snapped to the station.)
    """
    length, station = WOOD_BAT_34.length, 10.0 * 0.0254
    knob, tip = (0.0, 0.0, 0.0), (length, 0.0, 0.0)
    spots = []
    for place in station + np.linspace(-0.015, 0.015, 31):
        result = time_of_impact_profile((place, 0.2, 0.0), (place, 0.0, 0.0), tip, tip, knob,
                                        knob, 0.0366, WOOD_BAT_34, 0.01)
        spots.append(result.bat_fraction * length)
        assert abs(spots[-1] - place) < 1.1e-3, place
        # the ball's centre then at the ball radius plus the bat's own radius from the axis,
        # within what the taper's lean adds (under 0.02 mm)
        height = 0.2 - 20.0 * result.time
        assert 0.0 <= height - (0.0366 + WOOD_BAT_34.radius_at(place / length)) < 2e-5, place
    assert np.all(np.diff(spots) > 0.0)


def test_profile_thin_handle_lets_a_ball_pass() -> None:
    """A ball 6 cm from the handle's axis passes the thin handle but not the barrel."""
    knob, tip = np.zeros(3), np.array([WOOD_BAT_34.length, 0.0, 0.0])

    def crossing(at: float):
        return time_of_impact_profile([at, 0.06, 1.0], [at, 0.06, -1.0], tip, tip, knob, knob,
                                      0.0366, WOOD_BAT_34, 0.01)
    assert crossing(0.15) is None
    barrel = crossing(0.8)
    assert barrel is not None and barrel.feature == 'side'
    assert barrel.bat_fraction == pytest.approx(0.8 / WOOD_BAT_34.length, abs=1e-3)


# ----------------------------------------------------------------------------------------------
# How points may be passed: every layout gives the same answer


def test_every_row_layout_gives_the_same_result() -> None:
    """
    Tuples, lists, numpy rows (strided, big-endian, float32, int, read-only) agree to the bit.

    The kernel reads float64 rows of shape (3,) straight from the array struct, and anything
    else through the buffer protocol or as a sequence: the numbers must not depend on which.
    """
    points = [(0.0, 0.0, 0.0), (1.0, 0.1, 0.0), (0.5, -1.0, 0.05), (0.5, 1.0, 0.0),
              (0.45, 1.0, 0.0), (0.55, 1.0, 0.02)]
    expected = time_of_impact(*points, 0.1, 0.1, 0.01)
    assert isinstance(expected, ImpactResult) and expected.time > 0.0
    grid = np.array(points)
    wide = np.zeros((6, 6))
    wide[:, ::2] = grid
    frozen = grid.copy()
    frozen.setflags(write=False)
    layouts = {
        'lists': [list(p) for p in points],
        'rows': list(grid),
        'strided': [wide[i, ::2] for i in range(6)],
        'big-endian': [row.astype('>f8') for row in grid],
        'read-only': list(frozen),
        'float32 exact': [row.astype(np.float32) for row in np.round(grid * 64) / 64],
    }
    for name, rows in layouts.items():
        if name == 'float32 exact':
            exact = [tuple(float(x) for x in row) for row in rows]
            same = time_of_impact(*exact, 0.1, 0.1, 0.01)
            assert time_of_impact(*rows, 0.1, 0.1, 0.01) == same, name
            continue
        assert time_of_impact(*rows, 0.1, 0.1, 0.01) == expected, name
    assert time_of_impact(*[np.array(p, dtype=int) for p in [(0, 0, 0), (1, 0, 0), (0, -1, 0),
                                                             (0, 1, 0), (0, 1, 0), (0, 1, 0)]],
                          0.1, 0.1) is not None
    with pytest.raises(CoreError, match='ball0'):
        time_of_impact(np.zeros(4), *points[1:], 0.1, 0.1)


# ----------------------------------------------------------------------------------------------
# The gap at one instant, and its lowest over a linear sub-step

millimetre = st.integers(-1000, 1000).map(lambda k: k / 1000.0)
grid_point = st.tuples(millimetre, millimetre, millimetre)
"""A point on a millimetre grid (m): no denormal lengths (whose unit vectors are not unit)."""


@settings(max_examples=examples(300), deadline=None)
@given(ball=grid_point, knob=grid_point, tip=grid_point)
def test_profile_gap_is_the_distance_to_the_nearest_piece(ball, knob, tip) -> None:
    """The gap equals a dense search over the profile's round cones; the normal is unit length."""
    gap, normal, fraction = profile_gap(ball, knob, tip, 0.0366, WOOD_BAT_34)
    knob_a, axis = np.array(knob), np.array(tip) - np.array(knob)
    best = math.inf
    for f0, f1, r0, r1 in WOOD_BAT_34.segments():
        for g in np.linspace(0.0, 1.0, 400):
            best = min(best, math.dist(ball, knob_a + (f0 + g * (f1 - f0)) * axis)
                       - (r0 + g * (r1 - r0)))
    assert gap <= best - 0.0366 + 1e-12
    assert gap >= best - 0.0366 - 1e-3 * (1.0 + np.linalg.norm(axis))
    assert math.hypot(*normal) == pytest.approx(1.0)
    assert 0.0 <= fraction <= 1.0


def test_profile_gap_of_a_capsule() -> None:
    """A constant profile: 10 cm from the axis of a 3 cm bat is a 7 cm gap, minus the ball."""
    capsule = BatProfile.constant(0.03)
    gap, normal, fraction = profile_gap((0.5, 0.1, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0),
                                        0.02, capsule)
    assert gap == pytest.approx(0.05) and normal == pytest.approx((0, 1, 0))
    assert fraction == 0.5
    # beyond either end the closest axis point is that end (a capsule's cap)
    assert profile_gap((-0.3, 0.4, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), 0.02,
                       capsule)[2] == 0.0
    assert profile_gap((1.3, 0.4, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), 0.02,
                       capsule)[2] == 1.0


def test_profile_gap_has_a_normal_even_on_the_axis() -> None:
    """A ball centre on the bat's axis gets a unit normal across the axis; a bad point refused."""
    capsule = BatProfile.constant(0.03)
    gap, normal, fraction = profile_gap((0.5, 0.0, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0),
                                        0.02, capsule)
    assert gap == pytest.approx(-0.05) and fraction == 0.5
    assert math.hypot(*normal) == pytest.approx(1.0) and abs(normal[0]) < 1e-12
    with pytest.raises(CoreError, match='3 numbers'):
        profile_gap((0.5, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), 0.02, capsule)


def test_closest_offset_and_the_gap_calls_refuse_bad_input_with_core_error() -> None:
    """A point that is not 3 numbers, a radius not a number, no profile: CoreError, by name."""
    capsule = BatProfile.constant(0.03)
    knob, tip = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0)
    with pytest.raises(CoreError, match='closest_offset'):
        closest_offset((0.5, 0.0), (0.5, 0.1, 0.0), tip, tip, knob, knob)
    with pytest.raises(CoreError, match='closest_offset'):
        closest_offset((0.5, math.nan, 0.0), (0.5, 0.1, 0.0), tip, tip, knob, knob)
    with pytest.raises(CoreError, match='profile_gap'):
        profile_gap((0.5, 0.1, 0.0), knob, tip, 'big', capsule)
    with pytest.raises(CoreError, match='profile_gap'):
        profile_gap((0.5, 0.1, 0.0), knob, tip, 0.02, None)
    with pytest.raises(CoreError, match='lowest_gap_place'):
        lowest_gap_place(None, (0.5, 0.1, 0.0), knob, knob, tip, tip, 0.02, capsule)
    with pytest.raises(CoreError, match='lowest_gap_place'):
        lowest_gap_place(*[(0.5, 0.1, 0.0)] * 2, knob, knob, tip, tip, 0.02, 'wood')


def _golden_place(ball0, ball1, knob0, knob1, tip0, tip1, ball_radius, profile) -> float:
    """Search as the kernel must, step by step in Python (the same place to the bit)."""
    def gap(s):
        state = [tuple(a + (b - a) * s for a, b in zip(p, q))
                 for p, q in ((ball0, ball1), (knob0, knob1), (tip0, tip1))]
        return profile_gap(*state, ball_radius, profile)[0]

    golden = (math.sqrt(5.0) - 1.0) / 2.0
    lo, hi = 0.0, 1.0
    x1, x2 = hi - golden * (hi - lo), lo + golden * (hi - lo)
    g1, g2 = gap(x1), gap(x2)
    for _ in range(40):
        if g1 < g2:
            hi, x2, g2 = x2, x1, g1
            x1 = hi - golden * (hi - lo)
            g1 = gap(x1)
        else:
            lo, x1, g1 = x1, x2, g2
            x2 = lo + golden * (hi - lo)
            g2 = gap(x2)
    return min((gap(0.0), 0.0), (gap(1.0), 1.0), (min(g1, g2), x1 if g1 < g2 else x2))[1]


@settings(max_examples=examples(200), deadline=None)
@given(points=st.lists(grid_point, min_size=6, max_size=6))
@example(points=[(-0.039, -0.817, -0.698), (-0.065, 0.445, 0.635), (-0.347, -0.289, 0.172),
                 (0.291, 0.296, -0.374), (-0.505, 0.164, 0.537), (0.674, -0.196, -0.101)])
@example(points=[(-0.075, 0.349, 0.219), (0.36, 0.0, 0.0), (0.36, 0.0, 0.0),
                 (-0.075, 0.349, 0.219), (0.36, 0.0, 0.0), (-0.075, 0.349, 0.219)])
@example(points=[(0.507, -0.561, -0.178), (0.062, -0.938, 0.743), (0.062, -0.938, 0.743),
                 (-0.095, 0.021, -0.226), (0.769, -0.224, 0.336), (-0.09, 0.021, -0.225)])
def test_lowest_gap_place_is_the_golden_section_search(points) -> None:
    """
    The kernel's search is the step-by-step search in Python, to the bit.

    Its gap is no more than a dense scan's lowest where the gap has one valley along the
    sub-step, also looked at closer about its floor: the gap is the least of the bat's
    pieces', and two pieces' valleys can lie within one step of the scan (the first example:
    5 um apart in depth, a bump between them that 401 points do not show, and the search
    settles in the shallower one), or two steps apart with the closer look about the scan's
    lowest missing the search's valley (the third: 11 um apart, 0.0054 of the sub-step), so that
    look spans the place found too. The search ends in a bracket golden^40 wide (4.5e-9 of the
    sub-step) and the gap changes by at most how far the ball and the farther bat end move (it
    is 1-Lipschitz in each), so it may be that much above the floor where the valley is a V
    (the second example: ball and bat axis meeting head on, 1.0e-9 m above its floor).
    """
    ball0, ball1, knob0, knob1, tip0, tip1 = points
    place = lowest_gap_place(ball0, ball1, knob0, knob1, tip0, tip1, 0.0366, WOOD_BAT_34)
    assert place == _golden_place(ball0, ball1, knob0, knob1, tip0, tip1, 0.0366, WOOD_BAT_34)
    assert 0.0 <= place <= 1.0

    def gap(s):
        return profile_gap(*[tuple(a + (b - a) * s for a, b in zip(p, q))
                             for p, q in ((ball0, ball1), (knob0, knob1), (tip0, tip1))],
                           0.0366, WOOD_BAT_34)[0]

    def one_valley(values) -> bool:  # down, then up (or flat)
        falls = np.diff(values) < 0.0
        return not np.any(falls[np.argmax(~falls):])
    grid = np.linspace(0.0, 1.0, 401)
    dense = [gap(s) for s in grid]
    lowest = int(np.argmin(dense))
    floor = [gap(s) for s in np.linspace(min(grid[max(lowest - 1, 0)], place),
                                         max(grid[min(lowest + 1, 400)], place), 2001)]
    moved = math.dist(ball0, ball1) + max(math.dist(knob0, knob1), math.dist(tip0, tip1))
    bracket = ((math.sqrt(5.0) - 1.0) / 2.0) ** 40
    if one_valley(dense) and one_valley(floor):
        assert gap(place) <= min(dense + floor) + 1e-9 + moved * bracket


def test_a_profile_that_is_no_profile_is_refused_by_name() -> None:
    """time_of_impact_profile with profile None: a CoreError naming it (an AttributeError)."""
    with pytest.raises(CoreError, match='profile must be a BatProfile'):
        time_of_impact_profile((0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0, -1, 0),
                               (1, -1, 0), 0.0366, None, 0.01)
