"""The scene: what the markers show, as plain data (no ROS)."""

import math

from baseball_collision.core.bat import BatProfile, WOOD_BAT_34
from baseball_collision.core.detector import DetectorConfig, Impact
from baseball_collision.core.geometry import rotate
from baseball_collision.core.scene import (
    bat_ends, bat_items, CONTACT_DIAMETER, impact_scene, live_scene, NORMAL_LENGTH, Shape)
import pytest
from support.events import swing_events
from support.scenes import pose


def test_the_bat_is_one_piece_per_profile_segment_along_knob_tip() -> None:
    """Cylinders centred on their segment, axis along knob-tip, as long and wide as it."""
    knob, tip = (0.0, 0.0, 1.0), (0.0, 0.8636, 1.0)
    items = bat_items('bat', knob, tip, WOOD_BAT_34.segments(), 0.5)
    assert [item.number for item in items] == list(range(len(WOOD_BAT_34.segments())))
    for item, (f0, f1, r0, r1) in zip(items, WOOD_BAT_34.segments()):
        radius = 0.5 * (r0 + r1)  # (a round cone drawn at its mean radius)
        assert item.shape == Shape.CYLINDER and item.lifetime_s == 0.5
        assert item.position == pytest.approx((0.0, 0.8636 * 0.5 * (f0 + f1), 1.0))
        assert item.size == pytest.approx((2 * radius, 2 * radius, (f1 - f0) * 0.8636))
        assert rotate(item.orientation, (0.0, 0.0, 1.0)) == pytest.approx((0.0, 1.0, 0.0))
    one = bat_items('b', knob, tip, BatProfile.from_sequence([[0.4, 0.03]], 0.8).segments(), 0)
    assert one[0].shape == Shape.SPHERE and one[0].size == pytest.approx((0.06,) * 3)


def test_an_impact_scene_at_its_instant() -> None:
    """Bat, ball, contact, a normal arrow 15 cm long and a label, stamped with the impact."""
    impact = next(e for e in swing_events() if isinstance(e, Impact))
    config = DetectorConfig()
    scene = impact_scene(impact, 'world', config, 5.0)
    assert (scene.stamp_ns, scene.frame_id, scene.delete_all) == (impact.stamp_ns, 'world',
                                                                  False)
    spaces = [item.namespace for item in scene.items]
    assert spaces.count('impact_bat') == len(WOOD_BAT_34.segments())
    by_space = {item.namespace: item for item in scene.items}
    assert by_space['impact_ball'].position == pytest.approx(impact.ball_position)
    assert by_space['impact_ball'].size[0] == pytest.approx(2 * config.ball_radius)
    assert by_space['impact_contact'].size[0] == CONTACT_DIAMETER
    start, end = by_space['impact_normal'].points
    assert start == pytest.approx(impact.point)
    assert math.dist(start, end) == pytest.approx(NORMAL_LENGTH)
    assert 'mph' in by_space['impact_label'].text
    assert all(item.lifetime_s == 5.0 for item in scene.items)


def test_the_live_scene_from_the_last_samples() -> None:
    """The last pose gives knob and tip; without a bat only the ball; nothing without data."""
    config = DetectorConfig()
    position, quaternion = pose(0.05)
    ends = bat_ends({'bat_pose': (tuple(position), tuple(quaternion))}, config)
    assert ends is not None and ends[0] == pytest.approx(position)
    assert bat_ends({'bat_pose': ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0))}, config) is None
    scene = live_scene(7, 'world', (0.5, 0.5, 1.0), ends, config, 0.1)
    assert scene.stamp_ns == 7 and scene.items[-1].namespace == 'live_ball'
    assert [i.namespace for i in scene.items].count('live_bat') == len(WOOD_BAT_34.segments())
    assert live_scene(7, 'w', None, ((0, 0, 1), (0, 0, 1)), config, 0.1).items == ()
