"""
Bag files through rosbags: the only place rosbags is imported.

One module per concern, like rosbags' own layout: :mod:`.selection` (which topic plays which
role), :mod:`.decode` (tracker messages at fixed offsets), :mod:`.reader` (samples from a bag),
:mod:`.raw` (any bag's messages as CDR bytes, for a replay), :mod:`.plans` (an arm's bat plans
recorded on their topic), :mod:`.writer` (bags out, staged all-or-nothing), :mod:`.messages`
(the node's views as typestore messages, QoS profiles);
:mod:`.common` holds the typestores and opening a bag, :mod:`.names` the message type names
and topic roles (no rosbags). Import the names below from here: each is loaded when first
used (PEP 562), so ``from baseball_collision.bags import TOPIC_FLAGS`` works
without rosbags installed, and the rest imports rosbags on first use.
"""

import importlib
from typing import Any

_WHERE = {
    'names': ('PATH', 'POINT_STAMPED', 'POSE_STAMPED', 'TWIST_STAMPED', 'VECTOR3_STAMPED',
              'ROLES', 'TOPIC_FLAGS', 'ROLE_TYPES'),
    'plans': ('plan_arrays', 'PlanMessage', 'read_plans'),
    'decode': ('Sample', 'SampleChunk'),
    'messages': ('DIAGNOSTIC_ARRAY', 'health_message', 'MARKER_ARRAY', 'path_message',
                 'qos_profile', 'scene_message', 'STRING', 'text_message'),
    'raw': ('RawBag', 'RawMessage', 'RawTopic'),
    'reader': ('BagReader', 'count_messages', 'read_samples'),
    'selection': ('select_topics', 'TopicSelection', 'TopicSource'),
    'writer': ('BagWriter',),
}
_MODULE_OF = {name: module for module, names in _WHERE.items() for name in names}

__all__ = sorted(_MODULE_OF)


def __getattr__(name: str) -> Any:
    """Return a public name, importing its module on first use (PEP 562)."""
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'baseball_collision.bags' has no attribute '{name}'")
    value = getattr(importlib.import_module(f'.{module}', __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list:
    """Return the public names (for completion)."""
    return sorted(set(globals()) | set(__all__))
