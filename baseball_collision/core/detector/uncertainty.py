"""
The 1-sigma uncertainties of an impact: its time, its spot on the bat, its sweet-spot speed.

Measured only at an impact (impacts are rare), by re-solving it: never per sample, so the
detector's cost per message without an impact is unchanged.

With tracking noise under ``c2`` (``tracker_noise`` > 0, or each stream's estimate under auto),
linear propagation (``propagated``): its paths are linear in their windows' samples, so the
noise gives each path's position and rate at the impact a known spread, carried to the gap
along the contact normal (the time, over the closing speed), to the contact's place along the
bat (the spot) and to the sweet spot's velocity (the speed). From knob and tip points the
knob's error and the direction's are correlated (a knob marker's noise moves the knob and
turns the bat the other way), and the gap keeps their covariance (``fitting.bat_gains``'
correlation); a pose's orientation noise moves its knob too, by the knob's offset from the
pose's origin (``fitting.bat_variances``), sharing the direction's rows: the contact point moves
as far from the origin as it is. No re-solve, about a millisecond.
The ball's spread is its flight fit's (``fitting.point_gains``: the least-squares covariance,
widened by the residuals' excess over the noise) where the detector took one, else its
smoother's. The gap also holds the fits' own error, which no noise shows: a smoother's bias
on an accelerating swing, a parabola's on a ball whose drag changes over its window. Each
fit's move of the gap from the next richer fit of the same samples (``fitting.bat_shifts``,
``point_shifts``: the smoothed window from its interpolant, the quintic's where the window
takes one; the ball's flight fit from one of a degree more) is squared, less the variance the
noise alone gives that move (the square's expectation is the squared bias plus it), and added
in quadrature when positive. Without it, with 0.1 mm of noise on the ball alone, the time was
within 2 sigma in 0.72 of 36 contacts at 360 Hz (0.92 with it); on the calibration test's
contacts at 0.5-2 mm 0.91-0.96 (0.95-0.99), at 0.1-0.3 mm 0.83-0.94 (0.87-0.97):
BENCHMARKS.md, "The fits' own error in the error bars".
Under ``c2`` with a look-ahead, the difference from the same fit without it is added in
quadrature (how far the frames after the contact bent it: a bias, not noise).

With noise under the other models (which interpolate), a parametric bootstrap: the impact is
re-solved ``PERTURBATIONS`` times, each time on a copy of the samples around it with every
coordinate shaken by an independent Gaussian of that sigma (a bat pose: its position by sigma
and its orientation by sigma / ``MARKER_SPREAD_M`` rad per axis, the noise of a motion-capture
rigid body solved over markers that far apart), by the same model, windows and velocity fits
as the detector. For estimates close to linear in the samples the spread of the re-solves
around the reported impact is the spread of the reported impact around the truth. Re-solves
that miss (a graze) are left out. The uncertainty is that standard deviation; the speed's holds
in quadrature the fits' own bias as the noise-free estimate below bounds it (the difference from
``before_rule_speed``: the least-squares fits behind these models' speeds are biased on an
accelerating swing, which no shaking of the samples shows; without it `rigid`'s speed was
within its 1 sigma in 4-25 % of impacts at 0.3-2 mm, BENCHMARKS.md, "The node's default"), and
the time's the fits' own error as the higher-order ``c2`` shows it: the distance from the farther
of ``c2``'s two answers (``braked`` below, at every impact, not only at a hit; without it the
time was within 1 sigma in 36-57 % and within 2 in 65-90 % of impacts at 0.5-2 mm, pooled over
the swing families, BENCHMARKS.md, "`~/impact` before its error bars and its velocities"). With
fewer than two hits, the noise-free estimate below stands in. The random source is seeded from the
impact's stamps (``seed_for``), so the node and ``analyze``, given the same samples, report
the same uncertainties to the bit.

With ``tracker_noise`` 0, the interpolation's own error estimate: the absolute difference
between the impact and the one the model of next lower order solves over the same samples
(``ALTERNATIVE``: c2 against spline, spline against rigid, rigid against linear; linear, the
lowest, against rigid). It measures the lower-order model's error more than the deciding
one's: by design an over-estimate of the time and the spot (measured 2-30 times the error on
the simulator's swings). The lower-order model's velocities are its least-squares fits' (not
the quintic's bat rates ``kinematics.fit_velocities`` takes from exact samples at a high rate,
which both would share). The speed's can fall short where both models take their velocities
from the same least-squares fits (``rigid``, ``spline``, and ``c2`` at a low rate: there the
speed's is at least the difference from the speed ``c2``'s noise rule would give, the window
fits before the impact extrapolated to it, ``before_rule_speed``). When the alternative finds
no impact (a tick it sees pass just clear of the bat), its closest approach stands in for the
time and the spot, and 10 % of the speed for the speed; when it does not even see the ball
within the near-miss threshold, coarse bounds: the interval's length, the ball's radius, 10 %
of the speed. (The same for ``c2``'s look-ahead difference above.) Where bat frames were lost
just before the contact (the impact more than ``CARRY_STEPS`` typical steps after the bat's
last sample: a marker occluded, dropped samples), the speed is carried over more than a step,
which no model of the same fits shows: the speed's is then at least the difference from the
speed of the quadratic fit (``CARRY_DEGREE``, a constant acceleration) over the same samples.
At 90 Hz with two frames lost the speed's error was within 2 sigma in 67 % of impacts, now 100
% (one frame: 79 -> 100 %; none lost: unchanged, 90 %; ``bench_lost_frames.py``).

At a hit (the ball left its free flight over the impact's interval: ``departure``) every
model's time uncertainty also holds the bat's brake: the interval's closing bat frame is after
the contact, where a real bat has slowed within 1-3 ms, and a path through it comes out late;
the bat continued from before the interval (``fitting.c2_bat_ahead``) has no brake but
extrapolates over up to a step. The impact is re-solved under ``c2`` both ways (``braked``),
and its distance from the farther of the two is added in quadrature: the truth lies between
them or near (BENCHMARKS.md, "The brake in the error bars"). The same for the spot (session 65:
`analyze --decimate 2` on the bundled 180 Hz rebound bag found its spot at 90 Hz within 2 of
its sigma in 56 % of the hits, moved by up to 0.57 mm where the interpolation's estimate said
less; BENCHMARKS.md, "A bag at lower rates").

Not covered: a bias the fits share that the ball does not show. On the simulator's braking
swings without a rebound (the bat slows, the ball flies on through it, which no real hit does)
the time comes out late by about 2 sigma at 1 mm and 90 Hz.
"""

from bisect import bisect_left, bisect_right
from dataclasses import dataclass, replace
import math
from typing import List, Optional, Tuple, Union

import numpy as np

from . import fitting
from .config import DetectorConfig
from .departure import judging_noise, leaves_flight
from .episodes import EpisodeTracker
from .events import DetectorStats, Event, Impact, NearMiss
from .fitting import (
    bat_errors, bat_gains, c2_bat_path, c2_window, kept_history, MARKER_SPREAD_M, MAX_WINDOW,
    NOISE_SPAN, point_gains, point_shifts, stream_noise, swing_rate)
from .gate import Clock
from .kinematics import c2_velocities, rigid_bat, spline_window_for, velocity_interval
from .streams import excerpt, Stream
from .sweep import Sweep
from ..geometry import (
    add, advance, axis_angle_quaternions, cross, dot, norm, pose_point, quaternion_multiply,
    rigid_point_velocity, scale, sub, Vector)
from ..motion import BatSample, C2BatPath, samples_ahead, unit_axis

PERTURBATIONS = 16
"""Re-solves per impact under perturbed samples (noise, models but ``c2``)."""

ALTERNATIVE = {'c2': 'spline', 'spline': 'rigid', 'rigid': 'linear', 'linear': 'rigid'}
"""The model each model's noise-free error estimate is taken against."""

CARRY_STEPS = 1.5
"""An impact more than this many typical bat steps after the bat's last sample before it was
reached across lost frames (``carried_far``)."""

CARRY_DEGREE = 2
"""The velocity fit's degree an impact reached across lost frames is compared against."""

SLOPE_STEP_S = 1e-4
"""Half the central difference (s) that gives the sweet-spot speed's rate of change at an impact:
the time's error moves the instant the speed is read at (``propagated``)."""

MARGIN_SAMPLES = 3
"""Samples kept beyond the widest window either side of the re-solved intervals."""

Uncertainty = Tuple[float, float, float]
"""1-sigma uncertainties of the time (s), distance from the knob (m), sweet-spot speed (m/s)."""


def seed_for(impact: Impact) -> List[int]:
    """Return the random seed of an impact's perturbations (from its stamps, ns)."""
    return [int(impact.stamp_ns), int(impact.interval_start_ns), int(impact.interval_end_ns)]


def _span(stream: Stream, start: float, end: float, config: DetectorConfig, upto: float,
          tb: float) -> Tuple[int, int]:
    """
    Return the sample indices a re-solve of [start, end] (s) can need.

    None after ``upto`` (s) but the impact's own: its interval's closing sample after ``tb`` (s)
    and the look-ahead's, which the sweep had.
    """
    back = max(config.spline_window, MAX_WINDOW) + MARGIN_SAMPLES
    reach = max(config.velocity_window, NOISE_SPAN)
    if fitting.FLIGHT is not None and stream_noise(stream, config) > 0.0:
        reach = max(reach, kept_history(config))  # a flight fit's window
    first = bisect_right(stream.times, start - reach - 1e-6) - 1 - back
    last = bisect_left(stream.times, end) + config.look_ahead + 1 + MARGIN_SAMPLES
    held = max(bisect_right(stream.times, upto) - 1,
               bisect_left(stream.times, tb) + config.look_ahead)
    return max(first, 0), min(last, held, len(stream.times) - 1)


def _held(stream: Stream, tb: float, config: DetectorConfig) -> float:
    """
    Return the time (s) of the stream's newest sample an interval ending at tb (s) waits for.

    Its sample ``samples_ahead`` past the first at or after tb: the scheduler sweeps the
    interval only once both streams hold theirs (or the recording has ended: its newest).
    """
    times = stream.times
    last = bisect_left(times, tb) + samples_ahead(config.model, config.look_ahead)
    return times[min(last, len(times) - 1)]


def union_intervals(ball: Stream, bat: Stream, ta: float, tb: float,
                    upto: float = math.inf) -> List[Tuple[float, float]]:
    """Return the union intervals before [ta, tb] (s), it and after it (to upto), if any."""
    before = [s.times[k] for s in (ball, bat)
              for k in (bisect_left(s.times, ta) - 1,) if k >= 0]
    after = [s.times[k] for s in (ball, bat)
             for k in (bisect_right(s.times, tb),) if k < len(s.times) and s.times[k] <= upto]
    intervals = [(max(before), ta)] if before else []
    intervals.append((ta, tb))
    if after:
        intervals.append((tb, min(after)))
    return intervals


def resolve(config: DetectorConfig, clock: Clock, ball: Stream, bat: Stream,
            offsets: Tuple[Vector, Vector], ta: float, tb: float,
            bat_ahead: Optional[bool] = None, closest: bool = False,
            quintic_rates: bool = True) -> Optional[Union[Impact, NearMiss]]:
    """
    Return the first impact about the union interval [ta, tb] (s), or None.

    A fresh, armed sweep over the given streams (copies: a sweep caches its paths on them) of
    [ta, tb]; of the union interval before it too when the contact was already there at ta,
    of the one after it when there was none. ``bat_ahead``, ``quintic_rates``: the sweep's
    (``Sweep.bat_ahead``, ``Sweep.quintic_rates``). ``closest``: without an impact, the closest
    approach over what was swept instead (a ``NearMiss``: the ball passed within the near-miss
    threshold), if any.
    """
    stats = DetectorStats()
    episodes = EpisodeTracker(config, clock, stats)
    sweep = Sweep(config, clock, stats, ball, bat, episodes, offsets)
    sweep.bat_ahead, sweep.quintic_rates = bat_ahead, quintic_rates
    sweep.unexplained = False  # (armed anew after the contact too)
    sweep.bat_glitches = False  # (the bat's frames were judged when the impact was found)
    sweep.early_glitches = False  # (judged by the detector; a copy's first starts no segment)
    passes: List[Event] = []

    def first_impact(start: float, end: float) -> Optional[Impact]:
        events: List = []
        episodes.armed = True
        episodes.zone_clear = episodes.zone_clear or closest  # (any approach an episode)
        sweep.interval(start, end, events)
        passes.extend(event for event in events if event.__class__ is NearMiss)
        return next((event for event in events if event.__class__ is Impact), None)

    intervals = union_intervals(ball, bat, ta, tb)
    found = first_impact(ta, tb)
    if found is not None and found.initially_overlapping and intervals[0][1] == ta:
        return first_impact(*intervals[0]) or found
    if found is None and intervals[-1][0] == tb:
        found = first_impact(*intervals[-1])
    if found is None and closest:
        episodes.close(passes)  # (a pass still open at the end of what was swept)
        return min(passes, key=lambda event: event.gap_m, default=None)
    return found


def _shaken_points(stream: Stream, sigma: float, rng: 'np.random.Generator') -> Stream:
    copy = excerpt(stream, 0, len(stream.times) - 1)
    points = np.asarray(stream.values, dtype=float)
    copy.values = [tuple(p) for p in (points + rng.normal(0.0, sigma, points.shape)).tolist()]
    return copy


def _shaken_bat(stream: Stream, sigma: float, offsets: Tuple[Vector, Vector],
                rng: 'np.random.Generator') -> Stream:
    copy = excerpt(stream, 0, len(stream.times) - 1)
    samples = stream.values
    if samples[0].quaternion is None:
        ends = np.array([s.knob + s.tip for s in samples], dtype=float)
        ends += rng.normal(0.0, sigma, ends.shape)
        copy.values = [BatSample(tuple(e[:3]), tuple(e[3:])) for e in ends.tolist()]
        return copy
    positions = np.array([s.position for s in samples], dtype=float)
    positions += rng.normal(0.0, sigma, positions.shape)
    turn = rng.normal(0.0, sigma / MARKER_SPREAD_M, positions.shape)
    angles = np.linalg.norm(turn, axis=1)
    axes = turn / np.maximum(angles, 1e-300)[:, None]
    shakes = np.array([axis_angle_quaternions(a, np.array([angle]))[0]
                       for a, angle in zip(axes, angles)])
    quaternions = quaternion_multiply(shakes, np.array([s.quaternion for s in samples]))
    quaternions /= np.linalg.norm(quaternions, axis=1)[:, None]
    values = []
    for position, quaternion in zip(positions.tolist(), quaternions.tolist()):
        position, quaternion = tuple(position), tuple(quaternion)
        values.append(BatSample(pose_point(position, quaternion, offsets[0]),
                                pose_point(position, quaternion, offsets[1]),
                                position, quaternion))
    copy.values = values
    return copy


def _quantities(impact: Impact) -> Tuple[float, float, float]:
    return impact.stamp_ns * 1e-9, impact.distance_from_knob_m, impact.sweet_spot_speed_mps


def difference(config: DetectorConfig, other: DetectorConfig, clock: Clock, ball: Stream,
               bat: Stream, offsets: Tuple[Vector, Vector], impact: Impact, ta: float,
               tb: float) -> Uncertainty:
    """
    Return how far the impact solved under ``other`` is from ``impact`` (s, m, m/s).

    ``other``'s velocities are its least-squares fits' (``Sweep.quintic_rates`` False): from
    exact samples at a high rate both would otherwise share the quintic's bat rates, and their
    difference would say nothing of its error.

    Where ``other`` finds no impact (a tick it sees pass just clear), the time and spot of its
    closest approach stand in for its impact's, with the coarse speed bound; where it does not
    see the ball come within the near-miss threshold either, the coarse bounds (the module
    docstring).
    """
    found = resolve(other, clock, excerpt(ball, 0, len(ball.times) - 1),
                    excerpt(bat, 0, len(bat.times) - 1), offsets, ta, tb, closest=True,
                    quintic_rates=False)
    if found is None:
        return tb - ta, config.ball_radius, 0.1 * impact.sweet_spot_speed_mps
    if found.__class__ is NearMiss:
        length = math.dist(impact.knob, impact.tip)
        return (abs(found.stamp_ns - impact.stamp_ns) * 1e-9,
                abs(found.bat_fraction * length - impact.distance_from_knob_m),
                0.1 * impact.sweet_spot_speed_mps)
    return (abs(found.stamp_ns - impact.stamp_ns) * 1e-9,
            abs(found.distance_from_knob_m - impact.distance_from_knob_m),
            abs(found.sweet_spot_speed_mps - impact.sweet_spot_speed_mps))


def braked(config: DetectorConfig, clock: Clock, ball: Stream, bat: Stream,
           offsets: Tuple[Vector, Vector], impact: Impact, ta: float,
           tb: float) -> Tuple[float, float]:
    """
    Return how far the impact is from the farther of ``c2``'s two answers at a hit (s, m).

    The union interval [ta, tb] (s) re-solved under ``c2`` (the configuration's look-ahead and
    noise) with the bat through its closing frame, and with the bat continued from before the
    interval (``Sweep.bat_ahead`` False, True): the largest distance in time (s) and in the
    spot (m along the bat from the knob). An answer that finds no impact is left out; 0 when
    neither does.
    """
    c2 = config.variant(model='c2')
    found = [other for other in (
        resolve(c2, clock, excerpt(ball, 0, len(ball.times) - 1),
                excerpt(bat, 0, len(bat.times) - 1), offsets, ta, tb, ahead)
        for ahead in (False, True)) if other is not None]
    return (max((abs(other.stamp_ns - impact.stamp_ns) * 1e-9 for other in found), default=0.0),
            max((abs(other.distance_from_knob_m - impact.distance_from_knob_m)
                 for other in found), default=0.0))


def propagated(config: DetectorConfig, clock: Clock, ball: Stream, bat: Stream,
               impact: Impact) -> Uncertainty:
    """
    Return the 1-sigma errors (s, m, m/s) the tracking noise and the fits make, propagated.

    The ``c2`` paths are linear in their window's samples (``fitting.point_gains``,
    ``bat_gains``), so the noise gives each path's position and rate at the impact a known
    spread; it moves the gap along the contact normal (the time: that over the closing speed),
    the contact along the bat (the spot: plus the time's share of the sliding along it), and
    the sweet spot's velocity along itself (the speed; from the windows the velocities come
    from: ``kinematics.velocity_interval``; in quadrature the time's share, its sigma times the
    rate the speed changes at on those windows' path, which is most of an exact bat's beside a
    noisy ball; where they are extrapolated over up to a step, the larger of that and the
    extrapolation's own error estimate: the difference from the interval's own fits, which
    reach its closing frame).

    The gap also holds the fits' own error, which no noise shows (a smoother's bias on an
    accelerating swing, a parabola's on a ball whose drag changes): how far each fit moves the
    gap from the next richer fit of the same samples (``fitting.bat_shifts``, ``point_shifts``:
    the smoothed window from its interpolant, the quintic's where the window takes one; the
    ball's flight fit from one of a degree more), its square less what the noise alone gives
    that move (the square of a move is the squared bias plus that variance on average), when
    positive, in quadrature.
    """
    ta = clock.time(impact.interval_start_ns)
    t = clock.time(impact.stamp_ns)
    ball_sigma, bat_sigma = stream_noise(ball, config), stream_noise(bat, config)
    size, gap = config.spline_window, config.max_gap
    kb = ball.interval(ta)
    ball_window = c2_window(ball, kb, gap, config.look_ahead, size)
    ball_value, _ = point_gains(ball, ball_window, kb, t, ball_sigma, config)
    ball_error = ball_sigma * ball_value
    ball_shift, ball_spread = point_shifts(ball, ball_window, kb, t, ball_sigma, config)
    k = bat.interval(ta)
    bat_window = c2_window(bat, k, gap, config.look_ahead, size)
    ((knob, turn, length), _, correlation), (bat_shift, spreads, shift_correlation) = \
        bat_errors(bat, bat_window, k, t, bat_sigma)
    j = velocity_interval(bat, k, gap)  # the velocities' windows: samples before the impact
    _, (knob_rate, turn_rate, _), _ = bat_gains(bat, c2_window(bat, j, gap, 0, size), j, t,
                                                bat_sigma)
    normal = impact.normal  # (3-vectors as tuples: ``geometry``'s helpers, no numpy)
    bat_length = math.dist(impact.tip, impact.knob)
    axis = scale(sub(impact.tip, impact.knob), 1.0 / bat_length)
    reach = impact.bat_fraction * bat_length
    geometry = _GapGeometry(bat.values[k], normal, axis, reach, impact.bat_fraction)
    gap_variance = geometry.variance(ball_error, knob, turn, length, correlation)
    contact_shift = add(add(tuple(bat_shift[:3]),
                            scale(cross(tuple(bat_shift[3:6]), axis), reach)),
                        scale(axis, impact.bat_fraction * float(bat_shift[6])))
    gap_shift = dot(tuple(ball_shift), normal) - dot(contact_shift, normal)
    bias = gap_shift ** 2 - geometry.variance(ball_spread, *spreads, shift_correlation)
    gap_spread = math.sqrt(gap_variance + max(0.0, bias))
    closing = abs(impact.relative_normal_speed_mps)
    time_sigma = gap_spread / closing if closing > 0.0 else clock.time(
        impact.interval_end_ns) - ta
    arm = cross(axis, sub(impact.ball_position, impact.knob))
    sliding = dot(sub(impact.ball_velocity, impact.bat_velocity), axis)
    spot_sigma = math.sqrt(ball_error ** 2 + knob ** 2 + turn ** 2 * dot(arm, arm)
                           + (time_sigma * sliding) ** 2)
    velocity = impact.sweet_spot_velocity
    speed = norm(velocity)
    turned = 1.0  # (the share of the speed across the bat: all of it without a direction)
    if speed > 0.0:
        turning = cross(axis, scale(velocity, 1.0 / speed))
        turned = dot(turning, turning)
    lever = max(0.0, bat_length - config.sweet_spot_from_tip)
    speed_sigma = math.sqrt(knob_rate ** 2 + (lever * turn_rate) ** 2 * turned)
    before = c2_bat_path(bat, j, c2_window(bat, j, gap, 0, size), bat_sigma)
    late, early = (norm(_sweet_velocity(before, lever, t + d)) for d in (SLOPE_STEP_S,
                                                                         -SLOPE_STEP_S))
    speed_sigma = math.hypot(speed_sigma, time_sigma * (late - early) / (2.0 * SLOPE_STEP_S))
    if j != k:  # the extrapolation over up to a step: its own error estimate, the difference
        path = c2_bat_path(bat, k, c2_window(bat, k, gap, 0, size), bat_sigma)  # from the
        interpolated = _sweet_velocity(path, lever, t)  # interval's own fits
        speed_sigma = max(speed_sigma, abs(norm(interpolated) - speed))
    return time_sigma, spot_sigma, speed_sigma


def _sweet_velocity(path: C2BatPath, lever: float, t: float) -> Vector:
    """Return the velocity (m/s) at t (s) of a bat path's axis point ``lever`` m from its knob."""
    knob_at, tip_at = path.at(t)
    sweet = advance(knob_at, sub(tip_at, knob_at), lever / math.dist(tip_at, knob_at))
    return add(path.knob.velocity(t), cross(swing_rate(path, t), sub(sweet, knob_at)))


@dataclass(frozen=True)
class _GapGeometry:
    """
    How errors at a contact reach the gap along its normal (``propagated``).

    From knob and tip points the direction's noise is the two markers' difference across the
    bat over its length, so a knob marker's noise moves the knob and turns the bat the other
    way: the contact point (1 - f) knob + f tip across the bat, not knob + f (tip - knob) with
    the two apart. Their covariance along the normal, -f sigma^2 (a_knob . a_direction)
    |side|^2, is -sqrt(2) rho knob (reach turn) |side|^2 (turn = sqrt(2) sigma |a| / length,
    rho the rows' correlation). A pose's position and orientation noise are apart, but the
    orientation's moves the knob too, by its offset o from the pose's origin (the sample's,
    its part along the bat turned onto the impact's axis): along the normal by |a_knob|
    (sigma / MARKER_SPREAD_M) |o x normal|, sharing the direction's rows (rho): the contact
    point then moves as if it were o + reach along the bat from the origin.

    :ivar sample: the bat's sample opening the impact's interval.
    :ivar normal, axis: the contact normal and the bat's unit axis; ``reach``: the contact's
        distance from the knob (m), ``fraction`` along the bat.
    """

    sample: BatSample
    normal: Vector
    axis: Vector
    reach: float
    fraction: float

    def variance(self, ball: float, knob: float, turn: float, length: float,
                 correlation: float) -> float:
        """
        Return the gap's variance along the normal (m^2) from the errors' 1-sigma spreads.

        :param ball: the ball's, per coordinate (m); ``knob`` (m), ``turn`` (the direction's
            across the bat, rad), ``length`` (m): the bat's (``fitting.bat_gains``' values);
            ``correlation``: of the knob's rows and the direction's.
        """
        normal, axis, reach, pose = self.normal, self.axis, self.reach, self.sample
        side = cross(axis, normal)
        across = dot(side, side)
        if pose.quaternion is None:
            shared = -math.sqrt(2.0) * correlation * knob * reach * turn * across
        else:
            offset, pose_axis = sub(pose.knob, pose.position), unit_axis(pose)
            along = dot(offset, pose_axis)
            moved = cross(add(sub(offset, scale(pose_axis, along)), scale(axis, along)), normal)
            spin = knob / MARKER_SPREAD_M
            shared = (spin * spin * dot(moved, moved)
                      + 2.0 * correlation * spin * reach * turn * dot(moved, side))
        return max(0.0, ball ** 2 + knob ** 2 + (reach * turn) ** 2 * across + shared
                   + (self.fraction * length * dot(axis, normal)) ** 2)


def before_rule_speed(config: DetectorConfig, clock: Clock, ball: Stream, bat: Stream,
                      offsets: Tuple[Vector, Vector], impact: Impact) -> float:
    """
    Return the sweet-spot speed (m/s) at an impact by ``c2``'s window fits before it.

    ``kinematics.c2_velocities``' 'before' rule (``c2``'s rule under noise) at the impact's
    time, with the impact's knob and tip, whatever the model: a second estimate from the same
    samples before the impact as the least-squares fits that give the speed of ``rigid`` and
    ``spline``, and of ``c2`` with exact samples at a low rate.
    """
    t = clock.time(impact.stamp_ns)
    ta = clock.time(impact.interval_start_ns)
    config = config.variant(model='c2')
    stats = DetectorStats()
    sweep = Sweep(config, clock, stats, ball, bat, EpisodeTracker(config, clock, stats), offsets)
    velocities = c2_velocities(ball, bat, t, *sweep.paths(ball.interval(ta), bat.interval(ta)),
                               config, 'before')
    omega, pivot, sweet_point = rigid_bat(velocities, impact.knob, impact.tip,
                                          config.sweet_spot_from_tip)
    return norm(rigid_point_velocity(velocities.pivot, omega, pivot, sweet_point))


@dataclass(frozen=True)
class PendingUncertainty:
    """
    An impact whose uncertainties are yet to be measured, with what they are measured from.

    Taken when the impact is found (``uncertainty_basis``): the configuration, the clock's origin
    and the bat's offsets then in force, and copies of the samples the re-solves can need (none
    newer than what the sweep held), so ``measure`` gives the same uncertainties to the bit
    whenever it runs, whatever the detector took or cleared since (``Detector`` with
    ``deferred_uncertainty``: the node publishes the impact first).

    :ivar impact: the impact as found, its uncertainties zero.
    :ivar ta, tb: its union interval (s, on ``clock``).
    :ivar hit: the ball left its free flight over the interval (``departure``).
    :ivar spread: how far (s) the other answer of the rule that found it lies
        (``Sweep.time_spread``), half of which the time's uncertainty holds in quadrature.
    """

    impact: Impact
    config: DetectorConfig
    clock: Clock
    offsets: Tuple[Vector, Vector]
    ball: Stream
    bat: Stream
    ta: float
    tb: float
    hit: bool
    spread: float = 0.0

    def measure(self) -> Impact:
        """Return the impact with its 1-sigma uncertainties (the module docstring)."""
        return _measured(self)


def uncertainty_basis(config: DetectorConfig, clock: Clock, ball: Stream, bat: Stream,
                      offsets: Tuple[Vector, Vector], impact: Impact,
                      spread: float = 0.0) -> PendingUncertainty:
    """
    Return what an impact's uncertainties are measured from, taken now (``PendingUncertainty``).

    :param config, clock, ball, bat, offsets: the detector's, as they are when it found it.
    :param spread: how far (s) the other answer of the rule that found it lies.
    """
    ta, tb = clock.time(impact.interval_start_ns), clock.time(impact.interval_end_ns)
    hit = leaves_flight(ball, ball.interval(ta), judging_noise(config),
                        config.max_gap) is not None
    # nothing newer than what either stream surely held when the interval was swept: its
    # sample ``samples_ahead`` past the interval's closing one (the newest at the recording's
    # end), whatever the order the samples arrived in (the node's) or were read in (``analyze``)
    upto = min(_held(ball, tb, config), _held(bat, tb, config))
    intervals = union_intervals(ball, bat, ta, tb, upto)
    start, end = intervals[0][0], intervals[-1][1]
    ball_first, ball_last = _span(ball, start, end, config, upto, tb)
    bat_first, bat_last = _span(bat, start, end, config, upto, tb)
    origin = Clock()
    origin.origin = clock.origin
    return PendingUncertainty(impact, config, origin, offsets,
                              excerpt(ball, ball_first, ball_last),
                              excerpt(bat, bat_first, bat_last), ta, tb, hit, spread)


def impact_uncertainty(config: DetectorConfig, clock: Clock, ball: Stream, bat: Stream,
                       offsets: Tuple[Vector, Vector], impact: Impact) -> Impact:
    """
    Return the impact with its 1-sigma uncertainties (see the module docstring).

    :param config, clock, ball, bat, offsets: the detector's, as they were when it found it.
    """
    return uncertainty_basis(config, clock, ball, bat, offsets, impact).measure()


def carried_far(bat: Stream, t: float) -> bool:
    """
    Return whether an impact at t (s) is more than ``CARRY_STEPS`` typical steps past the bat.

    The typical step: the median of the bat's last eight steps up to its last sample at or
    before t (none: False).
    """
    k = bisect_right(bat.times, t) - 1
    if k < 1:
        return False
    times = bat.times[max(0, k - 8):k + 1]
    steps = sorted(b - a for a, b in zip(times[:-1], times[1:]))
    return t - bat.times[k] > CARRY_STEPS * steps[len(steps) // 2]


def _measured(pending: PendingUncertainty) -> Impact:
    """Return ``pending``'s impact with its 1-sigma uncertainties (re-solved from its copies)."""
    config, clock, ball, bat, offsets = (pending.config, pending.clock, pending.ball,
                                         pending.bat, pending.offsets)
    impact, ta, tb = pending.impact, pending.ta, pending.tb
    c2_answers = pending.hit  # at a hit: the bat's brake (the module docstring)
    ball_sigma, bat_sigma = stream_noise(ball, config), stream_noise(bat, config)
    uncertainty: Optional[Uncertainty] = None
    if (ball_sigma > 0.0 or bat_sigma > 0.0) and config.model == 'c2':
        uncertainty = propagated(config, clock, ball, bat, impact)
        if config.look_ahead:
            bent = difference(config, config.variant(look_ahead=0), clock, ball, bat, offsets,
                              impact, ta, tb)
            uncertainty = tuple(math.hypot(x, y) for x, y in zip(uncertainty, bent))
    elif ball_sigma > 0.0 or bat_sigma > 0.0:
        c2_answers = True  # the perturbed fits' own error too (the module docstring)
        rng = np.random.default_rng(seed_for(impact))
        found = []
        for _ in range(PERTURBATIONS):
            shaken = resolve(config, clock, _shaken_points(ball, ball_sigma, rng),
                             _shaken_bat(bat, bat_sigma, offsets, rng), offsets, ta, tb)
            if shaken is not None:
                found.append(_quantities(shaken))
        if len(found) >= 2:
            spread = tuple(float(x) for x in np.std(np.array(found), axis=0, ddof=1))
            other = before_rule_speed(config, clock, ball, bat, offsets, impact)
            uncertainty = (spread[0], spread[1],
                           math.hypot(spread[2], other - impact.sweet_spot_speed_mps))
    if uncertainty is None:
        uncertainty = difference(config, config.variant(model=ALTERNATIVE[config.model]),
                                 clock, ball, bat, offsets, impact, ta, tb)
        if config.model != 'c2' or spline_window_for(bat, clock.time(impact.stamp_ns),
                                                     config) == 0:
            other = before_rule_speed(config, clock, ball, bat, offsets, impact)
            uncertainty = (uncertainty[0], uncertainty[1], max(
                uncertainty[2], abs(other - impact.sweet_spot_speed_mps)))
        if config.velocity_degree > CARRY_DEGREE and carried_far(bat, clock.time(
                impact.stamp_ns)):
            quadratic = difference(config, config.variant(velocity_degree=CARRY_DEGREE),
                                   clock, ball, bat, offsets, impact, ta, tb)
            uncertainty = (uncertainty[0], uncertainty[1], max(uncertainty[2], quadratic[2]))
    if c2_answers:  # the distance from c2's two answers
        brake = braked(config, clock, ball, bat, offsets, impact, ta, tb)
        uncertainty = (math.hypot(uncertainty[0], brake[0]),
                       math.hypot(uncertainty[1], brake[1]), uncertainty[2])
    if not all(math.isfinite(x) for x in uncertainty):
        uncertainty = (tb - ta, config.ball_radius, 0.1 * impact.sweet_spot_speed_mps)
    if pending.spread:
        uncertainty = (math.hypot(uncertainty[0], 0.5 * pending.spread),) + uncertainty[1:]
    return replace(impact, time_uncertainty_s=uncertainty[0],
                   distance_from_knob_uncertainty_m=uncertainty[1],
                   sweet_spot_speed_uncertainty_mps=uncertainty[2])
