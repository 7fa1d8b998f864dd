"""
A ball in free flight through noisy samples: one low-order polynomial in time per coordinate.

Physics assumed: between release and contact a ball moves under gravity, air drag and a spin
(Magnus) force, and over a few tenths of a second these change slowly: the drag with the square
of a speed that falls by a few per cent, the spin force's direction with the velocity's. So its
acceleration is nearly constant (``degree`` 2: a parabola per coordinate, nine unknowns) or
changes at a nearly constant rate (``degree`` 3: a cubic per coordinate, twelve unknowns). No
drag coefficient, spin, mass or air density is assumed, and gravity is not assumed either (it
is one of the fitted accelerations), so a ball tossed, pitched or launched by a machine fits
alike. What it leaves out is the acceleration's own change (``degree`` 2) or its curvature
(``degree`` 3): for a 40 m/s pitch the drag's rate of change is about 5 m/s^3, a bias of about
``jerk span^3 / 120`` at the window's newest sample for a parabola (0.14 mm over 0.15 s,
1.1 mm over 0.3 s; more carried beyond it).

The fit is ordinary least squares (every sample of a stream has the same noise, so weighting
by it changes nothing but the scale), in time centred and scaled on the window for
conditioning: Householder QR in the compiled kernel (``toi._kernel.flight_fit``, the QR the
prediction's fits use), whose reflectors leave the residuals' sum of squares beside the
coefficients. The solution operator (``FlightFit.solve``, for the uncertainties) is made only
when asked, from the normal equations: on [-1, 1] those of a parabola or a cubic are well
conditioned (condition number 10-65 on evenly spaced samples, at most about 5e4 on stamps
bunched at random), so it gives the coefficients to about 1e-14 relative (1e-11 at worst).

The goodness-of-fit guard (``FlightFit.free``) is a chi-square test of the residuals against
the noise: ``sum (y - f)^2 / sigma^2`` over the three coordinates against the upper
``CHI_SQUARE_Z`` quantile of a chi-square with ``3 (n - degree - 1)`` degrees of freedom
(Wilson-Hilferty's normal approximation). A ball held in a hand, bounced, deflected or swapped
for another mid-window fails it; so does a noise level told too small. Everything is linear in
the samples: ``FlightFit.weights`` gives the value's and rate's weights at a time, for the
uncertainties (the covariance of a coordinate's value is ``sigma^2 |value weights|^2``,
scaled up by the residuals' excess over the noise when they have one: Birge's ratio).
"""

from dataclasses import dataclass
from functools import cached_property
import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from ..toi import _kernel

CHI_SQUARE_Z = 3.09
"""Standard normal quantile of the guard's chi-square test (one-sided p = 0.001)."""


def chi_square_bound(dof: int, z: float = CHI_SQUARE_Z) -> float:
    """
    Return the upper quantile of a chi-square of ``dof`` degrees of freedom at normal quantile z.

    Wilson and Hilferty (1931): (chi2 / dof)^(1/3) is close to normal with mean 1 - 2 / (9 dof)
    and variance 2 / (9 dof); good to about a per cent in the bound from 10 degrees on.

    :raises ValueError: dof < 1.
    """
    if dof < 1:
        raise ValueError(f'a chi-square needs at least one degree of freedom, got {dof}')
    spread = 2.0 / (9.0 * dof)
    return dof * (1.0 - spread + z * math.sqrt(spread)) ** 3


@dataclass(frozen=True)
class FlightFit:
    """
    One polynomial per coordinate fitted to a window of a point's samples.

    :ivar centre, scale: the time axis (s): ``tau = (t - centre) / scale``.
    :ivar coefficients: (degree + 1, 3) in powers of tau (m).
    :ivar times: the window's stamps (s).
    :ivar chi_square: weighted residual sum over the three coordinates (dimensionless).
    :ivar dof: its degrees of freedom, ``3 (n - degree - 1)``.
    """

    centre: float
    scale: float
    coefficients: np.ndarray
    times: Tuple[float, ...]
    chi_square: float
    dof: int

    @cached_property
    def solve(self) -> np.ndarray:
        """
        Return the least-squares operator (degree + 1, n): ``coefficients = solve @ values``.

        From the normal equations (the module docstring), made on first use.
        """
        tau = (np.asarray(self.times) - self.centre) / self.scale
        basis = tau[:, None] ** np.arange(self.degree + 1)[None, :]
        return np.linalg.solve(basis.T @ basis, basis.T)

    @property
    def degree(self) -> int:
        """Return the polynomials' degree."""
        return len(self.coefficients) - 1

    @property
    def free(self) -> bool:
        """Return True when the residuals pass the chi-square test (the module docstring)."""
        return self.passes()

    def passes(self, tolerance: float = 1.0) -> bool:
        """
        Return True when the residuals pass the chi-square test, the noise known to a factor.

        :param tolerance: how far (a factor >= 1) the sigma the fit was given may be below the
            true one (an estimated noise): the bound is raised by its square.
        """
        return self.chi_square <= tolerance * tolerance * chi_square_bound(self.dof)

    @property
    def excess(self) -> float:
        """Return the residuals' excess over the noise (>= 1): sqrt(chi_square / dof)."""
        return max(1.0, math.sqrt(self.chi_square / self.dof))

    def _rows(self, t: float) -> Tuple[List[float], List[float]]:
        """Return the basis at t (s) and its derivative per second, as floats."""
        tau = (t - self.centre) / self.scale
        value, rate = [1.0], [0.0]
        for power in range(1, self.degree + 1):
            rate.append(power * value[-1] / self.scale)
            value.append(value[-1] * tau)
        return value, rate

    @cached_property
    def _columns(self) -> List[List[float]]:
        """Return the coefficients per coordinate, as floats (made once)."""
        return self.coefficients.T.tolist()

    def at(self, t: float) -> Tuple[float, float, float]:
        """Return the fitted position (m) at t (s)."""
        return self.state(t)[0]

    def velocity(self, t: float) -> Tuple[float, float, float]:
        """Return the fitted rate of the position (m/s) at t (s)."""
        return self.state(t)[1]

    def state(self, t: float) -> Tuple[Tuple[float, float, float], Tuple[float, float, float]]:
        """
        Return the fitted position and its rate (m, m/s) at t (s) from one basis row.

        The kernel's (``toi._kernel.flight_state``): ``_rows``' basis, each coordinate's
        coefficients combined with it in order from the lowest power, as ``sum`` adds them.
        """
        return _kernel.flight_state(self._columns, self.centre, self.scale, t)

    def weights(self, t: float) -> Tuple[np.ndarray, np.ndarray]:
        """
        Return each sample's weight (n,) in the fitted value and rate (per s) at t (s).

        The same for each coordinate: value = ``value_weights @ values[:, c]``.
        """
        value, rate = self._rows(t)
        return np.array(value) @ self.solve, np.array(rate) @ self.solve


def fit_flight(times: Sequence[float], values: Sequence[Sequence[float]], sigma: float,
               degree: int = 2) -> FlightFit:
    """
    Return the least-squares polynomials of ``degree`` through a window of point samples.

    :param times: (n,) strictly increasing (s); ``values``: (n, 3) positions (m), an array or
        rows; ``sigma``: the noise per coordinate (m, > 0); ``degree``: 2 or 3 (the module
        docstring).
    :raises ValueError: fewer than ``degree + 2`` samples, shapes that do not match, a sigma
        that is not positive, times that do not increase, or stamps so bunched that the fit
        is rank deficient.
    """
    fit = _fitted(times, values, sigma, degree)
    if fit is None:
        raise ValueError('the stamps are too bunched for a flight fit (rank deficient)')
    return fit


def flight_or_none(times: Sequence[float], values: Sequence[Sequence[float]], sigma: float,
                   degree: int, min_samples: int, tolerance: float = 1.0) -> Optional[FlightFit]:
    """
    Return the flight fit of a window when it has ``min_samples`` and passes the guard, or None.

    None too where the stamps are too bunched for a fit (``fit_flight``'s rank deficiency).

    :param times, values, sigma, degree: as for ``fit_flight``; ``tolerance``: as for
        ``FlightFit.passes``.
    :raises ValueError: as ``fit_flight``, but for the rank deficiency.
    """
    if len(times) < max(min_samples, degree + 2):
        return None
    fit = _fitted(times, values, sigma, degree)
    return fit if fit is not None and fit.passes(tolerance) else None


def _fitted(times: Sequence[float], values: Sequence[Sequence[float]], sigma: float,
            degree: int) -> Optional[FlightFit]:
    """Return ``fit_flight``'s fit, or None where the kernel finds it rank deficient."""
    if not sigma > 0.0:
        raise ValueError(f'sigma must be positive, got {sigma!r}')
    times = times.tolist() if isinstance(times, np.ndarray) else list(times)
    if isinstance(values, np.ndarray):
        if values.ndim != 2:
            raise ValueError(f'values {values.shape} do not match {len(times)} stamps')
        values = values.tolist()
    found = _kernel.flight_fit(times, values, degree)
    if found is NotImplemented:
        return None
    centre, scale, coefficients, residual = found
    variance = sigma * sigma  # (0 under 1e-154 m: beyond any residual, the guard turns it away)
    return FlightFit(centre, scale, np.array(coefficients), tuple(times),
                     residual / variance if variance > 0.0 else math.inf,
                     3 * (len(times) - degree - 1))
