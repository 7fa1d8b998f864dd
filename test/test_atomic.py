"""Tests for baseball_collision.atomic: outputs appear whole at commit, or not at all."""

import os
from pathlib import Path
import signal

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
