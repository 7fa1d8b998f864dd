"""Tests for baseball_collision.bags raw messages: any bag as CDR bytes, for a replay."""

from pathlib import Path
from typing import Any, Dict, List, Tuple

from baseball_collision.bags import BagWriter, POINT_STAMPED, POSE_STAMPED, RawBag, RawTopic
from baseball_collision.errors import BagError
import pytest
from rosbags.highlevel import AnyReader
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability
from rosbags.interfaces import QosTime
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
from rosbags.typesys import get_types_from_msg, get_typestore, Stores
from support.bagfiles import reference_bag, tracker_rows, TS1, TS2

STRING = 'std_msgs/msg/String'


def _fields(message: Any) -> Any:
    """Return a rosbags message as nested plain values, without ROS 1 ``seq``."""
    if not hasattr(message, '__dataclass_fields__'):
        return message
    return {name: _fields(getattr(message, name)) for name in message.__dataclass_fields__
            if name not in ('seq', '__msgtype__')}


def _by_rosbags(path: Path) -> List[Tuple[str, int, Any]]:
    """Return (topic, log time, message fields) of every message, deserialised by rosbags."""
    with AnyReader([path], default_typestore=TS2) as reader:
        return [(connection.topic, log_time, _fields(reader.deserialize(raw, connection.msgtype)))
                for connection, log_time, raw in reader.messages()]


@pytest.mark.parametrize('name', ['dir_mcap', 'dir_sqlite3', 'ros1.bag'])
def test_every_message_as_cdr_in_log_time_order(tmp_path: Path, name: str) -> None:
    """ROS 2 bags give the recorded bytes, ROS 1 bags CDR with the same fields (no seq)."""
    path = tmp_path / name
    reference_bag(path, tracker_rows())
    with RawBag(path) as bag:
        assert bag.is_ros1 == name.endswith('.bag')
        assert set(bag.topics) == {'/ball', '/bat/pose'} and bag.skipped == {}
        assert bag.topics['/bat/pose'][:3] == ('/bat/pose', POSE_STAMPED, 24)
        messages = list(bag.messages())
        assert [m.topic for m in bag.messages(['/ball'])] == ['/ball'] * 24
        assert bag.start_time_ns == 1
    assert all(type(m.data) is bytes and m.data[:4] == b'\x00\x01\x00\x00' for m in messages)
    decoded = [(m.topic, m.log_time_ns, _fields(TS2.deserialize_cdr(m.data, m.msgtype)))
               for m in messages]
    assert decoded == _by_rosbags(path)
    if not name.endswith('.bag'):
        with AnyReader([path], default_typestore=TS2) as reader:
            assert [m.data for m in messages] == [bytes(raw) for _, _, raw in reader.messages()]


def test_messages_logged_at_one_time_keep_the_bags_connection_order(tmp_path: Path) -> None:
    """Equal log times come in the order the bag's connections were added, as rosbags reads."""
    path = tmp_path / 'ties.bag'
    with BagWriter(path) as bag:
        for i in range(5):
            bag.write_point('/z_first', i, 'w', (0.0, 0.0, float(i)), log_time_ns=i)
            bag.write_point('/a_second', i, 'w', (1.0, 0.0, float(i)), log_time_ns=i)
    with RawBag(path) as raw:
        topics = [m.topic for m in raw.messages()]
    assert topics == ['/z_first', '/a_second'] * 5


def test_topics_without_one_ros2_type_are_skipped(tmp_path: Path) -> None:
    """A topic of two types, or of a ROS 1 type ROS 2 Jazzy lacks, is listed in skipped."""
    mixed = tmp_path / 'mixed'
    with Writer2(mixed, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        for msgtype, data in ((STRING, TS2.serialize_cdr(TS2.types[STRING](data='a'), STRING)),
                              ('std_msgs/msg/Bool', b'\x00\x01\x00\x00\x01')):
            writer.write(writer.add_connection('/both', msgtype, typestore=TS2), 5, data)
        point = writer.add_connection('/ball', POINT_STAMPED, typestore=TS2)
        writer.write(point, 6, TS2.serialize_cdr(TS2.types[POINT_STAMPED](
            TS2.types['std_msgs/msg/Header'](TS2.types['builtin_interfaces/msg/Time'](0, 6), 'w'),
            TS2.types['geometry_msgs/msg/Point'](1.0, 2.0, 3.0)), POINT_STAMPED))
    with RawBag(mixed) as bag:
        assert list(bag.topics) == ['/ball']
        assert bag.skipped == {'/both': 'several types: std_msgs/msg/Bool | std_msgs/msg/String'}
        assert [m.topic for m in bag.messages()] == ['/ball']
    custom = tmp_path / 'custom.bag'
    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(get_types_from_msg('int32 count', 'tracker_msgs/msg/Count'))
    with Writer1(custom) as writer:
        connection = writer.add_connection('/count', 'tracker_msgs/msg/Count', typestore=store)
        writer.write(connection, 1, store.serialize_ros1(
            store.types['tracker_msgs/msg/Count'](count=3), 'tracker_msgs/msg/Count'))
        chatter = writer.add_connection('/chatter', STRING, typestore=TS1)
        writer.write(chatter, 2, TS1.serialize_ros1(TS1.types[STRING](data='hi'), STRING))
    with RawBag(custom) as bag:
        assert bag.skipped == {'/count': 'no ROS 2 type tracker_msgs/msg/Count'}
        [message] = list(bag.messages())
    assert TS2.deserialize_cdr(message.data, STRING).data == 'hi'


def test_recorded_qos_is_reported(tmp_path: Path) -> None:
    """The reliability and durability the recording publishers offered (ROS 2), or latching."""
    path = tmp_path / 'qos'
    never = QosTime(sec=0, nsec=0)
    profiles: Dict[str, Tuple[Qos, ...]] = {
        '/latched': (Qos(QosHistory.KEEP_LAST, 1, QosReliability.RELIABLE,
                         QosDurability.TRANSIENT_LOCAL, never, never, QosLiveliness.AUTOMATIC,
                         never, False),),
        '/lossy': (Qos(QosHistory.KEEP_LAST, 5, QosReliability.BEST_EFFORT,
                       QosDurability.VOLATILE, never, never, QosLiveliness.AUTOMATIC, never,
                       False),),
        '/unknown': (),
    }
    data = TS2.serialize_cdr(TS2.types[STRING](data='x'), STRING)
    with Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        for topic, offered in profiles.items():
            connection = writer.add_connection(topic, STRING, typestore=TS2,
                                               offered_qos_profiles=offered)
            writer.write(connection, 1, data)
    with RawBag(path) as bag:
        assert bag.topics == {
            '/latched': RawTopic('/latched', STRING, 1, 'reliable', 'transient_local',
                                 profiles['/latched']),
            '/lossy': RawTopic('/lossy', STRING, 1, 'best_effort', 'volatile',
                               profiles['/lossy']),
            '/unknown': RawTopic('/unknown', STRING, 1, '', '')}
    ros1 = tmp_path / 'latched.bag'
    with Writer1(ros1) as writer:
        for topic, latching in (('/map', 1), ('/chatter', 0)):
            connection = writer.add_connection(topic, STRING, typestore=TS1, latching=latching)
            writer.write(connection, 1, TS1.serialize_ros1(TS1.types[STRING](data='x'), STRING))
    with RawBag(ros1) as bag:
        assert {t.name: t.durability for t in bag.topics.values()} == {
            '/map': 'transient_local', '/chatter': 'volatile'}
        assert {t.name: [(p.durability, p.depth) for p in t.qos_profiles]
                for t in bag.topics.values()} == {
            '/map': [(QosDurability.TRANSIENT_LOCAL, 1)],
            '/chatter': [(QosDurability.VOLATILE, 10)]}


def test_errors_are_one_line_bag_errors(tmp_path: Path) -> None:
    """Missing or empty bags, unknown topics and a closed bag raise BagError."""
    with pytest.raises(BagError, match='bag not found'):
        RawBag(tmp_path / 'missing.mcap').open()
    with BagWriter(tmp_path / 'empty.mcap') as writer:
        writer.add_topic('/ball', POINT_STAMPED)
    with pytest.raises(BagError, match='contains no messages'):
        RawBag(tmp_path / 'empty.mcap').open()
    reference_bag(tmp_path / 'ok', tracker_rows(2))
    bag = RawBag(tmp_path / 'ok')
    with pytest.raises(BagError, match='is not open'):
        bag.messages()
    with bag:
        with pytest.raises(BagError, match='offers no topic /nope'):
            bag.messages(['/ball', '/nope'])
        with pytest.raises(BagError, match='already open'):
            bag.open()
    with pytest.raises(BagError, match='is not open'):
        _ = bag.topics


def test_a_corrupt_chunk_is_a_bag_error_while_iterating(tmp_path: Path) -> None:
    """Damage met lazily surfaces as a one-line BagError naming the bag."""
    path = tmp_path / 'big.mcap'
    with BagWriter(path) as bag:
        for i in range(12_000):
            bag.write_point('/ball', i * 1000, 'world_frame', (1.0, 2.0, 3.0))
    data = bytearray(path.read_bytes())
    middle = len(data) * 2 // 3
    data[middle:middle + 64] = b'\xff' * 64
    path.write_bytes(bytes(data))
    with pytest.raises(BagError) as caught:
        with RawBag(path) as raw:
            for _ in raw.messages():
                pass
    assert path.name in str(caught.value) and '\n' not in str(caught.value)
