"""The detector's health as plain data: level, message and grouped values, without ROS."""

from collections import Counter

from baseball_collision.core.detector import DetectorStats, DROP_REASONS
from baseball_collision.core.health import (
    format_stamp, health_status, Level, silent_streams, take_snapshot, Tally)

SETTINGS = {'stale_timeout': 1.0, 'model': 'rigid', 'bat_input': 'pose', 'qos': 'reliable'}
TOPICS = {'ball': '/ball', 'bat_pose': '/bat_pose'}


def _tally(now: float) -> Tally:
    tally = Tally(started=0.0)
    for i in range(100):
        tally.arrived('ball', now - 1.0 + i / 100)
        tally.arrived('bat_pose', now - 1.0 + i / 100)
    return tally


def test_a_tracking_status_in_groups() -> None:
    """OK 'tracking'; the groups in order, each key once; every drop reason; stamps as text."""
    stats = DetectorStats(received=Counter(ball=100, bat_pose=100), impacts=1)
    snapshot = take_snapshot(10.0, 'impact_node', ('ball', 'bat_pose'), TOPICS, _tally(10.0),
                             stats, 1_700_000_000_500_000_000, 'world', SETTINGS)
    status = health_status(snapshot, {})
    assert (status.level, status.message) == (Level.OK, 'tracking')
    assert [name for name, _ in status.groups] == ['state', 'inputs', 'drops', 'events',
                                                   'timing', 'session']
    keys = [key for key, _ in status.values()]
    assert len(keys) == len(set(keys))
    values = dict(status.values())
    assert {f'dropped_{reason}' for reason in DROP_REASONS} <= set(values)
    assert values['ball_rate_hz'] == '10.0' and values['impacts'] == '1'
    assert values['watermark_stamp'] == '1700000000.500000000' == format_stamp(
        1_700_000_000_500_000_000)


def test_stale_and_every_sample_dropped() -> None:
    """A silent input: WARN naming it; every sample of the period dropped: ERROR."""
    tally = _tally(10.0)
    stats = DetectorStats(dropped=Counter(wrong_frame=200))
    late = take_snapshot(12.5, 'n', ('ball', 'bat_pose'), TOPICS, tally, stats, None, '',
                         SETTINGS)
    assert silent_streams(late) == ['ball', 'bat_pose']
    status = health_status(late, {'ball': 'no publisher'})
    assert status.level == Level.ERROR
    assert '/ball (silent for' in status.message and 'no publisher' in status.message
    assert dict(status.values())['state'] == 'stale'
