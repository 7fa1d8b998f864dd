"""Tests for the bat's forecast from a window of its frames: the noise it carries."""

import math

from baseball_collision.core.detector.bat_window import noise_gain
import pytest


def test_the_noise_gain_is_the_forecasts_weights_norm() -> None:
    """
    A cubic through four evenly spaced samples forecasts by Lagrange's weights.

    One step on: 4, -6, 4, -1 (``sqrt(1 + 69)``); two steps on, across a lost one: 10, -20, 15,
    -4 (``sqrt(1 + 741)``), the same at any step size. More samples than the degree smooth it.
    """
    assert noise_gain([0.0, 1.0, 2.0, 3.0], 4.0, 3) == pytest.approx(math.sqrt(70.0))
    step = 1.0 / 90.0
    assert noise_gain([0.0, step, 2 * step, 3 * step], 5 * step, 3) == pytest.approx(
        math.sqrt(742.0))
    assert noise_gain([0.0, 1.0, 2.0, 3.0, 4.0], 5.0, 3) < math.sqrt(70.0)
