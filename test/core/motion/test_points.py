"""Tests for baseball_collision.core.motion.points: the ball's paths and the angle cubic."""

import math

from baseball_collision.core.motion import AngleCubic, hermite_tangent, PointPath
from hypothesis import example, given, settings, strategies as st
import numpy as np
import pytest
from support import examples

angle = st.floats(-3.0, 3.0).filter(lambda a: a == 0.0 or abs(a) > 1e-100)
"""An angle (rad), not denormal-small."""


def test_cubic_point_path_follows_a_cubic_and_bounds_its_chord_error() -> None:
    """With exact end tangents a cubic is reproduced, and the deviation bound holds."""
    def p(t: float) -> tuple:
        return (t ** 3, 1.0 - t * t, 0.5 * t)

    def v(t: float) -> tuple:
        return (3 * t * t, -2.0 * t, 0.5)
    path = PointPath(0.2, 0.7, p(0.2), p(0.7), v(0.2), v(0.7))
    for t in np.linspace(0.2, 0.7, 11):
        assert path.at(t) == pytest.approx(p(t))
        assert path.velocity(t) == pytest.approx(v(t))
    ta, tb = 0.3, 0.6
    chord = [np.array(path.at(ta)) + (np.array(path.at(tb)) - path.at(ta)) * s
             for s in np.linspace(0, 1, 101)]
    actual = max(np.linalg.norm(np.array(path.at(ta + (tb - ta) * s)) - c)
                 for s, c in zip(np.linspace(0, 1, 101), chord))
    assert actual <= path.deviation(ta, tb) + 1e-12
    assert PointPath(0.0, 1.0, (0, 0, 0), (1, 1, 1)).deviation(0.0, 1.0) == 0.0


def test_point_path_build_follows_the_model() -> None:
    """Chords for linear and rigid; the spline's cubic takes its tangents from the neighbours."""
    def p(t: float) -> tuple:
        return (t * t, 2.0 * t, -t * t * t)
    for model in ('linear', 'rigid'):
        path = PointPath.build(model, 0.1, 0.2, p(0.1), p(0.2), (0.0, p(0.0)), (0.3, p(0.3)))
        assert not path.curved and path.deviation(0.1, 0.2) == 0.0
    spline = PointPath.build('spline', 0.1, 0.2, p(0.1), p(0.2), (0.0, p(0.0)), (0.3, p(0.3)))
    assert spline.curved
    assert spline.at(0.15)[0] == pytest.approx(0.15 ** 2, abs=1e-12)  # a parabola is exact
    assert PointPath.build('spline', 0.1, 0.2, p(0.1), p(0.2)).curved  # chord tangents


@settings(max_examples=examples(200), deadline=None)
@given(angles=st.lists(angle, min_size=4, max_size=4),
       steps=st.lists(st.floats(0.002, 0.02), min_size=3, max_size=3),
       s=st.floats(0.0, 1.0))
def test_angle_cubic_is_the_point_path_of_its_angle(angles, steps, s: float) -> None:
    """
    Check the scalar cubic equals a PointPath along x (what the spline used before), bit for bit.

    Except below 1e-154 rad, where the 3-vector norm's square underflowed to 0 (abs does not).
    """
    t = np.concatenate([[0.0], np.cumsum(steps)]).tolist()
    v0, v1 = angles[1], angles[2]
    angle = AngleCubic.through(t[1], t[2], v0, v1, (t[0], angles[0]), (t[3], angles[3]))
    vector = PointPath(t[1], t[2], (v0, 0.0, 0.0), (v1, 0.0, 0.0),
                       hermite_tangent(t[0], (angles[0], 0.0, 0.0), t[1], (v0, 0.0, 0.0),
                                       t[2], (v1, 0.0, 0.0)),
                       hermite_tangent(t[1], (v0, 0.0, 0.0), t[2], (v1, 0.0, 0.0), t[3],
                                       (angles[3], 0.0, 0.0)))
    at = t[1] + s * (t[2] - t[1])
    assert angle.at(at) == vector.at(at)[0]
    assert angle.deviation(t[1], at) == vector.deviation(t[1], at)
    assert angle.bulge == vector.bulge


def test_a_uniform_turn_has_no_deviation() -> None:
    """Without rates the angle moves uniformly: linear in time, no departure."""
    angle = AngleCubic(0.0, 0.5, 0.0, 1.0)
    assert angle.at(0.25) == 0.5 and angle.deviation(0.0, 0.5) == 0.0 and angle.bulge == 0.0
    assert math.isclose(angle.at(0.5), 1.0)


def _norm(v) -> float:
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def _reference_slots(t0, t1, p0, p1, m0, m1, g0=None, g1=None) -> dict:
    """Return the path's slots by ``PointPath``'s formulas, written out in Python in its order."""
    h = t1 - t0
    chord = tuple(b - a for a, b in zip(p0, p1))
    slots = {'t0': t0, 't1': t1, 'h': h, 'a': p0, 'end': p1,
             'curved': m0 is not None and m1 is not None, 'e': None, 'f': None}
    if slots['curved'] and g0 is not None:  # the quintic Hermite, written out
        h2 = h * h
        b = tuple(h * m for m in m0)
        c = tuple(0.5 * h2 * g for g in g0)
        d, e, f = [], [], []
        for q, x, y, m, g in zip(chord, b, c, m1, g1):
            value, slope, bend = q - x - y, h * m - x - 2.0 * y, h2 * g - 2.0 * y
            d.append(10.0 * value - 4.0 * slope + 0.5 * bend)
            e.append(-15.0 * value + 7.0 * slope - bend)
            f.append(6.0 * value - 3.0 * slope + 0.5 * bend)
        d, e, f = tuple(d), tuple(e), tuple(f)
        slots.update(b=b, c=c, d=d, e=e, f=f, accel0=tuple(g0),
                     accel_rate=tuple(6.0 * x / h2 for x in d),
                     bulge=0.25 * _norm(c) + 0.38491 * _norm(d) + 0.4725 * _norm(e)
                     + 0.535 * _norm(f))
    elif slots['curved']:
        b = tuple(h * m for m in m0)
        e = tuple(h * m for m in m1)
        c = tuple(3.0 * q - 2.0 * x - y for q, x, y in zip(chord, b, e))
        d = tuple(x + y - 2.0 * q for q, x, y in zip(chord, b, e))
        h2 = h * h
        slots.update(b=b, c=c, d=d, accel0=tuple(2.0 * x / h2 for x in c),
                     accel_rate=tuple(6.0 * x / h2 for x in d),
                     bulge=0.25 * math.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])
                     + 0.38491 * math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]))
    else:
        slots.update(b=chord, c=(0.0, 0.0, 0.0), d=(0.0, 0.0, 0.0), bulge=0.0)
    slots['centre'] = tuple(a + (b - a) * 0.5 for a, b in zip(p0, p1))
    slots['radius'] = 0.5 * math.sqrt(sum(x * x for x in chord)) + slots['bulge']
    return slots


@settings(max_examples=examples(300), deadline=None)
@given(t0=st.floats(-1e3, 1e3), h=st.floats(1e-6, 1.0),
       points=st.lists(st.floats(-1e3, 1e3), min_size=12, max_size=12),
       curved=st.booleans(),
       bends=st.none() | st.lists(st.floats(-1e5, 1e5), min_size=6, max_size=6))
def test_the_kernel_fills_a_point_path_as_its_formulas_say(t0: float, h: float, points: list,
                                                           curved: bool, bends) -> None:
    """
    ``PointPath`` (filled by ``_kernel.point_path_init``) holds its formulas' numbers, bit for bit.

    Every slot against the formulas written out in Python, a chord, a cubic and a quintic; the
    ends and stamps are the objects given; bad points are refused.
    """
    p0, p1 = tuple(points[0:3]), tuple(points[3:6])
    m0, m1 = (tuple(points[6:9]), tuple(points[9:12])) if curved else (None, None)
    g0, g1 = (tuple(bends[0:3]), tuple(bends[3:6])) if bends is not None else (None, None)
    t1 = t0 + h
    path = PointPath(t0, t1, p0, p1, m0, m1, g0, g1)
    assert (path.e is not None) == (curved and bends is not None)
    for name, value in _reference_slots(t0, t1, p0, p1, m0, m1, g0, g1).items():
        assert getattr(path, name) == value and type(getattr(path, name)) is type(value), name
    assert path.a is p0 and path.end is p1
    with pytest.raises(TypeError):
        PointPath(t0, t1, p0[:2], p1)
    with pytest.raises(TypeError):
        PointPath(t0, t1, p0, p1, m0 or p0, (1.0, 'x', 2.0))


@settings(max_examples=examples(200), deadline=None)
@example(values=[0.0] * 9 + [1.0] + [0.0] * 8, t0=0.0, h=0.0625, cut=(0.0, 0.0))  # (s^3 - s:
# its largest size 2 / 3^1.5 = 0.3849002 was rounded down to 0.3849 in every bulge until this)
@given(values=st.lists(st.floats(-2.0, 2.0), min_size=18, max_size=18),
       t0=st.floats(-1.0, 1.0), h=st.floats(1e-3, 0.1), cut=st.tuples(
           st.floats(0.0, 1.0), st.floats(0.0, 1.0)))
def test_a_quintic_piece_is_its_polynomial_and_keeps_to_its_bounds(values: list, t0: float,
                                                                   h: float, cut) -> None:
    """
    A quintic ``PointPath`` / ``AngleCubic`` through a quintic's ends follows it (value, rate).

    Its chord bound (``deviation``: max |p''| span^2 / 8 by the Taylor bound on p'') and its
    bulge hold against a dense scan, in Python and in the kernel (``c2_deviation`` of a bat with
    quintic pieces sums the same bounds).
    """
    columns = [np.polynomial.Polynomial(values[6 * i:6 * i + 6], domain=[t0, t0 + h],
                                        window=[0.0, 1.0]) for i in range(3)]

    def at(t: float, derivative: int = 0) -> tuple:
        return tuple(float(c.deriv(derivative)(t)) if derivative else float(c(t))
                     for c in columns)
    t1 = t0 + h
    path = PointPath(t0, t1, at(t0), at(t1), at(t0, 1), at(t1, 1), at(t0, 2), at(t1, 2))
    angle = AngleCubic(t0, t1, at(t0)[0], at(t1)[0], at(t0, 1)[0], at(t1, 1)[0], at(t0, 2)[0],
                       at(t1, 2)[0])
    scale = max(1.0, max(abs(v) for v in values))
    for t in np.linspace(t0, t1, 7):
        assert np.allclose(path.at(t), at(t), atol=1e-9 * scale)
        assert np.allclose(path.velocity(t), at(t, 1), atol=1e-7 * scale / h)
        assert math.isclose(angle.at(t), at(t)[0], abs_tol=1e-9 * scale)
        assert math.isclose(angle.velocity(t), at(t, 1)[0], abs_tol=1e-7 * scale / h)
    ta, tb = sorted(t0 + h * np.array(cut))
    inside = np.linspace(ta, tb, 201)
    bends = [np.linalg.norm(at(t, 2)) for t in inside]
    assert max(bends) <= path.max_acceleration(ta, tb) * (1 + 1e-9) + 1e-9 * scale / h ** 2
    a, b = np.array(path.at(ta)), np.array(path.at(tb))
    off = max(np.linalg.norm(np.array(path.at(t)) - a - (t - ta) / (tb - ta) * (b - a))
              if tb > ta else 0.0 for t in inside)
    assert off <= path.deviation(ta, tb) * (1 + 1e-9) + 1e-12 * scale
    whole = np.linspace(t0, t1, 401)
    bulge = max(np.linalg.norm(np.array(path.at(t)) - np.array(at(t0))
                               - (t - t0) / h * (np.array(at(t1)) - at(t0))) for t in whole)
    assert bulge <= path.bulge * (1 + 1e-9) + 1e-12 * scale
    rise = angle.at(tb) - angle.at(ta)
    flat = max(abs(angle.at(t) - angle.at(ta) - (t - ta) / (tb - ta) * rise)
               if tb > ta else 0.0 for t in inside)
    assert flat <= angle.deviation(ta, tb) * (1 + 1e-9) + 1e-12 * scale
