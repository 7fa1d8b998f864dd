"""
The plain reference every motion model is measured against: a cubic spline per coordinate.

Pure numpy, no detector. The knob, tip and ball coordinates of a whole simulated pitch are
each fitted by one spline over all their samples, across the contact (this reference is not
bound by the detector's rules): without noise a not-a-knot cubic interpolating spline; with
noise ``sigma`` (known) the natural cubic smoothing spline of Reinsch (1967), its smoothing
chosen so that the residuals are the noise, ``sum ((y - S) / sigma)^2 = n``. The first contact
of the two fitted motions is then found exactly as the simulator's truth is (dense evaluation,
refinement, bisection: ``sim.compute_truth``), and the velocities are the splines'
derivatives at it. ``reference_result`` scores one pitch like ``accuracy.compare_pitch``.
"""

from typing import Tuple

import numpy as np

from .accuracy import PitchResult
from .sim import compute_truth, Samples, Scenario, TimeLike, Truth
from .sim.common import cubic_hermite
from ..core.bat import SWEET_SPOT_FROM_TIP
from ..core.motion import not_a_knot_slopes
from ..core.motion.smoothing import natural_parts


def _hermite(times: np.ndarray, values: np.ndarray, slopes: np.ndarray, t: np.ndarray,
             derivative: bool) -> np.ndarray:
    """Return the piecewise cubic Hermite (or its derivative) at times t: (len(t), columns)."""
    k = np.clip(np.searchsorted(times, t, side='right') - 1, 0, len(times) - 2)
    h = (times[k + 1] - times[k])[:, None]
    u = (t - times[k])[:, None]
    u = u / h
    return cubic_hermite(u, values[k], values[k + 1], slopes[k] * h, slopes[k + 1] * h, h,
                         derivative)


def smoothing_spline(times: np.ndarray, values: np.ndarray,
                     sigma: float) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return (values, slopes) at the knots of Reinsch's natural cubic smoothing spline.

    Each column is smoothed on its own, its weight found by bisection on a log scale so that
    ``sum ((y - S) / sigma)^2 = n``.
    """
    n = len(times)
    h = np.diff(times)
    q, r = natural_parts(h)
    fitted, slopes = np.empty_like(values), np.empty_like(values)
    for column in range(values.shape[1]):
        y = values[:, column]
        low, high = -30.0, 30.0  # log10 of the weight sigma^2 / p on the roughness
        for _ in range(60):
            middle = 0.5 * (low + high)
            gamma = np.linalg.solve(r + 10.0 ** middle * q.T @ q, q.T @ y)
            smooth = y - 10.0 ** middle * q @ gamma
            if np.sum(((y - smooth) / sigma) ** 2) > n:
                high = middle
            else:
                low = middle
        gamma = np.linalg.solve(r + 10.0 ** low * q.T @ q, q.T @ y)
        smooth = y - 10.0 ** low * q @ gamma
        moments = np.concatenate([[0.0], gamma, [0.0]])
        slope = np.empty(n)
        slope[:-1] = np.diff(smooth) / h - h * (2.0 * moments[:-1] + moments[1:]) / 6.0
        slope[-1] = (smooth[-1] - smooth[-2]) / h[-1] + h[-1] * (
            moments[-2] + 2.0 * moments[-1]) / 6.0
        fitted[:, column], slopes[:, column] = smooth, slope
    return fitted, slopes


class _Fitted:
    """Splines through one body's samples (each column a coordinate)."""

    def __init__(self, times: np.ndarray, values: np.ndarray, sigma: float) -> None:
        self.times = times
        if sigma > 0.0:
            self.values, self.slopes = smoothing_spline(times, values, sigma)
        else:
            self.values, self.slopes = values, not_a_knot_slopes(times, values)

    def at(self, t: TimeLike, derivative: bool = False) -> np.ndarray:
        """Return the fitted coordinates (or rates) at scenario times t: t.shape + (columns,)."""
        array = np.asarray(t, dtype=float)
        out = _hermite(self.times, self.values, self.slopes,
                       np.clip(array.reshape(-1), self.times[0], self.times[-1]), derivative)
        return out.reshape(array.shape + (self.values.shape[1],))


class SplineBat:
    """Knob and tip as fitted splines, answering what ``sim.compute_truth`` asks of a swing."""

    def __init__(self, times: np.ndarray, knobs: np.ndarray, tips: np.ndarray,
                 sigma: float) -> None:
        self.ends = _Fitted(times, np.hstack([knobs, tips]), sigma)
        self.length = float(np.mean(np.linalg.norm(tips - knobs, axis=1)))

    def knob_tip(self, t: TimeLike) -> Tuple[np.ndarray, np.ndarray]:
        """Return (knob, tip) in metres at scenario time(s) t."""
        both = self.ends.at(t)
        return both[..., :3], both[..., 3:]

    def point_velocity(self, t: TimeLike, fraction: float) -> np.ndarray:
        """Return the velocity (m/s) of the axis point at ``fraction``: the splines' rates."""
        rates = self.ends.at(t, derivative=True)
        return rates[..., :3] + float(fraction) * (rates[..., 3:] - rates[..., :3])

    def sweet_spot_fraction(self) -> float:
        """Return the fraction of the point 6 in from the tip."""
        return 1.0 - SWEET_SPOT_FROM_TIP / self.length


class SplineBall:
    """The ball as a fitted spline, answering what ``sim.compute_truth`` asks of a pitch."""

    def __init__(self, times: np.ndarray, positions: np.ndarray, sigma: float) -> None:
        self.path = _Fitted(times, positions, sigma)
        self.release_time, self.end_time = float(times[0]), float(times[-1])

    def position(self, t: TimeLike) -> np.ndarray:
        """Return the centre (m) at scenario time(s) t."""
        return self.path.at(t)

    def velocity(self, t: TimeLike) -> np.ndarray:
        """Return how fast the ball moves (a vector, m/s) at scenario time(s) t."""
        return self.path.at(t, derivative=True)


def reference_truth(scenario: Scenario, samples: Samples, noise_m: float = 0.0) -> Truth:
    """
    Return what the plain per-coordinate cubic splines say happened (a ``sim.Truth``).

    The bat comes as knob and tip points (``samples.knobs``, ``samples.tips``) and shares the
    ball's stamps; ``noise_m`` is the known noise (0: interpolate).
    """
    times = (samples.ball_stamps_ns - samples.start_ns) * 1e-9
    bat_times = (samples.bat_stamps_ns - samples.start_ns) * 1e-9
    ball = SplineBall(times, samples.ball_positions, noise_m)
    bat = SplineBat(bat_times, samples.knobs, samples.tips, noise_m)
    ball.release_time = min(0.0, ball.release_time)
    ball.end_time = max(scenario.t_end, ball.end_time)
    return compute_truth(bat, ball, scenario.t_end, scenario.profile, scenario.ball_radius)


def reference_result(scenario: Scenario, samples: Samples, noise_m: float = 0.0) -> PitchResult:
    """
    Score the reference on one pitch as ``accuracy.compare_pitch`` scores the detector.

    A contact of the fitted motions stands for an impact (a miss's is a false impact); its
    time, spot and sweet-spot speed are compared with the scenario's truth.
    """
    truth, found = scenario.truth, reference_truth(scenario, samples, noise_m)
    common = {'name': scenario.name, 'kind': scenario.kind, 'contact': truth.contact,
              'clearance_m': abs(truth.min_gap_m)}
    if not truth.contact:
        return PitchResult(detected=found.contact, false_impacts=int(found.contact), **common)
    if not found.contact:
        return PitchResult(detected=False, false_impacts=0, **common)
    return PitchResult(
        detected=True, false_impacts=0, time_error_s=found.time_s - truth.time_s,
        location_error_m=found.distance_from_tip_m - truth.distance_from_tip_m,
        sweet_spot_speed_error=found.sweet_spot_speed_mps / truth.sweet_spot_speed_mps - 1.0,
        **common)
