"""The event table: one kind per event type, each filed in its list."""

from dataclasses import fields
from pathlib import Path

from baseball_collision.core.detector import (
    DetectorConfig, PredictionCleared, StateReset, StreamGap)
from baseball_collision.core.detector.events import LateDrop
from baseball_collision.tools.analyze import BagAnalysis
from baseball_collision.tools.events import event_kind, EVENT_KINDS


def test_every_kept_event_type_has_a_kind_and_a_list() -> None:
    """Kinds name the BagAnalysis lists (clearings too: they end a prediction in force)."""
    collections = {kind.collection for kind in EVENT_KINDS.values()}
    assert collections == {'impacts', 'near_misses', 'predictions', 'cleared', 'gaps', 'resets'}
    assert collections <= {field.name for field in fields(BagAnalysis)}
    assert event_kind(StreamGap('ball', 1, 2)).name == 'gap'
    assert event_kind(StateReset(5, 'requested')).collection == 'resets'
    assert event_kind(PredictionCleared(3)).collection == 'cleared'
    analysis = BagAnalysis(path=Path('b.mcap'), selection=None, config=DetectorConfig())
    analysis.on_events([PredictionCleared(3), StateReset(5, 'requested')], 5, 'world')
    assert analysis.cleared == [PredictionCleared(3)] and len(analysis.resets) == 1


def test_other_types_are_not_kept() -> None:
    """A type not in the table (a late drop, anything else) has no kind."""
    assert event_kind(object()) is None
    assert event_kind(LateDrop('ball', 'stale', 1, 'world')) is None
