"""The node's intake: queued input messages taken in arrival order, and throttled log lines."""

from collections import deque
from typing import Any, Deque, List, Optional, Tuple

from baseball_collision.ros.inputs import Intake, Throttle
from rclpy.exceptions import InvalidHandle


class _Handle:
    """An rclpy subscription handle over a queue: ``take_message`` pops (message, info)."""

    def __init__(self, messages: List[Any], destroyed: bool = False) -> None:
        self.queue: Deque[Tuple[Any, dict]] = deque(
            m if isinstance(m, tuple) else (m, {}) for m in messages)
        self.destroyed = destroyed

    def __enter__(self) -> '_Handle':
        if self.destroyed:
            raise InvalidHandle('destroyed')
        return self

    def __exit__(self, *exc: Any) -> None:
        pass

    def take_message(self, msg_type: Any, raw: bool) -> Optional[Tuple[Any, dict]]:
        return self.queue.popleft() if self.queue else None


class _Subscription:
    """An rclpy subscription: its handle, message type and raw flag."""

    def __init__(self, messages: List[Any], destroyed: bool = False) -> None:
        self.handle = _Handle(messages, destroyed)
        self.msg_type, self.raw = object, False


def _intake(queues: List[List[Any]], limit: int) -> Tuple[Intake, List[Any], List[Any]]:
    """Return an intake over queued inputs, what it handled, and the executor's callbacks."""
    intake, seen, wrapped = Intake(limit), [], []
    for queue in queues:
        subscription = _Subscription(queue)
        callback = (lambda message, info: seen.append(message))
        wrapped.append(intake.wrap(callback))
        intake.attach(subscription, callback)
    return intake, seen, wrapped


def _received(name: str, ns: int) -> Tuple[str, dict]:
    """Return a queued message and rclpy's message info saying it was received at ``ns``."""
    return name, {'received_timestamp': ns, 'source_timestamp': ns - 100}


def test_queued_messages_are_taken_in_the_order_they_were_received() -> None:
    """Across inputs (a plan between a backlog's samples) by receive time, each in its order."""
    ball = [_received('b1', 20), _received('b2', 40), _received('b3', 50), _received('b4', 90)]
    bat = [_received('k1', 30), _received('k2', 45), _received('k3', 95)]
    plan = [_received('plan', 42)]
    _, seen, wrapped = _intake([ball, bat, plan], limit=100)
    wrapped[1]('k0', {'received_timestamp': 10})
    assert seen == ['k0', 'b1', 'k1', 'b2', 'plan', 'k2', 'b3', 'b4', 'k3']


def test_messages_without_a_receive_time_are_taken_one_per_input_in_turn() -> None:
    """The executor's message first, then the queues round-robin, each in its own order."""
    _, seen, wrapped = _intake([['b1', 'b2', 'b3', 'b4'], ['p1', 'p2']], limit=100)
    wrapped[0]('b0', {})
    assert seen == ['b0', 'p1', 'b1', 'p2', 'b2', 'b3', 'b4']


def test_at_most_limit_messages_per_executor_callback() -> None:
    """The rest stays queued for the next callback (timers and services get their turn)."""
    intake, seen, wrapped = _intake([list(range(10)), list(range(100, 110))], limit=5)
    wrapped[1]('first', {})
    assert seen == ['first', 0, 100, 1, 101]  # the executor's message counts
    intake.drain()
    assert seen[5:] == [2, 102, 3, 103, 4]
    for _ in range(3):
        intake.drain()
    assert len(seen) == 21 and [m for m in seen[1:] if m < 100] == list(range(10))


def test_a_message_of_an_input_never_attached_is_handled_at_once() -> None:
    """A callback wrapped but not attached (no subscription to merge) still gets its message."""
    intake, seen, wrapped = _intake([[_received('b1', 15)]], limit=10)
    intake.wrap(lambda message, info: seen.append(message))('lone', {'received_timestamp': 1})
    assert seen == ['lone']
    wrapped[0]('b0', {'received_timestamp': 9})
    assert seen == ['lone', 'b0', 'b1']


def test_a_destroyed_subscription_ends_the_drain_and_nested_calls_do_not_recurse() -> None:
    """Shutting down (InvalidHandle) stops taking, not handling; a nested drain takes nothing."""
    intake, seen = Intake(10), []
    intake.attach(_Subscription(['x'], destroyed=True), lambda m, i: seen.append(m))
    intake.drain()
    assert seen == []
    callback = (lambda message, info: seen.append(message))  # a message taken is handled
    intake.attach(_Subscription(['y']), callback)
    intake.wrap(callback)('taken', {})
    assert seen == ['taken']  # ('y' stays queued: nothing is taken once one is destroyed)
    nested = Intake(10)
    queue = _Subscription(['a', 'b'])
    nested.attach(queue, lambda m, i: (seen.append(m), nested.drain()))
    nested.drain()
    assert seen == ['taken', 'a', 'b']


def test_a_throttle_allows_one_line_of_a_kind_per_period() -> None:
    """The first line of each kind passes, the next of that kind within the period does not."""
    throttle = Throttle(3600.0)
    assert throttle.allows('stale_stamp') and throttle.allows('out_of_order')
    assert not throttle.allows('stale_stamp')
    always = Throttle(0.0)
    assert always.allows('x') and always.allows('x')
