"""
Conversions between ROS messages and the core's plain values, and detector events to messages.

Header stamps become integer nanoseconds (``sec * 10**9 + nanosec``) and back; points, vectors
and quaternions become tuples (quaternions in ROS order x, y, z, w). Each detector event type
maps, through one table keyed by the event's type (:func:`event_output`), to the messages it is
published as (by output name: ``impact``, ``impact_velocity``, ``near_miss``,
``predicted_impact``, ``markers``) and the line it is logged as.
"""

from dataclasses import dataclass
import struct
from typing import (
    Any, Callable, Dict, Mapping, Optional, Sequence, Tuple, Type, Union)

from builtin_interfaces.msg import Time as TimeMsg
from geometry_msgs.msg import Point, PointStamped, TwistStamped, Vector3Stamped
from std_msgs.msg import Header, String
from visualization_msgs.msg import MarkerArray

from ..core.detector import (
    DetectorConfig, Event, Impact, MPS_TO_MPH, NearMiss, Prediction, PredictionCleared,
    ResetReason, StateReset, StreamGap)
from ..core.geometry import Quaternion, Vector
from ..core.health import format_stamp, NS_PER_S
from ..core.records import contact_from_tip, EVENT_NAMES, event_record, record_text

# ----------------------------------------------------------------------------------------------
# stamps and geometry


def type_name(msg_type: Any) -> str:
    """Return a message class's ROS name, e.g. ``geometry_msgs/msg/PointStamped``."""
    return f"{msg_type.__module__.split('.')[0]}/msg/{msg_type.__name__}"


def stamp_to_ns(stamp: TimeMsg) -> int:
    """Return a header stamp as integer nanoseconds (``sec * 10**9 + nanosec``)."""
    return stamp.sec * NS_PER_S + stamp.nanosec


def ns_to_stamp(stamp_ns: int) -> TimeMsg:
    """Return integer nanoseconds as a ``builtin_interfaces/Time``."""
    return TimeMsg(sec=stamp_ns // NS_PER_S, nanosec=stamp_ns % NS_PER_S)


def stamped_header(stamp_ns: int, frame_id: str) -> Header:
    """Return a header stamped with integer nanoseconds."""
    return Header(stamp=ns_to_stamp(stamp_ns), frame_id=frame_id)


def xyz(v: Any) -> Vector:
    """Return the x, y, z fields of a Point or Vector3 message."""
    return (v.x, v.y, v.z)


def xyzw(q: Any) -> Quaternion:
    """Return a Quaternion message as (x, y, z, w)."""
    return (q.x, q.y, q.z, q.w)


def to_point(v: Vector) -> Point:
    """Return a vector (m) as a geometry_msgs/Point."""
    return Point(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def point_stamped(stamp_ns: int, frame_id: str, v: Vector,
                  message: Optional[PointStamped] = None) -> PointStamped:
    """
    Return a point (m) stamped with integer nanoseconds, as a geometry_msgs/PointStamped.

    Filled in place (a message built from keyword arguments makes and checks each nested
    default first: 14 us against 9 us); into ``message`` when given (a message made once and
    refilled), else into a new one.
    """
    if message is None:
        message = PointStamped()
    header, point = message.header, message.point
    header.stamp.sec, header.stamp.nanosec = divmod(stamp_ns, NS_PER_S)
    header.frame_id = frame_id
    point.x, point.y, point.z = float(v[0]), float(v[1]), float(v[2])
    return message


# ----------------------------------------------------------------------------------------------
# log lines


def describe_impact(impact: Impact) -> str:
    """Return the one-line, human-readable summary of an impact (m, cm, m/s, mph, ms)."""
    into = (impact.stamp_ns - impact.interval_start_ns) * 1e-6
    interval = (impact.interval_end_ns - impact.interval_start_ns) * 1e-6
    return (
        f'impact at {format_stamp(impact.stamp_ns)} s: {contact_from_tip(impact) * 100:.1f} cm '
        f'from the tip ({impact.feature}), sweet-spot speed {impact.sweet_spot_speed_mps:.1f} m/s '
        f'({impact.sweet_spot_speed_mps * MPS_TO_MPH:.1f} mph), bat at contact '
        f'{impact.bat_speed_at_contact_mps:.1f} m/s '
        f'({impact.bat_speed_at_contact_mps * MPS_TO_MPH:.1f} mph), ball '
        f'{impact.ball_speed_mps:.1f} m/s ({impact.ball_speed_mps * MPS_TO_MPH:.1f} mph), '
        f'attack angle {impact.attack_angle_deg:+.1f} deg, closing speed '
        f'{impact.relative_normal_speed_mps:.1f} m/s, {into:.3f} ms into a {interval:.3f} ms '
        f'interval ({impact.model}); 1 sigma: time {impact.time_uncertainty_s * 1e6:.1f} us, '
        f'spot {impact.distance_from_knob_uncertainty_m * 100:.2f} cm, sweet-spot speed '
        f'{impact.sweet_spot_speed_uncertainty_mps:.2f} m/s')


def describe_near_miss(miss: NearMiss) -> str:
    """Return the one-line summary of a near miss (cm)."""
    gap = ' '.join(f'{x:+.3f}' for x in miss.gap_vector)
    return (f'near miss at {format_stamp(miss.stamp_ns)} s: the ball passed '
            f'{miss.gap_m * 100:.1f} cm from the bat, {miss.distance_from_tip_m * 100:.1f} cm '
            f'from the tip (gap vector {gap} m)')


def describe_listening(settings: Mapping[str, Any], topics: Mapping[str, str],
                       published: Sequence[str], plan_topic: Optional[str] = None) -> str:
    """
    Return the node's start-up line: what it reads, from where, and what it publishes.

    :param settings: the node's parameter values; ``topics``: each input stream's resolved
        topic; ``published``: every topic the node publishes (resolved); ``plan_topic``: the
        bat plan's resolved topic (None: not subscribed).
    """
    if settings['bat_input'] == 'pose':
        bat = f"bat PoseStamped on {topics['bat_pose']} (axis {settings['bat_axis']})"
    else:
        bat = f"bat knob and tip PointStamped on {topics['knob']} and {topics['tip']}"
    kind = 'PointStamped' if settings['ball_type'] == 'point' else 'PoseStamped'
    frame = repr(settings['frame_id']) if settings['frame_id'] else 'the first every input sends'
    plan = '' if plan_topic is None else f'; bat plans Path on {plan_topic}'
    return (f"listening: ball {kind} on {topics['ball']}, {bat}; qos {settings['qos']} "
            f"depth {settings['qos_depth']}; model {settings['model']}; frame {frame}{plan}; "
            f"publishing {', '.join(published)}")


_DROP_DETAILS = {
    'wrong_frame': 'frame {frame!r} is not the tracking frame {expected!r} (every input must '
                   'share one frame, no TF: publish this stream in it, or set frame_id)',
    'non_finite': 'NaN or infinite coordinates',
    'duplicate_stamp': 'stamp {stamp} s was already received',
    'out_of_order': 'stamp {stamp} s is older than the newest of its stream',
    'bad_quaternion': 'orientation is not a unit quaternion (its norm is off 1 by more than '
                      '0.001)',
    'zero_length_bat': 'knob and tip coincide',
    'bat_length_jump': 'knob-tip length jumped beyond bat_length_tolerance',
    'speed_limit': 'moved faster than max_speed since the previous sample',
    'unexpected_input': 'this input does not match bat_input',
    'bad_stamp': 'stamp {stamp} s is zero or negative (an unset header stamp)',
    'stale_stamp': 'stamp {stamp} s is more than time_jump_reset behind its stream and no '
                   "jump back followed (another publisher's clock, e.g. a replay left running)",
    'stamp_ahead': 'stamp {stamp} s was well ahead of its stream and the next sample came '
                   'before it (a lone glitch)',
    'bad_frame': 'frame {frame!r} has control characters or bytes that were not UTF-8',
    'lost_body': 'bat pose at the origin with the identity orientation (motion capture lost '
                 'the rigid body; drop_lost_body)',
    'ball_glitch': "stamp {stamp} s is off the ball's flight and the next sample came back to "
                   'it (one bad frame near the bat: left out of its path)',
    'bat_glitch': 'stamp {stamp} s is off the swing before it and off its neighbours (one bad '
                  'bat frame that made a contact: left out of its path)',
    'no_common_frame': "frame {frame!r} waited for a frame every input sends (frame_id ''), and "
                       'the inputs send none in common (no TF: set frame_id or transform one)',
}


def describe_drop(reason: str, frame: str, expected: Optional[str], stamp_ns: int) -> str:
    """
    Return why a sample was dropped, in words (``reason`` is a ``DROP_REASONS`` entry).

    Every reason has its own words (the log line names the reason before them).
    """
    return _DROP_DETAILS.get(reason, reason).format(
        frame=frame, expected=expected or '', stamp=format_stamp(stamp_ns))


# ----------------------------------------------------------------------------------------------
# events


@dataclass(frozen=True)
class EventOutput:
    """
    What one detector event becomes in the node.

    :ivar messages: ``(output name, message)`` pairs to publish, in order.
    :ivar log: the line to log ('' for none), at ``level`` (``'info'`` or ``'warning'``).
    :ivar throttled: log at most once per throttle period (a burst of the same kind).
    :ivar echoes_clock_jump: the line repeats a ROS clock jump's warning when one was just
        logged (a state reset by the stamps' own jump back): log it at debug level then.
    :ivar predicting: the new ``~/impact_predicted`` state (None: unchanged).
    :ivar impact_ns: the stamp of the impact it publishes (None: not an impact).
    """

    messages: Tuple[Tuple[str, Any], ...] = ()
    log: str = ''
    level: str = 'info'
    throttled: bool = False
    echoes_clock_jump: bool = False
    predicting: Optional[bool] = None
    impact_ns: Optional[int] = None


ImpactMarkers = Callable[[Impact, str], Optional[Union[MarkerArray, bytes]]]
"""Makes the markers of an impact in a frame (None: markers off): the array, or its CDR bytes
(``markers.scene_cdr``, as the node's are); a publisher sends either."""


def impact_velocity(impact: Impact, frame_id: str) -> TwistStamped:
    """Return an impact's ``~/impact_velocity``: the bat's surface and angular velocity."""
    velocity = TwistStamped(header=stamped_header(impact.stamp_ns, frame_id))
    velocity.twist.linear.x, velocity.twist.linear.y, velocity.twist.linear.z = \
        impact.bat_velocity
    velocity.twist.angular.x, velocity.twist.angular.y, velocity.twist.angular.z = \
        impact.bat_angular_velocity
    return velocity


def _impact(impact: Impact, frame_id: str, markers: ImpactMarkers) -> EventOutput:
    messages = [('impact', point_stamped(impact.stamp_ns, frame_id, impact.point)),
                ('impact_velocity', impact_velocity(impact, frame_id))]
    array = markers(impact, frame_id)
    if array is not None:
        messages.append(('markers', array))
    return EventOutput(messages=tuple(messages), log=describe_impact(impact),
                       impact_ns=impact.stamp_ns)


def _near_miss(miss: NearMiss, frame_id: str, markers: ImpactMarkers) -> EventOutput:
    message = Vector3Stamped(header=stamped_header(miss.stamp_ns, frame_id))
    message.vector.x, message.vector.y, message.vector.z = miss.gap_vector
    return EventOutput(messages=(('near_miss', message),), log=describe_near_miss(miss))


class StampedCdr:
    """
    A stamped message of ``float64`` fields after its header, as the CDR bytes it serialises to.

    ``count`` doubles: 3 for a ``geometry_msgs/PointStamped`` (or ``Vector3Stamped``), 6 for a
    ``TwistStamped`` (linear, then angular). What rclpy's ``Publisher.publish`` sends for bytes
    (``publish_raw``): the very bytes the message of ``point_stamped`` or ``impact_velocity``
    serialises to (the CDR padding aside, which no reader reads), packed with one ``struct``
    call. Publishing the message makes rclpy convert it into a C message and serialise that in
    the executor's callback: with an arm subscribed, a fifth to two fifths of the send's CPU time
    (BENCHMARKS.md, "sixth pass"). A subscriber receives the same message either way. The node
    publishes a prediction's ``~/predicted_impact`` (and makes no ``EventOutput`` for it), an
    impact's ``~/impact`` (the moment its contact is solved) and its ``~/impact_velocity`` as
    these bytes. The layout depends on the frame's name only: made once per frame.

    :param count: the doubles after the header.
    """

    __slots__ = ('_count', '_frame_id', '_layout', '_frame')

    def __init__(self, count: int) -> None:
        self._count = count
        self._frame_id: Optional[str] = None
        self._layout = struct.Struct('<')
        self._frame = b''

    def __call__(self, stamp_ns: int, frame_id: str, values: Sequence[float]) -> bytes:
        """
        Return ``values`` in ``frame_id`` stamped at ``stamp_ns`` (ns) as CDR bytes.

        Little-endian CDR (encapsulation ``CDR_LE``), as rmw_fastrtps serialises it: the stamp's
        ``int32`` seconds and ``uint32`` nanoseconds, the frame's length (with its NUL) and
        UTF-8 bytes, padding to 8 bytes, then the values as ``float64``.

        :raises struct.error: a stamp outside ``builtin_interfaces/Time``'s range, or not
            ``count`` values.
        """
        if frame_id != self._frame_id:
            frame = frame_id.encode() + b'\0'
            padding = -(12 + len(frame)) % 8  # the doubles align to 8 from the payload's start
            self._layout = struct.Struct(f'<4siII{len(frame)}s{padding}x{self._count}d')
            self._frame_id, self._frame = frame_id, frame
        sec, nanosec = divmod(stamp_ns, NS_PER_S)
        return self._layout.pack(CDR_LE, sec, nanosec, len(self._frame), self._frame, *values)


CDR_LE = bytes((0, 1, 0, 0))
"""The CDR encapsulation header of a little-endian plain CDR payload (``CDR_LE``)."""

FLAG_CDR = {value: CDR_LE + bytes((value, 0, 0, 0)) for value in (False, True)}
"""``~/impact_predicted``'s two ``std_msgs/Bool`` messages as CDR bytes (padded to 4 bytes, as
rmw_fastrtps serialises them): published as they are, no message made or converted."""


def _prediction(prediction: Prediction, frame_id: str, markers: ImpactMarkers) -> EventOutput:
    # as a message (the node publishes StampedCdr's bytes of the same message)
    return EventOutput(messages=(('predicted_impact', point_stamped(
        prediction.stamp_ns, frame_id, prediction.point)),), predicting=True)


def _prediction_cleared(event: PredictionCleared, frame_id: str,
                        markers: ImpactMarkers) -> EventOutput:
    return EventOutput(predicting=False)


def _stream_gap(gap: StreamGap, frame_id: str, markers: ImpactMarkers) -> EventOutput:
    return EventOutput(
        log=f'{gap.stream} stream gap of {(gap.end_ns - gap.start_ns) * 1e-6:.1f} ms '
            f'(> max_gap) from {format_stamp(gap.start_ns)} s: not interpolated',
        throttled=True)


RESET_CAUSES = {
    ResetReason.TIME_JUMP_BACKWARDS: 'header stamps jumped back to {stamp} s',
    ResetReason.TIME_JUMP_FORWARD: 'header stamps jumped ahead to {stamp} s (a new session)',
    ResetReason.FRAME_CHANGED: 'the inputs agreed on another frame than the first one seen '
                               '(at {stamp} s): what the samples in the first built was dropped',
}
"""The warning's cause for each reason the detector resets itself on (a stamp's ``{stamp}``);
another reason is named as it is."""


def _state_reset(reset: StateReset, frame_id: str, markers: ImpactMarkers) -> EventOutput:
    # only a jump of the stamps can echo the ROS clock's jump (logged by ``_on_clock_jump``)
    stamp = format_stamp(reset.stamp_ns)
    cause = RESET_CAUSES.get(reset.reason, f'{reset.reason} at {{stamp}} s').format(stamp=stamp)
    return EventOutput(
        log=f'{cause}: detector state reset', level='warning',
        echoes_clock_jump=reset.reason == ResetReason.TIME_JUMP_BACKWARDS, predicting=False)


_EVENT_OUTPUTS: Dict[Type[Any], Callable[[Any, str, ImpactMarkers], EventOutput]] = {
    Impact: _impact,
    NearMiss: _near_miss,
    Prediction: _prediction,
    PredictionCleared: _prediction_cleared,
    StreamGap: _stream_gap,
    StateReset: _state_reset,
}
"""The one dispatch table: event type -> what it becomes."""


def event_output(event: Event, frame_id: str, markers: ImpactMarkers,
                 config: Optional[DetectorConfig] = None) -> EventOutput:
    """
    Return what a detector event becomes: messages stamped with its instant, and a log line.

    An impact, near miss or prediction is also an ``impact_report`` (``std_msgs/String``):
    its ``core.records.event_record`` as one line of JSON, exactly what ``analyze --json``
    writes for it (without analyze's ``bag`` and ``time_s``).

    :param frame_id: the tracking frame, for the headers and the report.
    :param markers: makes an impact's markers (returns None when markers are off).
    :param config: the detector configuration that found the event (names the report's
        ``zone``); None: no report.
    :raises KeyError: an event type the table does not know.
    """
    output = _EVENT_OUTPUTS[type(event)](event, frame_id, markers)
    report = None if config is None else event_report(event, frame_id, config)
    if report is None:
        return output
    return EventOutput(  # not dataclasses.replace: it looks the fields up on every call
        messages=output.messages + (('impact_report', report),), log=output.log,
        level=output.level, throttled=output.throttled,
        echoes_clock_jump=output.echoes_clock_jump, predicting=output.predicting,
        impact_ns=output.impact_ns)


def event_report(event: Event, frame_id: str, config: DetectorConfig) -> Optional[String]:
    """
    Return an event's ``~/impact_report`` message: its record as one line of JSON, or None.

    An impact's, near miss's or prediction's ``core.records.event_record`` (``std_msgs/String``),
    exactly what ``analyze --json`` writes for it (without analyze's ``bag`` and ``time_s``);
    None for the other events, which have no record.

    :param frame_id: the tracking frame, for the record.
    :param config: the detector configuration that found the event (names the ``zone``).
    """
    if type(event) not in EVENT_NAMES:
        return None
    return String(data=record_text(event_record(event, frame_id, config)))
