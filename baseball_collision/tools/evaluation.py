"""
Measure the detector against continuous-time truth: per pitch, and summarised.

Pure Python + numpy (no ROS). Used by the accuracy tests and benchmark (simulated scenarios
sampled like a tracker) and by the bag tools (truth files written beside simulated bags).

A pitch's truth is a ``simulation.truth_dict``. A detected impact is matched to a pitch with a
contact when it is the first impact reported for that pitch; every other impact in the pitch is
a false impact. Errors are detected minus true: the impact stamp (s), the spot on the bat
(``distance_from_tip_m``, m) and the sweet-spot speed (relative).
"""

from dataclasses import dataclass
import math
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from .sim import DEFAULT_START_NS, sample, Scenario, truth_dict
from ..core.detector import Detector, DetectorConfig, Event, Impact, NearMiss, Prediction


@dataclass(frozen=True)
class PitchResult:
    """
    One pitch, detected against its truth.

    :ivar name, kind: the pitch (from its truth).
    :ivar contact: the truth has a contact.
    :ivar clearance_m: the truth's smallest gap magnitude (m): how clear-cut the pitch is.
    :ivar detected: an impact was reported for the pitch.
    :ivar false_impacts: impacts that are not the pitch's first contact.
    :ivar time_error_s: first impact stamp minus the true contact stamp (s).
    :ivar location_error_m: detected minus true distance from the tip (m).
    :ivar sweet_spot_speed_error: detected / true sweet-spot speed - 1.
    :ivar near_miss_gap_error_m: reported minus true smallest gap of a near miss (m).
    """

    name: str
    kind: str
    contact: bool
    clearance_m: float
    detected: bool
    false_impacts: int
    time_error_s: Optional[float] = None
    location_error_m: Optional[float] = None
    sweet_spot_speed_error: Optional[float] = None
    near_miss_gap_error_m: Optional[float] = None


def compare_pitch(truth: Mapping[str, Any], impacts: Sequence[Impact],
                  near_misses: Sequence[NearMiss] = ()) -> PitchResult:
    """
    Compare the impacts and near misses reported during one pitch with its truth.

    :param truth: the pitch's ``simulation.truth_dict``.
    :param impacts: the impacts reported between the pitch's start and end stamps.
    :param near_misses: the near misses reported in that span.
    :returns: the pitch's result.
    """
    contact = bool(truth['contact'])
    common = {'name': str(truth.get('name', '')), 'kind': str(truth.get('kind', '')),
              'contact': contact, 'clearance_m': abs(float(truth['min_gap_m']))}
    if not contact:
        gap_error = None
        if near_misses:
            gap_error = min(m.gap_m for m in near_misses) - float(truth['min_gap_m'])
        return PitchResult(detected=bool(impacts), false_impacts=len(impacts),
                           near_miss_gap_error_m=gap_error, **common)
    if not impacts:
        return PitchResult(detected=False, false_impacts=0, **common)
    first = min(impacts, key=lambda impact: impact.stamp_ns)
    return PitchResult(
        detected=True, false_impacts=len(impacts) - 1,
        time_error_s=(first.stamp_ns - int(truth['stamp_ns'])) * 1e-9,
        location_error_m=first.distance_from_tip_m - float(truth['distance_from_tip_m']),
        sweet_spot_speed_error=first.sweet_spot_speed_mps / float(
            truth['sweet_spot_speed_mps']) - 1.0, **common)


def run_scenario(scenario: Scenario, rate_hz: float, config: DetectorConfig,
                 rng: np.random.Generator, *, jitter_s: float = 0.0,
                 grid_s: Optional[float] = None, noise_m: float = 0.0,
                 start_ns: int = DEFAULT_START_NS) -> Tuple[List[Event], PitchResult]:
    """
    Sample a scenario like a tracker, feed a fresh detector, and compare with the truth.

    :param scenario: the continuous-time pitch and swing.
    :param rate_hz: tracker rate; ``jitter_s``, ``grid_s``, ``noise_m`` as for ``sample``.
    :param config: the detector configuration (its ``bat_input`` picks poses or knob/tip).
    :returns: (every event, the pitch's result).
    """
    samples = sample(scenario, rate_hz, rng, jitter_s=jitter_s, grid_s=grid_s,
                     noise_m=noise_m, start_ns=start_ns)
    detector = Detector(config)
    events: List[Event] = []
    for stamp, role, values in samples.messages(config.bat_input):
        events += detector.add(role, stamp, values)
    events += detector.finish()
    result = compare_pitch(truth_dict(scenario, start_ns),
                           [e for e in events if isinstance(e, Impact)],
                           [e for e in events if isinstance(e, NearMiss)])
    return events, result


def _percentile(values: Sequence[float], q: float) -> float:
    return float(np.percentile(np.abs(values), q)) if len(values) else math.nan


def summarize(results: Sequence[PitchResult], min_clearance_m: float = 1e-4) -> Dict[str, float]:
    """
    Summarise pitch results: recall, precision and error percentiles.

    Recall and precision count only clear-cut pitches (a true overlap or a true clearance of
    more than ``min_clearance_m``); errors are over every matched contact.

    :returns: ``pitches``, ``contacts``, ``recall``, ``precision``, ``false_impacts``,
        ``time_error_us_p50/p99/max``, ``location_error_mm_p50/p99/max``,
        ``sweet_spot_speed_error_pct_p50/p99/max`` (absolute values).
    """
    clear = [r for r in results if r.clearance_m > min_clearance_m]
    contacts = [r for r in clear if r.contact]
    true_positive = sum(r.detected for r in contacts)
    reported = true_positive + sum(r.false_impacts for r in clear)
    matched = [r for r in results if r.contact and r.detected]
    times = [r.time_error_s * 1e6 for r in matched]
    spots = [r.location_error_m * 1e3 for r in matched]
    speeds = [r.sweet_spot_speed_error * 100.0 for r in matched]
    summary = {
        'pitches': float(len(results)), 'contacts': float(len(contacts)),
        'recall': true_positive / len(contacts) if contacts else math.nan,
        'precision': true_positive / reported if reported else math.nan,
        'false_impacts': float(sum(r.false_impacts for r in results)),
    }
    for name, values in (('time_error_us', times), ('location_error_mm', spots),
                         ('sweet_spot_speed_error_pct', speeds)):
        summary[f'{name}_p50'] = _percentile(values, 50)
        summary[f'{name}_p99'] = _percentile(values, 99)
        summary[f'{name}_max'] = float(np.max(np.abs(values))) if values else math.nan
    return summary


LEADS_S = (0.2, 0.1, 0.05, 0.02)
"""Lead times (s) at which predictions are scored."""


def prediction_errors(predictions: Sequence[Prediction], frames_ns: Sequence[int],
                      contact_ns: int, contact_point: Sequence[float],
                      leads_s: Sequence[float] = LEADS_S) -> Dict[float,
                                                                  Optional[Tuple[float, float]]]:
    """
    Score predictions of one contact at several lead times.

    For each lead L the prediction scored is the one made at the last processed frame at
    least L before the contact; a frame that had no prediction scores None (not predicted).

    :param predictions: the predictions made before the contact.
    :param frames_ns: every processed frame stamp (ns) (the union of the sample stamps).
    :param contact_ns: the contact's stamp (ns); ``contact_point`` its point (m).
    :returns: ``{lead: (time error s, point error m) or None}``; errors are predicted minus
        true, the point error a distance.
    """
    by_frame: Dict[int, Prediction] = {}
    for prediction in predictions:
        by_frame[prediction.made_at_ns] = prediction  # the last one made at a frame
    frames = sorted(frames_ns)
    result: Dict[float, Optional[Tuple[float, float]]] = {}
    for lead in leads_s:
        cut = contact_ns - int(round(lead * 1e9))
        index = np.searchsorted(frames, cut, side='right') - 1
        chosen = by_frame.get(frames[index]) if index >= 0 else None
        result[lead] = None if chosen is None else (
            (chosen.stamp_ns - contact_ns) * 1e-9,
            float(np.linalg.norm(np.subtract(chosen.point, contact_point))))
    return result
