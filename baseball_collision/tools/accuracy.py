"""
Measure the detector against continuous-time truth: per simulated pitch, and summarised.

Pure Python + numpy (no ROS, no bags). Used by the accuracy tests and benchmark: a simulated
scenario is sampled like a tracker (:mod:`~baseball_collision.tools.sim`), fed to a fresh
detector, and compared with its truth. The only module of the tools besides ``recording`` that
imports the simulator; ``analyze`` reads truth files through :mod:`.truth` instead.

Impacts are matched to a pitch by the one rule of :func:`.truth.match_pitch` (the first impact
in the pitch's span; every other impact is false). Errors are detected minus true: the impact
stamp (s), the spot on the bat (``distance_from_tip_m``, m) and the sweet-spot speed
(relative); beside each, the 1-sigma uncertainty the impact reported, so that ``summarize``
can say how often the error stayed within one and two sigma (calibration).
"""

from dataclasses import dataclass
import math
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from .sim import DEFAULT_START_NS, sample, Samples, Scenario, truth_dict
from .truth import match_pitch
from ..core.detector import Detector, DetectorConfig, Event, Impact, NearMiss


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
    :ivar knob_distance_error_m: detected minus true distance from the knob (m): what
        ``location_sigma_m`` is the uncertainty of (None without a true one).
    :ivar time_sigma_s, location_sigma_m: the impact's reported 1-sigma uncertainties (the
        location's of its distance from the knob).
    :ivar speed_sigma: its sweet-spot speed uncertainty over the true speed.
    :ivar ball_speed_error: detected / true ball speed at the impact - 1 (None without a true
        one).
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
    time_sigma_s: Optional[float] = None
    location_sigma_m: Optional[float] = None
    speed_sigma: Optional[float] = None
    knob_distance_error_m: Optional[float] = None
    ball_speed_error: Optional[float] = None


def _span(truth: Mapping[str, Any]) -> Optional[Tuple[int, int]]:
    """Return a pitch's ``(start_ns, end_ns)``, or None when the truth gives none."""
    if truth.get('start_ns') is None or truth.get('end_ns') is None:
        return None
    return int(truth['start_ns']), int(truth['end_ns'])


def compare_pitch(truth: Mapping[str, Any], impacts: Sequence[Impact],
                  near_misses: Sequence[NearMiss] = ()) -> PitchResult:
    """
    Compare the impacts and near misses reported during one pitch with its truth.

    The match is :func:`.truth.match_pitch`'s (within the truth's ``start_ns``/``end_ns``
    when it has them); every impact but the match is a false impact.

    :param truth: the pitch's ``simulation.truth_dict``.
    :param impacts: the impacts reported for the pitch.
    :param near_misses: the near misses reported for it.
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
    match, _ = match_pitch(contact, impacts, _span(truth))
    if match is None:
        return PitchResult(detected=False, false_impacts=len(impacts), **common)
    first = impacts[match]
    true_speed = float(truth['sweet_spot_speed_mps'])
    true_knob = truth.get('distance_from_knob_m')
    true_ball = truth.get('ball_speed_mps')
    return PitchResult(
        detected=True, false_impacts=len(impacts) - 1,
        time_error_s=(first.stamp_ns - int(truth['stamp_ns'])) * 1e-9,
        location_error_m=first.distance_from_tip_m - float(truth['distance_from_tip_m']),
        sweet_spot_speed_error=first.sweet_spot_speed_mps / true_speed - 1.0,
        knob_distance_error_m=(None if true_knob is None
                               else first.distance_from_knob_m - float(true_knob)),
        time_sigma_s=getattr(first, 'time_uncertainty_s', None),
        location_sigma_m=getattr(first, 'distance_from_knob_uncertainty_m', None),
        speed_sigma=_relative(getattr(first, 'sweet_spot_speed_uncertainty_mps', None),
                              true_speed),
        ball_speed_error=(None if not true_ball
                          else first.ball_speed_mps / float(true_ball) - 1.0), **common)


def _relative(sigma: Optional[float], scale: float) -> Optional[float]:
    """Return sigma / scale, None when sigma is None."""
    return None if sigma is None else sigma / scale


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
    return run_samples(scenario, samples, config)


def run_samples(scenario: Scenario, samples: Samples,
                config: DetectorConfig) -> Tuple[List[Event], PitchResult]:
    """
    Feed a scenario's tracker samples to a fresh detector and compare with the truth.

    :param config: the detector configuration (its ``bat_input`` picks poses or knob/tip).
    :returns: (every event, the pitch's result).
    """
    detector = Detector(config)
    events: List[Event] = []
    for stamp, role, values in samples.messages(config.bat_input):
        events += detector.add(role, stamp, values)
    events += detector.finish()
    result = compare_pitch(truth_dict(scenario, samples.start_ns),
                           [e for e in events if isinstance(e, Impact)],
                           [e for e in events if isinstance(e, NearMiss)])
    return events, result


def _percentile(values: Sequence[float], q: float) -> float:
    return float(np.percentile(np.abs(values), q)) if len(values) else math.nan


def summarize(results: Sequence[PitchResult], min_clearance_m: float = 1e-4) -> Dict[str, float]:
    """
    Summarise pitch results: recall, precision, error percentiles and calibration.

    Recall and precision count only clear-cut pitches (a true overlap or a true clearance of
    more than ``min_clearance_m``); errors are over every matched contact.

    :returns: ``pitches``, ``contacts``, ``recall``, ``precision``, ``false_impacts``,
        ``time_error_us_p50/p99/max``, ``location_error_mm_p50/p99/max``,
        ``sweet_spot_speed_error_pct_p50/p99/max``, ``ball_speed_error_pct_p50/p99/max``
        (absolute values; the ball's over the impacts with a true ball speed),
        ``time_error_us_mean`` (signed: the bias), and per quantity ``<name>_within_1_sigma`` and
        ``<name>_within_2_sigma``: the fraction of impacts whose error was within one and two
        of their reported sigmas (NaN when none reported one).
    """
    clear = [r for r in results if r.clearance_m > min_clearance_m]
    contacts = [r for r in clear if r.contact]
    true_positive = sum(r.detected for r in contacts)
    reported = true_positive + sum(r.false_impacts for r in clear)
    matched = [r for r in results if r.contact and r.detected]
    times = [r.time_error_s * 1e6 for r in matched]
    spots = [r.location_error_m * 1e3 for r in matched]
    speeds = [r.sweet_spot_speed_error * 100.0 for r in matched]
    balls = [r.ball_speed_error * 100.0 for r in matched if r.ball_speed_error is not None]
    summary = {
        'pitches': float(len(results)), 'contacts': float(len(contacts)),
        'recall': true_positive / len(contacts) if contacts else math.nan,
        'precision': true_positive / reported if reported else math.nan,
        'false_impacts': float(sum(r.false_impacts for r in results)),
    }
    for name, values in (('time_error_us', times), ('location_error_mm', spots),
                         ('sweet_spot_speed_error_pct', speeds),
                         ('ball_speed_error_pct', balls)):
        summary[f'{name}_p50'] = _percentile(values, 50)
        summary[f'{name}_p99'] = _percentile(values, 99)
        summary[f'{name}_max'] = float(np.max(np.abs(values))) if values else math.nan
    summary['time_error_us_mean'] = float(np.mean(times)) if times else math.nan
    for name, error, sigma in (('time', 'time_error_s', 'time_sigma_s'),
                               ('location', 'knob_distance_error_m', 'location_sigma_m'),
                               ('speed', 'sweet_spot_speed_error', 'speed_sigma')):
        pairs = [(abs(getattr(r, error)), getattr(r, sigma)) for r in matched
                 if getattr(r, sigma) is not None and getattr(r, error) is not None]
        for k in (1, 2):
            inside = [e <= k * s for e, s in pairs]
            summary[f'{name}_within_{k}_sigma'] = (float(np.mean(inside)) if inside
                                                   else math.nan)
    return summary
