"""
``analyze`` over many bags on every core (``tools/many_bags.py``): one report in input order.

Real bag files (the bundled ones, copied or linked into directories of bags); the pool's
results are compared with the same bags analysed one after another in this process.
"""

import json
import os
from pathlib import Path
import shutil
import subprocess
import sys
from typing import Callable, List, Tuple

from baseball_collision.bags import POINT_STAMPED, POSE_STAMPED
from baseball_collision.errors import ToolError
from baseball_collision.tools import many_bags, plots, pool
from baseball_collision.tools.analyze import BagAnalysis
from baseball_collision.tools.many_bags import analyze_bags, bag_paths, is_bag, worker_read_ahead
import pytest
from support.bagfiles import reference_bag
from support.bundled import bag_path
from support.schema import Validator

RunCli = Callable[[List[str]], Tuple[int, str, str]]

SMALL = ['pitches_90hz.mcap', 'pitches_120hz_sqlite3']
"""Two small bundled bags: a bare MCAP file and a ROS 2 (sqlite3) bag directory."""


def _events(analysis: BagAnalysis) -> tuple:
    return (analysis.path, analysis.messages, analysis.impacts, analysis.near_misses,
            analysis.gaps, analysis.resets, analysis.stats.dropped)


def _directory_of_bags(root: Path) -> Path:
    """Return a directory holding the two small bags (named so the directory order differs)."""
    directory = root / 'season'
    directory.mkdir()
    shutil.copy(bag_path(SMALL[0]), directory / 'b_first.mcap')
    shutil.copytree(bag_path(SMALL[1]), directory / 'a_second')
    (directory / 'notes.txt').write_text('not a bag')
    (directory / 'empty').mkdir()  # a directory inside that is not a bag: not taken
    return directory


def test_a_bag_directory_is_one_bag_and_a_directory_of_bags_is_its_bags(tmp_path: Path) -> None:
    """metadata.yaml makes a directory one bag; another directory stands for the bags in it."""
    assert is_bag(bag_path(SMALL[1])) and is_bag(bag_path(SMALL[0]))
    assert bag_paths([bag_path(SMALL[1])]) == [bag_path(SMALL[1])]
    directory = _directory_of_bags(tmp_path)
    assert bag_paths([directory, bag_path(SMALL[0])]) == [
        directory / 'a_second', directory / 'b_first.mcap', bag_path(SMALL[0])]
    missing = tmp_path / 'missing.mcap'
    assert bag_paths([missing]) == [missing]  # analyze_bag says what is wrong with it
    with pytest.raises(ToolError, match='no bags in'):
        bag_paths([directory / 'empty'])


def test_a_directory_stands_for_the_bags_in_its_subdirectories_too(tmp_path: Path) -> None:
    """A season of days of bags: each level's bags by name, then its subdirectories'."""
    season = tmp_path / 'season'
    (season / 'day2' / 'late').mkdir(parents=True)
    (season / 'day1').mkdir()
    shutil.copy(bag_path(SMALL[0]), season / 'day1' / 'a.mcap')
    shutil.copy(bag_path(SMALL[0]), season / 'day2' / 'late' / 'c.mcap')
    shutil.copytree(bag_path(SMALL[1]), season / 'day2' / 'b')  # a bag directory: not entered
    shutil.copy(bag_path(SMALL[0]), season / 'z.mcap')
    assert bag_paths([season]) == [season / 'z.mcap', season / 'day1' / 'a.mcap',
                                   season / 'day2' / 'b', season / 'day2' / 'late' / 'c.mcap']


@pytest.mark.parametrize('jobs', [1, 2])
def test_keep_going_skips_the_bags_that_cannot_be_analysed(tmp_path: Path, jobs: int) -> None:
    """A truncated and a missing bag among good ones: the good ones analysed, the rest named."""
    truncated = tmp_path / 'cut.mcap'
    truncated.write_bytes(bag_path(SMALL[0]).read_bytes()[:4000])
    paths = [truncated, bag_path(SMALL[0]), tmp_path / 'missing.mcap', bag_path(SMALL[1])]
    skipped: List[Tuple[Path, str]] = []
    analyses = analyze_bags(paths, jobs=jobs, progress=False, skipped=skipped)
    assert [a.path for a in analyses] == [bag_path(SMALL[0]), bag_path(SMALL[1])]
    assert [path for path, _ in skipped] == [truncated, tmp_path / 'missing.mcap']
    assert 'cannot read bag' in skipped[0][1] and 'bag not found' in skipped[1][1]
    alone = analyze_bags(paths[1::2], jobs=1, progress=False)
    assert [_events(a) for a in analyses] == [_events(a) for a in alone]


def test_cli_keep_going_writes_the_good_bags_and_exits_2(tmp_path: Path,
                                                         run_cli: RunCli) -> None:
    """``--keep-going``: a line per bag skipped, the others' report and JSON, exit code 2."""
    truncated = tmp_path / 'cut.mcap'
    truncated.write_bytes(bag_path(SMALL[0]).read_bytes()[:4000])
    out = tmp_path / 'o.json'
    argv = ['analyze', str(bag_path(SMALL[0])), str(truncated), '--json', str(out)]
    code, stdout, stderr = run_cli(argv + ['--keep-going'])
    assert code == 2 and stdout.count('summary:') == 1
    assert stderr.startswith(f'baseball-collision: skipped: cannot read bag {truncated}')
    assert stderr.count('\n') == 1
    document = json.loads(out.read_text())
    assert [b['path'] for b in document['bags']] == [str(bag_path(SMALL[0]))]
    assert [entry['path'] for entry in document['skipped']] == [str(truncated)]
    assert document['skipped'][0]['why'] == stderr[len('baseball-collision: skipped: '):-1]
    assert Validator('analyze.schema.json').errors(document) == []
    out.unlink()
    code, stdout, stderr = run_cli(argv)  # without it: the first bad bag ends the run
    assert code == 2 and stdout == '' and not out.exists()  # and nothing is written
    assert stderr.count('\n') == 1 and stderr.rstrip().endswith(
        '(--keep-going skips a bag that cannot be analysed and goes on with the others)')
    code, _, stderr = run_cli(['analyze', str(truncated)])  # one bag: nothing to keep going to
    assert code == 2 and 'keep-going' not in stderr
    code, _, stderr = run_cli(['analyze', str(truncated), '--keep-going'])
    assert code == 2 and stderr.splitlines()[-1] == (
        'baseball-collision: error: no bag could be analysed (1 skipped)')
    code, stdout, _ = run_cli(argv[:2] + ['--keep-going', '--json', '-'])
    assert code == 0 and json.loads(stdout)['skipped'] == []  # (asked to keep going: a list)
    code, stdout, _ = run_cli(argv[:2] + ['--json', '-'])
    assert code == 0 and 'skipped' not in json.loads(stdout)


def test_keep_going_lists_a_bag_whose_samples_were_all_dropped(tmp_path: Path,
                                                               run_cli: RunCli) -> None:
    """Skipped after its analysis (the bat in another frame than the ball): in the JSON too."""
    rows = [('/ball', POINT_STAMPED, 10**9 + 10**7 * i, 'world', (0.1 * i, 0.0, 1.0),
             10**7 * i + 1) for i in range(40)]
    rows += [('/bat_pose', POSE_STAMPED, 10**9 + 10**7 * i, 'mocap',
              (1.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0), 10**7 * i + 2) for i in range(40)]
    frames = tmp_path / 'frames'
    reference_bag(frames, sorted(rows, key=lambda row: row[5]))
    code, stdout, stderr = run_cli(['analyze', str(frames), str(bag_path(SMALL[0])),
                                    '--keep-going', '--json', '-', '--jobs', '1'])
    document = json.loads(stdout)
    assert code == 2 and [b['path'] for b in document['bags']] == [str(bag_path(SMALL[0]))]
    assert document['skipped'] == [{'path': str(frames), 'why': stderr.splitlines()[0][
        len('baseball-collision: skipped: '):]}]
    assert "ball sends 'world', bat_pose sends 'mocap'" in document['skipped'][0]['why']


def test_the_pool_gives_what_one_process_gives_in_input_order(tmp_path: Path) -> None:
    """Two jobs over a directory of bags and a bag: the same analyses, in the input order."""
    paths = [_directory_of_bags(tmp_path), bag_path(SMALL[0])]
    alone = analyze_bags(paths, jobs=1, progress=False)
    pooled = analyze_bags(paths, jobs=2, progress=False)
    assert [a.path for a in pooled] == bag_paths(paths)
    assert [_events(a) for a in pooled] == [_events(a) for a in alone]
    assert all(a.impacts for a in pooled) and all(a.truth is None for a in pooled[:2])
    assert pooled[2].truth is not None  # the truth file beside the bundled bag
    assert len(pooled[2].truth.matched) == len(alone[2].truth.matched) > 0


def test_workers_read_ahead_only_with_a_core_to_spare(monkeypatch: pytest.MonkeyPatch) -> None:
    """A worker on every core reads in turn; fewer workers than cores read one chunk ahead."""
    monkeypatch.setattr(many_bags, 'cores', lambda: 4)
    assert [worker_read_ahead(workers) for workers in (1, 2, 3, 4, 5)] == [1, 1, 1, 0, 0]
    monkeypatch.setattr(many_bags, 'cores', lambda: 1)
    assert worker_read_ahead(1) == 0


def test_the_first_failing_bag_in_input_order_is_the_error(tmp_path: Path) -> None:
    """A later bag failing sooner does not matter: the error is the first bad bag's."""
    truncated = tmp_path / 'cut.mcap'
    truncated.write_bytes(bag_path(SMALL[0]).read_bytes()[:4000])
    paths = [bag_path(SMALL[0]), tmp_path / 'missing.mcap', truncated]
    with pytest.raises(ToolError, match='bag not found'):
        analyze_bags(paths, jobs=3, progress=False)
    with pytest.raises(ToolError, match='cannot read bag'):
        analyze_bags([bag_path(SMALL[0]), truncated], jobs=2, progress=False)


@pytest.mark.parametrize('jobs', [0, -2, 1.5, '2'])
def test_jobs_under_one_or_not_a_count_are_refused(jobs: object) -> None:
    """``analyze_bags(jobs=0)`` is refused as the CLI's ``--jobs 0`` is, not run in one process."""
    with pytest.raises(ToolError, match='jobs must be a whole number'):
        analyze_bags([bag_path(SMALL[0])], jobs=jobs, progress=False)  # type: ignore[arg-type]


def test_cli_jobs_writes_one_report_in_input_order(tmp_path: Path, run_cli: RunCli) -> None:
    """``analyze DIR BAG --jobs 2``: one table, JSON and CSV, bags in the order given."""
    directory = _directory_of_bags(tmp_path)
    code, stdout, stderr = run_cli(['analyze', str(directory), str(bag_path(SMALL[0])),
                                    '--jobs', '2', '--json', str(tmp_path / 'o.json'),
                                    '--csv', str(tmp_path / 'o.csv')])
    assert code == 0 and stderr == ''
    assert stdout.count('summary:') == 3 and 'total: 3 bags' in stdout
    assert 'of wall time' in stdout
    document = json.loads((tmp_path / 'o.json').read_text())
    assert [b['path'] for b in document['bags']] == [
        str(p) for p in bag_paths([directory, bag_path(SMALL[0])])]
    first_bag_rows = (tmp_path / 'o.csv').read_text().splitlines()[1:]
    assert first_bag_rows and str(directory / 'a_second') in first_bag_rows[0]


def test_cli_jobs_draws_each_bags_plots_in_the_pool_the_same_files(
        tmp_path: Path, run_cli: RunCli, monkeypatch: pytest.MonkeyPatch) -> None:
    """``--plot --jobs 2``: the bags' figures drawn by two processes, byte for byte as one."""
    bags = []
    for name, kind in (('a.mcap', 'barrel'), ('b.mcap', 'end_cap')):
        bags.append(str(tmp_path / name))
        code, _, stderr = run_cli(['simulate', bags[-1], '--count', '1', '--kinds', kind,
                                   '--rate', '120'])
        assert code == 0, stderr
    pools: List[int] = []

    def spied(function: Callable, tasks: list, workers: int, **kwargs: object) -> list:
        pools.append(workers)
        return pool.in_pool(function, tasks, workers, **kwargs)

    monkeypatch.setattr(plots, 'in_pool', spied)
    drawn = {}
    for jobs in ('1', '2'):
        directory = tmp_path / f'plots_{jobs}'
        code, _, stderr = run_cli(['analyze', *bags, '--plot', str(directory), '--jobs', jobs,
                                   '--quiet'])
        assert code == 0, stderr
        drawn[jobs] = {file.name: file.read_bytes() for file in directory.iterdir()}
    assert pools == [2]  # (--jobs 1: no pool)
    assert sorted(drawn['1']) == ['a_impact_1.png', 'a_summary.png', 'b_impact_1.png',
                                  'b_summary.png']
    assert drawn['2'] == drawn['1']


@pytest.mark.parametrize('bad', [False, True], ids=['all good', 'a bad bag'])
def test_the_console_script_pool_ends_its_workers_quietly(tmp_path: Path, bad: bool) -> None:
    """
    A real ``analyze --jobs 2`` process: its workers end without a traceback.

    The command line turns SIGTERM into a cleanup; the pool ends its workers with SIGTERM
    (at once when a bag fails): a worker must just end. All good: nothing on stderr; a bad
    bag: its one-line error and exit code 2.
    """
    second = bag_path(SMALL[1])
    if bad:
        second = tmp_path / 'cut.mcap'
        second.write_bytes(bag_path(SMALL[0]).read_bytes()[:4000])
    env = dict(os.environ)
    env.pop('RMW_IMPLEMENTATION', None)
    script = Path(sys.executable).with_name('baseball-collision')
    done = subprocess.run([str(script), 'analyze', str(bag_path(SMALL[0])), str(second),
                           '--jobs', '2', '--quiet'], capture_output=True, text=True, env=env,
                          timeout=120)
    if bad:
        assert done.returncode == 2 and done.stderr.count('\n') == 1, done.stderr
        assert 'cannot read bag' in done.stderr
    else:
        assert done.returncode == 0 and done.stderr == ''


@pytest.mark.parametrize('argv, words', [
    (['--jobs', '0'], "'0' must be >= 1"),
    (['--jobs', '2', '--out-bag', 'OUT'], '--out-bag takes one BAG'),
])
def test_cli_jobs_errors_are_one_line(argv: List[str], words: str, tmp_path: Path,
                                      run_cli: RunCli) -> None:
    """Bad --jobs, or --out-bag with several bags: one line, exit 2, nothing written."""
    argv = [str(tmp_path / 'o.mcap') if a == 'OUT' else a for a in argv]
    code, stdout, stderr = run_cli(['analyze', str(bag_path(SMALL[0])),
                                    str(bag_path(SMALL[1]))] + argv)
    assert code == 2 and stdout == ''
    assert stderr.count('\n') == 1 and words in stderr
    assert list(tmp_path.iterdir()) == []
