"""
The stream detector: samples in, impact and near-miss events out.

Pure Python + numpy: no rclpy, no rosbags. The ROS node and the bag tools both translate their
messages into calls on one ``Detector`` and its events back into messages, so a bag gives the
same impacts through both.

Stamps at the boundary are integer nanoseconds (``header.stamp``); inside, times are float
seconds relative to the first accepted stamp (``gate.Clock``).

How samples become events (each step in its own module):

* ``gate``: each sample's values are checked (numbers, unit quaternion, a lost mocap body),
  then ``intake`` orders it (the frame the streams agree on, stamp order, a lone stamp glitched
  ahead, a jump back confirmed by the samples after it) and the physical bounds (speed, bat
  length) apply; a bad sample is dropped for one ``DropReason``, a confirmed jump resets;
* ``streams``: accepted samples are kept per body in a short buffer; ``pairing`` pairs knob and
  tip points into bat samples by stamp, interpolating the other point when stamps differ
  (never across a frame of its stream that came without a point: that frame is one drop);
* ``scheduler``: the union of both streams' sample times is walked up to the watermark;
* ``sweep``: each union interval is located in both streams (``StreamGap`` across a long gap),
  tested far apart (``broadphase``, then the motion paths), else cut into sub-steps solved
  exactly (``toi``); ``episodes`` decides when a contact is an ``Impact`` (armed) and when a
  pass is a ``NearMiss``; ``kinematics`` fits the velocities at an impact;
* ``predictor``: after each processed frame, a ``Prediction`` of the coming impact.

This module is the facade that wires them and keeps the public calls.
"""

from collections import Counter
from dataclasses import replace
import time
from typing import AbstractSet, Any, Callable, List, Optional, Sequence, Tuple, Union

from .bat_glitches import departures_ahead
from .chunks import feed_chunk, PLAN_MAX, UNPLANNED_AFTER_EARLY
from .config import DetectorConfig
from .episodes import bat_at_rest, EpisodeTracker
from .events import DetectorStats, DropReason, Event, Impact, ResetReason, Role, StateReset
from .fitting import stream_noise
from .gate import (
    Clock, FAR_AHEAD_NS, finite_point, frame_check, frame_text, integer_stamp, LengthCheck,
    lost_body, speed_check, unit_pose, values_error)
from .intake import Intake, Offer
from .noise import NoiseEstimate, record
from .pairing import Pairing
from .prediction_spread import PendingPrediction
from .predictor import Predictor
from .scheduler import Scheduler
from .streams import Stream
from .sweep import Sweep
from .uncertainty import PendingUncertainty, uncertainty_basis
from ..geometry import pose_point, Vector
from ..motion import BatSample, samples_ahead
from ...errors import CoreError

Check = Callable[[Role, Any], Any]
"""Checks one sample's values (role, values): returns them cleaned, or a ``DropReason``."""

# the roles as module constants: looking a member up on its enum class costs several times a
# global lookup, on the path every sample takes
_BALL, _BAT_POSE, _KNOB, _TIP = Role


class Detector:
    """
    Stateful impact detector: feed samples with ``add_*``, get events back.

    Every ``add_*`` returns the events that sample made decidable (often none). ``finish()``
    at the end of a recording processes what is left; ``reset()`` drops all state.

    :param config: the detector configuration.
    :param deferred_uncertainty: the impacts the calls return have their uncertainties zero,
        and the predictions None, and ``take_pending`` hands over what measures them
        (``PendingUncertainty.measure``, ``PendingPrediction.measure``: the same uncertainties
        to the bit, taken when the event was made), so an adapter can send an impact or a
        prediction before its error bars' re-solves (the node). Off: every impact and
        prediction returned carries them.
    :param on_contact: called with each impact's stamp (ns) and contact point (m) the moment
        its contact is solved, inside the ``add_*`` call that returns the impact, before its
        velocities are fitted (about 0.2 ms at 1 kHz; the node sends ``~/impact`` from it).
        The same stamp and point as the impact's.
    """

    RESTART_FIELDS = ('model', 'bat_input', 'profile', 'geometry', 'frame_id')
    """Config fields that cannot change on a running detector (they shape its buffers)."""

    ROLES = tuple(Role)
    """Sample roles accepted by ``add``."""

    def __init__(self, config: Optional[DetectorConfig] = None, *,
                 deferred_uncertainty: bool = False,
                 on_contact: Optional[Callable[[int, Vector], None]] = None) -> None:
        self._config = _checked(config) if config is not None else DetectorConfig()
        self._on_contact = on_contact
        self._pending: Optional[List[PendingUncertainty]] = [] if deferred_uncertainty else None
        self.stats = DetectorStats()
        self._plan_length = PLAN_MAX  # samples the next chunk plan covers (chunks.feed_chunk)
        self._unplanned_after = UNPLANNED_AFTER_EARLY  # (after a plan overturned early)
        self._offsets: Tuple[Vector, Vector] = (
            tuple(float(x) for x in self._config.geometry.knob_offset),
            tuple(float(x) for x in self._config.geometry.tip_offset))
        roles = (_BALL, _BAT_POSE) if self._config.bat_input == 'pose' else (_BALL, _KNOB, _TIP)
        self._intake = Intake(self._config, self.stats, self._stream_of, self._take, self._jump,
                              roles)
        self._clear()

    def _clear(self) -> None:
        """Start from nothing: new streams, clock, episodes, plan."""
        config = self._config
        self._clock = Clock()
        self._intake.clear()
        self._ball = Stream('ball')
        self._bat = Stream('bat')
        self._pairing = Pairing()
        self._lengths = LengthCheck()
        self._episodes = EpisodeTracker(config, self._clock, self.stats)
        self._sweep = Sweep(config, self._clock, self.stats, self._ball, self._bat,
                            self._episodes, self._offsets)
        self._scheduler = Scheduler(config, self._ball, self._bat)
        self._predictor = Predictor(config, self._clock, self._ball, self._bat, self._offsets)
        self._sweep.measure, self._sweep.on_contact = self._measure, self._on_contact
        self._sweep.frame_of = lambda: self._intake.frame
        self._predictor.drop_bat = self._sweep._bat_glitch  # (the forecast's frames judged)
        self._predictor.defer = None if self._pending is None else self._defer
        self._noise = None if config.tracker_noise >= 0.0 else (
            NoiseEstimate('point'), NoiseEstimate('length' if config.bat_input == 'points'
                                                  else 'pose'))
        self._sweep.estimators = self._noise  # (their estimates kept: ``noise.record``)

    def _measure(self, impact: Impact) -> Impact:
        """Return an impact with its 1-sigma uncertainties, or keep them pending (deferred)."""
        pending = uncertainty_basis(self._config, self._clock, self._ball, self._bat,
                                    self._offsets, impact, self._sweep.time_spread)
        if self._pending is None:
            return pending.measure()
        self._pending.append(pending)
        return impact

    def _defer(self, pending: PendingPrediction) -> None:
        """Keep a prediction's error bars pending (deferred: ``take_pending``)."""
        self._pending.append(pending)

    def take_pending(self) -> List[Union[PendingUncertainty, PendingPrediction]]:
        """
        Return the impacts and predictions since the last call whose error bars are pending.

        In the order the calls returned them. Only with ``deferred_uncertainty`` (else always
        empty). ``reset`` keeps them: each holds copies of what it is measured from, and its
        event was already returned.
        """
        if self._pending is None:
            return []
        pending, self._pending = self._pending, []
        return pending

    def departures_ahead(self) -> int:
        """
        Make the newest bat frames' departures ahead of the judgments that will read them.

        ``bat_glitches.departures_ahead`` at the bat's noise (m, 1 sigma: told or estimated):
        for a shell to call off a message's path (the node after its drain), so that a frame's
        first glitch judgment near the ball does not make them all in one message. Changes no
        event, verdict or output (a departure made ahead serves only at its very noise).
        Returns how many it made.
        """
        config = self._config
        return departures_ahead(self._bat, config.max_gap, config.spline_window,
                                stream_noise(self._bat, config))

    # ---- configuration -------------------------------------------------------------------

    @property
    def config(self) -> DetectorConfig:
        """Return the configuration in force."""
        return self._config

    @config.setter
    def config(self, config: DetectorConfig) -> None:
        """Set the configuration in force: ``reconfigure``, with its checks and errors."""
        self.reconfigure(config)

    def refusal(self, config: DetectorConfig) -> Optional[str]:
        """
        Return why the running detector cannot take ``config`` (a restart can), or None.

        It changes one of ``RESTART_FIELDS``, or asks for ``tracker_noise`` auto where the
        detector started with a told noise (its streams' estimates were never kept; from auto a
        told value and back are fine: the estimates go on).
        """
        changed = [name for name in self.RESTART_FIELDS
                   if getattr(config, name) != getattr(self._config, name)]
        if config.tracker_noise < 0.0 and self._noise is None:
            changed.append('tracker_noise (to auto, from the told noise it started with)')
        if changed:
            return f"{', '.join(changed)} cannot change while running: restart"
        return None

    def reconfigure(self, config: DetectorConfig) -> None:
        """
        Swap in a new configuration that differs only in thresholds.

        :raises CoreError: not a ``DetectorConfig``, or the running detector cannot take it
            (``refusal`` says why).
        """
        reason = self.refusal(_checked(config))
        if reason is not None:
            raise CoreError(reason)
        self._config = config
        for part in (self._episodes, self._sweep, self._scheduler, self._predictor, self._intake):
            part.config = config

    def set_bat_plan(self, stamps_ns: Sequence[int], positions: Sequence[Sequence[float]],
                     quaternions: Sequence[Sequence[float]]) -> None:
        """
        Set a commanded bat trajectory (poses in the bat's body frame, as for pose input).

        Predictions use it instead of extrapolating the bat, over the span it covers. An empty
        plan clears it.

        :raises CoreError: more than ``prediction.MAX_PLAN_POSES`` poses (10,000), lists of
            different lengths, stamps not integer nanoseconds or not increasing, a position
            not 3 finite numbers, a quaternion not 4 or not unit length.
        """
        self._predictor.set_plan(stamps_ns, positions, quaternions)

    def take_bat_plan(self, stamps_ns: Sequence[int], positions: Sequence[Sequence[float]],
                      quaternions: Sequence[Sequence[float]],
                      frames: AbstractSet[str] = frozenset()) -> Optional[str]:
        """
        Set a commanded bat trajectory sent in ``frames``, unless it is refused: say why.

        What the node and ``analyze`` do with a plan message (``frames``: every non-empty frame
        its header and poses name; none: the tracking frame, as a sample naming none). Refused:
        a frame other than the tracking frame (``frame_id``, or the one the streams agreed
        on), a frame named before any tracking frame is known (it cannot be checked), or what
        ``set_bat_plan`` raises for. An empty plan clears the one in force.

        :returns: None where it is taken, else the reason it was refused (one line).
        """
        expected = self.frame_id
        if expected is None and frames and stamps_ns:
            return (f'frame {sorted(frames)} cannot be checked: no tracking frame is known '
                    'yet (set frame_id, or send the plan once the trackers stream)')
        if expected is not None and set(frames) - {expected}:
            return f'frame {sorted(frames)} is not the tracking frame {expected!r}'
        try:
            self.set_bat_plan(stamps_ns, positions, quaternions)
        except CoreError as error:
            return str(error)
        return None

    def reset(self, stamp_ns: int = 0, reason: str = ResetReason.REQUESTED) -> StateReset:
        """
        Drop every buffered sample and episode (and the bat plan); counters are kept.

        :param stamp_ns: its stamp (ns, an integer).
        :param reason: a ``ResetReason`` (passed on as given).
        :returns: the ``StateReset`` event describing it.
        :raises CoreError: a stamp that is not an integer (nothing is cleared then).
        """
        stamp = integer_stamp(stamp_ns)
        self._sweep.settle_aside(None)  # (counted as dropped)
        self._clear()
        self.stats.resets += 1
        return StateReset(stamp_ns=stamp, reason=reason)

    @property
    def frame_id(self) -> Optional[str]:
        """Return the tracking frame: the configured one, else the one the streams agreed on."""
        return self._intake.frame

    @property
    def frame_disagreement(self) -> Optional[str]:
        """
        Return each input stream's frames while no frame can be adopted, else None.

        With ``frame_id`` '' and streams whose frames differ (no frame that every stream
        sending one has sent): ``"ball sends 'world', bat_pose sends 'arm_base'"``. Their
        samples waiting for agreement are dropped as ``no_common_frame``
        (``gate.FrameVote.disagreement``); the node and ``analyze`` say it in these words.
        """
        return self._intake.votes.disagreement()

    def positions_at(self, stamp_ns: int) -> Optional[Tuple[Vector, Vector, Vector]]:
        """
        Return where the detector moves the ball and the bat at a stamp: (ball, knob, tip), m.

        On the paths its motion model builds over the sample intervals holding the stamp (the
        very paths it solves there: windows, smoothing, a ball's free flight after it left the
        bat, a glitch left out), from the samples it still keeps (about
        ``kept_history`` behind the newest). None before the first sample, outside the kept
        samples or across a gap. For plots and inspection: it makes no event (a ball glitch
        it meets first is counted, as the sweep counts it).

        :param stamp_ns: the stamp (ns, an integer).
        :raises CoreError: a stamp that is not an integer.
        """
        stamp = integer_stamp(stamp_ns)
        if self._clock.origin is None:
            return None
        t = self._clock.time(stamp)
        paths = self._sweep.paths_at(t)
        if paths is None:
            return None
        knob, tip = paths[1].at(t)
        return tuple(paths[0].at(t)), tuple(knob), tuple(tip)

    @property
    def noise(self) -> Tuple[float, float]:
        """
        Return the tracking noise each body's fits take, ball then bat (m, 1 sigma a coordinate).

        The told ``tracker_noise`` for both, or under auto each stream's estimate from its
        newest samples (``noise.NoiseEstimate.sigma``: 0 for exact samples and until enough
        have come; a state reset starts it again). The same in the node and ``analyze`` after
        the same samples.
        """
        if self._noise is None:
            return self._config.tracker_noise, self._config.tracker_noise
        return self._noise[0].sigma, self._noise[1].sigma

    @property
    def watermark_ns(self) -> Optional[int]:
        """Return the newest instant (ns) up to which everything has been processed."""
        cursor = self._scheduler.cursor
        if cursor is None or self._clock.origin is None:
            return None
        return self._clock.stamp(cursor)

    # ---- input ---------------------------------------------------------------------------

    def add_ball(self, stamp_ns: int, position: Sequence[float],
                 frame_id: str = '') -> List[Event]:
        """
        Add a ball centre (m) stamped ``stamp_ns`` (ns); return the events it made decidable.

        :raises CoreError: as ``add``.
        """
        return self._timed(self._check_point, _BALL, stamp_ns, position, frame_id)

    def add_bat_pose(self, stamp_ns: int, position: Sequence[float],
                     quaternion: Sequence[float], frame_id: str = '') -> List[Event]:
        """
        Add a bat pose, position (m) and unit quaternion (x, y, z, w); return the events.

        :raises CoreError: as ``add`` (a position not 3 numbers, a quaternion not 4).
        """
        return self._timed(self._check_pose, _BAT_POSE, stamp_ns, (position, quaternion),
                           frame_id)

    def add_knob(self, stamp_ns: int, position: Sequence[float],
                 frame_id: str = '') -> List[Event]:
        """Add a knob (m), for a bat as knob and tip points; return the events."""
        return self._timed(self._check_point, _KNOB, stamp_ns, position, frame_id)

    def add_tip(self, stamp_ns: int, position: Sequence[float],
                frame_id: str = '') -> List[Event]:
        """Add a tip (barrel end, m), for a bat as knob and tip points; return the events."""
        return self._timed(self._check_point, _TIP, stamp_ns, position, frame_id)

    def add(self, role: str, stamp_ns: int, values: Sequence[float],
            frame_id: str = '') -> List[Event]:
        """
        Add a sample by role: the one entry point for message adapters (node, bag replay).

        :param role: ``'ball'``, ``'knob'`` or ``'tip'`` with values (x, y, z) in metres, or
            ``'bat_pose'`` with values (px, py, pz, qx, qy, qz, qw) (a ``Role``).
        :param stamp_ns: header stamp (ns, an integer).
        :param frame_id: the header's frame.
        :returns: the events this sample made decidable. A sample that cannot be taken is
            dropped, not raised: ``stats.last_drop_reason`` says why (a NaN or infinite value:
            ``non_finite``) and ``stats.dropped`` counts it.
        :raises CoreError: an unknown role, a stamp that is not an integer, a frame_id that
            is not a str, or values that are not 3 (7) numbers (programming errors, not bad
            data: nothing is counted).
        """
        if role == 'ball':
            return self._timed(self._check_point, _BALL, stamp_ns, values, frame_id)
        if role == 'bat_pose':  # split inside the guard: unsliceable values are dropped too
            return self._timed(self._check_pose_values, _BAT_POSE, stamp_ns, values,
                               frame_id)
        if role == 'knob':
            return self._timed(self._check_point, _KNOB, stamp_ns, values, frame_id)
        if role == 'tip':
            return self._timed(self._check_point, _TIP, stamp_ns, values, frame_id)
        raise CoreError(f"role must be one of {', '.join(self.ROLES)}, got '{role}'")

    def add_chunk(self, roles: Sequence[int], stamps_ns: Sequence[int], values: Any,
                  frame_ids: Sequence[str], drops: Optional[Counter] = None) -> List[Event]:
        """
        Add many samples, in arrival order: the same events as ``add`` for each in turn.

        The common case (samples far from any contact, passing every check) is taken with
        numpy for the whole chunk (``chunks``); every other sample goes through ``add``. A chunk
        of one sample is simply ``add``.

        :param roles: each sample's role as its index in ``ROLES`` (``chunks.ROLE_CODES``).
        :param stamps_ns: header stamps (ns).
        :param values: (n, 7) floats: (x, y, z) in the first three columns for a ball, knob or
            tip (m), (px, py, pz, qx, qy, qz, qw) for a bat pose.
        :param frame_ids: each sample's frame.
        :param drops: when given, counts ``(role, reason)`` of every sample dropped (late drops
            of samples that had waited included).
        :returns: the events the samples made decidable, in order.
        :raises CoreError: role codes or stamps that are not integers (or stamps beyond
            int64) or not 1-d, an unknown role code, values that are not numbers or not
            (n, 7), frame_ids that are not one str per sample (a sized sequence), or arrays of
            different lengths (nothing is taken then).
        """
        return feed_chunk(self, roles, stamps_ns, values, frame_ids, drops)

    def finish(self) -> List[Event]:
        """
        Process what is left at the end of a recording and close an open near miss.

        Not a flush: every call returns its events as soon as they are decidable, and a second
        ``finish`` returns none. Called before the recording ends, it closes the pass in
        progress: the samples after it start a new one (a second near miss, or a near miss and
        then the impact, for one pass of the ball finished a few frames before its contact).
        ``reset()`` starts another recording.

        :returns: the remaining events.
        """
        events: List[Event] = []
        self.stats.late_drops = []
        self._intake.flush(events)
        if samples_ahead(self._config.model, self._config.look_ahead) or self._sweep.held:
            self._advance(events, final=True)
        self._sweep.settle_aside(None)
        self._episodes.close(events)
        return events

    def _timed(self, check: Check, role: Role, stamp_ns: int, value: Any,
               frame_id: str) -> List[Event]:
        """Check a sample's values, offer it to the intake; count it, why dropped, the time."""
        start = time.perf_counter()
        events: List[Event] = []
        stats = self.stats  # inline, not a method: this runs for every sample offered
        if stats.late_drops:
            stats.late_drops = []
        stamp = stamp_ns if stamp_ns.__class__ is int else integer_stamp(stamp_ns)
        try:  # the values only: an error past the checks is the detector's own, raised
            clean = check(role, value)
        except (TypeError, ValueError) as error:  # not numbers of the role's shape: a bug
            if isinstance(error, CoreError):
                raise
            raise CoreError(values_error(role, value, check == self._check_pose)) from error
        if stamp <= 0:
            clean = DropReason.BAD_STAMP
        if frame_id.__class__ is not str:
            frame_id = frame_text(frame_id)
        if clean.__class__ is DropReason:
            reason = clean
            if clean is DropReason.NON_FINITE and (role is _KNOB or role is _TIP):
                self._missed(role, stamp, frame_id)
        else:
            reason = self._intake.offer(Offer(role, stamp, clean, frame_id), events)
        elapsed = time.perf_counter() - start
        stats.received[role] += 1
        stats.last_drop_reason = reason
        if reason is not None:
            stats.dropped[reason] += 1
        stats.calls += 1
        stats.last_processing_s = elapsed
        stats.total_processing_s += elapsed
        if elapsed > stats.max_processing_s:
            stats.max_processing_s = elapsed
        return events

    # ---- value checks (before any state is looked at) ------------------------------------

    def _check_point(self, role: Role, value: Sequence[float]) -> Union[DropReason, Vector]:
        """Return a ball, knob or tip as floats, or why it is dropped."""
        if role is not _BALL and self._config.bat_input != 'points':
            return DropReason.UNEXPECTED_INPUT
        point = finite_point(value)
        return DropReason.NON_FINITE if point is None else point

    def _check_pose(self, role: Role, value: Tuple[Sequence[float], Sequence[float]]) -> Any:
        """Return a bat pose (position, unit quaternion), or why it is dropped."""
        if self._config.bat_input != 'pose':
            return DropReason.UNEXPECTED_INPUT
        pose = unit_pose(value)
        if pose.__class__ is not DropReason and self._config.drop_lost_body and lost_body(*pose):
            return DropReason.LOST_BODY
        return pose

    def _check_pose_values(self, role: Role, values: Sequence[float]) -> Any:
        """Return a bat pose given as 7 numbers (``add``), or why it is dropped."""
        if self._config.bat_input != 'pose':  # (before the values, as for the other inputs)
            return DropReason.UNEXPECTED_INPUT
        return self._check_pose(role, (values[:3], values[3:]))

    # ---- taking admitted samples (the intake calls these) --------------------------------

    def _stream_of(self, role: Role) -> Stream:
        """Return the stream a sample of ``role`` is ordered in."""
        if role is _BALL:
            return self._ball
        if role is _BAT_POSE:
            return self._bat
        return self._pairing.knob if role is _KNOB else self._pairing.tip

    def _missed(self, role: Role, stamp: int, frame_id: str) -> None:
        """
        Note a knob or tip frame stamped (ns) whose point was not finite (``Pairing.missed``).

        The other point of that frame is then not paired with one interpolated across it: the
        frame is one drop (``non_finite``), not a second one for the length a chord gives. A
        frame the tracking frame refuses (another publisher's) is not this tracker's.
        """
        if frame_check(frame_id, self._intake.votes.frame) is None:
            self._pairing.missed(self._stream_of(role), stamp)

    def _jump(self, stamp: int, reason: ResetReason, events: List[Event]) -> None:
        """Reset for a time jump at ``stamp`` (ns): close the open episode first."""
        self._episodes.close(events)
        events.append(self.reset(stamp, reason))

    def _take(self, offer: Offer, events: List[Event]) -> Optional[DropReason]:
        """Put an admitted sample into its stream and process what it made decidable."""
        stamp = offer.stamp
        if self._clock.origin is not None and stamp - self._clock.origin > FAR_AHEAD_NS:
            # a new session (or a wild clock): a new origin keeps float times at ns resolution
            self._jump(stamp, ResetReason.TIME_JUMP_FORWARD, events)
        clock, stats = self._clock, self.stats
        if clock.origin is None:
            clock.origin = stamp
        if stats.newest_stamp_ns is None or stamp > stats.newest_stamp_ns:
            stats.newest_stamp_ns = stamp
        t = clock.time(stamp)
        role = offer.role
        if role is _BALL:
            ball = self._ball
            accept, new_segment = speed_check(ball, t, (offer.value,), ball.values[-1:],
                                              self._config.max_gap, self._config.max_speed)
            if not accept:  # (kept aside while its newest may be a glitch: ``Sweep``)
                return self._sweep.set_aside(t, offer, self._scheduler.cursor)
            if new_segment:  # (the flight before a tracking gap, kept: ``Sweep.note_gap``)
                self._sweep.note_gap(t)
            ball.append(t, stamp, offer.value, new_segment)
            if self._noise is not None:
                ball.noise = self._noise[0].update(ball)
                record(ball)
            self._advance(events)
            return None
        if role is _BAT_POSE:
            position, quaternion = offer.value
            knob_offset, tip_offset = self._offsets
            sample = BatSample(knob=pose_point(position, quaternion, knob_offset),
                               tip=pose_point(position, quaternion, tip_offset),
                               position=position, quaternion=quaternion)
            return self._accept_bat(t, stamp, sample, events)
        pairing = self._pairing
        pairing.append(pairing.knob if role is _KNOB else pairing.tip, t, stamp, offer.value)
        reason = None
        for tp, knob, tip in pairing.pairs(self._config.max_gap):
            reason = self._accept_bat(tp, clock.stamp(tp), BatSample(knob=knob, tip=tip),
                                      events, self._lengths) or reason
        pairing.trim()
        return reason

    def _accept_bat(self, t: float, stamp: int, sample: BatSample, events: List[Event],
                    lengths: Optional[LengthCheck] = None) -> Optional[DropReason]:
        """Take a bat sample after the length (points only) and speed checks."""
        config = self._config
        if lengths is not None:
            reason = lengths.check(sample.knob, sample.tip, config.bat_length_tolerance)
            if reason is not None:
                return reason
        bat = self._bat
        previous = (bat.values[-1].knob, bat.values[-1].tip) if bat.values else ()
        accept, new_segment = speed_check(bat, t, (sample.knob, sample.tip), previous,
                                          config.max_gap, config.max_speed)
        if not accept:
            return DropReason.SPEED_LIMIT
        bat.append(t, stamp, sample, new_segment)
        if self._noise is not None:
            bat.noise = self._noise[1].update(bat)
            record(bat)
        self._advance(events)
        return None

    def _advance(self, events: List[Event], final: bool = False) -> None:
        """Sweep every union interval now decidable, then predict from the new cursor."""
        first = len(events)
        self._sweep.final = final  # (an interval waiting for ball samples waits no longer)
        moved = self._scheduler.advance(self._sweep.interval, events, final)
        config = self._config
        if config.rest_tolerance > 0.0:
            for i in range(first, len(events)):
                event = events[i]
                if event.__class__ is Impact and bat_at_rest(
                        self._bat, self._clock.time(event.stamp_ns), config.velocity_window,
                        config.rest_tolerance):
                    events[i] = replace(event, bat_at_rest=True)
                    if self._pending:  # (deferred: its uncertainties measure this one)
                        self._pending = [replace(pending, impact=events[i])
                                         if pending.__class__ is PendingUncertainty
                                         and pending.impact is event else pending
                                         for pending in self._pending]
        if moved and config.prediction_horizon > 0.0:
            self._predictor.predict(self._scheduler.cursor, self._episodes.armed, events)


def _checked(config: Any) -> DetectorConfig:
    """
    Return ``config`` if it is a ``DetectorConfig``.

    :raises CoreError: anything else (a dict of node parameters:
        ``DetectorConfig.from_parameters`` makes one).
    """
    if isinstance(config, DetectorConfig):
        return config
    raise CoreError(f'config must be a DetectorConfig, not {type(config).__name__} (node '
                    'parameters as a dict: DetectorConfig.from_parameters(values))')
