"""
All-or-nothing outputs: write beside the target under a hidden name, move into place at the end.

The one mechanism behind every file the package writes for a user (bags, JSON, CSV, plot
directories): an output is staged in a hidden temporary directory ``.<name>.<random>.partial``
next to its target (the same file system, so placing it is a rename or a hard link), and only
:meth:`StagedOutput.commit` puts it in place, never replacing a path that exists.
:meth:`StagedOutput.abort`, or an exception inside a ``with`` block, deletes the temporary.

Every staged output not yet committed or aborted is known here (:func:`abort_all`), so that a
termination signal can delete them: inside :func:`cleanup_on_signals`, SIGTERM and SIGHUP
delete every temporary and raise :class:`Terminated` (a ``KeyboardInterrupt``, as Ctrl-C),
which unwinds the program like Ctrl-C does.

Standard library only, usable from every layer; it raises ``OSError`` subclasses, which each
layer turns into its own error.
"""

import contextlib
import os
from pathlib import Path
import shutil
import signal
import tempfile
import threading
from typing import Any, Iterator, Optional, Sequence, Set, Union

PARTIAL_SUFFIX = '.partial'
"""Suffix of the hidden temporary directories (``.<target name>.<random>.partial``)."""


CLEANUP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)
"""The signals :func:`cleanup_on_signals` turns into :class:`Terminated`."""

_LIVE: Set['StagedOutput'] = set()
"""Staged outputs neither committed nor aborted yet."""


class Terminated(KeyboardInterrupt):
    """
    The process got a termination signal (SIGTERM, SIGHUP) and is winding down as on Ctrl-C.

    :ivar signum: the signal's number (the exit code is 128 + it).
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def name(self) -> str:
        """Return the signal's name, e.g. ``SIGTERM``."""
        return signal.Signals(self.signum).name


def abort_all() -> int:
    """Delete every staged output not yet committed or aborted; return how many."""
    live = list(_LIVE)
    for output in live:
        output.abort()
    return len(live)


@contextlib.contextmanager
def cleanup_on_signals(signals: Sequence[int] = CLEANUP_SIGNALS) -> Iterator[None]:
    """
    Within the block, a signal of ``signals`` deletes every staged output and raises Terminated.

    The handlers are set only in the main thread (elsewhere the block runs unchanged) and the
    previous handlers are put back at the end.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminate(signum: int, frame: Any) -> None:
        abort_all()
        raise Terminated(signum)

    previous = {signum: signal.signal(signum, terminate) for signum in signals}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def worker_signals() -> None:
    """
    Set a worker process's signals: SIGTERM and SIGHUP end it at once, SIGINT is ignored.

    The initializer of a process pool forked inside :func:`cleanup_on_signals`: a worker owns
    no staged output, its parent stops it (``Pool.terminate`` sends SIGTERM) and handles Ctrl-C.
    """
    for signum in CLEANUP_SIGNALS:
        signal.signal(signum, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def check_target(target: Union[str, os.PathLike]) -> Path:
    """
    Return ``target`` as a path after checking that an output can be created there.

    :raises FileExistsError: the path exists (also a dangling symlink): never overwritten.
    :raises NotADirectoryError: what should be its directory is a file (or another non-directory).
    :raises FileNotFoundError: its directory does not exist.
    """
    path = Path(target)
    if path.exists() or path.is_symlink():
        raise FileExistsError(17, 'exists already; not overwriting', str(path))
    if not path.parent.is_dir():
        if path.parent.exists():
            raise NotADirectoryError(20, 'not a directory', str(path.parent))
        raise FileNotFoundError(2, 'output directory does not exist', str(path.parent))
    return path


def check_writable(directory: Union[str, os.PathLike]) -> None:
    """
    Check that files can be created in ``directory``: create and remove a hidden empty file.

    The permission bits do not say it all (root ignores them; an immutable directory, a
    read-only mount, a full disk's quota): this asks the file system itself.

    :raises OSError: the file cannot be created (``PermissionError``, ``EROFS``, ...).
    """
    handle, name = tempfile.mkstemp(prefix='.', suffix='.probe', dir=directory)
    os.close(handle)
    os.unlink(name)


class StagedOutput:
    """
    One output staged beside its target until :meth:`commit`.

    Write the output at :attr:`path` (a file or a directory named like the target, inside the
    temporary directory), or anywhere inside :attr:`directory` and pass that to :meth:`commit`.

    :param target: where the output goes; must not exist, its directory must.
    :raises OSError: as :func:`check_target`, or the temporary cannot be created.
    """

    def __init__(self, target: Union[str, os.PathLike]) -> None:
        self.target = check_target(target)
        self.directory: Optional[Path] = Path(tempfile.mkdtemp(
            prefix=f'.{self.target.name}.', suffix=PARTIAL_SUFFIX, dir=self.target.parent))
        _LIVE.add(self)

    @property
    def path(self) -> Path:
        """Return where to write the output: inside the temporary, named like the target."""
        if self.directory is None:
            raise ValueError(f'output {self.target} is already committed or aborted')
        return self.directory / self.target.name

    def commit(self, source: Optional[Path] = None) -> Path:
        """
        Move the output (``source``, default :attr:`path`) to the target; delete the temporary.

        A file is hard-linked into place (which never replaces an existing file; a rename where
        the file system has no hard links), a directory renamed after a check.

        :returns: the target.
        :raises FileExistsError: the target appeared meanwhile (the output is deleted).
        :raises OSError: the output cannot be placed (the output is deleted).
        """
        source = self.path if source is None else Path(source)
        try:
            if source.is_dir():
                check_target(self.target)
                os.rename(source, self.target)
            else:
                try:
                    os.link(source, self.target)
                except FileExistsError:
                    raise
                except OSError:  # no hard links on this file system
                    check_target(self.target)
                    os.rename(source, self.target)
        finally:
            self.abort()
        return self.target

    def abort(self) -> None:
        """Delete the temporary and whatever was written into it (idempotent)."""
        directory, self.directory = self.directory, None
        _LIVE.discard(self)
        if directory is not None:
            shutil.rmtree(directory, ignore_errors=True)

    def __enter__(self) -> 'StagedOutput':
        """Return self."""
        return self

    def __exit__(self, exc_type: Any, exc_value: Any, traceback: Any) -> None:
        """Delete the temporary if the block raised (a committed output stays)."""
        if exc_type is not None:
            self.abort()
