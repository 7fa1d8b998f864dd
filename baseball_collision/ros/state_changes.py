"""
What clears the node's state or changes its configuration while it runs.

* ``~/reset`` (std_srvs/Trigger) clears the detector's state (counters kept), fails only on the
  package's own bug, and says when a bat plan in force went with it.
* A ROS clock jump back by ``time_jump_reset`` or more (a replay restarted) resets the state with
  one WARN; ROS time activated or deactivated is an INFO line. Every state reset turns
  ``~/impact_predicted`` false, clears the markers and drops the bat plan.
* A parameter set at runtime is checked with the core's rules first (the start-up's one-line
  reason, read-only parameters, ``Detector.refusal``) and refused with a WARN, or applied to the
  running detector with an INFO line (``prediction_horizon`` off turns the flag false; a new
  ``time_jump_reset`` re-registers the jump callback).

:class:`StateChanges` is a mixin base of ``node.ImpactNode`` (before ``rclpy.node.Node``, whose
``set_parameters*`` and ``destroy_node`` it extends): it uses the node's detector, lock,
settings, log lines and the other mixins' ``_set_predicting``, ``_clear_markers`` and plan.
"""

import time
from typing import Any, List, Tuple

from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import ClockChange, JumpThreshold, TimeJump
from rclpy.duration import Duration
from rclpy.parameter import Parameter
from std_srvs.srv import Trigger

from .messages import format_stamp, NS_PER_S
from .parameters import check_change
from ..core.detector import SPECS, unknown_parameters
from ..errors import RosError


class StateChanges:
    """Serve ``~/reset``, follow the ROS clock's jumps, take runtime parameters (a mixin)."""

    _jump_handle: Any  # the clock jump callback's handle (None: none registered)
    _clock_jump_at: float  # when the ROS clock last jumped back (s, steady clock)

    def _on_reset(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        """
        Serve ~/reset: clear the detector state (counters are kept); fails only on a bug.

        The bat plan goes with the state: the reply says when one was in force (the plan topic
        is volatile, so the arm must send it again).
        """
        try:
            stamp_ns, resets, plan_dropped = self._reset('requested')
        except Exception as error:  # the package's own failure: the caller is told
            self._failed('the reset requested on ~/reset failed', 'it was refused', error)
            response.success = False
            response.message = f'the reset failed: {type(error).__name__}: {error} (see the log)'
            return response
        response.success = True
        when = f'at {format_stamp(stamp_ns)} s' if stamp_ns else 'before any sample'
        response.message = (f'detector state cleared {when} (buffers, armed state, open near '
                            f'miss, bat plan; counters kept; {resets} resets so far)')
        if plan_dropped:
            response.message += f'; {self._plan_dropped_text()}'
        self.get_logger().info(f'reset requested: {response.message}')
        return response

    def _reset(self, reason: str) -> Tuple[int, int, bool]:
        """
        Clear the detector state and the live values.

        :returns: the reset's stamp (ns), the resets so far, and whether a bat plan in force
            was dropped with the state.
        """
        with self._lock:
            return self._reset_locked(reason)

    def _reset_locked(self, reason: str, stamp_ns: int = 0) -> Tuple[int, int, bool]:
        """
        ``_reset`` with the node's lock held by the caller.

        :param stamp_ns: the reset's stamp (ns) before any sample was taken.
        """
        frame = self.detector.frame_id or ''
        event = self.detector.reset(self.detector.stats.newest_stamp_ns or stamp_ns, reason)
        self._set_predicting(False)
        self._clear_markers(event.stamp_ns, frame)
        return event.stamp_ns, self.detector.stats.resets, self._forget_plan()

    def _register_clock_jump(self) -> None:
        """(Re)register the ROS clock jump callback at ``time_jump_reset`` backwards."""
        if self._jump_handle is not None:
            self._jump_handle.unregister()
        backwards = max(1, int(self.settings['time_jump_reset'] * NS_PER_S))
        self._jump_handle = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=None, min_backward=Duration(nanoseconds=-backwards),
                          on_clock_change=True),
            post_callback=self._guarded(self._on_clock_jump, "handling the clock's jump"))

    def _on_clock_jump(self, jump: TimeJump) -> None:
        """Reset the detector, with one warning, when the ROS clock jumps back."""
        if jump.clock_change in (ClockChange.ROS_TIME_ACTIVATED, ClockChange.ROS_TIME_DEACTIVATED):
            active = jump.clock_change == ClockChange.ROS_TIME_ACTIVATED
            self._lines.info(f"ROS time {'activated' if active else 'deactivated'}")
            return
        if jump.delta.nanoseconds >= 0:
            return
        plan_dropped = self._reset('time_jump_backwards')[2]
        self._clock_jump_at = time.monotonic()
        self._lines.warning(
            f'the ROS clock jumped back by {-jump.delta.nanoseconds * 1e-9:.3f} s (replay '
            'restarted?): detector state reset')
        if plan_dropped:
            self._say_plan_dropped('time_jump_backwards')

    def destroy_node(self) -> None:
        """Unregister the clock jump callback, then destroy the node."""
        handle = getattr(self, '_jump_handle', None)
        if handle is not None:
            handle.unregister()
            self._jump_handle = None
        super().destroy_node()

    def set_parameters_atomically(self, parameter_list: List[Parameter]) -> SetParametersResult:
        """
        Set parameters all at once (see rclpy), checked with the core's rules first.

        A refusal gives the same one-line reason as at start-up; a read-only parameter, or a
        change the running detector cannot take (``Detector.refusal``: ``tracker_noise`` to auto
        from the told noise it started with), is refused saying why and to restart. A change
        applies to the running detector.

        :returns: the aggregate result.
        """
        try:
            unknown = unknown_parameters(
                [p.name for p in parameter_list if not self.has_parameter(p.name)],
                self.get_name())
            if unknown is not None:
                raise RosError(unknown.removeprefix('ignoring '))
            settings, parameters = check_change(self.settings, parameter_list)
            with self._lock:
                reason = self.detector.refusal(settings.detector)
            if reason is not None:
                raise RosError(reason)
        except RosError as refusal:
            self.get_logger().warning(f'refusing to set parameters at runtime: {refusal}')
            return SetParametersResult(successful=False, reason=str(refusal))
        result = super().set_parameters_atomically(parameters)
        if result.successful:
            with self._lock:
                self.detector.reconfigure(settings.detector)
                previous, self.settings = self.settings, settings
                if settings['prediction_horizon'] <= 0.0:  # off: no prediction in force
                    self._set_predicting(False)
            if settings['time_jump_reset'] != previous['time_jump_reset']:
                self._register_clock_jump()
            changes = ', '.join(f'{p.name}={p.value!r}' for p in parameters if p.name in SPECS)
            if changes:
                self.get_logger().info(f'parameters changed: {changes}')
        return result

    def set_parameters(self, parameter_list: List[Parameter]) -> List[SetParametersResult]:
        """Set parameters one by one (see ``set_parameters_atomically``): a result each."""
        return [self.set_parameters_atomically([parameter]) for parameter in parameter_list]
