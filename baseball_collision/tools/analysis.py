"""
Offline analysis of bags: run the one detector over recorded samples, report and export.

No rclpy: this is the ``baseball-collision analyze`` path and runs on rosbags and the core only
(matplotlib is imported only when plots are asked for).

What is here:

* Node parameter files (:func:`load_parameters`): the ROS 2 YAML the ``impact_node`` takes
  (``<node_name>: ros__parameters:`` and ``/**: ros__parameters:`` sections, nested keys joined by
  ``.``), and :func:`build_config` to turn them, with command-line overrides, into a
  :class:`~baseball_collision.detector.DetectorConfig`.
* :func:`analyze_bag`: read a bag with :class:`~baseball_collision.bag.BagReader` and feed every
  sample to :meth:`Detector.add` in the bag's order, then :meth:`Detector.finish`; optionally
  copy the input topics and the node's output topics into an MCAP as it goes.
* Truth files written by ``baseball-collision simulate`` (:func:`truth_path`, :func:`load_truth`,
  :func:`compare_truth`).
* Reports: the printed table (:func:`format_report`), JSON (:func:`to_json`), CSV
  (:func:`csv_text`) and plots (:func:`write_plots`).
* :class:`Outputs`: output paths checked before any work and committed atomically at the end, so
  a failure leaves no partial file behind.

Units are SI everywhere but in the printed table (cm, mph, ms, us).
"""

import csv
from dataclasses import asdict, dataclass, field
import io
import itertools
import json
import math
import os
from pathlib import Path
import shutil
import sys
import tempfile
import time
from typing import (
    Any, Callable, Dict, IO, Iterable, List, Mapping, Optional, Protocol, Sequence, Tuple)

import numpy as np

from .evaluation import LEADS_S, prediction_errors
from .parameters import build_config, load_parameters, NODE_NAME, OFFLINE_MODEL  # noqa: F401
from ..bags import BagReader, BagWriter, POSE_STAMPED, TopicSelection
from ..core.detector import (
    Detector, DetectorConfig, DetectorStats, Impact, MPS_TO_MPH, NearMiss, Prediction, StateReset,
    StreamGap)
from ..core.toi import profile_gap
from ..errors import BagError, ToolError

TRUTH_FORMAT = 'baseball_collision.truth/1'
"""``format`` value of a truth file."""

JSON_FORMAT = 'baseball_collision.analyze/1'
"""``format`` value of an ``analyze --json`` file."""

PROGRESS_MIN_MESSAGES = 100_000
"""Bags with more messages than this get a progress bar (also any bag when stderr is a TTY)."""

PLOT_WINDOW_S = 0.04
"""Half-width (s) of the time window each plot shows around an impact."""

BAG_SUFFIXES = ('.mcap', '.db3', '.bag')
"""File suffixes of bare bag files (anything else is a ROS 2 bag directory)."""

_CHUNK = 8192


# ----------------------------------------------------------------------------------------------
# Truth files


def truth_path(bag: os.PathLike) -> Path:
    """
    Return where the truth file of a bag lives: beside it, ``<name>.truth.json``.

    ``runs/a.mcap`` -> ``runs/a.truth.json`` (the ``.mcap``/``.db3``/``.bag`` suffix is
    replaced); a bag directory ``runs/a`` -> ``runs/a.truth.json``.
    """
    bag = Path(bag)
    stem = bag.name[:-len(bag.suffix)] if bag.suffix.lower() in BAG_SUFFIXES else bag.name
    return bag.with_name(f'{stem}.truth.json')


def load_truth(path: os.PathLike) -> Dict[str, Any]:
    """
    Read a truth file written by ``baseball-collision simulate``.

    :returns: the truth document (``pitches``: one :func:`simulation.truth_dict` each).
    :raises ToolError: unreadable, not JSON, or not a truth file.
    """
    path = Path(path)
    try:
        document = json.loads(path.read_text())
    except OSError as error:
        raise ToolError(f'cannot read truth file {path}: {error.strerror}') from error
    except ValueError as error:
        raise ToolError(f'truth file {path} is not valid JSON: {error}') from error
    if not isinstance(document, dict) or document.get('format') != TRUTH_FORMAT \
            or not isinstance(document.get('pitches'), list):
        raise ToolError(f'{path} is not a {TRUTH_FORMAT} truth file')
    return document


class ImpactLike(Protocol):
    """What a truth comparison needs of an impact (``Impact``, or one heard from the node)."""

    stamp_ns: int
    distance_from_tip_m: float
    sweet_spot_speed_mps: float


class EventLike(Protocol):
    """What a truth comparison needs of a near miss."""

    stamp_ns: int


@dataclass
class TruthComparison:
    """
    Detected impacts against a truth file.

    :ivar path: the truth file.
    :ivar contacts: pitches with a contact in the truth.
    :ivar matched: ``(truth pitch, impact)`` for every contact found (the impact in the pitch's
        time span closest to the true first contact).
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
    Match impacts to true contacts pitch by pitch.

    Every pitch spans ``[start_ns, end_ns]``. A pitch with a contact is matched to the impact
    inside its span closest to the true first contact; other impacts in the span, and impacts in
    no span, are false impacts.

    :param impacts: detected impacts.
    :param near_misses: detected near misses (counted for pitches without contact).
    :param truth: a truth document (:func:`load_truth`).
    :param path: where it came from (for reports).
    :returns: the comparison.
    :raises ToolError: a pitch entry without the needed keys.
    """
    result = TruthComparison(path=Path(path))
    used = set()
    try:
        for pitch in truth['pitches']:
            start, end = int(pitch['start_ns']), int(pitch['end_ns'])
            inside = [i for i, impact in enumerate(impacts) if start <= impact.stamp_ns <= end]
            if not pitch['contact']:
                result.misses += 1
                if any(start <= miss.stamp_ns <= end for miss in near_misses):
                    result.near_misses_in_misses += 1
                continue
            result.contacts += 1
            if not inside:
                result.missed.append(pitch)
                continue
            best = min(inside, key=lambda i: abs(impacts[i].stamp_ns - int(pitch['stamp_ns'])))
            used.add(best)
            result.matched.append((pitch, impacts[best]))
    except (KeyError, TypeError, ValueError) as error:
        raise ToolError(f'truth file {path} has a malformed pitch: {error!r}') from error
    result.false_impacts = [impact for i, impact in enumerate(impacts) if i not in used]
    return result


# ----------------------------------------------------------------------------------------------
# Running the detector over a bag


@dataclass
class BagAnalysis:
    """
    What the detector found in one bag.

    :ivar path: the bag.
    :ivar selection: the topics read.
    :ivar config: the detector configuration used.
    :ivar impacts, near_misses, gaps, resets: the detector's events, in order.
    :ivar predictions: predicted impacts (with ``--predict``), in order.
    :ivar frames_ns: every sample stamp (ns), kept with ``--predict`` to score predictions.
    :ivar stats: the detector's counters (``dropped`` by reason).
    :ivar messages: samples read and fed.
    :ivar seconds: wall time of reading and detecting (s).
    :ivar first_stamp_ns: the first sample's header stamp (ns): the table's time origin.
    :ivar truth: the comparison with the truth file beside the bag, if there is one.
    """

    path: Path
    selection: TopicSelection
    config: DetectorConfig
    impacts: List[Impact] = field(default_factory=list)
    near_misses: List[NearMiss] = field(default_factory=list)
    gaps: List[StreamGap] = field(default_factory=list)
    resets: List[StateReset] = field(default_factory=list)
    predictions: List[Prediction] = field(default_factory=list)
    frames_ns: List[int] = field(default_factory=list)
    stats: DetectorStats = field(default_factory=DetectorStats)
    messages: int = 0
    seconds: float = 0.0
    first_stamp_ns: Optional[int] = None
    truth: Optional[TruthComparison] = None

    @property
    def throughput(self) -> float:
        """Return samples per second of wall time (0 when nothing was timed)."""
        return self.messages / self.seconds if self.seconds > 0.0 else 0.0

    def relative_s(self, stamp_ns: int) -> float:
        """Return seconds from the first header stamp of the bag to ``stamp_ns``."""
        return (stamp_ns - (self.first_stamp_ns or 0)) * 1e-9

    def prediction_scores(self) -> List[Dict[float, Optional[Tuple[float, float]]]]:
        """
        Score the predictions of every impact at the lead times ``LEADS_S``.

        The reference is the true contact when a truth file matched the impact, else the
        detected impact itself. One ``evaluation.prediction_errors`` dict per impact.
        """
        truths = {}
        if self.truth is not None:
            truths = {impact.stamp_ns: truth for truth, impact in self.truth.matched}
        scores = []
        for impact in self.impacts:
            truth = truths.get(impact.stamp_ns)
            stamp = int(truth['stamp_ns']) if truth else impact.stamp_ns
            point = truth['point'] if truth else impact.point
            before = [p for p in self.predictions if p.made_at_ns < stamp
                      and stamp - p.made_at_ns <= 0.5e9]
            scores.append(prediction_errors(before, self.frames_ns, stamp, point))
        return scores


@dataclass(frozen=True)
class AnalysisOptions:
    """
    How to analyse: topics, parameters and overrides (None: not given).

    :ivar ball_topic, bat_pose_topic, knob_topic, tip_topic: topic flags.
    :ivar parameters: flat node parameters from ``--params`` (empty: none).
    :ivar model: ``--model``.
    :ivar ball_radius: ``--ball-radius`` (m).
    :ivar bat_radius: ``--bat-radius`` (m).
    :ivar prediction_horizon: ``--predict`` horizon (s).
    :ivar node_name: the node whose output topics ``--out-bag`` writes.
    """

    ball_topic: Optional[str] = None
    bat_pose_topic: Optional[str] = None
    knob_topic: Optional[str] = None
    tip_topic: Optional[str] = None
    parameters: Mapping[str, Any] = field(default_factory=dict)
    model: Optional[str] = None
    ball_radius: Optional[float] = None
    bat_radius: Optional[float] = None
    prediction_horizon: Optional[float] = None
    node_name: str = NODE_NAME

    def reader(self, path: os.PathLike) -> BagReader:
        """Return an unopened reader of ``path`` with these topic choices."""
        prefer = 'points' if self.parameters.get('bat_input') == 'points' else 'pose'
        return BagReader(path, ball=self.ball_topic, bat_pose=self.bat_pose_topic,
                         knob=self.knob_topic, tip=self.tip_topic, prefer_bat=prefer)


def output_topics(node_name: str = NODE_NAME) -> Dict[str, str]:
    """Return the node's event topics: ``{'impact': '/<node>/impact', ...}``."""
    base = '/' + node_name.strip('/')
    return {'impact': f'{base}/impact', 'impact_velocity': f'{base}/impact_velocity',
            'near_miss': f'{base}/near_miss', 'predicted_impact': f'{base}/predicted_impact'}


class _EventCopy:
    """Write the input samples and the detector's events to an output bag, in log-time order."""

    def __init__(self, writer: BagWriter, selection: TopicSelection, node_name: str) -> None:
        self.writer = writer
        self.topics = selection.topics
        self.ball_pose = selection.ball_type == POSE_STAMPED
        self.outputs = output_topics(node_name)
        self.frame = ''

    def sample(self, role: str, stamp: int, frame: str, values: Sequence[float],
               log_time: int) -> None:
        """Copy one input sample; a ball pose keeps its position, with an identity orientation."""
        topic = self.topics[role]
        if not self.frame:
            self.frame = frame
        if role == 'bat_pose':
            self.writer.write_pose(topic, stamp, frame, values[:3], values[3:], log_time)
        elif role == 'ball' and self.ball_pose:
            self.writer.write_pose(topic, stamp, frame, values, (0.0, 0.0, 0.0, 1.0), log_time)
        else:
            self.writer.write_point(topic, stamp, frame, values, log_time)

    def events(self, events: Iterable[Any], log_time: int, frame: str) -> None:
        """Write impact and near-miss events as the node publishes them."""
        frame = frame or self.frame
        for event in events:
            if isinstance(event, Impact):
                self.writer.write_point(self.outputs['impact'], event.stamp_ns, frame,
                                        event.point, log_time)
                self.writer.write_twist(self.outputs['impact_velocity'], event.stamp_ns, frame,
                                        event.bat_velocity, event.bat_angular_velocity,
                                        log_time)
            elif isinstance(event, NearMiss):
                self.writer.write_vector3(self.outputs['near_miss'], event.stamp_ns, frame,
                                          event.gap_vector, log_time)
            elif isinstance(event, Prediction):
                self.writer.write_point(self.outputs['predicted_impact'], event.stamp_ns, frame,
                                        event.point, log_time)


def _progress(total: int, label: str) -> Any:
    """Return a tqdm bar on stderr for long bags or a terminal, else None."""
    if total <= PROGRESS_MIN_MESSAGES and not sys.stderr.isatty():
        return None
    from tqdm import tqdm
    return tqdm(total=total, unit='msg', unit_scale=True, desc=label, file=sys.stderr,
                leave=False, dynamic_ncols=True)


def analyze_bag(path: os.PathLike, options: AnalysisOptions = AnalysisOptions(), *,
                out_bag: Optional[BagWriter] = None, progress: bool = True,
                use_truth: bool = True) -> BagAnalysis:
    """
    Run the detector over a bag: every selected sample in the bag's order, then ``finish()``.

    :param path: ROS 2 bag directory, ``.mcap``/``.db3`` file or ROS 1 ``.bag`` file.
    :param options: topics, parameters and overrides.
    :param out_bag: an open writer that receives the input samples and the event messages.
    :param progress: show a progress bar on stderr for long bags (see :func:`_progress`).
    :param use_truth: compare with the truth file beside the bag when there is one.
    :returns: the analysis.
    :raises ToolError: the bag cannot be read (missing, empty, corrupt, without the needed
        topics or with topics of the wrong type), a bad setting, a bad truth file, or a
        failure writing ``out_bag``.
    """
    path = Path(path)
    start = time.perf_counter()
    try:
        with options.reader(path) as bag:
            selection = bag.selection
            config = build_config(options.parameters, bat_input=selection.bat_mode,
                                  model=options.model, ball_radius=options.ball_radius,
                                  bat_radius=options.bat_radius,
                                  prediction_horizon=options.prediction_horizon)
            result = BagAnalysis(path=path, selection=selection, config=config)
            detector = Detector(config)
            bar = _progress(bag.message_count, path.name) if progress else None
            try:
                if out_bag is None:
                    _run(bag.samples(), detector, result, bar)
                else:
                    _run_copy(bag.samples(), detector, result,
                              _EventCopy(out_bag, selection, options.node_name))
            finally:
                if bar is not None:
                    bar.close()
    except BagError as error:
        raise ToolError(str(error)) from error
    result.seconds = time.perf_counter() - start
    result.stats = detector.stats
    truth_file = truth_path(path)
    if use_truth and truth_file.is_file():
        result.truth = compare_truth(result.impacts, result.near_misses, load_truth(truth_file),
                                     truth_file)
    return result


def _sort(events: Iterable[Any], result: BagAnalysis) -> None:
    """File events into the analysis by type."""
    for event in events:
        if isinstance(event, Impact):
            result.impacts.append(event)
        elif isinstance(event, NearMiss):
            result.near_misses.append(event)
        elif isinstance(event, StreamGap):
            result.gaps.append(event)
        elif isinstance(event, StateReset):
            result.resets.append(event)
        elif isinstance(event, Prediction):
            result.predictions.append(event)


def _run(samples: Iterable[Any], detector: Detector, result: BagAnalysis, bar: Any) -> None:
    """Feed samples to the detector (the fast loop: nothing but ``add`` per sample)."""
    add = detector.add
    iterator = iter(samples)
    count = 0
    frames = result.frames_ns if detector.config.prediction_horizon > 0.0 else None
    while True:
        chunk = 0
        for role, stamp, frame, values, _ in itertools.islice(iterator, _CHUNK):
            if result.first_stamp_ns is None:
                result.first_stamp_ns = stamp
            if frames is not None:
                frames.append(stamp)
            events = add(role, stamp, values, frame)
            if events:
                _sort(events, result)
            chunk += 1
        count += chunk
        if bar is not None:
            bar.update(chunk)
        if chunk < _CHUNK:
            break
    _sort(detector.finish(), result)
    result.messages = count


def _run_copy(samples: Iterable[Any], detector: Detector, result: BagAnalysis,
              copy: _EventCopy) -> None:
    """Feed samples to the detector and copy samples and events into the output bag."""
    add = detector.add
    count = 0
    log_time, frame = 0, ''
    frames = result.frames_ns if detector.config.prediction_horizon > 0.0 else None
    for role, stamp, frame, values, log_time in samples:
        if result.first_stamp_ns is None:
            result.first_stamp_ns = stamp
        if frames is not None:
            frames.append(stamp)
        copy.sample(role, stamp, frame, values, log_time)
        events = add(role, stamp, values, frame)
        if events:
            _sort(events, result)
            copy.events(events, log_time, detector.config.frame_id or frame)
        count += 1
    events = detector.finish()
    _sort(events, result)
    copy.events(events, log_time, detector.config.frame_id or frame)
    result.messages = count


# ----------------------------------------------------------------------------------------------
# Reports


def _cm(metres: float) -> str:
    return f'{metres * 100.0:.1f}'


def _mph(mps: float) -> str:
    return f'{mps * MPS_TO_MPH:.1f}'


TABLE_COLUMNS = (
    ('#', 3), ('event', 9), ('t (s)', 9), ('stamp (ns)', 19), ('from tip (cm)', 13),
    ('where', 8), ('sweet spot (mph)', 16), ('ball (mph)', 10), ('attack (deg)', 12),
    ('gap (cm)', 8))
"""Printed table: (title, width) per column."""


def _row(cells: Sequence[str]) -> str:
    parts = []
    for (title, width), cell in zip(TABLE_COLUMNS, cells):
        parts.append(cell.ljust(width) if title in ('event', 'where') else cell.rjust(width))
    return '  '.join(parts).rstrip()


def _events(analysis: BagAnalysis) -> List[Any]:
    """Return impacts and near misses in time order."""
    return sorted(analysis.impacts + analysis.near_misses, key=lambda e: e.stamp_ns)


def format_report(analysis: BagAnalysis) -> str:
    """
    Return the readable report of one bag: header, one row per event, summary, truth.

    Times are seconds from the bag's first header stamp, with the stamp itself; spots cm from
    the tip along the bat; speeds mph; gaps cm.
    """
    selection = analysis.selection
    bat = (f'bat {selection.bat_pose} (pose)' if selection.bat_pose
           else f'bat {selection.knob} + {selection.tip} (knob/tip)')
    lines = [f'{analysis.path}: ball {selection.ball}, {bat}, model {analysis.config.model}']
    if selection.note:
        lines.append(f'note: {selection.note}')
    lines.append(_row([title for title, _ in TABLE_COLUMNS]))
    for number, event in enumerate(_events(analysis), 1):
        t = f'{analysis.relative_s(event.stamp_ns):.4f}'
        if isinstance(event, Impact):
            cells = [str(number), 'impact', t, str(event.stamp_ns),
                     _cm(event.distance_from_tip_m), event.feature.replace('_', ' '),
                     _mph(event.sweet_spot_speed_mps), _mph(event.ball_speed_mps),
                     f'{event.attack_angle_deg:.1f}', '-']
        else:
            cells = [str(number), 'near miss', t, str(event.stamp_ns),
                     _cm(event.distance_from_tip_m), '-', '-', '-', '-', _cm(event.gap_m)]
        lines.append(_row(cells))
    if not analysis.impacts and not analysis.near_misses:
        lines.append('  (no impacts and no near misses)')
    if analysis.config.prediction_horizon > 0.0:
        lines.extend(prediction_lines(analysis))
    lines.append(summary_line(analysis))
    wrong_frame = analysis.stats.dropped.get('wrong_frame', 0)
    if analysis.config.frame_id and wrong_frame and wrong_frame >= analysis.messages:
        lines.append(f"hint: every sample was dropped as wrong_frame: the parameters' frame_id "
                     f"'{analysis.config.frame_id}' is not the bag's frame")
    if analysis.truth is not None:
        lines.append(truth_line(analysis.truth))
    return '\n'.join(lines)


def prediction_lines(analysis: BagAnalysis) -> List[str]:
    """
    Return the report's prediction section: per impact, the error at each lead time.

    ``time/point`` is the predicted minus the true instant (ms) and the distance from the
    predicted to the true contact point (cm); ``-`` where the frame at that lead predicted no
    impact.
    """
    reference = 'the truth' if analysis.truth is not None else 'the detected impact'
    lines = [f'predictions: {len(analysis.predictions)} made (horizon '
             f'{analysis.config.prediction_horizon:.2f} s); error against {reference} at lead '
             + ', '.join(f'{lead * 1e3:g} ms' for lead in LEADS_S) + ' (time ms / point cm)']
    for number, (impact, scores) in enumerate(zip(analysis.impacts,
                                                  analysis.prediction_scores()), 1):
        cells = []
        for lead in LEADS_S:
            score = scores[lead]
            cells.append(f'{lead * 1e3:g} ms ' + ('-' if score is None else
                                                  f'{score[0] * 1e3:+.2f}/{score[1] * 1e2:.1f}'))
        lines.append(f'  impact {number} at {analysis.relative_s(impact.stamp_ns):.4f} s: '
                     + ', '.join(cells))
    return lines


def summary_line(analysis: BagAnalysis) -> str:
    """Return the one-line summary: events, drops by reason, gaps, messages, throughput."""
    dropped = analysis.stats.dropped
    drops = ', '.join(f'{reason} {count}' for reason, count in sorted(dropped.items())
                      if count)
    detector_s = analysis.stats.total_processing_s
    share = f', detector {100.0 * detector_s / analysis.seconds:.0f}%' \
        if analysis.seconds > 0.0 else ''
    return (f'summary: {len(analysis.impacts)} impacts, {len(analysis.near_misses)} near misses, '
            f'{sum(dropped.values())} dropped{f" ({drops})" if drops else ""}, '
            f'{len(analysis.gaps)} stream gaps, {len(analysis.resets)} resets; '
            f'{analysis.messages:,} messages in {analysis.seconds:.2f} s '
            f'({analysis.throughput:,.0f} msg/s{share})')


def truth_line(comparison: TruthComparison) -> str:
    """Return the one-line truth comparison (time error us, spot error mm, speed error %)."""
    parts = [f'truth ({comparison.path.name}): {len(comparison.matched)}/{comparison.contacts} '
             f'contacts found, {len(comparison.missed)} missed, '
             f'{len(comparison.false_impacts)} false impacts']
    if comparison.matched:
        times = [abs(e) * 1e-3 for e in comparison.time_errors_ns]
        spots = [abs(e) * 1e3 for e in comparison.spot_errors_m]
        speeds = [abs(e) * 100.0 for e in comparison.speed_errors]
        parts.append(f'time error max {max(times):.1f} us (mean {sum(times) / len(times):.1f})')
        parts.append(f'spot error max {max(spots):.1f} mm')
        parts.append(f'sweet-spot speed error max {max(speeds):.2f} %')
    if comparison.misses:
        parts.append(f'{comparison.near_misses_in_misses}/{comparison.misses} misses reported '
                     'as near misses')
    return '; '.join(parts)


def _plain(value: Any) -> Any:
    """Return value with tuples as lists and non-finite floats as None (strict JSON)."""
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _selection_dict(selection: TopicSelection) -> Dict[str, Any]:
    return {'ball': selection.ball, 'ball_type': selection.ball_type,
            'bat_pose': selection.bat_pose, 'knob': selection.knob, 'tip': selection.tip,
            'bat_input': selection.bat_mode, 'note': selection.note}


def to_json(analyses: Sequence[BagAnalysis]) -> Dict[str, Any]:
    """
    Return the ``--json`` document for one or several bags.

    Top level: ``format``; ``impacts`` and ``near_misses`` (every field of the detector's
    events, vectors as lists, plus ``bag`` and ``time_s``: seconds from that bag's first
    stamp); ``dropped`` (``{reason: count}`` summed over the bags); ``bags`` (one entry per bag:
    ``path``, ``topics``, ``model``, ``messages``, ``seconds``, ``first_stamp_ns``, counts,
    ``dropped``, ``gaps``, ``resets`` and ``truth``: the comparison or None). With
    ``--predict``: ``predictions`` (every ``Prediction``, plus ``bag`` and ``time_s``) and, in
    each impact, ``prediction_errors``: ``{lead ms: {time_error_s, point_error_m} or None}``.
    """
    impacts, near_misses, predictions, bags = [], [], [], []
    dropped: Dict[str, int] = {}
    for analysis in analyses:
        name = str(analysis.path)
        predicting = analysis.config.prediction_horizon > 0.0
        scores = analysis.prediction_scores() if predicting else [None] * len(analysis.impacts)
        for impact, score in zip(analysis.impacts, scores):
            entry = {'bag': name, 'time_s': analysis.relative_s(impact.stamp_ns),
                     **asdict(impact)}
            if score is not None:
                entry['prediction_errors'] = {
                    f'{lead * 1e3:g}': None if error is None else {
                        'time_error_s': error[0], 'point_error_m': error[1]}
                    for lead, error in score.items()}
            impacts.append(entry)
        for prediction in analysis.predictions:
            predictions.append({'bag': name, 'time_s': analysis.relative_s(prediction.stamp_ns),
                                **asdict(prediction)})
        for miss in analysis.near_misses:
            near_misses.append({'bag': name, 'time_s': analysis.relative_s(miss.stamp_ns),
                                **asdict(miss)})
        for reason, count in analysis.stats.dropped.items():
            dropped[reason] = dropped.get(reason, 0) + count
        bags.append({
            'path': name, 'topics': _selection_dict(analysis.selection),
            'model': analysis.config.model, 'messages': analysis.messages,
            'seconds': analysis.seconds, 'first_stamp_ns': analysis.first_stamp_ns,
            'impacts': len(analysis.impacts), 'near_misses': len(analysis.near_misses),
            'dropped': dict(analysis.stats.dropped),
            'gaps': [asdict(gap) for gap in analysis.gaps],
            'resets': [asdict(reset) for reset in analysis.resets],
            'truth': None if analysis.truth is None else analysis.truth.as_dict(),
        })
    document = {'format': JSON_FORMAT, 'impacts': impacts, 'near_misses': near_misses,
                'dropped': dropped, 'bags': bags}
    if any(analysis.config.prediction_horizon > 0.0 for analysis in analyses):
        document['predictions'] = predictions
    return _plain(document)


CSV_COLUMNS = (
    'bag', 'event', 'stamp_ns', 'time_s', 'x', 'y', 'z', 'normal_x', 'normal_y', 'normal_z',
    'distance_from_knob_m', 'distance_from_tip_m', 'feature', 'sweet_spot_speed_mps',
    'bat_speed_at_contact_mps', 'ball_speed_mps', 'attack_angle_deg', 'gap_m', 'gap_x', 'gap_y',
    'gap_z', 'made_at_ns', 'lead_s')
"""``--csv`` columns: one row per impact, near miss or prediction (empty cells where not
applicable). ``x, y, z``: the contact point for an impact, the ball centre at closest approach
for a miss, the predicted contact point for a prediction (whose ``stamp_ns`` is the predicted
instant, ``made_at_ns`` when it was made)."""


def csv_text(analyses: Sequence[BagAnalysis]) -> str:
    """Return the ``--csv`` file's text (see :data:`CSV_COLUMNS`)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator='\n')
    writer.writerow(CSV_COLUMNS)
    for analysis in analyses:
        for event in _events(analysis):
            row: Dict[str, Any] = {'bag': str(analysis.path), 'stamp_ns': event.stamp_ns,
                                   'time_s': f'{analysis.relative_s(event.stamp_ns):.9f}',
                                   'distance_from_tip_m': event.distance_from_tip_m}
            if isinstance(event, Impact):
                row.update(event='impact', feature=event.feature,
                           distance_from_knob_m=event.distance_from_knob_m,
                           sweet_spot_speed_mps=event.sweet_spot_speed_mps,
                           bat_speed_at_contact_mps=event.bat_speed_at_contact_mps,
                           ball_speed_mps=event.ball_speed_mps,
                           attack_angle_deg=event.attack_angle_deg)
                row.update(zip(('x', 'y', 'z'), event.point))
                row.update(zip(('normal_x', 'normal_y', 'normal_z'), event.normal))
            else:
                row.update(event='near_miss', gap_m=event.gap_m)
                row.update(zip(('x', 'y', 'z'), event.ball_position))
                row.update(zip(('gap_x', 'gap_y', 'gap_z'), event.gap_vector))
            writer.writerow([row.get(column, '') for column in CSV_COLUMNS])
        for prediction in analysis.predictions:
            row = {'bag': str(analysis.path), 'event': 'prediction',
                   'stamp_ns': prediction.stamp_ns,
                   'time_s': f'{analysis.relative_s(prediction.stamp_ns):.9f}',
                   'distance_from_tip_m': prediction.distance_from_tip_m,
                   'made_at_ns': prediction.made_at_ns, 'lead_s': prediction.lead_s}
            row.update(zip(('x', 'y', 'z'), prediction.point))
            row.update(zip(('normal_x', 'normal_y', 'normal_z'), prediction.normal))
            writer.writerow([row.get(column, '') for column in CSV_COLUMNS])
    return buffer.getvalue()


# ----------------------------------------------------------------------------------------------
# Plots


@dataclass
class _Window:
    """Samples of a bag near one impact (arrays filled after the read)."""

    impact: Impact
    start_ns: int
    end_ns: int
    ball: List[Tuple[int, Sequence[float]]] = field(default_factory=list)
    bat: List[Tuple[int, Sequence[float]]] = field(default_factory=list)
    knob: List[Tuple[int, Sequence[float]]] = field(default_factory=list)
    tip: List[Tuple[int, Sequence[float]]] = field(default_factory=list)


def _collect_windows(analysis: BagAnalysis, options: AnalysisOptions) -> List[_Window]:
    """
    Read the bag again and keep the samples within :data:`PLOT_WINDOW_S` of each impact.

    :raises ToolError: the bag cannot be read again.
    """
    half = int(PLOT_WINDOW_S * 1e9)
    windows = [_Window(impact, impact.stamp_ns - half, impact.stamp_ns + half)
               for impact in analysis.impacts]
    if not windows:
        return windows
    lists = {'ball': 'ball', 'bat_pose': 'bat', 'knob': 'knob', 'tip': 'tip'}
    try:
        with BagReader(analysis.path, analysis.selection) as bag:
            for role, stamp, _, values, _ in bag.samples():
                for window in windows:
                    if window.start_ns <= stamp <= window.end_ns:
                        getattr(window, lists[role]).append((stamp, values))
    except BagError as error:
        raise ToolError(str(error)) from error
    return windows


def _bat_ends(window: _Window,
              config: DetectorConfig) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return bat stamps (ns), knobs and tips (metres) of a window."""
    if window.bat:
        stamps = np.array([s for s, _ in window.bat], dtype=np.int64)
        ends = [config.geometry.knob_and_tip(v[:3], v[3:]) for _, v in window.bat]
        return stamps, np.array([k for k, _ in ends]), np.array([t for _, t in ends])
    knob_stamps = np.array([s for s, _ in window.knob], dtype=np.int64)
    knobs = np.array([v for _, v in window.knob], dtype=float).reshape(-1, 3)
    tip_stamps = np.array([s for s, _ in window.tip], dtype=np.int64)
    tips = np.array([v for _, v in window.tip], dtype=float).reshape(-1, 3)
    if len(tip_stamps) == 0 or len(knob_stamps) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3))
    return knob_stamps, knobs, _interp(knob_stamps, tip_stamps, tips)


def _interp(at: np.ndarray, stamps: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Interpolate (N, 3) values linearly in time at the stamps ``at`` (ns)."""
    x = (at - stamps[0]).astype(float)
    xp = (stamps - stamps[0]).astype(float)
    return np.stack([np.interp(x, xp, values[:, i]) for i in range(3)], axis=1)


def _plot_one(window: _Window, analysis: BagAnalysis, true_stamp: Optional[int],
              target: Path) -> None:
    """Draw one impact's figure to ``target`` (PNG)."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot

    config = analysis.config
    impact = window.impact
    origin = impact.stamp_ns
    ball_stamps = np.array([s for s, _ in window.ball], dtype=np.int64)
    balls = np.array([v for _, v in window.ball], dtype=float).reshape(-1, 3)
    bat_stamps, knobs, tips = _bat_ends(window, config)
    figure, (gap_axes, top_axes, side_axes) = pyplot.subplots(1, 3, figsize=(16, 5))
    figure.suptitle(f'{analysis.path.name}: impact at {analysis.relative_s(origin):.4f} s '
                    f'({origin} ns), {impact.distance_from_tip_m * 100:.1f} cm from the tip, '
                    f'sweet spot {impact.sweet_spot_speed_mps * MPS_TO_MPH:.1f} mph '
                    f'[{config.model}]')
    if len(ball_stamps) >= 2 and len(bat_stamps) >= 2:
        dense = np.linspace(max(ball_stamps[0], bat_stamps[0]),
                            min(ball_stamps[-1], bat_stamps[-1]), 400).astype(np.int64)
        gaps = _gaps(_interp(dense, ball_stamps, balls), _interp(dense, bat_stamps, knobs),
                     _interp(dense, bat_stamps, tips), config)
        gap_axes.plot((dense - origin) * 1e-6, gaps * 100.0, color='0.6',
                      label='linear between samples')
        inside = (ball_stamps >= bat_stamps[0]) & (ball_stamps <= bat_stamps[-1])
        at_samples = _gaps(balls[inside], _interp(ball_stamps[inside], bat_stamps, knobs),
                           _interp(ball_stamps[inside], bat_stamps, tips), config)
        gap_axes.plot((ball_stamps[inside] - origin) * 1e-6, at_samples * 100.0, 'o',
                      color='tab:blue', label='at ball samples')
        # zoom on the approach: contact is at 0, the far samples only squash the plot
        low = min(-3.0, float(np.min(gaps)) * 100.0 - 1.0)
        gap_axes.set_ylim(low, min(float(np.max(gaps)) * 100.0, 40.0) + 2.0)
    for stamp in bat_stamps:
        gap_axes.axvline((stamp - origin) * 1e-6, color='tab:orange', alpha=0.15, lw=0.8)
    gap_axes.axvline(0.0, color='tab:red', label=f'impact ({config.model})')
    if true_stamp is not None:
        gap_axes.axvline((true_stamp - origin) * 1e-6, color='black', ls='--', label='truth')
    gap_axes.axhline(0.0, color='black', lw=0.8)
    gap_axes.set_xlabel('time from impact (ms); orange lines: bat samples')
    gap_axes.set_ylabel('gap ball to bat (cm)')
    gap_axes.legend(loc='best', fontsize='small')
    for axes, (i, j), title in ((top_axes, (0, 1), 'top view'), (side_axes, (1, 2), 'side view')):
        for knob, tip in zip(knobs, tips):
            axes.plot([knob[i], tip[i]], [knob[j], tip[j]], color='tab:orange', alpha=0.5)
        if len(balls):
            axes.plot(balls[:, i], balls[:, j], 'o-', color='tab:blue', ms=3, label='ball')
        axes.plot([impact.point[i]], [impact.point[j]], '*', color='tab:red', ms=14,
                  label='contact point')
        axes.set_xlabel('xyz'[i] + ' (m)')
        axes.set_ylabel('xyz'[j] + ' (m)')
        axes.set_aspect('equal', adjustable='datalim')
        axes.set_title(f'{title}: bat samples (orange), ball samples (blue)')
        axes.legend(loc='best', fontsize='small')
    figure.tight_layout()
    figure.savefig(target, dpi=80)
    pyplot.close(figure)


def _gaps(balls: np.ndarray, knobs: np.ndarray, tips: np.ndarray,
          config: DetectorConfig) -> np.ndarray:
    """Return the ball-bat gap (m) per row."""
    return np.array([profile_gap(tuple(b), tuple(k), tuple(t), config.ball_radius,
                                 config.profile)[0] for b, k, t in zip(balls, knobs, tips)])


def plot_names(analyses: Sequence[BagAnalysis]) -> List[str]:
    """Return the PNG names ``--plot`` writes: ``<bag name>_impact_<n>.png`` per impact."""
    names = []
    for index, analysis in enumerate(analyses):
        stem = truth_path(analysis.path).name[:-len('.truth.json')]
        if sum(1 for a in analyses if a.path.name == analysis.path.name) > 1:
            stem = f'{index + 1}_{stem}'
        names.extend(f'{stem}_impact_{n}.png' for n in range(1, len(analysis.impacts) + 1))
    return names


def write_plots(analyses: Sequence[BagAnalysis], options: AnalysisOptions,
                directory: Path) -> List[Path]:
    """
    Draw one PNG per impact into ``directory`` (which must exist).

    Each figure: the gap versus time around the impact (ball samples as dots, bat sample
    times as lines, the impact instant and the true one when known), and a top and a side view
    of the bat and ball samples around it with the contact point.

    :returns: the files written.
    :raises ToolError: the bag cannot be read again.
    """
    written = []
    names = iter(plot_names(analyses))
    for analysis in analyses:
        truths = {id(impact): int(truth['stamp_ns'])
                  for truth, impact in (analysis.truth.matched if analysis.truth else [])}
        for window in _collect_windows(analysis, options):
            target = directory / next(names)
            _plot_one(window, analysis, truths.get(id(window.impact)), target)
            written.append(target)
    return written


# ----------------------------------------------------------------------------------------------
# Outputs, all or nothing


class Outputs:
    """
    Output paths checked up front and written all at once at the end.

    Every target must not exist and its directory must. Files are written to hidden temporaries
    beside their targets and linked into place only by :meth:`commit`; :meth:`abort` (or an
    exception in the ``with`` block) deletes every temporary.

    :raises ToolError: from the constructor: a target exists, or its directory does not.
    """

    def __init__(self, **targets: Optional[os.PathLike]) -> None:
        self.targets = {name: Path(path) for name, path in targets.items() if path is not None}
        for name, path in self.targets.items():
            if path.exists() or path.is_symlink():
                raise ToolError(f'output {path} exists already; not overwriting')
            if not path.parent.is_dir():
                raise ToolError(f'output directory {path.parent} does not exist')
        self._staged: List[Tuple[Path, Path]] = []
        self._writers: List[BagWriter] = []

    def __enter__(self) -> 'Outputs':
        """Return self."""
        return self

    def __exit__(self, exc_type: Any, exc_value: Any, traceback: Any) -> None:
        """Delete every temporary if the block raised."""
        if exc_type is not None:
            self.abort()

    def bag_writer(self, name: str, storage: Optional[str] = None) -> BagWriter:
        """
        Open a bag writer for a target (placed by :meth:`commit`, removed by :meth:`abort`).

        :raises ToolError: the bag cannot be created.
        """
        writer = BagWriter(self.targets[name], storage)
        try:
            writer.open()
        except BagError as error:
            raise ToolError(str(error)) from error
        self._writers.append(writer)
        return writer

    def stage_text(self, name: str, text: str) -> None:
        """
        Write a target's text into its temporary.

        :raises ToolError: the temporary cannot be written.
        """
        target = self.targets[name]
        try:
            handle, temporary = tempfile.mkstemp(prefix=f'.{target.name}.', suffix='.partial',
                                                 dir=target.parent)
            self._staged.append((Path(temporary), target))
            with os.fdopen(handle, 'w') as stream:
                stream.write(text)
            os.chmod(temporary, 0o666 & ~_umask())
        except OSError as error:
            raise ToolError(f'cannot write {target}: {error.strerror}') from error

    def stage_directory(self, name: str, fill: Callable[[Path], Any]) -> None:
        """
        Create a target directory's temporary and let ``fill`` write into it.

        :raises ToolError: the temporary cannot be created (or what ``fill`` raises).
        """
        target = self.targets[name]
        try:
            temporary = Path(tempfile.mkdtemp(prefix=f'.{target.name}.', suffix='.partial',
                                              dir=target.parent))
            os.chmod(temporary, 0o777 & ~_umask())
        except OSError as error:
            raise ToolError(f'cannot create {target}: {error.strerror}') from error
        self._staged.append((temporary, target))
        fill(temporary)

    def commit(self) -> None:
        """
        Move every output into place (bags first, then files and directories).

        :raises ToolError: a target appeared meanwhile or cannot be written.
        """
        try:
            for writer in self._writers:
                writer.close()
        except BagError as error:
            self.abort()
            raise ToolError(str(error)) from error
        self._writers = []
        staged, self._staged = self._staged, []
        try:
            for temporary, target in staged:
                if target.exists() or target.is_symlink():
                    raise ToolError(f'output {target} exists already; not overwriting')
                if temporary.is_dir():
                    os.rename(temporary, target)
                else:
                    os.link(temporary, target)
                    os.unlink(temporary)
        except OSError as error:
            raise ToolError(f'cannot write {target}: {error.strerror}') from error
        finally:
            for temporary, _ in staged:
                _remove(temporary)

    def abort(self) -> None:
        """Delete every temporary and abandon open bag writers (idempotent)."""
        for writer in self._writers:
            writer.abort()
        self._writers = []
        for temporary, _ in self._staged:
            _remove(temporary)
        self._staged = []


def _umask() -> int:
    """Return the process's file creation mask."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _remove(path: Path) -> None:
    """Delete a temporary file or directory if it is still there."""
    if path.is_dir():
        shutil.rmtree(path, ignore_errors=True)
    elif path.exists():
        path.unlink()


def write_json(document: Mapping[str, Any], stream: IO[str]) -> None:
    """Write a JSON document (2-space indent, strict: no NaN)."""
    json.dump(document, stream, indent=2, allow_nan=False)
    stream.write('\n')
