"""Tests for baseball_collision.core.detector: events, streams, bad input, configuration."""

import math
from typing import Callable, List

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.detector import (
    Detector, DetectorConfig, DROP_REASONS, Impact, NearMiss, StateReset, StreamGap)
from baseball_collision.core.detector import sweep_impact as impact_module
from baseball_collision.errors import CoreError
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np
import pytest
from support.scenes import BASE_NS, first_contact, LENGTH, pitch, pose, swing


def feed(detector: Detector, ball: Callable[[float], np.ndarray], rate: float = 360.0,
         duration: float = 0.2, bat_as: str = 'points', tip_delay_s: float = 0.0,
         skip: Callable[[float], bool] = lambda t: False) -> List:
    """Publish the swing and the ball at ``rate`` into the detector; return every event."""
    events = []
    for i in range(int(duration * rate)):
        t = i / rate
        if skip(t):
            continue
        stamp = BASE_NS + int(round(t * 1e9))
        events += detector.add_ball(stamp, ball(t), 'world')
        if bat_as == 'pose':
            position, quaternion = pose(t)
            events += detector.add_bat_pose(stamp, position, quaternion, 'world')
        else:
            knob, _ = swing(t)
            _, tip = swing(t + tip_delay_s)
            events += detector.add_knob(stamp, knob, 'world')
            events += detector.add_tip(stamp + int(round(tip_delay_s * 1e9)), tip, 'world')
    return events + detector.finish()


def impacts(events: List) -> List[Impact]:
    """Return the impacts among events."""
    return [e for e in events if isinstance(e, Impact)]


@pytest.fixture(scope='module')
def truth_s() -> float:
    """Return the exact first-contact time of the hitting pitch (seconds from the start)."""
    t = first_contact(pitch())
    assert t is not None
    return t


@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline'])
@pytest.mark.parametrize('bat_as', ['points', 'pose'])
def test_one_impact_at_the_right_instant(model: str, bat_as: str, truth_s: float) -> None:
    """A hit at 360 Hz gives exactly one impact, stamped within 50 us of the truth."""
    detector = Detector(DetectorConfig(model=model, bat_input=bat_as))
    events = feed(detector, pitch(), bat_as=bat_as)
    found = impacts(events)
    assert len(found) == 1, events
    impact = found[0]
    assert abs((impact.stamp_ns - BASE_NS) * 1e-9 - truth_s) < 50e-6
    assert impact.interval_start_ns <= impact.stamp_ns <= impact.interval_end_ns
    assert impact.model == model
    assert impact.distance_from_knob_m + impact.distance_from_tip_m == pytest.approx(
        math.dist(impact.knob, impact.tip))
    assert math.dist(impact.knob, impact.tip) == pytest.approx(LENGTH, rel=0.002)
    # the sweet spot turns at omega(t) about hands moving at 2 m/s along y
    omega = 30.0 + 200.0 * truth_s
    knob, tip = swing(truth_s)
    direction = (tip - knob) / LENGTH
    sweet = (LENGTH - 0.1524) * omega * np.array([-direction[1], direction[0], 0.0]) + [0, 2, 0]
    assert impact.sweet_spot_speed_mps == pytest.approx(np.linalg.norm(sweet), rel=0.01)
    assert impact.ball_velocity == pytest.approx((0.0, -40.0, 0.0), abs=1e-4)  # ns stamps
    assert impact.attack_angle_deg == pytest.approx(0.0, abs=1e-6)
    assert impact.relative_normal_speed_mps > 0.0
    assert impact.velocities_from_history and not impact.bat_at_rest
    assert not [e for e in events if isinstance(e, NearMiss)]


@pytest.mark.parametrize('model', ['rigid', 'c2'])
def test_on_contact_tells_each_impact_before_its_velocities(
        model: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    ``on_contact``: each impact's stamp and point, in order, before its velocities are fitted.

    (The node sends ``~/impact`` from it: the velocities' fits are most of an impact's message.
    Its error bars deferred, as the node's, so no re-solve fits velocities of its own.)
    """
    told: List = []
    for name in ('c2_velocities', 'fit_velocities'):
        fit = getattr(impact_module, name)
        monkeypatch.setattr(impact_module, name, lambda *args, fit=fit: (
            told.append('velocities'), fit(*args))[1])
    detector = Detector(DetectorConfig(model=model, bat_input='pose'), deferred_uncertainty=True,
                        on_contact=lambda stamp_ns, point: told.append((stamp_ns, point)))
    events = []
    for height in (1.0, 1.09, 1.0):  # a hit, a near miss, a hit
        events += feed(detector, pitch(height), bat_as='pose')
        detector.reset()
    found = impacts(events)
    assert len(found) == 2 and told == [step for impact in found for step in (
        (impact.stamp_ns, impact.point), 'velocities')]


def test_near_miss_under_the_ball(truth_s: float) -> None:
    """The bat passing 2 cm under the ball is a near miss with an upward gap vector."""
    ball = pitch(height=1.09)
    assert first_contact(ball) is None
    detector = Detector(DetectorConfig(bat_input='points'))
    events = feed(detector, ball)
    misses = [e for e in events if isinstance(e, NearMiss)]
    assert not impacts(events) and len(misses) == 1
    miss = misses[0]
    assert miss.gap_m == pytest.approx(0.09 - 0.0366 - WOOD_BAT_34.max_radius, abs=2e-4)
    assert miss.gap_vector[2] == pytest.approx(miss.gap_m, abs=1e-3)
    assert abs((miss.stamp_ns - BASE_NS) * 1e-9 - truth_s) < 2e-3


def test_far_pass_is_nothing() -> None:
    """A ball far above the bat gives no event at all."""
    assert feed(Detector(DetectorConfig(bat_input='points')), pitch(height=2.0)) == []


def test_knob_and_tip_on_different_stamps(truth_s: float) -> None:
    """Tip stamped 1 ms after the knob: paired by interpolation, impact still on time."""
    detector = Detector(DetectorConfig(model='linear', bat_input='points'))
    found = impacts(feed(detector, pitch(), tip_delay_s=0.001))
    assert len(found) == 1
    assert abs((found[0].stamp_ns - BASE_NS) * 1e-9 - truth_s) < 100e-6


def test_streams_at_different_rates_with_uneven_steps(truth_s: float) -> None:
    """Ball at 360 Hz on a millisecond grid (steps of 2 and 3 ms), bat at 120 Hz."""
    detector = Detector(DetectorConfig(model='rigid', bat_input='pose'))
    events = []
    ball = pitch()
    ball_times = sorted({round(i / 360.0, 3) for i in range(72)})
    bat_times = [i / 120.0 for i in range(24)]
    assert {round(b - a, 3) for a, b in zip(ball_times[:-1], ball_times[1:])} == {0.002, 0.003}
    merged = sorted([(t, 'ball') for t in ball_times] + [(t, 'bat') for t in bat_times])
    for t, kind in merged:
        stamp = BASE_NS + int(round(t * 1e9))
        if kind == 'ball':
            events += detector.add_ball(stamp, ball(t))
        else:
            events += detector.add_bat_pose(stamp, *pose(t))
    found = impacts(events + detector.finish())
    assert len(found) == 1
    assert abs((found[0].stamp_ns - BASE_NS) * 1e-9 - truth_s) < 200e-6


def test_gap_longer_than_max_gap_is_not_interpolated() -> None:
    """Dropping 60 ms around the impact: a StreamGap, and no impact invented across it."""
    detector = Detector(DetectorConfig(max_gap=0.05, bat_input='points'))
    events = feed(detector, pitch(), skip=lambda t: 0.03 < t < 0.09)
    assert not impacts(events)
    gaps = [e for e in events if isinstance(e, StreamGap)]
    assert gaps and detector.stats.gaps == len(gaps)
    assert all(g.end_ns - g.start_ns > 50_000_000 for g in gaps)


def test_bad_samples_are_dropped_and_counted_by_reason(truth_s: float) -> None:
    """Every kind of bad sample is dropped with its reason; the real hit still comes once."""
    config = DetectorConfig(model='rigid', bat_input='points', frame_id='world')
    detector = Detector(config)
    ball = pitch()
    events = []
    t_bad = 0.02
    for i in range(72):
        t = i / 360.0
        stamp = BASE_NS + int(round(t * 1e9))
        knob, tip = swing(t)
        events += detector.add_ball(stamp, ball(t), 'world')
        events += detector.add_knob(stamp, knob, 'world')
        events += detector.add_tip(stamp, tip, 'world')
        if abs(t - t_bad) < 1.5 / 360.0 and t <= t_bad:
            later = stamp + 1_000_000
            events += detector.add_ball(later, [math.nan, 0.0, 1.0], 'world')  # non_finite
            events += detector.add_ball(stamp, ball(t), 'world')  # duplicate_stamp
            events += detector.add_ball(stamp - 1_000_000, ball(t), 'world')  # out_of_order
            events += detector.add_ball(later, ball(t), 'camera')  # wrong_frame
            events += detector.add_ball(later, ball(t) + [0.0, 0.0, 5.0], 'world')  # speed
            events += detector.add_bat_pose(later, knob, [0, 0, 0, 1], 'world')  # unexpected
            events += detector.add_knob(later, knob, 'world')
            events += detector.add_tip(later, knob + [0.0, 0.0, 1e-4], 'world')  # zero length
            events += detector.add_knob(later + 1, knob, 'world')
            events += detector.add_tip(later + 1, knob + [0.0, 0.0, 0.5], 'world')  # length
    events += detector.finish()
    dropped = detector.stats.dropped
    for reason in ('non_finite', 'duplicate_stamp', 'out_of_order', 'wrong_frame',
                   'speed_limit', 'unexpected_input', 'zero_length_bat', 'bat_length_jump'):
        assert dropped[reason] >= 1, (reason, dict(dropped))
    assert set(dropped) <= set(DROP_REASONS)
    found = impacts(events)
    assert len(found) == 1
    assert abs((found[0].stamp_ns - BASE_NS) * 1e-9 - truth_s) < 100e-6


@pytest.mark.parametrize('rate', [90.0, 360.0])
@pytest.mark.parametrize('tip_delay_s', [0.0, 0.001])
@pytest.mark.parametrize('lost', ['tip', 'knob'])
def test_a_bat_point_lost_as_nan_is_one_drop_and_not_paired_across(
        lost: str, tip_delay_s: float, rate: float, truth_s: float) -> None:
    """
    One knob or tip NaN mid-swing: one drop (``non_finite``), the other end never paired across.

    Its other end is a good sample of a bad frame: paired with a point interpolated on the
    chord across the lost frame (at 90 Hz 11 cm inside the bat's length) it was dropped a
    second time, as ``bat_length_jump``, on the call of a good sample after it (at 360 Hz kept,
    7 mm short). Now the bat has no sample in the lost frame's interval, as with a lost pose,
    and the hit is still found, once.
    """
    detector = Detector(DetectorConfig(bat_input='points'))
    ball, lost_at = pitch(), round(truth_s * rate) - 1  # the frame just before the contact
    delay_ns = int(round(tip_delay_s * 1e9))
    events, reasons = [], []
    for i in range(int(0.2 * rate)):
        t = i / rate
        stamp = BASE_NS + int(round(t * 1e9))
        knob, _ = swing(t)
        _, tip = swing(t + tip_delay_s)
        if i == lost_at:
            knob, tip = (np.full(3, math.nan), tip) if lost == 'knob' else (knob, [math.nan] * 3)
        for role, stamp_ns, values in (('ball', stamp, ball(t)), ('knob', stamp, knob),
                                       ('tip', stamp + delay_ns, tip)):
            events += detector.add(role, stamp_ns, values, 'world')
            reasons.append(detector.stats.last_drop_reason)
    events += detector.finish()
    assert [reason for reason in reasons if reason is not None] == ['non_finite']
    assert {k: v for k, v in detector.stats.dropped.items() if v} == {'non_finite': 1}
    offset = delay_ns if lost == 'tip' else 0  # no bat sample between the lost one's neighbours
    before, after = (BASE_NS + int(round(i / rate * 1e9)) + offset for i in (lost_at - 1,
                                                                             lost_at + 1))
    assert not [stamp for stamp in detector._bat.stamps if before < stamp < after]
    assert tip_delay_s or all(abs(math.dist(sample.knob, sample.tip) - LENGTH) < 1e-9
                              for sample in detector._bat.values)  # (only samples as sent)
    found = impacts(events)
    assert len(found) == 1
    assert abs((found[0].stamp_ns - BASE_NS) * 1e-9 - truth_s) < 1e-3


def test_bad_quaternions_are_dropped() -> None:
    """Zero, non-unit and non-finite quaternions never reach the motion model."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    for stamp, q in enumerate([(0, 0, 0, 0), (0, 0, 0, 2), (0, 0, math.inf, 1)]):
        assert detector.add_bat_pose(BASE_NS + stamp, (0, 0, 1), q) == []
    assert detector.stats.dropped['bad_quaternion'] == 2
    assert detector.stats.dropped['non_finite'] == 1


@pytest.mark.parametrize('bat_input, call, said', [
    ('pose', lambda d: d.add('ball', BASE_NS, (0.0, 1.0), 'world'),
     r'ball values must be 3 numbers \(x, y, z\) in m, got 2 values: \(0.0, 1.0\)'),
    ('points', lambda d: d.add('knob', BASE_NS, (0.0, 1.0, 2.0, 3.0), 'world'),
     'knob values must be 3 numbers .* got 4 values'),
    ('pose', lambda d: d.add('bat_pose', BASE_NS, (0.0, 0.0, 1.0, 0.0, 0.0, 1.0), 'world'),
     r'bat_pose values must be 7 numbers \(px, py, pz\) in m and a unit quaternion '
     r'\(qx, qy, qz, qw\), got 6 values'),
    ('pose', lambda d: d.add('bat_pose', BASE_NS, ((0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0))),
     'bat_pose values must be 7 numbers .* got 2 values'),
    ('pose', lambda d: d.add_bat_pose(BASE_NS, (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), 'world'),
     r'a unit quaternion of 4 \(x, y, z, w\), got 3 numbers: \(0.0, 0.0, 1.0\) and 3 values'),
    ('points', lambda d: d.add_ball(BASE_NS, ['a', 0, 0]),
     r"got 3 values, not all numbers: \['a', 0, 0\]"),
    ('points', lambda d: d.add_tip(BASE_NS, None), 'tip values must be 3 numbers .* NoneType'),
    ('pose', lambda d: d.add_ball(BASE_NS, np.zeros((1, 3))), r'an array of shape \(1, 3\)'),
    ('pose', lambda d: d.add_ball(0, (0.0, 1.0)), 'got 2 values'),  # (before the bad stamp)
])
def test_values_not_the_roles_numbers_are_an_error_saying_what_came(
        bat_input: str, call: Callable[[Detector], object], said: str) -> None:
    """
    A ball of 2 numbers, a knob of 4, a quaternion of 3: a ``CoreError`` saying what is expected.

    A programming error, as a float stamp is (the node's messages fix the shapes): they were
    dropped as ``non_finite``, which sent the caller looking for NaNs. Nothing is counted.
    """
    detector = Detector(DetectorConfig(bat_input=bat_input))
    with pytest.raises(CoreError, match=said) as raised:
        call(detector)
    assert isinstance(raised.value.__cause__, (TypeError, ValueError))
    assert not detector.stats.received and not detector.stats.dropped
    assert detector.stats.last_drop_reason is None


@pytest.mark.parametrize('error', [np.linalg.LinAlgError, TypeError])
def test_an_error_past_the_value_checks_is_raised_not_counted_as_a_drop(
        error: type, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A failure inside the detection (a fit's linear algebra, a bug) reaches the caller.

    Only the sample's own values are judged ``non_finite`` when they are not numbers: an
    error the pipeline raises past those checks is not the sample's fault, and dropping the
    sample under that reason would lose the impact it completes without a word.
    """
    def fails(*args: object) -> None:
        raise error('the fit failed')

    monkeypatch.setattr(impact_module, 'c2_velocities', fails)
    detector = Detector(DetectorConfig(model='c2', bat_input='pose'))
    with pytest.raises(error, match='the fit failed'):
        feed(detector, pitch(), bat_as='pose')
    assert detector.stats.dropped['non_finite'] == 0


def test_time_jump_backwards_resets_and_detects_again(truth_s: float) -> None:
    """A bag that restarts: the jump back resets the state, and the replayed hit is found."""
    detector = Detector(DetectorConfig(bat_input='points', time_jump_reset=0.1))
    first = feed(detector, pitch(), duration=0.2)
    second = feed(detector, pitch(), duration=0.2)
    resets = [e for e in second if isinstance(e, StateReset)]
    assert len(resets) == 1 and resets[0].reason == 'time_jump_backwards'
    assert len(impacts(first)) == 1 and len(impacts(second)) == 1
    assert impacts(first)[0].stamp_ns == impacts(second)[0].stamp_ns


def test_small_reordering_is_dropped_not_reset() -> None:
    """A stamp 2 ms behind its stream is out of order, not a time jump."""
    detector = Detector(DetectorConfig())
    detector.add_ball(BASE_NS + 10_000_000, (0, 0, 0))
    assert detector.add_ball(BASE_NS + 8_000_000, (0, 0, 0)) == []
    assert detector.stats.dropped['out_of_order'] == 1 and detector.stats.resets == 0


def test_ball_starting_inside_the_bat_is_not_an_impact(truth_s: float) -> None:
    """Data that starts mid-contact has no first-contact time: nothing is invented."""
    detector = Detector(DetectorConfig(bat_input='points'))
    events = feed(detector, pitch(), skip=lambda t: t < truth_s + 0.003)
    assert not impacts(events)


def test_requested_reset_clears_state() -> None:
    """reset() returns its event, keeps the counters and forgets the streams."""
    detector = Detector(DetectorConfig(bat_input='points'))
    feed(detector, pitch(), duration=0.03)
    received = sum(detector.stats.received.values())
    event = detector.reset(BASE_NS, 'requested')
    assert event == StateReset(stamp_ns=BASE_NS, reason='requested')
    assert detector.watermark_ns is None and detector.stats.resets == 1
    assert sum(detector.stats.received.values()) == received


def test_teleport_starts_a_new_segment() -> None:
    """A ball that really jumps (new pitch) is accepted after three refusals."""
    detector = Detector(DetectorConfig(max_speed=100.0))
    for i in range(3):
        detector.add_ball(BASE_NS + i * 2_777_778, (0.0, 0.0, 1.0))
    for i in range(3, 7):
        detector.add_ball(BASE_NS + i * 2_777_778, (5.0, 18.0, 2.0))
    assert detector.stats.dropped['speed_limit'] == 2
    assert detector._ball.breaks[-2] and detector._ball.values[-1] == (5.0, 18.0, 2.0)


def test_stats_are_readable(truth_s: float) -> None:
    """Counters, processing time and the watermark are exposed for diagnostics."""
    detector = Detector(DetectorConfig(bat_input='points'))
    feed(detector, pitch())
    stats = detector.stats
    assert stats.received['ball'] == 72 and stats.received['knob'] == 72
    assert stats.impacts == 1 and stats.intervals == 71 and stats.substeps > 0
    assert 0.0 < stats.mean_processing_s <= stats.max_processing_s
    assert stats.last_processing_s > 0.0
    assert detector.watermark_ns == BASE_NS + int(round(71 / 360.0 * 1e9))


def test_spline_waits_for_the_next_sample_and_finish_flushes() -> None:
    """Spline processes up to the second-newest sample live; finish() does the rest."""
    detector = Detector(DetectorConfig(model='spline', bat_input='pose'))
    for i in range(4):
        stamp = BASE_NS + i * 10_000_000
        detector.add_ball(stamp, (3.0, 3.0, 3.0))
        detector.add_bat_pose(stamp, *pose(0.0))
    assert detector.watermark_ns == BASE_NS + 20_000_000
    detector.finish()
    assert detector.watermark_ns == BASE_NS + 30_000_000


# ----------------------------------------------------------------------------------------------
# configuration


@pytest.mark.parametrize('field, value', [
    ('model', 'cubic'), ('bat_input', 'laser'), ('ball_radius', -0.1), ('max_gap', 0.0),
    ('max_chord_error', math.nan), ('near_miss_threshold', -1.0), ('up_axis', (0, 0, 0))])
def test_bad_config_values_are_refused(field: str, value) -> None:
    """Each bad value raises CoreError naming the field."""
    with pytest.raises(CoreError, match=field):
        DetectorConfig(**{field: value})


def test_config_from_parameters() -> None:
    """Flat ROS-style parameters build the profile, the pose geometry and the thresholds."""
    config = DetectorConfig.from_parameters({
        'model': 'spline', 'max_gap': 1, 'bat_profile': [0.0, 0.02, 0.5, 0.03, 0.8, 0.03],
        'bat_length': 0.8, 'bat_axis': '-x', 'knob_offset': 0.1, 'tip_offset': 0.9,
        'up_axis': [0, 2, 0], 'node_only_parameter': 'ignored'})
    assert config.model == 'spline' and config.max_gap == 1.0
    assert config.profile.segments() == ((0.0, 0.625, 0.02, 0.03), (0.625, 1.0, 0.03, 0.03))
    assert config.geometry.tip_offset == (-0.9, 0.0, 0.0)
    assert config.up_axis == (0.0, 1.0, 0.0)
    capsule = DetectorConfig.from_parameters({'bat_radius': 0.03})
    assert capsule.profile.segments() == ((0.0, 1.0, 0.03, 0.03),)
    assert DetectorConfig.from_parameters({}).profile == WOOD_BAT_34


@pytest.mark.parametrize('parameters, word', [
    ({'bat_profile': [0.0, 0.02, 0.5]}, 'pairs'), ({'bat_axis': 'w'}, 'axis'),
    ({'max_gap': 'soon'}, 'parameter'), ({'bat_profile': [0.5, 0.02, 0.1, 0.03]}, 'increase')])
def test_bad_parameters_are_refused(parameters: dict, word: str) -> None:
    """Malformed bat parameters raise CoreError with a reason."""
    with pytest.raises(CoreError, match=word):
        DetectorConfig.from_parameters(parameters)


def test_reconfigure_takes_thresholds_and_refuses_the_rest() -> None:
    """Thresholds change on a running detector; the model or the bat input do not."""
    detector = Detector(DetectorConfig())
    detector.reconfigure(DetectorConfig(near_miss_threshold=0.3, max_gap=0.1))
    assert detector.config.near_miss_threshold == 0.3 and detector.config.max_gap == 0.1
    with pytest.raises(CoreError, match='model'):
        detector.reconfigure(DetectorConfig(model='spline'))
    with pytest.raises(CoreError, match='bat_input'):
        detector.reconfigure(DetectorConfig(bat_input='points'))
    assert detector.config.model == 'c2'
    # auto noise: to a told value and back (the estimates go on), but not to auto from a told
    # value it started with (no estimates were kept)
    detector.reconfigure(DetectorConfig(tracker_noise=1e-3))
    detector.reconfigure(DetectorConfig(tracker_noise=-1.0))
    told = Detector(DetectorConfig(tracker_noise=0.0))
    told.reconfigure(DetectorConfig(tracker_noise=1e-3))
    assert 'tracker_noise' in told.refusal(DetectorConfig(tracker_noise=-1.0))
    with pytest.raises(CoreError, match='tracker_noise .to auto.*restart'):
        told.reconfigure(DetectorConfig(tracker_noise=-1.0))
    assert told.config.tracker_noise == 1e-3 and detector.refusal(detector.config) is None


def test_add_by_role_dispatches_like_the_typed_calls(truth_s: float) -> None:
    """``add(role, ...)`` gives the same impact as the typed calls; unknown roles raise."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    events = []
    ball = pitch()
    for i in range(72):
        t = i / 360.0
        stamp = BASE_NS + int(round(t * 1e9))
        position, quaternion = pose(t)
        events += detector.add('ball', stamp, tuple(ball(t)), 'world')
        events += detector.add('bat_pose', stamp, tuple(position) + tuple(quaternion), 'world')
    typed = feed(Detector(DetectorConfig(bat_input='pose')), pitch(), bat_as='pose')
    assert impacts(events + detector.finish()) == impacts(typed)
    with pytest.raises(CoreError, match='role'):
        detector.add('glove', BASE_NS, (0, 0, 0))


def test_frame_and_last_drop_reason_are_exposed() -> None:
    """The first frame seen is provisional until every stream sends it; then others drop."""
    detector = Detector(DetectorConfig())
    assert detector.frame_id is None
    detector.add_ball(BASE_NS, (0.0, 0.0, 1.0), 'mocap')
    assert detector.frame_id == 'mocap' and detector.stats.last_drop_reason is None
    detector.add_bat_pose(BASE_NS, *pose(0.0), 'mocap')  # both streams agree
    detector.add_ball(BASE_NS + 1, (0.0, 0.0, 1.0), 'camera')
    assert detector.stats.last_drop_reason == 'wrong_frame'
    detector.reset()
    assert detector.frame_id is None
    assert Detector(DetectorConfig(frame_id='world')).frame_id == 'world'


def _arrived(messages: List, lead: str, lag: int) -> List:
    """Return the messages with the ``lead`` body's stream ``lag`` samples ahead of the other."""
    first = [m for m in messages if (m[1] == 'ball') == (lead == 'ball')]
    second = [m for m in messages if (m[1] == 'ball') != (lead == 'ball')]
    order, j = [], 0
    for i, message in enumerate(first):
        order.append(message)
        while j < len(second) and j < i - lag:
            order.append(second[j])
            j += 1
    return order + second[j:]


@pytest.mark.parametrize('model, noise, rate, ball_rate', [
    ('rigid', 0.0, 180.0, None), ('c2', 0.0, 180.0, None), ('rigid', 3e-4, 180.0, None),
    ('c2', 3e-4, 180.0, None), ('c2', 0.0, 1000.0, 60.0), ('c2', 3e-4, 1000.0, 60.0)])
def test_the_same_impacts_whatever_order_the_streams_arrive_in(
        model: str, noise: float, rate: float, ball_rate: float) -> None:
    """
    The node's two streams can arrive skewed: the impacts are ``analyze``'s all the same.

    Real hits (the ball leaves the bat, its sigma holds the brake) of bat poses at 180 Hz (the
    ball too) or 1 kHz (a 60 Hz ball), exact or with 0.3 mm of noise the detector estimates
    (``tracker_noise`` auto, the default), the bat's or the ball's stream ahead of the other by
    up to 20 samples: the same impacts with the same uncertainties, to the bit up to 5 samples
    ahead, and to 1e-9 at 20 (the bat's summed turns then restart from another sample:
    rounding). The roll rate once fitted every sample its stream still held, an impact's
    re-solves took whatever samples had come after it (then what the slower stream held), and
    a sweep read each stream's noise estimate as of its newest sample: each moved with the
    order.
    """
    rng = np.random.default_rng(5)
    messages = []
    for i, kind in enumerate(('barrel', 'handle', 'end_cap')):
        scenario = make_scenario(kind, rng, family='rebound')
        samples = sample(scenario, rate, rng, jitter_s=2e-4, grid_s=1e-3, noise_m=noise,
                         marker_spread_m=0.3 if noise else None, ball_rate_hz=ball_rate,
                         start_ns=BASE_NS + i * 2_000_000_000)
        messages += samples.messages('pose')

    def impacts(order: List) -> List[Impact]:
        detector = Detector(DetectorConfig(model=model, tracker_noise=-1.0))
        events = [e for stamp, role, values in order for e in detector.add(role, stamp, values)]
        return [e for e in events + detector.finish() if isinstance(e, Impact)]

    expected = impacts(messages)
    assert len(expected) == 3 and all(e.time_uncertainty_s > 0.0 for e in expected)
    for lead in ('bat', 'ball'):
        for lag in (0, 2, 5):
            assert impacts(_arrived(messages, lead, lag)) == expected, (lead, lag)
        found = impacts(_arrived(messages, lead, 20))
        assert [e.stamp_ns for e in found] == [e.stamp_ns for e in expected]
        for got, want in zip(found, expected):
            for name in ('bat_velocity', 'bat_angular_velocity', 'sweet_spot_velocity'):
                assert getattr(got, name) == pytest.approx(getattr(want, name), rel=1e-9)
            for name in ('time_uncertainty_s', 'distance_from_knob_uncertainty_m',
                         'sweet_spot_speed_uncertainty_mps'):
                assert getattr(got, name) == pytest.approx(getattr(want, name), rel=1e-9)


@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline', 'c2'])
def test_positions_at_are_the_paths_through_the_samples(model: str) -> None:
    """
    positions_at: the ball and bat ends at a sample's stamp are the sample's; between, near.

    None before any sample and beyond the samples; between two 360 Hz samples of the swing,
    within 3 mm of the continuous motion (the chords of ``linear`` cut 1.4 mm inside the arc).
    """
    detector = Detector(DetectorConfig(model=model, bat_input='pose'))
    assert detector.positions_at(BASE_NS) is None
    stamps = [BASE_NS + int(round(i / 360.0 * 1e9)) for i in range(40)]
    for i, stamp in enumerate(stamps):
        detector.add_ball(stamp, tuple(pitch(3.0)(i / 360.0)), 'world')  # (far above: no hit)
        detector.add_bat_pose(stamp, *pose(i / 360.0), 'world')
    ball, knob, tip = detector.positions_at(stamps[10])
    assert np.allclose(ball, pitch(3.0)(10 / 360.0), atol=1e-9)
    assert np.allclose(knob, swing(10 / 360.0)[0], atol=1e-9)
    assert np.allclose(tip, swing(10 / 360.0)[1], atol=1e-9)
    middle = (stamps[20] + stamps[21]) // 2
    t = (middle - BASE_NS) * 1e-9
    ball, knob, tip = detector.positions_at(middle)
    assert math.dist(ball, pitch(3.0)(t)) < 1e-6
    assert math.dist(knob, swing(t)[0]) < 3e-3 and math.dist(tip, swing(t)[1]) < 3e-3
    assert detector.positions_at(stamps[-1] + 10**9) is None


def test_a_stamp_that_is_not_integer_nanoseconds_is_refused() -> None:
    """A float stamp (seconds, or epoch ns a double cannot hold) raises; it was truncated."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    for stamp in (1.7e9, 1.5, BASE_NS * 1.0, '1700000000000000000', True):
        with pytest.raises(CoreError, match='integer number of nanoseconds'):
            detector.add_ball(stamp, (0.0, 0.0, 1.0), 'world')
        with pytest.raises(CoreError, match='integer number of nanoseconds'):
            detector.reset(stamp)
    assert detector.add_ball(np.int64(BASE_NS), (0.0, 0.0, 1.0), 'world') == []
    assert detector.stats.received == {'ball': 1} and not detector.stats.dropped
    with pytest.raises(CoreError, match='bad bat plan'):
        detector.set_bat_plan([BASE_NS * 1.0, BASE_NS + 1e6], [(0, 0, 1)] * 2,
                              [(0, 0, 0, 1)] * 2)
    with pytest.raises(CoreError, match='3 finite numbers'):
        detector.set_bat_plan([BASE_NS, BASE_NS + 1_000_000], [(0, 0, 1), (0, float('nan'), 1)],
                              [(0, 0, 0, 1)] * 2)
    with pytest.raises(CoreError, match='3 finite numbers'):
        detector.set_bat_plan(np.array([BASE_NS, BASE_NS + 1_000_000]), np.zeros((2, 2)),
                              np.tile([0.0, 0.0, 0.0, 1.0], (2, 1)))
    detector.set_bat_plan(np.array([], dtype=np.int64), [], [])  # clears, as [] does
    for stamps in (None, 7, [BASE_NS, None]):
        with pytest.raises(CoreError, match='bad bat plan'):
            detector.set_bat_plan(stamps, [], [])


def test_a_frame_id_that_is_not_a_str_is_refused() -> None:
    """A frame given as bytes or a number raises ``CoreError`` (it raised AttributeError)."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    for frame in (b'world', 7):
        with pytest.raises(CoreError, match='frame_id must be a str'):
            detector.add_ball(BASE_NS, (0.0, 0.0, 1.0), frame)
        with pytest.raises(CoreError, match='frame_id must be a str'):
            detector.add_chunk(np.zeros(40, np.int8), BASE_NS + np.arange(40) * 10**7,
                               np.ones((40, 7)), [frame] * 40)
    assert detector.add_ball(BASE_NS, (0.0, 0.0, 1.0), None) == []
    assert detector.stats.received == {'ball': 1} and not detector.stats.dropped


def test_the_configuration_is_set_with_reconfigures_checks() -> None:
    """``detector.config = ...`` refuses what ``reconfigure`` refuses (it took a new input)."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    with pytest.raises(CoreError, match='bat_input cannot change while running'):
        detector.config = DetectorConfig(bat_input='points')
    with pytest.raises(CoreError, match='DetectorConfig'):
        detector.config = {'bat_input': 'pose'}
    detector.config = DetectorConfig(bat_input='pose', near_miss_threshold=0.2)
    assert detector.config.near_miss_threshold == 0.2


@pytest.mark.parametrize('family', ['plane', 'jerky', 'braking', 'rebound'])
@pytest.mark.parametrize('rate, noise_m', [(90.0, 0.0), (120.0, 1e-3)])
def test_departures_made_ahead_change_no_event(family: str, rate: float, noise_m: float) -> None:
    """
    ``departures_ahead`` after every message (as the node after its drain): the same events.

    To the bit and in order, predictions (0.3 s) included, with a bat frame turned 20 cm at
    the tip toward the ball two frames before the approach (a glitch). (A departure made ahead
    serves only at its very noise: exact samples, whose noise estimate stays 0, or a told
    ``tracker_noise``; ``test_bat_glitches`` checks the serving.)
    """
    rng = np.random.default_rng(7)
    scenario = make_scenario('barrel', rng, lead_s=0.4, family=family)
    samples = sample(scenario, rate, rng, noise_m=noise_m, jitter_s=2e-4)
    approach = samples.start_ns + int(scenario.truth.time_s * 1e9)
    j = int(np.argmin(np.abs(samples.bat_stamps_ns - approach))) - 2
    nearest = int(np.argmin(np.abs(samples.ball_stamps_ns - samples.bat_stamps_ns[j])))
    config = DetectorConfig(prediction_horizon=0.3)
    for feed in (samples, samples.with_bat_frame_turned(j, samples.ball_positions[nearest],
                                                        0.2)):
        runs, made = [], 0
        for ahead in (False, True):
            detector, events = Detector(config), []
            for stamp, role, values in feed.messages():
                events += detector.add(role, stamp, values)
                if ahead:
                    made += detector.departures_ahead()
            runs.append(repr(events + detector.finish()))
        assert runs[0] == runs[1] and made > 0


def test_a_bat_plan_is_taken_in_the_tracking_frame_only() -> None:
    """
    ``take_bat_plan``: the node's and ``analyze``'s rule, one place.

    Before any tracking frame is known a plan naming a frame cannot be checked (refused; one
    naming none is taken); with ``frame_id`` set, another frame is refused and its own taken;
    what ``set_bat_plan`` raises is the reason; an empty plan clears.
    """
    stamps = [1_000_000_000 + i * 5_000_000 for i in range(4)]
    positions = [(0.0, 0.01 * i, 1.0) for i in range(4)]
    quaternions = [(0.0, 0.0, 0.0, 1.0)] * 4
    loose = Detector(DetectorConfig(prediction_horizon=0.3))
    assert 'cannot be checked: no tracking frame is known yet' in loose.take_bat_plan(
        stamps, positions, quaternions, {'world'})
    assert loose._predictor.plan is None
    assert loose.take_bat_plan(stamps, positions, quaternions) is None
    assert loose._predictor.plan is not None
    framed = Detector(DetectorConfig(prediction_horizon=0.3, frame_id='world'))
    assert framed.take_bat_plan(stamps, positions, quaternions, {'arm_base'}) == (
        "frame ['arm_base'] is not the tracking frame 'world'")
    assert framed.take_bat_plan(stamps, positions, quaternions, {'world'}) is None
    assert 'bad bat plan' in framed.take_bat_plan(stamps[::-1], positions, quaternions)
    assert framed.take_bat_plan([], [], [], {'world'}) is None
    assert framed._predictor.plan is None
