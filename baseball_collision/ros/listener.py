"""
Listen to a running ``impact_node`` from another process: an rclpy session and subscriptions.

The rclpy side of ``baseball-collision demo``: the tools get the node's events as plain values
(stamps in ns, vectors as tuples in m, m/s, rad/s) through callbacks and import neither rclpy
nor a message package.

* :class:`RosSession`: a private rclpy context with one node, spun by a single-threaded
  executor in a daemon thread; closed in the order ENVIRONMENT.md asks (executor, thread, node,
  context).
* :class:`EventListener`: reliable subscriptions to the node's ``~/impact``,
  ``~/impact_report`` and ``~/near_miss``.

Callbacks run on the executor's thread.
"""

import threading
from typing import Any, Callable, Mapping

from geometry_msgs.msg import PointStamped, Vector3Stamped
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from .messages import stamp_to_ns, xyz
from ..core.geometry import Vector

LISTEN_DEPTH = 100
"""Keep-last depth of each event subscription (messages)."""


class RosSession:
    """
    A private rclpy context with one node spinning in a thread; a context manager.

    :param node_name: the node's name.
    :ivar node: the node (create subscriptions and players on it).
    """

    def __init__(self, node_name: str) -> None:
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node(node_name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._spinner = threading.Thread(target=self.executor.spin, daemon=True)
        self._spinner.start()

    def close(self) -> None:
        """Stop the executor and its thread, destroy the node, shut the context down."""
        self.executor.shutdown(timeout_sec=2.0)
        self._spinner.join(timeout=5.0)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)

    def __enter__(self) -> 'RosSession':
        """Return self."""
        return self

    def __exit__(self, exc_type: Any, exc_value: Any, traceback: Any) -> None:
        """Close the session."""
        self.close()


class EventListener:
    """
    Subscriptions to a node's event topics, each message handed on as plain values.

    :param node: the rclpy node to subscribe with.
    :param topics: the node's topics by event: ``'impact'``, ``'impact_report'``,
        ``'near_miss'`` (as ``tools.parameters.output_topics`` names them).
    :param on_impact: ``(stamp_ns, contact point)`` per ``~/impact`` message.
    :param on_report: the JSON text of each ``~/impact_report`` record (an impact's, a near
        miss's, a prediction's: the node makes them while a subscriber listens).
    :param on_near_miss: ``(stamp_ns, gap vector)`` per ``~/near_miss`` message.
    """

    def __init__(self, node: Any, topics: Mapping[str, str],
                 on_impact: Callable[[int, Vector], None],
                 on_report: Callable[[str], None],
                 on_near_miss: Callable[[int, Vector], None]) -> None:
        qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=LISTEN_DEPTH,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.VOLATILE)
        self.subscriptions = [
            node.create_subscription(
                PointStamped, topics['impact'],
                lambda message: on_impact(stamp_to_ns(message.header.stamp), xyz(message.point)),
                qos),
            node.create_subscription(
                String, topics['impact_report'], lambda message: on_report(message.data), qos),
            node.create_subscription(
                Vector3Stamped, topics['near_miss'],
                lambda message: on_near_miss(stamp_to_ns(message.header.stamp),
                                             xyz(message.vector)), qos)]

    def matched(self) -> bool:
        """Return whether every subscription has matched the node's publisher."""
        return all(s.get_publisher_count() >= 1 for s in self.subscriptions)
