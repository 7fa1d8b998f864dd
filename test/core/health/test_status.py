"""The detector's status as plain data: level, message and grouped values, without ROS."""

from collections import Counter
from dataclasses import replace

from baseball_collision.core.detector import DetectorStats, DROP_REASONS
from baseball_collision.core.health import (
    format_stamp, health_status, HealthStatus, Level, RESETS_ERROR, silent_streams,
    take_snapshot, Tally)

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
    status = health_status(late, {'ball': 'no publisher discovered yet'})
    assert status.level == Level.ERROR
    assert '/ball (silent for' in status.message and 'no publisher discovered' in status.message
    assert dict(status.values())['state'] == 'stale'


def test_losses_and_resets_in_a_period_raise_the_level() -> None:
    """Lost messages: WARN naming the topic; one reset: WARN; RESETS_ERROR resets: ERROR."""
    tally = _tally(10.0)
    for k in list(range(1, 50)) + list(range(60, 100)):
        tally.stamped('ball', 1_000_000 * k)
    status = health_status(take_snapshot(10.0, 'n', ('ball', 'bat_pose'), TOPICS, tally,
                                         DetectorStats(), None, '', SETTINGS), {})
    assert status.level == Level.WARN and 'about 10 messages lost on /ball' in status.message
    values = dict(status.values())
    assert values['ball_lost'] == '10' and values['lost_in_period'] == '10'
    for resets, level in ((0, Level.OK), (1, Level.WARN), (RESETS_ERROR, Level.ERROR)):
        tally = _tally(10.0)
        tally.next_period(9.0, 0, 5)
        status = health_status(take_snapshot(10.0, 'n', ('ball', 'bat_pose'), TOPICS, tally,
                                             DetectorStats(resets=5 + resets), None, '',
                                             SETTINGS), {})
        assert status.level == level, resets
        assert dict(status.values())['resets_in_period'] == str(resets)


def test_an_internal_error_in_a_period_is_an_error_that_drops_do_not_lower() -> None:
    """
    The node's own failure in a period: ERROR naming the count, the total in the values.

    Some drops in the same period (a WARN alone) leave it ERROR, as they leave RESETS_ERROR
    resets.
    """
    def status(failures_before: int, failures: int, resets_before: int,
               stats: DetectorStats) -> HealthStatus:
        tally = Tally(started=0.0, failures=failures_before)
        tally.next_period(9.0, 0, resets_before)
        tally = replace(_tally(10.0), period=tally.period, failures=failures)
        return health_status(take_snapshot(10.0, 'n', ('ball', 'bat_pose'), TOPICS, tally,
                                           stats, None, '', SETTINGS), {})

    dropped = Counter(non_finite=4)
    failed = status(2, 3, 0, DetectorStats(dropped=dropped))
    assert failed.level == Level.ERROR
    assert failed.message == \
        'tracking; 1 internal error(s) (see the log); dropped 4 of 200 samples'
    assert dict(failed.values())['internal_errors'] == '3'
    calm = status(3, 3, 0, DetectorStats())
    assert calm.level == Level.OK and dict(calm.values())['internal_errors'] == '3'
    reset = status(0, 0, 5, DetectorStats(resets=5 + RESETS_ERROR, dropped=dropped))
    assert reset.level == Level.ERROR and 'dropped 4 of 200 samples' in reset.message


def test_the_noise_the_fits_take_is_in_the_session_group() -> None:
    """``tracker_noise`` (auto or told) and each body's noise (mm; 0.000: exact samples)."""
    auto = dict(health_status(take_snapshot(10.0, 'n', ('ball', 'bat_pose'), TOPICS,
                                            _tally(10.0), DetectorStats(), None, '',
                                            dict(SETTINGS, tracker_noise=-1.0),
                                            (9.5e-4, 0.0)), {}).values())
    assert (auto['tracker_noise'], auto['ball_noise_mm'], auto['bat_noise_mm']) == (
        'auto', '0.950', '0.000')
    told = dict(health_status(take_snapshot(10.0, 'n', ('ball', 'bat_pose'), TOPICS,
                                            _tally(10.0), DetectorStats(), None, '',
                                            dict(SETTINGS, tracker_noise=5e-4),
                                            (5e-4, 5e-4)), {}).values())
    assert (told['tracker_noise'], told['ball_noise_mm'], told['bat_noise_mm']) == (
        'told', '0.500', '0.500')


def test_an_ended_session_is_idle_not_stale() -> None:
    """Every input silent past idle_timeout: OK 'idle'; before it: WARN stale; hardware_id."""
    settings = {**SETTINGS, 'idle_timeout': 30.0, 'hardware_id': 'cage_2_mocap'}
    stale = health_status(take_snapshot(20.0, 'n', ('ball', 'bat_pose'), TOPICS, _tally(10.0),
                                        DetectorStats(), None, '', settings), {})
    assert stale.level == Level.WARN and dict(stale.values())['state'] == 'stale'
    idle = health_status(take_snapshot(60.0, 'n', ('ball', 'bat_pose'), TOPICS, _tally(10.0),
                                       DetectorStats(), None, '', settings), {})
    assert idle.level == Level.OK and dict(idle.values())['state'] == 'idle'
    assert idle.message.startswith('idle: no input for 50 s')
    assert idle.hardware_id == 'cage_2_mocap'
