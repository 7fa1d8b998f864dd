"""Stamp and message conversions, and detector events to messages through the one table."""

from dataclasses import replace
import json
import typing

from baseball_collision.bags.plans import plan_arrays  # (the node's, without rosbags)
from baseball_collision.core.detector import (
    DetectorConfig, DROP_REASONS, Event, Impact, NearMiss, Prediction, PredictionCleared,
    ResetReason, StateReset, StreamGap)
from baseball_collision.core.records import event_record
from baseball_collision.ros.messages import (
    describe_drop, event_output, FLAG_CDR, format_stamp, ns_to_stamp,
    stamp_to_ns, StampedCdr)
from geometry_msgs.msg import PointStamped, PoseStamped, TwistStamped, Vector3Stamped
from nav_msgs.msg import Path
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from std_msgs.msg import Bool
from support.events import swing_events
from support.scenes import BASE_NS
from visualization_msgs.msg import MarkerArray

pytestmark = pytest.mark.ros


def test_stamps_round_trip_to_the_nanosecond() -> None:
    """Stamps go to sec * 10**9 + nanosec and back, even epoch stamps floats cannot hold."""
    for ns in (0, 1, 999_999_999, BASE_NS + 123_456_789, 2**62 + 7):
        assert stamp_to_ns(ns_to_stamp(ns)) == ns
    assert ns_to_stamp(BASE_NS + 5).nanosec == 5
    assert format_stamp(BASE_NS + 5) == '1700000000.000000005'


def test_every_event_type_has_an_entry() -> None:
    """The dispatch table covers every type of the Event union; others are refused."""
    for event_type in typing.get_args(Event):
        assert event_type in (Impact, NearMiss, Prediction, PredictionCleared, StreamGap,
                              StateReset)
    assert event_output(PredictionCleared(made_at_ns=5), 'world', None).predicting is False
    with pytest.raises(KeyError):
        event_output(object(), 'world', lambda impact, frame: None)


def test_an_impact_becomes_its_point_velocity_markers_and_a_line() -> None:
    """~/impact and ~/impact_velocity at the impact instant, in the frame; markers when on."""
    impact = next(e for e in swing_events() if isinstance(e, Impact))
    off = event_output(impact, 'world', lambda i, frame: None)
    assert [name for name, _ in off.messages] == ['impact', 'impact_velocity']
    point, twist = (message for _, message in off.messages)
    assert isinstance(point, PointStamped) and isinstance(twist, TwistStamped)
    assert stamp_to_ns(point.header.stamp) == impact.stamp_ns == off.impact_ns
    assert point.header == twist.header and point.header.frame_id == 'world'
    assert (point.point.x, point.point.y, point.point.z) == pytest.approx(impact.point)
    assert (twist.twist.linear.x, twist.twist.linear.y, twist.twist.linear.z) == \
        pytest.approx(impact.bat_velocity)
    assert off.log.startswith(f'impact at {format_stamp(impact.stamp_ns)} s')
    assert off.log.endswith(
        f'1 sigma: time {impact.time_uncertainty_s * 1e6:.1f} us, spot '
        f'{impact.distance_from_knob_uncertainty_m * 100:.2f} cm, sweet-spot speed '
        f'{impact.sweet_spot_speed_uncertainty_mps:.2f} m/s')
    on = event_output(impact, 'world', lambda i, frame: MarkerArray())
    assert [name for name, _ in on.messages] == ['impact', 'impact_velocity', 'markers']
    # the node's bytes of both (StampedCdr): the same messages, as long as rclpy's own
    for message, count, values in ((point, 3, impact.point), (twist, 6, (
            *impact.bat_velocity, *impact.bat_angular_velocity))):
        data = StampedCdr(count)(impact.stamp_ns, 'world', values)
        assert deserialize_message(data, type(message)) == message
        assert len(data) == len(serialize_message(message))


def test_the_log_line_gives_the_records_spot_also_for_an_end_cap_hit() -> None:
    """An end-cap hit's line reads the contact point's own distance (the record's), not 3.3 cm."""
    from dataclasses import replace
    side = next(e for e in swing_events() if isinstance(e, Impact))
    # the same impact, with its contact point moved beyond the tip, as an end-cap hit has it
    axis = [t - k for k, t in zip(side.knob, side.tip)]
    length = sum(c * c for c in axis) ** 0.5
    beyond = tuple(t + 0.02 * a / length for t, a in zip(side.tip, axis))
    end_cap = replace(side, feature='tip_end', point=beyond)
    for impact in (side, end_cap):
        record = event_record(impact, 'world', DetectorConfig())
        line = event_output(impact, 'world', lambda i, frame: None).log
        assert f"{record['distance_from_tip_m'] * 100:.1f} cm from the tip" in line
    assert event_record(end_cap, 'world', DetectorConfig())['distance_from_tip_m'] == \
        pytest.approx(-0.02)


def test_near_miss_prediction_gap_and_reset() -> None:
    """Each becomes what the node publishes and logs (see EventOutput)."""
    miss = next(e for e in swing_events(height=1.09) if isinstance(e, NearMiss))
    output = event_output(miss, 'world', None)
    (name, vector), = output.messages
    assert name == 'near_miss' and isinstance(vector, Vector3Stamped)
    assert (vector.vector.x, vector.vector.y, vector.vector.z) == pytest.approx(miss.gap_vector)
    assert stamp_to_ns(vector.header.stamp) == miss.stamp_ns and output.log
    prediction = next(e for e in swing_events(horizon=0.3) if isinstance(e, Prediction))
    output = event_output(prediction, 'world', None)
    assert output.predicting is True and output.messages[0][0] == 'predicted_impact'
    predicted = output.messages[0][1]
    assert stamp_to_ns(predicted.header.stamp) == prediction.stamp_ns
    assert predicted.header.frame_id == 'world'
    assert (predicted.point.x, predicted.point.y, predicted.point.z) == prediction.point
    made_once = StampedCdr(3)  # the node's: the message's CDR bytes
    predictions = [e for e in swing_events(horizon=0.3) if isinstance(e, Prediction)][-2:]
    assert len(predictions) == 2 and predictions[0].stamp_ns != predictions[1].stamp_ns
    for frame in ('world', '', 'camera_7', 'caméra'):  # lengths 6, 1, 9, 8 with the NUL
        for each in predictions:
            data = made_once(each.stamp_ns, frame, each.point)
            expected = event_output(each, frame, None)
            assert isinstance(data, bytes) and expected.predicting is True
            assert deserialize_message(data, PointStamped) == expected.messages[0][1]
            # the same bytes as rclpy's own serialisation, but for the padding (not zeroed)
            serialised = serialize_message(expected.messages[0][1])
            assert len(data) == len(serialised) and data[:16] == serialised[:16]
            assert data[-24:] == serialised[-24:]
    for value in (False, True):
        assert deserialize_message(FLAG_CDR[value], Bool) == Bool(data=value)
        assert len(FLAG_CDR[value]) == len(serialize_message(Bool(data=value)))
    gap = event_output(StreamGap('ball', BASE_NS, BASE_NS + 80_000_000), 'world', None)
    assert gap.throttled and not gap.messages and '80.0 ms' in gap.log
    reset = event_output(StateReset(BASE_NS, 'time_jump_backwards'), 'world', None)
    assert reset.level == 'warning' and reset.echoes_clock_jump and reset.predicting is False


def test_a_state_reset_names_its_own_cause() -> None:
    """
    Each reason the detector resets itself on reads as itself, not as a jump back.

    A robot's bat pose in its base frame beside a ball in the tracker's made the detector
    adopt the bat's frame (``frame_changed``), and the node warned 'header stamps jumped back'.
    Only a jump back may echo the ROS clock's own warning.
    """
    lines = {reason: event_output(StateReset(BASE_NS, reason), 'world', None)
             for reason in ResetReason}
    back = lines[ResetReason.TIME_JUMP_BACKWARDS]
    assert back.log.startswith('header stamps jumped back to ') and back.echoes_clock_jump
    frame = lines[ResetReason.FRAME_CHANGED]
    assert 'jumped' not in frame.log and 'another frame than the first one seen' in frame.log
    assert 'jumped ahead' in lines[ResetReason.TIME_JUMP_FORWARD].log
    assert len({output.log for output in lines.values()}) == len(ResetReason)
    for reason, output in lines.items():
        assert output.level == 'warning' and output.predicting is False
        assert output.log.endswith(': detector state reset')
        assert output.echoes_clock_jump == (reason == ResetReason.TIME_JUMP_BACKWARDS)


def test_plan_and_drop_texts() -> None:
    """A Path becomes stamps, positions, quaternions and its frames; drops read in words."""
    path = Path()
    path.header.frame_id = 'world'
    for i, frame in enumerate(('', 'world', 'camera')):
        message = PoseStamped()
        message.header.stamp = ns_to_stamp(BASE_NS + i)
        message.header.frame_id = frame
        message.pose.position.x = float(i)
        message.pose.orientation.w = 1.0
        path.poses.append(message)
    stamps, positions, quaternions, frames = plan_arrays(path)
    assert stamps == [BASE_NS, BASE_NS + 1, BASE_NS + 2] and frames == {'world', 'camera'}
    assert positions[2] == (2.0, 0.0, 0.0) and quaternions[0] == (0.0, 0.0, 0.0, 1.0)
    assert describe_drop('wrong_frame', 'camera', 'world', BASE_NS) == (
        "frame 'camera' is not the tracking frame 'world' (every input must share one frame, "
        'no TF: publish this stream in it, or set frame_id)')
    assert describe_drop('new_reason', '', None, BASE_NS) == 'new_reason'


def test_every_drop_reason_has_its_own_words() -> None:
    """No log line says a reason twice ('bad_stamp: bad_stamp'): each has words of its own."""
    for reason in DROP_REASONS:
        words = describe_drop(reason, 'camera', 'world', BASE_NS)
        assert words and words != reason, reason
    assert 'zero or negative' in describe_drop('bad_stamp', '', None, 0)


def test_impacts_near_misses_and_predictions_are_reported_as_their_records() -> None:
    """An impact_report (std_msgs/String) per impact, near miss and prediction: its record."""
    config = DetectorConfig()
    events = swing_events(horizon=0.3) + swing_events(height=1.09)
    reported = 0
    for event in events:
        output = event_output(event, 'world', lambda impact, frame: None, config)
        reports = [message for name, message in output.messages if name == 'impact_report']
        if isinstance(event, (Impact, NearMiss, Prediction)):
            assert len(reports) == 1
            assert json.loads(reports[0].data) == json.loads(json.dumps(
                event_record(event, 'world', config)))
            if isinstance(event, Impact):
                assert json.loads(reports[0].data)['time_uncertainty_s'] == \
                    event.time_uncertainty_s
            reported += 1
        else:
            assert reports == []
        unreported = event_output(event, 'world', lambda impact, frame: None)
        assert unreported.messages == tuple(
            pair for pair in output.messages if pair[0] != 'impact_report')
        assert replace(output, messages=unreported.messages) == unreported  # the rest carried
    kinds = {type(event) for event in events}
    assert {Impact, NearMiss, Prediction} <= kinds and reported >= 3
