"""
Tests for baseball_collision.ros.state_changes: ~/reset, the clock's jumps, runtime parameters.

In-process, over real rclpy topics and services (``conftest``'s harness, discovery off).
"""

from typing import Callable

import pytest
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock as ClockMsg
from std_srvs.srv import Trigger
from support.harness import Harness, RELIABLE, SAMPLES, stamp, stamp_ns
from support.node_inputs import publish_swing, swing_harness
from support.scenes import pitch

pytestmark = pytest.mark.ros


def test_reset_service_clears_the_state(harness: Callable[..., Harness], truth_ns: int) -> None:
    """~/reset answers success and clears the buffers; the swing after it is still found."""
    h = swing_harness(harness, 'pose')
    response = h.call(Trigger, '/impact_node/reset', Trigger.Request())
    assert response.success and response.message.startswith(
        'detector state cleared before any sample (')  # (not 'at 0.000000000 s')
    h.processed(publish_swing(h, 'pose', pitch(), samples=range(10)))  # 28 ms: before contact
    assert h.node.detector.watermark_ns is not None
    response = h.call(Trigger, '/impact_node/reset', Trigger.Request())
    assert response.success and response.message.startswith('detector state cleared at 17')
    assert h.node.detector.watermark_ns is None and h.node.detector.stats.resets == 2
    h.processed(publish_swing(h, 'pose', pitch(), samples=range(10, SAMPLES)) + 20)
    h.wait(lambda: h.received['impact'], 2.0, 'the impact after the reset')
    assert abs(stamp_ns(h.received['impact'][0]) - truth_ns) < 100_000
    h.diagnostics_where(lambda v: v['resets'] == '2')


def test_ros_clock_jump_back_resets_with_a_warning(harness: Callable[..., Harness]) -> None:
    """use_sim_time: /clock jumping back beyond time_jump_reset resets the detector."""
    h = swing_harness(harness, 'pose', {'use_sim_time': True, 'time_jump_reset': 0.5})
    clock = h.probe.create_publisher(ClockMsg, '/clock', RELIABLE)
    h.wait(lambda: clock.get_subscription_count() > 0, 5.0, '/clock matched')
    clock.publish(ClockMsg(clock=stamp(100 * 10**9)))
    h.wait(lambda: h.node.get_clock().now().nanoseconds == 100 * 10**9, 3.0, 'sim time')
    h.processed(publish_swing(h, 'pose', pitch(2.0), samples=range(10)))
    clock.publish(ClockMsg(clock=stamp(99_800_000_000)))  # 0.2 s back: below the threshold
    clock.publish(ClockMsg(clock=stamp(50 * 10**9)))
    h.wait(lambda: h.node.detector.stats.resets == 1, 3.0, 'the reset')
    assert h.node.detector.watermark_ns is None


def test_runtime_parameters(harness: Callable[..., Harness]) -> None:
    """Thresholds change at runtime (ints too); topics and the model are refused with a reason."""
    h = harness().start()
    ok = h.set_parameters(near_miss_threshold=0.3)[0]
    assert ok.successful, ok.reason
    assert h.node.detector.config.near_miss_threshold == 0.3
    ok = h.set_parameters(max_gap=1)[0]  # an integer for a double
    assert ok.successful, ok.reason
    assert h.node.detector.config.max_gap == 1.0
    assert h.node.get_parameter('max_gap').type_ == Parameter.Type.DOUBLE
    for name, value, words in (('ball_topic', 'other', ('read-only', 'ball_topic', 'restart')),
                               ('model', 'spline', ('read-only', 'model')),
                               ('bat_profile', [0.0, 0.02, 0.8, 0.03], ('read-only',)),
                               ('near_miss_threshold', -1.0, ('near_miss_threshold',)),
                               ('up_axis', [0.0, 0.0, 0.0], ('up_axis',)),
                               ('stale_timeout', 'soon', ('type',))):
        refused = h.set_parameters(**{name: value})[0]
        assert not refused.successful, name
        for word in words:
            assert word in refused.reason, (name, refused.reason)
    assert h.node.get_parameter('ball_topic').value == 'ball'
    assert h.node.detector.config.model == 'c2'
    assert h.node.detector.config.near_miss_threshold == 0.3
    ok = h.set_parameters(tracker_noise=0.001)[0]  # auto -> told (and back): the estimates go on
    assert ok.successful and h.node.detector.config.tracker_noise == 0.001
    assert h.set_parameters(tracker_noise=-1.0)[0].successful


def test_auto_noise_from_a_told_start_is_refused(harness: Callable[..., Harness]) -> None:
    """A node started with a told noise refuses auto at runtime, saying to restart."""
    h = harness({'tracker_noise': 0.0}).start()
    refused = h.set_parameters(tracker_noise=-1.0)[0]
    assert not refused.successful
    assert 'tracker_noise' in refused.reason and 'restart' in refused.reason
    assert h.node.get_parameter('tracker_noise').value == 0.0
    assert h.node.detector.config.tracker_noise == 0.0
    assert h.set_parameters(tracker_noise=0.002)[0].successful
