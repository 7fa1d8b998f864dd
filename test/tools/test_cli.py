"""
``baseball-collision`` end to end: simulate, analyze every bundled bag, outputs, bad input.

Accuracy bounds against the truth files (offline default model ``spline`` and the node's
``rigid``), measured on the bundled bags (maximum over the 8 contacts, spline / rigid):

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

import csv
import json
import os
from pathlib import Path
import shutil
import subprocess
import sys
from typing import Any, Dict, List, Tuple

from baseball_collision.bags import BagReader, BagWriter, POINT_STAMPED
from baseball_collision.tools.analysis import CSV_COLUMNS, output_topics, truth_path
from baseball_collision.tools.cli import main
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
from support.bundled import bag_path, BAGS, check_against_truth, PARAMS
from support.documents import differences

SCRIPT = Path(sys.executable).parent / 'baseball-collision'

IMPACT_KEYS = {'stamp_ns', 'point', 'normal', 'distance_from_knob_m', 'distance_from_tip_m',
               'sweet_spot_speed_mps', 'bat_speed_at_contact_mps', 'ball_speed_mps',
               'attack_angle_deg', 'bag', 'time_s', 'feature', 'bat_fraction'}
MISS_KEYS = {'stamp_ns', 'gap_m', 'gap_vector', 'bag', 'time_s', 'distance_from_tip_m'}


def run(argv: List[str], capsys: pytest.CaptureFixture) -> Tuple[int, str, str]:
    """Run main() in-process; return (exit code, stdout, stderr)."""
    try:
        code = main(argv)
    except SystemExit as exit_:  # argparse
        code = exit_.code
    captured = capsys.readouterr()
    return code, captured.out, captured.err


# ---- every bundled bag against its truth ----------------------------------------------------

@pytest.mark.parametrize('model', ['spline', 'rigid'])
@pytest.mark.parametrize('name', sorted(BAGS))
def test_bundled_bags_against_truth(name: str, model: str, tmp_path: Path,
                                    capsys: pytest.CaptureFixture) -> None:
    """Analyze finds every contact of every bundled bag, in time, and nothing else."""
    out = tmp_path / 'out.json'
    code, stdout, stderr = run(['analyze', str(bag_path(name)), '--params', str(PARAMS),
                                '--model', model, '--json', str(out)], capsys)
    assert code == 0, stderr
    document = json.loads(out.read_text())
    truth = json.loads(truth_path(bag_path(name)).read_text())
    check_against_truth(document, truth, BAGS[name])
    assert document['bags'][0]['model'] == model
    assert document['dropped'] == {}
    summary = document['bags'][0]['truth']
    assert summary['matched'] == summary['contacts'] == 8 and summary['false_impacts'] == []
    assert 'summary: 8 impacts, 4 near misses, 0 dropped' in stdout
    assert '8/8 contacts found, 0 missed, 0 false impacts' in stdout


def test_a_real_subprocess_with_csv_and_several_bags(tmp_path: Path) -> None:
    """The console script analyses several bags; CSV rows are the JSON events."""
    names = ['pitches_90hz.mcap', 'pitches_240hz_noisy.bag']
    env = dict(os.environ)
    env.pop('RMW_IMPLEMENTATION', None)
    done = subprocess.run(
        [str(SCRIPT), 'analyze'] + [str(bag_path(n)) for n in names]
        + ['--csv', str(tmp_path / 'e.csv'), '--json', str(tmp_path / 'e.json')],
        capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ''
    assert done.stdout.count('summary:') == 2 and 'total: 2 bags, 16 impacts' in done.stdout
    document = json.loads((tmp_path / 'e.json').read_text())
    assert [b['path'] for b in document['bags']] == [str(bag_path(n)) for n in names]
    with open(tmp_path / 'e.csv', newline='') as stream:
        rows = list(csv.DictReader(stream))
    assert tuple(rows[0].keys()) == CSV_COLUMNS
    impacts = [r for r in rows if r['event'] == 'impact']
    misses = [r for r in rows if r['event'] == 'near_miss']
    assert [int(r['stamp_ns']) for r in impacts] == [i['stamp_ns'] for i in document['impacts']]
    assert len(misses) == len(document['near_misses']) == 8
    first = document['impacts'][0]
    assert float(impacts[0]['sweet_spot_speed_mps']) == pytest.approx(
        first['sweet_spot_speed_mps'])
    assert float(impacts[0]['x']) == pytest.approx(first['point'][0])
    assert impacts[0]['gap_m'] == '' and misses[0]['sweet_spot_speed_mps'] == ''
    for name, truth_name in zip(names, (n for n in names)):
        truth = json.loads(truth_path(bag_path(truth_name)).read_text())
        mine = {'impacts': [i for i in document['impacts'] if i['bag'] == str(bag_path(name))],
                'near_misses': [m for m in document['near_misses']
                                if m['bag'] == str(bag_path(name))]}
        check_against_truth(mine, truth, BAGS[name])


def test_json_schema(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """The documented keys are there, with the documented types and units."""
    out = tmp_path / 'a.json'
    code, stdout, _ = run(['analyze', str(bag_path('pitches_360hz.mcap')), '--json', str(out),
                           '--quiet'], capsys)
    assert code == 0 and stdout == ''
    document = json.loads(out.read_text())
    assert set(document) >= {'format', 'impacts', 'near_misses', 'dropped', 'bags'}
    assert document['format'] == 'baseball_collision.analyze/1'
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
    assert set(bag) >= {'path', 'topics', 'model', 'messages', 'seconds', 'first_stamp_ns',
                        'impacts', 'near_misses', 'dropped', 'gaps', 'resets', 'truth'}
    assert bag['topics']['bat_pose'] == '/bat_pose' and bag['topics']['bat_input'] == 'pose'
    assert '/bat_knob' in bag['topics']['note']
    assert bag['messages'] == 3480 and bag['model'] == 'spline'


def test_knob_and_tip_topics_give_the_same_impacts(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture) -> None:
    """The bat as knob/tip points (flags) finds the same contacts as the pose."""
    bag = str(bag_path('pitches_360hz.mcap'))
    code, _, _ = run(['analyze', bag, '--json', str(tmp_path / 'pose.json')], capsys)
    assert code == 0
    code, stdout, _ = run(['analyze', bag, '--knob-topic', '/bat_knob', '--tip-topic',
                           '/bat_tip', '--json', str(tmp_path / 'points.json')], capsys)
    assert code == 0 and '/bat_knob + /bat_tip (knob/tip)' in stdout
    pose = json.loads((tmp_path / 'pose.json').read_text())['impacts']
    points = json.loads((tmp_path / 'points.json').read_text())['impacts']
    assert len(pose) == len(points) == 8
    for a, b in zip(pose, points):
        assert abs(a['stamp_ns'] - b['stamp_ns']) < 1000


def test_radius_flags_change_the_geometry(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """A bigger ball touches earlier; a thin constant-radius bat later."""
    bag = str(bag_path('pitches_360hz.mcap'))
    stamps = {}
    for label, flags in (('plain', []), ('big_ball', ['--ball-radius', '0.05']),
                         ('thin_bat', ['--bat-radius', '0.01'])):
        out = tmp_path / f'{label}.json'
        code, _, stderr = run(['analyze', bag, '--json', str(out), '--no-truth'] + flags,
                              capsys)
        assert code == 0, stderr
        stamps[label] = [i['stamp_ns'] for i in json.loads(out.read_text())['impacts']]
    barrel = stamps['plain'][0]  # the first pitch is a barrel hit
    assert stamps['big_ball'][0] < barrel
    assert stamps['thin_bat'][0] > barrel


def test_plots_are_pngs_one_per_impact(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """--plot writes one PNG per impact into a new directory."""
    plots = tmp_path / 'plots'
    code, _, stderr = run(['analyze', str(bag_path('pitches_90hz.mcap')), '--plot', str(plots)],
                          capsys)
    assert code == 0, stderr
    files = sorted(plots.iterdir())
    assert [f.name for f in files] == sorted(f'pitches_90hz_impact_{n}.png' for n in range(1, 9))
    for file in files:
        data = file.read_bytes()
        assert data.startswith(b'\x89PNG\r\n\x1a\n') and len(data) > 10_000


def test_out_bag_has_inputs_and_node_outputs(tmp_path: Path,
                                             capsys: pytest.CaptureFixture) -> None:
    """--out-bag: an MCAP with the input topics and the node's impact topics and types."""
    out = tmp_path / 'events.mcap'
    json_out = tmp_path / 'a.json'
    name = 'pitches_240hz_noisy.bag'
    code, _, stderr = run(['analyze', str(bag_path(name)), '--params', str(PARAMS),
                           '--out-bag', str(out), '--json', str(json_out)], capsys)
    assert code == 0, stderr
    document = json.loads(json_out.read_text())
    topics = output_topics()
    with AnyReader([out], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        assert types == {
            '/ball': POINT_STAMPED, '/bat_pose': 'geometry_msgs/msg/PoseStamped',
            topics['impact']: POINT_STAMPED,
            topics['impact_velocity']: 'geometry_msgs/msg/TwistStamped',
            topics['near_miss']: 'geometry_msgs/msg/Vector3Stamped'}
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
        tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """--predict: predictions in the report, JSON, CSV and the output bag, scored by lead."""
    json_out, csv_out, out = tmp_path / 'p.json', tmp_path / 'p.csv', tmp_path / 'p.mcap'
    name = 'pitches_360hz.mcap'
    code, stdout, stderr = run(['analyze', str(bag_path(name)), '--model', 'rigid', '--predict',
                                '--json', str(json_out), '--csv', str(csv_out),
                                '--out-bag', str(out)], capsys)
    assert code == 0, stderr
    assert 'predictions:' in stdout and 'error against the truth' in stdout
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
    code, stdout, _ = run(['analyze', str(bag_path(name)), '--model', 'rigid', '--json',
                           str(tmp_path / 'q.json')], capsys)
    assert code == 0 and 'predictions:' not in stdout
    assert 'predictions' not in json.loads((tmp_path / 'q.json').read_text())


# ---- simulate ------------------------------------------------------------------------------

@pytest.mark.parametrize('name, flags', [
    ('s.mcap', []), ('s.db3', []), ('s_dir', ['--storage', 'sqlite3']), ('s.bag', [])])
def test_simulate_round_trip(name: str, flags: List[str], tmp_path: Path,
                             capsys: pytest.CaptureFixture) -> None:
    """Simulate writes a bag and its truth; analyze finds the truth's contacts in it."""
    bag = tmp_path / name
    code, stdout, stderr = run(['simulate', str(bag), '--count', '4', '--rate', '200',
                                '--kinds', 'barrel,graze,miss_under,handle', '--seed', '7',
                                '--grid', '0.001', '--noise', '0.0001'] + flags, capsys)
    assert code == 0, stderr
    assert 'wrote' in stdout and '4 pitches (3 with contact)' in stdout
    truth = json.loads(truth_path(bag).read_text())
    assert truth['format'] == 'baseball_collision.truth/1'
    assert [p['kind'] for p in truth['pitches']] == ['barrel', 'graze', 'miss_under', 'handle']
    assert truth['topics'] == {'ball': '/ball', 'bat_pose': '/bat_pose', 'knob': '/bat_knob',
                               'tip': '/bat_tip'}
    assert truth['spec']['seed'] == 7 and 'simulate' in truth['command']
    starts = [p['start_ns'] for p in truth['pitches']]
    assert [b - a for a, b in zip(starts, starts[1:])] == [2_000_000_000] * 3
    with BagReader(bag) as reader:
        assert reader.topics == {'/ball': POINT_STAMPED,
                                 '/bat_pose': 'geometry_msgs/msg/PoseStamped',
                                 '/bat_knob': POINT_STAMPED, '/bat_tip': POINT_STAMPED}
        samples = list(reader.samples())
    assert {s.frame_id for s in samples} == {'world'}
    steps = {b.stamp_ns - a.stamp_ns for a, b in zip(samples, samples[1:])
             if a.role == b.role == 'ball' and b.stamp_ns - a.stamp_ns < 10**8}
    assert steps <= {4_000_000, 5_000_000, 6_000_000}  # 200 Hz on a millisecond grid
    assert truth['messages'] == len(samples) * 2  # only ball and pose were read
    out = tmp_path / 'a.json'
    code, _, _ = run(['analyze', str(bag), '--json', str(out)], capsys)
    assert code == 0
    check_against_truth(json.loads(out.read_text()), truth, 200.0)


def test_simulate_is_deterministic(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """Same seed, same truth; the bundled truth files regenerate from their commands."""
    for name in ('a.mcap', 'b.mcap'):
        assert run(['simulate', str(tmp_path / name), '--count', '2', '--seed', '3'],
                   capsys)[0] == 0
    a = json.loads((tmp_path / 'a.truth.json').read_text())
    b = json.loads((tmp_path / 'b.truth.json').read_text())
    assert a['pitches'] == b['pitches']  # same machine, same seed: bit for bit
    bundled = json.loads(truth_path(bag_path('pitches_90hz.mcap')).read_text())
    argv = bundled['command'].split()[1:]
    argv[1] = str(tmp_path / 'again.mcap')
    assert run(argv, capsys)[0] == 0
    again = json.loads((tmp_path / 'again.truth.json').read_text())
    # another machine or numpy build may differ in the last bits of a float, never in a stamp
    assert differences(again['pitches'], bundled['pitches']) == []


# ---- bad input: one line, exit 2, nothing written -------------------------------------------

def _empty_bag(path: Path) -> Path:
    with BagWriter(path) as writer:
        writer.add_topic('/ball', POINT_STAMPED)
    return path


def _unrelated_bag(path: Path) -> Path:
    with BagWriter(path) as writer:
        writer.write_point('/chatter', 1, 'world', (0.0, 0.0, 0.0))
    return path


def _truncated(path: Path) -> Path:
    data = bag_path('pitches_90hz.mcap').read_bytes()
    path.write_bytes(data[:len(data) // 2])
    return path


def _corrupt_ros1(path: Path) -> Path:
    data = bytearray(bag_path('pitches_240hz_noisy.bag').read_bytes())
    data[200_000:200_400] = b'\xab' * 400
    path.write_bytes(bytes(data))
    return path


def _corrupt_sqlite(path: Path) -> Path:
    shutil.copytree(bag_path('pitches_120hz_sqlite3'), path)
    db3 = path / 'pitches_120hz_sqlite3.db3'
    data = bytearray(db3.read_bytes())
    data[100_000:104_000] = b'\xab' * 4000
    db3.write_bytes(bytes(data))
    return path


def _random(path: Path) -> Path:
    path.write_bytes(os.urandom(4096))
    return path


def _file(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


BAD_BAGS = {
    'missing': (lambda d: d / 'missing.mcap', 'bag not found'),
    'empty': (lambda d: _empty_bag(d / 'empty.mcap'), 'contains no messages'),
    'zero_bytes': (lambda d: _file(d / 'zero.mcap', b''), 'cannot read bag'),
    'random': (lambda d: _random(d / 'random.mcap'), 'cannot read bag'),
    'truncated': (lambda d: _truncated(d / 'truncated.mcap'), 'cannot read bag'),
    'corrupt_ros1': (lambda d: _corrupt_ros1(d / 'corrupt.bag'), 'cannot read bag'),
    'corrupt_sqlite': (lambda d: _corrupt_sqlite(d / 'corrupt_dir'), 'cannot read bag'),
    'no_topics': (lambda d: _unrelated_bag(d / 'chatter.mcap'), 'no ball topic found'),
    'not_a_bag': (lambda d: _file(d / 'notes.txt', b'x'), 'not a bag'),
}


def _listing(directory: Path) -> List[str]:
    return sorted(str(p.relative_to(directory)) for p in directory.rglob('*'))


def _all_outputs(directory: Path) -> List[str]:
    return ['--json', str(directory / 'o.json'), '--csv', str(directory / 'o.csv'),
            '--plot', str(directory / 'plots'), '--out-bag', str(directory / 'o.mcap')]


@pytest.mark.parametrize('case', sorted(BAD_BAGS))
def test_bad_bags(case: str, tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """A bag that cannot be analysed: one error line, exit 2, no output file at all."""
    make, words = BAD_BAGS[case]
    bag = make(tmp_path)
    before = _listing(tmp_path)
    code, stdout, stderr = run(['analyze', str(bag)] + _all_outputs(tmp_path), capsys)
    assert code == 2
    assert stderr.count('\n') == 1 and stderr.startswith('baseball-collision: error: ')
    assert words in stderr
    assert _listing(tmp_path) == before  # not even a hidden temporary
    assert stdout == ''


def test_a_bad_second_bag_leaves_no_output(tmp_path: Path,
                                           capsys: pytest.CaptureFixture) -> None:
    """The first bag analysed fine, the second is corrupt: still nothing is written."""
    bad = _truncated(tmp_path / 't.mcap')
    before = _listing(tmp_path)
    code, _, stderr = run(['analyze', str(bag_path('pitches_90hz.mcap')), str(bad)]
                          + _all_outputs(tmp_path)[:6], capsys)
    assert code == 2 and stderr.count('\n') == 1
    assert _listing(tmp_path) == before


@pytest.mark.parametrize('flags, words', [
    (['--bat-pose-topic', '/ball'], "--bat-pose-topic '/ball' has type"),
    (['--ball-topic', '/nope'], "--ball-topic '/nope' is not in the bag"),
    (['--knob-topic', '/bat_knob', '--bat-pose-topic', '/bat_pose'], 'not both'),
    (['--params', 'missing.yaml'], 'cannot read parameter file'),
    (['--ball-radius', '-1'], "'-1' must be a finite number > 0"),
    (['--model', 'cubic'], "invalid choice: 'cubic'"),
])
def test_bad_flags(flags: List[str], words: str, tmp_path: Path,
                   capsys: pytest.CaptureFixture) -> None:
    """Wrong topics, types or values: one error line naming the flag, exit 2."""
    before = _listing(tmp_path)
    code, _, stderr = run(['analyze', str(bag_path('pitches_90hz.mcap'))] + flags
                          + _all_outputs(tmp_path), capsys)
    assert code == 2
    assert stderr.count('\n') == 1 and stderr.startswith('baseball-collision: error: ')
    assert words in stderr
    assert _listing(tmp_path) == before


@pytest.mark.parametrize('flag', ['--json', '--csv', '--plot', '--out-bag'])
def test_existing_outputs_are_refused(flag: str, tmp_path: Path,
                                      capsys: pytest.CaptureFixture) -> None:
    """An output that exists: error before any work, the file untouched, nothing else made."""
    existing = tmp_path / 'exists'
    existing.write_text('keep me')
    others = list(_all_outputs(tmp_path))
    index = others.index(flag)
    others[index + 1] = str(existing)
    before = _listing(tmp_path)
    code, _, stderr = run(['analyze', str(bag_path('pitches_90hz.mcap'))] + others, capsys)
    assert code == 2 and stderr.count('\n') == 1
    assert f'output {existing} exists already' in stderr
    assert existing.read_text() == 'keep me'
    assert _listing(tmp_path) == before


def test_simulate_refuses_existing_outputs(tmp_path: Path,
                                           capsys: pytest.CaptureFixture) -> None:
    """Simulate over an existing bag or truth file: exit 2, nothing changed."""
    (tmp_path / 'a.mcap').write_text('x')
    (tmp_path / 'b.truth.json').write_text('x')
    for name in ('a.mcap', 'b.mcap'):
        before = _listing(tmp_path)
        code, _, stderr = run(['simulate', str(tmp_path / name), '--count', '1'], capsys)
        assert code == 2 and 'exists already' in stderr and stderr.count('\n') == 1
        assert _listing(tmp_path) == before
    code, _, stderr = run(['simulate', str(tmp_path / 'c.mcap'), '--storage', 'rosbag1'],
                          capsys)
    assert code == 2 and stderr.count('\n') == 1
    code, _, stderr = run(['simulate', str(tmp_path / 'd.mcap'), '--kinds', 'bunt'], capsys)
    assert code == 2 and 'unknown kind(s) bunt' in stderr
    assert not (tmp_path / 'c.mcap').exists() and not (tmp_path / 'd.mcap').exists()


def test_replay_of_a_missing_bag(capsys: pytest.CaptureFixture) -> None:
    """Replay a bag that is not there: one line, exit 2."""
    code, _, stderr = run(['replay', 'no/such.mcap'], capsys)
    assert code == 2 and stderr == 'baseball-collision: error: bag not found: no/such.mcap\n'


@pytest.mark.parametrize('command', [[], ['simulate'], ['analyze'], ['replay'], ['demo']])
def test_help_on_every_subcommand(command: List[str], capsys: pytest.CaptureFixture) -> None:
    """--help prints usage and exits 0 for the program and every subcommand."""
    code, stdout, _ = run(command + ['--help'], capsys)
    assert code == 0 and stdout.startswith('usage: baseball-collision')
