"""Tests for the sweep's judgment of ball samples: what a glitch's speed drops become."""

from dataclasses import replace
import itertools
import math
from typing import Any, List, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, Impact, sweep_ball
from baseball_collision.core.detector.chunks import ROLE_CODES
from baseball_collision.core.detector.sweep_ball import ASIDE_MAX
from baseball_collision.core.motion.flight import fit_flight
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np
import pytest
from support.events import ball_lost_before, detect_late_drops, on_bat_axis


def _without_frame(samples: Any, k: int) -> Any:
    """Return ``samples`` (``sim.sample``) without ball sample k."""
    return replace(samples, ball_stamps_ns=np.delete(samples.ball_stamps_ns, k),
                   ball_positions=np.delete(samples.ball_positions, k, axis=0))


def _hit_after_gap(seed: int, back: int, rate: float = 360.0) -> Tuple[Any, int]:
    """
    Return a rebound hit and the index of the ball's first sample after a tracking gap.

    The ball tracked again ``back`` frames before the contact's first frame after it (1: one
    frame before the contact), exact samples at ``rate`` (Hz).
    """
    rng = np.random.default_rng(seed)
    scenario = make_scenario('barrel', rng, family='rebound', lead_s=0.4, trail_s=0.1)
    samples = sample(scenario, rate, rng)
    after = int(np.searchsorted(samples.ball_stamps_ns, samples.start_ns + int(
        round(scenario.truth.time_s * 1e9))))
    lost = ball_lost_before(samples, after - back)
    return lost, int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[after - back]))


def _impacts(events: List[Any]) -> List[Any]:
    return [event for event in events if isinstance(event, Impact)]


@pytest.mark.parametrize('back', [3, 4])
def test_a_frame_the_speed_check_refused_after_a_glitch_is_judged_again(back: int) -> None:
    """
    A glitch (the first sample after a gap, on the bat's axis) and the good frame after it.

    The good frame is too far from the glitch to be reached at ``max_speed``: the speed check
    refused it, and it stayed dropped once the glitch was forgotten, so the hit a few frames
    on was found from one frame fewer (moved, or lost; good frames after it dropped as
    glitches). Kept aside, it is judged again against the stream without the glitch and
    taken: the impacts and the drops are those of the run without the glitch frame, to the
    bit, but the glitch's own ``ball_glitch`` drop.
    """
    refused = found = 0
    for seed, look_ahead in itertools.product(range(3), (0, 2)):
        lost, k = _hit_after_gap(seed, back)
        config = DetectorConfig(tracker_noise=0.0, look_ahead=look_ahead)
        glitched = on_bat_axis(lost, k)
        step = np.linalg.norm(glitched.ball_positions[k + 1] - glitched.ball_positions[k])
        refused += step > config.max_speed * 1e-9 * float(
            glitched.ball_stamps_ns[k + 1] - glitched.ball_stamps_ns[k])
        events, late = detect_late_drops(config, glitched)
        expected, late_without = detect_late_drops(config, _without_frame(lost, k))
        assert [(drop.reason, drop.stamp_ns) for drop in late] == \
            [('ball_glitch', lost.ball_stamps_ns[k])] + \
            [(drop.reason, drop.stamp_ns) for drop in late_without]
        assert _impacts(events) == _impacts(expected)
        found += len(_impacts(expected))
    assert refused and found  # (the speed check refused the frame after the glitch)


def test_a_frame_set_aside_is_dropped_once_the_walk_passes_it() -> None:
    """
    Samples refused against a newest sample that is no glitch are dropped, counted late.

    A ball that moves 2 m in one 360 Hz frame, near nothing: its first two frames there are
    refused against the frame before (the third in a row is taken: it really moved), each
    waits aside (no drop counted yet: the frame they were refused against may be a glitch
    still to be judged) and is counted as ``speed_limit`` once the walk passed it; at the
    recording's end, whatever still waits.
    """
    base, step = 1_700_000_000_000_000_000, 2_777_778
    for last in (40, 21):
        detector = Detector(DetectorConfig(tracker_noise=0.0))
        late = []
        for i in range(last):
            stamp = base + i * step
            detector.add_bat_pose(stamp, (5.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
            detector.add_ball(stamp + 1, (0.01 * i + (2.0 if i >= 20 else 0.0), 0.0, 1.0))
            late += detector.stats.late_drops
            if i == 20:
                assert detector.stats.last_drop_reason is None and not detector.stats.dropped
        detector.finish()
        late += detector.stats.late_drops
        assert [(drop.reason, drop.stamp_ns) for drop in late] == \
            [('speed_limit', base + i * step + 1) for i in range(20, min(last, 22))]
        assert detector.stats.dropped == {'speed_limit': min(last, 22) - 20}
    assert ASIDE_MAX >= 2


def test_a_rebound_hit_tracked_again_a_frame_before_the_contact_loses_no_frame() -> None:
    """
    A genuine rebound hit, the ball tracked again one frame before the contact: no drop.

    The parabola through the segment's first sample (before the contact) and the two after
    it (after it) is no free flight; the next frame leaves it, with no contact found on that
    parabola, and was dropped as a ``ball_glitch`` (a departure no contact explains), and the
    two after it in turn. The first sample left the flight after it
    (``Sweep._hit_after_start``): no frame is dropped.
    """
    for seed, rate, look_ahead in itertools.product(range(2), (90.0, 360.0), (0, 2)):
        lost, _ = _hit_after_gap(seed, 1, rate)
        events, late = detect_late_drops(DetectorConfig(look_ahead=look_ahead), lost)
        assert late == [], (seed, rate, look_ahead)


@pytest.mark.parametrize('back', [1, 2])
def test_a_rebound_hit_tracked_again_just_before_the_contact_is_found(back: int) -> None:
    """
    A rebound hit, the ball tracked again one or two frames before the contact: found.

    The sweep has no flight before the contact (a segment's first or second sample) and lost
    it, or found it late. Solved from that sample and the flight after it
    (``Sweep._hit_before_flight``): within 0.1 ms of the truth, and within two of its
    reported sigmas; without the rule (``early_glitches`` False) not found within 0.1 ms.
    """
    for seed, rate, look_ahead in itertools.product(range(2), (120.0, 360.0), (0, 2)):
        rng = np.random.default_rng(seed)
        scenario = make_scenario('barrel', rng, family='rebound', lead_s=0.4, trail_s=0.1)
        samples = sample(scenario, rate, rng)
        truth = samples.start_ns + int(round(scenario.truth.time_s * 1e9))
        after = int(np.searchsorted(samples.ball_stamps_ns, truth))
        lost = ball_lost_before(samples, after - back)
        config = DetectorConfig(tracker_noise=0.0, look_ahead=look_ahead)
        found = []
        for judged in (True, False):
            detector = Detector(config)
            detector._sweep.early_glitches = judged
            events = []
            for stamp, role, values in lost.messages():
                events += detector.add(role, stamp, values)
            found.append(_impacts(events + detector.finish()))
        (impact,), unjudged = found
        error = abs(impact.stamp_ns - truth)
        assert error < 100_000 and error <= 2e9 * impact.time_uncertainty_s, (seed, rate)
        assert all(abs(other.stamp_ns - truth) > 100_000 for other in unjudged)


def test_a_rebound_hit_after_a_short_gap_is_solved_on_the_flight_before_it(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A rebound hit at 90 Hz, the ball lost 80 ms until one frame before the contact: found.

    The ball pushed off the bat from that frame (``departure.HitApproach``) never touches the
    sweep's bat, which brakes after the contact (nor the bat continued from before it), in
    these cases; the flight before the gap, continued over it through that frame
    (``BallSamples._flight_across_gap``), meets it within 0.1 ms of the contact. Without it
    none is found within 2 ms.
    """
    def errors(across: bool) -> List[int]:
        if not across:
            monkeypatch.setattr(sweep_ball.BallSamples, '_flight_across_gap',
                                lambda self, k, ta, tb: None)
        off = []
        for kind, seed in (('barrel', 7), ('end_cap', 7), ('end_cap', 2007)):
            rng = np.random.default_rng(seed)
            scenario = make_scenario(kind, rng, family='rebound')
            samples = sample(scenario, 90.0, rng, jitter_s=2e-4, grid_s=1e-3)
            truth = samples.start_ns + int(round(scenario.truth.time_s * 1e9))
            first = int(np.searchsorted(samples.ball_stamps_ns, truth)) - 1
            lost = ball_lost_before(samples, first, 0.08)
            for look_ahead in (0, 2):
                events, _ = detect_late_drops(DetectorConfig(look_ahead=look_ahead), lost)
                off.append(min((abs(impact.stamp_ns - truth) for impact in _impacts(events)),
                               default=10**9))
        return off

    assert max(errors(True)) < 100_000
    assert min(errors(False)) > 2_000_000


def test_a_rebound_hit_after_a_long_gap_is_solved_on_the_flight_kept_before_it(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A rebound hit at 90 Hz, the ball lost 150 ms until one frame before the contact: found.

    The trim behind the walk took the samples before the gap (the fits keep 0.15 s), so the
    flight before it is the one kept when the gap ended (``BallSamples.note_gap``,
    ``_kept_gap_flight``): continued over the gap through that frame, it meets the bat within
    0.1 ms of the contact, in the node (look-ahead 0) and ``analyze`` (2) alike, chunked or
    not. Without it, the pushed point alone (``departure.HitApproach``) finds none of these
    within 2 ms.
    """
    def errors(kept: bool) -> List[int]:
        if not kept:
            monkeypatch.setattr(sweep_ball.BallSamples, '_kept_gap_flight',
                                lambda self, first, k: None)
        off = []
        for kind, seed in (('barrel', 7), ('end_cap', 7), ('end_cap', 2007), ('end_cap', 5007)):
            rng = np.random.default_rng(seed)
            scenario = make_scenario(kind, rng, family='rebound', lead_s=0.35)
            samples = sample(scenario, 90.0, rng, jitter_s=2e-4, grid_s=1e-3)
            truth = samples.start_ns + int(round(scenario.truth.time_s * 1e9))
            first = int(np.searchsorted(samples.ball_stamps_ns, truth)) - 1
            lost = ball_lost_before(samples, first, 0.15)
            for look_ahead in (0, 2):
                config = DetectorConfig(bat_input='pose', look_ahead=look_ahead)
                events, _ = detect_late_drops(config, lost)
                off.append(min((abs(impact.stamp_ns - truth) for impact in _impacts(events)),
                               default=10**9))
                if kept:
                    assert _chunked(config, lost) == events
        return off

    assert max(errors(True)) < 100_000
    assert min(errors(False)) > 2_000_000


def test_the_flight_before_a_gap_drifts_by_the_jerk_bound_and_no_further() -> None:
    """
    ``_gap_bias``: a flight whose acceleration changes at ``GAP_FLIGHT_JERK`` the whole time.

    Its parabola over 0.15 s at 90 Hz, continued, is off it by exactly that drift (whatever the
    parabola it adds to): 2.2 cm 0.15 s after the window's newest sample, past a ball's radius
    (``GAP_FLIGHT_BIAS``, where ``_kept_gap_flight`` keeps no flight) between 0.18 and 0.2 s.
    """
    times = np.arange(-0.15, 1e-9, 1.0 / 90.0)
    jerk = sweep_ball.GAP_FLIGHT_JERK * np.array([0.6, -0.8, 0.0])

    def flight(t: Any) -> Any:
        t = np.asarray(t, dtype=float)[..., None]
        return (np.array([1.0, -20.0, 1.5]) + np.array([3.0, -38.0, -2.0]) * t
                + np.array([0.5, 9.0, -9.8]) * t * t / 2 + jerk * t ** 3 / 6)

    fit = fit_flight(times, flight(times), 1e-3)
    for t in (0.05, 0.15, 0.18, 0.2, 0.3):
        drift = float(np.linalg.norm(np.array(fit.at(t)) - flight(t)))
        assert sweep_ball._gap_bias(fit, t) == pytest.approx(drift, rel=1e-6)
    assert 0.021 < sweep_ball._gap_bias(fit, 0.15) < 0.023
    assert sweep_ball._gap_bias(fit, 0.18) < sweep_ball.GAP_FLIGHT_BIAS < sweep_ball._gap_bias(
        fit, 0.2)


def _chunked(config: DetectorConfig, samples: Any) -> List[Any]:
    """Return the events of ``samples`` fed through ``add_chunk`` in chunks of 7, 50 and 400."""
    rows = samples.messages(config.bat_input)
    detector, events, i, k = Detector(config), [], 0, 0
    while i < len(rows):
        part = rows[i:i + (7, 50, 400)[k % 3]]
        values = np.zeros((len(part), 7))
        for row, (_, _, value) in enumerate(part):
            values[row, :len(value)] = value
        events += detector.add_chunk([ROLE_CODES[role] for _, role, _ in part],
                                     [stamp for stamp, _, _ in part], values,
                                     ['world'] * len(part))
        i, k = i + len(part), k + 1
    return events + detector.finish()


def test_a_rebound_hit_three_frames_after_a_short_gap_leaves_the_flight_before_it(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A rebound hit at 90 Hz with 1 mm of noise, the ball lost 80 ms until three frames before.

    Under auto noise the departure test calls no departure of the segment's fourth frame from
    the parabola of its first three (no interval before them to measure the scatter by), and
    the sweep's path from the third frame to the rebound's first never met the bat: lost, in
    these cases. The first three lie on the flight before the gap and the fourth leaves that
    flight (``BallSamples._solved_on_gap_flight``): its first contact is the impact, within
    0.3 ms of the truth; its ball speed that flight's. Without the rule none is found within
    2 ms.
    """
    def runs(judged: bool) -> List[Tuple[int, List[Any], int, float]]:
        if not judged:
            monkeypatch.setattr(sweep_ball.BallSamples, '_solved_on_gap_flight',
                                lambda self, k, ta, tb, paths, events: False)
        found = []
        for kind, seed in (('end_cap', 6007), ('handle', 5007), ('barrel', 6007)):
            rng = np.random.default_rng(seed)
            scenario = make_scenario(kind, rng, family='rebound')
            samples = sample(scenario, 90.0, rng, jitter_s=2e-4, grid_s=1e-3, noise_m=1e-3,
                             marker_spread_m=0.3)
            truth = samples.start_ns + int(round(scenario.truth.time_s * 1e9))
            first = int(np.searchsorted(samples.ball_stamps_ns, truth)) - 3
            lost = ball_lost_before(samples, first, 0.08)
            for look_ahead in (0, 2):
                config = DetectorConfig(bat_input='pose', look_ahead=look_ahead)
                impacts = _impacts(detect_late_drops(config, lost)[0])
                near = [impact for impact in impacts if abs(impact.stamp_ns - truth) < 2_000_000]
                found.append((len(impacts) - len(near), near, truth,
                              scenario.truth.ball_speed_mps))
        return found

    for invented, near, truth, speed in runs(True):
        assert invented == 0 and len(near) == 1
        assert abs(near[0].stamp_ns - truth) < 300_000
        assert abs(near[0].ball_speed_mps - speed) < 0.05 * speed
    assert all(not near for _, near, _, _ in runs(False))


def test_a_first_sample_off_the_flight_before_the_gap_is_a_glitch(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A rebound hit, the ball lost 80 ms until two frames before the contact, the first a glitch.

    The glitch (6 or 10 cm from the bat's axis) is off the flight before the gap, the next
    frame on it: dropped (``BallSamples._off_gap_flight``) before the frames after it are
    judged, and the impacts are those with the glitch deleted. Without it the next, good,
    frame was dropped as a glitch (it looked off the flight after it) and the hit lost.
    """
    def runs(judged: bool) -> List[Tuple[List[int], List[int]]]:
        if not judged:
            monkeypatch.setattr(sweep_ball.BallSamples, '_off_gap_flight',
                                lambda self, k, ta: False)
        found = []
        for seed, distance, look_ahead in itertools.product((7, 1007), (0.06, 0.1), (0, 2)):
            rng = np.random.default_rng(seed)
            scenario = make_scenario('barrel', rng, family='rebound')
            samples = sample(scenario, 90.0, rng, jitter_s=2e-4, grid_s=1e-3)
            truth = samples.start_ns + int(round(scenario.truth.time_s * 1e9))
            first = int(np.searchsorted(samples.ball_stamps_ns, truth)) - 2
            lost = ball_lost_before(samples, first, 0.08)
            k = int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[first]))
            config = DetectorConfig(look_ahead=look_ahead)
            stamps = [[impact.stamp_ns for impact in _impacts(detect_late_drops(config, run)[0])]
                      for run in (on_bat_axis(lost, k, distance), _without_frame(lost, k))]
            assert len(stamps[1]) == 1 and abs(stamps[1][0] - truth) < 100_000
            found.append(stamps)
        return found

    assert all(glitched == deleted for glitched, deleted in runs(True))
    assert all(glitched != deleted for glitched, deleted in runs(False))


def test_a_first_sample_glitch_beside_a_miss_after_a_gap_makes_no_impact() -> None:
    """
    A miss tracked again after a gap, its first sample 6-10 cm from the bat's axis: no impact.

    That sample leaves the flight after it, which misses the bat: dropped as a glitch
    (``Sweep._first_glitch``) before the hit the rule solves from such a sample and the flight
    after it (``Sweep._hit_before_flight``) could be made of it.
    """
    for seed, rate, distance in itertools.product(range(3), (90.0, 360.0), (0.06, 0.1)):
        rng = np.random.default_rng(seed)
        scenario = make_scenario('miss_under', rng, family='rebound', lead_s=0.4, trail_s=0.1)
        samples = sample(scenario, rate, rng)
        closest = int(np.searchsorted(samples.ball_stamps_ns, samples.start_ns + int(
            round(scenario.truth.min_gap_time_s * 1e9))))
        lost = ball_lost_before(samples, closest - 1)
        k = int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[closest - 1]))
        for look_ahead in (0, 2):
            events, late = detect_late_drops(DetectorConfig(look_ahead=look_ahead),
                                             on_bat_axis(lost, k, distance))
            assert _impacts(events) == [], (seed, rate, distance)


def test_a_glitch_before_a_rebound_hit_times_no_hit_from_it(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A rebound hit tracked again one frame before the contact, that frame a glitch.

    The glitch, 6 or 10 cm from the bat's axis, is the only frame before the contact, and the
    flight after it, continued back to it, touches the bat (a hit: it is kept). The push a
    hit would need between them is across the contact normal (``FRICTION``): no hit is solved
    from it (``Sweep._pushed``), as with the frame missing. Without that test one was, 3-4 ms
    early, where the ball was lost 0.2 s (no flight before the gap in the kept history);
    lost 80 ms, the glitch is off the flight before the gap too, and dropped
    (``BallSamples._first_glitch``) whatever the friction.
    """
    def impacts_off(friction: float, lost_s: float = 0.2) -> List[int]:
        monkeypatch.setattr(sweep_ball, 'FRICTION', friction)
        off = []
        for distance in (0.06, 0.1):
            rng = np.random.default_rng(2007)
            scenario = make_scenario('barrel', rng, family='rebound')
            samples = sample(scenario, 90.0, rng, jitter_s=2e-4, grid_s=1e-3)
            truth = samples.start_ns + int(round(scenario.truth.time_s * 1e9))
            first = int(np.searchsorted(samples.ball_stamps_ns, truth)) - 1
            lost = ball_lost_before(samples, first, lost_s)
            k = int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[first]))
            events, _ = detect_late_drops(DetectorConfig(tracker_noise=0.0),
                                          on_bat_axis(lost, k, distance))
            off += [abs(impact.stamp_ns - truth) for impact in _impacts(events)
                    if abs(impact.stamp_ns - truth) > 2_000_000]
        return off

    assert impacts_off(sweep_ball.FRICTION) == []
    assert impacts_off(math.inf) != []
    assert impacts_off(math.inf, 0.08) == []
