"""The markers on their own: the bat along knob-tip, the ball, an impact's contact and normal."""

from dataclasses import replace

from baseball_collision.core.bat import BatProfile, WOOD_BAT_34
from baseball_collision.core.detector import DetectorConfig, Impact
from baseball_collision.core.geometry import quaternion_from_z, rotate
from baseball_collision.core.scene import impact_scene, live_scene
from baseball_collision.ros.markers import (
    bat_ends, bat_markers, impact_markers, lifetime, live_markers, scene_cdr, scene_markers)
from baseball_collision.ros.messages import NS_PER_S, stamp_to_ns
from hypothesis import given, settings, strategies as st
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from std_msgs.msg import Header
from support import examples
from support.events import swing_events
from support.scenes import pose
from visualization_msgs.msg import Marker, MarkerArray

pytestmark = pytest.mark.ros


@pytest.mark.parametrize('direction', [(0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, -0.6, 0.8),
                                       (0.0, 0.0, -1.0), (0.48, 0.6, -0.64)])
def test_quaternion_from_z_turns_z_onto_the_direction(direction) -> None:
    """The marker orientation: +z rotated by it is the direction; it is a unit quaternion."""
    q = quaternion_from_z(direction)
    assert sum(c * c for c in q) == pytest.approx(1.0)
    assert rotate(q, (0.0, 0.0, 1.0)) == pytest.approx(direction, abs=1e-12)


def test_bat_is_one_piece_per_profile_segment_along_knob_tip() -> None:
    """Cylinders centred on their segment, along knob-tip, as long and wide as the segment."""
    knob, tip = (0.0, 0.0, 1.0), (0.0, 0.8636, 1.0)
    markers = bat_markers(Header(frame_id='world'), 'bat', knob, tip, WOOD_BAT_34.segments(),
                          lifetime(0.5))
    assert len(markers) == len(WOOD_BAT_34.segments())
    for marker, (f0, f1, r0, r1) in zip(markers, WOOD_BAT_34.segments()):
        radius = 0.5 * (r0 + r1)  # (a round cone drawn at its mean radius)
        assert marker.type == Marker.CYLINDER and marker.ns == 'bat'
        assert marker.pose.position.y == pytest.approx(0.8636 * 0.5 * (f0 + f1))
        assert marker.scale.z == pytest.approx((f1 - f0) * 0.8636)
        assert marker.scale.x == pytest.approx(2.0 * radius)
        o = marker.pose.orientation
        assert rotate((o.x, o.y, o.z, o.w), (0.0, 0.0, 1.0)) == pytest.approx((0, 1, 0))
        assert (marker.lifetime.sec, marker.lifetime.nanosec) == (0, 500_000_000)
    ball = bat_markers(Header(), 'b', knob, tip, BatProfile.from_sequence([[0.4, 0.03]], 0.8)
                       .segments(), lifetime(0.0))
    assert ball[0].type == Marker.SPHERE and ball[0].scale.z == pytest.approx(0.06)


def test_impact_markers_at_the_impact_instant() -> None:
    """Bat, ball, contact, normal and label, all stamped with the impact in the frame."""
    impact = next(e for e in swing_events() if isinstance(e, Impact))
    config = DetectorConfig()
    array = impact_markers(impact, 'world', config, 5.0)
    names = [m.ns for m in array.markers]
    assert names.count('impact_bat') == len(WOOD_BAT_34.segments())
    assert {'impact_ball', 'impact_contact', 'impact_normal', 'impact_label'} <= set(names)
    assert all(stamp_to_ns(m.header.stamp) == impact.stamp_ns and
               m.header.frame_id == 'world' for m in array.markers)
    ball = next(m for m in array.markers if m.ns == 'impact_ball')
    assert ball.scale.x == pytest.approx(2 * config.ball_radius)
    arrow = next(m for m in array.markers if m.ns == 'impact_normal')
    assert (arrow.points[0].x, arrow.points[0].y, arrow.points[0].z) == pytest.approx(
        impact.point)
    assert 'mph' in next(m for m in array.markers if m.ns == 'impact_label').text


def test_live_markers_from_the_last_samples() -> None:
    """The last pose gives knob and tip; without a bat only the ball; nothing without data."""
    config = DetectorConfig()
    position, quaternion = pose(0.05)
    ends = bat_ends({'bat_pose': (tuple(position), tuple(quaternion))}, config)
    assert ends is not None and ends[0] == pytest.approx(position)
    assert bat_ends({'bat_pose': ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0))}, config) is None
    assert bat_ends({'knob': ((0.0, 0.0, 1.0),)}, config) is None
    assert bat_ends({'knob': ((0, 0, 1),), 'tip': ((0, 1, 1),)}, config) == ((0, 0, 1),
                                                                             (0, 1, 1))
    array = live_markers(Header(frame_id='world'), (0.5, 0.5, 1.0), ends, config, 0.1)
    assert [m.ns for m in array.markers].count('live_bat') == len(WOOD_BAT_34.segments())
    assert array.markers[-1].ns == 'live_ball'
    only_ball = live_markers(Header(), (0.5, 0.5, 1.0), None, config, 0.1)
    assert [m.ns for m in only_ball.markers] == ['live_ball']
    assert live_markers(Header(), None, ((0, 0, 1), (0, 0, 1)), config, 0.1).markers == []


def test_a_scene_becomes_one_marker_per_item() -> None:
    """scene_markers: each item one marker of its shape's type, DELETEALL first when clearing."""
    impact = next(e for e in swing_events() if isinstance(e, Impact))
    scene = impact_scene(impact, 'world', DetectorConfig(), 1.0)
    array = scene_markers(scene)
    assert [(m.ns, m.id) for m in array.markers] == [(i.namespace, i.number) for i in scene.items]
    assert {m.type for m in array.markers} == {Marker.CYLINDER, Marker.SPHERE, Marker.ARROW,
                                               Marker.TEXT_VIEW_FACING}
    cleared = scene_markers(replace(scene, delete_all=True, items=()))
    assert [m.action for m in cleared.markers] == [Marker.DELETEALL]
    assert stamp_to_ns(cleared.markers[0].header.stamp) == impact.stamp_ns


TEXT = st.characters(blacklist_categories=('Cs',), blacklist_characters='\x00')
"""Characters a ROS string can carry (UTF-8, no NUL)."""


@settings(max_examples=examples(40), deadline=None)
@given(frame=st.text(TEXT, max_size=12), label=st.text(TEXT, max_size=20),
       stamp_ns=st.integers(0, 2 ** 31 * NS_PER_S - 1), lifetime_s=st.floats(0.0, 30.0),
       delete_all=st.booleans(), live=st.booleans(), cut=st.integers(0, 13))
def test_a_scenes_cdr_bytes_are_the_messages(frame: str, label: str, stamp_ns: int,
                                             lifetime_s: float, delete_all: bool, live: bool,
                                             cut: int) -> None:
    """
    scene_cdr: the bytes rclpy serialises ``scene_markers``' array to, but for the padding.

    Any frame, label text (UTF-8), stamp and lifetime; an impact's scene or a live one, cut to
    its first ``cut`` items (none to all: each marker starts at every alignment), DELETEALL or
    not: deserialised, the same message as rclpy's own bytes give, and as long.
    """
    impact = next(e for e in swing_events() if isinstance(e, Impact))
    config = DetectorConfig()
    scene = (live_scene(stamp_ns, frame, impact.ball_position, (impact.knob, impact.tip),
                        config, lifetime_s) if live else
             impact_scene(impact, frame, config, lifetime_s))
    items = tuple(replace(item, text=label) if item.text else item for item in scene.items)
    scene = replace(scene, stamp_ns=stamp_ns, items=items[:cut], delete_all=delete_all)
    packed, serialised = scene_cdr(scene), serialize_message(scene_markers(scene))
    assert len(packed) == len(serialised)
    assert deserialize_message(packed, MarkerArray) == deserialize_message(serialised,
                                                                           MarkerArray)
