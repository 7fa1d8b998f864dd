"""
Tests for baseball_collision.ros.bat_plan: the bat plans the node takes, refuses and drops.

In-process, over real rclpy topics and services (``conftest``'s harness, discovery off).
"""

import json
from typing import Any, Callable, Dict, List, Sequence

from baseball_collision.core.prediction import MAX_PLAN_POSES
from nav_msgs.msg import Path as PathMsg
import pytest
from rcl_interfaces.msg import Log as LogMsg
from rosgraph_msgs.msg import Clock as ClockMsg
from std_srvs.srv import Trigger
from support.harness import Harness, pose_msg, RATE_HZ, RELIABLE, stamp, stamp_ns
from support.node_inputs import listen_to_rosout, make_plan_harness, publish_swing
from support.scenes import BASE_NS, pitch, pose

pytestmark = pytest.mark.ros


def test_bat_plan_topic_makes_early_exact_predictions(harness: Callable[..., Harness],
                                                      truth_ns: int) -> None:
    """
    A commanded swing on bat_plan_topic: predictions 40 ms ahead within 0.5 ms, with sigmas.

    Each prediction's ``~/impact_report`` record is planned and carries its 1-sigma error bars
    (``time_uncertainty_s``, ``distance_from_tip_uncertainty_m``: the scene's exact samples,
    so micro- and millimetres).
    """
    h = make_plan_harness(harness)
    plan = PathMsg()
    plan.header.frame_id = 'world'
    for i in range(0, 200, 5):  # every 5 ms over the swing
        position, quaternion = pose(i * 1e-3)
        plan.poses.append(pose_msg(BASE_NS + i * 1_000_000, position, quaternion))
    h.publishers['bat_plan'].publish(plan)
    h.wait(lambda: h.node.detector._predictor.plan is not None, 3.0, 'the plan taken')
    early = range(int((truth_ns - BASE_NS) * 1e-9 * RATE_HZ) - 14)  # up to ~40 ms before
    h.processed(publish_swing(h, 'pose', pitch(), samples=early))
    h.wait(lambda: h.received['predicted'], 3.0, 'a prediction')
    for message in h.received['predicted']:
        assert abs(stamp_ns(message) - truth_ns) < 500_000

    def records() -> List[Dict[str, Any]]:
        return [r for r in map(json.loads, (m.data for m in h.received['report']))
                if r['event'] == 'prediction']
    h.wait(records, 3.0, "a prediction's record")
    for record in records():
        assert record['planned'] and 0.0 < record['time_uncertainty_s'] < 1e-3
        assert 0.0 < record['distance_from_tip_uncertainty_m'] < 0.01


def test_a_plan_the_predictions_cannot_use_is_warned_about(
        harness: Callable[..., Harness], truth_ns: int) -> None:
    """
    A plan stamped 5 s before the trackers' clock: the predictions extrapolate, and a WARN says so.

    The detector takes a plan only where its poses reach past a prediction's start
    (``Prediction.planned``); it was ignored without a word.
    """
    h = make_plan_harness(harness)
    listen_to_rosout(h)
    plan = PathMsg()
    plan.header.frame_id = 'world'
    plan.poses = [pose_msg(BASE_NS - 5 * 10**9 + i * 1_000_000, *pose(i * 1e-3))
                  for i in range(0, 200, 5)]
    h.publishers['bat_plan'].publish(plan)
    h.wait(lambda: h.node.detector._predictor.plan is not None, 3.0, 'the plan taken')
    early = range(int((truth_ns - BASE_NS) * 1e-9 * RATE_HZ) - 3)
    h.processed(publish_swing(h, 'pose', pitch(), samples=early))
    h.wait(lambda: h.received['predicted'], 3.0, 'a prediction')

    def warned() -> List[LogMsg]:
        return [record for record in h.received['rosout'] if record.level == LogMsg.WARN
                and record.msg.startswith('the bat plan on /bat_plan (')]
    h.wait(warned, 5.0, "the unused plan's WARN")
    assert 'was not used: the prediction made at ' in warned()[0].msg


def test_a_plan_in_a_frame_before_any_tracking_frame_is_refused(
        harness: Callable[..., Harness]) -> None:
    """
    frame_id '': a plan naming a frame before any sample is refused with a WARN, not used.

    Its frame cannot be checked yet (it was taken, and used in whatever frame the trackers then
    sent); with ``frame_id`` set, the same plan in that frame is taken at once.
    """
    plan = PathMsg()
    plan.header.frame_id = 'base_link'
    plan.poses = [pose_msg(BASE_NS + i * 1_000_000, *pose(i * 1e-3), frame='base_link')
                  for i in range(5)]
    h = harness({'bat_input': 'pose', 'bat_plan_topic': 'bat_plan'})
    h.publisher(PathMsg, 'bat_plan')
    listen_to_rosout(h.start())
    h.publishers['bat_plan'].publish(plan)

    def warned() -> List[LogMsg]:
        return [record for record in h.received['rosout'] if record.level == LogMsg.WARN
                and record.msg.startswith('ignored a bat plan on /bat_plan: ')]
    h.wait(warned, 5.0, "the plan's WARN")
    assert "frame ['base_link']" in warned()[0].msg
    assert 'no tracking frame is known yet' in warned()[0].msg
    assert h.node.detector._predictor.plan is None
    configured = harness({'bat_input': 'pose', 'bat_plan_topic': 'bat_plan',
                          'frame_id': 'base_link'})
    configured.publisher(PathMsg, 'bat_plan')
    configured.start().publishers['bat_plan'].publish(plan)
    configured.wait(lambda: configured.node.detector._predictor.plan is not None, 5.0,
                    'the plan taken in the configured frame')


def test_a_plan_too_large_is_refused_before_any_work(harness: Callable[..., Harness]) -> None:
    """Issue 12.6 live: a plan over MAX_PLAN_POSES never reaches the detector; later ones do."""
    h = make_plan_harness(harness)
    detector = h.node.detector
    taken: List[int] = []
    set_plan = detector.set_bat_plan

    def spy(stamps: Sequence[int], *rest: Any) -> None:
        taken.append(len(stamps))
        set_plan(stamps, *rest)
    detector.set_bat_plan = spy
    huge = PathMsg()
    huge.poses = [pose_msg(BASE_NS + i * 1000, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0))
                  for i in range(MAX_PLAN_POSES + 1)]
    h.publishers['bat_plan'].publish(huge)
    small = PathMsg()
    small.poses = [pose_msg(BASE_NS + i * 1_000_000, *pose(i * 1e-3)) for i in range(5)]
    h.publishers['bat_plan'].publish(small)  # delivered after the huge one (reliable)
    h.wait(lambda: detector._predictor.plan is not None, 5.0, 'the small plan')
    assert taken == [5] and len(detector._predictor.plan[1].times) == 5


def test_a_state_reset_says_it_dropped_the_bat_plan(harness: Callable[..., Harness]) -> None:
    """
    ~/reset and a clock jump drop the bat plan with the state, and say so: the topic is volatile.

    ~/reset's reply names the plan when one was in force (not on a reset without one); the
    clock jump's reset says it in one INFO line.
    """
    h = harness({'bat_input': 'pose', 'bat_plan_topic': 'bat_plan', 'frame_id': 'world',
                 'use_sim_time': True, 'time_jump_reset': 0.5})
    h.publisher(PathMsg, 'bat_plan')
    listen_to_rosout(h.start())
    plan = PathMsg()
    plan.header.frame_id = 'world'
    plan.poses = [pose_msg(BASE_NS + i * 1_000_000, *pose(i * 1e-3)) for i in range(5)]
    predictor = h.node.detector._predictor
    h.publishers['bat_plan'].publish(plan)
    h.wait(lambda: predictor.plan is not None, 5.0, 'the plan taken')
    reply = h.call(Trigger, '/impact_node/reset', Trigger.Request()).message
    assert h.node.detector._predictor.plan is None
    assert 'the bat plan in force was dropped: send it again on /bat_plan' in reply
    assert 'dropped' not in h.call(Trigger, '/impact_node/reset', Trigger.Request()).message
    predictor = h.node.detector._predictor
    h.publishers['bat_plan'].publish(plan)
    h.wait(lambda: predictor.plan is not None, 5.0, 'the plan taken again')
    clock = h.probe.create_publisher(ClockMsg, '/clock', RELIABLE)
    h.wait(lambda: clock.get_subscription_count() > 0, 5.0, '/clock matched')
    clock.publish(ClockMsg(clock=stamp(100 * 10**9)))
    h.wait(lambda: h.node.get_clock().now().nanoseconds == 100 * 10**9, 3.0, 'sim time')
    clock.publish(ClockMsg(clock=stamp(50 * 10**9)))
    h.wait(lambda: any(
        record.level == LogMsg.INFO and record.msg.startswith(
            'state reset (time_jump_backwards): the bat plan in force was dropped: send it '
            'again on /bat_plan') for record in h.received['rosout']), 5.0, 'the INFO line')
    assert h.node.detector._predictor.plan is None
