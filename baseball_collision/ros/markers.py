"""
RViz / Foxglove markers (visualization_msgs/MarkerArray) of the bat, the ball and impacts.

The bat is drawn as one cylinder (or sphere) per profile segment between knob and tip, the ball
as a sphere; an impact adds its contact point, the normal as an arrow and a label. Lengths are
metres; lifetimes seconds (0: until replaced).
"""

import math
from typing import Any, List, Mapping, Optional, Sequence, Tuple

from builtin_interfaces.msg import Duration as DurationMsg
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from .messages import NS_PER_S, stamped_header, to_point
from ..core.detector import DetectorConfig, Impact, MPS_TO_MPH
from ..core.geometry import add, norm, quaternion_from_z, scale, sub, Vector
from ..errors import CoreError

BAT_COLOR = ColorRGBA(r=0.72, g=0.52, b=0.30, a=0.9)
BALL_COLOR = ColorRGBA(r=0.95, g=0.95, b=0.95, a=0.9)
CONTACT_COLOR = ColorRGBA(r=0.9, g=0.1, b=0.1, a=1.0)
NORMAL_COLOR = ColorRGBA(r=1.0, g=0.85, b=0.1, a=1.0)


def lifetime(seconds: float) -> DurationMsg:
    """Return how long a marker stays (s; 0 = until replaced) as a Duration message."""
    nanoseconds = int(seconds * NS_PER_S)
    return DurationMsg(sec=nanoseconds // NS_PER_S, nanosec=nanoseconds % NS_PER_S)


def bat_markers(header: Header, namespace: str, knob: Vector, tip: Vector,
                segments: Sequence[Tuple[float, float, float]],
                duration: DurationMsg) -> List[Marker]:
    """
    Return the bat as one cylinder (or sphere) per profile segment.

    :param knob, tip: bat ends (m).
    :param segments: ``BatProfile.segments()``: (fraction_start, fraction_end, radius m).
    :param duration: the markers' lifetime.
    """
    axis = sub(tip, knob)
    length = norm(axis)
    direction = scale(axis, 1.0 / length) if length > 0.0 else (0.0, 0.0, 1.0)
    x, y, z, w = quaternion_from_z(direction)
    markers = []
    for index, (f0, f1, radius) in enumerate(segments):
        marker = Marker(header=header, ns=namespace, id=index, action=Marker.ADD,
                        color=BAT_COLOR, lifetime=duration)
        marker.pose.position = to_point(add(knob, scale(axis, 0.5 * (f0 + f1))))
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
                  color: ColorRGBA, duration: DurationMsg) -> Marker:
    """Return a sphere marker (centre and diameter in m)."""
    marker = Marker(header=header, ns=namespace, id=0, type=Marker.SPHERE, action=Marker.ADD,
                    color=color, lifetime=duration)
    marker.pose.position = to_point(centre)
    marker.pose.orientation.w = 1.0
    marker.scale.x = marker.scale.y = marker.scale.z = diameter
    return marker


def impact_markers(impact: Impact, frame_id: str, config: DetectorConfig,
                   lifetime_s: float) -> MarkerArray:
    """
    Return the markers of an impact: bat, ball, contact point, normal arrow and a label.

    :param lifetime_s: how long they stay (s; 0 = until replaced).
    """
    header = stamped_header(impact.stamp_ns, frame_id)
    duration = lifetime(lifetime_s)
    markers = bat_markers(header, 'impact_bat', impact.knob, impact.tip,
                          config.profile.segments(), duration)
    markers.append(sphere_marker(header, 'impact_ball', impact.ball_position,
                                 2.0 * config.ball_radius, BALL_COLOR, duration))
    markers.append(sphere_marker(header, 'impact_contact', impact.point, 0.015,
                                 CONTACT_COLOR, duration))
    arrow = Marker(header=header, ns='impact_normal', id=0, type=Marker.ARROW,
                   action=Marker.ADD, color=NORMAL_COLOR, lifetime=duration)
    arrow.pose.orientation.w = 1.0
    arrow.points = [to_point(impact.point), to_point(add(impact.point,
                                                         scale(impact.normal, 0.15)))]
    arrow.scale.x, arrow.scale.y, arrow.scale.z = 0.008, 0.016, 0.03
    markers.append(arrow)
    label = Marker(header=header, ns='impact_label', id=0, type=Marker.TEXT_VIEW_FACING,
                   action=Marker.ADD, color=BALL_COLOR, lifetime=duration)
    label.pose.position = to_point(add(impact.point, (0.0, 0.0, 0.15)))
    label.pose.orientation.w = 1.0
    label.scale.z = 0.05
    label.text = (f'{impact.sweet_spot_speed_mps * MPS_TO_MPH:.1f} mph, '
                  f'{impact.distance_from_tip_m * 100:.0f} cm from tip')
    markers.append(label)
    return MarkerArray(markers=markers)


def live_markers(header: Header, ball: Optional[Vector],
                 ends: Optional[Tuple[Vector, Vector]], config: DetectorConfig,
                 lifetime_s: float) -> MarkerArray:
    """
    Return the live bat (when its ends are apart) and ball markers.

    :param ball: the last accepted ball centre (m), or None.
    :param ends: the last accepted knob and tip (m), or None.
    :param lifetime_s: how long they stay unless refreshed (s).
    """
    duration = lifetime(lifetime_s)
    markers = []
    if ends is not None and math.dist(*ends) > 0.0:
        markers += bat_markers(header, 'live_bat', ends[0], ends[1], config.profile.segments(),
                               duration)
    if ball is not None:
        markers.append(sphere_marker(header, 'live_ball', ball, 2.0 * config.ball_radius,
                                     BALL_COLOR, duration))
    return MarkerArray(markers=markers)


def bat_ends(last: Mapping[str, Tuple[Any, ...]],
             config: DetectorConfig) -> Optional[Tuple[Vector, Vector]]:
    """
    Return the knob and tip (m) of the last accepted bat samples, or None.

    :param last: the last accepted sample values by stream: ``bat_pose`` (position,
        quaternion), or ``knob`` and ``tip`` (position,).
    """
    if 'bat_pose' in last:
        try:
            knob, tip = config.geometry.knob_and_tip(*last['bat_pose'])
        except CoreError:
            return None
        return tuple(knob.tolist()), tuple(tip.tolist())
    if 'knob' in last and 'tip' in last:
        return last['knob'][0], last['tip'][0]
    return None
