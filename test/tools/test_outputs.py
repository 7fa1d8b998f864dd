"""All-or-nothing outputs: staged beside their targets, placed at commit, never overwriting."""

import errno
import os
from pathlib import Path
import subprocess
import sys
from typing import Callable, Iterator, List, Tuple

from baseball_collision.bags import BagWriter
from baseball_collision.errors import BagError, ToolError
import baseball_collision.tools.many_bags as many_bags_module
from baseball_collision.tools.outputs import Outputs
import pytest
from support import SIGNAL_AFTER_BAG
from support.bundled import bag_path

RunCli = Callable[[List[str]], Tuple[int, str, str]]


def test_outputs_are_all_or_nothing(tmp_path: Path) -> None:
    """Nothing appears before commit; an exception removes every temporary."""
    targets = {'json': tmp_path / 'a.json', 'plot': tmp_path / 'plots',
               'out_bag': tmp_path / 'o.mcap'}
    with pytest.raises(RuntimeError):
        with Outputs(**targets) as outputs:
            outputs.bag_writer('out_bag', 'mcap').write_point('/x', 1, 'f', (0.0, 0.0, 0.0))
            outputs.stage_text('json', '{}')
            outputs.stage_directory('plot', lambda d: (d / 'a.png').write_bytes(b'x'))
            raise RuntimeError('boom')
    assert list(tmp_path.iterdir()) == []
    with Outputs(**targets) as outputs:
        outputs.bag_writer('out_bag', 'mcap').write_point('/x', 1, 'f', (0.0, 0.0, 0.0))
        outputs.stage_text('json', '{}')
        outputs.stage_directory('plot', lambda d: (d / 'a.png').write_bytes(b'x'))
        assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith('.')) == []
        outputs.commit()
    assert sorted(p.name for p in tmp_path.iterdir()) == ['a.json', 'o.mcap', 'plots']
    assert (tmp_path / 'plots' / 'a.png').read_bytes() == b'x'
    with pytest.raises(ToolError, match='exists already'):
        Outputs(json=tmp_path / 'a.json')
    with pytest.raises(ToolError, match='does not exist'):
        Outputs(csv=tmp_path / 'nowhere' / 'a.csv')


def test_a_target_that_appears_before_the_commit_is_kept(tmp_path: Path) -> None:
    """Commit refuses a target made meanwhile, leaves it as it was, and no temporary behind."""
    with pytest.raises(ToolError, match='exists already'):
        with Outputs(json=tmp_path / 'a.json', csv=tmp_path / 'b.csv') as outputs:
            outputs.stage_text('json', '{"a": 1}\n')
            outputs.stage_text('csv', 'a\n')
            (tmp_path / 'b.csv').write_text('mine')
            outputs.commit()
    assert sorted(p.name for p in tmp_path.iterdir()) == ['a.json', 'b.csv']
    assert (tmp_path / 'a.json').read_text() == '{"a": 1}\n'
    assert (tmp_path / 'b.csv').read_text() == 'mine'


def test_outputs_get_the_usual_permissions(tmp_path: Path) -> None:
    """A staged file or directory ends up with the mode of one made directly (umask applied)."""
    (tmp_path / 'plain.txt').write_text('x')
    (tmp_path / 'plain').mkdir()
    with Outputs(text=tmp_path / 'a.txt', plot=tmp_path / 'plots') as outputs:
        outputs.stage_text('text', 'x')
        outputs.stage_directory('plot', lambda directory: None)
        outputs.commit()
    assert (tmp_path / 'a.txt').stat().st_mode == (tmp_path / 'plain.txt').stat().st_mode
    assert (tmp_path / 'plots').stat().st_mode == (tmp_path / 'plain').stat().st_mode


def test_one_path_for_two_outputs_is_refused_before_any_work(
        tmp_path: Path, run_cli: RunCli) -> None:
    """--json X --csv X, --json X --out-bag X, --json P --plot P: refused, nothing written."""
    bag = str(bag_path('pitches_90hz.mcap'))
    for first, second in (('--json', '--csv'), ('--json', '--out-bag'), ('--json', '--plot')):
        target = tmp_path / 'o.txt'
        code, stdout, stderr = run_cli(['analyze', bag, first, str(target), second,
                                        str(target), '--quiet'])
        assert code == 2 and stdout == ''
        assert f'{first} and {second} both name' in stderr and len(stderr.splitlines()) == 1
        assert list(tmp_path.iterdir()) == []


@pytest.fixture
def unwritable(tmp_path: Path) -> Iterator[Path]:
    """
    Return a directory in which no file can be created (for root too: immutable).

    Read-only permissions where they stop this process; else (root) ``chattr +i``; skipped
    where neither does.
    """
    directory = tmp_path / 'locked'
    directory.mkdir()
    directory.chmod(0o555)
    immutable = False
    if os.access(directory, os.W_OK):  # (root: the permissions do not apply)
        immutable = subprocess.run(['chattr', '+i', str(directory)],
                                   capture_output=True).returncode == 0
        if not immutable:
            directory.chmod(0o755)
            pytest.skip('no way to make a directory unwritable here')
    try:
        yield directory
    finally:
        if immutable:
            subprocess.run(['chattr', '-i', str(directory)], check=True)
        directory.chmod(0o755)


@pytest.mark.parametrize('flag', ['--json', '--csv', '--plot', '--out-bag'])
def test_an_unwritable_output_directory_is_refused_before_any_work(
        flag: str, unwritable: Path, run_cli: RunCli, monkeypatch: pytest.MonkeyPatch) -> None:
    """Checked up front (a file made and removed there), not after the whole analysis."""
    def analysed(*args: object, **kwargs: object) -> None:
        raise AssertionError('the bags were analysed before the outputs were checked')
    monkeypatch.setattr(many_bags_module, 'analyze_bags', analysed)
    target = unwritable / 'out.mcap'
    code, stdout, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap')), flag,
                                    str(target), '--quiet'])
    assert code == 2 and stdout == ''
    refusal = os.strerror(errno.EPERM if os.geteuid() == 0 else errno.EACCES)
    assert stderr.splitlines() == [
        f'baseball-collision: error: cannot write {target}: {refusal}']
    assert list(unwritable.iterdir()) == []


def test_a_file_named_as_the_output_directory_is_said_to_be_no_directory(
        tmp_path: Path, run_cli: RunCli) -> None:
    """--json base.mcap/x.json where base.mcap is a file: not 'does not exist'."""
    bag = tmp_path / 'base.mcap'
    bag.write_bytes(bag_path('pitches_90hz.mcap').read_bytes())
    for flag in ('--json', '--plot', '--out-bag'):
        code, _, stderr = run_cli(['analyze', str(bag), flag, str(bag / 'x'), '--quiet'])
        assert code == 2 and stderr == (f'baseball-collision: error: output directory {bag} is '
                                        'not a directory\n')
    with pytest.raises(BagError, match=f'output directory {bag} is not a directory'):
        BagWriter(bag / 'x.mcap')


SIGNALLED = SIGNAL_AFTER_BAG + """
import sys
from baseball_collision.tools import cli
sys.exit(cli.main(sys.argv[1:]))
"""


@pytest.mark.parametrize('name, code', [('SIGTERM', 143), ('SIGHUP', 129)])
def test_sigterm_and_sighup_leave_no_partial_output(tmp_path: Path, name: str,
                                                    code: int) -> None:
    """A termination signal mid-run: the staged bag and files are deleted, exit 128 + signal."""
    out = tmp_path / 'out'
    out.mkdir()
    result = subprocess.run(
        [sys.executable, '-c', SIGNALLED.format(name=name), 'analyze',
         str(bag_path('pitches_90hz.mcap')), '--out-bag', str(out / 'o.mcap'), '--json',
         str(out / 'o.json'), '--quiet'], capture_output=True, text=True, timeout=120)
    assert result.returncode == code, result.stderr
    assert f'terminated by {name}' in result.stderr
    assert list(out.iterdir()) == []
