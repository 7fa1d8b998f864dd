"""
The swing angle over time: a skewed Gaussian angular-speed profile and a brake after contact.

Closed forms (exact derivatives), in seconds and radians, on arrays of times. The angular speed
is ``peak * exp(-z^2 / 2) * (1 + skew * z)`` with ``z = (t - peak_time) / width``: a Gaussian
(``skew = 0``, today's swings) or one whose angular acceleration changes faster on one side
(angular jerk). A brake multiplies it by ``1 - fraction * r((t - brake_time) / duration)``,
``r`` the smoothstep ``3u^2 - 2u^3`` from 0 to 1: a bat losing that fraction of its angular
speed over ``duration`` after a contact, as a real one does. The braked angle's integral over
the ramp is a 16-point Gauss-Legendre sum (its integrand is smooth on the ramp: exact to
round-off); past the ramp it is closed form.
"""

from dataclasses import dataclass
import math
from typing import Optional

import numpy as np

from .common import erf, SQRT_HALF_PI, SQRT_TWO

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(16)


def _ramp(u: np.ndarray) -> np.ndarray:
    """Return the smoothstep 3u^2 - 2u^3 of u clipped to [0, 1]."""
    u = np.clip(u, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


@dataclass(frozen=True)
class AngleProfile:
    """
    A swing angle theta(t) (rad), 0 at ``reference_time``, and its rate (rad/s).

    :ivar peak: peak angular speed of the unbraked profile (rad/s).
    :ivar peak_time: when (s); ``width``: its standard deviation (s).
    :ivar skew: the (1 + skew z) factor: 0 for a Gaussian.
    :ivar reference_time: where the angle is 0 (s).
    :ivar brake_time: when the brake starts (s), None for none.
    :ivar brake_fraction: fraction of the angular speed it takes away (0-1).
    :ivar brake_duration: the ramp's length (s).
    """

    peak: float
    peak_time: float
    width: float
    skew: float = 0.0
    reference_time: float = 0.0
    brake_time: Optional[float] = None
    brake_fraction: float = 0.0
    brake_duration: float = 0.002

    def _free_angle(self, times: np.ndarray) -> np.ndarray:
        """Return the unbraked angle at times (relative to the reference)."""
        scale = 1.0 / (self.width * SQRT_TWO)
        amplitude = self.peak * self.width * SQRT_HALF_PI
        origin = math.erf((self.reference_time - self.peak_time) * scale)
        angle = amplitude * (erf((times - self.peak_time) * scale) - origin)
        if self.skew:
            z_ref = (self.reference_time - self.peak_time) / self.width
            z = (times - self.peak_time) / self.width
            angle = angle + self.skew * self.peak * self.width * (
                math.exp(-0.5 * z_ref * z_ref) - np.exp(-0.5 * z * z))
        return angle

    def _free_rate(self, times: np.ndarray) -> np.ndarray:
        """Return the unbraked angular speed at times."""
        z = (times - self.peak_time) / self.width
        rate = self.peak * np.exp(-0.5 * z * z)
        return rate * (1.0 + self.skew * z) if self.skew else rate

    def angle(self, times: np.ndarray) -> np.ndarray:
        """Return theta at times (N,) s: (N,) rad."""
        angle = self._free_angle(times)
        if self.brake_time is None or not self.brake_fraction:
            return angle
        start, duration = self.brake_time, self.brake_duration
        after = times > start
        if not np.any(after):
            return angle
        # the angle the brake took away: fraction * integral of ramp * free rate since start
        ends = np.minimum(times[after], start + duration)
        half = 0.5 * (ends - start)
        nodes = start + half[:, None] * (1.0 + _NODES[None, :])
        inside = ((_ramp((nodes - start) / duration) * self._free_rate(nodes.ravel()).reshape(
            nodes.shape)) @ _WEIGHTS) * half
        beyond = np.where(times[after] > start + duration,
                          self._free_angle(times[after]) - self._free_angle(ends), 0.0)
        lost = np.zeros_like(angle)
        lost[after] = self.brake_fraction * (inside + beyond)
        return angle - lost

    def rate(self, times: np.ndarray) -> np.ndarray:
        """Return theta' at times (N,) s: (N,) rad/s."""
        rate = self._free_rate(times)
        if self.brake_time is None or not self.brake_fraction:
            return rate
        return rate * (1.0 - self.brake_fraction * _ramp(
            (times - self.brake_time) / self.brake_duration))
