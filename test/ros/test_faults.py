"""
Fault tests of the live impact_node: publishers that die, silence, clock loops, frames, QoS.

Real rclpy on an isolated context (discovery off), with ``test_node``'s ``Harness``: the node
under test and a probe node spun by one executor thread. What ``test_node`` already covers is
not repeated (a single wrong-frame sample, topics going stale, one clock jump resetting, the
incompatible-QoS counter); these tests add the recovery after each fault, and the warnings as
they reach ``/rosout``. Every expectation is on header stamps.
"""

import time
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence

from geometry_msgs.msg import PointStamped, PoseStamped
import pytest
from rcl_interfaces.msg import Log
import rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock as ClockMsg
from std_msgs.msg import Bool
from std_srvs.srv import Trigger
from support.harness import (
    Harness, point_msg, pose_msg, RATE_HZ, RELIABLE, SAMPLES, stamp, stamp_ns, values)
from support.scenes import BASE_NS, first_contact, pitch, pose

pytestmark = pytest.mark.ros

LOG_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                     reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
SECOND = 10**9
BEFORE_CONTACT = 10  # samples 0-9 (25 ms) come before the first contact (~33 ms)


@pytest.fixture
def harness(monkeypatch: pytest.MonkeyPatch) -> Iterator[Callable[..., Harness]]:
    """Make harnesses whose probe also records /rosout; tear them all down after the test."""
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'OFF')
    made: List[Harness] = []

    def make(overrides: Optional[Dict[str, Any]] = None) -> Harness:
        h = Harness(overrides)
        h.received['log'] = []
        h.probe.create_subscription(Log, '/rosout', h._collector('log'), LOG_QOS)
        made.append(h)
        return h
    yield make
    for each in made:
        each.close()


@pytest.fixture(scope='module')
def truth_ns() -> int:
    """Return the exact first contact of the hitting pitch as an absolute stamp (ns)."""
    t = first_contact(pitch())
    assert t is not None and t > (BEFORE_CONTACT - 1) / RATE_HZ
    return BASE_NS + int(round(t * 1e9))


def publish(ball: Any, bat: Any, samples: Sequence[int], shift_ns: int = 0,
            frame: str = 'world', bat_frame: Optional[str] = None) -> int:
    """
    Publish the hitting swing's ball and bat pose samples, stamps shifted; return the count.

    Both in ``frame``, or the bat in ``bat_frame`` when given.
    """
    for i in samples:
        t = i / RATE_HZ
        ns = BASE_NS + int(round(t * 1e9)) + shift_ns
        ball.publish(point_msg(ns, pitch()(t), frame))
        position, quaternion = pose(t)
        bat.publish(pose_msg(ns, position, quaternion, bat_frame or frame))
    return 2 * len(samples)


def tracker(h: Harness, name: str = 'tracker') -> Node:
    """Create a tracker node with ball and bat pose publishers; wait until both matched."""
    node = rclpy.create_node(name, context=h.context)
    node.ball = node.create_publisher(PointStamped, 'ball', RELIABLE)
    node.bat = node.create_publisher(PoseStamped, 'bat_pose', RELIABLE)
    h.wait(lambda: node.ball.get_subscription_count() > 0
           and node.bat.get_subscription_count() > 0, 5.0, f'{name} matched')
    return node


def impacts(h: Harness) -> List[int]:
    """Return the stamps (ns) of the ~/impact messages received so far."""
    return [stamp_ns(message) for message in h.received['impact']]


def warnings(h: Harness, *words: str) -> List[str]:
    """Return the node's WARN lines on /rosout that contain every word."""
    return [log.msg for log in h.received['log'] if log.level == Log.WARN
            and log.name == 'impact_node' and all(word in log.msg for word in words)]


def test_publisher_dies_mid_swing_and_a_new_one_finishes_it(harness: Callable[..., Harness],
                                                            truth_ns: int) -> None:
    """
    A tracker node destroyed before the contact, a new one (same name) sends the rest.

    While it is gone the diagnostics say the inputs are stale with no publisher discovered.
    The node keeps the samples it had: the swing finished by the new publisher gives its
    impact at the true instant, and the next swing, a second later, gives the next one.
    """
    h = harness({'bat_input': 'pose', 'diagnostics_period': 0.1, 'stale_timeout': 0.3})
    h.start()
    first = tracker(h)
    h.processed(publish(first.ball, first.bat, range(BEFORE_CONTACT)))
    first.destroy_node()
    h.wait(lambda: h.node.count_publishers('/ball') == 0, 5.0, 'the publisher gone')
    gone = h.diagnostics_where(
        lambda v: v['stale_topics'].count('no publisher discovered yet') == 2)
    assert gone.level == gone.WARN and not h.received['impact']
    second = tracker(h)
    sent = 2 * BEFORE_CONTACT + publish(second.ball, second.bat, range(BEFORE_CONTACT, SAMPLES))
    h.processed(sent)
    h.wait(lambda: len(h.received['impact']) == 1, 2.0, 'the impact of the finished swing')
    assert abs(impacts(h)[0] - truth_ns) < 100_000
    h.processed(sent + publish(second.ball, second.bat, range(SAMPLES), SECOND))
    h.received['diagnostics'].clear()  # only statuses from after the last arrival count
    h.wait(lambda: len(h.received['impact']) == 2, 2.0, 'the impact of the next swing')
    assert abs(impacts(h)[1] - truth_ns - SECOND) < 100_000
    # a status after every message was taken (the second impact comes before the swing's end)
    status = h.diagnostics_where(lambda v: v['impacts'] == '2' and int(
        v['ball_received']) + int(v['bat_pose_received']) == 4 * SAMPLES)
    counts = {kv.key: kv.value for kv in status.values}
    assert counts['dropped_total'] == '0' and counts['ball_received'] == str(2 * SAMPLES)
    second.destroy_node()


def test_silent_topics_go_stale_then_back_to_tracking(harness: Callable[..., Harness],
                                                      truth_ns: int) -> None:
    """Both inputs silent past stale_timeout: 'stale' (WARN); when they resume: 'tracking'."""
    h = harness({'bat_input': 'pose', 'stale_timeout': 0.3, 'diagnostics_period': 0.1})
    ball = h.publisher(PointStamped, 'ball')
    bat = h.publisher(PoseStamped, 'bat_pose')
    h.start()
    h.processed(publish(ball, bat, range(BEFORE_CONTACT)))
    h.diagnostics_where(lambda v: v['state'] == 'tracking')
    stale = h.diagnostics_where(lambda v: v['state'] == 'stale')
    assert '/ball' in stale.message and '/bat_pose' in stale.message
    assert stale.level == stale.WARN
    h.received['diagnostics'].clear()
    h.processed(2 * BEFORE_CONTACT + publish(ball, bat, range(BEFORE_CONTACT, SAMPLES)))
    back = h.diagnostics_where(lambda v: v['state'] == 'tracking' and v['impacts'] == '1')
    assert back.level == back.OK and {kv.key: kv.value for kv in back.values}[
        'stale_topics'] == ''
    h.wait(lambda: h.received['impact'], 2.0, 'the impact after the silence')
    assert len(impacts(h)) == 1 and abs(impacts(h)[0] - truth_ns) < 100_000


def test_clock_loop_resets_with_one_warning_and_finds_the_replayed_hit(
        harness: Callable[..., Harness], truth_ns: int) -> None:
    """
    A bag played in a loop: /clock jumps back, the state is reset with a warning.

    The replayed swing (the same stamps again) gives the same impact again, and the stamps'
    own jump back makes no second warning.
    """
    h = harness({'bat_input': 'pose', 'use_sim_time': True, 'time_jump_reset': 0.5})
    ball = h.publisher(PointStamped, 'ball')
    bat = h.publisher(PoseStamped, 'bat_pose')
    clock = h.publisher(ClockMsg, '/clock')
    h.start()
    sent = 0
    for loop in range(2):
        for i in range(0, SAMPLES, 12):  # the clock runs with the messages, as a player's does
            clock.publish(ClockMsg(clock=stamp(BASE_NS + int(i / RATE_HZ * 1e9))))
            sent += publish(ball, bat, range(i, min(i + 12, SAMPLES)))
        clock.publish(ClockMsg(clock=stamp(BASE_NS + SECOND)))  # the bag's last second
        h.processed(sent)
        h.wait(lambda: len(h.received['impact']) == loop + 1, 2.0, f'impact of loop {loop}')
        assert h.node.detector.stats.resets == loop
        clock.publish(ClockMsg(clock=stamp(BASE_NS)))  # the loop restarts
        h.wait(lambda: h.node.detector.stats.resets == loop + 1, 3.0, 'the clock jump reset')
    assert impacts(h) == [impacts(h)[0]] * 2 and abs(impacts(h)[0] - truth_ns) < 100_000
    h.wait(lambda: len(warnings(h, 'clock jumped back')) == 2, 2.0, 'the warnings')
    assert not warnings(h, 'header stamps jumped back')  # no second warning for the same jump
    assert h.node.detector.stats.dropped == {}


def test_frame_change_is_dropped_until_a_reset_adopts_the_new_frame(
        harness: Callable[..., Harness], truth_ns: int) -> None:
    """
    With frame_id '' the first frame is kept; ~/reset lets the node adopt the next one.

    A switch to another frame mid-swing drops every sample (wrong_frame, counted, warned once
    per period) and makes no impact; after ~/reset the swing in the new frame is found and
    published in that frame.
    """
    h = harness({'bat_input': 'pose', 'diagnostics_period': 0.1})
    ball = h.publisher(PointStamped, 'ball')
    bat = h.publisher(PoseStamped, 'bat_pose')
    h.start()
    sent = publish(ball, bat, range(BEFORE_CONTACT))
    sent += publish(ball, bat, range(BEFORE_CONTACT, SAMPLES), frame='camera')
    h.processed(sent)
    dropped = 2 * (SAMPLES - BEFORE_CONTACT)
    status = h.diagnostics_where(lambda v: v['dropped_wrong_frame'] == str(dropped))
    counts = {kv.key: kv.value for kv in status.values}
    assert counts['frame_id'] == 'world' and counts['dropped_total'] == str(dropped)
    assert not h.received['impact'] and h.node.detector.stats.impacts == 0
    h.wait(lambda: warnings(h, 'wrong_frame', "'camera'", "'world'"), 2.0, 'the warning')
    assert len(warnings(h, 'wrong_frame')) <= 2  # rate limited, not one per sample
    assert h.call(Trigger, '/impact_node/reset', Trigger.Request()).success
    assert h.node.detector.frame_id is None
    h.processed(sent + publish(ball, bat, range(SAMPLES), SECOND, frame='camera'))
    h.wait(lambda: h.received['impact'], 2.0, 'the impact in the new frame')
    impact = h.received['impact'][0]
    assert impact.header.frame_id == 'camera'
    assert abs(stamp_ns(impact) - truth_ns - SECOND) < 100_000
    h.diagnostics_where(lambda v: v['frame_id'] == 'camera' and v['impacts'] == '1'
                        and v['dropped_total'] == str(dropped))


def test_a_bat_and_a_ball_in_two_frames_adopt_neither(harness: Callable[..., Harness],
                                                      truth_ns: int) -> None:
    """
    frame_id '': a bat pose in 'arm_base' beside a ball in 'world' (no TF): no frame adopted.

    The node warns once, naming each stream's frame and saying what to do; /diagnostics counts
    the bat's samples that waited as ``no_common_frame``, and the ball is never dropped (the
    bat's frame, the most common, was adopted after 32 samples and every ball sample dropped
    as ``wrong_frame``). Once the bat comes in 'world' too, the next swing's impact is found.
    """
    h = harness({'bat_input': 'pose', 'diagnostics_period': 0.1})
    ball = h.publisher(PointStamped, 'ball')
    bat = h.publisher(PoseStamped, 'bat_pose')
    h.start()
    sent = publish(ball, bat, range(SAMPLES), bat_frame='arm_base')
    h.processed(sent)
    waited = SAMPLES - 32  # the 32 newest still wait
    status = h.diagnostics_where(lambda v: v['dropped_no_common_frame'] == str(waited))
    counts = values(status)
    assert counts['dropped_wrong_frame'] == '0' and counts['dropped_total'] == str(waited)
    h.wait(lambda: warnings(h, 'no frame every input sends'), 2.0, 'the warning')
    (line,) = warnings(h, 'no frame every input sends')
    assert "ball sends 'world', bat_pose sends 'arm_base': set frame_id or transform one" in line
    assert 'ball on /ball, bat_pose on /bat_pose' in line
    assert not warnings(h, 'dropped a') and not h.received['impact']
    h.processed(sent + publish(ball, bat, range(SAMPLES), SECOND))
    h.wait(lambda: h.received['impact'], 2.0, 'the impact once the frames agree')
    assert abs(impacts(h)[0] - truth_ns - SECOND) < 100_000
    assert h.received['impact'][0].header.frame_id == 'world'
    assert len(warnings(h, 'no frame every input sends')) == 1
    # (the 32 bat samples that waited then dropped as wrong_frame, unless the bat's came first)
    h.diagnostics_where(lambda v: v['frame_id'] == 'world' and v['impacts'] == '1'
                        and v['dropped_no_common_frame'] == str(waited))


def test_configured_frame_survives_a_reset(harness: Callable[..., Harness]) -> None:
    """With frame_id 'world' set, samples in 'camera' stay dropped after ~/reset too."""
    h = harness({'bat_input': 'pose', 'frame_id': 'world'})
    ball = h.publisher(PointStamped, 'ball')
    bat = h.publisher(PoseStamped, 'bat_pose')
    h.start()
    sent = publish(ball, bat, range(5), frame='camera')
    h.processed(sent)
    assert h.call(Trigger, '/impact_node/reset', Trigger.Request()).success
    h.processed(sent + publish(ball, bat, range(SAMPLES), frame='camera'))
    time.sleep(0.1)
    assert h.node.detector.frame_id == 'world'
    assert h.node.detector.stats.dropped == {'wrong_frame': 2 * (5 + SAMPLES)}
    assert not h.received['impact']


def test_qos_mismatches_are_warned_naming_the_topic(harness: Callable[..., Harness]) -> None:
    """
    Mismatched QoS on an input and on an output: warnings naming the topic, counted.

    A best-effort publisher on the reliable ball input, and a transient-local subscriber on
    ~/impact (published volatile).
    """
    h = harness({'qos': 'reliable'})
    h.probe.create_publisher(PointStamped, 'ball', QoSProfile(
        depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    h.probe.create_subscription(PointStamped, '/impact_node/impact', lambda m: None, QoSProfile(
        depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL))
    h.start()
    h.wait(lambda: warnings(h, 'incompatible QoS on /ball', 'RELIABILITY', 'subscription'),
           3.0, 'the warning about /ball')
    h.wait(lambda: warnings(h, 'incompatible QoS on /impact_node/impact', 'DURABILITY',
                            'publisher'), 3.0, 'the warning about ~/impact')
    h.diagnostics_where(lambda v: int(v['incompatible_qos_events']) >= 2)


def test_an_arm_that_would_lose_the_latched_flag_is_named(harness: Callable[..., Harness]) -> None:
    """
    Subscribers of ~/impact_predicted whose QoS matches but loses its state get a warning each.

    The flag is sent once per change: a best-effort arm gets no value on joining and may lose
    a change for good, a volatile one gets none until the next change. ROS matches both
    without a word. The README's QoS (reliable, transient local, depth 1) is not named, nor a
    subscriber of another output; each lossy one is named once, with the QoS to use.
    """
    h = harness()
    arms = {}
    for name, reliability, durability in (
            ('arm_best_effort', ReliabilityPolicy.BEST_EFFORT, DurabilityPolicy.TRANSIENT_LOCAL),
            ('arm_volatile', ReliabilityPolicy.RELIABLE, DurabilityPolicy.VOLATILE),
            ('arm_as_readme_says', ReliabilityPolicy.RELIABLE, DurabilityPolicy.TRANSIENT_LOCAL)):
        arms[name] = rclpy.create_node(name, context=h.context)
        arms[name].create_subscription(
            Bool, '/impact_node/impact_predicted', lambda m: None,
            QoSProfile(depth=1, reliability=reliability, durability=durability))
    arms['arm_best_effort'].create_subscription(  # best effort on a volatile output: fine
        PointStamped, '/impact_node/predicted_impact', lambda m: None,
        QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    h.start()
    try:
        h.wait(lambda: len(warnings(h, 'loses the latched state')) >= 3, 3.0, 'the warnings')
        time.sleep(0.5)  # (several diagnostics periods: no repeat)
        named = {line.split()[1]: line for line in warnings(h, 'loses the latched state')}
        assert sorted(named) == ['/arm_best_effort', '/arm_volatile', '/probe']  # (volatile)
        assert len(warnings(h, 'loses the latched state')) == 3
        assert 'best effort' in named['/arm_best_effort']
        assert 'volatile' not in named['/arm_best_effort']
        assert 'volatile' in named['/arm_volatile'] and 'best effort' not in named['/arm_volatile']
        for line in named.values():
            assert 'on /impact_node/impact_predicted' in line
            assert line.endswith('subscribe reliable and transient local, depth 1')
    finally:
        for node in arms.values():
            node.destroy_node()


def test_a_failing_check_of_a_new_subscriber_is_logged_and_the_node_goes_on(
        harness: Callable[..., Harness], truth_ns: int) -> None:
    """
    The subscriber check at a match is an executor callback: its failure (a bug) is survived.

    The graph query raising at the flag's match makes the node's ERROR (``internal_errors``),
    not the end of its spin: the swing after it is still found.
    """
    h = harness({'bat_input': 'pose'})
    ball = h.publisher(PointStamped, 'ball')
    bat = h.publisher(PoseStamped, 'bat_pose')

    def broken(topic: str) -> List[Any]:
        raise RuntimeError('the graph is broken')
    h.node.get_subscriptions_info_by_topic = broken  # (the timer's check fails too: guarded)
    h.start()
    arm = rclpy.create_node('arm_after_start', context=h.context)
    try:
        arm.create_subscription(Bool, '/impact_node/impact_predicted', lambda m: None,
                                QoSProfile(depth=1))
        h.wait(lambda: h.node.tally.failures >= 1, 3.0, 'the failure counted')
        h.processed(publish(ball, bat, range(SAMPLES)))
        h.wait(lambda: h.received['impact'], 3.0, 'the impact after the failure')
        assert abs(impacts(h)[0] - truth_ns) < 100_000
    finally:
        arm.destroy_node()


def _settled(h: Harness, sent: int) -> Dict[str, str]:
    """Wait until the node's arrivals stop changing, then return a later status's values."""
    arrived, still = -1, 0
    while still < 10:  # 0.5 s without a new message
        time.sleep(0.05)
        now = sum(h.node.tally.arrivals.values())
        arrived, still = now, still + 1 if now == arrived else 0
    assert 0 < arrived <= sent
    count = len(h.received['diagnostics'])
    h.wait(lambda: len(h.received['diagnostics']) > count + 1, 3.0, 'a status after that')
    return values(h.received['diagnostics'][-1].status[0])


def test_every_lost_message_is_reported_across_a_pause_and_a_stale_publisher(
        harness: Callable[..., Harness]) -> None:
    """
    Issue 12.7: messages lost across a 1.5 s pause and a stale publisher's: all reported.

    The node stalls (queues of 20) while its trackers publish on, across the pause, and a
    stale second ball publisher (3 s behind) loses messages too. ``<stream>_lost`` (from the
    publishers' sequence numbers, rmw_fastrtps_cpp) is exactly the messages sent and not
    received, per stream; the stamps alone could not see the losses that span the pause nor
    the stale publisher's.

    (It was load-sensitive while the stamps alone told the publishers apart: under load the
    queue could hand over the stale publisher's message numbered n and then the good one's
    n + 1 after the pause, and both tracks explained it by a pause. The send times settle it:
    ``PublisherGaps``.)
    """
    h = harness({'qos_depth': 20}).start()
    node = tracker(h)
    stale = node.create_publisher(PointStamped, 'ball', RELIABLE)
    h.wait(lambda: stale.get_subscription_count() > 0, 5.0, 'the stale publisher matched')
    sent = {'ball': 0, 'bat_pose': 0}

    def frames(samples: range, shift_ns: int = 0) -> None:
        for i in samples:
            t, ns = (i % SAMPLES) / RATE_HZ, BASE_NS + int(round(i / RATE_HZ * 1e9)) + shift_ns
            node.ball.publish(point_msg(ns, pitch(2.0)(t)))
            node.bat.publish(pose_msg(ns, *pose(t)))
            stale.publish(point_msg(ns - 3 * SECOND, pitch(2.0)(t)))
            sent['ball'] += 2
            sent['bat_pose'] += 1
    frames(range(1))
    h.processed(3)  # each publisher's first message arrives (no count can see losses before it)
    frames(range(1, 30))  # queues of 20: a burst of 29 frames may lose some already
    h.processed(20)
    with h.node._lock:  # the node stalls in a callback: each queue keeps its newest 20
        frames(range(30, 130))
        time.sleep(1.5)  # a pause (stamps too) in the middle of the losses
        frames(range(130, 230), 3 * SECOND // 2)
        time.sleep(0.5)
    frames(range(230, 260), 3 * SECOND // 2)
    status = _settled(h, sum(sent.values()))
    lost = {stream: sent[stream] - int(status[f'{stream}_received']) for stream in sent}
    assert lost['ball'] > 200 and lost['bat_pose'] > 100, (lost, status)
    assert {stream: int(status[f'{stream}_lost']) for stream in sent} == lost, status
    node.destroy_node()


def test_no_loss_is_reported_for_glitches_a_pause_a_jump_back_or_a_stale_publisher(
        harness: Callable[..., Harness]) -> None:
    """Nothing lost (reliable, deep queues): a glitch, a 2 s pause, a jump back, 3 s behind."""
    h = harness().start()
    node = tracker(h)
    stale = node.create_publisher(PointStamped, 'ball', RELIABLE)
    h.wait(lambda: stale.get_subscription_count() > 0, 5.0, 'the stale publisher matched')
    sent = 0
    for i in range(SAMPLES):  # and a stale second ball publisher
        sent += publish(node.ball, node.bat, [i])
        t = i / RATE_HZ
        stale.publish(point_msg(BASE_NS + int(round(t * 1e9)) - 3 * SECOND, pitch()(t)))
        sent += 1
    node.ball.publish(point_msg(BASE_NS + 7 * SECOND // 10, pitch()(0.0)))  # a glitch
    time.sleep(2.0)  # a pause, stamps and all (1.3 s after the glitch)
    sent += 1 + publish(node.ball, node.bat, range(SAMPLES), 2 * SECOND)
    sent += publish(node.ball, node.bat, range(SAMPLES), -10 * SECOND)  # a jump back
    status = _settled(h, sent)
    assert sum(h.node.tally.arrivals.values()) == sent
    assert (status['ball_lost'], status['bat_pose_lost']) == ('0', '0'), status
    node.destroy_node()
