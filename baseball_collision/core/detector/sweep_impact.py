"""
A hit, reported: the bat's path at it and the ``Impact`` event its solved contact makes.

A part of ``sweep.Sweep`` (its base, reading the sweep's streams, configuration, clock and
counters). At a hit (the ball left its flight over the interval: ``departure.leaves_flight``)
the bat's closing frame is after the contact, which brakes a real bat: the bat may be continued
from before the interval instead (``_bat_ahead``, ``fitting.c2_bat_ahead``). A solved contact
(time in s, point and normal in m) becomes an ``Impact`` (``_report``, ``_impact``): its stamp
(ns), where on the bat (m from knob and tip), and how both bodies moved (m/s, rad/s, the attack
angle in degrees: ``kinematics``), told to ``on_contact`` first and measured (``measure``)
before it is appended.
"""

from dataclasses import replace
import math
from typing import List, Optional, Sequence, Tuple

from .departure import DEPARTURE_FLOOR, judging_noise, leaves_flight
from .events import Impact
from .fitting import c2_bat_ahead, stream_noise
from .kinematics import c2_velocities, fit_velocities, quintic_check, rigid_bat, SPARSE_SAMPLES
from ..geometry import dot, norm, rigid_point_velocity, Vector
from ..motion import BatSample, Paths
from ..motion.bat_paths import Ends
from ..toi import ImpactResult

BAT_DEPARTURE_RATIO = 4.0
"""How many times the continuation's own miss at the frame before a hit's closing bat frame must
be off its free swing for the sweep to take the continuation (``braked_miss``,
``SweepImpact._bat_ahead``)."""


def braked_miss(times: Sequence[float], frames: Tuple[BatSample, BatSample],
                missed: Ends, continued: Ends) -> Tuple[float, float]:
    """
    Return how far (m) a hit's closing bat frame is off its free swing, and the scale of that.

    The bat's own departure at a hit (``SweepImpact._bat_ahead``): the opening and closing
    ``frames`` (knob, tip), ``times`` (s) the stamps of the frame before the opening one, the
    opening and the closing frame; ``missed``: the knob and tip (m) continued from the window
    before the opening frame, at its stamp; ``continued``: those continued from the window up to
    the opening frame, at the closing stamp. The continuation's own miss at the opening frame
    (the scale, the larger of knob and tip) carries over to the next frame: a swing extrapolated
    a step from the same kind of window misses its next frame the same way (exact samples; at
    90 Hz 1-5 mm, the accelerating swing's tip mostly ahead of its continuation), so it is taken
    off the closing frame's miss, scaled as an error of the continued acceleration by the
    squared ratio of the steps. What is left is the brake's: a real bat loses speed within 1-3
    ms of the contact, so its closing frame lags its free swing. At 90 Hz the continuation is
    now taken at hits whose closing frame's whole miss was under ``BAT_DEPARTURE_RATIO`` times
    the own miss but what is left is over it (exact rebound hits: time p99 93 -> 59 us). On free
    swings, where nothing braked, what is left is at most 3.8 times the own miss at 90 Hz, 1.9
    at 120 and 2.6 at 360 Hz (the whole miss: 3.6, 2.9 and 4.4 times; BENCHMARKS.md, "The brake
    against the continuation's own miss carried over", session 61).
    """
    scale = ((times[2] - times[1]) / (times[1] - times[0])) ** 2
    opening, closing = frames
    miss = scatter = 0.0
    for expected, ahead, seen, now in zip(missed, continued, (opening.knob, opening.tip),
                                          (closing.knob, closing.tip)):
        own = tuple(scale * (s - e) for s, e in zip(seen, expected))  # carried to the closing
        miss = max(miss, math.dist(tuple(a + o for a, o in zip(ahead, own)), now))
        scatter = max(scatter, math.dist(expected, seen))
    return miss, scatter


class SweepImpact:
    """A hit's bat path and its ``Impact`` event: a base of ``sweep.Sweep`` (see there)."""

    __slots__ = ()

    def _report(self, t: float, hit: ImpactResult, interval: Tuple[float, float], paths: Paths,
                events: List, spread: float = 0.0, ball_velocity: Optional[Vector] = None) -> None:
        """
        Append the impact at t (s) solved on ``paths`` over the union ``interval``.

        ``spread``: how far (s) another answer of the rule that found it lies
        (``time_spread``, read by ``measure``); ``ball_velocity``: the ball's (m/s) as that
        rule found it, in place of the fits' (``kinematics``).
        """
        self.impact_t = t
        if self.on_contact is not None:  # before the velocities' fits
            self.on_contact(self.clock.stamp(t), tuple(hit.point))
        impact = self._impact(t, hit, interval, paths)
        if ball_velocity is not None:
            closing = dot(tuple(b - v for b, v in zip(impact.bat_velocity, ball_velocity)),
                          impact.normal)
            impact = replace(impact, ball_velocity=ball_velocity, ball_speed_mps=norm(
                ball_velocity), relative_normal_speed_mps=closing)
        self.time_spread = spread
        events.append(impact if self.measure is None else self.measure(impact))
        self.time_spread = 0.0
        self.stats.impacts += 1

    def _bat_ahead(self, interval: Tuple[float, float], paths: Paths,
                   hit: bool = False) -> Optional[Paths]:
        """
        Return the paths with the bat continued from before the interval at a hit, or None.

        Where the ball has left its flight over the interval (``departure``: a hit),
        the bat's closing frame is after the contact, which slows a real bat within 1-3 ms: its
        path through that frame is late, under every model. With exact bat samples the bat's path
        continued from ``c2``'s window up to the opening frame (``fitting.c2_bat_ahead``) is the
        better one there (BENCHMARKS.md, "A ball that leaves the bat"; for every model, as the
        ball's free flight is: "A hit's bat continued under every model"), where the closing frame
        has left that continuation, less the continuation's own miss at the opening frame carried
        over (``braked_miss``), by more than ``BAT_DEPARTURE_RATIO`` times that own miss (the
        samples follow their continuation closely: exact, not noisy; the bat braked). At a low
        rate (``SPARSE_SAMPLES`` or fewer in ``velocity_window``, the velocities'
        rule) only a quintic continuation (``splines.quintic_window``): a cubic's over a whole step
        is the larger error in the spot there (BENCHMARKS.md, "A hit's bat continued on the
        quintic"). At a higher rate only where the window up to the opening frame passes the
        velocities' quintic check (``kinematics.quintic_check``): a cubic continued from noisy
        samples the detector was not told of is worse than the frame that braked (BENCHMARKS.md, "A
        hit's bat continued only from samples that pass the quintic check"). None elsewhere.
        ``bat_ahead`` True takes the continuation at every hit (with noise: of the smoothed
        window), False never. ``hit``: the caller knows the ball was hit over the interval
        (``_hit_before_flight``: a segment's first sample, which has no flight before it).
        """
        ball, bat, config = self.ball, self.bat, self.config
        if self.bat_ahead is False or (
                self.bat_ahead is None and stream_noise(bat, config) > 0.0):
            return None
        ball_k, bat_k = ball.interval(interval[0]), bat.interval(interval[0])
        if not hit and leaves_flight(ball, ball_k, judging_noise(config), config.max_gap) is None:
            return None
        quintic = self.bat_ahead is None and len(bat.history(
            bat.times[bat_k], config.velocity_window)) <= SPARSE_SAMPLES
        if self.bat_ahead is None and not quintic:
            window = bat.history(bat.times[bat_k], 1.0)[-config.spline_window:]
            if quintic_check([bat.times[i] for i in window],
                             [bat.values[i] for i in window]) is False:
                return None  # noise the detector was not told of: its continuation is worse
        path = c2_bat_ahead(bat, bat_k, config.max_gap, config.spline_window,
                            stream_noise(bat, config), quintic)
        if path is None or self.bat_ahead:
            return None if path is None else (paths[0], path)
        before = c2_bat_ahead(bat, bat_k - 1, config.max_gap, config.spline_window,
                              quintic=quintic)
        if before is None:
            return None
        miss, scatter = braked_miss(bat.times[bat_k - 1:bat_k + 2],
                                    (bat.values[bat_k], bat.values[bat_k + 1]),
                                    before.at(before.t1), path.at(path.t1))
        if miss <= DEPARTURE_FLOOR or miss <= BAT_DEPARTURE_RATIO * scatter:
            return None
        return paths[0], path

    def _impact(self, t: float, hit: ImpactResult, interval: Tuple[float, float],
                paths: Paths) -> Impact:
        """Return the impact at t (s): where, and how both bodies moved (``kinematics``)."""
        ball_path, bat_path = paths
        knob, tip = bat_path.at(t)
        config = self.config
        if self.model == 'c2':
            velocities = c2_velocities(self.ball, self.bat, t, ball_path, bat_path, config)
        else:
            velocities = fit_velocities(self.ball, self.bat, t, ball_path, bat_path, config,
                                        self.quintic_rates)
        length = math.dist(knob, tip)
        omega, pivot, sweet_point = rigid_bat(velocities, knob, tip, config.sweet_spot_from_tip)
        # rigid body: every point moves with the pivot plus the turn about it
        sweet_velocity = rigid_point_velocity(velocities.pivot, omega, pivot, sweet_point)
        bat_velocity = rigid_point_velocity(velocities.pivot, omega, pivot, hit.point)
        sweet_speed = norm(sweet_velocity)
        attack = 0.0
        if sweet_speed > 0.0:
            rise = max(-1.0, min(1.0, dot(sweet_velocity, config.up_axis) / sweet_speed))
            attack = math.degrees(math.asin(rise))
        ball_velocity = velocities.ball
        closing = dot(tuple(b - v for b, v in zip(bat_velocity, ball_velocity)), hit.normal)
        stamp = self.clock.stamp
        return Impact(
            stamp_ns=stamp(t), point=tuple(hit.point), normal=tuple(hit.normal),
            bat_fraction=hit.bat_fraction, distance_from_knob_m=hit.bat_fraction * length,
            distance_from_tip_m=(1.0 - hit.bat_fraction) * length, feature=hit.feature,
            bat_velocity=bat_velocity, bat_angular_velocity=omega,
            sweet_spot_velocity=sweet_velocity, sweet_spot_speed_mps=sweet_speed,
            bat_speed_at_contact_mps=norm(bat_velocity), ball_velocity=ball_velocity,
            ball_speed_mps=norm(ball_velocity), relative_normal_speed_mps=closing,
            attack_angle_deg=attack, ball_position=ball_path.at(t), knob=knob, tip=tip,
            model=self.model, interval_start_ns=stamp(interval[0]),
            interval_end_ns=stamp(interval[1]), velocities_from_history=velocities.from_history,
            initially_overlapping=hit.initially_overlapping)
