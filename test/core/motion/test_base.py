"""Tests for baseball_collision.core.motion.base: models, tangents, sub-steps, bat turns."""

import math
import struct
from typing import Tuple

from baseball_collision.core.geometry import (
    add, dot, norm, rotation_between, sub, swing_rotation, Vector)
from baseball_collision.core.motion import (
    BatSample, check_model, hermite_slope, hermite_tangent, MODELS, PathKind, SAMPLES_AHEAD,
    substeps_for, swing_between, turn_between)
from baseball_collision.errors import CoreError
from hypothesis import given, settings, strategies as st
import pytest
from support import examples


def test_hermite_tangent_is_exact_for_a_parabola_on_uneven_steps() -> None:
    """The three-point tangent recovers the derivative of a quadratic on uneven stamps."""
    def p(t: float) -> tuple:
        return (3.0 * t * t - t, 2.0 * t, -4.9 * t * t)
    t_prev, t, t_next = 0.0, 0.002, 0.005
    tangent = hermite_tangent(t_prev, p(t_prev), t, p(t), t_next, p(t_next))
    assert tangent == pytest.approx((6.0 * t - 1.0, 2.0, -9.8 * t))
    assert hermite_tangent(None, None, t, p(t), t_next, p(t_next)) == pytest.approx(
        [(b - a) / (t_next - t) for a, b in zip(p(t), p(t_next))])
    assert hermite_tangent(None, None, t, p(t), None, None) == (0.0, 0.0, 0.0)


def test_substeps_for_meets_the_tolerance() -> None:
    """Enough sub-steps bring a quadratic deviation under the tolerance, and no more."""
    assert substeps_for(0.0, 1e-3) == 1
    assert substeps_for(1e-3, 1e-3) == 1
    n = substeps_for(0.02, 5e-4)
    assert 0.02 / n ** 2 <= 5e-4 < 0.02 / (n - 1) ** 2


def test_unknown_model_is_refused() -> None:
    """Only the three documented models exist."""
    assert check_model('spline') == 'spline'
    with pytest.raises(CoreError, match='linear, rigid, spline'):
        check_model('cubic')


def test_hermite_slope_is_the_tangent_of_a_scalar() -> None:
    """The scalar sibling gives the first component of the vector tangent, to the bit."""
    cases = [(0.0, 1.5, 0.002, 2.0, 0.005, 4.0), (None, None, 0.002, 2.0, 0.005, 4.0),
             (0.0, 1.5, 0.002, 2.0, None, None), (None, None, 0.002, 2.0, None, None)]
    for t_prev, v_prev, t, v, t_next, v_next in cases:
        vector = hermite_tangent(t_prev, None if v_prev is None else (v_prev, 0.0, 0.0), t,
                                 (v, 0.0, 0.0), t_next,
                                 None if v_next is None else (v_next, 0.0, 0.0))
        assert hermite_slope(t_prev, v_prev, t, v, t_next, v_next) == vector[0]


def test_every_model_says_how_many_samples_it_waits_for() -> None:
    """Only the spline needs the sample after an interval."""
    assert set(SAMPLES_AHEAD) == set(MODELS)
    assert [SAMPLES_AHEAD[m] for m in MODELS] == [0, 0, 1, 0]


def test_path_kinds_are_strings() -> None:
    """A PathKind is its plain value."""
    assert [str(kind) for kind in PathKind] == ['points', 'pose', 'axis', 'turning', 'c2']
    assert PathKind.POSE == 'pose'


def test_turn_between_bat_samples() -> None:
    """A quarter swing about z; from poses also the roll about the bat's own axis."""
    a = BatSample(knob=(0.0, 0.0, 0.0), tip=(1.0, 0.0, 0.0))
    b = BatSample(knob=(0.0, 0.0, 0.0), tip=(0.0, 1.0, 0.0))
    assert swing_between(a, b) == pytest.approx((0.0, 0.0, math.pi / 2))
    assert turn_between(a, b) == (swing_between(a, b), 0.0)
    # rolled by 0.3 rad about the bat's axis (x), not swung
    roll = (math.sin(0.15), 0.0, 0.0, math.cos(0.15))
    posed_a = BatSample(a.knob, a.tip, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    posed_b = BatSample(a.knob, a.tip, (0.0, 0.0, 0.0), roll)
    swing, rolled = turn_between(posed_a, posed_b)
    assert swing == (0.0, 0.0, 0.0) and rolled == pytest.approx(0.3)


def _turn_from_geometry(a: BatSample, b: BatSample) -> Tuple[Vector, float]:
    """Return ``turn_between``'s answer composed from the geometry module's functions."""
    d0, d1 = sub(a.tip, a.knob), sub(b.tip, b.knob)
    swing = swing_rotation(d0, d1)
    if a.quaternion is None or b.quaternion is None:
        return swing, 0.0
    full = rotation_between(a.quaternion, b.quaternion)
    mean_axis = add(d0, d1)
    length = norm(mean_axis)
    if full is None or length == 0.0:
        return swing, 0.0
    return swing, dot(full, mean_axis) / length


def _bits(turn: Tuple[Vector, float]) -> bytes:
    return struct.pack('<4d', *turn[0], turn[1])


finite = st.floats(-10.0, 10.0, allow_nan=False)
vectors = st.tuples(finite, finite, finite)
quaternions = st.one_of(st.none(), st.tuples(finite, finite, finite, finite).filter(
    lambda q: sum(x * x for x in q) > 1e-6).map(
    lambda q: tuple(x / math.sqrt(sum(y * y for y in q)) for x in q)))


@settings(max_examples=examples(300), deadline=None)
@given(knob=vectors, tip=vectors, knob1=vectors, tip1=vectors, q0=quaternions, q1=quaternions,
       case=st.sampled_from(['any', 'same', 'reversed', 'flipped', 'no axis']))
def test_turn_between_is_the_geometry_of_its_docstring_to_the_bit(knob, tip, knob1, tip1, q0, q1,
                                                                  case) -> None:
    """The kernel's turn is the swing rotation and the roll along the mean axis, to the bit."""
    a = BatSample(knob, tip, knob, q0)
    b = {'any': BatSample(knob1, tip1, knob1, q1), 'same': a,
         'reversed': BatSample(tip, knob, tip, q1),
         'flipped': BatSample(knob1, tip1, knob1, None if q0 is None else tuple(-x for x in q0)),
         'no axis': BatSample(knob1, knob1, knob1, q1)}[case]
    found = turn_between(a, b)
    assert type(found[1]) is float and all(type(x) is float for x in found[0])
    assert _bits(found) == _bits(_turn_from_geometry(a, b))


def test_turn_between_refuses_what_is_not_a_bat_sample() -> None:
    """A knob or tip that is not 3 numbers, or a quaternion neither None nor 4, raise."""
    a = BatSample((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    for bad in (BatSample((0.0, 0.0), (1.0, 0.0, 0.0)),
                BatSample((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 1.0))):
        with pytest.raises(TypeError):
            turn_between(a, bad)
    with pytest.raises(AttributeError):
        turn_between(a, (0.0, 0.0, 0.0))
