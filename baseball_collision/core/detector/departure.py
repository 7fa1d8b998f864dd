"""
A ball that leaves its free flight inside an interval: a hit, a catch, a bounce.

A tracked ball flies freely (gravity, drag, spin: an acceleration that changes slowly) until
something touches it. A bat's hit turns it round in about 0.6 ms, so the first frame after the
contact already shows it going away: an interpolant through that frame never reaches the bat
(every model, any noise level), and the contact is lost. So for each interval of the ball the
closing sample is compared with the free flight of the three before it: the parabola (one per
coordinate, Lagrange's, exact on uneven stamps) through samples k - 2, k - 1 and k, at the
closing stamp. Free flight misses it by the parabola's own error (the acceleration's change over
about three steps: micrometres for a pitch at 90 Hz) plus the noise; a hit by the velocity it
gained times the time since the contact: centimetres.

``leaves_flight`` calls the closing sample departed when it is more than ``DEPARTURE_FLOOR``
from the parabola, outside the noise's ``DEPARTURE_CHI_SQUARE`` bound (three coordinates, each
with the variance the noise gives the difference: sigma^2 (1 + sum of the squared Lagrange
weights)), and far outside the misses of the intervals just before it (the samples' own
scatter, whatever noise was told). The sweep then moves the ball over that interval on the parabola
(``flight_path``): where it would have gone, which is where the bat met it, and what it did
after does not matter to the first contact.

The far tests must let that path through: ``departure_reach`` bounds how far it strays from the
interval's chord (the closing sample's distance from the parabola, plus the parabola's own
bulge), and the tests grow the ball's bounds by it on every interval, departed or not, so they
need neither the noise nor the decision.
"""

import math
from typing import Optional, Tuple

import numpy as np

from .streams import Stream
from ..geometry import Vector
from ..motion import PointPath

DEPARTURE_FLOOR = 2e-4
"""m: a closing sample nearer than this to the free flight has not departed (exact samples: the
parabola's own error is micrometres at 90 Hz, a third of a millimetre at 30 Hz, where the
scatter test tells it apart; a hit moves the ball that far 3-6 us after the contact)."""

DEPARTURE_CHI_SQUARE = 21.11
"""The chi-square (3 degrees of freedom) a noisy closing sample must exceed: its upper 1e-4
quantile, so a ball in free flight is called departed in about one interval in 10,000."""

SCATTER_INTERVALS = 4
"""Intervals before one whose closing samples' misses measure the stream's scatter."""

SCATTER_RATIO = 25.0
"""How many times the scatter's mean square (per unit of spread) a departure must exceed: the
ratio of two chi-squares of 3 and 12 degrees of freedom, each over its own, passes 25 about
once in 70,000 draws (F(3, 12) > 25)."""

Parabola = Tuple[Tuple[float, float, float], Vector, Vector, Vector]
"""Lagrange weights of samples k - 2, k - 1, k at the closing stamp; the parabola's value
(m) there; its velocity (m/s) at the opening stamp and at the closing stamp."""


def parabola(stream: Stream, k: int, max_gap: float) -> Optional[Parabola]:
    """
    Return the parabola through a point stream's samples k - 2, k - 1 and k, or None.

    None when they and sample k + 1 are not all in one segment without a gap over
    ``max_gap`` (s), or k < 2.
    """
    if k < 2 or k + 1 >= len(stream.times) or not all(
            stream.continuous(i, max_gap) for i in (k - 2, k - 1, k)):
        return None
    t0, t1, t2, t3 = stream.times[k - 2:k + 2]
    p0, p1, p2 = stream.values[k - 2:k + 1]
    w0 = (t3 - t1) * (t3 - t2) / ((t0 - t1) * (t0 - t2))
    w1 = (t3 - t0) * (t3 - t2) / ((t1 - t0) * (t1 - t2))
    w2 = (t3 - t0) * (t3 - t1) / ((t2 - t0) * (t2 - t1))
    end = tuple(w0 * a + w1 * b + w2 * c for a, b, c in zip(p0, p1, p2))
    # the parabola's derivative at t: the Lagrange weights' derivatives
    rates = []
    for t in (t2, t3):
        d0 = ((t - t1) + (t - t2)) / ((t0 - t1) * (t0 - t2))
        d1 = ((t - t0) + (t - t2)) / ((t1 - t0) * (t1 - t2))
        d2 = ((t - t0) + (t - t1)) / ((t2 - t0) * (t2 - t1))
        rates.append(tuple(d0 * a + d1 * b + d2 * c for a, b, c in zip(p0, p1, p2)))
    return (w0, w1, w2), end, rates[0], rates[1]


def leaves_flight(stream: Stream, k: int, noise: float, max_gap: float) -> Optional[Parabola]:
    """
    Return the free flight's parabola when sample k + 1 has departed from it, else None.

    Departed: more than ``DEPARTURE_FLOOR`` from the parabola, outside the noise's chi-square
    bound, and outside the scatter of the ``SCATTER_INTERVALS`` intervals before it (their own
    closing samples' misses, each scaled by its Lagrange weights, against
    ``SCATTER_RATIO``): samples noisier than the noise told (``tracker_noise`` 0 on a noisy
    tracker) scatter that much in free flight too.

    :param noise: the stream's noise (m, 1 sigma per coordinate; 0 for exact samples).
    """
    fitted = parabola(stream, k, max_gap)
    if fitted is None:
        return None
    miss, spread = _miss(stream, k, fitted)
    if miss <= DEPARTURE_FLOOR or miss * miss <= DEPARTURE_CHI_SQUARE * noise * noise * spread:
        return None
    scatter = []
    for j in range(k - SCATTER_INTERVALS, k):
        before = parabola(stream, j, max_gap) if j >= 0 else None
        if before is not None:
            other, other_spread = _miss(stream, j, before)
            scatter.append(other * other / other_spread)
    if scatter and miss * miss <= SCATTER_RATIO * spread * sum(scatter) / len(scatter):
        return None
    return fitted


def _miss(stream: Stream, k: int, fitted: Parabola) -> Tuple[float, float]:
    """Return the closing sample's distance (m) from the parabola and 1 + its weights' squares."""
    weights, end, _, _ = fitted
    return math.dist(stream.values[k + 1], end), 1.0 + sum(w * w for w in weights)


def flight_path(stream: Stream, k: int, fitted: Parabola) -> PointPath:
    """Return the ball's path over interval k on the free flight's parabola (``parabola``)."""
    _, end, rate0, rate1 = fitted
    return PointPath(stream.times[k], stream.times[k + 1], stream.values[k], end, rate0, rate1)


def departure_reach(stream: Stream, k: int, max_gap: float) -> float:
    """
    Return how far (m) the free flight's path over interval k can stray beyond its chord's.

    The closing sample's distance from the parabola (the path ends there instead) plus the
    parabola's bulge from its own chord (its acceleration times h^2 / 8); 0 where there is no
    parabola (``parabola``).
    """
    fitted = parabola(stream, k, max_gap)
    if fitted is None:
        return 0.0
    _, end, rate0, rate1 = fitted
    h = stream.times[k + 1] - stream.times[k]
    bend = math.dist(rate0, rate1) * h / 8.0  # |a| h^2 / 8, a = (rate1 - rate0) / h
    return math.dist(stream.values[k + 1], end) + bend


def departure_reaches(points: np.ndarray, times: np.ndarray, k: np.ndarray) -> np.ndarray:
    """
    Return ``departure_reach`` over arrays of intervals, never below it.

    Every interval from the third sample on is given its parabola, across segments and gaps
    too (more than the scalar function, which gives those 0), rounded as numpy rounds: a caller
    that must not fall below the scalar bound adds a tolerance.

    :param points: (n, 3) a stream's samples (m); ``times``: (n,) their times (s).
    :param k: the intervals (m,), each with a sample after it.
    """
    reach = np.zeros(len(k))
    inside = np.flatnonzero(k >= 2)
    if not len(inside):
        return reach
    j = k[inside]
    t0, t1, t2, t3 = (times[j + offset] for offset in (-2, -1, 0, 1))
    p0, p1, p2, p3 = (points[j + offset] for offset in (-2, -1, 0, 1))
    with np.errstate(all='ignore'):
        w0 = (t3 - t1) * (t3 - t2) / ((t0 - t1) * (t0 - t2))
        w1 = (t3 - t0) * (t3 - t2) / ((t1 - t0) * (t1 - t2))
        w2 = (t3 - t0) * (t3 - t1) / ((t2 - t0) * (t2 - t1))
        end = w0[:, None] * p0 + w1[:, None] * p1 + w2[:, None] * p2
        # the parabola's acceleration: twice its second divided difference
        second = 2.0 * ((p2 - p1) / (t2 - t1)[:, None] - (p1 - p0) / (t1 - t0)[:, None]) / (
            t2 - t0)[:, None]
        bend = np.sqrt(np.einsum('ij,ij->i', second, second)) * (t3 - t2) ** 2 / 8.0
        miss = np.sqrt(np.einsum('ij,ij->i', p3 - end, p3 - end))
        found = miss + bend
    reach[inside] = np.where(np.isfinite(found), found, np.inf)
    return reach
