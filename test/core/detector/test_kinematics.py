"""Tests for the detector's kinematics: least-squares fits, pivot, turn rates, fallbacks."""

import math

from baseball_collision.core.detector.kinematics import (
    bat_rates, fit_coefficients, fit_polynomial, impact_velocities, pivot_degree, pivot_fraction,
    pivot_rates, point_velocity, turn_rates, turn_rows, window_turns)
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.geometry import dot, lerp, sub
from baseball_collision.core.motion import BatPath, BatSample, PointPath
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples

LENGTH = 0.86
GRIP = 0.2  # the hands, as a fraction along knob-tip
OMEGA = 30.0  # rad/s about +z
HANDS_VELOCITY = (1.0, 0.5, 0.0)


def _bat(t: float) -> BatSample:
    """Return a bat turning at OMEGA about the hands, which move at constant velocity."""
    hands = tuple(v * t for v in HANDS_VELOCITY)
    direction = (math.cos(OMEGA * t), math.sin(OMEGA * t), 0.0)
    knob = tuple(h - GRIP * LENGTH * d for h, d in zip(hands, direction))
    return BatSample(knob, tuple(k + LENGTH * d for k, d in zip(knob, direction)))


def _bat_stream(times) -> Stream:
    stream = Stream('bat')
    for i, t in enumerate(times):
        stream.append(t, i + 1, _bat(t), False)
    return stream


def test_fit_is_exact_for_a_polynomial_of_its_degree() -> None:
    """Value, velocity and acceleration of a cubic at t, from samples up to t."""
    def p(t: float) -> list:
        return [2.0 - t + 3.0 * t ** 3, 0.5 * t * t]
    times = [0.01 * i for i in range(8)]
    value, first, second = fit_polynomial(times, [p(t) for t in times], 0.07, 3)
    assert value == pytest.approx(p(0.07), abs=1e-12)
    assert first == pytest.approx([-1.0 + 9.0 * 0.07 ** 2, 0.07], abs=1e-9)
    assert second == pytest.approx([18.0 * 0.07, 1.0], abs=1e-7)
    # two samples: the degree drops to a line, no acceleration
    value, first, second = fit_polynomial(times[:2], [p(t) for t in times[:2]], 0.01, 5)
    assert second == [0.0, 0.0]


@settings(max_examples=examples(200), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(1, 70), degree=st.integers(0, 6),
       components=st.integers(1, 9))
def test_fit_equals_lapacks_least_squares(seed: int, n: int, degree: int,
                                          components: int) -> None:
    """
    The kernel's QR fit is numpy's (LAPACK's SVD) least squares, to rounding.

    Sample times in a 61 ms window (the default velocity window), rows of tracked-like values
    (a trend plus noise), any degree up to 6 (dropping to n - 1).
    """
    rng = np.random.default_rng(seed)
    times = np.sort(rng.uniform(0.0, 0.061, n))
    t = float(times[-1] + rng.uniform(0.0, 0.003))
    rows = rng.normal(0.0, 0.01, (n, components)) + np.outer(times, rng.normal(0.0, 30.0,
                                                                               components))
    coefficients, span = fit_coefficients(times.tolist(), rows.tolist(), t, degree)
    x = (times - t) / span
    vandermonde = np.vander(x, min(degree, n - 1) + 1, increasing=True)
    expected = np.linalg.lstsq(vandermonde, rows, rcond=None)[0]
    assert span == max(t - times[0], 1e-9)
    assert coefficients.shape == expected.shape
    # both are exact to rounding times the system's condition (an interpolating degree on
    # clustered stamps is ill-conditioned: 5e-9 apart relative at a condition of 1e6)
    tolerance = 1e-12 * max(1.0, np.linalg.cond(vandermonde)) * max(1.0, np.abs(expected).max())
    assert np.abs(coefficients - expected).max() <= tolerance


def test_a_rank_deficient_fit_is_the_minimum_norm_one() -> None:
    """Samples at one instant: no slope to fit; LAPACK's minimum-norm answer, the mean."""
    coefficients, _ = fit_coefficients([0.0, 0.0, 0.0], [(1.0,), (2.0,), (3.0,)], 0.0, 2)
    assert coefficients[0][0] == pytest.approx(2.0)
    assert np.abs(coefficients[1:]).max() < 1e-9


def test_point_velocity_from_the_samples_up_to_t() -> None:
    """A ball on a parabola: the quadratic fit's velocity is exact; one sample is not enough."""
    stream = Stream('ball')
    for i in range(6):
        t = 0.01 * i
        stream.append(t, i + 1, (40.0 * t, 0.0, 1.0 - 4.9 * t * t), False)
    velocity = point_velocity(stream, 0.05, lambda p: p, 0.06, 2)
    assert velocity == pytest.approx((40.0, 0.0, -9.8 * 0.05), abs=1e-9)
    assert point_velocity(stream, 0.0, lambda p: p, 0.06, 2) is None


def test_pivot_is_the_hands_of_a_turning_bat() -> None:
    """The least-accelerating axis point of a bat turning about the hands is the hands."""
    stream = _bat_stream([i / 360.0 for i in range(24)])
    t = stream.times[-1]
    assert pivot_fraction(stream, t, 0.061, 5) == pytest.approx(GRIP, abs=0.01)
    fraction, velocity, acceleration = pivot_rates(stream, t, 0.061, 5)
    assert velocity == pytest.approx(HANDS_VELOCITY, abs=0.02)


@pytest.mark.parametrize('count, after', [(3, 0.0), (5, 0.001), (24, 0.0), (24, 0.002)])
def test_one_fit_gives_the_pivot_of_separate_fits(count: int, after: float) -> None:
    """
    ``bat_rates``' one fit equals separate fits, as the pivot was found before.

    The reference fits knob and tip at the last sample, takes the least-accelerating point,
    fits its own rows at t; the turn is ``turn_rates``.
    """
    stream = _bat_stream([i / 360.0 + 1e-4 * math.sin(7.0 * i) for i in range(count)])
    times = list(stream.times)
    t = times[-1] + after
    degree = pivot_degree(count, 5)
    second = fit_polynomial(times, [v.knob + v.tip for v in stream.values], times[-1], degree)[2]
    knob, tip = second[:3], second[3:]
    change = sub(tip, knob)
    fraction = min(1.0, max(-0.5, -dot(knob, change) / dot(change, change)))
    rows = [lerp(v.knob, v.tip, fraction) for v in stream.values]
    _, first, second = fit_polynomial(times, rows, t, degree)
    pivot, turn = bat_rates(stream, t, 1.0, 5, 5)
    assert pivot[0] == pytest.approx(fraction, rel=1e-12, abs=1e-12)
    assert pivot[1] == pytest.approx(first, rel=1e-11, abs=1e-11)
    assert pivot[2] == pytest.approx(second, rel=1e-9, abs=1e-9)
    swing, roll, change = turn_rates(stream, t, 1.0, 5)
    assert turn[0] + (turn[1],) == pytest.approx(swing + (roll,), rel=1e-11, abs=1e-11)
    assert turn[2] == pytest.approx(change, rel=1e-9, abs=1e-9)
    assert pivot_rates(stream, t, 1.0, 5) == pivot


def test_turn_rates_of_a_steady_swing() -> None:
    """Turning at 30 rad/s about +z: swing rate (0, 0, 30), no roll, no angular acceleration."""
    stream = _bat_stream([i / 360.0 for i in range(24)])
    swing, roll, change = turn_rates(stream, stream.times[-1], 0.061, 5)
    assert swing == pytest.approx((0.0, 0.0, OMEGA), abs=1e-6)
    assert roll == 0.0
    assert change == pytest.approx((0.0, 0.0, 0.0), abs=1e-3)


def test_impact_velocities_fall_back_to_the_chords() -> None:
    """Too little history before the impact: the spanning interval's chords stand in."""
    ball = Stream('ball')
    ball.append(0.0, 1, (1.0, 0.0, 1.0), False)
    ball.append(0.01, 2, (0.6, 0.0, 1.0), False)
    bat = _bat_stream([0.0, 0.01])
    ball_path = PointPath(0.0, 0.01, ball.values[0], ball.values[1])
    bat_path = BatPath.build('linear', 0.0, 0.01, bat.values[0], bat.values[1])
    velocities = impact_velocities(ball, bat, 0.005, 0.061, 5, ball_path, bat_path)
    assert not velocities.from_history and velocities.pivot_fraction == 0.0
    assert velocities.ball == pytest.approx((-40.0, 0.0, 0.0))
    knob0, knob1 = bat.values[0].knob, bat.values[1].knob
    assert velocities.pivot == pytest.approx([(b - a) / 0.01 for a, b in zip(knob0, knob1)])
    assert velocities.swing == pytest.approx((0.0, 0.0, OMEGA))
    with_history = impact_velocities(ball, bat, 0.01, 0.061, 5, ball_path, bat_path)
    assert with_history.from_history


@settings(max_examples=examples(60), deadline=None)
@given(calls=st.lists(st.tuples(st.integers(0, 39), st.integers(1, 40)), min_size=1,
                      max_size=8))
def test_turn_rows_are_knob_tip_and_turn_for_any_windows(calls) -> None:
    """Windows in any order (forward, back, holes between): each row is knob + tip + turn."""
    stream = Stream('bat')
    for i in range(40):
        angle = 0.3 * i
        knob = (0.01 * i, 0.0, 1.0)
        tip = (knob[0] + 0.8 * math.cos(angle), 0.8 * math.sin(angle), 1.0)
        stream.append(0.01 * i, i, BatSample(knob, tip), i == 0)
    for first, end in calls:
        first = min(first, end - 1)
        rows = turn_rows(stream, first, end)
        for i in range(first, end):
            assert rows[i] == stream.values[i].knob + stream.values[i].tip + stream.turn(i)
        assert all(row is None or row == stream.values[i].knob + stream.values[i].tip
                   + stream.turns[i] for i, row in enumerate(rows))


def _turning_stream(count: int, breaks=()) -> Stream:
    """Return a bat turning 0.3 rad a sample about a slowly tilting axis, broken at ``breaks``."""
    stream = Stream('bat')
    for i in range(count):
        angle, tilt = 0.3 * i, 0.02 * i
        knob = (0.01 * i, 0.0, 1.0)
        tip = (knob[0] + 0.8 * math.cos(angle) * math.cos(tilt), 0.8 * math.sin(angle),
               1.0 + 0.8 * math.cos(angle) * math.sin(tilt))
        stream.append(0.01 * i, i, BatSample(knob, tip), i == 0 or i in breaks)
    return stream


@settings(max_examples=examples(60), deadline=None)
@given(calls=st.lists(st.tuples(st.integers(0, 39), st.integers(1, 40)), min_size=1,
                      max_size=6),
       breaks=st.sets(st.integers(1, 39), max_size=2))
def test_window_turns_are_a_call_per_sample_bit_for_bit(calls, breaks) -> None:
    """One kernel call from the newest: the same turns as a call per sample, oldest first."""
    one_call, per_sample = _turning_stream(40, breaks), _turning_stream(40, breaks)
    for first, end in calls:
        first = min(first, end - 1)
        expected = [per_sample.turn(i) for i in range(first, end)]
        assert window_turns(one_call, first, end) == expected
    assert None not in window_turns(one_call, 0, 40)  # across the breaks, each its own zero
