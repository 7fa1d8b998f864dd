"""``simulate``: a bag of simulated pitches with its truth file, and analyze finds the truth."""

import json
import math
from pathlib import Path
from typing import Callable, List, Tuple

from baseball_collision.bags import BagReader, POINT_STAMPED
from baseball_collision.errors import ToolError
from baseball_collision.tools.recording import RecordingSpec
from baseball_collision.tools.truth import truth_path
import numpy as np
import pytest
from support.bundled import bag_path, check_against_truth
from support.documents import differences

RunCli = Callable[[List[str]], Tuple[int, str, str]]


@pytest.mark.parametrize('name, flags', [
    ('s.mcap', []), ('s.db3', []), ('s_dir', ['--storage', 'sqlite3']), ('s.bag', [])])
def test_simulate_round_trip(name: str, flags: List[str], tmp_path: Path,
                             run_cli: RunCli) -> None:
    """Simulate writes a bag and its truth; analyze finds the truth's contacts in it."""
    bag = tmp_path / name
    code, stdout, stderr = run_cli(['simulate', str(bag), '--count', '4', '--rate', '200',
                                    '--kinds', 'barrel,graze,miss_under,handle', '--seed', '7',
                                    '--grid', '0.001', '--noise', '0.0001'] + flags)
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
    code, _, _ = run_cli(['analyze', str(bag), '--json', str(out)])
    assert code == 0
    check_against_truth(json.loads(out.read_text()), truth, 200.0)


def test_simulate_a_family_of_real_hits(tmp_path: Path, run_cli: RunCli) -> None:
    """
    ``--family rebound``: the ball leaves the bat at each hit, and analyze finds every hit.

    The frames after a hit show the ball going away (tens of m/s off its pitch), which no path
    through them reaches the bat from (``core.detector.departure``).
    """
    bag = tmp_path / 'hits.mcap'
    code, _, stderr = run_cli(['simulate', str(bag), '--count', '4', '--family', 'rebound',
                               '--kinds', 'barrel,handle,end_cap,miss_over', '--seed', '5'])
    assert code == 0, stderr
    truth = json.loads(truth_path(bag).read_text())
    assert truth['spec']['family'] == 'rebound'
    with BagReader(bag) as reader:
        balls = [s for s in reader.samples() if s.role == 'ball']
    hit = truth['pitches'][0]
    after = [s for s in balls if hit['stamp_ns'] < s.stamp_ns < hit['end_ns']]
    assert after[1].values[1] > after[0].values[1]  # going back toward the pitcher (+y)
    out = tmp_path / 'a.json'
    code, _, _ = run_cli(['analyze', str(bag), '--json', str(out)])
    assert code == 0
    check_against_truth(json.loads(out.read_text()), truth, 360.0)
    assert run_cli(['simulate', str(tmp_path / 'x.mcap'), '--family', 'curved'])[0] != 0


def test_simulate_spinning_pitches(tmp_path: Path, run_cli: RunCli) -> None:
    """
    ``--spin``: the same contacts as without it, the balls' flights bent; analyze finds them.

    The ball's acceleration (second differences of its exact samples 5 frames apart) is off
    gravity and drag by more than 1 m/s^2; each pitch meets the bat when and where it does
    without ``--spin`` (the same seed: the spin is drawn aside), and analyze finds every contact
    (its flight fits assume neither gravity nor spin) and predicts each hit 20 ms ahead.
    """
    bags = {}
    for name, flags in (('spin', ['--spin']), ('plain', [])):
        bags[name] = tmp_path / f'{name}.mcap'
        code, _, stderr = run_cli(['simulate', str(bags[name]), '--count', '3', '--jitter', '0',
                                   '--kinds', 'barrel,handle,miss_over', '--seed', '3'] + flags)
        assert code == 0, stderr
    truth = json.loads(truth_path(bags['spin']).read_text())
    plain = json.loads(truth_path(bags['plain']).read_text())
    assert truth['spec']['spin'] is True and plain['spec']['spin'] is False
    for pitch, twin in zip(truth['pitches'], plain['pitches']):
        assert pitch['contact'] == twin['contact']
        assert abs(pitch['min_gap_m'] - twin['min_gap_m']) < 1e-5  # (the bent path's own)
        if pitch['contact']:
            assert abs(pitch['stamp_ns'] - twin['stamp_ns']) < 1000
    with BagReader(bags['spin']) as reader:
        balls = [s for s in reader.samples() if s.role == 'ball']
    pitch = [s for s in balls if s.stamp_ns < truth['pitches'][0]['stamp_ns']]
    p = np.array([s.values for s in pitch[-11::5]])
    h = (pitch[-6].stamp_ns - pitch[-11].stamp_ns) * 1e-9
    acceleration = (p[2] - 2.0 * p[1] + p[0]) / (h * h)
    speed = np.linalg.norm((p[2] - p[0]) / (2.0 * h))
    drag = 0.0061 * speed * (p[2] - p[0]) / (2.0 * h)
    assert np.linalg.norm(acceleration - np.array([0.0, 0.0, -9.80665]) + drag) > 1.0
    out = tmp_path / 'a.json'
    assert run_cli(['analyze', str(bags['spin']), '--json', str(out), '--predict'])[0] == 0
    document = json.loads(out.read_text())
    check_against_truth(document, truth, 360.0)
    assert all(impact['prediction_errors']['20'] is not None for impact in document['impacts'])
    assert run_cli(['simulate', str(tmp_path / 'x.mcap'), '--spin', 'yes'])[0] != 0


def test_simulate_a_ball_slower_than_the_bat(tmp_path: Path, run_cli: RunCli) -> None:
    """``--ball-rate``: the ball at its own rate beside the bat's; analyze finds every contact."""
    bag = tmp_path / 'arm.mcap'
    code, stdout, stderr = run_cli(['simulate', str(bag), '--count', '3', '--rate', '1000',
                                    '--grid', '0.001', '--ball-rate', '60', '--bat', 'pose',
                                    '--kinds', 'barrel,handle,miss_over', '--seed', '4'])
    assert code == 0, stderr
    assert 'at 1000 Hz, the ball at 60 Hz on /ball, /bat_pose' in stdout
    truth = json.loads(truth_path(bag).read_text())
    assert truth['spec']['ball_rate_hz'] == 60.0 and truth['spec']['rate_hz'] == 1000.0
    with BagReader(bag) as reader:
        samples = list(reader.samples())
    counts = {}
    for role, low, high in (('ball', 15_000_000, 18_000_000), ('bat_pose', 1_000_000, 2_000_000)):
        stamps = [s.stamp_ns for s in samples if s.role == role]
        steps = {b - a for a, b in zip(stamps, stamps[1:]) if b - a < 10**8}
        assert low <= min(steps) and max(steps) <= high, role  # (jitter on a 1 ms grid)
        counts[role] = len(stamps)
    assert counts['bat_pose'] > 14 * counts['ball']
    out = tmp_path / 'a.json'
    assert run_cli(['analyze', str(bag), '--json', str(out)])[0] == 0
    check_against_truth(json.loads(out.read_text()), truth, 60.0)
    with pytest.raises(ToolError, match='ball_rate_hz'):
        RecordingSpec(ball_rate_hz=0.0).check()


def test_simulate_noise_on_one_body(tmp_path: Path, run_cli: RunCli) -> None:
    """
    ``--noise-on ball``: an arm's exact bat beside a noisy ball; analyze finds every contact.

    Same seed and noise: the ball's messages are those of ``--noise-on both`` (the same draws),
    the bat's differ from them; ``--noise-on bat`` shakes the bat, not the ball.
    """
    def messages(on: str) -> Tuple[Path, dict]:
        bag = tmp_path / f'{on}.mcap'
        code, _, stderr = run_cli(['simulate', str(bag), '--count', '3', '--rate', '240',
                                   '--noise', '0.001', '--noise-on', on, '--seed', '8',
                                   '--kinds', 'barrel,handle,miss_over'])
        assert code == 0, stderr
        with BagReader(bag) as reader:
            found: dict = {}
            for sample in reader.samples():
                found.setdefault(sample.role, []).append((sample.stamp_ns, sample.values))
        return bag, found

    ball_bag, on_ball = messages('ball')
    _, on_both = messages('both')
    _, on_bat = messages('bat')
    assert on_ball['ball'] == on_both['ball'] != on_bat['ball']
    assert on_ball['bat_pose'] != on_both['bat_pose'] == on_bat['bat_pose']  # (the pose read)
    truth = json.loads(truth_path(ball_bag).read_text())
    assert truth['spec']['noise_on'] == 'ball' and truth['spec']['noise_m'] == 0.001
    out = tmp_path / 'a.json'
    assert run_cli(['analyze', str(ball_bag), '--json', str(out)])[0] == 0
    check_against_truth(json.loads(out.read_text()), truth, 240.0)
    assert run_cli(['simulate', str(tmp_path / 'x.mcap'), '--noise-on', 'glove'])[0] != 0
    with pytest.raises(ToolError, match='noise_on'):
        RecordingSpec(noise_on='glove').check()


def test_simulate_markers_with_their_own_noise(tmp_path: Path, run_cli: RunCli) -> None:
    """
    ``--marker-spread 0.3``: knob and tip markers shaken apart, as a mocap rig's are.

    Without it one draw shakes the whole bat: its knob-tip length stays exact (auto reads the
    noise from the knob's own differences then). With it the length changes by the markers'
    noise, and auto reads about the noise from knob and tip points and from the pose.
    """
    def recorded(*flags: str) -> Tuple[float, dict]:
        bag = tmp_path / f'{len(list(tmp_path.iterdir()))}.mcap'
        assert run_cli(['simulate', str(bag), '--count', '2', '--rate', '240', '--noise',
                        '0.001', '--seed', '9', *flags])[0] == 0
        truth = json.loads(truth_path(bag).read_text())
        assert truth['spec']['marker_spread_m'] == (0.3 if flags else None)
        found = {}
        points = ['--knob-topic', '/bat_knob', '--tip-topic', '/bat_tip']
        for name, topics in (('pose', []), ('points', points)):
            out = bag.with_suffix(f'.{name}.json')
            assert run_cli(['analyze', str(bag), *topics, '--json', str(out), '--quiet'])[0] == 0
            found[name] = json.loads(out.read_text())['bags'][0]['tracker_noise']['bat_m']
        with BagReader(bag, knob='/bat_knob', tip='/bat_tip') as reader:
            ends: dict = {}
            for each in reader.samples():
                ends.setdefault(each.stamp_ns, {})[each.role] = each.values
        lengths = [math.dist(pair['knob'], pair['tip']) for pair in ends.values()
                   if {'knob', 'tip'} <= set(pair)]
        return float(np.std(lengths)), found

    spread, shared = recorded()
    assert spread < 1e-9  # the length exact
    assert shared['points'] == pytest.approx(1e-3, rel=0.3)
    assert shared['pose'] == pytest.approx(1e-3, rel=0.3)
    spread, markers = recorded('--marker-spread', '0.3')
    assert spread == pytest.approx(math.sqrt(2.0) * 1e-3, rel=0.2)  # along the bat: two ends
    assert markers['points'] == pytest.approx(1e-3, rel=0.2)
    assert markers['pose'] == pytest.approx(1e-3, rel=0.3)
    with pytest.raises(ToolError, match='marker_spread_m'):
        RecordingSpec(marker_spread_m=0.0).check()


def test_simulate_is_deterministic(tmp_path: Path, run_cli: RunCli) -> None:
    """Same seed, same truth; the bundled truth files regenerate from their commands."""
    for name in ('a.mcap', 'b.mcap'):
        assert run_cli(['simulate', str(tmp_path / name), '--count', '2', '--seed', '3'])[0] == 0
    a = json.loads((tmp_path / 'a.truth.json').read_text())
    b = json.loads((tmp_path / 'b.truth.json').read_text())
    assert a['pitches'] == b['pitches']  # same machine, same seed: bit for bit
    for name in ('pitches_90hz.mcap', 'pitches_180hz_rebound.mcap'):
        bundled = json.loads(truth_path(bag_path(name)).read_text())
        argv = bundled['command'].split()[1:]
        argv[1] = str(tmp_path / f'again-{name}')
        assert run_cli(argv)[0] == 0
        again = json.loads(truth_path(tmp_path / f'again-{name}').read_text())
        # another machine or numpy build may differ in the last bits of a float, never in a
        # stamp
        assert differences(again['pitches'], bundled['pitches']) == []


@pytest.mark.parametrize('flags, words', [
    (['--seed', '-1'], "'-1' must be from 0 to 2^64 - 1"),
    (['--seed', str(2 ** 64)], 'must be from 0 to 2^64 - 1'),
    (['--spacing', '1e30', '--count', '2'], 'would end after the latest stamp a ROS header'),
    (['--spacing', '1e8', '--count', '10'], 'lower spacing or count'),
    (['--rate', '1e12'], "'1e12' must be at most 100000 (Hz)"),
])
def test_simulate_refuses_what_it_cannot_make(tmp_path: Path, run_cli: RunCli,
                                              flags: List[str], words: str) -> None:
    """A negative seed, stamps past 2038, a terahertz tracker: one line, exit 2, no file."""
    code, stdout, stderr = run_cli(['simulate', str(tmp_path / 'x.mcap'), *flags])
    assert code == 2 and stdout == '' and words in stderr and len(stderr.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ToolError):
        RecordingSpec(seed=-1).check()
    with pytest.raises(ToolError, match='at most 100,000 Hz'):
        RecordingSpec(rate_hz=1e12).check()


def test_simulate_plan_writes_the_arms_plans(tmp_path: Path, run_cli: RunCli) -> None:
    """``--plan HZ``: a plan a pitch on /bat_plan, named in the truth; a bad rate is refused."""
    bag = tmp_path / 'arm.mcap'
    code, stdout, stderr = run_cli(['simulate', str(bag), '--count', '2', '--plan', '100'])
    assert code == 0, stderr
    assert '/bat_plan' in stdout
    assert json.loads(truth_path(bag).read_text())['topics']['bat_plan'] == '/bat_plan'
    with BagReader(bag) as reader:
        plans = reader.plans('/bat_plan')
    assert len(plans) == 2 and plans[0].stamps_ns[1] - plans[0].stamps_ns[0] == 10_000_000
    for rate in (0.0, -5.0, math.inf, 1e9):
        with pytest.raises(ToolError, match='plan_hz must be above 0'):
            RecordingSpec(plan_hz=rate).check()
