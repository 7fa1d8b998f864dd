"""The /diagnostics reporter on its own: counters and times in, a DiagnosticStatus out (no DDS)."""

from collections import Counter
from dataclasses import replace
from typing import Dict

from baseball_collision.core.detector import DetectorStats, DROP_REASONS
from baseball_collision.ros.diagnostics import (
    Period, report, silent_streams, Snapshot, take_snapshot, Tally)
from diagnostic_msgs.msg import DiagnosticStatus
import pytest

pytestmark = pytest.mark.ros

SETTINGS = {'stale_timeout': 1.0, 'model': 'rigid', 'bat_input': 'pose', 'qos': 'reliable'}
TOPICS = {'ball': '/ball', 'bat_pose': '/bat_pose'}


def snapshot(now: float = 10.0, **changes) -> Snapshot:
    """Return a tracking snapshot: both streams at 100 Hz over the last second, no drops."""
    period = Period(start=now - 1.0, arrivals=Counter(ball=900, bat_pose=900), dropped=0,
                    count=200, total_s=0.02, max_s=0.001)
    base = Snapshot(
        now=now, name='impact_node', streams=('ball', 'bat_pose'), topics=TOPICS, started=0.0,
        arrivals={'ball': 1000, 'bat_pose': 1000},
        last_arrival={'ball': now - 0.01, 'bat_pose': now - 0.01}, period=period, dropped={},
        counts={'impacts': 2, 'near_misses': 1, 'gaps': 0, 'resets': 0},
        detector_mean_s=5e-5, detector_max_s=1e-3, watermark_ns=1_700_000_000_500_000_000,
        last_impact_ns=1_700_000_000_250_000_000, frame_id='world', settings=SETTINGS,
        incompatible=0, incompatible_reported=0)
    return replace(base, **changes)


def values(status: DiagnosticStatus) -> Dict[str, str]:
    """Return a status's key/values."""
    return {kv.key: kv.value for kv in status.values}


def test_tracking_is_ok_with_rates_and_every_key() -> None:
    """Data on every input: OK, 'tracking', rates over the period, every documented key."""
    status = report(snapshot(), {})
    got = values(status)
    assert status.level == DiagnosticStatus.OK and status.message == 'tracking'
    assert status.name == 'impact_node: impact detector'
    assert got['ball_rate_hz'] == '100.0' and got['bat_pose_received'] == '1000'
    assert got['processing_mean_ms'] == '0.1000' and got['processing_max_ms'] == '1.0000'
    assert got['detector_mean_ms'] == '0.0500' and got['messages_in_period'] == '200'
    assert got['watermark_stamp'] == '1700000000.500000000'
    assert got['last_impact_stamp'] == '1700000000.250000000'
    assert (got['impacts'], got['near_misses'], got['frame_id']) == ('2', '1', 'world')
    assert {f'dropped_{reason}' for reason in DROP_REASONS} <= set(got)
    assert got['stale_topics'] == '' and got['qos'] == 'reliable'


def test_waiting_then_stale_naming_why() -> None:
    """No data yet: OK while young, then stale (WARN) with the reason the node found."""
    young = snapshot(now=0.5, last_arrival={}, arrivals={},
                     period=Period(0.0, Counter(), 0))
    assert silent_streams(young) == ['ball', 'bat_pose']
    status = report(young, {'ball': 'no publisher discovered yet'})
    assert status.level == DiagnosticStatus.OK
    assert status.message == 'waiting for data on /ball, no publisher discovered yet, /bat_pose'
    old = replace(young, now=5.0)
    status = report(old, {'bat_pose': 'publisher of geometry_msgs/msg/PointStamped'})
    assert status.level == DiagnosticStatus.WARN and values(status)['state'] == 'stale'
    assert '/ball (no data since start)' in status.message
    assert 'geometry_msgs/msg/PointStamped' in status.message
    silent = snapshot(last_arrival={'ball': 7.5, 'bat_pose': 9.99})
    assert silent_streams(silent) == ['ball']
    assert values(report(silent, {}))['stale_topics'] == '/ball (silent for 2.5 s)'


def test_drops_warn_and_all_dropped_is_an_error() -> None:
    """Drops in the period: WARN with the count; every sample of the period dropped: ERROR."""
    some = report(snapshot(dropped={'non_finite': 3}), {})
    assert some.level == DiagnosticStatus.WARN
    assert some.message == 'tracking; dropped 3 of 200 samples'
    assert values(some)['dropped_non_finite'] == '3' and values(some)['dropped_in_period'] == '3'
    period = replace(snapshot().period, dropped=50)
    earlier = snapshot(dropped={'wrong_frame': 250}, period=period)
    assert report(earlier, {}).level == DiagnosticStatus.ERROR
    assert report(earlier, {}).message == 'tracking; every sample was dropped (200)'


def test_a_new_incompatibility_warns_once() -> None:
    """A QoS or type mismatch not yet reported: WARN; once reported: OK again."""
    new = report(snapshot(incompatible=1, incompatible_reported=0), {})
    assert new.level == DiagnosticStatus.WARN and 'incompatible QoS' in new.message
    assert report(snapshot(incompatible=1, incompatible_reported=1), {}).level == \
        DiagnosticStatus.OK


def test_take_snapshot_copies_and_starts_the_next_period() -> None:
    """The snapshot holds copies; the tally's period restarts at now with the counters then."""
    tally = Tally(started=0.0)
    tally.arrived('ball', 0.4)
    tally.period.record(0.002)
    stats = DetectorStats()
    stats.dropped['non_finite'] += 1
    taken = take_snapshot(1.0, 'impact_node', ('ball',), {'ball': '/ball'}, tally, stats, None,
                          None, SETTINGS)
    tally.arrived('ball', 1.5)
    stats.dropped['non_finite'] += 1
    assert taken.arrivals == {'ball': 1} and taken.dropped == {'non_finite': 1}
    assert taken.period.count == 1 and taken.frame_id == ''
    assert tally.period.start == 1.0 and tally.period.arrivals == {'ball': 1}
    assert tally.period.dropped == 1 and tally.period.count == 0
    assert values(report(taken, {}))['watermark_stamp'] == ''
