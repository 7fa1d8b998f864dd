"""Tests for the c2 windows with noise: smoothed paths, their rates, the propagated spreads."""

from collections import Counter
import math
from typing import Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, fitting, Impact
from baseball_collision.core.detector.chunks import ROLE_CODES
from baseball_collision.core.detector.fitting import (
    ball_flight, bat_errors, bat_gains, bat_shifts, c2_bat_ahead, c2_bat_path, c2_point_path,
    c2_window, flight_window, kept_history, point_gains, point_shifts, quintic_piece_weights,
    swing_rate, widened)
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample, C2BatPath
from baseball_collision.core.motion.c2 import rotate, rotation_to
from baseball_collision.core.motion.flight import flight_or_none
from baseball_collision.core.motion.splines import quintic_window
from baseball_collision.tools.sim import DEFAULT_START_NS as START_NS, make_scenario, sample
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples


def _swing(t: float):
    """Return ball, knob and tip (m) at t (s): a bat turning about a tilting axis."""
    angle = 10.0 * t + 150.0 * t * t
    tilt = 2.0 * t
    direction = np.array([math.cos(angle) * math.cos(tilt), math.sin(angle),
                          math.cos(angle) * math.sin(tilt)])
    knob = np.array([0.5 * t, 0.1 * t * t, 1.0 + 0.2 * t])
    return (np.array([5.0 - 38.0 * t, 0.1, 1.2 - 4.9 * t * t]), knob, knob + 0.86 * direction)


def _streams(rate: float, noise: float, seed: int, count: int = 30, stamps: int = 0):
    """Return ball and bat streams of a swing on uneven stamps (seeded apart), noise in m."""
    rng = np.random.default_rng(seed)
    ball, bat = Stream('ball'), Stream('bat')
    times = np.cumsum(np.random.default_rng(stamps).uniform(0.8, 1.2, count)) / rate
    for i, t in enumerate(times):
        b, k, e = (p + rng.normal(0.0, noise, 3) for p in _swing(t))
        ball.append(float(t), i + 1, tuple(b), i == 0)
        bat.append(float(t), i + 1, BatSample(tuple(k), tuple(e)), i == 0)
    return ball, bat


def test_a_vanishing_noise_gives_the_interpolating_paths() -> None:
    """With 1 nm of noise the smoothed paths are the interpolating ones (chart carried over)."""
    ball, bat = _streams(120.0, 0.0, 1)
    k = 20
    window = c2_window(bat, k, 0.05, 0, 8)
    smooth_bat = c2_bat_path(bat, k, window, 1e-9)
    plain = C2BatPath.fitted(bat.times[window.start:window.stop],
                             bat.values[window.start:window.stop], k - window.start)
    smooth_ball = c2_point_path(ball, k, window, 1e-9)
    plain_ball = c2_point_path(ball, k, window)
    for s in np.linspace(0.0, 1.0, 7):
        t = bat.times[k] + s * (bat.times[k + 1] - bat.times[k])
        for a, b in zip(smooth_bat.at(t), plain.at(t)):
            assert np.allclose(a, b, atol=1e-6)
        assert np.allclose(swing_rate(smooth_bat, t), swing_rate(plain, t), rtol=1e-4)
        assert np.allclose(smooth_ball.at(t), plain_ball.at(t), atol=1e-6)


def test_swing_rate_is_the_turn_of_the_true_direction() -> None:
    """Without noise at 360 Hz, u x u' of the path matches the swing's own within 0.5 %."""
    _, bat = _streams(360.0, 0.0, 2, 40)
    k = 30
    path = c2_bat_path(bat, k, c2_window(bat, k, 0.05, 0, 8))
    t = 0.5 * (bat.times[k] + bat.times[k + 1])

    def direction(s: float) -> np.ndarray:
        _, knob, tip = _swing(s)
        return (tip - knob) / np.linalg.norm(tip - knob)
    truth = np.cross(direction(t), (direction(t + 1e-6) - direction(t - 1e-6)) / 2e-6)
    assert np.linalg.norm(np.subtract(swing_rate(path, t), truth)) < 5e-3 * np.linalg.norm(truth)


def test_smoothing_brings_the_paths_closer_to_the_truth() -> None:
    """Over seeded noisy swings (1 mm) the smoothed bat and ball are nearer the truth."""
    errors = {True: [], False: []}
    for seed in range(16):
        ball, bat = _streams(360.0, 1e-3, seed, 40)
        k = 34
        t = 0.5 * (bat.times[k] + bat.times[k + 1])
        truth = _swing(t)
        for smoothed in (True, False):
            window = c2_window(bat, k, 0.05, 0, 8)
            noise = 1e-3 if smoothed else 0.0
            knob, tip = c2_bat_path(bat, k, window, noise).at(t)
            ball_at = c2_point_path(ball, k, window, noise).at(t)
            errors[smoothed] += [np.linalg.norm(np.subtract(tip, truth[2])),
                                 np.linalg.norm(np.subtract(ball_at, truth[0]))]
    assert np.sqrt(np.mean(np.square(errors[True]))) < 0.8 * np.sqrt(
        np.mean(np.square(errors[False])))


def test_windows_widen_with_noise_within_their_segment() -> None:
    """A widened window reaches back NOISE_SPAN (at most 32 samples), never past a break."""
    _, bat = _streams(360.0, 0.0, 3, 60)
    window = c2_window(bat, 50, 0.05, 0, 8)
    wide = widened(bat, window)
    assert wide.stop == window.stop and len(wide) == 32
    bat.breaks[40] = True
    assert widened(bat, window).start == 40


@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_propagated_spreads_match_a_monte_carlo_of_the_paths(rate: float) -> None:
    """
    Brute force: the spread of the paths' positions and rates at t over 150 noisy draws.

    The propagated 1-sigma errors (``point_gains``, ``bat_gains``) agree within 25 % with the
    standard deviations measured across draws (ball per coordinate, the knob per coordinate,
    the direction across the bat, the knob's rate), and so does the spread across the bat of
    the point 0.8 of the way to the tip, with the knob's and the direction's correlation
    (from knob and tip points a knob marker's noise turns the bat the other way: without it
    the spread comes out 1.4-1.7 times too large).
    """
    noise, k, fraction = 1e-3, 22, 0.8
    measured = {'ball': [], 'knob': [], 'turn': [], 'knob_rate': [], 'point': []}
    predicted = None
    for seed in range(150):
        ball, bat = _streams(rate, noise, 100 + seed)
        t = 0.4 * bat.times[k] + 0.6 * bat.times[k + 1]
        window = c2_window(bat, k, 0.05, 0, 8)
        measured['ball'].append(c2_point_path(ball, k, window, noise).at(t))
        path = c2_bat_path(bat, k, window, noise)
        knob, tip = path.at(t)
        measured['knob'].append(knob)
        measured['turn'].append(np.subtract(tip, knob) / math.dist(tip, knob))
        measured['knob_rate'].append(path.knob.velocity(t))
        measured['point'].append(np.add(knob, fraction * np.subtract(tip, knob)))
        if predicted is None:
            predicted = (point_gains(ball, window, k, t, noise)[0] * noise,
                         bat_gains(bat, window, k, t, noise))
    spread = {name: np.std(np.array(values), axis=0) for name, values in measured.items()}
    ball_error, ((knob, turn, _), (knob_rate, _, _), correlation) = predicted
    assert np.mean(spread['ball']) == pytest.approx(ball_error, rel=0.25)
    assert np.mean(spread['knob']) == pytest.approx(knob, rel=0.25)
    assert np.sqrt(np.sum(spread['turn'] ** 2) / 2.0) == pytest.approx(turn, rel=0.25)
    assert np.mean(spread['knob_rate']) == pytest.approx(knob_rate, rel=0.25)
    axis = np.mean(measured['turn'], axis=0)
    axis /= np.linalg.norm(axis)
    across = np.linalg.svd(np.eye(3) - np.outer(axis, axis))[0][:, :2]  # two unit normals
    point_spread = np.sqrt(np.mean(np.var(np.array(measured['point']) @ across, axis=0)))
    lever = fraction * 0.86 * turn
    assert 0.5 < correlation <= 1.0
    assert point_spread == pytest.approx(math.sqrt(
        knob ** 2 + lever ** 2 - math.sqrt(2.0) * correlation * knob * lever), rel=0.25)
    assert math.hypot(knob, lever) > 1.3 * point_spread  # (the correlation left out)


@pytest.fixture
def flight(monkeypatch):
    """Turn the ball's flight fit on (degree 2 over 0.15 s, ending at the closing frame)."""
    monkeypatch.setattr(fitting, 'FLIGHT', (2, 0.15, 'closing'))


def _bounced(ball: Stream, at: int) -> None:
    """Send the ball back toward the pitcher from sample ``at`` on (a hit)."""
    t0, y0 = ball.times[at - 1], ball.values[at - 1]
    ball.values[at:] = [(y0[0] + 30.0 * (t - t0), y0[1], y0[2]) for t in ball.times[at:]]


def _same(path, other) -> bool:
    """Return True when two point paths give the same positions to the bit over their span."""
    return (path.t0, path.t1) == (other.t0, other.t1) and all(
        path.at(t) == other.at(t) for t in np.linspace(path.t0, path.t1, 5))


@pytest.mark.usefixtures('flight')
def test_flight_fit_takes_the_ball_in_free_flight_and_not_a_bounce() -> None:
    """
    A ballistic ball with noise gets the flight fit's path, closer to the truth than smoothed.

    Bounced at the closing frame, the fit ending at the opening frame; bounced before it, or
    without noise or a config, today's window paths.
    """
    config = DetectorConfig(model='c2')
    noise, k = 1e-3, 22
    errors = {'flight': [], 'smoothed': []}
    for seed in range(40):
        ball, _ = _streams(120.0, noise, 300 + seed)
        window = c2_window(ball, k, config.max_gap, 0, 8)
        t = 0.5 * (ball.times[k] + ball.times[k + 1])
        fit = ball_flight(ball, k, window, noise, config)
        assert fit is not None and fit.centre + fit.scale == pytest.approx(ball.times[k + 1])
        path = c2_point_path(ball, k, window, noise, config)
        assert np.allclose(path.at(t), fit.at(t), atol=1e-12)
        truth = _swing(t)[0]
        errors['flight'].append(np.subtract(path.at(t), truth))
        errors['smoothed'].append(np.subtract(c2_point_path(ball, k, window, noise).at(t), truth))
    assert np.std(errors['flight']) < 0.9 * np.std(errors['smoothed'])
    ball, _ = _streams(120.0, noise, 7)
    window = c2_window(ball, k, config.max_gap, 0, 8)
    assert _same(c2_point_path(ball, k, window, 0.0, config), c2_point_path(ball, k, window))
    assert _same(c2_point_path(ball, k, window, noise, None),
                 c2_point_path(ball, k, window, noise))
    _bounced(ball, k + 1)
    fit = ball_flight(ball, k, window, noise, config)
    assert fit is not None and fit.centre + fit.scale == pytest.approx(ball.times[k])
    _bounced(ball, k - 2)
    assert ball_flight(ball, k, window, noise, config) is None
    assert _same(c2_point_path(ball, k, window, noise, config),
                 c2_point_path(ball, k, window, noise))


@pytest.mark.usefixtures('flight')
def test_flight_window_keeps_to_its_segment_gaps_and_history() -> None:
    """It reaches back 0.15 s at most, not past a segment's start or a gap longer than max_gap."""
    ball, _ = _streams(360.0, 0.0, 1, 90)
    found = flight_window(ball, 80, 0.05, 0.15)
    assert ball.times[80] - ball.times[found.start] <= 0.15
    assert ball.times[80] - ball.times[found.start - 1] > 0.15
    ball.breaks[60] = True
    assert flight_window(ball, 80, 0.05, 0.15).start == 60
    assert flight_window(ball, 80, 0.3 * (ball.times[71] - ball.times[70]), 0.15).start == 80
    config = DetectorConfig(model='c2', velocity_window=0.02, prediction_window=0.02)
    assert kept_history(config) == pytest.approx(0.03)


@pytest.mark.usefixtures('flight')
def test_flight_gains_match_a_monte_carlo() -> None:
    """``point_gains`` of a flight fit: its positions' spread at t over 200 draws (+-15 %)."""
    config = DetectorConfig(model='c2')
    noise, k = 1e-3, 22
    at = []
    for seed in range(200):
        ball, _ = _streams(360.0, noise, 500 + seed)
        window = c2_window(ball, k, config.max_gap, 0, 8)
        t = 0.3 * ball.times[k] + 0.7 * ball.times[k + 1]
        at.append(c2_point_path(ball, k, window, noise, config).at(t))
    gain = point_gains(ball, window, k, t, noise, config)[0]
    assert gain < point_gains(ball, window, k, t, noise)[0]
    assert np.mean(np.std(np.array(at), axis=0)) == pytest.approx(gain * noise, rel=0.15)


def _jerking_ball(noise: float, seed: int, jerk: float) -> Stream:
    """Return a ball stream at 360 Hz over 0.2 s with a constant jerk (m/s^3) along x."""
    rng = np.random.default_rng(seed)
    ball = Stream('ball')
    for i, t in enumerate(np.arange(72) / 360.0):
        exact = (5.0 - 38.0 * t + jerk * t ** 3 / 6.0, 0.1 + 0.5 * t, 1.2 - 4.9 * t * t)
        ball.append(float(t), i + 1, tuple(np.add(exact, rng.normal(0.0, noise, 3))), i == 0)
    return ball


@pytest.mark.usefixtures('flight')
def test_a_flight_fits_shift_is_its_distance_from_the_richer_fit() -> None:
    """
    ``point_shifts`` of a flight fit: the cubic's position at t less the parabola's.

    A ball whose motion is a cubic (a constant jerk), exact samples fitted as if with 1 mm of
    noise: the shift is the parabola's own error at t (the truth less its path, to 1e-9 m).
    Over 200 draws of that noise on a parabola the shifts scatter by the spread reported
    (+-15 %) about nothing. Without noise, nothing.
    """
    config = DetectorConfig(model='c2')
    k, noise = 64, 1e-3
    ball = _jerking_ball(0.0, 0, 10.0)
    window = c2_window(ball, k, config.max_gap, 0, 8)
    t = 0.4 * ball.times[k] + 0.6 * ball.times[k + 1]
    shift, _ = point_shifts(ball, window, k, t, noise, config)
    truth = (5.0 - 38.0 * t + 10.0 * t ** 3 / 6.0, 0.1 + 0.5 * t, 1.2 - 4.9 * t * t)
    error = np.subtract(truth, c2_point_path(ball, k, window, noise, config).at(t))
    assert np.abs(error).max() > 1e-5 and np.allclose(shift, error, rtol=0.0, atol=1e-9)
    shifts = []
    for seed in range(200):
        ball = _jerking_ball(noise, 100 + seed, 0.0)
        shift, spread = point_shifts(ball, window, k, t, noise, config)
        shifts.append(shift)
    assert np.mean(np.std(shifts, axis=0)) == pytest.approx(spread, rel=0.15)
    assert np.abs(np.mean(shifts, axis=0)).max() < 0.3 * spread
    assert not point_shifts(ball, window, k, t, 0.0, config)[0].any()


def test_a_smoothed_bats_shift_is_its_distance_from_the_interpolant() -> None:
    """
    ``bat_shifts``: the smoothed window's knob at t less the interpolant's of the same window.

    1 mm of noise at 360 Hz: the knob's shift is the smoothed path's knob less the
    interpolating path's (the quintic's, as exact samples' paths take it at a window's end)
    through the samples the smoother took (``widened``), to 1e-9 m. Over 100 draws of that
    noise the knob's shifts scatter by the spread reported (+-20 %). Without noise, nothing.
    """
    k, noise = 20, 1e-3
    _, bat = _streams(360.0, noise, 1)
    window = c2_window(bat, k, 0.05, 0, 8)
    t = 0.5 * (bat.times[k] + bat.times[k + 1])
    moved, spreads, _ = bat_shifts(bat, window, k, t, noise)
    apart = np.subtract(c2_bat_path(bat, k, window, noise).at(t)[0],
                        c2_bat_path(bat, k, widened(bat, window), continued=True).at(t)[0])
    assert np.abs(apart).max() > 1e-5 and np.allclose(moved[:3], apart, rtol=0.0, atol=1e-9)
    knobs = [bat_shifts(s, window, k, t, noise)[0][:3]
             for s in (_streams(360.0, noise, 10 + seed)[1] for seed in range(100))]
    assert np.mean(np.std(knobs, axis=0)) == pytest.approx(spreads[0], rel=0.2)
    assert not bat_shifts(bat, window, k, t, 0.0)[0].any()


@settings(max_examples=examples(40), deadline=None)
@given(steps=st.lists(st.floats(0.8, 1.2), min_size=6, max_size=16), at=st.floats(0.0, 1.0),
       seed=st.integers(0, 2 ** 16))
def test_quintic_piece_weights_are_the_exact_paths_quintic(steps, at, seed) -> None:
    """
    ``quintic_piece_weights``: a quintic reproduced, and the exact path's knob on its last piece.

    On uneven stamps (steps within 1.5 of each other) the weights sum to 1, give any polynomial
    of degree 5 at t (1e-9 of its size) and, through a bat window's knobs, the knob of
    ``C2BatPath.fitted(..., continued=True)`` on the window's last piece (1e-12 m).
    """
    rng = np.random.default_rng(seed)
    times = list(np.cumsum(steps) / 90.0)
    j = len(times) - 2
    t = times[j] + at * (times[j + 1] - times[j])
    assert quintic_window(times, j, True)  # (the path below takes the quintic)
    weights = quintic_piece_weights(times, j, t)
    coefficients = rng.normal(0.0, 1.0, 6)
    assert math.isclose(float(weights.sum()), 1.0, abs_tol=1e-9)
    polynomial = np.polynomial.Polynomial(coefficients)
    assert abs(weights @ polynomial(np.array(times)) - polynomial(t)) <= 1e-9 * (
        1.0 + np.abs(coefficients).sum())
    bats = [BatSample(tuple(k), tuple(k + np.array((0.0, 0.86, 0.0))))
            for k in rng.normal(0.0, 0.1, (len(times), 3))]
    knob = C2BatPath.fitted(times, bats, j, True).at(t)[0]
    assert np.allclose(weights @ np.array([b.knob for b in bats]), knob, rtol=0.0, atol=1e-12)


def test_flight_fit_is_the_same_in_chunks_and_one_sample_at_a_time(monkeypatch) -> None:
    """Told the noise, ``add_chunk`` and ``add`` find the same impacts through flight fits."""
    taken = []

    def counting(*args, **kwargs):
        found = flight_or_none(*args, **kwargs)
        taken.append(found is not None)
        return found
    monkeypatch.setattr(fitting, 'flight_or_none', counting)
    rng = np.random.default_rng(11)
    messages = []
    for i, kind in enumerate(('barrel', 'handle', 'miss_over')):
        scenario = make_scenario(kind, rng, family='tilted')
        samples = sample(scenario, 360.0, np.random.default_rng(i), jitter_s=2e-4, grid_s=1e-3,
                         noise_m=1e-3, marker_spread_m=0.3, start_ns=START_NS + i * 10 ** 9)
        messages += samples.messages('pose')
    config = DetectorConfig(model='c2', bat_input='pose', tracker_noise=1e-3)
    one = Detector(config)
    expected = [event for stamp, role, row in messages for event in one.add(role, stamp, row)]
    expected += one.finish()
    values = np.zeros((len(messages), 7))
    for r, (_, _, row) in enumerate(messages):
        values[r, :len(row)] = row
    roles = np.array([ROLE_CODES[role] for _, role, _ in messages], np.int8)
    stamps = np.array([stamp for stamp, _, _ in messages], np.int64)
    chunked, events = Detector(config), []
    for start in range(0, len(messages), 200):
        part = slice(start, start + 200)
        events += chunked.add_chunk(roles[part], stamps[part], values[part],
                                    ['world'] * len(roles[part]), Counter())
    events += chunked.finish()
    assert events == expected
    assert sum(isinstance(event, Impact) for event in events) == 2
    assert any(taken)


def _fields(path: C2BatPath) -> tuple:
    """Return a bat path's numbers (its pieces' coefficients and bounds), to compare bits."""
    return (path.t0, path.t1, path.centre, path.radius, path.spread, path.reference,
            *((part.a, part.b, part.c, part.d, part.end)
              for part in (path.knob, path.turn, path.length)))


def test_a_window_fitted_again_under_noise_is_the_kept_fit() -> None:
    """The same window and noise give the same object, bit-equal to a fit made afresh."""
    ball, bat = _streams(360.0, 1e-3, 5, count=60)
    config = DetectorConfig(model='c2', bat_input='points', tracker_noise=1e-3)
    k = 50
    window = c2_window(bat, k, 0.05, 2, 8)
    fitting._FITS.clear()
    path = c2_bat_path(bat, k, window, 1e-3)
    assert c2_bat_path(bat, k, window, 1e-3) is path
    wide = widened(bat, window)
    fresh = fitting.smoothed_bat_path(bat.times[wide.start:wide.stop],
                                      bat.values[wide.start:wide.stop], k - wide.start, 1e-3)
    assert _fields(path) == _fields(fresh)
    # another noise, another window, other samples on the same stamps: fitted, not kept
    assert c2_bat_path(bat, k, window, 2e-3) is not path
    assert c2_bat_path(bat, k - 1, c2_window(bat, k - 1, 0.05, 2, 8), 1e-3) is not path
    other = Stream('bat')
    for t, stamp, value, broken in zip(bat.times, bat.stamps, bat.values, bat.breaks):
        other.append(t, stamp, BatSample(value.knob, tuple(x + 1e-4 for x in value.tip)),
                     broken)
    moved = c2_bat_path(other, k, window, 1e-3)
    assert moved is not path and _fields(moved) != _fields(path)
    fit = ball_flight(ball, k, c2_window(ball, k, 0.05, 2, 8), 1e-3, config)
    assert fit is not None
    assert ball_flight(ball, k, c2_window(ball, k, 0.05, 2, 8), 1e-3, config) is fit
    assert ball_flight(ball, k, c2_window(ball, k, 0.05, 2, 8), 2e-3, config) is not fit
    for _ in range(fitting._FITS_KEPT + 3):  # bounded
        c2_bat_path(bat, k, window, 1e-3 * (1.0 + 1e-3 * len(fitting._FITS)))
        assert len(fitting._FITS) <= fitting._FITS_KEPT


def test_the_bat_continued_from_before_is_a_cubic_swing_itself() -> None:
    """
    ``c2_bat_ahead``: a bat whose knob and turn are cubics in time continues on them exactly.

    The window's not-a-knot spline (cubic, or here, steps within a factor 2, the quintic)
    reproduces cubics, and its last piece continued over the next interval is the same cubic,
    on uneven stamps.
    """
    times = np.cumsum([0.0, 0.003, 0.002, 0.003, 0.003, 0.002, 0.003, 0.002])
    stream = _polynomial_bat(times, 3)
    k = len(times) - 2
    path = c2_bat_ahead(stream, k, 1.0, 8)
    for t in np.linspace(times[k], times[k + 1], 5):
        knob, tip = path.at(float(t))
        expected = _polynomial_ends(float(t), 3)
        assert math.dist(knob, expected[0]) < 1e-9 and math.dist(tip, expected[1]) < 1e-9


def _polynomial_ends(t: float, degree: int) -> Tuple[Tuple[float, ...], Tuple[float, ...]]:
    """Return the knob and tip at t of a bat whose knob and turn angle are polynomials."""
    axis = np.array([0.2, 0.3, 1.0]) / np.linalg.norm([0.2, 0.3, 1.0])
    knob = np.array([0.1, 0.2, 1.0]) + np.array([2.0, -1.0, 0.5]) * t + 40.0 * t ** 3
    angle = 30.0 * t + 400.0 * t * t - 5000.0 * t ** 3
    if degree == 5:
        knob = knob + np.array([3e4, -2e4, 1e4]) * t ** 5
        angle += 2e5 * t ** 4 - 4e6 * t ** 5
    start = np.cross(axis, [1.0, 0.0, 0.0])
    start = start / np.linalg.norm(start)
    direction = (math.cos(angle) * start + math.sin(angle) * np.cross(axis, start))
    return tuple(knob.tolist()), tuple((knob + 0.84 * direction).tolist())


def _polynomial_bat(times: np.ndarray, degree: int) -> Stream:
    """Return a bat stream sampled at ``times`` from ``_polynomial_ends``."""
    stream = Stream('bat')
    for i, t in enumerate(times):
        knob, tip = _polynomial_ends(float(t), degree)
        stream.append(float(t), int(round(t * 1e9)), BatSample(knob, tip), i == 0)
    return stream


def test_a_hits_bat_is_continued_on_the_quintic() -> None:
    """
    ``c2_bat_ahead``: a bat whose knob and turn angle are quintics continues on them closely.

    Exact samples, steps within a factor 2: the continued piece is the window's quintic (a
    cubic's is a tenth of a millimetre off at the closing stamp); ``quintic`` asks for nothing
    else: a window with steps further apart gives None.
    """
    times = np.cumsum([0.0, 0.003, 0.002, 0.003, 0.003, 0.002, 0.003, 0.002, 0.003])
    stream = _polynomial_bat(times, 5)
    k = len(times) - 2
    path = c2_bat_ahead(stream, k, 1.0, 8, quintic=True)
    assert path is not None
    worst = max(math.dist(got, want) for t in np.linspace(times[k], times[k + 1], 5)
                for got, want in zip(path.at(float(t)), _polynomial_ends(float(t), 5)))
    assert worst < 5e-6  # (the continuation's own Hermite over the interval, and the chart)
    window = c2_window(stream, k - 1, 1.0, 0, 8)
    cubic = C2BatPath.fitted(stream.times[window.start:window.stop],
                             stream.values[window.start:window.stop], k - 1 - window.start)
    assert math.dist(cubic.at(float(times[k + 1]))[1], _polynomial_ends(times[k + 1], 5)[1]) > 5e-5
    uneven = np.cumsum([0.0, 0.003, 0.0012, 0.003, 0.003, 0.002, 0.003, 0.002, 0.003])
    assert c2_bat_ahead(_polynomial_bat(uneven, 5), k, 1.0, 8, quintic=True) is None
    assert c2_bat_ahead(_polynomial_bat(uneven, 5), k, 1.0, 8) is not None


def test_a_noisy_bat_is_continued_from_its_smoothed_window() -> None:
    """
    ``c2_bat_ahead`` with noise: the smoothed window's own path, from the opening stamp on.

    It starts where the window's smoother puts the bat at the opening frame (not on the noisy
    sample) and goes on along that smoother's last piece to the closing stamp.
    """
    scenario = make_scenario('barrel', np.random.default_rng(4), family='rebound')
    samples = sample(scenario, 90.0, np.random.default_rng(4), jitter_s=2e-4, grid_s=1e-3,
                     noise_m=1e-3, marker_spread_m=0.3)
    stream = Stream('bat')
    for i, (stamp, knob, tip) in enumerate(zip(samples.bat_stamps_ns.tolist(),
                                               samples.knobs.tolist(), samples.tips.tolist())):
        stream.append((stamp - samples.start_ns) * 1e-9, stamp, BatSample(tuple(knob), tuple(tip)),
                      i == 0)
    k = len(stream.times) // 2
    window = c2_window(stream, k - 1, 1.0, 0, 8)
    smoothed = c2_bat_path(stream, k - 1, window, 1e-3)
    path = c2_bat_ahead(stream, k, 1.0, 8, 1e-3)
    t0, t1 = stream.times[k], stream.times[k + 1]
    for got, smooth, raw in zip(path.at(t0), smoothed.at(t0),
                                (stream.values[k].knob, stream.values[k].tip)):
        assert math.dist(got, smooth) < 1e-9 and math.dist(got, raw) > 1e-5
    for got, smooth in zip(path.at(t1), smoothed.at(t1)):  # the smoother's piece, continued
        assert math.dist(got, smooth) < 1e-9
    assert c2_bat_ahead(stream, k, 1.0, 8).at(t0)[0] == stream.values[k].knob  # exact: on it


def test_c2_window_is_the_longest_continuous_run_about_its_interval() -> None:
    """
    ``c2_window`` (the kernel's): interval k's ends, up to ``look_ahead`` samples after.

    Back to ``size`` samples in all; nothing across a segment break or a step over
    ``max_gap``; and it stops only where one of those says so (random streams).
    """
    rng = np.random.default_rng(21)
    max_gap = 0.03
    for _ in range(3000):
        n = int(rng.integers(2, 20))
        stream = Stream('ball')
        t = float(rng.uniform(0.0, 10.0))
        for i in range(n):
            t += float(rng.choice([0.0028, 0.0028, 0.0028, 0.011, 0.02, 0.1]))
            stream.append(t, i, (0.0, 0.0, 0.0), i == 0 or bool(rng.random() < 0.05))
        k = int(rng.integers(0, n - 1))
        look_ahead, size = int(rng.integers(0, 4)), int(rng.integers(2, 12))
        window = fitting.c2_window(stream, k, max_gap, look_ahead, size)
        times, breaks = stream.times, stream.breaks

        def joined(i: int) -> bool:  # sample i continues sample i - 1's segment
            return not breaks[i] and times[i] - times[i - 1] <= max_gap
        assert window.start <= k and window.stop - 1 >= k + 1
        assert all(joined(i) for i in range(window.start + 1, window.stop) if i != k + 1)
        last = window.stop - 1
        assert last - (k + 1) <= look_ahead
        assert last - (k + 1) == look_ahead or last == n - 1 or not joined(last + 1)
        assert last - window.start + 1 <= max(size, last - k + 1)
        assert (last - window.start + 1 >= size or window.start == 0
                or not joined(window.start) or window.start == k)


_vectors = st.tuples(*[st.floats(-3.0, 3.0)] * 3)


@settings(max_examples=examples(100), deadline=None)
@given(turn=_vectors, rate=_vectors, tilt=_vectors)
def test_recharted_rate_is_the_derivative_in_the_new_chart(turn, rate, tilt) -> None:
    """A rotation vector's rate moved to another chart: the new chart's vector's derivative."""
    reference = (0.0, 0.0, 1.0)
    turn = tuple(0.3 * x for x in turn[:2]) + (0.0,)  # (across the reference)
    origin = rotate(reference, tuple(0.2 * x for x in tilt[:2]) + (0.0,))
    rate = tuple(rate[:2]) + (0.0,)
    at, moved = fitting._recharted(reference, origin, np.array(turn), np.array(rate))
    assert at == rotation_to(origin, rotate(reference, turn))

    def charted(t: float) -> np.ndarray:
        return np.array(rotation_to(origin, rotate(reference, tuple(
            x + t * r for x, r in zip(turn, rate)))))

    h = 1e-6
    assert np.allclose(moved, (charted(h) - charted(-h)) / (2 * h), atol=1e-4)


def _reach_back(times, breaks, first, stop, max_gap, span, most) -> int:
    """Return the window's first sample, reached back one step at a time (the kernel's loop)."""
    newest = times[stop - 1]
    while (first > 0 and not breaks[first] and stop - first < most
           and times[first] - times[first - 1] <= max_gap and newest - times[first - 1] <= span):
        first -= 1
    return first


@settings(max_examples=examples(200), deadline=None)
@given(steps=st.lists(st.floats(0.001, 0.06), min_size=2, max_size=80),
       broken=st.sets(st.integers(1, 79), max_size=4), data=st.data())
def test_windows_reach_back_as_a_loop_over_the_samples(steps, broken, data) -> None:
    """``widened`` and ``flight_window`` stop where a break, a gap, the span or the count says."""
    times = list(np.cumsum([1.7e9] + steps))
    stream = Stream('bat')
    stream.times, stream.breaks = times, [i in broken for i in range(len(times))]
    last = data.draw(st.integers(0, len(times) - 1))
    for max_gap, span in ((0.05, 0.15), (0.02, 0.09), (math.inf, 1.0)):
        assert flight_window(stream, last, max_gap, span) == range(_reach_back(
            times, stream.breaks, last, last + 1, max_gap, span, len(times) + 1), last + 1)
    start = data.draw(st.integers(0, last))
    assert widened(stream, range(start, last + 1)) == range(_reach_back(
        times, stream.breaks, start, last + 1, math.inf, fitting.NOISE_SPAN,
        fitting.MAX_WINDOW), last + 1)


@pytest.mark.parametrize('rate, noise', [(90.0, 1e-3), (360.0, 3e-4), (360.0, 0.0)])
def test_a_bats_errors_at_once_are_its_gains_and_shifts(rate: float, noise: float) -> None:
    """``bat_errors``: ``bat_gains`` and ``bat_shifts`` of the same window, to the bit."""
    _, bat = _streams(rate, noise, 3)
    for k in (12, 20):
        window = c2_window(bat, k, 0.05, 0, 8)
        for t in (bat.times[k], 0.3 * bat.times[k] + 0.7 * bat.times[k + 1]):
            gains, shifts = bat_errors(bat, window, k, t, noise)
            for answer, alone in ((gains, bat_gains(bat, window, k, t, noise)),
                                  (shifts, bat_shifts(bat, window, k, t, noise))):
                assert all(np.array_equal(a, b) for a, b in zip(answer, alone))
            assert noise == 0.0 or shifts[0].any()
