"""
Replay a bag over ROS 2, as ``ros2 bag play --clock`` would (there is no ros2 CLI here).

Every topic of the bag whose type rclpy can import is published with its own name and type:

* Pacing: a message is published when the wall time since the start reaches its log time since
  the bag's first log time, divided by ``rate``.
* ``/clock`` (``rosgraph_msgs/Clock``) at ``clock_hz``: the bag time the pacing has reached, so
  nodes with ``use_sim_time`` follow the bag. ``loop`` restarts from the first message, and the
  clock jumps back (a node resets on that).
* QoS: reliable, volatile, keep-last ``depth`` deep. Delivery: a publisher never holds more
  than ``depth // 2`` messages its reliable subscribers have not acknowledged (after that many
  it waits for their acknowledgements, and the schedule resumes from there), so its keep-last
  queue never overwrites a message a subscriber has not received: a reliable keep-all
  subscriber (``impact_node``: ``qos:=reliable_all``) gets every message at any rate, the
  playback slowing to what it takes in. An acknowledgement says a message reached the
  subscriber's queue, not that it was read: a reliable keep-last subscriber that falls more
  than its depth behind loses the oldest unread ones, whatever the player does (measured: a
  depth-100 subscriber got 572 of 3,000 messages sent at once, every one acknowledged). What it
  cannot promise it says (``replay_summary``): an acknowledgement wait that timed out
  (``ack_timeouts``), publishing that fell behind the schedule (``late_s``: the player could
  not keep the rate; the acknowledgement waits, ``ack_wait_s``, are not counted), keep-last
  subscribers (``keep_last_subscribers``) and best-effort ones (``best_effort_subscribers``),
  which may drop under load. Fast DDS acknowledges on its heartbeat (every 3 s by default):
  one wait per ``depth // 2`` messages costs up to that.
* Every message is published as serialised CDR bytes (an rclpy publisher takes ``bytes``):
  ROS 2 bags (MCAP, sqlite3) as recorded, ROS 1 bags converted by rosbags
  (:class:`baseball_collision.bags.RawBag`; ``header.seq`` has no ROS 2 counterpart and is
  dropped). Nothing is deserialised.

The bag side is :mod:`baseball_collision.bags`; this module holds the rclpy side only.
"""

from dataclasses import dataclass, field
import importlib
import os
from pathlib import Path
import sys
import threading
import time
from typing import Any, Dict, IO, List, Optional, Sequence, Tuple

import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock

from ..bags import RawBag
from ..errors import BagError, RosError

CLOCK_TOPIC = '/clock'
"""Where the bag time is published."""

DEFAULT_DEPTH = 10000
"""Keep-last depth of every replay publisher (messages)."""

ACK_TIMEOUT_S = 60.0
"""How long (s) one wait for acknowledgements may take: a keep-all subscriber that fell behind
acknowledges only as it takes messages from its full queue, so the wait lasts as long as the
subscriber needs to catch up; past this the subscriber is taken as stuck (counted, warned)."""

ACK_SLICE_S = 0.2
"""s: an acknowledgement wait is made of waits this long, so Ctrl-C (a Python signal handler,
run between them) ends a replay that waits for a subscriber at once."""

LATE_WARN_S = 0.1
"""Publishing this late (s, wall time) against the schedule is said at the end."""


def message_class(msgtype: str) -> Any:
    """
    Return the rclpy message class of a ROS 2 type name (``pkg/msg/Name``): its type support.

    :raises RosError: the package or message is not installed.
    """
    package, _, name = msgtype.partition('/msg/')
    try:
        return getattr(importlib.import_module(f'{package}.msg'), name)
    except (ImportError, AttributeError, ValueError) as error:
        raise RosError(f'message type {msgtype} is not available to rclpy') from error


def _reliable(depth: int) -> QoSProfile:
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)


@dataclass
class ReplayResult:
    """
    What a replay did.

    :ivar messages: messages published (over all loops).
    :ivar loops: complete passes over the bag.
    :ivar seconds: wall time of the playback (s), also when it was stopped.
    :ivar in_loop: messages published of the pass that was running when it stopped (0: it
        ended at the end of a pass).
    :ivar ack_timeouts: waits for acknowledgements that timed out: a reliable subscriber did
        not keep up and may have lost messages.
    :ivar late_s: the most a message was published after its due time (s, wall time; the
        acknowledgement waits shift the schedule and are not lateness).
    :ivar ack_waits: waits for acknowledgements (one per ``depth // 2`` messages of a topic,
        and at the end); ``ack_wait_s``: their total wall time (s).
    :ivar keep_last_subscribers: ``(topic, depth)`` of the reliable keep-last subscribers
        matched at the end (each may lose what it falls more than ``depth`` behind).
    :ivar best_effort_subscribers: topics with a best-effort subscriber matched at the end.
    :ivar skipped_topics: topics not published (type unknown to rclpy, several types, or a
        ROS 1 type without a ROS 2 definition), sorted.
    """

    messages: int = 0
    loops: int = 0
    seconds: float = 0.0
    in_loop: int = 0
    ack_timeouts: int = 0
    late_s: float = 0.0
    ack_waits: int = 0
    ack_wait_s: float = 0.0
    keep_last_subscribers: List[Tuple[str, int]] = field(default_factory=list)
    best_effort_subscribers: List[str] = field(default_factory=list)
    skipped_topics: List[str] = field(default_factory=list)


class BagPlayer:
    """
    Publish a bag's topics from a node, paced by log time, with ``/clock``.

    Use as a context manager (closes the bag and destroys the publishers)::

        with BagPlayer(node, 'run.mcap', rate=2.0) as player:
            player.wait_for_subscribers(['/ball'], timeout_s=10.0)
            player.play()

    :param node: the rclpy node that owns the publishers (it need not spin).
    :param path: ROS 2 bag directory, ``.mcap``/``.db3`` file, or ROS 1 ``.bag`` file.
    :param rate: playback speed factor (> 0; 2.0 plays twice as fast).
    :param clock_hz: ``/clock`` publication rate (Hz, wall time); 0 for no clock.
    :param depth: keep-last depth of the publishers (>= 2); each waits for acknowledgements
        after ``depth // 2`` messages.
    :raises RosError: a missing or unreadable bag, an empty one, no topic rclpy knows, or a
        bad rate or depth.
    """

    def __init__(self, node: Node, path: os.PathLike, rate: float = 1.0,
                 clock_hz: float = 200.0, depth: int = DEFAULT_DEPTH) -> None:
        if not rate > 0.0 or rate == float('inf'):
            raise RosError(f'rate must be a finite number > 0, got {rate}')
        if not clock_hz >= 0.0:
            raise RosError(f'clock rate must be >= 0 Hz, got {clock_hz}')
        if depth < 2:
            raise RosError(f'depth must be at least 2 messages, got {depth}')
        self.node = node
        self.path = Path(path)
        self.rate = float(rate)
        self.clock_period = 1.0 / clock_hz if clock_hz > 0.0 else 0.0
        self.window = depth // 2
        self.result = ReplayResult()
        self._bag = self._open()
        self._publishers: Dict[str, Any] = {}
        self._message_count = 0
        try:
            self._setup(depth)
        except BaseException:
            self.close()
            raise
        self._clock = node.create_publisher(Clock, CLOCK_TOPIC, _reliable(10)) \
            if self.clock_period else None

    def _open(self) -> RawBag:
        """
        Open the bag.

        :raises RosError: missing, not a bag, unreadable or empty.
        """
        bag = RawBag(self.path)
        try:
            bag.open()
        except BagError as error:
            raise RosError(str(error)) from error
        return bag

    def _setup(self, depth: int) -> None:
        """
        Create a publisher per topic whose one type rclpy can import.

        :raises RosError: no topic can be published.
        """
        skipped = list(self._bag.skipped)
        for topic, info in self._bag.topics.items():
            try:
                cls = message_class(info.msgtype)
            except RosError:
                skipped.append(topic)
                continue
            self._publishers[topic] = self.node.create_publisher(cls, topic, _reliable(depth))
            self._message_count += info.message_count
        self.result.skipped_topics = sorted(skipped)
        if not self._publishers:
            raise RosError(f'bag {self.path} has no topic of a type rclpy knows')

    @property
    def message_count(self) -> int:
        """Return the number of messages one pass publishes."""
        return self._message_count

    @property
    def topics(self) -> List[str]:
        """Return the topics this player publishes."""
        return sorted(self._publishers)

    def wait_for_subscribers(self, topics: Sequence[str], timeout_s: float,
                             stop: Optional[threading.Event] = None) -> None:
        """
        Wait until each topic has at least one matched subscription.

        :param topics: topics of the bag, or ``/clock``.
        :param timeout_s: how long to wait (s).
        :param stop: set it to give up early (raises as a timeout).
        :raises RosError: a topic the bag does not publish, or the timeout passed.
        """
        publishers = dict(self._publishers)
        if self._clock is not None:
            publishers[CLOCK_TOPIC] = self._clock
        missing = [topic for topic in topics if topic not in publishers]
        if missing:
            raise RosError(
                f"cannot wait for {', '.join(missing)}: not published from this bag "
                f"(topics: {', '.join(sorted(publishers))})")
        deadline = time.monotonic() + timeout_s
        while True:
            waiting = [t for t in topics if publishers[t].get_subscription_count() < 1]
            if not waiting:
                return
            if time.monotonic() >= deadline or (stop is not None and stop.is_set()):
                raise RosError(
                    f"no subscriber on {', '.join(waiting)} after {timeout_s:.1f} s")
            time.sleep(0.02)

    def _publish_clock(self, stamp_ns: int) -> None:
        if self._clock is not None:
            message = Clock()
            message.clock.sec, message.clock.nanosec = divmod(int(stamp_ns), 1_000_000_000)
            self._clock.publish(message)

    def play(self, loop: bool = False, stop: Optional[threading.Event] = None,
             ack_timeout_s: float = ACK_TIMEOUT_S) -> ReplayResult:
        """
        Publish the bag (again and again with ``loop``) until done or ``stop`` is set.

        :param loop: restart at the end (the clock jumps back to the bag start).
        :param stop: an event that ends the playback when set.
        :param ack_timeout_s: how long to wait for reliable subscribers to acknowledge what
            was published, every ``depth // 2`` messages of a topic and at the end (s).
        :returns: the counts (also kept in :attr:`result`; ``seconds`` is set however the
            playback ends, Ctrl-C included).
        :raises RosError: the bag turns out corrupt while reading.
        """
        started = time.monotonic()
        try:
            return self._play(loop, stop, ack_timeout_s, started)
        finally:
            self.result.seconds = time.monotonic() - started

    def _play(self, loop: bool, stop: Optional[threading.Event], ack_timeout_s: float,
              started: float) -> ReplayResult:
        """Publish the bag (see ``play``)."""
        begin, end = self._bag.start_time_ns, self._bag.end_time_ns  # /clock stays inside
        publishers = self._publishers
        period = self.clock_period
        scale = 1e-9 / self.rate
        result = self.result
        unacked = dict.fromkeys(publishers, 0)
        window = self.window
        try:
            while not (stop is not None and stop.is_set()):
                result.in_loop = 0
                wall0 = time.monotonic()
                next_clock = wall0 + period
                self._publish_clock(begin)
                for topic, _, log_time, data in self._bag.messages(list(publishers)):
                    due = wall0 + (log_time - begin) * scale
                    while True:
                        now = time.monotonic()
                        if period and now >= next_clock:
                            self._publish_clock(min(begin + int((now - wall0) * self.rate
                                                                * 1e9), end))
                            next_clock = max(next_clock + period, now)
                        if now >= due:
                            break
                        wait = min(due, next_clock) - now if period else due - now
                        if stop is not None:
                            if stop.wait(max(wait, 0.0)):
                                return self._finish(started, ack_timeout_s)
                        else:
                            time.sleep(max(wait, 0.0))
                    if now - due > result.late_s:
                        result.late_s = now - due
                    publishers[topic].publish(data)
                    result.messages += 1
                    result.in_loop += 1
                    unacked[topic] += 1
                    if unacked[topic] >= window:  # its queue must not overwrite unreceived ones
                        unacked[topic] = 0
                        wall0 += self._await_acks(ack_timeout_s, [publishers[topic]])
                        next_clock = time.monotonic() + period
                result.loops += 1
                result.in_loop = 0
                if not loop:
                    break
        except BagError as error:
            raise RosError(str(error)) from error
        except RosError:
            raise
        except Exception as error:  # publishing failed: one line, like every replay error
            text = str(error).strip() or type(error).__name__
            raise RosError(f'replay of {self.path} failed: {text.splitlines()[0]}') from error
        return self._finish(started, ack_timeout_s)

    def _await_acks(self, ack_timeout_s: float, publishers: Sequence[Any]) -> float:
        """
        Wait until the reliable subscribers acknowledged what ``publishers`` sent.

        Counts the wait and a timeout; returns the wall time it took (s).
        """
        started = time.monotonic()
        deadline = started + ack_timeout_s
        pending = list(publishers)  # each waits, whatever the others did
        while pending:
            left = min(ACK_SLICE_S, deadline - time.monotonic())
            timeout = Duration(nanoseconds=int(max(left, 0.0) * 1e9))
            pending = [publisher for publisher in pending
                       if not publisher.wait_for_all_acked(timeout)]
            if left <= 0.0:
                break
        if pending:
            self.result.ack_timeouts += 1
        waited = time.monotonic() - started
        self.result.ack_waits += 1
        self.result.ack_wait_s += waited
        return waited

    def _finish(self, started: float, ack_timeout_s: float) -> ReplayResult:
        """Wait for acknowledgements, note lossy subscribers; record the wall time."""
        self._await_acks(ack_timeout_s, list(self._publishers.values()))
        keep_last, best_effort = set(), set()
        for topic in self._publishers:
            for info in self.node.get_subscriptions_info_by_topic(topic):
                profile = info.qos_profile
                if profile.reliability == ReliabilityPolicy.BEST_EFFORT:
                    best_effort.add(topic)
                elif profile.history == HistoryPolicy.KEEP_LAST:
                    keep_last.add((topic, int(profile.depth)))
        self.result.keep_last_subscribers = sorted(keep_last)
        self.result.best_effort_subscribers = sorted(best_effort)
        self.result.seconds = time.monotonic() - started
        return self.result

    def close(self) -> None:
        """Close the bag and destroy the publishers (idempotent)."""
        for publisher in list(self._publishers.values()):
            self.node.destroy_publisher(publisher)
        self._publishers.clear()
        clock, self._clock = getattr(self, '_clock', None), None
        if clock is not None:
            self.node.destroy_publisher(clock)
        bag, self._bag = getattr(self, '_bag', None), None
        if bag is not None:
            bag.close()

    def __enter__(self) -> 'BagPlayer':
        """Return the player."""
        return self

    def __exit__(self, exc_type: Any, exc_value: Any, traceback: Any) -> None:
        """Close the player."""
        self.close()


def replay_summary(result: ReplayResult, per_pass: int, loop: bool) -> str:
    """
    Return the line a replay ends with: messages, wall time, passes, what was skipped or lost.

    :param per_pass: messages in one pass over the bag.
    """
    line = f'published {result.messages:,} messages in {result.seconds:.1f} s'
    if loop or result.in_loop:
        line += f' ({result.loops} complete loops of {per_pass:,} messages'
        line += f', then {result.in_loop:,} more)' if result.in_loop else ')'
    if result.skipped_topics:
        line += f"; skipped {', '.join(result.skipped_topics)} (type not available)"
    if result.ack_timeouts:
        line += ('; WARNING: a reliable subscriber did not acknowledge every message in time: '
                 'it may have lost messages (play slower with --rate)')
    if result.late_s > LATE_WARN_S:
        line += (f'; WARNING: publishing fell up to {result.late_s:.2f} s behind the schedule '
                 '(this machine could not keep the rate)')
    if result.keep_last_subscribers:
        line += ('; note: reliable keep-last subscriber(s) on ' + ', '.join(
            f'{topic} (depth {depth})' for topic, depth in result.keep_last_subscribers)
            + ' lose what they fall more than their depth behind (keep-all subscribers get '
            'every message; impact_node: qos:=reliable_all)')
    if result.best_effort_subscribers:
        line += ('; note: best-effort subscriber(s) on '
                 f"{', '.join(result.best_effort_subscribers)} may drop messages under load")
    return line


def run_replay(bag: os.PathLike, rate: float = 1.0, loop: bool = False,
               clock_hz: float = 200.0, wait_for: Sequence[str] = (),
               wait_timeout_s: float = 30.0, out: Optional[IO[str]] = None) -> int:
    """
    Replay a bag from a node of its own (``baseball-collision replay``); Ctrl-C stops it.

    Prints what is replayed, then the counts (and the topics skipped).

    :param bag: ROS 2 bag directory, ``.mcap``/``.db3`` file, or ROS 1 ``.bag`` file.
    :param rate: playback speed factor (> 0).
    :param loop: restart at the end, until Ctrl-C.
    :param clock_hz: ``/clock`` rate (Hz); 0 for no clock.
    :param wait_for: topics (of the bag, or ``/clock``) to wait for a subscriber on first.
    :param wait_timeout_s: how long to wait for them (s).
    :param out: where to print; None for standard output.
    :returns: the exit code, 0.
    :raises RosError: see :class:`BagPlayer` and :meth:`BagPlayer.wait_for_subscribers`.
    """
    out = sys.stdout if out is None else out
    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node('baseball_collision_replay', context=context)
    try:
        with BagPlayer(node, bag, rate=rate, clock_hz=clock_hz) as player:
            out.write(f"replaying {bag} at {rate:g}x: {', '.join(player.topics)}"
                      + (f' and /clock at {clock_hz:g} Hz' if clock_hz else '')
                      + (' (looping; Ctrl-C stops)' if loop else '') + '\n')
            out.flush()
            if wait_for:
                player.wait_for_subscribers(wait_for, wait_timeout_s)
            try:
                result = player.play(loop=loop)
            except KeyboardInterrupt:
                result = player.result
                out.write('stopped\n')
            out.write(replay_summary(result, player.message_count, loop) + '\n')
            out.flush()
    finally:
        node.destroy_node()
        rclpy.try_shutdown(context=context)
    return 0
