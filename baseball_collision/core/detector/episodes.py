"""
Arming and near misses: when a contact counts as an impact, and when a pass is a near miss.

The detector is armed when it has seen the ball clear of the bat: a ball already overlapping
the bat at a start, a reset or a gap has no known first-contact time (an invented one is worse
than none), and after an impact the trackers keep reporting the ball inside or beyond the bat
for frames, so it re-arms only once the ball has separated by ``rearm_distance``, and only on
intervals from the ball's first frame after the impact on: up to that frame the ball's path is
its free flight continued through the contact (``departure``), which passes through the bat and
out beyond it, where a bat tracked at a higher rate than the ball has more intervals. After it,
no sub-step re-arms on a ball interval whose path does not end at its closing sample (the
flight continued where the departure shows only there, the frame just after the hit having
barely turned, or ``c2``'s flight fit ending at its opening frame: ``substeps_from``, set by
``Sweep._past_departure``).

A near miss is an episode: it opens when an armed pass comes into ``near_miss_threshold`` from
outside it, follows the sub-steps around the smallest gap seen, and closes when the ball moves
back out (or the stream breaks, or the recording ends); the closest approach is then refined
once over the kept sub-steps (``lowest_gap``) and reported as a ``NearMiss``.
"""

from dataclasses import dataclass, field
import math
from typing import List, Optional, Tuple

from .config import DetectorConfig
from .events import DetectorStats, NearMiss
from .gate import Clock
from .streams import Stream
from ..bat import BatProfile
from ..geometry import scale, Vector
from ..toi import lowest_gap_place, profile_gap


@dataclass(slots=True)
class State:
    """Ball and bat at one instant: time (s, detector clock), ball centre, knob, tip (m)."""

    t: float
    ball: Vector
    knob: Vector
    tip: Vector


SubStep = Tuple[State, State]
"""The two ends of one linear sub-step."""


@dataclass
class Episode:
    """
    An open near-miss episode.

    :ivar gap: smallest sub-step end gap seen so far (m).
    :ivar around: the sub-steps on both sides of it (the closest approach lies in one).
    :ivar follow: the smallest gap was a sub-step's end: keep the next sub-step too.
    """

    gap: float = math.inf
    around: List[SubStep] = field(default_factory=list)
    follow: bool = False


@dataclass(frozen=True)
class LowestGap:
    """
    The smallest gap over a sub-step.

    :ivar t: when (s, detector clock); ``gap``: metres; ``normal``: unit, bat axis to ball.
    :ivar fraction: where along knob-tip; ``ball``, ``knob``, ``tip``: the bodies then (m).
    """

    t: float
    gap: float
    normal: Vector
    fraction: float
    ball: Vector
    knob: Vector
    tip: Vector


def lowest_gap(start: State, end: State, ball_radius: float, profile: BatProfile) -> LowestGap:
    """Return the smallest gap over a linear sub-step (the kernel's golden-section search)."""
    s = lowest_gap_place(start.ball, end.ball, start.knob, end.knob, start.tip, end.tip,
                         ball_radius, profile)
    ball, knob, tip = (tuple(a + (b - a) * s for a, b in zip(p, q))
                       for p, q in ((start.ball, end.ball), (start.knob, end.knob),
                                    (start.tip, end.tip)))
    value, normal, fraction = profile_gap(ball, knob, tip, ball_radius, profile)
    return LowestGap(t=start.t + (end.t - start.t) * s, gap=value, normal=normal,
                     fraction=fraction, ball=ball, knob=knob, tip=tip)


def bat_at_rest(bat: Stream, t: float, window: float, tolerance: float) -> bool:
    """
    Return whether the bat stood still before time t (s): not a swing.

    Still: over at least half of ``window`` (s) of its samples at or before t (in t's
    segment), knob and tip each stayed within ``tolerance`` (m) of where they were in the
    last of them.
    """
    indices = bat.history(t, window)
    if len(indices) < 2 or bat.times[indices[-1]] - bat.times[indices[0]] < 0.5 * window:
        return False
    last = bat.values[indices[-1]]
    return all(math.dist(bat.values[i].knob, last.knob) <= tolerance
               and math.dist(bat.values[i].tip, last.tip) <= tolerance for i in indices)


class EpisodeTracker:
    """
    The arming state and the open near-miss episode.

    :ivar armed: True: a contact is an impact; False: after an impact, until re-armed; None:
        not yet seen clear of the bat (after a start, a reset or a gap).
    :ivar zone_clear: armed and seen outside the near-miss threshold since.
    :ivar episode: the open near-miss episode, or None.
    :ivar rearm_from: after an impact, the ball's first frame after it (s, detector clock):
        no sub-step or interval starting before it re-arms.
    :ivar substeps_from: after an impact, no sub-step starting before this (s) re-arms: the
        end of the ball intervals whose path missed its closing sample
        (``Sweep._past_departure``); far intervals, which the chunk plans decide on arrays, go
        by ``rearm_from`` alone.
    """

    __slots__ = ('config', 'clock', 'stats', 'armed', 'zone_clear', 'episode', 'rearm_from',
                 'substeps_from')

    def __init__(self, config: DetectorConfig, clock: Clock, stats: DetectorStats) -> None:
        self.config, self.clock, self.stats = config, clock, stats
        self.armed: Optional[bool] = None
        self.zone_clear = False
        self.episode: Optional[Episode] = None
        self.rearm_from = self.substeps_from = -math.inf

    def far(self, events: List, start: float) -> None:
        """
        Note an interval with the ball far from the bat all through it: separated.

        :param start: the interval's start (s, detector clock); for a run of intervals, the
            last one's.
        """
        if self.armed is not False or start >= self.rearm_from:
            self.armed = True
            self.zone_clear = True
        if self.episode is not None:
            self.close(events)

    def interrupted(self, events: List) -> None:
        """Note a stream gap: close the episode; clear of the bat must be seen again."""
        self.close(events)
        self.armed = None
        self.zone_clear = False
        self.rearm_from = self.substeps_from = -math.inf

    def arm(self, gap: float, start: float) -> Optional[bool]:
        """Return whether armed at the start (s) of a sub-step whose start gap (m) is ``gap``."""
        if self.armed is None and gap > 0.0:
            self.armed = True
        elif (self.armed is False and gap > self.config.rearm_distance
              and start >= self.rearm_from and start >= self.substeps_from):
            self.armed = True
        return self.armed

    def impact(self, ball_frame: float) -> None:
        """
        Note an impact: disarmed, and the pass ended in contact (no near miss).

        :param ball_frame: the ball's first frame after the impact (s, detector clock).
        """
        self.armed = False
        self.zone_clear = False
        self.episode = None
        self.rearm_from = ball_frame
        self.substeps_from = -math.inf

    def track(self, start: State, end: State, gap0: float, gap1: float, events: List) -> None:
        """
        Follow the gap (m) over a sub-step without contact, then re-arm if the ball cleared.

        An open episode keeps the sub-steps on both sides of its smallest end-point gap; the
        closest approach lies in one of them and is refined once, when the episode closes.
        """
        config = self.config
        threshold = config.near_miss_threshold
        # a pass is a near miss only when it came into the threshold from outside it while
        # armed (not the ball leaving after a contact, nor one first seen close to the bat)
        if self.armed and gap0 >= threshold:
            self.zone_clear = True
        episode = self.episode
        if self.zone_clear and (gap0 < threshold or gap1 < threshold) and episode is None:
            episode = self.episode = Episode()
        if episode is not None:
            if episode.follow:
                episode.around.append((start, end))
                episode.follow = False
            if gap0 < episode.gap:
                episode.gap, episode.around, episode.follow = gap0, [(start, end)], False
            if gap1 < episode.gap:
                episode.gap, episode.around, episode.follow = gap1, [(start, end)], True
            if gap1 >= threshold:
                self.close(events)
        if self.armed is False and gap1 > config.rearm_distance and \
                start.t >= self.rearm_from and start.t >= self.substeps_from:
            self.armed = True

    def close(self, events: List) -> None:
        """Close the open episode: a ``NearMiss`` when it came within the threshold."""
        episode = self.episode
        self.episode = None
        if episode is None or not episode.around:
            return
        config = self.config
        lowest = min((lowest_gap(start, end, config.ball_radius, config.profile)
                      for start, end in episode.around), key=lambda found: found.gap)
        if lowest.gap >= config.near_miss_threshold:
            return
        events.append(NearMiss(
            stamp_ns=self.clock.stamp(lowest.t), gap_m=lowest.gap,
            gap_vector=scale(lowest.normal, lowest.gap), ball_position=lowest.ball,
            bat_fraction=lowest.fraction,
            distance_from_tip_m=(1.0 - lowest.fraction) * math.dist(lowest.knob, lowest.tip)))
        self.stats.near_misses += 1
