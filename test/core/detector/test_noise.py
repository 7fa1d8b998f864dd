"""Tests for ``tracker_noise: auto``: each stream's noise estimated from its own samples."""

from typing import List, Tuple

from baseball_collision.core.detector import AUTO_NOISE, Detector, DetectorConfig, Impact
from baseball_collision.core.detector.noise import (
    _guarded, _point_residuals, EXACT_RATIO, HISTORY, MAD_TO_SIGMA, MIN_RESIDUALS, NOISE_FLOOR,
    NoiseEstimate, POINT_SPAN, POSE_SPAN)
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample
from baseball_collision.core.toi import _kernel
from baseball_collision.tools.sim import FAMILIES, make_scenario, sample
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples


def _streams(bat_input: str, rate: float, noise_m: float, seed: int,
             pose_kind: str = 'pose') -> Tuple[float, float]:
    """Return the ball's and the bat's estimates (m) after one pitch of each swing family."""
    ball, bat = _estimators(bat_input, rate, noise_m, seed, pose_kind)
    return ball.sigma, bat.sigma


def _estimators(bat_input: str, rate: float, noise_m: float, seed: int,
                pose_kind: str = 'pose',
                shared: bool = False) -> Tuple[NoiseEstimate, NoiseEstimate]:
    """
    Return the ball's and the bat's estimators after one pitch of each swing family.

    The estimator alone, fed as the detector feeds it (``test_the_detector_estimates_...``
    checks the wiring): each stream's samples in stamp order, a new segment per pitch; a pose
    bat's estimator of ``pose_kind`` (``'point'``: fourth differences, as the ball's). The
    markers have their own noise each, or with ``shared`` one draw shakes the whole bat.
    """
    estimates = (NoiseEstimate('point'),
                 NoiseEstimate('length' if bat_input == 'points' else pose_kind))
    ball, bat = Stream('ball'), Stream('bat')
    for i, family in enumerate(FAMILIES):
        scenario = make_scenario('barrel', np.random.default_rng(seed + i), family=family)
        samples = sample(scenario, rate, np.random.default_rng(seed + i), jitter_s=2e-4,
                         grid_s=1e-3, noise_m=noise_m,
                         marker_spread_m=0.3 if noise_m and not shared else None)
        times = (samples.ball_stamps_ns - samples.start_ns) * 1e-9 + 2.0 * i
        for j, (t, point) in enumerate(zip(times, samples.ball_positions.tolist())):
            ball.append(float(t), j, tuple(point), j == 0)
            estimates[0].update(ball)
        times = (samples.bat_stamps_ns - samples.start_ns) * 1e-9 + 2.0 * i
        for j, (t, knob, tip, position) in enumerate(zip(
                times, samples.knobs.tolist(), samples.tips.tolist(),
                samples.bat_positions.tolist())):
            bat.append(float(t), j, BatSample(tuple(knob), tuple(tip), tuple(position),
                                              (0.0, 0.0, 0.0, 1.0)), j == 0)
            estimates[1].update(bat)
    return estimates


@pytest.mark.parametrize('noise_mm', [0.5, 1.0, 2.0])
@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_auto_recovers_the_noise_of_knob_tip_swings(rate: float, noise_mm: float) -> None:
    """
    Five pitches (one per family) at 90 and 360 Hz: ball and bat within 25 % of the noise.

    (The estimate is a median over 100-384 residuals, whose spread is about 1.25 / sqrt(n):
    8-13 % 1-sigma; 25 % is 2-3 sigma.)
    """
    for estimate in _streams('points', rate, noise_mm * 1e-3, 30):
        assert estimate == pytest.approx(noise_mm * 1e-3, rel=0.25)


@pytest.mark.parametrize('noise_mm', [0.3, 1.0])
@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_knob_and_tip_sharing_their_noise_read_it_from_the_knob(rate: float,
                                                                noise_mm: float) -> None:
    """
    Knob and tip points shaken as one body (points from one rigid body's pose): not exact.

    Their length never changes, so the length alone read 0 and the points were interpolated
    with their noise; the knob's eighth differences read it as a pose's position's do (the mean
    of four draws within 12 %, ``test_auto_from_poses_is_close``). Markers with their own noise
    keep the length's estimate (the median of its residuals), not the knob's.
    """
    noise = noise_mm * 1e-3
    found = []
    for seed in (50, 56, 62, 68):
        _, bat = _estimators('points', rate, noise, seed, shared=True)
        assert max(map(abs, bat.residuals)) < 1e-9  # the length: exact
        found.append(bat.sigma)
    assert np.mean(found) == pytest.approx(noise, rel=0.12)
    _, bat = _estimators('points', rate, noise, 50)
    assert bat.sigma == MAD_TO_SIGMA * float(np.median(np.abs(bat.residuals)))


def test_exact_knob_and_tip_points_at_60_hz_stay_exact() -> None:
    """
    At 60 Hz a swing's own motion fills the knob's eighth differences (a pose reads it as noise).

    The tip's read it 6-9 times more, which shared noise never does: exact knob and tip points
    still read exact, where the knob's differences alone, past their own guard, read 0.29-0.38
    mm in four of these nine draws.
    """
    fooled = 0
    for seed in range(80, 130, 6):
        _, bat = _estimators('points', 60.0, 0.0, seed)
        assert bat.sigma == 0.0
        fooled += _guarded(bat._knob, bat._knob_motion) > 0.0
    assert fooled == 4


@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_auto_finds_no_noise_on_clean_swings(rate: float) -> None:
    """Exact samples: the ball's and the knob-tip bat's estimates are 0 (below NOISE_FLOOR)."""
    assert _streams('points', rate, 0.0, 40) == (0.0, 0.0)


@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_auto_on_exact_samples_reports_what_exact_interpolation_does(rate: float) -> None:
    """
    ``tracker_noise: auto`` on exact samples: the same impacts, to the last field, as 0.

    The estimate is 0, not a rounding-level sigma that would smooth the samples and report
    sigmas of that size in place of the interpolation's own error estimate.
    """
    scenario = make_scenario('barrel', np.random.default_rng(8), family='tilted')
    samples = sample(scenario, rate, np.random.default_rng(8), jitter_s=2e-4, grid_s=1e-3)
    found = []
    for noise in (AUTO_NOISE, 0.0):
        detector = Detector(DetectorConfig(bat_input='points', model='c2',
                                           tracker_noise=noise))
        events = [event for stamp, role, values in samples.messages('points')
                  for event in detector.add(role, stamp, values)] + detector.finish()
        found.append([event for event in events if isinstance(event, Impact)])
    assert len(found[0]) == 1 and found[0] == found[1]
    assert found[0][0].time_uncertainty_s > 1e-8


@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_auto_from_poses_is_close(rate: float) -> None:
    """
    A pose's position with 0.3 and 1 mm of noise: the mean of four draws within 12 %.

    (Eighth differences of one pitch per family, 23 samples each at 90 Hz, spread about 10 %
    per draw: 0.74-1.05 of the noise at 90 Hz, 0.90-1.04 at 360, in these four.)
    """
    for noise in (3e-4, 1e-3):
        found = [_streams('pose', rate, noise, seed)[1] for seed in (50, 56, 62, 68)]
        assert np.mean(found) == pytest.approx(noise, rel=0.12)


@pytest.mark.parametrize('rate', [90.0, 120.0])
def test_auto_takes_an_exact_pose_as_exact_where_its_swing_dwarfs_its_noise(rate) -> None:
    """
    An exact pose at 90 and 120 Hz: estimated 0, as its swing fills its fourth differences.

    Its eighth differences still read some of the swing at 90 Hz (micrometres: above
    ``NOISE_FLOOR``), its fourth ones 4-30 times more (``EXACT_RATIO``: taken as exact); a
    ball's estimate (fourth differences alone) of the same positions reads that much.
    """
    estimate = _estimators('pose', rate, 0.0, 50)[1]
    fourth = _streams('pose', rate, 0.0, 50, 'point')[1]
    assert estimate.sigma == 0.0 and fourth > 5e-5
    if rate == 90.0:
        assert estimate._median.sigma >= NOISE_FLOOR  # (zero by the ratio, not the floor)
    assert fourth > EXACT_RATIO * estimate._median.sigma


def test_the_detector_estimates_each_stream_under_auto_only() -> None:
    """
    tracker_noise -1: the streams carry their estimates (1 mm within 40 %); 0: none.

    The impact's time sigma then covers the noise: larger than the noise-free estimate.
    """
    scenario = make_scenario('barrel', np.random.default_rng(3), family='tilted')
    samples = sample(scenario, 90.0, np.random.default_rng(3), jitter_s=2e-4, grid_s=1e-3,
                     noise_m=1e-3, marker_spread_m=0.3)
    sigmas = []
    for noise, expected in ((AUTO_NOISE, 1e-3), (0.0, 0.0)):
        detector = Detector(DetectorConfig(bat_input='points', model='c2',
                                           tracker_noise=noise))
        impacts = [event for stamp, role, values in samples.messages('points')
                   for event in detector.add(role, stamp, values) if isinstance(event, Impact)]
        assert len(impacts) == 1
        for stream in (detector._ball, detector._bat):
            assert stream.noise == pytest.approx(expected, rel=0.4, abs=1e-12)
        sigmas.append(impacts[0].time_uncertainty_s)
    assert sigmas[0] > sigmas[1]


@pytest.mark.parametrize('bat_input, kinds', [
    ('points', ('point', 'length')), ('pose', ('point', 'pose'))])
def test_the_detector_takes_sixth_differences_for_a_pose_bat(bat_input: str, kinds) -> None:
    """The ball's estimate: fourth differences; a pose bat's sixth; knob and tip: its length."""
    detector = Detector(DetectorConfig(bat_input=bat_input, model='c2', tracker_noise=AUTO_NOISE))
    assert tuple(estimate.kind for estimate in detector._noise) == kinds
    assert detector._noise[0].span == 5 and (bat_input == 'points' or
                                             detector._noise[1].span == POSE_SPAN)


@pytest.mark.parametrize('kind', ['point', 'pose'])
def test_no_estimate_until_enough_residuals_and_none_across_a_break(kind: str) -> None:
    """Fewer than MIN_RESIDUALS residuals: 0; a new segment restarts the window's samples."""
    rng = np.random.default_rng(1)
    stream, estimate = Stream('ball'), NoiseEstimate(kind)
    span = {'point': POINT_SPAN, 'pose': POSE_SPAN}[kind]
    assert estimate.span == span
    for i in range(span - 1 + MIN_RESIDUALS // 3):
        stream.append(i * 0.01, i, tuple(rng.normal(0.0, 1e-3, 3)), i == 0)
        found = estimate.update(stream)
        assert (found > 0.0) == (3 * max(0, i - span + 2) >= MIN_RESIDUALS)
    stream.append(1.0, 99, (0.0, 0.0, 0.0), True)
    before = len(estimate.residuals)
    estimate.update(stream)
    assert len(estimate.residuals) == before


def test_length_residuals_are_half_the_length_change() -> None:
    """A knob-tip bat: the residual is half the change of its length, whatever it moved."""
    stream, estimate = Stream('bat'), NoiseEstimate('length')
    stream.append(0.0, 1, BatSample((0.0, 0.0, 0.0), (0.8, 0.0, 0.0)), True)
    stream.append(0.01, 2, BatSample((1.0, 2.0, 0.0), (1.0, 2.0, 0.802)), False)
    estimate.update(stream)
    assert list(estimate.residuals) == [pytest.approx(0.001)]


@settings(max_examples=examples(60), deadline=None)
@given(span=st.sampled_from([5, 7, 9]),
       steps=st.lists(st.floats(0.001, 0.02), min_size=8, max_size=8),
       coefficients=st.lists(st.floats(-100.0, 100.0), min_size=8, max_size=8))
def test_differences_vanish_on_polynomials_and_have_unit_noise_gain(span, steps,
                                                                    coefficients) -> None:
    """
    On uneven stamps the residual of a polynomial of degree span - 2 is 0; of noise, sigma's.

    Five samples (the ball's fourth differences): a cubic; nine (a pose's eighth): a septic.
    """
    times = np.concatenate([[0.0], np.cumsum(steps[:span - 1])]).tolist()
    polynomial = np.polyval(coefficients[:span - 1], times)
    scale = 1.0 + np.abs(polynomial).max()
    # each coordinate the polynomial: its own, twice it, and its negative
    points = [(c, 2.0 * c, -c) for c in polynomial.tolist()]
    assert max(map(abs, _point_residuals(times, points)[0])) <= 1e-8 * scale
    rng = np.random.default_rng(3)
    noise = rng.normal(0.0, 1.0, (7000, span, 3))
    residuals = [r for window in noise.tolist() for r in _point_residuals(times, window)[0]]
    assert np.std(residuals) == pytest.approx(1.0, rel=0.03)


def test_a_window_of_another_span_or_kind_is_refused() -> None:
    """Windows of an even number of samples, or of fewer than 3 or more than 9; other kinds."""
    times, points = [0.0, 0.01, 0.02, 0.03], [(0.0, 0.0, 0.0)] * 4
    with pytest.raises(ValueError, match='odd'):
        _point_residuals(times, points)
    with pytest.raises(ValueError, match='odd'):
        _point_residuals(times[:1], points[:1])
    with pytest.raises(ValueError, match='odd'):
        _point_residuals((times * 3)[:11], (points * 3)[:11])
    with pytest.raises(ValueError, match="'pose'"):
        NoiseEstimate('ball')
    with pytest.raises(ValueError, match='odd'):
        _kernel.NoiseMedian(HISTORY, MAD_TO_SIGMA, NOISE_FLOOR, MIN_RESIDUALS, 48, 11)


@settings(max_examples=examples(40), deadline=None)
@given(seed=st.integers(0, 10_000),
       runs=st.lists(st.one_of(st.integers(1, 40), st.integers(120, 300)), min_size=1,
                     max_size=12),
       breaks=st.lists(st.integers(0, 200), max_size=5), history=st.integers(0, 8),
       kind=st.sampled_from(['point', 'pose']))
def test_points_taken_in_bulk_are_updates_in_turn(seed: int, runs: List[int],
                                                  breaks: List[int], history: int,
                                                  kind: str) -> None:
    """
    ``take_points`` over a run of samples leaves the state ``update`` leaves after each.

    Random uneven stamps and 1 mm of noise on a moving point, segments starting anywhere
    (a sample that starts one goes through ``update``, as through ``Detector.add``), runs
    of any length after them: the same residuals in the same order and the same estimate, to
    the bit. A point's windows (five samples) and a pose's (seven); ``take_points`` is given
    the newest eight samples before the run, as the kernel's fast-forward gives them, and
    takes what its windows reach.
    """
    rng = np.random.default_rng(seed)
    total = history + sum(runs)
    times = np.cumsum(rng.uniform(0.002, 0.012, total))
    points = rng.normal(0.0, 1e-3, (total, 3)) + np.outer(times, (30.0, -4.0, 2.0))
    starts = {0} | {b for b in breaks if b < total}
    one, bulk = NoiseEstimate(kind), NoiseEstimate(kind)
    stream, mirror = Stream('ball'), Stream('ball')
    for i in range(total):
        stream.append(float(times[i]), i, tuple(points[i].tolist()), i in starts)
        one.update(stream)
    i, cuts = 0, [history] + runs
    for size in cuts:
        end = min(i + size, total)
        while i < end:
            if i in starts or i < history:
                mirror.append(float(times[i]), i, tuple(points[i].tolist()), i in starts)
                bulk.update(mirror)
                i += 1
                continue
            run = end
            while run > i and any(s in starts for s in range(i, run)):
                run -= 1
            before = (mirror.times[-8:], mirror.values[-8:], mirror.breaks[-8:])
            bulk.take_points(before, times[i:run], points[i:run])
            for k in range(i, run):
                mirror.append(float(times[k]), k, tuple(points[k].tolist()), False)
            i = run
    assert list(bulk.residuals) == list(one.residuals) and bulk.sigma == one.sigma
    assert bulk.motion_residuals == one.motion_residuals


@settings(max_examples=examples(200), deadline=None)
@given(batches=st.lists(st.tuples(st.integers(1, 120), st.floats(0.0, 1.0),
                                  st.sampled_from([1e-12, 1e-9, 5e-7, 6.7e-7, 1e-6, 1e-3])),
                        min_size=1, max_size=12),
       seed=st.integers(0, 1000))
def test_the_estimate_is_the_median_of_the_newest_residuals(
        batches: List[Tuple[int, float, float]], seed: int) -> None:
    """
    The estimate is ``MAD_TO_SIGMA`` times the newest ``HISTORY`` residuals' median.

    After any mix of small and large residuals, one by one or many at once (0 below
    ``NOISE_FLOOR``). Each batch holds a share of residuals far below the floor and the rest
    of one size (some about the floor's median itself), so that the small ones are about
    half of those kept: where they are more than half the estimate is 0 without the sorted
    list, else it is read off the list made again.
    """
    rng = np.random.default_rng(seed)
    estimate = NoiseEstimate('point')
    for size, share, scale in batches:
        found = np.where(rng.random(size) < share, 1e-12, scale) * rng.choice([-1.0, 1.0], size)
        estimate.take((found * rng.uniform(0.5, 1.5, size)).tolist())
        kept = sorted(map(abs, estimate.residuals))
        expected = 0.0
        if len(kept) >= MIN_RESIDUALS:
            middle = len(kept) // 2
            median = (kept[middle] if len(kept) % 2
                      else (kept[middle - 1] + kept[middle]) / 2.0)
            expected = MAD_TO_SIGMA * median if MAD_TO_SIGMA * median >= NOISE_FLOOR else 0.0
        assert estimate.sigma == expected


def test_the_kept_residuals_are_the_newest_in_order_and_take_points_checks_its_input() -> None:
    """
    The kernel's median keeps the newest ``HISTORY`` residuals in arrival order; bad input.

    Residuals taken one by one after a sort (the sorted values moved), then many at once,
    then more than it holds; ``take_points`` refuses windows outside its samples and points
    of another length than the stamps, ``take_run`` breaks of another length than the stamps,
    and their arrays may be any float arrays (copied).
    """
    estimate = NoiseEstimate('point')
    values = [(-1.0) ** i * 1e-3 * (1 + i % 7) for i in range(1000)]
    estimate.take(values[:30])
    estimate.take(values[30:31])
    assert estimate.residuals == values[:31]
    estimate.take(values[31:200])
    assert estimate.residuals == values[:200]
    estimate.take(values[200:])
    assert estimate.residuals == values[-HISTORY:]
    assert estimate.sigma == MAD_TO_SIGMA * sorted(map(abs, values[-HISTORY:]))[HISTORY // 2]
    median = estimate._median
    times, points = np.arange(6.0) * 0.01, np.zeros((6, 3))
    with pytest.raises(IndexError, match='outside'):
        median.take_points([], [], times, points, 0, 3)
    with pytest.raises(ValueError, match='len'):
        median.take_points([], [], times, points[:5], 0, 1)
    with pytest.raises(ValueError, match='length'):
        median.take_points([0.0], [], times, points, 0, 1)
    with pytest.raises(TypeError, match='3 numbers'):
        median.take_points([0.0], [(0.0, 1.0)], times, points, 0, 1)
    with pytest.raises(ValueError, match='old_breaks'):
        median.take_run([0.0], [(0.0, 0.0, 0.0)], [], times, points)
    with pytest.raises(TypeError, match='take_run'):
        median.take_run([], [], [], times)
    strided = NoiseEstimate('point')
    strided.take_points(((), (), ()), times[::-1][::-1], np.asfortranarray(points))
    assert strided.residuals == [0.0] * 6


def test_a_nan_residual_neither_crashes_nor_gives_a_number_it_should_not() -> None:
    """
    Residuals that are NaN (differences that overflowed) sort last: no crash, no NaN estimate.

    Under half of them NaN, the estimate is the finite ones' median; all NaN, 0.
    """
    estimate = NoiseEstimate('point')
    estimate.take([1e-3] * 100)
    estimate.take([float('nan')] * 10)
    assert estimate.sigma == MAD_TO_SIGMA * 1e-3
    for _ in range(HISTORY):
        estimate.take([float('nan')])
    assert estimate.sigma == 0.0 and len(estimate.residuals) == HISTORY
    estimate.take([2e-3] * HISTORY)
    assert estimate.sigma == MAD_TO_SIGMA * 2e-3


@settings(max_examples=examples(60), deadline=None)
@given(seed=st.integers(0, 10_000), kept=st.integers(0, 450), new=st.integers(1, 1200),
       noise=st.sampled_from([0.0, 1e-7, 1e-3]), hits=st.integers(0, 40),
       possible=st.lists(st.integers(0, 1200), max_size=12), real=st.floats(0.0, 1.0),
       kind=st.sampled_from(['point', 'pose']))
def test_the_bounds_hold_the_estimate_after_every_sample(
        seed: int, kept: int, new: int, noise: float, hits: int, possible: List[int],
        real: float, kind: str) -> None:
    """
    ``bounds`` never falls below the estimate after any of a chunk's samples.

    A point moving on a curve with noise, a share of samples kicked (hits: large residuals),
    ``kept`` samples taken before the chunk, then the chunk's one by one; of its possible
    breaks (``breaks`` True) some start a segment, the others do not, as at the plan's stops.
    """
    rng = np.random.default_rng(seed)
    total = kept + new
    times = np.cumsum(rng.uniform(0.001, 0.004, total))
    points = np.outer(np.sin(3.0 * times), (1.0, 2.0, -0.5))
    points += rng.normal(0.0, noise or 1e-300, (total, 3))
    points[rng.integers(0, total, hits)] += rng.normal(0.0, 0.05, (hits, 3))
    starts = {0} | {kept + b for b in possible if kept + b < total}
    taken = {s for s in starts if s < kept or rng.random() < real} | {0}
    estimate, stream = NoiseEstimate(kind), Stream('ball')
    for i in range(kept):
        stream.append(float(times[i]), i, tuple(points[i].tolist()), i in taken)
        estimate.update(stream)
    breaks = np.array([i in starts for i in range(total)])
    bounds = estimate.bounds(times, points, breaks, kept)
    assert bounds.shape == (new,)
    for i in range(kept, total):
        stream.append(float(times[i]), i, tuple(points[i].tolist()), i in taken)
        assert estimate.update(stream) <= bounds[i - kept]
    with pytest.raises(ValueError, match='shapes'):
        estimate.bounds(times, points[:-1], breaks, kept)
    with pytest.raises(ValueError, match='point streams'):
        NoiseEstimate('length').bounds(times, points, breaks, kept)


@pytest.mark.parametrize('kind', ['point', 'pose'])
def test_a_point_streams_update_takes_its_newest_points_or_positions(kind: str) -> None:
    """
    ``update`` takes the residuals of the ``span`` newest samples' points (a pose's positions).

    The same residuals as ``_point_residuals`` of those points, for tuples, lists and poses
    alike; nothing while a break is among the ``span - 1`` newest.
    """
    rng = np.random.default_rng(4)
    reach = NoiseEstimate(kind).span - 1
    n = reach + 5  # (a break at reach + 2: two windows before it, none after)
    times = np.cumsum(rng.uniform(0.002, 0.004, n)).tolist()
    points = rng.normal(0.0, 1e-3, (n, 3)).tolist()
    for make in (tuple, list, lambda p: BatSample((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), tuple(p),
                                                  (0.0, 0.0, 0.0, 1.0))):
        stream, estimate = Stream('s'), NoiseEstimate(kind)
        for i in range(n):
            stream.append(times[i], i, make(points[i]), i in (0, reach + 2))
            estimate.update(stream)
        expected = [r for k in (reach, reach + 1)
                    for r in _point_residuals(times[k - reach:k + 1], points[k - reach:k + 1])[0]]
        assert estimate.residuals == expected


@pytest.mark.parametrize('kind', ['point', 'pose', 'length'])
def test_update_at_a_sample_is_update_when_it_was_the_newest(kind: str) -> None:
    """
    ``update_at(stream, j)`` takes what ``update`` took when sample j was the newest.

    Every sample of a stream with a break, taken one by one after the whole stream is there
    (a fast-forward's samples after the cursor), gives the estimates and residuals of updates
    after each append, to the bit; a sample beyond the stream is an IndexError.
    """
    rng = np.random.default_rng(6)
    n = 3 * MIN_RESIDUALS + 20
    times = np.cumsum(rng.uniform(0.002, 0.004, n)).tolist()
    points = rng.normal(0.0, 1e-3, (n, 3))
    values = [BatSample(tuple(p), tuple(p + (0.8, 0.0, 0.0) + rng.normal(0.0, 1e-3, 3)),
                        tuple(p), (0.0, 0.0, 0.0, 1.0)) for p in points] \
        if kind != 'point' else [tuple(p) for p in points]
    after, at = NoiseEstimate(kind), NoiseEstimate(kind)
    stream = Stream('s')
    expected = []
    for i in range(n):
        stream.append(times[i], i, values[i], i in (0, n // 2))
        expected.append(after.update(stream))
    found = [at.update_at(stream, j) for j in range(n)]
    assert found == expected and at.residuals == after.residuals
    assert max(found) > 0.0
    if kind != 'length':
        with pytest.raises(IndexError):
            at.update_at(stream, n)
