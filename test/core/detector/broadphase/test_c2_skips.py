"""c2's scalar far test skips bulge bounds that cannot clear an interval: the same answers."""

import math

from baseball_collision.core.detector import Detector, DetectorConfig
from baseball_collision.core.detector.broadphase import (
    c2_bat_growth, c2_bulge, c2_jump_bulge, c2_reach, C2_STEP_RATIO, clearly_apart)
from baseball_collision.core.detector.fitting import c2_window
import numpy as np
from support.far import tilting_bat
from support.scenes import BASE_NS

MARGIN = 0.11
"""m: a margin like the detector's (ball radius, bat radius, near-miss threshold)."""


def _every_bound(ball, bat, k: int, look_ahead: int, size: int) -> str:
    """
    Return the far test's answer with every bound computed (the test before the skips).

    'first' or 'second': clear by that stage; 'near': not clear.
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
    ball_radius += c2_bulge(times, ball.values[window.start:window.stop], k - window.start)
    growth = c2_bat_growth(bat, k, c2_window(bat, k, 0.05, look_ahead, size))
    if growth is None:
        return 'near'
    clear = math.dist(ball_centre, bat_centre) - ball_radius - (bat_radius + growth) > MARGIN
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


def test_the_second_stage_at_its_edge() -> None:
    """A held bat, balls passing it 50 um apart across the margin: the same answers."""
    answers = []
    for offset in np.linspace(-2e-3, 2e-3, 81):  # 50 um apart
        detector = Detector(DetectorConfig(model='c2', bat_input='points', max_speed=1e5))
        for i in range(12):
            t = 0.0028 * i
            stamp = BASE_NS + int(round(t * 1e9))
            detector.add_knob(stamp, (0.0, 1e-4 * t, 1.0))
            detector.add_tip(stamp, (0.86, 1e-4 * t, 1.0))
            # beside the bat's middle: its four ends' sphere is 0.43 m, the ball's 1.4 mm
            detector.add_ball(stamp, (0.43 + 0.5 * t, 0.43 + MARGIN + 0.0014 + offset, 1.0))
        ball, bat = detector._ball, detector._bat
        k = len(bat.times) - 3
        expected = _every_bound(ball, bat, k, 0, 8)
        assert clearly_apart(ball, bat, k, k, MARGIN, 'c2', 0.05, 0, 8) is (expected != 'near')
        answers.append(expected)
    assert set(answers) == {'second', 'near'}
