"""The event table: one kind per event type, one flat record per event."""

from baseball_collision.core.detector import (
    NearMiss, Prediction, PredictionCleared, StateReset, StreamGap)
from baseball_collision.tools.events import event_kind, EVENT_KINDS, event_record
import pytest


def test_every_kept_event_type_has_a_kind_and_a_list() -> None:
    """Kinds name the BagAnalysis lists; PredictionCleared is not kept."""
    assert {kind.collection for kind in EVENT_KINDS.values()} == {
        'impacts', 'near_misses', 'predictions', 'gaps', 'resets'}
    assert event_kind(StreamGap('ball', 1, 2)).name == 'gap'
    assert event_kind(StateReset(5, 'requested')).collection == 'resets'
    assert event_kind(PredictionCleared(3)) is None


def test_records_spread_vectors_over_their_columns() -> None:
    """A near miss: its ball position as x, y, z and its gap vector as gap_x, gap_y, gap_z."""
    miss = NearMiss(stamp_ns=7, gap_m=0.05, gap_vector=(0.0, 0.03, 0.04),
                    ball_position=(1.0, 2.0, 3.0), bat_fraction=0.8, distance_from_tip_m=0.1)
    assert event_record(miss) == {
        'event': 'near_miss', 'stamp_ns': 7, 'distance_from_tip_m': 0.1, 'gap_m': 0.05,
        'x': 1.0, 'y': 2.0, 'z': 3.0, 'gap_x': 0.0, 'gap_y': 0.03, 'gap_z': 0.04}
    prediction = Prediction(stamp_ns=9, made_at_ns=4, lead_s=5e-9, point=(1.0, 0.0, 0.0),
                            normal=(0.0, 0.0, 1.0), bat_fraction=0.5, distance_from_tip_m=0.4,
                            ball_position=(0.0, 0.0, 0.0), ball_velocity=(0.0, 0.0, 0.0),
                            planned=False)
    record = event_record(prediction)
    assert (record['event'], record['made_at_ns'], record['x'], record['normal_z']) == (
        'prediction', 4, 1.0, 1.0)
    with pytest.raises(KeyError):
        event_record(PredictionCleared(3))
