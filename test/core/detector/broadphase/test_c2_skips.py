"""c2's scalar far test skips bulge bounds that cannot clear an interval: the same answers."""

import math

from baseball_collision.core.detector import Detector, DetectorConfig
from baseball_collision.core.detector.broadphase import (
    apart_margins, c2_bat_growth, c2_bulge, c2_jump_bulge, c2_reach, C2_STEP_RATIO,
    clearly_apart, hull_separation)
from baseball_collision.core.detector.broadphase.scalar import NOISE_REACH
from baseball_collision.core.detector.fitting import c2_window
import numpy as np
from support.far import tilting_bat
from support.scenes import BASE_NS

MARGIN = 0.11
"""m: a margin like the detector's (ball radius, bat radius, near-miss threshold)."""


def _every_bound(ball, bat, k: int, look_ahead: int, size: int, noise: float = 0.0) -> str:
    """
    Return the far test's answer with every bound computed (the test before the skips).

    'first' or 'second': clear by that stage (the second by the spheres or by the hulls, the
    hulls' bound less ``NOISE_REACH`` times the noise); 'near': not clear.
    """
    b0, b1 = ball.values[k], ball.values[k + 1]
    s0, s1 = bat.values[k], bat.values[k + 1]
    k0, e0, k1, e1 = s0.knob, s0.tip, s1.knob, s1.tip
    ball_centre = ((b0[0] + b1[0]) * 0.5, (b0[1] + b1[1]) * 0.5, (b0[2] + b1[2]) * 0.5)
    ball_radius = 0.5 * math.dist(b0, b1)
    bat_centre = ((k0[0] + e0[0] + k1[0] + e1[0]) * 0.25, (k0[1] + e0[1] + k1[1] + e1[1]) * 0.25,
                  (k0[2] + e0[2] + k1[2] + e1[2]) * 0.25)
    bat_radius = max(math.dist(p, bat_centre) for p in (k0, e0, k1, e1))
    quick = c2_jump_bulge(ball, k, look_ahead, size, 0.05)
    reach = None if quick is None else c2_reach(bat, k, look_ahead, size, 0.05)
    if reach is not None and (math.dist(ball_centre, reach[0]) - ball_radius - quick
                              - reach[1] > MARGIN):
        return 'first'
    window = c2_window(ball, k, 0.05, look_ahead, size)
    times = ball.times[window.start:window.stop]
    steps = [b - a for a, b in zip(times, times[1:])]
    if max(steps) > C2_STEP_RATIO * min(steps):
        return 'near'
    bulge = c2_bulge(times, ball.values[window.start:window.stop], k - window.start)
    growth = c2_bat_growth(bat, k, c2_window(bat, k, 0.05, look_ahead, size))
    if growth is None:
        return 'near'
    hull = hull_separation(b0, b1, k0, e0, k1, e1) - NOISE_REACH * noise
    clear = (math.dist(ball_centre, bat_centre) - (ball_radius + bulge) - (bat_radius + growth)
             > MARGIN or hull - bulge - growth > MARGIN)
    return 'second' if clear else 'near'


def test_the_skips_change_no_answer() -> None:
    """Balls passing a swing at every distance: the far test answers as with every bound."""
    rng = np.random.default_rng(3)
    answers = []
    for scene in range(60):
        look_ahead, size = scene % 3, 4 + scene % 9
        detector = Detector(DetectorConfig(model='c2', bat_input='points', max_speed=1e5,
                                           look_ahead=look_ahead, spline_window=size,
                                           bat_length_tolerance=1.0))
        miss = rng.uniform(0.0, 1.5)  # m: the ball's offset from the swing's plane
        spin, tilt = rng.uniform(-60.0, 60.0), rng.uniform(-3.0, 3.0)
        times = np.cumsum(rng.uniform(0.0027, 0.0029, 40))
        for t in times:
            stamp = BASE_NS + int(round(t * 1e9))
            knob, tip = tilting_bat(t, spin, tilt, rng, 0.0005 * (scene % 2))
            for role, value in (('knob', knob), ('tip', tip)):
                getattr(detector, f'add_{role}')(stamp, tuple(value))
            detector.add_ball(stamp, (1.5 - 30.0 * (t - times[0]), 0.3, 1.0 + miss))
        ball, bat = detector._ball, detector._bat
        for k in range(len(bat.times) - 1 - look_ahead):
            expected = _every_bound(ball, bat, k, look_ahead, size)
            assert clearly_apart(ball, bat, k, k, MARGIN, 'c2', 0.05, look_ahead,
                                 size) is (expected != 'near')
            answers.append(expected)
    assert set(answers) == {'first', 'second', 'near'}  # (about 1,500, 500 and 250)


def _held_bat_and_ball(across: float):
    """Return the streams of a held bat (along x) and a ball beside its middle, ``across`` off."""
    detector = Detector(DetectorConfig(model='c2', bat_input='points', max_speed=1e5))
    for i in range(12):
        t = 0.0028 * i
        stamp = BASE_NS + int(round(t * 1e9))
        detector.add_knob(stamp, (0.0, 1e-4 * t, 1.0))
        detector.add_tip(stamp, (0.86, 1e-4 * t, 1.0))
        detector.add_ball(stamp, (0.43 + 0.5 * t, across, 1.0))
    return detector._ball, detector._bat


def test_the_second_stage_at_its_edge() -> None:
    """
    A held bat, balls passing it 50 um apart across the spheres' margin: the same answers.

    Beside the bat's middle the bat's four ends' sphere is 0.43 m, the ball's 1.4 mm; the hulls
    would clear every one, so they are left out (under unbounded noise they bound nothing).
    """
    answers = []
    for offset in np.linspace(-2e-3, 2e-3, 81):  # 50 um apart
        ball, bat = _held_bat_and_ball(0.43 + MARGIN + 0.0014 + offset)
        k = len(bat.times) - 3
        expected = _every_bound(ball, bat, k, 0, 8, math.inf)
        assert clearly_apart(ball, bat, k, k, MARGIN, 'c2', 0.05, 0, 8,
                             math.inf) is (expected != 'near')
        answers.append(expected)
    assert set(answers) == {'second', 'near'}


def test_the_hulls_clear_a_ball_beside_the_bat_at_their_edge() -> None:
    """
    Balls beside a held bat's middle, 50 um apart across the margin: the hulls clear them.

    Inside the bat's four ends' sphere, the hulls clear the balls beyond the margin (and
    ``NOISE_REACH`` times the noise), and not those within it.
    """
    for noise in (0.0, 0.001):
        answers = []
        edge = MARGIN + NOISE_REACH * noise
        for offset in np.linspace(-2e-3, 2e-3, 81):
            ball, bat = _held_bat_and_ball(edge + offset)
            k = len(bat.times) - 3
            expected = _every_bound(ball, bat, k, 0, 8, noise)
            assert clearly_apart(ball, bat, k, k, MARGIN, 'c2', 0.05, 0, 8,
                                 noise) is (expected != 'near')
            if abs(offset) > 5e-4:  # (the ball's own chord and the bat's drift aside)
                assert expected == ('second' if offset > 0.0 else 'near'), (noise, offset)
            answers.append(expected)
        assert set(answers) == {'second', 'near'}


def test_the_arrays_hulls_clear_what_the_scalar_hulls_clear() -> None:
    """
    ``apart_margins``' ``c2`` clearance takes the hulls too, less ``hull_reach``: as the sweep's.

    The balls beside a held bat's middle: with ``hull_reach`` (``NOISE_REACH`` times the
    noise) the arrays clear those the scalar test clears, to 10 um of its edge; without it
    (None: no hulls) they clear none, the bat's sphere holding them all.
    """
    for noise in (0.0, 0.001):
        edge = MARGIN + NOISE_REACH * noise
        for offset in np.linspace(-2e-3, 2e-3, 41):
            ball, bat = _held_bat_and_ball(edge + offset)
            k = len(bat.times) - 3
            scalar = clearly_apart(ball, bat, k, k, MARGIN, 'c2', 0.05, 0, 8, noise)
            arrays = (np.array(ball.values), np.array([s.knob for s in bat.values]),
                      np.array([s.tip for s in bat.values]))
            none, at = np.array([-1]), np.array([k])
            times = (np.array(ball.times), np.array(bat.times))

            def clearance(hull_reach):
                return float(apart_margins(*arrays, None, at, at, none, none, none, none,
                                           *times, 'c2', 0, 8, MARGIN, None, hull_reach)[0])
            with_hulls = clearance(np.array([NOISE_REACH * noise]))
            assert not clearance(None) > MARGIN
            if abs(with_hulls - MARGIN) > 1e-5:
                assert (with_hulls > MARGIN) is scalar, (noise, offset)
            if abs(offset) > 5e-4:
                assert scalar is bool(offset > 0.0)
