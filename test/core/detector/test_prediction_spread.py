"""Tests for baseball_collision.core.detector.prediction_spread: a prediction's sigmas."""

import math

from baseball_collision.core.detector import (
    Detector, DetectorConfig, PendingPrediction, Prediction)
from baseball_collision.core.detector.prediction_spread import (
    backtest_frames, ball_spread, flight_miss, LIFT_SPEED_POWER, plan_sag,
    prediction_uncertainty, swing_change, SWING_TIME_SCALE, swing_variance)
from baseball_collision.core.geometry import lerp
from baseball_collision.core.prediction import (
    ball_numbers, BallForecast, BatForecast, contact_of, planned_bat, states_of)
from baseball_collision.core.toi import _kernel
from baseball_collision.tools.sim import FAMILIES, make_scenario, sample, truth_dict
import numpy as np
import pytest

GRAVITY = (0.0, 0.0, -9.80665)
DRAG = 0.0061  # 1/m: a baseball's


@pytest.mark.parametrize('rate, forecast, lift', [
    (90.0, 9, 22), (360.0, 36, 90), (1000.0, 100, 250),  # the defaults' windows
    (90.0, 9, 9), (360.0, 36, 20),  # a lift window no longer than the forecast's
    (90.0, 9, 4),  # a lift too short to be taken
    (360.0, 36, 0)])  # no lift (``lift_window`` 0)
def test_the_spread_is_the_norm_of_the_kernels_forecast_weights(rate: float, forecast: int,
                                                                lift: int) -> None:
    """
    ``ball_spread`` is the kernel forecast's sensitivity to each sample, summed in squares.

    The brute force: each sample moved by 1 um in turn, the forecast's position 0.2 s ahead
    (its value, rate and acceleration from ``ball_numbers``, drag 0) differenced. A pitch with
    5 m/s^2 of lift, exact samples on uneven stamps: the lift's gain is 1 and no glitch is
    left out, so the forecast is linear in the samples.
    """
    rng = np.random.default_rng(int(rate) + forecast + lift)
    count = max(forecast, lift)
    times = np.sort(np.arange(count) / rate + rng.uniform(0.0, 2e-4, count)).tolist()
    points = [(0.5 * t, 40.0 * t - 2.5 * t * t, 1.0 + 2.0 * t - 2.4 * t * t) for t in times]
    t0, end, lead = times[-1] + 1e-3, count, 0.2
    first, lift_first = end - forecast, end - lift if lift else end

    def ahead(samples) -> np.ndarray:
        numbers = ball_numbers(times, samples, first, end, t0, GRAVITY, 0.0, lift_first)
        return (np.array(numbers[1:4]) + lead * np.array(numbers[4:7])
                + 0.5 * lead * lead * np.array(numbers[7:10]))

    base, weights = ahead(points), []
    for k in range(count):
        moved = list(points)
        moved[k] = (points[k][0], points[k][1], points[k][2] + 1e-6)
        weights.append((ahead(moved) - base)[2] / 1e-6)
    spread, lifted = ball_spread(times, first, end, lift_first, t0, lead)
    assert spread == pytest.approx(float(np.linalg.norm(weights)), rel=1e-5)
    assert lifted == (lift >= _kernel.LIFT_MIN_SAMPLES
                      and times[-1] - times[end - lift] >= _kernel.LIFT_MIN_SPAN)
    assert spread > 1.0  # (more than a sample's own noise: the rate carried 0.2 s)


def _flown(position, velocity, lead: float, spin=None, step: float = 1e-4):
    """Return the ball (position, velocity) ``lead`` s on under gravity, drag and the lift."""
    state = np.concatenate([position, velocity]).astype(float)

    def rate(s: np.ndarray) -> np.ndarray:
        v = s[3:]
        speed = float(np.linalg.norm(v))
        acceleration = np.array(GRAVITY) - DRAG * speed * v
        if spin is not None:  # (lift w x v |v|^(p - 1): a spin axis that holds)
            acceleration += np.cross(spin, v) * speed ** (LIFT_SPEED_POWER - 1.0)
        return np.concatenate([v, acceleration])

    steps = int(round(abs(lead) / step))
    h = lead / steps
    for _ in range(steps):  # RK4
        k1 = rate(state)
        k2 = rate(state + 0.5 * h * k1)
        k3 = rate(state + 0.5 * h * k2)
        k4 = rate(state + h * k3)
        state = state + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return state[:3], state[3:]


def _acceleration(velocity, spin=None) -> np.ndarray:
    """Return the flight's acceleration at a velocity (m/s^2): ``_flown``'s."""
    speed = float(np.linalg.norm(velocity))
    lift = np.zeros(3) if spin is None else np.cross(spin, velocity) * speed ** (
        LIFT_SPEED_POWER - 1.0)
    return np.array(GRAVITY) - DRAG * speed * np.asarray(velocity) + lift


@pytest.mark.parametrize('lead', [0.1, 0.2, 0.3])
@pytest.mark.parametrize('spinning', [False, True])
def test_the_flight_miss_is_what_the_held_acceleration_misses(lead: float,
                                                              spinning: bool) -> None:
    """
    ``flight_miss`` is the flight integrated (RK4, 0.1 ms) less the forecast, within 12 %.

    A 40 m/s pitch. The forecast holds the drag at t0's speed and, spinning (about 5 m/s^2 of
    lift, a spin axis that holds), the lift of the window's middle, 0.125 s before t0 (a 0.25
    s ``lift_window``): what the kernel's forecast holds. Without the correction the forecast
    misses by 0.9-15 mm at these leads, so the test fails with the miss left out.
    """
    spin = np.array([0.0, 0.0, 0.0])
    position, velocity = np.array([0.0, 17.0, 1.8]), np.array([0.3, -40.0, 1.0])
    if spinning:  # (|w x v| |v|^0.5 of 5 m/s^2 across the flight)
        spin = np.array([0.9, 0.0, 0.4]) / 0.985 * 5.0 / 40.0 ** LIFT_SPEED_POWER
    window, held = 0.0, _acceleration(velocity)
    if spinning:
        window = 0.25
        _, middle = _flown(position, velocity, -0.5 * window, spin)
        held = held + _acceleration(middle, spin) - _acceleration(middle)
    ball = (0.0, *position, *velocity, *held)
    flown, _ = _flown(position, velocity, lead, spin if spinning else None)
    truth = flown - (position + velocity * lead + 0.5 * held * lead * lead)
    miss, doubt = flight_miss(ball, GRAVITY, DRAG, lead, window)
    assert np.linalg.norm(truth) > 5e-4
    assert np.linalg.norm(np.subtract(miss, truth)) < 0.12 * np.linalg.norm(truth)
    assert np.linalg.norm(doubt) == pytest.approx(0.0, abs=1e-12) or spinning


def _plan(times, positions, quaternions):
    """Return a plan's kernel numbers, the bat along z from its pose (knob 0, tip 0.8 m)."""
    return planned_bat(times, positions, quaternions, (0.0, 0.0, 0.0),
                       (0.0, 0.0, 0.8)).kernel_args


def test_a_plans_sag_is_its_chord_off_the_arc() -> None:
    """
    A pose origin on a circle, its orientation held: the plan's chords cut inside the arc.

    Radius 0.5 m, 40 rad/s, poses every 5 ms (0.2 rad a step): at a step's middle the LERP of
    the origin is ``R (1 - cos 0.1)`` = 2.5 mm inside; ``plan_sag`` says so within 10 %. On a
    straight line at constant speed it says nothing.
    """
    step, radius, rate = 0.005, 0.5, 40.0
    times = [k * step for k in range(12)]
    up = [(0.0, 0.0, 0.0, 1.0)] * len(times)
    circle = [(radius * math.cos(rate * t), radius * math.sin(rate * t), 1.0) for t in times]
    ball = (0.0,) * 10
    middle = 5.5 * step

    def sags_of(positions):
        plan = _plan(times, positions, up)
        _, _, knob, tip = states_of(ball, plan, middle)
        return plan_sag(ball, plan, times, middle, 0.5, lerp(knob, tip, 0.5))
    sags = sags_of(circle)
    expected = radius * (1.0 - math.cos(0.5 * rate * step))
    assert max(np.linalg.norm(s) for s in sags) == pytest.approx(expected, rel=0.1)
    line = [(0.0, 30.0 * t, 1.0) for t in times]
    assert max(np.linalg.norm(s) for s in sags_of(line)) < 1e-12


def _prediction_errors(family: str, count: int, rate: float, noise: float, seed: int = 21,
                       planned: bool = True):
    """
    Return (time error s, its sigma, spot error m, its sigma) of every prediction.

    With the swing as the arm's plan (poses 5 ms apart) where ``planned``, else extrapolated.
    """
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(count):
        scenario = make_scenario(('barrel', 'end_cap', 'handle')[i % 3], rng, lead_s=0.4,
                                 family=family)
        samples = sample(scenario, rate, np.random.default_rng(100 + i), jitter_s=2e-4,
                         noise_m=noise)
        detector = Detector(DetectorConfig(prediction_horizon=0.3, prediction_period=0.01))
        if planned:
            plan_times = np.arange(0.0, scenario.t_end, 0.005)
            positions, quaternions = scenario.swing.pose(plan_times)
            detector.set_bat_plan([samples.start_ns + int(round(t * 1e9)) for t in plan_times],
                                  positions.tolist(), quaternions.tolist())
        truth = truth_dict(scenario, samples.start_ns)
        for stamp, role, values in samples.messages('pose'):
            for event in detector.add(role, stamp, values):
                if isinstance(event, Prediction) and event.made_at_ns < truth['stamp_ns']:
                    assert event.planned is planned and event.time_uncertainty_s is not None
                    rows.append(((event.stamp_ns - truth['stamp_ns']) * 1e-9,
                                 event.time_uncertainty_s,
                                 event.distance_from_tip_m - truth['distance_from_tip_m'],
                                 event.distance_from_tip_uncertainty_m))
    return np.array(rows)


@pytest.mark.parametrize('rate, noise', [(90.0, 0.0005), (360.0, 0.001), (90.0, 0.002)])
def test_planned_predictions_sigmas_cover_their_errors(rate: float, noise: float) -> None:
    """
    Over noisy pitches a planned prediction's error is within 1 sigma about 68 % of the time.

    Six pitches of the fixed-plane and tilting families each (hits on the barrel, end and
    handle), every prediction from 0.4 s before the contact (leads 0-300 ms): within 1 sigma
    50-90 %, within 2 sigma at least 88 %, for the instant and the spot on the bat; and the
    sigmas grow with the noise (below: 1.5 mm of noise's are larger).
    """
    rows = np.concatenate([_prediction_errors(family, 6, rate, noise)
                           for family in ('plane', 'tilted')])
    assert len(rows) > 200
    for error, sigma in ((rows[:, 0], rows[:, 1]), (rows[:, 2], rows[:, 3])):
        z = np.abs(error) / sigma
        assert 0.5 <= np.mean(z <= 1.0) <= 0.9
        assert np.mean(z <= 2.0) >= 0.88


@pytest.mark.parametrize('rate, noise', [(90.0, 0.001), (360.0, 0.0)])
def test_extrapolated_predictions_sigmas_cover_their_errors(rate: float, noise: float) -> None:
    """
    Without a plan the sigmas carry the swing's change over the lead, and cover its errors.

    Three pitches of each swing family, every prediction (the extrapolated bat's: 0-120 ms
    ahead, off by 0.2-2 ms rms): the instant within 1 sigma 50-90 %, within 2 sigma at least
    85 %; the spot within 1 sigma at least 60 %, within 2 at least 85 %.
    """
    rows = np.concatenate([_prediction_errors(family, 3, rate, noise, seed=31, planned=False)
                           for family in FAMILIES])
    assert len(rows) > 60
    z = np.abs(rows[:, 0]) / rows[:, 1]
    assert 0.5 <= np.mean(z <= 1.0) <= 0.9 and np.mean(z <= 2.0) >= 0.85
    z = np.abs(rows[:, 2]) / rows[:, 3]
    assert np.mean(z <= 1.0) >= 0.6 and np.mean(z <= 2.0) >= 0.85


def test_backtest_frames_are_the_segments_frames_15_to_35_ms_back() -> None:
    """
    90 Hz: the frames 2 and 3 back; 360 Hz: the first and last of the 6th-12th back.

    A segment begun 3 frames back at 360 Hz: the nearest to 25 ms of its frames; begun at the
    newest, none; 20 Hz (50 ms steps): the one 50 ms back (within twice 35 ms).
    """
    at_90 = [k / 90.0 for k in range(11)]
    assert backtest_frames(at_90, [False] * 11, 10) == [7, 8]
    at_360 = [k / 360.0 for k in range(40)]
    assert backtest_frames(at_360, [False] * 40, 39) == [27, 33]
    breaks = [False] * 40
    breaks[36] = True  # (frame 36 begins a segment: 37-39 follow it)
    assert backtest_frames(at_360, breaks, 39) == [36]
    breaks[39] = True
    assert backtest_frames(at_360, breaks, 39) == []
    assert backtest_frames([k * 0.05 for k in range(5)], [False] * 5, 4) == [3]


def _turning_bat(rate: float = 40.0, pivot_velocity=(3.0, -1.0, 0.5)) -> BatForecast:
    """Return a bat turning about +z at ``rate`` rad/s around a pivot at 1 m, its tip along x."""
    return BatForecast(t0=0.0, pivot=(0.0, 0.0, 1.0), pivot_velocity=pivot_velocity,
                       pivot_acceleration=(0.0, 0.0, 0.0), knob_arm=(-0.1, 0.0, 0.3),
                       tip_arm=(0.8, 0.0, 0.3), axis=(0.0, 0.0, 1.0), rate=rate,
                       rate_change=500.0)


def test_swing_change_is_the_turn_and_the_hands_a_changing_acceleration_adds() -> None:
    """
    The turn's vector: the point turned by |w| lead^3 / (6 tau^2) more, against Rodrigues.

    An angular acceleration changing at ``|w| / tau^2`` turns the bat by ``|w| lead^3 / (6
    tau^2)`` more over the lead; its point 3/4 of the way from knob to tip, 0.575 m from the
    axis, moves across it. The pivot's: its velocity times ``lead^3 / (6 tau^2)``.
    """
    bat = _turning_bat()
    lead = 0.002  # (a small angle: the displacement is the arc's chord to 1e-6)
    turn, pivot = swing_change(bat.kernel_args, 0.75, lead)
    angle = 40.0 * lead ** 3 / (6.0 * SWING_TIME_SCALE ** 2)
    arm = np.array([0.575, 0.0, 0.3])  # knob_arm + 0.75 (tip_arm - knob_arm)
    axis = np.array([0.0, 0.0, 1.0])
    turned = (arm * math.cos(angle) + np.cross(axis, arm) * math.sin(angle)
              + axis * (axis @ arm) * (1.0 - math.cos(angle)))
    assert turn == pytest.approx(turned - arm, rel=1e-4, abs=1e-8)  # (the chord's 1e-9 off)
    assert pivot == pytest.approx(np.array([3.0, -1.0, 0.5]) * lead ** 3 / (
        6.0 * SWING_TIME_SCALE ** 2))
    backwards, _ = swing_change(_turning_bat(rate=-40.0).kernel_args, 0.75, lead)
    assert backwards == pytest.approx(turn)  # (the size of the change, not its sign)


def test_recent_misses_scale_with_the_lead_then_its_cube() -> None:
    """A 1 mm miss 20 ms back: 0.5 mm 10 ms ahead, 8 mm 40 ms ahead; two are averaged."""
    miss = (0.02, (0.001, 0.0, 0.0))
    along_x = (1.0, 0.0, 0.0)
    assert swing_variance([miss], 0.01, [], 0.0)(along_x) == pytest.approx(0.0005 ** 2)
    assert swing_variance([miss], 0.04, [], 0.0)(along_x) == pytest.approx(0.008 ** 2)
    assert swing_variance([miss], 0.04, [], 0.0)((0.0, 1.0, 0.0)) == 0.0
    other = (0.02, (0.0, 0.003, 0.0))
    variance = swing_variance([miss, other], 0.02, [(0.0, 0.0, 0.002)], 0.0005)
    assert variance(along_x) == pytest.approx(0.5 * 0.001 ** 2 + 0.0005 ** 2)
    assert variance((0.0, 1.0, 0.0)) == pytest.approx(0.5 * 0.003 ** 2 + 0.0005 ** 2)
    assert variance((0.0, 0.0, 1.0)) == pytest.approx(0.002 ** 2 + 0.0005 ** 2)


def test_a_spread_wider_than_the_contact_takes_the_closing_speed() -> None:
    """
    Moved 10 m either way the ball meets no bat: the sigma is the spread over the closing speed.

    A ball at 35 m/s toward a turning bat; the closing speed along the contact's normal taken
    independently, by central differences of the two paths at the contact.
    """
    bat = _turning_bat(rate=-30.0, pivot_velocity=(0.0, 0.0, 0.0))
    ball = BallForecast.ballistic(0.0, (0.55, 1.0, 1.3), (0.0, -35.0, 0.0), (0.0, 0.0, 0.0),
                                  0.0).kernel_args
    search = (0.2, 0.0366, DetectorConfig().profile, 1e-5)
    found = contact_of(ball, bat.kernel_args, 0.0, *search)
    assert found is not None
    t, hit = found
    velocity, (knob, tip) = states_of(ball, bat.kernel_args, t)[1], bat.at(t)
    sigma, spot = prediction_uncertainty(
        ball, bat.kernel_args, 0.0, found, (velocity, knob, tip), 0.0, True, (0.0, 0.0, 0.0),
        lambda direction: 100.0, search)
    h = 1e-6
    gaps = []
    for when in (t - h, t + h):
        ball_at = np.array(states_of(ball, bat.kernel_args, when)[0])
        knob_at, tip_at = bat.at(when)
        gaps.append(ball_at @ hit.normal - np.array(lerp(knob_at, tip_at, hit.bat_fraction))
                    @ hit.normal)
    closing = abs(gaps[1] - gaps[0]) / (2.0 * h)
    assert 10.0 < closing < 80.0
    assert sigma == pytest.approx(10.0 / closing, rel=1e-3)
    assert spot >= 0.0


def test_exact_planned_predictions_are_microseconds_off_far_ahead() -> None:
    """
    Exact samples and a smooth plan: 150-300 ms ahead the instant is within 40 us, in its sigma.

    The forecast's held drag alone would put it 100-400 us late there (``flight_miss``), and
    the search's own chords 30-40 us off at a tip end (``REFINED_CHORD``). Within 2 sigma and
    12 us (the plan's interpolation, 200 Hz).
    """
    rows = _prediction_errors('plane', 3, 360.0, 0.0)
    assert len(rows) > 50
    assert np.max(np.abs(rows[:, 0])) < 40e-6
    assert np.all(np.abs(rows[:, 0]) <= 2.0 * rows[:, 1] + 12e-6)


@pytest.mark.parametrize('planned', [False, True])
def test_deferred_predictions_error_bars_are_the_same_measured_later(planned: bool) -> None:
    """
    ``deferred_uncertainty``: predictions come without their error bars, measured later alike.

    The node sends ``~/predicted_impact`` first and measures the error bars with the reports;
    ``PendingPrediction`` keeps copies of what they are measured from, so measured after the
    detector has taken every later sample and been reset they equal, to the bit, those of a
    detector that measured each at once (an extrapolated bat's recent misses read frames the
    stream has since trimmed; a plan's poses outlive a plan replaced).
    """
    scenario = make_scenario('barrel', np.random.default_rng(6), lead_s=0.4, family='tilted')
    samples = sample(scenario, 360.0, np.random.default_rng(4), jitter_s=2e-4, noise_m=0.001)
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    at_once, deferred = Detector(config), Detector(config, deferred_uncertainty=True)
    if planned:
        plan_times = np.arange(0.0, scenario.t_end, 0.005)
        positions, quaternions = scenario.swing.pose(plan_times)
        plan = ([samples.start_ns + int(round(t * 1e9)) for t in plan_times],
                positions.tolist(), quaternions.tolist())
        at_once.set_bat_plan(*plan)
        deferred.set_bat_plan(*plan)
    measured, returned, pending = [], [], []
    for stamp, role, values in samples.messages('pose'):
        measured += [e for e in at_once.add(role, stamp, values) if isinstance(e, Prediction)]
        returned += [e for e in deferred.add(role, stamp, values) if isinstance(e, Prediction)]
        pending += [p for p in deferred.take_pending() if isinstance(p, PendingPrediction)]
    deferred.reset()
    assert len(measured) >= 5 and len(pending) == len(returned) == len(measured)
    assert all(p.planned is planned and p.time_uncertainty_s is None
               and p.distance_from_tip_uncertainty_m is None for p in returned)
    assert [p.prediction for p in pending] == returned
    assert [p.measure() for p in pending] == measured
    assert all(p.time_uncertainty_s > 0.0 for p in measured)
