"""
The node under test and a probe node in one fresh rclpy context, and message builders.

Shared by the in-process node tests (``test/ros``): every expectation there is on header stamps.
"""

import threading
import time
from typing import Any, Callable, Dict, List, Optional, Sequence

from baseball_collision.ros.node import ImpactNode
from builtin_interfaces.msg import Time as TimeMsg
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PointStamped, PoseStamped, TwistStamped, Vector3Stamped
import pytest
from rcl_interfaces.srv import SetParameters
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Bool, String
from support.scenes import BASE_NS
from visualization_msgs.msg import MarkerArray

RATE_HZ = 360.0
SAMPLES = 72  # 0.2 s of swing at 360 Hz
RELIABLE = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)


def stamp(ns: int) -> TimeMsg:
    """Return integer nanoseconds as a message stamp."""
    return TimeMsg(sec=ns // 10**9, nanosec=ns % 10**9)


def stamp_ns(message: Any) -> int:
    """Return a message's header stamp in nanoseconds."""
    return message.header.stamp.sec * 10**9 + message.header.stamp.nanosec


def point_msg(ns: int, xyz: Sequence[float], frame: str = 'world') -> PointStamped:
    """Return a PointStamped (m) stamped ``ns``."""
    message = PointStamped()
    message.header.stamp, message.header.frame_id = stamp(ns), frame
    message.point.x, message.point.y, message.point.z = (float(v) for v in xyz)
    return message


def pose_msg(ns: int, position: Sequence[float], quaternion: Sequence[float],
             frame: str = 'world') -> PoseStamped:
    """Return a PoseStamped stamped ``ns`` (quaternion x, y, z, w)."""
    message = PoseStamped()
    message.header.stamp, message.header.frame_id = stamp(ns), frame
    p, q = message.pose.position, message.pose.orientation
    p.x, p.y, p.z = (float(v) for v in position)
    q.x, q.y, q.z, q.w = (float(v) for v in quaternion)
    return message


def sample_ns(i: int) -> int:
    """Return the stamp (ns) of sample i of the 360 Hz swing."""
    return BASE_NS + int(round(i / RATE_HZ * 1e9))


def values(status: DiagnosticStatus) -> Dict[str, str]:
    """Return a diagnostic status's key/values as a dict."""
    return {kv.key: kv.value for kv in status.values}


class Harness:
    """
    The node under test and a probe node in one fresh context, spun by a background thread.

    :param overrides: parameters of the node under test.
    :param args: extra ROS command line for the context (e.g. ``--params-file``).
    """

    def __init__(self, overrides: Optional[Dict[str, Any]] = None,
                 args: Optional[List[str]] = None) -> None:
        self.context = rclpy.Context()
        rclpy.init(context=self.context, args=['--ros-args'] + (args or []))
        self.node: Optional[ImpactNode] = None
        self.executor: Optional[SingleThreadedExecutor] = None
        self.thread: Optional[threading.Thread] = None
        self.probe = rclpy.create_node('probe', context=self.context)
        self.received: Dict[str, List[Any]] = {}
        self._condition = threading.Condition()
        settings = {'qos': 'reliable', 'qos_depth': 1000, 'diagnostics_period': 0.2}
        settings.update(overrides or {})
        self.node = ImpactNode(
            context=self.context,
            parameter_overrides=[Parameter(k, value=v) for k, v in settings.items()])
        for name, msg_type, topic in (
                ('impact', PointStamped, '/impact_node/impact'),
                ('velocity', TwistStamped, '/impact_node/impact_velocity'),
                ('near_miss', Vector3Stamped, '/impact_node/near_miss'),
                ('markers', MarkerArray, '/impact_node/markers'),
                ('diagnostics', DiagnosticArray, '/diagnostics'),
                ('predicted', PointStamped, '/impact_node/predicted_impact'),
                ('predicting', Bool, '/impact_node/impact_predicted'),
                ('report', String, '/impact_node/impact_report')):
            self.received[name] = []
            self.probe.create_subscription(msg_type, topic, self._collector(name), RELIABLE)
        self.publishers: Dict[str, Any] = {}

    def _collector(self, name: str) -> Callable[[Any], None]:
        def collect(message: Any) -> None:
            with self._condition:
                self.received[name].append(message)
                self._condition.notify_all()
        return collect

    def publisher(self, msg_type: Any, topic: str, qos: QoSProfile = RELIABLE) -> Any:
        """Create a probe publisher on ``topic``; call before ``start``."""
        publisher = self.probe.create_publisher(msg_type, topic, qos)
        self.publishers[topic] = publisher
        return publisher

    def start(self) -> 'Harness':
        """Spin both nodes in a background thread and wait for every publisher to match."""
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.executor.add_node(self.probe)
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)
        self.thread.start()
        self.wait(lambda: all(p.get_subscription_count() > 0
                              for p in self.publishers.values()), 5.0, 'publishers matched')
        return self

    def unsubscribe(self, topic: str) -> None:
        """
        Destroy the probe's subscriptions on ``topic``, in the spin thread.

        Destroyed from another thread while the executor builds its wait set, a subscription's
        event handler raises ``InvalidHandle`` there and ends the spin (seen under load).
        """
        done = threading.Event()

        def drop() -> None:
            timer.cancel()
            for subscription in list(self.probe.subscriptions):
                if subscription.topic_name == topic:
                    self.probe.destroy_subscription(subscription)
            done.set()

        timer = self.probe.create_timer(0.001, drop)
        assert done.wait(5.0), f'the probe did not unsubscribe from {topic}'

    def wait(self, predicate: Callable[[], bool], timeout: float, what: str) -> None:
        """Wait until predicate() holds, or fail naming ``what``."""
        deadline = time.monotonic() + timeout
        with self._condition:
            while not predicate():
                left = deadline - time.monotonic()
                if left <= 0.0:
                    pytest.fail(f'timed out waiting for {what}')
                self._condition.wait(min(left, 0.02))

    def processed(self, count: int, timeout: float = 5.0) -> None:
        """Wait until the node took ``count`` messages in, then let it publish."""
        self.wait(lambda: sum(self.node.tally.arrivals.values()) >= count, timeout,
                  f'{count} messages processed')
        time.sleep(0.05)

    def call(self, srv_type: Any, name: str, request: Any, timeout: float = 5.0) -> Any:
        """Call a service from the probe and return the response."""
        client = self.probe.create_client(srv_type, name)
        assert client.wait_for_service(timeout_sec=timeout), name
        future = client.call_async(request)
        self.wait(future.done, timeout, f'response of {name}')
        return future.result()

    def set_parameters(self, **parameters: Any) -> List[Any]:
        """Set parameters through the node's parameter service; return the results."""
        request = SetParameters.Request(
            parameters=[Parameter(k, value=v).to_parameter_msg() for k, v in parameters.items()])
        return self.call(SetParameters, '/impact_node/set_parameters', request).results

    def diagnostics_where(self, predicate: Callable[[Dict[str, str]], bool],
                          timeout: float = 3.0) -> DiagnosticStatus:
        """Wait for a /diagnostics status whose key/values satisfy predicate; return it."""
        found: List[DiagnosticStatus] = []

        def match() -> bool:
            for array in self.received['diagnostics']:
                for status in array.status:
                    if status.name.startswith('impact_node') and predicate(values(status)):
                        found.append(status)
                        return True
            return False
        self.wait(match, timeout, 'a matching /diagnostics status')
        return found[0]

    def close(self) -> None:
        """Tear down in the order ENVIRONMENT.md found safe."""
        if self.executor is not None:
            self.executor.shutdown(timeout_sec=2.0)
        if self.thread is not None:
            self.thread.join(timeout=5.0)
        if self.node is not None:
            self.node.destroy_node()
        self.probe.destroy_node()
        rclpy.shutdown(context=self.context)
