"""
Any bag's messages as serialised CDR, in log-time order: what a replay publishes.

ROS 2 bags (MCAP, sqlite3) give the recorded CDR bytes as they are. ROS 1 bags are converted
to ROS 2 CDR by rosbags' own conversion (the converter ``rosbags-convert`` uses: byte-level
``Typestore.ros1_to_cdr`` where the ROS 1 and ROS 2 Jazzy definitions have the same wire
format, ``header.seq`` dropped; a migration through the deserialised message where they
differ). Nothing is deserialised for a ROS 2 bag.
"""

import contextlib
import io
import os
from typing import (
    Any, Callable, Dict, Iterable, Iterator, List, NamedTuple, Optional, Tuple, Union)

from rosbags.convert.converter import generate_message_converter
from rosbags.highlevel import AnyReader
from rosbags.interfaces import MessageDefinitionFormat

from .common import BagFile, first_line, jazzy_typestore
from .messages import qos_profile
from ..errors import BagError


class RawTopic(NamedTuple):
    """
    One topic of a bag, as recorded.

    :ivar name: topic name.
    :ivar msgtype: its one message type (``pkg/msg/Name``).
    :ivar message_count: its messages in the bag (from the index).
    :ivar reliability: ``'reliable'`` or ``'best_effort'`` as offered by the recording
        publishers (ROS 2 bags), '' when not recorded or not the same for all.
    :ivar durability: ``'transient_local'`` (ROS 2, or a latched ROS 1 topic) or
        ``'volatile'``, '' when not recorded or not the same for all.
    :ivar qos_profiles: the QoS profiles offered by the recording publishers (rosbags
        ``Qos``, as a ROS 2 bag records them; a ROS 1 bag: one profile with its latching).
    """

    name: str
    msgtype: str
    message_count: int
    reliability: str
    durability: str
    qos_profiles: Tuple[Any, ...] = ()


class RawMessage(NamedTuple):
    """
    One message of a bag, serialised.

    :ivar topic: topic name.
    :ivar msgtype: message type (``pkg/msg/Name``).
    :ivar log_time_ns: when it was recorded (integer nanoseconds).
    :ivar data: the message as CDR bytes (ROS 2 serialisation, with its encapsulation header).
    """

    topic: str
    msgtype: str
    log_time_ns: int
    data: bytes


def _profiles(connections: List[Any]) -> Tuple[Any, ...]:
    """Return the QoS profiles a topic's connections offered (ROS 1: from the latching)."""
    profiles: List[Any] = []
    for connection in connections:
        if hasattr(connection.ext, 'callerid'):  # ROS 1: latched or not, nothing more
            latched = bool(getattr(connection.ext, 'latching', None))
            profiles.append(qos_profile(depth=1 if latched else 10, transient_local=latched))
        else:
            profiles += getattr(connection.ext, 'offered_qos_profiles', None) or ()
    return tuple(dict.fromkeys(profiles))


def _qos(connections: List[Any]) -> Dict[str, str]:
    """Return the reliability and durability all of a topic's connections agree on."""
    found: Dict[str, set] = {'reliability': set(), 'durability': set()}
    for connection in connections:
        latching = getattr(connection.ext, 'latching', None)
        if latching is not None:
            found['durability'].add('transient_local' if latching else 'volatile')
        for profile in getattr(connection.ext, 'offered_qos_profiles', None) or ():
            for name in found:
                value = getattr(profile, name, None)
                found[name].add(getattr(value, 'name', '').lower())
    return {name: values.pop() if len(values) == 1 else '' for name, values in found.items()}


def _definition(connections: List[Any]) -> Tuple[str, str]:
    """Return the first definition a topic's connections hold: ('msg' or 'idl', text), or none."""
    formats = {MessageDefinitionFormat.MSG: 'msg', MessageDefinitionFormat.IDL: 'idl'}
    for connection in connections:
        msgdef = getattr(connection, 'msgdef', None)
        if msgdef is not None and msgdef.format in formats and msgdef.data:
            return formats[msgdef.format], str(msgdef.data)
    return '', ''


def _ros1_converter(reader: AnyReader, msgtype: str) -> Callable[[bytes], Any]:
    """
    Return rosbags' ROS 1 -> ROS 2 (Jazzy) CDR converter of a message type.

    :raises KeyError: the type has no ROS 2 Jazzy definition.
    """
    target = jazzy_typestore()
    if msgtype not in target.fielddefs:
        raise KeyError(msgtype)
    # rosbags prints a line when a type must be migrated; this is a library, not its CLI
    with contextlib.redirect_stdout(io.StringIO()):
        return generate_message_converter(reader.typestore, target, msgtype, msgtype, {},
                                          src_is2=False, dst_is2=True)


class RawBag(BagFile):
    """
    A bag's topics and its messages as CDR bytes, in log-time order across topics.

    Use as a context manager::

        with RawBag('run.bag') as bag:
            for message in bag.messages(['/ball']):
                publish(message.topic, message.data)

    A topic with several message types, or (ROS 1) with a type ROS 2 Jazzy does not define, or
    whose messages are not ROS (an MCAP's JSON or protobuf channel), is not offered: it is
    listed in :attr:`skipped` with the reason.

    :param path: ROS 2 bag directory, bare ``.mcap``/``.db3`` file, or ROS 1 ``.bag`` file.
    """

    def __init__(self, path: Union[str, os.PathLike]) -> None:
        super().__init__(path)
        self._topics: Dict[str, RawTopic] = {}
        self._order: List[Any] = []
        self._convert: Dict[int, Callable[[bytes], Any]] = {}
        self._definitions: Dict[str, Tuple[str, str]] = {}
        self.skipped: Dict[str, str] = {}
        """Topics not offered, with why (several types, no ROS 2 type)."""

    def _setup(self, reader: AnyReader) -> None:
        """
        List the topics of an open reader and prepare the ROS 1 converters.

        :raises BagError: no messages, or the reader fails.
        """
        try:
            total = reader.message_count
            connections = list(reader.connections)
        except Exception as error:
            raise BagError(f'cannot read bag {self.path}: {first_line(error)}') from error
        if total == 0:
            raise BagError(f'bag {self.path} contains no messages')
        self.skipped.update(self.skipped_topics)  # (not ROS: taken out by BagFile.open)
        by_topic: Dict[str, List[Any]] = {}
        for connection in connections:
            by_topic.setdefault(connection.topic, []).append(connection)
        for topic, group in sorted(by_topic.items()):
            msgtypes = sorted({c.msgtype for c in group})
            if len(msgtypes) != 1:
                self.skipped[topic] = f'several types: {" | ".join(msgtypes)}'
                continue
            try:
                for connection in group:
                    self._convert[id(connection)] = bytes if reader.is2 else _ros1_converter(
                        reader, connection.msgtype)
            except KeyError:
                self.skipped[topic] = f'no ROS 2 type {msgtypes[0]}'
                continue
            if reader.is2:
                self._definitions[topic] = _definition(group)
            self._topics[topic] = RawTopic(topic, msgtypes[0],
                                           sum(max(int(c.msgcount), 0) for c in group),
                                           **_qos(group), qos_profiles=_profiles(group))
        self._order = [c for c in connections if c.topic in self._topics]

    def definition(self, topic: str) -> Tuple[str, str]:
        """
        Return the message definition a ROS 2 bag holds for a topic's type: (format, text).

        The format is ``'msg'`` (the ``.msg`` text rosbag2 records, the types it uses appended)
        or ``'idl'``; ``('', '')`` where the bag holds none (an older bag, or ROS 1: its
        definitions are ROS 1's).

        :raises BagError: the bag is not open, or offers no such topic.
        """
        self._open_reader()
        if topic not in self._topics:
            raise BagError(f'bag {self.path} offers no topic {topic}')
        return self._definitions.get(topic, ('', ''))

    @property
    def is_ros1(self) -> bool:
        """
        Return True for a ROS 1 bag (its messages are converted to CDR).

        :raises BagError: the bag is not open.
        """
        return not self._open_reader().is2

    @property
    def topics(self) -> Dict[str, RawTopic]:
        """
        Return the topics :meth:`messages` can give, by name (sorted).

        :raises BagError: the bag is not open.
        """
        self._open_reader()
        return dict(self._topics)

    def messages(self, topics: Optional[Iterable[str]] = None) -> Iterator[RawMessage]:
        """
        Yield the messages of some topics as CDR, in log-time order across them; streams.

        :param topics: topics of :attr:`topics`; None for all of them.
        :returns: an iterator of :class:`RawMessage`.
        :raises BagError: the bag is not open, a topic it does not offer, or the bag turns out
            corrupt (raised while iterating).
        """
        reader = self._open_reader()
        names = list(self._topics) if topics is None else list(topics)
        unknown = [name for name in names if name not in self._topics]
        if unknown:
            raise BagError(f"bag {self.path} offers no topic {', '.join(unknown)}")
        wanted = set(names)
        # in the bag's connection order: it decides the order of messages logged at one time
        connections = [c for c in self._order if c.topic in wanted]
        return self._messages(reader, connections)

    def _messages(self, reader: AnyReader, connections: List[Any]) -> Iterator[RawMessage]:
        """Yield raw messages (the generator behind :meth:`messages`)."""
        if not connections:
            return
        convert = self._convert
        try:
            for connection, log_time, raw in reader.messages(connections=connections):
                yield RawMessage(connection.topic, connection.msgtype, log_time,
                                 bytes(convert[id(connection)](raw)))
        except Exception as error:
            raise BagError(f'cannot read bag {self.path}: {first_line(error)}') from error
