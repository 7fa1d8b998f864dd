"""``--plot``: one PNG per impact and a session summary; what the figures show."""

import dataclasses
import json
from pathlib import Path
import re
from typing import Any, Callable, Dict, List, Sequence, Tuple

from baseball_collision.bags import BagReader
from baseball_collision.core.detector import DetectorConfig, MPS_TO_MPH
from baseball_collision.core.toi import profile_gap
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag, BagAnalysis
from baseball_collision.tools.parameters import load_parameters
from baseball_collision.tools.plots import (
    AHEAD_S, bat_samples, collect_windows, HISTORY_S, impact_figure, impact_title, ModelGap,
    plot_names, PLOT_WINDOW_S, PlotWindow, shown)
from baseball_collision.tools.summary_plot import summary_figure
import numpy as np
import pytest
from support.bundled import bag_path, PARAMS
from support.schema import Validator

RunCli = Callable[[List[str]], Tuple[int, str, str]]


def test_plots_are_pngs_one_per_impact(tmp_path: Path, run_cli: RunCli) -> None:
    """--plot writes one PNG per impact and a summary into a new directory."""
    plots = tmp_path / 'plots'
    code, _, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap')), '--plot',
                               str(plots)])
    assert code == 0, stderr
    files = sorted(plots.iterdir())
    assert [f.name for f in files] == sorted(
        [f'pitches_90hz_impact_{n}.png' for n in range(1, 9)] + ['pitches_90hz_summary.png'])
    for file in files:
        data = file.read_bytes()
        assert data.startswith(b'\x89PNG\r\n\x1a\n') and len(data) > 10_000


def test_plot_names_tell_bags_of_the_same_name_apart() -> None:
    """<bag>_impact_<n>.png; two bags of one name get their position as a prefix."""
    def analysis(path: str, impacts: int) -> BagAnalysis:
        result = BagAnalysis(path=Path(path), selection=None, config=DetectorConfig())
        result.impacts = [None] * impacts
        return result
    names = plot_names([analysis('a/run.mcap', 2), analysis('b/run.mcap', 1),
                        analysis('c/other', 1)])
    assert names == ['1_run_impact_1.png', '1_run_impact_2.png', '1_run_summary.png',
                     '2_run_impact_1.png', '2_run_summary.png', 'other_impact_1.png',
                     'other_summary.png']


def test_plot_names_of_bags_differing_in_suffix_or_case_are_unique() -> None:
    """session.mcap, session.bag, session/ (rosbags-convert's) and 2_session.mcap: no clash."""
    def analysis(path: str, impacts: int) -> BagAnalysis:
        result = BagAnalysis(path=Path(path), selection=None, config=DetectorConfig())
        result.impacts = [None] * impacts
        return result
    bags = [analysis('d/session.mcap', 1), analysis('d/session.bag', 1), analysis('d/session', 1),
            analysis('d/other.DB3', 0)]
    assert plot_names(bags) == [
        '1_session_impact_1.png', '1_session_summary.png', '2_session_impact_1.png',
        '2_session_summary.png', '3_session_impact_1.png', '3_session_summary.png',
        'other_summary.png']
    assert plot_names([analysis('Run.mcap', 0), analysis('run.db3', 0)]) == [
        '1_Run_summary.png', '2_run_summary.png']  # (one file on a case-blind file system)
    taken = [analysis('2_session.mcap', 0), analysis('session.mcap', 0), analysis('session', 0)]
    names = plot_names(taken)  # '2_session' twice: every bag numbered
    assert names == ['1_2_session_summary.png', '2_session_summary.png',
                     '3_session_summary.png'] and len(set(names)) == len(names)


def test_bags_of_one_name_keep_their_own_plots_and_say_which(
        tmp_path: Path, run_cli: RunCli) -> None:
    """A session as MCAP, as ROS 1 and converted to a bag directory: every PNG, each named."""
    day = tmp_path / 'day'
    day.mkdir()
    for count, name, flags in ((1, 'session', ['--storage', 'sqlite3']),
                               (1, 'session.bag', ['--rate', '120']), (2, 'session.mcap', [])):
        made = tmp_path / name.replace('.', '_')
        made.mkdir()
        code, _, stderr = run_cli(['simulate', str(made / name), '--count', str(count),
                                   '--kinds', 'barrel', *flags])
        assert code == 0, stderr
        (made / name).rename(day / name)
    plots, out = tmp_path / 'plots', tmp_path / 'o.json'
    code, _, stderr = run_cli(['analyze', str(day), '--plot', str(plots), '--json', str(out),
                               '--quiet', '--jobs', '1'])
    assert code == 0, stderr
    document = json.loads(out.read_text())
    listed = {bag['path']: bag['plots'] for bag in document['bags']}
    assert listed == {str(day / 'session'): ['1_session_impact_1.png', '1_session_summary.png'],
                      str(day / 'session.bag'): ['2_session_impact_1.png',
                                                 '2_session_summary.png'],
                      str(day / 'session.mcap'): ['3_session_impact_1.png',
                                                  '3_session_impact_2.png',
                                                  '3_session_summary.png']}
    assert sorted(file.name for file in plots.iterdir()) == sorted(
        name for names in listed.values() for name in names)
    assert Validator('analyze.schema.json').errors(document) == []
    code, stdout, _ = run_cli(['analyze', str(day), '--json', '-', '--jobs', '1'])
    assert code == 0 and all('plots' not in bag for bag in json.loads(stdout)['bags'])


@pytest.fixture(scope='module')
def rigid_90hz() -> Dict[str, Any]:
    """Analyse the 90 Hz bag with the node's parameters and the rigid model; keep its windows."""
    analysis = analyze_bag(bag_path('pitches_90hz.mcap'),
                           AnalysisOptions(parameters=load_parameters(PARAMS), model='rigid'),
                           progress=False)
    assert analysis.config.model == 'rigid'
    return {'analysis': analysis, 'windows': collect_windows(analysis)}


def _windows_sample_by_sample(analysis: BagAnalysis) -> List[PlotWindow]:
    """Return the plot windows as one loop over ``BagReader.samples`` finds them."""
    half, before, after = (int(seconds * 1e9) for seconds in (PLOT_WINDOW_S, HISTORY_S, AHEAD_S))
    windows = [PlotWindow(impact, impact.stamp_ns - half, impact.stamp_ns + half)
               for impact in analysis.impacts]
    lists = {'ball': 'ball', 'bat_pose': 'bat', 'knob': 'knob', 'tip': 'tip'}
    with BagReader(analysis.path, analysis.selection) as bag:
        for role, stamp, _, values, _ in bag.samples():
            for window in windows:
                if window.start_ns - before <= stamp <= window.end_ns + after:
                    getattr(window, lists[role]).append((stamp, tuple(values)))
    return windows


def _assert_windows_as_sample_by_sample(analysis: BagAnalysis, roles: Sequence[str]) -> None:
    """Assert the windows read by chunks hold what a loop over every sample keeps."""
    assert analysis.impacts
    windows = collect_windows(analysis)
    expected = _windows_sample_by_sample(analysis)
    for window, reference in zip(windows, expected, strict=True):
        assert all(getattr(window, role) for role in roles)
        for role in ('ball', 'bat', 'knob', 'tip'):
            assert getattr(window, role) == getattr(reference, role), role


@pytest.mark.parametrize('bag, options', [
    ('pitches_90hz.mcap', AnalysisOptions()),
    ('pitches_90hz.mcap', AnalysisOptions(knob_topic='/bat_knob', tip_topic='/bat_tip')),
    ('pitches_120hz_sqlite3', AnalysisOptions()),
    ('pitches_240hz_noisy.bag', AnalysisOptions(knob_topic='/bat_knob', tip_topic='/bat_tip')),
    ('pitches_1khz_arm.mcap', AnalysisOptions())], ids=['mcap', 'mcap points', 'sqlite3',
                                                        'ros1 points', 'mcap 1khz'])
def test_plot_windows_hold_the_samples_near_each_impact_in_bag_order(
        bag: str, options: AnalysisOptions) -> None:
    """The windows read by chunks hold what a loop over every sample keeps: same order, values."""
    analysis = analyze_bag(bag_path(bag), options, progress=False, use_truth=False)
    _assert_windows_as_sample_by_sample(
        analysis, ('ball', 'knob', 'tip') if options.knob_topic else ('ball', 'bat'))


def test_plot_windows_end_where_they_end_in_a_crowded_recording(tmp_path: Path,
                                                                run_cli: RunCli) -> None:
    """Pitches 0.42 s apart: each window starts and ends among another pitch's samples."""
    bag = tmp_path / 'crowded.mcap'
    code, _, stderr = run_cli(['simulate', str(bag), '--count', '8', '--spacing', '0.42',
                               '--kinds', 'barrel', '--rate', '240'])
    assert code == 0, stderr
    analysis = analyze_bag(bag, AnalysisOptions(), progress=False, use_truth=False)
    with BagReader(bag) as reader:
        stamps = [sample.stamp_ns for sample in reader.samples()]
    half, before = int(PLOT_WINDOW_S * 1e9), int(HISTORY_S * 1e9)
    cut = [impact for impact in analysis.impacts
           if min(stamps) < impact.stamp_ns - half - before and
           max(stamps) > impact.stamp_ns + half + int(AHEAD_S * 1e9)]
    assert len(cut) >= 3  # (windows whose both ends fall inside the recording)
    _assert_windows_as_sample_by_sample(analysis, ('ball', 'bat'))


def _streams(window: Any, config: DetectorConfig) -> Any:
    balls = shown(window, window.ball)
    return ([s for s, _ in balls], [v for _, v in balls]), bat_samples(window, config)


@pytest.mark.parametrize('bag, model', [
    ('pitches_360hz.mcap', 'linear'), ('pitches_360hz.mcap', 'rigid'),
    ('pitches_360hz.mcap', 'spline'), ('pitches_90hz.mcap', None),
    ('pitches_180hz_rebound.mcap', None), ('pitches_240hz_noisy.bag', None)])
def test_model_gap_touches_zero_at_each_impact_of_its_model(bag: str, model: Any) -> None:
    """
    The gap curve of the model that found an impact is 0 at its instant (within 0.3 mm).

    ``analyze``'s default (``c2``, look-ahead 2, auto noise: None) too, with a hit's bat
    continued from before its interval and noise smoothed. Its curve was the straight-line gap
    before (``BatPath.build`` knows no ``c2``), 1.3-4.5 mm off at end-cap hits.
    """
    analysis = analyze_bag(bag_path(bag), AnalysisOptions(model=model), progress=False,
                           use_truth=False)
    assert analysis.impacts
    for window in collect_windows(analysis):
        gap = ModelGap(analysis.config, analysis.config.model, window.impact.stamp_ns, window,
                       analysis.frame_id)
        assert abs(gap.at(0.0)) < 3e-4


def test_linear_model_gap_is_the_straight_line_gap(rigid_90hz: Dict[str, Any]) -> None:
    """linear: ball and bat ends interpolated on straight lines (an independent np.interp)."""
    config = rigid_90hz['analysis'].config
    window = rigid_90hz['windows'][0]
    ball, bat = _streams(window, config)
    origin = window.impact.stamp_ns
    gap = ModelGap(config, 'linear', origin, window, 'world')
    bat_t = np.array([s - origin for s in bat[0]], dtype=float)
    knobs = np.array([s.knob for s in bat[1]])
    tips = np.array([s.tip for s in bat[1]])
    ball_t = np.array([s - origin for s in ball[0]], dtype=float)
    balls = np.array(ball[1], dtype=float)
    start, end = gap.span
    for t in np.linspace(start, end, 37)[1:-1]:
        stamp = t * 1e9
        at = [tuple(float(np.interp(stamp, times, values[:, i])) for i in range(3))
              for times, values in ((ball_t, balls), (bat_t, knobs), (bat_t, tips))]
        expected = profile_gap(at[0], at[1], at[2], config.ball_radius, config.profile)[0]
        assert gap.at(t) == pytest.approx(expected, abs=1e-7)  # (t to the ns: 40 m/s x 1 ns)


def _line(axes: Any, label: str) -> Any:
    (line,) = [line for line in axes.get_lines() if line.get_label().startswith(label)]
    return line


def test_impact_figure_agrees_with_the_impact(rigid_90hz: Dict[str, Any]) -> None:
    """
    An end-cap hit: the model's curve touches 0 at the impact, the straight one stays above.

    Every line labelled and visible; time in ms; a readable title.
    """
    analysis = rigid_90hz['analysis']
    window = rigid_90hz['windows'][1]
    assert window.impact.feature == 'tip_end'
    truth = [t for t, i in analysis.truth.matched if i is window.impact][0]
    figure = impact_figure(window, analysis, 2, int(truth['stamp_ns']))
    gap_axes, top_axes, side_axes = figure.axes[:3]
    model = _line(gap_axes, 'gap, rigid model')
    x, y = model.get_data()
    assert abs(float(np.interp(0.0, x, y))) < 0.05  # cm
    straight = _line(gap_axes, 'gap, straight lines')
    assert np.nanmin(straight.get_ydata()) > 0.2  # what the old grey curve showed alone
    legend = [text.get_text() for text in gap_axes.get_legend().get_texts()]
    assert legend[:2] == ['gap, rigid model (used)', 'gap, straight lines (comparison)']
    assert {'at ball samples', 'bat samples', 'impact found'} <= set(legend)
    assert any(text.startswith('true contact (') and text.endswith(' ms)') for text in legend)
    for line in gap_axes.get_lines():
        assert line.get_alpha() is None or line.get_alpha() >= 0.3
    impact_line, truth_line = _line(gap_axes, 'impact found'), _line(gap_axes, 'true contact')
    assert impact_line.get_zorder() > truth_line.get_zorder()
    assert gap_axes.get_xlabel() == 'time from the impact (ms)'
    title = figure._suptitle.get_text()
    assert title.startswith('Impact 2: end cap,') and 'mph' in title
    assert not re.search(r'\d{10}', title)
    for axes in (top_axes, side_axes):
        labels = [text.get_text() for text in axes.get_legend().get_texts()]
        assert {'bat at impact (knob to tip)', 'ball at impact', 'contact point'} <= set(labels)
        assert axes.get_xlabel().endswith('from the contact point (cm)')


def test_summary_figure_spots_speeds_and_misses(rigid_90hz: Dict[str, Any]) -> None:
    """One spot per impact on the drawn bat; a bar per impact (mph) and per near miss (cm)."""
    analysis = rigid_90hz['analysis']
    figure = summary_figure(analysis)
    bat_axes, speed_axes, miss_axes = figure.axes
    spots = [line for line in bat_axes.get_lines()
             if line.get_label().startswith('contact:')]
    assert sum(len(line.get_xdata()) for line in spots) == len(analysis.impacts) == 8
    assert [p.get_height() for p in speed_axes.patches] == pytest.approx(
        [i.sweet_spot_speed_mps * MPS_TO_MPH for i in analysis.impacts])
    assert [p.get_height() for p in miss_axes.patches] == pytest.approx(
        [m.gap_m * 100.0 for m in analysis.near_misses])
    assert 'Session summary: pitches_90hz.mcap' in figure._suptitle.get_text()


def test_the_summary_shows_each_speeds_uncertainty_and_when_the_session_was(
        rigid_90hz: Dict[str, Any]) -> None:
    """A coach sees the 1-sigma error bar on each speed, and the session's date and time."""
    analysis = rigid_90hz['analysis']
    speed_axes = summary_figure(analysis).axes[1]
    (bars,) = [c for c in speed_axes.containers if hasattr(c, 'errorbar')]  # BarContainer
    segments = bars.errorbar.lines[2][0].get_segments()  # one vertical line per bar
    assert [abs(segment[1][1] - segment[0][1]) / 2 for segment in segments] == pytest.approx(
        [i.sweet_spot_speed_uncertainty_mps * MPS_TO_MPH for i in analysis.impacts])
    assert all(i.sweet_spot_speed_uncertainty_mps > 0.0 for i in analysis.impacts)
    assert 'error bars: 1 sigma' in speed_axes.get_title()
    # the bundled bag's first stamp, 1700000000000000000 ns and a little: 2023-11-14 22:13 UTC
    assert summary_figure(analysis)._suptitle.get_text().startswith(
        'Session summary: pitches_90hz.mcap, 2023-11-14 22:13 UTC (8 impacts, ')


def test_a_bag_named_dot_is_named_in_the_titles(rigid_90hz: Dict[str, Any], tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """``analyze .`` in a bag directory: the figures name the directory, not ''."""
    (tmp_path / 'tuesday').mkdir()
    monkeypatch.chdir(tmp_path / 'tuesday')
    analysis = dataclasses.replace(rigid_90hz['analysis'], path=Path('.'))
    assert summary_figure(analysis)._suptitle.get_text().startswith('Session summary: tuesday, ')
    title = impact_title(analysis, analysis.impacts[0], 1, None)
    assert title.splitlines()[1].startswith('tuesday, ')


def test_a_duplicate_stamp_in_a_window_is_fed_not_compared() -> None:
    """Two ball samples of one stamp (a bag with duplicates): the plot's detector drops one."""
    window = PlotWindow(None, 0, 10)
    window.ball = [(5, np.array([0.0, 0.0, 1.0])), (5, np.array([0.0, 0.0, 2.0]))]
    gap = ModelGap(DetectorConfig(), 'c2', 5, window, 'world')
    assert gap.detector.stats.dropped == {'duplicate_stamp': 1}
