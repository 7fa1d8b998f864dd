"""
Tests for baseball_collision.ros.node: the impact_node over real rclpy topics and services.

In-process tests run the node and a probe node in one fresh ``rclpy.Context`` with discovery
off (``ROS_AUTOMATIC_DISCOVERY_RANGE=OFF``); the process tests start ``.venv/bin/impact_node``
on this run's random domain with discovery limited to the host (``conftest``). Messages are
published reliably after the subscriptions matched, and every expectation is on header stamps,
so no result depends on arrival timing. What ``ImpactNode``'s mixin bases decide is tested beside
this file, a module each: ``test_outputs``, ``test_prediction_flag``, ``test_bat_plan`` and
``test_state_changes``.
"""

import gc
import math
import os
from pathlib import Path
import re
import subprocess
import sys
import threading
import time
from typing import Any, Callable, Dict, List, Sequence, Tuple

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.detector import DROP_REASONS, PARAMETERS
from baseball_collision.core.detector import sweep_impact as impact_module
from baseball_collision.errors import RosError
from baseball_collision.ros import bat_plan as bat_plan_module
from baseball_collision.ros import node as node_module
from baseball_collision.ros.inputs import Throttle
from baseball_collision.ros.node import freeze_start_up, ImpactNode
from baseball_collision.tools.demo import stop_node
from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import PointStamped, PoseStamped
from nav_msgs.msg import Path as PathMsg
import numpy as np
import pytest
from rcl_interfaces.msg import Log as LogMsg
from rcl_interfaces.srv import GetParameters
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter, parameter_value_to_python
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock as ClockMsg
from std_srvs.srv import Trigger
from support import REPO_ROOT
from support.harness import (
    Harness, point_msg, pose_msg, RATE_HZ, RELIABLE, sample_ns, SAMPLES, stamp, stamp_ns, values)
from support.node_inputs import (
    listen_to_rosout, make_plan_harness, publish_swing, swing_harness)
from support.scenes import BASE_NS, first_contact, pitch, pose, swing
import yaml

pytestmark = pytest.mark.ros

SCRIPT = Path(sys.executable).parent / 'impact_node'
CONFIG = REPO_ROOT / 'config' / 'impact_node.yaml'
POINTS_CONFIG = REPO_ROOT / 'config' / 'impact_node_points.yaml'
LAUNCH_FILE = REPO_ROOT / 'launch' / 'impact_node.launch.py'


def pose_angular_velocity(t: float, h: float = 1e-6) -> np.ndarray:
    """Return the angular velocity (rad/s, world) of ``pose(t)``: the swing and its roll."""
    def rotation(q: np.ndarray) -> np.ndarray:
        x, y, z, w = q
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    derivative = (rotation(pose(t + h)[1]) - rotation(pose(t - h)[1])) / (2 * h)
    skew = derivative @ rotation(pose(t)[1]).T
    return np.array([skew[2, 1], skew[0, 2], skew[1, 0]])


def expected_bat_velocity(point: Sequence[float], t: float,
                          bat_input: str) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return the analytic bat surface velocity (m/s) at a point and angular velocity at t.

    The pose's minimal rotation from +z rolls the bat about its own axis as it swings; knob
    and tip points carry no roll.
    """
    knob, _ = swing(t)
    omega = pose_angular_velocity(t) if bat_input == 'pose' \
        else np.array([0.0, 0.0, 30.0 + 200.0 * t])
    return np.array([0.0, 2.0, 0.0]) + np.cross(omega, np.asarray(point) - knob), omega


# ----------------------------------------------------------------------------------------------
# impacts and near misses


@pytest.mark.parametrize('bat_input', ['pose', 'points'])
def test_swing_gives_one_impact_at_the_true_instant(harness: Callable[..., Harness],
                                                    bat_input: str, truth_ns: int) -> None:
    """A 360 Hz swing: one ~/impact stamped within 100 us of the truth, a matching velocity."""
    h = swing_harness(harness, bat_input)
    sent = publish_swing(h, bat_input, pitch())
    h.processed(sent)
    h.wait(lambda: h.received['impact'] and h.received['velocity'], 2.0, 'the impact')
    time.sleep(0.1)
    assert len(h.received['impact']) == 1 and len(h.received['velocity']) == 1
    assert not h.received['near_miss']
    impact, velocity = h.received['impact'][0], h.received['velocity'][0]
    assert abs(stamp_ns(impact) - truth_ns) < 100_000
    assert impact.header.frame_id == 'world'
    assert velocity.header == impact.header
    # the contact point is on the barrel, touching the ball at that instant
    t = (stamp_ns(impact) - BASE_NS) * 1e-9
    point = np.array([impact.point.x, impact.point.y, impact.point.z])
    assert np.linalg.norm(point - pitch()(t)) == pytest.approx(0.0366, abs=2e-3)
    linear, omega = expected_bat_velocity(point, t, bat_input)
    twist = velocity.twist
    assert [twist.linear.x, twist.linear.y, twist.linear.z] == pytest.approx(
        linear, rel=0.02, abs=0.1)
    assert [twist.angular.x, twist.angular.y, twist.angular.z] == pytest.approx(
        omega, abs=0.5)
    # markers: the bat, ball, contact and normal at the impact instant
    h.wait(lambda: any(m.markers and m.markers[0].ns == 'impact_bat'
                       for m in h.received['markers']), 2.0, 'impact markers')
    array = next(m for m in h.received['markers'] if m.markers[0].ns == 'impact_bat')
    namespaces = {m.ns for m in array.markers}
    assert {'impact_bat', 'impact_ball', 'impact_contact', 'impact_normal'} <= namespaces
    assert all(stamp_ns(m) == stamp_ns(impact) for m in array.markers)
    bat = [m for m in array.markers if m.ns == 'impact_bat']
    assert len(bat) == len(WOOD_BAT_34.segments())
    assert max(m.scale.x for m in bat) == pytest.approx(2 * WOOD_BAT_34.max_radius)
    # the diagnostics count it
    h.diagnostics_where(lambda v: v['impacts'] == '1' and v['dropped_total'] == '0')


def test_near_miss_publishes_a_gap_and_no_impact(harness: Callable[..., Harness]) -> None:
    """The bat passing 2 cm under the ball: one ~/near_miss with an upward gap, no impact."""
    ball = pitch(height=1.09)
    assert first_contact(ball) is None
    h = swing_harness(harness, 'pose')
    h.processed(publish_swing(h, 'pose', ball))
    h.wait(lambda: h.received['near_miss'], 2.0, 'the near miss')
    time.sleep(0.1)
    assert len(h.received['near_miss']) == 1 and not h.received['impact']
    miss = h.received['near_miss'][0]
    gap = 0.09 - 0.0366 - WOOD_BAT_34.max_radius
    assert miss.vector.z == pytest.approx(gap, abs=1e-3)
    assert math.hypot(miss.vector.x, miss.vector.y) < 2e-3
    assert miss.header.frame_id == 'world'
    assert abs((stamp_ns(miss) - BASE_NS) * 1e-9 - first_contact(pitch())) < 3e-3
    h.diagnostics_where(lambda v: v['near_misses'] == '1' and v['impacts'] == '0')


# ----------------------------------------------------------------------------------------------
# bad input and diagnostics


def test_bad_messages_are_dropped_counted_and_never_hit(harness: Callable[..., Harness],
                                                        truth_ns: int) -> None:
    """NaN, wrong frame, out of order and a zero quaternion: counted, the hit is unchanged."""
    h = swing_harness(harness, 'pose', {'stale_timeout': 0.5})
    ball, bat = h.publishers['ball'], h.publishers['bat_pose']
    at = pitch()

    def bad(i: int) -> int:
        ns = sample_ns(i)
        if i == 10:  # 1 ms behind the newest ball sample
            ball.publish(point_msg(ns - 1_000_000, at(i / RATE_HZ)))
        elif i == 20:  # a zero quaternion
            bat.publish(pose_msg(ns + 1_000_000, pose(i / RATE_HZ)[0], (0.0, 0.0, 0.0, 0.0)))
        elif i == 30:
            ball.publish(point_msg(ns + 1_000_000, (math.nan, 0.0, 1.0)))
        elif i == 40:  # a ball in another frame, on the bat's path before the real contact
            knob, tip = swing((truth_ns - BASE_NS) * 1e-9)
            ball.publish(point_msg(ns + 1_000_000, 0.5 * (knob + tip), frame='camera'))
        else:
            return 0
        return 1
    h.processed(publish_swing(h, 'pose', at, extra=bad))
    h.wait(lambda: h.received['impact'], 2.0, 'the impact')
    time.sleep(0.1)
    assert len(h.received['impact']) == 1 and not h.received['near_miss']
    assert abs(stamp_ns(h.received['impact'][0]) - truth_ns) < 100_000
    # a status after every message was taken (an earlier one may have all four drops already)
    status = h.diagnostics_where(lambda v: v['dropped_total'] == '4' and int(
        v['ball_received']) + int(v['bat_pose_received']) == 2 * SAMPLES + 4)
    counts = values(status)
    for reason in DROP_REASONS:
        expected = 1 if reason in (
            'out_of_order', 'bad_quaternion', 'non_finite', 'wrong_frame') else 0
        assert counts[f'dropped_{reason}'] == str(expected), reason
    assert counts['ball_received'] == str(SAMPLES + 3)
    assert counts['bat_pose_received'] == str(SAMPLES + 1)
    assert counts['impacts'] == '1' and counts['near_misses'] == '0'
    assert float(counts['processing_max_ms']) >= float(counts['processing_mean_ms']) >= 0.0
    warned = [a.status[0] for a in h.received['diagnostics']
              if values(a.status[0])['dropped_in_period'] != '0']
    assert warned and all(s.level >= DiagnosticStatus.WARN for s in warned)
    assert any('dropped' in s.message for s in warned)
    # then the topics go silent: stale, WARN, naming them
    stale = h.diagnostics_where(lambda v: v['state'] == 'stale', timeout=3.0)
    assert stale.level == DiagnosticStatus.WARN
    assert '/ball' in stale.message and '/bat_pose' in stale.message


def test_a_tip_lost_as_nan_at_90_hz_is_one_drop(harness: Callable[..., Harness],
                                                truth_ns: int) -> None:
    """
    Knob and tip at 90 Hz, the tip NaN the frame before the contact: one drop, the hit found.

    Its knob is not paired with a tip on the chord across the lost frame (11 cm short of the
    bat: a second drop, ``bat_length_jump``, warned about on the next tip's message before).
    """
    h = swing_harness(harness, 'points', {'stale_timeout': 0.5})
    ball, knob_out, tip_out = (h.publishers[name] for name in ('ball', 'bat_knob', 'bat_tip'))
    rate, at = 90.0, pitch()
    lost = round((truth_ns - BASE_NS) * 1e-9 * rate) - 1
    frames = 18
    for i in range(frames):
        t, ns = i / rate, BASE_NS + int(round(i / rate * 1e9))
        knob, tip = swing(t)
        ball.publish(point_msg(ns, at(t)))
        knob_out.publish(point_msg(ns, knob))
        tip_out.publish(point_msg(ns, (math.nan, 0.0, 0.0) if i == lost else tip))
    h.processed(3 * frames)
    h.wait(lambda: h.received['impact'], 2.0, 'the impact')
    assert abs(stamp_ns(h.received['impact'][0]) - truth_ns) < 1_000_000
    counts = values(h.diagnostics_where(
        lambda v: int(v['ball_received']) + int(v['knob_received']) + int(v['tip_received'])
        == 3 * frames))
    assert counts['dropped_total'] == '1' and counts['dropped_non_finite'] == '1'
    assert counts['dropped_bat_length_jump'] == '0'
    assert counts['impacts'] == '1'


def test_waiting_then_tracking_with_rates(harness: Callable[..., Harness]) -> None:
    """Before data: 'waiting for data' (OK); with data: 'tracking', rates and live markers."""
    h = swing_harness(harness, 'points')
    waiting = h.diagnostics_where(lambda v: v['state'] == 'waiting for data')
    assert waiting.level == DiagnosticStatus.OK and '/ball' in waiting.message
    for key in ('ball_rate_hz', 'knob_rate_hz', 'tip_rate_hz', 'processing_mean_ms'):
        assert key in values(waiting)
    h.processed(publish_swing(h, 'points', pitch(2.0), samples=range(20)))
    tracking = h.diagnostics_where(
        lambda v: v['state'] == 'tracking' and v['ball_received'] == '20')
    assert tracking.level == DiagnosticStatus.OK
    assert values(tracking)['frame_id'] == 'world'
    noise = (values(tracking)[key] for key in ('tracker_noise', 'ball_noise_mm', 'bat_noise_mm'))
    assert tuple(noise) == ('auto', '0.000', '0.000')  # exact samples, estimated as such
    # the live bat (one cylinder per profile segment) and ball, in the tracking frame
    h.wait(lambda: any({'live_bat', 'live_ball'} <= {m.ns for m in array.markers}
                       for array in h.received['markers']), 2.0, 'live markers')
    live = next(a for a in h.received['markers']
                if {'live_bat', 'live_ball'} <= {m.ns for m in a.markers})
    assert all(m.header.frame_id == 'world' for m in live.markers)
    assert sum(m.ns == 'live_bat' for m in live.markers) == len(WOOD_BAT_34.segments())


def test_incompatible_qos_is_reported(harness: Callable[..., Harness]) -> None:
    """A best-effort publisher on a topic the node reads reliably: counted and in diagnostics."""
    h = harness({'qos': 'reliable'})
    h.probe.create_publisher(PointStamped, 'ball', QoSProfile(
        depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    h.start()
    h.wait(lambda: h.node.tally.incompatible > 0, 3.0, 'the incompatible QoS event')
    status = h.diagnostics_where(lambda v: v['incompatible_qos_events'] != '0')
    assert status.level >= DiagnosticStatus.WARN and 'incompatible' in status.message


def test_a_silent_inputs_incompatible_qos_stays_named_in_diagnostics(
        harness: Callable[..., Harness]) -> None:
    """
    The stale /ball names its best-effort publisher's QoS in every status, not only the first.

    The period that caught the QoS event says 'incompatible QoS or type on a topic'; the ones
    after it said only '/ball (no data since start)'.
    """
    h = harness({'qos': 'reliable', 'stale_timeout': 0.3})
    h.probe.create_publisher(PointStamped, 'ball', QoSProfile(
        depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    h.start()
    h.wait(lambda: h.node.tally.incompatible > 0, 3.0, 'the incompatible QoS event')

    def later_stale() -> List[DiagnosticStatus]:
        return [status for array in h.received['diagnostics'] for status in array.status
                if values(status)['state'] == 'stale' and 'on a topic' not in status.message]
    h.wait(lambda: len(later_stale()) >= 2, 5.0, 'two stale statuses after the event')
    for status in later_stale():
        assert ('/ball (no data since start, incompatible QoS: Best effort publisher and '
                'reliable subscription)') in status.message, status.message


# ----------------------------------------------------------------------------------------------
# failures the node survives, a bad value


def test_a_detector_failure_resets_the_state_logs_an_error_and_the_node_goes_on(
        harness: Callable[..., Harness], truth_ns: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    The detector raising while it takes a sample (a bug) neither stops the node nor is hidden.

    The velocities of the first hit fail: its state is reset (a reset /diagnostics counts), an
    ERROR line with the traceback reaches /rosout, and the same swing a second later is found.
    """
    failures: List[int] = []
    fit = impact_module.c2_velocities

    def fails_once(*args: Any) -> Any:
        if not failures:
            failures.append(1)
            raise ZeroDivisionError('a fit divided by zero')
        return fit(*args)

    monkeypatch.setattr(impact_module, 'c2_velocities', fails_once)
    h = swing_harness(harness, 'pose')
    listen_to_rosout(h)
    sent = publish_swing(h, 'pose', pitch())
    h.processed(sent)

    def errors() -> List[LogMsg]:
        return [record for record in h.received['rosout'] if record.name == 'impact_node'
                and record.level == LogMsg.ERROR and 'the detector failed' in record.msg]
    h.wait(lambda: errors(), 5.0, "the failure's ERROR line on /rosout")
    record, = errors()
    assert 'ZeroDivisionError: a fit divided by zero' in record.msg
    assert 'Traceback' in record.msg and 'fails_once' in record.msg
    assert failures and h.node.detector.stats.resets == 1 and not h.received['velocity']
    h.processed(sent + publish_swing(h, 'pose', pitch(), later_ns=10**9))
    h.wait(lambda: h.received['velocity'], 5.0, 'the impact of the swing a second later')
    assert abs(stamp_ns(h.received['velocity'][0]) - 10**9 - truth_ns) < 100_000
    h.diagnostics_where(lambda v: v['resets'] == '1')


def test_every_callback_survives_its_own_failure_counted_in_diagnostics(
        harness: Callable[..., Harness], truth_ns: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A bug raising in any executor callback (not the detector's call) is an ERROR, not the end.

    In turn: an input message (before the detector), the bat plan, ``~/reset`` (which answers
    ``success: false``), the clock's jump back and the diagnostics timer each raise once; each
    logs its ERROR, ``/diagnostics`` counts five ``internal_errors`` at ERROR level, and the
    swing after them all is found.
    """
    h = harness({'bat_input': 'pose', 'use_sim_time': True, 'time_jump_reset': 0.5,
                 'bat_plan_topic': 'bat_plan'})
    for msg_type, topic in ((PointStamped, 'ball'), (PoseStamped, 'bat_pose'),
                            (PathMsg, 'bat_plan')):
        h.publisher(msg_type, topic)
    h.start()
    node = h.node
    node._log_throttle = Throttle(0.0)  # every failure's line, not one per 2 s
    listen_to_rosout(h)

    def errors(what: str) -> List[LogMsg]:
        return [record for record in h.received['rosout'] if record.level == LogMsg.ERROR
                and record.msg.startswith(what)]

    def once(owner: Any, name: str, error: Exception) -> None:
        original = getattr(owner, name)

        def fails(*args: Any, **kwargs: Any) -> Any:
            monkeypatch.setattr(owner, name, original)
            raise error
        monkeypatch.setattr(owner, name, fails)

    once(node.tally, 'stamped', KeyError('a stream never seen'))
    h.processed(publish_swing(h, 'pose', pitch(2.0), samples=range(1)))
    h.wait(lambda: errors('taking a message on the ball input failed'), 5.0, "the input's ERROR")
    first, = errors('taking a message on the ball input failed')
    assert "KeyError: 'a stream never seen'" in first.msg and 'Traceback' in first.msg

    once(bat_plan_module, 'plan_arrays', IndexError('a pose out of range'))
    plan = PathMsg()
    plan.poses = [pose_msg(BASE_NS + i * 1_000_000, *pose(i * 1e-3)) for i in range(5)]
    h.publishers['bat_plan'].publish(plan)
    h.wait(lambda: errors('taking a bat plan failed'), 5.0, "the plan's ERROR")
    assert 'IndexError: a pose out of range' in errors('taking a bat plan failed')[0].msg
    assert 'Traceback' not in errors('taking a bat plan failed')[0].msg  # the first's only
    h.publishers['bat_plan'].publish(plan)
    h.wait(lambda: node.detector._predictor.plan is not None, 5.0, 'the next plan taken')

    once(node, '_reset', RuntimeError('a lock lost'))
    refused = h.call(Trigger, '/impact_node/reset', Trigger.Request())
    assert not refused.success and 'RuntimeError: a lock lost' in refused.message
    assert errors('the reset requested on ~/reset failed')
    assert h.call(Trigger, '/impact_node/reset', Trigger.Request()).success

    clock = h.probe.create_publisher(ClockMsg, '/clock', RELIABLE)
    h.wait(lambda: clock.get_subscription_count() > 0, 5.0, '/clock matched')
    clock.publish(ClockMsg(clock=stamp(100 * 10**9)))
    h.wait(lambda: node.get_clock().now().nanoseconds == 100 * 10**9, 3.0, 'sim time')
    once(node, '_reset', ZeroDivisionError('a jump of zero'))
    clock.publish(ClockMsg(clock=stamp(50 * 10**9)))
    h.wait(lambda: errors("handling the clock's jump failed"), 5.0, "the jump's ERROR")

    once(node_module, 'report', TypeError('a key without a value'))
    h.wait(lambda: errors('publishing /diagnostics failed'), 5.0, "the diagnostics' ERROR")
    status = h.diagnostics_where(lambda v: v['internal_errors'] == '5')
    assert status.level == DiagnosticStatus.ERROR and '1 internal error(s)' in status.message

    h.received['impact'].clear()
    h.processed(publish_swing(h, 'pose', pitch(), later_ns=10**9), timeout=10.0)
    h.wait(lambda: h.received['impact'], 5.0, 'the impact after the failures')
    assert abs(stamp_ns(h.received['impact'][0]) - 10**9 - truth_ns) < 100_000
    assert node.tally.failures == 5


def test_bad_value_in_process_raises_node_config_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """The constructor refuses a bad value with RosError naming it."""
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'OFF')
    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        with pytest.raises(RosError, match='bat_axis'):
            ImpactNode(context=context, parameter_overrides=[Parameter('bat_axis', value='w')])
        node = ImpactNode(context=context, parameter_overrides=[
            Parameter('max_gap', value=1), Parameter('up_axis', value=[0, 2, 0])])
        assert node.detector.config.max_gap == 1.0 and node.detector.config.up_axis == (0, 1, 0)
        node.destroy_node()
        # rcl's expansion refuses an unknown substitution with a ValueError: the node ended
        # with its traceback (analyze --params refuses the file too: test/tools)
        for name, topic in (('ball_topic', '{foo}/ball'), ('bat_plan_topic', '{foo}/plan')):
            refusal = f'{topic!r}: topic name {topic!r} is invalid: unknown substitution: {{foo}}'
            with pytest.raises(RosError, match=re.escape(refusal)):
                ImpactNode(context=context, parameter_overrides=[Parameter(name, value=topic)])
    finally:
        rclpy.shutdown(context=context)


# ----------------------------------------------------------------------------------------------
# parameter files


def test_points_params_file_loads(harness: Callable[..., Harness]) -> None:
    """The knob + tip example file loads through --params-file and builds its bat profile."""
    h = harness(args=['--params-file', str(POINTS_CONFIG)])
    node = h.node
    assert node.get_parameter('qos').value == 'reliable'  # the file wins over the harness
    config = node.detector.config
    assert config.bat_input == 'points' and config.frame_id == 'mocap'
    assert config.profile.length == pytest.approx(0.8382)
    assert node.endpoints.topics == {'ball': '/mocap/ball', 'knob': '/mocap/bat_knob',
                                     'tip': '/mocap/bat_tip'}


def test_params_files_and_the_launch_remappings_apply_under_a_namespace(
        harness: Callable[..., Harness]) -> None:
    """
    The node under /cage2 (launch ``namespace:=cage2``) takes both shipped files (``/**``).

    The remappings of the launch file's own example map its inputs there; a file named for
    ``impact_node:`` alone, or ``/ball:=...``, matched only a node in the root namespace.
    """
    example = re.search(r'remappings:=(\S+)', LAUNCH_FILE.read_text()).group(1)
    remappings = [word for pair in example.split(',') for word in ('-r', pair)]
    h = harness(args=['-r', '__ns:=/cage2', '--params-file', str(CONFIG)] + remappings)
    assert h.node.get_fully_qualified_name() == '/cage2/impact_node'
    assert h.node.endpoints.topics == {'ball': '/mocap/ball', 'bat_pose': '/mocap/bat'}
    points = harness(args=['-r', '__ns:=/cage2', '--params-file', str(POINTS_CONFIG)]).node
    assert points.detector.config.bat_input == 'points'
    assert points.detector.config.frame_id == 'mocap'
    assert points.endpoints.topics == {'ball': '/cage2/mocap/ball',
                                       'knob': '/cage2/mocap/bat_knob',
                                       'tip': '/cage2/mocap/bat_tip'}


def _env() -> Dict[str, str]:
    """Return the environment for a node process: this run's domain, host-only discovery."""
    env = dict(os.environ)
    env.pop('RMW_IMPLEMENTATION', None)
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONUNBUFFERED'] = '1'
    return env


def test_console_script_loads_the_params_files_and_stops_on_ctrl_c() -> None:
    """
    .venv/bin/impact_node with both example files: parameters as loaded; SIGINT exits 0.

    The points file comes second and wins where both set a value; ``-p`` wins over both. A
    PoseStamped publisher on the PointStamped ball topic gets a warning naming both types.
    """
    assert SCRIPT.exists(), SCRIPT
    process = subprocess.Popen(
        [str(SCRIPT), '--ros-args', '--params-file', str(CONFIG), '--params-file',
         str(POINTS_CONFIG), '-p', 'max_gap:=1', '-p', 'diagnostics_period:=0.2'],
        env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines: List[str] = []
    reader = threading.Thread(target=lambda: lines.extend(process.stderr), daemon=True)
    reader.start()
    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node('param_probe', context=context)
    executor = SingleThreadedExecutor(context=context)
    names = [spec.name for spec in PARAMETERS]
    try:
        client = node.create_client(GetParameters, '/impact_node/get_parameters')
        assert client.wait_for_service(timeout_sec=20.0), 'the node did not come up'
        future = client.call_async(GetParameters.Request(names=names))
        rclpy.spin_until_future_complete(node, future, executor=executor, timeout_sec=10.0)
        got = {name: parameter_value_to_python(value)
               for name, value in zip(names, future.result().values)}
        node.create_publisher(PoseStamped, '/mocap/ball', 10)
        deadline = time.monotonic() + 10.0
        while not any('another type' in line for line in lines):
            assert time.monotonic() < deadline, 'no warning about the PoseStamped publisher'
            time.sleep(0.05)
    finally:
        executor.shutdown(timeout_sec=2.0)
        node.destroy_node()
        rclpy.shutdown(context=context)
        stop_node(process)
        reader.join(timeout=5)
    defaults = yaml.safe_load(CONFIG.read_text())['/**']['ros__parameters']
    points = yaml.safe_load(POINTS_CONFIG.read_text())['/**']['ros__parameters']
    expected = dict(defaults, **points, max_gap=1.0, diagnostics_period=0.2)
    assert set(got) == set(expected)
    for name, value in expected.items():
        assert got[name] == pytest.approx(value), name
    assert isinstance(got['max_gap'], float)
    err = ''.join(lines)
    assert process.returncode == 0, err
    assert 'Traceback' not in err
    assert 'listening: ball PointStamped on /mocap/ball, bat knob and tip' in err
    warning = next(line for line in lines if 'another type' in line)
    assert 'geometry_msgs/msg/PoseStamped' in warning and 'ball_type' in warning


@pytest.mark.parametrize('line, word', [('max_gap: -1', 'max_gap'), ('model: cubic', 'model'),
                                        ('bat_profile: [0.1, 0.02, 0.3]', 'bat_profile')])
def test_bad_params_file_value_exits_with_one_line(tmp_path: Path, line: str, word: str) -> None:
    """``python -m baseball_collision.ros.node`` with a bad value: exit 1, one clear error line."""
    params = tmp_path / 'bad.yaml'
    params.write_text(f'/**:\n  ros__parameters:\n    {line}\n')
    completed = subprocess.run(
        [sys.executable, '-m', 'baseball_collision.ros.node', '--ros-args', '--params-file',
         str(params)], env=_env(), capture_output=True, text=True, timeout=30)
    assert completed.returncode == 1
    lines = (completed.stdout + completed.stderr).strip().splitlines()
    assert len(lines) == 1, lines
    assert 'ERROR' in lines[0] and word in lines[0] and 'not starting' in lines[0]


def _main_patched(patch: str) -> subprocess.CompletedProcess:
    """
    Run the node's ``main`` in a fresh interpreter after ``patch``, capturing its output.

    :param patch: code run first, with ``rclpy``, ``rclpy.executors`` and the node module
        imported (as ``node``).
    """
    driver = ('import sys, rclpy, rclpy.executors\n'
              'from baseball_collision.ros import node\n'
              f"{patch}sys.exit(node.main(['impact_node']))\n")
    return subprocess.run([sys.executable, '-c', driver], env=_env(), capture_output=True,
                          text=True, timeout=60)


@pytest.mark.parametrize('shut_down', [True, False])
def test_an_error_from_rclpys_handles_after_ctrl_c_is_the_shutdown(shut_down: bool) -> None:
    """
    Ctrl-C that shuts the context down under the executor mid-wait exits 0 without a traceback.

    rclpy's wait set can then meet a destroyed handle (``'NoneType' object has no attribute
    'handle'``): once in a loaded suite the node exited 1 with it after a SIGINT right after
    start-up. The same error with the context still up is the node's own: raised, exit 1.
    """
    completed = _main_patched(
        'def spin(_node, _executor=None):\n'
        f'    if {shut_down}:\n'
        '        rclpy.try_shutdown()\n'
        "    raise AttributeError(\"'NoneType' object has no attribute 'handle'\")\n"
        'node.rclpy.spin = spin\n')
    output = completed.stdout + completed.stderr
    if shut_down:
        assert completed.returncode == 0 and 'Traceback' not in output, output
    else:
        assert completed.returncode == 1 and 'AttributeError' in output, output


def test_ctrl_c_while_the_executor_is_made_exits_0_without_a_traceback() -> None:
    """
    A SIGINT in the executor's construction: exit 0, and nothing printed by its collection.

    rclpy's ``Executor.__del__`` read an attribute ``__init__`` had not set yet: under load a
    node stopped right after start-up printed ``Exception ignored in ... __del__`` with a
    traceback (``'SingleThreadedExecutor' object has no attribute '_sigint_gc'``).
    """
    completed = _main_patched(
        'def interrupted(*args, **kwargs):\n'
        '    raise KeyboardInterrupt\n'
        'rclpy.executors.SignalHandlerGuardCondition = interrupted\n')
    output = completed.stdout + completed.stderr
    assert completed.returncode == 0, output
    assert 'Traceback' not in output and 'Exception ignored' not in output, output


def test_a_params_file_for_another_node_is_warned_about_at_start_up(tmp_path: Path) -> None:
    """The console script given a file whose only section is another node's: a WARN, runs."""
    params = tmp_path / 'other.yaml'
    params.write_text('my_node:\n  ros__parameters:\n    model: linear\n')
    process = subprocess.Popen(
        [sys.executable, '-m', 'baseball_collision.ros.node', '--ros-args', '--params-file',
         str(params)], env=_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines: List[str] = []
    reader = threading.Thread(target=lambda: lines.extend(process.stdout), daemon=True)
    reader.start()
    try:
        deadline = time.monotonic() + 20.0
        while not any('has no section for node' in line for line in lines):
            assert time.monotonic() < deadline and process.poll() is None, lines
            time.sleep(0.05)
    finally:
        stop_node(process)
        reader.join(timeout=5)
    warning, = [line for line in lines if 'has no section for node' in line]
    assert warning.startswith('[WARN]') and "'/impact_node' (found: my_node)" in warning
    assert process.returncode == 0 and 'Traceback' not in ''.join(lines), lines


def test_predicted_impact_is_published_before_the_hit(harness: Callable[..., Harness],
                                                      truth_ns: int) -> None:
    """With a horizon, ~/predicted_impact leads the impact, and ~/impact_predicted toggles."""
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3})
    sent = publish_swing(h, 'pose', pitch())
    h.processed(sent)
    h.wait(lambda: h.received['impact'] and h.received['predicting'][-1:]
           and not h.received['predicting'][-1].data, 3.0, 'the impact and a cleared prediction')
    predicted = h.received['predicted']
    assert predicted, 'no prediction before the impact'
    closest = predicted[-1]  # made at the last frame before the contact
    assert abs(stamp_ns(closest) - truth_ns) < 2_000_000
    assert {m.header.frame_id for m in predicted} == {'world'}  # CDR bytes: the whole message
    # the node packs each prediction's bytes: each went out with its own values
    assert len({(stamp_ns(m), m.point.x) for m in predicted}) > 1
    # the start-up False is latched for transient-local subscribers; this probe is volatile
    assert [m.data for m in h.received['predicting']][-2:] == [True, False]


def test_start_up_objects_are_frozen_out_of_the_collections() -> None:
    """freeze_start_up keeps what lives now out of later collections; new objects stay in."""
    kept = [object()]  # a container: tracked by the collector
    assert any(each is kept for each in gc.get_objects())
    try:
        frozen = freeze_start_up()
        assert frozen == gc.get_freeze_count() > 0
        assert not any(each is kept for each in gc.get_objects())  # a full collection skips it
        made_after = [object()]
        assert any(each is made_after for each in gc.get_objects())
    finally:
        gc.unfreeze()  # this test process's collector as it was
    assert any(each is kept for each in gc.get_objects())


def test_the_start_up_line_lists_every_topic(harness: Callable[..., Harness]) -> None:
    """'listening:' names the bat plan's subscription and every topic the node publishes."""
    h = make_plan_harness(harness)
    listen_to_rosout(h)
    h.wait(lambda: any(record.msg.startswith('listening: ') for record in h.received['rosout']),
           5.0, 'the start-up line')
    line = next(r.msg for r in h.received['rosout'] if r.msg.startswith('listening: '))
    assert '; bat plans Path on /bat_plan;' in line
    published = line.split('; publishing ')[1].split(', ')
    assert published == [f'/impact_node/{name}' for name in (
        'predicted_impact', 'impact_predicted', 'impact', 'impact_velocity', 'near_miss',
        'impact_report', 'markers')] + ['/diagnostics']


def test_a_silent_input_is_named_in_the_log_once(harness: Callable[..., Harness]) -> None:
    """
    A node started beside no tracker says, once per input, which topic it still waits for.

    After ``stale_timeout`` with nothing on an input, one INFO line names its topic, type,
    why (no publisher discovered yet: DDS discovery may still find one that exists) and the
    parameter to set; ``/diagnostics`` says the same beside each topic.
    """
    h = harness({'stale_timeout': 0.3, 'diagnostics_period': 0.1})
    listen_to_rosout(h)
    h.start()

    def waiting() -> List[LogMsg]:
        return [record for record in h.received['rosout'] if record.name == 'impact_node'
                and record.msg.startswith('no ') and 'still waiting' in record.msg]
    h.wait(lambda: len(waiting()) >= 2, 5.0, 'a line for each silent input')
    time.sleep(0.5)  # five more diagnostics periods: no second line
    lines = sorted(record.msg for record in waiting())
    assert len(lines) == 2, lines
    ball, bat = lines
    assert ball.startswith('no ball message yet on /ball (geometry_msgs/msg/PointStamped) ')
    assert ': no publisher discovered yet; still waiting' in ball and 'set ball_topic' in ball
    assert bat.startswith('no bat_pose message yet on /bat_pose (geometry_msgs/msg/PoseStamped)')
    assert ': no publisher discovered yet; still waiting' in bat and 'set bat_pose_topic' in bat
    assert all(record.level == LogMsg.INFO for record in waiting())
    stale = h.diagnostics_where(
        lambda v: v['stale_topics'].count('no publisher discovered yet') == 2)
    assert 'no publisher discovered yet' in stale.message


# ----------------------------------------------------------------------------------------------
# issue 12: faults on the wire, QoS overrides, the hardware id


def test_a_stale_second_publisher_is_dropped_not_a_reset(harness: Callable[..., Harness],
                                                         truth_ns: int) -> None:
    """Issue 12.1 live: a replay left running 3 s behind: dropped and said, the hit found."""
    h = swing_harness(harness, 'pose')
    stale = h.probe.create_publisher(PointStamped, 'ball', RELIABLE)

    def behind(i: int) -> int:
        stale.publish(point_msg(sample_ns(i) - 3 * 10**9, pitch()(i / RATE_HZ)))
        return 1
    h.processed(publish_swing(h, 'pose', pitch(), extra=behind))
    h.wait(lambda: h.received['impact'], 2.0, 'the impact')
    assert abs(stamp_ns(h.received['impact'][0]) - truth_ns) < 100_000
    stats = h.node.detector.stats
    assert stats.resets == 0 and stats.dropped['stale_stamp'] >= SAMPLES - 10
    status = h.diagnostics_where(lambda v: int(v['dropped_stale_stamp']) >= SAMPLES - 10)
    assert status.level == bytes([1]) and 'dropped' in status.message


def test_lost_input_messages_show_in_diagnostics(harness: Callable[..., Harness]) -> None:
    """Issue 12.7: ten ball messages never sent (lost upstream): ball_lost 10, a WARN."""
    h = swing_harness(harness, 'pose')
    sent = 0
    for i in range(SAMPLES):
        t, ns = i / RATE_HZ, sample_ns(i)
        if not 30 <= i < 40:
            h.publishers['ball'].publish(point_msg(ns, pitch(2.0)(t)))
            sent += 1
        h.publishers['bat_pose'].publish(pose_msg(ns, *pose(t)))
        sent += 1
    h.processed(sent)
    status = h.diagnostics_where(lambda v: v['ball_lost'] == '10')
    assert values(status)['bat_pose_lost'] == '0'
    found = h.diagnostics_where(lambda v: v['lost_in_period'] == '10')
    assert found.level == bytes([1]) and 'about 10 messages lost on /ball' in found.message


def test_standard_qos_overrides_change_the_input_qos(harness: Callable[..., Harness]) -> None:
    """qos_overrides./ball.subscription.reliability beats the simple qos default."""
    h = harness({'qos': 'reliable',
                 'qos_overrides./ball.subscription.reliability': 'best_effort',
                 'qos_overrides./ball.subscription.depth': 7})
    qos = {s.topic_name: s.qos_profile for s in h.node.subscriptions}
    assert qos['/ball'].reliability == ReliabilityPolicy.BEST_EFFORT and qos['/ball'].depth == 7
    assert qos['/bat_pose'].reliability == ReliabilityPolicy.RELIABLE
    assert qos['/bat_pose'].depth == 1000


def test_hardware_id_names_the_node_or_the_rig(harness: Callable[..., Harness]) -> None:
    """hardware_id: the node's fully qualified name by default, else the parameter."""
    assert harness().node.diagnostics().hardware_id == '/impact_node'
    assert harness({'hardware_id': 'cage_2'}).node.diagnostics().hardware_id == 'cage_2'
