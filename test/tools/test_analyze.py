"""
``analyze``: the one detector loop over bags, its sinks, and every bundled bag against truth.

Accuracy bounds against the truth files (``spline``, the offline default before ``c2`` with
look-ahead 2 and ``tracker_noise`` auto, and the node's ``rigid``; the offline default is held
to the same bounds), measured on the bundled bags (maximum over the 8 contacts, spline / rigid):

=========================  ======  ================  =============  =============
bag                        rate    time error        spot error     speed error
=========================  ======  ================  =============  =============
pitches_90hz.mcap          90 Hz   2.6 / 40 us       0.2 / 2.1 mm   0.5 / 0.5 %
pitches_120hz_sqlite3      120 Hz  1.9 / 14 us       0.1 / 1.8 mm   1.2 / 1.2 %
pitches_240hz_noisy.bag    240 Hz  14 / 9 us         0.4 / 0.8 mm   0.8 / 0.8 %
pitches_360hz.mcap         360 Hz  2.5 / 2.5 us      0.1 / 0.3 mm   0.6 / 0.4 %
=========================  ======  ================  =============  =============

The time bound is 1 % of the bag's frame period (111 us at 90 Hz, 28 us at 360 Hz): at least
twice the worst error measured with either model, and at 40 m/s the ball moves 4.4 mm in
111 us, far less than its radius, where a frame-by-frame check is off by up to a whole frame.
Spot within 5 mm, sweet-spot speed within 2 % (the velocities come from samples before the
impact only, by design).
"""

from dataclasses import replace
import json
import math
from pathlib import Path
import sys
import threading
from typing import Any, Callable, Dict, List, Optional, Tuple

from baseball_collision.bags import (
    BagReader, BagWriter, path_message, POINT_STAMPED, POSE_STAMPED)
from baseball_collision.core.detector import (
    Detector, DetectorConfig, Impact, NearMiss, Prediction, PredictionCleared, StateReset,
    StreamGap)
from baseball_collision.errors import ToolError, TopicError
import baseball_collision.tools.analyze as analyze_module
from baseball_collision.tools.analyze import (
    AnalysisOptions, analyze_bag, BagAnalysis, CHUNK, progress_bar, run_detector)
from baseball_collision.tools.parameters import output_topics
from baseball_collision.tools.recording import RecordingSpec, write_recording
from baseball_collision.tools.truth import LEADS_S, truth_path
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
from support import modules_loaded
from support.bagfiles import reference_bag, still_rows
from support.bundled import bag_path, BAGS, check_against_truth, PARAMS
from support.events import swing_events

RunCli = Callable[[List[str]], Tuple[int, str, str]]


# ---- every bundled bag against its truth ----------------------------------------------------

@pytest.mark.parametrize('model', ['spline', 'rigid', None])
@pytest.mark.parametrize('name', sorted(BAGS))
def test_bundled_bags_against_truth(name: str, model: Optional[str], tmp_path: Path,
                                    run_cli: RunCli) -> None:
    """
    Analyze finds every contact of every bundled bag, in time, and nothing else.

    Under a model named with the node's parameter file, and under the offline default (no
    file, no model: ``c2`` with look-ahead 2 and ``tracker_noise`` auto).
    """
    out = tmp_path / 'out.json'
    named = ['--params', str(PARAMS), '--model', model] if model else []
    code, stdout, stderr = run_cli(['analyze', str(bag_path(name)), *named, '--json', str(out)])
    assert code == 0, stderr
    document = json.loads(out.read_text())
    truth = json.loads(truth_path(bag_path(name)).read_text())
    check_against_truth(document, truth, BAGS[name])
    assert document['bags'][0]['model'] == (model or 'c2')
    assert document['dropped'] == {}
    summary = document['bags'][0]['truth']
    assert summary['matched'] == summary['contacts'] == 8 and summary['false_impacts'] == []
    assert 'summary: 8 impacts, 4 near misses, 0 dropped' in stdout
    assert '8/8 contacts found, 0 missed, 0 false impacts' in stdout


def test_knob_and_tip_topics_give_the_same_impacts(tmp_path: Path,
                                                   run_cli: RunCli) -> None:
    """The bat as knob/tip points (flags) finds the same contacts as the pose."""
    bag = str(bag_path('pitches_360hz.mcap'))
    code, _, _ = run_cli(['analyze', bag, '--json', str(tmp_path / 'pose.json')])
    assert code == 0
    code, stdout, _ = run_cli(['analyze', bag, '--knob-topic', '/bat_knob', '--tip-topic',
                               '/bat_tip', '--json', str(tmp_path / 'points.json')])
    assert code == 0 and '/bat_knob + /bat_tip (knob/tip)' in stdout
    pose = json.loads((tmp_path / 'pose.json').read_text())['impacts']
    points = json.loads((tmp_path / 'points.json').read_text())['impacts']
    assert len(pose) == len(points) == 8
    for a, b in zip(pose, points):
        assert abs(a['stamp_ns'] - b['stamp_ns']) < 1000


def test_radius_flags_change_the_geometry(tmp_path: Path, run_cli: RunCli) -> None:
    """A bigger ball touches earlier; a thin constant-radius bat later."""
    bag = str(bag_path('pitches_360hz.mcap'))
    stamps = {}
    for label, flags in (('plain', []), ('big_ball', ['--ball-radius', '0.05']),
                         ('thin_bat', ['--bat-radius', '0.01'])):
        out = tmp_path / f'{label}.json'
        code, _, stderr = run_cli(['analyze', bag, '--json', str(out), '--no-truth'] + flags)
        assert code == 0, stderr
        stamps[label] = [i['stamp_ns'] for i in json.loads(out.read_text())['impacts']]
    barrel = stamps['plain'][0]  # the first pitch is a barrel hit
    assert stamps['big_ball'][0] < barrel
    assert stamps['thin_bat'][0] > barrel


def test_out_bag_has_inputs_and_node_outputs(tmp_path: Path,
                                             run_cli: RunCli) -> None:
    """--out-bag: an MCAP with every input topic and the node's output topics and types."""
    out = tmp_path / 'events.mcap'
    json_out = tmp_path / 'a.json'
    name = 'pitches_240hz_noisy.bag'
    code, _, stderr = run_cli(['analyze', str(bag_path(name)), '--params', str(PARAMS),
                               '--out-bag', str(out), '--json', str(json_out)])
    assert code == 0, stderr
    document = json.loads(json_out.read_text())
    topics = output_topics()
    with AnyReader([out], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        assert types == {  # every input topic, not only the selected ones
            '/ball': POINT_STAMPED, '/bat_pose': 'geometry_msgs/msg/PoseStamped',
            '/bat_knob': POINT_STAMPED, '/bat_tip': POINT_STAMPED,
            topics['impact']: POINT_STAMPED,
            topics['impact_velocity']: 'geometry_msgs/msg/TwistStamped',
            topics['near_miss']: 'geometry_msgs/msg/Vector3Stamped',
            topics['predicted_impact']: POINT_STAMPED,
            topics['impact_report']: 'std_msgs/msg/String',
            topics['markers']: 'visualization_msgs/msg/MarkerArray',
            topics['diagnostics']: 'diagnostic_msgs/msg/DiagnosticArray'}
        found: Dict[str, List[Any]] = {}
        for connection, _, raw in reader.messages():
            if connection.topic in topics.values():
                found.setdefault(connection.topic, []).append(
                    reader.deserialize(raw, connection.msgtype))
    stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec
              for m in found[topics['impact']]]
    assert stamps == [i['stamp_ns'] for i in document['impacts']]
    first = found[topics['impact']][0].point
    assert [first.x, first.y, first.z] == pytest.approx(document['impacts'][0]['point'])
    twist = found[topics['impact_velocity']][0].twist.linear
    speed = (twist.x ** 2 + twist.y ** 2 + twist.z ** 2) ** 0.5
    assert speed == pytest.approx(document['impacts'][0]['bat_speed_at_contact_mps'])
    assert len(found[topics['near_miss']]) == len(document['near_misses'])
    with BagReader(out) as bag:  # readable with bag.py, inputs intact
        assert bag.message_count == 2300
        assert bag.selection.bat_pose == '/bat_pose'


def test_predict_scores_predictions_and_exports_them(
        tmp_path: Path, run_cli: RunCli) -> None:
    """--predict: predictions in the report, JSON, CSV and the output bag, scored by lead."""
    json_out, csv_out, out = tmp_path / 'p.json', tmp_path / 'p.csv', tmp_path / 'p.mcap'
    name = 'pitches_360hz.mcap'
    code, stdout, stderr = run_cli(['analyze', str(bag_path(name)), '--model', 'rigid',
                                    '--predict',
                                    '--json', str(json_out), '--csv', str(csv_out),
                                    '--out-bag', str(out)])
    assert code == 0, stderr
    assert 'predictions:' in stdout and 'error against the truth' in stdout
    assert "'-': no prediction in force that far ahead" in stdout
    document = json.loads(json_out.read_text())
    predictions = document['predictions']
    assert predictions and all(p['stamp_ns'] > p['made_at_ns'] for p in predictions)
    for impact in document['impacts']:
        errors = impact['prediction_errors']
        assert set(errors) == {'200', '100', '50', '20'}
        close = errors['20']  # 20 ms ahead of a 360 Hz swing: within 3 ms and 8 cm
        assert close is not None
        assert abs(close['time_error_s']) < 3e-3 and close['point_error_m'] < 0.08
    rows = [line for line in csv_out.read_text().splitlines() if ',prediction,' in line]
    assert len(rows) == len(predictions)
    with AnyReader([out], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        predicted = [c for c in reader.connections
                     if c.topic == output_topics()['predicted_impact']]
        assert predicted and predicted[0].msgcount == len(predictions)
    code, stdout, _ = run_cli(['analyze', str(bag_path(name)), '--model', 'rigid', '--json',
                               str(tmp_path / 'q.json')])
    assert code == 0 and 'predictions:' not in stdout
    assert 'predictions' not in json.loads((tmp_path / 'q.json').read_text())


@pytest.mark.parametrize('model', ['spline', None])
@pytest.mark.parametrize('period', [0.0, 0.01])
@pytest.mark.parametrize('name', ['pitches_360hz.mcap', 'pitches_90hz.mcap',
                                  'pitches_240hz_noisy.bag', 'pitches_1khz_arm.mcap'])
def test_predict_goes_a_chunk_at_a_time_with_the_events_of_the_sample_loop(
        name: str, period: float, model: Optional[str]) -> None:
    """
    ``--predict`` feeds the detector a chunk at a time.

    The events, drops, counters and clearings are those of the loop one sample at a time
    (``run_detector``, which ``--predict`` ran before), under ``spline`` and the offline
    default (its noise estimated), on exact and noisy bags and a 60 Hz ball beside a 1 kHz bat.
    """
    options = AnalysisOptions(model=model, prediction_horizon=0.3,
                              parameters={'prediction_period': period})
    chunked = analyze_bag(bag_path(name), options, progress=False)
    with BagReader(bag_path(name)) as bag:
        one = BagAnalysis(path=bag_path(name), selection=bag.selection, config=chunked.config)
        detector = Detector(chunked.config)
        count, _ = run_detector(bag.samples(), detector, [one], None, one.drops_by_role)
    assert chunked.predictions and chunked.impacts and chunked.cleared
    assert count == chunked.messages
    for name in ('impacts', 'near_misses', 'predictions', 'cleared', 'gaps', 'resets',
                 'drops_by_role'):
        assert getattr(one, name) == getattr(chunked, name), name
    assert detector.stats.intervals == chunked.stats.intervals


@pytest.mark.parametrize('name', ['pitches_120hz_sqlite3', 'pitches_180hz_rebound.mcap'])
def test_reading_ahead_finds_the_events_of_reading_in_turn(
        name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """``analyze_bag`` reads a bag ahead on another thread (by default): the same events."""
    asked = []
    chunks = BagReader.chunks

    def watched(self: BagReader, size: int, read_ahead: int = 0) -> Any:
        asked.append(read_ahead)
        return chunks(self, size, read_ahead)
    monkeypatch.setattr(BagReader, 'chunks', watched)
    threads = threading.active_count()
    ahead = analyze_bag(bag_path(name), progress=False)
    assert threading.active_count() == threads  # (its reading thread ended: a pool may fork)
    in_turn = analyze_bag(bag_path(name), progress=False, read_ahead=0)
    assert asked == [1, 0] and ahead.impacts
    for part in ('impacts', 'near_misses', 'gaps', 'resets', 'drops_by_role'):
        assert getattr(ahead, part) == getattr(in_turn, part), part
    assert ahead.messages == in_turn.messages


@pytest.fixture(scope='module')
def plan_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Return a bag of 6 noisy pitches at 120 Hz with an arm's plan on /bat_plan (200 Hz)."""
    bag = tmp_path_factory.mktemp('plans') / 'arm.mcap'
    write_recording(bag, RecordingSpec(count=6, rate_hz=120.0, noise_m=0.001, plan_hz=200.0,
                                       lead_s=0.35, seed=4))
    return bag


def test_predict_takes_the_bags_bat_plans_where_the_samples_pass_them(plan_bag: Path) -> None:
    """
    ``--bat-plan-topic``: the node's plans from the bag, each before the samples logged after it.

    The chunk path cuts a chunk where a plan falls (``PlanFeed``); the reference is a detector
    fed one sample at a time, each plan set where the samples' log times first pass its own:
    the same predictions to the bit, planned and with their error bars. Without the topic the
    predictions extrapolate the bat and a note names the bag's Path topic.
    """
    planned = analyze_bag(plan_bag, AnalysisOptions(prediction_horizon=0.3,
                                                    bat_plan_topic='/bat_plan'), progress=False)
    assert planned.predictions and all(p.planned for p in planned.predictions)
    assert all(p.time_uncertainty_s is not None for p in planned.predictions)
    assert "bat plans on '/bat_plan': 6 taken for the predictions" in planned.notes
    detector = Detector(planned.config)
    with BagReader(plan_bag) as bag:
        plans = bag.plans('/bat_plan')
        made = []
        for role, stamp, frame, values, log_time in bag.samples():
            while plans and plans[0].log_time_ns < log_time:
                assert detector.take_bat_plan(plans[0].stamps_ns, plans[0].positions,
                                              plans[0].quaternions, plans[0].frames) is None
                plans.pop(0)
            made += [e for e in detector.add(role, stamp, values, frame)
                     if isinstance(e, Prediction)]
    assert made == planned.predictions
    plain = analyze_bag(plan_bag, AnalysisOptions(prediction_horizon=0.3), progress=False)
    assert plain.predictions and not any(p.planned for p in plain.predictions)
    assert any("nav_msgs/msg/Path topic '/bat_plan' was not read: --bat-plan-topic" in note
               for note in plain.notes)
    from_file = analyze_bag(plan_bag, AnalysisOptions(
        prediction_horizon=0.3, parameters={'bat_plan_topic': 'bat_plan'}), progress=False)
    assert from_file.predictions == planned.predictions
    none = analyze_bag(plan_bag, AnalysisOptions(
        prediction_horizon=0.3, parameters={'bat_plan_topic': 'bat_plan'}, bat_plan_topic=''),
        progress=False)
    assert none.predictions == plain.predictions
    missing = analyze_bag(plan_bag, AnalysisOptions(prediction_horizon=0.3,
                                                    bat_plan_topic='/arm/plan'), progress=False)
    assert "no bat plan topic '/arm/plan' in the bag: the predictions extrapolate the bat" \
        in missing.notes and missing.predictions == plain.predictions


def test_a_plan_in_another_frame_is_refused_and_counted(tmp_path: Path, run_cli: RunCli) -> None:
    """The node's rule offline: a plan naming another frame than the trackers' is not used."""
    bag = tmp_path / 'frames.mcap'
    write_recording(bag, RecordingSpec(count=2, rate_hz=120.0, plan_hz=200.0, lead_s=0.35,
                                       frame_id='world'))
    moved = tmp_path / 'arm_frame.mcap'
    with BagReader(bag) as source, BagWriter(moved) as writer:
        plans = {plan.log_time_ns: plan for plan in source.plans('/bat_plan')}
        for role, stamp, frame, values, log_time in source.samples():
            for at in [t for t in plans if t < log_time]:
                plan = plans.pop(at)
                writer.write_message('/bat_plan', path_message(
                    plan.stamps_ns, plan.positions, plan.quaternions, 'arm_base',
                    writer.typestore), at)
            topic = source.selection.topics[role]
            if role == 'bat_pose':
                writer.write_pose(topic, stamp, frame, values[:3], values[3:], log_time)
            else:
                writer.write_point(topic, stamp, frame, values, log_time)
    code, stdout, stderr = run_cli(['analyze', str(moved), '--predict', '--bat-plan-topic',
                                    '/bat_plan'])
    assert code == 0, stderr
    assert ("bat plans on '/bat_plan': 0 taken for the predictions, 2 refused (2 x frame "
            "['arm_base'] is not the tracking frame 'world')") in stdout


# ---- the loop and its sinks -----------------------------------------------------------------

def test_progress_bar_only_on_long_bags_or_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    """A tqdm bar on stderr above 100k messages; none for a short bag off a terminal."""
    monkeypatch.setattr(sys.stderr, 'isatty', lambda: False)
    assert progress_bar(1000, 'x') is None
    bar = progress_bar(200_000, 'x')
    assert bar is not None
    bar.close()


MISS = NearMiss(stamp_ns=25, gap_m=0.05, gap_vector=(0.0, 0.0, 0.05),
                ball_position=(0.0, 0.0, 0.0), bat_fraction=0.8, distance_from_tip_m=0.1)
GAP = StreamGap(stream='ball', start_ns=30, end_ns=40)


class _Detector:
    """A detector stand-in: a near miss from the second sample, a stream gap from finish()."""

    config = DetectorConfig()

    def __init__(self) -> None:
        self.fed: List[Tuple[str, int, str]] = []

    def add(self, role: str, stamp_ns: int, values: Any, frame_id: str) -> List[Any]:
        self.fed.append((role, stamp_ns, frame_id))
        return [MISS] if len(self.fed) == 2 else []

    def finish(self) -> List[Any]:
        return [GAP]


class _Sink:
    """Records what the loop hands it."""

    def __init__(self) -> None:
        self.samples: List[Tuple[Any, ...]] = []
        self.events: List[Tuple[List[Any], int, str]] = []

    def on_sample(self, *sample: Any) -> None:
        self.samples.append(sample)

    def on_events(self, events: List[Any], log_time_ns: int, frame_id: str) -> None:
        self.events.append((list(events), log_time_ns, frame_id))


class _Bar:

    def __init__(self) -> None:
        self.updates: List[int] = []

    def update(self, count: int) -> None:
        self.updates.append(count)


def test_one_loop_feeds_the_detector_and_every_sink() -> None:
    """Samples in order to the sample sinks and the detector; events, finish()'s too, onwards."""
    samples = [('ball', 10, 'w', (0.0, 0.0, 0.0), 100),
               ('bat_pose', 20, 'w', (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0), 200),
               ('ball', 30, 'v', (0.0, 0.0, 1.0), 300)]
    detector, sink, bar = _Detector(), _Sink(), _Bar()
    result = BagAnalysis(path=Path('x.mcap'), selection=None, config=DetectorConfig())
    count, first = run_detector(iter(samples), detector, [result, sink], bar)
    assert (count, first) == (3, 10) and bar.updates == [3]
    assert detector.fed == [('ball', 10, 'w'), ('bat_pose', 20, 'w'), ('ball', 30, 'v')]
    assert sink.samples == samples
    assert sink.events == [([MISS], 200, 'w'), ([GAP], 300, 'v')]  # finish: the last sample's
    assert result.near_misses == [MISS] and result.gaps == [GAP] and result.impacts == []


def test_the_loop_counts_in_chunks_and_takes_an_empty_bag() -> None:
    """The progress bar moves chunk by chunk; no sample: no first stamp, finish() still heard."""
    samples = [('ball', 10 + i, 'w', (0.0, 0.0, 0.0), i) for i in range(CHUNK + 5)]
    bar, sink = _Bar(), _Sink()
    assert run_detector(samples, _Detector(), [sink], bar) == (CHUNK + 5, 10)
    assert bar.updates == [CHUNK, 5] and len(sink.samples) == CHUNK + 5
    empty = _Sink()
    assert run_detector([], _Detector(), [empty]) == (0, None)
    assert empty.samples == [] and empty.events == [([GAP], 0, '')]


def test_analyze_loads_no_simulator_plotting_or_ros() -> None:
    """analyze, its reports, plots, truth and outputs import no simulator, matplotlib or rclpy."""
    code = ('import baseball_collision.tools.analyze, baseball_collision.tools.report\n'
            'import baseball_collision.tools.plots, baseball_collision.tools.truth\n'
            'import baseball_collision.tools.outputs, baseball_collision.tools.parameters')
    assert modules_loaded(code, ('baseball_collision.tools.sim', 'matplotlib', 'rclpy')) == []


def test_the_command_lines_start_up_leaves_what_a_run_may_not_need() -> None:
    """
    The command line and analyze import numpy's random generators and a thread pool lazily.

    Only a noisy impact's uncertainty draws random numbers and only a big batch of queries
    takes threads (about 16 ms of every start-up when imported with the modules).
    """
    code = 'import baseball_collision.tools.cli, baseball_collision.tools.analyze'
    assert modules_loaded(code, ('numpy.random', 'concurrent.futures')) == []


@pytest.mark.parametrize('name, out_bag, loaded', [
    ('pitches_90hz.mcap', False, []),
    ('pitches_120hz_sqlite3', False, ['baseball_collision.bags.sqlite']),
    ('pitches_90hz.mcap', True,
     ['baseball_collision.bags.writer', 'baseball_collision.core.health']),
])
def test_analyzing_a_bag_imports_what_its_storage_and_outputs_need(
        name: str, out_bag: bool, loaded: List[str], tmp_path: Path) -> None:
    """
    A whole ``analyze`` (in a fresh interpreter) imports no module its bag and outputs do not use.

    An MCAP bag's: no sqlite3 reader; without ``--out-bag``: no bag writer and no node health
    (each a few ms of every start-up: issue 13). A sqlite3 bag loads its reader, an output bag
    the writer and the health its ``/diagnostics`` are made of.
    """
    argv = ['analyze', str(bag_path(name)), '--quiet', '--no-progress']
    argv += ['--out-bag', str(tmp_path / 'out.mcap')] if out_bag else []
    code = f'from baseball_collision.tools.cli import main\nassert main({argv!r}) == 0'
    modules = ('baseball_collision.bags.sqlite', 'baseball_collision.bags.writer',
               'baseball_collision.core.health')
    assert modules_loaded(code, modules) == loaded


def test_a_reset_ends_the_prediction_in_force() -> None:
    """A prediction is scored until the next, a clearing or a reset (the node's flag goes off)."""
    events = swing_events(horizon=0.3)
    impact = next(e for e in events if isinstance(e, Impact))
    prediction = next(e for e in events if isinstance(e, Prediction))
    analysis = BagAnalysis(path=Path('b.mcap'), selection=None,
                           config=DetectorConfig(prediction_horizon=0.3))
    analysis.impacts.append(replace(impact, stamp_ns=1_000_000_000))
    analysis.predictions.append(replace(prediction, made_at_ns=700_000_000,
                                        stamp_ns=1_000_000_000))
    kept = analysis.prediction_scores()[0]
    assert all(kept[lead] is not None for lead in LEADS_S)
    analysis.resets.append(StateReset(stamp_ns=920_000_000, reason='requested'))
    scores = analysis.prediction_scores()[0]
    assert scores[0.1] is not None and scores[0.05] is None and scores[0.02] is None


def test_prediction_scores_index_the_predictions_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """300 impacts, 10 predictions and a clearing each: one index for all, each scored right."""
    events = swing_events(horizon=0.3)
    impact = next(e for e in events if isinstance(e, Impact))
    prediction = next(e for e in events if isinstance(e, Prediction))
    analysis = BagAnalysis(path=Path('b.mcap'), selection=None,
                           config=DetectorConfig(prediction_horizon=0.3))
    for i in range(300):
        base = i * 1_000_000_000
        analysis.impacts.append(replace(impact, stamp_ns=base + 500_000_000))
        for k in range(10):
            made = base + 250_000_000 + 25_000_000 * k
            analysis.predictions.append(replace(prediction, made_at_ns=made,
                                                stamp_ns=base + 500_000_000))
        analysis.cleared.append(PredictionCleared(made_at_ns=base + 510_000_000))  # (hit)
    built = []
    index_class = analyze_module.PredictionIndex

    def counted(*args: Any) -> Any:
        built.append(args)
        return index_class(*args)

    monkeypatch.setattr(analyze_module, 'PredictionIndex', counted)
    scores = analysis.prediction_scores()
    assert len(built) == 1 and len(scores) == 300
    assert all(score[0.2] == (0.0, pytest.approx(math.dist(prediction.point, impact.point)))
               for score in scores)


@pytest.mark.parametrize('offset_s, noted', [(3600.0, True), (0.0, False)])
def test_streams_that_never_overlap_in_time_are_noted(tmp_path: Path, offset_s: float,
                                                      noted: bool) -> None:
    """A ball stamped an hour off the bat: a note that nothing could be solved, not silence."""
    rows = [('/ball', POINT_STAMPED, 1_000_000_000 + 10_000_000 * i, 'world',
             (0.1 * i, 0.0, 1.0), 10_000_000 * i + 1) for i in range(40)]
    rows += [('/bat_pose', POSE_STAMPED, 1_000_000_000 + int(offset_s * 1e9) + 10_000_000 * i,
              'world', (1.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0), 10_000_000 * i + 2)
             for i in range(40)]
    bag = tmp_path / 'apart'
    reference_bag(bag, sorted(rows, key=lambda row: row[5]))
    analysis = analyze_bag(bag, AnalysisOptions(), progress=False)
    assert (analysis.notes == [
        'the ball and the bat were never tracked at the same time (their stamps do not '
        'overlap): nothing could be solved; are both stamped by one clock?']) == noted
    assert noted or analysis.stats.intervals > 0


def test_options_of_the_wrong_kind_are_refused() -> None:
    """analyze_bag(path, a dict): a ToolError saying what to pass (an AttributeError before)."""
    with pytest.raises(ToolError, match='options must be AnalysisOptions, not dict'):
        analyze_bag(bag_path('pitches_90hz.mcap'), {'model': 'c2'})


def test_a_truth_file_written_for_another_bag_is_named(tmp_path: Path) -> None:
    """Another bag's truth file under this bag's name: compared, with a note naming its bag."""
    bag = tmp_path / 'session.mcap'
    bag.write_bytes(bag_path('pitches_90hz.mcap').read_bytes())
    truth_path(bag).write_text(truth_path(bag_path('pitches_360hz.mcap')).read_text())
    analysis = analyze_bag(bag, progress=False)
    assert analysis.truth is not None
    assert analysis.notes == ['session.truth.json was written for pitches_360hz.mcap, not '
                              'session.mcap: compared all the same (a renamed copy?)']
    assert analyze_bag(bag_path('pitches_90hz.mcap'), progress=False).notes == []


def test_no_truth_never_looks_for_a_truth_file(monkeypatch: pytest.MonkeyPatch) -> None:
    """``use_truth=False`` (``--no-truth``) does not even work out where the truth would be."""
    def refuse(bag: Any) -> Any:
        raise AssertionError(f'truth_path({bag}) called')
    monkeypatch.setattr(analyze_module, 'truth_path', refuse)
    analysis = analyze_bag(bag_path('pitches_90hz.mcap'), progress=False, use_truth=False)
    assert analysis.truth is None and len(analysis.impacts) == 8


def test_a_stream_too_slow_for_max_gap_is_not_called_another_clock(tmp_path: Path) -> None:
    """A bat at 10 Hz beside a 100 Hz ball: stamps overlap; the note names max_gap, not clocks."""
    bag = tmp_path / 'slow'
    reference_bag(bag, still_rows(100, 10, 100_000_000))
    analysis = analyze_bag(bag, AnalysisOptions(), progress=False)
    assert analysis.stats.intervals == 0
    assert analysis.stamp_spans == {'ball': (1_000_000_000, 1_990_000_000),
                                    'bat_pose': (1_000_000_000, 1_900_000_000)}
    assert len(analysis.notes) == 1 and 'do not overlap' not in analysis.notes[0]
    assert analysis.notes[0].startswith(
        'the ball and the bat were tracked at the same time (their stamps overlap) but nothing '
        'could be solved: no stretch had both streams stepping within max_gap (0.05 s; pauses '
        'in tracking: bat ')
    assert 'bat_pose /bat_pose' in analysis.notes[0]


def test_spans_and_frames_of_the_sample_loop_and_the_chunks_agree(tmp_path: Path) -> None:
    """Each role's stamp span and first frame: the same a chunk or a sample at a time."""
    bag = bag_path('pitches_90hz.mcap')
    chunked = analyze_bag(bag, AnalysisOptions(), progress=False)
    with BagWriter(tmp_path / 'out.mcap') as writer:
        sampled = analyze_bag(bag, AnalysisOptions(), progress=False, out_bag=writer)
    assert chunked.stamp_spans == sampled.stamp_spans and len(chunked.stamp_spans) == 2
    assert chunked.first_frames == sampled.first_frames == {'ball': 'world',
                                                            'bat_pose': 'world'}
    with BagReader(bag) as reader:
        stamps: Dict[str, List[int]] = {}
        for sample in reader.samples():
            stamps.setdefault(sample.role, []).append(sample.stamp_ns)
    assert chunked.stamp_spans == {role: (min(s), max(s)) for role, s in stamps.items()}


def test_header_stamps_all_zero_are_named_as_such(tmp_path: Path, run_cli: RunCli) -> None:
    """A tracker that leaves header.stamp at 0: the error says so and that stamps are needed."""
    topics = [('/ball', POINT_STAMPED), ('/bat_pose', POSE_STAMPED)]
    rows = [(topic, msgtype, 0, 'world', (0.1 * i, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
             10_000_000 * i + k) for i in range(20) for k, (topic, msgtype) in enumerate(topics)]
    bag = tmp_path / 'unstamped'
    reference_bag(bag, rows)
    code, _, stderr = run_cli(['analyze', str(bag), '--no-progress'])
    assert code == 2 and len(stderr.splitlines()) == 1
    assert 'every sample of /ball (20) and /bat_pose (20) was dropped (bad_stamp); their ' \
        'header stamps are zero' in stderr and 'needs real stamps' in stderr


@pytest.mark.parametrize('topic_flags, said', [
    (True, "ball_topic '/tracking/ball' (from the parameter file; --ball-topic overrides it) "
           'is not in the bag; topics: /ball'),
    (False, "ball_topic '/tracking/ball' (from the parameter file) is not in the bag; topics: "
            '/ball'),
])
def test_a_topic_error_names_where_the_topic_came_from(topic_flags: bool, said: str) -> None:
    """
    A topic the parameter file gave is named by its parameter; one a flag gave, by the flag.

    The reader names the topics as ``AnalysisOptions.named`` says (the caller with topic flags
    or without: the demo); the error's cause is a ``TopicError`` naming the role. Those words
    were made by rewriting the reader's message (``--ball-topic '/x'``) afterwards, and the
    demo rewrote that again with a regex to drop the flag.
    """
    bag = bag_path('pitches_90hz.mcap')
    from_file = AnalysisOptions(parameters={'ball_topic': 'tracking/ball'},
                                topic_flags=topic_flags)
    with pytest.raises(ToolError) as raised:
        analyze_bag(bag, from_file, progress=False)
    assert str(raised.value).startswith(said) and '\n' not in str(raised.value)
    assert isinstance(raised.value.__cause__, TopicError)
    assert raised.value.__cause__.role == 'ball'
    with pytest.raises(ToolError, match=r"^--ball-topic '/tracking/ball' is not in the bag"):
        analyze_bag(bag, replace(from_file, ball_topic='/tracking/ball'), progress=False)
    wrong_type = AnalysisOptions(parameters={'bat_pose_topic': '/ball'}, topic_flags=topic_flags)
    with pytest.raises(ToolError, match=r"^bat_pose_topic '/ball' \(from the parameter file"
                       r'(; --bat-pose-topic overrides it)?\) has type geometry_msgs/msg/'
                       'PointStamped; the bat_pose topic needs'):
        analyze_bag(bag, wrong_type, progress=False)


def test_options_and_paths_of_another_kind_are_an_error() -> None:
    """
    A parameter file's path or a list of pairs as parameters, None as the bag: one ToolError.

    Each raised AttributeError or TypeError from inside ``analyze_bag``.
    """
    for parameters in ('config/impact_node.yaml', [('model', 'linear')]):
        with pytest.raises(ToolError, match=r'takes node parameters by name .* '
                           r'\(a parameter file: load_parameters\(path\)\)'):
            AnalysisOptions(parameters=parameters)
    with pytest.raises(ToolError, match='path must be a bag path'):
        analyze_bag(None, progress=False)
