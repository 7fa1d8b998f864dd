"""
The seed derivation's own method and its gap to the infinite line, kept for comparison.

Do not use them to find impacts: ``time_of_impact`` is exact where these fail (see
``seed_time_of_impact``).
"""

from typing import Optional

import numpy as np

from .batch import positions_at
from .result import ArrayLike


def line_distance(t: ArrayLike, ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike,
                  tip1: ArrayLike, knob0: ArrayLike, knob1: ArrayLike, ball_radius: float,
                  bat_radius: float, dt: float) -> np.ndarray:
    """
    Seed Eq. (6): gap between the ball and the INFINITE line through knob and tip.

    ``d(t) = |(B - E) x (B - S)| / |S - E| - r_bat - r_ball`` with every point linear in t.

    :param t: times in seconds from the interval start (any shape).
    :param ball0 ... dt: as for ``time_of_impact``.

    :returns: Gap in metres, same shape as t (NaN where knob and tip coincide).
    """
    ball, tip, knob = positions_at(t, dt, ball0, ball1, tip0, tip1, knob0, knob1)
    numerator = np.linalg.norm(np.cross(ball - tip, ball - knob), axis=-1)
    denominator = np.linalg.norm(knob - tip, axis=-1)
    with np.errstate(divide='ignore', invalid='ignore'):
        return numerator / denominator - bat_radius - ball_radius


def seed_time_of_impact(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
                        knob0: ArrayLike, knob1: ArrayLike, ball_radius: float,
                        bat_radius: float, dt: float = 1.0) -> Optional[float]:
    """
    Run the seed derivation's method: first real root in [0, dt] of its quartic (Eq. 15f).

    Kept to compare against; do not use it to find impacts. Its known failures:

    * the bat is an infinite line, so it reports hits past the tip and behind the knob;
    * a ball already in contact at t = 0 with no crossing in the interval is missed (it looks
      for roots, not for the sign at the start);
    * a tangential touch is a double root, which ``numpy.roots`` returns with a small imaginary
      part, so grazes are lost;
    * coefficients are formed in raw seconds and metres, so they are badly scaled.

    :param ball0 ... dt: as for ``time_of_impact``.

    :returns: Seconds from the interval start of the smallest real root in [0, dt], or None.
    """
    b0, b1 = np.asarray(ball0, float), np.asarray(ball1, float)
    e0, e1 = np.asarray(tip0, float), np.asarray(tip1, float)
    s0, s1 = np.asarray(knob0, float), np.asarray(knob1, float)
    # Eqs. (4)-(5): B - E = a t + b, B - S = c t + d, S - E = e t + f
    a = (b1 - b0 - e1 + e0) / dt
    b = b0 - e0
    c = (b1 - b0 - s1 + s0) / dt
    d = b0 - s0
    e = (s1 - s0 - e1 + e0) / dt
    f = s0 - e0
    r = ball_radius + bat_radius
    alpha = np.array([0.0, 0.0, e @ e, 2.0 * (e @ f), f @ f])  # Eq. (13)
    x = np.stack([np.cross(a, c), np.cross(b, c) + np.cross(a, d), np.cross(b, d)], axis=1)
    beta = np.array([  # Eq. (12)
        np.sum(x[:, 0] ** 2),
        np.sum(2.0 * x[:, 0] * x[:, 1]),
        np.sum(x[:, 1] ** 2 + 2.0 * x[:, 0] * x[:, 2]),
        np.sum(2.0 * x[:, 1] * x[:, 2]),
        np.sum(x[:, 2] ** 2),
    ])
    coefficients = beta - r * r * alpha  # Eq. (15f)
    nonzero = np.flatnonzero(coefficients)
    if nonzero.size == 0:
        return None
    roots = np.roots(coefficients[nonzero[0]:])
    real = roots[np.isreal(roots)].real
    in_range = real[(real >= 0.0) & (real <= dt)]
    return float(in_range.min()) if in_range.size else None
