"""
The node's views (markers, diagnostics, reports) as messages of rosbags' Jazzy typestore.

:func:`default_message` builds any message type with every field at its zero value (rosbags'
message classes have no defaults); :func:`scene_message`, :func:`health_message` and
:func:`text_message` turn the core's plain data (``core.scene.Scene``,
``core.health.HealthStatus``) and text into ``visualization_msgs/msg/MarkerArray``,
``diagnostic_msgs/msg/DiagnosticArray`` and ``std_msgs/msg/String``: what the live node
publishes on ``~/markers``, ``/diagnostics`` and ``~/impact_report``. :func:`qos_profile` is a
QoS profile as a bag records it (what a publisher offered).
"""

from typing import Any, Dict, Sequence

import numpy as np
from rosbags.interfaces import (
    Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime)
from rosbags.typesys.store import Typestore

from .common import jazzy_typestore
from .names import PATH
from ..core.health import HealthStatus, NS_PER_S
from ..core.scene import Item, Scene, Shape

MARKER_ARRAY = 'visualization_msgs/msg/MarkerArray'
DIAGNOSTIC_ARRAY = 'diagnostic_msgs/msg/DiagnosticArray'
STRING = 'std_msgs/msg/String'

MARKER_TYPES = {Shape.ARROW: 0, Shape.SPHERE: 2, Shape.CYLINDER: 3, Shape.TEXT: 9}
"""visualization_msgs/Marker ``type`` of each scene shape (ARROW, SPHERE, CYLINDER,
TEXT_VIEW_FACING)."""

MARKER_ADD, MARKER_DELETEALL = 0, 3

_NUMPY = {'bool': np.bool_, 'byte': np.uint8, 'char': np.uint8, 'int8': np.int8,
          'uint8': np.uint8, 'int16': np.int16, 'uint16': np.uint16, 'int32': np.int32,
          'uint32': np.uint32, 'int64': np.int64, 'uint64': np.uint64, 'float32': np.float32,
          'float64': np.float64}
_NAME, _ARRAY = 2, 3  # rosbags Nodetype values: BASE 1, NAME 2, ARRAY 3, SEQUENCE 4


def _zero(store: Typestore, node: Any) -> Any:
    """Return the zero value of one field description of the typestore."""
    kind, detail = node
    if kind == _NAME:
        return default_message(store, detail)
    if kind in (_ARRAY, _ARRAY + 1):
        (item_kind, item), size = detail
        if item_kind == 1 and item[0] in _NUMPY:
            return np.zeros(size if kind == _ARRAY else 0, dtype=_NUMPY[item[0]])
        return [_zero(store, (item_kind, item)) for _ in range(size if kind == _ARRAY else 0)]
    name = detail[0]
    if name == 'bool':
        return False
    if name in ('string', 'wstring'):
        return ''
    return 0.0 if name.startswith('float') else 0


def default_message(store: Typestore, msgtype: str, **fields: Any) -> Any:
    """
    Return a message of ``msgtype`` with every field zero (or empty), but ``fields``.

    :raises KeyError: a type the typestore does not know.
    """
    _, definition = store.fielddefs[msgtype]
    values: Dict[str, Any] = {name: fields[name] if name in fields else _zero(store, node)
                              for name, node in definition}
    return store.types[msgtype](**values)


def _header(store: Typestore, stamp_ns: int, frame_id: str) -> Any:
    sec, nanosec = divmod(int(stamp_ns), NS_PER_S)
    return default_message(store, 'std_msgs/msg/Header', frame_id=frame_id,
                           stamp=default_message(store, 'builtin_interfaces/msg/Time',
                                                 sec=sec, nanosec=nanosec))


def path_message(stamps_ns: Sequence[int], positions: Sequence[Sequence[float]],
                 quaternions: Sequence[Sequence[float]], frame_id: str,
                 store: Typestore = None) -> Any:
    """
    Return a commanded bat trajectory as a ``nav_msgs/msg/Path`` of the typestore.

    Its poses stamped ``stamps_ns`` (ns) at ``positions`` (m) and ``quaternions`` (x, y, z, w),
    every header in ``frame_id``: what an arm sends on the node's ``bat_plan_topic``.
    """
    store = store or jazzy_typestore()
    poses = [default_message(store, 'geometry_msgs/msg/PoseStamped',
                             header=_header(store, stamp, frame_id),
                             pose=default_message(
                                 store, 'geometry_msgs/msg/Pose',
                                 position=_vector(store, 'geometry_msgs/msg/Point', position),
                                 orientation=_vector(store, 'geometry_msgs/msg/Quaternion',
                                                     quaternion)))
             for stamp, position, quaternion in zip(stamps_ns, positions, quaternions)]
    return default_message(store, PATH, header=_header(
        store, stamps_ns[0] if len(stamps_ns) else 0, frame_id), poses=poses)


def _vector(store: Typestore, msgtype: str, values: Any) -> Any:
    names = ('x', 'y', 'z', 'w')
    return default_message(store, msgtype, **dict(zip(names, (float(v) for v in values))))


def _marker(store: Typestore, item: Item, header: Any) -> Any:
    seconds, nanoseconds = divmod(int(item.lifetime_s * NS_PER_S), NS_PER_S)
    pose = default_message(
        store, 'geometry_msgs/msg/Pose',
        position=_vector(store, 'geometry_msgs/msg/Point', item.position),
        orientation=_vector(store, 'geometry_msgs/msg/Quaternion', item.orientation))
    color = item.color
    return default_message(
        store, 'visualization_msgs/msg/Marker', header=header, ns=item.namespace,
        id=item.number, type=MARKER_TYPES[item.shape], action=MARKER_ADD, pose=pose,
        scale=_vector(store, 'geometry_msgs/msg/Vector3', item.size),
        color=default_message(store, 'std_msgs/msg/ColorRGBA', r=color.r, g=color.g,
                              b=color.b, a=color.a),
        lifetime=default_message(store, 'builtin_interfaces/msg/Duration', sec=seconds,
                                 nanosec=nanoseconds),
        points=[_vector(store, 'geometry_msgs/msg/Point', p) for p in item.points],
        text=item.text)


def scene_message(scene: Scene, store: Typestore = None) -> Any:
    """Return a scene as a MarkerArray (a DELETEALL marker first when the scene clears)."""
    store = store or jazzy_typestore()
    header = _header(store, scene.stamp_ns, scene.frame_id)
    markers = [default_message(store, 'visualization_msgs/msg/Marker', header=header,
                               action=MARKER_DELETEALL)] if scene.delete_all else []
    markers += [_marker(store, item, header) for item in scene.items]
    return default_message(store, MARKER_ARRAY, markers=markers)


def health_message(status: HealthStatus, stamp_ns: int, store: Typestore = None) -> Any:
    """Return a health status as a DiagnosticArray of one status, stamped ``stamp_ns``."""
    store = store or jazzy_typestore()
    values = [default_message(store, 'diagnostic_msgs/msg/KeyValue', key=key, value=value)
              for key, value in status.values()]
    entry = default_message(store, 'diagnostic_msgs/msg/DiagnosticStatus',
                            level=int(status.level), name=status.name, message=status.message,
                            hardware_id=status.hardware_id, values=values)
    return default_message(store, DIAGNOSTIC_ARRAY, header=_header(store, stamp_ns, ''),
                           status=[entry])


def text_message(text: str, store: Typestore = None) -> Any:
    """Return a ``std_msgs/msg/String``."""
    return default_message(store or jazzy_typestore(), STRING, data=text)


_INFINITE = QosTime(sec=2147483647, nsec=4294967295)  # rmw's "infinite" duration in a bag


def qos_profile(depth: int = 10, reliable: bool = True, transient_local: bool = False) -> Qos:
    """
    Return a publisher's QoS profile as a ROS 2 bag records it (``offered_qos_profiles``).

    :param depth: history depth (KEEP_LAST).
    :param reliable: RELIABLE, else BEST_EFFORT.
    :param transient_local: TRANSIENT_LOCAL (latched), else VOLATILE.
    """
    return Qos(history=QosHistory.KEEP_LAST, depth=depth,
               reliability=QosReliability.RELIABLE if reliable else QosReliability.BEST_EFFORT,
               durability=(QosDurability.TRANSIENT_LOCAL if transient_local
                           else QosDurability.VOLATILE),
               deadline=_INFINITE, lifespan=_INFINITE, liveliness=QosLiveliness.AUTOMATIC,
               liveliness_lease_duration=_INFINITE, avoid_ros_namespace_conventions=False)
