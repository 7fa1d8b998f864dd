"""
The order samples are taken in: the frame vote, stamp order, lone glitches and jumps back.

A checked sample (its values are numbers, its pose a unit quaternion) is an ``Offer``. Before it
reaches its stream it passes, in order:

* the frame: refused when bad or not the tracking frame. With ``frame_id`` '' the first frame
  seen is provisional: its samples are taken at once, others wait. The frame every input
  stream sends (or, once ``FRAME_PENDING_MAX`` wait, the most common that every stream sending
  a frame has sent: ``FrameVote.candidate``) is adopted: when it is the provisional one the
  waiting samples are dropped as ``WRONG_FRAME``; when it is another (the first was a lone
  stray) the state is reset (``FRAME_CHANGED``) and they are taken. Where there is none (a bat
  in ``arm_base`` beside a ball in ``world``) nothing is adopted: the oldest waiting sample is
  dropped (``NO_COMMON_FRAME``) as each new one waits, until the streams agree;
* the stamp against its stream's newest (``gate.stamp_check``): a duplicate or a little behind
  is dropped; far behind waits in the ``JumpWatch``: ``JUMP_CONFIRM`` such samples in a row are
  a jump back (the state resets once and they are taken), and a sample on the current clock
  between them shows another publisher's clock (they are dropped as ``STALE_STAMP``). Another
  stream's sample on the candidates' own clock (within ``time_jump_reset`` of them) keeps them:
  the stream that waits is the one behind, its newest a lone sample of the old clock (one
  delivered after a reset, or two glitched ahead in a row), and without it that stream dropped
  every sample until the new clock overtook its newest;
* a step well beyond the stream's usual one (``gate.hold_ahead``) waits for the stream's next
  sample: if that comes before it, it was a lone glitch ahead (dropped as ``STAMP_AHEAD``),
  else it is taken then (a real gap costs one sample of latency on that stream). A step that
  is not ahead of the newest stamp taken on any stream is no glitch (the stream lagged, or its
  own newest samples were a stale publisher's): it is taken, at once or when it waited.

Offers that waited and are dropped later are counted then (``DetectorStats.late_drops``);
``flush`` (the end of a recording) takes what still waits (with no candidate frame, the offers
waiting for one are dropped as ``NO_COMMON_FRAME``).
"""

from typing import Any, Callable, Dict, List, Optional, Sequence

from .config import DetectorConfig
from .events import DetectorStats, DropReason, Event, ResetReason, Role
from .gate import frame_check, FRAME_PENDING_MAX, FrameVote, hold_ahead, JumpWatch, stamp_check
from .streams import Stream


class Offer:
    """
    A sample whose values passed their checks (a plain slotted class: one is made per sample).

    :ivar role: what it is; ``stamp``: header stamp (ns, > 0); ``value``: a point (m) or a
        (position, unit quaternion) pose; ``frame``: the header's frame.
    """

    __slots__ = ('role', 'stamp', 'value', 'frame')

    def __init__(self, role: Role, stamp: int, value: Any, frame: str) -> None:
        self.role, self.stamp, self.value, self.frame = role, stamp, value, frame

    def __repr__(self) -> str:
        """Return the offer's fields."""
        return f'Offer({self.role!r}, {self.stamp}, {self.value!r}, {self.frame!r})'


Take = Callable[[Offer, List[Event]], Optional[DropReason]]
"""Puts an admitted offer into its stream and processes; returns why it is dropped."""

Reset = Callable[[int, ResetReason, List[Event]], None]
"""Resets the detector's state at a stamp (ns) for a reason, appending its events."""


class Intake:
    """
    The waiting offers: frame vote, held glitches, jump candidates; and the clock's newest.

    :param config: the detector's configuration (``frame_id``, ``time_jump_reset``).
    :param stats: where late drops are counted.
    :param stream_of: the stream an offer of a role is checked against (looked up each time:
        a reset makes new streams).
    :param take: takes an admitted offer; ``reset``: resets the detector (which calls
        ``clear``).
    :param roles: the input roles that must agree on the frame.
    :ivar newest: the newest stamp taken since the last reset (ns; the reference of a stream
        without samples).
    """

    __slots__ = ('_config', 'reset_ns', 'stats', 'stream_of', 'take', 'reset', 'roles', 'votes',
                 'pending', 'held', 'jumps', 'newest')

    def __init__(self, config: DetectorConfig, stats: DetectorStats,
                 stream_of: Callable[[Role], Stream], take: Take, reset: Reset,
                 roles: Sequence[Role]) -> None:
        self.config = config
        self.stats, self.stream_of = stats, stream_of
        self.take, self.reset, self.roles = take, reset, tuple(roles)
        self.clear()

    @property
    def config(self) -> DetectorConfig:
        """Return the configuration in force."""
        return self._config

    @config.setter
    def config(self, config: DetectorConfig) -> None:
        """Set the configuration (``time_jump_reset`` may change at runtime)."""
        self._config = config
        self.reset_ns = int(round(config.time_jump_reset * 1e9))

    def clear(self) -> None:
        """Forget every waiting offer and the frame (unless configured)."""
        self.votes = FrameVote(self.config.frame_id, self.roles)
        self.pending: List[Offer] = []
        self.held: Dict[Role, Offer] = {}
        self.jumps = JumpWatch()
        self.newest: Optional[int] = None

    @property
    def frame(self) -> Optional[str]:
        """Return the tracking frame: agreed, else provisional (None before any)."""
        return self.votes.frame or self.votes.provisional

    def offer(self, offer: Offer, events: List[Event]) -> Optional[DropReason]:
        """
        Admit (or keep waiting, or refuse) an offer; append the events it makes decidable.

        :returns: why this offer is dropped; None when it was taken or waits.
        """
        frame, tracking = offer.frame, self.votes.frame
        if frame and frame != tracking:
            reason = frame_check(frame, tracking)
            if reason is not None:
                return reason
            if tracking is None:
                return self._vote(offer, events)
        elif tracking is None:  # an empty frame before agreement: in any frame (the vote's)
            self.votes.blank.add(offer.role)
        return self._stamp(offer, events)

    def flush(self, events: List[Event]) -> None:
        """At the end of a recording: settle the frame, take held offers, drop candidates."""
        if self.pending:
            agreed = self.votes.candidate()
            if agreed is not None:
                self._adopt(agreed, None, events)
            else:  # no frame every stream sends: none is adopted, what waited is dropped
                pending, self.pending = self.pending, []
                for each in pending:
                    self._late(each, DropReason.NO_COMMON_FRAME)
        self._abandon()
        for held in sorted(self.held.values(), key=lambda offer: offer.stamp):
            if self.held.pop(held.role, None) is held:  # (a reset may have cleared it)
                self._take_waited(held, events)

    # ---- the steps -----------------------------------------------------------------------

    def _vote(self, offer: Offer, events: List[Event]) -> Optional[DropReason]:
        """
        Before agreement: take an offer in the provisional frame, keep others waiting.

        Once ``FRAME_PENDING_MAX`` wait, the candidate frame (``FrameVote.candidate``) is
        adopted; where there is none (frames that differ per stream) the oldest waiting offer
        is dropped (``no_common_frame``) as each new one comes, ``FRAME_PENDING_MAX`` waiting
        on.
        """
        votes = self.votes
        agreed = votes.vote(offer.role, offer.frame)
        if offer.frame != votes.provisional:
            self.pending.append(offer)
            if agreed is None and len(self.pending) >= FRAME_PENDING_MAX:
                agreed = votes.candidate()
                if agreed is None and len(self.pending) > FRAME_PENDING_MAX:
                    self._late(self.pending.pop(0), DropReason.NO_COMMON_FRAME)
        if agreed is None:
            return self._stamp(offer, events) if offer.frame == votes.provisional else None
        return self._adopt(agreed, offer, events)

    def _adopt(self, agreed: str, current: Optional[Offer],
               events: List[Event]) -> Optional[DropReason]:
        """Adopt the agreed frame; settle the waiting offers; return ``current``'s reason."""
        pending, self.pending = self.pending, []
        if agreed == self.votes.provisional:
            self.votes.frame = agreed
            own = None
            for each in pending:
                if each is current:
                    own = DropReason.WRONG_FRAME
                else:
                    self._late(each, DropReason.WRONG_FRAME)
            if current is not None and current.frame == agreed:
                own = self._stamp(current, events)
            return own
        # the provisional frame was a stray: forget what it built, take the agreed frame's
        self.reset(pending[0].stamp, ResetReason.FRAME_CHANGED, events)
        self.votes.frame = agreed
        return self._replay(pending, current, events)

    def _stamp(self, offer: Offer, events: List[Event]) -> Optional[DropReason]:
        """Check an offer's stamp against its stream; take it, keep it waiting or drop it."""
        role, stamp = offer.role, offer.stamp
        stream = self.stream_of(role)
        stamps = stream.stamps
        if self.held and role in self.held and (not stamps or stamp > stamps[-1]):
            held = self.held.pop(role)
            if stamp >= held.stamp or self._on_clock(held.stamp):  # a real step
                self._take_waited(held, events)
                stamps = self.stream_of(role).stamps  # new after a reset
            else:  # the next sample came before it: a lone glitch ahead
                self._late(held, DropReason.STAMP_AHEAD)
        if stamps and stamp > stamps[-1]:  # in order: the common case
            jumps = self.jumps
            if jumps.candidates and abs(stamp - jumps.newest) > self.reset_ns:
                self._abandon()  # the current clock is alive: those were another clock
            if hold_ahead(stamps, stamp, self.reset_ns) and not self._on_clock(stamp):
                self.held[role] = offer
                return None
            reason = self.take(offer, events)
            if self.newest is None or stamp > self.newest:
                self.newest = stamp
            return reason
        # a stream's first sample is taken even far behind the others: that stream lags (a
        # loaded subscription, a fast replay); the scheduler waits for it
        verdict = stamp_check(stamps[-1], stamp, None, self._config.time_jump_reset) \
            if stamps else None
        if verdict is ResetReason.TIME_JUMP_BACKWARDS:
            confirmed, abandoned = self.jumps.behind(offer, stamp, self.reset_ns)
            for stale in abandoned:
                self._late(stale, DropReason.STALE_STAMP)
            if not confirmed:
                return None
            candidates = self.jumps.take()
            self.reset(candidates[0].stamp, ResetReason.TIME_JUMP_BACKWARDS, events)
            return self._replay(candidates, offer, events)
        if self.jumps.candidates:
            self._abandon()
        return verdict if verdict is not None else self._take(offer, events)

    def _on_clock(self, stamp: int) -> bool:
        """
        Return whether a stamp (ns) ahead of its stream is not ahead of the clock's newest.

        Another stream reached it: the stream itself lagged (or its newest samples were another
        publisher's, older clock), so the step is no glitch.
        """
        return self.newest is not None and stamp <= self.newest

    def _abandon(self) -> None:
        """Drop the jump candidates: a sample on the current clock came between them."""
        for stale in self.jumps.take():
            self._late(stale, DropReason.STALE_STAMP)

    def _take(self, offer: Offer, events: List[Event]) -> Optional[DropReason]:
        """Take an admitted offer (a late drop when it waited); note the clock's newest."""
        reason = self.take(offer, events)
        if self.newest is None or offer.stamp > self.newest:
            self.newest = offer.stamp
        return reason

    def _take_waited(self, offer: Offer, events: List[Event]) -> None:
        """Take an offer that waited (held): a drop now is a late drop."""
        reason = self._take(offer, events)
        if reason is not None:
            self._late(offer, reason)

    def _replay(self, offers: List[Offer], current: Optional[Offer],
                events: List[Event]) -> Optional[DropReason]:
        """Offer waiting offers again in order; return ``current``'s reason, late-drop others."""
        own = None
        for each in offers:
            reason = self.offer(each, events)
            if each is current:
                own = reason
            elif reason is not None:
                self._late(each, reason)
        return own

    def _late(self, offer: Offer, reason: DropReason) -> None:
        """Count the drop of an offer that had waited."""
        self.stats.drop_late(offer.role, reason, offer.stamp, offer.frame)
