"""bags.messages: zero-valued typestore messages, scenes, statuses and QoS profiles."""

from baseball_collision.bags import health_message, qos_profile, scene_message, text_message
from baseball_collision.bags.common import jazzy_typestore
from baseball_collision.bags.messages import default_message, MARKER_TYPES
from baseball_collision.core.health import HealthStatus, Level
from baseball_collision.core.scene import BALL_COLOR, Item, Scene, Shape
import numpy as np
from rosbags.interfaces import QosDurability, QosReliability


def test_default_message_is_zero_and_serialises() -> None:
    """Every field zero or empty (fixed arrays of numbers as zeros); CDR round trip."""
    store = jazzy_typestore()
    marker = default_message(store, 'visualization_msgs/msg/Marker', ns='a', id=3)
    assert (marker.ns, marker.id, marker.type, marker.points) == ('a', 3, 0, [])
    assert marker.scale.x == 0.0
    assert marker.header.frame_id == '' and marker.lifetime.sec == 0
    data = store.serialize_cdr(marker, 'visualization_msgs/msg/Marker')
    again = store.deserialize_cdr(data, 'visualization_msgs/msg/Marker')
    assert (again.ns, again.id) == ('a', 3)
    imu = default_message(store, 'sensor_msgs/msg/Imu')
    assert isinstance(imu.orientation_covariance, np.ndarray)
    assert imu.orientation_covariance.shape == (9,) and not imu.orientation_covariance.any()


def test_scene_message_items_and_delete_all() -> None:
    """A scene's items become markers (shape, pose, size, colour, lifetime); DELETEALL first."""
    item = Item('impact_ball', 7, Shape.SPHERE, (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0),
                (0.07, 0.07, 0.07), BALL_COLOR, 1.25, text='x')
    array = scene_message(Scene(5_000_000_123, 'world', (item,), delete_all=True))
    clear, marker = array.markers
    assert clear.action == 3 and marker.action == 0
    assert (marker.ns, marker.id, marker.type) == ('impact_ball', 7, MARKER_TYPES[Shape.SPHERE])
    assert (marker.pose.position.x, marker.pose.position.z, marker.scale.y) == (1.0, 3.0, 0.07)
    assert (marker.lifetime.sec, marker.lifetime.nanosec) == (1, 250_000_000)
    assert (marker.header.stamp.sec, marker.header.stamp.nanosec) == (5, 123)
    assert marker.header.frame_id == 'world' and marker.color.a == BALL_COLOR.a


def test_health_and_text_messages() -> None:
    """One status with every key/value of every group, stamped; a String."""
    status = HealthStatus(Level.WARN, 'n: impact detector', 'stale', 'hw',
                          (('state', (('state', 'stale'),)), ('events', (('impacts', '2'),))))
    array = health_message(status, 2_000_000_001)
    (entry,) = array.status
    assert (entry.level, entry.name, entry.message, entry.hardware_id) == (
        1, 'n: impact detector', 'stale', 'hw')
    assert [(kv.key, kv.value) for kv in entry.values] == [('state', 'stale'), ('impacts', '2')]
    assert (array.header.stamp.sec, array.header.stamp.nanosec) == (2, 1)
    assert text_message('{"a":1}').data == '{"a":1}'


def test_qos_profile() -> None:
    """Depth, reliability and durability as asked."""
    latched = qos_profile(depth=1, transient_local=True)
    assert (latched.depth, latched.durability) == (1, QosDurability.TRANSIENT_LOCAL)
    lossy = qos_profile(depth=5, reliable=False)
    assert lossy.reliability == QosReliability.BEST_EFFORT
    assert lossy.durability == QosDurability.VOLATILE
