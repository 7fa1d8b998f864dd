"""
What the bag modules share: the rosbags typestores, opening a bag.

Every bag is opened here (:func:`open_bag`, :class:`BagFile`), so reading samples and replaying
raw messages refuse the same paths with the same one-line :class:`BagError`, and read the same
bags in the same way:

* an MCAP channel that is not ROS (JSON, protobuf, ...: Foxglove's ``/foxglove/log``) is left
  out with a note (:attr:`BagFile.skipped_topics`), the rest of the bag read as usual;
* an MCAP file without its footer (a recording that crashed, was killed or is still being
  written) is refused with how to recover it (rosbags' MCAP reader needs the footer);
* a sqlite3 file with a write-ahead log not yet checkpointed into it (``<file>-wal``: rosbag2's
  ``resilient`` storage preset, a recording that crashed or is still being written; rosbags
  opens the file ``immutable`` and would not see those messages) is read through a temporary
  copy with the log checkpointed, with a note (:attr:`BagFile.notes`); the bag itself is never
  changed.
"""

import contextlib
import errno
import functools
import os
from pathlib import Path
import shutil
import sqlite3
import stat
import tempfile
import threading
from types import TracebackType
from typing import Any, Dict, Iterator, List, Optional, Tuple, Type, TypeVar, Union
import weakref

from rosbags.highlevel import AnyReader
from rosbags.interfaces import MessageDefinition, MessageDefinitionFormat
from rosbags.rosbag2 import storage_mcap
from rosbags.typesys import get_typestore, Stores
from rosbags.typesys.store import Typestore

from ..errors import BagError


FRAME_CACHE_LIMIT = 1024
"""Most frame_ids a decoder or writer remembers (the cache is emptied when full)."""


@functools.lru_cache(maxsize=None)
def jazzy_typestore() -> Typestore:
    """Return the ROS 2 Jazzy typestore (built once)."""
    return get_typestore(Stores.ROS2_JAZZY)


class _JazzyDefaults:
    """
    The default types an ``AnyReader`` is given: the Jazzy typestore's, built on first use.

    ``AnyReader`` reads ``default_typestore.fielddefs`` only for a bag that carries no type
    definitions of its own (a ROS 2 bag from before Iron); every other bag opens without the
    Jazzy store being built (0.1-0.2 s of CPU, most of a short ``analyze``'s fixed cost).
    """

    @property
    def fielddefs(self) -> Any:
        """Return the Jazzy typestore's field definitions (building the store once)."""
        return jazzy_typestore().fielddefs


@functools.lru_cache(maxsize=None)
def noetic_typestore() -> Typestore:
    """Return the ROS 1 Noetic typestore (built once)."""
    return get_typestore(Stores.ROS1_NOETIC)


def first_line(error: BaseException) -> str:
    """Return the first line of an error's message, or its type name if it has none."""
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__


MAGIC = ((b'\x89MCAP', '.mcap'), (b'SQLite format 3\x00', '.db3'), (b'#ROSBAG V2.0', '.bag'))
"""The first bytes of each bag file format, and the suffix rosbags reads it by."""

FILE_KINDS = ((stat.S_ISFIFO, 'a FIFO'), (stat.S_ISSOCK, 'a socket'),
              (stat.S_ISCHR, 'a character device'), (stat.S_ISBLK, 'a block device'))


def _status(path: Path) -> os.stat_result:
    """Return ``os.stat`` of a bag path, or raise a BagError saying why there is none."""
    try:
        return os.stat(path)
    except FileNotFoundError:
        raise BagError(f'bag not found: {path}') from None
    except OSError as error:
        if error.errno == errno.ELOOP:
            raise BagError(f'cannot read bag {path}: a symbolic link loop') from None
        raise BagError(f'cannot read bag {path}: {error.strerror}') from error


def _regular(path: Path, mode: int) -> None:
    """Refuse a path that is not a regular file (a FIFO would block the reader forever)."""
    for test, kind in FILE_KINDS:
        if test(mode):
            raise BagError(f'not a bag: {path} is {kind}, not a regular file')


def file_format(path: Path) -> Optional[str]:
    """Return a bag file's suffix by its first bytes (``.mcap``, ``.db3``, ``.bag``), or None."""
    try:
        with open(path, 'rb') as stream:
            head = stream.read(16)
    except OSError as error:
        raise BagError(f'cannot read bag {path}: {error.strerror}') from error
    return next((suffix for magic, suffix in MAGIC if head.startswith(magic)), None)


ROS_ENCODINGS = ('cdr',)
"""The message encodings of a ROS 2 bag's topics this package reads (rosbag2 records CDR)."""

MCAP_MAGIC = b'\x89MCAP0\r\n'
"""The bytes an MCAP file starts and, when finished, ends with."""

_SCHEMAS_LOCK = threading.Lock()


@contextlib.contextmanager
def _foreign_schemas_read_as_unknown() -> Iterator[None]:
    """
    Within the block, rosbags' MCAP reader takes a schema it does not know as one without text.

    rosbags (0.11) looks a schema's encoding up in a table of ROS ones and raises ``KeyError``
    for any other (``jsonschema``, ``protobuf``, ...), refusing the whole file for one channel;
    here such a schema reads as a message definition of format NONE, the channel stays (its
    ``message_encoding`` tells it apart: :func:`foreign_channels`) and nothing is registered for
    it. Known encodings go to rosbags' own function unchanged.
    """
    original = storage_mcap.get_msgdef

    def tolerant(schema: Any) -> MessageDefinition:
        try:
            return original(schema)
        except KeyError:
            return MessageDefinition(MessageDefinitionFormat.NONE, '')

    with _SCHEMAS_LOCK:
        storage_mcap.get_msgdef = tolerant  # type: ignore[assignment]
        try:
            yield
        finally:
            storage_mcap.get_msgdef = original  # type: ignore[assignment]


def foreign_channels(reader: AnyReader) -> List[Tuple[Any, str]]:
    """
    Return the connections of an open ROS 2 reader whose messages are not ROS, each with why.

    A connection is one MCAP channel: ``(connection, 'json messages (schema foxglove.Log), not
    ROS CDR')``. A topic may have a ROS channel beside one that is not (a Foxglove bridge's
    JSON ``/ball`` recorded with the CDR one): only the latter is listed. Empty for a ROS 1 bag.
    """
    if not reader.is2:
        return []
    foreign: List[Tuple[Any, str]] = []
    for connection in reader.connections:
        encoding = getattr(connection.ext, 'serialization_format', 'cdr')
        if encoding not in ROS_ENCODINGS:
            foreign.append((connection, f'{encoding or "unnamed"} messages (schema '
                                        f'{connection.msgtype}), not ROS CDR'))
    return foreign


def _unfinished_mcap(path: Path) -> Optional[Path]:
    """Return the MCAP file of a bag that starts as MCAP but does not end as one, or None."""
    files = sorted(path.glob('*.mcap')) if path.is_dir() else [path]
    for file in files:
        try:
            with open(file, 'rb') as stream:
                head = stream.read(len(MCAP_MAGIC))
                stream.seek(0, os.SEEK_END)
                size = stream.tell()
                stream.seek(max(size - len(MCAP_MAGIC), 0))
                tail = stream.read()
        except OSError:
            continue
        if head == MCAP_MAGIC and (size < 2 * len(MCAP_MAGIC) or tail != MCAP_MAGIC):
            return file
    return None


def _unfinished(path: Path, file: Path, error: BaseException) -> BagError:
    """Return the error for an MCAP file without its footer, with how to recover it."""
    return BagError(
        f'cannot read bag {path}: {file} is an unfinished MCAP recording: it ends without '
        'the footer a recorder writes when it stops (it crashed or was killed, the file was '
        'cut short, or it is still being written), which the reader (rosbags) needs; recover '
        f"what it holds with the mcap CLI, 'mcap recover {file} -o recovered.mcap', and "
        f'analyse that ({first_line(error)})')


def _listed_foreign(path: Path) -> Dict[str, str]:
    """Return ``{topic: serialization format}`` of a bag directory's topics that are not ROS."""
    try:
        import yaml  # (only for this message: rosbags reads the metadata itself)
        with open(path / 'metadata.yaml') as stream:
            metadata = yaml.safe_load(stream)['rosbag2_bagfile_information']
        listed = metadata['topics_with_message_count']
        return {str(entry['topic_metadata']['name']): str(
                    entry['topic_metadata']['serialization_format'])
                for entry in listed
                if entry['topic_metadata']['serialization_format'] not in ROS_ENCODINGS}
    except Exception:  # (damaged metadata: rosbags' own error says so)
        return {}


def _foreign_listed(path: Path, foreign: Dict[str, str], error: BaseException) -> BagError:
    """Return the error for a bag directory whose metadata lists topics that are not ROS."""
    topics = ', '.join(f'{topic} ({encoding})' for topic, encoding in sorted(foreign.items()))
    files = ', '.join(str(file) for file in sorted(path.glob('*.mcap'))) or 'its storage file'
    return BagError(
        f'cannot read bag {path}: its metadata.yaml lists topics that are not ROS CDR: '
        f'{topics}, and the reader (rosbags) refuses such a bag directory; analyse its file '
        f'{files} instead, where they are skipped with a note ({first_line(error)})')


def _wal_files(path: Path, sniffed: Optional[str]) -> List[Path]:
    """Return a bag's sqlite3 files that have a write-ahead log with something in it."""
    if path.is_dir():
        files = sorted(path.glob('*.db3'))
    elif sniffed == '.db3' or (sniffed is None and path.suffix == '.db3'):
        files = [path]
    else:
        return []
    found = []
    for file in files:
        try:
            if os.stat(f'{file}-wal').st_size > 0:
                found.append(file)
        except OSError:
            pass
    return found


def _checkpointed_copy(path: Path, logged: List[Path], notes: Optional[List[str]]) -> Path:
    """
    Return a temporary copy of a sqlite3 bag with its write-ahead logs checkpointed.

    The copy (a bag directory: its metadata and storage files; a bare file: ``bag.db3``) is in
    a new temporary directory, which the caller removes. The bag is only read.

    :raises BagError: the copy cannot be made or checkpointed (with how to do it by hand).
    """
    scratch = Path(tempfile.mkdtemp(prefix='.baseball_collision.wal.'))
    try:
        if path.is_dir():
            copy = scratch / path.name
            shutil.copytree(path, copy, ignore=shutil.ignore_patterns('*-shm', '*-wal'))
            pairs = [(file, copy / file.name) for file in logged]
        else:
            copy = scratch / 'bag.db3'
            shutil.copyfile(path, copy)
            pairs = [(path, copy)]
        for file, copied in pairs:
            shutil.copyfile(f'{file}-wal', f'{copied}-wal')
            with contextlib.closing(sqlite3.connect(copied)) as database:
                busy, _, _ = database.execute('PRAGMA wal_checkpoint(TRUNCATE)').fetchone()
                if busy:
                    raise sqlite3.OperationalError('the checkpoint was blocked')
                database.execute('PRAGMA journal_mode=DELETE')
    except (OSError, sqlite3.Error) as error:
        shutil.rmtree(scratch, ignore_errors=True)
        names = ', '.join(f'{file.name}-wal' for file in logged)
        reason = getattr(error, 'strerror', None) or first_line(error)
        raise BagError(
            f'cannot read bag {path}: {names} holds messages not yet checkpointed into the '
            'database (a recording that crashed or is still being written), and a temporary '
            f'checkpointed copy could not be made ({reason}); checkpoint a copy by '
            "hand (cp -r the bag, then sqlite3 COPY/FILE.db3 'PRAGMA wal_checkpoint') and "
            'analyse the copy') from error
    if notes is not None:
        sizes = ', '.join(f'{file.name}-wal ({os.stat(f"{file}-wal").st_size:,} bytes)'
                          for file in logged)
        notes.append(f'{sizes}: a write-ahead log not checkpointed into the database (a '
                     'recording that crashed or is still being written); read through a '
                     'temporary copy with the log checkpointed (the bag is not changed)')
    return scratch


_SCRATCH: 'weakref.WeakKeyDictionary[AnyReader, Any]' = weakref.WeakKeyDictionary()
"""An open reader's temporary copy of its bag: removed when the reader is closed (or freed)."""


def open_bag(path: Union[str, os.PathLike], notes: Optional[List[str]] = None) -> AnyReader:
    """
    Open a bag with rosbags' :class:`AnyReader` (ROS 2 types default to Jazzy).

    A bag file is read by its first bytes: an MCAP named ``.bag`` or ``x.MCAP`` opens as the
    MCAP it is (through a temporary link with the suffix rosbags expects). A sqlite3 bag with
    a write-ahead log not checkpointed is read through a checkpointed temporary copy (removed
    by :func:`close_quietly`), with a note. MCAP channels that are not ROS stay in the reader's
    connections (:func:`foreign_channels` lists them); their schemas are not read.

    :param path: ROS 2 bag directory, bare ``.mcap`` or ``.db3`` file, or ROS 1 ``.bag`` file.
    :param notes: what the reader should be told about how the bag was read is appended here.
    :returns: the open reader (close it with :func:`close_quietly`).
    :raises BagError: path missing, a symbolic link loop, not a bag (a directory without
        ``metadata.yaml``, a FIFO or device, another file suffix and content), an unfinished
        MCAP recording (with how to recover it), a write-ahead log that cannot be
        checkpointed into a copy, or unreadable or corrupt.
    """
    path = Path(path)
    mode = _status(path).st_mode
    alias, opened, sniffed = None, path, None
    if stat.S_ISDIR(mode):
        if not (path / 'metadata.yaml').is_file():
            raise BagError(f'not a ROS 2 bag directory (no metadata.yaml): {path}')
        for entry in path.iterdir():
            if entry.suffix in ('.mcap', '.db3'):
                _regular(entry, _status(entry).st_mode)
    else:
        _regular(path, mode)
        sniffed = file_format(path)
        if sniffed is None and path.suffix not in ('.mcap', '.db3', '.bag'):
            raise BagError(
                f'not a bag: {path} (expected a bag directory or a .mcap, .db3 or .bag file)')
    scratch = None
    logged = _wal_files(path, sniffed)
    if logged:
        scratch = _checkpointed_copy(path, logged, notes)
        opened = scratch / path.name if stat.S_ISDIR(mode) else scratch / 'bag.db3'
    elif sniffed is not None and sniffed != path.suffix:
        alias = Path(tempfile.mkdtemp(prefix='.baseball_collision.'))
        opened = alias / f'bag{sniffed}'
        os.symlink(path.resolve(), opened)
    try:
        reader = AnyReader([opened], default_typestore=_JazzyDefaults())  # type: ignore
        with _foreign_schemas_read_as_unknown():
            reader.open()
    except Exception as error:
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)
        unfinished = _unfinished_mcap(path)
        if unfinished is not None:
            raise _unfinished(path, unfinished, error) from error
        foreign = _listed_foreign(path) if stat.S_ISDIR(mode) else {}
        if foreign:
            raise _foreign_listed(path, foreign, error) from error
        if not stat.S_ISDIR(mode) and sniffed is None:
            raise BagError(
                f'cannot read bag {path}: its first bytes are not those of an MCAP, SQLite 3 or '
                f'ROS 1 bag, so it is no {path.suffix} recording (an empty file or another '
                f'format): {first_line(error)}') from error
        raise BagError(f'cannot read bag {path}: {first_line(error)}') from error
    finally:
        if alias is not None:
            shutil.rmtree(alias, ignore_errors=True)
    if scratch is not None:
        _SCRATCH[reader] = weakref.finalize(reader, shutil.rmtree, scratch, True)
    return reader


def close_quietly(reader: AnyReader) -> None:
    """Close a reader, ignoring errors; remove its temporary copy of the bag, if any."""
    try:
        reader.close()
    except Exception:  # noqa: S110 - a first error, if any, is the one to report
        pass
    finalizer = _SCRATCH.pop(reader, None)
    if finalizer is not None:
        finalizer()


OpenedBag = TypeVar('OpenedBag', bound='BagFile')


class BagFile:
    """
    A bag read through an :class:`AnyReader`: open and close, context manager, log times.

    Subclasses prepare what they read in :meth:`_setup` (called on the open reader; an error
    there closes it again). Channels whose messages are not ROS (:func:`foreign_channels`) are
    taken out of the reader's connections before, each named in :attr:`notes`; a topic left
    with no channel is listed in :attr:`skipped_topics` (one with a ROS channel as well is
    read from that channel).

    :param path: ROS 2 bag directory, bare ``.mcap``/``.db3`` file, or ROS 1 ``.bag`` file.
    """

    def __init__(self, path: Union[str, os.PathLike]) -> None:
        self.path = Path(path)
        self._reader: Optional[AnyReader] = None
        self.notes: List[str] = []
        """What the user should know about how the bag was read (set by :meth:`open`)."""
        self.skipped_topics: Dict[str, str] = {}
        """Topics left out because their messages are not ROS, with why (set by :meth:`open`)."""

    def open(self) -> None:  # noqa: A003 - the rosbags reader name
        """
        Open the bag and prepare it (:meth:`_setup`).

        :raises BagError: already open, path missing, not a bag, unreadable or corrupt, or
            refused by the set-up (e.g. no messages).
        """
        if self._reader is not None:
            raise BagError(f'bag {self.path} is already open')
        notes: List[str] = []
        reader = open_bag(self.path, notes)
        try:
            self._leave_out_foreign(reader)
            self.notes = notes + self.notes
            self._setup(reader)
        except BaseException:
            close_quietly(reader)
            raise
        self._reader = reader

    def _leave_out_foreign(self, reader: AnyReader) -> None:
        """
        Take the channels that are not ROS out of an open reader's connections; note each.

        Sets :attr:`notes` (one line per channel) and :attr:`skipped_topics` (the topics left
        with no channel). By connection, not topic name: a JSON channel on ``/ball`` beside the
        CDR one leaves the CDR one to be read.
        """
        foreign = foreign_channels(reader)
        left_out = {id(connection) for connection, _ in foreign}
        if left_out:
            reader.connections = [c for c in reader.connections if id(c) not in left_out]
        kept = {connection.topic for connection in reader.connections}
        self.notes, self.skipped_topics = [], {}
        for connection, why in sorted(foreign, key=lambda pair: (pair[0].topic, pair[0].id)):
            topic = connection.topic
            if topic in kept:
                self.notes.append(f'{topic}: its channel {connection.id} not read: {why} (its '
                                  'ROS CDR channel is read)')
            else:
                self.notes.append(f'{topic} not read: {why}')
                self.skipped_topics[topic] = '; '.join(
                    filter(None, (self.skipped_topics.get(topic), why)))

    def _setup(self, reader: AnyReader) -> None:
        """Prepare reading from the open reader (nothing here)."""

    def close(self) -> None:
        """Close the bag (idempotent)."""
        reader, self._reader = self._reader, None
        if reader is not None:
            close_quietly(reader)

    def __enter__(self: OpenedBag) -> OpenedBag:
        """
        Open the bag.

        :raises BagError: see :meth:`open`.
        """
        self.open()
        return self

    def __exit__(self, exc_type: Optional[Type[BaseException]],
                 exc_value: Optional[BaseException],
                 traceback: Optional[TracebackType]) -> None:
        """Close the bag."""
        self.close()

    def _open_reader(self) -> AnyReader:
        """
        Return the open AnyReader.

        :raises BagError: the bag is not open.
        """
        if self._reader is None:
            raise BagError(f'bag {self.path} is not open')
        return self._reader

    @property
    def start_time_ns(self) -> int:
        """
        Return the log time of the bag's first message, any topic (integer nanoseconds).

        :raises BagError: the bag is not open.
        """
        return int(self._open_reader().start_time)

    @property
    def end_time_ns(self) -> int:
        """
        Return the log time just after the bag's last message (integer nanoseconds).

        :raises BagError: the bag is not open.
        """
        return int(self._open_reader().end_time)
