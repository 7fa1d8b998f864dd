"""
All-or-nothing outputs of a command: every target checked before any work, placed at the end.

Every text file, directory and bag a tool writes goes through
:class:`~baseball_collision.atomic.StagedOutput` (bags through
:class:`~baseball_collision.bags.BagWriter`, which stages the same way): written beside its
target under a hidden name, moved into place only by :meth:`Outputs.commit`, deleted by
:meth:`Outputs.abort` or an exception in the ``with`` block. A failure therefore leaves no
partial file behind, not even a hidden temporary.
"""

import os
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, TYPE_CHECKING

from .. import bags
from ..atomic import check_target, check_writable, StagedOutput
from ..errors import BagError, ToolError

if TYPE_CHECKING:  # rosbags is imported only when a bag is written
    from ..bags import BagWriter


def _flag(name: str) -> str:
    """Return the command-line flag of an output's name (``out_bag`` -> ``--out-bag``)."""
    return '--' + name.replace('_', '-')


def _refused(error: OSError, target: Path) -> ToolError:
    """Return the one-line error for an output that cannot be staged or placed."""
    if isinstance(error, FileExistsError):
        return ToolError(f'output {target} exists already; not overwriting')
    if isinstance(error, NotADirectoryError) and target.parent.exists():
        return ToolError(f'output directory {target.parent} is not a directory')
    if isinstance(error, FileNotFoundError) and not target.parent.is_dir():
        return ToolError(f'output directory {target.parent} does not exist')
    return ToolError(f'cannot write {target}: {error.strerror or error}')


class Outputs:
    """
    Output paths checked up front and written all at once at the end.

    Use as a context manager; name each target by keyword (None: not asked for)::

        with Outputs(json=path, out_bag=None) as outputs:
            outputs.stage_text('json', text)
            outputs.commit()

    :param targets: ``name=path`` per output; every path must not exist, its directory must
        and must take new files, and no two may name the same file.
    :raises ToolError: from the constructor: two targets name the same file, a target exists,
        its directory does not or is not a directory, or a file cannot be created in it (a
        file created and removed there: checked before any work is done).
    """

    def __init__(self, **targets: Optional[os.PathLike]) -> None:
        self.targets: Dict[str, Path] = {
            name: Path(path) for name, path in targets.items() if path is not None}
        seen: Dict[str, str] = {}
        for name, path in self.targets.items():
            key = os.path.normcase(os.path.realpath(path))
            if key in seen:
                raise ToolError(f'{_flag(seen[key])} and {_flag(name)} both name {path}: give '
                                'each output its own path')
            seen[key] = name
        for path in self.targets.values():
            try:
                check_target(path)
                check_writable(path.parent)
            except OSError as error:
                raise _refused(error, path) from error
        self._staged: List[StagedOutput] = []
        self._writers: List['BagWriter'] = []

    def __enter__(self) -> 'Outputs':
        """Return self."""
        return self

    def __exit__(self, exc_type: Any, exc_value: Any, traceback: Any) -> None:
        """Delete every temporary if the block raised."""
        if exc_type is not None:
            self.abort()

    def bag_writer(self, name: str, storage: Optional[str] = None) -> 'BagWriter':
        """
        Open a bag writer for a target (placed by :meth:`commit`, removed by :meth:`abort`).

        :param name: the target's name.
        :param storage: as for :class:`~baseball_collision.bags.BagWriter` (None: by name).
        :raises ToolError: the bag cannot be created.
        """
        writer = bags.BagWriter(self.targets[name], storage)
        try:
            writer.open()
        except BagError as error:
            raise ToolError(str(error)) from error
        self._writers.append(writer)
        return writer

    def _stage(self, name: str) -> StagedOutput:
        """Return a new staged output for a target, kept until :meth:`commit` or abort."""
        target = self.targets[name]
        try:
            staged = StagedOutput(target)
        except OSError as error:
            raise _refused(error, target) from error
        self._staged.append(staged)
        return staged

    def stage_text(self, name: str, text: str) -> None:
        """
        Write a target's text into its temporary.

        :raises ToolError: the temporary cannot be written.
        """
        staged = self._stage(name)
        try:
            staged.path.write_text(text)
        except OSError as error:
            raise _refused(error, staged.target) from error

    def stage_directory(self, name: str, fill: Callable[[Path], Any]) -> None:
        """
        Create a target directory's temporary and let ``fill`` write into it.

        :raises ToolError: the temporary cannot be created (or what ``fill`` raises).
        """
        staged = self._stage(name)
        try:
            staged.path.mkdir()
        except OSError as error:
            raise _refused(error, staged.target) from error
        fill(staged.path)

    def commit(self) -> None:
        """
        Move every output into place (bags first, then files and directories).

        :raises ToolError: a target appeared meanwhile or cannot be written (the outputs not
            yet placed are deleted).
        """
        try:
            for writer in self._writers:
                writer.close()
        except BagError as error:
            self.abort()
            raise ToolError(str(error)) from error
        self._writers = []
        staged, self._staged = self._staged, []
        try:
            for output in staged:
                try:
                    output.commit()
                except OSError as error:
                    raise _refused(error, output.target) from error
        finally:
            for output in staged:
                output.abort()

    def abort(self) -> None:
        """Delete every temporary and abandon open bag writers (idempotent)."""
        for writer in self._writers:
            writer.abort()
        self._writers = []
        for output in self._staged:
            output.abort()
        self._staged = []
