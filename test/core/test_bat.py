"""Tests for baseball_collision.core.bat: profiles and knob/tip from a pose."""

import math

from baseball_collision.core.bat import (
    BatProfile, INCH, MAX_STATIONS, PoseBatGeometry, WOOD_BAT_34)
from baseball_collision.core.detector.config import DetectorConfig
from baseball_collision.core.geometry import quaternion_to_matrix
from baseball_collision.errors import CoreError
import numpy as np
import pytest


def test_default_bat_is_34_inches_with_a_2_61_inch_barrel() -> None:
    """The default profile is the documented wood bat and its ends finish at the bat's ends."""
    assert WOOD_BAT_34.length == pytest.approx(34 * INCH)
    assert 2 * WOOD_BAT_34.max_radius == pytest.approx(2.61 * INCH)
    first_d, first_r = WOOD_BAT_34.stations[0]
    last_d, last_r = WOOD_BAT_34.stations[-1]
    assert first_d - first_r == pytest.approx(0.0, abs=1e-12)
    assert last_d + last_r == pytest.approx(WOOD_BAT_34.length)
    assert WOOD_BAT_34.radius_at(0.2) < 0.5 * WOOD_BAT_34.max_radius  # thin handle


def test_segments_are_fractions_with_their_stations_radii() -> None:
    """Round cones run between consecutive stations (fractions of the length), each end its own."""
    profile = BatProfile(stations=((0.0, 0.01), (0.5, 0.03), (1.0, 0.03)), length=1.0)
    assert profile.segments() == ((0.0, 0.5, 0.01, 0.03), (0.5, 1.0, 0.03, 0.03))
    assert BatProfile(stations=((0.4, 0.02),), length=1.0).segments() == (
        (0.4, 0.4, 0.02, 0.02),)


@pytest.mark.parametrize('stations, length', [
    (((0.0, 0.01), (0.0, 0.02)), 1.0),
    (((0.0, 0.01), (2.0, 0.02)), 1.0),
    (((0.0, -0.01),), 1.0),
    (((0.0, math.nan),), 1.0),
    ((), 1.0),
    (((0.0, 0.01),), 0.0),
])
def test_bad_profiles_are_refused(stations, length: float) -> None:
    """Non-increasing, out-of-range, non-positive or empty profiles raise CoreError."""
    with pytest.raises(CoreError):
        BatProfile(stations=stations, length=length)


def test_profile_from_sequence_rejects_non_pairs() -> None:
    """A flat list is not a list of stations."""
    with pytest.raises(CoreError):
        BatProfile.from_sequence([0.0, 0.01, 1.0], 1.0)


@pytest.mark.parametrize('stations, length', [
    (((0.0, 0.01), (1.0, 0.01)), 'abc'),
    (((0.0, 0.01), (1.0, 0.01)), None),
    (((0.0, 0.01), (1.0, 0.01, 0.5)), 1.0),
    (((0.0, 0.01), 1.0), 1.0),
    (((0.0, 0.01), ('x', 0.01)), 1.0),
    (((0.0, 0.01), (1.0, None)), 1.0),
    (None, 1.0),
])
def test_profile_values_of_the_wrong_type_raise_core_error(stations, length) -> None:
    """A length or a station that is not a number (or a pair) is refused with CoreError."""
    with pytest.raises(CoreError):
        BatProfile(stations=stations, length=length)
    with pytest.raises(CoreError):
        BatProfile.from_sequence(stations, length)


def test_profile_keeps_lists_and_arrays_as_tuples_of_floats() -> None:
    """Stations given as lists or an array are kept as tuples of floats (the profile hashes)."""
    profile = BatProfile(stations=np.array([[0.0, 0.01], [1.0, 0.02]]), length=1)
    assert profile.stations == ((0.0, 0.01), (1.0, 0.02))
    assert all(type(v) is float for station in profile.stations for v in station)
    assert type(profile.length) is float
    assert hash(profile) == hash(BatProfile(stations=[[0, 0.01], [1, 0.02]], length=1.0))


def test_quaternion_to_matrix_turns_about_z() -> None:
    """A quarter turn about z maps x to y."""
    half = math.sqrt(0.5)
    rotation = quaternion_to_matrix((0.0, 0.0, half, half))
    assert rotation @ np.array([1.0, 0, 0]) == pytest.approx([0.0, 1.0, 0.0])


@pytest.mark.parametrize('quaternion', [(0, 0, 0, 0), (0, 0, 0, 2.0), (math.nan, 0, 0, 1)])
def test_malformed_quaternions_raise(quaternion) -> None:
    """Zero, non-unit and non-finite quaternions are refused."""
    with pytest.raises(CoreError):
        quaternion_to_matrix(quaternion)


def test_pose_geometry_along_axis() -> None:
    """Knob and tip offsets on a body axis are placed by the pose."""
    geometry = PoseBatGeometry.along_axis('-y', 0.1, 0.9)
    half = math.sqrt(0.5)
    knob, tip = geometry.knob_and_tip((1.0, 2.0, 3.0), (0.0, 0.0, half, half))
    assert knob == pytest.approx([1.1, 2.0, 3.0])
    assert tip == pytest.approx([1.9, 2.0, 3.0])
    for axis in ('w', None, ['x'], 3, '--x', '+-x', '-+x', 'xx', ''):
        with pytest.raises(CoreError, match='bat axis must be one of'):
            PoseBatGeometry.along_axis(axis, 0.0, 1.0)
    with pytest.raises(CoreError, match='tip_distance must be a number'):
        PoseBatGeometry.along_axis('x', 0.0, 'far')
    with pytest.raises(CoreError):
        PoseBatGeometry(knob_offset=(0, 0, 0), tip_offset=(0, 0, 0))


def test_a_profile_has_at_most_max_stations() -> None:
    """MAX_STATIONS stations are a bat; one more is refused, naming the bound."""
    stations = [(0.8 * i / MAX_STATIONS, 0.03) for i in range(MAX_STATIONS)]
    assert len(BatProfile.from_sequence(stations, 0.8).segments()) == MAX_STATIONS - 1
    with pytest.raises(CoreError, match=f'at most {MAX_STATIONS} stations, got 257'):
        BatProfile.from_sequence(stations + [(0.8, 0.03)], 0.8)


def test_pose_geometry_keeps_lists_and_arrays_as_tuples_of_floats() -> None:
    """Offsets given as a list or an array are kept as tuples: a config variant can hash them."""
    geometry = PoseBatGeometry(knob_offset=[0, 0, 0], tip_offset=np.array([0.0, 0.0, 0.8636]))
    assert geometry.knob_offset == (0.0, 0.0, 0.0)
    assert geometry.tip_offset == (0.0, 0.0, 0.8636)
    assert all(type(c) is float for c in geometry.knob_offset + geometry.tip_offset)
    config = DetectorConfig(geometry=geometry)
    assert config.variant(look_ahead=1).geometry == geometry


@pytest.mark.parametrize('knob, tip', [
    ((0, 0), (0, 0, 1)),
    ((0, 0, 0), (0, 0, 1, 0)),
    ([[0, 0, 0]], (0, 0, 1)),
    ((0, 0, 0), ((0,), (0,), (1,))),
    ((0, 0, math.nan), (0, 0, 1)),
    ((0, 0, 0), (0, 0, math.inf)),
    (None, (0, 0, 1)),
])
def test_pose_geometry_refuses_offsets_that_are_not_3_finite_numbers(knob, tip) -> None:
    """Wrong shapes and non-finite offsets are refused when the geometry is made."""
    with pytest.raises(CoreError, match='offset must be'):
        PoseBatGeometry(knob_offset=knob, tip_offset=tip)


@pytest.mark.parametrize('make', [
    lambda: BatProfile(stations=((0.0, 0.01), (True, 0.01)), length=1.0),
    lambda: BatProfile(stations=((0.0, True), (1.0, 0.01)), length=1.0),
    lambda: BatProfile(stations=((0.0, 0.01), (1.0, 0.01)), length=True),
    lambda: BatProfile.from_sequence([[False, 0.01], [1.0, 0.01]], 1.0),
    lambda: PoseBatGeometry(knob_offset=(0.0, 0.0, False), tip_offset=(0.0, 0.0, 0.8)),
    lambda: PoseBatGeometry(knob_offset=(0, 0, 0), tip_offset=np.array([False, False, True])),
    lambda: PoseBatGeometry.along_axis('z', 0.0, True),
    lambda: PoseBatGeometry.along_axis('z', False, 0.8),
])
def test_bools_are_not_metres(make) -> None:
    """A bool is no length or coordinate of the bat: refused, not read as 0 or 1 m."""
    with pytest.raises(CoreError, match='must be'):
        make()
