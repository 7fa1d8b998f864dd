"""
What the bag modules share: message type names, the rosbags typestores, opening a bag.

Every bag is opened here (:func:`open_bag`, :class:`BagFile`), so reading samples and replaying
raw messages refuse the same paths with the same one-line :class:`BagError`.
"""

import functools
import os
from pathlib import Path
from types import TracebackType
from typing import Optional, Type, TypeVar, Union

from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
from rosbags.typesys.store import Typestore

from ..errors import BagError

POINT_STAMPED = 'geometry_msgs/msg/PointStamped'
POSE_STAMPED = 'geometry_msgs/msg/PoseStamped'
TWIST_STAMPED = 'geometry_msgs/msg/TwistStamped'
VECTOR3_STAMPED = 'geometry_msgs/msg/Vector3Stamped'

NS_PER_S = 1_000_000_000
FRAME_CACHE_LIMIT = 1024
"""Most frame_ids a decoder or writer remembers (the cache is emptied when full)."""


@functools.lru_cache(maxsize=None)
def jazzy_typestore() -> Typestore:
    """Return the ROS 2 Jazzy typestore (built once)."""
    return get_typestore(Stores.ROS2_JAZZY)


@functools.lru_cache(maxsize=None)
def noetic_typestore() -> Typestore:
    """Return the ROS 1 Noetic typestore (built once)."""
    return get_typestore(Stores.ROS1_NOETIC)


def first_line(error: BaseException) -> str:
    """Return the first line of an error's message, or its type name if it has none."""
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__


def open_bag(path: Union[str, os.PathLike]) -> AnyReader:
    """
    Open a bag with rosbags' :class:`AnyReader` (ROS 2 types default to Jazzy).

    :param path: ROS 2 bag directory, bare ``.mcap`` or ``.db3`` file, or ROS 1 ``.bag`` file.
    :returns: the open reader (close it).
    :raises BagError: path missing, not a bag (a directory without ``metadata.yaml``, another
        file suffix), or unreadable or corrupt.
    """
    path = Path(path)
    if not path.exists():
        raise BagError(f'bag not found: {path}')
    if path.is_dir() and not (path / 'metadata.yaml').is_file():
        raise BagError(f'not a ROS 2 bag directory (no metadata.yaml): {path}')
    if not path.is_dir() and path.suffix not in ('.mcap', '.db3', '.bag'):
        raise BagError(
            f'not a bag: {path} (expected a bag directory or a .mcap, .db3 or .bag file)')
    try:
        reader = AnyReader([path], default_typestore=jazzy_typestore())
        reader.open()
    except Exception as error:
        raise BagError(f'cannot read bag {path}: {first_line(error)}') from error
    return reader


def close_quietly(reader: AnyReader) -> None:
    """Close a reader, ignoring errors (nothing useful to report on close)."""
    try:
        reader.close()
    except Exception:  # noqa: S110 - a first error, if any, is the one to report
        pass


OpenedBag = TypeVar('OpenedBag', bound='BagFile')


class BagFile:
    """
    A bag read through an :class:`AnyReader`: open and close, context manager, log times.

    Subclasses prepare what they read in :meth:`_setup` (called on the open reader; an error
    there closes it again).

    :param path: ROS 2 bag directory, bare ``.mcap``/``.db3`` file, or ROS 1 ``.bag`` file.
    """

    def __init__(self, path: Union[str, os.PathLike]) -> None:
        self.path = Path(path)
        self._reader: Optional[AnyReader] = None

    def open(self) -> None:  # noqa: A003 - the rosbags reader name
        """
        Open the bag and prepare it (:meth:`_setup`).

        :raises BagError: already open, path missing, not a bag, unreadable or corrupt, or
            refused by the set-up (e.g. no messages).
        """
        if self._reader is not None:
            raise BagError(f'bag {self.path} is already open')
        reader = open_bag(self.path)
        try:
            self._setup(reader)
        except BaseException:
            close_quietly(reader)
            raise
        self._reader = reader

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
