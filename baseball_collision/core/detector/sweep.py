"""
One union interval, swept: from the streams' samples to exact solves, impacts and near misses.

For each interval between consecutive union times the sweep locates both streams' sample
intervals (a ``StreamGap`` where one spans more than ``max_gap``: not interpolated), then tries
ever finer far tests: the raw samples (``broadphase``), under noise the near-miss zone on the
bat's raw spline before its window is smoothed (``Sweep._outside_zone``), the motion paths'
bounding spheres, the chords' closest approach. An interval that may come close is cut into
sub-steps small enough for the chord error bound and each is solved exactly
(``toi.profile_contact``). The first contact while armed is an ``Impact``; every sub-step
without one feeds the near-miss episodes.
"""

import math
from typing import Any, Callable, List, Optional, Tuple

from .broadphase import c2_path_apart, clearly_apart, NOISE_REACH
from .config import DetectorConfig
from .departure import (
    DEPARTURE_CHI_SQUARE, DEPARTURE_FLOOR, flight_path, glitch_path, judging_noise,
    leaves_flight)
from .episodes import EpisodeTracker, State
from .events import DetectorStats, Impact, StreamGap
from .fitting import (
    ball_flight, c2_bat_path, c2_point_path, c2_window, flight_point_path, stream_noise)
from .gap_flight import GapFlight
from .gate import Clock
from .noise import ESTIMATES, NoiseEstimate
from .speed_aside import Aside
from .streams import Stream
from .sweep_ball import BallSamples
from .sweep_bat import BatFrames
from .sweep_impact import SweepImpact
from ..geometry import norm, Vector
from ..motion import BatPath, Paths, PointPath, samples_ahead, substeps_for
from ..toi import _kernel, closest_offset, ImpactResult, profile_contact, profile_gap
from ...errors import CoreError

IMPACT_CHORD_FACTOR = 0.04
"""An impact's sub-step is solved again in chords this times ``max_chord_error`` (0.5 mm ->
0.02 mm): about 5 chords a sub-step, only at impacts (``Sweep._refined``)."""

ZONE_STEPS = 16
"""Sub-steps at least that ``Sweep._outside_zone`` looks at an interval in."""


class Sweep(BallSamples, BatFrames, SweepImpact):
    """
    Sweeps union intervals of the ball and bat streams (``visit`` for the ``Scheduler``).

    Its judgments of the ball's samples near the bat and of the bat's frames near the ball
    (glitches dropped and forgotten, intervals that wait for the samples that judge them) are
    its bases' (``sweep_ball.BallSamples``, itself on ``speed_aside.SpeedAside``: the ball
    samples the speed check set aside; ``sweep_bat.BatFrames``); a hit's bat path and its
    ``Impact`` are its base ``sweep_impact.SweepImpact``'s.

    :param config: the detector's configuration (``DetectorConfig``).
    :param clock, stats: the detector's clock and counters.
    :param ball, bat: the streams.
    :param episodes: the arming state and near-miss episodes.
    :param offsets: (knob, tip) in the bat's body frame (m), for rigid paths from poses.
    :ivar measure: None, or what adds an impact's uncertainties (the detector's: the
        ``uncertainty`` module's, or with them kept pending; its own re-solves leave it None).
    :ivar on_contact: None, or what is told each impact's stamp (ns) and contact point (m) as
        soon as its contact is solved, before its velocities are fitted (``Detector``'s).
    :ivar bat_ahead: None: a hit's bat continued by ``_bat_ahead``'s rule; True: wherever the
        ball left its flight (under ``c2``); False: never (``uncertainty``'s re-solves).
    :ivar quintic_rates: True: ``kinematics.fit_velocities``' rule (the quintic's bat rates from
        exact samples at a high rate); False: the least-squares fits alone (``uncertainty``'s
        re-solve by the model of lower order, an estimate apart from the quintic).
    :ivar early_glitches: True: a segment's first three ball samples are judged by the
        flight after them (the first by the bat too), an interval near the bat waiting for it
        (``_early_glitch``), and a hit after its first or second solved from the flight after
        it (``_hit_before_flight``); False: neither (``uncertainty``'s re-solves, on copies
        whose first samples start no segment of the ball's).
    :ivar final: the recording ended (``Detector.finish``): nothing is waited for.
    :ivar held: the last interval visited waits for samples (``interval``): the ball's
        (``_early_glitch``), the bat frame after a hit's closing one (``_closing_glitch``), or
        the bat frames after an early one a contact hangs on (``_early_bat_glitch``).
    :ivar aside: ball samples the speed check set aside, judged again where the sample they
        were judged against is forgotten as a glitch (``speed_aside.SpeedAside.set_aside``).
    :ivar until: the end (s) of the union interval visited last: a sample set aside is put
        back only at or after it (the walk has not passed it).
    :ivar gap_flight: the ball's flight before its last tracking gap (``note_gap``:
        ``gap_flight.GapFlight``), or None.
    :ivar time_spread: while ``measure`` measures an impact, how far (s) from it lies the other
        answer of the rule that found it (``_hit_before_flight``), which its time's
        uncertainty holds; else 0.
    """

    __slots__ = ('config', 'clock', 'stats', 'ball', 'bat', 'episodes', 'offsets', 'model',
                 'max_radius', 'last_gap', 'measure', 'bat_ahead', 'quintic_rates', 'estimators',
                 'ahead', 'on_contact', 'glitch_ns', 'glitches', 'frame_of', 'unexplained',
                 'forgotten_run', 'impact_t', 'bat_glitches', 'bat_suspect', 'early_glitches',
                 'final', 'held', 'aside', 'until', 'time_spread', 'gap_flight')

    def __init__(self, config: DetectorConfig, clock: Clock, stats: DetectorStats, ball: Stream,
                 bat: Stream, episodes: EpisodeTracker, offsets: Tuple[Vector, Vector]) -> None:
        self.config, self.clock, self.stats = config, clock, stats
        self.ball, self.bat, self.episodes, self.offsets = ball, bat, episodes, offsets
        self.model = config.model
        self.max_radius = config.profile.max_radius
        self.last_gap: Optional[Tuple[State, float]] = None  # the last gap computed (m)
        self.measure: Optional[Callable[[Impact], Impact]] = None  # adds the uncertainties
        self.on_contact: Optional[Callable[[int, Vector], None]] = None  # told at once
        self.bat_ahead: Optional[bool] = None  # the rule (``_bat_ahead``), or always / never
        self.quintic_rates = True  # ``fit_velocities``' rule, or the fits alone
        # tracker_noise auto: the ball's and the bat's estimators, whose kept estimates set the
        # streams' noise at each interval (``_estimates``); None: the streams' noise as it is
        self.estimators: Optional[Tuple[NoiseEstimate, NoiseEstimate]] = None
        self.ahead = samples_ahead(config.model, config.look_ahead)
        self.glitch_ns: Optional[int] = None  # the ball glitch last counted (``_glitch``)
        self.glitches: List[int] = []  # stamps (ns) of the ball glitches still to forget
        # a ball sample that left the flight while armed (no contact on the flight before it)
        # is a glitch too (``_judged_glitch``; not in the uncertainty's re-solves, armed anew)
        self.unexplained = True
        self.forgotten_run = 0  # ball samples forgotten in a row for that
        self.impact_t: Optional[float] = None  # the last impact found (s), which explains one
        # bat frames off the swing are judged near the ball (``_bat_frames``; not in the
        # uncertainty's re-solves, of an impact that stood)
        self.bat_glitches = True
        self.bat_suspect: Optional[int] = None  # the stamp (ns) of a departed frame to judge
        self.early_glitches = True  # (a segment's first samples judged: ``_early_glitch``)
        self.final = False
        self.held = False
        self.aside: List[Aside] = []  # ball samples the speed check set aside (``set_aside``)
        self.until = -math.inf  # the end (s) of the interval visited last
        self.time_spread = 0.0  # (s: ``_report``'s, while its impact is measured)
        self.gap_flight: Optional[GapFlight] = None  # (``BallSamples.note_gap``)
        # the tracking frame (None: none yet), which a glitch's drop names (``Detector``'s)
        self.frame_of: Callable[[], Optional[str]] = lambda: None

    def interval(self, ta: float, tb: float, events: List) -> bool:
        """
        Sweep the union interval [ta, tb] (s), appending the events it makes; False: wait.

        False where the interval may come near the bat and the ball's path over it reaches
        one of its segment's first three samples, which only the samples after it judge
        (``_early_glitch``): nothing of it is swept, and the scheduler's walk stops before it,
        to visit it again once more ball samples are in (or the recording ended: ``final``).
        Once it is done with, the ball samples set aside at or before tb are dropped
        (``settle_aside``).

        Where the interval opens at a ball sample that is a glitch (``departure.glitch_path``)
        and the ball is not clearly apart from the bat, the sample is dropped as
        ``ball_glitch`` and forgotten before the interval is swept (``Stream.remove``): the
        interval is then part of the ball's interval from the sample before it to the one
        after, as if it had never come, and no later fit, departure test, velocity or noise
        estimate reads it (it stayed, and the test of a hit a few frames on was judged against
        the scatter it made: the hit was lost). A glitch a fit's window finds behind it
        (``_ball_path``, over an interval that was clear) is forgotten once the interval is
        swept.
        """
        self.held, self.until = False, tb
        self._swept(ta, tb, events)
        if self.glitches:
            self._forget_glitches()
        if self.aside and not self.held:
            self.settle_aside(tb)
        return not self.held

    def _bat_path(self, b: int) -> BatPath:
        """Return the bat's path over its sample interval b under the model (kept by ``paths``)."""
        bat, config = self.bat, self.config
        if bat.path_key == (bat.stamps[b], bat.stamps[b + 1]):
            return bat.path
        if self.model == 'c2':
            window = c2_window(bat, b, config.max_gap, config.look_ahead, config.spline_window)
            return c2_bat_path(bat, b, window, stream_noise(bat, config), window.stop == b + 2)
        before, after = _neighbours(bat, b, config.max_gap)
        return BatPath.build(self.model, bat.times[b], bat.times[b + 1], bat.values[b],
                             bat.values[b + 1], before, after, self.offsets)

    def _swept(self, ta: float, tb: float, events: List) -> None:
        """Sweep the union interval [ta, tb] (s) (``interval``)."""
        located = self._locate(ta, events)
        if located is None:
            return
        if self.bat_suspect is not None:
            self._judge_suspect(located[1])
            located = self._locate(ta, events)
            if located is None:
                return
        self.stats.intervals += 1
        config = self.config
        if self.estimators is not None:
            self._estimates(located)
        margin = (config.ball_radius + self.max_radius + 1e-6
                  + max(config.near_miss_threshold, config.rearm_distance))
        ball, bat = self.ball, self.bat
        ball_noise, bat_noise = stream_noise(ball, config), stream_noise(bat, config)
        if clearly_apart(ball, bat, located[0], located[1], margin, self.model, config.max_gap,
                         config.look_ahead, config.spline_window, ball_noise + bat_noise):
            self.episodes.far(events, ta)
            return
        if ball.times[located[0]] == ta and self._judged_glitch(located[0], ball_noise):
            self._glitch(located[0])
            self._forget_glitches()
            located = self._locate(ta, events)
            if located is None:  # (its neighbours are further apart than ``max_gap``)
                return
            if self.estimators is not None:
                self._estimates(located)
            ball_noise, bat_noise = stream_noise(ball, config), stream_noise(bat, config)
        if self.model == 'c2' and ball_noise > 0.0 and c2_path_apart(
                self._kept_ball_path(located[0]), ball, bat, located[0], located[1], margin,
                config.max_gap, config.look_ahead, config.spline_window, bat_noise):
            self.episodes.far(events, ta)
            return
        if (bat_noise > 0.0 and self.model == 'c2' and self.episodes.episode is None
                and self._outside_zone(located, ta, tb, bat_noise)):
            self.episodes.far(events, ta)  # (what the sweep's sub-steps would come to: see there)
            return
        self._solve(ta, tb, located, self.paths(*located), events)

    def _solve(self, ta: float, tb: float, located: Tuple[int, int], paths: Paths,
               events: List, judged: bool = False) -> None:
        """
        Solve the union interval [ta, tb] (s) on the paths over the sample intervals located.

        Where the paths come near, the bat frames they read are judged first (``_bat_frames``;
        ``judged``: they were): the interval is located again without a glitch, or solved on
        the bat's path without a frame that departed.
        """
        config = self.config
        margin = (config.ball_radius + self.max_radius + 1e-6
                  + max(config.near_miss_threshold, config.rearm_distance))
        ball_path, bat_path = paths
        apart = math.dist(ball_path.centre, bat_path.centre) - ball_path.radius - bat_path.radius
        if apart > margin:
            # the bounding spheres of both whole sample intervals are clear: far apart
            self.episodes.far(events, ta)
            return
        ball_a, ball_b = ball_path.at(ta), ball_path.at(tb)
        knob_a, tip_a = bat_path.at(ta)
        knob_b, tip_b = bat_path.at(tb)
        deviation = ball_path.deviation(ta, tb) + bat_path.deviation(ta, tb)
        reach = 0.5 * max(math.dist(knob_a, tip_a), math.dist(knob_b, tip_b)) + deviation + margin
        if norm(closest_offset(ball_a, ball_b, tip_a, tip_b, knob_a, knob_b)) > reach:
            self.episodes.far(events, ta)
            return
        if not judged and self.bat_glitches and self.episodes.armed is not False:
            without = self._bat_frames((ta, tb), located[1], paths)
            if without is None:  # (a glitch forgotten: located again; or it waits: ``held``)
                self.stats.intervals -= 1  # (counted again, or when it is swept)
                if not self.held:
                    self._swept(ta, tb, events)
                return
            if without is not paths:  # (its far tests again, on the bat without the frame)
                self._solve(ta, tb, located, without, events, True)
                return
        if self.early_glitches and (self._early_glitch(located[0], ta, tb, events)
                                    or self._hit_before_flight(located[0], ta, tb, paths, events)):
            return
        if self.episodes.armed is False:
            self._past_departure(located[0], ball_path)
        n = substeps_for(deviation, config.max_chord_error)
        self.stats.substeps += n
        previous = State(ta, ball_a, knob_a, tip_a)
        gap_previous = self._gap_at(previous)
        earlier = previous
        for j in range(1, n + 1):
            if j == n:
                state = State(tb, ball_b, knob_b, tip_b)
            else:
                t1 = ta + (tb - ta) * j / n
                state = self._state_at(t1, paths)
            gap = self._gap_at(state)
            if self._substep(previous, state, gap_previous, gap, (ta, tb), paths, events,
                             earlier):
                return
            earlier, previous, gap_previous = previous, state, gap

    def _contact(self, interval: Tuple[float, float], paths: Paths,
                 radius: Optional[float] = None, backwards: bool = False) -> Optional[float]:
        """
        Return when (s) ``paths`` first touch in the sub-steps a sweep of the interval cuts.

        The first sub-step whose chords touch (``toi.profile_contact``), at its contact; None
        where none does. ``radius``: the ball's (m; None: ``ball_radius``). ``backwards``: the
        sub-steps run from the interval's end, time reversed: when they last touch.
        """
        ta, tb = interval
        config = self.config
        radius = config.ball_radius if radius is None else radius
        n = substeps_for(paths[0].deviation(ta, tb) + paths[1].deviation(ta, tb),
                         config.max_chord_error)
        start = self._state_at(tb if backwards else ta, paths)
        for j in range(1, n + 1):
            if backwards:
                end = self._state_at(ta if j == n else tb - (tb - ta) * j / n, paths)
            else:
                end = self._state_at(tb if j == n else ta + (tb - ta) * j / n, paths)
            hit = profile_contact(start.ball, end.ball, start.tip, end.tip, start.knob, end.knob,
                                  radius, config.profile, abs(end.t - start.t))
            if hit is not None:
                return start.t - hit.time if backwards else start.t + hit.time
            start = end
        return None

    def _estimates(self, located: Tuple[int, int]) -> None:
        """
        Set each stream's noise to its estimate after its sample ``ahead`` past the closing one.

        Under ``tracker_noise`` auto: the samples an interval's fits may use end there
        (``samples_ahead``), whichever stream has run further ahead when it is swept
        (``noise.ESTIMATES``); at the recording's end, the newest (the estimator's own where a
        fast-forward kept none for it).

        :raises CoreError: no estimate kept for that sample (a fast-forward took it at once: a
            broken invariant, never an answer made from another estimate).
        """
        ahead, estimators = self.ahead, self.estimators
        for stream, k, estimator in ((self.ball, located[0], estimators[0]),
                                     (self.bat, located[1], estimators[1])):
            kept = stream.aligned.get(ESTIMATES, ())
            newest = len(stream.times) - 1
            last = min(k + 1 + ahead, newest)
            estimate = kept[last] if last < len(kept) else None
            if estimate is None:
                if last != newest:
                    raise CoreError(f'no noise estimate kept for {stream.name} sample '
                                    f'{stream.stamps[last]} ns')
                estimate = estimator.sigma
            stream.noise = estimate

    def _outside_zone(self, located: Tuple[int, int], ta: float, tb: float,
                      bat_noise: float) -> bool:
        """
        Return whether the ball stays beyond the near-miss and re-arm distances over [ta, tb].

        Under noise, before the bat's window is smoothed (the costly part of an interval near
        the bat), on the bat's ``c2`` spline through its window's raw samples, which the
        smoothed path leaves by at most ``NOISE_REACH`` times the bat's noise (the far test's
        bound), and the ball's own path: in at least ``ZONE_STEPS`` sub-steps, each within
        ``max_chord_error`` of its chords, the gap at every point of one is at least the mean
        of its ends' less half of how far the ball and the farther bat end moved (the gap is
        1-Lipschitz in each). When even that clears both distances by the bounds, the sweep's
        own sub-steps would find no contact and only gaps beyond them: with no near miss open,
        the same as ``EpisodeTracker.far`` (armed, the zone cleared). False as soon as a gap
        comes closer. The instants' loop is the kernel's (``toi._kernel.zone_clear``; each
        distance moved the square root of the summed squares).
        """
        config = self.config
        floor = (max(config.near_miss_threshold, config.rearm_distance)
                 + NOISE_REACH * bat_noise + config.max_chord_error)
        ball_k, bat_k = located
        bat = self.bat
        ball_path = self._kept_ball_path(ball_k)
        window = c2_window(bat, bat_k, config.max_gap, config.look_ahead, config.spline_window)
        raw = c2_bat_path(bat, bat_k, window)  # (without noise: through the raw samples)
        n = max(substeps_for(ball_path.deviation(ta, tb) + raw.deviation(ta, tb),
                             config.max_chord_error), ZONE_STEPS)
        return _kernel.zone_clear(ball_path, raw, ta, tb, n, config.ball_radius,
                                  config.profile, floor)

    @staticmethod
    def _state_at(t: float, paths: Paths) -> State:
        """Return the ball and the bat on their paths at t (s)."""
        knob, tip = paths[1].at(t)
        return State(t, paths[0].at(t), knob, tip)

    def _refined(self, earlier: State, end: State,
                 paths: Paths) -> Optional[Tuple[float, ImpactResult]]:
        """
        Return the first contact over [earlier.t, end.t] in chords ``IMPACT_CHORD_FACTOR`` finer.

        A sub-step's chords may leave the paths by ``max_chord_error``, and the time and the
        spot with them; solved again in finer chords, the impact is as exact as the paths.
        None when the finer chords touch nowhere (the caller keeps the sub-step's own
        contact). Only at an impact.
        """
        ball_path, bat_path = paths
        config = self.config
        deviation = (ball_path.deviation(earlier.t, end.t)
                     + bat_path.deviation(earlier.t, end.t))
        m = substeps_for(deviation, config.max_chord_error * IMPACT_CHORD_FACTOR)
        start = earlier
        for i in range(1, m + 1):
            stop = end if i == m else self._state_at(
                earlier.t + (end.t - earlier.t) * i / m, paths)
            hit = profile_contact(start.ball, stop.ball, start.tip, stop.tip, start.knob,
                                  stop.knob, config.ball_radius, config.profile,
                                  stop.t - start.t)
            if hit is not None:
                return start.t + hit.time, hit
            start = stop
        return None

    def _locate(self, ta: float, events: List) -> Optional[Tuple[int, int]]:
        """Return each stream's sample interval index holding ta, or None across a gap."""
        indices = []
        for stream in (self.ball, self.bat):
            k = stream.interval(ta)
            if k < 0 or k + 1 >= len(stream.times):
                return None
            if not stream.continuous(k, self.config.max_gap):
                if stream.reported_gap != stream.stamps[k]:
                    stream.reported_gap = stream.stamps[k]
                    self.stats.gaps += 1
                    events.append(StreamGap(stream=stream.name, start_ns=stream.stamps[k],
                                            end_ns=stream.stamps[k + 1]))
                    self.episodes.interrupted(events)
                return None
            indices.append(k)
        return indices[0], indices[1]

    def paths_at(self, t: float) -> Optional[Paths]:
        """
        Return the paths over the sample intervals holding t (s), as a sweep builds them there.

        Each stream's interval as ``_locate`` finds it (None outside the samples or across a
        gap), under ``tracker_noise`` auto with each stream's noise as of that interval
        (``_estimates``); the bat's without a frame that departed from its continuation
        (``_without_departed``); where the ball left its flight there and the rule continues
        the bat from before the interval (``_bat_ahead``: a hit), that bat, which solved the
        hit. For drawing and inspecting the motion the detector solves.
        """
        located = []
        for stream in (self.ball, self.bat):
            k = stream.interval(t)
            if k < 0 or k + 1 >= len(stream.times) or \
                    not stream.continuous(k, self.config.max_gap):
                return None
            located.append(k)
        if self.estimators is not None:
            self._estimates((located[0], located[1]))
        paths = self.paths(located[0], located[1])
        if self.bat_glitches:
            ball, bat = self.ball, self.bat
            union = (max(ball.times[located[0]], bat.times[located[1]]),
                     min(ball.times[located[0] + 1], bat.times[located[1] + 1]))
            paths = self._without_departed(union, located[1], paths)[0]
        return self._bat_ahead((t, t), paths) or paths

    def paths(self, ball_k: int, bat_k: int) -> Paths:
        """
        Return (ball path, bat path) over the sample intervals ball_k and bat_k (cached).

        ``c2``'s bat, exact (``tracker_noise`` 0, or auto reading none) over an interval that
        is its window's last piece (look-ahead 0, or a segment's newest samples): that piece
        may be the quintic spline's (``splines.quintic_window``, ``continued``), as an inner
        piece is. Its end weights amplify noise the detector was not told of, as the
        quintic's do at look-ahead 1 (BENCHMARKS.md, "The quintic's last piece at look-ahead
        0").
        """
        bat = self.bat
        ball_path = self._kept_ball_path(ball_k)
        key = (bat.stamps[bat_k], bat.stamps[bat_k + 1])
        if bat.path_key != key:
            bat.path, bat.path_key = self._bat_path(bat_k), key
        return ball_path, bat.path

    def _kept_ball_path(self, ball_k: int) -> PointPath:
        """Return the ball's path over its sample interval ball_k (kept by its stamps)."""
        ball = self.ball
        key = (ball.stamps[ball_k], ball.stamps[ball_k + 1])
        if ball.path_key != key:
            ball.path = self._ball_path(ball_k)
            ball.path_key = key
        return ball.path

    def _ball_path(self, k: int) -> PointPath:
        """
        Return the ball's path over its sample interval k under the model.

        Where the closing sample has left the ball's free flight (``departure.leaves_flight``:
        a hit turns the ball round before the next frame), the free flight's parabola instead,
        but where ``c2`` with noise takes a flight fit (whose guard turns from a departed frame
        to the fit ending at the opening frame: ``fitting.ball_flight``); and neither a
        spline's tangent nor a ``c2`` look-ahead reaches across a departure after the interval.
        A ``c2`` smoother is no free flight either (noise so small that a parabola over the
        flight fit's span fails its guard: the smoother then follows the departed frame).
        """
        ball, config = self.ball, self.config
        gap, noise, judged = config.max_gap, stream_noise(ball, config), judging_noise(config)
        glitch = glitch_path(ball, k, judged, gap, noise)
        if glitch is not None:
            self._glitch(k)
            return glitch
        if self.model == 'c2':
            window = c2_window(ball, k, gap, config.look_ahead, config.spline_window)
            for j in range(k - 1, window.start - 1, -1):  # nor from behind a glitch
                if glitch_path(ball, j, judged, gap, noise) is not None:
                    self._glitch(j)
                    window = range(j + 1, window.stop)
                    break
            for j in range(k + 1, window.stop - 1):  # the look-ahead ends at a departure
                if leaves_flight(ball, j, judged, gap) is not None:
                    window = range(window.start, j + 1)
                    break
            fit = ball_flight(ball, k, window, noise, config)
            if fit is not None:
                return flight_point_path(ball, k, fit)
            path = c2_point_path(ball, k, window, noise)
        else:
            before, after = _neighbours(ball, k, gap)
            if after is not None and leaves_flight(ball, k + 1, judged, gap) is not None:
                after = None
            if before is not None and glitch_path(ball, k - 1, judged, gap, noise) is not None:
                self._glitch(k - 1)
                before = None
            path = PointPath.build(self.model, ball.times[k], ball.times[k + 1], ball.values[k],
                                   ball.values[k + 1], before, after)
        departed = leaves_flight(ball, k, judged, gap)
        return path if departed is None else flight_path(ball, k, departed)

    def _past_departure(self, k: int, path: PointPath) -> None:
        """
        After an impact, let no sub-step re-arm on a ball interval k whose path is fiction.

        The ball's path over interval k is fiction where it does not end at its closing sample:
        where that sample has left the ball's free flight (``leaves_flight``: the ball turned
        round in it), the path is that flight continued through the bat and beyond
        (``_ball_path``), and where ``c2`` takes a flight fit its guard ends the fit at the
        opening frame; the path then ends more than the departure floor, and more than the
        noise's ``DEPARTURE_CHI_SQUARE`` bound, from the sample. No sub-step re-arms before
        its closing frame (``EpisodeTracker.substeps_from``; the far tests, which the chunk
        plans decide on arrays, keep ``rearm_from``). The frame just after a hit can still look
        like free flight (the ball had barely turned), so the departure may show an interval
        later than the impact's.
        """
        ball, config = self.ball, self.config
        bound = max(DEPARTURE_FLOOR, math.sqrt(DEPARTURE_CHI_SQUARE) * stream_noise(ball, config))
        if leaves_flight(ball, k, judging_noise(config), config.max_gap) is not None or \
                math.dist(path.at(ball.times[k + 1]), ball.values[k + 1]) > bound:
            episodes = self.episodes
            episodes.substeps_from = max(episodes.substeps_from, ball.times[k + 1])

    def _gap_at(self, state: State) -> float:
        """Return the gap (m) at a state, reusing the last one computed."""
        cached = self.last_gap
        if cached is not None and cached[0] == state:
            return cached[1]
        gap = profile_gap(state.ball, state.knob, state.tip, self.config.ball_radius,
                          self.config.profile)[0]
        self.last_gap = (state, gap)
        return gap

    def _substep(self, start: State, end: State, gap0: float, gap1: float,
                 interval: Tuple[float, float], paths: Paths, events: List,
                 earlier: State) -> bool:
        """
        Solve one linear sub-step between two states; True on an impact.

        A contact found is solved again in finer chords (``_refined``) over this sub-step, or,
        when its chords found it already touching at ``start`` (the previous sub-step's chords
        passed just outside it), from ``earlier``: that sub-step's start (``start`` for the
        interval's first). The ball was armed and apart there: else that sub-step would have
        made the impact.
        """
        episodes = self.episodes
        if episodes.arm(gap0, start.t):
            config = self.config
            hit = profile_contact(start.ball, end.ball, start.tip, end.tip, start.knob, end.knob,
                                  config.ball_radius, config.profile, end.t - start.t)
            if hit is not None:
                ball = self.ball
                episodes.impact(ball.times[ball.interval(interval[0]) + 1])
                found = self._refined(earlier if hit.initially_overlapping else start, end,
                                      paths)
                t, hit = found if found is not None else (start.t + hit.time, hit)
                ahead = self._bat_ahead(interval, paths)
                again = None if ahead is None else self._refined(
                    self._state_at(interval[0], ahead), self._state_at(interval[1], ahead), ahead)
                if again is not None and not again[1].initially_overlapping:
                    (t, hit), paths = again, ahead
                self._report(t, hit, interval, paths, events)
                return True
        episodes.track(start, end, gap0, gap1, events)
        return False


def _neighbours(stream: Stream, k: int, max_gap: float) -> Tuple[Any, Any]:
    """Return the samples (time, value) before k and after k + 1 in its segment, or None."""
    before, after = stream.neighbours(k, max_gap)
    return (None if before is None else (stream.times[before], stream.values[before]),
            None if after is None else (stream.times[after], stream.values[after]))
