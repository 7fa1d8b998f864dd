"""Tests for baseball_collision.core.toi.capsule: one copy of the contact polynomials."""

from baseball_collision.core.toi.capsule import BATCH, cap_quadratics, SCALAR, side_quartic
from baseball_collision.core.toi.polynomials import evaluate
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples
from support.scenes import point


@settings(max_examples=examples(200), deadline=None)
@given(w0=point, w1=point, u0=point, u1=point, r=st.floats(0.0, 0.5), tau=st.floats(0.0, 1.0))
def test_polynomials_are_the_squared_distances(w0, w1, u0, u1, r: float, tau: float) -> None:
    """At any tau: caps |p|^2 - R^2, side |w x u|^2 - R^2 |u|^2, and the axis quadratics."""
    w = np.array(w0) + tau * np.array(w1)
    u = np.array(u0) + tau * np.array(u1)
    rr = r * r
    knob, tip = cap_quadratics(w0, w1, u0, u1, rr, SCALAR)
    for (a, b, c), p in ((knob, w), (tip, w - u)):
        assert a * tau * tau + b * tau + c == pytest.approx(p @ p - rr, abs=1e-12)
    quartic, uu, wu = side_quartic(w0, w1, u0, u1, rr, SCALAR)
    side = np.cross(w, u) @ np.cross(w, u) - rr * (u @ u)
    assert evaluate(quartic, tau) == pytest.approx(side, abs=1e-11)
    assert evaluate(uu + (0.0, 0.0), tau) == pytest.approx(u @ u, abs=1e-12)
    assert evaluate(wu + (0.0, 0.0), tau) == pytest.approx(w @ u, abs=1e-12)


def test_scalar_and_batch_algebras_give_the_same_coefficients() -> None:
    """The one formula, on tuples and on (N, 3) rows, gives identical numbers."""
    rng = np.random.default_rng(5)
    rows = [rng.normal(size=(6, 3)) for _ in range(4)]
    rr = rng.uniform(0.0, 0.1, 6)
    batch_caps = cap_quadratics(*rows, rr, BATCH)
    batch_side = side_quartic(*rows, rr, BATCH)
    for i in range(6):
        w0, w1, u0, u1 = (tuple(float(x) for x in row[i]) for row in rows)
        caps = cap_quadratics(w0, w1, u0, u1, float(rr[i]), SCALAR)
        side = side_quartic(w0, w1, u0, u1, float(rr[i]), SCALAR)
        for scalar_part, batch_part in zip(caps + side, batch_caps + batch_side):
            assert scalar_part == pytest.approx([float(b[i]) for b in batch_part], rel=1e-14,
                                                abs=1e-15)
