"""
What ``analyze`` says about its bags: the printed table and summary lines, JSON and CSV.

Pure formatting of :class:`~baseball_collision.tools.analyze.BagAnalysis` results (no I/O but
:func:`write_json`'s stream). Events become records in one place,
:func:`baseball_collision.core.records.event_record` (the node's ``~/impact_report`` says the
same): a JSON entry is the record with the bag and the time, a CSV row is the record flattened
(:func:`csv_row`), a table row is drawn from the same record. Units are SI everywhere but in the
printed table (cm, mph, ms, us). The schemas are ``schema/analyze.schema.json`` (the JSON) and
``schema/analyze.csv.json`` (the CSV's columns).
"""

from collections import Counter
import csv
from dataclasses import asdict
from datetime import datetime, timedelta, timezone
import io
import json
import textwrap
from typing import Any, Dict, IO, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from .analyze import BagAnalysis
from .rates import rate_lines
from .truth import bag_stem, LEADS_S, TruthComparison
from ..bags import TopicSelection
from ..core.detector import DetectorConfig, MPS_TO_MPH
from ..core.records import event_record, plain, ZONES

JSON_FORMAT = 'baseball_collision.analyze/2'
"""``format`` value of an ``analyze --json`` file (2: records with ``format``, ``frame_id``,
``zone``; end-cap distances of the contact point itself)."""

TABLE_COLUMNS = (
    ('#', 3), ('event', 9), ('t (s)', 9), ('stamp (ns)', 19), ('+- (us)', 7),
    ('from tip (cm)', 13), ('+- (mm)', 7), ('where', 10), ('sweet spot (mph)', 16),
    ('+- (mph)', 8), ('ball (mph)', 10), ('attack (deg)', 12), ('gap (cm)', 8))
"""Printed table: (title, width) per column."""

NARROW_COLUMNS = (
    ('#', '', 3), ('event', '', 9), ('t', '(s)', 8), ('+-', '(us)', 6), ('from tip', '(cm)', 8),
    ('+-', '(mm)', 5), ('where', '', 10), ('sweet spot', '(mph)', 10), ('+-', '(mph)', 5),
    ('ball', '(mph)', 5), ('attack', '(deg)', 6), ('gap', '(cm)', 5))
"""The table in a terminal narrower than :data:`TABLE_COLUMNS` (99 columns): (title, unit,
width) per column, the titles over their units, ``t (s)`` to the ms and no ``stamp (ns)``; a
``+-`` column one space from its value's."""

TABLE_WIDTH = sum(width for _, width in TABLE_COLUMNS) + 2 * (len(TABLE_COLUMNS) - 1)
"""The full table's width in characters (155)."""

CSV_VECTORS = (('point', 'contact'), ('normal', 'normal'), ('ball_position', 'ball'),
               ('gap_vector', 'gap'))
"""Record vectors spread over three CSV columns each: (record key, column prefix)."""

CSV_COLUMNS = (
    'bag', 'event', 'frame_id', 'stamp_ns', 'time_s', 'made_at_ns', 'lead_s', 'zone', 'feature',
    'distance_from_knob_m', 'distance_from_tip_m', 'contact_x', 'contact_y', 'contact_z',
    'normal_x', 'normal_y', 'normal_z', 'ball_x', 'ball_y', 'ball_z', 'sweet_spot_speed_mps',
    'bat_speed_at_contact_mps', 'ball_speed_mps', 'attack_angle_deg', 'gap_m', 'gap_x',
    'gap_y', 'gap_z', 'time_uncertainty_s', 'distance_from_knob_uncertainty_m',
    'sweet_spot_speed_uncertainty_mps', 'number', 'stamp_utc', 'distance_from_tip_uncertainty_m')
"""``--csv`` columns: one row per impact, near miss or prediction (empty cells where not
applicable; ``schema/analyze.csv.json`` describes each). ``contact_*``: the contact point (an
impact) or the predicted one (a prediction); ``ball_*``: the ball centre at the impact, at the
closest approach (a near miss) or at the predicted contact; a prediction's ``stamp_ns`` is the
predicted instant, ``made_at_ns`` when it was made, its ``time_uncertainty_s`` and
``distance_from_tip_uncertainty_m`` its 1-sigma error bars (with a bat plan); ``number`` the
event's ``#`` in the table (:func:`event_numbers`); ``stamp_utc`` ``stamp_ns`` as a date and
time (:func:`utc_text`). Columns are only ever added at the end."""


def _cm(metres: float) -> str:
    return f'{metres * 100.0:.1f}'


def _mph(mps: float) -> str:
    return f'{mps * MPS_TO_MPH:.1f}'


def _events(analysis: BagAnalysis) -> List[Any]:
    """Return impacts and near misses in time order."""
    return sorted(analysis.impacts + analysis.near_misses, key=lambda e: e.stamp_ns)


ENTRY_KEYS = ('bag', 'number', 'time_s', 'stamp_utc')
"""The keys an ``analyze`` entry adds to the node's record (:func:`entry`; ``number`` not in a
prediction's): the rest of an entry is what ``~/impact_report`` says."""

EPOCH = datetime(1970, 1, 1, tzinfo=timezone.utc)


def utc_text(stamp_ns: int) -> str:
    """
    Return a stamp (ns since the Unix epoch) as ISO 8601 UTC, to the ns.

    ``1700000000250117442`` is ``2023-11-14T22:13:20.250117442Z``: what a person reads beside
    ``stamp_ns``. A bag stamped on another clock (simulated time from 0) reads as 1970.
    """
    seconds, nanoseconds = divmod(stamp_ns, 1_000_000_000)
    return f'{EPOCH + timedelta(seconds=seconds):%Y-%m-%dT%H:%M:%S}.{nanoseconds:09d}Z'


def event_numbers(analysis: BagAnalysis) -> Dict[int, int]:
    """
    Return each impact's and near miss's number, by ``id(event)``: the table's ``#``.

    Each kind is numbered on its own, 1 up, in the bag's order: impact 5 is the fifth impact
    of its bag in the table, the JSON and CSV (``number``), the plots
    (``<bag>_impact_5.png``) and ``--predict``'s lines.
    """
    return {id(event): number for events in (analysis.impacts, analysis.near_misses)
            for number, event in enumerate(events, 1)}


def entry(analysis: BagAnalysis, event: Any, number: Optional[int] = None) -> Dict[str, Any]:
    """
    Return an event's JSON entry: its record with ``bag``, ``time_s`` and ``stamp_utc``.

    ``time_s``: s from the bag's first stamp; ``stamp_utc``: :func:`utc_text`.

    :param number: the event's number in its bag (:func:`event_numbers`): the entry's
        ``number``; None: no such key (a prediction).
    :raises KeyError: an event with no record (see ``core.records.event_record``).
    """
    numbered = {} if number is None else {'number': number}
    return {'bag': str(analysis.path), **numbered, 'time_s': analysis.relative_s(event.stamp_ns),
            'stamp_utc': utc_text(event.stamp_ns),
            **event_record(event, analysis.frame_id, analysis.config)}


def csv_row(record: Mapping[str, Any]) -> Dict[str, Any]:
    """Return a record (or entry) as CSV cells by column: vectors spread, others by name."""
    row = {column: record[column] for column in CSV_COLUMNS if column in record}
    for key, prefix in CSV_VECTORS:
        if record.get(key) is not None:
            row.update(zip((f'{prefix}_x', f'{prefix}_y', f'{prefix}_z'), record[key]))
    return row


# ----------------------------------------------------------------------------------------------
# The printed report


def _row(cells: Sequence[str]) -> str:
    parts = []
    for (title, width), cell in zip(TABLE_COLUMNS, cells):
        parts.append(cell.ljust(width) if title in ('event', 'where') else cell.rjust(width))
    return '  '.join(parts).rstrip()


def _narrow_row(cells: Sequence[str]) -> str:
    parts = []
    for index, ((title, _, width), cell) in enumerate(zip(NARROW_COLUMNS, cells)):
        gap = '' if index == 0 else ' ' if title == '+-' else '  '
        parts.append(gap + (cell.ljust(width) if title in ('event', 'where') else
                            cell.rjust(width)))
    return ''.join(parts).rstrip()


def _narrow_cells(cells: Sequence[str], record: Mapping[str, Any]) -> List[str]:
    """Return a narrow table row's cells from the full table's: no stamp, ``t`` to the ms."""
    return [cells[0], cells[1], f"{record['time_s']:.3f}", *cells[4:]]


def fitted(lines: Sequence[str], width: Optional[int]) -> List[str]:
    """
    Return lines wrapped at spaces to ``width`` columns, a continuation indented two spaces.

    :param width: the terminal's columns; None: the lines as they are (a pipe or a file).
    """
    if width is None:
        return list(lines)
    return [wrapped for line in lines for wrapped in (
        textwrap.wrap(line, width, subsequent_indent='  ', break_long_words=False,
                      break_on_hyphens=False) or [line])]


def _cells(number: int, record: Mapping[str, Any]) -> List[str]:
    """Return a table row's cells from an event record (``-`` where the event has no value)."""
    def shown(name: str, format_value: Any) -> str:
        value = record.get(name)
        return '-' if value is None else format_value(value)

    return [str(number), record['event'].replace('_', ' '), f"{record['time_s']:.4f}",
            str(record['stamp_ns']), shown('time_uncertainty_s', lambda s: f'{s * 1e6:.1f}'),
            _cm(record['distance_from_tip_m']),
            shown('distance_from_knob_uncertainty_m', lambda metres: f'{metres * 1e3:.1f}'),
            record['zone'].replace('_', ' '),
            shown('sweet_spot_speed_mps', _mph), shown('sweet_spot_speed_uncertainty_mps', _mph),
            shown('ball_speed_mps', _mph),
            shown('attack_angle_deg', lambda degrees: f'{degrees:.1f}'),
            shown('gap_m', _cm)]


def format_report(analysis: BagAnalysis, width: Optional[int] = None) -> str:
    """
    Return the readable report of one bag: header, one row per event, summary, truth.

    Times are seconds from the bag's first header stamp, with the stamp itself; spots cm from
    the tip along the bat; speeds mph; gaps cm.

    :param width: the terminal's columns: under :data:`TABLE_WIDTH`, the narrow table
        (:data:`NARROW_COLUMNS`: no ``stamp (ns)``, which the JSON and CSV keep) and every
        other line wrapped to it (:func:`fitted`); None: the full table (a pipe or a file).
    """
    narrow = width is not None and width < TABLE_WIDTH
    selection = analysis.selection
    bat = (f'bat {selection.bat_pose} (pose)' if selection.bat_pose
           else f'bat {selection.knob} + {selection.tip} (knob/tip)')
    head = [f'{analysis.path}: ball {selection.ball}, {bat}, {model_text(analysis.config)}']
    if selection.note:
        head.append(f'note: {selection.note}')
    lines = fitted(head, width)
    if narrow:
        lines += [_narrow_row([title for title, _, _ in NARROW_COLUMNS]),
                  _narrow_row([unit for _, unit, _ in NARROW_COLUMNS])]
    else:
        lines.append(_row([title for title, _ in TABLE_COLUMNS]))
    numbers = event_numbers(analysis)  # each kind its own: 'impact 5' is the fifth everywhere
    for event in _events(analysis):
        record = entry(analysis, event)
        cells = _cells(numbers[id(event)], record)
        lines.append(_narrow_row(_narrow_cells(cells, record)) if narrow else _row(cells))
    if not analysis.impacts and not analysis.near_misses:
        lines.append('  (no impacts and no near misses)')
    elif narrow:
        lines.append(f'  (each stamp in ns: --json or --csv, or a terminal {TABLE_WIDTH} wide)')
    lines += fitted(_report_tail(analysis), width)
    return '\n'.join(lines)


def _report_tail(analysis: BagAnalysis) -> List[str]:
    """Return the report's lines after the table: predictions, summary, truth, notes."""
    lines: List[str] = []
    if analysis.config.prediction_horizon > 0.0:
        lines.extend(prediction_lines(analysis))
    lines.append(summary_line(analysis))
    lines.extend(f'warning: {line}' for line in analysis.silenced_topics())
    if analysis.truth is not None:
        lines.append(truth_line(analysis.truth))
    lines.extend(rate_lines(analysis.rates))
    lines.extend(f'note: {note}' for note in analysis.notes)
    return lines


NO_PREDICTION = ("'-': no prediction in force that far ahead (the ball or bat not yet "
                 'tracked, or the contact beyond the horizon)')
"""What a ``-`` lead cell means (the report's prediction header and ``--help`` say it)."""


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
             + ', '.join(f'{lead * 1e3:g} ms' for lead in LEADS_S) + ' (time ms / point cm; '
             + NO_PREDICTION + ')']
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


def model_text(config: DetectorConfig) -> str:
    """
    Return the motion model with what sets its latency: ``model c2 (look-ahead 2)``.

    The node's default and ``analyze``'s differ in the look-ahead alone (0 and 2), which moves
    the stamps a little: the header says which ran.
    """
    if config.model == 'c2':
        return f'model c2 (look-ahead {config.look_ahead})'
    return f'model {config.model}'


def noise_text(noise: Tuple[float, float], auto: bool) -> str:
    """
    Return what tracking noise the fits took: ``tracker noise (auto): ball 0.95 mm, bat exact``.

    :param noise: the ball's and the bat's (m, 1 sigma per coordinate; 0: exact samples).
    :param auto: estimated from the samples (``tracker_noise`` auto), else told.
    """
    ball, bat = (f'{value * 1e3:.2f} mm' if value > 0.0 else 'exact' for value in noise)
    return f"tracker noise ({'auto' if auto else 'told'}): ball {ball}, bat {bat}"


def summary_line(analysis: BagAnalysis) -> str:
    """Return the one-line summary: events, drops, gaps, the noise, messages, throughput."""
    dropped = analysis.stats.dropped
    drops = ', '.join(f'{reason} {count}' for reason, count in sorted(dropped.items())
                      if count)
    detector_s = analysis.stats.total_processing_s
    share = f', detector {100.0 * detector_s / analysis.seconds:.0f}%' \
        if analysis.seconds > 0.0 else ''
    return (f'summary: {_count(len(analysis.impacts), "impact")}, '
            f'{_count(len(analysis.near_misses), "near miss", "near misses")}, '
            f'{sum(dropped.values())} dropped{f" ({drops})" if drops else ""}, '
            f'{_count(len(analysis.gaps), "pause")} in tracking (gaps over max_gap), '
            f'{_count(len(analysis.resets), "reset")}; '
            f'{noise_text(analysis.noise, analysis.config.tracker_noise < 0.0)}; '
            f'{analysis.messages:,} input messages in {analysis.seconds:.2f} s '
            f'({analysis.throughput:,.0f} msg/s{share})')


def _count(n: int, noun: str, plural: str = '') -> str:
    """Return ``n noun``, the plural (``noun`` + s unless given) where ``n`` is not 1."""
    return f'{n} {noun}' if n == 1 else f'{n} {plural or noun + "s"}'


def total_line(analyses: Sequence[BagAnalysis], wall_s: Optional[float] = None) -> str:
    """
    Return the one-line total over several bags: events, messages, throughput.

    :param wall_s: the wall time of the whole run (s), when the bags ran at once (``--jobs``):
        the throughput is then over it; else over the sum of the bags' times.
    """
    messages = sum(a.messages for a in analyses)
    seconds = sum(a.seconds for a in analyses)
    elapsed = seconds if wall_s is None else wall_s
    rate = messages / elapsed if elapsed > 0 else 0.0
    timing = f'{seconds:.2f} s' if wall_s is None else (
        f'{wall_s:.2f} s of wall time ({seconds:.2f} s summed over the bags)')
    return (f'total: {len(analyses)} bags, {sum(len(a.impacts) for a in analyses)} impacts, '
            f'{sum(len(a.near_misses) for a in analyses)} near misses; {messages:,} messages in '
            f'{timing} ({rate:,.0f} msg/s)')


def season_lines(analyses: Sequence[BagAnalysis]) -> List[str]:
    """
    Return the season summary of the impacts of all the bags: where on the bat, how fast.

    ``impacts by zone: end cap 4, sweet spot 2, barrel 7, handle 4 (sweet spot 2/17, 12 %)``:
    each zone's count, tip end first, and the share in the sweet-spot zone; ``sweet-spot
    speed: median 70.6 mph, p90 76.7 mph, 64.1 to 80.8 mph over 17 impacts``: the median, 90th
    percentile (numpy's linear interpolation), least and greatest over the impacts that have
    one (a speed that is not finite is left out, and the count says so).
    """
    records = [entry(analysis, impact) for analysis in analyses for impact in analysis.impacts]
    if not records:
        return ['impacts by zone: none']
    zones = Counter(record['zone'] for record in records)
    counts = ', '.join(f"{zone.replace('_', ' ')} {zones[zone]}" for zone in reversed(ZONES)
                       if zones[zone])
    sweet = zones['sweet_spot']
    lines = [f'impacts by zone: {counts} (sweet spot {sweet}/{len(records)}, '
             f'{100.0 * sweet / len(records):.0f} %)']
    speeds = np.array([record['sweet_spot_speed_mps'] for record in records
                       if record['sweet_spot_speed_mps'] is not None]) * MPS_TO_MPH
    if speeds.size:
        median, p90 = np.percentile(speeds, (50.0, 90.0))
        lines.append(f'sweet-spot speed: median {median:.1f} mph, p90 {p90:.1f} mph, '
                     f'{speeds.min():.1f} to {speeds.max():.1f} mph over '
                     f'{_count(speeds.size, "impact")}')
    return lines


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


# ----------------------------------------------------------------------------------------------
# JSON and CSV


def plot_files(analyses: Sequence[BagAnalysis]) -> List[List[str]]:
    """
    Return the PNG names ``--plot`` writes for each bag: one list per bag, in order.

    ``<stem>_impact_<n>.png`` per impact, then ``<stem>_summary.png``. A bag's stem is its name
    without a ``.mcap``, ``.db3`` or ``.bag`` suffix (a bag directory: its name; ``.``: the
    directory's own: :func:`~.truth.bag_stem`). Bags whose stems are the same (compared
    without case: ``session.mcap``, ``session.bag`` and ``session/`` beside them; one name in
    two folders) get their position in the run as a prefix: ``2_session``; were a name still
    taken twice (a bag named ``2_session`` too), every stem gets its position. The names are
    therefore unique (a stem ends before ``_impact_<n>`` or ``_summary``, which the stem of
    another bag cannot take apart).
    """
    stems = [bag_stem(analysis.path) for analysis in analyses]
    counts = Counter(stem.casefold() for stem in stems)
    named = [f'{index}_{stem}' if counts[stem.casefold()] > 1 else stem
             for index, stem in enumerate(stems, 1)]
    if len({name.casefold() for name in named}) < len(named):
        named = [f'{index}_{stem}' for index, stem in enumerate(stems, 1)]
    return [[f'{stem}_impact_{n}.png' for n in range(1, len(analysis.impacts) + 1)]
            + [f'{stem}_summary.png'] for stem, analysis in zip(named, analyses)]


def _selection_dict(selection: TopicSelection) -> Dict[str, Any]:
    return {'ball': selection.ball, 'ball_type': selection.ball_type,
            'bat_pose': selection.bat_pose, 'knob': selection.knob, 'tip': selection.tip,
            'bat_input': selection.bat_mode, 'note': selection.note}


def _bag_entry(analysis: BagAnalysis) -> Dict[str, Any]:
    """Return one bag's ``bags`` entry of the JSON document."""
    return {
        'path': str(analysis.path), 'topics': _selection_dict(analysis.selection),
        'model': analysis.config.model, 'frame_id': analysis.frame_id,
        'messages': analysis.messages,
        'seconds': analysis.seconds, 'first_stamp_ns': analysis.first_stamp_ns,
        'first_stamp_utc': None if analysis.first_stamp_ns is None else utc_text(
            analysis.first_stamp_ns),
        'impacts': len(analysis.impacts), 'near_misses': len(analysis.near_misses),
        'dropped': dict(analysis.stats.dropped),
        'gaps': [asdict(gap) for gap in analysis.gaps],
        'resets': [asdict(reset) for reset in analysis.resets],
        'truth': None if analysis.truth is None else analysis.truth.as_dict(),
        'notes': list(analysis.notes),
        'tracker_noise': {'auto': analysis.config.tracker_noise < 0.0,
                          'ball_m': analysis.noise[0], 'bat_m': analysis.noise[1]},
        **({'rates': [check.summary() for check in analysis.rates]} if analysis.rates else {}),
    }


def to_json(analyses: Sequence[BagAnalysis], *, plots: bool = False,
            skipped: Optional[Sequence[Tuple[Any, str]]] = None) -> Dict[str, Any]:
    """
    Return the ``--json`` document for one or several bags.

    Top level: ``format``; ``impacts`` and ``near_misses`` (the events' records,
    ``core.records.event_record``, plus ``bag``, ``number``: :func:`event_numbers`, and
    ``time_s``: seconds from that bag's first stamp, ``stamp_utc``: :func:`entry`); ``dropped``
    (``{reason: count}`` summed over the bags); ``bags`` (one entry per bag: ``path``,
    ``topics``, ``model``, ``frame_id``, ``messages``, ``seconds``, ``first_stamp_ns`` and
    ``first_stamp_utc``, counts, ``dropped``, ``gaps``, ``resets``, ``truth``: the comparison
    or None, ``notes``, and ``tracker_noise``: ``auto``, ``ball_m`` and ``bat_m``, the noise at
    the bag's end; with ``--decimate``, ``rates``: ``rates.RateCheck.summary`` per factor).
    With ``--predict``: ``predictions`` (every prediction's entry) and, in each impact,
    ``prediction_errors``: ``{lead ms: {time_error_s, point_error_m} or None}``.
    The schema is ``schema/analyze.schema.json``.

    :param plots: ``--plot`` was given: each bag entry lists its PNG files (``plots``,
        :func:`plot_files`).
    :param skipped: ``--keep-going``'s bags that could not be analysed, ``(path, why)``: the
        document's ``skipped`` (``[{path, why}]``; None: no such key).
    """
    impacts, near_misses, predictions, bags = [], [], [], []
    dropped: Dict[str, int] = {}

    files = plot_files(analyses) if plots else [None] * len(analyses)
    for analysis, pngs in zip(analyses, files):
        predicting = analysis.config.prediction_horizon > 0.0
        scores = analysis.prediction_scores() if predicting else [None] * len(analysis.impacts)
        numbers = event_numbers(analysis)
        for impact, score in zip(analysis.impacts, scores):
            impacts.append(entry(analysis, impact, numbers[id(impact)]))
            if score is not None:
                impacts[-1]['prediction_errors'] = plain({
                    f'{lead * 1e3:g}': None if error is None else {
                        'time_error_s': error[0], 'point_error_m': error[1]}
                    for lead, error in score.items()})
        predictions.extend(entry(analysis, p) for p in analysis.predictions)
        near_misses.extend(entry(analysis, miss, numbers[id(miss)])
                           for miss in analysis.near_misses)
        for reason, count in analysis.stats.dropped.items():
            dropped[reason] = dropped.get(reason, 0) + count
        bags.append(plain(_bag_entry(analysis)))
        if pngs is not None:
            bags[-1]['plots'] = pngs
    document: Dict[str, Any] = {'format': JSON_FORMAT, 'impacts': impacts,
                                'near_misses': near_misses, 'dropped': dropped, 'bags': bags}
    if any(analysis.config.prediction_horizon > 0.0 for analysis in analyses):
        document['predictions'] = predictions
    if skipped is not None:
        document['skipped'] = [{'path': str(path), 'why': why} for path, why in skipped]
    return document  # the records are plain already, the rest made plain above


def write_json(document: Mapping[str, Any], stream: IO[str]) -> None:
    """Write a JSON document (2-space indent, strict: no NaN)."""
    json.dump(document, stream, indent=2, allow_nan=False)
    stream.write('\n')


def json_text(analyses: Sequence[BagAnalysis], **options: Any) -> str:
    """Return the ``--json`` file's text (:func:`to_json` with ``options``, :func:`write_json`)."""
    buffer = io.StringIO()
    write_json(to_json(analyses, **options), buffer)
    return buffer.getvalue()


def csv_text(analyses: Sequence[BagAnalysis]) -> str:
    """Return the ``--csv`` file's text (see :data:`CSV_COLUMNS`)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator='\n')
    writer.writerow(CSV_COLUMNS)
    for analysis in analyses:
        numbers = event_numbers(analysis)
        for event in _events(analysis) + analysis.predictions:
            row = csv_row(entry(analysis, event, numbers.get(id(event))))
            row['time_s'] = f"{row['time_s']:.9f}"
            writer.writerow(['' if row.get(column) is None else row[column]
                             for column in CSV_COLUMNS])
    return buffer.getvalue()
