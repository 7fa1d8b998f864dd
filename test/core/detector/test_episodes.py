"""Tests for the detector's arming and near-miss episodes."""

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.detector import DetectorConfig, DetectorStats, NearMiss
from baseball_collision.core.detector.episodes import (
    bat_at_rest, EpisodeTracker, lowest_gap, State)
from baseball_collision.core.detector.gate import Clock
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample
from baseball_collision.core.toi import profile_gap
import pytest

KNOB, TIP = (0.0, 0.0, 1.0), (0.0, WOOD_BAT_34.length, 1.0)
BARREL_Y = 0.75  # m from the knob, on the barrel
BARREL_RADIUS = WOOD_BAT_34.segments()[-1][2]  # the barrel's capsule there


def _tracker():
    clock = Clock()
    clock.origin = 1_000_000_000
    stats = DetectorStats()
    return EpisodeTracker(DetectorConfig(), clock, stats), stats


def _ball(t: float, gap: float) -> tuple:
    """Return a ball passing the barrel along z at 20 m/s, ``gap`` (m) from it at t = 0."""
    return (BARREL_RADIUS + 0.0366 + gap, BARREL_Y, 1.0 + 20.0 * t)


def _pass(tracker: EpisodeTracker, gap: float, steps: int = 40) -> list:
    """Feed sub-steps of a pass from t = -0.02 s to 0.02 s; return the events."""
    events = []
    times = [-0.02 + 0.04 * j / steps for j in range(steps + 1)]
    states = [State(t, _ball(t, gap), KNOB, TIP) for t in times]
    gaps = [profile_gap(s.ball, KNOB, TIP, 0.0366, WOOD_BAT_34)[0] for s in states]
    for j in range(steps):
        if tracker.arm(gaps[j], times[j]):
            pass  # no contact in these passes
        tracker.track(states[j], states[j + 1], gaps[j], gaps[j + 1], events)
    return events


def test_arming_needs_the_ball_seen_clear() -> None:
    """Not armed until clear; disarmed by an impact until the ball separates by rearm."""
    tracker, _ = _tracker()
    assert tracker.arm(-0.01, 0.0) is None  # overlapping from the start: no first contact known
    assert tracker.arm(0.001, 0.001) is True
    tracker.impact(0.003)
    assert tracker.arm(0.05, 0.003) is False  # within rearm_distance (0.1 m)
    assert tracker.arm(0.2, 0.004) is True


def test_no_rearming_before_the_balls_next_frame() -> None:
    """
    After an impact, nothing before the ball's first frame after it re-arms.

    There the ball's path is its free flight continued through the contact (a departure), out
    beyond the bat: a bat tracked at a higher rate than the ball has intervals in between.
    """
    tracker, _ = _tracker()
    tracker.far([], 0.0)
    tracker.impact(0.010)  # the ball's next frame at 10 ms
    assert tracker.arm(0.2, 0.005) is False
    far_state, next_state = (State(t, _ball(t, 0.3), KNOB, TIP) for t in (0.005, 0.006))
    tracker.track(far_state, next_state, 0.3, 0.3, [])
    assert tracker.armed is False
    tracker.far([], 0.009)
    assert tracker.armed is False and not tracker.zone_clear
    tracker.far([], 0.010)  # from the frame on: a real sample, clear by rearm_distance
    assert tracker.armed is True and tracker.zone_clear
    tracker.impact(0.020)
    tracker.track(far_state, next_state, 0.3, 0.3, [])
    tracker.interrupted([])  # a gap: the streams start again, clear of the bat must be seen
    assert tracker.arm(0.001, 0.012) is True


def test_a_close_pass_is_one_near_miss_at_its_closest() -> None:
    """Into the threshold from outside, then out: one NearMiss with the smallest gap."""
    tracker, stats = _tracker()
    tracker.far([], -1.0)  # armed and clear of the zone
    events = _pass(tracker, 0.05)
    misses = [e for e in events if isinstance(e, NearMiss)]
    assert len(misses) == 1 and stats.near_misses == 1
    miss = misses[0]
    assert miss.gap_m == pytest.approx(0.05, abs=1e-9)
    assert miss.stamp_ns == pytest.approx(1_000_000_000, abs=1_000)  # closest at t = 0
    assert miss.gap_vector == pytest.approx((0.05, 0.0, 0.0), abs=1e-9)
    assert miss.distance_from_tip_m == pytest.approx(WOOD_BAT_34.length - BARREL_Y, abs=1e-9)
    assert tracker.episode is None


def test_no_near_miss_without_coming_in_from_outside() -> None:
    """A pass first seen inside the threshold (never clear of the zone) reports nothing."""
    tracker, stats = _tracker()
    tracker.armed = True  # armed, but the zone was never seen clear
    states = [State(t, _ball(t, 0.05), KNOB, TIP) for t in (-0.001, 0.0, 0.001)]
    events = []
    tracker.track(states[0], states[1], 0.06, 0.05, events)
    tracker.track(states[1], states[2], 0.05, 0.2, events)
    assert events == [] and stats.near_misses == 0


def test_an_impact_ends_the_episode_without_a_near_miss() -> None:
    """Contact during an episode: the pass was a hit, not a near miss."""
    tracker, stats = _tracker()
    tracker.far([], -1.0)
    states = [State(t, _ball(t, 0.05), KNOB, TIP) for t in (-0.002, -0.001)]
    tracker.track(states[0], states[1], 0.2, 0.1, [])
    assert tracker.episode is not None
    tracker.impact(0.0)
    events = []
    tracker.close(events)
    assert events == [] and stats.near_misses == 0


def test_a_gap_closes_the_episode_and_disarms() -> None:
    """A stream gap reports the open episode's near miss and needs the ball seen clear again."""
    tracker, stats = _tracker()
    tracker.far([], -1.0)
    events = []
    states = [State(t, _ball(t, 0.0), KNOB, TIP) for t in (-0.004, -0.002, 0.0)]
    gaps = [profile_gap(s.ball, KNOB, TIP, 0.0366, WOOD_BAT_34)[0] for s in states]
    tracker.track(states[0], states[1], 0.2, gaps[1], events)
    tracker.track(states[1], states[2], gaps[1], gaps[2] + 0.03, events)
    tracker.interrupted(events)
    assert tracker.armed is None and not tracker.zone_clear
    assert [type(e) for e in events] == [NearMiss] and stats.near_misses == 1


def test_lowest_gap_refines_the_closest_approach() -> None:
    """Golden-section search over a linear sub-step finds the analytic closest point."""
    start = State(-0.01, _ball(-0.01, 0.04), KNOB, TIP)
    end = State(0.03, _ball(0.03, 0.04), KNOB, TIP)
    lowest = lowest_gap(start, end, 0.0366, WOOD_BAT_34)
    assert lowest.t == pytest.approx(0.0, abs=1e-9)
    assert lowest.gap == pytest.approx(0.04, abs=1e-12)
    assert lowest.normal == pytest.approx((1.0, 0.0, 0.0), abs=1e-6)  # 40 golden steps
    assert lowest.fraction == pytest.approx(BARREL_Y / WOOD_BAT_34.length)
    assert (lowest.knob, lowest.tip) == (KNOB, TIP)


def _bat_stream(moves: float) -> Stream:
    """Return a bat at 360 Hz for 0.1 s whose knob and tip move ``moves`` m in all."""
    bat = Stream('bat')
    for i in range(36):
        shift = moves * i / 35
        bat.append(i / 360.0, i, BatSample(knob=(shift, 0.0, 1.0), tip=(shift, 0.86, 1.0)),
                   False)
    return bat


def test_a_bat_at_rest_stayed_within_the_tolerance() -> None:
    """Still (within 1 cm over the window): at rest; a swing, or too short a history: not."""
    assert bat_at_rest(_bat_stream(0.0), 0.09, 0.061, 0.01)
    assert bat_at_rest(_bat_stream(0.005), 0.09, 0.061, 0.01)  # 3 mm over the window
    assert not bat_at_rest(_bat_stream(0.5), 0.09, 0.061, 0.01)
    assert not bat_at_rest(_bat_stream(0.0), 0.01, 0.061, 0.01)  # 10 ms seen: unknown
