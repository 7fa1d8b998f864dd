"""Tests for the sweep's judgment of ball samples near the bat: glitches, hits after a gap."""

import itertools
import math
from typing import Any, List

from baseball_collision.core.detector import Detector, DetectorConfig, Impact, sweep_ball
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np
import pytest
from support.events import ball_lost_before, detect_late_drops, hit_after_gap, on_bat_axis


def _impacts(events: List[Any]) -> List[Any]:
    return [event for event in events if isinstance(event, Impact)]


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
        lost, _ = hit_after_gap(seed, 1, rate)
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
