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
  ``~/impact_predicted`` (std_msgs/Bool, latched; false right after an ``~/impact``, once
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
``markers``, the status in ``diagnostics`` and QoS or type mismatches in ``endpoints``. See
``config/impact_node.yaml`` for every parameter.
"""

from collections import deque
from dataclasses import replace
import gc
import math
import sys
import threading
import time
import traceback
from typing import Any, Callable, Deque, Dict, List, Optional, Tuple, Union

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PointStamped, TwistStamped, Vector3Stamped
from nav_msgs.msg import Path
from rcl_interfaces.msg import SetParametersResult
import rclpy
from rclpy.clock import Clock, ClockChange, ClockType, JumpThreshold, TimeJump
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Bool, Header, String
from std_srvs.srv import Trigger
from visualization_msgs.msg import MarkerArray

from .diagnostics import report, silent_streams, take_snapshot, Tally
from .endpoints import Endpoints, input_qos
from .inputs import DropWarnings, input_callback, input_streams, Intake, Throttle
from .logger import DirectLogger
from .markers import latest_scene, scene_cdr
from .messages import (
    describe_impact, describe_listening, event_output, event_report, EventOutput, FLAG_CDR,
    format_stamp, NS_PER_S, plan_arrays, stamp_to_ns, StampedCdr)
from .parameters import check_change, declare, start_warnings
from .prediction_watch import PredictionWatch
from ..core.detector import (
    Detector, DetectorConfig, Event, Impact, NODE_NAME, PendingUncertainty, Prediction,
    ResetReason, SPECS, StateReset, unknown_parameters)
from ..core.detector.predictor import kept_flight_span
from ..core.geometry import Vector
from ..core.prediction import MAX_PLAN_POSES
from ..core.records import EVENT_NAMES
from ..core.scene import impact_scene, Scene
from ..errors import CoreError, RosError
from ..threads import single_threaded_blas


CLOCK_ECHO_S = 2.0
"""A state reset by the stamps this soon (s) after a ROS clock jump echoes it: logged at debug."""

_EVENTS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                     reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
_VIEWS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                    reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
_LATCHED = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL)
_OUTPUTS = (  # output name, message type, topic, QoS
    ('predicted_impact', PointStamped, '~/predicted_impact', _EVENTS),
    ('impact_predicted', Bool, '~/impact_predicted', _LATCHED),
    ('impact', PointStamped, '~/impact', _EVENTS),
    ('impact_velocity', TwistStamped, '~/impact_velocity', _EVENTS),
    ('near_miss', Vector3Stamped, '~/near_miss', _EVENTS),
    ('impact_report', String, '~/impact_report', _EVENTS),
    ('markers', MarkerArray, '~/markers', _VIEWS),
    ('diagnostics', DiagnosticArray, '/diagnostics', _VIEWS),
)


class ImpactNode(Node):
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
        # (event, frame, config) to complete once the inputs are drained: reports, and an
        # impact's error bars, line and markers (its PendingUncertainty in place of the event)
        self._to_complete: Deque[Tuple[Union[Event, PendingUncertainty], str, DetectorConfig]] = \
            deque()
        self._clock_jump_at = -math.inf
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
        self.endpoints = Endpoints(self, self.tally)
        self._outputs = {name: self.endpoints.advertise(msg_type, topic, qos)
                         for name, msg_type, topic, qos in _OUTPUTS}
        self._outputs['impact_predicted'].publish(FLAG_CDR[False])  # latched
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
        if s['bat_plan_topic']:
            self._plan_sub = self.create_subscription(
                Path, s['bat_plan_topic'], self._guarded(self._on_plan, 'taking a bat plan'),
                _VIEWS)

    # ---- input ---------------------------------------------------------------------------

    def _on_plan(self, message: Path) -> None:
        """
        Take a commanded bat trajectory (stamped poses) for the predictions; empty clears.

        Refused with a throttled WARN: over ``MAX_PLAN_POSES`` poses, a frame other than the
        tracking frame (the configured ``frame_id``, else the trackers'), a frame named before
        any tracking frame is known (``frame_id`` '' and no sample yet: it cannot be checked),
        or values the core refuses. A plan naming no frame is taken as in the tracking frame,
        as samples are.
        """
        if len(message.poses) > MAX_PLAN_POSES:  # refused before converting a single pose
            if self._log_throttle.allows('plan_size'):
                self._lines.warning(
                    f'ignored a bat plan on {self._plan_sub.topic_name}: {len(message.poses)} '
                    f'poses is more than the {MAX_PLAN_POSES} a plan may hold')
            return
        stamps, positions, quaternions, frames = plan_arrays(message)
        with self._lock:
            expected = self.detector.frame_id
            if expected is None and frames and stamps:
                reason = (f'frame {sorted(frames)} cannot be checked: no tracking frame is known '
                          'yet (set frame_id, or send the plan once the trackers stream)')
            elif expected is not None and frames - {expected}:
                reason = f'frame {sorted(frames)} is not the tracking frame {expected!r}'
            else:
                try:
                    self.detector.set_bat_plan(stamps, positions, quaternions)
                    self._plan = (stamps[0], stamps[-1]) if stamps else None
                    return
                except CoreError as error:
                    reason = str(error)
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
            previous = self._last_values.get(stream)
            if dropped is None:
                self._last_values[stream] = (stamp, values)
                self._watch.accepted(stream, stamp, None if previous is None else previous[0],
                                     arrival)
            pending = iter(self.detector.take_pending())  # the impacts' error bars, to come
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
                    contact = self._contact_ns  # (one made before a contact solved since: off)
                    if (contact is None or event.made_at_ns >= contact) and self._watch.raises(
                            event.stamp_ns, self.detector.config.max_gap):
                        self._set_predicting(True)
                        self._watch.instant_ns = event.stamp_ns
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
            warn(each.role, topics.get(each.role, each.role), each.reason, each.frame_id,
                 expected, each.stamp_ns, stats.dropped[each.reason])
        self._record_processing(time.perf_counter() - start)

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

    def _on_contact(self, stamp_ns: int, point: Vector) -> None:
        """
        Publish ``~/impact`` the moment the detector solves a contact (``Detector.on_contact``).

        Inside ``_take``'s ``add``, before the impact's velocities are fitted: its message's
        stamp and point are the impact's; ``~/impact_velocity`` follows once it is returned.
        ``~/impact_predicted`` turns false right after it: the contact came (the detector's
        ``PredictionCleared`` comes only at its next frame that predicts, up to
        ``prediction_period`` later). A prediction the same ``add`` returns that was made before
        the contact does not turn it on again.
        """
        self._outputs['impact'].publish(self._point_cdr(
            stamp_ns, self._frame or self.detector.frame_id or '', point))
        self.tally.last_impact_ns = stamp_ns
        self._contact_ns = stamp_ns
        self._set_predicting(False)

    def _then_reports(self, on_message: Callable[[Any, Any], None]) -> Callable[[Any, Any], None]:
        """Return an input's executor callback: ``on_message`` (and the drain), then reports."""
        complete = self._guarded(self._complete_events, "completing the impacts' reports")

        def handled(message: Any, info: Any) -> None:
            on_message(message, info)
            complete()
        return handled

    def _complete_events(self) -> None:
        """
        Complete the queued events in order: impacts' error bars, lines, markers; reports.

        An impact's ``~/impact`` and ``~/impact_velocity`` went out as its message was handled;
        here its 1-sigma uncertainties are measured (``PendingUncertainty.measure``: re-solves
        from copies of its samples taken then, 0.3-0.6 ms; the same to the bit as ``analyze``'s),
        its INFO line logged and its markers published. Then each event's ``~/impact_report``.
        Called after each input's executor callback, once the intake has drained the queues
        (no message waiting, or ``DRAIN_LIMIT`` taken), so the error bars and a record's JSON (a
        third of the message that predicts, with a recorder subscribed) delay no message taken
        in it and no output an arm reads. Records are made only while the topic has a subscriber
        (it is volatile: a record published to nobody reaches nobody).
        """
        queued, publisher = self._to_complete, self._outputs['impact_report']
        subscribed = bool(queued) and publisher.get_subscription_count() > 0
        while queued:
            event, frame, config = queued.popleft()
            if event.__class__ is PendingUncertainty:
                try:
                    event = self._measured(event, frame)
                except Exception as error:  # the error bars' own failure (a bug)
                    self._failed(f'the error bars of the impact at '
                                 f'{format_stamp(event.impact.stamp_ns)} s failed',
                                 'its line, markers and report are left out', error)
                    continue
            if subscribed:
                publisher.publish(event_report(event, frame, config))

    def _measured(self, pending: PendingUncertainty, frame: str) -> Impact:
        """Return a pending impact with its error bars; log its line, publish its markers."""
        impact = pending.measure()
        self._lines.info(describe_impact(impact))
        markers = self._markers(impact, frame)
        if markers is not None:
            self._outputs['markers'].publish(markers)
        return impact

    def _record_processing(self, elapsed_s: float) -> None:
        """Account the wall time (s) one message took in its callback."""
        self.tally.period.record(elapsed_s)

    # ---- events --------------------------------------------------------------------------

    def _markers(self, impact: Impact, frame: str) -> Optional[bytes]:
        """Return an impact's markers (CDR bytes), or None when ``publish_markers`` is off."""
        if not self.settings['publish_markers']:
            return None
        return scene_cdr(impact_scene(impact, frame, self.detector.config,
                                      self.settings['marker_lifetime']))

    def _publish(self, output: EventOutput) -> None:
        """Publish what one event became and log its line."""
        if output.predicting is not None:
            self._set_predicting(output.predicting)
        for name, message in output.messages:
            self._outputs[name].publish(message)
        if output.impact_ns is not None:
            self.tally.last_impact_ns = output.impact_ns
        if not output.log:
            return
        logger = self._lines
        if output.throttled:
            if self._log_throttle.allows('event'):
                logger.info(output.log)
        elif output.echoes_clock_jump and time.monotonic() - self._clock_jump_at < CLOCK_ECHO_S:
            logger.debug(output.log)  # the clock jump already warned
        elif output.level == 'warning':
            logger.warning(output.log)
        else:
            logger.info(output.log)

    def _set_predicting(self, predicting: bool) -> None:
        """Publish a change of ~/impact_predicted (latched)."""
        if predicting != self._predicting:
            self._predicting = predicting
            self._outputs['impact_predicted'].publish(FLAG_CDR[predicting])  # a Bool's bytes

    def _publish_live_markers(self) -> None:
        """
        Publish the last accepted bat and ball as markers (timer, steady clock).

        Stamped with the newest of their samples' stamps; published only when a new sample
        came since the last array (they expire two periods after input stops).
        """
        if not self.settings['publish_markers']:
            return
        with self._lock:
            last = dict(self._last_values)
            frame = self.detector.frame_id or ''
            config = self.detector.config
        newest = max((stamp for stamp, _ in last.values()), default=None)
        if newest is None or newest == self._markers_stamp:
            return  # nothing new: no republish
        self._markers_stamp = newest
        scene = latest_scene(last, frame, config, 2.0 / self.settings['marker_rate'])
        if scene is not None:
            self._outputs['markers'].publish(scene_cdr(scene))

    # ---- services and clock --------------------------------------------------------------

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

    def _clear_markers(self, stamp_ns: int, frame: str) -> None:
        """After a state reset: forget the live values, clear the markers (DELETEALL)."""
        self._last_values.clear()
        self._watch.clear()
        self._markers_stamp = None
        if self.settings['publish_markers']:
            self._outputs['markers'].publish(scene_cdr(
                Scene(stamp_ns, frame, (), delete_all=True)))

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

    # ---- parameters at runtime, diagnostics ----------------------------------------------

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
        """Publish the status on /diagnostics (timer, steady clock); end a silent prediction."""
        array = DiagnosticArray(status=[self.diagnostics()])
        array.header.stamp = self.get_clock().now().to_msg()
        self._outputs['diagnostics'].publish(array)
        self._withdraw_a_silent_prediction()

    def _withdraw_a_passed_prediction(self, now: float) -> None:
        """
        Turn ``~/impact_predicted`` false once no input can still bring the predicted contact.

        Called under the node's lock after an input sample was taken, at ``now`` (s, the
        steady clock its arrival was counted on): when the prediction has passed
        (``PredictionWatch.passed``: every stream took two samples more than ``max_gap`` past
        the predicted instant without a contact, or the bat did and the ball has been silent
        longer than its lag behind the bat plus ``max_gap``, the bat streams past the span its
        flight holds unseen, ``kept_flight_span``; the detector's own frames clear a
        prediction only at its next frame that predicts), or when an input has been silent
        beyond ``stale_timeout`` (``_silent_locked``; checked here too, so a stream lost while
        another streams on ends it then, not up to a ``diagnostics_period`` later). The
        detector's prediction is left as it is.

        :param now: the steady-clock time (s) of the sample just taken.
        """
        config = self.detector.config
        if self._watch.passed(now, self.tally.last_arrival, config.max_gap,
                              kept_flight_span(config.prediction_window)) \
                or self._silent_locked(now):
            self._set_predicting(False)

    def _withdraw_a_silent_prediction(self) -> None:
        """
        Turn ``~/impact_predicted`` false once an input has been silent beyond ``stale_timeout``.

        A prediction is cleared by the frame that shows it wrong or past; when the frames stop
        (the tracker lost the ball, the streams died) none comes, and the flag stayed true for
        good: an arm waited on a contact that nothing will measure. Checked every
        ``diagnostics_period`` (all streams silent) and after each input sample (one silent,
        the others streaming: ``_withdraw_a_passed_prediction``). The detector's prediction is
        left as it is: its next prediction turns the flag true again.
        """
        with self._lock:
            if self._predicting and self._silent_locked(time.monotonic()):
                self._set_predicting(False)

    def _silent_locked(self, now: float) -> bool:
        """
        Return whether an input has been silent beyond ``stale_timeout`` at ``now``.

        :param now: the steady-clock time (s) to measure the silence to; the node's lock held.
        """
        timeout = self.settings['stale_timeout']
        return any(now - self.tally.last_arrival.get(stream, -math.inf) > timeout
                   for stream in self._streams)

    def destroy_node(self) -> None:
        """Unregister the clock jump callback, then destroy the node."""
        handle = getattr(self, '_jump_handle', None)
        if handle is not None:
            handle.unregister()
            self._jump_handle = None
        super().destroy_node()


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


def main(args: Optional[List[str]] = None) -> int:
    """
    Run the node until Ctrl-C or shutdown.

    :param args: command line (``--ros-args ...``); ``None``: ``sys.argv``.
    :returns: the exit code: 0 after a clean shutdown, 1 for a bad configuration, 2 when rcl
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
        freeze_start_up()
        rclpy.spin(node)
    except RosError as error:
        logger.error(f'invalid configuration, not starting: {error}')
        return 1
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
