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
    """
    Halving the step on a tilting swing cuts the tip's error by about 16 (order 4).

    With a sample after the interval (look-ahead 1 or 2: the quintic) by about 64 (order 6).
    """
    for look_ahead, least in ((0, 10.0), (1, 40.0), (2, 40.0)):
        coarse, fine = _worst_error(180.0, look_ahead), _worst_error(360.0, look_ahead)
        assert coarse / fine > least, (look_ahead, coarse, fine)
    assert _worst_error(360.0, 1) < 1e-6


@settings(max_examples=examples(150), deadline=None)
@given(steps=st.lists(st.floats(0.002, 0.012), min_size=5, max_size=7),
       tilt=st.floats(-3.0, 3.0), noise=st.floats(0.0, 0.01), seed=st.integers(0, 1000),
       k=st.integers(0, 3), cut=st.tuples(st.floats(0.0, 1.0), st.floats(0.0, 1.0)),
       even=st.booleans())
def test_path_never_leaves_its_chord_by_more_than_the_bound(steps, tilt, noise, seed, k,
                                                            cut, even) -> None:
    """
    Every axis point stays within deviation(ta, tb) of its chord, and in the sphere.

    Cubic and (``even``: steps within a factor 1.85, so a sample after the interval makes it one)
    quintic pieces.
    """
    if even:
        steps = [0.0065 + 0.55 * (step - 0.002) for step in steps]
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
       tilt=st.floats(-3.0, 3.0), k=st.integers(0, 3), at=st.floats(0.0, 1.0),
       even=st.booleans())
def test_the_kernels_inside_is_the_python_written_out(steps, tilt, k, at, even) -> None:
    """
    A ``c2`` bat path's (knob, tip) inside its interval is its pieces' Python, to the bit.

    The knob piece's polynomial (a cubic, or a quintic in a window with a sample after the
    interval), the reference turned by the turn piece's (``rotate``), the tip the knob plus the
    length piece's value times that direction; at the ends, the samples' own.
    """
    from baseball_collision.core.toi import _kernel
    if even:  # (steps within a factor 1.85: a quintic where a sample follows the interval)
        steps = [0.0065 + 0.55 * (step - 0.002) for step in steps]
    times = np.concatenate([[0.0], np.cumsum(steps)])
    path = _path(times, _swing(times, tilt), k)
    if even:
        assert (path.knob.e is not None) == (k + 2 < len(times))

    def polynomial(piece, t):  # type: ignore[no-untyped-def]
        s = (t - piece.t0) / piece.h
        a, b, c, d, e, f = piece.a, piece.b, piece.c, piece.d, piece.e, piece.f
        if isinstance(a, float):
            return (a + s * (b + s * (c + s * (d + s * (e + s * f))))) if e is not None else (
                a + s * (b + s * (c + s * d)))
        if e is not None:
            return tuple(a[i] + s * (b[i] + s * (c[i] + s * (d[i] + s * (e[i] + s * f[i]))))
                         for i in range(3))
        return tuple(a[i] + s * (b[i] + s * (c[i] + s * d[i])) for i in range(3))
    t = path.t0 + at * path.h
    if path.t0 < t < path.t1:
        knob = polynomial(path.knob, t)
        d = rotate(path.reference, polynomial(path.turn, t))
        length = polynomial(path.length, t)
        tip = (knob[0] + length * d[0], knob[1] + length * d[1], knob[2] + length * d[2])
        assert path.at(t) == (knob, tip)
    assert _kernel.c2_inside(path, path.t0)[0] is path.knob.a
    assert _kernel.c2_inside(path, path.t1)[0] is path.knob.end


def _reference_path(t0, t1, sample0, sample1, knob_slopes, turn_slopes, length_slopes,
                    seconds=None):
    """Return the slots of ``C2BatPath``'s constructor as it was in Python (written out)."""
    knob_seconds, turn_seconds, length_seconds = seconds or ((), (), ())
    from baseball_collision.core.motion import AngleCubic, PointPath
    from baseball_collision.core.motion.c2 import axis_and_length, rotation_to
    k0, e0, k1, e1 = sample0.knob, sample0.tip, sample1.knob, sample1.tip
    centre = (0.25 * (k0[0] + e0[0] + k1[0] + e1[0]), 0.25 * (k0[1] + e0[1] + k1[1] + e1[1]),
              0.25 * (k0[2] + e0[2] + k1[2] + e1[2]))
    radius = max(math.dist(k0, centre), math.dist(e0, centre), math.dist(k1, centre),
                 math.dist(e1, centre))
    knob = PointPath(t0, t1, k0, k1, *knob_slopes, *knob_seconds)
    reference, length0 = axis_and_length(sample0)
    direction, length1 = axis_and_length(sample1)
    closing = rotation_to(reference, direction)
    turn = PointPath(t0, t1, (0.0, 0.0, 0.0), closing, *turn_slopes, *turn_seconds)
    length = AngleCubic(t0, t1, length0, length1, *length_slopes, *length_seconds)
    from baseball_collision.core.toi import _kernel
    spread = _kernel.c2_deviation(knob, turn, length, t0, t1)
    return {'t0': t0, 't1': t1, 'h': t1 - t0, 'sample0': sample0, 'sample1': sample1,
            'centre': centre, 'radius': radius + spread, 'knob': knob, 'turn': turn,
            'length': length, 'reference': reference, 'lever': max(length0, length1),
            'angle': math.sqrt(closing[0] * closing[0] + closing[1] * closing[1]
                               + closing[2] * closing[2]), 'spread': spread}


def _same_piece(made, reference) -> bool:
    """Return whether two path pieces hold the same numbers (bit for bit) in every slot."""
    for name in type(reference).__slots__:
        if hasattr(reference, name) != hasattr(made, name):
            return False
        if hasattr(reference, name):
            mine, theirs = getattr(made, name), getattr(reference, name)
            if mine != theirs or type(mine) is not type(theirs):
                return False
    return True


@settings(max_examples=examples(200), deadline=None)
@given(steps=st.lists(st.floats(0.002, 0.012), min_size=5, max_size=7),
       tilt=st.floats(-3.0, 3.0), k=st.integers(0, 3),
       slopes=st.lists(st.floats(-50.0, 50.0), min_size=14, max_size=14),
       plain=st.sampled_from(['none', 'knob', 'turn', 'length']),
       bends=st.none() | st.lists(st.floats(-5e3, 5e3), min_size=14, max_size=14))
def test_the_kernel_fills_a_c2_path_as_its_python_did(steps, tilt, k, slopes, plain,
                                                      bends) -> None:
    """
    ``C2BatPath`` (filled by ``_kernel.c2_path_init``) is its old Python constructor, to the bit.

    Every slot of the path and of its three pieces against that constructor written out, on
    fitted windows (cubic, or quintic with a sample after the interval) and on arbitrary slopes
    and second derivatives (each piece also without slopes: a chord, a uniform turn); the
    samples and stamps are the objects given; bad arguments are refused.
    """
    times = np.concatenate([[0.0], np.cumsum(steps)]).tolist()
    ends = _swing(np.array(times), tilt)
    samples = [BatSample(tuple(row[:3]), tuple(row[3:])) for row in ends.tolist()]
    pairs = [((tuple(slopes[0:3]), tuple(slopes[3:6])) if plain != 'knob' else (None, None)),
             ((tuple(slopes[6:9]), tuple(slopes[9:12])) if plain != 'turn' else (None, None)),
             ((slopes[12], slopes[13]) if plain != 'length' else (None, None))]
    seconds = None if bends is None else (
        (tuple(bends[0:3]), tuple(bends[3:6])), (tuple(bends[6:9]), tuple(bends[9:12])),
        (bends[12], bends[13]))
    from baseball_collision.core.motion.c2 import c2_rows
    from baseball_collision.core.motion.splines import (
        not_a_knot_quintic_rows, not_a_knot_slope_rows, quintic_window)
    first, rows = c2_rows(samples, k)
    window_seconds = None
    if quintic_window(times[first:first + len(rows)], k - first):
        (s0, s1), (g0, g1) = (pair[:2] for pair in not_a_knot_quintic_rows(
            times[first:first + len(rows)], rows, k - first))
        window_seconds = ((g0[:3], g1[:3]), (g0[3:6], g1[3:6]), (g0[6], g1[6]))
    else:
        s0, s1 = not_a_knot_slope_rows(times[first:first + len(rows)], rows, k - first)[:2]
    window_pairs = ((tuple(s0[:3]), tuple(s1[:3])), (tuple(s0[3:6]), tuple(s1[3:6])),
                    (s0[6], s1[6]))
    built = C2BatPath(times[k], times[k + 1], samples[k], samples[k + 1], *pairs, seconds)
    for path, given_pairs, given_seconds in (
            (built, pairs, seconds),
            (C2BatPath.fitted(times, samples, k), window_pairs, window_seconds)):
        reference = _reference_path(times[k], times[k + 1], samples[k], samples[k + 1],
                                    *given_pairs, given_seconds)
        for name, value in reference.items():
            mine = getattr(path, name)
            if name in ('knob', 'turn', 'length'):
                assert _same_piece(mine, value), name
            else:
                assert mine == value and type(mine) is type(value), name
    assert built.sample0 is samples[k] and built.t1 is times[k + 1]
    assert built.knob.a is samples[k].knob and built.knob.end is samples[k + 1].knob
    assert built.deviation(built.t0, built.t1) == built.spread


def test_a_c2_path_refuses_what_is_not_a_path() -> None:
    """Bad samples, slopes, second derivatives or times raise, not a half-filled path."""
    import pytest
    a, b = BatSample((0.0, 0.0, 0.0), (0.8, 0.0, 0.0)), BatSample((0.0, 0.1, 0.0), (0.8, 0.2, 0.0))
    good = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    with pytest.raises(TypeError):
        C2BatPath(0.0, 0.01, a, b, good, good, (0.0,))  # length slopes not a pair
    with pytest.raises(TypeError):
        C2BatPath(0.0, 0.01, a, b, good, good, (0.0, 'x'))
    with pytest.raises(TypeError):
        C2BatPath('0', 0.01, a, b, good, good, (0.0, 0.0))
    with pytest.raises((TypeError, AttributeError)):
        C2BatPath(0.0, 0.01, a, (0.0, 0.0, 0.0), good, good, (0.0, 0.0))
    with pytest.raises(TypeError):
        C2BatPath(0.0, 0.01, a, b, ((0.0, 0.0), (0.0, 0.0, 0.0)), good, (0.0, 0.0))
    # second derivatives (quintic pieces): three pairs, of 3, 3 and 1 numbers
    for seconds in (5, (good, good, (0.0, 'x')), (good, good, (0.0,)),
                    (good, ((1.0, 2.0), (1.0, 2.0, 3.0)), (0.0, 0.0))):
        with pytest.raises(TypeError):
            C2BatPath(0.0, 0.01, a, b, good, good, (0.0, 0.0), seconds)
    with pytest.raises(IndexError):
        C2BatPath(0.0, 0.01, a, b, good, good, (0.0, 0.0), ((0.0, 0.0),))
    assert C2BatPath(0.0, 0.01, a, b, good, good, (0.0, 0.0), (good, good, (0.0, 0.0))
                     ).length.e is not None
