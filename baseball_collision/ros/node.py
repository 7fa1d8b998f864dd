"""
The ROS 2 node ``impact_node``: a thin rclpy shell around ``detector.Detector``.

Subscriptions (``ball_topic``, and ``bat_pose_topic`` or ``knob_topic`` + ``tip_topic``) are
turned into ``Detector.add_*`` calls: the header stamp becomes integer nanoseconds
(``sec * 10**9 + nanosec``) and the header frame is passed through. The detector's events come
back out as messages:

* ``~/impact`` (geometry_msgs/PointStamped): stamped with the impact instant, the contact point.
* ``~/impact_velocity`` (geometry_msgs/TwistStamped): same stamp; bat surface velocity at the
  contact point (linear, m/s) and bat angular velocity (angular, rad/s).
* ``~/near_miss`` (geometry_msgs/Vector3Stamped): closest approach; gap vector from the bat
  surface to the ball surface (m).
* ``~/markers`` (visualization_msgs/MarkerArray): the bat profile, ball, contact point and normal
  at each impact, and the live bat and ball.
* ``/diagnostics`` (diagnostic_msgs/DiagnosticArray): rates, drops by reason, events,
  processing time and the state (waiting for data, tracking, stale).
* ``~/reset`` (std_srvs/Trigger): clears the detector state.

All detection logic lives in ``detector``; this module only converts, publishes and reports.
Parameters carry the ``DetectorConfig.from_parameters`` names; see ``config/impact_node.yaml``.
"""

from collections import Counter
from dataclasses import dataclass
import math
import re
import sys
import threading
import time
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple

from builtin_interfaces.msg import Duration as DurationMsg, Time as TimeMsg
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point, PointStamped, PoseStamped, TwistStamped, Vector3Stamped
from nav_msgs.msg import Path
from rcl_interfaces.msg import (
    FloatingPointRange, IntegerRange, ParameterDescriptor, SetParametersResult)
import rclpy
from rclpy.clock import Clock, ClockChange, ClockType, JumpThreshold, TimeJump
from rclpy.duration import Duration
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.exceptions import (
    InvalidParameterTypeException, InvalidParameterValueException, InvalidTopicNameException)
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.validate_topic_name import validate_topic_name
from std_msgs.msg import Bool, ColorRGBA, Header
from std_srvs.srv import Trigger
from visualization_msgs.msg import Marker, MarkerArray

from ..core.bat import WOOD_BAT_34
from ..core.detector import (
    Detector, DetectorConfig, DROP_REASONS, Event, Impact, MPS_TO_MPH, NearMiss, Prediction,
    PredictionCleared, StateReset, StreamGap)
from ..core.geometry import add, norm, scale, sub, Vector
from ..errors import CoreError, RosError

NODE_NAME = 'impact_node'
"""Default node name (the YAML files' top-level key)."""

NS_PER_S = 1_000_000_000
"""Nanoseconds per second."""

WARN_PERIOD_S = 2.0
"""Shortest time (s) between two warnings about the same kind of dropped sample."""

_DEFAULTS = DetectorConfig()
_DOUBLE = Parameter.Type.DOUBLE
_DOUBLE_ARRAY = Parameter.Type.DOUBLE_ARRAY
_INTEGER = Parameter.Type.INTEGER
_STRING = Parameter.Type.STRING
_BOOL = Parameter.Type.BOOL


# ----------------------------------------------------------------------------------------------
# Parameters


@dataclass(frozen=True)
class ParameterSpec:
    """
    One declared parameter: its name, default, type, range and whether it needs a restart.

    :ivar name: parameter name (a ``DetectorConfig.from_parameters`` key for detector values).
    :ivar default: default value; ``None`` for an unset double array (``bat_profile``).
    :ivar kind: the rclpy parameter type.
    :ivar description: what it is, with units.
    :ivar low, high: inclusive range of a numeric parameter (``None``: no range).
    :ivar choices: allowed strings (empty: any).
    :ivar restart: why a change needs a restart (non-empty: the parameter is read-only).
    """

    name: str
    default: Any
    kind: Parameter.Type
    description: str
    low: Optional[float] = None
    high: Optional[float] = None
    choices: Tuple[str, ...] = ()
    restart: str = ''

    def descriptor(self, lock: bool = True) -> ParameterDescriptor:
        """
        Return a new ParameterDescriptor for this parameter (rclpy mutates what it gets).

        :param lock: False: leave it writable even when the parameter needs a restart.
        """
        constraints = []
        if self.choices:
            constraints.append('one of: ' + ', '.join(self.choices))
        if self.restart:
            constraints.append(f'read-only: {self.restart}; restart the node to change it')
        descriptor = ParameterDescriptor(
            name=self.name, type=self.kind.value, description=self.description,
            additional_constraints='; '.join(constraints),
            read_only=lock and bool(self.restart))
        if self.low is not None and self.kind == _DOUBLE:
            descriptor.floating_point_range = [FloatingPointRange(
                from_value=float(self.low), to_value=float(self.high), step=0.0)]
        if self.low is not None and self.kind == _INTEGER:
            descriptor.integer_range = [IntegerRange(
                from_value=int(self.low), to_value=int(self.high), step=1)]
        return descriptor


_TOPIC = 'the subscriptions are created at start-up'
_GEOMETRY = 'the bat geometry shapes the detector buffers'
_SETUP = 'set once at start-up'

PARAMETERS: Tuple[ParameterSpec, ...] = (
    # inputs
    ParameterSpec('ball_topic', 'ball', _STRING, 'Topic of the ball centre (m).',
                  restart=_TOPIC),
    ParameterSpec('ball_type', 'point', _STRING,
                  "Message type on ball_topic: 'point' = geometry_msgs/PointStamped, "
                  "'pose' = geometry_msgs/PoseStamped (position used).",
                  choices=('point', 'pose'), restart=_TOPIC),
    ParameterSpec('bat_input', _DEFAULTS.bat_input, _STRING,
                  "How the bat arrives: 'pose' = PoseStamped on bat_pose_topic, 'points' = "
                  'PointStamped knob and tip on knob_topic and tip_topic.',
                  choices=('pose', 'points'), restart=_TOPIC),
    ParameterSpec('bat_pose_topic', 'bat_pose', _STRING,
                  'Topic of the bat pose (geometry_msgs/PoseStamped), bat_input pose.',
                  restart=_TOPIC),
    ParameterSpec('knob_topic', 'bat_knob', _STRING,
                  'Topic of the knob end (geometry_msgs/PointStamped, m), bat_input points.',
                  restart=_TOPIC),
    ParameterSpec('tip_topic', 'bat_tip', _STRING,
                  'Topic of the barrel end (geometry_msgs/PointStamped, m), bat_input points.',
                  restart=_TOPIC),
    ParameterSpec('bat_plan_topic', '', _STRING,
                  'Topic of a commanded bat trajectory (nav_msgs/Path of stamped bat poses, '
                  "as on bat_pose_topic) that predictions follow; '' = none.", restart=_TOPIC),
    ParameterSpec('frame_id', _DEFAULTS.frame_id, _STRING,
                  "Frame every input must be in; '' = the first frame seen. Other frames are "
                  'dropped (no tf2 here).', restart='the detector keeps its frame'),
    ParameterSpec('qos', 'sensor_data', _STRING,
                  "Subscription QoS: 'sensor_data' = best effort (matches any publisher), "
                  "'reliable' = reliable (only reliable publishers).",
                  choices=('sensor_data', 'reliable'), restart=_TOPIC),
    ParameterSpec('qos_depth', 100, _INTEGER,
                  'Subscription queue depth per input (messages); 100 holds 0.1 s at 1 kHz.',
                  low=1, high=10000, restart=_TOPIC),
    # bat geometry
    ParameterSpec('model', _DEFAULTS.model, _STRING,
                  'Motion between samples: linear (chords), rigid (translation + SLERP, live '
                  'default) or spline (cubic; waits one sample).',
                  choices=('linear', 'rigid', 'spline'), restart=_GEOMETRY),
    ParameterSpec('bat_axis', 'z', _STRING,
                  'Bat body axis from knob to tip in the pose frame (pose input).',
                  choices=('x', 'y', 'z', '-x', '-y', '-z'), restart=_GEOMETRY),
    ParameterSpec('knob_offset', 0.0, _DOUBLE,
                  'Knob end along bat_axis from the pose origin (m, pose input).',
                  low=-5.0, high=5.0, restart=_GEOMETRY),
    ParameterSpec('tip_offset', WOOD_BAT_34.length, _DOUBLE,
                  'Barrel end along bat_axis from the pose origin (m, pose input); '
                  'knob_offset + the bat length.', low=-5.0, high=5.0, restart=_GEOMETRY),
    ParameterSpec('bat_profile', None, _DOUBLE_ARRAY,
                  'Bat radius profile, flat [distance_from_knob, radius, ...] (m); unset or '
                  'empty = the default 34-inch wood bat.', restart=_GEOMETRY),
    ParameterSpec('bat_length', 0.0, _DOUBLE,
                  'Knob-to-tip length the profile was measured on (m); 0 = the last station '
                  '(or 0.8636 m for the default bat).', low=0.0, high=3.0, restart=_GEOMETRY),
    ParameterSpec('bat_radius', 0.0, _DOUBLE,
                  'Constant bat radius (m); > 0 replaces the profile by a capsule.',
                  low=0.0, high=0.5, restart=_GEOMETRY),
    # thresholds (changeable at runtime)
    ParameterSpec('ball_radius', _DEFAULTS.ball_radius, _DOUBLE,
                  'Ball radius (m); a baseball is 0.0366.', low=0.0, high=0.5),
    ParameterSpec('max_gap', _DEFAULTS.max_gap, _DOUBLE,
                  'Longest time between two samples of a stream that is interpolated (s).',
                  low=0.0, high=10.0),
    ParameterSpec('max_chord_error', _DEFAULTS.max_chord_error, _DOUBLE,
                  'Largest distance a curved path may leave the chords solved (m).',
                  low=0.0, high=0.1),
    ParameterSpec('rearm_distance', _DEFAULTS.rearm_distance, _DOUBLE,
                  'Gap the ball must clear after an impact before another (m).',
                  low=0.0, high=5.0),
    ParameterSpec('near_miss_threshold', _DEFAULTS.near_miss_threshold, _DOUBLE,
                  'A pass closer than this without contact is a near miss (m).',
                  low=0.0, high=5.0),
    ParameterSpec('max_speed', _DEFAULTS.max_speed, _DOUBLE,
                  'Fastest plausible speed of a tracked point between samples (m/s).',
                  low=0.0, high=1000.0),
    ParameterSpec('bat_length_tolerance', _DEFAULTS.bat_length_tolerance, _DOUBLE,
                  'Knob-tip length change beyond which a bat sample is a jump (m, points).',
                  low=0.0, high=1.0),
    ParameterSpec('time_jump_reset', _DEFAULTS.time_jump_reset, _DOUBLE,
                  'A stamp (or the ROS clock) this far behind the newest resets the state (s).',
                  low=0.0, high=86400.0),
    ParameterSpec('up_axis', list(_DEFAULTS.up_axis), _DOUBLE_ARRAY,
                  'Up direction [x, y, z] in the tracking frame, for the attack angle.'),
    ParameterSpec('sweet_spot_from_tip', _DEFAULTS.sweet_spot_from_tip, _DOUBLE,
                  "Distance from the barrel end of the point whose speed is the 'bat speed' "
                  '(m; Statcast: 6 in = 0.1524).', low=0.0, high=3.0),
    ParameterSpec('velocity_window', _DEFAULTS.velocity_window, _DOUBLE,
                  'Span of the samples before an impact its velocities are fitted to (s).',
                  low=0.001, high=1.0),
    ParameterSpec('velocity_degree', _DEFAULTS.velocity_degree, _INTEGER,
                  "Degree of the bat's velocity fit (1-6); lower it for a noisy low-rate "
                  'tracker (3 at 90 Hz with 1 mm noise).', low=1, high=6),
    ParameterSpec('prediction_horizon', _DEFAULTS.prediction_horizon, _DOUBLE,
                  'How far ahead to predict the coming impact after every processed frame '
                  '(s); 0 = no ~/predicted_impact.', low=0.0, high=2.0),
    ParameterSpec('prediction_window', _DEFAULTS.prediction_window, _DOUBLE,
                  "Span of the latest ball samples the prediction's ballistic fit uses (s).",
                  low=0.001, high=1.0),
    ParameterSpec('ball_drag', _DEFAULTS.ball_drag, _DOUBLE,
                  'Ball drag rho Cd A / (2 m) for predictions (1/m); 0.0061 for a baseball.',
                  low=0.0, high=1.0),
    ParameterSpec('gravity', _DEFAULTS.gravity, _DOUBLE,
                  'Gravity along -up_axis for predictions (m/s^2).', low=0.0, high=100.0),
    # the node's own
    ParameterSpec('diagnostics_period', 1.0, _DOUBLE, 'Period of /diagnostics (s).',
                  low=0.05, high=3600.0, restart=_SETUP),
    ParameterSpec('stale_timeout', 1.0, _DOUBLE,
                  'An input topic silent longer than this is stale: diagnostics WARN (s).',
                  low=0.01, high=86400.0),
    ParameterSpec('publish_markers', True, _BOOL, 'Publish ~/markers for RViz / Foxglove.'),
    ParameterSpec('marker_rate', 20.0, _DOUBLE,
                  'Rate of the live bat and ball markers (Hz); 0 = markers at impacts only.',
                  low=0.0, high=1000.0, restart=_SETUP),
    ParameterSpec('marker_lifetime', 5.0, _DOUBLE,
                  'How long impact markers stay visible (s); 0 = until replaced.',
                  low=0.0, high=3600.0),
)
"""Every parameter of the node, in the order of ``config/impact_node.yaml``."""

SPECS: Dict[str, ParameterSpec] = {spec.name: spec for spec in PARAMETERS}
"""The parameters by name."""


@dataclass(frozen=True)
class Settings:
    """
    The node's validated parameters.

    :ivar values: every parameter value by name (``bat_profile`` as a list, maybe empty).
    :ivar detector: the detector configuration built from them.
    """

    values: Mapping[str, Any]
    detector: DetectorConfig

    @classmethod
    def from_values(cls, values: Mapping[str, Any]) -> 'Settings':
        """
        Validate parameter values and build the detector configuration.

        :param values: parameter values by name (``None`` for an unset array).
        :returns: the settings.
        :raises RosError: a value the node cannot run with, naming the parameter.
        """
        values = dict(values)
        values['bat_profile'] = list(values.get('bat_profile') or [])
        for spec in PARAMETERS:
            value = values.get(spec.name)
            if spec.choices and value not in spec.choices:
                raise RosError(
                    f"parameter '{spec.name}' must be one of {', '.join(spec.choices)}, "
                    f'got {value!r}')
            if spec.name.endswith('_topic') and (value or spec.name != 'bat_plan_topic'):
                try:
                    validate_topic_name(value)
                except InvalidTopicNameException as error:
                    first = str(error).splitlines()[0].rstrip(':')
                    raise RosError(
                        f"parameter '{spec.name}' = {value!r}: {first}") from error
        topics = [values['ball_topic']] + (
            [values['bat_pose_topic']] if values['bat_input'] == 'pose'
            else [values['knob_topic'], values['tip_topic']])
        if len(set(topics)) != len(topics):
            raise RosError(f'the input topics must differ, got {", ".join(topics)}')
        try:
            detector = DetectorConfig.from_parameters(values)
        except CoreError as error:
            raise RosError(str(error)) from error
        return cls(values=values, detector=detector)

    def __getitem__(self, name: str) -> Any:
        """Return the value of a parameter by name."""
        return self.values[name]


def _as_double(spec: ParameterSpec, value: Any) -> Any:
    """
    Convert an integer (or integer array) given for a double (array) parameter.

    :raises RosError: the value is not a number (or a list of numbers).
    """
    def number(x: Any) -> float:
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise RosError(
                f"parameter '{spec.name}' must be a number ({spec.description}), "
                f'got {value!r}')
        return float(x)

    if spec.kind == _DOUBLE_ARRAY:
        if not isinstance(value, (list, tuple)) and not hasattr(value, 'tolist'):
            raise RosError(
                f"parameter '{spec.name}' must be a list of numbers, got {value!r}")
        return [number(x) for x in list(value)]
    return number(value)


_RCLPY_VALUE = re.compile(r'value: (?P<value>.*?)\)?(: \w+)?$', re.S)
_RCLPY_TYPE = re.compile(r"to '(?P<value>.*)' of type '(?P<type>\w+)'", re.S)


def _range_message(spec: ParameterSpec, error: Exception) -> str:
    """Return a one-line message for a value refused by the descriptor's range."""
    match = _RCLPY_VALUE.search(str(error))
    given = f"{match.group('value')} " if match else ''
    return (f"parameter '{spec.name}' = {given}is out of range [{spec.low}, {spec.high}] "
            f'({spec.description})')


def _type_message(spec: ParameterSpec, error: Exception) -> str:
    """Return a one-line message for a value of the wrong type."""
    match = _RCLPY_TYPE.search(str(error))
    given = f", got {match.group('value')!r} ({match.group('type').lower()})" if match else ''
    kind = {_INTEGER: 'an integer', _STRING: 'a string', _BOOL: 'a boolean'}.get(
        spec.kind, spec.kind.name.lower())
    return f"parameter '{spec.name}' must be {kind} ({spec.description}){given}"


# ----------------------------------------------------------------------------------------------
# Conversions


def stamp_to_ns(stamp: TimeMsg) -> int:
    """Return a header stamp as integer nanoseconds (``sec * 10**9 + nanosec``)."""
    return stamp.sec * NS_PER_S + stamp.nanosec


def ns_to_stamp(stamp_ns: int) -> TimeMsg:
    """Return integer nanoseconds as a ``builtin_interfaces/Time``."""
    return TimeMsg(sec=stamp_ns // NS_PER_S, nanosec=stamp_ns % NS_PER_S)


def format_stamp(stamp_ns: int) -> str:
    """Return integer nanoseconds as ``seconds.nanoseconds`` text."""
    return f'{stamp_ns // NS_PER_S}.{stamp_ns % NS_PER_S:09d}'


def describe_impact(impact: Impact) -> str:
    """Return the one-line, human-readable summary of an impact (m, cm, m/s, mph, ms)."""
    into = (impact.stamp_ns - impact.interval_start_ns) * 1e-6
    interval = (impact.interval_end_ns - impact.interval_start_ns) * 1e-6
    return (
        f'impact at {format_stamp(impact.stamp_ns)} s: {impact.distance_from_tip_m * 100:.1f} cm '
        f'from the tip ({impact.feature}), sweet-spot speed {impact.sweet_spot_speed_mps:.1f} m/s '
        f'({impact.sweet_spot_speed_mps * MPS_TO_MPH:.1f} mph), bat at contact '
        f'{impact.bat_speed_at_contact_mps:.1f} m/s '
        f'({impact.bat_speed_at_contact_mps * MPS_TO_MPH:.1f} mph), ball '
        f'{impact.ball_speed_mps:.1f} m/s ({impact.ball_speed_mps * MPS_TO_MPH:.1f} mph), '
        f'attack angle {impact.attack_angle_deg:+.1f} deg, closing speed '
        f'{impact.relative_normal_speed_mps:.1f} m/s, {into:.3f} ms into a {interval:.3f} ms '
        f'interval ({impact.model})')


def describe_near_miss(miss: NearMiss) -> str:
    """Return the one-line summary of a near miss (cm)."""
    gap = ' '.join(f'{x:+.3f}' for x in miss.gap_vector)
    return (f'near miss at {format_stamp(miss.stamp_ns)} s: the ball passed '
            f'{miss.gap_m * 100:.1f} cm from the bat, {miss.distance_from_tip_m * 100:.1f} cm '
            f'from the tip (gap vector {gap} m)')


_DROP_DETAILS = {
    'wrong_frame': 'frame {frame!r} is not the tracking frame {expected!r}',
    'non_finite': 'NaN or infinite coordinates',
    'duplicate_stamp': 'stamp {stamp} s was already received',
    'out_of_order': 'stamp {stamp} s is older than the newest of its stream',
    'bad_quaternion': 'orientation is not a unit quaternion',
    'zero_length_bat': 'knob and tip coincide',
    'bat_length_jump': 'knob-tip length jumped beyond bat_length_tolerance',
    'speed_limit': 'moved faster than max_speed since the previous sample',
    'unexpected_input': 'this input does not match bat_input',
}


# ----------------------------------------------------------------------------------------------
# Markers


def _color(r: float, g: float, b: float, a: float = 1.0) -> ColorRGBA:
    """Return an RGBA colour (components 0-1)."""
    return ColorRGBA(r=r, g=g, b=b, a=a)


_BAT_COLOR = _color(0.72, 0.52, 0.30, 0.9)
_BALL_COLOR = _color(0.95, 0.95, 0.95, 0.9)
_CONTACT_COLOR = _color(0.9, 0.1, 0.1)
_NORMAL_COLOR = _color(1.0, 0.85, 0.1)


def _point(v: Vector) -> Point:
    """Return a vector (m) as a geometry_msgs/Point."""
    return Point(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def _z_to(direction: Vector) -> Tuple[float, float, float, float]:
    """Return the quaternion (x, y, z, w) turning +z onto a unit direction."""
    x, y, z = direction
    if z < -1.0 + 1e-9:
        return (1.0, 0.0, 0.0, 0.0)
    q = (-y, x, 0.0, 1.0 + z)
    length = math.sqrt(sum(c * c for c in q))
    return tuple(c / length for c in q)


def bat_markers(header: Header, namespace: str, knob: Vector, tip: Vector,
                segments: Sequence[Tuple[float, float, float]],
                lifetime: DurationMsg) -> List[Marker]:
    """
    Return the bat as one cylinder (or sphere) per profile segment.

    :param knob, tip: bat ends (m).
    :param segments: ``BatProfile.segments()``: (fraction_start, fraction_end, radius m).
    """
    axis = sub(tip, knob)
    length = norm(axis)
    direction = scale(axis, 1.0 / length) if length > 0.0 else (0.0, 0.0, 1.0)
    x, y, z, w = _z_to(direction)
    markers = []
    for index, (f0, f1, radius) in enumerate(segments):
        marker = Marker(header=header, ns=namespace, id=index, action=Marker.ADD,
                        color=_BAT_COLOR, lifetime=lifetime)
        centre = add(knob, scale(axis, 0.5 * (f0 + f1)))
        marker.pose.position = _point(centre)
        marker.pose.orientation.x, marker.pose.orientation.y = x, y
        marker.pose.orientation.z, marker.pose.orientation.w = z, w
        piece = (f1 - f0) * length
        if piece > 0.0:
            marker.type = Marker.CYLINDER
            marker.scale.x = marker.scale.y = 2.0 * radius
            marker.scale.z = piece
        else:
            marker.type = Marker.SPHERE
            marker.scale.x = marker.scale.y = marker.scale.z = 2.0 * radius
        markers.append(marker)
    return markers


def sphere_marker(header: Header, namespace: str, centre: Vector, diameter: float,
                  color: ColorRGBA, lifetime: DurationMsg) -> Marker:
    """Return a sphere marker (centre and diameter in m)."""
    marker = Marker(header=header, ns=namespace, id=0, type=Marker.SPHERE, action=Marker.ADD,
                    color=color, lifetime=lifetime)
    marker.pose.position = _point(centre)
    marker.pose.orientation.w = 1.0
    marker.scale.x = marker.scale.y = marker.scale.z = diameter
    return marker


def impact_markers(impact: Impact, frame_id: str, config: DetectorConfig,
                   lifetime_s: float) -> MarkerArray:
    """
    Return the markers of an impact: bat, ball, contact point, normal arrow and a label.

    :param lifetime_s: how long they stay (s; 0 = until replaced).
    """
    header = Header(stamp=ns_to_stamp(impact.stamp_ns), frame_id=frame_id)
    lifetime = Duration(nanoseconds=int(lifetime_s * NS_PER_S)).to_msg()
    markers = bat_markers(header, 'impact_bat', impact.knob, impact.tip,
                          config.profile.segments(), lifetime)
    markers.append(sphere_marker(header, 'impact_ball', impact.ball_position,
                                 2.0 * config.ball_radius, _BALL_COLOR, lifetime))
    markers.append(sphere_marker(header, 'impact_contact', impact.point, 0.015,
                                 _CONTACT_COLOR, lifetime))
    arrow = Marker(header=header, ns='impact_normal', id=0, type=Marker.ARROW,
                   action=Marker.ADD, color=_NORMAL_COLOR, lifetime=lifetime)
    arrow.pose.orientation.w = 1.0
    arrow.points = [_point(impact.point), _point(add(impact.point, scale(impact.normal, 0.15)))]
    arrow.scale.x, arrow.scale.y, arrow.scale.z = 0.008, 0.016, 0.03
    markers.append(arrow)
    label = Marker(header=header, ns='impact_label', id=0, type=Marker.TEXT_VIEW_FACING,
                   action=Marker.ADD, color=_BALL_COLOR, lifetime=lifetime)
    label.pose.position = _point(add(impact.point, (0.0, 0.0, 0.15)))
    label.pose.orientation.w = 1.0
    label.scale.z = 0.05
    label.text = (f'{impact.sweet_spot_speed_mps * MPS_TO_MPH:.1f} mph, '
                  f'{impact.distance_from_tip_m * 100:.0f} cm from tip')
    markers.append(label)
    return MarkerArray(markers=markers)


# ----------------------------------------------------------------------------------------------
# The node


class ImpactNode(Node):
    """
    Subscribe to the tracked ball and bat, publish impacts, near misses and diagnostics.

    :param node_name: the node's name.
    :param kwargs: passed to ``rclpy.node.Node`` (``context``, ``parameter_overrides`` ...).
    :raises RosError: a parameter value the node cannot run with (the node is
        destroyed before raising).
    """

    def __init__(self, node_name: str = NODE_NAME, **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        try:
            self._setup()
        except RosError:
            self.destroy_node()
            raise

    # ---- set-up --------------------------------------------------------------------------

    def _setup(self) -> None:
        """Declare the parameters, build the detector, create the I/O (see the class)."""
        self._lock = threading.Lock()
        self._pending: Optional[Settings] = None
        self._jump_handle = None
        self.settings = Settings.from_values(self._declare_parameters())
        self.detector = Detector(self.settings.detector)
        self._warn_unknown_overrides()
        self._check_bat_length()

        self._streams = ('ball', 'bat_pose') if self.settings['bat_input'] == 'pose' \
            else ('ball', 'knob', 'tip')
        self._arrivals: Counter = Counter()
        self._last_arrival: Dict[str, float] = {}
        self._last_values: Dict[str, Any] = {}
        self._drop_warned: Dict[str, Tuple[float, int]] = {}
        self._incompatible = 0
        self._incompatible_reported = 0
        self._clock_jump_at = -math.inf
        self._last_impact_ns: Optional[int] = None
        self._predicting = False
        self._started = time.monotonic()
        self._period = _Period(time.monotonic(), Counter(), 0)

        self._create_publishers()
        self._predicting_pub.publish(Bool(data=False))  # latched: late joiners get the state
        self._create_subscriptions()
        self.create_service(Trigger, '~/reset', self._on_reset)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(self.settings['diagnostics_period'], self._publish_diagnostics,
                          clock=steady)
        if self.settings['marker_rate'] > 0.0:
            self.create_timer(1.0 / self.settings['marker_rate'], self._publish_live_markers,
                              clock=steady)
        self._register_clock_jump()
        self.add_pre_set_parameters_callback(self._pre_set_parameters)
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.add_post_set_parameters_callback(self._post_set_parameters)
        self.get_logger().info(self._summary())

    def _declare_parameters(self) -> Dict[str, Any]:
        """
        Declare every parameter; return their values.

        :raises RosError: a value of the wrong type or out of range.
        """
        values = {}
        for spec in PARAMETERS:
            values[spec.name] = self._declare(spec)
        return values

    def _declare(self, spec: ParameterSpec) -> Any:
        """
        Declare one parameter and return its value.

        Two cases go through a second step that applies the final (typed, maybe read-only)
        descriptor with ``set_descriptor``: an integer where a double is declared (YAML
        ``max_gap: 1``: declared loosely, then converted), and an array without a default
        (rclpy cannot declare an empty array by value: it is declared by type, then set to
        ``[]``, so that ``get_parameters`` answers for it).

        :raises RosError: a value of the wrong type or out of range.
        """
        try:
            if spec.default is not None:
                return self.declare_parameter(spec.name, spec.default, spec.descriptor()).value
            given = self.declare_parameter(spec.name, spec.kind, spec.descriptor(lock=False)).value
        except InvalidParameterValueException as error:
            raise RosError(_range_message(spec, error)) from error
        except InvalidParameterTypeException as error:
            if spec.kind not in (_DOUBLE, _DOUBLE_ARRAY):
                raise RosError(_type_message(spec, error)) from error
            loose = ParameterDescriptor(description=spec.description, dynamic_typing=True)
            given = self.declare_parameter(spec.name, spec.default, loose).value
        if given is None:
            given = []
            self.set_parameters([Parameter(spec.name, spec.kind, given)])
        value = _as_double(spec, given)
        try:
            self.set_descriptor(spec.name, spec.descriptor(),
                                Parameter(spec.name, spec.kind, value).get_parameter_value())
        except InvalidParameterValueException as error:
            raise RosError(_range_message(spec, error)) from error
        return value

    def _warn_unknown_overrides(self) -> None:
        """Warn about overrides (params file, ``-p``) that name no parameter (typos)."""
        # rclpy has no public accessor for the overrides given on the command line / params file
        overrides = getattr(self, '_parameter_overrides', {}) or {}
        unknown = sorted(name for name in overrides if not self.has_parameter(name)
                         and not name.startswith('qos_overrides.'))
        if unknown:
            self.get_logger().warning(
                f"ignoring unknown parameter(s) {', '.join(unknown)}: not parameters of "
                f'{self.get_name()} (see config/impact_node.yaml)')

    def _check_bat_length(self) -> None:
        """Warn when the pose offsets and the bat profile disagree on the bat length."""
        config = self.settings.detector
        if config.bat_input != 'pose':
            return
        length = math.dist(config.geometry.knob_offset, config.geometry.tip_offset)
        if abs(length - config.profile.length) > 0.01:
            self.get_logger().warning(
                f'tip_offset - knob_offset = {length:.4f} m but the bat profile is '
                f'{config.profile.length:.4f} m long: the profile is stretched to knob-tip')

    def _subscription_qos(self) -> QoSProfile:
        """Return the input QoS: ``qos`` (best effort or reliable), ``qos_depth``, volatile."""
        reliable = self.settings['qos'] == 'reliable'
        return QoSProfile(
            history=HistoryPolicy.KEEP_LAST, depth=self.settings['qos_depth'],
            reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
            durability=DurabilityPolicy.VOLATILE)

    def _create_publishers(self) -> None:
        """Create the event, marker and diagnostics publishers (reliable, volatile)."""
        events = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                            reliability=ReliabilityPolicy.RELIABLE,
                            durability=DurabilityPolicy.VOLATILE)
        markers = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                             reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.VOLATILE)

        def create(msg_type: Any, topic: str, qos: QoSProfile) -> Any:
            name = [topic]  # resolved once the publisher exists
            callbacks = PublisherEventCallbacks(
                incompatible_qos=lambda info: self._on_incompatible_qos(
                    name[0], 'publisher', info))
            publisher = self.create_publisher(msg_type, topic, qos, event_callbacks=callbacks)
            name[0] = publisher.topic_name
            return publisher

        latched = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                             reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self._predicted_pub = create(PointStamped, '~/predicted_impact', events)
        self._predicting_pub = create(Bool, '~/impact_predicted', latched)
        self._impact_pub = create(PointStamped, '~/impact', events)
        self._velocity_pub = create(TwistStamped, '~/impact_velocity', events)
        self._near_miss_pub = create(Vector3Stamped, '~/near_miss', events)
        self._marker_pub = create(MarkerArray, '~/markers', markers)
        self._diagnostics_pub = create(DiagnosticArray, '/diagnostics', markers)

    def _create_subscriptions(self) -> None:
        """
        Subscribe to the ball and the bat topics of ``ball_type`` and ``bat_input``.

        :raises RosError: a topic name that fails once expanded.
        """
        qos = self._subscription_qos()
        settings = self.settings
        self._topics: Dict[str, str] = {}
        self._types: Dict[str, str] = {}
        self._type_warned: set = set()
        detector = self.detector

        def subscribe(stream: str, msg_type: Any, topic: str, callback: Callable) -> None:
            callbacks = SubscriptionEventCallbacks(
                incompatible_qos=lambda info: self._on_incompatible_qos(
                    self._topics.get(stream, topic), 'subscription', info),
                incompatible_type=lambda info: self._on_incompatible_type(stream))
            try:
                subscription = self.create_subscription(msg_type, topic, callback, qos,
                                                        event_callbacks=callbacks)
            except InvalidTopicNameException as error:  # fails only once expanded: 'a//b'
                first = str(error).splitlines()[0].rstrip(':')
                raise RosError(f'{stream} topic {topic!r}: {first}') from error
            self._topics[stream] = subscription.topic_name
            self._types[stream] = _type_name(msg_type)

        if settings['ball_type'] == 'point':
            subscribe('ball', PointStamped, settings['ball_topic'], lambda msg: self._sample(
                'ball', msg.header, detector.add_ball, _xyz(msg.point)))
        else:
            subscribe('ball', PoseStamped, settings['ball_topic'], lambda msg: self._sample(
                'ball', msg.header, detector.add_ball, _xyz(msg.pose.position)))
        if settings['bat_input'] == 'pose':
            subscribe('bat_pose', PoseStamped, settings['bat_pose_topic'],
                      lambda msg: self._sample('bat_pose', msg.header, detector.add_bat_pose,
                                               _xyz(msg.pose.position),
                                               _xyzw(msg.pose.orientation)))
        else:
            subscribe('knob', PointStamped, settings['knob_topic'], lambda msg: self._sample(
                'knob', msg.header, detector.add_knob, _xyz(msg.point)))
            subscribe('tip', PointStamped, settings['tip_topic'], lambda msg: self._sample(
                'tip', msg.header, detector.add_tip, _xyz(msg.point)))
        if settings['bat_plan_topic']:
            plans = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                               reliability=ReliabilityPolicy.RELIABLE,
                               durability=DurabilityPolicy.VOLATILE)
            self._plan_sub = self.create_subscription(Path, settings['bat_plan_topic'],
                                                      self._on_plan, plans)

    def _on_plan(self, message: Path) -> None:
        """Take a commanded bat trajectory (stamped poses) for the predictions; empty clears."""
        frames = {message.header.frame_id} | {p.header.frame_id for p in message.poses}
        frames.discard('')
        with self._lock:
            expected = self.detector.frame_id
            if expected is not None and frames - {expected}:
                reason = f'frame {sorted(frames)} is not the tracking frame {expected!r}'
            else:
                try:
                    self.detector.set_bat_plan(
                        [p.header.stamp.sec * NS_PER_S + p.header.stamp.nanosec
                         for p in message.poses],
                        [_xyz(p.pose.position) for p in message.poses],
                        [_xyzw(p.pose.orientation) for p in message.poses])
                    return
                except CoreError as error:
                    reason = str(error)
        self.get_logger().warning(f'ignored a bat plan on {self._plan_sub.topic_name}: {reason}',
                                  throttle_duration_sec=WARN_PERIOD_S)

    def _register_clock_jump(self) -> None:
        """(Re)register the ROS clock jump callback at ``time_jump_reset`` backwards."""
        if self._jump_handle is not None:
            self._jump_handle.unregister()
        backwards = max(1, int(self.settings['time_jump_reset'] * NS_PER_S))
        self._jump_handle = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=None, min_backward=Duration(nanoseconds=-backwards),
                          on_clock_change=True),
            post_callback=self._on_clock_jump)

    def _summary(self) -> str:
        """Return the start-up line: what is read, from where, and what is published."""
        s = self.settings
        if s['bat_input'] == 'pose':
            bat = f"bat PoseStamped on {self._topics['bat_pose']} (axis {s['bat_axis']})"
        else:
            bat = (f"bat knob and tip PointStamped on {self._topics['knob']} and "
                   f"{self._topics['tip']}")
        kind = 'PointStamped' if s['ball_type'] == 'point' else 'PoseStamped'
        frame = repr(s['frame_id']) if s['frame_id'] else 'the first frame seen'
        return (f"listening: ball {kind} on {self._topics['ball']}, {bat}; qos {s['qos']} "
                f"depth {s['qos_depth']}; model {s['model']}; frame {frame}; publishing "
                f'{self._impact_pub.topic_name}, {self._velocity_pub.topic_name}, '
                f'{self._near_miss_pub.topic_name}, {self._marker_pub.topic_name}')

    def destroy_node(self) -> None:
        """Unregister the clock jump callback, then destroy the node."""
        handle = getattr(self, '_jump_handle', None)
        if handle is not None:
            handle.unregister()
            self._jump_handle = None
        super().destroy_node()

    # ---- samples -------------------------------------------------------------------------

    def _sample(self, stream: str, header: Header, add_sample: Callable[..., List[Event]],
                *values: Any) -> None:
        """Feed one message to the detector, publish what it decided, count and time it."""
        start = time.perf_counter()
        stamp = header.stamp.sec * NS_PER_S + header.stamp.nanosec
        frame = header.frame_id
        with self._lock:
            self._arrivals[stream] += 1
            self._last_arrival[stream] = time.monotonic()
            events = add_sample(stamp, *values, frame)
            dropped = self.detector.stats.last_drop_reason
            expected = self.detector.frame_id
            if dropped is None:
                self._last_values[stream] = values
            if events:
                self._publish_events(events, frame or expected or '')
        if dropped is not None:
            self._warn_drops(stream, dropped, frame, expected, stamp)
        self._record_processing(time.perf_counter() - start)

    def _record_processing(self, elapsed_s: float) -> None:
        """Account the wall time (s) one message took in its callback."""
        period = self._period
        period.count += 1
        period.total_s += elapsed_s
        if elapsed_s > period.max_s:
            period.max_s = elapsed_s

    def _warn_drops(self, stream: str, reason: str, frame: str, expected: Optional[str],
                    stamp: int) -> None:
        """Warn about a dropped sample, at most once per reason every ``WARN_PERIOD_S``."""
        now = time.monotonic()
        last, suppressed = self._drop_warned.get(reason, (-math.inf, 0))
        if now - last < WARN_PERIOD_S:
            self._drop_warned[reason] = (last, suppressed + 1)
            return
        self._drop_warned[reason] = (now, 0)
        detail = _DROP_DETAILS.get(reason, reason).format(
            frame=frame, expected=expected or '', stamp=format_stamp(stamp))
        more = f' (and {suppressed} more of this kind since the last warning)' \
            if suppressed else ''
        self.get_logger().warning(
            f'dropped a {stream} sample on {self._topics[stream]}: {reason}: {detail}; '
            f'{self.detector.stats.dropped[reason]} dropped for this reason so far{more}')

    # ---- events --------------------------------------------------------------------------

    def _publish_events(self, events: List[Event], frame: str) -> None:
        """Publish or log each detector event; ``frame`` is the tracking frame."""
        for event in events:
            if isinstance(event, Impact):
                self._publish_impact(event, frame)
            elif isinstance(event, NearMiss):
                self._publish_near_miss(event, frame)
            elif isinstance(event, Prediction):
                if not self._predicting:
                    self._predicting = True
                    self._predicting_pub.publish(Bool(data=True))
                self._predicted_pub.publish(PointStamped(
                    header=Header(stamp=ns_to_stamp(event.stamp_ns), frame_id=frame),
                    point=_point(event.point)))
            elif isinstance(event, PredictionCleared):
                self._predicting = False
                self._predicting_pub.publish(Bool(data=False))
            elif isinstance(event, StreamGap):
                self.get_logger().info(
                    f'{event.stream} stream gap of {(event.end_ns - event.start_ns) * 1e-6:.1f}'
                    f' ms (> max_gap) from {format_stamp(event.start_ns)} s: not interpolated',
                    throttle_duration_sec=WARN_PERIOD_S)
            elif isinstance(event, StateReset):
                self._clear_prediction()
                message = (f'header stamps jumped back to {format_stamp(event.stamp_ns)} s: '
                           'detector state reset')
                if time.monotonic() - self._clock_jump_at < 2.0:
                    self.get_logger().debug(message)  # the clock jump already warned
                else:
                    self.get_logger().warning(message)

    def _publish_impact(self, impact: Impact, frame: str) -> None:
        """Publish ~/impact, ~/impact_velocity (impact stamp), the markers; log one line."""
        header = Header(stamp=ns_to_stamp(impact.stamp_ns), frame_id=frame)
        self._impact_pub.publish(PointStamped(header=header, point=_point(impact.point)))
        velocity = TwistStamped(header=header)
        velocity.twist.linear.x, velocity.twist.linear.y, velocity.twist.linear.z = \
            impact.bat_velocity
        velocity.twist.angular.x, velocity.twist.angular.y, velocity.twist.angular.z = \
            impact.bat_angular_velocity
        self._velocity_pub.publish(velocity)
        self._last_impact_ns = impact.stamp_ns
        if self.settings['publish_markers']:
            self._marker_pub.publish(impact_markers(
                impact, frame, self.detector.config, self.settings['marker_lifetime']))
        self.get_logger().info(describe_impact(impact))

    def _publish_near_miss(self, miss: NearMiss, frame: str) -> None:
        """Publish ~/near_miss (closest-approach stamp, gap vector) and log one line."""
        message = Vector3Stamped(header=Header(stamp=ns_to_stamp(miss.stamp_ns), frame_id=frame))
        message.vector.x, message.vector.y, message.vector.z = miss.gap_vector
        self._near_miss_pub.publish(message)
        self.get_logger().info(describe_near_miss(miss))

    def _publish_live_markers(self) -> None:
        """Publish the last accepted bat and ball as markers (timer, steady clock)."""
        if not self.settings['publish_markers']:
            return
        with self._lock:
            values = dict(self._last_values)
            frame = self.detector.frame_id or ''
            config = self.detector.config
        ball = values.get('ball')
        ends = None
        if 'bat_pose' in values:
            try:
                knob, tip = config.geometry.knob_and_tip(*values['bat_pose'])
                ends = tuple(knob.tolist()), tuple(tip.tolist())
            except CoreError:
                ends = None
        elif 'knob' in values and 'tip' in values:
            ends = values['knob'][0], values['tip'][0]
        if ball is None and ends is None:
            return
        header = Header(stamp=self.get_clock().now().to_msg(), frame_id=frame)
        lifetime = Duration(nanoseconds=int(2.0 / self.settings['marker_rate'] * NS_PER_S))
        markers = []
        if ends is not None and math.dist(*ends) > 0.0:
            markers += bat_markers(header, 'live_bat', ends[0], ends[1],
                                   config.profile.segments(), lifetime.to_msg())
        if ball is not None:
            markers.append(sphere_marker(header, 'live_ball', ball[0], 2.0 * config.ball_radius,
                                         _BALL_COLOR, lifetime.to_msg()))
        self._marker_pub.publish(MarkerArray(markers=markers))

    # ---- services and clock --------------------------------------------------------------

    def _clear_prediction(self) -> None:
        """Say ~/impact_predicted false if a prediction was standing (the state was dropped)."""
        if self._predicting:
            self._predicting = False
            self._predicting_pub.publish(Bool(data=False))

    def _on_reset(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        """Serve ~/reset: clear the detector state (counters are kept); always succeeds."""
        with self._lock:
            event = self.detector.reset(self.detector.stats.newest_stamp_ns or 0, 'requested')
            self._last_values.clear()
            self._clear_prediction()
            resets = self.detector.stats.resets
        response.success = True
        response.message = (f'detector state cleared at {format_stamp(event.stamp_ns)} s '
                            f'(buffers, armed state, open near miss; counters kept; '
                            f'{resets} resets so far)')
        self.get_logger().info(f'reset requested: {response.message}')
        return response

    def _on_clock_jump(self, jump: TimeJump) -> None:
        """Reset the detector, with one warning, when the ROS clock jumps back."""
        if jump.clock_change in (ClockChange.ROS_TIME_ACTIVATED, ClockChange.ROS_TIME_DEACTIVATED):
            active = jump.clock_change == ClockChange.ROS_TIME_ACTIVATED
            self.get_logger().info(f"ROS time {'activated' if active else 'deactivated'}")
            return
        if jump.delta.nanoseconds >= 0:
            return
        with self._lock:
            self.detector.reset(self.detector.stats.newest_stamp_ns or 0, 'time_jump_backwards')
            self._last_values.clear()
            self._clear_prediction()
        self._clock_jump_at = time.monotonic()
        self.get_logger().warning(
            f'the ROS clock jumped back by {-jump.delta.nanoseconds * 1e-9:.3f} s (replay '
            'restarted?): detector state reset')

    def _on_incompatible_qos(self, topic: str, role: str, info: Any) -> None:
        """Warn that an endpoint on ``topic`` has QoS incompatible with ours, naming the policy."""
        self._incompatible += 1
        policy = getattr(info.last_policy_kind, 'name', str(info.last_policy_kind))
        policy = policy.replace('RMW_QOS_POLICY_', '')
        hint = ''
        if role == 'subscription' and 'RELIABILITY' in policy:
            hint = ("; this node subscribes 'reliable': publish reliable or set "
                    'qos:=sensor_data')
        elif role == 'subscription' and 'DURABILITY' in policy:
            hint = '; the publisher offers volatile durability, this node asks for more'
        self.get_logger().warning(
            f'incompatible QoS on {topic} ({role} side): policy {policy}; '
            f'{info.total_count} incompatible endpoint(s), no messages flow{hint}')

    def _on_incompatible_type(self, stream: str, others: Sequence[str] = ()) -> None:
        """Warn (once per stream and type) that a publisher has another type than expected."""
        key = (stream, tuple(others))
        if key in self._type_warned:
            return
        self._type_warned.add(key)
        self._incompatible += 1
        hint = " (set ball_type to 'point' or 'pose')" if stream == 'ball' else ''
        other = f" ({', '.join(others)})" if others else ''
        self.get_logger().warning(
            f'a publisher on {self._topics[stream]} has another type{other} than '
            f'{self._types[stream]}: no messages flow{hint}')

    def _publisher_problem(self, stream: str) -> str:
        """Return why a silent input may be silent: no publisher, or one of another type."""
        infos = self.get_publishers_info_by_topic(self._topics[stream])
        if not infos:
            return 'no publisher'
        others = sorted({info.topic_type for info in infos} - {self._types[stream]})
        if others:
            self._on_incompatible_type(stream, others)
            return f"publisher of {', '.join(others)}, expected {self._types[stream]}"
        return ''

    # ---- parameters at runtime -----------------------------------------------------------

    def _pre_set_parameters(self, parameters: List[Parameter]) -> List[Parameter]:
        """Convert integers given for double parameters (``max_gap:=1``); log read-only tries."""
        converted = []
        for parameter in parameters:
            spec = SPECS.get(parameter.name)
            if spec is not None and spec.kind in (_DOUBLE, _DOUBLE_ARRAY) and \
                    parameter.type_ in (_INTEGER, Parameter.Type.INTEGER_ARRAY):
                try:
                    parameter = Parameter(parameter.name, spec.kind,
                                          _as_double(spec, parameter.value))
                except RosError:
                    pass  # the type check refuses it with its own reason
            if spec is not None and spec.restart:
                self.get_logger().warning(
                    f"refusing to set '{parameter.name}' at runtime: {spec.restart}; restart "
                    'the node with the new value')
            converted.append(parameter)
        return converted

    def _on_set_parameters(self, parameters: List[Parameter]) -> SetParametersResult:
        """Validate a runtime change; threshold changes are kept for the post-set callback."""
        values = dict(self.settings.values)
        for parameter in parameters:
            if parameter.name in SPECS:
                values[parameter.name] = parameter.value
        try:
            settings = Settings.from_values(values)
        except RosError as error:
            return SetParametersResult(successful=False, reason=str(error))
        changed = [name for name in Detector.RESTART_FIELDS
                   if getattr(settings.detector, name) != getattr(self.detector.config, name)]
        if changed:
            return SetParametersResult(
                successful=False,
                reason=f"{', '.join(changed)} cannot change while running: restart the node")
        self._pending = settings
        return SetParametersResult(successful=True)

    def _post_set_parameters(self, parameters: List[Parameter]) -> None:
        """Apply the change the on-set callback validated: reconfigure the detector."""
        settings, self._pending = self._pending, None
        if settings is None:
            return
        with self._lock:
            self.detector.reconfigure(settings.detector)
            previous, self.settings = self.settings, settings
        if settings['time_jump_reset'] != previous['time_jump_reset']:
            self._register_clock_jump()
        changes = ', '.join(f'{p.name}={p.value!r}' for p in parameters if p.name in SPECS)
        if changes:
            self.get_logger().info(f'parameters changed: {changes}')

    def set_parameters(self, parameter_list: List[Parameter]) -> List[SetParametersResult]:
        """
        Set parameters (see ``rclpy.node.Node.set_parameters``), explaining read-only refusals.

        :returns: one result per parameter.
        """
        results = super().set_parameters(parameter_list)
        return [_explain(result, [parameter])
                for result, parameter in zip(results, parameter_list)]

    def set_parameters_atomically(self, parameter_list: List[Parameter]) -> SetParametersResult:
        """
        Set parameters all at once, explaining read-only refusals.

        :returns: the aggregate result.
        """
        return _explain(super().set_parameters_atomically(parameter_list), parameter_list)

    # ---- diagnostics ---------------------------------------------------------------------

    def diagnostics(self) -> DiagnosticStatus:
        """
        Return the detector's status over the period since the previous call.

        Keys: ``state``, ``stale_topics``, per stream ``<stream>_topic``, ``<stream>_rate_hz``,
        ``<stream>_received``; ``dropped_<reason>`` for every reason in ``DROP_REASONS``,
        ``dropped_total``, ``dropped_in_period``; ``impacts``, ``near_misses``, ``gaps``,
        ``resets``; ``messages_in_period``, ``processing_mean_ms``, ``processing_max_ms``
        (whole callback, over the period); ``detector_mean_ms``, ``detector_max_ms`` (since
        start); ``watermark_stamp``, ``last_impact_stamp``, ``frame_id``, ``model``,
        ``bat_input``, ``qos``, ``incompatible_qos_events``.
        """
        now = time.monotonic()
        with self._lock:
            stats = self.detector.stats
            dropped = dict(stats.dropped)
            counts = {'impacts': stats.impacts, 'near_misses': stats.near_misses,
                      'gaps': stats.gaps, 'resets': stats.resets}
            detector_mean, detector_max = stats.mean_processing_s, stats.max_processing_s
            watermark = self.detector.watermark_ns
            arrivals = Counter(self._arrivals)
            last_arrival = dict(self._last_arrival)
            frame = self.detector.frame_id or ''
            period, self._period = self._period, _Period(now, arrivals, sum(dropped.values()))
        elapsed = max(now - period.start, 1e-9)
        timeout = self.settings['stale_timeout']
        stale, waiting = [], []
        for stream in self._streams:
            last = last_arrival.get(stream)
            silent = last is None or now - last > timeout
            why = self._publisher_problem(stream) if silent else ''
            why = f', {why}' if why else ''
            if last is None:
                if now - self._started > timeout:
                    stale.append(f'{self._topics[stream]} (no data since start{why})')
                else:
                    waiting.append(f'{self._topics[stream]}{why}')
            elif now - last > timeout:
                stale.append(f'{self._topics[stream]} (silent for {now - last:.1f} s{why})')
        state = 'stale' if stale else 'waiting for data' if waiting else 'tracking'
        dropped_total = sum(dropped.values())
        dropped_now = dropped_total - period.dropped
        received_now = sum(arrivals.values()) - sum(period.arrivals.values())

        level, problems = DiagnosticStatus.OK, []
        if stale:
            level = DiagnosticStatus.WARN
            problems.append('stale: ' + ', '.join(stale))
        if dropped_now:
            level = DiagnosticStatus.WARN
            problems.append(f'dropped {dropped_now} of {received_now} samples')
            if dropped_now >= received_now:
                level = DiagnosticStatus.ERROR
                problems[-1] = f'every sample was dropped ({dropped_now})'
        if self._incompatible != self._incompatible_reported:
            level = max(level, DiagnosticStatus.WARN)
            problems.append('incompatible QoS or type on a topic (see the log)')
            self._incompatible_reported = self._incompatible
        if state == 'waiting for data':
            message = 'waiting for data on ' + ', '.join(waiting)
        else:
            message = state
        if problems:
            message = '; '.join(problems) if stale else f"{message}; {'; '.join(problems)}"

        values = [('state', state), ('stale_topics', ', '.join(stale))]
        for stream in self._streams:
            rate = (arrivals[stream] - period.arrivals[stream]) / elapsed
            values += [(f'{stream}_topic', self._topics[stream]),
                       (f'{stream}_rate_hz', f'{rate:.1f}'),
                       (f'{stream}_received', str(arrivals[stream]))]
        values += [(f'dropped_{reason}', str(dropped.get(reason, 0))) for reason in DROP_REASONS]
        values += [('dropped_total', str(dropped_total)), ('dropped_in_period', str(dropped_now))]
        values += [(name, str(count)) for name, count in counts.items()]
        mean = period.total_s / period.count if period.count else 0.0
        values += [
            ('messages_in_period', str(period.count)),
            ('processing_mean_ms', f'{mean * 1e3:.4f}'),
            ('processing_max_ms', f'{period.max_s * 1e3:.4f}'),
            ('detector_mean_ms', f'{detector_mean * 1e3:.4f}'),
            ('detector_max_ms', f'{detector_max * 1e3:.4f}'),
            ('watermark_stamp', '' if watermark is None else format_stamp(watermark)),
            ('last_impact_stamp', '' if self._last_impact_ns is None
             else format_stamp(self._last_impact_ns)),
            ('frame_id', frame), ('model', self.settings['model']),
            ('bat_input', self.settings['bat_input']), ('qos', self.settings['qos']),
            ('incompatible_qos_events', str(self._incompatible))]
        return DiagnosticStatus(
            level=level, name=f'{self.get_name()}: impact detector', message=message,
            hardware_id='baseball_collision',
            values=[KeyValue(key=key, value=value) for key, value in values])

    def _publish_diagnostics(self) -> None:
        """Publish the status on /diagnostics (timer, steady clock)."""
        array = DiagnosticArray(status=[self.diagnostics()])
        array.header.stamp = self.get_clock().now().to_msg()
        self._diagnostics_pub.publish(array)


@dataclass
class _Period:
    """Counters at the start of a diagnostics period, and the processing times inside it."""

    start: float
    arrivals: Counter
    dropped: int
    count: int = 0
    total_s: float = 0.0
    max_s: float = 0.0


def _type_name(msg_type: Any) -> str:
    """Return a message class's ROS name, e.g. ``geometry_msgs/msg/PointStamped``."""
    return f"{msg_type.__module__.split('.')[0]}/msg/{msg_type.__name__}"


def _xyz(v: Any) -> Tuple[float, float, float]:
    """Return the x, y, z fields of a Point or Vector3 message."""
    return (v.x, v.y, v.z)


def _xyzw(q: Any) -> Tuple[float, float, float, float]:
    """Return a Quaternion message as (x, y, z, w)."""
    return (q.x, q.y, q.z, q.w)


def _explain(result: SetParametersResult, parameters: List[Parameter]) -> SetParametersResult:
    """Replace rclpy's read-only refusal by one that says why and what to do."""
    if result.successful or not result.reason.startswith('Trying to set a read-only'):
        return result
    for parameter in parameters:
        spec = SPECS.get(parameter.name)
        if spec is not None and spec.restart:
            result.reason = (f"parameter '{spec.name}' is read-only: {spec.restart}; restart "
                             'the node with the new value')
            break
    return result


# ----------------------------------------------------------------------------------------------
# Entry point


def main(args: Optional[List[str]] = None) -> int:
    """
    Run the node until Ctrl-C or shutdown.

    :param args: command line (``--ros-args ...``); ``None``: ``sys.argv``.
    :returns: the exit code: 0 after a clean shutdown, 1 for a bad configuration, 2 when rcl
        refuses the command line (e.g. an unreadable params file).
    """
    logger = rclpy.logging.get_logger(NODE_NAME)
    try:
        rclpy.init(args=args)
    except RuntimeError as error:  # rclpy's RCLError: e.g. an unreadable params file
        text = ' '.join(str(error).split())
        logger.error(f'cannot start: {text}')
        return 2
    node = None
    try:
        node = ImpactNode()
        rclpy.spin(node)
    except RosError as error:
        logger.error(f'invalid configuration, not starting: {error}')
        return 1
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
