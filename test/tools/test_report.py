"""The report: the printed table, summary lines, JSON and CSV from one record per event."""

import csv
import datetime
import io
import json
from pathlib import Path
import statistics
import sys
from typing import Callable, List, Tuple

from baseball_collision.core.detector import DetectorConfig, MPS_TO_MPH
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag, BagAnalysis
from baseball_collision.tools.plots import plot_names
from baseball_collision.tools.report import (
    CSV_COLUMNS, csv_row, csv_text, entry, format_report, json_text, season_lines, TABLE_COLUMNS,
    TABLE_WIDTH, to_json, total_line)
import pytest
from support.bundled import bag_path
from support.schema import load_schema, Validator

RunCli = Callable[[List[str]], Tuple[int, str, str]]

IMPACT_KEYS = {'format', 'frame_id', 'zone', 'stamp_ns', 'point', 'normal',
               'distance_from_knob_m', 'distance_from_tip_m',
               'sweet_spot_speed_mps', 'bat_speed_at_contact_mps', 'ball_speed_mps',
               'attack_angle_deg', 'bag', 'time_s', 'feature', 'bat_fraction'}

MISS_KEYS = {'stamp_ns', 'gap_m', 'gap_vector', 'bag', 'time_s', 'distance_from_tip_m'}


def test_json_schema(tmp_path: Path, run_cli: RunCli) -> None:
    """The documented keys are there, with the documented types and units."""
    out = tmp_path / 'a.json'
    code, stdout, _ = run_cli(['analyze', str(bag_path('pitches_360hz.mcap')), '--json', str(out),
                               '--quiet'])
    assert code == 0 and stdout == ''
    document = json.loads(out.read_text())
    assert set(document) >= {'format', 'impacts', 'near_misses', 'dropped', 'bags'}
    assert document['format'] == 'baseball_collision.analyze/2'
    assert Validator('analyze.schema.json').errors(document) == []
    for impact in document['impacts']:
        assert set(impact) >= IMPACT_KEYS
        assert isinstance(impact['stamp_ns'], int)
        assert len(impact['point']) == 3 and len(impact['normal']) == 3
        assert sum(n * n for n in impact['normal']) == pytest.approx(1.0)
        assert 26.0 < impact['sweet_spot_speed_mps'] < 37.0  # 60-80 mph swings
        # knob to tip (34 in); the spline interpolant keeps the length to within a millimetre
        assert impact['distance_from_knob_m'] + impact['distance_from_tip_m'] == \
            pytest.approx(0.8636, abs=1e-3)
    for miss in document['near_misses']:
        assert set(miss) >= MISS_KEYS
        assert miss['gap_m'] == pytest.approx(sum(g * g for g in miss['gap_vector']) ** 0.5)
        assert 0.0 < miss['gap_m'] < 0.15
    bag = document['bags'][0]
    assert bag['frame_id'] == 'world' and bag['notes'] == []
    assert set(bag) >= {'path', 'topics', 'model', 'messages', 'seconds', 'first_stamp_ns',
                        'impacts', 'near_misses', 'dropped', 'gaps', 'resets', 'truth'}
    assert bag['topics']['bat_pose'] == '/bat_pose' and bag['topics']['bat_input'] == 'pose'
    assert '/bat_knob' in bag['topics']['note']
    assert bag['messages'] == 3480 and bag['model'] == 'c2'  # the offline default


def test_c2_json_follows_the_schema(tmp_path: Path, run_cli: RunCli) -> None:
    """``--model c2``'s document is valid too (the schema once knew three models)."""
    out = tmp_path / 'c2.json'
    code, _, _ = run_cli(['analyze', str(bag_path('pitches_360hz.mcap')), '--model', 'c2',
                          '--json', str(out), '--quiet'])
    document = json.loads(out.read_text())
    assert code == 0 and document['bags'][0]['model'] == 'c2' and document['impacts']
    assert Validator('analyze.schema.json').errors(document) == []


def test_the_bags_tracker_noise_is_reported(tmp_path: Path, run_cli: RunCli) -> None:
    """
    Each bag says the noise its fits took: estimated (auto) or told, the ball's and the bat's.

    The 240 Hz bag has 0.3 mm of noise on every body: a pose reads about that (its samples
    shaken as one body), exact ones read exact; told, both are the told value.
    """
    def analysed(name: str, *flags: str) -> Tuple[dict, str]:
        out = tmp_path / f'{len(list(tmp_path.iterdir()))}.json'
        code, stdout, stderr = run_cli(['analyze', str(bag_path(name)), *flags, '--json',
                                        str(out)])
        assert code == 0, stderr
        document = json.loads(out.read_text())
        assert Validator('analyze.schema.json').errors(document) == []
        return document['bags'][0]['tracker_noise'], stdout

    noisy, stdout = analysed('pitches_240hz_noisy.bag')
    assert noisy['auto'] and noisy['ball_m'] == pytest.approx(3e-4, rel=0.15)
    assert noisy['bat_m'] == pytest.approx(3e-4, rel=0.15)
    shown = f"tracker noise (auto): ball {noisy['ball_m'] * 1e3:.2f} mm, bat "
    assert shown + f"{noisy['bat_m'] * 1e3:.2f} mm; " in stdout
    exact, stdout = analysed('pitches_90hz.mcap')
    assert exact == {'auto': True, 'ball_m': 0.0, 'bat_m': 0.0}
    assert 'tracker noise (auto): ball exact, bat exact; ' in stdout
    params = tmp_path / 'told.yaml'
    params.write_text('impact_node:\n  ros__parameters:\n    tracker_noise: 0.0005\n')
    told, stdout = analysed('pitches_90hz.mcap', '--params', str(params))
    assert told == {'auto': False, 'ball_m': 0.0005, 'bat_m': 0.0005}
    assert 'tracker noise (told): ball 0.50 mm, bat 0.50 mm; ' in stdout


def test_table_and_csv_rows_come_from_one_record_per_event() -> None:
    """Each CSV row is its event's record; each table row shows the record's values."""
    analysis = analyze_bag(bag_path('pitches_90hz.mcap'), progress=False)
    rows = list(csv.DictReader(io.StringIO(csv_text([analysis]))))
    events = sorted(analysis.impacts + analysis.near_misses, key=lambda e: e.stamp_ns)
    table = [line.split() for line in format_report(analysis).splitlines()
             if line.split()[1:2] in (['impact'], ['near'])]
    assert len(rows) == len(table) == len(events) == 12
    for row, cells, event in zip(rows, table, events):
        record = entry(analysis, event)
        flat = csv_row(record)
        assert set(flat) <= set(CSV_COLUMNS) and flat['frame_id'] == 'world'
        assert {key: row[key] for key in flat if key != 'time_s'} == {
            k: str(v) for k, v in flat.items() if k != 'time_s'}
        assert float(row['time_s']) == pytest.approx(record['time_s'], abs=1e-9)
        assert cells[1] == record['event'].split('_')[0]
        assert str(record['stamp_ns']) in cells
        assert f"{record['distance_from_tip_m'] * 100:.1f}" in cells
        if record['event'] == 'near_miss':
            assert cells[-1] == f"{record['gap_m'] * 100:.1f}" and cells.count('-') == 6
            assert cells[8] == record['zone'].split('_')[0]  # where it passed ('near miss')
            assert (row['ball_x'], row['contact_x'], row['gap_x']) == (
                str(event.ball_position[0]), '', str(event.gap_vector[0]))
        else:
            assert cells[-1] == '-' and f"{record['attack_angle_deg']:.1f}" in cells
            assert cells[7] == record['zone'].split('_')[0]
            assert cells[4:7:2] == [f"{record['time_uncertainty_s'] * 1e6:.1f}",
                                    f"{record['distance_from_knob_uncertainty_m'] * 1e3:.1f}"]
            assert f"{record['sweet_spot_speed_uncertainty_mps'] * MPS_TO_MPH:.1f}" in cells
            assert row['time_uncertainty_s'] == str(event.time_uncertainty_s)
            assert (row['contact_x'], row['ball_x']) == (str(event.point[0]),
                                                         str(event.ball_position[0]))
    assert len(TABLE_COLUMNS) == 13


def test_the_csv_columns_are_the_documented_ones() -> None:
    """The CSV schema beside the JSON one names every column, in order, with a description."""
    columns = load_schema('analyze.csv.json')['tableSchema']['columns']
    assert tuple(column['name'] for column in columns) == CSV_COLUMNS
    assert all(column['dc:description'] and column['datatype'] in ('string', 'integer',
                                                                   'double')
               for column in columns)
    assert 'x' not in CSV_COLUMNS and {'contact_x', 'ball_x', 'frame_id'} <= set(CSV_COLUMNS)


def test_json_and_total_of_several_bags() -> None:
    """The JSON text is the document; the total line sums the bags."""
    analyses: List[BagAnalysis] = [
        analyze_bag(bag_path(name), progress=False, use_truth=False)
        for name in ('pitches_90hz.mcap', 'pitches_360hz.mcap')]
    document = json.loads(json_text(analyses))
    assert document == to_json(analyses)
    assert [bag['truth'] for bag in document['bags']] == [None, None]
    assert total_line(analyses).startswith('total: 2 bags, 16 impacts, 8 near misses; ')


def test_an_empty_analysis_reports_so() -> None:
    """No events: the table says so, the CSV is its header."""
    empty = BagAnalysis(path=Path('e.mcap'), selection=_Selection(), config=DetectorConfig())
    assert '(no impacts and no near misses)' in format_report(empty)
    assert csv_text([empty]) == ','.join(CSV_COLUMNS) + '\n'
    assert to_json([empty])['bags'][0]['first_stamp_ns'] is None


class _Selection:
    ball, ball_type, bat_pose, knob, tip = '/ball', 'p', '/bat_pose', None, None
    bat_mode, note = 'pose', ''
    topics = {'ball': '/ball', 'bat_pose': '/bat_pose'}


def test_the_table_numbers_each_kind_as_the_plots_and_predictions_do() -> None:
    """'impact 5' is the fifth impact in the table, the plot names and the prediction lines."""
    analysis = analyze_bag(bag_path('pitches_90hz.mcap'))
    rows = [line.split() for line in format_report(analysis).splitlines()
            if line.split()[1:2] in (['impact'], ['near'])]
    impacts = [int(row[0]) for row in rows if row[1] == 'impact']
    near_misses = [int(row[0]) for row in rows if row[1] == 'near']
    assert impacts == list(range(1, len(analysis.impacts) + 1)) and len(impacts) == 8
    assert near_misses == list(range(1, len(analysis.near_misses) + 1))
    assert plot_names([analysis])[:8] == [f'pitches_90hz_impact_{n}.png' for n in impacts]
    # the header says which look-ahead ran (the node's default 0, analyze's 2)
    assert format_report(analysis).splitlines()[0].endswith(', model c2 (look-ahead 2)')


def test_each_json_and_csv_event_carries_its_table_number() -> None:
    """An analyst finds a CSV row's or JSON entry's table line and plot by bag and number."""
    analysis = analyze_bag(bag_path('pitches_90hz.mcap'), progress=False, use_truth=False)
    document = to_json([analysis], plots=True)
    assert [impact['number'] for impact in document['impacts']] == list(range(1, 9))
    assert [miss['number'] for miss in document['near_misses']] == list(range(1, 5))
    assert document['bags'][0]['plots'][:8] == [
        f"pitches_90hz_impact_{impact['number']}.png" for impact in document['impacts']]
    assert Validator('analyze.schema.json').errors(document) == []
    table = {(cells[1], int(cells[0]), cells[3 if cells[1] == 'impact' else 4])
             for cells in (line.split() for line in format_report(analysis).splitlines())
             if cells[1:2] in (['impact'], ['near'])}
    rows = list(csv.DictReader(io.StringIO(csv_text([analysis]))))
    assert CSV_COLUMNS.index('number') == 31  # after the first 31: those keep their places
    assert {(row['event'].split('_')[0], int(row['number']), row['stamp_ns'])
            for row in rows} == table and len(rows) == 12


def test_the_season_lines_count_the_zones_and_the_bat_speeds(run_cli: RunCli) -> None:
    """Where on the bat and how fast, over every bag: the figures the CSV gives by hand."""
    names = ('pitches_90hz.mcap', 'pitches_360hz.mcap')
    analyses = [analyze_bag(bag_path(name), progress=False, use_truth=False) for name in names]
    rows = [row for row in csv.DictReader(io.StringIO(csv_text(analyses)))
            if row['event'] == 'impact']
    mph = sorted(float(row['sweet_spot_speed_mps']) * MPS_TO_MPH for row in rows)
    zones = [row['zone'] for row in rows]
    sweet = zones.count('sweet_spot')
    p90 = statistics.quantiles(mph, n=10, method='inclusive')[-1]  # numpy's 'linear'
    zone_line, speed_line = season_lines(analyses)
    assert zone_line.startswith('impacts by zone: ') and zone_line.endswith(
        f'(sweet spot {sweet}/16, {100 * sweet / 16:.0f} %)')
    for zone in set(zones):
        assert f"{zone.replace('_', ' ')} {zones.count(zone)}" in zone_line
    assert speed_line == (f'sweet-spot speed: median {statistics.median(mph):.1f} mph, p90 '
                          f'{p90:.1f} mph, {mph[0]:.1f} to {mph[-1]:.1f} mph over 16 impacts')
    assert season_lines([BagAnalysis(path=Path('e.mcap'), selection=_Selection(),
                                     config=DetectorConfig())]) == ['impacts by zone: none']
    code, stdout, _ = run_cli(['analyze', *map(str, map(bag_path, names)), '--no-truth',
                               '--no-progress', '--jobs', '1'])
    assert code == 0 and stdout.rstrip().endswith(f'{zone_line}\n{speed_line}')


def _table(report: str) -> List[List[str]]:
    return [line.split() for line in report.splitlines()
            if line.split()[1:2] in (['impact'], ['near'])]


def test_a_100_column_terminal_gets_a_table_that_fits_it() -> None:
    """The narrow table: the same rows without the ns stamp; every other line wrapped."""
    analysis = analyze_bag(bag_path('pitches_90hz.mcap'), progress=False)
    wide, narrow = format_report(analysis), format_report(analysis, 100)
    assert max(map(len, wide.splitlines())) > TABLE_WIDTH  # (the summary line)
    assert max(map(len, narrow.splitlines())) <= 100
    assert format_report(analysis, 1000) == wide  # a terminal the lines fit in: as they are
    rows, narrow_rows = _table(wide), _table(narrow)
    assert len(narrow_rows) == len(rows) == 12
    for full, short in zip(rows, narrow_rows):
        stamp = full.pop(4 if full[1] == 'near' else 3)  # (the event 'near miss' is 2 words)
        assert int(stamp) > 0 and stamp not in short
        time_at = 3 if full[1] == 'near' else 2
        assert short[time_at] == f'{float(full[time_at]):.3f}'
        assert short[:time_at] + short[time_at + 1:] == full[:time_at] + full[time_at + 1:]
    lines = narrow.splitlines()
    head = next(index for index, line in enumerate(lines) if line.split()[:2] == ['#', 'event'])
    assert 'sweet spot' in lines[head] and lines[head + 1].split()[:2] == ['(s)', '(us)']
    assert ' '.join(narrow.split()).count('summary: 8 impacts, 4 near misses') == 1


def test_analyze_fits_the_terminal_it_prints_in(run_cli: RunCli,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """A terminal: its width (``COLUMNS``); a pipe or file: the full table, whatever COLUMNS."""
    monkeypatch.setenv('COLUMNS', '100')
    bags = [str(bag_path(name)) for name in ('pitches_90hz.mcap', 'pitches_360hz.mcap')]
    code, piped, _ = run_cli(['analyze', *bags, '--no-progress', '--jobs', '1'])
    assert code == 0 and 'stamp (ns)' in piped and max(map(len, piped.splitlines())) > 150
    monkeypatch.setattr(sys.stdout, 'isatty', lambda: True)
    code, shown, _ = run_cli(['analyze', *bags, '--no-progress', '--jobs', '1'])
    assert code == 0 and 'stamp (ns)' not in shown and max(map(len, shown.splitlines())) <= 100
    assert len(_table(shown)) == len(_table(piped)) == 24
    assert ' '.join(shown.split()).count('total: 2 bags, 16 impacts, 8 near misses;') == 1


def _ns_of(utc: str) -> int:
    """Return an ISO 8601 UTC text's ns since the epoch, read back independently."""
    whole, fraction = utc.rstrip('Z').split('.')
    when = datetime.datetime.strptime(whole, '%Y-%m-%dT%H:%M:%S').replace(
        tzinfo=datetime.timezone.utc)
    return int(when.timestamp()) * 1_000_000_000 + int(fraction)


def test_each_stamp_is_also_a_date_and_time_a_person_reads() -> None:
    """``stamp_utc`` beside every ``stamp_ns`` (JSON and CSV), ``first_stamp_utc`` per bag."""
    analysis = analyze_bag(bag_path('pitches_90hz.mcap'), progress=False, use_truth=False,
                           options=AnalysisOptions(prediction_horizon=0.3))
    document = to_json([analysis])
    assert Validator('analyze.schema.json').errors(document) == []
    events = document['impacts'] + document['near_misses'] + document['predictions']
    assert len(events) > 12 and all(
        _ns_of(event['stamp_utc']) == event['stamp_ns'] for event in events)
    assert document['impacts'][0]['stamp_utc'] == '2023-11-14T22:13:20.248723296Z'
    bag = document['bags'][0]
    assert _ns_of(bag['first_stamp_utc']) == bag['first_stamp_ns']
    rows = list(csv.DictReader(io.StringIO(csv_text([analysis]))))
    assert CSV_COLUMNS[-3:-1] == ('number', 'stamp_utc') and len(rows) == len(events)
    assert all(_ns_of(row['stamp_utc']) == int(row['stamp_ns']) for row in rows)
    assert to_json([BagAnalysis(path=Path('e.mcap'), selection=_Selection(),
                                config=DetectorConfig())])['bags'][0]['first_stamp_utc'] is None
