"""Tests for baseball_collision.core.detector.departure: a ball that leaves its free flight."""

from dataclasses import replace
import itertools
import json
import math
from typing import Any, Dict, List, Sequence, Tuple

from baseball_collision.bags import BagReader
from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.detector import (
    Detector, DetectorConfig, Impact, sweep, sweep_impact)
from baseball_collision.core.detector.departure import (
    back_miss, CONTACT_TIME, DEPARTURE_FLOOR, departure_reach, departure_reaches,
    FEW_SCATTER_RATIOS, FLIGHT_AFTER, flight_before, flight_path, glitch_before_flight,
    HitApproach, judging_noise, leaves_flight, parabola, SCATTER_INTERVALS, SCATTER_RATIO)
from baseball_collision.core.detector.events import StreamGap
from baseball_collision.core.detector.fitting import c2_point_path, c2_window
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.detector.sweep import Sweep
from baseball_collision.core.detector.sweep_ball import UNEXPLAINED_RUN
from baseball_collision.core.motion import PointPath
from baseball_collision.core.toi import profile_gap
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag
from baseball_collision.tools.parameters import load_parameters
from baseball_collision.tools.report import entry
from baseball_collision.tools.sim import CLOSE_KINDS, KINDS, make_scenario, sample
from baseball_collision.tools.truth import truth_path
from hypothesis import example, given, settings, strategies as st
import numpy as np
import pytest
from support import examples
from support.bundled import bag_path, BAGS, check_against_truth, PARAMS, time_bound_ns
from support.events import (
    arrays, ball_lost_before, detect, detect_late_drops, on_bat_axis)

RATE = 90.0


def _stream(times: Sequence[float], points: Sequence[Sequence[float]],
            breaks: Sequence[int] = ()) -> Stream:
    """Return a ball stream of the points at the times (s), a segment starting at ``breaks``."""
    stream = Stream('ball')
    for i, (t, p) in enumerate(zip(times, points)):
        stream.append(float(t), int(round(t * 1e9)), tuple(float(x) for x in p), i in breaks)
    return stream


def _rebound(seed: int, noise_m: float = 0.0, rate: float = RATE):
    """Return a 'rebound' barrel hit and its samples (knob and tip markers)."""
    scenario = make_scenario('barrel', np.random.default_rng(seed), family='rebound')
    samples = sample(scenario, rate, np.random.default_rng(seed), jitter_s=2e-4, grid_s=1e-3,
                     noise_m=noise_m, marker_spread_m=0.3 if noise_m else None)
    return scenario, samples


def _ball(samples) -> Stream:
    times = (samples.ball_stamps_ns - samples.start_ns) * 1e-9
    return _stream(times, samples.ball_positions)


@settings(max_examples=examples(100), deadline=None)
@given(steps=st.lists(st.floats(0.002, 0.02), min_size=4, max_size=4),
       coefficients=st.lists(st.floats(-50.0, 50.0), min_size=9, max_size=9))
def test_a_parabola_is_its_own_free_flight(steps: List[float],
                                           coefficients: List[float]) -> None:
    """On uneven stamps a quadratic's samples never depart; the flight path is the quadratic."""
    times = np.concatenate(([0.0], np.cumsum(steps)))
    c = np.array(coefficients).reshape(3, 3)
    points = [c[0] + c[1] * t + c[2] * t * t for t in times]
    stream = _stream(times, points)
    for k in (2, 3):
        assert leaves_flight(stream, k, 0.0, 1.0) is None
        assert departure_reach(stream, k, 1.0) <= (
            np.linalg.norm(2.0 * c[2]) * (times[k + 1] - times[k]) ** 2 / 8.0 + 1e-9)
    path = flight_path(stream, 3, parabola(stream, 3, 1.0))
    for t in np.linspace(times[3], times[4], 7):
        expected = c[0] + c[1] * t + c[2] * t * t
        assert math.dist(path.at(float(t)), expected) < 1e-9 * (1.0 + np.abs(expected).max())


def test_a_hit_departs_at_its_interval_only() -> None:
    """The frame after a hit departs from the free flight; no interval of the pitch before."""
    for seed in range(4):
        scenario, samples = _rebound(seed)
        stream = _ball(samples)
        contact = stream.interval(scenario.truth.time_s)
        departed = [k for k in range(len(stream.times) - 1)
                    if leaves_flight(stream, k, 0.0, 1.0) is not None]
        assert departed[0] == contact
        assert departed == [contact]  # the parabolas after it run through the hit: no flight
        assert departure_reach(stream, contact, 1.0) > 0.05  # m: centimetres at least


def test_noise_is_not_a_departure() -> None:
    """
    A pitch with 1 mm of noise: no interval departs, told the noise or not (its own scatter).

    Not told, from the intervals with ``SCATTER_INTERVALS`` before them (at a segment's first
    ones nothing tells noise from a departure but the floor). Fails with the chi-square alone
    when the noise is not told.
    """
    departed = told = 0
    for seed in range(12):
        _, samples = _rebound(seed, noise_m=1e-3, rate=360.0)
        stream = _ball(samples)
        end = stream.interval(0.12)  # before every contact
        for k in range(end):
            if k >= 2 + SCATTER_INTERVALS:
                departed += leaves_flight(stream, k, 0.0, 1.0) is not None
            told += leaves_flight(stream, k, 1e-3, 1.0) is not None
    assert departed <= 2 and told <= 2  # of about 360 and 500 intervals


def test_a_noisy_hit_departs() -> None:
    """With 1 mm of noise, told or not, the frame after a hit still departs (most hits)."""
    found = 0
    for seed in range(8):
        scenario, samples = _rebound(seed, noise_m=1e-3)
        stream = _ball(samples)
        contact = stream.interval(scenario.truth.time_s)
        found += all(leaves_flight(stream, contact, noise, 1.0) is not None
                     for noise in (0.0, 1e-3))
    assert found >= 7


def test_segments_and_gaps_have_no_parabola() -> None:
    """Three samples before the closing one, in its segment and without a long gap, or none."""
    times = [0.0, 0.01, 0.02, 0.03, 0.04, 0.2, 0.21]
    points = [(t, 0.0, 0.0) for t in times]
    assert parabola(_stream(times, points), 2, 0.05) is not None
    assert parabola(_stream(times, points, breaks=(2,)), 2, 0.05) is None
    assert parabola(_stream(times, points), 4, 0.05) is None  # the gap after it
    assert parabola(_stream(times, points), 1, 0.05) is None
    assert departure_reach(_stream(times, points), 4, 0.05) == 0.0


@settings(max_examples=examples(100), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(4, 30))
def test_vectorised_reach_is_the_scalar_one(seed: int, n: int) -> None:
    """
    ``departure_reaches`` is ``departure_reach`` to rounding given the segments, else not below.

    Without the intervals' continuity it gives every interval from the third sample on its
    parabola (across breaks and gaps too).
    """
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.001, 0.02, n))
    points = rng.normal(size=(n, 3))
    breaks = {int(b) for b in rng.integers(1, n, 2)} if rng.random() < 0.5 else set()
    stream = _stream(times, points, breaks)
    k = np.arange(n - 1)
    closed = np.array([stream.continuous(int(i), 0.015) for i in k])
    loose = departure_reaches(points, times, k)
    found = departure_reaches(points, times, k, closed)
    for j in k:
        scalar = departure_reach(stream, int(j), 0.015)
        assert loose[j] >= scalar - 1e-12 * (1.0 + scalar)
        assert abs(found[j] - scalar) <= 1e-12 * (1.0 + scalar)


@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline', 'c2'])
@pytest.mark.parametrize('noise_m', [0.0, 1e-3])
def test_every_model_finds_a_hit_the_ball_rebounds_from(model: str, noise_m: float) -> None:
    """
    A hit whose ball rebounds is found, near its true instant, by every model.

    Without the free flight no model finds it (the frames after it show the ball going away).
    Noise not told (``tracker_noise`` 0): the departure is told apart from the scatter.
    """
    errors = []
    for seed in range(3):
        scenario, samples = _rebound(seed, noise_m)
        _, impacts = detect(DetectorConfig(model=model, bat_input='points'), samples)
        assert len(impacts) == 1
        t = (impacts[0].stamp_ns - samples.start_ns) * 1e-9
        errors.append(abs(t - scenario.truth.time_s))
    assert max(errors) < (2e-4 if model != 'linear' or noise_m else 1e-3)


@pytest.mark.parametrize('noise_m', [3e-6, 3e-5])
@pytest.mark.parametrize('told', [True, False])
def test_c2_finds_a_rebound_under_noise_too_small_for_the_flight_fit(
        noise_m: float, told: bool) -> None:
    """
    A hit the ball rebounds from, with a few micrometres of noise, told or estimated (auto).

    A parabola over the flight fit's span misses a pitch by more than such noise, so its guard
    turns every window away and the ball's path is the smoother's, which (so little noise to
    smooth) follows the departed frame back from the bat: it must give way to the free flight's
    parabola as exact samples' path does (it did not: no impact at 3 um, nor at 30 um told).
    """
    for seed in range(3):
        scenario, samples = _rebound(seed, noise_m)
        config = DetectorConfig(model='c2', look_ahead=2, bat_input='points',
                                tracker_noise=noise_m if told else -1.0)
        _, impacts = detect(config, samples)
        assert len(impacts) == 1
        t = (impacts[0].stamp_ns - samples.start_ns) * 1e-9
        assert abs(t - scenario.truth.time_s) < 2e-4


@pytest.mark.parametrize('model', ['rigid', 'spline', 'c2'])
def test_a_hit_in_a_noisy_ball_streams_first_frames_is_found(model: str) -> None:
    """
    A ball tracked from 60 ms before a hit, at 60 Hz with 0.3 mm of noise not told: found.

    The hit's interval is the stream's fourth; its first parabola's closing sample, off by the
    noise, was called departed and blocked the hit's own departure (each of these was lost).
    """
    rng = np.random.default_rng(7)
    scenarios = [make_scenario(kind, rng, family='rebound', lead_s=0.06)
                 for kind in ('barrel', 'end_cap') for _ in range(2)]
    for i, scenario in enumerate(scenarios):
        samples = sample(scenario, 60.0, np.random.default_rng(i), jitter_s=2e-4, grid_s=1e-3,
                         noise_m=3e-4, marker_spread_m=0.3)
        _, impacts = detect(DetectorConfig(model=model, bat_input='points'), samples)
        assert len(impacts) == 1
        t = (impacts[0].stamp_ns - samples.start_ns) * 1e-9
        assert abs(t - scenario.truth.time_s) < 1e-3


@pytest.mark.parametrize('noise_m', [3e-4, 1e-3])
def test_a_hit_tracked_from_60_ms_before_is_judged_without_its_own_frames(noise_m: float) -> None:
    """
    The offline default finds every real hit of a ball tracked from 60 ms before the bat.

    ``c2``, look-ahead 2, ``tracker_noise`` auto; 90 Hz, 0.3 and 1 mm of noise. The ball's
    estimate then rests on four residual windows, two of them holding the hit's look-ahead
    frames: the hit swelled it (25 mm at 0.3 mm of noise), and judged against it the hit's 0.5
    m departure was none, so two deep hits (end cap, handle: 21-23 mm) were lost. Departures
    are judged by the scatter before them instead (``judging_noise``).
    """
    rng = np.random.default_rng(7)
    scenarios = [make_scenario(kind, rng, family='rebound', lead_s=0.06)
                 for kind in KINDS + CLOSE_KINDS for _ in range(2)]
    config = DetectorConfig(model='c2', look_ahead=2, tracker_noise=-1.0, bat_input='points')
    hits = 0
    for i, scenario in enumerate(scenarios):
        truth = scenario.truth
        if not truth.contact or -truth.min_gap_m < 3e-3:
            continue
        samples = sample(scenario, RATE, np.random.default_rng(i), jitter_s=2e-4, grid_s=1e-3,
                         noise_m=noise_m, marker_spread_m=0.3)
        _, impacts = detect(config, samples)
        assert impacts, (i, scenario.kind)
        assert abs((impacts[0].stamp_ns - samples.start_ns) * 1e-9 - truth.time_s) < 1e-3
        hits += 1
    assert hits >= 6  # (7 deeper than 3 mm)


def test_judging_noise_is_the_noise_told() -> None:
    """A departure is judged against ``tracker_noise`` when told, against none under auto."""
    assert judging_noise(DetectorConfig(tracker_noise=3e-4)) == 3e-4
    assert judging_noise(DetectorConfig(tracker_noise=0.0)) == 0.0
    assert judging_noise(DetectorConfig(tracker_noise=-1.0)) == 0.0


@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline', 'c2'])
def test_a_bat_tracked_faster_than_the_ball_has_one_impact_per_hit(model: str) -> None:
    """
    A ball at 60 Hz (cameras) beside a bat at 1 kHz (a robot's joints): one impact a hit.

    Between the hit and the ball's next frame the bat's intervals see the ball on its free
    flight continued through the contact, out beyond the bat: that re-armed the detector, and
    the next frame, the ball still on the bat, was a second impact (every model, rebounds at
    the barrel). The same events sample by sample as in chunks (the bat as poses).
    """
    rng = np.random.default_rng(7)
    scenarios = [make_scenario('barrel', rng, family='rebound') for _ in range(4)]
    for i, scenario in enumerate(scenarios):
        samples = sample(scenario, 1000.0, np.random.default_rng(i), jitter_s=2e-4,
                         grid_s=1e-3, ball_rate_hz=60.0)
        config = DetectorConfig(model=model)
        detector, impacts = detect(config, samples)
        assert len(impacts) == 1, scenario.name
        t = (impacts[0].stamp_ns - samples.start_ns) * 1e-9
        assert abs(t - scenario.truth.time_s) < (1e-3 if model == 'linear' else 2e-4)
        chunked, events = Detector(config), []
        rows = [(role, stamp, values, 'world') for stamp, role, values in samples.messages('pose')]
        for part in np.array_split(np.arange(len(rows)), 3):
            events += chunked.add_chunk(*arrays([rows[j] for j in part]))
        events += chunked.finish()
        assert [e for e in events if isinstance(e, Impact)] == impacts
        assert chunked.stats.intervals == detector.stats.intervals


def test_a_flight_fit_past_a_hit_does_not_re_arm() -> None:
    """
    After a hit, no sub-step re-arms on a ball path that does not end at its closing sample.

    A rebound barrel hit at 120 Hz with 1 mm of noise, tracked from 60 ms before (the third
    scenario of ``bench_accuracy --families rebound --lead 0.06``, seed 7), under the offline
    default: over the interval after the hit's, ``c2``'s flight fit ends at the opening frame
    (its guard: the closing frame departed) and continues the ball 0.1 m past the bat, which
    re-armed the detector; the next frame, 16 mm inside the bat, was a second, initially
    overlapping impact. Now the hit alone, at its time.
    """
    rng = np.random.default_rng(7)
    scenario = [make_scenario(KINDS[0], rng, family='rebound', lead_s=0.06) for _ in range(3)][-1]
    samples = sample(scenario, 120.0, np.random.default_rng(2), jitter_s=2e-4, grid_s=1e-3,
                     noise_m=1e-3, marker_spread_m=0.3)
    _, impacts = detect(DetectorConfig(model='c2', look_ahead=2, tracker_noise=-1.0,
                                       bat_input='points'), samples)
    assert len(impacts) == 1
    assert abs((impacts[0].stamp_ns - samples.start_ns) * 1e-9 - scenario.truth.time_s) < 2e-4


@settings(max_examples=examples(12), deadline=None)
@example(seed=1542793, kind='handle', bat_rate=90.0, ball_rate=60.0, bat_as='pose',
         model='rigid')  # re-armed by the ball's free flight through the bat: two impacts
@example(seed=8447, kind='barrel', bat_rate=90.0, ball_rate=240.0, bat_as='pose',
         model='c2')  # re-armed on the interval after the hit's, whose closing frame departed
@example(seed=11141679, kind='handle', bat_rate=90.0, ball_rate=60.0, bat_as='pose',
         model='rigid')  # the bat braked after the hit: its continuation met the ball again
@given(seed=st.integers(0, 2 ** 32 - 1), kind=st.sampled_from(['barrel', 'end_cap', 'handle']),
       bat_rate=st.sampled_from([90.0, 180.0, 360.0, 500.0, 1000.0]),
       ball_rate=st.sampled_from([60.0, 90.0, 120.0, 240.0, 360.0]),
       bat_as=st.sampled_from(['pose', 'points']), model=st.sampled_from(['rigid', 'c2']))
def test_a_hit_is_one_impact_whatever_the_two_rates(seed: int, kind: str, bat_rate: float,
                                                    ball_rate: float, bat_as: str,
                                                    model: str) -> None:
    """
    A real hit with ball and bat each at its own rate: the hit once, and only real contacts.

    Exact samples; the ball leaves the bat, the bat brakes. The first impact is the hit, near the
    truth (``rigid`` within 1 ms: at 90 Hz its bat turns about one axis a frame and its ball moves
    on chords, and it may miss a hit there, its bat interpolated to the braked closing frame;
    ``c2`` within 0.5 ms), and any other is a real second contact: the simulator's ball, off the
    handle slowly, can be caught by the still turning barrel (it then passes through it). Its true
    gap went out beyond the re-arm distance since the impact before (nearly: 90 mm), and comes
    within 3 mm of the bat within 1 ms of it. Nothing else: the ball's free flight continued
    through the first contact does not re-arm the detector (``episodes``), also where the
    departure shows only on the interval after the hit's (its opening frame barely turned:
    ``Sweep._past_departure``), nor does a ball that leaves the bat only slowly (the
    simulator's may stay on it for milliseconds).
    """
    rng = np.random.default_rng(seed)
    scenario = make_scenario(kind, rng, family='rebound')
    samples = sample(scenario, bat_rate, rng, jitter_s=2e-4, grid_s=1e-3,
                     ball_rate_hz=ball_rate)
    _, impacts = detect(DetectorConfig(model=model, bat_input=bat_as), samples)
    if not impacts and model == 'rigid' and bat_rate < 180.0:
        return  # (at 90 Hz rigid interpolates to a braked bat frame: a hit can pass unseen)
    assert impacts
    t = (impacts[0].stamp_ns - samples.start_ns) * 1e-9
    assert abs(t - scenario.truth.time_s) < (1e-3 if model == 'rigid' else 5e-4)

    def true_gaps(times: np.ndarray) -> List[float]:
        knobs, tips = scenario.swing.knob_tip(times)
        return [profile_gap(tuple(ball), tuple(knob), tuple(tip), scenario.pitch.radius,
                            WOOD_BAT_34)[0]
                for ball, knob, tip in zip(scenario.pitch.position(times), knobs, tips)]

    for before, later in zip(impacts, impacts[1:]):
        t0, t1 = ((i.stamp_ns - samples.start_ns) * 1e-9 for i in (before, later))
        assert max(true_gaps(np.linspace(t0, t1, 200))) > 0.09
        assert min(true_gaps(t1 + np.linspace(-1e-3, 1e-3, 41))) < 3e-3


def test_floor() -> None:
    """A closing sample less than ``DEPARTURE_FLOOR`` off the free flight has not departed."""
    times = [0.0, 0.01, 0.02, 0.03, 0.04]
    points = [(0.4 * i, 0.0, 0.0) for i in range(4)] + [(1.6 + 0.9 * DEPARTURE_FLOOR, 0.0, 0.0)]
    assert leaves_flight(_stream(times, points), 3, 0.0, 1.0) is None
    points[4] = (1.6 + 1.1 * DEPARTURE_FLOOR, 0.0, 0.0)
    assert leaves_flight(_stream(times, points), 3, 0.0, 1.0) is not None


def test_a_segments_first_intervals_need_their_noise_told_or_more_scatter() -> None:
    """
    The first interval with a parabola departs only with noise told; the next few need more.

    Without noise told its closing sample's miss cannot be told from noise (a noisy ball's
    first parabola misses by millimetres: it blocked the next two intervals, where a hit
    then went unseen). With one to three intervals before, the ratio to their scatter is
    ``FEW_SCATTER_RATIOS``' (261, 33, 18) rather than ``SCATTER_RATIO``'s 13.
    """
    times = [0.01 * i for i in range(8)]
    line = [(0.4 * i, 0.0, 0.0) for i in range(8)]
    far = list(line[:3]) + [(1.2 + 0.05, 0.0, 0.0)]
    assert leaves_flight(_stream(times[:4], far), 2, 0.0, 1.0) is None
    assert leaves_flight(_stream(times[:4], far), 2, 1e-3, 1.0) is not None  # (noise told)
    # one interval of scatter before: sample 3 off by 1 mm, then sample 4 off by 11 or 30 mm
    for off, departs in ((0.011, False), (0.03, True)):
        points = list(line[:5])
        points[3] = (1.2 + 1e-3, 0.0, 0.0)
        points[4] = (1.6 + off, 0.0, 0.0)
        stream = _stream(times[:5], points)
        (before, spread_before), (miss, spread) = (parabola(stream, k, 1.0)[:2] for k in (2, 3))
        ratio = miss * miss / (spread * before * before / spread_before)
        assert (ratio > FEW_SCATTER_RATIOS[0]) == departs and ratio > SCATTER_RATIO
        assert (leaves_flight(stream, 3, 0.0, 1.0) is not None) == departs


def test_look_ahead_rebounds_within_microseconds() -> None:
    """
    ``c2`` at look-ahead 2 on hits whose ball rebounds: within 10 us of the truth.

    The bat unbraked, so the ball alone is tested (one closing frame 0.25 ms after the contact,
    the two after it decimetres off the free flight).
    """
    rng = np.random.default_rng(7)
    kinds = KINDS + CLOSE_KINDS
    scenarios = [make_scenario(kind, rng, family='rebound') for kind in kinds for _ in range(8)]
    errors = []
    for i in (16, 23, 27):  # handle hits and a graze
        scenario = scenarios[i]
        swing = replace(scenario.swing, brake_time=None, brake_fraction=0.0)
        scenario = replace(scenario, swing=swing, truth=scenario.truth)
        samples = sample(scenario, RATE, np.random.default_rng(i), jitter_s=2e-4, grid_s=1e-3)
        _, impacts = detect(DetectorConfig(model='c2', look_ahead=2, bat_input='points'),
                            samples)
        errors.append(abs((impacts[0].stamp_ns - samples.start_ns) * 1e-9
                          - scenario.truth.time_s))
    assert max(errors) < 1e-5


def test_a_look_ahead_stops_at_a_departure() -> None:
    """The ball's ``c2`` path before a hit's interval, at look-ahead 2, is fitted up to it only."""
    scenario, samples = _rebound(1)
    config = DetectorConfig(model='c2', look_ahead=2, bat_input='points')
    detector, _ = detect(config, samples)
    ball = detector._ball
    k = ball.interval(scenario.truth.time_s)
    assert leaves_flight(ball, k, 0.0, config.max_gap) is not None
    ball.path_key = None
    path = detector._sweep.paths(k - 1, detector._bat.interval(scenario.truth.time_s))[0]
    window = c2_window(ball, k - 1, config.max_gap, 2, config.spline_window)
    assert window.stop - 1 == k + 2  # the look-ahead reaches two frames after the hit
    kept = c2_point_path(ball, k - 1, range(window.start, k + 1))
    bent = c2_point_path(ball, k - 1, window)
    t = 0.5 * (path.t0 + path.t1)
    assert path.at(t) == kept.at(t) and math.dist(bent.at(t), kept.at(t)) > 1e-3


REBOUND_BAG = 'pitches_180hz_rebound.mcap'
"""The bundled bag of real hits (``simulate --family rebound``, 180 Hz)."""


def _in_time(document: Dict[str, Any], truth: Dict[str, Any], rate_hz: float) -> int:
    """Return how many true contacts have one impact within the bundled time bound."""
    return sum(1 for pitch in truth['pitches'] if pitch['contact'] and [
        impact for impact in document['impacts']
        if pitch['start_ns'] <= impact['stamp_ns'] <= pitch['end_ns']
        and abs(impact['stamp_ns'] - pitch['stamp_ns']) <= time_bound_ns(rate_hz)])


@pytest.mark.parametrize('model', ['rigid', 'spline', 'c2'])
def test_the_bundled_bag_of_real_hits(model: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    ``analyze`` on the bundled rebound bag: every contact, the ball leaving after each.

    Every contact within the bundled bounds (``check_against_truth``); at each impact the ball
    came in toward the plate (-y) and the frames after it show it braked by more than 5 m/s
    along y, and going back toward the pitcher (+y) after the barrel and handle hits; the bat
    is continued at some hits, under every model (``SweepImpact._bat_ahead``: 180 Hz is a high
    rate). With the departure decision switched off, contacts are missed or misplaced.
    """
    path, rate = bag_path(REBOUND_BAG), BAGS[REBOUND_BAG]
    truth = json.loads(truth_path(path).read_text())
    options = AnalysisOptions(parameters=load_parameters(PARAMS), model=model)
    continued = []
    bat_ahead = Sweep._bat_ahead

    def counted(self: Sweep, *args: Any) -> Any:
        found = bat_ahead(self, *args)
        if self.bat_ahead is None:  # the detector's own sweep, not an uncertainty's re-solve
            continued.append(found)
        return found

    def document() -> Dict[str, Any]:
        analysis = analyze_bag(path, options, progress=False)
        return {'impacts': [entry(analysis, e) for e in analysis.impacts],
                'near_misses': [entry(analysis, e) for e in analysis.near_misses]}

    monkeypatch.setattr(Sweep, '_bat_ahead', counted)
    found = document()
    check_against_truth(found, truth, rate)
    assert _in_time(found, truth, rate) == 8
    assert any(continued)
    with BagReader(path) as bag:
        balls = [s for s in bag.samples() if s.role == 'ball']
    stamps = np.array([s.stamp_ns for s in balls])
    y = np.array([s.values[1] for s in balls])
    for pitch, impact in zip([p for p in truth['pitches'] if p['contact']], found['impacts']):
        assert pitch['start_ns'] <= impact['stamp_ns'] <= pitch['end_ns']
        i = int(np.searchsorted(stamps, impact['stamp_ns']))  # the first frame after the hit
        before, after = ((y[j + 1] - y[j]) / ((stamps[j + 1] - stamps[j]) * 1e-9)
                         for j in (i - 2, i))
        assert impact['ball_velocity'][1] < 0.0 and before < 0.0, pitch['name']
        assert after > before + 5.0, pitch['name']
        assert (after > 0.0) == (pitch['kind'] in ('barrel', 'handle')), pitch['name']
    for module in (sweep, sweep_impact):  # the sweep's own test and its hits' (``_bat_ahead``)
        monkeypatch.setattr(module, 'leaves_flight', lambda *args: None)
    assert _in_time(document(), truth, rate) < 8


def test_vectorised_reach_refuses_an_interval_without_a_sample_after_it() -> None:
    """An interval at the stream's last sample, or points that do not match, are a ValueError."""
    times = np.arange(5) * 0.01
    points = np.zeros((5, 3))
    assert departure_reaches(points, times, np.array([-1, 0, 1])).tolist() == [0.0] * 3
    with pytest.raises(ValueError):
        departure_reaches(points, times, np.array([4]))
    with pytest.raises(ValueError):
        departure_reaches(points[:4], times, np.array([2]))
    with pytest.raises(ValueError):
        departure_reaches(points, times, np.array([2]), np.ones(3, bool))


def _parabola_written_out(times, values, breaks, k, max_gap):  # type: ignore[no-untyped-def]
    """``departure.parabola``'s computation as its Python was."""
    if k < 2 or breaks[k - 1] or breaks[k] or breaks[k + 1]:
        return None
    t0, t1, t2, t3 = times[k - 2:k + 2]
    h0, h1, h = t1 - t0, t2 - t1, t3 - t2
    if h0 > max_gap or h1 > max_gap or h > max_gap:
        return None
    (x0, y0, z0), (x1, y1, z1), (x2, y2, z2), (x3, y3, z3) = values[k - 2:k + 2]
    w0 = (t3 - t1) * h / ((t0 - t1) * (t0 - t2))
    w1 = (t3 - t0) * h / ((t1 - t0) * (t1 - t2))
    w2 = 1.0 - w0 - w1
    end = (w0 * x0 + w1 * x1 + w2 * x2, w0 * y0 + w1 * y1 + w2 * y2,
           w0 * z0 + w1 * z1 + w2 * z2)
    span = 0.5 * (t2 - t0)
    acceleration = (((x2 - x1) / h1 - (x1 - x0) / h0) / span,
                    ((y2 - y1) / h1 - (y1 - y0) / h0) / span,
                    ((z2 - z1) / h1 - (z1 - z0) / h0) / span)
    ax, ay, az = acceleration
    miss = math.dist((x3, y3, z3), end)
    bend = math.sqrt(ax * ax + ay * ay + az * az) * h * h / 8.0
    return miss, 1.0 + w0 * w0 + w1 * w1 + w2 * w2, bend, end, acceleration


@settings(max_examples=examples(200), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(4, 12), gap=st.floats(0.002, 0.02),
       scale=st.sampled_from([1e-3, 1.0, 40.0]))
def test_the_kernels_parabola_is_the_python_written_out(seed: int, n: int, gap: float,
                                                        scale: float) -> None:
    """
    ``parabola`` (the kernel's, kept) is the free flight's Python written out, to the bit.

    Uneven stamps (some steps over the gap), breaks, every interval of the stream in a
    shuffled order, each asked twice (the kept answer the same object) and under another gap
    (computed again); none without a sample after the interval or before the third;
    points that are not 3 numbers are refused.
    """
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.001, 0.012, n)).tolist()
    values = [tuple(p) for p in (rng.normal(size=(n, 3)) * scale).tolist()]
    breaks = (rng.random(n) < 0.15).tolist()
    stream = _stream(times, values)
    stream.breaks = breaks
    for k in rng.permutation(n - 1).tolist():
        found = parabola(stream, k, gap)
        assert found == _parabola_written_out(times, values, breaks, k, gap)
        assert parabola(stream, k, gap) is found
        wider = _parabola_written_out(times, values, breaks, k, 2.0 * gap)
        assert parabola(stream, k, 2.0 * gap) == wider
    assert parabola(stream, n - 1, gap) is None
    bad = _stream(times, [(0.0, 1.0)] * n)
    with pytest.raises(TypeError):
        parabola(bad, 2, 1.0)


def _leaves_written_out(times, values, breaks, k, noise, max_gap):  # type: ignore
    """
    ``departure.leaves_flight`` as its Python was (its parabolas written out too).

    With session 38's ratios for a segment's first intervals (``FEW_SCATTER_RATIOS``), and no
    departure without noise told where no interval before it scatters.
    """
    from baseball_collision.core.detector.departure import (
        DEPARTURE_CHI_SQUARE, FEW_SCATTER_RATIOS, SCATTER_RATIO)

    def fit(j):  # type: ignore[no-untyped-def]
        return (_parabola_written_out(times, values, breaks, j, max_gap)
                if 0 <= j and j + 1 < len(times) else None)

    def departed(j):  # type: ignore[no-untyped-def]
        fitted = fit(j) if j >= 0 else None
        if fitted is None:
            return None
        miss, spread = fitted[0], fitted[1]
        if miss <= DEPARTURE_FLOOR or miss * miss <= DEPARTURE_CHI_SQUARE * noise * noise * spread:
            return None
        scatter = []
        for i in range(j - SCATTER_INTERVALS, j):
            before = fit(i) if i >= 0 else None
            if before is not None:
                scatter.append(before[0] * before[0] / before[1])
        if not scatter:
            return fitted if noise > 0.0 else None
        ratio = SCATTER_RATIO if len(scatter) > 3 else FEW_SCATTER_RATIOS[len(scatter) - 1]
        if miss * miss <= ratio * spread * sum(scatter) / len(scatter):
            return None
        return fitted
    fitted = departed(k)
    if fitted is None or any(departed(j) is not None for j in (k - 1, k - 2)):
        return None
    return fitted


@settings(max_examples=examples(150), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(4, 40), noise=st.sampled_from(
    [0.0, 1e-4, 1e-3]), hit=st.floats(0.2, 0.8))
def test_the_kernels_departure_is_the_python_written_out(seed: int, n: int, noise: float,
                                                         hit: float) -> None:
    """
    ``leaves_flight`` (the kernel's) is the Python it replaced, to the bit, at every interval.

    A pitched ball with tracking noise on jittered stamps, hit back part-way (a departure),
    some segments broken; every interval asked, in a shuffled order.
    """
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.002, 0.004, n))
    turn = times[int(hit * (n - 1))]
    x = np.where(times < turn, -40.0 * times, -40.0 * turn + 50.0 * (times - turn))
    points = np.stack((x, 0.1 * times, 1.0 - 4.9 * times ** 2), axis=1)
    points += rng.normal(0.0, noise, points.shape)
    values = [tuple(p) for p in points.tolist()]
    breaks = [True] + (rng.random(n - 1) < 0.05).tolist()
    stream = _stream(times.tolist(), values)
    stream.breaks = list(breaks)
    for k in rng.permutation(n - 1).tolist():
        assert leaves_flight(stream, k, noise, 0.01) == _leaves_written_out(
            stream.times, values, breaks, k, noise, 0.01)


def _config_of(model: str) -> DetectorConfig:
    """Return a pose input's detector under a model ('c2-la2-auto': ``analyze``'s default)."""
    c2 = model.startswith('c2')
    return DetectorConfig(model='c2' if c2 else model, bat_input='pose',
                          look_ahead=2 if model == 'c2-la2-auto' else 0,
                          tracker_noise=-1.0 if model == 'c2-la2-auto' else 0.0)


@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline', 'c2', 'c2-la2-auto'])
@pytest.mark.parametrize('kind', ['miss_over', 'miss_under'])
@pytest.mark.parametrize('frames', [(0,), (0, 1), (0, 2), (-1, 0, 1)])
def test_ball_frames_on_the_bat_are_glitches_not_an_impact(model: str, kind: str,
                                                           frames: Tuple[int, ...]) -> None:
    """
    A miss whose ball samples nearest the bat are reported on the bat's axis: no impact.

    Bad frames (a mislabelled marker, a reflection) put the ball inside the bat: one, two or
    three in a row, or two with a good frame between. Each made an impact (the ball already
    overlapping, at 120-220 mph) under every model: one frame until session 49, two or three
    until session 50 (the second was judged against a flight through the first, which blocked
    its departure). Now each is dropped as ``ball_glitch`` (a late drop) and the miss is what it
    was without them.
    """
    config = _config_of(model)
    for seed in range(3):
        rng = np.random.default_rng(seed)
        samples = sample(make_scenario(kind, rng), RATE, rng, jitter_s=2e-4, grid_s=1e-3)
        near_misses = detect(config, samples)[0].stats.near_misses
        bat_at = np.searchsorted(samples.bat_stamps_ns, samples.ball_stamps_ns).clip(
            0, len(samples.bat_stamps_ns) - 1)
        axis_middle = 0.5 * (samples.knobs[bat_at] + samples.tips[bat_at])
        k = int(np.argmin(np.linalg.norm(samples.ball_positions - axis_middle, axis=1)))
        for j in frames:
            samples.ball_positions[k + j] = axis_middle[k + j]
        detector, impacts = detect(config, samples)
        assert impacts == []
        dropped = detector.stats.dropped  # (the frame back after one: too far for the speed check)
        assert set(dropped) <= {'ball_glitch', 'speed_limit'} and dropped['ball_glitch']
        assert detector.stats.near_misses == near_misses


@pytest.mark.parametrize('model', ['c2', 'c2-la2-auto'])
@pytest.mark.parametrize('kind', ['miss_over', 'miss_under'])
def test_frames_stuck_on_the_bat_after_the_ball_passed_are_glitches(model: str,
                                                                    kind: str) -> None:
    """
    Two noisy ball frames reported on the bat just after the ball passed it: no impact.

    Off the flight along one line, as a hit's frames are (the ball seems to have stopped at the
    bat), so the hit's line passed them with 1 mm of noise at 90 Hz, and an impact was invented
    (6 of 4,032 audit cases). No contact on the flight explains that departure (the detector
    is still armed): both frames are dropped as ``ball_glitch`` and forgotten.
    """
    config = _config_of(model)
    for seed in range(4):
        rng = np.random.default_rng(seed)
        scenario = make_scenario(kind, rng, lead_s=0.15, trail_s=0.1)
        samples = sample(scenario, RATE, rng, noise_m=1e-3)
        near_misses = detect(config, samples)[0].stats.near_misses
        k = int(np.argmin(np.abs(samples.ball_stamps_ns - samples.start_ns
                                 - scenario.truth.min_gap_time_s * 1e9))) + 1
        for j in (k, k + 1):  # the bat's axis point nearest the ball, at its nearest frame
            m = int(np.argmin(np.abs(samples.bat_stamps_ns - samples.ball_stamps_ns[j])))
            knob, axis = samples.knobs[m], samples.tips[m] - samples.knobs[m]
            along = np.clip((samples.ball_positions[j] - knob) @ axis / (axis @ axis), 0, 1)
            samples.ball_positions[j] = knob + along * axis
        detector, impacts = detect(config, samples)
        assert impacts == []
        assert detector.stats.dropped['ball_glitch'] == 2
        assert detector.stats.near_misses == near_misses


def test_a_grazes_late_departure_is_explained_by_its_impact() -> None:
    """
    A graze with the ball at 60 Hz (the bat at 240): its frames after the impact are kept.

    A graze barely turns the ball: its departure shows a frame after the impact's interval,
    after the detector re-armed, and was taken for one no contact explains: three frames
    forgotten, a gap over ``max_gap`` made of them (2 of 40 such hits). The impact since the
    flight's first sample explains it.
    """
    for seed in (1000, 1001):
        rng = np.random.default_rng(seed)
        scenario = make_scenario('graze', rng, family='rebound', lead_s=0.15, trail_s=0.1)
        samples = sample(scenario, 240.0, rng, ball_rate_hz=60.0)
        for config in (_config_of('c2'), _config_of('c2-la2-auto')):
            detector, impacts = detect(config, samples)
            assert len(impacts) == 1
            assert not detector.stats.dropped and detector.stats.gaps == 0


@pytest.mark.parametrize('rate', [RATE, 60.0])
def test_a_ball_deflected_near_the_bat_by_something_else_is_tracked_again(rate: float) -> None:
    """
    A miss deflected just after it passed the bat (the batter's hands): a few frames forgotten.

    No contact on the flight explains the departure, so its first frames are dropped as
    ``ball_glitch``, but no more than ``UNEXPLAINED_RUN`` in a row, and none whose neighbours
    would be more than ``max_gap`` apart (at 60 Hz a gap was made of them): the ball really
    left its flight, and it is tracked again after them. No impact either way.
    """
    config = _config_of('c2')
    rng = np.random.default_rng(0)
    scenario = make_scenario('miss_under', rng, lead_s=0.15, trail_s=0.1)
    samples = sample(scenario, rate, rng)
    t = (samples.ball_stamps_ns - samples.start_ns) * 1e-9
    after = np.clip(t - scenario.truth.min_gap_time_s - 0.002, 0.0, None)
    samples.ball_positions[:] += np.outer(after, (0.0, 8.0, -12.0))  # m/s from 2 ms on
    detector, impacts = detect(config, samples)
    assert impacts == [] and detector.stats.gaps == 0
    forgotten = detector.stats.dropped['ball_glitch']
    assert forgotten == UNEXPLAINED_RUN if rate == RATE else 0 < forgotten < UNEXPLAINED_RUN


@pytest.mark.parametrize('model', ['c2', 'c2-la2-auto', 'rigid'])
def test_a_glitch_before_a_hit_is_forgotten(model: str) -> None:
    """
    A ball frame 5 cm off its flight 1-8 frames before a hit: the hit as without that frame.

    The glitch stayed in the stream once dropped: it swelled the scatter the hit's departure
    is judged against (and blocked it one or two frames on), so the contact was lost (at 90
    Hz, 16 of 16 hits 2-3 frames after it, 6 of 16 4-10 frames after), and the ball's speed at
    the impact was fitted through it. One frame before the contact, its next frame is the
    hit's first, off the flight along another line, and hid it (14 of 16 lost). Now the glitch
    is forgotten before its interval is swept: the impact is the one found with the frame
    deleted, to the nanosecond and the bit (``rigid``, whose velocities reach further back
    than where it judges glitches, its ball speed within 0.5 %).
    """
    config = _config_of(model)
    for seed in range(2):
        scenario, samples = _rebound(seed)
        contact = int(np.searchsorted(samples.ball_stamps_ns, samples.start_ns + int(
            round(scenario.truth.time_s * 1e9))))
        for before in (1, 2, 3, 5, 8):
            k = contact - before
            without = replace(samples, ball_stamps_ns=np.delete(samples.ball_stamps_ns, k),
                              ball_positions=np.delete(samples.ball_positions, k, axis=0))
            expected = detect(config, without)[1]
            glitched = replace(samples, ball_positions=samples.ball_positions.copy())
            glitched.ball_positions[k, 2] += 0.05
            detector, impacts = detect(config, glitched)
            assert len(impacts) == len(expected) == 1
            assert impacts[0].stamp_ns == expected[0].stamp_ns
            if model == 'rigid':
                assert impacts[0].ball_speed_mps == pytest.approx(expected[0].ball_speed_mps,
                                                                  rel=0.005)
            else:
                assert dict(detector.stats.dropped) == {'ball_glitch': 1}
                assert impacts[0].ball_speed_mps == expected[0].ball_speed_mps
                assert impacts[0].sweet_spot_speed_mps == expected[0].sweet_spot_speed_mps


@pytest.mark.parametrize('rate', [RATE, 360.0])
def test_a_noisy_hits_frames_are_no_glitch(rate: float) -> None:
    """
    With 0.3 or 1 mm of noise, the frames after a hit are on the hit's line: no ``ball_glitch``.

    The next frame after a departed one is off the flight along the same line (``hit_bend``,
    with the noise of both offsets): a hit's frames must pass, whichever model, or the sweep
    would take the hit's frame for a glitch and forget it.
    """
    for noise_m in (3e-4, 1e-3):
        for seed in range(6):
            _, samples = _rebound(seed, noise_m, rate)
            for model in ('c2-la2-auto', 'c2'):
                detector, impacts = detect(replace(_config_of(model), bat_input='points'),
                                           samples)
                assert len(impacts) == 1
                assert 'ball_glitch' not in detector.stats.dropped


@pytest.mark.parametrize('model', ['rigid', 'c2'])
def test_a_hits_frames_are_no_glitch(model: str) -> None:
    """The frames after a hit go on leaving the free flight: no ``ball_glitch``, one impact."""
    for seed in range(4):
        scenario, samples = _rebound(seed)
        detector, impacts = detect(DetectorConfig(model=model, bat_input='points'), samples)
        assert len(impacts) == 1 and not detector.stats.dropped


def _young_flight(hit_after: int = -1) -> Tuple[List[float], List[Tuple[float, ...]]]:
    """
    Return 12 samples at 90 Hz of a pitch's free flight, the first a segment's first.

    With ``hit_after`` >= 0, a hit halfway between that sample and the next: 30 m/s more along
    (0.6, -0.8, 0) from then on.
    """
    times = [0.5 + i / RATE for i in range(12)]
    t_c = times[hit_after] + 0.5 / RATE if hit_after >= 0 else math.inf
    return times, [(0.05 * t, -38.0 * t + max(t - t_c, 0.0) * -24.0,
                    1.8 - 4.9 * t * t + max(t - t_c, 0.0) * 18.0) for t in times]


def test_a_segments_second_and_third_samples_are_judged_by_the_flight_after_them() -> None:
    """
    ``glitch_before_flight``: ``glitch_path``'s rule with time run backwards.

    A sample 10 cm off the flight of the samples after it, the one before it on that flight:
    a glitch; the flight's own samples and a hit's are not (before the contact they leave the
    flight after it along one line, farther the earlier). Not judged with fewer than three
    samples after it (four with no noise told: one interval's scatter), nor the segment's
    first (none before it), nor across a segment break.
    """
    times, flight = _young_flight()
    for k in (1, 2):
        glitched = list(flight)
        glitched[k] = (flight[k][0] + 0.1, flight[k][1], flight[k][2])
        assert glitch_before_flight(_stream(times, glitched), k, 0.0, 0.05)
        assert not glitch_before_flight(_stream(times, flight), k, 0.0, 0.05)
        # three after it: the flight, no scatter (with none told, the noise could be anything)
        assert not glitch_before_flight(_stream(times[:k + 4], glitched[:k + 4]), k, 0.0, 0.05)
        assert glitch_before_flight(_stream(times[:k + 4], glitched[:k + 4]), k, 1e-3, 0.05)
        assert glitch_before_flight(_stream(times[:k + 5], glitched[:k + 5]), k, 0.0, 0.05)
        assert not glitch_before_flight(_stream(times, glitched, breaks=(k,)), k, 0.0, 0.05)
        assert not glitch_before_flight(_stream(times, glitched, breaks=(k + 2,)), k, 0.0, 0.05)
    glitched = list(flight)
    glitched[0] = (flight[0][0] + 0.1, flight[0][1], flight[0][2])
    assert not glitch_before_flight(_stream(times, glitched), 0, 0.0, 0.05)
    for hit_after in (0, 1, 2, 3):
        times, hit = _young_flight(hit_after)
        stream = _stream(times, hit)
        assert not any(glitch_before_flight(stream, k, 0.0, 0.05) for k in (1, 2, 3))
    assert FLIGHT_AFTER >= 4  # (the scatter of one interval at least: no noise told)


def test_a_segments_first_sample_is_judged_against_the_flight_after_it_continued_back() -> None:
    """
    ``flight_before``: the flight of the samples after a segment's first, back over its interval.

    A first sample 10 cm off the flight after it: that flight, from where the ball was at its
    stamp (the pitch's own parabola, to rounding) to the next sample; the flight's own first
    sample is on it: None. A hit between the first two samples leaves the first off the
    flight after the contact too (the ``Sweep`` tells the two apart by the bat); a hit later
    leaves no free flight after it to judge by: None. Not judged with fewer than three
    samples after it in its segment (four with no noise told: one interval's scatter).
    ``back_miss``: the first sample's distance from the parabola of the three after it.
    """
    times, flight = _young_flight()
    glitched = list(flight)
    glitched[0] = (flight[0][0] + 0.1, flight[0][1], flight[0][2])
    path = flight_before(_stream(times, glitched), 0, 0.0, 0.05)
    assert path is not None and (path.t0, path.t1) == (times[0], times[1])
    assert math.dist(path.at(times[0]), flight[0]) < 1e-12
    assert math.dist(path.at(times[1]), flight[1]) < 1e-12
    middle = 0.5 * (times[0] + times[1])
    assert math.dist(path.at(middle), (0.05 * middle, -38.0 * middle,
                                       1.8 - 4.9 * middle * middle)) < 1e-12
    assert flight_before(_stream(times, flight), 0, 0.0, 0.05) is None
    assert flight_before(_stream(times[:4], glitched[:4]), 0, 0.0, 0.05) is None
    assert flight_before(_stream(times[:4], glitched[:4]), 0, 1e-3, 0.05) is not None
    assert flight_before(_stream(times[:5], glitched[:5]), 0, 0.0, 0.05) is not None
    for k in (1, 3):
        assert flight_before(_stream(times, glitched, breaks=(k,)), 0, 1e-3, 0.05) is None
    assert abs(back_miss(_stream(times, glitched), 0, 0.05) - 0.1) < 1e-12
    assert back_miss(_stream(times, flight), 0, 0.05) < 1e-12
    assert back_miss(_stream(times, glitched, breaks=(3,)), 0, 0.05) is None
    times, hit = _young_flight(0)
    path = flight_before(_stream(times, hit), 0, 0.0, 0.05)
    assert path is not None and math.dist(path.at(times[0]), hit[0]) > 0.1
    for hit_after in (1, 2, 3):
        times, hit = _young_flight(hit_after)
        assert flight_before(_stream(times, hit), 0, 0.0, 0.05) is None


_GAP_CONFIGS = {
    'rigid': DetectorConfig(model='rigid', bat_input='pose', tracker_noise=0.0),
    'linear': DetectorConfig(model='linear', bat_input='pose', tracker_noise=0.0),
    'spline': DetectorConfig(model='spline', bat_input='pose', tracker_noise=0.0),
    'node': DetectorConfig(bat_input='pose'),
    'analyze': DetectorConfig(bat_input='pose', look_ahead=2),
}
"""The models, and the node's and ``analyze``'s defaults (``c2``, ``tracker_noise`` auto)."""


@pytest.mark.parametrize('name', sorted(_GAP_CONFIGS))
@pytest.mark.parametrize('kind', ['miss_over', 'miss_under'])
def test_a_glitch_among_the_first_samples_after_a_gap_is_no_impact(name: str,
                                                                   kind: str) -> None:
    """
    A miss tracked again after 0.2 s without the ball, its 1st, 2nd or 3rd sample on the axis.

    Fewer than three samples before it, so nothing judged it: the path through the 2nd or 3rd
    made an impact (the audit: 24 of 24 cases each, every model), and the samples after the
    1st were judged against a flight through it (good frames dropped). It is judged by the
    flight of the samples after it (``departure.glitch_before_flight``; the 1st by the bat too:
    ``Sweep._first_glitch``), the interval that reaches it waiting for them: dropped as
    ``ball_glitch`` (a late drop at its stamp), and the events are those without that frame,
    to the bit.
    """
    config = _GAP_CONFIGS[name]
    for seed in range(3):
        rng = np.random.default_rng(seed)
        scenario = make_scenario(kind, rng, lead_s=0.4, trail_s=0.1)
        samples = sample(scenario, RATE, rng, jitter_s=2e-4, grid_s=1e-3)
        closest = int(np.searchsorted(samples.ball_stamps_ns, samples.start_ns + int(
            round(scenario.truth.min_gap_time_s * 1e9))))
        for young in (0, 1, 2):
            lost = ball_lost_before(samples, closest - 2 - young)
            k = int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[closest - 2]))
            events, late = detect_late_drops(config, on_bat_axis(lost, k))
            without = replace(lost, ball_stamps_ns=np.delete(lost.ball_stamps_ns, k),
                              ball_positions=np.delete(lost.ball_positions, k, axis=0))
            assert not any(isinstance(event, Impact) for event in events)
            assert [(drop.reason, drop.stamp_ns) for drop in late] == [
                ('ball_glitch', int(lost.ball_stamps_ns[k]))]
            expected = detect_late_drops(config, without)[0]
            if young == 0:  # (the gap was told before its first sample was judged)
                expected = [replace(event, end_ns=int(lost.ball_stamps_ns[k]))
                            if isinstance(event, StreamGap) and event.stream == 'ball' else event
                            for event in expected]
            assert events == expected


def _without_frame(samples: Any, k: int) -> Any:
    """Return ``samples`` (``sim.sample``) without ball sample k."""
    return replace(samples, ball_stamps_ns=np.delete(samples.ball_stamps_ns, k),
                   ball_positions=np.delete(samples.ball_positions, k, axis=0))


def _gap_told_at(events: List[Any], stamp: int) -> List[Any]:
    """Return the events with the ball's stream gaps ending at ``stamp`` (ns)."""
    return [replace(event, end_ns=stamp) if isinstance(event, StreamGap)
            and event.stream == 'ball' else event for event in events]


@pytest.mark.parametrize('kind', ['miss_over', 'miss_under'])
def test_a_first_sample_after_a_gap_just_outside_the_bat_is_no_impact(kind: str) -> None:
    """
    A miss tracked again at the bat, its first sample 8 or 10 cm from the bat's axis.

    Clear of the bat (1.3 and 3.3 cm from a 3 cm barrel), but the path from it to the next
    sample went through the bat: an impact invented at the node in one case in about
    thirty. It left the flight of the samples after it continued back, which does not touch
    the bat (``Sweep._first_glitch``): dropped as ``ball_glitch``, the events those without it.
    """
    config = DetectorConfig(bat_input='pose')
    for seed in range(4):
        rng = np.random.default_rng(seed)
        scenario = make_scenario(kind, rng, lead_s=0.4, trail_s=0.1)
        samples = sample(scenario, RATE, rng)
        closest = int(np.argmin(np.abs(samples.ball_stamps_ns - samples.start_ns - int(
            round(scenario.truth.min_gap_time_s * 1e9)))))
        for first, distance in itertools.product((closest - 1, closest), (0.08, 0.10)):
            lost = ball_lost_before(samples, first)
            k = int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[first]))
            events, late = detect_late_drops(config, on_bat_axis(lost, k, distance))
            stamp = int(lost.ball_stamps_ns[k])
            assert not any(isinstance(event, Impact) for event in events)
            assert [(drop.reason, drop.stamp_ns) for drop in late] == [('ball_glitch', stamp)]
            assert events == _gap_told_at(
                detect_late_drops(config, _without_frame(lost, k))[0], stamp)


@pytest.mark.parametrize('kind', ['barrel', 'end_cap', 'graze'])
def test_a_hit_after_a_first_sample_on_the_bat_is_found(kind: str) -> None:
    """
    A hit 2 or 3 ball frames after a tracking gap, the gap's first sample on the bat's axis.

    The samples after it were judged against a flight through it (the hit's frames dropped
    as glitches, the hit lost or moved). It overlaps the bat deeper than a ball squashes
    (``Sweep._inside_bat``): dropped as ``ball_glitch`` before the samples after it are
    judged, and the impacts are those without it, within a microsecond (the node's speed
    check may have dropped the frame after the glitch, too far from it, before the glitch
    was judged: then the hit is found from one frame fewer).
    """
    configs = DetectorConfig(bat_input='pose', tracker_noise=0.0), DetectorConfig(bat_input='pose')
    found_any = False
    for seed, rate, config in itertools.product(range(3), (RATE, 360.0), configs):
        rng = np.random.default_rng(seed)
        scenario = make_scenario(kind, rng, lead_s=0.4, trail_s=0.1)
        samples = sample(scenario, rate, rng)
        truth = samples.start_ns + int(round(scenario.truth.time_s * 1e9))
        after = int(np.searchsorted(samples.ball_stamps_ns, truth))
        for back in (2, 3):
            lost = ball_lost_before(samples, after - back)
            k = int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[after - back]))
            events, late = detect_late_drops(config, on_bat_axis(lost, k))
            expected = detect_late_drops(config, _without_frame(lost, k))[0]
            assert (late[0].reason, late[0].stamp_ns) == ('ball_glitch', lost.ball_stamps_ns[k])
            found = [event.stamp_ns for event in events if isinstance(event, Impact)]
            without = [event.stamp_ns for event in expected if isinstance(event, Impact)]
            assert len(found) == len(without) and all(
                abs(a - b) < 1000 for a, b in zip(found, without))
            found_any = found_any or found != []
    assert found_any


@pytest.mark.parametrize('noise_m', [0.0, 1e-3])
def test_a_hit_just_after_a_gap_is_no_glitch(noise_m: float) -> None:
    """
    Real hits with the ball tracked again 1-6 frames before the contact: none lost.

    The frames after a hit are the flight after it, and those before leave it along the
    hit's line, so none of a segment's first samples is taken for a glitch: the impacts
    are those without the rules (``Sweep.early_glitches``) but where a rebound's frame
    before the contact is its segment's first or second, whose hit the rules find from the
    flight after it (``Sweep._hit_before_flight``; without them lost, or found ten times
    farther from the truth): exact, within 0.1 ms of it; with 1 mm of noise within 1 ms
    (0.54 ms at 90 Hz); each within two of its sigmas. No frame is dropped that is not
    without them (fewer: a departure from the parabola through a segment's first sample that
    left the flight after it is no unexplained one, ``Sweep._hit_after_start``).
    """
    for seed, rate, family in ((0, RATE, 'rebound'), (1, 360.0, 'rebound'), (2, RATE, 'plane')):
        rng = np.random.default_rng(seed)
        scenario = make_scenario('barrel', rng, family=family, lead_s=0.4, trail_s=0.1)
        samples = sample(scenario, rate, rng, noise_m=noise_m,
                         marker_spread_m=0.3 if noise_m else None)
        truth = samples.start_ns + int(round(scenario.truth.time_s * 1e9))
        after = int(np.searchsorted(samples.ball_stamps_ns, truth))
        for back in range(1, 7):
            lost = ball_lost_before(samples, after - back)
            for config in (DetectorConfig(bat_input='points'),
                           DetectorConfig(bat_input='points', look_ahead=2)):
                found = []
                for judged in (True, False):
                    detector = Detector(config)
                    detector._sweep.early_glitches = judged
                    events = []
                    for stamp, role, values in lost.messages('points'):
                        events += detector.add(role, stamp, values)
                    events += detector.finish()
                    found.append(([event for event in events if isinstance(event, Impact)],
                                  detector.stats.dropped))
                (judged, dropped), (unjudged, more) = found
                if [event.stamp_ns for event in judged] != [e.stamp_ns for e in unjudged]:
                    assert family == 'rebound' and len(judged) == 1
                    error = abs(judged[0].stamp_ns - truth)
                    assert error <= 2e9 * judged[0].time_uncertainty_s
                    if noise_m == 0.0:
                        assert back <= 2 and error < 100_000
                        assert all(abs(other.stamp_ns - truth) > 10 * error
                                   for other in unjudged)
                    else:  # (a second sample at the contact: the rule's answer 0.1 ms early)
                        assert back <= 3 and error < 1_000_000
                assert dropped <= more


def test_the_ball_pushed_off_the_bat_is_at_the_approach_at_its_contact() -> None:
    """
    ``HitApproach``: a push dv from t_c leaves the ball on a flight F; at t_c it is ``at(t_c)``.

    The ball before the push, F - dv (t - t_c - h) (h half ``CONTACT_TIME``), sampled once at
    t_k: the approach at t_c is that ball then, and ``incoming(t_c)`` runs from the sample to
    it at the ball's velocity before the push.
    """
    t_k, t_1, t_c, h = 0.0, 0.011, 0.004, 0.5 * CONTACT_TIME
    start, velocity, acceleration = np.array([0.1, 0.2, 1.0]), np.array([30.0, -5.0, 2.0]), \
        np.array([0.0, 1.0, -9.8])
    push = np.array([-60.0, 4.0, 1.0])

    def flight(t: float) -> np.ndarray:
        return start + velocity * t + 0.5 * acceleration * t * t

    def before(t: float) -> np.ndarray:
        return flight(t) - push * (t - t_c - h)

    path = PointPath(t_k, t_1, tuple(flight(t_k)), tuple(flight(t_1)),
                     tuple(velocity + acceleration * t_k), tuple(velocity + acceleration * t_1))
    approach = HitApproach(path, tuple(before(t_k)))
    assert np.allclose(approach.at(t_c), before(t_c), atol=1e-12)
    assert np.allclose(approach.at(t_k), before(t_k), atol=1e-12)
    incoming = approach.incoming(t_c)
    assert np.allclose(incoming.at(t_k), before(t_k), atol=1e-12)
    assert np.allclose(incoming.at(t_c), before(t_c), atol=1e-12)
    assert np.allclose(incoming.velocity(t_c), velocity + acceleration * t_c - push, atol=1e-9)
    assert np.allclose(incoming.at(0.5 * t_c), before(0.5 * t_c), atol=1e-12)
    # the chords' bound holds over the sharp bend just after t_k
    for ta, tb in ((t_k, 0.002), (0.001, 0.003), (t_k, t_1)):
        chord = np.subtract(approach.at(tb), approach.at(ta))
        worst = max(np.linalg.norm(np.subtract(approach.at(t), approach.at(ta))
                                   - chord * (t - ta) / (tb - ta))
                    for t in np.linspace(ta, tb, 201))
        assert worst <= approach.deviation(ta, tb)
