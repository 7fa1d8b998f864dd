"""Tests for the sweep: an impact is the first contact of the paths, not of their chords."""

import math
from types import SimpleNamespace
from typing import List, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, Impact, sweep
from baseball_collision.core.detector.departure import FLIGHT_AFTER
from baseball_collision.core.detector.fitting import c2_window
from baseball_collision.core.geometry import norm, sub
from baseball_collision.core.motion import C2BatPath
from baseball_collision.core.toi import _kernel, profile_gap
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np
import pytest
from support.events import ball_lost_before, detect, on_bat_axis
from support.far import tilting_bat
from support.scenes import BASE_NS


def _impacts(config: DetectorConfig, seed: int, kind: str) -> Tuple[Detector, List[Impact]]:
    scenario = make_scenario(kind, np.random.default_rng(seed), family='tilted')
    return detect(config, sample(scenario, 90.0, np.random.default_rng(seed), jitter_s=2e-4,
                                 grid_s=1e-3))


def _first_contact_of_the_paths(detector: Detector, impact: Impact) -> float:
    """Return the paths' own first contact (s) in the impact's interval: dense, then bisected."""
    clock, config = detector._clock, detector.config
    ta, tb = clock.time(impact.interval_start_ns), clock.time(impact.interval_end_ns)
    ball_path, bat_path = detector._sweep.paths(detector._ball.interval(ta),
                                                detector._bat.interval(ta))

    def gap(t: float) -> float:
        knob, tip = bat_path.at(t)
        return profile_gap(ball_path.at(t), knob, tip, config.ball_radius, config.profile)[0]

    times = np.linspace(ta, tb, 4001)
    first = next(i for i, t in enumerate(times) if gap(float(t)) <= 0.0)
    assert first > 0  # the ball was apart at the interval's start
    low, high = float(times[first - 1]), float(times[first])
    for _ in range(60):
        middle = 0.5 * (low + high)
        low, high = (low, middle) if gap(middle) <= 0.0 else (middle, high)
    return high


@pytest.mark.parametrize('model', ['rigid', 'spline', 'c2'])
def test_an_impact_is_the_first_contact_of_the_paths(model: str,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """
    An impact's time is the paths' own first contact within 0.3 us.

    The sub-steps' chords leave the paths by up to ``max_chord_error`` (0.5 mm: microseconds
    at a bat's speed); the impact's sub-step is solved again in chords 25 times finer (0.02
    mm: measured 0.2-103 ns off here). Without that (the factor 1) one impact of each model
    is 1.6-3.3 us off.
    """
    errors, refined = {}, sweep.IMPACT_CHORD_FACTOR
    for factor in (refined, 1.0):
        monkeypatch.setattr(sweep, 'IMPACT_CHORD_FACTOR', factor)
        errors[factor] = []
        for seed, kind in ((3, 'barrel'), (4, 'handle'), (5, 'barrel'), (6, 'end_cap')):
            detector, impacts = _impacts(DetectorConfig(bat_input='points', model=model),
                                         seed, kind)
            impact = impacts[0]
            truth = _first_contact_of_the_paths(detector, impact)
            errors[factor].append(abs(detector._clock.time(impact.stamp_ns) - truth))
    assert max(errors[refined]) < 3e-7 and max(errors[1.0]) > 1e-6, errors
    assert max(errors[refined]) < 0.1 * max(errors[1.0]), errors


def _noisy_pitches(seeds, rate: float = 360.0, noise_m: float = 1e-3):  # type: ignore
    """Return (scenario, samples) of simulated pitches of every kind under tracking noise."""
    from baseball_collision.tools.sim import CLOSE_KINDS, KINDS
    kinds = KINDS + CLOSE_KINDS
    for seed in seeds:
        kind = kinds[seed % len(kinds)]
        scenario = make_scenario(kind, np.random.default_rng(seed), family='tilted')
        yield scenario, sample(scenario, rate, np.random.default_rng(seed), jitter_s=2e-4,
                               grid_s=1e-3, noise_m=noise_m, marker_spread_m=0.3)


def test_an_interval_outside_the_zone_stays_outside_on_the_smoothed_paths(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Where ``_outside_zone`` clears an interval, the smoothed paths stay beyond both distances.

    Under 1 mm of noise (auto), every interval it clears, its paths as the sweep would have
    smoothed them, the gap at 400 instants: over the near-miss threshold and the re-arm
    distance. It clears many (the point of it), and never one with a near miss open.
    """
    cleared: List[Tuple[Detector, Tuple[int, int], float, float]] = []
    original = sweep.Sweep._outside_zone

    def watching(self, located, ta, tb, bat_noise):  # type: ignore[no-untyped-def]
        assert self.episodes.episode is None
        found = original(self, located, ta, tb, bat_noise)
        if found:
            paths = self.paths(*located)  # (the smoothed paths, as the sweep builds them)
            config = self.config
            for t in np.linspace(ta, tb, 400):
                knob, tip = paths[1].at(float(t))
                gap = profile_gap(paths[0].at(float(t)), knob, tip, config.ball_radius,
                                  config.profile)[0]
                assert gap > max(config.near_miss_threshold, config.rearm_distance), (t, gap)
            cleared.append((ta, tb))
        return found
    monkeypatch.setattr(sweep.Sweep, '_outside_zone', watching)
    config = DetectorConfig(bat_input='points', model='c2', look_ahead=2, tracker_noise=-1.0)
    for _, samples in _noisy_pitches(range(12)):
        detect(config, samples)
    assert len(cleared) > 50


def _zone_bounds(ball_path, bat_path, ta: float, tb: float, n: int, ball_radius: float,
                 profile) -> List[float]:  # type: ignore[no-untyped-def]
    """``_outside_zone``'s bounds written out: each instant's gap, each sub-step's lowest."""
    bounds: List[float] = []
    before = None
    for j in range(n + 1):
        t = tb if j == n else ta + (tb - ta) * j / n
        ball = ball_path.at(t)
        knob, tip = bat_path.at(t)
        gap = profile_gap(ball, knob, tip, ball_radius, profile)[0]
        bounds.append(gap)
        if before is not None:
            moved = norm(sub(ball, before[0])) + max(norm(sub(knob, before[1])),
                                                     norm(sub(tip, before[2])))
            bounds.append(0.5 * (gap + before[3] - moved))
        before = (ball, knob, tip, gap)
    return bounds


def test_the_zone_loop_is_its_bounds_written_out(monkeypatch: pytest.MonkeyPatch) -> None:
    """
    The kernel's ``zone_clear`` clears exactly above the lowest of the bounds written out.

    For each interval the sweep asks about under noise: with the floor the lowest bound
    (written out in Python, each gap and each sub-step's mean less half the distances moved),
    not clear; a floor one float below it, clear: the kernel's numbers are those, to the bit.
    """
    asked = []
    zone_clear = _kernel.zone_clear

    def recording(*args):  # type: ignore[no-untyped-def]
        asked.append(args)
        return zone_clear(*args)
    monkeypatch.setattr(sweep, '_kernel', SimpleNamespace(zone_clear=recording))
    config = DetectorConfig(bat_input='points', model='c2', look_ahead=2, tracker_noise=-1.0)
    for _, samples in _noisy_pitches(range(3)):
        detect(config, samples)
    assert len(asked) > 20
    for ball_path, bat_path, ta, tb, n, ball_radius, profile, floor in asked:
        lowest = min(_zone_bounds(ball_path, bat_path, ta, tb, n, ball_radius, profile))
        assert zone_clear(ball_path, bat_path, ta, tb, n, ball_radius, profile, floor) == (
            lowest > floor)
        assert not zone_clear(ball_path, bat_path, ta, tb, n, ball_radius, profile, lowest)
        assert zone_clear(ball_path, bat_path, ta, tb, n, ball_radius, profile,
                          math.nextafter(lowest, -math.inf))
    with pytest.raises(TypeError):
        zone_clear(ball_path, bat_path, ta, tb, 0, ball_radius, profile, floor)
    with pytest.raises(AttributeError):
        zone_clear(ball_path, ball_path, ta, tb, n, ball_radius, profile, floor)


@pytest.mark.parametrize('noise_m', [2e-4, 1e-3, 3e-3])
def test_clearing_the_zone_changes_no_event(noise_m: float,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """
    The intervals ``_outside_zone`` clears come to what their sweep would have: every event.

    The same pitches (hits, grazes, near misses, clear misses) under noise, with and without
    it: the same impacts, near misses and gaps, to the last bit, uncertainties included.
    """
    config = DetectorConfig(bat_input='points', model='c2', look_ahead=2, tracker_noise=-1.0)
    runs = {}
    for shortcut in (True, False):
        if not shortcut:
            monkeypatch.setattr(sweep.Sweep, '_outside_zone', lambda *args: False)
        events = []
        for _, samples in _noisy_pitches(range(20, 30), noise_m=noise_m):
            detector = Detector(config)
            for stamp, role, values in samples.messages(config.bat_input):
                events += detector.add(role, stamp, values)
            events += detector.finish()
        runs[shortcut] = [repr(event) for event in events]
    assert runs[True] == runs[False]
    assert any('Impact(' in event for event in runs[True])
    assert any('NearMiss(' in event for event in runs[True])


@pytest.mark.parametrize('tracker_noise', [0.0, -1.0])
def test_an_exact_bat_ending_its_window_takes_the_quintic_piece(tracker_noise: float) -> None:
    """Look-ahead 0, exact: the interval's own bat path is the quintic's last piece, nearer."""
    rate, spin, tilt = 90.0, 20.0, 2.0
    detector = Detector(DetectorConfig(model='c2', bat_input='points', look_ahead=0,
                                       tracker_noise=tracker_noise, max_speed=1e5,
                                       bat_length_tolerance=1.0))
    for i in range(9):
        knob, tip = tilting_bat(i / rate, spin, tilt)
        stamp = BASE_NS + int(round(i / rate * 1e9))
        detector.add_knob(stamp, tuple(knob))
        detector.add_tip(stamp, tuple(tip))
        detector.add_ball(stamp, (3.0 - 40.0 * i / rate, 1.0, 1.0))
    bat = detector._bat
    k = len(bat.times) - 2  # the newest interval: the last piece of its window
    path = detector._sweep.paths(k, k)[1]
    window = c2_window(bat, k, 0.05, 0, 8)
    assert window.stop == k + 2 and path.knob.e is not None  # a quintic's piece
    cubic = C2BatPath.fitted(bat.times[window.start:window.stop],
                             bat.values[window.start:window.stop], k - window.start)
    assert cubic.knob.e is None

    def worst(fit) -> float:
        return max(float(np.linalg.norm(np.array(fit.at(t)[1]) - tilting_bat(t, spin, tilt)[1]))
                   for t in np.linspace(bat.times[k], bat.times[k + 1], 41))
    assert worst(path) < worst(cubic)


@pytest.mark.parametrize('look_ahead', [0, 2])
def test_an_interval_near_the_bat_waits_for_the_flight_after_a_segments_first_samples(
        look_ahead: int) -> None:
    """
    A hit at the 4th ball sample after a tracking gap: its impact once the flight after is in.

    Its interval opens at the segment's third sample, which only the samples after it judge
    (``departure.glitch_before_flight``): the interval waits for ``FLIGHT_AFTER`` of them
    (the scheduler's walk stops before it), then the impact is the one found without the rule
    (``early_glitches`` off: at once). A recording that ends sooner has it from ``finish``.
    """
    rng = np.random.default_rng(0)
    scenario = make_scenario('barrel', rng, family='rebound', lead_s=0.4, trail_s=0.1)
    samples = sample(scenario, 90.0, rng)
    after = int(np.searchsorted(samples.ball_stamps_ns, samples.start_ns + int(
        round(scenario.truth.time_s * 1e9))))
    lost = ball_lost_before(samples, after - 3)
    third = int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[after - 1]))
    config = DetectorConfig(bat_input='pose', look_ahead=look_ahead)
    ends = lost.ball_stamps_ns[third + 2], lost.ball_stamps_ns[-1]

    def impact_after(end: int, judged: bool) -> Tuple[int, int]:
        """Return the impact's stamp and the newest ball stamp when it came (ns; 0: finish)."""
        detector = Detector(config)
        detector._sweep.early_glitches = judged
        newest = 0
        for stamp, role, values in lost.messages('pose'):
            if stamp > end:
                break
            newest = stamp if role == 'ball' else newest
            impacts = [e for e in detector.add(role, stamp, values) if isinstance(e, Impact)]
            if impacts:
                return impacts[0].stamp_ns, newest
        return next(e.stamp_ns for e in detector.finish() if isinstance(e, Impact)), 0

    stamp, newest = impact_after(ends[1], True)
    assert stamp == impact_after(ends[1], False)[0]
    assert newest == lost.ball_stamps_ns[third + FLIGHT_AFTER]
    assert impact_after(ends[1], False)[1] == lost.ball_stamps_ns[third + 1 + look_ahead]
    assert impact_after(ends[0], True) == (stamp, 0)


def test_a_segments_first_sample_waits_for_the_bat_over_its_interval() -> None:
    """
    ``Sweep._first_glitch``: judged once the bat's frames its paths over the interval read are in.

    A miss tracked again at the bat, its first sample on the bat's axis, the bat tracked at
    360 Hz and the ball at 90: None (wait) while the bat's newest frame is before the next
    ball sample, or the interval's last bat frame has not its ``ahead`` frames after it
    (``_bat_over``), then a glitch; at the recording's end (``final``) judged on what there is.
    """
    rng = np.random.default_rng(1)
    scenario = make_scenario('miss_over', rng, lead_s=0.4, trail_s=0.1)
    samples = sample(scenario, 360.0, rng, ball_rate_hz=90.0)
    closest = int(np.argmin(np.abs(samples.ball_stamps_ns - samples.start_ns - int(
        round(scenario.truth.min_gap_time_s * 1e9)))))
    lost = ball_lost_before(samples, closest - 1)
    k = int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[closest - 1]))
    lost = on_bat_axis(lost, k)
    next_ball = int(lost.ball_stamps_ns[k + 1])
    for look_ahead in (0, 2):
        verdicts = []
        for bat_until in (next_ball - 1, next_ball, next_ball + 3_000_000, next_ball + 9_000_000):
            detector = Detector(DetectorConfig(bat_input='pose', look_ahead=look_ahead))
            detector._sweep.early_glitches = False  # (judged here)
            for stamp, role, values in lost.messages('pose'):
                if role == 'ball' or stamp <= bat_until:
                    detector.add(role, stamp, values)
            judge = detector._sweep
            first = judge.ball.stamps.index(int(lost.ball_stamps_ns[k]))
            bat = judge.bat.times
            ready = bat[-1] >= judge.ball.times[first + 1] and len(bat) - 1 >= judge.bat.interval(
                judge.ball.times[first + 1]) + 1 + judge.ahead
            verdicts.append(judge._first_glitch(first))
            assert (verdicts[-1] is None) == (not ready)
            judge.final = True
            assert judge._first_glitch(first) is True
        assert verdicts[0] is None and verdicts[-1] is True
