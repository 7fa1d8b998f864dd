"""
Tests for impact velocities from samples before t: the c2 model's, and the quintic's rates.

The c2 model's velocities (the splines' rates), and the quintic spline's rates every model
takes for the bat from exact samples at a high rate (``quintic_bat_rates``).
"""

from dataclasses import replace
import math
from typing import Callable, Optional, Sequence, Tuple

from baseball_collision.core.detector import DetectorConfig, kinematics
from baseball_collision.core.detector.fitting import (
    ball_flight, c2_bat_path, c2_point_path, c2_window)
from baseball_collision.core.detector.kinematics import (
    c2_velocities, chart_swing, fit_velocities, impact_velocities, knot_bat_rates,
    poly_bat_rates, quintic_bat_rates, spline_velocities)
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample, c2_rows, unit_axis
from baseball_collision.core.motion.splines import end_state
from hypothesis import example, given, settings, strategies as st
import numpy as np
import pytest
from support import examples


def _streams(rate: float, spin: float, tilt: float, stamps: Optional[Sequence[float]] = None):
    """
    Return ball and bat streams up to 0.1 s: the bat turning about a tilting axis.

    :param stamps: the samples' times (s; None: every 1 / rate from 0).
    """
    ball, bat = Stream('ball'), Stream('bat')
    stamps = np.arange(0.0, 0.1, 1.0 / rate) if stamps is None else stamps
    for i, t in enumerate(stamps):
        angle = spin * t
        knob = (2.0 * t, 0.0, 1.0 + t * t)
        direction = (math.cos(angle) * math.cos(tilt * t), math.sin(angle),
                     math.cos(angle) * math.sin(tilt * t))
        tip = tuple(k + 0.8 * d for k, d in zip(knob, direction))
        ball.append(t, i, (5.0 - 40.0 * t, 0.0, 1.0 - 4.9 * t * t), i == 0)
        bat.append(t, i, BatSample(knob, tip), i == 0)
    return ball, bat


def _tip_velocity(t: float, spin: float, tilt: float) -> np.ndarray:
    """Return the true tip velocity (m/s) by central differences of the closed form."""
    def tip(s: float) -> np.ndarray:
        angle = spin * s
        return np.array([2.0 * s + 0.8 * math.cos(angle) * math.cos(tilt * s),
                         0.8 * math.sin(angle), 1.0 + s * s + 0.8 * math.cos(angle)
                         * math.sin(tilt * s)])
    return (tip(t + 1e-6) - tip(t - 1e-6)) / 2e-6


def test_velocities_come_from_samples_before_t_and_converge() -> None:
    """At 360 Hz the ball's and the tip's velocity half a step after the last sample are close."""
    spin, tilt = 40.0, 2.0
    ball, bat = _streams(360.0, spin, tilt)
    t = bat.times[-1] + 0.5 / 360.0
    found = spline_velocities(ball, bat, t, 8, 0.061)
    assert found is not None and found.from_history and found.pivot_fraction == 0.0
    assert np.allclose(found.ball, (-40.0, 0.0, -9.8 * t), atol=1e-6)
    knob_rate = np.array(found.pivot)
    assert np.allclose(knob_rate, (2.0, 0.0, 2.0 * t), atol=1e-4)
    # the tip: the knob's velocity plus the swing's turn of the 0.8 m axis (length constant)
    angle = spin * t
    direction = np.array([math.cos(angle) * math.cos(tilt * t), math.sin(angle),
                          math.cos(angle) * math.sin(tilt * t)])
    tip_rate = knob_rate + np.cross(found.swing, 0.8 * direction)
    truth = _tip_velocity(t, spin, tilt)
    assert np.linalg.norm(tip_rate - truth) < 1e-3 * np.linalg.norm(truth)


def test_too_few_samples_give_none() -> None:
    """One sample of the bat before t: no spline velocities (the chords stand in)."""
    ball, bat = Stream('ball'), Stream('bat')
    ball.append(0.0, 0, (0.0, 0.0, 0.0), True)
    bat.append(0.0, 0, BatSample((0.0, 0.0, 0.0), (0.8, 0.0, 0.0)), True)
    assert spline_velocities(ball, bat, 0.001, 8, 0.061) is None


def _sweet_rate(found, t: float, spin: float, tilt: float) -> np.ndarray:
    """Return the tip's velocity (m/s) from a knob velocity and swing (0.8 m axis)."""
    angle = spin * t
    direction = np.array([math.cos(angle) * math.cos(tilt * t), math.sin(angle),
                          math.cos(angle) * math.sin(tilt * t)])
    return np.array(found[0]) + np.cross(found[1], 0.8 * direction)


@pytest.mark.parametrize('rates, at_90_hz, shrink', [
    (knot_bat_rates, 5e-3, (4.0, 4.0)),
    # one interpolating polynomial through the 8 samples: at 90 Hz this 40 rad/s swing turns
    # 0.44 rad a frame and the degree-7 extrapolation is off by about 2 %; from 180 Hz on its
    # error falls by far more than h^4
    (poly_bat_rates, 5e-2, (64.0, 16.0)),
], ids=['knot', 'poly'])
def test_window_rates_converge_with_the_rate(rates: Callable, at_90_hz: float,
                                             shrink: Tuple[float, float]) -> None:
    """The window's fit (knot at t, or one polynomial): the tip's velocity error falls fast."""
    spin, tilt = 40.0, 2.0
    errors = []
    for rate in (90.0, 180.0, 360.0):
        _, bat = _streams(rate, spin, tilt)
        t = bat.times[-1] + 0.5 / rate
        found = rates(bat, range(len(bat.times) - 8, len(bat.times)), t)
        truth = _tip_velocity(t, spin, tilt)
        errors.append(np.linalg.norm(_sweet_rate(found, t, spin, tilt) - truth)
                      / np.linalg.norm(truth))
    assert errors[0] < at_90_hz
    assert errors[1] < errors[0] / shrink[0] and errors[2] < errors[1] / shrink[1]


def test_poly_rates_are_exact_for_a_polynomial_swing() -> None:
    """Knob and swing angle (about z) of degree 7 through 8 uneven samples: exact at t."""
    rng = np.random.default_rng(3)
    knob_terms, angle_terms = rng.normal(size=(8, 3)), rng.normal(size=8) * 0.3
    bat = Stream('bat')
    times = np.sort(rng.uniform(0.0, 0.08, 8))
    for i, t in enumerate(times.tolist()):
        knob = np.polynomial.polynomial.polyval(t / 0.08, knob_terms)
        angle = np.polynomial.polynomial.polyval(t / 0.08, angle_terms)
        tip = knob + 0.8 * np.array([math.cos(angle), math.sin(angle), 0.0])
        bat.append(t, i, BatSample(tuple(knob.tolist()), tuple(tip.tolist())), i == 0)
    t = 0.09  # past the last sample, as at an impact
    knob_rate, swing = poly_bat_rates(bat, range(8), t)
    derivative = np.polynomial.polynomial.polyder
    true_knob = np.polynomial.polynomial.polyval(t / 0.08, derivative(knob_terms)) / 0.08
    true_spin = np.polynomial.polynomial.polyval(t / 0.08, derivative(angle_terms)) / 0.08
    assert np.allclose(knob_rate, true_knob, rtol=1e-7, atol=1e-7)
    assert np.allclose(swing, (0.0, 0.0, true_spin), rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize('rule', ['auto', 'knot', 'poly'])
def test_a_bat_braking_after_the_opening_frame_does_not_reach_the_velocities(
        rule: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Issue 11's rule: the bat stopping 1-3 ms after the contact leaves its velocities alone.

    Exact samples at 90 Hz: ``c2_velocities`` of an impact in the newest interval read the
    samples up to its opening frame only (the default rule and the knot fit), so a bat that
    stops right after the contact (its closing frame, held still) reports the same
    pre-contact speed, close to the truth.
    """
    monkeypatch.setattr(kinematics, 'VELOCITIES', rule)
    spin, tilt = 40.0, 2.0
    ball, bat = _streams(90.0, spin, tilt)
    k = len(bat.times) - 2
    t = bat.times[k] + 0.4 / 90.0  # the contact
    braked = Stream('bat')
    for i, (time, value) in enumerate(zip(bat.times, bat.values)):
        stopped = bat.values[k] if i == k + 1 else value  # stopped within the frame
        braked.append(time, i, stopped, i == 0)
    config = DetectorConfig(model='c2', bat_input='points')
    found = []
    for stream in (bat, braked):
        window = c2_window(stream, k, config.max_gap, 0, config.spline_window)
        paths = (c2_point_path(ball, k, window), c2_bat_path(stream, k, window))
        found.append(c2_velocities(ball, stream, t, *paths, config))
    assert found[0].pivot == found[1].pivot and found[0].swing == found[1].swing
    truth = _tip_velocity(t, spin, tilt)
    tip = _sweet_rate((found[1].pivot, found[1].swing), t, spin, tilt)
    within = 3e-2 if rule == 'poly' else 1e-2  # the polynomial's own error here: 2.2 %
    assert np.linalg.norm(tip - truth) < within * np.linalg.norm(truth)


def _window_at(rate: float, spin: float, tilt: float):
    """Return the newest 8 bat stamps and samples of ``_streams`` and t half a step on."""
    bat = _streams(rate, spin, tilt)[1]
    times, samples = list(bat.times[-8:]), list(bat.values[-8:])
    return times, samples, times[-1] + 0.5 / rate


def _cubic_rates(times, samples, t: float):
    """Return the knob velocity and swing at t from the cubic spline's last piece."""
    first, rows = c2_rows(samples, len(samples) - 2)
    state, rates = end_state(times[first:], rows, t)
    return (tuple(rates[:3].tolist()),
            chart_swing(unit_axis(samples[-2]), state[3:6], rates[3:6]))


def _shaken(samples, sigma: float, rng: np.random.Generator):
    """Return the bat samples with Gaussian noise of sigma (m) on each knob and tip coordinate."""
    return [BatSample(tuple((np.array(sample.knob) + rng.normal(0.0, sigma, 3)).tolist()),
                      tuple((np.array(sample.tip) + rng.normal(0.0, sigma, 3)).tolist()))
            for sample in samples]


def _relative_error(found, t: float, spin: float, tilt: float) -> float:
    """Return the tip velocity's error relative to its speed."""
    truth = _tip_velocity(t, spin, tilt)
    return float(np.linalg.norm(_sweet_rate(found, t, spin, tilt) - truth)
                 / np.linalg.norm(truth))


def test_the_quintic_rates_are_nearer_than_the_cubics_and_fall_faster() -> None:
    """
    Exact samples of a tilting swing: the quintic's extrapolated rates beat the cubic's.

    Half a step after the newest sample at 240 Hz the tip velocity from the quintic spline is
    within a third of the cubic's error (measured: 5.9e-6 against 2.8e-5 of the speed), and
    halving the step divides it by more than 32 (h^5; measured 70) where the cubic's falls by
    less (measured 19).
    """
    spin, tilt = 40.0, 2.0
    errors = {}
    for rate in (240.0, 480.0):
        times, samples, t = _window_at(rate, spin, tilt)
        found = quintic_bat_rates(times, samples, t)
        assert found is not None
        errors[rate] = (_relative_error(found, t, spin, tilt),
                        _relative_error(_cubic_rates(times, samples, t), t, spin, tilt))
    assert errors[240.0][0] < errors[240.0][1] / 3.0
    assert errors[240.0][0] > 32.0 * errors[480.0][0]
    assert errors[240.0][1] < 32.0 * errors[480.0][1]


@settings(max_examples=examples(40), deadline=None)
@given(spin=st.floats(5.0, 60.0), tilt=st.floats(-3.0, 3.0), rate=st.floats(240.0, 480.0),
       fraction=st.floats(0.05, 0.95))
@example(spin=5.0, tilt=0.0, rate=240.0, fraction=0.5)  # both exact to rounding: the floor
def test_exact_swings_pass_the_check_and_the_quintic_is_near(
        spin: float, tilt: float, rate: float, fraction: float) -> None:
    """
    Any smooth swing sampled exactly at 240-480 Hz passes the check; its speed within 0.02 %.

    5-60 rad/s about an axis tilting at up to 3 rad/s, the impact anywhere in the step after
    the newest sample (over 3,000 draws: the check passed on all, the tip velocity's error at
    most 7.5e-5 of the speed; the quintic nearer than the cubic on all but 2, at most 1.7 times
    the cubic's there). Without tilt the rotation vector is linear in time and both
    continuations meet the newest sample to within rounding (6e-15 and 7e-16 m): the check's
    floor passes it.
    """
    bat = _streams(rate, spin, tilt)[1]
    times, samples = list(bat.times[-8:]), list(bat.values[-8:])
    t = times[-1] + fraction / rate
    found = quintic_bat_rates(times, samples, t)
    assert found is not None
    assert _relative_error(found, t, spin, tilt) <= 2e-4


@pytest.mark.parametrize('rate', [240.0, 480.0])
def test_noise_the_detector_was_not_told_of_fails_the_quintic_check(rate: float) -> None:
    """0.1 mm of noise on knob and tip: the quintic's check refuses every draw (None)."""
    times, samples, t = _window_at(rate, 40.0, 2.0)
    for seed in range(20):
        noisy = _shaken(samples, 1e-4, np.random.default_rng(seed))
        assert quintic_bat_rates(times, noisy, t) is None


def test_the_quintic_rates_need_seven_samples_on_steps_within_a_factor_two() -> None:
    """Six samples, or one step more than twice another: None (the cubic stands in)."""
    times, samples, t = _window_at(240.0, 40.0, 2.0)
    assert quintic_bat_rates(times, samples, t) is not None
    assert quintic_bat_rates(times[2:], samples[2:], t) is None
    # steps of 2 and 1 units of 1/256 s (exact in binary): taken at a factor of 2, refused
    # with the first step 1/16 of a unit longer
    for first_step, taken in ((2.0, True), (2.0625, False)):
        stamps = [x / 256.0 for x in (0.0, first_step, 4.0, 6.0, 8.0, 9.0, 10.0, 11.0)]
        bat = _streams(1e3, 20.0, 1.0, stamps)[1]
        found = quintic_bat_rates(list(bat.times), list(bat.values), 11.5 / 256.0)
        assert (found is not None) == taken


def test_spline_velocities_take_the_quintic_where_its_check_passes() -> None:
    """240 Hz: the bat's rates are the quintic's; 120 Hz (a 0.33 rad step): the cubic's."""
    spin, tilt = 40.0, 2.0
    for rate, quintic in ((240.0, True), (120.0, False)):
        ball, bat = _streams(rate, spin, tilt)
        times, samples, t = _window_at(rate, spin, tilt)
        found = spline_velocities(ball, bat, t, 8, 0.061)
        assert (quintic_bat_rates(times, samples, t) is not None) == quintic
        expected = (quintic_bat_rates(times, samples, t) if quintic
                    else _cubic_rates(times, samples, t))
        assert (found.pivot, found.swing) == expected


def test_the_fit_models_take_the_quintic_rates_from_exact_samples_at_a_high_rate() -> None:
    """
    ``rigid``, ``spline``, ``linear``: the fits, but the bat's rates the quintic's at 240 Hz.

    Exact samples at 240 Hz: the knob velocity and swing are ``quintic_bat_rates``' (fraction
    0: the knob), the ball's velocity and the roll the fits'; the tip velocity then within
    1e-5 of the truth, where the fits' is off by more than 1e-3 (measured 6.3e-6 and 4.3e-3:
    a degree-3 fit's bias on an accelerating swing). At 90 Hz (a low rate), told of
    noise, or with 0.1 mm of noise the detector was not told of (the check fails): the fits.
    """
    spin, tilt = 40.0, 2.0
    config = DetectorConfig(model='rigid', bat_input='points')
    for rate, noise_m, told, quintic in ((240.0, 0.0, False, True), (90.0, 0.0, False, False),
                                         (240.0, 0.0, True, False), (240.0, 1e-4, False, False)):
        ball, bat = _streams(rate, spin, tilt)
        if noise_m:
            shaken = Stream('bat')
            noisy = _shaken(bat.values, noise_m, np.random.default_rng(3))
            for i, (stamp, sample) in enumerate(zip(bat.times, noisy)):
                shaken.append(stamp, i, sample, i == 0)
            bat = shaken
        k = len(bat.times) - 2
        t = bat.times[k] + 0.5 / rate
        window = c2_window(bat, k, config.max_gap, 0, config.spline_window)
        paths = (c2_point_path(ball, k, window), c2_bat_path(bat, k, window))
        used = replace(config, tracker_noise=1e-4) if told else config
        found = fit_velocities(ball, bat, t, *paths, used)
        fits = impact_velocities(ball, bat, t, config.velocity_window, config.velocity_degree,
                                 *paths)
        if not quintic:
            assert found == fits
            continue
        times, samples = list(bat.times[-9:-1]), list(bat.values[-9:-1])  # up to t
        rates = quintic_bat_rates(times, samples, t)
        assert (found.pivot_fraction, found.pivot, found.swing) == (0.0, *rates)
        assert (found.ball, found.roll, found.from_history) == (fits.ball, fits.roll, True)
        assert _relative_error(rates, t, spin, tilt) < 1e-5
        # the fits' tip: their pivot's velocity and the swing about it, (1 - f) of the 0.8 m
        angle = spin * t
        direction = np.array([math.cos(angle) * math.cos(tilt * t), math.sin(angle),
                              math.cos(angle) * math.sin(tilt * t)])
        lever = (1.0 - fits.pivot_fraction) * 0.8 * direction
        truth = _tip_velocity(t, spin, tilt)
        fits_error = np.linalg.norm(np.array(fits.pivot) + np.cross(fits.swing, lever) - truth)
        assert fits_error > 1e-3 * np.linalg.norm(truth)


def test_exact_samples_take_the_fits_at_a_low_rate_and_the_splines_at_a_high_one() -> None:
    """
    The 'auto' rule with exact samples: 90 Hz the least-squares fits, 360 Hz the splines.

    Both from the samples up to t only. With noise it is the window fits before the impact
    interval ('before'), whatever the rate.
    """
    spin, tilt = 40.0, 2.0
    config = DetectorConfig(model='c2', bat_input='points')
    for rate, expected in ((90.0, 'fits'), (360.0, 'splines')):
        ball, bat = _streams(rate, spin, tilt)
        k = len(bat.times) - 2
        t = bat.times[k] + 0.4 / rate
        window = c2_window(bat, k, config.max_gap, 0, config.spline_window)
        paths = (c2_point_path(ball, k, window), c2_bat_path(bat, k, window))
        found = c2_velocities(ball, bat, t, *paths, config)
        fits = impact_velocities(ball, bat, t, config.velocity_window, config.velocity_degree,
                                 *paths)
        splines = spline_velocities(ball, bat, t, config.spline_window,
                                    config.velocity_window)
        assert found == (fits if expected == 'fits' else splines)
        assert found != (splines if expected == 'fits' else fits)
        assert found != c2_velocities(ball, bat, t, *paths, config, 'before')
        noisy = replace(config, tracker_noise=1e-4)
        assert c2_velocities(ball, bat, t, *paths, noisy) == c2_velocities(
            ball, bat, t, *paths, noisy, 'before')


@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_under_auto_each_body_takes_the_rule_of_its_own_samples(rate: float) -> None:
    """
    Under auto an exact bat beside a noisy ball keeps the exact samples' rates.

    A robot's own kinematics beside a tracked ball: the bat's rates
    are the exact samples' ('fits': the least-squares fits at 90 Hz, the splines at 360 Hz),
    the same to the bit as beside an exact ball, and the ball's its 'before' rule's. (Before,
    any noise sent both bodies to 'before': the bat's sweet-spot speed p99 at 90 Hz doubled.)
    """
    spin, tilt, noise = 40.0, 2.0, 1e-3
    ball, bat = _streams(rate, spin, tilt)
    rng = np.random.default_rng(5)
    noisy = Stream('ball')
    for i, (time, value) in enumerate(zip(ball.times, ball.values)):
        noisy.append(time, i, tuple(v + e for v, e in zip(value, rng.normal(0.0, noise, 3))),
                     i == 0)
    noisy.noise = noise  # the auto estimate's place (bat.noise stays 0: exact)
    config = DetectorConfig(model='c2', bat_input='points', tracker_noise=-1.0)
    k = len(bat.times) - 2
    t = bat.times[k] + 0.4 / rate
    window = c2_window(bat, k, config.max_gap, 0, config.spline_window)
    bat_path = c2_bat_path(bat, k, window)
    found = c2_velocities(noisy, bat, t, c2_point_path(noisy, k, window, noise, config),
                          bat_path, config)
    exact = c2_velocities(ball, bat, t, c2_point_path(ball, k, window), bat_path, config)
    before = c2_velocities(noisy, bat, t, c2_point_path(noisy, k, window, noise, config),
                           bat_path, config, 'before')
    assert found.from_history and found.ball == before.ball != exact.ball
    assert replace(found, ball=exact.ball) == exact
    assert (found.pivot, found.swing) != (before.pivot, before.swing)


def test_a_noisy_ball_velocity_comes_from_its_flight_fit_before_the_contact() -> None:
    """
    With noise the impact's ball velocity is the flight fit's of the samples before the impact.

    A ball tracked with 1 mm of noise at 360 Hz: ``c2_velocities`` differentiates the
    parabola fitted up to the impact interval's opening frame (``fitting.ball_flight``, as the
    sweep's paths take it), not the smoother's window; the closing frame (here knocked 5 cm
    aside, as a hit ball is) does not reach it; and it is within 0.5 % of the true velocity,
    where the smoother's window extrapolated to the impact is several times further off.
    """
    spin, tilt, noise = 40.0, 2.0, 1e-3
    ball, bat = _streams(360.0, spin, tilt)
    rng = np.random.default_rng(11)
    noisy, hit = Stream('ball'), Stream('ball')
    last = len(ball.times) - 1
    for i, (time, value) in enumerate(zip(ball.times, ball.values)):
        shaken = tuple(v + e for v, e in zip(value, rng.normal(0.0, noise, 3)))
        noisy.append(time, i, shaken, i == 0)
        hit.append(time, i, (shaken[0], shaken[1] + 0.05, shaken[2]) if i == last else shaken,
                   i == 0)
    config = DetectorConfig(model='c2', bat_input='points', tracker_noise=noise)
    k = last - 1
    t = ball.times[k] + 0.4 / 360.0
    truth = np.array((-40.0, 0.0, -9.8 * t))
    found = []
    for stream in (noisy, hit):
        window = c2_window(stream, k, config.max_gap, 0, config.spline_window)
        paths = (c2_point_path(stream, k, window, noise, config),
                 c2_bat_path(bat, k, c2_window(bat, k, config.max_gap, 0, config.spline_window)))
        found.append(c2_velocities(stream, bat, t, *paths, config).ball)
    j = kinematics.velocity_interval(noisy, k, config.max_gap)
    before = c2_window(noisy, j, config.max_gap, 0, config.spline_window)
    flight = ball_flight(noisy, j, before, noise, config)
    assert flight is not None and found[0] == found[1]
    assert np.allclose(found[0], flight.velocity(t), rtol=1e-12, atol=0.0)  # its Hermite piece
    smoothed = c2_point_path(noisy, j, before, noise).velocity(t)
    error = np.linalg.norm(np.subtract(found[0], truth))
    assert error < 5e-3 * np.linalg.norm(truth)
    assert error < np.linalg.norm(np.subtract(smoothed, truth)) / 3.0
