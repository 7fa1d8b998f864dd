"""
The one parameter table of ``impact_node`` and the detector, its checks, and DetectorConfig.

Pure Python: no rclpy, no rosbags. Every parameter is defined once, in :data:`PARAMETERS`:
name, type, default, range, unit, choices, whether it may change at runtime, and what it is.
The node declares its parameters from it (``ros.parameters``), ``analyze --params`` and
:meth:`DetectorConfig.from_parameters` check values with :func:`validate_parameters` (the
node's rules exactly), :class:`DetectorConfig` takes its defaults and checks from it, and the
tests hold ``config/impact_node.yaml`` and the README's table to it.
"""

from dataclasses import dataclass, field, fields, replace
import difflib
from enum import Enum
from functools import lru_cache
import math
import re
from typing import Any, Dict, Iterable, List, Mapping, Optional, Tuple

from ..bat import BatProfile, MAX_STATIONS, PoseBatGeometry, SWEET_SPOT_FROM_TIP, WOOD_BAT_34
from ..geometry import Vector
from ..motion import MODELS
from ...errors import CoreError

NODE_NAME = 'impact_node'
"""Default name of the live node: the YAML files' top-level key; its outputs are ``~/...``."""


class Kind(str, Enum):
    """A parameter's type, named as ROS 2 names parameter types."""

    BOOL = 'bool'
    INTEGER = 'integer'
    DOUBLE = 'double'
    STRING = 'string'
    DOUBLE_ARRAY = 'double_array'


@dataclass(frozen=True)
class Range:
    """
    The values a number may take: ``[low, high]``, a bound left out when it is open.

    :ivar low, high: the bounds (in the parameter's unit).
    :ivar low_open, high_open: True: that bound itself is refused (``(0, 10]``: > 0 and <= 10).
    """

    low: float
    high: float
    low_open: bool = False
    high_open: bool = False

    def __contains__(self, value: float) -> bool:
        """Return whether ``value`` lies in the range (NaN never does)."""
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above and below

    def __str__(self) -> str:
        """Return the range in interval notation, e.g. ``(0.0, 10.0]``."""
        return (f"{'(' if self.low_open else '['}{self.low}, {self.high}"
                f"{')' if self.high_open else ']'}")


_KIND_PHRASES = {Kind.BOOL: 'a boolean', Kind.INTEGER: 'an integer', Kind.DOUBLE: 'a number',
                 Kind.STRING: 'a string', Kind.DOUBLE_ARRAY: 'a list of numbers'}


@dataclass(frozen=True)
class ParameterSpec:
    """
    One parameter: everything the node, the offline tools and the docs need to know.

    :ivar name: the ROS parameter name (a :class:`DetectorConfig` field, a bat description
        key, or the node's own).
    :ivar kind: its type.
    :ivar default: its default (a tuple for an array).
    :ivar doc: what it is, with its unit.
    :ivar unit: SI unit ('' for none).
    :ivar bounds: the values a number may take (None for a bool, a string or an array).
    :ivar choices: the strings it may take (empty: any).
    :ivar read_only: why it cannot change while the node runs ('' : it can).
    :ivar max_items: most values an array may hold (None: any number).
    """

    name: str
    kind: Kind
    default: Any
    doc: str
    unit: str = ''
    bounds: Optional[Range] = None
    choices: Tuple[str, ...] = ()
    read_only: str = ''
    max_items: Optional[int] = None

    def __post_init__(self) -> None:
        """Check the entry itself once: a known kind and a default it accepts."""
        object.__setattr__(self, 'kind', Kind(self.kind))
        self.check(self.default)

    def check(self, value: Any) -> Any:
        """
        Return ``value`` as this parameter's type, or refuse it as the node does.

        An integer is accepted (and converted) for a double, integers for a double array; a
        bool is not a number.

        :returns: the value (float for a double, a list of floats for an array).
        :raises CoreError: wrong type, out of range or not one of the choices: one line
            naming the parameter.
        """
        kind = self.kind
        if kind == Kind.DOUBLE_ARRAY:
            if value is None:
                items = []  # unset: rclpy's NOT_SET for an array declared by type
            else:
                items = value.tolist() if hasattr(value, 'tolist') else value  # array.array
            if not isinstance(items, (list, tuple)):
                raise self._wrong_type(value)
            if self.max_items is not None and len(items) > self.max_items:
                raise CoreError(f"parameter '{self.name}' has {len(items):,} values, at most "
                                f'{self.max_items} are taken ({self.doc})')
            if not all(_is_number(x) for x in items):
                raise self._wrong_type(value)
            return [float(x) for x in items]
        if kind == Kind.DOUBLE and _is_number(value):
            value = float(value)
        elif not _is_a(kind, value):
            raise self._wrong_type(value)
        if self.bounds is not None and value not in self.bounds:
            raise CoreError(f"parameter '{self.name}' = {value!r} is out of range {self.bounds} "
                            f'({self.doc})')
        if self.choices and value not in self.choices:
            raise CoreError(f"parameter '{self.name}' must be one of {', '.join(self.choices)}, "
                            f'got {value!r}')
        return value

    def _wrong_type(self, value: Any) -> CoreError:
        """Return the refusal of a value of the wrong type."""
        return CoreError(f"parameter '{self.name}' must be {_KIND_PHRASES[self.kind]} "
                         f'({self.doc}), got {value!r} of type {_type_name(value)}')


def _is_a(kind: Kind, value: Any) -> bool:
    """Return whether ``value`` is exactly of a scalar kind (an int is no double here)."""
    if kind == Kind.BOOL:
        return isinstance(value, bool)
    if kind == Kind.INTEGER:
        return isinstance(value, int) and not isinstance(value, bool)
    return isinstance(value, {Kind.DOUBLE: float, Kind.STRING: str}[kind])


def _is_number(value: Any) -> bool:
    """Return whether ``value`` is an int or a float (a bool is not a number)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _type_name(value: Any) -> str:
    """Return the ROS name of a value's type (``double``, ``integer``, ``string`` ...)."""
    for python, name in ((bool, 'bool'), (int, 'integer'), (float, 'double'), (str, 'string'),
                         (type(None), 'not set')):
        if isinstance(value, python):
            return name
    return 'array' if isinstance(value, (list, tuple)) else type(value).__name__


_TOPIC = 'the subscriptions are created at start-up'
_GEOMETRY = 'the bat geometry shapes the detector buffers'
_SETUP = 'set once at start-up'
_MODEL = 'the motion model shapes the paths and the samples the streams keep'
_D, _I, _S, _B, _A = Kind.DOUBLE, Kind.INTEGER, Kind.STRING, Kind.BOOL, Kind.DOUBLE_ARRAY


def _closed(low: float, high: float) -> Range:
    return Range(low, high)


def _positive(high: float) -> Range:
    return Range(0.0, high, low_open=True)


PARAMETERS: Tuple[ParameterSpec, ...] = (
    # ---- inputs (read-only)
    ParameterSpec(
        'ball_topic', _S, 'ball', 'Topic of the ball centre (m).', read_only=_TOPIC),
    ParameterSpec(
        'ball_type', _S, 'point', "Message type on ball_topic: 'point' = geometry_msgs/"
        "PointStamped, 'pose' = geometry_msgs/PoseStamped (position used).",
        choices=('point', 'pose'), read_only=_TOPIC),
    ParameterSpec(
        'bat_input', _S, 'pose', "How the bat arrives: 'pose' = PoseStamped on bat_pose_topic, "
        "'points' = PointStamped knob and tip on knob_topic and tip_topic.",
        choices=('pose', 'points'), read_only=_TOPIC),
    ParameterSpec(
        'bat_pose_topic', _S, 'bat_pose',
        'Topic of the bat pose (geometry_msgs/PoseStamped), bat_input pose.', read_only=_TOPIC),
    ParameterSpec(
        'knob_topic', _S, 'bat_knob',
        'Topic of the knob end (geometry_msgs/PointStamped, m), bat_input points.',
        read_only=_TOPIC),
    ParameterSpec(
        'tip_topic', _S, 'bat_tip',
        'Topic of the barrel end (geometry_msgs/PointStamped, m), bat_input points.',
        read_only=_TOPIC),
    ParameterSpec(
        'bat_plan_topic', _S, '', 'Topic of a commanded bat trajectory (nav_msgs/Path of stamped '
        "bat poses, as on bat_pose_topic) that predictions follow; '' = none.", read_only=_TOPIC),
    ParameterSpec(
        'frame_id', _S, '', "Frame every input must be in; '' = the first frame every input "
        'stream has sent (the first frame seen is taken until then). Other frames are dropped '
        '(no tf2 here).', read_only='the detector keeps its frame'),
    ParameterSpec(
        'qos', _S, 'sensor_data', "Subscription QoS: 'sensor_data' = best effort (matches any "
        "publisher), 'reliable' = reliable (only reliable publishers) keeping the newest "
        "qos_depth unread, 'reliable_all' = reliable keeping every message until taken (a "
        'replay: nothing lost however far behind the node falls; memory grows meanwhile).',
        choices=('sensor_data', 'reliable', 'reliable_all'), read_only=_TOPIC),
    ParameterSpec(
        'qos_depth', _I, 100, 'Subscription queue depth per input (messages); 100 holds 0.1 s '
        "at 1 kHz ('reliable_all' keeps every message).", 'messages', _closed(1, 10000),
        read_only=_TOPIC),
    # ---- motion model and bat geometry (read-only)
    ParameterSpec(
        'model', _S, 'c2', 'Motion between samples: linear (chords), rigid (translation + '
        'SLERP), spline (cubic; waits one sample) or c2 (the default: windowed not-a-knot '
        'spline of knob, direction and length; waits look_ahead samples).', choices=MODELS,
        read_only=_MODEL),
    ParameterSpec(
        'look_ahead', _I, 0, 'c2: samples after an interval its fit may use (0-2), each one '
        'more frame of latency; 0 keeps the frames after a contact out of its fit; exact samples '
        'are fitted by the quintic spline (6th order; at 0 the bat only).', 'samples',
        _closed(0, 2), read_only=_MODEL),
    ParameterSpec(
        'spline_window', _I, 8, 'c2: samples in the spline fitted for an interval (4-32), the '
        'newest its closing frame plus look_ahead; every model: in the quintic spline behind '
        'impact velocities from exact samples at a high rate.', 'samples', _closed(4, 32),
        read_only=_MODEL),
    ParameterSpec(
        'bat_axis', _S, 'z', 'Bat body axis from knob to tip in the pose frame (pose input).',
        choices=('x', 'y', 'z', '-x', '-y', '-z'), read_only=_GEOMETRY),
    ParameterSpec(
        'knob_offset', _D, 0.0, 'Knob end along bat_axis from the pose origin (m, pose input).',
        'm', _closed(-5.0, 5.0), read_only=_GEOMETRY),
    ParameterSpec(
        'tip_offset', _D, WOOD_BAT_34.length, 'Barrel end along bat_axis from the pose origin '
        '(m, pose input); knob_offset + the bat length.', 'm', _closed(-5.0, 5.0),
        read_only=_GEOMETRY),
    ParameterSpec(
        'bat_profile', _A, (), 'Bat radius profile, flat [distance_from_knob, radius, ...] (m), '
        f'at most {MAX_STATIONS} stations, the radius tapering linearly between them; unset or '
        'empty = the default 34-inch wood bat.', 'm',
        read_only=_GEOMETRY, max_items=2 * MAX_STATIONS),
    ParameterSpec(
        'bat_length', _D, 0.0, 'Knob-to-tip length the profile was measured on (m); 0 = the '
        'last station (or 0.8636 m for the default bat).', 'm', _closed(0.0, 3.0),
        read_only=_GEOMETRY),
    ParameterSpec(
        'bat_radius', _D, 0.0, 'Constant bat radius (m); > 0 replaces the profile by a capsule.',
        'm', _closed(0.0, 0.5), read_only=_GEOMETRY),
    # ---- thresholds (changeable at runtime)
    ParameterSpec(
        'ball_radius', _D, 0.0366, 'Ball radius (m); a baseball is 0.0366.', 'm',
        _positive(0.5)),
    ParameterSpec(
        'max_gap', _D, 0.05, 'Longest time between two samples of a stream that is '
        'interpolated (s).', 's', _positive(10.0)),
    ParameterSpec(
        'max_chord_error', _D, 0.0005, 'Largest distance a curved path may leave the chords '
        'solved (m).', 'm', _positive(0.1)),
    ParameterSpec(
        'rearm_distance', _D, 0.1, 'Gap the ball must clear after an impact before another (m).',
        'm', _closed(0.0, 5.0)),
    ParameterSpec(
        'near_miss_threshold', _D, 0.15, 'A pass closer than this without contact is a near '
        'miss (m).', 'm', _closed(0.0, 5.0)),
    ParameterSpec(
        'max_speed', _D, 150.0, 'Fastest plausible speed of a tracked point between samples '
        '(m/s).', 'm/s', _positive(100000.0)),
    ParameterSpec(
        'bat_length_tolerance', _D, 0.05, 'Knob-tip length change beyond which a bat sample is '
        'a jump (m, points).', 'm', _positive(1.0)),
    ParameterSpec(
        'time_jump_reset', _D, 1.0, 'A stamp (or the ROS clock) this far behind the newest '
        'resets the state (s).', 's', _positive(86400.0)),
    ParameterSpec(
        'drop_lost_body', _B, True, 'Drop bat poses exactly at the origin with the identity '
        'orientation (what motion capture publishes for a lost rigid body) as lost_body.'),
    ParameterSpec(
        'rest_tolerance', _D, 0.01, 'An impact whose bat knob and tip stayed within this of '
        'where they were at the impact over velocity_window is flagged bat_at_rest, not a '
        'swing (m); 0 = never flagged.', 'm', _closed(0.0, 1.0)),
    ParameterSpec(
        'up_axis', _A, (0.0, 0.0, 1.0), 'Up direction [x, y, z] in the tracking frame, for the '
        'attack angle.'),
    ParameterSpec(
        'sweet_spot_from_tip', _D, SWEET_SPOT_FROM_TIP, 'Distance from the barrel end of the '
        "point whose speed is the 'bat speed' (m; Statcast: 6 in = 0.1524).", 'm',
        _closed(0.0, 3.0)),
    ParameterSpec(
        'velocity_window', _D, 0.061, 'Span of the samples before an impact its velocities are '
        'fitted to (s).', 's', _closed(0.001, 1.0)),
    ParameterSpec(
        'tracker_noise', _D, -1.0, 'Tracking noise, 1 sigma per coordinate (m); 0 = exact '
        'samples (interpolated); > 0: c2 smooths its windows with it; negative (-1, the '
        'default) = auto: estimated per stream from its samples (exact ones read as 0).', 'm',
        _closed(-1.0, 0.1)),
    ParameterSpec(
        'velocity_degree', _I, 5, "Degree of the bat's velocity fit (1-6); lower it for a noisy "
        'low-rate tracker (3 at 90 Hz with 1 mm noise).', '', _closed(1, 6)),
    ParameterSpec(
        'prediction_horizon', _D, 0.3, 'How far ahead to predict the coming impact after every '
        'processed frame (s); 0 = no ~/predicted_impact (a DetectorConfig made in code predicts '
        'only when given one).', 's', _closed(0.0, 2.0)),
    ParameterSpec(
        'prediction_period', _D, 0.01, "Predict at most this often (s, by the frames' stamps): "
        'a frame less than this after the last prediction keeps it; 0 = every processed frame '
        '(a DetectorConfig made in code: every frame).', 's', _closed(0.0, 1.0)),
    ParameterSpec(
        'prediction_window', _D, 0.1, "Span of the latest ball samples the prediction's "
        'ballistic fit uses (s).', 's', _closed(0.001, 1.0)),
    ParameterSpec(
        'lift_window', _D, 0.25, 'Span of the latest ball samples whose flight gives the lift '
        "(the spin's Magnus force) a prediction's ball carries beside gravity and drag (s); 0 = "
        'none (a ball without spin).', 's', _closed(0.0, 1.0)),
    ParameterSpec(
        'ball_drag', _D, 0.0061, 'Ball drag rho Cd A / (2 m) for predictions (1/m); 0.0061 for '
        'a baseball.', '1/m', _closed(0.0, 1.0)),
    ParameterSpec(
        'gravity', _D, 9.80665, 'Gravity along -up_axis for predictions (m/s^2).', 'm/s^2',
        _closed(0.0, 100.0)),
    # ---- the node's own
    ParameterSpec(
        'diagnostics_period', _D, 1.0, 'Period of /diagnostics (s).', 's',
        _closed(0.05, 3600.0), read_only=_SETUP),
    ParameterSpec(
        'stale_timeout', _D, 1.0, 'An input topic silent longer than this is stale: '
        'diagnostics WARN (s).', 's', _closed(0.01, 86400.0)),
    ParameterSpec(
        'idle_timeout', _D, 30.0, 'Every input silent longer than this after data came: the '
        'session ended, diagnostics say idle at OK instead of stale at WARN (s); 0 = never.',
        's', _closed(0.0, 86400.0)),
    ParameterSpec(
        'hardware_id', _S, '', "The diagnostics' hardware_id (the tracking rig this node "
        "watches); '' = the node's fully qualified name.", read_only=_SETUP),
    ParameterSpec(
        'publish_markers', _B, True, 'Publish ~/markers for RViz / Foxglove.'),
    ParameterSpec(
        'marker_rate', _D, 20.0, 'Rate of the live bat and ball markers (Hz); 0 = markers at '
        'impacts only.', 'Hz', _closed(0.0, 1000.0), read_only=_SETUP),
    ParameterSpec(
        'marker_lifetime', _D, 5.0, 'How long impact markers stay visible (s); 0 = until '
        'replaced.', 's', _closed(0.0, 3600.0)),
)
"""Every parameter, in the order of ``config/impact_node.yaml``."""

AUTO_NOISE = -1.0
"""``tracker_noise`` for auto (any negative value means it): each stream's noise estimated."""

SPECS: Dict[str, ParameterSpec] = {spec.name: spec for spec in PARAMETERS}
"""The parameters by name."""

DEFAULTS: Dict[str, Any] = {spec.name: spec.default for spec in PARAMETERS}
"""Every parameter's default by name (arrays as tuples)."""


ROS_OWN_PARAMETERS = ('use_sim_time', 'start_type_description_service')
"""Parameters every rclpy node declares itself (and ``qos_overrides.`` names: its QoS)."""


def section_applies(key: str, node_fqn: str) -> bool:
    """
    Return whether a params file's section ``key`` applies to the node ``node_fqn``, as rcl's.

    A key without a leading ``/`` is taken from the root; ``*`` stands for one name token and
    ``**`` for any number of them (none included): ``/**``, ``impact_node``,
    ``/**/impact_node`` and ``/impact_node/**`` apply to ``/impact_node``, ``/*`` only in the
    root namespace, ``/cage2/*`` to the nodes of ``/cage2``. The one matching of the node's
    start-up warning (``ros.parameters.params_file_warnings``) and ``analyze --params``
    (``tools.parameters.load_parameters``), held to rcl's by test
    (test/ros/test_parameters.py).
    """
    pattern = ''
    for token in (key if key.startswith('/') else '/' + key).split('/')[1:]:
        pattern += {'**': '(?:/[^/]+)*', '*': '/[^/]+'}.get(token, '/' + re.escape(token))
    return re.fullmatch(pattern, node_fqn) is not None


def node_fqn(node_name: str) -> str:
    """Return a node's fully qualified name: ``impact_node`` -> ``/impact_node``."""
    return '/' + node_name.strip('/')


def unknown_parameters(names: Iterable[str], node_name: str = NODE_NAME) -> Optional[str]:
    """
    Return a warning naming the parameters among ``names`` the node does not have, or None.

    Typos in a params file (``modle``, ``tracker_noize``): rclpy ignores what no node
    declares, so the node and ``analyze --params`` say so, each with the nearest parameter
    name where one is close. ROS's own (``ROS_OWN_PARAMETERS``, ``qos_overrides.*``) are known.
    """
    unknown = sorted(name for name in names if name not in SPECS
                     and name not in ROS_OWN_PARAMETERS and not name.startswith('qos_overrides.'))
    if not unknown:
        return None
    described = []
    for name in unknown:
        near = difflib.get_close_matches(name, SPECS, n=1)
        described.append(f'{name} (did you mean {near[0]}?)' if near else name)
    return (f"ignoring unknown parameter(s) {', '.join(described)}: not parameters of "
            f'{node_name} (see config/impact_node.yaml)')


def validate_parameters(values: Mapping[str, Any]) -> Dict[str, Any]:
    """
    Check parameter values exactly as ``impact_node`` does; return every parameter's value.

    Each value is checked for its type (an int is taken for a double and converted; a bool is
    not a number), its range and its choices, in table order; then the values together: the
    input topics must differ, ``up_axis`` must be a non-zero 3-vector, and the bat description
    (``bat_profile``, ``bat_length``, ``bat_radius``, ``bat_axis``, ``knob_offset``,
    ``tip_offset``) must describe a bat. Topic name syntax is ROS's to check (the node does).

    :param values: parameter values by name; missing ones take their default, names not in
        the table are ignored (the node warns about them), ``None`` for an array means unset.
    :returns: ``{name: value}`` for every parameter of :data:`PARAMETERS`: doubles as float,
        arrays as lists of floats.
    :raises CoreError: the first value the node would refuse: one line naming the parameter;
        ``values`` not a mapping.
    """
    checked = _check_each(values)
    _check_together(checked)
    return checked


def _check_each(values: Mapping[str, Any]) -> Dict[str, Any]:
    """
    Return every parameter's value, each checked on its own (see validate_parameters).

    :raises CoreError: ``values`` not a mapping (a list of pairs was taken as no parameter at
        all: every default, silently; a str raised from inside), or a value the node refuses.
    """
    if not isinstance(values, Mapping):
        raise CoreError('parameters must be a mapping of names to values (a dict), not '
                        f'{type(values).__name__}')
    return {spec.name: spec.check(values[spec.name]) if spec.name in values
            else spec.check(spec.default) for spec in PARAMETERS}


def _check_together(checked: Mapping[str, Any]) -> Tuple[BatProfile, PoseBatGeometry]:
    """
    Check what depends on several values; return the bat profile and pose geometry.

    :raises CoreError: naming the parameters.
    """
    names = ['ball_topic'] + (['bat_pose_topic'] if checked['bat_input'] == 'pose'
                              else ['knob_topic', 'tip_topic'])
    topics = [checked[name] for name in names]
    if len(set(topics)) != len(topics):
        raise CoreError(f"parameters {', '.join(repr(name) for name in names)} must name "
                        f"different topics, got {', '.join(repr(topic) for topic in topics)}")
    unit_vector(checked['up_axis'], 'up_axis')
    try:
        profile = _profile(checked)
    except CoreError as error:
        raise CoreError(f"parameters 'bat_profile', 'bat_length', 'bat_radius' describe no "
                        f'bat: {error}') from error
    try:
        geometry = PoseBatGeometry.along_axis(checked['bat_axis'], checked['knob_offset'],
                                              checked['tip_offset'])
    except CoreError as error:
        raise CoreError(f"parameters 'knob_offset', 'tip_offset': {error}") from error
    return profile, geometry


def unit_vector(value: Any, name: str) -> Vector:
    """
    Return a non-zero 3-vector scaled to length 1.

    :raises CoreError: not three finite numbers with a non-zero length, naming ``name``.
    """
    try:
        x, y, z = (float(c) for c in value)
    except (TypeError, ValueError):
        x = y = z = math.nan
    length = math.sqrt(x * x + y * y + z * z)
    if not (math.isfinite(length) and length > 0.0):
        raise CoreError(f"parameter '{name}' must be a non-zero 3-vector, got {value!r}")
    return (x / length, y / length, z / length)


def _profile(checked: Mapping[str, Any]) -> BatProfile:
    """Return the bat profile the checked parameters describe (see DetectorConfig)."""
    flat: List[float] = checked['bat_profile']
    length = checked['bat_length'] or (WOOD_BAT_34.length if len(flat) < 2 else flat[-2])
    if checked['bat_radius'] > 0.0:
        return BatProfile.constant(checked['bat_radius'], length)
    if not flat:
        return WOOD_BAT_34 if length == WOOD_BAT_34.length else BatProfile(
            stations=tuple((d * length / WOOD_BAT_34.length, r)
                           for d, r in WOOD_BAT_34.stations), length=length)
    if len(flat) % 2:
        raise CoreError('bat_profile must list pairs: distance_from_knob, radius')
    return BatProfile.from_sequence(list(zip(flat[::2], flat[1::2])), length)


@dataclass(frozen=True)
class DetectorConfig:
    """
    Everything the detector needs to know; defaults and checks from :data:`PARAMETERS`.

    :ivar model: motion model between samples: ``'linear'``, ``'rigid'``, ``'spline'`` or
        ``'c2'``.
    :ivar look_ahead: ``c2``: samples after an interval's closing frame its fit may use (0-2).
    :ivar spline_window: ``c2``: samples in each interval's spline (4-32); every model: in the
        quintic spline behind impact velocities from exact samples at a high rate.
    :ivar bat_input: ``'pose'`` (one pose stream) or ``'points'`` (knob and tip streams).
    :ivar ball_radius: metres.
    :ivar profile: the bat's radius profile (stations from the knob), scaled to knob-tip.
    :ivar geometry: where knob and tip sit in the bat's body frame (pose input).
    :ivar max_gap: longest time (s) between two samples of a stream that is interpolated.
    :ivar max_chord_error: largest distance (m) a curved path may leave the chords solved.
    :ivar rearm_distance: gap (m) the ball must clear after an impact before another.
    :ivar near_miss_threshold: a pass with a smallest gap (m) below this is a near miss.
    :ivar max_speed: fastest plausible speed (m/s) of any tracked point between samples.
    :ivar bat_length_tolerance: knob-tip length change (m) beyond which a bat sample is a jump.
    :ivar time_jump_reset: stamps this far (s) behind their streams' newest are a jump back
        (the state resets once later samples confirm it) or another clock (dropped).
    :ivar drop_lost_body: drop bat poses exactly at the origin with the identity orientation.
    :ivar rest_tolerance: an impact whose bat stayed within this (m) over the velocity window
        is flagged ``bat_at_rest`` (0: never).
    :ivar frame_id: frame every input must be in; empty: the first frame every input stream
        has sent (or, when too many samples wait, the most common that every stream sending a
        frame has sent; none where the streams' frames differ: ``no_common_frame``), the first
        frame seen taken meanwhile (``gate.FrameVote``, ``intake``).
    :ivar up_axis: unit vector up, for the attack angle.
    :ivar sweet_spot_from_tip: distance (m) from the barrel end of the sweet spot (Statcast: 6 in).
    :ivar velocity_window: span (s) of the samples before an impact that its velocities are
        fitted to (six samples at 90 Hz, twenty-two at 360 Hz).
    :ivar prediction_horizon: how far ahead (s) to predict the coming impact after every
        processed frame; 0 turns prediction off. Made in code it is 0 unless given; from
        parameters (the node, a parameter file) the table's 0.3.
    :ivar prediction_period: predict at most this often (s between the stamps of the frames
        that predict); a frame sooner keeps the last prediction in force. 0: every frame (made
        in code, unless given); from parameters the table's 0.01.
    :ivar prediction_window: span (s) of the latest samples the prediction's state is fitted to.
    :ivar lift_window: span (s) of the latest ball samples whose flight gives the lift (its
        spin's Magnus force) the prediction's ball carries (``core.prediction``'s docstring;
        within what the stream keeps, ``LIFT_MOST_SAMPLES`` at most); 0: none.
    :ivar ball_drag: the ball's quadratic drag, rho Cd A / (2 m) (1/m): deceleration
        ``ball_drag * |v| * v``; 0.0061 for a baseball, 0 for none.
    :ivar gravity: m/s^2, along -``up_axis``.
    :ivar tracker_noise: tracking noise (m, 1 sigma per coordinate); 0: exact samples
        (interpolated). Under ``c2`` > 0 smooths each interval's window (``fitting``); a
        negative value (``AUTO_NOISE``) estimates each stream's noise from its samples
        (``noise.NoiseEstimate``).
    :ivar velocity_degree: degree (1-6) of the fit to the bat's rotation and, at low rates (six
        samples or fewer in the window), to the hands; at higher rates the hands' fit uses at
        most 3 and the ball's always at most 2 (a parabola). The default interpolates at 90 Hz,
        which is exact for clean tracking but amplifies noise: for a noisy low-rate tracker
        lower it (3 at 90 Hz with 1 mm of noise, as measured: BENCHMARKS.md) or lengthen the
        window.
    """

    model: str = DEFAULTS['model']
    look_ahead: int = DEFAULTS['look_ahead']
    spline_window: int = DEFAULTS['spline_window']
    bat_input: str = DEFAULTS['bat_input']
    ball_radius: float = DEFAULTS['ball_radius']
    profile: BatProfile = WOOD_BAT_34
    geometry: PoseBatGeometry = field(default_factory=PoseBatGeometry)
    max_gap: float = DEFAULTS['max_gap']
    max_chord_error: float = DEFAULTS['max_chord_error']
    rearm_distance: float = DEFAULTS['rearm_distance']
    near_miss_threshold: float = DEFAULTS['near_miss_threshold']
    max_speed: float = DEFAULTS['max_speed']
    bat_length_tolerance: float = DEFAULTS['bat_length_tolerance']
    time_jump_reset: float = DEFAULTS['time_jump_reset']
    drop_lost_body: bool = DEFAULTS['drop_lost_body']
    rest_tolerance: float = DEFAULTS['rest_tolerance']
    frame_id: str = DEFAULTS['frame_id']
    up_axis: Vector = DEFAULTS['up_axis']
    sweet_spot_from_tip: float = DEFAULTS['sweet_spot_from_tip']
    velocity_window: float = DEFAULTS['velocity_window']
    velocity_degree: int = DEFAULTS['velocity_degree']
    tracker_noise: float = DEFAULTS['tracker_noise']
    prediction_horizon: float = 0.0  # made in code: predicts only when asked (the node: 0.3)
    prediction_period: float = 0.0  # made in code: every frame (the node: 0.01)
    prediction_window: float = DEFAULTS['prediction_window']
    lift_window: float = DEFAULTS['lift_window']
    ball_drag: float = DEFAULTS['ball_drag']
    gravity: float = DEFAULTS['gravity']

    def __post_init__(self) -> None:
        """
        Check every value against its parameter (doubles become floats; up_axis unit length).

        :raises CoreError: a value of the wrong type or out of its range, naming the field; a
            ``profile`` that is not a ``BatProfile`` or a ``geometry`` not a
            ``PoseBatGeometry``.
        """
        for name in _TABLE_FIELDS:
            object.__setattr__(self, name, SPECS[name].check(getattr(self, name)))
        object.__setattr__(self, 'up_axis', unit_vector(self.up_axis, 'up_axis'))
        for name, kind in (('profile', BatProfile), ('geometry', PoseBatGeometry)):
            if not isinstance(getattr(self, name), kind):
                raise CoreError(f'{name} must be a {kind.__name__}, not '
                                f'{type(getattr(self, name)).__name__} (the node parameters '
                                'of the bat: DetectorConfig.from_parameters)')

    def variant(self, **changes: Any) -> 'DetectorConfig':
        """
        Return this configuration with ``changes`` (``dataclasses.replace``), checked once.

        An impact's uncertainty re-solves it under a few variants of the detector's
        configuration (another model, no look-ahead), the same at every impact: each is made
        and checked once (45 us) and kept (``_variant``; the configuration is immutable).

        :raises CoreError: a change the checks refuse.
        """
        return _variant(self, tuple(sorted(changes.items())))

    @classmethod
    def from_parameters(cls, parameters: Mapping[str, Any]) -> 'DetectorConfig':
        """
        Build a config from flat parameters, as in the node's YAML file.

        Keys are the field names, plus the bat description: ``bat_profile`` (flat list
        ``[distance_from_knob, radius, ...]`` in metres, empty for the default wood bat),
        ``bat_length`` (metres the profile was measured on), ``bat_radius`` (> 0 replaces the
        profile by a capsule of that radius), ``bat_axis`` (body axis from knob to tip: x, y, z,
        -x, -y, -z), ``knob_offset`` and ``tip_offset`` (signed distances along that axis, m).
        Every value is checked as the node checks it (:func:`validate_parameters`); unknown
        keys are ignored (the node has parameters of its own).

        :raises CoreError: a value the node would refuse, naming the parameter; parameters
            not a mapping.
        """
        checked = _check_each(parameters)
        profile, geometry = _check_together(checked)
        return cls(profile=profile, geometry=geometry,
                   **{name: checked[name] for name in _TABLE_FIELDS})


@lru_cache(maxsize=16)
def _variant(config: DetectorConfig, changes: Tuple[Tuple[str, Any], ...]) -> DetectorConfig:
    """``DetectorConfig.variant``'s, kept by the configuration (by value) and the changes."""
    return replace(config, **dict(changes))


_TABLE_FIELDS = tuple(f.name for f in fields(DetectorConfig) if f.name in SPECS)
"""The DetectorConfig fields that are parameters (all but ``profile`` and ``geometry``)."""
