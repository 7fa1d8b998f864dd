"""
Bag files through rosbags: the only place rosbags is imported.

One module per concern, like rosbags' own layout: :mod:`.selection` (which topic plays which
role), :mod:`.decode` (tracker messages at fixed offsets), :mod:`.reader` (samples from a bag),
:mod:`.raw` (any bag's messages as CDR bytes, for a replay), :mod:`.writer` (bags out, staged
all-or-nothing); :mod:`.common` holds the type names, the typestores and opening a bag.
Import the names below from here.
"""

from .common import POINT_STAMPED, POSE_STAMPED, TWIST_STAMPED, VECTOR3_STAMPED
from .decode import Sample
from .raw import RawBag, RawMessage, RawTopic
from .reader import BagReader, count_messages, read_samples
from .selection import (
    ROLE_TYPES, ROLES, select_topics, TOPIC_FLAGS, TopicSelection, TopicSource)
from .writer import BagWriter

__all__ = [
    'POINT_STAMPED', 'POSE_STAMPED', 'TWIST_STAMPED', 'VECTOR3_STAMPED', 'ROLES', 'TOPIC_FLAGS',
    'ROLE_TYPES', 'Sample', 'TopicSelection', 'TopicSource', 'select_topics', 'BagReader',
    'read_samples', 'count_messages', 'BagWriter', 'RawBag', 'RawMessage', 'RawTopic',
]
