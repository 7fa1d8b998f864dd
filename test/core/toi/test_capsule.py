"""Tests for the kernel's contact polynomials: one copy, the squared distances they stand for."""

from baseball_collision.core.toi._kernel import cap_quadratics, side_quartic
from hypothesis import given, settings, strategies as st
import numpy as np
from numpy.polynomial import polynomial
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
    knob, tip = cap_quadratics(w0, w1, u0, u1, rr)
    for (a, b, c), p in ((knob, w), (tip, w - u)):
        assert a * tau * tau + b * tau + c == pytest.approx(p @ p - rr, abs=1e-12)
    quartic, uu, wu = side_quartic(w0, w1, u0, u1, rr)
    side = np.cross(w, u) @ np.cross(w, u) - rr * (u @ u)
    assert polynomial.polyval(tau, quartic) == pytest.approx(side, abs=1e-11)
    assert polynomial.polyval(tau, uu) == pytest.approx(u @ u, abs=1e-12)
    assert polynomial.polyval(tau, wu) == pytest.approx(w @ u, abs=1e-12)
