"""Tests for a hit's report: the bat continued from before a hit (``SweepImpact._bat_ahead``)."""

from typing import Any

from baseball_collision.core.detector import DetectorConfig, sweep_impact
from baseball_collision.core.detector.sweep import Sweep
from baseball_collision.core.detector.sweep_impact import braked_miss
from baseball_collision.core.motion import BatSample
from baseball_collision.tools.sim import CLOSE_KINDS, KINDS, make_scenario, sample
import numpy as np
import pytest
from support.events import detect


def test_a_hits_bat_is_continued_only_from_samples_that_pass_the_quintic_check(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Untold noise on a 1 kHz bat fails the quintic check: its hit's bat is not continued.

    An end-cap hit, the ball at 120 Hz, 0.3 mm of noise the detector is not told of: the bat's
    closing frame left the continuation of its noisy samples by 4 times what the frame before
    did, and the cubic continued from them put the impact 335 us early (without the check, as
    before it); through the braked frame it is 20 us late. Without noise: within microseconds.
    """
    rng = np.random.default_rng(7)
    scenarios = [make_scenario(kind, rng, family='rebound', lead_s=0.15)
                 for kind in KINDS + CLOSE_KINDS for _ in range(4)]
    scenario = scenarios[5]
    assert scenario.kind == 'end_cap'
    taken = []
    bat_ahead = Sweep._bat_ahead

    def counted(self: Sweep, *args: Any) -> Any:
        found = bat_ahead(self, *args)
        if self.bat_ahead is None:
            taken.append(found is not None)
        return found

    def error(noise: float) -> float:
        samples = sample(scenario, 1000.0, np.random.default_rng(5), jitter_s=2e-4, grid_s=1e-3,
                         noise_m=noise, marker_spread_m=0.3 if noise else None,
                         ball_rate_hz=120.0)
        taken.clear()
        untold = DetectorConfig(model='c2', bat_input='points', tracker_noise=0.0)
        _, impacts = detect(untold, samples)
        assert len(impacts) == 1
        return (impacts[0].stamp_ns - samples.start_ns) * 1e-9 - scenario.truth.time_s

    monkeypatch.setattr(Sweep, '_bat_ahead', counted)
    assert abs(error(3e-4)) < 1e-4 and not any(taken)
    assert abs(error(0.0)) < 5e-6
    monkeypatch.setattr(sweep_impact, 'quintic_check', lambda *args: None)  # no check: as before
    assert error(3e-4) < -3e-4 and any(taken)


def test_a_hit_at_a_high_rate_takes_the_bat_from_before() -> None:
    """
    At 360 Hz a hit's bat comes from before its closing frame (which has braked): microseconds.

    The braking family's closing frame after the contact makes its impact late by tens of
    microseconds; continued from before the hit (``fitting.c2_bat_ahead``), ``c2`` is within
    3 us on barrel and handle hits of the rebound family.
    """
    errors = []
    for kind in ('barrel', 'handle'):
        rng = np.random.default_rng(11)
        for _ in range(4):
            scenario = make_scenario(kind, rng, family='rebound')
            samples = sample(scenario, 360.0, rng, jitter_s=2e-4, grid_s=1e-3)
            _, impacts = detect(DetectorConfig(model='c2', bat_input='points'), samples)
            errors.append(abs((impacts[0].stamp_ns - samples.start_ns) * 1e-9
                              - scenario.truth.time_s))
    assert max(errors) < 3e-6


def test_the_bat_is_continued_only_where_it_braked_off_its_continuation() -> None:
    """
    Exact samples: most hits' bats are continued; noisy ones (noise not told): most are not.

    With 1 mm of noise the continuation's own frame before misses by millimetres, about as
    much as most brakes: continuing noisy samples over a frame would be the larger error. (An
    exact bat that hardly braked is not continued either: its frame is on its path.)
    """
    taken = {0.0: 0, 1e-3: 0}
    for noise_m in taken:
        for seed in range(8):
            scenario = make_scenario('barrel', np.random.default_rng(seed), family='rebound')
            samples = sample(scenario, 120.0, np.random.default_rng(seed), jitter_s=2e-4,
                             grid_s=1e-3, noise_m=noise_m,
                             marker_spread_m=0.3 if noise_m else None)
            detector, impacts = detect(DetectorConfig(model='c2', bat_input='points'), samples)
            swept, clock = detector._sweep, detector._sweep.clock
            interval = (clock.time(impacts[0].interval_start_ns),
                        clock.time(impacts[0].interval_end_ns))
            paths = swept.paths(detector._ball.interval(interval[0]),
                                detector._bat.interval(interval[0]))
            taken[noise_m] += swept._bat_ahead(interval, paths) is not None
    assert taken[0.0] >= 6 and taken[1e-3] <= 2


def test_braked_miss_takes_the_continuations_own_miss_off_the_closing_frames() -> None:
    """
    ``braked_miss``: the continuation's miss at the opening frame, carried a step, is not a brake.

    A closing frame off its continuation by just what the opening frame was off its own (the
    steps even) has not braked: no miss left. One that lags by 5 mm more along the swing has:
    5 mm, on the opening frame's scale. The carried miss grows as the squared ratio of the steps.
    """
    knob, tip = (0.0, 0.0, 0.0), (0.0, 0.8, 0.0)
    missed = ((0.0, 0.0, -0.002), (0.003, 0.8, 0.0))  # continued to the opening frame
    opening = BatSample(knob, tip)  # its knob 2 mm above that, its tip 3 mm behind
    continued = ((0.1, 0.0, 0.0), (0.5, 0.8, 0.0))  # continued to the closing frame
    on_its_own = BatSample((0.1, 0.0, 0.002), (0.497, 0.8, 0.0))
    braked = BatSample((0.1, 0.0, 0.002), (0.492, 0.8, 0.0))
    even = (0.0, 0.01, 0.02)
    assert braked_miss(even, (opening, on_its_own), missed, continued) == pytest.approx(
        (0.0, 0.003), abs=1e-12)
    assert braked_miss(even, (opening, braked), missed, continued) == pytest.approx(
        (0.005, 0.003), abs=1e-12)
    # the closing step twice the one before: the own miss carried 4 times (the tip 12 mm behind
    # its continuation where the frame is 3 mm behind: 9 mm off it)
    longer = (0.0, 0.01, 0.03)
    assert braked_miss(longer, (opening, on_its_own), missed, continued)[0] == pytest.approx(
        0.009, abs=1e-12)


def test_a_hits_bat_is_continued_where_its_closing_frame_braked_beyond_its_own_miss() -> None:
    """
    90 Hz, exact: a barrel hit whose closing bat frame the brake left 4 times its own miss off.

    The bat's continuation from before the interval misses each next frame of a free swing by
    1-5 mm at 90 Hz, mostly the same way from frame to frame (the accelerating swing ahead of
    it). Here the opening frame was 3.3 mm off its own continuation and the closing frame 12.9
    mm off the interval's, 3.9 times: the impact was solved through the braked frame, 99 us
    late. With the opening frame's miss carried over and taken off, the closing frame is 4.9
    times off (the brake's share): the continuation is taken, and the impact is within 35 us.
    """
    rng = np.random.default_rng(7)
    scenario = [make_scenario(kind, rng, family='rebound', lead_s=0.15)
                for kind in KINDS + CLOSE_KINDS for _ in range(4)][0]
    assert scenario.kind == 'barrel'
    samples = sample(scenario, 90.0, np.random.default_rng(0), jitter_s=2e-4, grid_s=1e-3)
    for look_ahead in (0, 2):
        config = DetectorConfig(model='c2', bat_input='points', tracker_noise=-1.0,
                                look_ahead=look_ahead)
        _, impacts = detect(config, samples)
        assert len(impacts) == 1
        error = (impacts[0].stamp_ns - samples.start_ns) * 1e-9 - scenario.truth.time_s
        assert abs(error) < 3.5e-5
