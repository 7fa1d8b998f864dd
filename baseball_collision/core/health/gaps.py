"""
Messages lost on an input, counted from its header stamps and its publishers' sequence numbers.

Pure Python (no ROS): :class:`StampGaps` estimates losses from gaps in one stream's stamps
(an RMW that gives no sequence numbers); :class:`PublisherGaps` counts them exactly from each
publisher's sequence numbers, with the stamps for frames a tracker skipped upstream. The node's
``Tally`` (``core.health.tally``) keeps one per stream. Stamps are integer nanoseconds.
"""

from collections import deque
from dataclasses import dataclass, field
from typing import Deque, List, Optional, Tuple

LOSS_FACTOR = 1.5
"""A stamp step more than this many typical steps is a gap: messages lost (see StampGaps)."""

LOSS_GAP_MAX_NS = 1_000_000_000
"""A longer stamp step is a pause of the publisher (a stale input), not messages lost."""

OTHER_PUBLISHER_NS = 1_000_000_000
"""A message numbered next on a publisher track but stamped more than this (ns) behind where the
track would be is another publisher's (a stale one 3 s behind) or a jump back: it starts a track
of its own. Ahead is a pause or a glitch: it stays."""

SENT_SLACK_NS = 1_000_000
"""A message sent (by the writer's clock) up to this long before its track's last is still the
same writer's (a writer sends in order): the clocks' granularity and send-time jitter."""

SEND_STEPS = 8
"""Consecutive send steps a track keeps: their median is its typical send step."""

PACE_SPAN_NS = 500_000_000
"""A track's pace of stamps against send times is its own once its sends span this much."""

PACE_HORIZON_NS = 10_000_000_000
"""A track silent longer than this (send time) has no pace to judge by: its stamps would be
extrapolated past what its pace can tell (a stale publisher silent for minutes whose lag the
extrapolation error happens to cancel). Such a track ranks after those with a pace."""

PACE_BIN_NS = 100_000_000
"""Candidates whose stamps are within this of each other's distance from their pace tie."""


class StampGaps:
    """
    Messages of one stream estimated lost from gaps in its header stamps.

    A publisher at a steady rate steps its stamps by about the same amount; a step of more
    than ``LOSS_FACTOR`` typical steps (the median of the last eight) and at most
    ``LOSS_GAP_MAX_NS`` (longer: a pause, reported as stale) means ``round(step / typical) -
    1`` messages did not arrive. A step is counted when the next stamp comes after it: a lone
    stamp glitched ahead (the next one comes before it) is not a gap, and its message counts
    as the one after the stamp before it (its own, misstamped). Stamps at or behind the newest
    (another publisher, a jump back) are ignored until the stream passes them.

    :param confirm: count a gap only when the step after it is a typical one (used where
        sequence numbers say nothing was lost in transport: a glitch, or a pause, right after
        the big step is then not a loss).
    :ivar lost: messages estimated lost so far.
    """

    __slots__ = ('lost', '_newest', '_steps', '_pending', '_confirm')

    def __init__(self, confirm: bool = False) -> None:
        self.lost = 0
        self._confirm = confirm
        self._newest: Optional[int] = None
        self._steps: List[int] = []
        self._pending: Optional[Tuple[int, int]] = None  # (stamp before the step, lost)

    def take(self, stamp_ns: int) -> None:
        """Count in the header stamp (ns) of the next message (see the class)."""
        newest = self._settle(stamp_ns)
        if newest is None or stamp_ns <= newest:
            if newest is None:
                self._newest = stamp_ns
            return
        step = stamp_ns - newest
        steps = self._steps
        typical = self._typical() or None
        if step > LOSS_GAP_MAX_NS or (typical is not None and step > LOSS_FACTOR * typical):
            lost = 0 if typical is None or step > LOSS_GAP_MAX_NS else round(step / typical) - 1
            self._pending = (newest, max(0, lost))  # decided by the next stamp
            self._newest = stamp_ns
            return
        steps.append(step)
        if len(steps) > 8:
            del steps[0]
        self._newest = stamp_ns

    def resume(self, stamp_ns: int) -> None:
        """
        Take the stamp (ns) of a message after messages counted elsewhere: no gap counted.

        The step before it is not a typical step either (:class:`PublisherGaps` counted the
        messages it spans from their sequence numbers).
        """
        newest = self._settle(stamp_ns)
        if newest is None or stamp_ns > newest:
            self._newest = stamp_ns

    def _settle(self, stamp_ns: int) -> Optional[int]:
        """Decide a pending big step by the stamp (ns) after it; return the newest stamp."""
        newest = self._newest
        if self._pending is not None:
            before, lost = self._pending
            self._pending = None
            if stamp_ns < newest:  # the big step was a lone glitch: it took the slot after
                newest = self._newest = before + self._typical()  # before (misstamped)
            elif not self._confirm or stamp_ns - newest <= LOSS_FACTOR * self._typical():
                self.lost += lost
        return newest

    @property
    def typical_ns(self) -> int:
        """Return the typical step between stamps (ns; 0 while unknown)."""
        return self._typical()

    def _typical(self) -> int:
        """Return the typical step (ns): the median of the last eight, 0 before four."""
        steps = self._steps
        return sorted(steps)[len(steps) // 2] if len(steps) >= 4 else 0


@dataclass(slots=True, eq=False)
class PublisherTrack:
    """
    One publisher's messages on a stream, as :class:`PublisherGaps` attributes them.

    :ivar last: its last sequence number; ``last_stamp``: that message's header stamp (ns).
    :ivar gaps: frames its tracker skipped upstream, from its stamps between consecutive
        numbers.
    :ivar first: its first sequence number; ``first_stamp``: that message's stamp (ns).
    :ivar before: (number, stamp ns) of the message before the last; None before a second.
    :ivar last_sent: its writer's send time (ns) of the last message; ``first_sent``: of the
        first (None where the RMW gives none).
    :ivar send_steps: the last ``SEND_STEPS`` send steps (ns) between consecutive numbers.
    """

    last: int
    last_stamp: int
    gaps: StampGaps
    first: int
    first_stamp: int
    before: Optional[Tuple[int, int]] = None
    last_sent: Optional[int] = None
    first_sent: Optional[int] = None
    send_steps: Deque[int] = field(default_factory=lambda: deque(maxlen=SEND_STEPS))


class PublisherGaps:
    """
    Messages of one stream lost, counted from each publisher's sequence numbers.

    An RMW that gives a message's publication sequence number (rmw_fastrtps_cpp: the
    writer's, 1, 2, 3 ... per publisher) makes transport losses exact: messages between two
    received numbers of one publisher never arrived, however long the pause between them and
    whatever their stamps said (a queue overflowing in a burst, a lossy link). rclpy gives no
    publisher id with the number, so each message is attributed to a publisher *track* (at
    most ``MAX_TRACKS``). Candidates are the tracks whose last number is below the message's,
    where the stamp is not behind the track's prediction (its last stamp + the numbers between
    x its typical step) by more than ``OTHER_PUBLISHER_NS`` for the next number, or by more
    than two typical steps and a twelfth of the skipped ones past a gap (the skipped messages
    needed that time, less the error of a typical step learnt from jittery stamps; a pause only
    adds to it; judged from the message before the last too, in case the last was a glitch
    ahead). The message joins first a track whose prediction it fits (within two typical
    steps; ``OTHER_PUBLISHER_NS`` while the step is unknown, or the stream's while a new track
    does not know its own), then the one whose stamps' mean pace (pauses included) predicts
    its stamp best (a pause before the next number explains itself). Without a candidate it
    starts a track
    of its own (a stale publisher 3 s behind, one that joined late with larger numbers,
    a jump back); the first message of a track counts nothing before it. Within a track,
    consecutive numbers whose stamps skip steps (a tracker that dropped frames upstream,
    publishing on) are counted from the stamps as in :class:`StampGaps` (steps up to
    ``LOSS_GAP_MAX_NS``, confirmed by a typical step after), so the two never count a message
    twice. Frames skipped upstream across a longer step (a pause) are not counted: there is no
    sound rule, the step being the pause plus the skipped frames' steps and the pause's length
    unknown (a 1.5 s step is a 1.5 s pause, or a 1.499 s one and a frame skipped; stamps on a
    fixed grid do not help, a pause is whole steps too).

    With the writers' send times (rmw_fastrtps_cpp's source timestamps) a track is a candidate
    only if its writer can have sent the message: not before its last message (a writer sends
    in order, ``SENT_SLACK_NS`` of slack). Among the candidates, first those whose stamp is
    nearer where their pace of stamps against send times puts it (in bins of ``PACE_BIN_NS``; a
    pace that counts their pauses and the gaps in their stamps, 1 while unknown; a track silent
    for more than ``PACE_HORIZON_NS`` comes last), then those that did not send the skipped
    numbers at more than twice their typical pace (not excluded: a burst sends faster than
    ever, and its first messages are the ones a full queue loses). A stale publisher 3 s behind
    then does not take the good one's messages, whatever its numbers, and a loss across a pause
    stays with its own track; a clock that jumps ahead while its publisher sends on, the only
    candidate, keeps its track. Measured on 1,500 random three-publisher cases (1 ms steps, a
    1.5 s pause, send times jittered 0.3 ms) and 1,500 two-publisher ones (4 ms steps, 1.2 s
    pause): none miscounted, against 72 and 27 without the send times; exact on the 10-minute
    fault run's phases with bursts of up to 2,000 messages lost (``test_gaps`` checks these and
    the live cases below).

    Without send times, ambiguous when publishers share a clock, or when a loss spans a pause
    and another publisher's numbers and stamps happen to predict the message as well: measured,
    exact on the fault benchmark's streams with random bursts lost (10 of 10 runs), 13 of 1,500
    random three-publisher cases with a 1.5 s pause miscounted (``test_gaps``). Two cases seen
    live are of this kind: a stale publisher numbering from 1 beside the good one, whose
    message n is handed over just before the good one's n + 1 after a pause (both explain it by
    a pause: ``test_faults``' slow lost-messages test), and a stale publisher that started as
    many numbers after the good one as its lag holds (``test_fault_soak``: 750 numbers x 4 ms =
    its 3 s; the stale track then predicts the good stamps exactly). Other rules measured on
    1,500 random three-publisher cases (1.5 s pause) and 1,500 two-publisher ones (4 ms steps,
    1.2 s pause), miscounted against 18 and 27 for this rule: the fewest skipped numbers among
    fitting tracks with a pause as a fit, 33 and 32; the smallest implied pause alone, 77 and
    90; undoing a switch when the next message continues the track's state before it, 17 on the
    first (and neither live case fixed). Sound attribution needs the publisher's identity,
    which rclpy 7.1's message info does not give (no GID): hence the send times, which the node
    passes where the RMW gives them.

    :ivar lost: messages lost so far (numbers skipped, and stamps skipped between consecutive
        numbers).
    """

    MAX_TRACKS = 8
    """Publishers tracked at once; the one heard from longest ago makes room for a new one."""

    __slots__ = ('_tracks', '_skipped', '_typical')

    def __init__(self) -> None:
        self._tracks: List[PublisherTrack] = []  # the one used last first
        self._skipped = 0
        self._typical = 0  # the last typical step a track knew: a new track's until it knows

    @property
    def lost(self) -> int:
        """Return the messages lost so far."""
        return self._skipped + sum(track.gaps.lost for track in self._tracks)

    def take(self, sequence: int, stamp_ns: int, sent_ns: Optional[int] = None) -> None:
        """
        Count in a message's publication sequence number and header stamp (ns).

        :param sent_ns: its writer's send time (ns), when the RMW gives it (see the class).
        """
        tracks = self._tracks
        track = tracks[0] if tracks else None
        if track is None or sequence != track.last + 1 \
                or abs(stamp_ns - track.last_stamp - track.gaps.typical_ns) > LOSS_GAP_MAX_NS:
            track = self._attribute(sequence, stamp_ns, sent_ns)
            if track is None:  # a new publisher (or one that restarted)
                gaps = StampGaps(confirm=True)
                gaps.take(stamp_ns)
                tracks.insert(0, PublisherTrack(sequence, stamp_ns, gaps, sequence, stamp_ns,
                                                last_sent=sent_ns, first_sent=sent_ns))
                if len(tracks) > self.MAX_TRACKS:
                    self._retire(tracks.pop())
                return
            tracks.remove(track)
            tracks.insert(0, track)
        skipped = sequence - track.last - 1
        lost = skipped - self._detours(track, sequence) if skipped else 0
        track.before = (track.last, track.last_stamp)  # a glitched last stamp's check
        if sent_ns is not None and track.last_sent is not None and not skipped \
                and sent_ns >= track.last_sent:
            step = sent_ns - track.last_sent
            track.send_steps.append(step)
        track.last, track.last_stamp, track.last_sent = sequence, stamp_ns, sent_ns
        if track.first_sent is None:
            track.first_sent = sent_ns
        if skipped:
            self._skipped += lost
            track.gaps.resume(stamp_ns)
        else:
            track.gaps.take(stamp_ns)

    def _detours(self, track: PublisherTrack, sequence: int) -> int:
        """
        Return the numbers a track skips up to ``sequence`` that other tracks hold whole.

        A publisher that stamps a few messages on another clock (stamps seconds behind, a
        glitch of its clock) puts them on a track of their own; its next message on its own
        clock comes back to its track having skipped their numbers, which arrived. A track
        whose first and last numbers both lie inside the skip is such a detour: its numbers
        (and the losses it counted among them) are not this track's loss. (They were counted
        lost before: 4 messages stamped 5 s back read as 4 lost.)
        """
        return sum(other.last - other.first + 1 for other in self._tracks
                   if other is not track and track.last < other.first and other.last < sequence)

    def _attribute(self, sequence: int, stamp_ns: int,
                   sent_ns: Optional[int]) -> Optional[PublisherTrack]:
        """Return the track a message belongs to (see the class), None for a new one."""
        best, best_rank = None, None
        for track in self._tracks:
            last, last_stamp, gaps = track.last, track.last_stamp, track.gaps
            first, first_stamp, before = track.first, track.first_stamp, track.before
            if last >= sequence:
                continue
            typical = gaps.typical_ns
            if typical:
                self._typical = typical
            else:
                typical = self._typical
            sent = sent_ns is not None and track.last_sent is not None
            if sent and sent_ns - track.last_sent < -SENT_SLACK_NS:
                continue  # a writer sends in order
            steps = sequence - last
            error = stamp_ns - last_stamp - steps * typical
            fit = 2 * typical or OTHER_PUBLISHER_NS
            if steps == 1 and error < -OTHER_PUBLISHER_NS:
                continue  # the next number, but stamped far behind: another publisher
            slack = fit + steps * typical // 12  # the typical step learnt off by jitter
            if steps > 1 and error < -slack and before is not None:  # the last a glitch ahead?
                error = max(error, stamp_ns - before[1] - (sequence - before[0]) * typical)
            if steps > 1 and error < -slack:
                continue  # stamps advanced less than the skipped messages took: another one
            mean = (last_stamp - first_stamp) / (last - first) if last - first >= 8 else typical
            off = stamp_ns - last_stamp - steps * mean  # against its stamps' mean pace
            hurried = sent and _sent_hurried(track, sequence, sent_ns)
            astray = _pace_deviation(track, stamp_ns, sent_ns) // PACE_BIN_NS if sent else 0
            rank = (astray, hurried, abs(error) > fit,
                    0 if steps == 1 and off > 0 else abs(off), steps)
            if best_rank is None or rank < best_rank:
                best, best_rank = track, rank
        return best

    def _retire(self, track: PublisherTrack) -> None:
        """Forget a track, keeping the messages its stamps counted lost."""
        self._skipped += track.gaps.lost


def _sent_hurried(track: PublisherTrack, sequence: int, sent_ns: int) -> bool:
    """
    Return whether a track's writer would have sent the numbers it skipped in a hurry.

    In a hurry: at more than twice its typical pace (the median of its last consecutive send
    steps); most likely another writer's message.
    """
    steps, skipped = sorted(track.send_steps), sequence - track.last - 1
    return bool(steps) and skipped > 0 and \
        skipped * steps[len(steps) // 2] > 2 * max(sent_ns - track.last_sent, 0)


def _pace_deviation(track: PublisherTrack, stamp_ns: int, sent_ns: int) -> int:
    """
    Return how far (ns) a message's stamp is from where a track's pace puts it.

    The pace is of the track's stamps against its send times, from its first message to its
    last (1 until its sends span ``PACE_SPAN_NS``), continued from its last message; a track
    silent for more than ``PACE_HORIZON_NS`` is as far as can be.
    """
    elapsed = sent_ns - track.last_sent
    if elapsed > PACE_HORIZON_NS:
        return PACE_HORIZON_NS * PACE_BIN_NS  # no pace so far ahead: after any that has one
    span = track.last_sent - track.first_sent
    pace = (track.last_stamp - track.first_stamp) / span if span >= PACE_SPAN_NS else 1.0
    return int(abs(stamp_ns - track.last_stamp - pace * elapsed))
