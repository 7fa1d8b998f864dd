"""
The node's input streams: which topic and type each reads, and what it hands the detector.

``ball_type`` and ``bat_input`` choose the streams (:func:`input_streams`); each becomes one
subscription whose callback (:func:`input_callback`) takes the message and rclpy's message info
(a ``dict``) and hands the node the stream, the header, the ``Detector`` method and its values
(m, quaternion ``x, y, z, w``), and the publication sequence number when the RMW gives one
(:func:`sequence_number`). Drop warnings, throttled per reason, are :class:`DropWarnings`.
"""

from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Mapping, Optional, Tuple

from geometry_msgs.msg import PointStamped, PoseStamped
import rclpy

from .messages import describe_drop, xyz, xyzw

WARN_PERIOD_S = 2.0
"""Shortest time (s) between two log lines of one kind (rclpy's throttle; per drop reason)."""


@dataclass(frozen=True)
class InputStream:
    """
    One input of the node.

    :ivar stream: its name in the detector and the diagnostics (``ball``, ``bat_pose``, ...).
    :ivar msg_type: the rclpy message class.
    :ivar topic_parameter: the parameter naming its topic.
    :ivar method: the ``Detector`` method its samples go to.
    :ivar values: a message's values for that method.
    """

    stream: str
    msg_type: Any
    topic_parameter: str
    method: str
    values: Callable[[Any], Tuple[Any, ...]]


_STREAMS = {
    ('ball', 'point'): InputStream('ball', PointStamped, 'ball_topic', 'add_ball',
                                   lambda m: (xyz(m.point),)),
    ('ball', 'pose'): InputStream('ball', PoseStamped, 'ball_topic', 'add_ball',
                                  lambda m: (xyz(m.pose.position),)),
    ('bat_pose', 'pose'): InputStream(
        'bat_pose', PoseStamped, 'bat_pose_topic', 'add_bat_pose',
        lambda m: (xyz(m.pose.position), xyzw(m.pose.orientation))),
    ('knob', 'point'): InputStream('knob', PointStamped, 'knob_topic', 'add_knob',
                                   lambda m: (xyz(m.point),)),
    ('tip', 'point'): InputStream('tip', PointStamped, 'tip_topic', 'add_tip',
                                  lambda m: (xyz(m.point),)),
}


def input_streams(settings: Mapping[str, Any]) -> List[InputStream]:
    """Return the inputs ``ball_type`` (``point``, ``pose``) and ``bat_input`` choose."""
    chosen = [_STREAMS['ball', settings['ball_type']]]
    if settings['bat_input'] == 'pose':
        chosen.append(_STREAMS['bat_pose', 'pose'])
    else:
        chosen += [_STREAMS['knob', 'point'], _STREAMS['tip', 'point']]
    return chosen


def sequence_number(info: Optional[Mapping[str, Any]]) -> Optional[int]:
    """
    Return a message's publication sequence number from rclpy's message info, or None.

    rmw_fastrtps_cpp (Jazzy's default) numbers each publisher's messages 1, 2, 3 ...; an RMW
    that does not gives None (rclpy maps ``RMW_MESSAGE_INFO_SEQUENCE_NUMBER_UNSUPPORTED``).
    """
    number = info.get('publication_sequence_number') if info else None
    return number if number else None


def input_callback(take: Callable[..., None], each: InputStream,
                   detector: Any) -> Callable[[Any, Mapping[str, Any]], None]:
    """
    Return the subscription callback of one input (it takes the message and message info).

    It calls ``take(stream, header, add_sample, *values, sequence=number)``: ``add_sample``
    the ``detector`` method of the stream, ``number`` from :func:`sequence_number`.
    """
    add_sample, values, stream = getattr(detector, each.method), each.values, each.stream

    def callback(message: Any, info: Mapping[str, Any]) -> None:
        take(stream, message.header, add_sample, *values(message),
             sequence=sequence_number(info))
    return callback


class DropWarnings:
    """
    Warn about dropped samples, each reason at most once every ``WARN_PERIOD_S``.

    :param logger_name: the node's logger's name.
    """

    def __init__(self, logger_name: str) -> None:
        self._name = logger_name
        self._loggers: Dict[str, Any] = {}

    def warn(self, stream: str, topic: str, reason: str, frame: str, expected: Optional[str],
             stamp: int, so_far: int) -> None:
        """
        Warn that a sample of ``stream`` on ``topic`` was dropped for ``reason``.

        :param frame: its frame; ``expected``: the tracking frame; ``stamp``: its stamp (ns);
            ``so_far``: samples dropped for this reason since start-up.
        """
        logger = self._loggers.get(reason)
        if logger is None:  # a logger per reason: rclpy throttles per logger and call site
            logger = self._loggers[reason] = rclpy.logging.get_logger(self._name)
        logger.warning(
            f'dropped a {stream} sample on {topic}: {reason}: '
            f'{describe_drop(reason, frame, expected, stamp)}; '
            f'{so_far} dropped for this reason so far',
            throttle_duration_sec=WARN_PERIOD_S)
