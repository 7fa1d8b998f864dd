"""
Write bags: ROS 2 (MCAP or sqlite3, as a bag directory or a bare file) and ROS 1.

Messages are built from the rosbags typestore (ROS 2 Jazzy, or ROS 1 Noetic for ``.bag``) and
serialised by it (``serialize_cdr``, little-endian; ``serialize_ros1``). The output is staged
by :class:`baseball_collision.atomic.StagedOutput`: it appears whole on success, or not at all.
"""

import functools
import operator
import os
from pathlib import Path
import struct
from types import TracebackType
from typing import Any, Callable, Dict, Optional, Sequence, Tuple, Type, Union

from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
from rosbags.typesys import get_types_from_msg, get_typestore, Stores
from rosbags.typesys.store import Typestore

from .common import first_line, jazzy_typestore, noetic_typestore
from .names import POINT_STAMPED, POSE_STAMPED, TWIST_STAMPED, VECTOR3_STAMPED
from ..atomic import check_target, StagedOutput
from ..core.health import NS_PER_S
from ..errors import BagError

_STORAGES = ('mcap', 'sqlite3', 'rosbag1')
_FLOAT_COUNTS = {POINT_STAMPED: 3, POSE_STAMPED: 7, TWIST_STAMPED: 6, VECTOR3_STAMPED: 3}
_UINT32 = 2**32


def _layout(path: Path, storage: Optional[str]) -> Tuple[str, bool]:
    """
    Return ``(storage, bare_file)`` for an output path and a requested storage.

    ``.bag`` is ROS 1; ``.mcap`` and ``.db3`` are bare ROS 2 storage files; any other name is a
    ROS 2 bag directory (MCAP unless ``storage='sqlite3'``).

    :raises BagError: an unknown storage, or one that contradicts the file name.
    """
    suffix = path.suffix.lower()
    by_suffix = {'.bag': 'rosbag1', '.mcap': 'mcap', '.db3': 'sqlite3'}.get(suffix)
    if storage is not None and storage not in _STORAGES:
        raise BagError(f"unknown bag storage '{storage}'; use one of {', '.join(_STORAGES)}")
    if by_suffix is not None and storage is not None and storage != by_suffix:
        raise BagError(f"output {path} has a {suffix} name but storage '{storage}' was asked")
    if storage == 'rosbag1' and by_suffix is None:
        raise BagError(f'a ROS 1 bag needs a .bag file name, got {path}')
    if by_suffix is not None:
        return by_suffix, by_suffix != 'rosbag1'
    return storage or 'mcap', False


class _Serializer:
    """
    Builds stamped messages from the typestore and serialises them (ROS 1: ``seq`` per topic).

    :param ros1: ROS 1 Noetic types and serialisation; else ROS 2 Jazzy and little-endian CDR.
    :param typestore: the types (None: the shared Noetic or Jazzy store).
    """

    def __init__(self, ros1: bool, typestore: Optional[Typestore] = None) -> None:
        self.ros1 = ros1
        self.typestore = typestore or (noetic_typestore() if ros1 else jazzy_typestore())
        types = self.typestore.types
        self._time = types['builtin_interfaces/msg/Time']
        self._header = types['std_msgs/msg/Header']
        self._messages = {msgtype: types[msgtype] for msgtype in _FLOAT_COUNTS}
        point = types['geometry_msgs/msg/Point']
        quaternion = types['geometry_msgs/msg/Quaternion']
        vector3 = types['geometry_msgs/msg/Vector3']
        pose = types['geometry_msgs/msg/Pose']
        twist = types['geometry_msgs/msg/Twist']
        self._bodies: Dict[str, Callable[[Tuple[float, ...]], Any]] = {
            POINT_STAMPED: lambda v: point(*v),
            POSE_STAMPED: lambda v: pose(point(*v[:3]), quaternion(*v[3:])),
            TWIST_STAMPED: lambda v: twist(vector3(*v[:3]), vector3(*v[3:])),
            VECTOR3_STAMPED: lambda v: vector3(*v),
        }
        self.serialize: Callable[[Any, str], Any] = (
            self.typestore.serialize_ros1 if ros1
            else functools.partial(self.typestore.serialize_cdr, little_endian=True))
        self._seq: Dict[str, int] = {}

    def stamped(self, topic: str, msgtype: str, sec: int, nanosec: int, frame_id: str,
                values: Tuple[float, ...]) -> bytes:
        """
        Return a header + float64s message serialised.

        :raises struct.error, TypeError, ValueError: values that are not the type's numbers.
        """
        if len(values) != _FLOAT_COUNTS[msgtype]:
            raise ValueError(f'{len(values)} values')
        if self.ros1:
            seq = self._seq.get(topic, 0)
            self._seq[topic] = (seq + 1) & 0xFFFFFFFF
            # ROS 1 seconds are uint32, the typestore's int32: the same four bytes
            stamp = self._time(sec - _UINT32 if sec > 2**31 - 1 else sec, nanosec)
            header = self._header(seq, stamp, frame_id)
        else:
            header = self._header(self._time(sec, nanosec), frame_id)
        message = self._messages[msgtype](header, self._bodies[msgtype](values))
        return bytes(self.serialize(message, msgtype))


class BagWriter:
    """
    Write a bag atomically: staged beside ``path``, moved into place on success.

    The output is staged by :class:`~baseball_collision.atomic.StagedOutput` in a hidden
    temporary directory ``.<name>.<random>.partial`` beside ``path``; a finished file is
    hard-linked into place (which never replaces an existing file), a bag directory renamed. The
    temporary is removed on success, on :meth:`abort` and on an exception inside the ``with``
    block; only a killed process leaves it behind.

    Use as a context manager; on an exception inside the ``with`` block nothing is left behind::

        with BagWriter('out.mcap') as bag:
            bag.write_point('/ball', stamp_ns, 'world', (x, y, z))

    Output kinds, by ``path``: ``*.bag`` a ROS 1 bag; ``*.mcap`` / ``*.db3`` a bare ROS 2
    storage file (no metadata.yaml; rosbags reads it directly); anything else a ROS 2 bag
    directory (``metadata.yaml`` + storage file) in ``storage`` (default ``'mcap'``).
    Messages are built from :attr:`typestore` and serialised by it (CDR little-endian, or
    ROS 1 with ``header.seq`` counting from 0 on each topic).

    :param path: output path; must not exist, its parent directory must.
    :param storage: ``'mcap'``, ``'sqlite3'`` or ``'rosbag1'``; None to follow the file name.
    :raises BagError: the output exists, its directory is missing (or is not a directory), or
        storage and name clash.
    """

    def __init__(self, path: Union[str, os.PathLike], storage: Optional[str] = None) -> None:
        self.path = Path(path)
        self.storage, self.bare_file = _layout(self.path, storage)
        try:
            check_target(self.path)
        except FileExistsError as error:
            raise BagError(f'output {self.path} exists already; not overwriting') from error
        except FileNotFoundError as error:
            raise BagError(f'output directory {self.path.parent} does not exist') from error
        except NotADirectoryError as error:
            raise BagError(f'output directory {self.path.parent} is not a directory') from error
        self._ros1 = self.storage == 'rosbag1'
        self._staged: Optional[StagedOutput] = None
        self._inner = self.path
        self._writer: Any = None
        self._connections: Dict[str, Any] = {}
        self._types: Dict[str, str] = {}
        self._serializer = _Serializer(self._ros1)
        self._max_sec = _UINT32 - 1 if self._ros1 else 2**31 - 1
        self._min_sec = 0 if self._ros1 else -2**31

    @property
    def typestore(self) -> Any:
        """Return the rosbags typestore to build :meth:`write_message` messages from."""
        return self._serializer.typestore

    def register_definition(self, msgtype: str, definition: str) -> None:
        """
        Make a message type known to this bag from its ``.msg`` definition (a bag's own).

        The definition as rosbag2 records it (the type's ``.msg`` text, the types it uses
        appended after ``====`` lines) is parsed by rosbags (``get_types_from_msg``); the types
        this bag does not know yet are added to its own copy of the typestore (the shared
        Jazzy or Noetic store is left as it is), so :meth:`add_topic` can declare the type and
        the bag records its definition.

        :raises BagError: the definition cannot be parsed, or its types cannot be added (a
            clash with a known type's definition, a type it uses missing).
        """
        try:
            types = get_types_from_msg(definition, msgtype)
        except Exception as error:
            raise BagError(f'cannot read the definition of {msgtype}: '
                           f'{first_line(error)}') from error
        store = self.typestore
        if store is jazzy_typestore() or store is noetic_typestore():
            store = get_typestore(Stores.ROS1_NOETIC if self._ros1 else Stores.ROS2_JAZZY)
        try:
            store.register({name: fields for name, fields in types.items()
                            if name not in store.fielddefs})
            store.generate_msgdef(msgtype, ros_version=1 if self._ros1 else 2)
        except Exception as error:
            raise BagError(f'cannot add the definition of {msgtype}: '
                           f'{first_line(error)}') from error
        if store is not self.typestore:
            self._serializer = _Serializer(self._ros1, store)

    def open(self) -> None:  # noqa: A003 - the rosbags reader/writer name
        """
        Stage the output and open the rosbags writer.

        :raises BagError: already open, the output appeared meanwhile, or it cannot be created.
        """
        if self._writer is not None:
            raise BagError(f'bag writer for {self.path} is already open')
        try:
            staged = StagedOutput(self.path)
        except FileExistsError as error:
            raise BagError(f'output {self.path} exists already; not overwriting') from error
        except OSError as error:
            raise BagError(f'cannot create bag {self.path}: {first_line(error)}') from error
        # a bare storage file is the one file of a bag directory staged under another name
        inner = staged.path.with_name('bag') if self.bare_file else staged.path
        try:
            if self._ros1:
                writer: Any = Writer1(inner)
            else:
                plugin = StoragePlugin.MCAP if self.storage == 'mcap' else StoragePlugin.SQLITE3
                writer = Writer2(inner, version=9, storage_plugin=plugin)
            writer.open()
        except Exception as error:
            staged.abort()
            raise BagError(f'cannot create bag {self.path}: {first_line(error)}') from error
        self._staged = staged
        self._inner = inner
        self._writer = writer

    def close(self) -> None:
        """
        Finish the bag and move it into place.

        :raises BagError: the bag cannot be finished, or the output path appeared meanwhile
            (the staged output is removed in both cases).
        """
        writer, self._writer = self._writer, None
        staged, self._staged = self._staged, None
        if writer is None or staged is None:
            return
        try:
            writer.close()
            if self.bare_file:
                suffix = '.mcap' if self.storage == 'mcap' else '.db3'
                staged.commit(self._inner / f'bag{suffix}')
            else:
                staged.commit()
        except FileExistsError as error:
            raise BagError(f'output {self.path} exists already; not overwriting') from error
        except Exception as error:
            raise BagError(f'cannot write bag {self.path}: {first_line(error)}') from error
        finally:
            staged.abort()

    def abort(self) -> None:
        """Stop writing and delete the staged output (idempotent)."""
        writer, self._writer = self._writer, None
        staged, self._staged = self._staged, None
        if writer is not None:
            try:
                writer.abort()
            except Exception:  # noqa: S110 - the files are deleted next anyway
                pass
        if staged is not None:
            staged.abort()

    def __enter__(self) -> 'BagWriter':
        """
        Open the writer.

        :raises BagError: see :meth:`open`.
        """
        self.open()
        return self

    def __exit__(self, exc_type: Optional[Type[BaseException]],
                 exc_value: Optional[BaseException],
                 traceback: Optional[TracebackType]) -> None:
        """
        Finish the bag, or on an exception delete the staged output and let it propagate.

        :raises BagError: see :meth:`close`.
        """
        if exc_type is None:
            self.close()
        else:
            self.abort()

    def add_topic(self, name: str, msgtype: str, qos_profiles: Sequence[Any] = ()) -> None:
        """
        Declare a topic (writing to an undeclared topic declares it with the written type).

        :param name: topic name, e.g. ``'/ball'``.
        :param msgtype: message type, e.g. ``'geometry_msgs/msg/PointStamped'``.
        :param qos_profiles: the QoS offered by its publishers (rosbags ``Qos``, e.g. from
            :func:`.messages.qos_profile` or a read bag), recorded in a ROS 2 bag; a ROS 1 bag
            records none.
        :raises BagError: the writer is not open, the type is unknown, or the topic was declared
            with another type.
        """
        if self._writer is None:
            raise BagError(f'bag writer for {self.path} is not open')
        known = self._types.get(name)
        if known is not None:
            if known != msgtype:
                raise BagError(f"topic '{name}' is already declared as {known}, not {msgtype}")
            return
        if msgtype not in self.typestore.types:
            raise BagError(f"unknown message type '{msgtype}' for topic '{name}'")
        try:
            extra = {} if self._ros1 else {'offered_qos_profiles': tuple(qos_profiles)}
            connection = self._writer.add_connection(name, msgtype, typestore=self.typestore,
                                                     **extra)
        except Exception as error:
            raise BagError(f"cannot add topic '{name}': {first_line(error)}") from error
        self._connections[name] = connection
        self._types[name] = msgtype

    def write_serialized(self, topic: str, msgtype: str, log_time_ns: int, data: bytes) -> None:
        """
        Write a message serialised as this bag stores it (ROS 2: CDR; ROS 1: ROS 1 bytes).

        Declares the topic first if needed (without QoS: :meth:`add_topic` records it).

        :raises BagError: not open, a clashing type, a bad log time, or a writer failure.
        """
        if self._writer is None:
            raise BagError(f'bag writer for {self.path} is not open')
        if self._types.get(topic) != msgtype:
            self.add_topic(topic, msgtype)
        try:
            log_time_ns = operator.index(log_time_ns)
        except TypeError:
            log_time_ns = -1
        if log_time_ns < 0:
            raise BagError(f'log time must be a non-negative integer of ns, got {log_time_ns!r}')
        try:
            self._writer.write(self._connections[topic], log_time_ns, data)
        except Exception as error:
            raise BagError(f"cannot write to '{topic}': {first_line(error)}") from error

    def _stamped(self, topic: str, msgtype: str, stamp_ns: int, frame_id: str,
                 floats: Sequence[float], log_time_ns: Optional[int]) -> None:
        """
        Build a header + float64 message, serialise it with the typestore, and write it.

        :raises BagError: see the public ``write_*`` methods.
        """
        try:
            stamp_ns = operator.index(stamp_ns)
        except TypeError as error:
            raise BagError(f'stamp must be integer nanoseconds, got {stamp_ns!r}') from error
        sec, nanosec = divmod(stamp_ns, NS_PER_S)
        if not self._min_sec <= sec <= self._max_sec:
            raise BagError(f'stamp {stamp_ns} ns is out of range for this bag format')
        if not isinstance(frame_id, str) or '\x00' in frame_id:
            raise BagError(f'frame_id must be a string without NUL, got {frame_id!r}')
        try:
            data = self._serializer.stamped(topic, msgtype, sec, nanosec, frame_id,
                                            tuple(floats))
        except (struct.error, TypeError, ValueError) as error:
            raise BagError(
                f"cannot write {msgtype} to '{topic}': expected {_FLOAT_COUNTS[msgtype]} "
                f'numbers, got {floats!r}') from error
        log_time_ns = stamp_ns if log_time_ns is None else log_time_ns
        self.write_serialized(topic, msgtype, log_time_ns, data)

    def write_point(self, topic: str, stamp_ns: int, frame_id: str, xyz: Sequence[float],
                    log_time_ns: Optional[int] = None) -> None:
        """
        Write a ``geometry_msgs/msg/PointStamped``.

        :param topic: topic name.
        :param stamp_ns: ``header.stamp`` in integer nanoseconds.
        :param frame_id: ``header.frame_id``.
        :param xyz: point (metres).
        :param log_time_ns: bag log time in integer nanoseconds; None for ``stamp_ns``.
        :raises BagError: not open, bad stamp/values/frame_id, or a clashing topic type.
        """
        self._stamped(topic, POINT_STAMPED, stamp_ns, frame_id, xyz, log_time_ns)

    def write_pose(self, topic: str, stamp_ns: int, frame_id: str, position: Sequence[float],
                   quaternion_xyzw: Sequence[float], log_time_ns: Optional[int] = None) -> None:
        """
        Write a ``geometry_msgs/msg/PoseStamped``.

        :param position: position (metres).
        :param quaternion_xyzw: orientation ``(x, y, z, w)``, written as given.
        :raises BagError: see :meth:`write_point`.
        """
        self._stamped(topic, POSE_STAMPED, stamp_ns, frame_id,
                      (*position, *quaternion_xyzw), log_time_ns)

    def write_twist(self, topic: str, stamp_ns: int, frame_id: str, linear: Sequence[float],
                    angular: Sequence[float], log_time_ns: Optional[int] = None) -> None:
        """
        Write a ``geometry_msgs/msg/TwistStamped``.

        :param linear: linear velocity (m/s).
        :param angular: angular velocity (rad/s).
        :raises BagError: see :meth:`write_point`.
        """
        self._stamped(topic, TWIST_STAMPED, stamp_ns, frame_id, (*linear, *angular),
                      log_time_ns)

    def write_vector3(self, topic: str, stamp_ns: int, frame_id: str, vector: Sequence[float],
                      log_time_ns: Optional[int] = None) -> None:
        """
        Write a ``geometry_msgs/msg/Vector3Stamped``.

        :param vector: the vector (units of the caller's choosing, e.g. m/s).
        :raises BagError: see :meth:`write_point`.
        """
        self._stamped(topic, VECTOR3_STAMPED, stamp_ns, frame_id, vector, log_time_ns)

    def write_message(self, topic: str, message: Any, log_time_ns: int) -> None:
        """
        Write any message built from :attr:`typestore` (serialised by rosbags).

        :param message: a typestore message object (its type is ``message.__msgtype__``).
        :param log_time_ns: bag log time in integer nanoseconds.
        :raises BagError: not open, a clashing topic type, or a message that cannot be
            serialised.
        """
        msgtype = getattr(message, '__msgtype__', None)
        if not isinstance(msgtype, str):
            raise BagError(f"cannot write {type(message).__name__} to '{topic}': not a message")
        try:
            data = self._serializer.serialize(message, msgtype)
        except Exception as error:
            raise BagError(
                f"cannot serialise {msgtype} for '{topic}': {first_line(error)}") from error
        self.write_serialized(topic, msgtype, log_time_ns, bytes(data))
