"""
The detector's events as the tools see them: one table by event type.

Every place in the tools that treats events by type (filing them into a
:class:`~baseball_collision.tools.analyze.BagAnalysis`, writing them to an output bag) looks the
type up once in :data:`EVENT_KINDS`. The record of an event (JSON, CSV, the table's cells, the
node's ``~/impact_report``) is made in one place,
:func:`baseball_collision.core.records.event_record`. Events of a type not in the table are not
kept. (A ``PredictionCleared`` has no record: it is kept because it ends the prediction in force
when predictions are scored.)
"""

from dataclasses import dataclass
from typing import Any, Dict, Optional

from ..core.detector import Impact, NearMiss, Prediction, PredictionCleared, StateReset, StreamGap


@dataclass(frozen=True)
class EventKind:
    """
    How the tools file one type of detector event.

    :ivar name: the event's name (a record's ``event``: ``'impact'``, ``'near_miss'``, ...).
    :ivar collection: the :class:`BagAnalysis` list the events are filed in.
    """

    name: str
    collection: str


EVENT_KINDS: Dict[type, EventKind] = {
    Impact: EventKind('impact', 'impacts'),
    NearMiss: EventKind('near_miss', 'near_misses'),
    Prediction: EventKind('prediction', 'predictions'),
    PredictionCleared: EventKind('prediction_cleared', 'cleared'),
    StreamGap: EventKind('gap', 'gaps'),
    StateReset: EventKind('reset', 'resets'),
}
"""What the tools do with each event type: the one dispatch by type."""


def event_kind(event: Any) -> Optional[EventKind]:
    """Return the kind of a detector event, or None for a type the tools do not keep."""
    return EVENT_KINDS.get(type(event))
