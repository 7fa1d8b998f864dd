"""
What the detector says: typed events, the names it uses (enums) and its counters.

Every enum here is a ``str`` (``enum.StrEnum``): a member compares equal to, hashes like,
prints and serialises (JSON, CSV, ROS strings) as its plain value, so ``'side'``, ``'ball'`` or
``'speed_limit'`` work wherever a member is expected and the other way round.
"""

from collections import Counter
from dataclasses import dataclass, field
import enum
from typing import List, Optional, Union

from ..geometry import Vector
from ..toi import Feature

MPS_TO_MPH = 1.0 / 0.44704
"""Metres per second to miles per hour."""


class Role(enum.StrEnum):
    """What a sample offered to ``Detector.add`` is (the keys of ``DetectorStats.received``)."""

    BALL = 'ball'
    BAT_POSE = 'bat_pose'
    KNOB = 'knob'
    TIP = 'tip'


class DropReason(enum.StrEnum):
    """Why a sample was dropped (the keys of ``DetectorStats.dropped``)."""

    WRONG_FRAME = 'wrong_frame'
    NON_FINITE = 'non_finite'
    BAD_STAMP = 'bad_stamp'
    DUPLICATE_STAMP = 'duplicate_stamp'
    OUT_OF_ORDER = 'out_of_order'
    BAD_QUATERNION = 'bad_quaternion'
    ZERO_LENGTH_BAT = 'zero_length_bat'
    BAT_LENGTH_JUMP = 'bat_length_jump'
    SPEED_LIMIT = 'speed_limit'
    UNEXPECTED_INPUT = 'unexpected_input'
    STALE_STAMP = 'stale_stamp'
    """More than ``time_jump_reset`` behind its stream, and not (yet) a jump back: another
    publisher's clock (a replay left running), or a jump not confirmed by later samples."""
    STAMP_AHEAD = 'stamp_ahead'
    """A lone sample stamped well ahead of its stream: the next sample came before it."""
    BAD_FRAME = 'bad_frame'
    """A frame_id with control characters (an embedded NUL) or undecodable bytes."""
    LOST_BODY = 'lost_body'
    """A bat pose exactly at the origin with the identity orientation: what motion capture
    publishes for a rigid body it lost (``drop_lost_body``)."""
    BALL_GLITCH = 'ball_glitch'
    """A ball sample off its free flight that no hit explains (a mislabelled marker, a
    reflection: ``departure.glitch_path``): judged where the ball is near the bat, counted when
    the next sample shows it, and then forgotten (``Sweep.interval``)."""
    BAT_GLITCH = 'bat_glitch'
    """A bat frame off both its continuation and its neighbours' spline (a swapped marker, a
    rigid body solved onto the wrong markers: ``bat_glitches``): judged where a contact
    depends on it, then forgotten (``Sweep``). Counted under the input that was off: the pose,
    or the knob or the tip."""
    NO_COMMON_FRAME = 'no_common_frame'
    """``frame_id`` '' and no frame that every input stream sending one has sent (a bat pose in
    ``arm_base`` beside a ball in ``world``: no TF): none is adopted; a sample that waited for
    agreement beyond ``FRAME_PENDING_MAX`` (or to the end of a recording) is dropped, and the
    waiting goes on (``Detector.frame_disagreement`` names each stream's frames)."""


DROP_REASONS = tuple(reason.value for reason in DropReason)
"""Every reason a sample can be dropped for (the keys of ``DetectorStats.dropped``)."""


class ResetReason(enum.StrEnum):
    """Why the detector dropped its state (``StateReset.reason``)."""

    TIME_JUMP_BACKWARDS = 'time_jump_backwards'
    """A stamp ``time_jump_reset`` behind its stream."""
    TIME_JUMP_FORWARD = 'time_jump_forward'
    """A stamp more than ``FAR_AHEAD_NS`` after the clock's origin: a new session."""
    REQUESTED = 'requested'
    """``Detector.reset`` was called."""
    FRAME_CHANGED = 'frame_changed'
    """The input streams agreed on another frame than the first one seen (a stray): what the
    stray frame's samples built is dropped."""
    DETECTOR_ERROR = 'detector_error'
    """The detector raised while it took a sample (a bug): the node dropped the state to go on
    (``impact_node`` only; ``analyze`` stops on it)."""


@dataclass(frozen=True)
class Impact:
    """
    First contact of a ball with the bat.

    :ivar stamp_ns: the impact instant (ns, same clock as the input stamps).
    :ivar point: contact point on the bat surface (m); ``normal``: unit, bat to ball.
    :ivar bat_fraction: along knob-tip, 0 at the knob, 1 at the tip.
    :ivar distance_from_knob_m, distance_from_tip_m: along the axis, metres.
    :ivar feature: ``'side'``, ``'knob_end'`` or ``'tip_end'`` (a ``Feature``).
    :ivar bat_velocity: bat surface velocity at the contact point (m/s).
    :ivar bat_angular_velocity: rad/s (world frame; without the roll about the bat's axis when
        the bat came as knob and tip points).
    :ivar sweet_spot_velocity: velocity (m/s) of the axis point ``sweet_spot_from_tip`` from
        the tip; ``sweet_spot_speed_mps`` its norm (Statcast's bat speed).
    :ivar bat_speed_at_contact_mps: speed of the bat surface at the contact point.
    :ivar ball_velocity: m/s; ``ball_speed_mps`` its norm.
    :ivar relative_normal_speed_mps: closing speed along the normal (positive approaching).
    :ivar attack_angle_deg: vertical angle of the sweet spot's velocity (degrees, up > 0).
    :ivar ball_position, knob, tip: where the bodies were at the impact (m).
    :ivar model: motion model used.
    :ivar interval_start_ns, interval_end_ns: the union sample interval the impact fell in.
    :ivar velocities_from_history: False when too few samples before the impact existed and
        the velocities had to come from the interval spanning it.
    :ivar initially_overlapping: the contact was already there at the interval start.
    :ivar bat_at_rest: the bat's knob and tip stayed within ``rest_tolerance`` of where they
        were at the impact over the ``velocity_window`` before it: the ball hit a still bat
        (a bat on a stand, a lost body frozen in place), not a swing.
    :ivar time_uncertainty_s, distance_from_knob_uncertainty_m,
        sweet_spot_speed_uncertainty_mps: 1-sigma uncertainties of ``stamp_ns`` (s),
        ``distance_from_knob_m`` (m) and ``sweet_spot_speed_mps`` (m/s): with tracking noise
        its spread (``c2``: propagated from the smoother; other models: the impact re-solved
        under perturbed samples), the interpolation's own error estimate without (``uncertainty``).
    """

    stamp_ns: int
    point: Vector
    normal: Vector
    bat_fraction: float
    distance_from_knob_m: float
    distance_from_tip_m: float
    feature: Feature
    bat_velocity: Vector
    bat_angular_velocity: Vector
    sweet_spot_velocity: Vector
    sweet_spot_speed_mps: float
    bat_speed_at_contact_mps: float
    ball_velocity: Vector
    ball_speed_mps: float
    relative_normal_speed_mps: float
    attack_angle_deg: float
    ball_position: Vector
    knob: Vector
    tip: Vector
    model: str
    interval_start_ns: int
    interval_end_ns: int
    velocities_from_history: bool
    initially_overlapping: bool
    bat_at_rest: bool = False
    time_uncertainty_s: float = 0.0
    distance_from_knob_uncertainty_m: float = 0.0
    sweet_spot_speed_uncertainty_mps: float = 0.0


@dataclass(frozen=True)
class NearMiss:
    """
    A pass of the ball by the bat without contact, at the closest approach.

    :ivar stamp_ns: closest approach (ns).
    :ivar gap_m: smallest surface gap (m, > 0).
    :ivar gap_vector: from the bat surface to the ball surface (m): +z means the bat passed
        under the ball.
    :ivar ball_position: ball centre at closest approach (m).
    :ivar bat_fraction: where along knob-tip the bat came closest.
    :ivar distance_from_tip_m: metres along the axis from the tip to that point.
    """

    stamp_ns: int
    gap_m: float
    gap_vector: Vector
    ball_position: Vector
    bat_fraction: float
    distance_from_tip_m: float


@dataclass(frozen=True)
class Prediction:
    """
    The coming impact, predicted from the samples up to ``made_at_ns``.

    :ivar stamp_ns: predicted impact instant (ns).
    :ivar made_at_ns: the newest processed instant the prediction starts from (ns).
    :ivar lead_s: how far ahead (s): ``(stamp_ns - made_at_ns) * 1e-9``.
    :ivar point: predicted contact point on the bat surface (m); ``normal``: bat to ball.
    :ivar bat_fraction: where along knob-tip; ``distance_from_tip_m``: metres from the tip.
    :ivar ball_position, ball_velocity: the ball's predicted centre (m) and velocity (m/s).
    :ivar planned: the bat's path came from a commanded plan (else extrapolated).
    :ivar time_uncertainty_s, distance_from_tip_uncertainty_m: 1 sigma of the instant (s) and
        of where on the bat (m) (``prediction_spread``): the ball's forecast and the plan's
        interpolation, or an extrapolated bat's change over the lead; the time's None where the
        ball does not close on the bat at the predicted instant (None both: not computed).
    """

    stamp_ns: int
    made_at_ns: int
    lead_s: float
    point: Vector
    normal: Vector
    bat_fraction: float
    distance_from_tip_m: float
    ball_position: Vector
    ball_velocity: Vector
    planned: bool
    time_uncertainty_s: Optional[float] = None
    distance_from_tip_uncertainty_m: Optional[float] = None


@dataclass(frozen=True)
class PredictionCleared:
    """A contact was predicted and no longer is (as of ``made_at_ns``)."""

    made_at_ns: int


@dataclass(frozen=True)
class StreamGap:
    """A stream went longer than ``max_gap`` between samples; that span was not interpolated."""

    stream: str
    start_ns: int
    end_ns: int


@dataclass(frozen=True)
class StateReset:
    """
    The detector dropped its state.

    :ivar reason: ``'time_jump_backwards'``, ``'time_jump_forward'``, ``'frame_changed'`` or
        ``'requested'`` (a ``ResetReason``; ``Detector.reset`` passes on the string it is
        given).
    """

    stamp_ns: int
    reason: str


Event = Union[Impact, NearMiss, StreamGap, StateReset, Prediction, PredictionCleared]


@dataclass(frozen=True)
class LateDrop:
    """A sample dropped after the call that offered it returned (it had been waiting)."""

    role: Role
    reason: DropReason
    stamp_ns: int
    frame_id: str


@dataclass
class DetectorStats:
    """
    Counters for diagnostics.

    :ivar received: samples offered, by role (ball, bat_pose, knob, tip).
    :ivar dropped: samples dropped, by reason (see ``DROP_REASONS``).
    :ivar impacts, near_misses, gaps, resets: events emitted.
    :ivar intervals: union intervals processed; ``substeps``: the chord sub-steps the sweep
        cut those the far tests did not clear into for the exact solver (as cut, also when a
        contact ends the interval early; the finer chords re-solving an impact and the zone
        test's instants are not counted).
    :ivar last_processing_s, total_processing_s, max_processing_s, calls: wall time spent in
        the detector per call.
    :ivar newest_stamp_ns: newest accepted stamp of any stream (None before any).
    :ivar last_drop_reason: why the last sample offered was dropped (None: it was accepted,
        or it waits: a sample held until the next one of its stream tells whether its stamp is
        a glitch, or while the streams have not agreed on a frame or a jump back).
    :ivar late_drops: samples offered by earlier calls that the last call dropped, as
        ``LateDrop``; cleared at each call.
    """

    received: Counter = field(default_factory=Counter)
    dropped: Counter = field(default_factory=Counter)
    impacts: int = 0
    near_misses: int = 0
    gaps: int = 0
    resets: int = 0
    intervals: int = 0
    substeps: int = 0
    last_processing_s: float = 0.0
    total_processing_s: float = 0.0
    max_processing_s: float = 0.0
    calls: int = 0
    newest_stamp_ns: Optional[int] = None
    last_drop_reason: Optional[DropReason] = None
    late_drops: List['LateDrop'] = field(default_factory=list)

    def drop_late(self, role: Role, reason: DropReason, stamp_ns: int, frame_id: str) -> None:
        """Count a sample that had waited as dropped now, for ``reason`` (a ``LateDrop``)."""
        self.dropped[reason] += 1
        self.late_drops.append(LateDrop(role=role, reason=reason, stamp_ns=stamp_ns,
                                        frame_id=frame_id))

    @property
    def mean_processing_s(self) -> float:
        """Mean wall time per call (seconds)."""
        return self.total_processing_s / self.calls if self.calls else 0.0
