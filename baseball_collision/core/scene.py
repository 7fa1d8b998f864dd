"""
What the markers show, as plain data: the bat's profile pieces, the ball, an impact's contact.

Pure Python (no ROS). A :class:`Scene` is what one ``visualization_msgs/MarkerArray`` carries:
a stamp, a frame and :class:`Item` s (one marker each: shape, pose, size, colour, lifetime).
``ros.markers`` turns a scene into a MarkerArray for the live node; ``tools`` writes the same
scenes into ``analyze --out-bag``. Lengths are metres, lifetimes seconds (0: until replaced),
stamps integer ns, quaternions ``(x, y, z, w)``, colours RGBA in [0, 1].

The bat is one cylinder per profile segment between knob and tip (a sphere for a one-station
profile), the ball a sphere; an impact adds its contact point (a small sphere), the normal (an
arrow 15 cm long) and a label (sweet-spot speed, distance from the tip).
"""

from dataclasses import dataclass
import enum
import math
from typing import Any, List, Mapping, Optional, Sequence, Tuple

from .detector import DetectorConfig, Impact, MPS_TO_MPH
from .geometry import add, norm, Quaternion, quaternion_from_z, scale, sub, Vector
from ..errors import CoreError

IDENTITY: Quaternion = (0.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Color:
    """An RGBA colour, each channel in [0, 1]."""

    r: float
    g: float
    b: float
    a: float


BAT_COLOR = Color(0.72, 0.52, 0.30, 0.9)
BALL_COLOR = Color(0.95, 0.95, 0.95, 0.9)
CONTACT_COLOR = Color(0.9, 0.1, 0.1, 1.0)
NORMAL_COLOR = Color(1.0, 0.85, 0.1, 1.0)

CONTACT_DIAMETER = 0.015
"""Diameter (m) of the contact point's sphere."""

NORMAL_LENGTH = 0.15
"""Length (m) of the normal's arrow."""

LABEL_HEIGHT = 0.05
"""Height (m) of the label's letters; the label floats :data:`NORMAL_LENGTH` above the contact."""


class Shape(enum.StrEnum):
    """What an item is drawn as (the ``visualization_msgs/Marker`` type of the same name)."""

    CYLINDER = 'cylinder'
    SPHERE = 'sphere'
    ARROW = 'arrow'
    TEXT = 'text'


@dataclass(frozen=True)
class Item:
    """
    One drawn thing (one marker).

    :ivar namespace, number: the marker's ``ns`` and ``id`` (a later item with both replaces
        it).
    :ivar shape: a :class:`Shape`.
    :ivar position: centre (m); ``orientation``: ``(x, y, z, w)``; a cylinder's axis is its +z.
    :ivar size: cylinder (diameter, diameter, length); sphere (diameter x3); arrow (shaft
        diameter, head diameter, head length); text (0, 0, letter height) (m).
    :ivar color: RGBA.
    :ivar lifetime_s: how long it stays unless replaced (s; 0: until replaced).
    :ivar points: an arrow's start and end (m); empty for other shapes.
    :ivar text: a text item's text.
    """

    namespace: str
    number: int
    shape: Shape
    position: Vector
    orientation: Quaternion
    size: Vector
    color: Color
    lifetime_s: float
    points: Tuple[Vector, ...] = ()
    text: str = ''


@dataclass(frozen=True)
class Scene:
    """
    The items of one marker array, stamped and in one frame.

    :ivar stamp_ns: the stamp of every item (ns).
    :ivar frame_id: their frame.
    :ivar items: what is drawn.
    :ivar delete_all: clear everything drawn before (a ``DELETEALL`` marker first).
    """

    stamp_ns: int
    frame_id: str
    items: Tuple[Item, ...]
    delete_all: bool = False


def bat_items(namespace: str, knob: Vector, tip: Vector,
              segments: Sequence[Tuple[float, float, float, float]],
              lifetime_s: float) -> List[Item]:
    """
    Return the bat as one cylinder (or sphere) per profile segment, ids 0, 1, ...

    A round cone is drawn as a cylinder of its mean radius (a marker has no cone).

    :param knob, tip: bat ends (m).
    :param segments: ``BatProfile.segments()``: (fraction_start, fraction_end, radius_start,
        radius_end m).
    :param lifetime_s: how long they stay (s).
    """
    axis = sub(tip, knob)
    length = norm(axis)
    direction = scale(axis, 1.0 / length) if length > 0.0 else (0.0, 0.0, 1.0)
    orientation = quaternion_from_z(direction)
    items = []
    for index, (f0, f1, radius_start, radius_end) in enumerate(segments):
        radius = 0.5 * (radius_start + radius_end)
        piece = (f1 - f0) * length
        centre = add(knob, scale(axis, 0.5 * (f0 + f1)))
        if piece > 0.0:
            shape, size = Shape.CYLINDER, (2.0 * radius, 2.0 * radius, piece)
        else:
            shape, size = Shape.SPHERE, (2.0 * radius,) * 3
        items.append(Item(namespace, index, shape, centre, orientation, size, BAT_COLOR,
                          lifetime_s))
    return items


def sphere_item(namespace: str, centre: Vector, diameter: float, color: Color,
                lifetime_s: float) -> Item:
    """Return a sphere (centre and diameter in m), id 0."""
    return Item(namespace, 0, Shape.SPHERE, tuple(centre), IDENTITY, (diameter,) * 3, color,
                lifetime_s)


def impact_scene(impact: Impact, frame_id: str, config: DetectorConfig,
                 lifetime_s: float) -> Scene:
    """
    Return an impact's scene at its instant: bat, ball, contact point, normal arrow, label.

    Namespaces ``impact_bat``, ``impact_ball``, ``impact_contact``, ``impact_normal``,
    ``impact_label``.

    :param lifetime_s: how long they stay (s; 0 = until replaced).
    """
    items = bat_items('impact_bat', impact.knob, impact.tip, config.profile.segments(),
                      lifetime_s)
    items.append(sphere_item('impact_ball', impact.ball_position, 2.0 * config.ball_radius,
                             BALL_COLOR, lifetime_s))
    items.append(sphere_item('impact_contact', impact.point, CONTACT_DIAMETER, CONTACT_COLOR,
                             lifetime_s))
    end = add(impact.point, scale(impact.normal, NORMAL_LENGTH))
    items.append(Item('impact_normal', 0, Shape.ARROW, (0.0, 0.0, 0.0), IDENTITY,
                      (0.008, 0.016, 0.03), NORMAL_COLOR, lifetime_s,
                      points=(tuple(impact.point), end)))
    label = (f'{impact.sweet_spot_speed_mps * MPS_TO_MPH:.1f} mph, '
             f'{impact.distance_from_tip_m * 100:.0f} cm from tip')
    items.append(Item('impact_label', 0, Shape.TEXT, add(impact.point, (0.0, 0.0, 0.15)),
                      IDENTITY, (0.0, 0.0, LABEL_HEIGHT), BALL_COLOR, lifetime_s, text=label))
    return Scene(impact.stamp_ns, frame_id, tuple(items))


def live_items(ball: Optional[Vector], ends: Optional[Tuple[Vector, Vector]],
               config: DetectorConfig, lifetime_s: float) -> List[Item]:
    """
    Return the live bat (when its ends are apart) and ball: namespaces ``live_bat``, ``live_ball``.

    :param ball: the last accepted ball centre (m), or None.
    :param ends: the last accepted knob and tip (m), or None.
    :param lifetime_s: how long they stay unless refreshed (s).
    """
    items = []
    if ends is not None and math.dist(*ends) > 0.0:
        items += bat_items('live_bat', ends[0], ends[1], config.profile.segments(), lifetime_s)
    if ball is not None:
        items.append(sphere_item('live_ball', ball, 2.0 * config.ball_radius, BALL_COLOR,
                                 lifetime_s))
    return items


def live_scene(stamp_ns: int, frame_id: str, ball: Optional[Vector],
               ends: Optional[Tuple[Vector, Vector]], config: DetectorConfig,
               lifetime_s: float) -> Scene:
    """Return the live scene (:func:`live_items`) stamped ``stamp_ns`` in ``frame_id``."""
    return Scene(stamp_ns, frame_id, tuple(live_items(ball, ends, config, lifetime_s)))


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
