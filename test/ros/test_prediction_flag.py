"""
Tests for baseball_collision.ros.prediction_flag: ~/impact_predicted raised and withdrawn.

In-process, over real rclpy topics (``conftest``'s harness, discovery off); every expectation
is on header stamps or the order of the node's own publications.
"""

import time
from typing import Any, Callable, List, Tuple

from baseball_collision.core.detector.predictor import kept_flight_span
import pytest
from rclpy.parameter import Parameter
from support.harness import Harness, point_msg, pose_msg, RATE_HZ, sample_ns, SAMPLES
from support.node_inputs import publish_swing, swing_harness
from support.scenes import BASE_NS, pitch, pose

pytestmark = pytest.mark.ros


def test_an_impact_turns_the_prediction_off_at_once(harness: Callable[..., Harness],
                                                    truth_ns: int) -> None:
    """
    ~/impact_predicted turns false with the ~/impact, not at the next frame that predicts.

    With ``prediction_period`` 0.01 the frame of the contact does not predict and the next
    one is never sent: ``PredictionCleared`` never comes (``stale_timeout`` is far off).
    """
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3, 'prediction_period': 0.01,
                                        'stale_timeout': 30.0})
    contact = int((truth_ns - BASE_NS) * 1e-9 * RATE_HZ) + 1  # the first frame after it
    h.processed(publish_swing(h, 'pose', pitch(), samples=range(contact + 1)))
    h.wait(lambda: h.received['impact'], 5.0, 'the impact')
    assert any(message.data for message in h.received['predicting'])
    h.wait(lambda: not h.received['predicting'][-1].data, 5.0, 'the prediction withdrawn')


@pytest.mark.parametrize('ended_by', ['silence', 'prediction_off'])
def test_a_prediction_in_force_is_withdrawn_when_no_frame_can_end_it(
        harness: Callable[..., Harness], truth_ns: int, ended_by: str) -> None:
    """
    The streams stop 8 ms before the predicted contact: ~/impact_predicted turns false.

    Within ``stale_timeout`` and a diagnostics period (``silence``), or at once when the
    prediction is turned off at runtime (``prediction_off``). It stayed true for good: only a
    frame could clear it.
    """
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3, 'stale_timeout': 0.3,
                                        'diagnostics_period': 0.1})
    early = range(int((truth_ns - BASE_NS) * 1e-9 * RATE_HZ) - 3)  # up to ~8 ms before
    h.processed(publish_swing(h, 'pose', pitch(), samples=early))
    h.wait(lambda: h.received['predicting'][-1:] and h.received['predicting'][-1].data, 3.0,
           'a prediction in force')
    if ended_by == 'prediction_off':
        result = h.node.set_parameters([Parameter('prediction_horizon', value=0.0)])
        assert result[0].successful
    h.wait(lambda: not h.received['predicting'][-1].data, 3.0, 'the prediction withdrawn')
    assert not h.received['impact']


class PublishOrder:
    """A node's output publisher that also notes, in a shared list, what it published."""

    def __init__(self, publisher: Any, name: str, order: List[Tuple[str, Any]]) -> None:
        self._publisher, self._name, self._order = publisher, name, order

    def publish(self, message: Any) -> None:
        """Note ``(name, message)``, then publish the message."""
        self._order.append((self._name, message))
        self._publisher.publish(message)

    def __getattr__(self, attribute: str) -> Any:
        """Return the publisher's own attribute (topic_name, get_subscription_count ...)."""
        return getattr(self._publisher, attribute)


@pytest.mark.parametrize('paced', [False, True])
@pytest.mark.parametrize('late_samples', [22, 36])  # the ball 61 ms and 100 ms after the bat
def test_a_late_ball_keeps_the_prediction_until_its_impact(
        harness: Callable[..., Harness], truth_ns: int, late_samples: int, paced: bool) -> None:
    """
    The ball's messages come 61-100 ms after the bat's: ~/impact_predicted turns true once.

    Then false right after the ``~/impact``. The bat passes the predicted instant by
    ``max_gap`` (18 frames) long before the late ball reaches it: a prediction withdrawn on
    the bat's stamps alone flapped with each of the ball's next predictions, and turned false
    before the impact (``stale_timeout`` is far off here). ``paced``: the frames sent at their
    rate, so that the ball is late on the node's clock too; it streams on, silent for far
    less than its lag plus ``max_gap``: not taken for lost (``PredictionWatch.ball_lost``).
    """
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3, 'stale_timeout': 30.0})
    order: List[Tuple[str, Any]] = []
    for name in ('impact', 'impact_predicted'):
        h.node._outputs[name] = PublishOrder(h.node._outputs[name], name, order)
    sent = 0
    for i in range(SAMPLES + late_samples):
        t = i / RATE_HZ
        h.publishers['bat_pose'].publish(pose_msg(sample_ns(i), *pose(t)))
        sent += 1
        if paced:
            time.sleep(1.0 / RATE_HZ)
        elif i == late_samples - 1:
            h.processed(sent)  # the bat's lead taken before the first ball
        if i >= late_samples:
            j = i - late_samples
            h.publishers['ball'].publish(point_msg(sample_ns(j), pitch()(j / RATE_HZ)))
            sent += 1
    h.processed(sent)
    h.wait(lambda: h.received['impact'] and h.received['predicting'][-1:]
           and not h.received['predicting'][-1].data, 5.0, 'the impact and a cleared prediction')
    assert [message.data for message in h.received['predicting']] == [True, False]
    assert [name for name, _ in order] == ['impact_predicted', 'impact', 'impact_predicted']


@pytest.mark.parametrize('lost', ['ball', 'bat_pose'])
def test_a_prediction_is_withdrawn_when_one_stream_stops_and_the_other_streams_on(
        harness: Callable[..., Harness], truth_ns: int, lost: str) -> None:
    """
    One stream is lost 8 ms before the predicted contact, the other streams on: the flag goes off.

    The ball lost: once the bat passed the predicted instant by ``max_gap`` and the ball has
    been silent longer than its lag behind the bat plus ``max_gap``, and the bat passed the
    ball's last stamp by the span its flight holds unseen (``PredictionWatch``,
    ``kept_flight_span``: a paused tracker may still bring the contact till then): an arm
    learns that no contact is coming then, not a ``stale_timeout`` (30 s here) later.
    The bat lost: once it has been silent beyond ``stale_timeout`` (0.3 s), at a ball message
    (the diagnostics period, whose timer also checks it, is far off here).
    """
    h = swing_harness(harness, 'pose', {'prediction_horizon': 0.3, 'diagnostics_period': 60.0,
                                        'stale_timeout': 30.0 if lost == 'ball' else 0.3})
    last = int((truth_ns - BASE_NS) * 1e-9 * RATE_HZ) - 3  # the last frame, ~8 ms before
    h.processed(publish_swing(h, 'pose', pitch(), samples=range(last + 1)))
    h.wait(lambda: h.received['predicting'][-1:] and h.received['predicting'][-1].data, 3.0,
           'a prediction in force')
    passed = h.node._watch.instant_ns + round(h.node.detector.config.max_gap * 1e9)
    withdrawn_at: List[int] = []  # the bat's stamp before its newest as the flag turned false
    set_predicting = h.node._set_predicting

    def noting(predicting: bool) -> None:
        if h.node._predicting and not predicting:
            withdrawn_at.append(h.node._watch.before_newest['bat_pose'])
        set_predicting(predicting)
    h.node._set_predicting = noting
    i = last + 1
    while h.received['predicting'][-1].data and i < last + 600:  # (3 s of frames)
        if lost == 'ball':
            h.publishers['bat_pose'].publish(pose_msg(sample_ns(i), *pose(i / RATE_HZ)))
        else:
            h.publishers['ball'].publish(point_msg(sample_ns(i), pitch()(i / RATE_HZ)))
        i += 1
        time.sleep(0.005)
    assert not h.received['predicting'][-1].data, 'the prediction was not withdrawn'
    assert len(withdrawn_at) == 1
    assert withdrawn_at[0] > passed or lost == 'bat_pose'  # not before the bat passed
    held = h.node._watch.ball_newest_ns + round(
        kept_flight_span(h.node.detector.config.prediction_window) * 1e9)
    assert withdrawn_at[0] > held or lost == 'bat_pose'  # nor while the ball's flight holds
    assert not h.received['impact']
