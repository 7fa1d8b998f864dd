"""
Commanded bat trajectories (``nav_msgs/Path``) from a bag: what the node takes on its plan topic.

A robot arm's session recorded with its plan topic (the node's ``bat_plan_topic``) holds the
plans the live node predicted with. :func:`read_plans` reads that topic's messages in a pass of
their own (a plan is a message or a few a pitch, so they are held: each some hundred poses), in
log-time order, each with its log time; ``analyze`` hands each to the detector where the
samples' log times pass it (``Detector.take_bat_plan``: the node's rules). :func:`plan_arrays`
is a plan message as the detector takes it, for rosbags' messages and rclpy's alike (the same
field names): the node's too, which imports this module without rosbags (it is imported where
a bag is read).
"""

from typing import Any, List, NamedTuple, Optional, Set, Tuple

from .names import PATH
from ..core.geometry import Quaternion, Vector
from ..core.prediction import MAX_PLAN_POSES
from ..errors import BagError


class PlanMessage(NamedTuple):
    """
    One plan message of a bag, as the detector takes it.

    :ivar log_time_ns: its record time (ns): where it falls among the samples.
    :ivar stamps_ns: its poses' header stamps (ns); ``positions`` (m) and ``quaternions``
        (x, y, z, w) beside them; all empty for an empty plan (it clears the one in force).
    :ivar frames: every non-empty frame its header and poses name.
    :ivar refused: why it was refused before a pose was read (over ``MAX_PLAN_POSES`` poses,
        as the node refuses it), else None.
    """

    log_time_ns: int
    stamps_ns: List[int]
    positions: List[Vector]
    quaternions: List[Quaternion]
    frames: Set[str]
    refused: Optional[str] = None


def plan_arrays(path: Any) -> Tuple[List[int], List[Vector], List[Quaternion], Set[str]]:
    """
    Return a commanded bat trajectory (a ``nav_msgs/Path``) as the detector takes it.

    Works on rclpy's message and rosbags' alike (their field names are ROS's).

    :returns: the poses' stamps (ns), positions (m) and quaternions (x, y, z, w), and every
        non-empty frame named by the path or its poses.
    """
    frames = {path.header.frame_id} | {pose.header.frame_id for pose in path.poses}
    frames.discard('')
    return ([pose.header.stamp.sec * 1_000_000_000 + pose.header.stamp.nanosec  # (decode's)
             for pose in path.poses],
            [(p.pose.position.x, p.pose.position.y, p.pose.position.z) for p in path.poses],
            [(p.pose.orientation.x, p.pose.orientation.y, p.pose.orientation.z,
              p.pose.orientation.w) for p in path.poses], frames)


def read_plans(reader: Any, topic: str, bag: str) -> Optional[List[PlanMessage]]:
    """
    Return the plan messages on ``topic`` in log-time order, or None: the bag has no such topic.

    :param reader: the open bag (rosbags' ``AnyReader``); ``bag``: its name, for errors.
    :raises BagError: the topic is not of type ``nav_msgs/msg/Path``, or a message cannot be
        read or deserialised (a corrupt bag).
    """
    from .common import first_line  # (rosbags: where a bag is read, not in the node)
    connections = [c for c in reader.connections if c.topic == topic]
    if not connections:
        return None
    types = sorted({c.msgtype for c in connections})
    if types != [PATH]:
        raise BagError(f"the bat plan topic '{topic}' of bag {bag} is of type "
                       f"{' | '.join(types)}, not {PATH}")
    plans = []
    try:
        for connection, log_time, raw in reader.messages(connections=connections):
            message = reader.deserialize(raw, connection.msgtype)
            if len(message.poses) > MAX_PLAN_POSES:  # (the node's: before a pose is read)
                plans.append(PlanMessage(int(log_time), [], [], [], set(), (
                    f'{len(message.poses)} poses is more than the {MAX_PLAN_POSES} a plan '
                    'may hold')))
                continue
            plans.append(PlanMessage(int(log_time), *plan_arrays(message)))
    except BagError:
        raise
    except Exception as error:
        raise BagError(f"cannot read the bat plan topic '{topic}' of bag {bag}: "
                       f'{first_line(error)}') from error
    return plans
