"""
Tests for baseball_collision.ros.outputs: what the node's events send out, in which order.

In-process, over real rclpy topics (``conftest``'s harness, discovery off): log lines on
/rosout, an impact's completion after the drain, ~/impact_report, the live markers.
"""

import json
import os
from pathlib import Path
import time
from typing import Any, Callable, Dict, List, Optional, Tuple

from baseball_collision.core.detector import Detector, PendingUncertainty
from baseball_collision.core.records import RECORD_FORMAT
from baseball_collision.ros import outputs as outputs_module
from baseball_collision.ros.node import ImpactNode
import pytest
from rcl_interfaces.msg import Log as LogMsg
from rclpy.duration import Duration
from rclpy.qos import DurabilityPolicy, LivelinessPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Bool
from std_srvs.srv import Trigger
from support.harness import Harness, sample_ns, stamp_ns
from support.node_inputs import listen_to_rosout, publish_swing, swing_harness
from support.scenes import pitch
from support.schema import Validator
from visualization_msgs.msg import Marker

pytestmark = pytest.mark.ros


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
    logging_file = os.path.abspath(outputs_module.__file__)  # (ImpactNode's mixin base)
    assert getattr(ImpactNode, function).__module__ == outputs_module.__name__
    assert (record.level, record.function, record.file) == (LogMsg.INFO, function, logging_file)
    assert call in Path(logging_file).read_text().splitlines()[record.line - 1]


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


def test_impact_report_is_the_event_record(harness: Callable[..., Harness],
                                           truth_ns: int) -> None:
    """One ~/impact_report per impact and prediction: the schema's record, lead and error bars."""
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
        assert not record['planned']  # (an extrapolated bat's error bars: wide, but there)
        assert record['time_uncertainty_s'] > 0.0
        assert record['distance_from_tip_uncertainty_m'] > 0.0


def test_no_report_is_made_without_a_subscriber(harness: Callable[..., Harness]) -> None:
    """With nobody on ~/impact_report no record is made; the other outputs are unchanged."""
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3})
    h.unsubscribe('/impact_node/impact_report')
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


def test_bat_departures_are_made_ahead_after_the_drain(harness: Callable[..., Harness],
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    """After each input's drain (none while it drains), the newest bat departures are made."""
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3})
    made: List[Tuple[int, bool]] = []
    ahead = Detector.departures_ahead

    def recorded(detector: Detector) -> int:
        made.append((ahead(detector), h.node._intake._draining))
        return made[-1][0]
    monkeypatch.setattr(Detector, 'departures_ahead', recorded)
    h.processed(publish_swing(h, 'pose', pitch()))
    h.wait(lambda: h.received['impact'], 2.0, 'the impact')
    assert sum(count for count, _ in made) > 0 and not any(draining for _, draining in made)


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


def test_an_arm_can_ask_the_flag_for_a_liveliness_lease(harness: Callable[..., Harness]) -> None:
    """
    ~/impact_predicted offers a finite liveliness lease, so an arm can watch the node's death.

    The flag is sent once per change: a node killed while it was true left the arm on true, and
    Fast DDS dropped the dead node's endpoints only after its 20 s participant lease. An arm
    that asks for a lease of 1 s (``LIVELINESS_LEASE_S`` or more) is matched and gets the
    flag (before, offered an infinite lease, it was incompatible and got nothing); one that
    asks for none still matches.
    """
    h = harness()
    received: Dict[str, List[bool]] = {'lease': [], 'none': []}
    arm = h.probe
    for name, lease in (('lease', Duration(seconds=1.0)), ('none', None)):
        qos = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
        if lease is not None:
            qos.liveliness_lease_duration = lease
        arm.create_subscription(Bool, '/impact_node/impact_predicted',
                                lambda message, name=name: received[name].append(message.data),
                                qos)
    h.start()
    h.wait(lambda: received['lease'] and received['none'], 3.0, 'the latched flag')
    assert received == {'lease': [False], 'none': [False]}
    offered = h.node._outputs['impact_predicted'].qos_profile
    assert offered.liveliness == LivelinessPolicy.AUTOMATIC
    assert offered.liveliness_lease_duration == Duration(
        seconds=outputs_module.LIVELINESS_LEASE_S) <= Duration(seconds=1.0)
