"""Tests for baseball_collision.tools.sim pitches: drag, RK4 + Hermite, built backward."""

import math

from baseball_collision.errors import ToolError
from baseball_collision.tools.sim import BALL_RADIUS, GRAVITY, MPH, Pitch
import numpy as np
import pytest


def test_pitch_without_drag_is_the_parabola() -> None:
    """With drag off, RK4 + Hermite reproduce the closed form to round-off."""
    p0, v0 = np.array([0.3, 16.8, 1.8]), np.array([-0.5, -40.0, -1.0])
    pitch = Pitch(tuple(p0), tuple(v0), -0.3, duration=0.5, drag=False)
    t = np.random.default_rng(0).uniform(-0.3, 0.2, 500)
    s = (t + 0.3)[:, None]
    g = np.array([0.0, 0.0, -GRAVITY])
    assert np.abs(pitch.position(t) - (p0 + v0 * s + 0.5 * g * s * s)).max() < 1e-11
    assert np.abs(pitch.velocity(t) - (v0 + g * s)).max() < 1e-10
    assert pitch.position(-0.3) == pytest.approx(p0, abs=1e-15)
    assert pitch.position(0.1).shape == (3,)


def test_pitch_matches_a_finer_integration() -> None:
    """The default 1 ms step agrees with a 50 us integration to far below 1e-9 m."""
    args = ((0.3, 16.8, 1.8), (-0.5, -40.0, -1.0), -0.3)
    coarse = Pitch(*args, duration=0.5)
    fine = Pitch(*args, duration=0.5, step=5e-5)
    t = np.random.default_rng(1).uniform(-0.3, 0.2, 500)
    assert np.abs(coarse.position(t) - fine.position(t)).max() < 1e-10
    assert np.abs(coarse.velocity(t) - fine.velocity(t)).max() < 1e-7


def test_drag_slows_a_90_mph_pitch_by_8_to_10_percent_over_17_m() -> None:
    """A 90 mph pitch loses 8-10 % of its speed on the way to the plate; no drag, it gains."""
    for drag, low, high in ((True, 0.08, 0.10), (False, -0.01, 0.0)):
        pitch = Pitch((0.0, 17.0, 1.8), (0.0, -90.0 * MPH, 0.0), drag=drag, duration=0.6)
        t = np.linspace(0.0, 0.6, 60001)
        arrival = t[np.argmax(pitch.position(t)[:, 1] <= 0.0)]
        loss = 1.0 - np.linalg.norm(pitch.velocity(arrival)) / (90.0 * MPH)
        assert low <= loss <= high, (drag, loss)


def test_pitch_through_passes_the_given_state() -> None:
    """A pitch built backward from a state passes it at that instant, released near y=16.8."""
    position, velocity = np.array([0.1, 0.3, 0.8]), np.array([0.2, -37.0, -4.0])
    pitch = Pitch.through(position, velocity, 0.15, release_y=16.8, end_time=0.3)
    assert np.abs(pitch.position(0.15) - position).max() < 1e-11
    assert np.abs(pitch.velocity(0.15) - velocity).max() < 1e-9
    assert 16.8 <= pitch.release_position[1] < 16.9
    assert pitch.release_time < 0.0 and pitch.end_time >= 0.3


def test_pitch_refuses_bad_input() -> None:
    """Times outside the flight, non-finite states and balls flying away raise."""
    pitch = Pitch((0.0, 17.0, 1.8), (0.0, -40.0, 0.0), duration=0.5)
    with pytest.raises(ToolError):
        pitch.position(0.6)
    with pytest.raises(ToolError):
        pitch.velocity(-0.01)
    with pytest.raises(ToolError):
        Pitch((0.0, math.nan, 1.8), (0.0, -40.0, 0.0))
    with pytest.raises(ToolError):
        Pitch((0.0, 17.0, 1.8), (0.0, -40.0, 0.0), step=0.0)
    with pytest.raises(ToolError):
        Pitch.through((0.0, 0.0, 1.0), (0.0, 40.0, 0.0), 0.1)


def test_a_rebound_adds_its_change_smoothly_after_its_instant() -> None:
    """
    A pushed ball: unchanged before the push, the whole change after it, smooth in between.

    The velocity is the position's derivative (central differences) inside and around the
    push; the position gained by its end is half the change times its duration.
    """
    free = Pitch((0.0, 17.0, 1.8), (0.0, -40.0, 0.0), duration=0.6)
    change = (3.0, 70.0, -20.0)
    pushed = Pitch((0.0, 17.0, 1.8), (0.0, -40.0, 0.0), duration=0.6, rebound_time=0.4,
                   rebound_change=change, rebound_duration=6e-4)
    early = np.linspace(0.0, 0.4, 9)
    assert np.array_equal(pushed.position(early), free.position(early))
    after = np.array([0.4006, 0.45, 0.5])
    assert np.allclose(pushed.velocity(after) - free.velocity(after), change, atol=1e-12)
    assert np.allclose(pushed.position(0.4006) - free.position(0.4006),
                       0.5 * 6e-4 * np.array(change), atol=1e-12)
    step = 1e-7
    for t in (0.4, 0.4001, 0.4003, 0.4006, 0.401):
        slope = (pushed.position(t + step) - pushed.position(t - step)) / (2.0 * step)
        assert np.allclose(slope, pushed.velocity(t), atol=1e-5)
    with pytest.raises(ToolError):
        Pitch((0.0, 17.0, 1.8), (0.0, -40.0, 0.0), rebound_time=0.4, rebound_duration=0.0)


def test_a_spinning_pitch_feels_the_magnus_force() -> None:
    """
    Spin adds ``0.5 rho A C_L |v|^2`` along ``omega_hat x v_hat`` (Nathan's C_L), nothing else.

    The acceleration (velocity differenced over 2 ms) less gravity and drag against that force
    computed here; 2,300 rpm of backspin at 40 m/s lifts 5.5-7 m/s^2, the same topspin drops
    as much, gyro spin (along the flight) next to nothing, and a finer step agrees.
    """
    rpm = 2.0 * math.pi / 60.0
    start = ((0.0, 17.0, 1.8), (0.0, -40.0, 0.0))
    plain = Pitch(*start, duration=0.5)
    for spin, low, high in (((-2300 * rpm, 0.0, 0.0), 5.5, 7.0),
                            ((2300 * rpm, 0.0, 0.0), -7.0, -5.5),
                            ((0.0, -2300 * rpm, 0.0), -0.01, 0.01)):
        pitch = Pitch(*start, duration=0.5, spin=spin)
        fine = Pitch(*start, duration=0.5, spin=spin, step=1e-4)
        t = np.array([0.05, 0.2, 0.35])
        assert np.abs(pitch.position(t) - fine.position(t)).max() < 1e-9
        v = pitch.velocity(t)
        measured = (pitch.velocity(t + 1e-3) - pitch.velocity(t - 1e-3)) / 2e-3
        speed = np.linalg.norm(v, axis=1, keepdims=True)
        expected = -plain.drag_constant * speed * v - np.array([0.0, 0.0, GRAVITY])
        rate = np.linalg.norm(spin)
        if rate:
            s = BALL_RADIUS * rate / speed
            lift = 0.5 * 1.2 * math.pi * BALL_RADIUS ** 2 / 0.145 / (2.32 + 0.4 / s)
            expected += lift * speed * np.cross(np.asarray(spin) / rate, v)
        assert np.abs(measured - expected).max() < 1e-4
        assert low <= (measured - (-plain.drag_constant * speed * v))[0, 2] + GRAVITY <= high
