"""The event table: one kind per event type, each filed in its list."""

from baseball_collision.core.detector import PredictionCleared, StateReset, StreamGap
from baseball_collision.tools.events import event_kind, EVENT_KINDS


def test_every_kept_event_type_has_a_kind_and_a_list() -> None:
    """Kinds name the BagAnalysis lists; PredictionCleared is not kept."""
    assert {kind.collection for kind in EVENT_KINDS.values()} == {
        'impacts', 'near_misses', 'predictions', 'gaps', 'resets'}
    assert event_kind(StreamGap('ball', 1, 2)).name == 'gap'
    assert event_kind(StateReset(5, 'requested')).collection == 'resets'
    assert event_kind(PredictionCleared(3)) is None
