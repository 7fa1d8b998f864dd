"""Bag files through rosbags: the only place rosbags is imported."""

from .bag import (
    BagReader, BagWriter, count_messages, POINT_STAMPED, POSE_STAMPED, read_samples, ROLE_TYPES,
    ROLES, Sample, select_topics, TOPIC_FLAGS, TopicSelection, TopicSource, TWIST_STAMPED,
    VECTOR3_STAMPED)

__all__ = [
    'POINT_STAMPED', 'POSE_STAMPED', 'TWIST_STAMPED', 'VECTOR3_STAMPED', 'ROLES', 'TOPIC_FLAGS',
    'ROLE_TYPES', 'Sample', 'TopicSelection', 'TopicSource', 'select_topics', 'BagReader',
    'read_samples', 'count_messages', 'BagWriter',
]
