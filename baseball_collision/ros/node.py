"""
The ROS 2 node ``impact_node``: the tracked ball and bat in, the one ``Detector``, events out.

Subscriptions (``ball_topic``, and ``bat_pose_topic`` or ``knob_topic`` + ``tip_topic``; one
callback per input) become ``Detector.add_*`` calls: the header stamp becomes integer
nanoseconds (``sec * 10**9 + nanosec``) and the header frame is passed through. The detector's
events come back out as messages:

* ``~/impact`` (geometry_msgs/PointStamped): stamped with the impact instant, the contact point;
  sent the moment the contact is solved (``Detector``'s ``on_contact``), before its velocities.
* ``~/impact_velocity`` (geometry_msgs/TwistStamped): same stamp; bat surface velocity at the
  contact point (linear, m/s) and bat angular velocity (angular, rad/s), once they are fitted.
  The impact's error bars (``Detector`` with ``deferred_uncertainty``), INFO line and markers
  follow after the drain, with the reports.
* ``~/near_miss`` (geometry_msgs/Vector3Stamped): closest approach; gap vector from the bat
  surface to the ball surface (m).
* ``~/predicted_impact`` (PointStamped, stamped with the predicted future instant) and
  ``~/impact_predicted`` (std_msgs/Bool, latched, with a ``LIVELINESS_LEASE_S`` liveliness
  lease so an arm learns of the node's death; a subscriber whose QoS would lose it is named
  in a warning, ``Endpoints.lossy_readers``; false right after an ``~/impact``, once
  every input stream went ``max_gap`` past the predicted instant without one, once the bat did
  and the ball has been silent longer than its measured lag behind the bat plus ``max_gap``
  and the span its flight holds unseen, or once an input has been silent beyond ``stale_timeout``).
* ``~/impact_report`` (std_msgs/String, reliable): one line of JSON per impact, near miss and
  prediction: exactly the ``core.records`` record ``analyze --json`` writes (schema
  ``schema/event_record.schema.json``); a prediction's says when it was made (``made_at_ns``)
  and its lead time (``lead_s``) beside the predicted instant (``stamp_ns``). Made only while
  the topic has a subscriber (volatile: nobody else would get it), after the executor callback
  that took the waiting input messages (the intake's drain, at most ``DRAIN_LIMIT`` of them),
  so no message handled in it and no arm's output waits for a record.
* ``~/markers`` (visualization_msgs/MarkerArray): the bat profile, ball, contact point and normal
  at each impact, and the live bat and ball (stamped with their samples' stamp, published only
  when a new sample came; a ``DELETEALL`` on every state reset); sent as the array's CDR bytes
  (``markers.scene_cdr``), no message made in the executor's thread.
* ``/diagnostics`` (diagnostic_msgs/DiagnosticArray): rates, messages estimated lost, drops by
  reason, events and resets, processing time and the state (waiting for data, tracking, stale,
  idle), grouped; ``hardware_id`` the parameter (default the node's name).
* ``~/reset`` (std_srvs/Trigger): clears the detector state, the bat plan included (the reply,
  and on other state resets an INFO line, says when a plan in force was dropped: its topic is
  volatile, the arm must send it again).

Every callback survives the package's own failure (a bug): an ERROR with the traceback (the
first; later ones throttled), ``internal_errors`` in ``/diagnostics``, and the failed call's work
skipped; a failure inside the detector also resets its state (``detector_error``).

Inputs are subscribed with ``qos``/``qos_depth`` (``reliable_all``: keep all), which the standard
``qos_overrides./TOPIC.subscription.{reliability,history,depth}`` parameters override.

This module is the wiring: detection is the core's, the parameters are declared from the core's
table (``parameters``), the input streams (with each message's publication sequence number, for
the loss count), the intake (queued messages taken round-robin in one executor callback) and
the drop warnings are in ``inputs``, conversions in ``messages``, markers in
``markers``, the status in ``diagnostics`` and QoS or type mismatches in ``endpoints``.
``ImpactNode``'s mixin bases hold the rest: what each event sends out and when (``outputs``),
``~/impact_predicted``'s raising and withdrawal (``prediction_flag``), the bat plan
(``bat_plan``), and the reset service, the clock's jumps and runtime parameters
(``state_changes``). See ``config/impact_node.yaml`` for every parameter.
"""

from collections import deque
from dataclasses import replace
import gc
import math
import sys
import threading
import time
import traceback
from typing import Any, Callable, Deque, Dict, List, Optional, Set, Tuple, Union

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Header
from std_srvs.srv import Trigger

from .bat_plan import BatPlanInput
from .diagnostics import report, silent_streams, take_snapshot, Tally
from .endpoints import Endpoints, input_qos
from .inputs import DropWarnings, input_callback, input_streams, Intake, Throttle
from .logger import DirectLogger
from .messages import (
    describe_listening, event_output, format_stamp, stamp_to_ns, StampedCdr)
from .outputs import Outputs
from .parameters import declare, params_file_warnings, start_warnings
from .prediction_flag import PredictionFlag
from .prediction_watch import PredictionWatch
from .state_changes import StateChanges
from ..core.detector import (
    Detector, DetectorConfig, DropReason, Event, Impact, NODE_NAME, PendingPrediction,
    PendingUncertainty, Prediction, ResetReason, StateReset)
from ..core.records import EVENT_NAMES
from ..errors import RosError
from ..threads import single_threaded_blas


class ImpactNode(Outputs, PredictionFlag, BatPlanInput, StateChanges, Node):
    """
    Subscribe to the tracked ball and bat, publish impacts, near misses and diagnostics.

    :param node_name: the node's name.
    :param kwargs: passed to ``rclpy.node.Node`` (``context``, ``parameter_overrides`` ...).
    :raises RosError: a parameter value the node cannot run with (the node is
        destroyed before raising).
    """

    def __init__(self, node_name: str = NODE_NAME, **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        self._jump_handle = None
        self.tally = Tally(started=time.monotonic())
        self._lock = threading.Lock()
        self._last_values: Dict[str, Tuple[int, Any]] = {}
        self._markers_stamp: Optional[int] = None
        self._predicting = False
        self._plan: Optional[Tuple[int, int]] = None  # the plan in force: first, last stamp (ns)
        self._point_cdr = StampedCdr(3)  # ~/impact's and ~/predicted_impact's CDR bytes
        self._twist_cdr = StampedCdr(6)  # ~/impact_velocity's
        self._frame = ''  # the frame of the message being taken (``_on_contact``'s)
        self._contact_ns: Optional[int] = None  # a contact solved in the add being taken
        # (event, frame, config) to complete once the inputs are drained: reports, an impact's
        # error bars, line and markers and a prediction's error bars (its PendingUncertainty or
        # PendingPrediction in place of the event)
        self._to_complete: Deque[Tuple[Union[Event, PendingUncertainty, PendingPrediction],
                                       str, DetectorConfig]] = deque()
        self._clock_jump_at = -math.inf
        self._waited_for: Set[str] = set()  # inputs said to have sent nothing yet
        self._frames_said: Optional[str] = None  # the frame disagreement last warned about
        self._drop_warnings = DropWarnings(self.get_logger().name)
        self._log_throttle = Throttle()
        self._lines = DirectLogger(self.get_logger().name)  # lines logged in callbacks
        try:
            self._start()
        except RosError:
            self.destroy_node()
            raise

    def _start(self) -> None:
        """Declare the parameters, make the detector, wire the I/O (raises RosError)."""
        self.settings = declare(self)
        self.detector = Detector(self.settings.detector, deferred_uncertainty=True,
                                 on_contact=self._on_contact)
        for warning in start_warnings(self, self.settings.detector):
            self.get_logger().warning(warning)
        self.endpoints = Endpoints(self, self.tally, self._guarded)
        self._advertise_outputs()
        self._subscribe_inputs()
        self.create_service(Trigger, '~/reset', self._on_reset)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(self.settings['diagnostics_period'],
                          self._guarded(self._publish_diagnostics, 'publishing /diagnostics'),
                          clock=steady)
        if self.settings['marker_rate'] > 0.0:
            self.create_timer(1.0 / self.settings['marker_rate'],
                              self._guarded(self._publish_live_markers,
                                            'publishing the live markers'), clock=steady)
        self._register_clock_jump()
        plan = getattr(self, '_plan_sub', None)
        self.get_logger().info(describe_listening(
            self.settings.values, self.endpoints.topics,
            [publisher.topic_name for publisher in self._outputs.values()],
            None if plan is None else plan.topic_name))

    # ---- I/O -----------------------------------------------------------------------------

    def _subscribe_inputs(self) -> None:
        """Subscribe to the inputs ``ball_type`` and ``bat_input`` name (raises RosError)."""
        s = self.settings
        chosen = input_streams(s.values)
        self._streams = tuple(each.stream for each in chosen)
        self._topic_parameters = {each.stream: each.topic_parameter for each in chosen}
        self._watch = PredictionWatch(self._streams)  # (when a prediction has passed)
        self._intake = Intake()
        for each in chosen:  # a profile each: overrides change it
            callback = self._guarded(input_callback(self._take, each, self.detector),
                                     f'taking a message on the {each.stream} input')
            subscription = self.endpoints.subscribe(
                each.stream, each.msg_type, s[each.topic_parameter],
                self._then_reports(self._intake.wrap(callback)),
                input_qos(s['qos'], s['qos_depth']))
            self._intake.attach(subscription, callback)
        self._subscribe_plan()

    # ---- input ---------------------------------------------------------------------------

    def _take(self, stream: str, header: Header, add_sample: Callable[..., List[Event]],
              *values: Any, sequence: Optional[int] = None,
              sent: Optional[int] = None) -> None:
        """
        Feed one message to the detector, publish what it decided, count and time it.

        :param sequence: its publication sequence number (None: the RMW gives none).
        :param sent: its writer's send time (ns; None: the RMW gives none).
        """
        start = time.perf_counter()
        stamp = stamp_to_ns(header.stamp)
        frame = header.frame_id
        with self._lock:
            self._frame = frame  # (``_on_contact``'s, inside the add below)
            self._contact_ns = None
            arrival = time.monotonic()
            self.tally.arrived(stream, arrival)
            self.tally.stamped(stream, stamp, sequence, sent)
            try:
                events = add_sample(stamp, *values, frame)
            except Exception as error:  # the detector's own failure (a bug): not the node's end
                self._detector_failed(stream, stamp, error)
                self._record_processing(time.perf_counter() - start)
                return
            stats = self.detector.stats
            dropped, late = stats.last_drop_reason, stats.late_drops
            expected = self.detector.frame_id
            frames = self.detector.frame_disagreement if late and any(
                each.reason is DropReason.NO_COMMON_FRAME for each in late) else None
            previous = self._last_values.get(stream)
            if dropped is None:
                self._last_values[stream] = (stamp, values)
                self._watch.accepted(stream, stamp, None if previous is None else previous[0],
                                     arrival)
            pending = iter(self.detector.take_pending())  # the error bars, to come
            for event in events:
                kind, where = event.__class__, frame or expected or ''
                if kind is StateReset:
                    self._clear_markers(event.stamp_ns, expected or frame)
                    if self._forget_plan():
                        self._say_plan_dropped(event.reason)
                if kind is Prediction:  # the point (its message's CDR bytes), then on
                    self._outputs['predicted_impact'].publish(
                        self._point_cdr(event.stamp_ns, where, event.point))
                    if not event.planned and self._plan is not None:
                        self._warn_plan_unused(event.made_at_ns)
                    self._raise_prediction(event)
                    event = next(pending)  # (its error bars: with its report, if one is made)
                elif kind is Impact:  # ~/impact went out; its error bars, line, markers later
                    self._outputs['impact_velocity'].publish(self._twist_cdr(
                        event.stamp_ns, where, (*event.bat_velocity, *event.bat_angular_velocity)))
                    event = next(pending)
                else:
                    self._publish(event_output(event, where, self._markers))
                if kind in EVENT_NAMES:  # its report: after the drain
                    self._to_complete.append((event, where, self.detector.config))
            if self._predicting:
                self._withdraw_a_passed_prediction(arrival)
        warn, topics = self._drop_warnings.warn, self.endpoints.topics
        if dropped is not None:
            warn(stream, topics[stream], dropped, frame, expected, stamp, stats.dropped[dropped])
        for each in late:  # samples that waited (a held glitch, a frame vote) dropped now
            if each.reason is not DropReason.NO_COMMON_FRAME:  # (said once: below)
                warn(each.role, topics.get(each.role, each.role), each.reason, each.frame_id,
                     expected, each.stamp_ns, stats.dropped[each.reason])
        if frames is not None and frames != self._frames_said:
            self._say_frames_differ(frames)
        self._record_processing(time.perf_counter() - start)

    def _say_frames_differ(self, frames: str) -> None:
        """
        Warn, once per disagreement, that the inputs send no frame in common (``frame_id`` '').

        ``frames`` is the detector's ``frame_disagreement`` (each stream's frames); no frame is
        adopted, and the samples waiting for one are dropped (``no_common_frame``, counted in
        ``/diagnostics``) until the inputs agree.
        """
        self._frames_said = frames
        topics = ', '.join(f'{stream} on {topic}'
                           for stream, topic in self.endpoints.topics.items())
        self._lines.warning(
            f'no frame every input sends ({topics}): {frames}: set frame_id or transform one '
            "(no TF here); frame_id '' adopts none, and the samples waiting for a frame every "
            'input sends are dropped (no_common_frame) until the inputs agree')

    def _detector_failed(self, stream: str, stamp_ns: int, error: Exception) -> None:
        """
        Go on after the detector raised while it took a sample: reset its state, log the error.

        The state a half-done update left is dropped (``ResetReason.DETECTOR_ERROR``, a reset
        ``/diagnostics`` counts), ``~/impact_predicted`` turns false and the markers are cleared,
        as on ``~/reset``; the sample and the pitch it was in are lost. (Called under the node's
        lock; ``analyze`` stops on the same error instead.)
        """
        if self._reset_locked(ResetReason.DETECTOR_ERROR, stamp_ns)[2]:
            self._say_plan_dropped(ResetReason.DETECTOR_ERROR)
        self._failed(f'the detector failed on a {stream} sample stamped {format_stamp(stamp_ns)} '
                     's', 'its state was reset', error)

    def _failed(self, what: str, then: str, error: Exception) -> None:
        """
        Log the package's own failure (a bug) at ERROR, which the node survives.

        The first with its traceback, later ones at most once per throttle period, each with
        the count so far; ``/diagnostics`` counts them (``internal_errors``, ERROR in a period
        with one).
        """
        self.tally.failures += 1
        failures = self.tally.failures
        allowed = self._log_throttle.allows('failure')  # (the first starts the period)
        if failures == 1 or allowed:
            trace = ''.join(traceback.format_exception(error)) if failures == 1 else ''
            self._lines.error(f'{what} ({type(error).__name__}: {error}); {then} and the node '
                              f'goes on ({failures} failure(s) so far)'
                              + (f'\n{trace}' if trace else ''))

    def _guarded(self, callback: Callable[..., None], what: str) -> Callable[..., None]:
        """
        Return ``callback`` made to survive its own failure (a bug), logged by ``_failed``.

        For the executor's callbacks (an input's message, the timers, the bat plan, the clock
        jump): an exception out of one would end ``rclpy.spin`` and the node. What the failed
        call would have done is skipped (a message's outputs, one diagnostics status, ...); a
        failure inside the detector's own call also resets its state (``_detector_failed``).
        """
        def guarded(*args: Any) -> None:
            try:
                callback(*args)
            except Exception as error:  # the package's own failure: not the node's end
                self._failed(f'{what} failed', 'it was skipped', error)
        return guarded

    def _record_processing(self, elapsed_s: float) -> None:
        """Account the wall time (s) one message took in its callback."""
        self.tally.period.record(elapsed_s)

    # ---- diagnostics ---------------------------------------------------------------------

    def diagnostics(self) -> DiagnosticStatus:
        """Return the detector's status over the period since the previous call (see report)."""
        settings = dict(self.settings.values)
        settings['hardware_id'] = settings['hardware_id'] or self.get_fully_qualified_name()
        with self._lock:
            snapshot = take_snapshot(
                time.monotonic(), self.get_name(), self._streams, self.endpoints.topics,
                self.tally, self.detector.stats, self.detector.watermark_ns,
                self.detector.frame_id, settings, self.detector.noise)
        problems = {stream: self.endpoints.silence(stream) for stream in silent_streams(snapshot)}
        snapshot = replace(snapshot, incompatible=self.tally.incompatible)  # found just now too
        self.tally.incompatible_reported = snapshot.incompatible
        return report(snapshot, problems)

    def _publish_diagnostics(self) -> None:
        """
        Publish the status on /diagnostics (timer, steady clock); end a silent prediction.

        Then say which inputs sent nothing yet, and which subscribers of the latched flag lose
        its state (``Endpoints.lossy_readers``), each once.
        """
        array = DiagnosticArray(status=[self.diagnostics()])
        array.header.stamp = self.get_clock().now().to_msg()
        self._outputs['diagnostics'].publish(array)
        self._withdraw_a_silent_prediction()
        self._say_still_waiting()
        self.endpoints.lossy_readers()

    def _say_still_waiting(self) -> None:
        """
        Log, once per input, that nothing came on it in the ``stale_timeout`` after start-up.

        The line names the topic, its type and why it may be silent (no publisher discovered
        yet, one of another type or QoS: ``Endpoints.silence``), so a node started beside the
        wrong topics says so in its own log, not only in ``/diagnostics`` (whose status keeps
        saying it).
        """
        timeout = self.settings['stale_timeout']
        waited = time.monotonic() - self.tally.started
        if waited <= timeout:
            return
        with self._lock:
            silent = [stream for stream in self._streams
                      if stream not in self.tally.last_arrival and stream not in self._waited_for]
        for stream in silent:
            self._waited_for.add(stream)
            why = self.endpoints.silence(stream)
            self.get_logger().info(
                f'no {stream} message yet on {self.endpoints.topics[stream]} '
                f'({self.endpoints.types[stream]}) {waited:.1f} s after start-up'
                + (f': {why}' if why else '') + '; still waiting (remap the topic or set '
                f'{self._topic_parameters[stream]} if the tracker publishes elsewhere)')


def freeze_start_up() -> int:
    """
    Collect once, then keep every object alive now out of later garbage collections.

    After start-up the process holds some 44,000 objects (rclpy, numpy, the message types, the
    node) that live as long as it does; a full (generation 2) collection walks them all: 23-26
    ms of CPU on the benchmark machine, about once in 8,000-40,000 messages at 1 kHz per
    stream, delaying the messages behind it (0.4-1.1 ms once frozen; BENCHMARKS.md, "sixth
    pass"). ``gc.freeze`` moves them into the permanent generation, so a collection walks only
    what was made since. The collection first frees start-up's own garbage cycles, which a
    freeze would keep. Call it once, after the node is made.

    :returns: the objects frozen (``gc.get_freeze_count()``).
    """
    gc.collect()
    gc.freeze()
    return gc.get_freeze_count()


class Executor(SingleThreadedExecutor):
    """
    rclpy's single-threaded executor, whose clean-up survives Ctrl-C in its construction.

    rclpy's ``Executor.__del__`` reads ``_sigint_gc``, set near the end of ``__init__``: a
    SIGINT that cut ``__init__`` short (the node stopped right after start-up, on a loaded
    machine) left an object whose collection printed ``Exception ignored in ... __del__``, a
    traceback, as the node exited. The class attribute answers None there: nothing to destroy.
    """

    _sigint_gc = None


def main(args: Optional[List[str]] = None) -> int:
    """
    Run the node until Ctrl-C or shutdown.

    :param args: command line (``--ros-args ...``); ``None``: ``sys.argv``.
    :returns: the exit code: 0 after a clean shutdown (also where an error came from rclpy's
        handles after Ctrl-C had shut the context down), 1 for a bad configuration, 2 when rcl
        refuses the command line (e.g. an unreadable params file).
    """
    single_threaded_blas()
    logger = rclpy.logging.get_logger(NODE_NAME)
    try:
        rclpy.init(args=args)
    except RuntimeError as error:  # rclpy's RCLError: e.g. an unreadable params file
        text = ' '.join(str(error).split())
        logger.error(f'cannot start: {text}')
        return 2
    node = None
    try:
        node = ImpactNode()
        for warning in params_file_warnings(sys.argv if args is None else args,
                                            node.get_fully_qualified_name()):
            node.get_logger().warning(warning)
        freeze_start_up()
        rclpy.spin(node, Executor())
    except RosError as error:
        logger.error(f'invalid configuration, not starting: {error}')
        return 1
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except Exception:  # noqa: B902 - re-raised unless the context was shut down under it
        if rclpy.ok():
            raise
        # Ctrl-C (or SIGTERM) shut the context down under the executor mid-wait: rclpy's
        # handles gone (an AttributeError or InvalidHandle from its wait set) are the shutdown
        # asked for, not a failure, so no traceback and exit 0
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
