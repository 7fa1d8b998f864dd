"""Tests for the c2 model: not-a-knot slopes, the bat's path, its chord bound, its order."""

import math

from baseball_collision.core.motion import BatSample, C2BatPath, not_a_knot_slopes
from baseball_collision.core.motion.c2 import rotate
from hypothesis import given, settings, strategies as st
import numpy as np
from support import examples

steps = st.lists(st.floats(0.003, 0.012), min_size=3, max_size=9)


@settings(max_examples=examples(100), deadline=None)
@given(steps=steps, coefficients=st.lists(st.floats(-50.0, 50.0), min_size=4, max_size=4))
def test_slopes_are_exact_for_a_cubic_on_uneven_stamps(steps, coefficients) -> None:
    """The not-a-knot spline reproduces any cubic: its slopes are the cubic's derivative."""
    times = np.concatenate([[0.0], np.cumsum(steps)])
    a, b, c, d = coefficients
    values = (a + b * times + c * times ** 2 + d * times ** 3)[:, None]
    slopes = not_a_knot_slopes(times, values)[:, 0]
    expected = b + 2.0 * c * times + 3.0 * d * times ** 2
    assert np.allclose(slopes, expected, rtol=1e-7, atol=1e-6 * (1.0 + np.abs(expected).max()))


def test_two_and_three_samples_give_the_chord_and_the_parabola() -> None:
    """Two samples: the chord's slope; three: the parabola's derivative."""
    assert np.allclose(not_a_knot_slopes([0.0, 2.0], np.array([[1.0], [5.0]]))[:, 0], [2.0, 2.0])
    times = np.array([0.0, 0.5, 2.0])
    slopes = not_a_knot_slopes(times, (times ** 2 - times)[:, None])[:, 0]
    assert np.allclose(slopes, 2.0 * times - 1.0)


def _swing(t: np.ndarray, tilt: float) -> np.ndarray:
    """Return knob and tip (len(t), 6) of a bat turning about an axis that tilts as it goes."""
    angle = 10.0 * t + 100.0 * t ** 2  # 50 rad/s at 0.2 s
    axis = np.stack([np.sin(tilt * t), np.zeros_like(t), np.cos(tilt * t)], axis=1)
    radial = np.stack([np.cos(angle), np.sin(angle), np.zeros_like(t)], axis=1)
    direction = radial - axis * np.sum(radial * axis, axis=1)[:, None]
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    knob = np.stack([0.3 * np.cos(5.0 * t), 0.3 * np.sin(5.0 * t), 1.0 + 0.1 * t], axis=1)
    return np.hstack([knob, knob + 0.86 * direction])


def _path(times: np.ndarray, ends: np.ndarray, k: int) -> C2BatPath:
    samples = [BatSample(tuple(row[:3]), tuple(row[3:])) for row in ends]
    return C2BatPath.fitted(list(times), samples, k)


def _worst_error(rate: float, look_ahead: int) -> float:
    """Return the largest tip error (m) of the c2 path over the interval ending 0.2 s in."""
    times = 0.2 + (np.arange(8) - 6 + look_ahead) / rate
    path = _path(times, _swing(times, 2.0), 6 - look_ahead)
    inside = np.linspace(path.t0, path.t1, 50)
    truth = _swing(inside, 2.0)
    return max(math.dist(path.at(t)[1], row[3:]) for t, row in zip(inside, truth))


def test_error_falls_with_the_fourth_power_of_the_step() -> None:
    """Halving the step on a tilting swing cuts the tip's error by about 16 (order 4)."""
    for look_ahead in (0, 1, 2):
        coarse, fine = _worst_error(180.0, look_ahead), _worst_error(360.0, look_ahead)
        assert coarse / fine > 10.0, (look_ahead, coarse, fine)
    assert _worst_error(360.0, 1) < 1e-5


@settings(max_examples=examples(150), deadline=None)
@given(steps=st.lists(st.floats(0.002, 0.012), min_size=5, max_size=7),
       tilt=st.floats(-3.0, 3.0), noise=st.floats(0.0, 0.01), seed=st.integers(0, 1000),
       k=st.integers(0, 3), cut=st.tuples(st.floats(0.0, 1.0), st.floats(0.0, 1.0)))
def test_path_never_leaves_its_chord_by_more_than_the_bound(steps, tilt, noise, seed, k,
                                                            cut) -> None:
    """Every axis point stays within deviation(ta, tb) of its chord, and in the sphere."""
    times = np.concatenate([[0.0], np.cumsum(steps)])
    ends = _swing(times, tilt) + np.random.default_rng(seed).normal(0.0, noise, (len(times), 6))
    path = _path(times, ends, k)
    ta, tb = sorted(path.t0 + path.h * np.array(cut))
    bound = path.deviation(ta, tb)
    for fraction in (0.0, 0.5, 1.0):
        def point(t: float) -> np.ndarray:
            knob, tip = (np.array(p) for p in path.at(t))
            return knob + fraction * (tip - knob)
        a, b = point(ta), point(tb)
        for s in np.linspace(0.0, 1.0, 41):
            p = point(ta + s * (tb - ta))
            assert np.linalg.norm(p - (a + s * (b - a))) <= bound + 1e-12
            assert math.dist(p, path.centre) <= path.radius + 1e-12
    if noise == 0.0:  # a rigid bat keeps its length
        assert abs(math.dist(*path.at(path.t0 + 0.37 * path.h)) - 0.86) < 1e-3


vectors = st.tuples(*[st.floats(-3.0, 3.0)] * 3)


@settings(max_examples=examples(200), deadline=None)
@given(direction=vectors, rotation=vectors)
def test_rotate_is_rodrigues_step_by_step(direction, rotation) -> None:
    """The kernel's rotate is Rodrigues' formula written out in Python, to the bit."""
    length = math.sqrt(sum(x * x for x in direction))
    if length < 1e-3:
        return
    reference = tuple(x / length for x in direction)
    angle = math.sqrt(rotation[0] * rotation[0] + rotation[1] * rotation[1]
                      + rotation[2] * rotation[2])
    if angle < 1e-15:
        assert rotate(reference, rotation) is reference
        return
    across = (rotation[1] * reference[2] - rotation[2] * reference[1],
              rotation[2] * reference[0] - rotation[0] * reference[2],
              rotation[0] * reference[1] - rotation[1] * reference[0])
    c, s = math.cos(angle), math.sin(angle) / angle
    assert rotate(reference, rotation) == tuple(c * f + s * a for f, a in zip(reference, across))


@settings(max_examples=examples(150), deadline=None)
@given(steps=st.lists(st.floats(0.002, 0.012), min_size=5, max_size=7),
       tilt=st.floats(-3.0, 3.0), k=st.integers(0, 3), at=st.floats(0.0, 1.0))
def test_the_kernels_inside_is_the_python_written_out(steps, tilt, k, at) -> None:
    """
    A ``c2`` bat path's (knob, tip) inside its interval is its pieces' Python, to the bit.

    The knob piece's cubic, the reference turned by the turn piece's (``rotate``), the tip the
    knob plus the length piece's value times that direction; at the ends, the samples' own.
    """
    from baseball_collision.core.toi import _kernel
    times = np.concatenate([[0.0], np.cumsum(steps)])
    path = _path(times, _swing(times, tilt), k)

    def cubic(piece, t):  # type: ignore[no-untyped-def]
        s = (t - piece.t0) / piece.h
        a, b, c, d = piece.a, piece.b, piece.c, piece.d
        if isinstance(a, float):
            return a + s * (b + s * (c + s * d))
        return tuple(a[i] + s * (b[i] + s * (c[i] + s * d[i])) for i in range(3))
    t = path.t0 + at * path.h
    if path.t0 < t < path.t1:
        knob = cubic(path.knob, t)
        d = rotate(path.reference, cubic(path.turn, t))
        length = cubic(path.length, t)
        tip = (knob[0] + length * d[0], knob[1] + length * d[1], knob[2] + length * d[2])
        assert path.at(t) == (knob, tip)
    assert _kernel.c2_inside(path, path.t0)[0] is path.knob.a
    assert _kernel.c2_inside(path, path.t1)[0] is path.knob.end
