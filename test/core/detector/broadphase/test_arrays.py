"""Tests for the far test over arrays: apart_margins and hull_separations."""

from baseball_collision.core.detector import Detector
from baseball_collision.core.detector.broadphase import (
    apart_margins, hull_separation, hull_separations)
from baseball_collision.core.detector.broadphase.arrays import rows
from baseball_collision.core.detector.departure import departure_reaches
from hypothesis import assume, given, settings, strategies as st
import numpy as np
import pytest
from support import examples
from support.far import closest_distance, MOTIONS, turning_swing


def _vectorised_bound(detector: Detector, model: str) -> float:
    """Return ``apart_margins`` over interval 1 of the detector's streams (m)."""
    ball, bat = detector._ball, detector._bat
    one = np.array([1])
    return float(apart_margins(
        np.array(ball.values), np.array([s.knob for s in bat.values]),
        np.array([s.tip for s in bat.values]), np.array([s.position for s in bat.values]),
        one, one, one - 1, one + 2, one - 1, one + 2, np.array(ball.times),
        np.array(bat.times), model)[0])


@settings(max_examples=examples(200), deadline=None)
@given(**MOTIONS)
def test_vectorised_far_bound_never_exceeds_the_paths_distance(model: str, offset, ball_moves,
                                                               hand_moves, turns,
                                                               steps) -> None:
    """
    ``apart_margins`` (spheres and hulls) is a lower bound on the paths' least distance.

    Ball and bat within a metre, moving up to 0.15 m a sample, so many cases are close. Fails
    when the growth terms are left out (hulls' separation alone), and when either bound is raised
    by 1 mm.
    """
    hands = np.cumsum(hand_moves, axis=0)
    balls = np.array(offset) + np.cumsum(ball_moves, axis=0)
    detector = turning_swing(model, [tuple(b) for b in balls], [tuple(h) for h in hands],
                             turns, steps)
    assert _vectorised_bound(detector, model) <= closest_distance(detector) + 1e-9


def test_the_hulls_without_the_growth_overshoot_a_turning_bat() -> None:
    """
    Need the growth terms: without them a turning bat's bound overshoots.

    A bat turning fast bows out of its end samples' hull, and the hulls' separation alone
    then exceeds the true distance (the property above fails when they are left out); with
    them, the bound holds.
    """
    for model in ('rigid', 'spline'):
        # the bat turns 1.2 rad a step about the tilted axis; the ball waits just outside the
        # hull of the middle interval's end samples, on the side the arc bows to
        probe = turning_swing(model, [(5.0, 5.0, 5.0)] * 4, [(0.0, 0.0, 0.0)] * 4,
                              [-1.2, 0.0, 1.2, 2.4], [0.005] * 3)
        s0, s1 = probe._bat.values[1], probe._bat.values[2]
        bow = np.array(s0.tip) + np.array(s1.tip) - np.array(s0.knob) - np.array(s1.knob)
        ball = tuple(0.5 * (np.array(s0.tip) + np.array(s1.tip)) + 0.05 * bow / np.linalg.norm(
            bow))
        detector = turning_swing(model, [ball] * 4, [(0.0, 0.0, 0.0)] * 4,
                                 [-1.2, 0.0, 1.2, 2.4], [0.005] * 3)
        closest = closest_distance(detector)
        b0, b1 = (np.array([v]) for v in detector._ball.values[1:3])
        k0, k1 = (np.array([s.knob]) for s in detector._bat.values[1:3])
        e0, e1 = (np.array([s.tip]) for s in detector._bat.values[1:3])
        assert hull_separations(b0, b1, k0, e0, k1, e1)[0] > closest + 0.01
        assert _vectorised_bound(detector, model) <= closest + 1e-9


@settings(max_examples=examples(100), deadline=None)
@given(points=st.lists(st.tuples(*[st.floats(-3.0, 3.0)] * 3), min_size=6, max_size=6))
def test_hull_separation_scalar_and_arrays_agree(points) -> None:
    """
    ``hull_separation`` and ``hull_separations`` give one number (to rounding).

    Where the direction they bound along is defined: not where the ball chord's middle lies on
    the bat's middle segment to within rounding (its length then a few ulps, its direction each
    one's rounding; every unit direction gives a lower bound, so both are still bounds).
    """
    b0, b1, k0, e0, k1, e1 = (np.array(p, dtype=float) for p in points)
    middle, axis = (k0 + k1) * 0.5, (e0 + e1) * 0.5 - (k0 + k1) * 0.5
    offset = (b0 + b1) * 0.5 - middle
    along = float(axis @ axis)
    s = min(max(float(offset @ axis) / along, 0.0), 1.0) if along > 0.0 else 0.0
    assume(np.linalg.norm(offset - s * axis) > 1e-6 * (1.0 + np.abs(points).max()))
    scalar = hull_separation(*points)
    array = hull_separations(*(np.array([p], dtype=float) for p in points))[0]
    assert scalar == array or abs(scalar - array) <= 1e-9 * (1.0 + abs(scalar))


def _dist(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the row-wise distances of two (m, 3) arrays (as the array code sums them)."""
    d = a - b
    return np.sqrt(np.einsum('ij,ij->i', d, d))


def _bulges_by_rule(points, times, k, before, after):
    """``bulge_bounds`` of one picked point over intervals k, written out as the rule."""
    h = times[k + 1] - times[k]
    here, there = points[k], points[k + 1]
    bound = 3.04 * _dist(here, there)
    has = before >= 0
    b = np.where(has, before, k)
    bound = bound + np.where(has, 0.885 * h / np.where(has, times[k] - times[b], 1.0)
                             * _dist(points[b], here), 0.0)
    has = after >= 0
    a = np.where(has, after, k + 1)
    return bound + np.where(has, 0.635 * h / np.where(has, times[a] - times[k + 1], 1.0)
                            * _dist(there, points[a]), 0.0)


@settings(max_examples=examples(100), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(4, 40), m=st.integers(1, 30),
       model=st.sampled_from(['linear', 'rigid', 'spline']))
def test_apart_margins_are_the_bounds_written_out_to_the_bit(seed: int, n: int, m: int,
                                                             model: str) -> None:
    """
    ``apart_margins`` gives the spheres' and hulls' bounds of its docstring, bit for bit.

    Less the ball's departure reach (``departure.departure_reaches``) on every interval.

    The reference is the rule written out with fancy indexing, each bulge on its own (the
    array code shares the bat's neighbours and weights and takes rows with ``np.take``).
    """
    rng = np.random.default_rng(seed)
    ball, knob, tip, position = (rng.normal(size=(n, 3)) for _ in range(4))
    ball_times = np.cumsum(rng.uniform(0.001, 0.01, n))
    bat_times = np.cumsum(rng.uniform(0.001, 0.01, n))
    ball_k, bat_k = rng.integers(0, n - 1, m), rng.integers(0, n - 1, m)
    ball_before = np.where(rng.random(m) < 0.7, ball_k - 1, -1)
    ball_after = np.where((rng.random(m) < 0.7) & (ball_k + 2 < n), ball_k + 2, -1)
    bat_before = np.where(rng.random(m) < 0.7, bat_k - 1, -1)
    bat_after = np.where((rng.random(m) < 0.7) & (bat_k + 2 < n), bat_k + 2, -1)
    ball_before[ball_k == 0], bat_before[bat_k == 0] = -1, -1
    with np.errstate(all='ignore'):
        clearance = apart_margins(ball, knob, tip, position, ball_k, bat_k, ball_before,
                                  ball_after, bat_before, bat_after, ball_times, bat_times, model)
        dist = _dist
        b0, b1, k0, k1 = ball[ball_k], ball[ball_k + 1], knob[bat_k], knob[bat_k + 1]
        e0, e1 = tip[bat_k], tip[bat_k + 1]
        ball_centre, bat_centre = (b0 + b1) * 0.5, (k0 + e0 + k1 + e1) * 0.25
        bat_radius = np.maximum(np.maximum(dist(k0, bat_centre), dist(e0, bat_centre)),
                                np.maximum(dist(k1, bat_centre), dist(e1, bat_centre)))
        ball_bulge = bat_growth = 0.0
        if model == 'rigid':
            bat_growth = 0.5 * (np.maximum(dist(k0, k1), dist(e0, e1))
                                + dist(position[bat_k], position[bat_k + 1]))
        elif model == 'spline':
            ball_bulge = _bulges_by_rule(ball, ball_times, ball_k, ball_before, ball_after)
            bat_growth = (_bulges_by_rule(knob, bat_times, bat_k, bat_before, bat_after)
                          + 0.25 * np.pi * dist(e0 - k0, e1 - k1)
                          + np.pi * _bulges_by_rule(tip - knob, bat_times, bat_k, bat_before,
                                                    bat_after)
                          + np.abs(dist(k0, e0) - dist(k1, e1)))
        sphere = (dist(ball_centre, bat_centre) - (0.5 * dist(b0, b1) + ball_bulge)
                  - (bat_radius + bat_growth))
        expected = np.maximum(sphere, hull_separations(b0, b1, k0, e0, k1, e1) - ball_bulge
                              - bat_growth) - departure_reaches(ball, ball_times, ball_k)
    assert clearance.tobytes() == expected.tobytes()


@settings(max_examples=examples(100), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(1, 20), shape=st.sampled_from(
    [(0,), (5,), (3, 4)]), columns=st.integers(1, 7))
def test_rows_are_fancy_indexing(seed: int, n: int, shape, columns: int) -> None:
    """``rows`` takes the same rows as ``points[index]`` (negative indices from the end)."""
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n, columns))
    index = rng.integers(-n, n, shape)
    taken = rows(points, index)
    assert taken.shape == points[index].shape and np.array_equal(taken, points[index])


@settings(max_examples=examples(100), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(4, 40), m=st.integers(1, 30),
       model=st.sampled_from(['linear', 'rigid', 'spline']), margin=st.floats(-1.0, 3.0))
def test_a_margin_skips_only_hulls_that_cannot_matter(seed: int, n: int, m: int, model: str,
                                                      margin: float) -> None:
    """
    With a margin, the intervals the spheres clear skip the hulls: the same decisions.

    Where the clearance is not above the margin it is the whole clearance, to the bit.
    """
    rng = np.random.default_rng(seed)
    ball, knob, tip, position = (rng.normal(size=(n, 3)) for _ in range(4))
    times = np.cumsum(rng.uniform(0.001, 0.01, n))
    ball_k, bat_k = rng.integers(0, n - 1, m), rng.integers(0, n - 1, m)
    before = np.where(ball_k >= 1, ball_k - 1, -1)
    after = np.where(bat_k + 2 < n, bat_k + 2, -1)
    arguments = (ball, knob, tip, position, ball_k, bat_k, before, -np.ones(m, np.int64),
                 np.where(bat_k >= 1, bat_k - 1, -1), after, times, times, model)
    with np.errstate(all='ignore'):
        whole = apart_margins(*arguments)
        cut = apart_margins(*arguments, margin=margin)
    assert ((cut > margin) == (whole > margin)).all()
    kept = ~(whole > margin)
    assert cut[kept].tobytes() == whole[kept].tobytes()


@settings(max_examples=examples(100), deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(3, 40), m=st.integers(1, 30),
       look_ahead=st.integers(0, 2), size=st.integers(4, 12), margin=st.floats(-1.0, 3.0),
       segments=st.booleans())
def test_c2_clearance_of_an_interval_does_not_depend_on_the_others(
        seed: int, n: int, m: int, look_ahead: int, size: int, margin: float,
        segments: bool) -> None:
    """
    ``c2``'s clearance of each interval is the same asked alone or among others, to the bit.

    The kernel's ``c2_margins`` keeps per-sample numbers across the intervals of one call.
    """
    rng = np.random.default_rng(seed)
    ball, knob = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    tip = knob + rng.normal(size=(n, 3))
    times = np.cumsum(rng.uniform(0.002, 0.006, n))
    closed = (rng.random(n - 1) > 0.2, rng.random(n - 1) > 0.2) if segments else None
    ball_k, bat_k = rng.integers(0, n - 1, m), rng.integers(0, n - 1, m)
    none = -np.ones(m, np.int64)

    def clearance(i: slice) -> np.ndarray:
        return apart_margins(ball, knob, tip, None, ball_k[i], bat_k[i], none[i], none[i],
                             none[i], none[i], times, times, 'c2', look_ahead, size, margin,
                             closed)

    together = clearance(slice(None))
    alone = np.concatenate([clearance(slice(i, i + 1)) for i in range(m)])
    assert together.tobytes() == alone.tobytes()


def test_c2_clearance_refuses_an_interval_outside_its_streams() -> None:
    """
    An interval without a sample after it, or arrays that do not match, are a ValueError.

    No interval at all is an empty answer, whatever the streams (a single sample too).
    """
    n = 6
    points, times = np.zeros((n, 3)), np.arange(n) * 0.01
    tips = points + 1.0
    none = np.zeros(0, np.int64)
    assert len(apart_margins(points[:1], points[:1], tips[:1], None, none, none, none, none,
                             none, none, times[:1], times[:1], 'c2', 0, 8)) == 0
    for ball_k, bat_k, tip in (([n - 1], [0], tips), ([0], [-1], tips), ([0], [0], tips[1:])):
        one = np.array([-1])
        with pytest.raises(ValueError):
            apart_margins(points, points, tip, None, np.array(ball_k), np.array(bat_k), one,
                          one, one, one, times, times, 'c2', 0, 8)
