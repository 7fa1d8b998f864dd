"""Bags for the bag tests: reference bags written by rosbags alone, and read back by it."""

import math
from pathlib import Path
from typing import Any, List, Mapping, Sequence, Tuple

from baseball_collision.bags import POINT_STAMPED, POSE_STAMPED, Sample
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


def reference_message(store: Any, msgtype: str, stamp_ns: int, frame_id: str,
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


def still_rows(balls: int, bats: int, bat_step_ns: int, bat_frame: str = 'world') -> List[Row]:
    """
    Return a ball moving 1 m/s in 'world' at 100 Hz and a bat pose standing still, log-ordered.

    From stamp 1 s on; the bat every ``bat_step_ns`` in ``bat_frame``; each logged just after its
    stamp (ns from 0).
    """
    rows = [('/ball', POINT_STAMPED, 1_000_000_000 + 10_000_000 * i, 'world',
             (0.1 * i, 0.0, 1.0), 10_000_000 * i + 1) for i in range(balls)]
    rows += [('/bat_pose', POSE_STAMPED, 1_000_000_000 + bat_step_ns * i, bat_frame,
              (1.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0), bat_step_ns * i + 2) for i in range(bats)]
    return sorted(rows, key=lambda row: row[5])


def reference_bag(path: Path, rows: Sequence[Row], little_endian: bool = True,
                  extra_topics: Sequence[Tuple[str, str]] = ()) -> None:
    """Write a bag with the rosbags writer and typestore serialiser (not the package's)."""
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
            message = reference_message(store, msgtype, stamp, frame, values)
            if ros1:
                data = store.serialize_ros1(message, msgtype)
            else:
                data = store.serialize_cdr(message, msgtype, little_endian=little_endian)
            writer.write(connections[topic], log_time, data)


def renamed_bag(source: Path, path: Path, topics: Mapping[str, str]) -> None:
    """
    Copy the ``topics`` of a ROS 2 bag into a new MCAP, each under its new name, bytes as read.

    :param topics: ``{old topic: new topic}``; the source's other topics are left out.
    """
    with AnyReader([source], default_typestore=TS2) as reader, \
            Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        kept = [c for c in reader.connections if c.topic in topics]
        connections = {c.id: writer.add_connection(topics[c.topic], c.msgtype, typestore=TS2)
                       for c in kept}
        for connection, log_time, raw in reader.messages(connections=kept):
            writer.write(connections[connection.id], log_time, raw)


def tracker_rows(count: int = 24, ball_type: str = POINT_STAMPED) -> List[Row]:
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


def read_by_rosbags(path: Path, skip: Sequence[str] = ()
                    ) -> List[Tuple[str, int, str, Tuple[float, ...], int]]:
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


def expected_samples(rows: Sequence[Row], roles: dict) -> List[Sample]:
    """Return the samples read_samples should yield for rows, in log-time order."""
    samples = []
    for topic, msgtype, stamp, frame, values, log_time in sorted(rows, key=lambda r: r[5]):
        role = roles[topic]
        samples.append(Sample(role, stamp, frame, tuple(values[:7 if role == 'bat_pose' else 3]),
                              log_time))
    return samples
