"""
Ball samples the speed check refused, kept aside while the sample they were judged against waits.

A part of ``sweep.Sweep`` (a base of ``sweep_ball.BallSamples``, reading the sweep's ball
stream, configuration, counters and ``aside``/``until``). A ball sample too far from the
stream's newest to be reached at ``max_speed`` (``gate.speed_check``) may follow a glitch the
sweep has still to judge (a sample right after a glitch is too far from it, however good): it
waits aside, not counted (``set_aside``), until that sample is forgotten as a glitch
(``_judged_aside``: judged again against the stream without it, put back or dropped) or the
walk passes it (``settle_aside``: dropped as ``speed_limit``, a late drop). Times in s, stamps
in ns.
"""

from typing import NamedTuple, Optional

from .events import DropReason, Role
from .gate import within_speed
from .intake import Offer
from .noise import ESTIMATES

ASIDE_MAX = 4
"""Ball samples the speed check keeps aside at most (``SpeedAside.set_aside``): a glitch
makes one or two (``gate.SPEED_DROPS_TO_JUMP``: the third in a row is taken); beyond them the
oldest is dropped, so a silent bat (the walk stalled) keeps the memory bounded."""


class Aside(NamedTuple):
    """
    A ball sample the speed check refused, kept aside (``SpeedAside.set_aside``).

    Its time (s), its offer, and the stamp (ns) of the sample it was judged against (the
    stream's newest then).
    """

    t: float
    offer: Offer
    against: int


class SpeedAside:
    """The ball samples the speed check set aside: a base of ``sweep_ball.BallSamples``."""

    __slots__ = ()

    def set_aside(self, t: float, offer: Offer, cursor: Optional[float]) -> Optional[DropReason]:
        """
        Keep a ball sample the speed check refused aside; return why it is dropped now, if so.

        Refused against the stream's newest sample, which may be a glitch the sweep has still
        to judge (its interval not visited: after ``cursor``, s): a sample right after a glitch
        is too far from it to be reached at ``max_speed`` however good it is. It waits, not
        counted, until that sample is forgotten (``_judged_aside``: put back or dropped) or the
        walk passes it (``settle_aside``); ``SPEED_LIMIT`` at once where the newest was swept
        already, or there is no walk yet. At most ``ASIDE_MAX`` wait (the oldest dropped).

        :param t: the sample's time (s); ``offer``: the sample.
        """
        ball = self.ball
        if cursor is None or not ball.times or ball.times[-1] < cursor:
            return DropReason.SPEED_LIMIT
        if len(self.aside) >= ASIDE_MAX:
            self._dropped_aside(self.aside.pop(0))
        self.aside.append(Aside(t, offer, ball.stamps[-1]))
        return None

    def settle_aside(self, until: Optional[float]) -> None:
        """
        Drop the samples set aside at or before ``until`` (s): the walk passed them.

        Each a late drop, ``SPEED_LIMIT``; None: all (the recording's end, a reset).
        """
        kept = []
        for entry in self.aside:
            if until is None or entry.t <= until:
                self._dropped_aside(entry)
            else:
                kept.append(entry)
        self.aside = kept

    def _judged_aside(self, glitch: int) -> None:
        """
        Judge again the samples set aside against a glitch (stamp, ns) now forgotten.

        In order, each against the stream as it is without the glitch: put back
        (``Stream.insert``) where it is after the interval visited (``until``) and within
        ``max_speed`` of the sample before it and of the one after (each within ``max_gap``;
        a longer gap starts a segment, as the speed check's), else dropped as
        ``SPEED_LIMIT``.
        """
        ball, config = self.ball, self.config
        gap, kept = config.max_gap, []
        for entry in self.aside:
            if entry.against != glitch:
                kept.append(entry)
                continue
            t, value = entry.t, entry.offer.value
            k = ball.interval(t)
            times, values = ball.times, ball.values
            steps = []  # (s, the later point, the earlier)
            if k >= 0:
                steps.append((t - times[k], value, values[k]))
            if k + 1 < len(times):
                steps.append((times[k + 1] - t, values[k + 1], value))
            if t >= self.until and (k < 0 or times[k] < t) and all(
                    dt > gap or within_speed(dt, (p,), (q,), config.max_speed)
                    for dt, p, q in steps):
                ball.insert(t, entry.offer.stamp, value, gap, (ESTIMATES,))
            else:
                self._dropped_aside(entry)
        self.aside = kept

    def _dropped_aside(self, entry: Aside) -> None:
        """Count a sample set aside as dropped by the speed check (a late drop)."""
        self.stats.drop_late(Role.BALL, DropReason.SPEED_LIMIT, entry.offer.stamp,
                             entry.offer.frame)
