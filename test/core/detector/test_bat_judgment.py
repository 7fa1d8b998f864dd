"""Tests for the judgment of the bat frames a prediction's forecast reads (``bat_judgment``)."""

import math
from typing import Any, List, Tuple

from baseball_collision.core.detector import (
    Detector, DetectorConfig, Impact, Prediction, PredictionCleared)
from baseball_collision.core.detector.events import DropReason
from baseball_collision.core.detector.predictor import Predictor
from baseball_collision.core.motion import BatSample
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np
import pytest
from support.events import arrays, glitched_pitch, lost_glitched_pitch
from support.predictors import BASE_NS, Point, predictor_of, STILL


def _still_bat_turned_last(sign: float) -> Tuple[Predictor, List[Tuple[int, int]], Point]:
    """
    Return a still bat's predictor whose newest frame is turned, its drops, the ball's next.

    5 ms steps, a ball passing 0.5 m beside the bat; the newest frame turned 15 cm up (``sign``
    1) or down (-1) at the tip. ``drop_bat`` records (j, last) in the list as it removes frame j.
    """
    count = 14
    balls = [(0.1 + 0.2 * (count - 2 - i), 0.5, 1.15) for i in range(count)]
    angle = 2.0 * math.asin(0.5 * 0.15 / 0.86)
    turned = ((0.0, 0.0, 1.0),
              (0.0, 0.86 * math.cos(angle), 1.0 + sign * 0.86 * math.sin(angle)))
    predictor = predictor_of(balls[:-1], [STILL] * (count - 2) + [turned])
    dropped: List[Tuple[int, int]] = []

    def drop(j: int, last: int) -> None:
        dropped.append((j, last))
        predictor.bat.remove(j)
    predictor.drop_bat = drop
    return predictor, dropped, balls[-1]


def _next_still_frame(predictor: Predictor, ball: Point, events: List[Any]) -> None:
    """Add the ball's sample and a still bat frame 5 ms after the newest, and predict there."""
    k = len(predictor.bat.times)
    predictor.ball.append(0.005 * k, BASE_NS + k, ball, False)
    predictor.bat.append(0.005 * k, BASE_NS + k, BatSample(*STILL), False)
    predictor.predict(0.005 * k, True, events)


def _turned(frames_off: int, count: int = 8) -> Predictor:
    """
    Return a predictor whose ball passes 15 cm over a still bat, its newest frames turned up.

    The last ``frames_off`` bat frames have the tip 15 cm higher (turned about the knob): one
    is a tracker's glitch, two in a row the bat that moved.
    """
    balls = [(1.5 - 40.0 * 0.005 * i, 0.5, 1.15) for i in range(count)]
    angle = 2.0 * math.asin(0.5 * 0.15 / 0.86)
    up = ((0.0, 0.0, 1.0), (0.0, 0.86 * math.cos(angle), 1.0 + 0.86 * math.sin(angle)))
    bats = [((0.0, 0.0, 1.0), (0.0, 0.86, 1.0))] * (count - frames_off) + [up] * frames_off
    return predictor_of(balls, bats)


def test_a_bat_glitch_as_the_newest_frame_predicts_nothing() -> None:
    """A newest bat frame off the swing (the one before on it) neither predicts nor clears."""
    t0 = 0.005 * 7
    events = []
    predictor = _turned(1)
    predictor.predict(t0, True, events)
    assert events == [] and not predictor.predicting and predictor.last_ns is None
    predictor.predicting, predictor.last_ns = True, BASE_NS  # one in force stays
    predictor.predict(t0, True, events)
    assert events == [] and predictor.predicting and predictor.last_ns == BASE_NS
    # the frame before off too: the bat moved (or the glitch is in the window), predicted
    predictor = _turned(2)
    predictor.predict(t0, True, events)
    assert [type(e) for e in events] == [Prediction]


@pytest.mark.parametrize('family, seed, frame', [('jerky', 0, -4), ('lefty', 1, -1)])
def test_a_bat_glitch_in_the_forecast_window_is_dropped_before_it_predicts(
        family: str, seed: int, frame: int) -> None:
    """
    A 90 Hz miss (1 mm of noise) whose bat frame 4 or 1 before the closest approach is off.

    Turned 20 cm at the tip toward the ball: the frames after it, whose bat fit reads it,
    predicted a contact the miss does not have (the sweep dropped the glitch only near the
    ball, 3 ms before the closest approach or 7 ms after it). A frame that finds a contact
    judges the forecast's bat frames first (``Predictor._bat_glitch_dropped``): the glitch is
    dropped there, once, as ``bat_glitch``, and nothing is predicted.
    """
    rows, closest = glitched_pitch('miss_over', family, seed, 90.0, frame, noise_m=0.001)
    detector = Detector(DetectorConfig(look_ahead=0, prediction_horizon=0.3,
                                       prediction_period=0.01))
    events, dropped_at = [], None
    for role, stamp, values, frame_id in rows:
        events += detector.add(role, stamp, values, frame_id)
        if dropped_at is None and detector.stats.dropped[DropReason.BAT_GLITCH]:
            dropped_at = stamp
    events += detector.finish()
    assert not [e for e in events if isinstance(e, (Impact, Prediction))]
    assert detector.stats.dropped[DropReason.BAT_GLITCH] == 1
    assert dropped_at < closest


def test_a_newest_bat_frame_off_after_a_lost_one_predicts_without_it_till_the_next() -> None:
    """
    A newest bat frame two steps after the one before, a glitch's distance off, is not used.

    The forecast of the frames before it reaches over two steps, where a swing's own frame may
    land centimetres off it, so the frame is not held (``Predictor._bat_off``: ``ACROSS``): it
    predicts from the frames before it (here the still bat, which the ball passes over), and
    the frame after it says which it was: on the same pose, the bat moved, and the contact is
    predicted.
    """
    angle = 2.0 * math.asin(0.5 * 0.15 / 0.86)
    still = ((0.0, 0.0, 1.0), (0.0, 0.86, 1.0))
    up = ((0.0, 0.0, 1.0), (0.0, 0.86 * math.cos(angle), 1.0 + 0.86 * math.sin(angle)))
    balls = [(1.6 - 40.0 * 0.005 * i, 0.5, 1.15) for i in range(9)]  # (15 cm over the still bat)
    predictor = predictor_of(balls[:8], [still] * 7 + [up])
    predictor.drop_bat = lambda j, last: None
    predictor.bat.remove(6)  # (a still frame: the newest, turned up, 10 ms after the one before)
    events = []
    predictor.predict(0.005 * 7, True, events)
    assert events == [] and predictor.last_ns == predictor.clock.stamp(0.005 * 7)  # (not held)
    assert predictor.suspect == predictor.bat.times[-1]
    predictor.ball.append(0.005 * 8, BASE_NS + 8, balls[8], False)
    predictor.bat.append(0.005 * 8, BASE_NS + 8, BatSample(*up), False)
    predictor.predict(0.005 * 8, True, events)
    assert [type(e) for e in events] == [Prediction]


@pytest.mark.parametrize('family', ['plane', 'jerky'])
def test_a_bat_glitch_right_after_a_lost_frame_neither_holds_nor_bends_the_prediction(
        family: str) -> None:
    """
    A 90 Hz hit whose bat frame 4 before the contact, turned 10 cm, follows a frame lost.

    The typical optical tracker's fault: a marker re-acquired with the wrong label right after
    an occlusion. Taken as the swing's own (its step twice the one before), it bent the
    forecast away from the ball until the prediction 20 ms ahead was gone. Now it is more than
    the hole's floor off the forecast of the frames before it (``Predictor._across_floor``), so
    it predicts from those, and the frame after it, off the forecast through it, leaves it out
    (``_followed``): the prediction 20 ms ahead is the pitch without it's, on the contact.
    """
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    rows, deleted, contact = lost_glitched_pitch('barrel', family, 0, 4, -1)
    ahead = []
    for feed in (rows, deleted):
        detector = Detector(config)
        made = [(e.made_at_ns, getattr(e, 'stamp_ns', None)) for row in feed
                for e in detector.add(*row) if isinstance(e, (Prediction, PredictionCleared))]
        ahead.append([stamp for made_at, stamp in made if made_at <= contact - 0.02e9][-1])
    assert ahead[0] == ahead[1] and abs(ahead[0] - contact) < 0.001e9


def test_a_swing_frame_centimetres_off_after_a_lost_frame_keeps_its_prediction(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A 90 Hz graze with 1 mm of noise, the bat frame 4 before the contact lost: no glitch.

    The frame after the hole lands more than a glitch's floor (5 cm) off the forecast of the
    frames before it: the forecast across two steps carries the noise 6.1 times as far as the
    one-step forecast that floor is for. Judged against the hole's floor (the window's one-step
    miss that far on, ``Predictor._across_floor``), it is the swing's own, and predicts: the
    prediction 20 ms ahead stays on the contact (left out with the floor alone, none was in
    force there).
    """
    floors = []
    across_floor = Predictor._across_floor

    def spied(self: Predictor, first: int, end: int) -> float:
        floors.append(across_floor(self, first, end))
        return floors[-1]
    monkeypatch.setattr(Predictor, '_across_floor', spied)
    rng = np.random.default_rng(0)
    scenario = make_scenario('graze', rng, lead_s=0.4, family='plane')
    samples = sample(scenario, 90.0, rng, jitter_s=2e-4, noise_m=0.001)
    contact = samples.start_ns + int(round(scenario.truth.time_s * 1e9))
    j = int(np.flatnonzero(samples.bat_stamps_ns < contact)[-2])
    samples = samples.without_bat_frame(j - 2)
    detector, made = Detector(DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)), []
    for stamp, role, values in samples.messages():
        made += [(e.made_at_ns, getattr(e, 'stamp_ns', None)) for e in detector.add(
            role, stamp, values, 'world') if isinstance(e, (Prediction, PredictionCleared))]
    assert any(floor > 0.05 for floor in floors)  # (over the glitch floor: judged by the hole's)
    ahead = [stamp for made_at, stamp in made if made_at <= contact - 0.02e9]
    assert ahead[-1] is not None and abs(ahead[-1] - contact) < 0.001e9


def test_the_frame_after_a_bat_frame_stamped_off_predicts_without_it() -> None:
    """
    A 90 Hz hit whose bat frame 3 before the contact is stamped 2 ms late, its pose right.

    That frame, 7 cm along the swing from where its stamp puts it, is under a glitch's floor
    and taken; the frame after it is off the forecast it bends, and held the prediction (none
    shown until 4 ms before the contact). It is ``BEFORE_OFF`` times nearer the forecast of
    the frames before them both (``Predictor._bat_off``: ``BEFORE``), so it predicts from the
    forecast without the frame before: the prediction the pitch without that frame makes there,
    to the nanosecond.
    """
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    rows, closest = glitched_pitch('barrel', 'tilted', 0, 90.0, -3, stamp_off_s=0.002)
    # (1e-12 s rounds to a 0 ns shift: the same pitch as sampled, no frame faulted)
    sampled, _ = glitched_pitch('barrel', 'tilted', 0, 90.0, -3, stamp_off_s=1e-12)
    stamped = [row for row in rows if row not in sampled]
    without = [row for row in sampled if row[0] != 'bat_pose' or row[2] != stamped[0][2]]
    made = []
    for feed in (rows, without):
        detector = Detector(config)
        made.append({e.made_at_ns: e.stamp_ns for row in feed for e in detector.add(*row)
                     if isinstance(e, Prediction) and e.made_at_ns < closest})
    after = min(ns for ns in made[0] if ns > stamped[0][1])  # the frame after it
    assert len(stamped) == 1 and len(without) == len(rows) - 1
    assert after < closest - 0.02e9 and made[0][after] == made[1][after]
    assert abs(made[0][after] - closest) < 0.001e9


def test_a_bat_frame_that_held_a_prediction_is_judged_by_the_next_forecast() -> None:
    """
    A newest bat frame off the swing held the prediction; the next frame judges it.

    Whatever that frame's forecast shows: here it finds no contact and none is in force (the
    glitch in the window bends the fit away from the ball), where only a frame that would
    change what is shown judged the window's frames, and a glitch stayed in the forecasts
    until one did (at 90 Hz a hit lost its prediction 20 ms ahead). The frame is dropped
    (``drop_bat``: the sweep's ``bat_glitch`` drop) and no longer awaited (``suspect``).
    """
    predictor, dropped, ball = _still_bat_turned_last(1.0)
    events: List[Any] = []
    predictor.predict(0.005 * 12, True, events)
    assert events == [] and predictor.suspect == predictor.bat.times[-1] and not dropped
    _next_still_frame(predictor, ball, events)
    assert events == [] and dropped == [(12, 13)] and predictor.suspect is None


def test_a_suspect_bat_frame_is_forgotten_where_nothing_is_forecast() -> None:
    """
    A newest frame that held the prediction is awaited only while frames forecast.

    A due frame that forecasts nothing (disarmed, the ball out of reach) forgets it, so a chunk
    plan (which stops at every due frame while one is awaited) stops no more for it.
    """
    predictor = _turned(1)
    predictor.predict(0.005 * 7, True, [])
    assert predictor.suspect == predictor.bat.times[-1]
    predictor.predict(0.005 * 7, False, [])  # disarmed: nothing forecast
    assert predictor.suspect is None


def _after_a_hole(newest) -> Predictor:
    """Return a predictor whose ball passes 15 cm over a still bat, its frame 6 of 8 lost."""
    still = ((0.0, 0.0, 1.0), (0.0, 0.86, 1.0))
    balls = [(1.6 - 40.0 * 0.005 * i, 0.5, 1.15) for i in range(8)]
    predictor = predictor_of(balls, [still] * 7 + [newest])
    predictor.drop_bat = lambda j, last: None
    predictor.bat.remove(6)  # (the newest 10 ms after the one before)
    return predictor


def test_a_bat_glitch_after_a_hole_whose_forecast_finds_nothing_is_suspect() -> None:
    """
    A newest bat frame after a lost one, off the swing, whose forecast finds nothing, none shown.

    Turned down 15 cm, away from the ball that passes over the still bat: its forecast finds
    nothing, as the forecast without it does, so nothing is shown either way, and it was not
    judged: a glitch stayed in the forecasts after it, bent off the ball, until a frame showed a
    contact. Now it is judged as where a prediction is in force (``Predictor._bat_off``:
    ``ACROSS``): suspect, not held, nothing predicted from the forecast without it; the frame
    after it, off the forecast through it, leaves it out (``_followed``).
    """
    angle = 2.0 * math.asin(0.5 * 0.15 / 0.86)
    down = ((0.0, 0.0, 1.0), (0.0, 0.86 * math.cos(angle), 1.0 - 0.86 * math.sin(angle)))
    predictor = _after_a_hole(down)
    events = []
    predictor.predict(0.005 * 7, True, events)
    assert events == [] and not predictor.predicting
    assert predictor.suspect == predictor.bat.times[-1]
    assert predictor.last_ns == predictor.clock.stamp(0.005 * 7)  # (not held)
    glitch = len(predictor.bat.times) - 1
    predictor.ball.append(0.005 * 8, BASE_NS + 8, (1.6 - 40.0 * 0.005 * 8, 0.5, 1.15), False)
    predictor.bat.append(0.005 * 8, BASE_NS + 8, BatSample((0.0, 0.0, 1.0), (0.0, 0.86, 1.0)),
                         False)
    predictor.predict(0.005 * 8, True, events)
    assert events == [] and predictor._left_out == glitch


def test_a_still_bat_after_a_hole_whose_forecast_finds_nothing_suspects_no_frame() -> None:
    """The same pass, the frame after the hole the still bat's own: nothing held or suspect."""
    predictor = _after_a_hole(((0.0, 0.0, 1.0), (0.0, 0.86, 1.0)))
    events = []
    predictor.predict(0.005 * 7, True, events)
    assert events == [] and predictor.suspect is None
    assert predictor.last_ns == predictor.clock.stamp(0.005 * 7)


def test_a_bat_glitch_on_a_regular_step_whose_forecast_finds_nothing_is_judged() -> None:
    """
    A newest bat frame on a regular step, off the swing, whose forecast finds nothing, none shown.

    The ball passes 15 cm over a still bat; the newest frame is turned down 15 cm, away from
    it. Its forecast finds nothing, as the forecast without it does, so nothing is shown either
    way, and the frame was not judged: the glitch stayed in the window, bending the forecasts
    after it, until a frame showed a contact. Now it is held as where a prediction is in force
    (``Predictor._bat_off``: ``NEWEST``), and the next frame judges it: dropped as the sweep
    drops a glitch (``drop_bat``).
    """
    predictor, dropped, ball = _still_bat_turned_last(-1.0)
    events: List[Any] = []
    predictor.predict(0.005 * 12, True, events)
    assert events == [] and not predictor.predicting
    assert predictor.suspect == predictor.bat.times[-1] and predictor.last_ns is None  # (held)
    _next_still_frame(predictor, ball, events)
    assert events == [] and dropped == [(12, 13)] and predictor.suspect is None


def test_a_still_bat_on_regular_steps_whose_forecast_finds_nothing_suspects_no_frame() -> None:
    """The same pass over a still bat, no frame turned: nothing found, nothing held or judged."""
    count = 14
    balls = [(0.1 + 0.2 * (count - 2 - i), 0.5, 1.15) for i in range(count)]
    predictor = predictor_of(balls[:-1], [((0.0, 0.0, 1.0), (0.0, 0.86, 1.0))] * (count - 1))
    predictor.drop_bat = lambda j, last: pytest.fail('a still bat frame dropped')
    events = []
    predictor.predict(0.005 * (count - 2), True, events)
    assert events == [] and predictor.suspect is None
    assert predictor.last_ns == predictor.clock.stamp(0.005 * (count - 2))  # (not held)


@pytest.mark.parametrize('family', ['tilted', 'jerky'])
def test_a_bat_glitch_after_a_lost_frame_whose_forecast_found_nothing_is_left_out(
        family: str) -> None:
    """
    A 90 Hz hit whose bat frame 4 before the contact, turned 10 cm, follows a frame lost.

    No prediction was in force there yet, and the glitch's own forecast found none: nothing
    was judged, so the glitch stayed in the forecasts after it, bent off the ball until 20 ms
    before the contact. Now a frame whose forecast finds nothing still judges its newest frame
    (``Predictor._bat_off``): more than the hole's floor off (``ACROSS``) it is suspect, the
    frame after it leaves it out (``_followed``), and the prediction 20 ms ahead is the pitch
    without it's, on the contact. The chunk path stops at that frame too
    (``plan_prediction.prediction_stops``): the same events.
    """
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    rows, deleted, contact = lost_glitched_pitch('barrel', family, 1, 4, -1)
    ahead, fed = [], []
    for feed in (rows, deleted):
        detector = Detector(config)
        fed.append([e for row in feed for e in detector.add(*row)] + detector.finish())
        made = [(e.made_at_ns, getattr(e, 'stamp_ns', None)) for e in fed[-1]
                if isinstance(e, (Prediction, PredictionCleared))]
        ahead.append([stamp for made_at, stamp in made if made_at <= contact - 0.02e9][-1])
    assert ahead[0] == ahead[1] and abs(ahead[0] - contact) < 0.001e9
    detector = Detector(config)
    chunked = []
    for start in range(0, len(rows), 50):
        chunked += detector.add_chunk(*arrays(rows[start:start + 50]))
    assert chunked + detector.finish() == fed[0]


@pytest.mark.parametrize('lost, segment', [(0, 4), (-2, 0)])
def test_a_bat_glitch_the_window_cannot_judge_is_left_out_till_it_is_judged(
        lost: int, segment: int) -> None:
    """
    A 90 Hz hit whose bat frame 4 before the contact, turned 10 cm, the window cannot judge.

    Its segment's 4th frame (the tracker re-acquired the bat 3 frames before it), or beside a
    frame lost two before it (a hole over ``bat_glitches.LOST_HOLE``): the sweep's rule for it
    (``early_glitch``, ``hole_glitch``) needs frames after it. It held the prediction as the
    newest frame (``Predictor._bat_off``: with 4 frames in a window that starts its segment),
    then bent the forecasts after it, which withdrew the prediction 20 ms ahead. Now the frames
    after it forecast without it while that rule waits for them or judges it a glitch
    (``Predictor._late_verdict``): the predictions the pitch without it makes, to the nanosecond.
    """
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    rows, deleted, contact = lost_glitched_pitch('barrel', 'plane', 0, 4, lost, segment)
    made = []
    for feed in (rows, deleted):
        detector = Detector(config)
        made.append([(e.made_at_ns, getattr(e, 'stamp_ns', None)) for row in feed
                     for e in detector.add(*row)
                     if isinstance(e, (Prediction, PredictionCleared))
                     and e.made_at_ns < contact])
    assert made[0] == made[1]
    ahead = [stamp for made_at, stamp in made[1] if made_at <= contact - 0.02e9]
    assert ahead[-1] is not None and abs(ahead[-1] - contact) < 0.001e9


def _made(config: DetectorConfig, rows: List[Tuple[Any, ...]], since: int,
          until: int) -> Tuple[List[Tuple[int, Any]], List[Any]]:
    """Return the predictions and clearings made in [since, until) ns (made, stamp), and all."""
    detector = Detector(config)
    events = [e for row in rows for e in detector.add(*row)] + detector.finish()
    return [(e.made_at_ns, getattr(e, 'stamp_ns', None)) for e in events
            if isinstance(e, (Prediction, PredictionCleared)) and since <= e.made_at_ns < until
            ], events


@pytest.mark.parametrize('kind, family', [('graze', 'plane'), ('barrel', 'jerky')])
def test_a_bat_glitch_as_its_segments_2nd_frame_is_told_by_the_frames_before_the_gap(
        kind: str, family: str) -> None:
    """
    A 90 Hz hit whose bat frame 4 before the contact, turned 20 cm, is its segment's 2nd.

    No forecast is made from two frames, so it was never suspect: it bent the forecast of the
    segment's first four frames, which held the genuine 4th (``Predictor._bat_off``), and
    nothing was predicted 20 ms ahead; the forecasts after it (the 4th left out, the glitch in)
    missed the contact by 3-5 ms. The frames before the tracking gap tell which of the 2nd and
    the 4th is off (``_second_across``): the 2nd is left out from the 4th frame on, till the
    sweep's rule judges it. The predictions before the contact are then the pitch without the
    glitch's, to the nanosecond, the one 20 ms ahead on the contact; the chunk path's events
    are one sample at a time's.
    """
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    rows, deleted, contact = lost_glitched_pitch(kind, family, 1, 4, segment=2, turn=0.2)
    made, events = _made(config, rows, 0, contact)
    assert made == _made(config, deleted, 0, contact)[0]
    ahead = [stamp for made_at, stamp in made if made_at <= contact - 0.02e9]
    assert ahead[-1] is not None and abs(ahead[-1] - contact) < 0.001e9
    detector = Detector(config)
    chunked = []
    for start in range(0, len(rows), 50):
        chunked += detector.add_chunk(*arrays(rows[start:start + 50]))
    assert chunked + detector.finish() == events


@pytest.mark.parametrize('kind, family', [('graze', 'plane'), ('barrel', 'jerky')])
def test_a_bat_glitch_as_the_streams_2nd_frame_is_left_out_once_the_5th_tells(
        kind: str, family: str) -> None:
    """
    As above, with no bat frame before the segment (the bat first tracked there).

    From four frames a glitch at the 4th and one at the 2nd cannot be told apart, so the 4th is
    held; the 5th frame tells (``_second_instead``: it leaves the forecast through the 2nd and
    lands on the one without it), and the 2nd is left out from then on, till the sweep's rule
    judges it (``early_glitch``). The predictions the 5th frame on makes before the contact are
    the pitch without the glitch's, to the nanosecond, on the contact.
    """
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    feeds = lost_glitched_pitch(kind, family, 1, 4, segment=2, turn=0.2)
    contact = feeds[2]
    bat = [row[1] for row in feeds[1] if row[0] != 'ball']
    first = next(b for a, b in zip(bat, bat[1:]) if b - a > config.max_gap * 1e9)
    rows, deleted = ([row for row in feed if row[0] == 'ball' or row[1] >= first]
                     for feed in feeds[:2])
    made = _made(config, rows, contact - int(0.015e9), contact)[0]
    assert made and made == _made(config, deleted, contact - int(0.015e9), contact)[0]
    assert all(stamp is not None and abs(stamp - contact) < 0.001e9 for _, stamp in made)


@pytest.mark.parametrize('kind, family', [('graze', 'plane'), ('barrel', 'jerky')])
def test_a_bat_glitch_as_its_segments_3rd_frame_is_told_by_the_frames_before_the_gap(
        kind: str, family: str) -> None:
    """
    A 90 Hz hit whose bat frame 4 before the contact, turned 20 cm, is its segment's 3rd.

    Three frames cannot judge their newest, so the forecast of the segment's first three, the
    glitch in, missed the contact; the next window held the genuine 4th as off
    (``Predictor._bat_off``) while the glitch stayed in, and nothing was predicted 20 ms
    ahead. The frames before the tracking gap tell that the 3rd is off (``_third_across``: the
    fit without it in ``motion.c2``'s chart leaves the others nearest): it is held and then
    left out till the sweep's rule judges it. The prediction in force 20 ms ahead is then on
    the contact, as the pitch without the glitch's; the chunk path's events are one sample at
    a time's.
    """
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    rows, deleted, contact = lost_glitched_pitch(kind, family, 1, 4, segment=3, turn=0.2)
    made, events = _made(config, rows, 0, contact)
    for feed in (made, _made(config, deleted, 0, contact)[0]):
        ahead = [stamp for made_at, stamp in feed if made_at <= contact - 0.02e9]
        assert ahead and ahead[-1] is not None and abs(ahead[-1] - contact) < 0.001e9
    detector = Detector(config)
    chunked = []
    for start in range(0, len(rows), 50):
        chunked += detector.add_chunk(*arrays(rows[start:start + 50]))
    assert chunked + detector.finish() == events
