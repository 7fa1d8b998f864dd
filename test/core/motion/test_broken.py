"""Tests for the window splines broken at an instant (issue 11's contact-aware fit)."""

from baseball_collision.core.motion.broken import broken_fit, broken_knots
from baseball_collision.core.motion.smoothing import penalty, third_jumps
from baseball_collision.core.motion.splines import end_state, not_a_knot_slopes
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples

steps = st.lists(st.floats(0.003, 0.012), min_size=9, max_size=14)
cubics = st.lists(st.floats(-30.0, 30.0), min_size=4, max_size=4)


def _times(steps) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(steps)])


def _kinked(times: np.ndarray, t_break: float, left, right) -> np.ndarray:
    """Return samples of two cubics in (t - t_break) meeting at t_break (values equal there)."""
    x = times - t_break
    right = [left[0]] + list(right[1:])
    pick = [np.polyval(list(reversed(c)), x) for c in (left, right)]
    return np.where(x <= 0.0, pick[0], pick[1])[:, None]


@settings(max_examples=examples(60), deadline=None)
@given(steps=steps, left=cubics, right=cubics, where=st.floats(0.05, 0.95))
def test_a_velocity_kink_at_the_break_is_reproduced_exactly(steps, left, right, where) -> None:
    """
    Two cubics meeting at t* with any velocity jump: the left cubic's value and rate at t*.

    Four samples or more on each side: the right side cannot bend the left-limit rate.
    """
    times = _times(steps)
    k = len(times) - 5  # four samples after the break's interval
    t_break = times[k] + where * (times[k + 1] - times[k])
    values = _kinked(times, t_break, left, right)
    knots, fitted, slopes = broken_fit(times, values, [0.0], t_break)
    scale = 1.0 + float(np.max(np.abs(values)))
    assert knots[-1] == t_break
    assert fitted[-1, 0] == pytest.approx(left[0], abs=1e-6 * scale)
    assert slopes[-1, 0] == pytest.approx(left[1], abs=1e-4 * scale / (times[-1] - times[0]))


@settings(max_examples=examples(40), deadline=None)
@given(steps=steps, left=cubics, right=cubics, where=st.floats(0.05, 0.95))
def test_the_value_at_the_break_is_the_least_rough_one(steps, left, right, where) -> None:
    """
    Brute force: the fitted value at t* minimises both sides' penalties.

    The penalty is a parabola in it, found from three trial values; the samples are kept.
    """
    times = _times(steps)
    k = len(times) - 6
    t_break = times[k] + where * (times[k + 1] - times[k])
    values = _kinked(times, t_break, left, right)[:, 0] + np.sin(40.0 * times)  # not cubic
    knots, star, inserted = broken_knots(times, t_break)
    assert inserted

    def roughness(value: float) -> float:
        f = np.insert(values, star, value)
        sides = (knots[:star + 1], f[:star + 1]), (knots[star:], f[star:])
        return sum(float(side @ penalty(t, 'not-a-knot') @ side) / np.mean(np.diff(t)) ** 6
                   for t, side in sides)

    trials = np.array([-1.0, 0.0, 1.0])
    costs = [roughness(x) for x in trials]
    curvature = costs[0] - 2.0 * costs[1] + costs[2]
    best = 0.5 * (costs[0] - costs[2]) / curvature
    fitted = broken_fit(times, values[:, None], [0.0], t_break)[1][-1, 0]
    assert fitted == pytest.approx(best, abs=1e-6 * (1.0 + abs(best)))


def test_without_samples_after_the_break_the_left_spline_is_continued() -> None:
    """
    One sample after t* constrains nothing: the spline before it is continued.

    With four knots or fewer on each side neither side's penalty holds the value at t*.
    """
    times = np.array([0.0, 0.011, 0.021, 0.032])
    values = np.c_[np.cos(20.0 * times)]
    t_break = 0.025
    fitted = broken_fit(times, values, [0.0], t_break)[1][-1]
    assert np.allclose(fitted, end_state(times[:3], values[:3], t_break)[0])


@settings(max_examples=examples(40), deadline=None)
@given(steps=steps, where=st.floats(0.05, 0.95), sigma=st.sampled_from([0.0, 1e-3]))
def test_one_sample_after_the_break_changes_nothing(steps, where, sigma) -> None:
    """
    The fit broken after the last sample is the fit with one more sample after the break.

    A right side of two knots is any line: that sample pins nothing, exact or smoothed. Exact,
    each number to 1e-7 of itself; smoothed, to 1e-7 of the largest of its kind: the smoother
    solves a larger system with the extra sample, and its rounding is relative to the fit's
    scale (a slope of 0.2 beside slopes of 30 differed by 5e-8; the worst of 4,000 random
    draws, 7.9e-9 of the scale).
    """
    times = _times(steps)
    values = np.c_[np.sin(30.0 * times), times ** 4] + np.random.default_rng(len(steps)).normal(
        0.0, sigma, (len(times), 2))
    t_break = times[-2] + where * (times[-1] - times[-2])
    alone = broken_fit(times[:-1], values[:-1], [sigma ** 2] * 2, t_break)
    with_after = broken_fit(times, values, [sigma ** 2] * 2, t_break)
    for a, b in zip(alone, with_after):
        if sigma == 0.0:
            assert np.allclose(a, b, rtol=1e-7, atol=1e-9)
        else:
            assert np.abs(a - b).max() <= 1e-7 * max(1.0, np.abs(b).max())


def test_a_break_at_a_sample_is_no_knot_of_its_own() -> None:
    """t* on a sample: the left spline ends at that sample, its value kept."""
    times = np.linspace(0.0, 0.1, 11)
    values = np.c_[times ** 3, np.sin(times)]
    knots, fitted, slopes = broken_fit(times, values, [0.0, 0.0], times[6])
    assert len(knots) == 7 and np.array_equal(fitted, values[:7])
    assert np.allclose(slopes, not_a_knot_slopes(times[:7], values[:7]))


def test_noise_is_smoothed_and_the_kink_survives() -> None:
    """
    With noise the left-limit rate stays near the left motion's, not the braked right's.

    Over 200 draws its mean is within a few standard errors of the truth.
    """
    rng = np.random.default_rng(11)
    times = np.cumsum(rng.uniform(0.008, 0.014, 16))
    t_break = times[10] + 0.004
    clean = _kinked(times, t_break, [0.5, 30.0, 40.0, -200.0], [0.5, 12.0, 0.0, 0.0])
    rates = [broken_fit(times, clean + rng.normal(0.0, 1e-3, clean.shape), [1e-6],
                        t_break)[2][-1, 0] for _ in range(200)]
    assert abs(np.mean(rates) - 30.0) < 4.0 * np.std(rates) / np.sqrt(len(rates)) + 0.05
    assert np.std(rates) < 1.0  # m/s: smoothed (the samples' own differences spread ~0.15 m/s
    # per 1 mm over a step; 12 m/s would be the braked side)


def test_third_jumps_factor_the_penalty() -> None:
    """``penalty`` (not-a-knot) is J^T J of ``third_jumps`` scaled by the mean step cubed."""
    times = np.cumsum(np.random.default_rng(3).uniform(0.003, 0.012, 12))
    jumps = third_jumps(times) * float(np.mean(np.diff(times))) ** 3
    assert np.allclose(penalty(times, 'not-a-knot'), jumps.T @ jumps)
    assert third_jumps(times[:4]).shape == (0, 4)


def test_bad_input_is_refused() -> None:
    """A break outside the samples or mismatched shapes raise ValueError."""
    times = np.linspace(0.0, 0.1, 8)
    with pytest.raises(ValueError):
        broken_fit(times, np.zeros((8, 1)), [0.0], float('nan'))
    with pytest.raises(ValueError):
        broken_fit(times, np.zeros((8, 1)), [0.0], 0.0)
    with pytest.raises(ValueError):
        broken_fit(times, np.zeros((7, 1)), [0.0], 0.05)
