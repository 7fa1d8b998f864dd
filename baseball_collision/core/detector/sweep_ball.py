"""
The sweep's judgment of ball samples near the bat: glitches dropped and forgotten.

A part of ``sweep.Sweep`` (its base, reading the sweep's streams, configuration and counters).
A ball sample off its free flight that no hit explains is a glitch (``departure.glitch_path``,
``Sweep._judged_glitch``); a segment's first three samples, which have too few before them,
are judged by the flight after them (``departure.glitch_before_flight``), the first by the bat
too (``_first_glitch``, ``_inside_bat``), the interval near the bat that reaches them waiting
for those samples (``_early_glitch``). A glitch is dropped as ``ball_glitch`` (a ``LateDrop``)
and forgotten (``Stream.remove``). A hit between a segment's first or second sample and the
next, which no flight before it finds, is solved from that sample and the flight after it
(``_hit_before_flight``: the approach's first contact swept as a path, ``_first_contact``,
its last one the other answer; or, where the flight before the tracking gap runs on through
that sample, that flight's first contact: ``gap_flight.flight_across_gap``); a hit between its
third and fourth, where the first three lie on the flight before the gap and the fourth leaves
it, on that flight (``_solved_on_gap_flight``). Whether a segment's samples lie on the flight
before its gap is ``gap_flight``'s to say; a segment's first sample off it while the next is
on it is a glitch too (``gap_flight.off_gap_flight``). The samples the speed check refused
against a glitch are judged again once it is forgotten (its base ``speed_aside.SpeedAside``).
"""

from bisect import bisect_left
import math
from typing import Any, List, Optional, Tuple

from .departure import (
    back_miss, DEPARTURE_CHI_SQUARE, DEPARTURE_FLOOR, FLIGHT_AFTER, flight_before, FRICTION,
    glitch_before_flight, glitch_path, HitApproach, judging_noise, leaves_flight)
from .episodes import lowest_gap
from .events import DropReason, Role
from .fitting import stream_noise
from .gap_flight import (
    flight_across_gap, flight_before_gap, left_gap_flight, off_gap_flight, on_gap_flight,
    segment_starts)
from .noise import ESTIMATES
from .speed_aside import SpeedAside
from .streams import Stream
from ..geometry import dot
from ..motion import BatPath, Paths, PointPath, substeps_for
from ..toi import ImpactResult, profile_contact, profile_gap

BACK_GAIN = 5.0
"""The noise gain of a parabola through three samples continued one step back (Lagrange's
weights 3, -3 and 1 at even steps: 4.4; a little more at uneven ones): ``Sweep._slack``."""

BAT_PATH_GAIN = 2.0
"""The most a bat's path through noisy frames strays, in their noise (a spline's end pieces,
which a look-ahead of 0 sweeps on, carry up to about twice it): ``Sweep._slack``."""

SQUASH = 0.5
"""The most of its radius a ball's centre comes nearer a bat than in touch, squashed in a hit
(a baseball squashes 1-2 cm at the fastest: under half its 3.66 cm): ``Sweep._inside_bat``."""

TOUCH_SLACK = 1e-7
"""m: how much more than its closest approach's gap a ball is grown to touch the bat there
(``BallSamples._first_contact``: the contact of a path that comes within a slack of the bat)."""


SURFACE_STEP = 1e-6
"""s: half the step over which the bat's velocity at a contact is differenced
(``BallSamples._pushed``)."""

UNEXPLAINED_RUN = 3
"""Ball samples in a row at most that ``Sweep`` forgets for a departure no contact explains: a
ball that really left its flight near the bat without touching it (off the batter's hands) is
tracked again after them."""


class BallSamples(SpeedAside):
    """The ball's samples judged near the bat: a base of ``sweep.Sweep`` (see there)."""

    __slots__ = ()

    def note_gap(self, t: float) -> None:
        """
        Keep the ball's flight before a tracking gap, a sample at t (s) coming after it.

        Called before a ball sample is put in its stream: where it comes more than ``max_gap``
        after the stream's newest, the flight of the newest's segment
        (``gap_flight.flight_before_gap``) as ``gap_flight`` (None where there is none), which
        ``gap_flight.on_gap_flight`` reads once the trim behind the walk has taken its
        samples. No interval after the newest is visited yet (the walk waits for the ball's
        samples), so the node and ``analyze``'s chunks (which take such a sample through
        ``Detector.add``: ``plans.plan_chunk``) hold those samples alike then. One summary
        (the fit's stamps and coefficients) per gap.
        """
        ball = self.ball
        if ball.times and t - ball.times[-1] > self.config.max_gap:
            self.gap_flight = flight_before_gap(ball, self.config)

    def _early_glitch(self, k: int, ta: float, tb: float, events: List) -> bool:
        """
        Judge the ball's young samples interval k reaches; True: the interval is done with.

        Young: a segment's first, second or third sample (after a tracking gap), which
        ``glitch_path`` cannot judge (fewer than three samples before it). A segment's first
        sample, where it opens interval k, is judged first by its overlap with the bat
        (``_inside_bat``, once its segment holds ``FLIGHT_AFTER`` samples after it or can take
        no more). Each young sample the ball's path over interval k can reach (its opening
        and closing samples, and those of the model's look-ahead), latest first, is judged by
        the free flight after it
        (``departure.glitch_before_flight``) once its segment holds ``FLIGHT_AFTER`` samples
        after it, or can take no more (a sample after the segment, or ``final``); then the
        segment's first sample, where it opens interval k, by the flight after it and the bat
        (``_first_glitch``: the bat's samples over the interval in too). Until then the
        interval waits (``held``: True). A glitch is dropped as ``ball_glitch`` and forgotten
        (``_glitch``), and the interval swept again without it: the samples after it are then
        judged against the flight of the good ones (its next sample is the segment's first).
        """
        ball, config = self.ball, self.config
        gap, times, n = config.max_gap, ball.times, len(ball.times)
        top = min(k + 1 + self.ahead, n - 1)
        if k >= 3 and True not in ball.breaks[k - 2:top] and times[top - 1] - times[k - 3] <= gap:
            return False  # (no segment starts at sample k - 2 or after: none is young)
        starts = segment_starts(ball, k, gap)
        if starts:  # (its segment's first sample: its overlap with the bat judged first)
            if self._flight_to_come(k):
                self.held = True
                return self._judged_again(ta, tb, events)
            if self._inside_bat(k) or off_gap_flight(ball, k, ta, config, self.gap_flight):
                self._glitch(k)
                self._forget_glitches()
                return self._judged_again(ta, tb, events)
        for j in range(top, k - 1, -1):
            first = j == k and starts
            if not (first or _young(ball, j, gap)):
                continue
            if self._flight_to_come(j):
                self.held = True  # (its segment may still grow)
            elif first:
                glitch = self._first_glitch(k, ta)
                if glitch is None:
                    self.held = True  # (the bat over its interval still to come)
                elif glitch:
                    self._glitch(k)
                    self._forget_glitches()
                else:
                    continue
            elif glitch_before_flight(ball, j, judging_noise(config), gap,
                                      stream_noise(ball, config)):
                self._glitch(j)
                self._forget_glitches()
            else:
                continue
            return self._judged_again(ta, tb, events)
        return False

    def _hit_before_flight(self, k: int, ta: float, tb: float, paths: Paths,
                           events: List) -> bool:
        """
        Solve a hit after the ball's sample k, its segment's first or second; True: found.

        Where sample k left the free flight of the samples after it continued back to it
        (``departure.flight_before``; kept by ``_first_glitch``: that flight touches the bat
        over the interval), the ball was hit between them, and the sweep has no flight before
        the contact to find it on (a path through sample k and those after it bends round the
        bat; the flight after it, continued back, runs through the bat from a contact before
        the hit to one after it). The contact is the first instant in the union interval [ta,
        tb] (s) at which the ball, pushed off the bat then onto that flight from sample k,
        touches the bat (``departure.HitApproach``, swept as a path: ``_first_contact``), where
        a bat gives the push that needs (``_pushed``); the ball's velocity at the impact is
        that ball's before the push (the fits' would reach across the contact). Where the
        ball's flight before its tracking gap runs on through the segment's samples up to k
        (``gap_flight.flight_across_gap``), the contact is that flight's first contact instead (its
        velocity the impact's), if a bat gives the push it needs: that pushed point only grazes
        the bat where the push about matches the ball's approach (the sweep's bat, braked
        after the contact, a millimetre off, then never meets it), and its first contact is
        early where the push outran the approach. Only while armed (that ball clear of the
        bat at ta). Where k is the segment's third sample, the hit after it on the flight
        before the gap (``_solved_on_gap_flight``). False (the interval swept as any other,
        the arming as it was) where neither rule holds or no such instant is in [ta, tb].
        """
        episodes = self.episodes
        armed = episodes.armed
        if self._solved_before_flight(k, ta, tb, paths, events) or \
                self._solved_on_gap_flight(k, ta, tb, paths, events):
            return True
        episodes.armed = armed  # (a path that found no hit arms nothing: ``_first_contact``)
        return False

    def _solved_before_flight(self, k: int, ta: float, tb: float, paths: Paths,
                              events: List) -> bool:
        """Return ``_hit_before_flight``'s answer (the detector armed where it looked)."""
        ball, config = self.ball, self.config
        flight = self._flight_after_start(k)
        if flight is None:
            return False
        approach, interval = HitApproach(flight, ball.values[k]), (ta, tb)
        across = flight_across_gap(ball, k, ta, tb, config, self.gap_flight)
        ahead = self._bat_ahead(interval, paths, True)
        bat_paths = (paths[1],) if ahead is None else (paths[1], ahead[1])
        found = None
        for ball_path in ((approach,) if across is None else (across, approach)):
            found = self._contact_on(interval, ball_path, bat_paths)
            if found is not None:
                break
        if found is None:
            return False
        t, hit, bat_path, slack = found
        if not self._pushed(approach, t, hit, bat_path):
            return False
        # the other answers: that point leaving the bat (a push that outran the ball), or
        # within the slack of it
        radius = config.ball_radius + slack
        first = self._contact(interval, (approach, bat_path), radius)
        last = self._contact((t, tb), (approach, bat_path), radius, backwards=True)
        spread = max(0.0 if last is None else last - t, 0.0 if first is None else t - first)
        self.episodes.impact(ball.times[k + 1])
        incoming = approach.incoming(t) if ball_path is approach else ball_path
        self._report(t, hit, interval, (incoming, bat_path), events, spread, incoming.velocity(t))
        return True

    def _solved_on_gap_flight(self, k: int, ta: float, tb: float, paths: Paths,
                              events: List) -> bool:
        """
        Solve a hit after the ball's sample k, its segment's third, on the flight before the gap.

        Where the segment's first three samples lie on the ball's flight before its tracking
        gap and its fourth, sample k + 1, is off the parabola through that flight and those
        three continued to it (``gap_flight.left_gap_flight``), the ball left that flight
        between samples k and k + 1. The departure test
        (``leaves_flight``) calls none there where the noise is not told (no interval before
        it to measure the scatter by), so the sweep's path over interval k runs from sample k
        to the rebound's frame, fiction that may never meet the bat. The contact is that
        flight's first contact with the bat over the union interval [ta, tb] (s) (the sweep's
        bat, or the bat continued from before the interval: ``_contact_on``, but no slack: a
        flight that only comes near the bat makes no hit, whatever a glitch did to the noise's
        estimate), its velocity the impact's. False where the rule does not hold or the flight
        does not touch the bat there (the interval swept as any other).
        """
        ball = self.ball
        flight = left_gap_flight(ball, k, ta, tb, self.config, self.gap_flight)
        if flight is None:
            return False
        interval = (ta, tb)
        ahead = self._bat_ahead(interval, paths, True)
        found = self._contact_on(interval, flight,
                                 (paths[1],) if ahead is None else (paths[1], ahead[1]), False)
        if found is None:
            return False
        t, hit, bat_path, _ = found
        self.episodes.impact(ball.times[k + 1])
        self._report(t, hit, interval, (flight, bat_path), events, 0.0, flight.velocity(t))
        return True

    def _contact_on(self, interval: Tuple[float, float], ball_path: Any,
                    bat_paths: Tuple[BatPath, ...], near: bool = True
                    ) -> Optional[Tuple[float, ImpactResult, BatPath, float]]:
        """
        Return a hit ball's first contact over the interval with the bat, and the bat's path.

        ``bat_paths``: the sweep's bat path, and the bat continued from before the interval
        where ``_bat_ahead`` gives one (taken where both touch: the bat brakes after the
        contact). Where neither touches and ``near``, the closest approach on the sweep's
        within the slack that kept the ball's sample (``_slack(BACK_GAIN)``). Each answer with
        that slack (m, 0: a touch); None where none is found (``_first_contact``).
        """
        found = None
        for bat_path in bat_paths:
            again = self._first_contact(interval, (ball_path, bat_path))
            if again is not None:
                found = (*again, bat_path, 0.0)
        if found is None and near:  # (off by the noise: within the slack that kept sample k)
            slack = self._slack(BACK_GAIN)
            again = self._first_contact(interval, (ball_path, bat_paths[0]), slack)
            if again is not None:
                found = (*again, bat_paths[0], slack)
        return found

    def _first_contact(self, interval: Tuple[float, float], paths: Paths,
                       slack: float = 0.0) -> Optional[Tuple[float, ImpactResult]]:
        """
        Return when (s) ``paths`` first touch over the interval while armed, and the contact.

        The sweep's sub-steps (``_contact``'s), the one that touches solved again in finer
        chords (``_refined``). Where none touches, the closest approach where it is within
        ``slack`` (m) of the bat (``episodes.lowest_gap`` over the sub-steps beside the
        smallest gap at their ends): the contact of a ball grown by that gap. None where they
        do not touch (nor come that near), touch at the interval's start, or the detector is
        not armed there (``EpisodeTracker.arm``: it arms where the ball is clear of the bat).
        """
        ta, tb = interval
        config = self.config
        start = self._state_at(ta, paths)
        if not self.episodes.arm(self._gap_at(start), ta):
            return None
        n = substeps_for(paths[0].deviation(ta, tb) + paths[1].deviation(ta, tb),
                         config.max_chord_error)
        self.stats.substeps += n
        states, gaps = [start], [self._gap_at(start)]
        for j in range(1, n + 1):
            end = self._state_at(tb if j == n else ta + (tb - ta) * j / n, paths)
            hit = profile_contact(start.ball, end.ball, start.tip, end.tip, start.knob, end.knob,
                                  config.ball_radius, config.profile, end.t - start.t)
            if hit is not None:
                if hit.initially_overlapping:
                    return None
                found = self._refined(start, end, paths)
                return found if found is not None else (start.t + hit.time, hit)
            states.append(end)
            gaps.append(profile_gap(end.ball, end.knob, end.tip, config.ball_radius,
                                    config.profile)[0])
            start = end
        if slack <= 0.0:
            return None
        m = gaps.index(min(gaps))
        steps = [(states[i], states[i + 1]) for i in (m - 1, m) if 0 <= i < n]
        nearest, (a, b) = min(((lowest_gap(a, b, config.ball_radius, config.profile), (a, b))
                               for a, b in steps), key=lambda pair: pair[0].gap)
        if nearest.gap > slack:
            return None
        hit = profile_contact(a.ball, b.ball, a.tip, b.tip, a.knob, b.knob,
                              config.ball_radius + nearest.gap + TOUCH_SLACK, config.profile,
                              b.t - a.t)
        return None if hit is None or hit.initially_overlapping else (a.t + hit.time, hit)

    @staticmethod
    def _pushed(approach: HitApproach, t: float, hit: ImpactResult, bat_path: BatPath) -> bool:
        """
        Return whether a bat gives the push a hit at t (s) needs (``HitApproach.push``).

        Away from the bat along the contact normal, its part across the normal at most
        ``FRICTION`` times that, and the ball coming at the bat's surface (its velocity before
        the push less the bat's axis's at the contact's place, along the normal) before it. A
        glitch before the flight after a hit needs a push across the normal, or toward the bat.
        """
        push, normal = approach.push(t), hit.normal
        along = dot(push, normal)
        across = math.sqrt(max(dot(push, push) - along * along, 0.0))
        if along <= 0.0 or across > FRICTION * along:
            return False
        ta, tb = max(t - SURFACE_STEP, bat_path.t0), min(t + SURFACE_STEP, bat_path.t1)
        places = []
        for u in (ta, tb):
            knob, tip = bat_path.at(u)
            places.append([k + hit.bat_fraction * (e - k) for k, e in zip(knob, tip)])
        surface = [(b - a) / (tb - ta) for a, b in zip(*places)]
        coming = approach.incoming(t).velocity(t)
        return dot(tuple(c - v for c, v in zip(coming, surface)), normal) < 0.0

    def _flight_to_come(self, j: int) -> bool:
        """
        Return whether ball sample j's segment may still take samples its judgment reads.

        The ``FLIGHT_AFTER`` samples after it: not in yet, the stream's newest sample in its
        segment, and the recording going on (not ``final``).
        """
        ball, gap = self.ball, self.config.max_gap
        n, last = len(ball.times), j
        while last < n - 1 and last < j + FLIGHT_AFTER and ball.continuous(last, gap):
            last += 1
        return last < j + FLIGHT_AFTER and last == n - 1 and not self.final

    def _judged_again(self, ta: float, tb: float, events: List) -> bool:
        """Sweep the union interval [ta, tb] (s) again unless it waits (``held``); True."""
        self.stats.intervals -= 1  # (counted when it is swept)
        if not self.held:
            self._swept(ta, tb, events)
        return True

    def _first_glitch(self, k: int, ta: Optional[float] = None) -> Optional[bool]:
        """
        Return whether the ball's sample k, its segment's first, is a glitch; None: wait.

        A glitch: it left the free flight of the samples after it continued back to it
        (``departure.flight_before``), and that flight does not touch the bat over interval k
        (the ball grown by ``_slack``): a hit between samples k and k + 1 leaves the
        sample before it off the flight after it too, but that flight, continued back, meets
        the bat at the contact; a glitch on a miss does not. A glitch too where it is off the
        flight before its tracking gap as well (``gap_flight.on_gap_flight``, ta (s) opening
        the union interval visited; None: not judged by it): no hit between it and the next
        sample explains a sample off both. None until the bat's samples that its paths over
        the interval read are in (``_bat_over``).
        """
        ball, config = self.ball, self.config
        flight = flight_before(ball, k, judging_noise(config), config.max_gap)
        if flight is None:
            return False
        if ta is not None:
            judged = on_gap_flight(ball, k, ta, config, self.gap_flight)
            if judged is not None and not judged[0][0]:
                return True
        bat_paths = self._bat_over(flight.t0, flight.t1)
        if bat_paths is None:
            return None
        radius = config.ball_radius + self._slack(BACK_GAIN)
        return not any(self._contact((max(flight.t0, path.t0), min(flight.t1, path.t1)),
                                     (flight, path), radius) is not None for path in bat_paths)

    def _inside_bat(self, k: int) -> bool:
        """
        Return whether the ball's sample k overlaps the bat deeper than a ball squashes.

        Deeper than ``SQUASH`` of the ball's radius, and ``_slack`` (a frame on the
        bat's axis, or at its knob or tip, which ``_first_glitch`` cannot judge before a
        hit), and off the parabola of the three samples after it continued back to it
        (``departure.back_miss``: by more than ``DEPARTURE_FLOOR`` and the noise's
        ``DEPARTURE_CHI_SQUARE`` bound at ``BACK_GAIN``; free flight or not, a hit may follow
        within those samples; a simulated ball that flies on through the bat, or a test's ball
        placed on it, is on it). For a segment's
        first sample, judged before the samples after it: as the sample before the second, it
        would make a hit's frame before the contact look off the hit's line
        (``departure.glitch_before_flight``), and it leaves no free flight after it to judge it
        by where a hit follows within two frames. On the bat's path over its sample interval
        that holds t_k, as the sweep builds it (its frames are in: an interval at or after it
        is swept); False where the bat has none there.
        """
        ball, bat, config = self.ball, self.bat, self.config
        t, gap = ball.times[k], config.max_gap
        b = bat.interval(t)
        if b < 0 or b + 1 >= len(bat.times) or not bat.continuous(b, gap):
            return False
        knob, tip = self._bat_path(b).at(t)
        depth = -profile_gap(ball.values[k], knob, tip, config.ball_radius, config.profile)[0]
        if depth <= SQUASH * config.ball_radius + self._slack(1.0):
            return False
        miss = back_miss(ball, k, gap)
        return miss is not None and miss > DEPARTURE_FLOOR + math.sqrt(
            DEPARTURE_CHI_SQUARE) * BACK_GAIN * stream_noise(ball, config)

    def _slack(self, ball_gain: float) -> float:
        """
        Return how far (m) a ball's path may seem from the bat, off by the noise.

        The chords' error (``max_chord_error``) and the noise's ``DEPARTURE_CHI_SQUARE`` bound
        on the root sum of squares of two errors: the ball's, ``ball_gain`` times its noise (1:
        a sample, ``_inside_bat``; ``BACK_GAIN``: the flight continued a step back from its
        three samples, ``_first_glitch``), and the bat's path's through noisy frames
        (``BAT_PATH_GAIN`` times the bat's).
        """
        config = self.config
        ball_noise, bat_noise = stream_noise(self.ball, config), stream_noise(self.bat, config)
        return config.max_chord_error + math.sqrt(DEPARTURE_CHI_SQUARE) * math.hypot(
            ball_gain * ball_noise, BAT_PATH_GAIN * bat_noise)

    def _bat_over(self, t0: float, t1: float) -> Optional[List[BatPath]]:
        """
        Return the bat's paths over its sample intervals within [t0, t1] (s), or None: wait.

        Each as the sweep builds it (``_bat_path``), none over a gap. None while a sample
        those paths read has not come (up to ``ahead`` past the last interval's closing
        sample, or its segment's end), unless the recording ended (``final``): the node and
        ``analyze``'s chunks then read the same samples.
        """
        bat, gap = self.bat, self.config.max_gap
        times, n = bat.times, len(bat.times)
        b = max(bat.interval(t0), 0)
        settled = times[-1] >= t1 and _settled(bat, bat.interval(t1) + 1, self.ahead, gap)
        if not (settled or self.final):
            return None
        paths = []
        while b + 1 < n and times[b] < t1:
            if times[b + 1] > t0 and bat.continuous(b, gap):
                paths.append(self._bat_path(b))
            b += 1
        return paths

    def _judged_glitch(self, k: int, spread: float) -> bool:
        """
        Return whether the ball's sample k, near the bat, is a glitch to drop and forget.

        A glitch by ``departure.glitch_path`` (no hit's line), or a departure no contact
        explains: sample k left the flight (``leaves_flight``) of samples k - 3 .. k - 1
        while the detector is armed and found no impact since the first of them, so the sweep
        found no contact on the flight, which a hit on this bat would have made (not where
        the first or second of them is its segment's first or second and left the flight
        after it, ``_hit_after_start``: those samples are no flight, and no sweep finds that
        hit; up to
        ``UNEXPLAINED_RUN`` in a row: two bad frames stuck on the bat after the ball passed it
        lie on one line from the flight, as a hit's do), and only where its neighbours stay
        within ``max_gap`` of each other (a ball really deflected at 60 Hz made a gap of its
        forgotten frames). Not after an impact since: a graze
        barely turns the ball, whose departure then shows a frame later, after the detector
        re-armed (a 60 Hz ball's frames after a graze were forgotten, a gap made of them).

        :param spread: the ball's noise (m, 1 sigma).
        """
        ball, config = self.ball, self.config
        judged = judging_noise(config)
        if glitch_path(ball, k, judged, config.max_gap, spread) is not None or (
                self.unexplained and self.episodes.armed is True
                and self.forgotten_run < UNEXPLAINED_RUN and k + 1 < len(ball.times)
                and ball.continuous(k, config.max_gap)
                and ball.times[k + 1] - ball.times[k - 1] <= config.max_gap
                and (self.impact_t is None or self.impact_t < ball.times[max(k - 3, 0)])
                and leaves_flight(ball, k - 1, judged, config.max_gap) is not None
                and not (self.early_glitches and self._hit_after_start(k - 3, k - 2))):
            self.forgotten_run += 1
            return True
        self.forgotten_run = 0
        return False

    def _hit_after_start(self, *samples: int) -> bool:
        """
        Return whether one of these ball samples (its segment's first or second) left it.

        Left the flight after it (``departure.flight_before``): a hit between it and the next
        sample. The sweep has no departure to find a hit in a segment's first two intervals by (too
        few samples before them), so a parabola through a sample before such a hit and the
        samples after it is no free flight: the next sample leaves it with no contact found,
        a genuine rebound's frame (``_judged_glitch``). (A first sample that left it where
        that flight does not touch the bat was dropped as a glitch: ``_first_glitch``.)
        """
        return any(j >= 0 and self._flight_after_start(j) is not None for j in samples)

    def _flight_after_start(self, k: int) -> Optional[PointPath]:
        """
        Return the flight after ball sample k where k, its segment's first or second, left it.

        ``departure.flight_before``: the free flight of the samples after k continued back over
        interval k, where sample k is off it (a hit between k and k + 1, or a glitch); None
        where k is later in its segment or on that flight.
        """
        ball, gap = self.ball, self.config.max_gap
        if not (segment_starts(ball, k, gap)
                or _young(ball, k, gap) and segment_starts(ball, k - 1, gap)):
            return None
        return flight_before(ball, k, judging_noise(self.config), gap)

    def _forget_glitches(self) -> None:
        """
        Remove the ball glitches counted (``glitches``) from the ball's stream.

        The samples the speed check set aside against one of them are judged again against
        the stream without it (``_judged_aside``).
        """
        ball, stamps = self.ball, self.ball.stamps
        for stamp in self.glitches:
            k = bisect_left(stamps, stamp)
            if k < len(stamps) and stamps[k] == stamp:
                ball.remove(k, (ESTIMATES,))
                if self.aside:
                    self._judged_aside(stamp)
        self.glitches.clear()

    def _glitch(self, k: int) -> None:
        """
        Count the ball's sample k, a glitch (``departure.glitch_path``), as a dropped sample.

        Once: its interval's path is kept by its stamps, and the sample leaves the stream once
        the union interval is swept (``interval``; until then every fit leaves it out:
        ``_ball_path``). A late drop (``LateDrop``, reason ``ball_glitch``), told by the call
        that judged it, as the node and ``analyze`` tell any other.
        """
        stamp = self.ball.stamps[k]
        if stamp == self.glitch_ns:
            return
        self.glitch_ns = stamp
        self.glitches.append(stamp)
        self.stats.drop_late(Role.BALL, DropReason.BALL_GLITCH, stamp, self.frame_of() or '')


def _young(stream: Stream, k: int, max_gap: float) -> bool:
    """Return whether sample k is its segment's second or third (a segment's start seen)."""
    if k < 1 or not stream.continuous(k - 1, max_gap):
        return False
    return segment_starts(stream, k - 1, max_gap) or (
        k >= 2 and stream.continuous(k - 2, max_gap) and segment_starts(stream, k - 2, max_gap))


def _settled(stream: Stream, k: int, ahead: int, max_gap: float) -> bool:
    """Return whether sample k + ``ahead`` has come, or sample k's segment ended before it."""
    n = len(stream.times)
    for j in range(k, k + ahead):
        if j + 1 >= n:
            return False
        if not stream.continuous(j, max_gap):
            return True
    return k + ahead < n
