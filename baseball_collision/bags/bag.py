"""
Rosbags adapter: read tracker samples from bags, write bags. I/O only, no detection logic.

Reads ROS 2 bags (a bag directory, or a bare ``.mcap`` / ``.db3`` file) and ROS 1 ``.bag`` files
through :class:`rosbags.highlevel.AnyReader`; writes ROS 2 bags (MCAP or sqlite3, as a bag
directory or a bare file) and ROS 1 bags through the rosbags writers. Imports rosbags and the
standard library only (no rclpy), so it runs without a ROS installation.

Topic roles
    ``ball`` (``geometry_msgs/msg/PointStamped``, or ``PoseStamped`` whose position is the ball
    centre), ``bat_pose`` (``PoseStamped``), ``knob`` and ``tip`` (``PointStamped``). A bat is
    either one ``bat_pose`` topic or a ``knob`` + ``tip`` pair.

Topic auto-detection (:func:`select_topics`)
    A topic name is lower-cased and split into words on every non-alphanumeric character. A role
    is filled automatically only when exactly one topic of an accepted type matches it:

    - ``ball``: PointStamped or PoseStamped; a word contains ``ball`` and no word names a bat
      part (contains ``bat``, ``knob``, ``handle``, ``barrel``, or is ``tip`` or ``end``).
    - ``bat_pose``: PoseStamped; a word contains ``bat``.
    - ``knob``: PointStamped; a word contains ``knob`` or ``handle``.
    - ``tip``: PointStamped; a word contains ``barrel`` or a word is ``tip`` or ``end``.

    Topics named explicitly are taken as given (type-checked) and removed from the candidates of
    the other roles. When neither a bat pose nor knob/tip topics were named and the bag holds both
    one bat pose candidate and one knob/tip pair (``baseball-collision simulate`` writes both),
    the bat pose is used (or the points, with ``prefer_bat='points'``, e.g. a node parameter file
    with ``bat_input: points``), and :attr:`TopicSelection.note` says which topics were left
    out and the flags that pick them. Every selection error is one line naming the flag to pass
    (see :data:`TOPIC_FLAGS`).

Fast decoding
    Only the connections of the selected topics are read, so other topics are never
    deserialised. PointStamped and PoseStamped are decoded from the raw bytes with
    ``struct.unpack_from`` at offsets cached per frame_id: CDR (4-byte encapsulation header,
    int32 sec, uint32 nanosec, uint32 length incl. NUL, frame_id, padding to 8 bytes counted from
    the end of the encapsulation header, float64s) and ROS 1 (uint32 seq, uint32 secs, uint32
    nsecs, uint32 length, frame_id without NUL, float64s unaligned). Anything else (big-endian
    CDR, malformed data) falls back to ``AnyReader.deserialize``, which raises on corrupt data.
    ROS 1 seconds are read as uint32 as ROS 1 defines them (rosbags' deserialiser reads them as
    int32, so the two differ only for stamps after 2038).

Errors
    Every failure is a :class:`BagError` with a one-line message, raised ``from`` its cause,
    including errors met lazily while iterating (a corrupt chunk).
"""

from dataclasses import dataclass, field
import operator
import os
from pathlib import Path
import re
import shutil
import struct
import tempfile
from types import TracebackType
from typing import (
    Any, Callable, Dict, Iterable, Iterator, List, Mapping, NamedTuple, Optional, Sequence, Tuple,
    Type, Union)

from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
from rosbags.typesys import get_typestore, Stores

from ..errors import BagError

POINT_STAMPED = 'geometry_msgs/msg/PointStamped'
POSE_STAMPED = 'geometry_msgs/msg/PoseStamped'
TWIST_STAMPED = 'geometry_msgs/msg/TwistStamped'
VECTOR3_STAMPED = 'geometry_msgs/msg/Vector3Stamped'

ROLES = ('ball', 'bat_pose', 'knob', 'tip')
"""Topic roles, in the order of :class:`TopicSelection`'s fields."""

TOPIC_FLAGS = {
    'ball': '--ball-topic',
    'bat_pose': '--bat-pose-topic',
    'knob': '--knob-topic',
    'tip': '--tip-topic',
}
"""Command-line flag that names each role's topic; error messages refer to these."""

ROLE_TYPES = {
    'ball': (POINT_STAMPED, POSE_STAMPED),
    'bat_pose': (POSE_STAMPED,),
    'knob': (POINT_STAMPED,),
    'tip': (POINT_STAMPED,),
}
"""Message types accepted for each role."""

_HINTS = {
    'ball': "a PointStamped or PoseStamped with 'ball' in its name",
    'bat_pose': "a PoseStamped with 'bat' in its name",
    'knob': "a PointStamped with 'knob' or 'handle' in its name",
    'tip': "a PointStamped named with 'tip', 'end' or 'barrel'",
}
_NS_PER_S = 1_000_000_000
_FRAME_CACHE_LIMIT = 1024
_TOPIC_LIST_LIMIT = 20


class Sample(NamedTuple):
    """
    One tracker message, decoded.

    A NamedTuple rather than a dataclass: the reader makes one per message and a tuple is the
    cheapest typed record to build.

    :ivar role: ``'ball'``, ``'bat_pose'``, ``'knob'`` or ``'tip'``.
    :ivar stamp_ns: ``header.stamp`` as integer nanoseconds (``sec * 10**9 + nanosec``).
    :ivar frame_id: ``header.frame_id``.
    :ivar values: ``(x, y, z)`` metres for points and the ball (a ball pose gives its position);
        ``(px, py, pz, qx, qy, qz, qw)`` for a bat pose.
    :ivar log_time_ns: time the message was recorded in the bag (integer nanoseconds).
    """

    role: str
    stamp_ns: int
    frame_id: str
    values: Tuple[float, ...]
    log_time_ns: int


@dataclass(frozen=True)
class TopicSelection:
    """
    Which bag topic plays which role.

    :ivar ball: ball centre topic.
    :ivar ball_type: message type of the ball topic (PointStamped or PoseStamped).
    :ivar bat_pose: bat pose topic, or None when the bat is given as knob + tip.
    :ivar knob: knob end topic, or None when the bat is given as a pose.
    :ivar tip: barrel end topic, or None when the bat is given as a pose.
    :ivar note: one line on a choice made between candidates (a bat pose preferred to knob/tip
        points found too, or the reverse), naming the flags that choose otherwise; '' if none.
        Not part of equality.
    """

    ball: str
    ball_type: str = POINT_STAMPED
    bat_pose: Optional[str] = None
    knob: Optional[str] = None
    tip: Optional[str] = None
    note: str = field(default='', compare=False)

    def __post_init__(self) -> None:
        """
        Check the selection describes a ball and one bat.

        :raises BagError: no ball topic, a ball type that is not PointStamped or PoseStamped,
            neither or both of ``bat_pose`` and ``knob``/``tip``, only one of ``knob``/``tip``,
            or one topic in two roles.
        """
        if not self.ball:
            raise BagError(f'no ball topic given; pass {TOPIC_FLAGS["ball"]}')
        if self.ball_type not in ROLE_TYPES['ball']:
            raise BagError(
                f'ball topic type must be {POINT_STAMPED} or {POSE_STAMPED}, '
                f'got {self.ball_type}')
        points = (self.knob is not None, self.tip is not None)
        if self.bat_pose is not None and any(points):
            raise BagError(
                f'give either {TOPIC_FLAGS["bat_pose"]} or {TOPIC_FLAGS["knob"]} + '
                f'{TOPIC_FLAGS["tip"]}, not both')
        if self.bat_pose is None and not all(points):
            missing = 'tip' if points[0] else 'knob' if points[1] else 'bat_pose'
            raise BagError(f'no bat topic selected; pass {TOPIC_FLAGS[missing]}')
        names = list(self.topics.values())
        if len(set(names)) != len(names):
            raise BagError(f'one topic cannot play two roles: {self.topics}')

    @property
    def bat_mode(self) -> str:
        """Return ``'pose'`` for a bat pose topic, ``'points'`` for knob + tip topics."""
        return 'pose' if self.bat_pose is not None else 'points'

    @property
    def topics(self) -> Dict[str, str]:
        """Return the selected topics as ``{role: topic}`` (roles that are used only)."""
        return {role: getattr(self, role) for role in ROLES if getattr(self, role) is not None}

    def msgtype(self, role: str) -> str:
        """Return the message type the selection expects on a role's topic."""
        return self.ball_type if role == 'ball' else ROLE_TYPES[role][0]


TopicSource = Union[AnyReader, Mapping[str, str], Iterable[Any]]
"""An open AnyReader, ``{topic: msgtype}``, or rosbags connections (``.topic``, ``.msgtype``)."""


def _topic_types(source: TopicSource) -> Dict[str, Tuple[str, ...]]:
    """Return ``{topic: (msgtype, ...)}`` of a reader, mapping or connections, sorted by topic."""
    if isinstance(source, AnyReader):
        source = source.connections
    types: Dict[str, set] = {}
    if isinstance(source, Mapping):
        for topic, msgtype in source.items():
            types.setdefault(str(topic), set()).add(str(msgtype))
    else:
        for connection in source:
            types.setdefault(connection.topic, set()).add(connection.msgtype)
    return {topic: tuple(sorted(types[topic])) for topic in sorted(types)}


def _describe_topics(types: Mapping[str, Tuple[str, ...]]) -> str:
    """Return a one-line list of topics with their types (the first 20 of them)."""
    if not types:
        return 'the bag has no topics'
    items = [f'{topic} ({" | ".join(msgtypes)})' for topic, msgtypes in types.items()]
    more = len(items) - _TOPIC_LIST_LIMIT
    listed = ', '.join(items[:_TOPIC_LIST_LIMIT])
    return f'topics: {listed}' + (f', ... and {more} more' if more > 0 else '')


def _words(topic: str) -> List[str]:
    """Return the lower-case words of a topic name (split on non-alphanumerics)."""
    return [word for word in re.split(r'[^a-z0-9]+', topic.lower()) if word]


def _is_bat_part(words: Sequence[str]) -> bool:
    """Return True if a topic name mentions a bat or a bat end."""
    return any(
        'bat' in w or 'knob' in w or 'handle' in w or 'barrel' in w or w in ('tip', 'end')
        for w in words)


def _name_matches(role: str, topic: str) -> bool:
    """Return True if a topic's name fits a role (see the module's auto-detection rules)."""
    words = _words(topic)
    if role == 'ball':
        return any('ball' in w for w in words) and not _is_bat_part(words)
    if role == 'bat_pose':
        return any('bat' in w for w in words)
    if role == 'knob':
        return any('knob' in w or 'handle' in w for w in words)
    return (any('barrel' in w or w in ('tip', 'end') for w in words)
            and not any('knob' in w or 'handle' in w for w in words))


def _candidates(role: str, types: Mapping[str, Tuple[str, ...]],
                taken: Iterable[str]) -> List[str]:
    """Return the topics that could fill a role: accepted type, matching name, not taken."""
    taken = set(taken)
    return [
        topic for topic, msgtypes in types.items()
        if topic not in taken and len(msgtypes) == 1 and msgtypes[0] in ROLE_TYPES[role]
        and _name_matches(role, topic)]


def _check_given(role: str, topic: str, types: Mapping[str, Tuple[str, ...]]) -> str:
    """
    Return the message type of an explicitly named topic after checking it fits the role.

    :raises BagError: the topic is not in the bag, or has a type the role does not accept.
    """
    flag = TOPIC_FLAGS[role]
    if topic not in types:
        raise BagError(
            f"{flag} '{topic}' is not in the bag; {_describe_topics(types)}")
    msgtypes = types[topic]
    if len(msgtypes) != 1 or msgtypes[0] not in ROLE_TYPES[role]:
        wanted = ' or '.join(ROLE_TYPES[role])
        raise BagError(
            f"{flag} '{topic}' has type {' | '.join(msgtypes)}; {flag} needs {wanted}")
    return msgtypes[0]


def _pick_one(role: str, candidates: Sequence[str],
              types: Mapping[str, Tuple[str, ...]]) -> str:
    """
    Return the one candidate for a role.

    :raises BagError: no candidate, or several (listed).
    """
    flag = TOPIC_FLAGS[role]
    if not candidates:
        if role == 'bat_pose':
            flag = f'{flag}, or {TOPIC_FLAGS["knob"]} + {TOPIC_FLAGS["tip"]}'
        raise BagError(
            f'no {role} topic found ({_HINTS[role]}); pass {flag}; {_describe_topics(types)}')
    if len(candidates) > 1:
        raise BagError(
            f'several {role} topics: {", ".join(candidates)}; pass {flag} to choose one')
    return candidates[0]


def select_topics(source: TopicSource, ball: Optional[str] = None,
                  bat_pose: Optional[str] = None, knob: Optional[str] = None,
                  tip: Optional[str] = None, prefer_bat: str = 'pose') -> TopicSelection:
    """
    Choose the ball and bat topics of a bag: the names given, else auto-detection.

    See the module docstring for the detection rules. Names given explicitly always win; naming
    ``knob`` or ``tip`` selects the knob + tip bat (the other end is auto-detected), naming
    ``bat_pose`` selects the pose bat. With no bat topic named and both one bat pose and one
    knob/tip pair found, ``prefer_bat`` decides and the selection's ``note`` says so.

    :param source: an open :class:`AnyReader`, a mapping ``{topic: msgtype}``, or connections
        with ``.topic`` and ``.msgtype``.
    :param ball: ball topic, or None to detect it.
    :param bat_pose: bat pose topic, or None.
    :param knob: knob topic, or None.
    :param tip: tip topic, or None.
    :param prefer_bat: ``'pose'`` or ``'points'``: which bat to take when both are found.
    :returns: the selection.
    :raises BagError: a named topic is missing (the message lists the bag's topics) or has the
        wrong type; no candidate or several candidates for a role. The message names the flag
        to pass.
    :raises ValueError: ``prefer_bat`` is neither ``'pose'`` nor ``'points'``.
    """
    if prefer_bat not in ('pose', 'points'):
        raise ValueError(f"prefer_bat must be 'pose' or 'points', got {prefer_bat!r}")
    types = _topic_types(source)
    given = {'ball': ball, 'bat_pose': bat_pose, 'knob': knob, 'tip': tip}
    chosen: Dict[str, str] = {}
    chosen_types: Dict[str, str] = {}
    for role, topic in given.items():
        if topic is not None:
            chosen_types[role] = _check_given(role, topic, types)
            chosen[role] = topic
    if bat_pose is not None and (knob is not None or tip is not None):
        raise BagError(
            f'give either {TOPIC_FLAGS["bat_pose"]} or {TOPIC_FLAGS["knob"]} + '
            f'{TOPIC_FLAGS["tip"]}, not both')

    def taken() -> List[str]:
        return list(chosen.values())

    if 'ball' not in chosen:
        chosen['ball'] = _pick_one('ball', _candidates('ball', types, taken()), types)
        chosen_types['ball'] = types[chosen['ball']][0]
    note = ''
    if bat_pose is None and knob is None and tip is None:
        poses = _candidates('bat_pose', types, taken())
        knobs = _candidates('knob', types, taken())
        tips = _candidates('tip', types, taken())
        both = len(poses) == 1 and len(knobs) == 1 and len(tips) == 1
        if both:
            note = _both_note(prefer_bat, poses[0], knobs[0], tips[0])
        if (poses or not (knobs or tips)) and not (both and prefer_bat == 'points'):
            chosen['bat_pose'] = _pick_one('bat_pose', poses, types)
        else:
            chosen['knob'] = _pick_one('knob', knobs, types)
            chosen['tip'] = _pick_one('tip', tips, types)
    elif bat_pose is None:
        for role in ('knob', 'tip'):
            if role not in chosen:
                chosen[role] = _pick_one(role, _candidates(role, types, taken()), types)
    return TopicSelection(
        ball=chosen['ball'], ball_type=chosen_types['ball'], bat_pose=chosen.get('bat_pose'),
        knob=chosen.get('knob'), tip=chosen.get('tip'), note=note)


def _both_note(prefer_bat: str, pose: str, knob: str, tip: str) -> str:
    """Return the note on a bag holding both a bat pose and knob/tip points."""
    if prefer_bat == 'pose':
        return (f'bat pose {pose} used; the bag also has knob/tip points {knob}, {tip} '
                f'(pass {TOPIC_FLAGS["knob"]} + {TOPIC_FLAGS["tip"]} to use them)')
    return (f'bat knob/tip points {knob}, {tip} used; the bag also has a bat pose {pose} '
            f'(pass {TOPIC_FLAGS["bat_pose"]} to use it)')


def _check_selection(selection: TopicSelection, types: Mapping[str, Tuple[str, ...]]) -> None:
    """
    Check that a ready-made selection fits a bag: topics present with the expected types.

    :raises BagError: a topic missing or of another type than the selection says.
    """
    for role, topic in selection.topics.items():
        msgtype = _check_given(role, topic, types)
        if msgtype != selection.msgtype(role):
            raise BagError(
                f"{TOPIC_FLAGS[role]} '{topic}' has type {msgtype} in this bag, "
                f'the selection expects {selection.msgtype(role)}')


def _first_line(error: BaseException) -> str:
    """Return the first line of an error's message, or its type name if it has none."""
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__


_JAZZY: Optional[Any] = None
_NOETIC: Optional[Any] = None


def _jazzy() -> Any:
    """Return the ROS 2 Jazzy typestore (built once)."""
    global _JAZZY
    if _JAZZY is None:
        _JAZZY = get_typestore(Stores.ROS2_JAZZY)
    return _JAZZY


def _noetic() -> Any:
    """Return the ROS 1 Noetic typestore (built once)."""
    global _NOETIC
    if _NOETIC is None:
        _NOETIC = get_typestore(Stores.ROS1_NOETIC)
    return _NOETIC


# Raw layouts. In both CDR and ROS 1, bytes 0-3 are the CDR encapsulation header (ROS 1: seq),
# then sec, nanosec and the frame_id length sit at bytes 4, 8 and 12, and frame_id starts at 16.
_CDR_HEAD = struct.Struct('<BBxxiII').unpack_from
_ROS1_HEAD = struct.Struct('<BBxxIII').unpack_from


def _cdr_frame(field: bytes) -> Tuple[str, int]:
    """
    Return ``(frame_id, offset of the first float64)`` for a CDR frame_id field.

    :param field: bytes 12 onwards up to the end of the string: uint32 length (including the
        terminating NUL), then the string and its NUL.
    :raises ValueError: no terminating NUL, or not UTF-8.
    """
    if len(field) < 5 or field[-1] != 0:
        raise ValueError('CDR string without terminating NUL')
    end = 12 + len(field)
    return bytes(field[4:-1]).decode(), 4 + ((end - 4 + 7) & ~7)


def _ros1_frame(field: bytes) -> Tuple[str, int]:
    """
    Return ``(frame_id, offset of the first float64)`` for a ROS 1 frame_id field.

    :param field: bytes 12 onwards up to the end of the string: uint32 length, then the string.
    :raises ValueError: not UTF-8.
    """
    return bytes(field[4:]).decode(), 12 + len(field)


class _Route:
    """
    How to decode one connection's raw messages (mutable: it remembers the last frame_id).

    :ivar field: the last frame_id field seen (length + string bytes, see :func:`_cdr_frame`).
    :ivar hit: ``(frame_id, float64 offset)`` for ``field``.
    :ivar cache: every frame_id field seen (bounded), for topics that alternate frames.
    """

    __slots__ = ('role', 'cdr', 'head', 'values', 'frame', 'field', 'hit', 'cache', 'msgtype')

    def __init__(self, role: str, cdr: bool, floats: int, msgtype: str) -> None:
        self.role = role
        self.cdr = cdr
        self.head = _CDR_HEAD if cdr else _ROS1_HEAD
        self.values = struct.Struct(f'<{floats}d').unpack_from
        self.frame = _cdr_frame if cdr else _ros1_frame
        # Before the first lookup: a length of 2**32 - 1 that, if ever matched by a malformed
        # message, points the float64s out of range so the message takes the checked slow path.
        self.field = b'\xff\xff\xff\xff'
        self.hit: Tuple[str, int] = ('', 2**62)
        self.cache: Dict[bytes, Tuple[str, int]] = {}
        self.msgtype = msgtype

    def lookup(self, field: bytes) -> Tuple[str, int]:
        """
        Return ``(frame_id, float64 offset)`` for a frame_id field and remember it.

        :raises ValueError: a malformed field.
        """
        hit = self.cache.get(field)
        if hit is None:
            if int.from_bytes(field[:4], 'little') != len(field) - 4:
                raise ValueError('frame_id runs past the end of the message')
            hit = self.frame(field)
            if len(self.cache) >= _FRAME_CACHE_LIMIT:
                self.cache.clear()
            self.cache[field] = hit
        self.field = field
        self.hit = hit
        return hit


def _values_slow(role: str, message: Any) -> Tuple[float, ...]:
    """Return a deserialised message's values tuple for its role."""
    if hasattr(message, 'pose'):
        p, q = message.pose.position, message.pose.orientation
        if role == 'ball':
            return (float(p.x), float(p.y), float(p.z))
        return (float(p.x), float(p.y), float(p.z),
                float(q.x), float(q.y), float(q.z), float(q.w))
    p = message.point
    return (float(p.x), float(p.y), float(p.z))


class BagReader:
    """
    Read ball and bat samples from a bag, streaming, in log-time order across topics.

    Use as a context manager::

        with BagReader('run.mcap') as bag:
            total = bag.message_count          # for a progress bar
            for sample in bag.samples():
                ...

    :param path: ROS 2 bag directory, bare ``.mcap`` or ``.db3`` file, or ROS 1 ``.bag`` file.
    :param selection: topics to read; None to select them with :func:`select_topics`.
    :param ball: explicit ball topic (only without ``selection``).
    :param bat_pose: explicit bat pose topic (only without ``selection``).
    :param knob: explicit knob topic (only without ``selection``).
    :param tip: explicit tip topic (only without ``selection``).
    :param prefer_bat: ``'pose'`` or ``'points'``: the bat to auto-select when the bag has both
        (see :func:`select_topics`).
    :raises ValueError: both a selection and topic names given.
    """

    def __init__(self, path: Union[str, os.PathLike], selection: Optional[TopicSelection] = None,
                 *, ball: Optional[str] = None, bat_pose: Optional[str] = None,
                 knob: Optional[str] = None, tip: Optional[str] = None,
                 prefer_bat: str = 'pose') -> None:
        overrides = {'ball': ball, 'bat_pose': bat_pose, 'knob': knob, 'tip': tip}
        if selection is not None and any(v is not None for v in overrides.values()):
            raise ValueError('pass either a TopicSelection or topic names, not both')
        self.path = Path(path)
        self._given = selection
        self._overrides = overrides
        self._prefer_bat = prefer_bat
        self._reader: Optional[AnyReader] = None
        self._selection: Optional[TopicSelection] = None
        self._connections: List[Any] = []
        self._routes: Dict[int, _Route] = {}
        self._types: Dict[str, Tuple[str, ...]] = {}

    def open(self) -> None:  # noqa: A003 - the rosbags reader/writer name
        """
        Open the bag and select its topics.

        :raises BagError: path missing, not a bag, unreadable or corrupt, no messages, or topics
            that cannot be selected.
        """
        if self._reader is not None:
            raise BagError(f'bag {self.path} is already open')
        if not self.path.exists():
            raise BagError(f'bag not found: {self.path}')
        if self.path.is_dir() and not (self.path / 'metadata.yaml').is_file():
            raise BagError(f'not a ROS 2 bag directory (no metadata.yaml): {self.path}')
        if not self.path.is_dir() and self.path.suffix not in ('.mcap', '.db3', '.bag'):
            raise BagError(
                f'not a bag: {self.path} (expected a bag directory or a .mcap, .db3 or .bag file)')
        try:
            reader = AnyReader([self.path], default_typestore=_jazzy())
            reader.open()
        except Exception as error:
            raise BagError(f'cannot read bag {self.path}: {_first_line(error)}') from error
        try:
            self._setup(reader)
        except BaseException:
            try:
                reader.close()
            except Exception:  # noqa: S110 - the first error is the one to report
                pass
            raise
        self._reader = reader

    def _setup(self, reader: AnyReader) -> None:
        """
        Select topics and prepare the decoders of an open reader.

        :raises BagError: empty bag, or topics that cannot be selected.
        """
        try:
            total = reader.message_count
            connections = list(reader.connections)
        except Exception as error:
            raise BagError(f'cannot read bag {self.path}: {_first_line(error)}') from error
        self._types = _topic_types(connections)
        if total == 0:
            raise BagError(f'bag {self.path} contains no messages')
        if self._given is None:
            selection = select_topics(connections, **self._overrides,
                                      prefer_bat=self._prefer_bat)
        else:
            selection = self._given
            _check_selection(selection, self._types)
        role_of = {topic: role for role, topic in selection.topics.items()}
        chosen = [c for c in connections if c.topic in role_of]
        for role, topic in selection.topics.items():
            if sum(max(int(c.msgcount), 0) for c in chosen if c.topic == topic) == 0:
                raise BagError(
                    f"{TOPIC_FLAGS[role]} '{topic}' has no messages in bag {self.path}")
        routes = {}
        for connection in chosen:
            role = role_of[connection.topic]
            # A ball pose is read as its position: the first 3 float64s of a Pose.
            routes[id(connection)] = _Route(
                role, reader.is2, 7 if role == 'bat_pose' else 3, connection.msgtype)
        self._selection = selection
        self._connections = chosen
        self._routes = routes

    def close(self) -> None:
        """Close the bag (idempotent)."""
        reader, self._reader = self._reader, None
        if reader is not None:
            try:
                reader.close()
            except Exception:  # noqa: S110 - nothing useful to report on close
                pass

    def __enter__(self) -> 'BagReader':
        """
        Open the bag.

        :raises BagError: see :meth:`open`.
        """
        self.open()
        return self

    def __exit__(self, exc_type: Optional[Type[BaseException]],
                 exc_value: Optional[BaseException],
                 traceback: Optional[TracebackType]) -> None:
        """Close the bag."""
        self.close()

    def _open_reader(self) -> AnyReader:
        """
        Return the open AnyReader.

        :raises BagError: the bag is not open.
        """
        if self._reader is None:
            raise BagError(f'bag {self.path} is not open')
        return self._reader

    @property
    def selection(self) -> TopicSelection:
        """
        Return the selected topics.

        :raises BagError: the bag is not open.
        """
        self._open_reader()
        assert self._selection is not None
        return self._selection

    @property
    def topics(self) -> Dict[str, str]:
        """
        Return all topics of the bag as ``{topic: msgtype}`` (types joined by `` | `` if mixed).

        :raises BagError: the bag is not open.
        """
        self._open_reader()
        return {topic: ' | '.join(msgtypes) for topic, msgtypes in self._types.items()}

    @property
    def message_count(self) -> int:
        """
        Return the number of messages on the selected topics (what :meth:`samples` yields).

        From the bag's index/metadata, no scan.

        :raises BagError: the bag is not open.
        """
        self._open_reader()
        return sum(max(int(c.msgcount), 0) for c in self._connections)

    @property
    def start_time_ns(self) -> int:
        """
        Return the log time of the bag's first message (integer nanoseconds).

        :raises BagError: the bag is not open.
        """
        return int(self._open_reader().start_time)

    @property
    def end_time_ns(self) -> int:
        """
        Return the log time just after the bag's last message (integer nanoseconds).

        :raises BagError: the bag is not open.
        """
        return int(self._open_reader().end_time)

    def samples(self) -> Iterator[Sample]:
        """
        Yield the selected topics' messages as samples, in the bag's log-time order.

        Streams (memory does not grow with the bag). Only the selected topics' connections are
        read.

        :returns: an iterator of :class:`Sample`.
        :raises BagError: the bag is not open, or is corrupt (raised while iterating).
        """
        reader = self._open_reader()
        return self._samples(reader)

    def _samples(self, reader: AnyReader) -> Iterator[Sample]:
        """Yield samples (the generator behind :meth:`samples`)."""
        routes = self._routes
        new = tuple.__new__
        expected = self.message_count
        count = 0
        try:
            for connection, log_time, raw in reader.messages(connections=self._connections):
                count += 1
                route = routes[id(connection)]
                try:
                    b0, b1, sec, nanosec, length = route.head(raw, 0)
                    if route.cdr and (b0 or b1 != 1):
                        raise ValueError('not little-endian CDR')
                    if raw.startswith(route.field, 12):
                        frame_id, offset = route.hit
                    else:
                        frame_id, offset = route.lookup(raw[12:16 + length])
                    values = route.values(raw, offset)
                    stamp = sec * 1_000_000_000 + nanosec
                except (ValueError, struct.error, AttributeError):
                    stamp, frame_id, values = self._slow(reader, route, raw)
                yield new(Sample, (route.role, stamp, frame_id, values, log_time))
        except BagError:
            raise
        except Exception as error:
            raise BagError(f'cannot read bag {self.path}: {_first_line(error)}') from error
        if count < expected:
            # rosbags skips records it cannot place in a damaged chunk without an error: the
            # bag's own index still counts them
            raise BagError(f'bag {self.path} is damaged: read {count} of the {expected} '
                           'messages its index lists on the selected topics')

    def _slow(self, reader: AnyReader, route: _Route,
              raw: bytes) -> Tuple[int, str, Tuple[float, ...]]:
        """
        Decode one message with the rosbags deserialiser (big-endian or unusual data).

        :raises BagError: the message cannot be deserialised (corrupt); names the bag.
        """
        try:
            message: Any = reader.deserialize(raw, route.msgtype)
            stamp = message.header.stamp
            stamp_ns = int(stamp.sec) * _NS_PER_S + int(stamp.nanosec)
            return stamp_ns, str(message.header.frame_id), _values_slow(route.role, message)
        except Exception as error:
            raise BagError(
                f'corrupt {route.msgtype} message on the {route.role} topic of bag '
                f'{self.path}: {_first_line(error)}') from error


def read_samples(path: Union[str, os.PathLike], selection: Optional[TopicSelection] = None,
                 **overrides: Optional[str]) -> Iterator[Sample]:
    """
    Yield the ball and bat samples of a bag, in log-time order (see :class:`BagReader`).

    The bag is opened on the first ``next()`` and closed when the iterator is exhausted or
    closed. Use :class:`BagReader` to get the selection and message count first.

    :param path: ROS 2 bag directory, bare ``.mcap``/``.db3`` file, or ROS 1 ``.bag`` file.
    :param selection: topics to read; None to select them with :func:`select_topics`.
    :param overrides: explicit topics ``ball``, ``bat_pose``, ``knob``, ``tip``.
    :returns: an iterator of :class:`Sample`.
    :raises BagError: see :meth:`BagReader.open` and :meth:`BagReader.samples`.
    :raises TypeError: an unknown override name.
    """
    unknown = set(overrides) - set(ROLES)
    if unknown:
        raise TypeError(f'unknown topic roles: {", ".join(sorted(unknown))}')
    with BagReader(path, selection, **overrides) as bag:
        yield from bag.samples()


def count_messages(path: Union[str, os.PathLike], selection: Optional[TopicSelection] = None,
                   **overrides: Optional[str]) -> int:
    """
    Return how many samples :func:`read_samples` will yield (from the bag index, no scan).

    :raises BagError: see :meth:`BagReader.open`.
    """
    with BagReader(path, selection, **overrides) as bag:
        return bag.message_count


# ---------------------------------------------------------------------------------------------
# Writing

_STORAGES = ('mcap', 'sqlite3', 'rosbag1')
_FLOAT_COUNTS = {POINT_STAMPED: 3, POSE_STAMPED: 7, TWIST_STAMPED: 6, VECTOR3_STAMPED: 3}


def _layout(path: Path, storage: Optional[str]) -> Tuple[str, bool]:
    """
    Return ``(storage, bare_file)`` for an output path and a requested storage.

    ``.bag`` is ROS 1; ``.mcap`` and ``.db3`` are bare ROS 2 storage files; any other name is a
    ROS 2 bag directory (MCAP unless ``storage='sqlite3'``).

    :raises BagError: an unknown storage, or one that contradicts the file name.
    """
    suffix = path.suffix.lower()
    by_suffix = {'.bag': 'rosbag1', '.mcap': 'mcap', '.db3': 'sqlite3'}.get(suffix)
    if storage is not None and storage not in _STORAGES:
        raise BagError(f"unknown bag storage '{storage}'; use one of {', '.join(_STORAGES)}")
    if by_suffix is not None and storage is not None and storage != by_suffix:
        raise BagError(f"output {path} has a {suffix} name but storage '{storage}' was asked")
    if storage == 'rosbag1' and by_suffix is None:
        raise BagError(f'a ROS 1 bag needs a .bag file name, got {path}')
    if by_suffix is not None:
        return by_suffix, by_suffix != 'rosbag1'
    return storage or 'mcap', False


class BagWriter:
    """
    Write a bag atomically: into a hidden temporary next to ``path``, renamed on success.

    The temporary is a directory ``.<name>.<random>.partial`` beside ``path`` (same file system,
    so the final rename is atomic; a finished file is hard-linked into place, which never
    replaces an existing file). It is removed on success, on :meth:`abort` and on an exception
    inside the ``with`` block; only a killed process leaves it behind.

    Use as a context manager; on an exception inside the ``with`` block nothing is left behind::

        with BagWriter('out.mcap') as bag:
            bag.write_point('/ball', stamp_ns, 'world', (x, y, z))

    Output kinds, by ``path``: ``*.bag`` a ROS 1 bag; ``*.mcap`` / ``*.db3`` a bare ROS 2
    storage file (no metadata.yaml; rosbags reads it directly); anything else a ROS 2 bag
    directory (``metadata.yaml`` + storage file) in ``storage`` (default ``'mcap'``).
    Messages are serialised with fixed ``struct`` layouts (CDR little-endian, or ROS 1).

    :param path: output path; must not exist, its parent directory must.
    :param storage: ``'mcap'``, ``'sqlite3'`` or ``'rosbag1'``; None to follow the file name.
    :raises BagError: the output exists, its directory is missing, or storage and name clash.
    """

    def __init__(self, path: Union[str, os.PathLike], storage: Optional[str] = None) -> None:
        self.path = Path(path)
        self.storage, self.bare_file = _layout(self.path, storage)
        self._check_target()
        if not self.path.parent.is_dir():
            raise BagError(f'output directory {self.path.parent} does not exist')
        self._ros1 = self.storage == 'rosbag1'
        self._tmpdir: Optional[Path] = None
        self._inner = self.path
        self._writer: Any = None
        self._connections: Dict[str, Any] = {}
        self._types: Dict[str, str] = {}
        self._seq: Dict[str, int] = {}
        self._packers: Dict[Tuple[str, int], Callable[..., bytes]] = {}
        self._max_sec = 2**32 - 1 if self._ros1 else 2**31 - 1
        self._min_sec = 0 if self._ros1 else -2**31

    def _check_target(self) -> None:
        """
        Refuse an output path that exists.

        :raises BagError: the path exists (or is a dangling symlink).
        """
        if self.path.exists() or self.path.is_symlink():
            raise BagError(f'output {self.path} exists already; not overwriting')

    @property
    def typestore(self) -> Any:
        """Return the rosbags typestore to build :meth:`write_message` messages from."""
        return _noetic() if self._ros1 else _jazzy()

    def open(self) -> None:  # noqa: A003 - the rosbags reader/writer name
        """
        Create the temporary output and open the rosbags writer.

        :raises BagError: already open, the output appeared meanwhile, or it cannot be created.
        """
        if self._writer is not None:
            raise BagError(f'bag writer for {self.path} is already open')
        self._check_target()
        try:
            self._tmpdir = Path(tempfile.mkdtemp(
                prefix=f'.{self.path.name}.', suffix='.partial', dir=self.path.parent))
            inner = self._tmpdir / ('bag' if self.bare_file else self.path.name)
            if self._ros1:
                writer: Any = Writer1(inner)
            else:
                plugin = StoragePlugin.MCAP if self.storage == 'mcap' else StoragePlugin.SQLITE3
                writer = Writer2(inner, version=9, storage_plugin=plugin)
            writer.open()
        except Exception as error:
            self._remove_tmp()
            raise BagError(f'cannot create bag {self.path}: {_first_line(error)}') from error
        self._inner = inner
        self._writer = writer

    def _remove_tmp(self) -> None:
        """Delete the temporary output, if any."""
        tmpdir, self._tmpdir = self._tmpdir, None
        if tmpdir is not None:
            shutil.rmtree(tmpdir, ignore_errors=True)

    def close(self) -> None:
        """
        Finish the bag and move it into place.

        :raises BagError: the bag cannot be finished, or the output path appeared meanwhile
            (the temporary output is removed in both cases).
        """
        writer, self._writer = self._writer, None
        if writer is None:
            return
        try:
            writer.close()
            if self.bare_file:
                suffix = '.mcap' if self.storage == 'mcap' else '.db3'
                self._place_file(self._inner / f'bag{suffix}')
            elif self._ros1:
                self._place_file(self._inner)
            else:
                self._check_target()
                os.rename(self._inner, self.path)
        except BagError:
            raise
        except Exception as error:
            raise BagError(f'cannot write bag {self.path}: {_first_line(error)}') from error
        finally:
            self._remove_tmp()

    def _place_file(self, source: Path) -> None:
        """
        Move a finished file to the output path without ever replacing an existing file.

        :raises BagError: the output path exists.
        """
        try:
            os.link(source, self.path)
        except FileExistsError as error:
            raise BagError(f'output {self.path} exists already; not overwriting') from error
        except OSError:  # no hard links on this file system
            self._check_target()
            os.rename(source, self.path)

    def abort(self) -> None:
        """Stop writing and delete the temporary output (idempotent)."""
        writer, self._writer = self._writer, None
        if writer is not None:
            try:
                writer.abort()
            except Exception:  # noqa: S110 - the files are deleted next anyway
                pass
        self._remove_tmp()

    def __enter__(self) -> 'BagWriter':
        """
        Open the writer.

        :raises BagError: see :meth:`open`.
        """
        self.open()
        return self

    def __exit__(self, exc_type: Optional[Type[BaseException]],
                 exc_value: Optional[BaseException],
                 traceback: Optional[TracebackType]) -> None:
        """
        Finish the bag, or on an exception delete the temporary output and let it propagate.

        :raises BagError: see :meth:`close`.
        """
        if exc_type is None:
            self.close()
        else:
            self.abort()

    def add_topic(self, name: str, msgtype: str) -> None:
        """
        Declare a topic (writing to an undeclared topic declares it with the written type).

        :param name: topic name, e.g. ``'/ball'``.
        :param msgtype: message type, e.g. ``'geometry_msgs/msg/PointStamped'``.
        :raises BagError: the writer is not open, the type is unknown, or the topic was declared
            with another type.
        """
        if self._writer is None:
            raise BagError(f'bag writer for {self.path} is not open')
        known = self._types.get(name)
        if known is not None:
            if known != msgtype:
                raise BagError(f"topic '{name}' is already declared as {known}, not {msgtype}")
            return
        if msgtype not in self.typestore.types:
            raise BagError(f"unknown message type '{msgtype}' for topic '{name}'")
        try:
            connection = self._writer.add_connection(name, msgtype, typestore=self.typestore)
        except Exception as error:
            raise BagError(f"cannot add topic '{name}': {_first_line(error)}") from error
        self._connections[name] = connection
        self._types[name] = msgtype
        self._seq[name] = 0

    def _write_raw(self, topic: str, msgtype: str, log_time_ns: int, data: bytes) -> None:
        """
        Write serialised data to a topic, declaring it first if needed.

        :raises BagError: not open, a clashing type, a bad log time, or a writer failure.
        """
        if self._types.get(topic) != msgtype:
            self.add_topic(topic, msgtype)
        try:
            log_time_ns = operator.index(log_time_ns)
        except TypeError:
            log_time_ns = -1
        if log_time_ns < 0:
            raise BagError(f'log time must be a non-negative integer of ns, got {log_time_ns!r}')
        try:
            self._writer.write(self._connections[topic], log_time_ns, data)
        except Exception as error:
            raise BagError(f"cannot write to '{topic}': {_first_line(error)}") from error

    def _stamped(self, topic: str, msgtype: str, stamp_ns: int, frame_id: str,
                 floats: Sequence[float], log_time_ns: Optional[int]) -> None:
        """
        Serialise a header + float64 message (fixed layout) and write it.

        :raises BagError: see the public ``write_*`` methods.
        """
        try:
            stamp_ns = operator.index(stamp_ns)
        except TypeError as error:
            raise BagError(f'stamp must be integer nanoseconds, got {stamp_ns!r}') from error
        sec, nanosec = divmod(stamp_ns, _NS_PER_S)
        if not self._min_sec <= sec <= self._max_sec:
            raise BagError(f'stamp {stamp_ns} ns is out of range for this bag format')
        count = _FLOAT_COUNTS[msgtype]
        packer = self._packers.get((frame_id, count))
        if packer is None:
            packer = self._packer(frame_id, count)
        try:
            if self._ros1:
                seq = self._seq.get(topic, 0)
                self._seq[topic] = (seq + 1) & 0xFFFFFFFF
                data = packer(seq, sec, nanosec, *floats)
            else:
                data = packer(sec, nanosec, *floats)
        except (struct.error, TypeError) as error:
            raise BagError(
                f"cannot write {msgtype} to '{topic}': expected {count} numbers, "
                f'got {floats!r}') from error
        self._write_raw(topic, msgtype, stamp_ns if log_time_ns is None else log_time_ns, data)

    def _packer(self, frame_id: str, count: int) -> Callable[..., bytes]:
        """
        Return a packer for a frame_id and number of float64s (cached).

        :raises BagError: frame_id is not a string or contains a NUL character.
        """
        if not isinstance(frame_id, str) or '\x00' in frame_id:
            raise BagError(f'frame_id must be a string without NUL, got {frame_id!r}')
        encoded = frame_id.encode()
        size = len(encoded)
        if self._ros1:
            layout = struct.Struct(f'<IIII{size}s{count}d')

            def pack(seq: int, sec: int, nanosec: int, *floats: float) -> bytes:
                return layout.pack(seq, sec, nanosec, size, encoded, *floats)
        else:
            pad = (-(12 + size + 1)) % 8
            layout = struct.Struct(f'<4siII{size + 1}s{pad}x{count}d')
            terminated = encoded + b'\x00'

            def pack(sec: int, nanosec: int, *floats: float) -> bytes:  # type: ignore[misc]
                return layout.pack(b'\x00\x01\x00\x00', sec, nanosec, size + 1, terminated,
                                   *floats)
        if len(self._packers) >= _FRAME_CACHE_LIMIT:
            self._packers.clear()
        self._packers[(frame_id, count)] = pack
        return pack

    def write_point(self, topic: str, stamp_ns: int, frame_id: str, xyz: Sequence[float],
                    log_time_ns: Optional[int] = None) -> None:
        """
        Write a ``geometry_msgs/msg/PointStamped``.

        :param topic: topic name.
        :param stamp_ns: ``header.stamp`` in integer nanoseconds.
        :param frame_id: ``header.frame_id``.
        :param xyz: point (metres).
        :param log_time_ns: bag log time in integer nanoseconds; None for ``stamp_ns``.
        :raises BagError: not open, bad stamp/values/frame_id, or a clashing topic type.
        """
        self._stamped(topic, POINT_STAMPED, stamp_ns, frame_id, xyz, log_time_ns)

    def write_pose(self, topic: str, stamp_ns: int, frame_id: str, position: Sequence[float],
                   quaternion_xyzw: Sequence[float], log_time_ns: Optional[int] = None) -> None:
        """
        Write a ``geometry_msgs/msg/PoseStamped``.

        :param position: position (metres).
        :param quaternion_xyzw: orientation ``(x, y, z, w)``, written as given.
        :raises BagError: see :meth:`write_point`.
        """
        self._stamped(topic, POSE_STAMPED, stamp_ns, frame_id,
                      (*position, *quaternion_xyzw), log_time_ns)

    def write_twist(self, topic: str, stamp_ns: int, frame_id: str, linear: Sequence[float],
                    angular: Sequence[float], log_time_ns: Optional[int] = None) -> None:
        """
        Write a ``geometry_msgs/msg/TwistStamped``.

        :param linear: linear velocity (m/s).
        :param angular: angular velocity (rad/s).
        :raises BagError: see :meth:`write_point`.
        """
        self._stamped(topic, TWIST_STAMPED, stamp_ns, frame_id, (*linear, *angular),
                      log_time_ns)

    def write_vector3(self, topic: str, stamp_ns: int, frame_id: str, vector: Sequence[float],
                      log_time_ns: Optional[int] = None) -> None:
        """
        Write a ``geometry_msgs/msg/Vector3Stamped``.

        :param vector: the vector (units of the caller's choosing, e.g. m/s).
        :raises BagError: see :meth:`write_point`.
        """
        self._stamped(topic, VECTOR3_STAMPED, stamp_ns, frame_id, vector, log_time_ns)

    def write_message(self, topic: str, message: Any, log_time_ns: int) -> None:
        """
        Write any message built from :attr:`typestore` (serialised by rosbags).

        :param message: a typestore message object (its type is ``message.__msgtype__``).
        :param log_time_ns: bag log time in integer nanoseconds.
        :raises BagError: not open, a clashing topic type, or a message that cannot be
            serialised.
        """
        msgtype = getattr(message, '__msgtype__', None)
        if not isinstance(msgtype, str):
            raise BagError(f"cannot write {type(message).__name__} to '{topic}': not a message")
        try:
            if self._ros1:
                data = self.typestore.serialize_ros1(message, msgtype)
            else:
                data = self.typestore.serialize_cdr(message, msgtype, little_endian=True)
        except Exception as error:
            raise BagError(
                f"cannot serialise {msgtype} for '{topic}': {_first_line(error)}") from error
        self._write_raw(topic, msgtype, log_time_ns, bytes(data))
