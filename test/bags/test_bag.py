"""Tests for baseball_collision.bags.bag: reading samples from real bags, writing bags, errors."""

import ast
import math
from pathlib import Path
import sqlite3
import struct
import subprocess
import sys
import time
from typing import Any, List, Optional, Sequence, Tuple

from baseball_collision.bags import (
    BagReader, BagWriter, count_messages, POINT_STAMPED, POSE_STAMPED, read_samples, Sample,
    select_topics, TopicSelection, TWIST_STAMPED, VECTOR3_STAMPED)
from baseball_collision.errors import BagError
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
from rosbags.typesys import get_typestore, Stores

TS2 = get_typestore(Stores.ROS2_JAZZY)
TS1 = get_typestore(Stores.ROS1_NOETIC)
NS = 1_000_000_000

# frame_ids of every length 0-9 (all CDR paddings), a long one and a multi-byte UTF-8 one.
FRAMES = [''.join(chr(ord('a') + k) for k in range(n)) for n in range(10)] + [
    'mocap_world_frame_with_a_long_name', 'wörld']
# stamps (ns) at and around second boundaries, and at the edge of uint32/int32 seconds.
STAMPS = [0, 1, NS - 1, NS, NS + 1, 1_700_000_000 * NS + 999_999_999,
          (2**31 - 1) * NS + 999_999_999]

# Output layouts: (file name, storage argument).
LAYOUTS = [('dir_mcap', None), ('dir_sqlite3', 'sqlite3'), ('bare.mcap', None),
           ('bare.db3', None), ('ros1.bag', None)]


def _message(store: Any, msgtype: str, stamp_ns: int, frame_id: str,
             values: Sequence[float]) -> Any:
    """Build a PointStamped or PoseStamped with the rosbags typestore (the reference encoder)."""
    types = store.types
    sec, nanosec = divmod(stamp_ns, NS)
    stamp = types['builtin_interfaces/msg/Time'](sec=sec, nanosec=nanosec)
    if store is TS1:
        header = types['std_msgs/msg/Header'](seq=7, stamp=stamp, frame_id=frame_id)
    else:
        header = types['std_msgs/msg/Header'](stamp=stamp, frame_id=frame_id)
    point = types['geometry_msgs/msg/Point'](x=values[0], y=values[1], z=values[2])
    if msgtype == POINT_STAMPED:
        return types[POINT_STAMPED](header=header, point=point)
    quaternion = types['geometry_msgs/msg/Quaternion'](
        x=values[3], y=values[4], z=values[5], w=values[6])
    pose = types['geometry_msgs/msg/Pose'](position=point, orientation=quaternion)
    return types[POSE_STAMPED](header=header, pose=pose)


Row = Tuple[str, str, int, str, Tuple[float, ...], int]  # topic, type, stamp, frame, values, log


def _reference_bag(path: Path, rows: Sequence[Row], little_endian: bool = True,
                   extra_topics: Sequence[Tuple[str, str]] = ()) -> None:
    """Write a bag with the rosbags writer and typestore serialiser (independent of bag.py)."""
    ros1 = path.suffix == '.bag'
    store = TS1 if ros1 else TS2
    if ros1:
        writer: Any = Writer1(path)
    else:
        plugin = StoragePlugin.SQLITE3 if path.name.endswith('sqlite3') else StoragePlugin.MCAP
        writer = Writer2(path, version=9, storage_plugin=plugin)
    with writer:
        connections = {}
        for topic, msgtype in list(dict.fromkeys((r[0], r[1]) for r in rows)) + list(extra_topics):
            connections[topic] = writer.add_connection(topic, msgtype, typestore=store)
        for topic, msgtype, stamp, frame, values, log_time in rows:
            message = _message(store, msgtype, stamp, frame, values)
            if ros1:
                data = store.serialize_ros1(message, msgtype)
            else:
                data = store.serialize_cdr(message, msgtype, little_endian=little_endian)
            writer.write(connections[topic], log_time, data)


def _rows(count: int = 24, ball_type: str = POINT_STAMPED) -> List[Row]:
    """Return ball + bat pose rows with varied frames and stamps; log times unrelated."""
    rows: List[Row] = []
    for i in range(count):
        stamp = STAMPS[i % len(STAMPS)]
        ball = (0.1 * i, -2.5e-3 * i, math.pi)
        if ball_type == POSE_STAMPED:
            ball += (0.0, 0.0, 0.0, 1.0)
        rows.append(('/ball', ball_type, stamp, FRAMES[i % len(FRAMES)], ball, 10_000 * i + 1))
        rows.append(('/bat/pose', POSE_STAMPED, STAMPS[-1 - i % len(STAMPS)],
                     FRAMES[-1 - i % len(FRAMES)],
                     (1.0, 2.0, 3.0 + i, 0.0, 0.0, math.sin(0.1 * i), math.cos(0.1 * i)),
                     10_000 * i + 2))
    return rows


def _deserialized(path: Path,
                  skip: Sequence[str] = ()) -> List[Tuple[str, int, str, Tuple[float, ...], int]]:
    """Read a bag with rosbags' own deserialiser: (topic, stamp, frame, values, log time)."""
    out = []
    with AnyReader([path], default_typestore=TS2) as reader:
        connections = [c for c in reader.connections if c.topic not in skip]
        for connection, log_time, raw in reader.messages(connections=connections):
            message: Any = reader.deserialize(raw, connection.msgtype)
            stamp = message.header.stamp.sec * NS + message.header.stamp.nanosec
            if hasattr(message, 'pose'):
                p, q = message.pose.position, message.pose.orientation
                values: Tuple[float, ...] = (p.x, p.y, p.z, q.x, q.y, q.z, q.w)
            elif hasattr(message, 'point'):
                values = (message.point.x, message.point.y, message.point.z)
            elif hasattr(message, 'twist'):
                lin, ang = message.twist.linear, message.twist.angular
                values = (lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)
            else:
                values = (message.vector.x, message.vector.y, message.vector.z)
            out.append((connection.topic, stamp, message.header.frame_id, values, log_time))
    return out


def _expected(rows: Sequence[Row], roles: dict) -> List[Sample]:
    """Return the samples read_samples should yield for rows, in log-time order."""
    samples = []
    for topic, msgtype, stamp, frame, values, log_time in sorted(rows, key=lambda r: r[5]):
        role = roles[topic]
        samples.append(Sample(role, stamp, frame, tuple(values[:7 if role == 'bat_pose' else 3]),
                              log_time))
    return samples


def test_module_imports_neither_rclpy_nor_the_tools() -> None:
    """The bags layer is I/O on rosbags and the core: usable without ROS."""
    code = ('import sys, baseball_collision.bags; '
            'print(sorted(m for m in sys.modules if m.split(".")[0] in '
            '("rclpy", "baseball_collision")))')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         check=True, timeout=60)
    loaded = set(ast.literal_eval(out.stdout.strip()))
    assert 'baseball_collision.bags' in loaded
    assert not any(m.startswith(('rclpy', 'baseball_collision.ros', 'baseball_collision.tools'))
                   for m in loaded), loaded


# --- reading --------------------------------------------------------------------------------

@pytest.mark.parametrize('name', ['dir_mcap', 'dir_sqlite3', 'ros1.bag'])
def test_fast_decode_equals_rosbags_deserialize(tmp_path: Path, name: str) -> None:
    """Samples from the struct fast path equal rosbags' deserialisation, field for field."""
    path = tmp_path / name
    rows = _rows()
    _reference_bag(path, rows)
    samples = list(read_samples(path))
    reference = _deserialized(path)
    assert len(samples) == len(reference) == len(rows)
    roles = {'/ball': 'ball', '/bat/pose': 'bat_pose'}
    for sample, (topic, stamp, frame, values, log_time) in zip(samples, reference):
        assert sample == Sample(roles[topic], stamp, frame, values, log_time)
        assert all(type(v) is float for v in sample.values)
    assert samples == _expected(rows, roles)


def test_bare_files_read_like_directories(tmp_path: Path) -> None:
    """The storage file inside a bag directory reads on its own (bare .mcap and .db3)."""
    rows = _rows(8)
    roles = {'/ball': 'ball', '/bat/pose': 'bat_pose'}
    for name, suffix in (('dir_mcap', '.mcap'), ('dir_sqlite3', '.db3')):
        _reference_bag(tmp_path / name, rows)
        bare = tmp_path / name / f'{name}{suffix}'
        assert list(read_samples(bare)) == _expected(rows, roles)


def test_big_endian_cdr_is_read_through_the_fallback(tmp_path: Path) -> None:
    """Big-endian CDR is legal; it is decoded by rosbags and gives the same samples."""
    rows = _rows(6)
    _reference_bag(tmp_path / 'be', rows, little_endian=False)
    assert list(read_samples(tmp_path / 'be')) == _expected(
        rows, {'/ball': 'ball', '/bat/pose': 'bat_pose'})


@pytest.mark.parametrize('name', ['dir_mcap', 'ros1.bag'])
def test_ball_pose_gives_its_position(tmp_path: Path, name: str) -> None:
    """A PoseStamped ball topic yields (x, y, z) of its position; the selection says its type."""
    rows = _rows(5, ball_type=POSE_STAMPED)
    _reference_bag(tmp_path / name, rows)
    with BagReader(tmp_path / name) as bag:
        assert bag.selection.ball_type == POSE_STAMPED
        samples = list(bag.samples())
    assert samples == _expected(rows, {'/ball': 'ball', '/bat/pose': 'bat_pose'})
    assert all(len(s.values) == 3 for s in samples if s.role == 'ball')


@pytest.mark.parametrize('name', ['dir_mcap', 'dir_sqlite3', 'ros1.bag'])
def test_samples_come_in_log_time_order_with_header_stamps(tmp_path: Path, name: str) -> None:
    """Order is the bag's log time across topics (as a node would receive), stamps are headers."""
    knob = [('/bat/knob', POINT_STAMPED, 5_000 + i, 'w', (0.0, 0.0, float(i)), 100 + 30 * i)
            for i in range(5)]
    tip = [('/bat/tip', POINT_STAMPED, 9_000 + i, 'w', (1.0, 0.0, float(i)), 110 + 30 * i)
           for i in range(5)]
    ball = [('/ball', POINT_STAMPED, 1_000 + i, 'w', (2.0, 0.0, float(i)), 95 + 10 * i)
            for i in range(15)]
    rows = ball + knob + tip  # written topic by topic, not in time order
    _reference_bag(tmp_path / name, rows)
    samples = list(read_samples(tmp_path / name))
    assert [s.log_time_ns for s in samples] == sorted(r[5] for r in rows)
    assert samples == _expected(rows, {'/ball': 'ball', '/bat/knob': 'knob', '/bat/tip': 'tip'})
    assert [s.role for s in samples[:4]] == ['ball', 'knob', 'ball', 'tip']


def test_unrelated_topics_are_never_decoded(tmp_path: Path, monkeypatch: Any) -> None:
    """50k messages on another topic are skipped undecoded (they are not even valid CDR)."""
    path = tmp_path / 'noisy'
    garbage = b'\xff' * 40  # would make any deserialiser fail
    with Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        noise = writer.add_connection('/camera/info', 'std_msgs/msg/String', typestore=TS2)
        ball = writer.add_connection('/ball', POINT_STAMPED, typestore=TS2)
        bat = writer.add_connection('/bat_pose', POSE_STAMPED, typestore=TS2)
        for i in range(50_000):
            writer.write(noise, i * 1000, garbage)
            if i % 10_000 == 5:
                stamp = i * 1000
                writer.write(ball, stamp, TS2.serialize_cdr(
                    _message(TS2, POINT_STAMPED, stamp, 'w', (1.0, 2.0, 3.0)), POINT_STAMPED))
                writer.write(bat, stamp + 1, TS2.serialize_cdr(
                    _message(TS2, POSE_STAMPED, stamp, 'w', (0, 0, 0, 0, 0, 0, 1.0)),
                    POSE_STAMPED))
    requested = []
    original = AnyReader.messages

    def spy(self: AnyReader, connections: Any = (), *args: Any, **kwargs: Any) -> Any:
        requested.append(sorted(c.topic for c in connections))
        return original(self, connections, *args, **kwargs)

    monkeypatch.setattr(AnyReader, 'messages', spy)
    start = time.perf_counter()
    with BagReader(path) as bag:
        assert bag.message_count == 10
        samples = list(bag.samples())
    elapsed = time.perf_counter() - start
    assert requested == [['/ball', '/bat_pose']]
    assert [s.role for s in samples] == ['ball', 'bat_pose'] * 5
    assert elapsed < 5.0, f'{elapsed:.2f} s for 50k skipped messages'


def test_message_count_matches_what_is_read(tmp_path: Path) -> None:
    """message_count / count_messages (from the index) equal the number of samples."""
    rows = _rows(9)
    _reference_bag(tmp_path / 'b.bag', rows, extra_topics=[('/other', 'std_msgs/msg/String')])
    assert count_messages(tmp_path / 'b.bag') == len(rows) == len(list(
        read_samples(tmp_path / 'b.bag')))


def test_selection_from_another_bag_and_explicit_topics(tmp_path: Path) -> None:
    """A ready-made selection is checked against the bag; names and a selection don't mix."""
    rows = _rows(3)
    _reference_bag(tmp_path / 'a', rows)
    with BagReader(tmp_path / 'a') as bag:
        selection = bag.selection
        assert bag.topics == {'/ball': POINT_STAMPED, '/bat/pose': POSE_STAMPED}
        assert bag.start_time_ns == 1
    assert len(list(read_samples(tmp_path / 'a', selection))) == len(rows)
    assert len(list(read_samples(tmp_path / 'a', ball='/ball', bat_pose='/bat/pose'))) == 6
    other = TopicSelection(ball='/ball', bat_pose='/somewhere/else')
    with pytest.raises(BagError, match="--bat-pose-topic '/somewhere/else' is not in the bag"):
        list(read_samples(tmp_path / 'a', other))
    with pytest.raises(ValueError):
        BagReader(tmp_path / 'a', selection, ball='/ball')
    with pytest.raises(BagError, match='is not open'):
        BagReader(tmp_path / 'a').samples()


# --- topic selection ------------------------------------------------------------------------

def test_auto_detection_unambiguous() -> None:
    """One ball-like and one bat-like topic are picked; knob/tip pairs too; others ignored."""
    selection = select_topics({'/tracker/ball': POINT_STAMPED, '/tracker/bat': POSE_STAMPED,
                               '/camera/image': 'sensor_msgs/msg/Image',
                               '/ball_count': 'std_msgs/msg/String'})
    assert selection == TopicSelection(ball='/tracker/ball', ball_type=POINT_STAMPED,
                                       bat_pose='/tracker/bat')
    assert selection.bat_mode == 'pose'
    points = select_topics({'/baseball': POSE_STAMPED, '/bat/knob': POINT_STAMPED,
                            '/bat/barrel_end': POINT_STAMPED})
    assert (points.ball, points.ball_type, points.knob, points.tip) == (
        '/baseball', POSE_STAMPED, '/bat/knob', '/bat/barrel_end')
    assert points.bat_mode == 'points'
    # 'baseball_bat' names a bat, not a ball; 'multiple' does not contain the word 'tip'.
    named = select_topics({'/baseball_bat/pose': POSE_STAMPED, '/ball': POINT_STAMPED,
                           '/multiple': POINT_STAMPED})
    assert (named.ball, named.bat_pose) == ('/ball', '/baseball_bat/pose')


def test_explicit_topics_override_detection() -> None:
    """Names given win, and a given knob picks the knob+tip bat with the tip detected."""
    topics = {'/ball_a': POINT_STAMPED, '/ball_b': POINT_STAMPED, '/bat': POSE_STAMPED,
              '/hand/knob': POINT_STAMPED, '/hand/tip': POINT_STAMPED, '/x': POINT_STAMPED}
    chosen = select_topics(topics, ball='/ball_b', knob='/x')
    assert (chosen.ball, chosen.bat_pose, chosen.knob, chosen.tip) == (
        '/ball_b', None, '/x', '/hand/tip')
    assert select_topics(topics, ball='/ball_a', bat_pose='/bat').bat_pose == '/bat'


def test_bat_pose_preferred_to_knob_and_tip_points() -> None:
    """A bag with both bats (as `simulate` writes) uses the pose and notes the points."""
    topics = {'/ball': POINT_STAMPED, '/bat': POSE_STAMPED, '/bat/knob': POINT_STAMPED,
              '/bat/tip': POINT_STAMPED}
    chosen = select_topics(topics)
    assert (chosen.bat_pose, chosen.knob, chosen.tip) == ('/bat', None, None)
    assert '/bat/knob' in chosen.note and '--knob-topic + --tip-topic' in chosen.note
    assert '\n' not in chosen.note
    points = select_topics(topics, prefer_bat='points')
    assert (points.bat_pose, points.knob, points.tip) == (None, '/bat/knob', '/bat/tip')
    assert '--bat-pose-topic' in points.note
    assert select_topics(topics, knob='/bat/knob').note == ''
    assert select_topics({'/ball': POINT_STAMPED, '/bat': POSE_STAMPED}).note == ''
    with pytest.raises(ValueError):
        select_topics(topics, prefer_bat='knob')


@pytest.mark.parametrize('topics, kwargs, flag, words', [
    ({'/ball_a': POINT_STAMPED, '/ball_b': POINT_STAMPED, '/bat': POSE_STAMPED}, {},
     '--ball-topic', ['/ball_a', '/ball_b']),
    ({'/p': POINT_STAMPED, '/bat': POSE_STAMPED}, {}, '--ball-topic', ['/p (geometry_msgs']),
    ({'/ball': POINT_STAMPED, '/bat/knob': POINT_STAMPED}, {}, '--tip-topic', ['no tip']),
    ({'/ball': POINT_STAMPED}, {}, '--bat-pose-topic', ['no bat_pose']),
    ({'/ball': POINT_STAMPED, '/bat': POSE_STAMPED}, {'ball': '/missing'}, '--ball-topic',
     ['not in the bag', '/bat (geometry_msgs/msg/PoseStamped)']),
    ({'/ball': 'std_msgs/msg/String', '/bat': POSE_STAMPED}, {'ball': '/ball'}, '--ball-topic',
     ['has type std_msgs/msg/String']),
    ({'/ball': POINT_STAMPED, '/bat': POINT_STAMPED}, {'bat_pose': '/bat'},
     '--bat-pose-topic', ['needs geometry_msgs/msg/PoseStamped']),
    ({'/ball': POINT_STAMPED, '/bat': POSE_STAMPED, '/k': POINT_STAMPED},
     {'bat_pose': '/bat', 'knob': '/k'}, '--bat-pose-topic', ['not both']),
])
def test_selection_errors_name_the_flag(topics: dict, kwargs: dict, flag: str,
                                        words: List[str]) -> None:
    """Every selection error is one line naming the flag to pass (and what it found)."""
    with pytest.raises(BagError) as caught:
        select_topics(topics, **kwargs)
    message = str(caught.value)
    assert '\n' not in message
    assert flag in message
    for word in words:
        assert word in message


def test_selection_errors_from_a_real_bag(tmp_path: Path) -> None:
    """A bag without the needed topics, or with a wrong explicit topic, raises BagError."""
    path = tmp_path / 'unrelated'
    with Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection('/chatter', 'std_msgs/msg/String', typestore=TS2)
        writer.write(conn, 1, TS2.serialize_cdr(
            TS2.types['std_msgs/msg/String'](data='hi'), 'std_msgs/msg/String'))
    with pytest.raises(BagError, match='no ball topic found.*--ball-topic.*/chatter'):
        BagReader(path).open()
    with pytest.raises(BagError, match="--ball-topic '/chatter' has type std_msgs/msg/String"):
        list(read_samples(path, ball='/chatter', bat_pose='/chatter'))


# --- bad inputs -----------------------------------------------------------------------------

def _raises_one_line(path: Path, **kwargs: Any) -> str:
    with pytest.raises(BagError) as caught:
        for _ in read_samples(path, **kwargs):
            pass
    message = str(caught.value)
    assert message and '\n' not in message
    return message


def test_bad_paths_and_non_bags(tmp_path: Path) -> None:
    """Missing path, text files, a foreign sqlite3 file, a bare directory: one-line BagError."""
    assert 'not found' in _raises_one_line(tmp_path / 'missing.mcap')
    (tmp_path / 'notes.txt').write_text('not a bag\n')
    _raises_one_line(tmp_path / 'notes.txt')
    (tmp_path / 'fake.mcap').write_text('not a bag\n')
    _raises_one_line(tmp_path / 'fake.mcap')
    (tmp_path / 'fake.bag').write_text('not a bag\n')
    _raises_one_line(tmp_path / 'fake.bag')
    connection = sqlite3.connect(tmp_path / 'other.db3')
    connection.execute('CREATE TABLE people (name TEXT)')
    connection.commit()
    connection.close()
    _raises_one_line(tmp_path / 'other.db3')
    (tmp_path / 'folder').mkdir()
    _raises_one_line(tmp_path / 'folder')


@pytest.mark.parametrize('name', ['dir_mcap', 'e.db3', 'e.bag'])
def test_empty_bags(tmp_path: Path, name: str) -> None:
    """A bag without messages, or whose selected topic has none, is refused."""
    with BagWriter(tmp_path / name) as bag:
        bag.add_topic('/ball', POINT_STAMPED)
        bag.add_topic('/bat', POSE_STAMPED)
    assert 'no messages' in _raises_one_line(tmp_path / name)
    with BagWriter(tmp_path / f'half_{name}') as bag:
        bag.add_topic('/bat', POSE_STAMPED)
        bag.write_point('/ball', 5, 'w', (0.0, 0.0, 0.0))
    assert "'/bat' has no messages" in _raises_one_line(tmp_path / f'half_{name}')


def _multi_chunk_bag(path: Path, count: int = 12_000) -> None:
    """Write ~2.5 MB (three MCAP chunks); message 9000 has the frame_id 'MARKER'."""
    with BagWriter(path) as bag:
        for i in range(count):
            frame = 'MARKER' if i == 9000 else 'world_frame'
            bag.write_point('/ball', i * 1000, frame, (1.0, 2.0, 3.0))
            bag.write_pose('/bat', i * 1000 + 1, 'world_frame', (0, 0, 0), (0, 0, 0, 1))


def test_truncated_mcap_is_refused(tmp_path: Path) -> None:
    """An MCAP cut mid-chunk (e.g. a recorder killed) raises BagError, not a rosbags error."""
    _multi_chunk_bag(tmp_path / 'full.mcap', 4000)
    data = (tmp_path / 'full.mcap').read_bytes()
    (tmp_path / 'cut.mcap').write_bytes(data[:len(data) // 2])
    assert 'cannot read bag' in _raises_one_line(tmp_path / 'cut.mcap')
    _reference_bag(tmp_path / 'r.bag', _rows(40))
    data = (tmp_path / 'r.bag').read_bytes()
    (tmp_path / 'cut.bag').write_bytes(data[:len(data) // 2])
    _raises_one_line(tmp_path / 'cut.bag')


def test_corruption_found_while_iterating_is_a_bag_error(tmp_path: Path) -> None:
    """Damage inside a later chunk surfaces lazily, after good samples, as BagError."""
    _multi_chunk_bag(tmp_path / 'ok.mcap')
    data = bytearray((tmp_path / 'ok.mcap').read_bytes())
    marker = data.index(b'MARKER\x00')
    length_field = marker - 4  # uint32 frame_id length in the CDR header

    bad_payload = bytearray(data)
    bad_payload[length_field:length_field + 4] = struct.pack('<I', 0x7FFFFFF0)
    (tmp_path / 'payload.mcap').write_bytes(bad_payload)

    record_start = marker - 16 - 22 - 8 - 1  # CDR head, message record fields, length, opcode
    assert data[record_start] == 0x05
    bad_record = bytearray(data)
    bad_record[record_start + 1:record_start + 9] = struct.pack('<Q', 2**40)
    (tmp_path / 'record.mcap').write_bytes(bad_record)

    for name, words in (('payload.mcap', 'corrupt'), ('record.mcap', 'cannot read bag')):
        seen = 0
        with pytest.raises(BagError) as caught:
            for _ in read_samples(tmp_path / name):
                seen += 1
        assert seen > 1000, 'the error should come lazily, after the intact chunks'
        assert words in str(caught.value) and '\n' not in str(caught.value)


# --- writing --------------------------------------------------------------------------------

@pytest.mark.parametrize('name, storage', LAYOUTS)
def test_writer_round_trip(tmp_path: Path, name: str, storage: Optional[str]) -> None:
    """Struct-serialised bags read back exactly, by bag.py and by rosbags."""
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
        r[1:] for r in _deserialized(path)]


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
    assert _deserialized(path, skip={'/events'}) == [
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
