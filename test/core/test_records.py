"""Event records: one JSON record per impact, near miss and prediction, held to the schema."""

from dataclasses import replace
import json
import math

from baseball_collision.core.bat import BatProfile, INCH, WOOD_BAT_34
from baseball_collision.core.detector import (
    DetectorConfig, Impact, NearMiss, Prediction, PredictionCleared, StreamGap)
from baseball_collision.core.records import (
    along_axis_from_tip, bat_zone, event_record, RECORD_FORMAT, record_text, ZONES)
import numpy as np
import pytest
from support.events import swing_events
from support.schema import Validator

RECORDS = Validator('event_record.schema.json')


def _events(kind: type, horizon: float = 0.0, height: float = 1.0) -> list:
    return [e for e in swing_events(height=height, horizon=horizon) if isinstance(e, kind)]


def test_every_record_follows_the_schema_and_is_strict_json() -> None:
    """Impacts, near misses and predictions: format, event, frame_id, zone; JSON without NaN."""
    config = DetectorConfig(prediction_horizon=0.3)
    events = _events(Impact) + _events(Prediction, 0.3) + _events(NearMiss, height=1.09)
    assert {type(event) for event in events} == {Impact, Prediction, NearMiss}
    for event in events:
        record = event_record(event, 'world', config)
        assert RECORDS.errors(record) == []
        assert record['format'] == RECORD_FORMAT and record['frame_id'] == 'world'
        assert record['zone'] in ZONES and record['stamp_ns'] == event.stamp_ns
        assert json.loads(record_text(record)) == record
        assert '\n' not in record_text(record)
    prediction = event_record(_events(Prediction, 0.3)[0], 'world', config)
    assert prediction['stamp_ns'] - prediction['made_at_ns'] == pytest.approx(
        prediction['lead_s'] * 1e9, abs=2.0)


def test_the_validator_finds_what_breaks_the_schema() -> None:
    """A missing key, a wrong type, an extra key, a bad zone: each named."""
    record = event_record(_events(Impact)[0], 'world', DetectorConfig())
    broken = dict(record, stamp_ns=1.5, zone='bottom', colour='red')
    del broken['frame_id']
    found = ' '.join(RECORDS.errors(broken, '#/$defs/impact'))
    for word in ("missing 'frame_id'", 'stamp_ns', "'bottom'", "unexpected key 'colour'"):
        assert word in found
    assert RECORDS.errors(dict(record, event='near_miss')) != []


def test_non_finite_values_become_null() -> None:
    """A NaN attack angle is null in the record (strict JSON), still valid."""
    impact = replace(_events(Impact)[0], attack_angle_deg=math.nan)
    record = event_record(impact, 'world', DetectorConfig())
    assert record['attack_angle_deg'] is None and RECORDS.errors(record) == []
    record_text(record)


def test_other_events_have_no_record() -> None:
    """Gaps and cleared predictions are not reported."""
    for event in (StreamGap('ball', 1, 2), PredictionCleared(3)):
        with pytest.raises(KeyError):
            event_record(event, 'world', DetectorConfig())


@pytest.mark.parametrize('from_tip_in, feature, zone', [
    (0.5, 'tip_end', 'end_cap'), (33.8, 'knob_end', 'knob'), (6.0, 'side', 'sweet_spot'),
    (5.1, 'side', 'sweet_spot'), (3.0, 'side', 'barrel'), (9.0, 'side', 'barrel'),
    (22.4, 'side', 'handle'), (30.0, 'side', 'handle')])
def test_zones_of_the_wood_bat(from_tip_in: float, feature: str, zone: str) -> None:
    """Zones from the profile: the 57 cm handle hit is 'handle', 6 in from the tip sweet."""
    fraction = 1.0 - from_tip_in / 34.0
    assert bat_zone(WOOD_BAT_34, feature, fraction, from_tip_in * INCH, 6.0 * INCH) == zone


def test_a_constant_radius_is_barrel() -> None:
    """A capsule has no handle: every side hit off the sweet spot is barrel."""
    profile = BatProfile.constant(0.03, 0.8)
    assert bat_zone(profile, 'side', 0.1, 0.72, 0.15) == 'barrel'


def test_end_cap_hits_report_the_contact_points_own_distance() -> None:
    """A tip-end contact: the distances are its projection on the axis, not the cap centre's."""
    base = _events(Impact)[0]
    knob, tip = np.array([0.0, 0.0, 1.0]), np.array([0.8636, 0.0, 1.0])
    point = tip + np.array([-0.012, 0.02, 0.01])
    impact = replace(base, knob=tuple(knob), tip=tuple(tip), point=tuple(point),
                     feature='tip_end', bat_fraction=0.96, distance_from_knob_m=0.96 * 0.8636,
                     distance_from_tip_m=0.04 * 0.8636)
    record = event_record(impact, 'world', DetectorConfig())
    assert record['distance_from_tip_m'] == pytest.approx(0.012)
    assert record['distance_from_knob_m'] == pytest.approx(0.8636 - 0.012)
    assert record['zone'] == 'end_cap'
    side = event_record(replace(impact, feature='side'), 'world', DetectorConfig())
    assert side['distance_from_tip_m'] == impact.distance_from_tip_m  # the core's own value
    assert along_axis_from_tip(tuple(tip), tuple(knob), tuple(tip)) == 0.0
    assert along_axis_from_tip((1.0, 2.0, 3.0), (1.0, 2.0, 3.0), (1.0, 2.0, 3.0)) == 0.0
