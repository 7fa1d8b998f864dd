"""
The node's publishers and subscriptions, and the mismatches on their topics.

ROS delivers nothing between endpoints whose QoS or message types do not match, and says so
only through event callbacks. :class:`Endpoints` creates the node's publishers and
subscriptions with those callbacks: each mismatch is warned about, naming the topic, the side
and the policy (or both types), and counted in the diagnostics tally; and it tells why a silent
input may be silent (no publisher discovered yet, one of another type, or of incompatible QoS),
every time.
A latched output (``~/impact_predicted``: sent only when it changes) also names each subscriber
whose compatible QoS still loses its state (best effort or volatile: ``lossy_readers``).
"""

from typing import Any, Callable, Dict, List, Sequence, Set, Tuple

from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.exceptions import InvalidTopicNameException
from rclpy.node import Node
from rclpy.qos import (
    DurabilityPolicy, HistoryPolicy, qos_check_compatible, QoSCompatibility, QoSProfile,
    ReliabilityPolicy)
from rclpy.qos_overriding_options import QoSOverridingOptions

from .diagnostics import Tally
from .messages import type_name
from ..errors import RosError


UNKNOWN_NODE = '_NODE_NAME_UNKNOWN_'
"""The node name the graph gives an endpoint whose node it does not know (yet, or any more)."""


NO_PUBLISHER = 'no publisher discovered yet'
"""Why an input may be silent when the graph knows no publisher on its topic (DDS discovery
may not have found one that exists yet: over 1 s seen on a loaded machine)."""


Guard = Callable[[Callable[..., None], str], Callable[..., None]]
"""Makes an executor callback survive its own failure, given what it does (``_guarded``)."""


def unguarded(callback: Callable[..., None], what: str) -> Callable[..., None]:
    """Return ``callback`` as it is (a ``Guard`` for endpoints outside ``ImpactNode``)."""
    return callback


def input_qos(qos: str, depth: int) -> QoSProfile:
    """
    Return the inputs' QoS for the ``qos`` parameter, volatile.

    ``sensor_data``: best effort, keep last ``depth``; ``reliable``: reliable, keep last
    ``depth``; ``reliable_all``: reliable, keep all (no unread message is overwritten).
    """
    keep_all = qos == 'reliable_all'
    return QoSProfile(
        history=HistoryPolicy.KEEP_ALL if keep_all else HistoryPolicy.KEEP_LAST, depth=depth,
        reliability=ReliabilityPolicy.BEST_EFFORT if qos == 'sensor_data'
        else ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)


def topic_error_line(error: Exception) -> str:
    """
    Return the first line of rclpy's refusal of a topic name, without rcl's source location.

    ``InvalidTopicNameException`` (a name invalid once expanded) or the ``ValueError`` of rcl's
    expansion (an unknown substitution: ``topic name '{foo}/x' is invalid: unknown
    substitution: {foo}``, which rclpy raises as it is, where a node would end with it).
    """
    return str(error).splitlines()[0].rstrip(':').split(', at /')[0]


class Endpoints:
    """
    Create a node's endpoints with mismatch warnings; name the inputs' topics and types.

    :param node: the node the endpoints belong to (and whose logger warns).
    :param tally: where mismatches are counted (``incompatible``).
    :param guard: makes an executor callback survive its own failure, given what it does (the
        node's ``_guarded``; default: the callback as it is).
    :ivar topics: each input stream's resolved topic (``/ball`` ...).
    :ivar types: each input stream's message type (``geometry_msgs/msg/PointStamped`` ...).
    """

    def __init__(self, node: Node, tally: Tally, guard: Guard = unguarded) -> None:
        self._node = node
        self._tally = tally
        self._guard = guard
        self.topics: Dict[str, str] = {}
        self.types: Dict[str, str] = {}
        self._subscriptions: Dict[str, Any] = {}
        self._type_warned: Set[Tuple[str, Tuple[str, ...]]] = set()
        self._latched: List[Any] = []  # publishers whose readers must keep their state
        self._reader_warned: Set[Tuple[str, bytes]] = set()  # (topic, subscriber's gid)

    def advertise(self, msg_type: Any, topic: str, qos: QoSProfile) -> Any:
        """
        Return a new publisher whose QoS mismatches are warned about, naming the topic.

        A transient-local one (latched) also has its lossy subscribers named
        (``lossy_readers``) as each matches, and at each ``lossy_readers`` call after.
        """
        name = [topic]  # resolved once the publisher exists
        latched = qos.durability == DurabilityPolicy.TRANSIENT_LOCAL
        callbacks = PublisherEventCallbacks(
            incompatible_qos=lambda info: self._incompatible_qos(name[0], 'publisher', info),
            matched=self._guard(lambda info: self.lossy_readers(),
                                'checking the QoS of a new subscriber') if latched else None)
        publisher = self._node.create_publisher(msg_type, topic, qos, event_callbacks=callbacks)
        name[0] = publisher.topic_name
        if latched:
            self._latched.append(publisher)
        return publisher

    def lossy_readers(self) -> List[str]:
        """
        Warn, once each, about a latched output's subscribers whose QoS loses its state.

        ``~/impact_predicted`` is sent once per change and kept for late joiners. A volatile
        subscriber gets no value until the next change; a best-effort one gets none on joining
        (Fast DDS gives its stored value to reliable readers only) and may lose a change, which
        is never sent again: an arm could wait on a prediction withdrawn long ago. Their QoS is
        compatible, so ROS says nothing. Asked of the graph at each match and at each call (the
        diagnostics timer), as a match may come before the graph knows the subscriber's QoS; a
        subscriber whose node the graph does not know (yet, or any more as it leaves) is left
        for a later call.

        :returns: the warnings given in this call.
        """
        given = []
        for publisher in self._latched:
            topic = publisher.topic_name
            for info in self._node.get_subscriptions_info_by_topic(topic):
                qos = info.qos_profile
                lost = tuple(reason for reason, holds in (
                    ('best effort: no value on joining, and a lost change is never sent again',
                     qos.reliability == ReliabilityPolicy.BEST_EFFORT),
                    ('volatile: no value until the next change',
                     qos.durability != DurabilityPolicy.TRANSIENT_LOCAL)) if holds)
                who = f"{info.node_namespace.rstrip('/')}/{info.node_name}"
                key = (topic, bytes(info.endpoint_gid))
                if not lost or key in self._reader_warned or UNKNOWN_NODE in who:
                    continue  # (an unknown node is asked again, once the graph knows it)
                self._reader_warned.add(key)
                given.append(f'subscriber {who} on {topic} loses the latched state: '
                             + '; '.join(lost) + ' (it is sent once per change): subscribe '
                             'reliable and transient local, depth 1')
                self._node.get_logger().warning(given[-1])
        return given

    def subscribe(self, stream: str, msg_type: Any, topic: str, callback: Callable[[Any], None],
                  qos: QoSProfile) -> Any:
        """
        Return a new subscription of an input stream, its QoS and type mismatches warned about.

        ``qos`` is the default; the standard ``qos_overrides./TOPIC.subscription.`` parameters
        (``reliability``, ``history``, ``depth``; read-only, from a params file or
        ``-p``) override it (rclpy's ``QoSOverridingOptions``).

        :raises RosError: a topic name that fails once expanded (``a//b``, ``{ns}//x``) or
            has an unknown substitution (``{foo}/x``).
        """
        events = SubscriptionEventCallbacks(
            incompatible_qos=lambda info: self._incompatible_qos(
                self.topics.get(stream, topic), 'subscription', info),
            incompatible_type=lambda info: self._incompatible_type(stream))
        self.types[stream] = type_name(msg_type)
        try:
            subscription = self._node.create_subscription(
                msg_type, topic, callback, qos, event_callbacks=events,
                qos_overriding_options=QoSOverridingOptions.with_default_policies())
        except (InvalidTopicNameException, ValueError) as error:
            raise RosError(f'{stream} topic {topic!r}: {topic_error_line(error)}') from error
        self.topics[stream] = subscription.topic_name
        self._subscriptions[stream] = subscription
        return subscription

    def silence(self, stream: str) -> str:
        """
        Return why an input may be silent: no publisher, one of another type or QoS, or ''.

        Asked of the graph each time, so the reason stays in every status while it holds (the
        QoS event that warned about a mismatch comes once). The graph knows only the publishers
        DDS discovery has found: a publisher that exists may be found a second or more after
        start-up on a loaded machine, so the reason says what is known (:data:`NO_PUBLISHER`),
        not that there is none.
        """
        infos = self._node.get_publishers_info_by_topic(self.topics[stream])
        if not infos:
            return NO_PUBLISHER
        others = sorted({info.topic_type for info in infos} - {self.types[stream]})
        if others:
            self._incompatible_type(stream, others)
            return f"publisher of {', '.join(others)}, expected {self.types[stream]}"
        ours = self._subscriptions[stream].qos_profile
        reasons = []
        for info in infos:
            compatibility, reason = qos_check_compatible(info.qos_profile, ours)
            if compatibility == QoSCompatibility.ERROR:
                reasons.append(reason.removeprefix('ERROR:').strip().rstrip(';'))
        if not reasons:
            return ''
        some = f' ({len(reasons)} of {len(infos)} publishers)' if len(reasons) < len(infos) else ''
        return f"incompatible QoS{some}: {'; '.join(sorted(set(reasons)))}"

    def _incompatible_qos(self, topic: str, role: str, info: Any) -> None:
        """Warn that an endpoint on ``topic`` has QoS incompatible with ours, naming the policy."""
        self._tally.incompatible += 1
        policy = getattr(info.last_policy_kind, 'name', str(info.last_policy_kind))
        policy = policy.replace('RMW_QOS_POLICY_', '')
        hint = ''
        if role == 'subscription' and 'RELIABILITY' in policy:
            hint = ("; this node subscribes 'reliable': publish reliable or set "
                    'qos:=sensor_data')
        elif role == 'subscription' and 'DURABILITY' in policy:
            hint = '; the publisher offers volatile durability, this node asks for more'
        self._node.get_logger().warning(
            f'incompatible QoS on {topic} ({role} side): policy {policy}; '
            f'{info.total_count} incompatible endpoint(s), no messages flow{hint}')

    def _incompatible_type(self, stream: str, others: Sequence[str] = ()) -> None:
        """Warn (once per stream and type) that a publisher has another type than expected."""
        key = (stream, tuple(others))
        if key in self._type_warned:
            return
        self._type_warned.add(key)
        self._tally.incompatible += 1
        hint = " (set ball_type to 'point' or 'pose')" if stream == 'ball' else ''
        other = f" ({', '.join(others)})" if others else ''
        self._node.get_logger().warning(
            f'a publisher on {self.topics[stream]} has another type{other} than '
            f'{self.types[stream]}: no messages flow{hint}')
