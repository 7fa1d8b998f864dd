"""Tests for the ball's flight before a tracking gap: hits solved on it, glitches off it."""

import itertools
from typing import Any, List, Tuple

from baseball_collision.core.detector import (
    Detector, DetectorConfig, gap_flight, Impact, sweep_ball)
from baseball_collision.core.motion.flight import fit_flight
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np
import pytest
from support.events import (
    arrays, ball_lost_before, detect_late_drops, on_bat_axis, without_ball_frame)


def _impacts(events: List[Any]) -> List[Any]:
    return [event for event in events if isinstance(event, Impact)]


def test_a_rebound_hit_after_a_short_gap_is_solved_on_the_flight_before_it(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A rebound hit at 90 Hz, the ball lost 80 ms until one frame before the contact: found.

    The ball pushed off the bat from that frame (``departure.HitApproach``) never touches the
    sweep's bat, which brakes after the contact (nor the bat continued from before it), in
    these cases; the flight before the gap, continued over it through that frame
    (``gap_flight.flight_across_gap``), meets it within 0.1 ms of the contact. Without it
    none is found within 2 ms.
    """
    def errors(across: bool) -> List[int]:
        if not across:
            monkeypatch.setattr(sweep_ball, 'flight_across_gap', lambda *args: None)
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
    ``flight_before_gap``; ``_on_kept_flight``): continued over the gap through that frame, it
    meets the bat within 0.1 ms of the contact, in the node (look-ahead 0) and ``analyze`` (2)
    alike, chunked or not. Without it, the pushed point alone (``departure.HitApproach``)
    finds none of these within 2 ms.
    """
    def errors(kept: bool) -> List[int]:
        if not kept:
            monkeypatch.setattr(gap_flight, '_on_kept_flight', lambda *args: None)
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
    ``gap_bias``: a flight whose acceleration changes at ``GAP_FLIGHT_JERK`` the whole time.

    Its parabola over 0.15 s at 90 Hz, continued, is off it by exactly that drift (whatever the
    parabola it adds to): 2.2 cm 0.15 s after the window's newest sample, past a ball's radius
    (``GAP_FLIGHT_BIAS``, where ``_on_kept_flight`` keeps no flight) between 0.18 and 0.2 s.
    """
    times = np.arange(-0.15, 1e-9, 1.0 / 90.0)
    jerk = gap_flight.GAP_FLIGHT_JERK * np.array([0.6, -0.8, 0.0])

    def flight(t: Any) -> Any:
        t = np.asarray(t, dtype=float)[..., None]
        return (np.array([1.0, -20.0, 1.5]) + np.array([3.0, -38.0, -2.0]) * t
                + np.array([0.5, 9.0, -9.8]) * t * t / 2 + jerk * t ** 3 / 6)

    fit = fit_flight(times, flight(times), 1e-3)
    for t in (0.05, 0.15, 0.18, 0.2, 0.3):
        drift = float(np.linalg.norm(np.array(fit.at(t)) - flight(t)))
        assert gap_flight.gap_bias(fit, t) == pytest.approx(drift, rel=1e-6)
    assert 0.021 < gap_flight.gap_bias(fit, 0.15) < 0.023
    assert gap_flight.gap_bias(fit, 0.18) < gap_flight.GAP_FLIGHT_BIAS < gap_flight.gap_bias(
        fit, 0.2)


def _chunked(config: DetectorConfig, samples: Any) -> List[Any]:
    """Return the events of ``samples`` fed through ``add_chunk`` in chunks of 7, 50 and 400."""
    rows = [(role, stamp, values, 'world')
            for stamp, role, values in samples.messages(config.bat_input)]
    detector, events, i, k = Detector(config), [], 0, 0
    while i < len(rows):
        part = rows[i:i + (7, 50, 400)[k % 3]]
        events += detector.add_chunk(*arrays(part))
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
    flight (``gap_flight.left_gap_flight``): its first contact is the impact, within
    0.3 ms of the truth; its ball speed that flight's. Without the rule none is found within
    2 ms.
    """
    def runs(judged: bool) -> List[Tuple[int, List[Any], int, float]]:
        if not judged:
            monkeypatch.setattr(sweep_ball, 'left_gap_flight', lambda *args: None)
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
    frame on it: dropped (``gap_flight.off_gap_flight``) before the frames after it are
    judged, and the impacts are those with the glitch deleted. Without it the next, good,
    frame was dropped as a glitch (it looked off the flight after it) and the hit lost.
    """
    def runs(judged: bool) -> List[Tuple[List[int], List[int]]]:
        if not judged:
            monkeypatch.setattr(sweep_ball, 'off_gap_flight', lambda *args: False)
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
                      for run in (on_bat_axis(lost, k, distance), without_ball_frame(lost, k))]
            assert len(stamps[1]) == 1 and abs(stamps[1][0] - truth) < 100_000
            found.append(stamps)
        return found

    assert all(glitched == deleted for glitched, deleted in runs(True))
    assert all(glitched != deleted for glitched, deleted in runs(False))
