"""
The node tests' inputs: a swing published on a harness, harnesses with their publishers, /rosout.

Shared by the in-process node tests (``test/ros/test_node.py`` and the tests of the node's
mixin modules beside it).
"""

from typing import Any, Callable, Dict, Optional

from geometry_msgs.msg import PointStamped, PoseStamped
from nav_msgs.msg import Path as PathMsg
import numpy as np
from rcl_interfaces.msg import Log as LogMsg
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from support.harness import Harness, point_msg, pose_msg, RATE_HZ, sample_ns, SAMPLES
from support.scenes import pose, swing


def publish_swing(h: Harness, bat_input: str, ball: Callable[[float], np.ndarray],
                  samples: range = range(SAMPLES),
                  extra: Optional[Callable[[int], None]] = None, later_ns: int = 0) -> int:
    """
    Publish ball and bat at 360 Hz on the harness's topics; return the messages sent.

    ``later_ns``: the same swing stamped that much later (a second pitch).
    """
    sent = 0
    for i in samples:
        t = i / RATE_HZ
        ns = sample_ns(i) + later_ns
        h.publishers['ball'].publish(point_msg(ns, ball(t)))
        if bat_input == 'pose':
            position, quaternion = pose(t)
            h.publishers['bat_pose'].publish(pose_msg(ns, position, quaternion))
            sent += 2
        else:
            knob, tip = swing(t)
            h.publishers['bat_knob'].publish(point_msg(ns, knob))
            h.publishers['bat_tip'].publish(point_msg(ns, tip))
            sent += 3
        if extra is not None:
            sent += extra(i)
    return sent


def listen_to_rosout(h: Harness) -> None:
    """Collect every /rosout record (including those sent before) in ``h.received['rosout']``."""
    h.received['rosout'] = []
    h.probe.create_subscription(LogMsg, '/rosout', h._collector('rosout'), QoSProfile(
        depth=1000, reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL))


def swing_harness(make: Callable[..., Harness], bat_input: str,
                  overrides: Optional[Dict[str, Any]] = None) -> Harness:
    """Return a started harness with the ball and the bat publishers of ``bat_input``."""
    h = make(dict({'bat_input': bat_input}, **(overrides or {})))
    h.publisher(PointStamped, 'ball')
    if bat_input == 'pose':
        h.publisher(PoseStamped, 'bat_pose')
    else:
        h.publisher(PointStamped, 'bat_knob')
        h.publisher(PointStamped, 'bat_tip')
    return h.start()


def make_plan_harness(make: Callable[..., Harness]) -> Harness:
    """Return a started pose harness with a plan publisher, a 0.3 s horizon, every frame."""
    h = make({'bat_input': 'pose', 'prediction_horizon': 0.3, 'bat_plan_topic': 'bat_plan',
              'prediction_period': 0.0,  # every frame: the scene's ball is tracked ~30 ms
              'frame_id': 'world'})  # a plan before the first sample is checked against it
    h.publisher(PointStamped, 'ball')
    h.publisher(PoseStamped, 'bat_pose')
    h.publisher(PathMsg, 'bat_plan')
    return h.start()
