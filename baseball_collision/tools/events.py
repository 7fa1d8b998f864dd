"""
The detector's events as the tools see them: one table by event type, one record per event.

Every place in the tools that treats events by type (filing them into a
:class:`~baseball_collision.tools.analyze.BagAnalysis`, writing them to an output bag, the CSV
rows and the printed table) looks the type up once in :data:`EVENT_KINDS`; :func:`event_record`
is the one place that turns an event into a flat record (the CSV row; the table's cells come
from it). Events of a type not in the table (``PredictionCleared``) are not kept.
"""

from dataclasses import dataclass
from typing import Any, Dict, Optional, Tuple

from ..core.detector import Impact, NearMiss, Prediction, StateReset, StreamGap

XYZ = ('x', 'y', 'z')
NORMAL_XYZ = ('normal_x', 'normal_y', 'normal_z')
GAP_XYZ = ('gap_x', 'gap_y', 'gap_z')


@dataclass(frozen=True)
class EventKind:
    """
    How the tools file and record one type of detector event.

    :ivar name: the record's ``event`` value (``'impact'``, ``'near_miss'``, ...).
    :ivar collection: the :class:`BagAnalysis` list the events are filed in.
    :ivar fields: attributes copied into the record under their own names.
    :ivar vectors: ``(attribute, (x field, y field, z field))``: vectors spread over three
        record fields.
    """

    name: str
    collection: str
    fields: Tuple[str, ...] = ()
    vectors: Tuple[Tuple[str, Tuple[str, str, str]], ...] = ()


EVENT_KINDS: Dict[type, EventKind] = {
    Impact: EventKind(
        'impact', 'impacts',
        ('stamp_ns', 'distance_from_tip_m', 'feature', 'distance_from_knob_m',
         'sweet_spot_speed_mps', 'bat_speed_at_contact_mps', 'ball_speed_mps',
         'attack_angle_deg'),
        (('point', XYZ), ('normal', NORMAL_XYZ))),
    NearMiss: EventKind(
        'near_miss', 'near_misses', ('stamp_ns', 'distance_from_tip_m', 'gap_m'),
        (('ball_position', XYZ), ('gap_vector', GAP_XYZ))),
    Prediction: EventKind(
        'prediction', 'predictions', ('stamp_ns', 'distance_from_tip_m', 'made_at_ns', 'lead_s'),
        (('point', XYZ), ('normal', NORMAL_XYZ))),
    StreamGap: EventKind('gap', 'gaps'),
    StateReset: EventKind('reset', 'resets'),
}
"""What the tools do with each event type: the one dispatch by type."""


def event_kind(event: Any) -> Optional[EventKind]:
    """Return the kind of a detector event, or None for a type the tools do not keep."""
    return EVENT_KINDS.get(type(event))


def event_record(event: Any) -> Dict[str, Any]:
    """
    Return an event as a flat record: ``event`` (its kind's name), its fields and vectors.

    An impact's ``x, y, z`` are its contact point, a near miss's the ball centre at closest
    approach, a prediction's the predicted contact point. Units as in the event (SI, ns).

    :raises KeyError: an event of a type not in :data:`EVENT_KINDS`.
    """
    kind = EVENT_KINDS[type(event)]
    record: Dict[str, Any] = {'event': kind.name}
    record.update((name, getattr(event, name)) for name in kind.fields)
    for attribute, names in kind.vectors:
        record.update(zip(names, getattr(event, attribute)))
    return record
