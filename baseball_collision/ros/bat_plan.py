"""
The bat plan input: which commanded bat trajectories the node hands the detector, and when.

A plan (nav_msgs/Path on ``bat_plan_topic``: stamped poses, empty clears) is taken for the
predictions unless it is refused, with a throttled WARN: over ``MAX_PLAN_POSES`` poses (before a
single pose is converted), a frame other than the tracking frame, a frame named before any
tracking frame is known, or values the core refuses. A plan in force that a prediction could
not use (it ended before the instant the prediction starts from) is warned about, throttled.
Every state reset drops the plan with the detector's: the topic is volatile, so the node says
once at INFO (or in the ``~/reset`` reply) that the arm must send it again.

:class:`BatPlanInput` is a mixin base of ``node.ImpactNode``: it uses the node's detector,
lock, settings, log lines and throttle, and keeps the plan in force (``_plan``: its first and
last stamp, ns).
"""

from typing import Any, Optional, Tuple

from nav_msgs.msg import Path
from rclpy.exceptions import InvalidTopicNameException

from .endpoints import topic_error_line
from .messages import format_stamp
from .outputs import VIEWS
from ..bags.plans import plan_arrays
from ..core.prediction import MAX_PLAN_POSES
from ..errors import RosError


class BatPlanInput:
    """Take, refuse, warn about and drop the bat plan (a mixin base of ``ImpactNode``)."""

    _plan: Optional[Tuple[int, int]]  # the plan in force: first, last stamp (ns)
    _plan_sub: Any  # the plan's subscription (only with a ``bat_plan_topic``)
    _intake: Any  # the node's ``inputs.Intake``: the plan is taken in turn with the samples

    def _subscribe_plan(self) -> None:
        """
        Subscribe to ``bat_plan_topic`` when it names one (its callback guarded).

        :raises RosError: a topic name rcl refuses once expanded (an unknown substitution).
        """
        topic = self.settings['bat_plan_topic']
        if topic:
            callback = self._guarded(self._on_plan, 'taking a bat plan')
            try:
                self._plan_sub = self.create_subscription(
                    Path, topic, self._then_reports(self._intake.wrap(callback)), VIEWS)
            except (InvalidTopicNameException, ValueError) as error:
                raise RosError(f'bat plan topic {topic!r}: {topic_error_line(error)}') from error
            self._intake.attach(self._plan_sub, callback)

    def _on_plan(self, message: Path, info: Any = None) -> None:
        """
        Take a commanded bat trajectory (stamped poses) for the predictions; empty clears.

        Taken with the samples, in the order they were received (``inputs.Intake``: the order
        ``analyze`` takes a bag's plans in; ``info`` is rclpy's message info, unused here).

        Refused with a throttled WARN: over ``MAX_PLAN_POSES`` poses (before a pose is
        converted), else what ``Detector.take_bat_plan`` refuses (the rule ``analyze`` keeps
        too): a frame other than the tracking frame (the configured ``frame_id``, else the
        trackers'), a frame named before any tracking frame is known (``frame_id`` '' and no
        sample yet: it cannot be checked), or values the core refuses. A plan naming no frame
        is taken as in the tracking frame, as samples are.
        """
        if len(message.poses) > MAX_PLAN_POSES:  # refused before converting a single pose
            if self._log_throttle.allows('plan_size'):
                self._lines.warning(
                    f'ignored a bat plan on {self._plan_sub.topic_name}: {len(message.poses)} '
                    f'poses is more than the {MAX_PLAN_POSES} a plan may hold')
            return
        stamps, positions, quaternions, frames = plan_arrays(message)
        with self._lock:
            reason = self.detector.take_bat_plan(stamps, positions, quaternions, frames)
            if reason is None:
                self._plan = (stamps[0], stamps[-1]) if stamps else None
                return
        if self._log_throttle.allows('plan'):
            self._lines.warning(f'ignored a bat plan on {self._plan_sub.topic_name}: {reason}')

    def _warn_plan_unused(self, made_at_ns: int) -> None:
        """
        Warn (throttled) that a prediction made at ``made_at_ns`` extrapolated the bat.

        A plan was in force, but the detector takes it only when its last pose is after the
        instant the prediction starts from (``Prediction.planned`` says whether it did): a
        plan that ended before it, or stamped on another clock than the trackers'.
        """
        if self._log_throttle.allows('plan_unused'):
            first, last = self._plan
            self._lines.warning(
                f'the bat plan on {self._plan_sub.topic_name} ({format_stamp(first)} to '
                f'{format_stamp(last)} s) was not used: the prediction made at '
                f'{format_stamp(made_at_ns)} s extrapolated the bat, the plan ending before '
                "it (stamp the plan on the trackers' clock, over the coming swing)")

    def _forget_plan(self) -> bool:
        """Forget the bat plan after a state reset (the detector's went too); True if one was."""
        in_force, self._plan = self._plan is not None, None
        return in_force

    def _plan_dropped_text(self) -> str:
        """Return the sentence saying that the bat plan in force was dropped, and what to do."""
        return (f'the bat plan in force was dropped: send it again on '
                f'{self._plan_sub.topic_name} (the topic is volatile)')

    def _say_plan_dropped(self, reason: str) -> None:
        """Log, once at INFO, that a state reset for ``reason`` dropped the bat plan in force."""
        self._lines.info(f'state reset ({reason}): {self._plan_dropped_text()}')
