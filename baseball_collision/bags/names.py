"""
The names the bag modules use, without rosbags: message types, topic roles and their flags.

Importable where rosbags is not installed (the command line builds its ``--help`` from these).
"""

from typing import Dict, Tuple

POINT_STAMPED = 'geometry_msgs/msg/PointStamped'
POSE_STAMPED = 'geometry_msgs/msg/PoseStamped'
TWIST_STAMPED = 'geometry_msgs/msg/TwistStamped'
VECTOR3_STAMPED = 'geometry_msgs/msg/Vector3Stamped'
PATH = 'nav_msgs/msg/Path'

ROLES = ('ball', 'bat_pose', 'knob', 'tip')
"""Topic roles, in the order of ``TopicSelection``'s fields."""

TOPIC_FLAGS: Dict[str, str] = {
    'ball': '--ball-topic',
    'bat_pose': '--bat-pose-topic',
    'knob': '--knob-topic',
    'tip': '--tip-topic',
}
"""Command-line flag that names each role's topic; error messages refer to these."""

ROLE_TYPES: Dict[str, Tuple[str, ...]] = {
    'ball': (POINT_STAMPED, POSE_STAMPED),
    'bat_pose': (POSE_STAMPED,),
    'knob': (POINT_STAMPED,),
    'tip': (POINT_STAMPED,),
}
"""Message types accepted for each role."""
