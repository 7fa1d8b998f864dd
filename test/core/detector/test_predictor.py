"""Tests for the detector's predictor: the plan on the detector's clock, the reach test."""

from dataclasses import asdict, FrozenInstanceError, replace
import math
from typing import Tuple

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.detector import (
    Detector, DetectorConfig, Prediction, PredictionCleared)
from baseball_collision.core.detector.gap_flight import GAP_FLIGHT_BIAS, GAP_FLIGHT_JERK
from baseball_collision.core.detector.kinematics import turn_rows
from baseball_collision.core.detector.predictor import (
    kept_flight_span, PREDICTION_CHORD_FACTOR, Predictor)
from baseball_collision.core.prediction import (
    BallForecast, BatForecast, MAX_PLAN_POSES, PlannedBat)
from baseball_collision.errors import CoreError
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np
import pytest
from support.predictors import BASE_NS, predictor_of


def test_a_plan_is_put_on_the_detector_clock_once() -> None:
    """The plan's stamps become seconds on the clock; an empty plan clears it."""
    stamps = [BASE_NS + 10_000_000, BASE_NS + 20_000_000]
    plan = (stamps, [(0.0, 0.0, 1.0)] * 2, [(0.0, 0.0, 0.0, 1.0)] * 2)
    predictor = predictor_of([(5.0, 0.0, 1.0)] * 3, [((0, 0, 1), (0, 0.86, 1))] * 3, plan)
    forecast = predictor._bat_forecast(0.0)
    assert isinstance(forecast, PlannedBat)
    assert forecast.times == pytest.approx((0.01, 0.02))
    assert predictor._bat_forecast(0.0) is forecast
    predictor.set_plan([], [], [])
    assert predictor.plan is None and predictor.plan_on_clock is None
    with pytest.raises(CoreError, match='bat plan'):
        predictor.set_plan([2, 1], [(0, 0, 0)] * 2, [(0, 0, 0, 1)] * 2)


def test_no_prediction_for_a_ball_out_of_reach() -> None:
    """A ball 50 m away, still: not even searched; a prediction that ends is cleared once."""
    predictor = predictor_of([(50.0, 0.0, 1.0)] * 4, [((0, 0, 1), (0, 0.86, 1))] * 4)
    assert not predictor._may_reach()
    events = []
    predictor.predict(0.015, True, events)
    assert events == []
    predictor.predicting = True
    predictor.predict(0.015, True, events)
    assert events == [PredictionCleared(made_at_ns=BASE_NS + 15_000_000)]
    assert not predictor.predicting


def test_a_ball_flying_at_a_still_bat_is_predicted() -> None:
    """A ball at 40 m/s towards a still bat 1 m away: contact predicted about 25 ms ahead."""
    balls = [(2.0 - 40.0 * 0.005 * i, 0.5, 1.0) for i in range(6)]
    predictor = predictor_of(balls, [((0, 0, 1), (0, 0.86, 1))] * 6)
    events = []
    predictor.predict(0.025, True, events)
    assert [type(e) for e in events] == [Prediction] and predictor.predicting
    prediction = events[0]
    # where the ball (centre at y = 0.5 m) meets the tapered bat, by dense search: the nearest
    # of the spheres along the axis (radius as the stations give it), the contact point between
    fractions = np.linspace(0.0, 1.0, 200001)
    radii = np.interp(fractions * WOOD_BAT_34.length, *zip(*WOOD_BAT_34.stations))

    def reach(x: float) -> Tuple[float, int]:
        gaps = np.hypot(0.86 * fractions - 0.5, x) - radii
        return float(gaps.min()), int(gaps.argmin())
    low, high = 0.0, 0.2
    for _ in range(60):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if reach(middle)[0] < 0.0366 else (low, middle)
    nearest = reach(high)[1]
    offset = np.array([high, 0.5 - 0.86 * fractions[nearest]])
    along = 0.86 * fractions[nearest] + radii[nearest] * offset[1] / np.linalg.norm(offset)
    expected = (balls[-1][0] - high) / 40.0  # to the bat's surface (drag: 0.1 ms)
    assert prediction.lead_s == pytest.approx(expected, abs=2e-4)
    assert prediction.bat_fraction == pytest.approx(along / 0.86, abs=2e-5)
    assert abs(prediction.bat_fraction - 0.5 / 0.86) > 1e-3  # (the taper moves it)
    assert not prediction.planned
    # made without the frozen __init__: the same as the constructor's, in every use
    fields = {name: getattr(prediction, name) for name in Prediction.__dataclass_fields__}
    made = Prediction(**fields)
    assert prediction == made and hash(prediction) == hash(made)
    assert repr(prediction) == repr(made) and asdict(prediction) == asdict(made)
    assert replace(prediction, lead_s=1.0) == replace(made, lead_s=1.0)
    with pytest.raises(FrozenInstanceError):
        prediction.lead_s = 1.0


def test_the_forecast_is_the_kernels_numbers_of_the_forecast_objects() -> None:
    """``_ball_forecast`` and ``_bat_forecast`` give what the forecast classes' fits hold."""
    balls = [(2.0 - 40.0 * 0.005 * i, 0.5, 1.0 + 0.001 * i * i) for i in range(6)]
    bats = [((0.0, 0.01 * i, 1.0), (0.86 * math.cos(0.1 * i), 0.86 * math.sin(0.1 * i), 1.0))
            for i in range(6)]
    predictor = predictor_of(balls, bats)
    config = predictor.config
    ball, bat = predictor.ball, predictor.bat
    gravity = (0.0, 0.0, -config.gravity)
    assert predictor._ball_forecast(0.025) == BallForecast.fitted(
        ball.times, ball.values, 0, 6, 0.025, gravity, config.ball_drag).kernel_args
    assert predictor._bat_forecast(0.025) == BatForecast.fitted(
        bat.times, turn_rows(bat, 0, 6), 0, 6, 3).kernel_args
    assert predictor._ball_forecast(0.005) is None  # fewer than 3 samples


def test_a_new_configuration_moves_what_the_predictions_derive_from_it() -> None:
    """Gravity and the chord tolerance follow ``config`` (the detector's ``reconfigure``)."""
    predictor = predictor_of([(5.0, 0.0, 1.0)] * 3, [((0, 0, 1), (0, 0.86, 1))] * 3)
    predictor.config = replace(predictor.config, gravity=1.5, max_chord_error=0.002,
                               up_axis=(0.0, 1.0, 0.0))
    assert predictor._gravity == (0.0, -1.5, 0.0)
    assert predictor._tolerance == PREDICTION_CHORD_FACTOR * 0.002


def test_a_plan_too_large_is_refused_before_any_work() -> None:
    """More than MAX_PLAN_POSES poses: a CoreError saying the limit, the plan unchanged."""
    predictor = predictor_of([(5.0, 0.0, 1.0)] * 3, [((0, 0, 1), (0, 0.86, 1))] * 3)
    n = MAX_PLAN_POSES + 1
    with pytest.raises(CoreError, match=f'{n} poses is more than the {MAX_PLAN_POSES}'):
        predictor.set_plan(range(BASE_NS, BASE_NS + n), [(0.0, 0.0, 1.0)] * n,
                           [(0.0, 0.0, 0.0, 1.0)] * n)
    assert predictor.plan is None
    stamps = [BASE_NS + k * 1000 for k in range(MAX_PLAN_POSES)]
    predictor.set_plan(stamps, [(0.0, 0.0, 1.0)] * len(stamps),
                       [(0.0, 0.0, 0.0, 1.0)] * len(stamps))
    assert len(predictor.plan[1].times) == MAX_PLAN_POSES


def _passing(glitch: bool, count: int = 8) -> Predictor:
    """Return a predictor whose ball flies at 40 m/s 15 cm over a still bat, 1.5 m off."""
    balls = [(1.5 - 40.0 * 0.005 * i, 0.5, 1.15) for i in range(count)]
    if glitch:  # the newest sample 15 cm lower: a tracker's glitch onto the bat's height
        balls[-1] = (balls[-1][0], 0.5, 1.0)
    return predictor_of(balls, [((0, 0, 1), (0, 0.86, 1))] * count)


def test_a_ball_glitch_as_the_newest_sample_predicts_nothing() -> None:
    """
    A newest ball sample off its flight (not judged yet) neither predicts nor clears.

    The forecast leaves it out (the kernel's ``without_ball_glitch``: the flight of the samples
    before it, to rounding), so the pass is forecast to miss the bat as it does; a prediction
    in force stays: not withdrawn, nor moved, by the glitch.
    """
    t0 = 0.005 * 7
    events = []
    clean = _passing(False)
    clean.predict(t0, True, events)
    assert events == []  # the pass misses the bat
    predictor = _passing(True)
    assert predictor._ball_forecast(t0) == pytest.approx(clean._ball_forecast(t0), abs=1e-9)
    predictor.predict(t0, True, events)
    assert events == [] and not predictor.predicting
    predictor.predicting, predictor.last_ns = True, BASE_NS
    predictor.predict(t0, True, events)
    assert events == [] and predictor.predicting and predictor.last_ns == BASE_NS


@pytest.mark.parametrize('window', [0.02, 0.1, 0.15, 0.3])
def test_the_kept_flight_span_is_where_the_parabola_drifts_a_balls_radius(window: float) -> None:
    """
    The parabola fitted to a flight's last ``window`` s, its acceleration changing by the jerk.

    Continued past the last sample (360 Hz stamps), the fit of the cubic ``jerk u^3 / 6`` misses
    it by ``GAP_FLIGHT_BIAS`` at the span (to 1 ms), not before.
    """
    span = kept_flight_span(window)
    stamps = np.arange(-window, 1e-12, 1.0 / 360.0)
    stamps -= stamps[-1]
    fit = np.polyfit(stamps, GAP_FLIGHT_JERK / 6.0 * stamps ** 3, 2)
    after = np.linspace(0.0, 0.5, 50_001)
    drift = np.abs(GAP_FLIGHT_JERK / 6.0 * after ** 3 - np.polyval(fit, after))
    assert after[np.argmax(drift > GAP_FLIGHT_BIAS)] == pytest.approx(span, abs=1e-3)


def test_the_kept_flight_span_by_window() -> None:
    """0.215 s for the default window, less for longer ones, the bare cubic's at most; 0 past."""
    assert kept_flight_span(0.1) == pytest.approx(0.2154, abs=1e-4)
    assert kept_flight_span(0.15) == pytest.approx(0.193, abs=1e-3)  # (sweep_ball's 0.19 s)
    bare = (6.0 * GAP_FLIGHT_BIAS / GAP_FLIGHT_JERK) ** (1 / 3)
    assert kept_flight_span(0.001) == pytest.approx(bare, abs=1e-3)
    spans = [kept_flight_span(w) for w in (0.001, 0.05, 0.1, 0.2, 0.4, 0.6)]
    assert spans == sorted(spans, reverse=True) and spans[-1] > 0.0
    assert kept_flight_span(1.0) == 0.0


@pytest.mark.parametrize('family', ['plane', 'tilted', 'rebound'])
@pytest.mark.parametrize('rate_hz, noise_m', [(90.0, 0.0), (90.0, 0.001), (360.0, 0.001)])
def test_the_nodes_predictions_are_made_at_the_message_that_sends_them(
        family: str, rate_hz: float, noise_m: float) -> None:
    """
    At look-ahead 0, every prediction starts from the newest input stamp fed when it comes out.

    ``made_at_ns`` is the detector's cursor; an arm gets the prediction with the message that
    moved it there, so a cursor behind the newest message would send a stale forecast as fresh
    (under a held bat glitch it can be: docs/faults.md). On genuine pitches it never is.
    """
    detector = Detector(DetectorConfig(prediction_horizon=0.3, prediction_period=0.01))
    scenario = make_scenario('barrel', np.random.default_rng(7), family=family)
    samples = sample(scenario, rate_hz, np.random.default_rng(1), jitter_s=2e-4, noise_m=noise_m)
    newest, made = 0, 0
    for stamp, role, values in samples.messages('pose'):
        newest = max(newest, stamp)
        for event in detector.add(role, stamp, values):
            if isinstance(event, (Prediction, PredictionCleared)):
                assert event.made_at_ns == newest
                made += 1
    assert made > 0
