"""
Truth: the files ``simulate`` writes beside a bag, and the one rule matching impacts to them.

Pure Python + numpy (no ROS, no simulator): a truth file is read here, whoever wrote it.

* :func:`truth_path` and :func:`load_truth`: ``<bag name>.truth.json`` beside a bag, one
  ``simulation.truth_dict`` per pitch (``start_ns``, ``end_ns``, ``contact``, ``stamp_ns``,
  ``distance_from_tip_m``, ``sweet_spot_speed_mps``, ...).
* :func:`match_pitch`: THE matching rule, used by ``analyze`` (:func:`compare_truth`) and by
  the accuracy evaluation (:func:`~baseball_collision.tools.accuracy.compare_pitch`).
* :func:`prediction_errors`: predictions of one contact scored at lead times.

Errors are detected minus true: stamps in ns (or s where named), spots in m, speeds relative.
"""

import bisect
from dataclasses import dataclass, field
import json
import math
import os
from pathlib import Path
from typing import Any, Dict, List, Mapping, Optional, Protocol, Sequence, Tuple

import numpy as np

from ..core.detector import Prediction
from ..errors import ToolError

TRUTH_FORMAT = 'baseball_collision.truth/1'
"""``format`` value of a truth file."""

BAG_SUFFIXES = ('.mcap', '.db3', '.bag')
"""File suffixes of bare bag files (anything else is a ROS 2 bag directory)."""

LEADS_S = (0.2, 0.1, 0.05, 0.02)
"""Lead times (s) at which predictions are scored."""


def _named(bag: Path) -> Path:
    """
    Return a bag path with a name of its own: ``.``, ``..``, ``a/..`` made absolute.

    :raises ToolError: the file system's root (no name, nothing beside it).
    """
    if bag.name in ('', '.', '..'):
        bag = Path(os.path.abspath(bag))  # (normalised, symbolic links kept: not resolve())
        if not bag.name:
            raise ToolError(f'{bag} cannot be a bag with a truth file beside it')
    return bag


def bag_name(bag: os.PathLike) -> str:
    """
    Return a bag's own name, suffix and all: what the figures' titles name a bag by.

    ``runs/a.mcap`` -> ``a.mcap``; a bag directory ``.`` inside ``runs/a`` -> ``a``.

    :raises ToolError: the file system's root.
    """
    return _named(Path(bag)).name


def bag_stem(bag: os.PathLike) -> str:
    """
    Return a bag's name without its ``.mcap``, ``.db3`` or ``.bag`` suffix (``.``: resolved).

    ``runs/a.mcap`` -> ``a``; a bag directory ``runs/a`` -> ``a``; ``.`` inside ``runs/a`` ->
    ``a``. The truth file's name and the ``--plot`` files' start.

    :raises ToolError: the file system's root.
    """
    bag = _named(Path(bag))
    return bag.name[:-len(bag.suffix)] if bag.suffix.lower() in BAG_SUFFIXES else bag.name


def truth_path(bag: os.PathLike) -> Path:
    """
    Return where the truth file of a bag lives: beside it, ``<name>.truth.json``.

    ``runs/a.mcap`` -> ``runs/a.truth.json`` (the ``.mcap``/``.db3``/``.bag`` suffix is
    replaced: :func:`bag_stem`); a bag directory ``runs/a`` -> ``runs/a.truth.json``. A path
    without a name of its own (``.``, ``..``, ``runs/a/..``: a bag directory one is in) is made
    absolute first: ``.`` inside ``runs/a`` -> ``runs/a.truth.json`` (absolute).

    :raises ToolError: the file system's root (no name, nothing beside it).
    """
    bag = _named(Path(bag))
    return bag.with_name(f'{bag_stem(bag)}.truth.json')


PITCH_INTEGERS = ('start_ns', 'end_ns')
"""Keys every pitch of a truth file has, integers (ns)."""

CONTACT_INTEGERS = ('stamp_ns',)
"""Keys a pitch with a contact has, integers (ns)."""

CONTACT_NUMBERS = ('distance_from_tip_m', 'sweet_spot_speed_mps')
"""Keys a pitch with a contact has, finite numbers (``sweet_spot_speed_mps`` > 0)."""


def _refuse_constant(name: str) -> Any:
    """Refuse ``NaN``, ``Infinity`` and ``-Infinity`` in a truth file (``json.loads`` hook)."""
    raise ValueError(f'{name} is not a number a truth file may hold')


def _check_pitch(index: int, pitch: Any) -> None:
    """
    Check one pitch entry of a truth file has what the comparison reads, of the right types.

    :raises ValueError: naming the pitch and the key.
    """
    if not isinstance(pitch, dict):
        raise ValueError(f'pitch {index} is not an object')
    if not isinstance(pitch.get('contact'), bool):
        raise ValueError(f"pitch {index}: 'contact' must be true or false")
    integers = PITCH_INTEGERS + (CONTACT_INTEGERS if pitch['contact'] else ())
    numbers = CONTACT_NUMBERS if pitch['contact'] else ()
    for key in integers:
        if not isinstance(pitch.get(key), int) or isinstance(pitch.get(key), bool):
            raise ValueError(f"pitch {index}: '{key}' must be an integer (ns), got "
                             f'{pitch.get(key)!r:.40}')
    for key in numbers:
        value = pitch.get(key)
        if not isinstance(value, (int, float)) or isinstance(value, bool) \
                or not math.isfinite(value):
            raise ValueError(f"pitch {index}: '{key}' must be a finite number, got {value!r:.40}")
    if pitch['start_ns'] > pitch['end_ns']:
        raise ValueError(f'pitch {index}: start_ns is after end_ns')
    if pitch['contact'] and pitch['sweet_spot_speed_mps'] <= 0.0:
        raise ValueError(f"pitch {index}: 'sweet_spot_speed_mps' must be > 0")


def load_truth(path: os.PathLike) -> Dict[str, Any]:
    """
    Read a truth file written by ``baseball-collision simulate``, checked whole.

    Every pitch must have integer ``start_ns`` <= ``end_ns`` and a boolean ``contact``; a pitch
    with a contact an integer ``stamp_ns``, finite ``distance_from_tip_m`` and
    ``sweet_spot_speed_mps`` > 0. ``NaN`` and ``Infinity`` are refused, and so is nesting too
    deep to read.

    :returns: the truth document (``pitches``: one :func:`simulation.truth_dict` each).
    :raises ToolError: unreadable, not JSON, not a truth file, or a pitch without what the
        comparison needs (one line naming the pitch and the key).
    """
    path = Path(path)
    try:
        document = json.loads(path.read_text(), parse_constant=_refuse_constant)
    except OSError as error:
        raise ToolError(f'cannot read truth file {path}: {error.strerror}') from error
    except RecursionError as error:
        raise ToolError(f'truth file {path} is nested too deeply to read') from error
    except ValueError as error:  # also UnicodeDecodeError
        first = str(error).splitlines()[0][:120]
        raise ToolError(f'truth file {path} is not valid JSON: {first}') from error
    if not isinstance(document, dict) or document.get('format') != TRUTH_FORMAT \
            or not isinstance(document.get('pitches'), list):
        raise ToolError(f'{path} is not a {TRUTH_FORMAT} truth file')
    try:
        for index, pitch in enumerate(document['pitches']):
            _check_pitch(index, pitch)
    except ValueError as error:
        raise ToolError(f'truth file {path}: {error}') from error
    return document


class ImpactLike(Protocol):
    """What a truth comparison needs of an impact (``Impact``, or one heard from the node)."""

    stamp_ns: int
    distance_from_tip_m: float
    sweet_spot_speed_mps: float


class EventLike(Protocol):
    """What a truth comparison needs of a near miss."""

    stamp_ns: int


def match_pitch(contact: bool, impacts: Sequence[EventLike],
                span: Optional[Tuple[int, int]] = None) -> Tuple[Optional[int], List[int]]:
    """
    Match one pitch's impacts to its truth: the one rule of ``analyze`` and the evaluation.

    The pitch's impacts are those stamped inside its span ``[start_ns, end_ns]`` (inclusive;
    ``span=None``: every impact given). A pitch with a contact is matched to the FIRST of them
    (the earliest stamp; on a tie the earlier in ``impacts``). Every other impact of the pitch
    is a false impact; a pitch without a contact matches none.

    Why the first and not the one closest to the true contact: the truth's ``stamp_ns`` is the
    first contact, and the detector reports a contact once; a second report during a pitch is
    wrong wherever it lies. Picking the closest would let a spurious report near the truth
    take the credit and hide the error of the report a live consumer acted on, and would
    choose with knowledge (the true stamp) the detector does not have.

    :param contact: the pitch has a contact in its truth.
    :param impacts: detected impacts (anything with ``stamp_ns``).
    :param span: the pitch's ``(start_ns, end_ns)``; None: no bounds.
    :returns: (index in ``impacts`` of the match or None, indices of the pitch's impacts).
    """
    inside = [index for index, impact in enumerate(impacts)
              if span is None or span[0] <= impact.stamp_ns <= span[1]]
    if not contact or not inside:
        return None, inside
    return min(inside, key=lambda index: impacts[index].stamp_ns), inside


@dataclass
class TruthComparison:
    """
    Detected impacts against a truth file.

    :ivar path: the truth file.
    :ivar contacts: pitches with a contact in the truth.
    :ivar matched: ``(truth pitch, impact)`` for every contact found (the first impact in the
        pitch's time span: :func:`match_pitch`).
    :ivar missed: truth pitches with a contact and no impact in their span.
    :ivar false_impacts: impacts matched to no true contact.
    :ivar near_misses_in_misses: pitches without contact that got a near-miss report.
    :ivar misses: pitches without contact.
    """

    path: Path
    contacts: int = 0
    matched: List[Tuple[Dict[str, Any], ImpactLike]] = field(default_factory=list)
    missed: List[Dict[str, Any]] = field(default_factory=list)
    false_impacts: List[ImpactLike] = field(default_factory=list)
    near_misses_in_misses: int = 0
    misses: int = 0

    @property
    def time_errors_ns(self) -> List[int]:
        """Return detected minus true first-contact stamp, per match (ns)."""
        return [impact.stamp_ns - int(truth['stamp_ns']) for truth, impact in self.matched]

    @property
    def spot_errors_m(self) -> List[float]:
        """Return detected minus true contact distance from the tip, per match (m)."""
        return [impact.distance_from_tip_m - float(truth['distance_from_tip_m'])
                for truth, impact in self.matched]

    @property
    def speed_errors(self) -> List[float]:
        """Return relative sweet-spot speed errors (detected / true - 1), per match."""
        return [impact.sweet_spot_speed_mps / float(truth['sweet_spot_speed_mps']) - 1.0
                for truth, impact in self.matched]

    def as_dict(self) -> Dict[str, Any]:
        """Return the comparison as JSON-ready data (SI units, ns)."""
        def biggest(values: Sequence[float]) -> Optional[float]:
            return max((abs(v) for v in values), default=None)

        return {
            'path': str(self.path),
            'contacts': self.contacts,
            'matched': len(self.matched),
            'missed': [truth.get('name') for truth in self.missed],
            'false_impacts': [impact.stamp_ns for impact in self.false_impacts],
            'misses': self.misses,
            'near_misses_in_misses': self.near_misses_in_misses,
            'max_abs_time_error_ns': biggest(self.time_errors_ns),
            'max_abs_spot_error_m': biggest(self.spot_errors_m),
            'max_abs_speed_error': biggest(self.speed_errors),
            'pitches': [
                {'name': truth.get('name'), 'kind': truth.get('kind'),
                 'truth_stamp_ns': truth['stamp_ns'], 'stamp_ns': impact.stamp_ns,
                 'time_error_ns': impact.stamp_ns - int(truth['stamp_ns']),
                 'spot_error_m': impact.distance_from_tip_m
                 - float(truth['distance_from_tip_m']),
                 'sweet_spot_speed_error': impact.sweet_spot_speed_mps
                 / float(truth['sweet_spot_speed_mps']) - 1.0}
                for truth, impact in self.matched],
        }


def compare_truth(impacts: Sequence[ImpactLike], near_misses: Sequence[EventLike],
                  truth: Mapping[str, Any], path: os.PathLike) -> TruthComparison:
    """
    Match impacts to true contacts pitch by pitch (:func:`match_pitch`).

    Every pitch spans ``[start_ns, end_ns]``. A pitch with a contact is matched to the first
    impact inside its span; other impacts in the span, and impacts in no span, are false
    impacts. The impacts and near misses are sorted by stamp once and each pitch's are found by
    bisection: O((pitches + impacts) log impacts), not pitches x impacts.

    :param impacts: detected impacts.
    :param near_misses: detected near misses (counted for pitches without contact).
    :param truth: a truth document (:func:`load_truth`).
    :param path: where it came from (for reports).
    :returns: the comparison.
    :raises ToolError: a pitch entry without the needed keys.
    """
    result = TruthComparison(path=Path(path))
    order = sorted(range(len(impacts)), key=lambda index: (impacts[index].stamp_ns, index))
    stamps = [impacts[index].stamp_ns for index in order]
    miss_stamps = sorted(miss.stamp_ns for miss in near_misses)
    used = set()
    try:
        for pitch in truth['pitches']:
            start, end = int(pitch['start_ns']), int(pitch['end_ns'])
            if not pitch['contact']:
                result.misses += 1
                first_after = bisect.bisect_left(miss_stamps, start)
                if first_after < len(miss_stamps) and miss_stamps[first_after] <= end:
                    result.near_misses_in_misses += 1
                continue
            inside = order[bisect.bisect_left(stamps, start):bisect.bisect_right(stamps, end)]
            match, _ = match_pitch(True, [impacts[index] for index in inside])
            result.contacts += 1
            if match is None:
                result.missed.append(pitch)
                continue
            used.add(inside[match])
            result.matched.append((pitch, impacts[inside[match]]))
    except (KeyError, TypeError, ValueError) as error:
        raise ToolError(f'truth file {path} has a malformed pitch: {error!r}') from error
    result.false_impacts = [impact for i, impact in enumerate(impacts) if i not in used]
    return result


class PredictionIndex:
    """
    Predictions and their clearings indexed once, to score the predictions of many contacts.

    A prediction is in force from the frame that made it until the next prediction or the
    next ``PredictionCleared``: what the node's ``~/predicted_impact`` and
    ``~/impact_predicted`` say in between (a frame that does not predict, within the
    ``prediction_period`` or before the detector can process it, keeps it in force; a bat
    tracked faster than the ball has many such frames). Built in O(n log n) over the
    predictions and clearings; each contact is then scored in O(leads x log n)
    (:meth:`errors`).

    :param predictions: every prediction, in any order (the last one made at a frame counts).
    :param cleared_ns: when each ``PredictionCleared`` was made (its ``made_at_ns``), or the
        detector was reset (a ``StateReset``'s stamp), any order.
    """

    def __init__(self, predictions: Sequence[Prediction], cleared_ns: Sequence[int] = ()) -> None:
        by_frame: Dict[int, Prediction] = {}
        for prediction in predictions:
            by_frame[prediction.made_at_ns] = prediction  # the last one made at a frame
        self.made = np.array(sorted(by_frame), dtype=np.int64)
        self.made_predictions = [by_frame[int(stamp)] for stamp in self.made]
        self.cleared = np.sort(np.asarray(cleared_ns, dtype=np.int64))

    def in_force(self, at_ns: int) -> Optional[Prediction]:
        """Return the prediction in force at a stamp (ns): the last made, unless cleared since."""
        index = int(np.searchsorted(self.made, at_ns, side='right')) - 1
        if index < 0:
            return None
        made = int(self.made[index])
        cleared = int(np.searchsorted(self.cleared, at_ns, side='right')) - 1
        if cleared >= 0 and int(self.cleared[cleared]) > made:
            return None
        return self.made_predictions[index]

    def errors(self, contact_ns: int, contact_point: Sequence[float],
               leads_s: Sequence[float] = LEADS_S,
               window_ns: Optional[int] = None) -> Dict[float, Optional[Tuple[float, float]]]:
        """
        Score the predictions of one contact at several lead times (see prediction_errors).

        :param window_ns: only predictions made at most this long before the contact count
            (None: any made before it).
        :returns: ``{lead: (time error s, point error m) or None}``.
        """
        result: Dict[float, Optional[Tuple[float, float]]] = {}
        for lead in leads_s:
            chosen = self.in_force(contact_ns - int(round(lead * 1e9)))
            if chosen is not None and (chosen.made_at_ns >= contact_ns or (
                    window_ns is not None and contact_ns - chosen.made_at_ns > window_ns)):
                chosen = None
            result[lead] = None if chosen is None else (
                (chosen.stamp_ns - contact_ns) * 1e-9,
                float(np.linalg.norm(np.subtract(chosen.point, contact_point))))
        return result


def silence_clearings(index: PredictionIndex, ball_gaps: Sequence[Tuple[int, int]],
                      max_gap: float, flight_span: float) -> List[int]:
    """
    Return when the node's ``~/impact_predicted`` ends a prediction for the ball's silence (ns).

    The node's rule (``ros.prediction_watch.PredictionWatch.passed``) on the stamps, the ball
    no later than the bat: across a ball gap (its sample before, its next, ns) the prediction in
    force at the gap's start ends once the stamps pass its instant + ``max_gap`` and the gap's
    start + ``flight_span`` (s, ``predictor.kept_flight_span``: the flight before the silence
    holds till then, and a paused tracker may still bring the contact), where that comes before
    the ball's next sample. (The node's bat takes a sample or two more; the detector itself
    clears a prediction at its next frame that predicts, after the gap.)
    """
    span, gap_ns = round(flight_span * 1e9), round(max_gap * 1e9)
    ends = []
    for start, end in ball_gaps:
        held = index.in_force(start)
        if held is not None and (ends_at := max(start + span, held.stamp_ns + gap_ns)) < end:
            ends.append(ends_at)
    return ends


def prediction_errors(predictions: Sequence[Prediction], cleared_ns: Sequence[int],
                      contact_ns: int, contact_point: Sequence[float],
                      leads_s: Sequence[float] = LEADS_S) -> Dict[float,
                                                                  Optional[Tuple[float, float]]]:
    """
    Score predictions of one contact at several lead times.

    For each lead L the prediction scored is the one in force L before the contact: the last
    made by then, unless a ``PredictionCleared`` came after it (None: nothing was predicted
    then). (For many contacts build one :class:`PredictionIndex` and call its ``errors``.)

    :param predictions: the predictions made before the contact.
    :param cleared_ns: when the detector cleared a prediction (``PredictionCleared.made_at_ns``).
    :param contact_ns: the contact's stamp (ns); ``contact_point`` its point (m).
    :returns: ``{lead: (time error s, point error m) or None}``; errors are predicted minus
        true, the point error a distance.
    """
    return PredictionIndex(predictions, cleared_ns).errors(contact_ns, contact_point, leads_s)
