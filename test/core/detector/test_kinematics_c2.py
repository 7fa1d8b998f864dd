"""Tests for the c2 model's impact velocities: the splines' rates from samples before t."""

import math

from baseball_collision.core.detector.kinematics import spline_velocities
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample
import numpy as np


def _streams(rate: float, spin: float, tilt: float):
    """Return ball and bat streams up to 0.1 s: the bat turning about a tilting axis."""
    ball, bat = Stream('ball'), Stream('bat')
    for i, t in enumerate(np.arange(0.0, 0.1, 1.0 / rate)):
        angle = spin * t
        knob = (2.0 * t, 0.0, 1.0 + t * t)
        direction = (math.cos(angle) * math.cos(tilt * t), math.sin(angle),
                     math.cos(angle) * math.sin(tilt * t))
        tip = tuple(k + 0.8 * d for k, d in zip(knob, direction))
        ball.append(t, i, (5.0 - 40.0 * t, 0.0, 1.0 - 4.9 * t * t), i == 0)
        bat.append(t, i, BatSample(knob, tip), i == 0)
    return ball, bat


def _tip_velocity(t: float, spin: float, tilt: float) -> np.ndarray:
    """Return the true tip velocity (m/s) by central differences of the closed form."""
    def tip(s: float) -> np.ndarray:
        angle = spin * s
        return np.array([2.0 * s + 0.8 * math.cos(angle) * math.cos(tilt * s),
                         0.8 * math.sin(angle), 1.0 + s * s + 0.8 * math.cos(angle)
                         * math.sin(tilt * s)])
    return (tip(t + 1e-6) - tip(t - 1e-6)) / 2e-6


def test_velocities_come_from_samples_before_t_and_converge() -> None:
    """At 360 Hz the ball's and the tip's velocity half a step after the last sample are close."""
    spin, tilt = 40.0, 2.0
    ball, bat = _streams(360.0, spin, tilt)
    t = bat.times[-1] + 0.5 / 360.0
    found = spline_velocities(ball, bat, t, 8)
    assert found is not None and found.from_history and found.pivot_fraction == 0.0
    assert np.allclose(found.ball, (-40.0, 0.0, -9.8 * t), atol=1e-6)
    knob_rate = np.array(found.pivot)
    assert np.allclose(knob_rate, (2.0, 0.0, 2.0 * t), atol=1e-4)
    # the tip: the knob's velocity plus the swing's turn of the 0.8 m axis (length constant)
    angle = spin * t
    direction = np.array([math.cos(angle) * math.cos(tilt * t), math.sin(angle),
                          math.cos(angle) * math.sin(tilt * t)])
    tip_rate = knob_rate + np.cross(found.swing, 0.8 * direction)
    truth = _tip_velocity(t, spin, tilt)
    assert np.linalg.norm(tip_rate - truth) < 1e-3 * np.linalg.norm(truth)


def test_too_few_samples_give_none() -> None:
    """One sample of the bat before t: no spline velocities (the chords stand in)."""
    ball, bat = Stream('ball'), Stream('bat')
    ball.append(0.0, 0, (0.0, 0.0, 0.0), True)
    bat.append(0.0, 0, BatSample((0.0, 0.0, 0.0), (0.8, 0.0, 0.0)), True)
    assert spline_velocities(ball, bat, 0.001, 8) is None
