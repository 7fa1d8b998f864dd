"""
Tests for baseball_collision.ros.node: the impact_node over real rclpy topics and services.

In-process tests run the node and a probe node in one fresh ``rclpy.Context`` with discovery
off (``ROS_AUTOMATIC_DISCOVERY_RANGE=OFF``); the process tests start ``.venv/bin/impact_node``
on this run's random domain with discovery limited to the host (``conftest``). Messages are
published reliably after the subscriptions matched, and every expectation is on header stamps,
so no result depends on arrival timing.
"""

import gc
import json
import math
import os
from pathlib import Path
import re
import signal
import subprocess
import sys
import threading
import time
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.detector import DROP_REASONS, PARAMETERS, PendingUncertainty
from baseball_collision.core.detector import sweep_impact as impact_module
from baseball_collision.core.detector.predictor import kept_flight_span
from baseball_collision.core.prediction import MAX_PLAN_POSES
from baseball_collision.core.records import RECORD_FORMAT
from baseball_collision.errors import RosError
from baseball_collision.ros import node as node_module
from baseball_collision.ros.inputs import Throttle
from baseball_collision.ros.node import freeze_start_up, ImpactNode
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
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock as ClockMsg
from std_srvs.srv import Trigger
from support import REPO_ROOT
from support.harness import (
    Harness, point_msg, pose_msg, RATE_HZ, RELIABLE, sample_ns, SAMPLES, stamp, stamp_ns, values)
from support.scenes import BASE_NS, first_contact, pitch, pose, swing
from support.schema import Validator
from visualization_msgs.msg import Marker
import yaml

pytestmark = pytest.mark.ros

SCRIPT = Path(sys.executable).parent / 'impact_node'
CONFIG = REPO_ROOT / 'config' / 'impact_node.yaml'
POINTS_CONFIG = REPO_ROOT / 'config' / 'impact_node_points.yaml'
LAUNCH_FILE = REPO_ROOT / 'launch' / 'impact_node.launch.py'


@pytest.fixture(scope='module')
def truth_ns() -> int:
    """Return the exact first contact of the hitting pitch as an absolute stamp (ns)."""
    t = first_contact(pitch())
    assert t is not None
    return BASE_NS + int(round(t * 1e9))


def publish_swing(h: Harness, bat_input: str, ball: Callable[[float], np.ndarray],
                  samples: range = range(SAMPLES),
                  extra: Optional[Callable[[int], None]] = None, later_ns: int = 0) -> int:
    """
    Publish ball and bat at 360 Hz on the harness's topics; return the messages sent.

    ``later_ns``: the same swing stamped that much later (a second pitch).
    """
    sent = 0
    for i in samples:
        t = i / RATE_HZ
        ns = sample_ns(i) + later_ns
        h.publishers['ball'].publish(point_msg(ns, ball(t)))
        if bat_input == 'pose':
            position, quaternion = pose(t)
            h.publishers['bat_pose'].publish(pose_msg(ns, position, quaternion))
            sent += 2
        else:
            knob, tip = swing(t)
            h.publishers['bat_knob'].publish(point_msg(ns, knob))
            h.publishers['bat_tip'].publish(point_msg(ns, tip))
            sent += 3
        if extra is not None:
            sent += extra(i)
    return sent


def listen_to_rosout(h: Harness) -> None:
    """Collect every /rosout record (including those sent before) in ``h.received['rosout']``."""
    h.received['rosout'] = []
    h.probe.create_subscription(LogMsg, '/rosout', h._collector('rosout'), QoSProfile(
        depth=1000, reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL))


def swing_harness(make: Callable[..., Harness], bat_input: str,
                  overrides: Optional[Dict[str, Any]] = None) -> Harness:
    """Return a started harness with the ball and the bat publishers of ``bat_input``."""
    h = make(dict({'bat_input': bat_input}, **(overrides or {})))
    h.publisher(PointStamped, 'ball')
    if bat_input == 'pose':
        h.publisher(PoseStamped, 'bat_pose')
    else:
        h.publisher(PointStamped, 'bat_knob')
        h.publisher(PointStamped, 'bat_tip')
    return h.start()


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
# impacts, near misses, markers


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


@pytest.mark.parametrize('height, kind, function, call', [
    (1.09, 'near miss', '_publish', 'logger.info(output.log)'),
    (None, 'impact', '_measured', 'self._lines.info(describe_impact(impact))')],
    ids=['near-miss', 'impact'])
def test_log_lines_reach_rosout_naming_their_call_site(
        harness: Callable[..., Harness], height: Optional[float], kind: str, function: str,
        call: str) -> None:
    """A near miss's line and an impact's on /rosout: INFO, the node's name, where logged."""
    h = swing_harness(harness, 'pose')
    listen_to_rosout(h)
    h.processed(publish_swing(h, 'pose', pitch() if height is None else pitch(height=height)))

    def lines() -> List[LogMsg]:
        return [record for record in h.received['rosout']
                if record.name == 'impact_node' and record.msg.startswith(f'{kind} at ')]
    h.wait(lambda: lines(), 5.0, f'the {kind} line on /rosout')
    record, = lines()
    node_file = os.path.abspath(sys.modules[ImpactNode.__module__].__file__)
    assert (record.level, record.function, record.file) == (LogMsg.INFO, function, node_file)
    assert call in Path(node_file).read_text().splitlines()[record.line - 1]


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
# services, clock and parameters


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


def test_an_impacts_error_bars_failing_leave_its_completion_out_and_the_node_goes_on(
        harness: Callable[..., Harness], truth_ns: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    The error bars of an impact raising (a bug) after the drain do not stop the node.

    The impact's ``~/impact`` and ``~/impact_velocity`` went out; its line, markers and report
    are left out with an ERROR line (traceback included); the next hit is whole.
    """
    failures: List[int] = []
    measure = PendingUncertainty.measure

    def fails_once(pending: PendingUncertainty) -> Any:
        if not failures:
            failures.append(1)
            raise ValueError('a re-solve found nothing')
        return measure(pending)

    monkeypatch.setattr(PendingUncertainty, 'measure', fails_once)
    h = swing_harness(harness, 'pose')
    listen_to_rosout(h)

    def impact_records() -> List[Dict[str, Any]]:
        return [record for record in (json.loads(m.data) for m in h.received['report'])
                if record['event'] == 'impact']
    sent = publish_swing(h, 'pose', pitch())
    h.processed(sent)
    h.wait(lambda: [record for record in h.received['rosout'] if record.level == LogMsg.ERROR
                    and 'the error bars of the impact' in record.msg], 5.0, 'the ERROR line')
    error, = [record for record in h.received['rosout'] if record.level == LogMsg.ERROR]
    assert 'ValueError: a re-solve found nothing' in error.msg and 'Traceback' in error.msg
    assert len(h.received['velocity']) == 1 and not impact_records()
    assert h.node.detector.stats.resets == 0
    h.processed(sent + publish_swing(h, 'pose', pitch(), later_ns=10**9))
    h.wait(lambda: impact_records(), 5.0, 'the report of the next hit')
    record, = impact_records()
    assert abs(record['stamp_ns'] - 10**9 - truth_ns) < 100_000
    assert record['time_uncertainty_s'] > 0.0


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

    once(node_module, 'plan_arrays', IndexError('a pose out of range'))
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
        process.send_signal(signal.SIGINT)
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
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


def test_an_impact_turns_the_prediction_off_at_once(harness: Callable[..., Harness],
                                                    truth_ns: int) -> None:
    """
    ~/impact_predicted turns false with the ~/impact, not at the next frame that predicts.

    With ``prediction_period`` 0.01 the frame of the contact does not predict and the next
    one is never sent: ``PredictionCleared`` never comes (``stale_timeout`` is far off).
    """
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3, 'prediction_period': 0.01,
                                        'stale_timeout': 30.0})
    contact = int((truth_ns - BASE_NS) * 1e-9 * RATE_HZ) + 1  # the first frame after it
    h.processed(publish_swing(h, 'pose', pitch(), samples=range(contact + 1)))
    h.wait(lambda: h.received['impact'], 5.0, 'the impact')
    assert any(message.data for message in h.received['predicting'])
    h.wait(lambda: not h.received['predicting'][-1].data, 5.0, 'the prediction withdrawn')


@pytest.mark.parametrize('ended_by', ['silence', 'prediction_off'])
def test_a_prediction_in_force_is_withdrawn_when_no_frame_can_end_it(
        harness: Callable[..., Harness], truth_ns: int, ended_by: str) -> None:
    """
    The streams stop 8 ms before the predicted contact: ~/impact_predicted turns false.

    Within ``stale_timeout`` and a diagnostics period (``silence``), or at once when the
    prediction is turned off at runtime (``prediction_off``). It stayed true for good: only a
    frame could clear it.
    """
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3, 'stale_timeout': 0.3,
                                        'diagnostics_period': 0.1})
    early = range(int((truth_ns - BASE_NS) * 1e-9 * RATE_HZ) - 3)  # up to ~8 ms before
    h.processed(publish_swing(h, 'pose', pitch(), samples=early))
    h.wait(lambda: h.received['predicting'][-1:] and h.received['predicting'][-1].data, 3.0,
           'a prediction in force')
    if ended_by == 'prediction_off':
        result = h.node.set_parameters([Parameter('prediction_horizon', value=0.0)])
        assert result[0].successful
    h.wait(lambda: not h.received['predicting'][-1].data, 3.0, 'the prediction withdrawn')
    assert not h.received['impact']


class PublishOrder:
    """A node's output publisher that also notes, in a shared list, what it published."""

    def __init__(self, publisher: Any, name: str, order: List[Tuple[str, Any]]) -> None:
        self._publisher, self._name, self._order = publisher, name, order

    def publish(self, message: Any) -> None:
        """Note ``(name, message)``, then publish the message."""
        self._order.append((self._name, message))
        self._publisher.publish(message)

    def __getattr__(self, attribute: str) -> Any:
        """Return the publisher's own attribute (topic_name, get_subscription_count ...)."""
        return getattr(self._publisher, attribute)


@pytest.mark.parametrize('paced', [False, True])
@pytest.mark.parametrize('late_samples', [22, 36])  # the ball 61 ms and 100 ms after the bat
def test_a_late_ball_keeps_the_prediction_until_its_impact(
        harness: Callable[..., Harness], truth_ns: int, late_samples: int, paced: bool) -> None:
    """
    The ball's messages come 61-100 ms after the bat's: ~/impact_predicted turns true once.

    Then false right after the ``~/impact``. The bat passes the predicted instant by
    ``max_gap`` (18 frames) long before the late ball reaches it: a prediction withdrawn on
    the bat's stamps alone flapped with each of the ball's next predictions, and turned false
    before the impact (``stale_timeout`` is far off here). ``paced``: the frames sent at their
    rate, so that the ball is late on the node's clock too; it streams on, silent for far
    less than its lag plus ``max_gap``: not taken for lost (``PredictionWatch.ball_lost``).
    """
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3, 'stale_timeout': 30.0})
    order: List[Tuple[str, Any]] = []
    for name in ('impact', 'impact_predicted'):
        h.node._outputs[name] = PublishOrder(h.node._outputs[name], name, order)
    sent = 0
    for i in range(SAMPLES + late_samples):
        t = i / RATE_HZ
        h.publishers['bat_pose'].publish(pose_msg(sample_ns(i), *pose(t)))
        sent += 1
        if paced:
            time.sleep(1.0 / RATE_HZ)
        elif i == late_samples - 1:
            h.processed(sent)  # the bat's lead taken before the first ball
        if i >= late_samples:
            j = i - late_samples
            h.publishers['ball'].publish(point_msg(sample_ns(j), pitch()(j / RATE_HZ)))
            sent += 1
    h.processed(sent)
    h.wait(lambda: h.received['impact'] and h.received['predicting'][-1:]
           and not h.received['predicting'][-1].data, 5.0, 'the impact and a cleared prediction')
    assert [message.data for message in h.received['predicting']] == [True, False]
    assert [name for name, _ in order] == ['impact_predicted', 'impact', 'impact_predicted']


@pytest.mark.parametrize('lost', ['ball', 'bat_pose'])
def test_a_prediction_is_withdrawn_when_one_stream_stops_and_the_other_streams_on(
        harness: Callable[..., Harness], truth_ns: int, lost: str) -> None:
    """
    One stream is lost 8 ms before the predicted contact, the other streams on: the flag goes off.

    The ball lost: once the bat passed the predicted instant by ``max_gap`` and the ball has
    been silent longer than its lag behind the bat plus ``max_gap``, and the bat passed the
    ball's last stamp by the span its flight holds unseen (``PredictionWatch``,
    ``kept_flight_span``: a paused tracker may still bring the contact till then): an arm
    learns that no contact is coming then, not a ``stale_timeout`` (30 s here) later.
    The bat lost: once it has been silent beyond ``stale_timeout`` (0.3 s), at a ball message
    (the diagnostics period, whose timer also checks it, is far off here).
    """
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3, 'diagnostics_period': 60.0,
                                        'stale_timeout': 30.0 if lost == 'ball' else 0.3})
    last = int((truth_ns - BASE_NS) * 1e-9 * RATE_HZ) - 3  # the last frame, ~8 ms before
    h.processed(publish_swing(h, 'pose', pitch(), samples=range(last + 1)))
    h.wait(lambda: h.received['predicting'][-1:] and h.received['predicting'][-1].data, 3.0,
           'a prediction in force')
    passed = h.node._watch.instant_ns + round(h.node.detector.config.max_gap * 1e9)
    withdrawn_at: List[int] = []  # the bat's stamp before its newest as the flag turned false
    set_predicting = h.node._set_predicting

    def noting(predicting: bool) -> None:
        if h.node._predicting and not predicting:
            withdrawn_at.append(h.node._watch.before_newest['bat_pose'])
        set_predicting(predicting)
    h.node._set_predicting = noting
    i = last + 1
    while h.received['predicting'][-1].data and i < last + 600:  # (3 s of frames)
        if lost == 'ball':
            h.publishers['bat_pose'].publish(pose_msg(sample_ns(i), *pose(i / RATE_HZ)))
        else:
            h.publishers['ball'].publish(point_msg(sample_ns(i), pitch()(i / RATE_HZ)))
        i += 1
        time.sleep(0.005)
    assert not h.received['predicting'][-1].data, 'the prediction was not withdrawn'
    assert len(withdrawn_at) == 1
    assert withdrawn_at[0] > passed or lost == 'bat_pose'  # not before the bat passed
    held = h.node._watch.ball_newest_ns + round(
        kept_flight_span(h.node.detector.config.prediction_window) * 1e9)
    assert withdrawn_at[0] > held or lost == 'bat_pose'  # nor while the ball's flight holds
    assert not h.received['impact']


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


def test_bat_plan_topic_makes_early_exact_predictions(harness: Callable[..., Harness],
                                                      truth_ns: int) -> None:
    """A commanded swing on bat_plan_topic: predictions 40 ms ahead within 0.5 ms."""
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


def make_plan_harness(make: Callable[..., Harness]) -> Harness:
    """Return a started pose harness with a plan publisher, a 0.3 s horizon, every frame."""
    h = make({'bat_input': 'pose', 'prediction_horizon': 0.3, 'bat_plan_topic': 'bat_plan',
              'prediction_period': 0.0,  # every frame: the scene's ball is tracked ~30 ms
              'frame_id': 'world'})  # a plan before the first sample is checked against it
    h.publisher(PointStamped, 'ball')
    h.publisher(PoseStamped, 'bat_pose')
    h.publisher(PathMsg, 'bat_plan')
    return h.start()


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


# ----------------------------------------------------------------------------------------------
# issue 12 and 14: reports, faults on the wire, markers, QoS overrides


def test_impact_report_is_the_event_record(harness: Callable[..., Harness],
                                           truth_ns: int) -> None:
    """One ~/impact_report per impact and prediction: the schema's record, with lead times."""
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3})
    h.processed(publish_swing(h, 'pose', pitch()))
    h.wait(lambda: h.received['impact'] and any(
        json.loads(m.data)['event'] == 'impact' for m in h.received['report']), 2.0, 'reports')
    records = [json.loads(m.data) for m in h.received['report']]
    validator = Validator('event_record.schema.json')
    assert all(validator.errors(record) == [] for record in records)
    impacts = [r for r in records if r['event'] == 'impact']
    predictions = [r for r in records if r['event'] == 'prediction']
    assert len(impacts) == 1 and impacts[0]['stamp_ns'] == stamp_ns(h.received['impact'][0])
    assert impacts[0]['format'] == RECORD_FORMAT and impacts[0]['frame_id'] == 'world'
    assert not impacts[0]['bat_at_rest']
    assert predictions and len(predictions) == len(h.received['predicted'])
    for record, message in zip(predictions, h.received['predicted']):
        assert record['stamp_ns'] == stamp_ns(message) > record['made_at_ns']
        assert record['lead_s'] == pytest.approx((record['stamp_ns'] - record['made_at_ns'])
                                                 * 1e-9)


def test_no_report_is_made_without_a_subscriber(harness: Callable[..., Harness]) -> None:
    """With nobody on ~/impact_report no record is made; the other outputs are unchanged."""
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3})
    report_topic = '/impact_node/impact_report'
    for subscription in list(h.probe.subscriptions):
        if subscription.topic_name == report_topic:
            h.probe.destroy_subscription(subscription)
    reports = h.node._outputs['impact_report']
    h.wait(lambda: reports.get_subscription_count() == 0, 5.0, 'the report unmatched')
    published = []

    class Counted:
        """The report publisher, counting what the node publishes on it."""

        def get_subscription_count(self) -> int:
            return reports.get_subscription_count()

        def publish(self, message: object) -> None:
            published.append(message)
            reports.publish(message)

    h.node._outputs['impact_report'] = Counted()
    h.processed(publish_swing(h, 'pose', pitch()))
    h.wait(lambda: h.received['impact'], 2.0, 'the impact')
    assert h.received['predicted'] and published == []


def test_reports_are_made_after_the_drain(harness: Callable[..., Harness],
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A record is made and sent once no input message waits, after what an arm reads.

    Each report goes out after the drain (no input being taken), in the events' order, after
    the ``~/predicted_impact`` or ``~/impact`` of its event; the node's queue ends empty. An
    impact's error bars are measured after the drain too, after its ``~/impact`` went out and
    before its record (which carries them). ``~/impact`` goes out as the contact is solved,
    before the detector has counted the impact (its velocities fitted), ``~/impact_velocity``
    after; a first prediction's point before ``~/impact_predicted`` turns on.
    """
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3})
    h.wait(lambda: h.node._outputs['impact_report'].get_subscription_count() > 0, 5.0,
           'the report matched')
    sent: List[Tuple[str, bool]] = []

    def logged(name: str, publisher: Any) -> Any:
        class Logged:
            """The publisher, saying what went out and whether the intake was draining."""

            def __getattr__(self, attribute: str) -> Any:
                return getattr(publisher, attribute)

            def publish(self, message: Any) -> None:
                sent.append((name, h.node._intake._draining))
                counted.append(h.node.detector.stats.impacts)
                publisher.publish(message)
        return Logged()

    counted: List[int] = []  # the detector's impacts as each went out
    for name in ('predicted_impact', 'impact', 'impact_report', 'impact_velocity',
                 'impact_predicted'):
        h.node._outputs[name] = logged(name, h.node._outputs[name])
    measure = PendingUncertainty.measure

    def measured(pending: PendingUncertainty) -> Any:
        sent.append(('measure', h.node._intake._draining))
        counted.append(h.node.detector.stats.impacts)
        return measure(pending)
    monkeypatch.setattr(PendingUncertainty, 'measure', measured)
    h.processed(publish_swing(h, 'pose', pitch()))
    h.wait(lambda: h.received['impact'] and any(
        json.loads(m.data)['event'] == 'impact' for m in h.received['report']), 2.0, 'reports')
    names = [name for name, _ in sent]
    assert names.index('predicted_impact') < names.index('impact_predicted')  # point, then on
    kept = [i for i, name in enumerate(names) if name != 'impact_predicted']
    sent, counted = [sent[i] for i in kept], [counted[i] for i in kept]
    names = [name for name, _ in sent]
    impact, velocity = names.index('impact'), names.index('impact_velocity')
    assert names.count('impact') == 1 and impact < velocity
    assert counted[impact] == 0 and counted[velocity] == 1
    del sent[velocity]
    (measuring,) = [i for i, (name, _) in enumerate(sent) if name == 'measure']
    assert impact < measuring and not sent[measuring][1]  # after ~/impact, not in the drain
    assert sent[measuring + 1][0] == 'impact_report'  # then the impact's record
    del sent[measuring]
    reports = [i for i, (name, _) in enumerate(sent) if name == 'impact_report']
    outputs = [i for i, (name, _) in enumerate(sent) if name != 'impact_report']
    events = [sent[i][0] for i in outputs]
    assert reports and len(reports) == len(outputs) and not h.node._to_complete
    assert not any(sent[i][1] for i in reports)  # none while the intake was draining
    assert all(e < r for e, r in zip(outputs, reports))  # each after its event's output
    records = [json.loads(m.data)['event'] for m in h.received['report']]
    assert records == ['prediction' if name == 'predicted_impact' else 'impact'
                       for name in events]


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


def test_live_markers_carry_sample_stamps_and_a_reset_clears_them(
        harness: Callable[..., Harness]) -> None:
    """Live markers: the samples' stamp, not republished when nothing new; reset: DELETEALL."""
    h = swing_harness(harness, 'pose', {'marker_rate': 50.0, 'diagnostics_period': 1.0})
    h.processed(publish_swing(h, 'pose', pitch(2.0), samples=range(20)))
    h.wait(lambda: any(a.markers and a.markers[0].ns.startswith('live')
                       for a in h.received['markers']), 2.0, 'live markers')

    def live() -> List[Any]:
        return [a for a in h.received['markers']
                if a.markers and a.markers[0].ns.startswith('live')]
    h.wait(lambda: stamp_ns(live()[-1].markers[0]) == sample_ns(19), 2.0, 'the newest')
    count = len(live())
    time.sleep(0.2)  # ten marker periods with no new sample: nothing republished
    assert len(live()) == count
    assert all(stamp_ns(m) == sample_ns(19) for m in live()[-1].markers)  # not now()
    h.call(Trigger, '/impact_node/reset', Trigger.Request())
    h.wait(lambda: any(a.markers and a.markers[0].action == Marker.DELETEALL
                       for a in h.received['markers']), 2.0, 'a DELETEALL')


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
