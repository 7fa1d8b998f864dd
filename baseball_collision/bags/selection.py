"""
Which bag topic plays which role: topic roles, auto-detection and explicit choices.

Topic roles
    ``ball`` (``geometry_msgs/msg/PointStamped``, or ``PoseStamped`` whose position is the ball
    centre), ``bat_pose`` (``PoseStamped``), ``knob`` and ``tip`` (``PointStamped``). A bat is
    either one ``bat_pose`` topic or a ``knob`` + ``tip`` pair.

Topic auto-detection (:func:`select_topics`)
    A topic name is cut into words (:func:`name_words`): at every character that is not a
    letter or a digit (``/``, ``_``, ``-``, ``.``), where a lower-case letter meets an upper-case
    one (``batPose``) and where letters meet digits (``bat2``); the words are lower-cased. A
    ball word starts or ends with ``ball`` (``ball``, ``balls``, ``ballpos``, ``baseball``),
    unless it starts with one of :data:`NOT_BALL` (``ballot``). A bat word starts with ``bat``
    (``bat``, ``bats``, ``batpose``), unless it starts with one of :data:`NOT_BAT` (``batting``,
    ``batter``, ``battery``, ``batch``): ``/batting_cage/ball`` has the words ``batting``,
    ``cage`` and ``ball``, and no bat. A bat word's rest names a part too (``batknob``: the
    bat and its knob). The other words are matched whole. A role is filled automatically only
    when exactly one topic of an accepted type matches it:

    - ``ball``: PointStamped or PoseStamped; a ball word, and no word names the bat or a bat
      part (``knob``, ``handle``, ``barrel``, ``tip``, ``end``).
    - ``bat_pose``: PoseStamped; a bat word.
    - ``knob``: PointStamped; a part ``knob`` or ``handle``.
    - ``tip``: PointStamped; a part ``tip``, ``end`` or ``barrel``, and none ``knob`` or
      ``handle``.

    Topics named explicitly are taken as given (type-checked) and removed from the candidates of
    the other roles. When neither a bat pose nor knob/tip topics were named and the bag holds both
    one bat pose candidate and one knob/tip pair (``baseball-collision simulate`` writes both),
    the bat pose is used (or the points, with ``prefer_bat='points'``, e.g. a node parameter file
    with ``bat_input: points``), and :attr:`TopicSelection.note` says which topics were left
    out and the flags that pick them. Every selection error is one line naming the flag to pass
    (see :data:`TOPIC_FLAGS`).
"""

from dataclasses import dataclass, field
import re
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Set, Tuple, Union

from rosbags.highlevel import AnyReader

from .names import POINT_STAMPED, POSE_STAMPED, ROLE_TYPES, ROLES, TOPIC_FLAGS
from ..errors import BagError, TopicError

_HINTS = {
    'ball': ("a PointStamped or PoseStamped with a word starting or ending with 'ball' in "
             'its name (ball, ballpos, baseball)'),
    'bat_pose': ("a PoseStamped with a word starting with 'bat' in its name (bat, batpose; "
                 'not batting, batter, batch)'),
    'knob': "a PointStamped with the word 'knob' or 'handle' in its name",
    'tip': "a PointStamped with the word 'tip', 'end' or 'barrel' in its name",
}
NOT_BALL = ('ballot', 'ballast', 'ballet', 'balloon')
"""Starts of words that start with 'ball' and are no ball (``ballot``, ``ballots``)."""
NOT_BAT = ('batting', 'batter', 'batch')
"""Starts of words that start with 'bat' and are no bat (``battery``, ``batters``, ``batches``)."""
_BAT_PARTS = frozenset(('bat', 'knob', 'handle', 'barrel', 'tip', 'end'))
_WORD = re.compile(r'[A-Z]+(?![a-z])|[A-Z]?[a-z]+|[0-9]+')
_TOPIC_LIST_LIMIT = 20


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


def topic_types(source: TopicSource) -> Dict[str, Tuple[str, ...]]:
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


def _listed(names: Sequence[str], limit: int = _TOPIC_LIST_LIMIT) -> str:
    """Return names joined by commas, the first ``limit`` of them and how many more."""
    more = len(names) - limit
    return ', '.join(names[:limit]) + (f', ... and {more} more' if more > 0 else '')


def _describe_topics(types: Mapping[str, Tuple[str, ...]]) -> str:
    """Return a one-line list of topics with their types (the first 20 of them)."""
    if not types:
        return 'the bag has no topics'
    items = [f'{topic} ({" | ".join(msgtypes)})' for topic, msgtypes in types.items()]
    return f'topics: {_listed(items)}'


def name_words(topic: str) -> List[str]:
    """
    Return the lower-case words of a topic name, which auto-detection matches whole.

    Words are cut at every character that is not an ASCII letter or digit, where a lower-case
    letter meets an upper-case one, and where letters meet digits: ``/batting_cage/ballPos2``
    -> ``['batting', 'cage', 'ball', 'pos', '2']``.
    """
    return [word.lower() for word in _WORD.findall(topic)]


def _is_ball(word: str) -> bool:
    """Return True for a ball word: it starts or ends with ``ball``, and is not a ``NOT_BALL``."""
    return (word.startswith('ball') or word.endswith(('ball', 'balls'))) \
        and not word.startswith(NOT_BALL)


def _parts(words: Iterable[str]) -> Set[str]:
    """
    Return the bat and the bat's parts some words name, with the other words.

    A bat word (it starts with ``bat``, and not with a ``NOT_BAT``) names ``bat`` and its rest:
    ``batknob`` -> ``bat``, ``knob``; the other words name themselves.
    """
    parts: Set[str] = set()
    for word in words:
        if word.startswith('bat') and not word.startswith(NOT_BAT):
            parts.update(('bat', word[3:]))
        else:
            parts.add(word)
    return parts


def _name_matches(role: str, topic: str) -> bool:
    """Return True if a topic's name fits a role (see the module's auto-detection rules)."""
    words = name_words(topic)
    parts = _parts(words)
    if role == 'ball':
        return any(map(_is_ball, words)) and not parts & _BAT_PARTS
    if role == 'bat_pose':
        return 'bat' in parts
    if role == 'knob':
        return bool(parts & {'knob', 'handle'})
    return bool(parts & {'tip', 'end', 'barrel'}) and not parts & {'knob', 'handle'}


def _candidates(role: str, types: Mapping[str, Tuple[str, ...]],
                taken: Iterable[str]) -> List[str]:
    """Return the topics that could fill a role: accepted type, matching name, not taken."""
    taken = set(taken)
    return [
        topic for topic, msgtypes in types.items()
        if topic not in taken and len(msgtypes) == 1 and msgtypes[0] in ROLE_TYPES[role]
        and _name_matches(role, topic)]


def given_words(role: str, topic: str, named: Optional[Mapping[str, str]] = None) -> str:
    """
    Return the words an error names a given topic by: ``named[role]``, else its flag and it.

    :param named: how the caller names each topic it gave, by role (a topic from a parameter
        file: ``ball_topic '/x' (from the parameter file)``); a role not in it is named by its
        flag: ``--ball-topic '/x'``.
    """
    words = named.get(role) if named else None
    return words or f"{TOPIC_FLAGS[role]} '{topic}'"


def _check_given(role: str, topic: str, types: Mapping[str, Tuple[str, ...]],
                 named: Optional[Mapping[str, str]] = None) -> str:
    """
    Return the message type of an explicitly named topic after checking it fits the role.

    :param named: how each given topic is named in the error (:func:`given_words`).
    :raises TopicError: the topic is not in the bag, or has a type the role does not accept.
    """
    if topic not in types:
        raise TopicError(f'{given_words(role, topic, named)} is not in the bag; '
                         f'{_describe_topics(types)}', role)
    msgtypes = types[topic]
    if len(msgtypes) != 1 or msgtypes[0] not in ROLE_TYPES[role]:
        wanted = ' or '.join(ROLE_TYPES[role])
        raise TopicError(f"{given_words(role, topic, named)} has type {' | '.join(msgtypes)}; "
                         f'the {role} topic needs {wanted}', role)
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
            f'{len(candidates)} {role} topics: {_listed(candidates)}; pass {flag} to choose one')
    return candidates[0]


def select_topics(source: TopicSource, ball: Optional[str] = None,
                  bat_pose: Optional[str] = None, knob: Optional[str] = None,
                  tip: Optional[str] = None, prefer_bat: str = 'pose',
                  named: Optional[Mapping[str, str]] = None) -> TopicSelection:
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
    :param named: how the caller names the topics it gave, by role, in errors (default: by
        their flags; :func:`given_words`).
    :returns: the selection.
    :raises BagError: a named topic is missing (the message lists the bag's topics) or has the
        wrong type (a ``TopicError``); no candidate or several candidates for a role. The
        message names the flag to pass. ``prefer_bat`` neither ``'pose'`` nor ``'points'``.
    """
    if prefer_bat not in ('pose', 'points'):
        raise BagError(f"prefer_bat must be 'pose' or 'points', got {prefer_bat!r}")
    types = topic_types(source)
    given = {'ball': ball, 'bat_pose': bat_pose, 'knob': knob, 'tip': tip}
    chosen: Dict[str, str] = {}
    chosen_types: Dict[str, str] = {}
    for role, topic in given.items():
        if topic is not None:
            chosen_types[role] = _check_given(role, topic, types, named)
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


def check_selection(selection: TopicSelection, types: Mapping[str, Tuple[str, ...]]) -> None:
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
