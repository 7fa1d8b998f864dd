"""
The bat's forecast from a window of its frames, as the predictor fits it.

The fit's degree (``PREDICTION_DEGREE``), the step rows a stream keeps for it (``STEP_ROWS``),
how far a newest frame lands from the forecast of the frames before it (``newest_miss``) and
how much of the frames' noise such a forecast carries (``noise_gain``). Shared by the forecast
(``predictor``), its judgment of the newest bat frames (``bat_judgment``) and a chunk's plan
(``plan_prediction``), so that all three read the same fit, to the bit.
"""

import math
from typing import List, Sequence

import numpy as np

from ..prediction import bat_window_numbers, states_of

STEP_ROWS = 'step_rows'
"""A bat stream's ``aligned`` list of knob + tip + the turn from the sample before, per sample
(``prediction.bat_window_numbers``)."""

PREDICTION_DEGREE = 3
"""Largest degree of the bat fits behind a prediction: it extrapolates tens of milliseconds,
where higher degrees amplify tracking noise (at 90 Hz with 1 mm noise they lose the swing)."""


def noise_gain(times: Sequence[float], t: float, degree: int) -> float:
    """
    Return how many times a sample's noise (1 sigma) a forecast's miss of a sample at t carries.

    The forecast: from the last of ``times`` (s) on, by the least-squares polynomial of
    ``degree`` through the samples at ``times`` (as ``prediction.bat_window_numbers``
    extrapolates a bat: the newest sample plus the fit's change since its stamp), so it is
    a sum of those samples by weights w; its miss of a new sample at t (s) with the same
    independent noise has ``sqrt(1 + sum w^2)`` times that noise. A rank-deficient fit takes
    the least-norm solution, as LAPACK does.
    """
    last = times[-1]
    design = np.vander([u - last for u in times], degree + 1, increasing=True)
    change = np.array([(t - last) ** m for m in range(degree + 1)])
    change[0] = 0.0  # (the fit's change since the last sample: the sample itself is added)
    weights = change @ np.linalg.pinv(design)
    weights[-1] += 1.0
    return math.sqrt(1.0 + float(weights @ weights))


def newest_miss(times: List[float], values: List, rows: List, first: int, end: int,
                degree: int) -> float:
    """
    Return how far (m) bat sample end - 1 is from the forecast of samples [first, end - 1).

    The larger of the knob's and the tip's distances; the forecast ``bat_window_numbers``' of
    ``degree`` (``rows``: the stream's step rows, or a list of the caller's: the same bits), at
    sample end - 1's time (s). 0 where the fit would read fewer than 3 samples or is rank
    deficient. The predictor's (``Predictor._bat_miss``) and a chunk's plan's
    (``plan_prediction``) on the same samples.
    """
    if end - 1 - first < 3:
        return 0.0
    before = bat_window_numbers(times, values, rows, first, end - 1, degree)
    if before is None:
        return 0.0
    knob, tip = states_of(None, before, times[end - 1])[2:]
    newest = values[end - 1]
    return max(math.dist(knob, newest.knob), math.dist(tip, newest.tip))
