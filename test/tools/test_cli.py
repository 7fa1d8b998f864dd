"""
``baseball-collision`` end to end: the console script and its bad-input contract.

Bad input (a bag that cannot be read, wrong flags, an existing output, any error of the
package) ends in one line on stderr and exit code 2, with no output written at all.
"""

import csv
import json
import os
from pathlib import Path
import shutil
import subprocess
import sys
from typing import Callable, List, Tuple

from baseball_collision import __version__
from baseball_collision.bags import BagWriter, POINT_STAMPED
from baseball_collision.errors import CoreError
from baseball_collision.tools import many_bags
from baseball_collision.tools.report import CSV_COLUMNS
from baseball_collision.tools.truth import truth_path
import pytest
from support import modules_loaded, REPO_ROOT
from support.bundled import bag_path, BAGS, check_against_truth

SCRIPT = Path(sys.executable).parent / 'baseball-collision'
RunCli = Callable[[List[str]], Tuple[int, str, str]]


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
    assert float(impacts[0]['contact_x']) == pytest.approx(first['point'][0])
    assert impacts[0]['gap_m'] == '' and misses[0]['sweet_spot_speed_mps'] == ''
    for name, truth_name in zip(names, (n for n in names)):
        truth = json.loads(truth_path(bag_path(truth_name)).read_text())
        mine = {'impacts': [i for i in document['impacts'] if i['bag'] == str(bag_path(name))],
                'near_misses': [m for m in document['near_misses']
                                if m['bag'] == str(bag_path(name))]}
        check_against_truth(mine, truth, BAGS[name])


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
def test_bad_bags(case: str, tmp_path: Path, run_cli: RunCli) -> None:
    """A bag that cannot be analysed: one error line, exit 2, no output file at all."""
    make, words = BAD_BAGS[case]
    bag = make(tmp_path)
    before = _listing(tmp_path)
    code, stdout, stderr = run_cli(['analyze', str(bag)] + _all_outputs(tmp_path))
    assert code == 2
    assert stderr.count('\n') == 1 and stderr.startswith('baseball-collision: error: ')
    assert words in stderr
    assert _listing(tmp_path) == before  # not even a hidden temporary
    assert stdout == ''


def test_a_bad_second_bag_leaves_no_output(tmp_path: Path,
                                           run_cli: RunCli) -> None:
    """The first bag analysed fine, the second is corrupt: still nothing is written."""
    bad = _truncated(tmp_path / 't.mcap')
    before = _listing(tmp_path)
    code, _, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap')), str(bad)]
                              + _all_outputs(tmp_path)[:6])
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
                   run_cli: RunCli) -> None:
    """Wrong topics, types or values: one error line naming the flag, exit 2."""
    before = _listing(tmp_path)
    code, _, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap'))] + flags
                              + _all_outputs(tmp_path))
    assert code == 2
    assert stderr.count('\n') == 1 and stderr.startswith('baseball-collision: error: ')
    assert words in stderr
    assert _listing(tmp_path) == before


@pytest.mark.parametrize('flag', ['--json', '--csv'])
def test_a_document_to_standard_output(flag: str, tmp_path: Path, run_cli: RunCli) -> None:
    """``--json -`` or ``--csv -``: the document alone on stdout (no table, no file '-')."""
    bag = str(bag_path('pitches_90hz.mcap'))
    code, stdout, stderr = run_cli(['analyze', bag, flag, '-'])
    assert code == 0 and stderr == '' and not Path('-').exists()
    written = tmp_path / 'out'
    assert run_cli(['analyze', bag, flag, str(written), '--quiet'])[0] == 0
    if flag == '--csv':
        assert stdout == written.read_text()
    else:  # the same document but the run's own time
        documents = [json.loads(text) for text in (stdout, written.read_text())]
        for document in documents:
            for each in document['bags']:
                each.pop('seconds')
        assert documents[0] == documents[1]
    code, stdout, stderr = run_cli(['analyze', bag, '--json', '-', '--csv', '-'])
    assert code == 2 and stdout == '' and 'only one of --json and --csv can be -' in stderr


def test_unknown_parameters_in_a_params_file_are_named(tmp_path: Path,
                                                       run_cli: RunCli) -> None:
    """Typos in ``--params``: a note naming each with the nearest name; the rest runs."""
    params = tmp_path / 'typos.yaml'
    params.write_text('/**:\n  ros__parameters:\n    modle: linear\n    tracker_noize: 0.001\n'
                      '    use_sim_time: true\n    qos_overrides./ball.subscription.depth: 5\n'
                      '    model: rigid\n')
    code, stdout, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap')), '--params',
                                    str(params), '--no-progress'])
    assert code == 0 and stderr == ''
    assert stdout.splitlines()[-1] == (
        'note: ignoring unknown parameter(s) modle (did you mean model?), '
        'tracker_noize (did you mean tracker_noise?): not parameters of impact_node (see '
        'config/impact_node.yaml)')
    assert 'model rigid' in stdout


@pytest.mark.parametrize('flag', ['--json', '--csv', '--plot', '--out-bag'])
def test_existing_outputs_are_refused(flag: str, tmp_path: Path,
                                      run_cli: RunCli) -> None:
    """An output that exists: error before any work, the file untouched, nothing else made."""
    existing = tmp_path / 'exists'
    existing.write_text('keep me')
    others = list(_all_outputs(tmp_path))
    index = others.index(flag)
    others[index + 1] = str(existing)
    before = _listing(tmp_path)
    code, _, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap'))] + others)
    assert code == 2 and stderr.count('\n') == 1
    assert f'output {existing} exists already' in stderr
    assert existing.read_text() == 'keep me'
    assert _listing(tmp_path) == before


def test_simulate_refuses_existing_outputs(tmp_path: Path,
                                           run_cli: RunCli) -> None:
    """Simulate over an existing bag or truth file: exit 2, nothing changed."""
    (tmp_path / 'a.mcap').write_text('x')
    (tmp_path / 'b.truth.json').write_text('x')
    for name in ('a.mcap', 'b.mcap'):
        before = _listing(tmp_path)
        code, _, stderr = run_cli(['simulate', str(tmp_path / name), '--count', '1'])
        assert code == 2 and 'exists already' in stderr and stderr.count('\n') == 1
        assert _listing(tmp_path) == before
    code, _, stderr = run_cli(['simulate', str(tmp_path / 'c.mcap'), '--storage', 'rosbag1'])
    assert code == 2 and stderr.count('\n') == 1
    code, _, stderr = run_cli(['simulate', str(tmp_path / 'd.mcap'), '--kinds', 'bunt'])
    assert code == 2 and 'unknown kind(s) bunt' in stderr
    assert not (tmp_path / 'c.mcap').exists() and not (tmp_path / 'd.mcap').exists()


def test_replay_of_a_missing_bag(run_cli: RunCli) -> None:
    """Replay a bag that is not there: one line, exit 2."""
    code, _, stderr = run_cli(['replay', 'no/such.mcap'])
    assert code == 2 and stderr == 'baseball-collision: error: bag not found: no/such.mcap\n'


def test_any_package_error_is_one_line(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                       run_cli: RunCli) -> None:
    """An error of any layer (here the core's) ends in one line and exit 2, nothing written."""
    def refuse(*args: object, **kwargs: object) -> None:
        raise CoreError('max_gap must be > 0')
    monkeypatch.setattr(many_bags, 'analyze_bags', refuse)  # the cli imports it when it runs
    code, stdout, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap'))]
                                   + _all_outputs(tmp_path))
    assert code == 2 and stdout == ''
    assert stderr == 'baseball-collision: error: max_gap must be > 0\n'
    assert _listing(tmp_path) == []


@pytest.mark.parametrize('command', [[], ['simulate'], ['analyze'], ['replay'], ['demo']])
def test_help_on_every_subcommand(command: List[str], run_cli: RunCli) -> None:
    """--help prints usage and exits 0 for the program and every subcommand."""
    code, stdout, _ = run_cli(command + ['--help'])
    assert code == 0 and stdout.startswith('usage: baseball-collision')


def test_options_may_stand_between_the_bags(tmp_path: Path, run_cli: RunCli) -> None:
    """``analyze BAG1 --json o.json BAG2``: both bags analysed (not 'unrecognized arguments')."""
    out = tmp_path / 'o.json'
    first, second = bag_path('pitches_90hz.mcap'), bag_path('pitches_240hz_noisy.bag')
    code, stdout, stderr = run_cli(['analyze', str(first), '--json', str(out), str(second),
                                    '--quiet', '--jobs', '1'])
    assert (code, stdout, stderr) == (0, '', '')
    paths = [bag['path'] for bag in json.loads(out.read_text())['bags']]
    assert paths == [str(first), str(second)]


def test_double_dash_ends_the_options_between_the_bags(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, run_cli: RunCli) -> None:
    """
    After ``--`` every argument is a bag, even one named like an option.

    ``analyze --quiet -- BAG --json j.json`` wrote j.json: argparse's intermixed parsing took
    the option after ``--`` when no bag stood before it.
    """
    monkeypatch.chdir(tmp_path)
    shutil.copyfile(bag_path('pitches_90hz.mcap'), tmp_path / '--odd.mcap')
    first = str(bag_path('pitches_90hz.mcap'))
    code, stdout, stderr = run_cli(['analyze', '--quiet', '--', first, '--json', 'j.json'])
    assert (code, stdout) == (2, '') and stderr == 'baseball-collision: error: bag not found: ' \
        '--json (--keep-going skips a bag that cannot be analysed and goes on with the others)\n'
    assert not (tmp_path / 'j.json').exists()
    code, stdout, stderr = run_cli(['analyze', first, '--json', 'o.json', '--quiet', '--jobs',
                                    '1', '--', '--odd.mcap'])
    assert (code, stdout, stderr) == (0, '', '')
    assert [bag['path'] for bag in json.loads((tmp_path / 'o.json').read_text())['bags']] == [
        first, '--odd.mcap']


def test_an_unknown_option_between_the_bags_is_named_alone(run_cli: RunCli) -> None:
    """``analyze A --bogus B``: 'unrecognized arguments: --bogus', not '--bogus B'."""
    code, stdout, stderr = run_cli(['analyze', 'a.mcap', '--bogus', 'b.bag', '--bogus2=3'])
    assert (code, stdout) == (2, '')
    assert stderr == ('baseball-collision: error: unrecognized arguments: --bogus --bogus2=3 '
                      '(see baseball-collision analyze --help)\n')


@pytest.mark.parametrize('argv, command', [
    (['analyze', 'a.mcap', '--bogus'], 'analyze'), (['analyze'], 'analyze'),
    (['analyze', 'a.mcap', '--jobs', 'x'], 'analyze'), (['simulate', 'x.mcap', 'y'], 'simulate'),
    (['replay'], 'replay'), (['demo', '--rate'], 'demo'), (['bogus'], '')])
def test_a_usage_error_points_to_the_help_of_its_command(argv: List[str], command: str,
                                                         run_cli: RunCli) -> None:
    """One line pointing to ``baseball-collision analyze --help``, not the program's help."""
    code, stdout, stderr = run_cli(argv)
    program = ' '.join(['baseball-collision', command]).strip()
    assert code == 2 and stdout == '' and len(stderr.splitlines()) == 1
    assert stderr.startswith('baseball-collision: error: ')
    assert stderr.endswith(f'(see {program} --help)\n'), stderr


def test_help_says_what_a_missing_prediction_means(run_cli: RunCli) -> None:
    """The analyze help explains the '-' of a --predict lead cell."""
    code, stdout, _ = run_cli(['analyze', '--help'])
    assert code == 0
    assert "'-' where no prediction was in force that far ahead" in ' '.join(stdout.split())


def test_demo_domain_is_chosen_or_refused(run_cli: RunCli) -> None:
    """The demo runs on --domain 0-101 when given (to watch it in RViz); others exit 2."""
    from baseball_collision.tools.cli import build_parser
    assert build_parser().parse_args(['demo', '--domain', '7']).domain == 7
    assert build_parser().parse_args(['demo']).domain is None
    code, _, stderr = run_cli(['demo', '--domain', '102'])
    assert code == 2 and "'102' must be a ROS domain id from 0 to 101" in stderr


def test_version(run_cli: RunCli) -> None:
    """--version prints the package's version."""
    code, stdout, _ = run_cli(['--version'])
    assert code == 0 and stdout == f'baseball-collision {__version__}\n'


WITHOUT_ROSBAGS = """
import importlib.abc, sys
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] == 'rosbags':
            raise ModuleNotFoundError(f"No module named '{name}'", name=name)
sys.meta_path.insert(0, Block())
from baseball_collision.tools.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_help_works_without_rosbags_and_analyze_says_what_is_missing() -> None:
    """Where rosbags is not installed: --help works; analyze names the package in one line."""
    def run(*argv: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, '-c', WITHOUT_ROSBAGS, *argv], cwd=REPO_ROOT,
                              capture_output=True, text=True, timeout=120)

    for argv in (['--help'], ['analyze', '--help'], ['simulate', '--help']):
        shown = run(*argv)
        assert shown.returncode == 0 and 'usage: baseball-collision' in shown.stdout, argv
    failed = run('analyze', 'bags/pitches_90hz.mcap')
    assert failed.returncode == 2 and failed.stdout == ''
    assert failed.stderr == ('baseball-collision: error: analyze needs the Python package '
                             "'rosbags', which is not installed (pip install rosbags)\n")


def test_starting_the_command_line_imports_no_simulator() -> None:
    """Building every command's options imports neither the simulator nor the recording writer."""
    code = 'from baseball_collision.tools.cli import build_parser\nbuild_parser()'
    assert modules_loaded(code, ('baseball_collision.tools.sim',
                                 'baseball_collision.tools.recording')) == []


def test_simulate_options_are_the_recording_limits() -> None:
    """The options' constants are the ones the simulator and the writer check against."""
    from baseball_collision.tools import choices, recording, sim
    assert sim.KINDS is choices.KINDS and recording.KINDS is choices.KINDS
    assert recording.BAT_CHOICES is choices.BAT_CHOICES
    assert (recording.MAX_RATE_HZ, recording.MAX_SEED) == (choices.MAX_RATE_HZ, choices.MAX_SEED)
