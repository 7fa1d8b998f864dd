"""Tests for the kernel's polynomial building blocks: the derivative chain, roots, cap entry."""

import math

from baseball_collision.core.toi._kernel import (
    bracketed_root, critical_points, quadratic_entry, quadratic_roots, touch_candidates)
from hypothesis import given, settings, strategies as st
import numpy as np
from numpy.polynomial import polynomial
import pytest
from support import examples

coefficient = st.floats(-10.0, 10.0, allow_nan=False)
quartic = st.tuples(*[coefficient] * 5)

NO_SLACK = (0.0, (1.0, 0.0, 0.0, 0.0, 0.0))
"""A slack of zero everywhere: ``touch_candidates``' (scale, polynomial)."""


def _values(c, xs: np.ndarray) -> np.ndarray:
    """Evaluate the quartic c (lowest power first) with numpy: the independent reference."""
    return polynomial.polyval(xs, c)


def test_quadratic_roots_are_stable_and_ordered() -> None:
    """Roots of a x^2 + b x + c, ascending; lines and no-root cases too."""
    assert quadratic_roots(1.0, -3.0, 2.0) == [1.0, 2.0]
    assert quadratic_roots(1.0, 0.0, 1.0) == []
    assert quadratic_roots(0.0, 2.0, -1.0) == [0.5]
    assert quadratic_roots(0.0, 0.0, 1.0) == []
    small, large = quadratic_roots(1.0, -1e8, 1.0)  # cancellation-prone in the naive form
    assert small == pytest.approx(1e-8, rel=1e-12) and large == pytest.approx(1e8)


def test_bracketed_root_reaches_double_precision() -> None:
    """A monotone polynomial's sign change (x^2 - 0.5, and its derivative's) to the last bits."""
    root = bracketed_root((-0.5, 0.0, 1.0, 0.0, 0.0), 0, 0.0, 1.0, -0.5)
    assert root == pytest.approx(math.sqrt(0.5), abs=2e-16)
    # order 1: the root of the derivative 3 x^2 - 0.75 of x^3 - 0.75 x
    turn = bracketed_root((0.0, -0.75, 0.0, 1.0, 0.0), 1, 0.0, 1.0, -0.75)
    assert turn == pytest.approx(0.5, abs=2e-16)


def test_critical_points_of_a_known_quartic() -> None:
    """(x - 0.25)(x - 0.5)(x - 0.75) x integrated: extrema where its derivative vanishes."""
    # p'(x) = 4 (x - 0.2)(x - 0.5)(x - 0.8) => p = x^4 - 2 x^3 + 1.32 x^2 - 0.32 x
    c = (0.0, -0.32, 1.32, -2.0, 1.0)
    assert critical_points(c) == pytest.approx([0.2, 0.5, 0.8], abs=1e-15)


def test_a_double_root_is_a_touch() -> None:
    """
    Find (x - 0.5)^2 touching zero without crossing (numpy.roots loses it).

    A double root is only good to about sqrt(machine epsilon).
    """
    slack = (1e-18, (1.0, 0.0, 0.0, 0.0, 0.0))
    found = touch_candidates((0.25, -1.0, 1.0, 0.0, 0.0), *slack)
    assert found == pytest.approx([0.5], abs=1e-7)
    assert touch_candidates((0.25 + 1e-6, -1.0, 1.0, 0.0, 0.0), *slack) == []


def test_touch_candidates_start_with_zero_when_touching() -> None:
    """Already at or below zero at the start: the first candidate is 0."""
    assert touch_candidates((-1.0, 1.0, 0.0, 0.0, 0.0), *NO_SLACK)[0] == 0.0


def test_the_slack_is_a_polynomial_times_a_scale() -> None:
    """A local minimum counts when within scale * slack_poly(x) of zero there, and only then."""
    c = (0.25 + 1e-3, -1.0, 1.0, 0.0, 0.0)  # minimum 1e-3 at 0.5
    assert touch_candidates(c, 1e-3, (0.0, 0.0, 4.4, 0.0, 0.0)) == [0.5]  # 1.1e-3 there
    assert touch_candidates(c, 1e-3, (0.0, 0.0, 3.6, 0.0, 0.0)) == []


@settings(max_examples=examples(300), deadline=None)
@given(c=quartic)
def test_first_candidate_is_the_first_crossing(c) -> None:
    """No sampled point before the first candidate is <= 0; the candidate itself is ~0 or less."""
    found = touch_candidates(c, *NO_SLACK)
    xs = np.linspace(0.0, 1.0, 2001)
    values = _values(c, xs)
    if not found:
        assert np.all(values > -1e-9)
        return
    assert found == sorted(found) and all(0.0 <= x <= 1.0 for x in found)
    first = found[0]
    assert np.all(values[xs < first - 1e-9] > -1e-9)
    assert _values(c, first) <= 1e-9 * (1.0 + sum(abs(v) for v in c))


@settings(max_examples=examples(200), deadline=None)
@given(c=quartic)
def test_critical_points_split_into_monotone_pieces(c) -> None:
    """Between consecutive critical points (and 0, 1) the derivative keeps one sign (sampled)."""
    cuts = [0.0] + critical_points(c) + [1.0]
    assert cuts == sorted(cuts)
    slope = polynomial.polyder(c)
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        if hi - lo < 1e-6:
            continue
        slopes = polynomial.polyval(np.linspace(lo, hi, 41)[1:-1], slope)
        scale = 1e-9 * (1.0 + sum(abs(v) for v in c))
        assert np.all(slopes >= -scale) or np.all(slopes <= scale)


@settings(max_examples=examples(300), deadline=None)
@given(a=st.floats(0.0, 10.0), b=coefficient, c=coefficient, slack=st.floats(0.0, 0.1))
def test_quadratic_entry_is_the_first_contact(a: float, b: float, c: float,
                                              slack: float) -> None:
    """
    The closed-form cap entry against sampling: nothing earlier is <= 0, it is a contact.

    As for a cap, a = |w1|^2 = 0 only with b = 2 w0.w1 = 0 (a line is not a cap's form).
    """
    if a == 0.0:
        b = 0.0
    entry = quadratic_entry(a, b, c, slack)
    xs = np.linspace(0.0, 1.0, 2001)
    values = a * xs * xs + b * xs + c
    scale = 1e-9 * (1.0 + abs(a) + abs(b) + abs(c))
    if entry is None:
        assert np.all(values > -scale)
        return
    assert 0.0 <= entry <= 1.0
    assert np.all(values[xs < entry - 1e-9] > -scale)
    assert a * entry * entry + b * entry + c <= slack + scale
