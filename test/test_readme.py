"""
The README's Python code blocks, run as a user copies them.

Every ```python block of README.md runs here: the Python API's (with the names it leaves to the
reader, ``ball0`` ... and ``samples``, taken from a bundled bag) and the arm controller's (the
class made on a real rclpy context and each callback called with a message). A new block
fails :func:`test_every_python_block_of_the_readme_is_run` until it has its set-up here.
"""

import re
from types import SimpleNamespace
from typing import Any, Dict, List

from baseball_collision.bags import read_samples
from baseball_collision.core.toi import ImpactResult
from baseball_collision.ros.outputs import LIVELINESS_LEASE_S
from builtin_interfaces.msg import Time
from geometry_msgs.msg import PointStamped
import pytest
import rclpy
from rclpy.duration import Duration
from rclpy.qos import DurabilityPolicy, ReliabilityPolicy
from std_msgs.msg import Bool
from support import REPO_ROOT

README = REPO_ROOT / 'README.md'
BAG = REPO_ROOT / 'bags' / 'pitches_90hz.mcap'


def python_blocks() -> List[str]:
    """Return the README's ```python blocks, in order."""
    return re.findall(r'^```python\n(.*?)^```', README.read_text(), flags=re.S | re.M)


def block(marker: str) -> str:
    """Return the one python block holding ``marker``."""
    found, = [text for text in python_blocks() if marker in text]
    return found


API = 'from baseball_collision import Detector'
CONTROLLER = 'class SwingController(Node)'


def test_every_python_block_of_the_readme_is_run() -> None:
    """Each python block is one of those run below (a new one needs its set-up here)."""
    blocks = python_blocks()
    assert len(blocks) == 2
    assert sorted(text for text in blocks if API in text or CONTROLLER in text) == sorted(blocks)


def test_the_python_api_block_runs_on_a_bundled_bag(capsys: pytest.CaptureFixture) -> None:
    """The API block: a hit between two frames, then the bag's 8 impacts printed."""
    namespace: Dict[str, Any] = {
        # a ball crossing a still bat lying along x, 1 m up, within one 90 Hz frame
        'ball0': (0.2, 0.3, 1.0), 'ball1': (0.2, -0.1, 1.0),
        'knob0': (-0.5, 0.0, 1.0), 'knob1': (-0.5, 0.0, 1.0),
        'tip0': (0.36, 0.0, 1.0), 'tip1': (0.36, 0.0, 1.0),
        'samples': [(s.stamp_ns, s.role, s.values) for s in read_samples(BAG)],
    }
    exec(compile(block(API), 'README.md', 'exec'), namespace)
    hit = namespace['hit']
    assert isinstance(hit, ImpactResult)
    assert hit.point[1] == pytest.approx(0.0331) and 0.0 < hit.time < 1 / 90
    printed = capsys.readouterr().out.splitlines()
    assert len(printed) == 8  # the bag's 8 impacts (its truth), one line each
    stamp, from_tip, speed = printed[0].split()
    assert int(stamp) > 0 and 0.0 < float(from_tip) < 0.9 and 20.0 < float(speed) < 40.0
    assert namespace['events'] == []  # every impact came before the end


def test_the_arm_controller_block_makes_its_node_and_takes_each_message(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The controller block: its node subscribes and publishes as it says; callbacks run."""
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'OFF')
    namespace: Dict[str, Any] = {}
    exec(compile(block(CONTROLLER), 'README.md', 'exec'), namespace)
    rclpy.init()  # the block's node takes the default context, as a user's script does
    try:
        node = namespace['SwingController']()
        try:
            topics = sorted(s.topic_name for s in node.subscriptions)
            assert topics == ['/impact_node/impact', '/impact_node/impact_predicted',
                              '/impact_node/predicted_impact']
            assert '/bat_plan' in [publisher.topic_name for publisher in node.publishers]
            # ~/impact is taken before the flag when both wait (rclpy's executor: this order)
            order = [s.topic_name for s in node.subscriptions]
            assert order.index('/impact_node/impact') < order.index(
                '/impact_node/impact_predicted')
            flag, = [s for s in node.subscriptions
                     if s.topic_name == '/impact_node/impact_predicted']
            lease = flag.qos_profile.liveliness_lease_duration
            assert Duration(seconds=LIVELINESS_LEASE_S) <= lease < Duration(seconds=2.0)
            assert flag.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
            assert flag.qos_profile.reliability == ReliabilityPolicy.RELIABLE
            prediction = PointStamped()
            prediction.header.stamp = Time(sec=1_700_000_000, nanosec=5)
            node.on_prediction(prediction)
            node.on_predicted(Bool(data=False))
            node.on_impact(PointStamped())
            node.on_node_liveliness(SimpleNamespace(alive_count=0, alive_count_change=-1))
        finally:
            node.destroy_node()
    finally:
        rclpy.shutdown()
