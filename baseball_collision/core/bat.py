"""
Bat geometry: the radius profile along the knob-to-tip axis, and knob/tip from a pose.

Pure Python + numpy; no ROS imports. Lengths are metres.

A bat profile is a list of stations ``(distance_from_knob, radius)``. Between two consecutive
stations the bat is a round cone: the hull of the spheres at the two stations, each of its
station's radius (the union of the spheres along the axis whose radius grows linearly from one
station to the next). So the surface follows the taper without a step at any station: adjacent
pieces share the station's sphere, and the round cone's side stands off the straight taper by
r (1 / cos a - 1) at a slope a (at most 0.073 mm on the default bat's steepest taper). A piece
of one radius is a capsule. Stations are given for a bat of ``length`` metres and are scaled to the
measured knob-to-tip distance when the bat is tracked, so every piece's ends are fixed
fractions of knob-to-tip: they move linearly when knob and tip do, and the exact linear solver
applies to every piece (its side's contact is still the first root of a quartic).
"""

from dataclasses import dataclass
import math
from typing import Sequence, Tuple

import numpy as np

from .geometry import finite_number, finite_vector, quaternion_to_matrix, Vector
from ..errors import CoreError

INCH = 0.0254
"""One inch in metres."""

SWEET_SPOT_FROM_TIP = 6.0 * INCH
"""Statcast's bat-speed point: 6 inches from the barrel end (metres)."""

MAX_STATIONS = 256
"""Most stations a profile may have: a turned bat needs a few dozen; every station starts a piece
the detector solves for, so a million of them would take minutes per sample."""


def _metres(name: str, value: float) -> float:
    """
    Return a length or a coordinate (metres) as a finite float.

    :raises CoreError: a bool (``True`` is no length), not a number, or not finite.
    """
    if isinstance(value, (bool, np.bool_)):
        raise CoreError(f'{name} must be a number of metres, got {value!r}')
    return finite_number(name, value)


def _point(name: str, value: Sequence[float]) -> Vector:
    """
    Return a point (metres) as 3 finite floats.

    :raises CoreError: not 3 numbers (a bool is none), or not all finite.
    """
    point = finite_vector(name, value, ' (metres)')
    if any(isinstance(c, (bool, np.bool_)) for c in value):
        raise CoreError(f'{name} must be 3 numbers (metres), got {value!r}')
    return point


@dataclass(frozen=True)
class BatProfile:
    """
    Radius of the bat along its axis, as stations measured from the knob end.

    :ivar stations: ``((distance_from_knob_m, radius_m), ...)`` with strictly increasing distances
        from 0 to ``length``, radii > 0.
    :ivar length: knob-to-tip length the stations were measured on (metres).
    """

    stations: Tuple[Tuple[float, float], ...]
    length: float

    def __post_init__(self) -> None:
        """
        Check the stations describe a bat; keep them as tuples of floats.

        :raises CoreError: a length or a station value that is not a number (a bool is none),
            a station that is not a pair, fewer than one station or more than
            :data:`MAX_STATIONS`, non-finite or non-positive values, distances not strictly
            increasing, or outside [0, length].
        """
        length = _metres('bat length', self.length)
        if not length > 0.0:
            raise CoreError(f'bat length must be finite and > 0 m, got {self.length!r}')
        try:
            pairs = tuple((distance, radius) for distance, radius in self.stations)
        except (TypeError, ValueError) as error:
            raise CoreError('bat profile stations must be pairs (distance_from_knob, radius), '
                            f'got {self.stations!r}') from error
        if len(pairs) < 1:
            raise CoreError('a bat profile needs at least one station')
        if len(pairs) > MAX_STATIONS:
            raise CoreError(f'a bat profile has at most {MAX_STATIONS} stations, got '
                            f'{len(pairs):,}')
        stations = tuple((_metres('station distance', distance), _metres('station radius', radius))
                         for distance, radius in pairs)
        previous = -math.inf
        for distance, radius in stations:
            if not radius > 0.0:
                raise CoreError(f'station ({distance!r}, {radius!r}) must have radius > 0 m')
            if distance <= previous or distance < 0.0 or distance > length * (1 + 1e-12):
                raise CoreError(
                    'station distances must increase strictly within [0, length], '
                    f'got {distance!r} after {previous!r} (length {length!r})')
            previous = distance
        object.__setattr__(self, 'stations', stations)
        object.__setattr__(self, 'length', length)
        object.__setattr__(self, '_segments', self._build_segments())

    @classmethod
    def constant(cls, radius: float, length: float = 1.0) -> 'BatProfile':
        """
        Return a plain capsule of one radius (metres) over the whole knob-to-tip axis.

        :raises CoreError: as the class.
        """
        return cls(stations=((0.0, radius), (length, radius)), length=length)

    @classmethod
    def from_sequence(cls, stations: Sequence[Sequence[float]],
                      length: float) -> 'BatProfile':
        """
        Build a profile from ``[[distance_from_knob, radius], ...]`` (metres).

        :raises CoreError: the stations do not describe a bat (see the class).
        """
        return cls(stations=stations, length=length)

    @property
    def max_radius(self) -> float:
        """Largest radius of the profile (metres)."""
        return max(radius for _, radius in self.stations)

    def segments(self) -> Tuple[Tuple[float, float, float, float], ...]:
        """
        Return the round cones making up the bat: ``(fraction_start, fraction_end, r0, r1)``.

        Fractions are of the knob-to-tip distance (0 at the knob, 1 at the tip), radii in
        metres (each piece the hull of the spheres of those radii at its ends; equal radii: a
        capsule). One station gives a single sphere (start == end).
        """
        return self._segments

    def _build_segments(self) -> Tuple[Tuple[float, float, float, float], ...]:
        if len(self.stations) == 1:
            distance, radius = self.stations[0]
            fraction = distance / self.length
            return ((fraction, fraction, radius, radius),)
        return tuple((d0 / self.length, d1 / self.length, r0, r1)
                     for (d0, r0), (d1, r1) in zip(self.stations[:-1], self.stations[1:]))

    def radius_at(self, fraction: float) -> float:
        """Radius (metres) at a fraction of knob-to-tip, interpolated between stations."""
        distances = [d for d, _ in self.stations]
        radii = [r for _, r in self.stations]
        return float(np.interp(fraction * self.length, distances, radii))


def _wood_bat_34() -> BatProfile:
    """
    Build the default: a 34-inch wood bat with a 2.61-inch barrel.

    Diameters (inches) at distances from the knob end, close to a common big-league model
    (271 turning): a 1.6-inch knob, a 0.94-inch handle, a taper from 10 to 27 inches and a
    2.61-inch barrel to the end. The first and last stations are inset by their radius so the
    rounded capsule ends finish at the knob end and at the barrel end.
    """
    length = 34.0 * INCH
    diameters = (
        (0.80, 1.60), (1.00, 0.94), (10.0, 0.98), (14.0, 1.20), (18.0, 1.60),
        (21.0, 2.05), (24.0, 2.40), (27.0, 2.61), (34.0 - 1.305, 2.61),
    )
    return BatProfile(
        stations=tuple((d * INCH, 0.5 * dia * INCH) for d, dia in diameters), length=length)


WOOD_BAT_34 = _wood_bat_34()
"""Default profile: 34-inch (0.8636 m) wood bat, barrel radius 1.305 in (33.1 mm)."""


@dataclass(frozen=True)
class PoseBatGeometry:
    """
    Where knob and tip sit in the frame of a tracked bat pose.

    :ivar knob_offset: knob end in the bat body frame (metres).
    :ivar tip_offset: barrel end in the bat body frame (metres).
    """

    knob_offset: Vector = (0.0, 0.0, 0.0)
    tip_offset: Vector = (0.0, 0.0, 34.0 * INCH)

    def __post_init__(self) -> None:
        """
        Check the offsets and keep them as tuples of 3 floats (the geometry is hashable).

        :raises CoreError: an offset that is not 3 finite numbers (a bool is none), or knob and
            tip closer than 1 mm.
        """
        knob = _point('knob_offset', self.knob_offset)
        tip = _point('tip_offset', self.tip_offset)
        if math.dist(knob, tip) < 1e-3:
            raise CoreError('knob_offset and tip_offset must be at least 1 mm apart')
        object.__setattr__(self, 'knob_offset', knob)
        object.__setattr__(self, 'tip_offset', tip)

    @classmethod
    def along_axis(cls, axis: str, knob_distance: float,
                   tip_distance: float) -> 'PoseBatGeometry':
        """
        Knob and tip on a body axis (``'x'``, ``'y'``, ``'z'``, ``'-x'`` ...) at signed distances.

        The axis is one of six names: ``'x'``, ``'y'``, ``'z'``, ``'-x'``, ``'-y'``, ``'-z'``;
        the distances are metres.

        :raises CoreError: an axis that is not one of those six names, a distance that is not a
            finite number (a bool is none), or knob and tip closer than 1 mm.
        """
        names = ('x', 'y', 'z', '-x', '-y', '-z')
        if not (isinstance(axis, str) and axis in names):
            raise CoreError(f'bat axis must be one of {", ".join(names)}, got {axis!r}')
        index = names.index(axis) % 3
        sign = -1.0 if axis.startswith('-') else 1.0
        knob = [0.0, 0.0, 0.0]
        tip = [0.0, 0.0, 0.0]
        knob[index] = sign * _metres('knob_distance', knob_distance)
        tip[index] = sign * _metres('tip_distance', tip_distance)
        return cls(knob_offset=tuple(knob), tip_offset=tuple(tip))

    def knob_and_tip(self, position: Sequence[float],
                     quaternion: Sequence[float]) -> Tuple[np.ndarray, np.ndarray]:
        """
        Return world knob and tip (metres) for a bat pose (position, quaternion x y z w).

        :raises CoreError: a malformed quaternion.
        """
        rotation = quaternion_to_matrix(quaternion)
        origin = np.asarray(position, dtype=float)
        knob = origin + rotation @ np.asarray(self.knob_offset, dtype=float)
        tip = origin + rotation @ np.asarray(self.tip_offset, dtype=float)
        return knob, tip
