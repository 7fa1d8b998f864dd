"""
RViz / Foxglove markers (visualization_msgs/MarkerArray): the core's scenes as messages.

What is drawn (the bat's profile pieces, the ball, an impact's contact point, normal and label)
is plain data made by :mod:`baseball_collision.core.scene`; this module only converts
:class:`~baseball_collision.core.scene.Item` s and scenes into ``Marker`` s and a
``MarkerArray``. Lengths are metres; lifetimes seconds (0: until replaced).
"""

import struct
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from builtin_interfaces.msg import Duration as DurationMsg
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from .messages import CDR_LE, NS_PER_S, stamped_header, to_point
from ..core.detector import DetectorConfig, Impact
from ..core.geometry import Vector
from ..core.scene import (
    bat_ends, bat_items, Color, impact_scene, Item, live_items, live_scene, Scene, Shape,
    sphere_item)

__all__ = ['bat_ends', 'bat_markers', 'impact_markers', 'latest_scene', 'lifetime',
           'live_markers', 'scene_cdr', 'scene_markers', 'sphere_marker', 'to_marker']

MARKER_TYPES = {Shape.CYLINDER: Marker.CYLINDER, Shape.SPHERE: Marker.SPHERE,
                Shape.ARROW: Marker.ARROW, Shape.TEXT: Marker.TEXT_VIEW_FACING}
"""The Marker type of each scene shape."""


def lifetime(seconds: float) -> DurationMsg:
    """Return how long a marker stays (s; 0 = until replaced) as a Duration message."""
    nanoseconds = int(seconds * NS_PER_S)
    return DurationMsg(sec=nanoseconds // NS_PER_S, nanosec=nanoseconds % NS_PER_S)


def _color(color: Color) -> ColorRGBA:
    return ColorRGBA(r=color.r, g=color.g, b=color.b, a=color.a)


def to_marker(item: Item, header: Header) -> Marker:
    """Return one scene item as an ``ADD`` marker with the given header."""
    marker = Marker(header=header, ns=item.namespace, id=item.number,
                    type=MARKER_TYPES[item.shape], action=Marker.ADD, color=_color(item.color),
                    lifetime=lifetime(item.lifetime_s), text=item.text)
    marker.pose.position = to_point(item.position)
    o = marker.pose.orientation
    o.x, o.y, o.z, o.w = (float(c) for c in item.orientation)
    marker.scale.x, marker.scale.y, marker.scale.z = (float(c) for c in item.size)
    marker.points = [to_point(point) for point in item.points]
    return marker


def scene_markers(scene: Scene) -> MarkerArray:
    """Return a scene as a MarkerArray (a ``DELETEALL`` first when the scene clears)."""
    header = stamped_header(scene.stamp_ns, scene.frame_id)
    markers = [Marker(header=header, action=Marker.DELETEALL)] if scene.delete_all else []
    return MarkerArray(markers=markers + [to_marker(item, header) for item in scene.items])


def scene_cdr(scene: Scene) -> bytes:
    """
    Return the CDR bytes ``scene_markers(scene)`` serialises to: a MarkerArray, no message made.

    Little-endian plain CDR (encapsulation ``CDR_LE``), as rmw_fastrtps serialises it and what
    rclpy's ``Publisher.publish`` sends for bytes (as ``messages.StampedCdr``): each
    marker packed by one ``struct`` call whose layout (its fields' alignment from the payload's
    start, its strings' lengths, its points) is made once per shape of marker and kept (the
    padding is zeros; rclpy leaves whatever its buffer held, which no reader reads). Making the
    markers as messages and having rclpy convert and serialise them costs 15 times as much
    (``benchmarks/bench_markers.py``: 358 against 24 us for an impact's 12 markers), in the
    executor's thread at every impact and every live refresh (``marker_rate``).

    :raises struct.error: a stamp outside ``builtin_interfaces/Time``'s range, or an id
        outside ``int32``.
    """
    sec, nanosec = divmod(scene.stamp_ns, NS_PER_S)
    frame = scene.frame_id.encode() + b'\0'
    markers = [_DELETE_ALL] if scene.delete_all else []
    markers += [(item.namespace.encode() + b'\0', item.number, MARKER_TYPES[item.shape],
                 Marker.ADD, item.position, item.orientation, item.size,
                 (item.color.r, item.color.g, item.color.b, item.color.a),
                 divmod(int(item.lifetime_s * NS_PER_S), NS_PER_S), item.points,
                 item.text.encode() + b'\0') for item in scene.items]
    parts, offset = [CDR_LE, struct.pack('<I', len(markers))], 4
    for ns, number, shape, action, position, orientation, size, color, life, points, text \
            in markers:
        layout = _marker_layout(offset % 8, len(frame), len(ns), len(text), len(points))
        parts.append(layout.pack(
            sec, nanosec, len(frame), frame, len(ns), ns, number, shape, action, *position,
            *orientation, *size, *color, *life, False, len(points),
            *(c for point in points for c in point), 0, 1, b'\0', 0, 0, 1, b'\0', 1, b'\0', 0,
            0, len(text), text, 1, b'\0', 1, b'\0', 0, False))
        offset += layout.size
    return b''.join(parts)


_DELETE_ALL = (b'\0', 0, 0, Marker.DELETEALL, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0),
               (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0), (0, 0), (), b'\0')
"""A ``DELETEALL`` marker's fields (``scene_cdr``), as ``Marker(action=DELETEALL)`` has them."""

_LAYOUTS: Dict[Tuple[int, int, int, int, int], struct.Struct] = {}
"""The marker layouts made so far (``_marker_layout``), by their key."""

_LAYOUTS_KEPT = 1024
"""Most layouts kept (then they start again): a node meets a few dozen (labels' lengths vary)."""


def _marker_layout(start: int, frame: int, ns: int, text: int, points: int) -> struct.Struct:
    """
    Return (kept) the ``struct`` layout of one ``visualization_msgs/Marker`` in CDR.

    :param start: the marker's offset in the payload, modulo 8 (its doubles align to 8 from
        the payload's start); ``frame``, ``ns``, ``text``: the UTF-8 lengths of its header's
        frame, namespace and text, with their NUL; ``points``: how many points it has.
    """
    key = (start, frame, ns, text, points)
    found = _LAYOUTS.get(key)
    if found is not None:
        return found
    codes, offset = ['<'], start

    def put(code: str, size: int, count: int = 1) -> None:  # aligned to size
        nonlocal offset
        padding = -offset % size
        codes.append(f'{padding}x{count}{code}' if padding else f'{count}{code}')
        offset += padding + size * count

    def string(length: int) -> None:  # uint32 length (with the NUL), then the bytes
        nonlocal offset
        put('I', 4)
        codes.append(f'{length}s')
        offset += length

    put('i', 4)  # header: stamp (sec, nanosec), frame_id
    put('I', 4)
    string(frame)
    string(ns)
    put('i', 4, 3)  # id, type, action
    put('d', 8, 7 + 3)  # pose (position, orientation), scale
    put('f', 4, 4)  # color
    put('i', 4)  # lifetime
    put('I', 4)
    put('?', 1)  # frame_locked
    put('I', 4)  # points
    if points:
        put('d', 8, 3 * points)
    put('I', 4)  # colors (none)
    string(1)  # texture_resource
    put('i', 4)  # texture: header (stamp, frame_id), format, data (none)
    put('I', 4)
    string(1)
    string(1)
    put('I', 4)
    put('I', 4)  # uv_coordinates (none)
    string(text)
    string(1)  # mesh_resource
    string(1)  # mesh_file: filename, data (none)
    put('I', 4)
    put('?', 1)  # mesh_use_embedded_materials
    layout = struct.Struct(''.join(codes))
    if len(_LAYOUTS) >= _LAYOUTS_KEPT:
        _LAYOUTS.clear()
    _LAYOUTS[key] = layout
    return layout


def bat_markers(header: Header, namespace: str, knob: Vector, tip: Vector,
                segments: Sequence[Tuple[float, float, float, float]],
                duration: DurationMsg) -> List[Marker]:
    """
    Return the bat as one cylinder (or sphere) per profile segment (``core.scene.bat_items``).

    :param knob, tip: bat ends (m).
    :param segments: ``BatProfile.segments()``: (fraction_start, fraction_end, radius_start,
        radius_end m).
    :param duration: the markers' lifetime.
    """
    seconds = duration.sec + duration.nanosec / NS_PER_S
    return [to_marker(item, header)
            for item in bat_items(namespace, knob, tip, segments, seconds)]


def sphere_marker(header: Header, namespace: str, centre: Vector, diameter: float,
                  color: ColorRGBA, duration: DurationMsg) -> Marker:
    """Return a sphere marker (centre and diameter in m)."""
    seconds = duration.sec + duration.nanosec / NS_PER_S
    return to_marker(sphere_item(namespace, centre, diameter,
                                 Color(color.r, color.g, color.b, color.a), seconds), header)


def impact_markers(impact: Impact, frame_id: str, config: DetectorConfig,
                   lifetime_s: float) -> MarkerArray:
    """
    Return the markers of an impact: bat, ball, contact point, normal arrow and a label.

    :param lifetime_s: how long they stay (s; 0 = until replaced).
    """
    return scene_markers(impact_scene(impact, frame_id, config, lifetime_s))


def live_markers(header: Header, ball: Optional[Vector],
                 ends: Optional[Tuple[Vector, Vector]], config: DetectorConfig,
                 lifetime_s: float) -> MarkerArray:
    """
    Return the live bat (when its ends are apart) and ball markers (``core.scene.live_items``).

    :param ball: the last accepted ball centre (m), or None.
    :param ends: the last accepted knob and tip (m), or None.
    :param lifetime_s: how long they stay unless refreshed (s).
    """
    return MarkerArray(markers=[to_marker(item, header)
                                for item in live_items(ball, ends, config, lifetime_s)])


def latest_scene(last: Mapping[str, Tuple[int, Tuple[Any, ...]]], frame_id: str,
                 config: DetectorConfig, lifetime_s: float) -> Optional[Scene]:
    """
    Return the live bat and ball from the last accepted values of each stream, or None.

    :param last: per stream (``ball``, ``bat_pose``, ``knob``, ``tip``), the stamp (ns) and
        the values its detector method took (m; quaternion ``x, y, z, w``); not empty.
    :param lifetime_s: how long the markers last (s).
    :returns: the scene stamped with the newest stamp; None when there is neither a ball nor
        a whole bat.
    """
    newest = max(stamp for stamp, _ in last.values())
    values = {stream: value for stream, (_, value) in last.items()}
    ball, ends = values.get('ball'), bat_ends(values, config)
    if ball is None and ends is None:
        return None
    return live_scene(newest, frame_id, ball and ball[0], ends, config, lifetime_s)
