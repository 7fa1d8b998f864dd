"""Tests for baseball_collision.core.motion.base: models, tangents, sub-steps, bat turns."""

import math

from baseball_collision.core.motion import (
    BatSample, check_model, hermite_slope, hermite_tangent, MODELS, PathKind, SAMPLES_AHEAD,
    substeps_for, swing_between, turn_between)
from baseball_collision.errors import CoreError
import pytest


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
