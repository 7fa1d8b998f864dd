"""Tests for baseball_collision.bags writing: round trips, all-or-nothing outputs, errors."""

import math
from pathlib import Path
from typing import Optional

from baseball_collision.bags import (
    BagWriter, POINT_STAMPED, read_samples, Sample, TWIST_STAMPED,
    VECTOR3_STAMPED)
from baseball_collision.bags.common import jazzy_typestore
from baseball_collision.errors import BagError
import pytest
from rosbags.highlevel import AnyReader
from support.bagfiles import (
    FRAMES, LAYOUTS, NS, read_by_rosbags, reference_message, STAMPS, TS1, TS2)


@pytest.mark.parametrize('name, storage', LAYOUTS)
def test_writer_round_trip(tmp_path: Path, name: str, storage: Optional[str]) -> None:
    """Written bags read back exactly, by the package and by rosbags."""
    path = tmp_path / name
    ros1 = name.endswith('.bag')
    written = []
    with BagWriter(path, storage=storage) as bag:
        for i, frame in enumerate(FRAMES):
            stamp = STAMPS[i % len(STAMPS)]
            xyz = (0.1 * i, -1e-300, 1e300 * (i % 2))
            bag.write_point('/ball', stamp, frame, xyz, log_time_ns=1000 * i)
            pose = ((1.0, 2.0, float(i)), (0.0, math.sin(i), 0.0, math.cos(i)))
            bat_stamp = STAMPS[-1 - i % len(STAMPS)]
            bag.write_pose('/bat/pose', bat_stamp, frame, *pose, log_time_ns=1000 * i + 1)
            written.append(Sample('ball', stamp, frame, xyz, 1000 * i))
            written.append(Sample('bat_pose', bat_stamp, frame, pose[0] + pose[1], 1000 * i + 1))
        if not ros1:  # int32 seconds in ROS 2: negative stamps are legal
            bag.write_point('/ball', -1, 'w', (1.0, 1.0, 1.0), log_time_ns=10**6)
            written.append(Sample('ball', -1, 'w', (1.0, 1.0, 1.0), 10**6))
    assert path.is_dir() == name.startswith('dir')
    assert [p.name for p in tmp_path.iterdir()] == [name]  # no temporaries left
    assert list(read_samples(path)) == written
    assert [(s.stamp_ns, s.frame_id, s.values, s.log_time_ns) for s in written] == [
        r[1:] for r in read_by_rosbags(path)]


@pytest.mark.parametrize('name', ['tw.mcap', 'tw.bag'])
def test_writer_twist_vector3_and_generic_messages(tmp_path: Path, name: str) -> None:
    """TwistStamped, Vector3Stamped and any typestore message are written readable."""
    path = tmp_path / name
    with BagWriter(path) as bag:
        bag.write_twist('/velocity', 2 * NS + 5, 'bat', (1.0, 2.0, 3.0), (4.0, 5.0, 6.0))
        bag.write_vector3('/ball_velocity', 3 * NS, 'world', (-40.0, 0.5, 1.5), log_time_ns=9)
        string = bag.typestore.types['std_msgs/msg/String'](data='impact')
        bag.write_message('/events', string, log_time_ns=3 * NS)
    with AnyReader([path], default_typestore=TS2) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        assert types == {'/velocity': TWIST_STAMPED, '/ball_velocity': VECTOR3_STAMPED,
                         '/events': 'std_msgs/msg/String'}
        events = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages()
                  if c.topic == '/events']
    assert [e.data for e in events] == ['impact']
    assert read_by_rosbags(path, skip={'/events'}) == [
        ('/ball_velocity', 3 * NS, 'world', (-40.0, 0.5, 1.5), 9),
        ('/velocity', 2 * NS + 5, 'bat', (1.0, 2.0, 3.0, 4.0, 5.0, 6.0), 2 * NS + 5)]


def test_writer_refuses_existing_outputs_before_writing(tmp_path: Path) -> None:
    """An existing file or directory is refused up front and left untouched."""
    (tmp_path / 'taken.mcap').write_text('keep me')
    (tmp_path / 'taken_dir').mkdir()
    for name in ('taken.mcap', 'taken_dir'):
        with pytest.raises(BagError, match='exists already') as caught:
            BagWriter(tmp_path / name)
        assert '\n' not in str(caught.value)
    assert (tmp_path / 'taken.mcap').read_text() == 'keep me'
    assert sorted(p.name for p in tmp_path.iterdir()) == ['taken.mcap', 'taken_dir']
    assert list((tmp_path / 'taken_dir').iterdir()) == []


def test_writer_leaves_nothing_after_an_exception(tmp_path: Path) -> None:
    """An exception inside the with block removes the temporary output and propagates."""
    for name in ('a', 'b.mcap', 'c.db3', 'd.bag'):
        with pytest.raises(RuntimeError):
            with BagWriter(tmp_path / name) as bag:
                bag.write_point('/ball', 1, 'w', (1.0, 2.0, 3.0))
                raise RuntimeError('simulated failure')
    with pytest.raises(BagError):
        with BagWriter(tmp_path / 'e.mcap') as bag:
            bag.write_point('/ball', 1, 'w', (1.0, 2.0))  # two values: a BagError
    assert list(tmp_path.iterdir()) == []


def test_writer_argument_errors(tmp_path: Path) -> None:
    """Bad storage, stamps, values, types and frame_ids raise one-line BagErrors."""
    with pytest.raises(BagError, match='does not exist'):
        BagWriter(tmp_path / 'no' / 'such.mcap')
    with pytest.raises(BagError, match="storage 'sqlite3'"):
        BagWriter(tmp_path / 'x.mcap', storage='sqlite3')
    with pytest.raises(BagError, match='.bag file name'):
        BagWriter(tmp_path / 'x', storage='rosbag1')
    with pytest.raises(BagError, match='unknown bag storage'):
        BagWriter(tmp_path / 'x', storage='zip')
    with pytest.raises(BagError, match='not open'):
        BagWriter(tmp_path / 'x').add_topic('/ball', POINT_STAMPED)
    with BagWriter(tmp_path / 'ros1.bag') as bag:
        with pytest.raises(BagError, match='out of range'):
            bag.write_point('/ball', -1, 'w', (0.0, 0.0, 0.0))  # ROS 1 time is unsigned
        with pytest.raises(BagError, match='integer nanoseconds'):
            bag.write_point('/ball', 1.5, 'w', (0.0, 0.0, 0.0))
        with pytest.raises(BagError, match='log time'):
            bag.write_point('/ball', 1, 'w', (0.0, 0.0, 0.0), log_time_ns=-5)
        with pytest.raises(BagError, match='expected 7 numbers'):
            bag.write_pose('/bat', 1, 'w', (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
        with pytest.raises(BagError, match='without NUL'):
            bag.write_point('/ball', 1, 'a\x00b', (0.0, 0.0, 0.0))
        with pytest.raises(BagError, match='already declared'):
            bag.write_pose('/ball', 1, 'w', (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
        with pytest.raises(BagError, match='unknown message type'):
            bag.add_topic('/x', 'nope_msgs/msg/Nothing')
        # ROS 1 time is uint32 seconds (to 2106). rosbags' deserialiser reads it as int32 (this
        # stamp comes back as -1 ns); the fast path follows the ROS 1 definition.
        bag.write_point('/ball', 2**32 * NS - 1, 'w', (0.0, 0.0, 0.0), log_time_ns=0)
        bag.write_pose('/bat', 2**32 * NS - 1, 'w', (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    assert [s.stamp_ns for s in read_samples(tmp_path / 'ros1.bag')] == [2**32 * NS - 1] * 2


@pytest.mark.parametrize('name', ['s.mcap', 's.bag'])
def test_writer_bytes_are_the_typestore_serialisation(tmp_path: Path, name: str) -> None:
    """Each message is what rosbags' typestore serialises (ROS 1: seq counts per topic)."""
    ros1 = name.endswith('.bag')
    store = TS1 if ros1 else TS2
    with BagWriter(tmp_path / name) as bag:
        for i in range(3):
            bag.write_point('/ball', STAMPS[i], FRAMES[i], (0.5 * i, -1.0, 2.0))
            bag.write_point('/other', STAMPS[i], 'w', (0.0, 0.0, 0.0))
    with AnyReader([tmp_path / name], default_typestore=TS2) as reader:
        written = [bytes(raw) for c, _, raw in reader.messages() if c.topic == '/ball']
    expected = []
    for i in range(3):
        message = reference_message(store, POINT_STAMPED, STAMPS[i], FRAMES[i],
                                    (0.5 * i, -1.0, 2.0))
        if ros1:
            message.header.seq = i
            expected.append(bytes(store.serialize_ros1(message, POINT_STAMPED)))
        else:
            expected.append(bytes(store.serialize_cdr(message, POINT_STAMPED,
                                                      little_endian=True)))
    assert written == expected


@pytest.mark.parametrize('name', ['late.mcap', 'late_dir', 'late.bag'])
def test_writer_refuses_an_output_that_appeared_meanwhile(tmp_path: Path, name: str) -> None:
    """An output created while the bag was written is kept; the bag is dropped, nothing left."""
    bag = BagWriter(tmp_path / name)
    bag.open()
    bag.write_point('/ball', 1, 'w', (1.0, 2.0, 3.0))
    (tmp_path / name).write_text('someone else')
    with pytest.raises(BagError, match='exists already'):
        bag.close()
    assert (tmp_path / name).read_text() == 'someone else'
    assert [p.name for p in tmp_path.iterdir()] == [name]
    bag.close()  # closed already: nothing to do


def test_writer_abort_leaves_nothing(tmp_path: Path) -> None:
    """abort() deletes the staged output; it is idempotent, and close() after it a no-op."""
    bag = BagWriter(tmp_path / 'a.bag')
    bag.open()
    bag.write_point('/ball', 1, 'w', (1.0, 2.0, 3.0))
    assert len(list(tmp_path.iterdir())) == 1  # the hidden staging directory
    bag.abort()
    bag.abort()
    bag.close()
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(BagError, match='not open'):
        bag.write_point('/ball', 2, 'w', (1.0, 2.0, 3.0))


def test_a_type_defined_by_a_bag_is_registered_in_the_writers_own_store(tmp_path: Path) -> None:
    """register_definition: the type writable here, the shared Jazzy store untouched."""
    with BagWriter(tmp_path / 'a.mcap') as writer:
        writer.register_definition('rig_msgs/msg/Marker', 'uint32 id\nstring label\n')
        writer.add_topic('/rig', 'rig_msgs/msg/Marker')
        message = writer.typestore.types['rig_msgs/msg/Marker'](id=3, label='x')
        writer.write_message('/rig', message, 5)
        writer.write_point('/ball', 7, 'world', (1.0, 2.0, 3.0))
        with pytest.raises(BagError, match='cannot add the definition of rig_msgs/msg/Markers: '
                           ".*'rig_msgs/msg/Missing' is unknown"):
            writer.register_definition('rig_msgs/msg/Markers', 'rig_msgs/Missing[] markers\n')
        with pytest.raises(BagError, match='cannot read the definition of rig_msgs/msg/Bad'):
            writer.register_definition('rig_msgs/msg/Bad', 'uint32[ id\n')
    assert 'rig_msgs/msg/Marker' not in jazzy_typestore().types
    with AnyReader([tmp_path / 'a.mcap']) as reader:
        rig = [c for c in reader.connections if c.topic == '/rig']
        assert [reader.deserialize(raw, 'rig_msgs/msg/Marker').label
                for _, _, raw in reader.messages(connections=rig)] == ['x']
