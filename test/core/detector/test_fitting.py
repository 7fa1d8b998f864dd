"""Tests for the c2 windows with noise: smoothed paths, their rates, the propagated spreads."""

import math

from baseball_collision.core.detector.fitting import (
    bat_gains, c2_bat_path, c2_point_path, c2_window, point_gains, swing_rate, widened)
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample, C2BatPath
import numpy as np
import pytest


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
    the direction across the bat, the knob's rate).
    """
    noise, k = 1e-3, 22
    measured = {'ball': [], 'knob': [], 'turn': [], 'knob_rate': []}
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
        if predicted is None:
            predicted = (point_gains(ball, window, k, t, noise)[0] * noise,
                         bat_gains(bat, window, k, t, noise))
    spread = {name: np.std(np.array(values), axis=0) for name, values in measured.items()}
    ball_error, ((knob, turn, _), (knob_rate, _, _)) = predicted
    assert np.mean(spread['ball']) == pytest.approx(ball_error, rel=0.25)
    assert np.mean(spread['knob']) == pytest.approx(knob, rel=0.25)
    assert np.sqrt(np.sum(spread['turn'] ** 2) / 2.0) == pytest.approx(turn, rel=0.25)
    assert np.mean(spread['knob_rate']) == pytest.approx(knob_rate, rel=0.25)
