"""PredictionWatch: when a predicted impact has passed without its contact (no rclpy)."""

from typing import Dict, List, Tuple

from baseball_collision.core.detector.predictor import kept_flight_span
from baseball_collision.ros.prediction_watch import BALL_LAGS, PredictionWatch

MAX_GAP = 0.05
SPAN = 0.0  # s: the flight span (``kept_flight_span``) where it is not what is tested
HOLD = kept_flight_span(0.1)  # s: the flight span of the default prediction_window
STEP_NS = 10_000_000  # 100 Hz
INSTANT_NS = 1_000_000_000  # the predicted instant


def _stream(watch: PredictionWatch, arrivals: Dict[str, float], stream: str,
            stamps: List[int], lag: float) -> None:
    """Feed ``stream`` its stamps, each taken ``lag`` s after its stamp on the steady clock."""
    previous = None
    for stamp in stamps:
        arrival = stamp * 1e-9 + lag
        watch.accepted(stream, stamp, previous, arrival)
        arrivals[stream] = arrival
        previous = stamp


def _swing(ball_lag: float, ball_until_ns: int, bat_until_ns: int
           ) -> Tuple[PredictionWatch, Dict[str, float]]:
    """Return a watch fed a bat and a ball at 100 Hz to their last stamps, the ball lagging."""
    watch, arrivals = PredictionWatch(('ball', 'bat_pose')), {}
    watch.instant_ns = INSTANT_NS
    _stream(watch, arrivals, 'bat_pose', list(range(0, bat_until_ns + 1, STEP_NS)), 0.002)
    _stream(watch, arrivals, 'ball', list(range(0, ball_until_ns + 1, STEP_NS)), ball_lag)
    return watch, arrivals


def test_a_prediction_passed_by_every_stream_has_passed() -> None:
    """Two samples more than max_gap past the instant on each stream: passed; one short: not."""
    beyond = INSTANT_NS + round(MAX_GAP * 1e9) + 2 * STEP_NS
    watch, arrivals = _swing(0.0, beyond, beyond)
    assert watch.passed(beyond * 1e-9, arrivals, MAX_GAP, SPAN)
    watch, arrivals = _swing(0.0, beyond - STEP_NS, beyond)  # the ball one sample short
    assert not watch.passed((beyond - STEP_NS) * 1e-9, arrivals, MAX_GAP, SPAN)


def test_a_late_ball_streaming_on_is_not_lost_and_a_silent_one_is() -> None:
    """
    The ball's messages 80 ms behind the bat's: silent for less than 80 ms + max_gap, not lost.

    The bat passed the instant; the ball's newest is before it. Silent longer than its lag plus
    ``max_gap``: lost, the prediction passed. A stamp alone (the bat's) would have said passed
    80 ms too soon.
    """
    bat_end = INSTANT_NS + 200_000_000
    watch, arrivals = _swing(0.080, INSTANT_NS - 30_000_000, bat_end)
    last_ball = arrivals['ball']
    assert not watch.passed(last_ball + 0.080 + MAX_GAP - 0.005, arrivals, MAX_GAP, SPAN)
    assert watch.passed(last_ball + 0.080 + MAX_GAP + 0.005, arrivals, MAX_GAP, SPAN)
    assert watch.ball_lost(last_ball + 0.080 + MAX_GAP + 0.005, arrivals, MAX_GAP)


def test_the_lag_is_the_largest_of_the_recent_ball_messages() -> None:
    """A camera's bursts: one message 150 ms late among the last BALL_LAGS keeps the lag at it."""
    watch, arrivals = _swing(0.0, INSTANT_NS - 30_000_000, INSTANT_NS + 200_000_000)
    stamp = INSTANT_NS - 20_000_000
    watch.accepted('ball', stamp, stamp - STEP_NS, stamp * 1e-9 + 0.150)  # a late burst
    arrivals['ball'] = stamp * 1e-9 + 0.150
    assert not watch.ball_lost(arrivals['ball'] + 0.150 + MAX_GAP - 0.01, arrivals, MAX_GAP)
    for _ in range(BALL_LAGS):  # the burst falls out of the messages kept
        stamp += STEP_NS // 100
        watch.accepted('ball', stamp, stamp - STEP_NS // 100, stamp * 1e-9)
        arrivals['ball'] = stamp * 1e-9
    assert watch.ball_lost(arrivals['ball'] + MAX_GAP + 0.01, arrivals, MAX_GAP)


def test_no_bat_sample_past_the_instant_no_passing() -> None:
    """The bat has not passed the instant: never passed, however long the ball is silent."""
    watch, arrivals = _swing(0.0, INSTANT_NS - 30_000_000, INSTANT_NS)
    assert not watch.passed(arrivals['ball'] + 10.0, arrivals, MAX_GAP, SPAN)
    assert watch.ball_lost(arrivals['ball'] + 10.0, arrivals, MAX_GAP)


def test_clear_forgets_the_streams() -> None:
    """After a state reset the streams' samples are forgotten: nothing has passed."""
    beyond = INSTANT_NS + round(MAX_GAP * 1e9) + 2 * STEP_NS
    watch, arrivals = _swing(0.0, beyond, beyond)
    watch.clear()
    assert watch.before_newest == {}
    assert not watch.passed(beyond * 1e-9, arrivals, MAX_GAP, SPAN)


def test_a_paused_balls_flushed_samples_do_not_raise_the_withdrawn_prediction_again() -> None:
    """
    The ball pauses 30 ms before the instant; the bat streams past it; the ball was silent.

    The prediction is withdrawn for the ball's silence (``passed``), its instant + max_gap kept
    (``silenced_ns``). The ball's tracker catches up, flushing its samples: a prediction of the
    same instant, or of another the bat passed as far, does not turn the flag on again
    (``raises``); one ahead of the bat does; once the ball's samples pass the instant withdrawn
    any prediction does.
    """
    bat_end = INSTANT_NS + 200_000_000
    watch, arrivals = _swing(0.0, INSTANT_NS - 30_000_000, bat_end)
    assert watch.raises(INSTANT_NS, MAX_GAP)  # (nothing withdrawn yet)
    silent = arrivals['ball'] + MAX_GAP + 0.01
    assert watch.passed(silent, arrivals, MAX_GAP, SPAN)
    assert watch.silenced_ns == INSTANT_NS + round(MAX_GAP * 1e9)
    flushed = list(range(INSTANT_NS - 20_000_000, INSTANT_NS + 1, STEP_NS))
    _stream(watch, arrivals, 'ball', flushed, silent - flushed[-1] * 1e-9)
    assert not watch.raises(INSTANT_NS, MAX_GAP)
    assert not watch.raises(INSTANT_NS + 100_000_000, MAX_GAP)
    assert watch.raises(bat_end, MAX_GAP)  # ahead of the bat
    later = list(range(INSTANT_NS + STEP_NS, INSTANT_NS + 80_000_000, STEP_NS))
    _stream(watch, arrivals, 'ball', later, silent - flushed[-1] * 1e-9)
    assert watch.raises(INSTANT_NS, MAX_GAP) and watch.silenced_ns is None


def test_a_prediction_passed_by_the_balls_samples_raises_again() -> None:
    """Passed by every stream's samples (not the ball's silence): nothing is kept from raising."""
    beyond = INSTANT_NS + round(MAX_GAP * 1e9) + 2 * STEP_NS
    watch, arrivals = _swing(0.0, beyond, beyond)
    assert watch.passed(beyond * 1e-9, arrivals, MAX_GAP, SPAN)
    assert watch.silenced_ns is None and watch.raises(INSTANT_NS, MAX_GAP)
    watch.silenced_ns = INSTANT_NS
    watch.clear()
    assert watch.silenced_ns is None


def test_a_silent_ball_holds_the_prediction_while_its_flight_holds() -> None:
    """
    The ball silent 30 ms before the instant, the bat streaming on: held past lag + max_gap.

    Not passed while the bat's sample before its newest is within the flight span after the
    ball's newest stamp (the flight before the silence still good: a paused tracker still brings
    the contact), however long the ball has been silent by the arrivals; passed one bat sample
    past it, the instant + max_gap kept (``silenced_ns``). The ball's newest is forgotten on a
    state reset.
    """
    last_ball = INSTANT_NS - 30_000_000
    hold_end = last_ball + round(HOLD * 1e9)
    bat_end = hold_end - hold_end % STEP_NS + STEP_NS  # (the first bat stamp past the span)
    watch, arrivals = _swing(0.0, last_ball, bat_end)
    assert watch.ball_newest_ns == last_ball
    silent = bat_end * 1e-9 + 0.01  # (silent far longer than its lag plus max_gap)
    assert watch.ball_lost(silent, arrivals, MAX_GAP)
    assert not watch.passed(silent, arrivals, MAX_GAP, HOLD)  # (the bat's sample before: within)
    assert watch.silenced_ns is None
    _stream(watch, arrivals, 'bat_pose', [bat_end, bat_end + STEP_NS], 0.002)
    assert watch.passed(silent + STEP_NS * 1e-9, arrivals, MAX_GAP, HOLD)
    assert watch.silenced_ns == INSTANT_NS + round(MAX_GAP * 1e9)
    watch.clear()
    assert watch.ball_newest_ns is None


def test_a_lagging_balls_flight_holds_its_lag_longer() -> None:
    """
    The ball's messages 60 ms behind the bat's, silent 30 ms before the instant: held till then.

    The bat streams well past the ball's newest stamp + the flight span; the samples of that span
    would come 60 ms later than their stamps: not passed until the ball has been silent the
    span since its last arrival.
    """
    last_ball = INSTANT_NS - 30_000_000
    watch, arrivals = _swing(0.060, last_ball, last_ball + round(HOLD * 1e9) + 100_000_000)
    held = arrivals['ball'] + HOLD
    assert not watch.passed(held - 0.001, arrivals, MAX_GAP, HOLD)
    assert watch.passed(held + 0.001, arrivals, MAX_GAP, HOLD)


def test_the_flight_span_does_not_hold_a_ball_streaming_past_the_instant() -> None:
    """The ball's own samples past the instant + max_gap: passed whatever the flight span."""
    beyond = INSTANT_NS + round(MAX_GAP * 1e9) + 2 * STEP_NS
    watch, arrivals = _swing(0.0, beyond, beyond)
    assert watch.passed(beyond * 1e-9, arrivals, MAX_GAP, HOLD)
