"""
Tests for the detector's intake: the faults a real rig produces (issue 12, items 1-5).

A second publisher on an old clock, a lone stamp glitched ahead, a stray first frame, a bad
frame, a lost mocap body and a dead tracker: each through the whole ``Detector`` (the node and
``analyze`` drive the same one), each against the swing and pitch of ``support.scenes`` with
its exact first contact.
"""

import random
from typing import Any, Callable, List

from baseball_collision.core.detector import (
    Detector, DetectorConfig, Impact, PendingUncertainty, StateReset, StreamGap)
from baseball_collision.core.detector.gate import JUMP_CONFIRM
from baseball_collision.core.detector.streams import SILENT_AFTER, SILENT_KEEP
import pytest
from support.scenes import BASE_NS, first_contact, pitch, pose, swing

RATE = 360.0
SECOND = 10**9


@pytest.fixture(scope='module')
def truth_ns() -> int:
    """Return the exact first contact of the hitting pitch as a stamp (ns)."""
    t = first_contact(pitch())
    assert t is not None
    return BASE_NS + int(round(t * 1e9))


def stamp_of(i: int, rate: float = RATE) -> int:
    """Return the stamp (ns) of sample i."""
    return BASE_NS + int(round(i / rate * 1e9))


def run(detector: Detector, extra: Callable[[Detector, int, float], List] = lambda d, i, t: [],
        ball_stamp: Callable[[int], int] = stamp_of, bat_stamp: Callable[[int], int] = stamp_of,
        frame: str = 'world') -> List[Any]:
    """Feed the 0.2 s swing (pose) and pitch at 360 Hz with ``extra`` offers; every event."""
    events: List[Any] = []
    for i in range(72):
        t = i / RATE
        events += detector.add_ball(ball_stamp(i), pitch()(t), frame)
        events += detector.add_bat_pose(bat_stamp(i), *pose(t), frame)
        events += extra(detector, i, t)
    return events + detector.finish()


def impacts(events: List[Any]) -> List[Impact]:
    """Return the impacts among events."""
    return [event for event in events if isinstance(event, Impact)]


def one_impact_at(events: List[Any], truth_ns: int) -> Impact:
    """Return the one impact, checked within 50 us of the truth."""
    found = impacts(events)
    assert len(found) == 1, found
    assert abs(found[0].stamp_ns - truth_ns) < 50_000
    return found[0]


# ---- 1: a stale second publisher -----------------------------------------------------------


def test_a_stale_second_publisher_is_dropped_not_a_jump(truth_ns: int) -> None:
    """A replay left running 3 s behind on the ball topic: its samples drop, nothing resets."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    events = run(detector, lambda d, i, t: d.add_ball(stamp_of(i) - 3 * SECOND, pitch()(t),
                                                      'world'))
    one_impact_at(events, truth_ns)
    assert detector.stats.resets == 0 and not [e for e in events if isinstance(e, StateReset)]
    assert dict(detector.stats.dropped) == {'stale_stamp': 72}


def test_a_stale_publisher_first_does_not_take_the_stream(truth_ns: int) -> None:
    """
    The replay 3 s behind was running first (the node restarted): its ball comes before each.

    The first ball sample is on the stale clock; the good one after it steps 3 s ahead of its
    stream but not of the bat's clock: it is no lone glitch (found by the fault benchmark:
    every good ball sample was dropped as ``stamp_ahead``, no impact ever).
    """
    detector = Detector(DetectorConfig(bat_input='pose'))
    events: List[Any] = []
    for i in range(72):
        t = i / RATE
        events += detector.add_ball(stamp_of(i) - 3 * SECOND, pitch()(t), 'world')
        events += detector.add_ball(stamp_of(i), pitch()(t), 'world')
        events += detector.add_bat_pose(stamp_of(i), *pose(t), 'world')
    one_impact_at(events + detector.finish(), truth_ns)
    assert detector.stats.resets == 0
    assert dict(detector.stats.dropped) == {'stale_stamp': 71}  # all but the first, taken


def test_random_stamps_on_a_second_publisher_never_reset(truth_ns: int) -> None:
    """A second publisher with stamps anywhere within +-1000 s: drops only, the hit found."""
    rng = random.Random(7)
    detector = Detector(DetectorConfig(bat_input='pose'))
    events = run(detector, lambda d, i, t: [] if i == 71 else d.add_ball(
        stamp_of(i) + rng.randint(-1000 * SECOND, 1000 * SECOND), pitch()(t), 'world'))
    one_impact_at(events, truth_ns)
    assert detector.stats.resets == 0
    dropped = detector.stats.dropped
    assert dropped['stale_stamp'] + dropped['stamp_ahead'] + dropped['out_of_order'] == 71


def test_a_real_jump_back_resets_once_and_loses_nothing() -> None:
    """A looped recording: one reset, and the replayed pass gives the very same impact."""
    detector = Detector(DetectorConfig(bat_input='pose', time_jump_reset=0.1))
    first = run(detector)
    second = run(detector)
    resets = [e for e in second if isinstance(e, StateReset)]
    assert len(resets) == 1 and resets[0].reason == 'time_jump_backwards'
    assert resets[0].stamp_ns == BASE_NS  # the first sample of the loop, kept
    assert impacts(first) == impacts(second) and len(impacts(first)) == 1  # every field
    assert detector.stats.dropped == {}


def test_a_jump_back_needs_samples_in_a_row() -> None:
    """Fewer than JUMP_CONFIRM samples far behind, then the current clock: dropped, no reset."""
    detector = Detector(DetectorConfig())
    detector.add_ball(BASE_NS, (0.0, 0.0, 1.0))
    for k in range(JUMP_CONFIRM - 1):
        assert detector.add_ball(BASE_NS - 5 * SECOND + k, (0.0, 0.0, 1.0)) == []
        assert detector.stats.last_drop_reason is None  # waits
    detector.add_ball(BASE_NS + 1_000_000, (0.0, 0.0, 1.0))
    assert detector.stats.resets == 0
    assert [(d.reason, d.stamp_ns) for d in detector.stats.late_drops] == [
        ('stale_stamp', BASE_NS - 5 * SECOND + k) for k in range(JUMP_CONFIRM - 1)]
    for k in range(JUMP_CONFIRM):
        events = detector.add_ball(BASE_NS - 5 * SECOND + 100 + k, (0.0, 0.0, 1.0))
    assert [e.reason for e in events if isinstance(e, StateReset)] == ['time_jump_backwards']
    assert detector._ball.stamps == [BASE_NS - 5 * SECOND + 100 + k for k in range(JUMP_CONFIRM)]


@pytest.mark.parametrize('lone', ['after_a_reset', 'two_ahead'])
def test_a_stream_behind_its_own_lone_newest_comes_back(lone: str, truth_ns: int) -> None:
    """
    One stream's newest is a lone sample of another clock: a reset, then the pitch's hit.

    ``after_a_reset``: a looped recording, the node's reset at the ROS clock's jump back, and one
    bat sample of the old loop delivered after it (``replay --loop``); ``two_ahead``: two bat
    samples in a row glitched 5 s ahead. The bat's samples then wait far behind its newest
    while the ball's, on their clock, come in order. Those kept them from ever making the jump
    back: every bat sample was dropped as ``stale_stamp`` until the stamps overtook the lone
    one, the hit lost.
    """
    detector = Detector(DetectorConfig(bat_input='pose'))
    lone_stamps = [stamp_of(71) + 10 * SECOND] if lone == 'after_a_reset' else [
        stamp_of(3) + 5 * SECOND, stamp_of(4) + 5 * SECOND]
    events: List[Any] = []
    if lone == 'after_a_reset':
        run(detector)
        detector.reset(stamp_of(71), 'time_jump_backwards')
        detector.add_bat_pose(lone_stamps[0], *pose(0.2), 'world')  # a longer loop's last, late
    for i in range(72):
        t = i / RATE
        events += detector.add_ball(stamp_of(i), pitch()(t), 'world')
        if lone == 'two_ahead' and i in (3, 4):
            events += detector.add_bat_pose(lone_stamps[i - 3], *pose(t), 'world')
            continue
        events += detector.add_bat_pose(stamp_of(i), *pose(t), 'world')
    one_impact_at(events + detector.finish(), truth_ns)
    assert [e.reason for e in events if isinstance(e, StateReset)] == ['time_jump_backwards']
    assert 'stale_stamp' not in detector.stats.dropped


# ---- 2: one sample glitched ahead ----------------------------------------------------------


@pytest.mark.parametrize('ahead_s', [0.03, 0.2, 1.0, 30.0])
@pytest.mark.parametrize('role', ['ball', 'bat_pose'])
def test_a_lone_sample_glitched_ahead_is_dropped_and_the_hit_found(
        role: str, ahead_s: float, truth_ns: int) -> None:
    """One sample, just before the contact, stamped ahead: dropped alone; the hit is found."""
    glitched = 10  # 28 ms; the contact is at 33 ms

    def stamps(i: int) -> int:
        return stamp_of(i) + (int(ahead_s * 1e9) if i == glitched else 0)
    detector = Detector(DetectorConfig(bat_input='pose'))
    events = run(detector, **({'ball_stamp': stamps} if role == 'ball' else
                              {'bat_stamp': stamps}))
    one_impact_at(events, truth_ns)
    assert dict(detector.stats.dropped) == {'stamp_ahead': 1}
    assert detector.stats.resets == 0


def test_a_real_gap_waits_one_sample_and_is_kept() -> None:
    """A step far beyond the usual one waits for the next sample; after it, it is taken."""
    detector = Detector(DetectorConfig())
    for i in range(6):
        detector.add_ball(stamp_of(i), (0.0, 0.0, 1.0))
    late = stamp_of(5) + SECOND // 5  # a 200 ms gap
    detector.add_ball(late, (0.0, 0.0, 1.0))
    assert detector._ball.newest() == stamp_of(5)  # held
    detector.add_ball(late + 2_777_778, (0.0, 0.0, 1.0))
    assert detector._ball.stamps[-2:] == [late, late + 2_777_778]
    assert detector.stats.dropped == {}


def test_finish_takes_a_sample_still_held() -> None:
    """The last sample of a recording after a gap is not lost at the end."""
    detector = Detector(DetectorConfig())
    for i in range(6):
        detector.add_ball(stamp_of(i), (0.0, 0.0, 1.0))
    detector.add_ball(stamp_of(5) + SECOND // 5, (0.0, 0.0, 1.0))
    detector.finish()
    assert detector._ball.newest() == stamp_of(5) + SECOND // 5


# ---- 3: one silent stream ------------------------------------------------------------------


@pytest.mark.parametrize('bat_input', ['pose', 'points'])
def test_a_dead_tracker_keeps_memory_flat_and_the_hit_is_found(bat_input: str) -> None:
    """
    Ball at 1 kHz, the bat (or its tip) silent for 3 s: every buffer stays bounded; the hit.

    Bounded: ``SILENT_KEEP`` samples (``SILENT_AFTER`` s at least) plus the fits' history at
    1 kHz, not the 3000 samples of the silence, so memory and the walk when the bat comes back
    stay flat.
    """
    rate, start = 1000.0, 3.0  # the bat is silent from 50 ms to 3 s; then the swing
    detector = Detector(DetectorConfig(bat_input=bat_input))
    events: List[Any] = []
    largest = 0
    for i in range(int((start + 0.2) * rate)):
        t = i / rate
        stamp = stamp_of(i, rate)
        events += detector.add_ball(stamp, (0.6, 2.9 - 40.0 * (t - start), 1.0), 'world')
        alive = t < 0.05 or t >= start
        knob, tip = swing(max(t - start, 0.0))
        if bat_input == 'pose' and alive:
            events += detector.add_bat_pose(stamp, *pose(max(t - start, 0.0)), 'world')
        elif bat_input == 'points':  # the knob goes on, the tip tracker dies
            events += detector.add_knob(stamp, knob, 'world')
            if alive:
                events += detector.add_tip(stamp, tip, 'world')
        pairing = detector._pairing
        largest = max(largest, len(detector._ball.times), len(pairing.knob.times),
                      len(pairing.tip.times))
    events += detector.finish()
    assert largest < max(SILENT_AFTER * rate, SILENT_KEEP) + 0.2 * rate
    contact = first_contact(pitch())
    truth = BASE_NS + int(round((start + contact) * 1e9))
    assert len(impacts(events)) == 1 and abs(impacts(events)[0].stamp_ns - truth) < 100_000
    assert [e.stream for e in events if isinstance(e, StreamGap)] == ['bat']


def test_a_lagging_stream_loses_nothing() -> None:
    """
    A bat 1.5 s of stamps late (a loaded node, a fast replay): the events of an in-order feed.

    A lag is neither a dead tracker (``SILENT_KEEP``) nor a jump back: nothing is dropped.
    """
    rate, start, lag = 1000.0, 1.6, 1500

    def run(delay: int) -> List[Any]:
        detector = Detector(DetectorConfig())
        events: List[Any] = []
        total = int((start + 0.2) * rate)
        for i in range(total + delay):
            if i < total:
                t = i / rate
                events += detector.add_ball(stamp_of(i, rate),
                                            (0.6, 2.9 - 40.0 * (t - start), 1.0), 'world')
            j = i - delay
            if 0 <= j < total:
                events += detector.add_bat_pose(stamp_of(j, rate),
                                                *pose(max(j / rate - start, 0.0)), 'world')
        return events + detector.finish()
    in_order, lagging = run(0), run(lag)
    assert len(impacts(in_order)) == 1 and lagging == in_order


def test_a_tracker_never_seen_keeps_memory_flat() -> None:
    """Ball only, the bat never came: the ball keeps its own history, not every sample."""
    detector = Detector(DetectorConfig())
    for i in range(5000):
        detector.add_ball(stamp_of(i, 1000.0), (0.0, 0.0, 1.0))
    assert len(detector._ball.times) < max(SILENT_AFTER * 1000, SILENT_KEEP) + 200


# ---- 4: a lost mocap body ------------------------------------------------------------------


def _through_the_origin(detector: Detector, moving_bat: bool) -> List[Any]:
    """Feed a ball through x = 0 at 0.5 m up past a bat at the identity pose (or swinging)."""
    events: List[Any] = []
    for i in range(72):
        t = i / RATE
        events += detector.add_ball(stamp_of(i), (0.0, 1.5 - 20.0 * t, 0.5), 'world')
        position, quaternion = pose(t) if moving_bat else ((0.0, 0.0, 0.0), (0, 0, 0, 1.0))
        events += detector.add_bat_pose(stamp_of(i), position, quaternion, 'world')
    return events + detector.finish()


def test_a_bat_frozen_at_the_identity_pose_is_a_lost_body() -> None:
    """Mocap's lost body (origin, identity) is dropped for its own reason: no impact."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    assert not impacts(_through_the_origin(detector, moving_bat=False))
    assert dict(detector.stats.dropped) == {'lost_body': 72}


def test_a_hit_on_a_still_bat_is_flagged_at_rest() -> None:
    """Taken on purpose (drop_lost_body off), a hit on a bat that stood still is flagged."""
    detector = Detector(DetectorConfig(bat_input='pose', drop_lost_body=False))
    found = impacts(_through_the_origin(detector, moving_bat=False))
    assert len(found) == 1 and found[0].bat_at_rest
    assert found[0].sweet_spot_speed_mps == pytest.approx(0.0, abs=1e-9)
    off = Detector(DetectorConfig(bat_input='pose', drop_lost_body=False, rest_tolerance=0.0))
    assert [i.bat_at_rest for i in impacts(_through_the_origin(off, False))] == [False]
    deferred = Detector(DetectorConfig(bat_input='pose', drop_lost_body=False),
                        deferred_uncertainty=True)  # (the node's: the flag reaches the record)
    returned = impacts(_through_the_origin(deferred, moving_bat=False))
    (pending,) = [each for each in deferred.take_pending()
                  if isinstance(each, PendingUncertainty)]  # (the impact's, beside predictions')
    assert pending.impact is returned[0] and pending.measure() == found[0]


# ---- 5: the tracking frame -----------------------------------------------------------------


@pytest.mark.parametrize('stray', ['camera', 'wor', ''])
def test_a_stray_first_frame_is_not_adopted(stray: str, truth_ns: int) -> None:
    """One ball sample in another frame first (rclpy cuts a frame at a NUL: 'wor')."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    detector.add_ball(BASE_NS - 5_000_000, pitch()(-0.005), stray)
    one_impact_at(run(detector), truth_ns)
    assert detector.frame_id == 'world'
    assert detector.stats.dropped == {}
    assert detector.stats.resets == (1 if stray else 0)  # what the stray built is dropped


def test_the_first_frame_is_kept_when_the_streams_send_it() -> None:
    """Agreement on the first frame: later strays drop as wrong_frame (late, if they waited)."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    detector.add_ball(stamp_of(0), pitch()(0.0), 'world')
    detector.add_ball(stamp_of(1), pitch()(1 / RATE), 'camera')
    assert detector.stats.last_drop_reason is None  # waits for the vote
    detector.add_bat_pose(stamp_of(0), *pose(0.0), 'world')
    assert [(d.reason, d.frame_id) for d in detector.stats.late_drops] == [
        ('wrong_frame', 'camera')]
    detector.add_ball(stamp_of(2), pitch()(2 / RATE), 'camera')
    assert detector.stats.last_drop_reason == 'wrong_frame'


@pytest.mark.parametrize('frame', ['wor\x00ld', 'w\ufffdrld', 'world\n'])
def test_a_bad_frame_is_dropped_and_never_adopted(frame: str, truth_ns: int) -> None:
    """An embedded NUL (bags keep it), undecodable bytes (U+FFFD) or a newline: bad_frame."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    detector.add_ball(BASE_NS - 5_000_000, pitch()(-0.005), frame)
    assert detector.stats.last_drop_reason == 'bad_frame' and detector.frame_id is None
    one_impact_at(run(detector), truth_ns)
    assert dict(detector.stats.dropped) == {'bad_frame': 1}


def test_without_agreement_the_most_common_frame_wins() -> None:
    """The bat never comes: after FRAME_PENDING_MAX waiting, the majority frame is adopted."""
    detector = Detector(DetectorConfig())
    detector.add_ball(BASE_NS, (0.0, 0.0, 1.0), 'stray')
    for i in range(1, 40):
        detector.add_ball(stamp_of(i), (0.0, 0.0, 1.0), 'world')
    assert detector.frame_id == 'world' and detector.stats.resets == 1
    assert detector._ball.stamps[-1] == stamp_of(39) and len(detector._ball.stamps) == 39


def _swing_in_frames(detector: Detector, ball_frame: str, bat_frame: str,
                     bat_first: bool = False, later_ns: int = 0) -> List[Any]:
    """Feed the swing and pitch with the ball and the bat each in its own frame; the events."""
    events: List[Any] = []
    for i in range(72):
        t = i / RATE
        feeds = [lambda: detector.add_ball(stamp_of(i) + later_ns, pitch()(t), ball_frame),
                 lambda: detector.add_bat_pose(stamp_of(i) + later_ns, *pose(t), bat_frame)]
        for feed in feeds[::-1] if bat_first else feeds:
            events += feed()
    return events


@pytest.mark.parametrize('bat_first', [False, True])
def test_streams_in_two_frames_adopt_neither_until_they_agree(bat_first: bool,
                                                              truth_ns: int) -> None:
    """
    A bat in ``arm_base`` beside a ball in ``world`` (no TF): no frame is adopted, ever.

    The first stream's frame stays provisional; the other's samples wait, and beyond
    FRAME_PENDING_MAX the oldest is dropped as ``no_common_frame`` (the most common frame, the
    one the other stream never sent, was adopted and that stream dropped for good as
    ``wrong_frame``). ``frame_disagreement`` names each stream's frame. Once the bat is sent in
    the ball's frame, the frame is adopted and the next swing's impact found.
    """
    detector = Detector(DetectorConfig(bat_input='pose'))
    events = _swing_in_frames(detector, 'world', 'arm_base', bat_first)
    assert not impacts(events) and detector.stats.resets == 0
    assert dict(detector.stats.dropped) == {'no_common_frame': 72 - 32}
    assert detector.frame_disagreement == "ball sends 'world', bat_pose sends 'arm_base'"
    assert detector.frame_id == ('arm_base' if bat_first else 'world')  # provisional
    events = _swing_in_frames(detector, 'world', 'world', bat_first, SECOND)
    assert detector.frame_id == 'world' and detector.frame_disagreement is None
    one_impact_at(events + detector.finish(), truth_ns + SECOND)
    dropped = detector.stats.dropped  # the 32 waiting: the other frame's, or the stray's
    # the 32 waiting at agreement: the bat's in 'arm_base' (wrong_frame), or, the bat's frame
    # provisional, the ball's in 'world', taken after the reset (frame_changed)
    assert dropped == ({'no_common_frame': 40} if bat_first else
                       {'no_common_frame': 40, 'wrong_frame': 32})
    assert detector.stats.resets == (1 if bat_first else 0)


def test_two_frames_to_the_end_are_dropped_not_adopted() -> None:
    """At the end of a recording the samples waiting in the other frame are dropped too."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    events = _swing_in_frames(detector, 'world', 'arm_base') + detector.finish()
    assert not impacts(events)
    assert dict(detector.stats.dropped) == {'no_common_frame': 72}
    assert detector.frame_disagreement == "ball sends 'world', bat_pose sends 'arm_base'"


@pytest.mark.parametrize('stray_on', ['bat_pose', 'ball'])
def test_a_stream_sending_empty_frames_does_not_block_the_adoption(stray_on: str,
                                                                   truth_ns: int) -> None:
    """
    A ball publisher that never sets frame_id, a stray first frame (bat's or ball's): as before.

    The empty frame is taken as in any frame, so it never holds the vote up, nor does a stray
    on the stream that sends it: after FRAME_PENDING_MAX waiting the bat's frame is adopted
    (the stray's state reset: this swing's contact falls before it, as it did), and the next
    swing's impact is found in it.
    """
    detector = Detector(DetectorConfig(bat_input='pose'))
    if stray_on == 'ball':
        detector.add_ball(BASE_NS - 5_000_000, pitch()(-0.005), 'camera')
    else:
        detector.add_bat_pose(BASE_NS - 5_000_000, *pose(-0.005), 'camera')
    events = _swing_in_frames(detector, '', 'world')
    assert detector.frame_id == 'world' and detector.frame_disagreement is None
    events += _swing_in_frames(detector, '', 'world', later_ns=SECOND)
    one_impact_at(events + detector.finish(), truth_ns + SECOND)
    assert detector.stats.dropped == {} and detector.stats.resets == 1
