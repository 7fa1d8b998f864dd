"""Tests for baseball_collision.atomic: outputs appear whole at commit, or not at all."""

import os
from pathlib import Path
import signal
import subprocess
import sys
import tempfile

from baseball_collision.atomic import (
    abort_all, check_target, cleanup_on_signals, PARTIAL_SUFFIX, StagedOutput, Terminated)
import pytest


def _partials(directory: Path) -> list:
    return [p for p in directory.iterdir() if p.name.endswith(PARTIAL_SUFFIX)]


def test_a_file_appears_only_at_commit(tmp_path: Path) -> None:
    """Nothing at the target while writing; the whole file after commit; no temporary left."""
    target = tmp_path / 'out.json'
    staged = StagedOutput(target)
    staged.path.write_text('{"a": 1}\n')
    assert not target.exists() and len(_partials(tmp_path)) == 1
    assert staged.commit() == target
    assert target.read_text() == '{"a": 1}\n' and _partials(tmp_path) == []


def test_a_directory_and_a_nested_source_commit(tmp_path: Path) -> None:
    """A directory target is renamed into place; commit takes a file from deeper inside too."""
    plots = StagedOutput(tmp_path / 'plots')
    plots.path.mkdir()
    (plots.path / 'a.png').write_bytes(b'png')
    plots.commit()
    assert (tmp_path / 'plots' / 'a.png').read_bytes() == b'png'
    bag = StagedOutput(tmp_path / 'x.mcap')
    (bag.directory / 'inner').mkdir()
    (bag.directory / 'inner' / 'inner.mcap').write_bytes(b'mcap')
    bag.commit(bag.directory / 'inner' / 'inner.mcap')
    assert (tmp_path / 'x.mcap').read_bytes() == b'mcap' and _partials(tmp_path) == []


def test_an_exception_or_abort_leaves_nothing(tmp_path: Path) -> None:
    """The with block deletes the temporary on an exception; abort is idempotent."""
    target = tmp_path / 'out.csv'
    with pytest.raises(RuntimeError):
        with StagedOutput(target) as staged:
            staged.path.write_text('half')
            raise RuntimeError('failed mid-way')
    assert not target.exists() and _partials(tmp_path) == []
    staged = StagedOutput(target)
    staged.abort()
    staged.abort()
    assert _partials(tmp_path) == []
    with pytest.raises(ValueError):
        staged.path


def test_never_overwrites(tmp_path: Path) -> None:
    """An existing target (or dangling link) is refused up front, and if it appears meanwhile."""
    existing = tmp_path / 'exists.txt'
    existing.write_text('keep')
    with pytest.raises(FileExistsError):
        StagedOutput(existing)
    os.symlink(tmp_path / 'nowhere', tmp_path / 'dangling')
    with pytest.raises(FileExistsError):
        check_target(tmp_path / 'dangling')
    with pytest.raises(FileNotFoundError):
        check_target(tmp_path / 'missing' / 'out.txt')
    late = tmp_path / 'late.txt'
    staged = StagedOutput(late)
    staged.path.write_text('new')
    late.write_text('someone else')
    with pytest.raises(FileExistsError):
        staged.commit()
    assert late.read_text() == 'someone else' and _partials(tmp_path) == []


def test_a_termination_signal_deletes_every_staged_output(tmp_path: Path) -> None:
    """Inside cleanup_on_signals, SIGTERM deletes the temporaries and raises Terminated."""
    first, second = StagedOutput(tmp_path / 'a'), StagedOutput(tmp_path / 'b')
    second.path.write_text('half')
    previous = signal.getsignal(signal.SIGTERM)
    with pytest.raises(Terminated) as raised:
        with cleanup_on_signals():
            os.kill(os.getpid(), signal.SIGTERM)
            signal.pause()  # never reached: the handler raises
    assert raised.value.signum == signal.SIGTERM and raised.value.name == 'SIGTERM'
    assert isinstance(raised.value, KeyboardInterrupt)
    assert _partials(tmp_path) == [] and first.directory is None and second.directory is None
    assert signal.getsignal(signal.SIGTERM) is previous
    assert abort_all() == 0


WORKER_SCRIPT = """
import multiprocessing, signal
from baseball_collision.atomic import cleanup_on_signals, worker_signals
with cleanup_on_signals():
    for _ in range(3):
        with multiprocessing.get_context('forkserver').Pool(
                2, initializer=worker_signals) as pool:
            assert pool.map(abs, [1, -2]) == [1, 2]
            handlers = pool.apply(signal.getsignal, (signal.SIGTERM,)), pool.apply(
                signal.getsignal, (signal.SIGINT,))
            assert handlers == (signal.SIG_DFL, signal.SIG_IGN), handlers
"""


def test_pool_workers_end_quietly_on_terminate() -> None:
    """Pool workers forked inside cleanup_on_signals end on SIGTERM without a traceback."""
    # files, not pipes: the verdict is the parent's exit and its stderr, whatever a worker that
    # CPython's Pool.terminate may leave behind still holds open
    with tempfile.TemporaryFile('w+') as out, tempfile.TemporaryFile('w+') as err:
        process = subprocess.Popen([sys.executable, '-c', WORKER_SCRIPT], stdout=out, stderr=err)
        try:
            code = process.wait(timeout=60)
        finally:
            process.kill()
        err.seek(0)
        stderr = err.read()
    assert code == 0 and stderr == '', stderr
