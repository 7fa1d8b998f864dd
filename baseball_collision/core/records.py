"""
One JSON record per detector event: what ``analyze --json`` writes and ``~/impact_report`` says.

Pure Python (no ROS, no rosbags). :func:`event_record` is THE function turning an impact, a near
miss or a prediction into its record, a JSON-ready ``dict``: every field of the event (vectors
as lists, non-finite floats as ``None``), plus

* ``format``: :data:`RECORD_FORMAT` (``baseball_collision.event/<version>``; the version goes
  up when a field changes meaning or disappears, not when one is added);
* ``event``: ``impact``, ``near_miss`` or ``prediction``;
* ``frame_id``: the frame every position and vector is in;
* ``zone``: where on the bat (:func:`bat_zone`: ``barrel``, ``sweet_spot``, ``handle``,
  ``end_cap``, ``knob``), named from the bat's profile.

An impact on an end (``feature`` ``tip_end`` or ``knob_end``) has ``distance_from_tip_m`` and
``distance_from_knob_m`` of the contact point itself (its projection on the knob-tip axis), not
of the centre of the rounded end. A prediction's ``stamp_ns`` is the predicted impact instant
(the stamp ``~/predicted_impact`` carries); ``made_at_ns`` is the instant of the newest sample
it was made from and ``lead_s`` the time between them.

The schema of the records is ``schema/event_record.schema.json`` (installed under
``share/baseball_collision/schema``); ``analyze --json`` adds ``bag`` and ``time_s`` (and, with
``--predict``, an impact's ``prediction_errors``) to the record of each event.
"""

import bisect
from dataclasses import fields
import functools
import json
import math
from typing import Any, Dict, List, Mapping, Optional, Tuple

from .bat import BatProfile, INCH
from .detector import DetectorConfig, Impact, NearMiss, Prediction
from .geometry import Vector

RECORD_FORMAT = 'baseball_collision.event/1'
"""``format`` of every event record."""

EVENT_NAMES = {Impact: 'impact', NearMiss: 'near_miss', Prediction: 'prediction'}
"""The ``event`` of a record, by event type (other event types have no record)."""

_FIELDS = {kind: tuple(field.name for field in fields(kind)) for kind in EVENT_NAMES}

ZONES = ('knob', 'handle', 'barrel', 'sweet_spot', 'end_cap')
"""The zones of a bat, knob end to barrel end (the values of a record's ``zone``)."""

SWEET_SPOT_HALF_WIDTH = 1.0 * INCH
"""The sweet-spot zone spans the sweet spot (``sweet_spot_from_tip``) +- this (m)."""

BARREL_SHARE = 0.5
"""Where the profile's radius is above this share of the way from its thinnest to its thickest
radius, the bat is barrel; below, handle (the taper is split at half its radius step)."""


def bat_zone(profile: BatProfile, feature: str, bat_fraction: float,
             distance_from_tip_m: float, sweet_spot_from_tip: float) -> str:
    """
    Name where on the bat a point is: one of :data:`ZONES`.

    ``end_cap`` and ``knob`` are the rounded ends (``feature`` ``tip_end``, ``knob_end``); on
    the side, ``sweet_spot`` within :data:`SWEET_SPOT_HALF_WIDTH` of the sweet spot (on the
    barrel), ``barrel`` where the radius is at least :data:`BARREL_SHARE` of the way from the
    profile's thinnest to its thickest radius, else ``handle``. A constant radius is all barrel.

    :param profile: the bat's radius profile.
    :param feature: ``side``, ``tip_end`` or ``knob_end``.
    :param bat_fraction: where along knob-tip (0 knob, 1 tip).
    :param distance_from_tip_m: metres along the axis from the tip.
    :param sweet_spot_from_tip: the sweet spot's distance from the tip (m).
    """
    if feature == 'tip_end':
        return 'end_cap'
    if feature == 'knob_end':
        return 'knob'
    if _radius_share(profile, bat_fraction) < BARREL_SHARE:
        return 'handle'
    if abs(distance_from_tip_m - sweet_spot_from_tip) <= SWEET_SPOT_HALF_WIDTH:
        return 'sweet_spot'
    return 'barrel'


@functools.lru_cache(maxsize=64)
def _stations(profile: BatProfile) -> Tuple[List[float], List[float], float, float]:
    """Return a profile's station distances, radii, thinnest and thickest radius (cached)."""
    distances = [distance for distance, _ in profile.stations]
    radii = [radius for _, radius in profile.stations]
    return distances, radii, min(radii), max(radii)


def _radius_share(profile: BatProfile, bat_fraction: float) -> float:
    """Return where the radius at a fraction lies from the thinnest (0) to the thickest (1)."""
    distances, radii, thinnest, thickest = _stations(profile)
    if thickest - thinnest <= 0.0:
        return 1.0
    distance = min(max(bat_fraction, 0.0), 1.0) * profile.length
    index = bisect.bisect_right(distances, distance)
    if index == 0:
        radius = radii[0]
    elif index == len(distances):
        radius = radii[-1]
    else:
        d0, d1 = distances[index - 1], distances[index]
        radius = radii[index - 1] + (radii[index] - radii[index - 1]) * (distance - d0) / (
            d1 - d0)
    return (radius - thinnest) / (thickest - thinnest)


def along_axis_from_tip(point: Vector, knob: Vector, tip: Vector) -> float:
    """Return how far (m) a point lies from the tip along the knob-tip axis (tip-wards < 0)."""
    axis = [t - k for k, t in zip(knob, tip)]
    length = math.sqrt(sum(c * c for c in axis))
    if length <= 0.0:
        return 0.0
    return sum((t - p) * a for p, t, a in zip(point, tip, axis)) / length


def contact_from_tip(impact: Impact) -> float:
    """
    Return an impact's spot as its record gives it: distance (m) from the tip along the axis.

    A side hit's is the impact's own ``distance_from_tip_m`` (the contact point's place along
    the axis); an end hit's is the contact point's own too, not the end cap centre's.
    """
    if impact.feature == 'side':
        return impact.distance_from_tip_m
    return along_axis_from_tip(impact.point, impact.knob, impact.tip)


_AS_IS = frozenset((int, str, bool, type(None)))
"""Classes :func:`plain` returns unchanged without a test (their subclasses, e.g. str enums,
are tested)."""


def plain(value: Any) -> Any:
    """Return ``value`` as strict JSON data: tuples as lists, str enums as str, NaN/inf None."""
    if value.__class__ in _AS_IS:
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, (tuple, list)):  # a vector's finite floats without a call each
        return [item if item.__class__ is float and math.isfinite(item) else plain(item)
                for item in value]
    if isinstance(value, dict):
        return {key if key.__class__ is str else str(key): plain(item)
                for key, item in value.items()}
    if isinstance(value, bool) or value is None:
        return value
    if isinstance(value, str):
        return str(value)
    return value


def event_record(event: Any, frame_id: str, config: DetectorConfig) -> Dict[str, Any]:
    """
    Return the JSON record of an impact, near miss or prediction (see the module).

    :param event: an ``Impact``, ``NearMiss`` or ``Prediction``.
    :param frame_id: the frame of its positions and vectors.
    :param config: the detector configuration that found it (its bat profile and sweet spot
        name the zone).
    :returns: a new dict of JSON types only (``json.dumps(..., allow_nan=False)`` works).
    :raises KeyError: an event of another type (``StreamGap``, ``StateReset``, ...).
    """
    name = EVENT_NAMES[type(event)]
    values = {key: getattr(event, key) for key in _FIELDS[type(event)]}
    feature = str(values.get('feature', 'side'))
    if isinstance(event, Impact) and feature != 'side':
        from_tip = contact_from_tip(event)
        values['distance_from_knob_m'] += values['distance_from_tip_m'] - from_tip
        values['distance_from_tip_m'] = from_tip
    zone = bat_zone(config.profile, feature, event.bat_fraction, values['distance_from_tip_m'],
                    config.sweet_spot_from_tip)
    return plain({'format': RECORD_FORMAT, 'event': name, 'frame_id': frame_id, 'zone': zone,
                  **values})


def record_text(record: Mapping[str, Any], indent: Optional[int] = None) -> str:
    """
    Return a record (or any JSON-ready document) as strict JSON text (no NaN).

    :param indent: None: one compact line (``~/impact_report``); else spaces per level.
    :raises ValueError: a non-finite float (records from :func:`event_record` have none).
    """
    if indent is None:
        return _COMPACT.encode(record)
    return json.dumps(record, indent=indent, allow_nan=False, separators=(',', ': '))


_COMPACT = json.JSONEncoder(allow_nan=False, separators=(',', ':'))
"""``json.dumps(..., allow_nan=False, separators=(',', ':'))`` made once, not per record."""
