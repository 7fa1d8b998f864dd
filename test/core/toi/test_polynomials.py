"""Tests for baseball_collision.core.toi.polynomials: the derivative chain, scalar and batch."""

import math

from baseball_collision.core.toi.polynomials import (
    bracketed_root, critical_points, evaluate, evaluate_batch, evaluate_d1, monotone_bounds_batch,
    quadratic_entry, quadratic_entry_batch, quadratic_roots, touch_candidates,
    touch_candidates_batch)
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples

coefficient = st.floats(-10.0, 10.0, allow_nan=False)
quartic = st.tuples(*[coefficient] * 5)
grid_quartic = st.tuples(*[st.integers(-1000, 1000).map(lambda k: k / 100.0)] * 5)
"""Quartics with coefficients on a 0.01 grid: no denormal corner where siblings round apart."""


def _no_slack(x: float) -> float:
    return 0.0


def test_quadratic_roots_are_stable_and_ordered() -> None:
    """Roots of a x^2 + b x + c, ascending; lines and no-root cases too."""
    assert quadratic_roots(1.0, -3.0, 2.0) == [1.0, 2.0]
    assert quadratic_roots(1.0, 0.0, 1.0) == []
    assert quadratic_roots(0.0, 2.0, -1.0) == [0.5]
    assert quadratic_roots(0.0, 0.0, 1.0) == []
    small, large = quadratic_roots(1.0, -1e8, 1.0)  # cancellation-prone in the naive form
    assert small == pytest.approx(1e-8, rel=1e-12) and large == pytest.approx(1e8)


def test_bracketed_root_reaches_double_precision() -> None:
    """A monotone function's sign change is found to the last bits."""
    root = bracketed_root(lambda x: x * x - 0.5, lambda x: 2.0 * x, 0.0, 1.0, -0.5)
    assert root == pytest.approx(math.sqrt(0.5), abs=2e-16)


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
    found = list(touch_candidates((0.25, -1.0, 1.0, 0.0, 0.0), lambda x: 1e-18))
    assert found == pytest.approx([0.5], abs=1e-7)
    assert list(touch_candidates((0.25 + 1e-6, -1.0, 1.0, 0.0, 0.0), lambda x: 1e-18)) == []


def test_touch_candidates_start_with_zero_when_touching() -> None:
    """Already at or below zero at the start: the first candidate is 0."""
    assert next(touch_candidates((-1.0, 1.0, 0.0, 0.0, 0.0), _no_slack)) == 0.0


@settings(max_examples=examples(300), deadline=None)
@given(c=quartic)
def test_first_candidate_is_the_first_crossing(c) -> None:
    """No sampled point before the first candidate is <= 0; the candidate itself is ~0 or less."""
    found = list(touch_candidates(c, _no_slack))
    xs = np.linspace(0.0, 1.0, 2001)
    values = np.array([evaluate(c, x) for x in xs])
    if not found:
        assert np.all(values > -1e-9)
        return
    first = found[0]
    assert np.all(values[xs < first - 1e-9] > -1e-9)
    assert evaluate(c, first) <= 1e-9 * (1.0 + sum(abs(v) for v in c))


@settings(max_examples=examples(200), deadline=None)
@given(rows=st.lists(grid_quartic, min_size=1, max_size=8))
def test_batch_candidates_match_the_scalar_ones(rows) -> None:
    """Batch and scalar siblings find the same candidate times."""
    c = np.array(rows)
    batch = touch_candidates_batch(c, lambda x: np.zeros_like(x))
    for row, got in zip(rows, batch):
        expected = list(touch_candidates(row, _no_slack))
        picked = sorted(set(np.round(got[~np.isnan(got)], 9)))
        assert picked == pytest.approx(sorted(set(np.round(expected, 9))), abs=2e-9)


@settings(max_examples=examples(200), deadline=None)
@given(rows=st.lists(quartic, min_size=1, max_size=8))
def test_monotone_bounds_split_into_monotone_pieces(rows) -> None:
    """Between consecutive bounds the derivative keeps one sign (sampled)."""
    bounds = monotone_bounds_batch(np.array(rows))
    for row, cuts in zip(rows, bounds):
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            if hi - lo < 1e-6:
                continue
            slopes = [evaluate_d1(row, x) for x in np.linspace(lo, hi, 41)[1:-1]]
            scale = 1e-9 * (1.0 + sum(abs(v) for v in row))
            assert all(s >= -scale for s in slopes) or all(s <= scale for s in slopes)


@settings(max_examples=examples(300), deadline=None)
@given(a=st.floats(0.0, 10.0), b=coefficient, c=coefficient, slack=st.floats(0.0, 0.1))
def test_quadratic_entry_batch_matches_scalar(a: float, b: float, c: float,
                                              slack: float) -> None:
    """The closed-form cap entry agrees between siblings (inf for None)."""
    scalar = quadratic_entry(a, b, c, slack)
    with np.errstate(over='ignore', invalid='ignore'):  # a denormal a overflows b / a
        batch = quadratic_entry_batch(np.array([a]), np.array([b]), np.array([c]),
                                      np.array([slack]))[0]
    assert (math.inf if scalar is None else scalar) == batch


def test_evaluate_batch_matches_scalar_for_vectors_and_grids() -> None:
    """(N,) and (N, K) evaluation points give the scalar values."""
    rng = np.random.default_rng(1)
    c = rng.normal(size=(4, 5))
    x = rng.uniform(size=(4, 3))
    grid = evaluate_batch(c, x)
    row = evaluate_batch(c, x[:, 0])
    for i in range(4):
        assert row[i] == evaluate(c[i], x[i, 0])
        assert list(grid[i]) == [evaluate(c[i], v) for v in x[i]]
