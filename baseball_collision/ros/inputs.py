"""
The node's input streams: which topic and type each reads, and what it hands the detector.

``ball_type`` and ``bat_input`` choose the streams (:func:`input_streams`); each becomes one
subscription whose callback (:func:`input_callback`) takes the message and rclpy's message info
(a ``dict``) and hands the node the stream, the header, the ``Detector`` method and its values
(m, quaternion ``x, y, z, w``), and the publication sequence number when the RMW gives one
(:func:`sequence_number`). Drop warnings, throttled per reason, are :class:`DropWarnings`.
"""

from dataclasses import dataclass
import math
import time
from typing import Any, Callable, Dict, List, Mapping, Optional, Tuple

from geometry_msgs.msg import PointStamped, PoseStamped
from rclpy.exceptions import InvalidHandle

from .logger import DirectLogger
from .messages import describe_drop, xyz, xyzw

WARN_PERIOD_S = 2.0
"""Shortest time (s) between two log lines of one kind (per drop reason)."""

DRAIN_LIMIT = 64
"""Queued input messages one executor callback takes at most (see :class:`Intake`)."""


@dataclass(frozen=True)
class InputStream:
    """
    One input of the node.

    :ivar stream: its name in the detector and the diagnostics (``ball``, ``bat_pose``, ...).
    :ivar msg_type: the rclpy message class.
    :ivar topic_parameter: the parameter naming its topic.
    :ivar method: the ``Detector`` method its samples go to.
    :ivar values: a message's values for that method.
    """

    stream: str
    msg_type: Any
    topic_parameter: str
    method: str
    values: Callable[[Any], Tuple[Any, ...]]


_STREAMS = {
    ('ball', 'point'): InputStream('ball', PointStamped, 'ball_topic', 'add_ball',
                                   lambda m: (xyz(m.point),)),
    ('ball', 'pose'): InputStream('ball', PoseStamped, 'ball_topic', 'add_ball',
                                  lambda m: (xyz(m.pose.position),)),
    ('bat_pose', 'pose'): InputStream(
        'bat_pose', PoseStamped, 'bat_pose_topic', 'add_bat_pose',
        lambda m: (xyz(m.pose.position), xyzw(m.pose.orientation))),
    ('knob', 'point'): InputStream('knob', PointStamped, 'knob_topic', 'add_knob',
                                   lambda m: (xyz(m.point),)),
    ('tip', 'point'): InputStream('tip', PointStamped, 'tip_topic', 'add_tip',
                                  lambda m: (xyz(m.point),)),
}


def input_streams(settings: Mapping[str, Any]) -> List[InputStream]:
    """Return the inputs ``ball_type`` (``point``, ``pose``) and ``bat_input`` choose."""
    chosen = [_STREAMS['ball', settings['ball_type']]]
    if settings['bat_input'] == 'pose':
        chosen.append(_STREAMS['bat_pose', 'pose'])
    else:
        chosen += [_STREAMS['knob', 'point'], _STREAMS['tip', 'point']]
    return chosen


def sequence_number(info: Optional[Mapping[str, Any]]) -> Optional[int]:
    """
    Return a message's publication sequence number from rclpy's message info, or None.

    rmw_fastrtps_cpp (Jazzy's default) numbers each publisher's messages 1, 2, 3 ...; an RMW
    that does not gives None (rclpy maps ``RMW_MESSAGE_INFO_SEQUENCE_NUMBER_UNSUPPORTED``).
    """
    return _given(info, 'publication_sequence_number')


def sent_time(info: Optional[Mapping[str, Any]]) -> Optional[int]:
    """
    Return a message's send time (ns, the writer's clock) from rclpy's message info, or None.

    rmw_fastrtps_cpp gives each message its writer's source timestamp; 0 (not given) is None.
    """
    return _given(info, 'source_timestamp')


def _given(info: Optional[Mapping[str, Any]], key: str) -> Optional[int]:
    """Return rclpy's message info's ``key``, or None where the RMW gave none (0, None)."""
    value = info.get(key) if info else None
    return value if value else None


def input_callback(take: Callable[..., None], each: InputStream,
                   detector: Any) -> Callable[[Any, Mapping[str, Any]], None]:
    """
    Return the subscription callback of one input (it takes the message and message info).

    It calls ``take(stream, header, add_sample, *values, sequence=number, sent=ns)``:
    ``add_sample`` the ``detector`` method of the stream, ``number`` from
    :func:`sequence_number`, ``ns`` from :func:`sent_time`.
    """
    add_sample, values, stream = getattr(detector, each.method), each.values, each.stream

    def callback(message: Any, info: Mapping[str, Any]) -> None:
        take(stream, message.header, add_sample, *values(message),
             sequence=sequence_number(info), sent=sent_time(info))
    return callback


class Intake:
    """
    Take the inputs' queued messages inside one executor callback, in the order they arrived.

    rclpy's executors take one message per ready subscription per wait, and build the wait set
    (every subscription, timer, service and event handler of the node) and a task around each
    message: several times the node's own work per message, so a node behind by a burst, or
    under a stale publisher's doubled input, fell further behind and lost messages from its
    queue. Each callback :meth:`wrap` returns handles its message and whatever waits in the
    attached subscriptions' queues (the samples' and the bat plan's), at most ``limit``
    (timers and services get their turn between).

    They are handled in the order the RMW received them (``received_timestamp`` of rclpy's
    message info: one clock for every subscription), each queue's head against the others':
    the order a recorder logs them in, which ``analyze`` keeps. Topics keep no order between
    them, so taken in turn a plan sent before a backlog's samples came after them (replayed 8
    times as fast, 11 of 19 runs of an arm's bag lost some of its first planned predictions).
    Messages with no receive time (an RMW that gives none: 0) or the same one are taken one per
    input in turn, each input keeping its own order.

    :param limit: messages taken at most per executor callback.
    """

    def __init__(self, limit: int = DRAIN_LIMIT) -> None:
        self._limit = limit
        self._inputs: List[Tuple[Any, Callable[..., None]]] = []
        self._index: Dict[Callable[..., None], int] = {}
        self._draining = False

    def wrap(self, callback: Callable[[Any, Any], None]) -> Callable[[Any, Any], None]:
        """Return the executor's callback for an input: ``callback`` in turn, and the queues."""
        def on_message(message: Any, info: Any) -> None:
            self.drain((callback, message, info))
        return on_message

    def attach(self, subscription: Any, callback: Callable[[Any, Any], None]) -> None:
        """Add an input's subscription and its (unwrapped) callback to the merge."""
        self._index[callback] = len(self._inputs)
        self._inputs.append((subscription, callback))

    def drain(self, taken: Optional[Tuple[Callable[..., None], Any, Any]] = None) -> None:
        """
        Handle ``taken`` (callback, message, info) and the queued messages in arrival order.

        Each attached queue's head is taken, and the earliest received of the heads handled,
        then its queue's next taken, until every queue is empty or ``limit`` messages were
        taken (those held are handled then). A message whose callback was never attached is
        handled first. Inside a drain (a callback that drains) this handles ``taken`` only.
        """
        if self._draining or (taken is not None and taken[0] not in self._index):
            if taken is not None:
                taken[0](taken[1], taken[2])
            return
        self._draining = True
        try:
            self._merge(taken)
        finally:
            self._draining = False

    def _merge(self, taken: Optional[Tuple[Callable[..., None], Any, Any]]) -> None:
        """Handle ``taken`` and the queues' messages, earliest received first (``drain``)."""
        heads: List[Optional[Tuple[Tuple[int, int], Any, Any]]] = [None] * len(self._inputs)
        turn = count = 0
        if taken is not None:
            heads[self._index[taken[0]]] = ((_received(taken[2]), turn), taken[1], taken[2])
            count = 1
        closed = False  # a subscription destroyed (shutting down): what is held is handled
        while True:
            for index, (subscription, _) in enumerate(self._inputs):
                if heads[index] is None and count < self._limit and not closed:
                    try:
                        with subscription.handle:
                            got = subscription.handle.take_message(subscription.msg_type,
                                                                   subscription.raw)
                    except InvalidHandle:
                        closed = True
                        continue
                    if got is not None:
                        turn += 1
                        heads[index] = ((_received(got[1]), turn), *got)
                        count += 1
            waiting = [index for index, head in enumerate(heads) if head is not None]
            if not waiting:
                return
            first = min(waiting, key=lambda index: heads[index][0])
            _, message, info = heads[first]
            heads[first] = None
            self._inputs[first][1](message, info)


def _received(info: Optional[Mapping[str, Any]]) -> int:
    """Return a message's receive time (ns, the RMW's clock) from rclpy's message info, or 0."""
    return _given(info, 'received_timestamp') or 0


class Throttle:
    """
    Say whether a log line of one kind may go out: at most once every ``WARN_PERIOD_S``.

    rclpy's own ``throttle_duration_sec`` finds the caller's frame and source line (file system
    calls) on every call, before it knows whether the line is throttled: about 1 ms a call on a
    loaded machine, on every dropped sample (half the ball input under a stale publisher). This
    decides first, on the monotonic clock, so a throttled line costs a dictionary look-up.

    :param period_s: shortest time (s) between two lines of one kind.
    """

    __slots__ = ('_period', '_next')

    def __init__(self, period_s: float = WARN_PERIOD_S) -> None:
        self._period = period_s
        self._next: Dict[Any, float] = {}

    def allows(self, kind: Any) -> bool:
        """Return True (and start a quiet period) when a line of ``kind`` may be logged now."""
        now = time.monotonic()
        if now < self._next.get(kind, -math.inf):
            return False
        self._next[kind] = now + self._period
        return True


class DropWarnings:
    """
    Warn about dropped samples, each reason at most once every ``WARN_PERIOD_S``.

    :param logger_name: the node's logger's name.
    """

    def __init__(self, logger_name: str) -> None:
        self._logger = DirectLogger(logger_name)
        self._throttle = Throttle()

    def warn(self, stream: str, topic: str, reason: str, frame: str, expected: Optional[str],
             stamp: int, so_far: int) -> None:
        """
        Warn that a sample of ``stream`` on ``topic`` was dropped for ``reason``.

        :param frame: its frame; ``expected``: the tracking frame; ``stamp``: its stamp (ns);
            ``so_far``: samples dropped for this reason since start-up.
        """
        if not self._throttle.allows(reason):
            return  # before any text is made: the cheap path for a stream of drops
        self._logger.warning(
            f'dropped a {stream} sample on {topic}: {reason}: '
            f'{describe_drop(reason, frame, expected, stamp)}; '
            f'{so_far} dropped for this reason so far')
