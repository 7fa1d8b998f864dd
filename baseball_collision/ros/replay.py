"""
Replay a bag over ROS 2, as ``ros2 bag play --clock`` would (there is no ros2 CLI here).

Every topic of the bag whose type rclpy can import is published with its own name and type:

* Pacing: a message is published when the wall time since the start reaches its log time since
  the bag's first log time, divided by ``rate``.
* ``/clock`` (``rosgraph_msgs/Clock``) at ``clock_hz``: the bag time the pacing has reached, so
  nodes with ``use_sim_time`` follow the bag. ``loop`` restarts from the first message, and the
  clock jumps back (a node resets on that).
* QoS: reliable, volatile, keep-last with a deep queue (``depth``), so a live subscriber that
  asks for reliable delivery gets every message; at the end the player waits until the
  subscribers acknowledged everything.
* ROS 2 bags (MCAP, sqlite3) are published as the recorded CDR bytes (no decode); ROS 1 bags
  are deserialised by rosbags and copied field by field into the rclpy message (``header.seq``
  has no ROS 2 counterpart and is dropped).

This is the only module besides ``node`` that imports rclpy.
"""

from dataclasses import dataclass, field
import importlib
import os
from pathlib import Path
import threading
import time
from typing import Any, Callable, Dict, List, Optional, Sequence

from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
from rosgraph_msgs.msg import Clock

from ..errors import RosError

CLOCK_TOPIC = '/clock'
"""Where the bag time is published."""

DEFAULT_DEPTH = 10000
"""Keep-last depth of every replay publisher (messages)."""


def message_class(msgtype: str) -> Any:
    """
    Return the rclpy message class of a ROS 2 type name (``pkg/msg/Name``).

    :raises RosError: the package or message is not installed.
    """
    package, _, name = msgtype.partition('/msg/')
    try:
        return getattr(importlib.import_module(f'{package}.msg'), name)
    except (ImportError, AttributeError, ValueError) as error:
        raise RosError(f'message type {msgtype} is not available to rclpy') from error


def _slot_class(cls: Any, index: int) -> Optional[Any]:
    """Return the message class of the elements of a sequence field, or None for primitives."""
    value_type = getattr(cls.SLOT_TYPES[index], 'value_type', None)
    namespaces = getattr(value_type, 'namespaces', None)
    if not namespaces:
        return None
    return message_class(f'{namespaces[0]}/msg/{value_type.name}')


def to_rclpy(value: Any, cls: Any) -> Any:
    """
    Copy a rosbags message (e.g. deserialised from a ROS 1 bag) into an rclpy message.

    Fields are matched by name; fields the rclpy type does not have (``header.seq``) are dropped,
    fields the source lacks keep their defaults. Nested messages and sequences of messages are
    copied recursively, numpy arrays as lists.

    :param value: the rosbags message object.
    :param cls: the rclpy message class.
    :returns: the rclpy message.
    """
    message = cls()
    for index, name in enumerate(cls.get_fields_and_field_types()):
        if not hasattr(value, name):
            continue
        source = getattr(value, name)
        current = getattr(message, name)
        if hasattr(type(current), 'get_fields_and_field_types'):
            setattr(message, name, to_rclpy(source, type(current)))
            continue
        if hasattr(source, 'tolist'):
            source = source.tolist()
        if isinstance(source, (list, tuple)) and source and hasattr(source[0], '__msgtype__'):
            element = _slot_class(cls, index)
            source = [to_rclpy(item, element) for item in source]
        setattr(message, name, source)
    return message


def _reliable(depth: int) -> QoSProfile:
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)


def _first_line(error: BaseException) -> str:
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__


@dataclass
class ReplayResult:
    """
    What a replay did.

    :ivar messages: messages published (over all loops).
    :ivar loops: complete passes over the bag.
    :ivar seconds: wall time of the playback (s).
    :ivar skipped_topics: topics not published (type unknown to rclpy, or several types).
    """

    messages: int = 0
    loops: int = 0
    seconds: float = 0.0
    skipped_topics: List[str] = field(default_factory=list)


class BagPlayer:
    """
    Publish a bag's topics from a node, paced by log time, with ``/clock``.

    Use as a context manager (closes the bag and destroys the publishers)::

        with BagPlayer(node, 'run.mcap', rate=2.0) as player:
            player.wait_for_subscribers(['/ball'], timeout_s=10.0)
            player.play()

    :param node: the rclpy node that owns the publishers (it need not spin).
    :param path: ROS 2 bag directory, ``.mcap``/``.db3`` file, or ROS 1 ``.bag`` file.
    :param rate: playback speed factor (> 0; 2.0 plays twice as fast).
    :param clock_hz: ``/clock`` publication rate (Hz, wall time); 0 for no clock.
    :param depth: keep-last depth of the publishers.
    :raises RosError: a missing or unreadable bag, an empty one, no topic rclpy knows, or a
        bad rate.
    """

    def __init__(self, node: Node, path: os.PathLike, rate: float = 1.0,
                 clock_hz: float = 200.0, depth: int = DEFAULT_DEPTH) -> None:
        if not rate > 0.0 or rate == float('inf'):
            raise RosError(f'rate must be a finite number > 0, got {rate}')
        if not clock_hz >= 0.0:
            raise RosError(f'clock rate must be >= 0 Hz, got {clock_hz}')
        self.node = node
        self.path = Path(path)
        self.rate = float(rate)
        self.clock_period = 1.0 / clock_hz if clock_hz > 0.0 else 0.0
        self.result = ReplayResult()
        self._reader = self._open()
        self._publishers: Dict[str, Any] = {}
        self._convert: Dict[int, Callable[[bytes], Any]] = {}
        self._connections: List[Any] = []
        try:
            self._setup(depth)
        except BaseException:
            self.close()
            raise
        self._clock = node.create_publisher(Clock, CLOCK_TOPIC, _reliable(10)) \
            if self.clock_period else None

    def _open(self) -> AnyReader:
        """
        Open the bag.

        :raises RosError: missing, not a bag, unreadable or empty.
        """
        if not self.path.exists():
            raise RosError(f'bag not found: {self.path}')
        try:
            reader = AnyReader([self.path], default_typestore=get_typestore(Stores.ROS2_JAZZY))
            reader.open()
        except Exception as error:
            raise RosError(f'cannot read bag {self.path}: {_first_line(error)}') from error
        if reader.message_count == 0:
            reader.close()
            raise RosError(f'bag {self.path} contains no messages')
        return reader

    def _setup(self, depth: int) -> None:
        """
        Create a publisher per topic whose one type rclpy can import.

        :raises RosError: no topic can be published.
        """
        types: Dict[str, set] = {}
        for connection in self._reader.connections:
            types.setdefault(connection.topic, set()).add(connection.msgtype)
        for topic, msgtypes in sorted(types.items()):
            if len(msgtypes) != 1:
                self.result.skipped_topics.append(topic)
                continue
            msgtype = next(iter(msgtypes))
            try:
                cls = message_class(msgtype)
            except RosError:
                self.result.skipped_topics.append(topic)
                continue
            self._publishers[topic] = self.node.create_publisher(cls, topic, _reliable(depth))
        self._connections = [c for c in self._reader.connections if c.topic in self._publishers]
        if not self._connections:
            raise RosError(f'bag {self.path} has no topic of a type rclpy knows')
        ros2 = self._reader.is2
        for connection in self._connections:
            if ros2:
                self._convert[id(connection)] = bytes
            else:
                self._convert[id(connection)] = self._ros1_converter(connection)

    def _ros1_converter(self, connection: Any) -> Callable[[bytes], Any]:
        """Return raw ROS 1 bytes -> rclpy message for one connection."""
        cls = self._publishers[connection.topic].msg_type
        deserialize = self._reader.deserialize
        msgtype = connection.msgtype

        def convert(raw: bytes) -> Any:
            return to_rclpy(deserialize(raw, msgtype), cls)
        return convert

    @property
    def message_count(self) -> int:
        """Return the number of messages one pass publishes."""
        return sum(max(int(c.msgcount), 0) for c in self._connections)

    @property
    def topics(self) -> List[str]:
        """Return the topics this player publishes."""
        return sorted(self._publishers)

    def wait_for_subscribers(self, topics: Sequence[str], timeout_s: float,
                             stop: Optional[threading.Event] = None) -> None:
        """
        Wait until each topic has at least one matched subscription.

        :param topics: topics of the bag, or ``/clock``.
        :param timeout_s: how long to wait (s).
        :param stop: set it to give up early (raises as a timeout).
        :raises RosError: a topic the bag does not publish, or the timeout passed.
        """
        publishers = dict(self._publishers)
        if self._clock is not None:
            publishers[CLOCK_TOPIC] = self._clock
        missing = [topic for topic in topics if topic not in publishers]
        if missing:
            raise RosError(
                f"cannot wait for {', '.join(missing)}: not published from this bag "
                f"(topics: {', '.join(sorted(publishers))})")
        deadline = time.monotonic() + timeout_s
        while True:
            waiting = [t for t in topics if publishers[t].get_subscription_count() < 1]
            if not waiting:
                return
            if time.monotonic() >= deadline or (stop is not None and stop.is_set()):
                raise RosError(
                    f"no subscriber on {', '.join(waiting)} after {timeout_s:.1f} s")
            time.sleep(0.02)

    def _publish_clock(self, stamp_ns: int) -> None:
        if self._clock is not None:
            message = Clock()
            message.clock.sec, message.clock.nanosec = divmod(int(stamp_ns), 1_000_000_000)
            self._clock.publish(message)

    def play(self, loop: bool = False, stop: Optional[threading.Event] = None,
             ack_timeout_s: float = 5.0) -> ReplayResult:
        """
        Publish the bag (again and again with ``loop``) until done or ``stop`` is set.

        :param loop: restart at the end (the clock jumps back to the bag start).
        :param stop: an event that ends the playback when set.
        :param ack_timeout_s: at the end, wait this long for reliable subscribers to
            acknowledge every message (s).
        :returns: the counts (also kept in :attr:`result`).
        :raises RosError: the bag turns out corrupt while reading.
        """
        started = time.monotonic()
        begin = int(self._reader.start_time)
        publishers = {id(c): self._publishers[c.topic] for c in self._connections}
        convert = self._convert
        period = self.clock_period
        scale = 1e-9 / self.rate
        try:
            while not (stop is not None and stop.is_set()):
                wall0 = time.monotonic()
                next_clock = wall0 + period
                self._publish_clock(begin)
                for connection, log_time, raw in self._reader.messages(self._connections):
                    due = wall0 + (log_time - begin) * scale
                    while True:
                        now = time.monotonic()
                        if period and now >= next_clock:
                            self._publish_clock(begin + int((now - wall0) * self.rate * 1e9))
                            next_clock = max(next_clock + period, now)
                        if now >= due:
                            break
                        wait = min(due, next_clock) - now if period else due - now
                        if stop is not None:
                            if stop.wait(max(wait, 0.0)):
                                return self._finish(started, ack_timeout_s)
                        else:
                            time.sleep(max(wait, 0.0))
                    key = id(connection)
                    publishers[key].publish(convert[key](raw))
                    self.result.messages += 1
                self.result.loops += 1
                if not loop:
                    break
        except RosError:
            raise
        except Exception as error:
            raise RosError(f'cannot read bag {self.path}: {_first_line(error)}') from error
        return self._finish(started, ack_timeout_s)

    def _finish(self, started: float, ack_timeout_s: float) -> ReplayResult:
        """Wait for acknowledgements; record the wall time."""
        timeout = Duration(nanoseconds=int(ack_timeout_s * 1e9))
        for publisher in self._publishers.values():
            publisher.wait_for_all_acked(timeout)
        self.result.seconds = time.monotonic() - started
        return self.result

    def close(self) -> None:
        """Close the bag and destroy the publishers (idempotent)."""
        for publisher in list(self._publishers.values()):
            self.node.destroy_publisher(publisher)
        self._publishers.clear()
        clock, self._clock = getattr(self, '_clock', None), None
        if clock is not None:
            self.node.destroy_publisher(clock)
        reader, self._reader = self._reader, None
        if reader is not None:
            try:
                reader.close()
            except Exception:  # noqa: S110 - nothing useful to report on close
                pass

    def __enter__(self) -> 'BagPlayer':
        """Return the player."""
        return self

    def __exit__(self, exc_type: Any, exc_value: Any, traceback: Any) -> None:
        """Close the player."""
        self.close()
