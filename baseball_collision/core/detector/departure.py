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

``leaves_flight`` calls the closing sample departed when it is more than ``DEPARTURE_FLOOR`` from
the parabola, outside the told noise's ``DEPARTURE_CHI_SQUARE`` bound (none under ``tracker_noise``
auto, whose estimate holds the frames judged: ``judging_noise``; three coordinates, each with the
variance the noise gives the difference: sigma^2 (1 + sum of the squared Lagrange weights)), and
far outside the misses of the intervals just before it (the samples' own scatter, whatever noise
was told); a parabola through a departed sample is no free flight, so the two intervals after a
departure do not depart. The sweep then moves the ball over that interval on the parabola
(``flight_path``): where it would have gone, which is where the bat met it, and what it did after
does not matter to the first contact.

The far tests must let that path through: ``departure_reach`` bounds how far it strays from the
interval's chord (the closing sample's distance from the parabola, plus the parabola's own
bulge), and the tests grow the ball's bounds by it on every interval, departed or not, so they
need neither the noise nor the decision.
"""

import math
from typing import Any, Optional, Sequence, Tuple

import numpy as np

from .streams import reversed_excerpt, Stream
from ..geometry import Vector
from ..motion import PointPath
from ..toi import _kernel

DEPARTURE_FLOOR = 2e-4
"""m: a closing sample nearer than this to the free flight has not departed (exact samples: the
parabola's own error is micrometres at 90 Hz, a third of a millimetre at 30 Hz, where the
scatter test tells it apart; a hit moves the ball that far 3-6 us after the contact)."""

DEPARTURE_CHI_SQUARE = 21.11
"""The chi-square (3 degrees of freedom) a noisy closing sample must exceed: its upper 1e-4
quantile, so a ball in free flight is called departed in about one interval in 10,000."""

SCATTER_INTERVALS = 12
"""Intervals before one whose closing samples' misses measure the stream's scatter."""

SCATTER_RATIO = 13.0
"""How many times the scatter's mean square (per unit of spread) a departure must exceed: a
ratio of two chi-squares, of 3 and 36 degrees of freedom, each over its own, passes 13 about
once in 100,000 draws (F(3, 36), 12 intervals before it; with 4, F(3, 12), once in 2,500:
a segment's first intervals, which a free flight's parabola serves as well)."""

FEW_SCATTER_RATIOS = (261.0, 33.0, 18.0)
"""The ratio a departure must exceed with only one, two or three intervals before it (a
segment's first: the quantile of F(3, 3), F(3, 6), F(3, 9) that a free flight's noise passes
once in 2,500, as ``SCATTER_RATIO`` with four; Monte Carlo, 2e7 draws). With none and no noise
told, a departure cannot be told from the noise, and none is called: a noisy ball (1.4-2.2 mm
off its first parabola at 60 Hz with 0.3 mm of noise) was called departed there, and a
departed sample blocks the next two intervals, so a hit within the first samples of a ball's
stream was lost (BENCHMARKS.md, "A hit in a ball stream's first frames")."""

_RULES = (DEPARTURE_FLOOR, DEPARTURE_CHI_SQUARE, SCATTER_INTERVALS, SCATTER_RATIO,
          FEW_SCATTER_RATIOS)
"""The rules as the kernel's ``leaves_flight`` takes them."""

Parabola = Tuple[float, float, float, Vector, Vector]
"""The free flight over an interval: the closing sample's distance from the parabola (m), the
noise gain of that difference (1 + the squared Lagrange weights), the parabola's bulge from its
own chord over the interval (m), its value at the closing stamp (m) and its acceleration
(m/s^2)."""


def parabola(stream: Stream, k: int, max_gap: float) -> Optional[Parabola]:
    """
    Return the parabola through a point stream's samples k - 2, k - 1 and k, or None.

    None when they and sample k + 1 are not all in one segment without a gap over
    ``max_gap`` (s), or k < 2. Kept per interval in ``stream.aligned`` once sample k + 1 is
    there (the four samples never change): the far test and the sweep ask for it in turn. The
    kernel's (``toi._kernel.kept_parabola``, the same operations in the same order as the
    Python it replaced): Lagrange's weights of samples k - 2 .. k at the closing stamp, the
    parabola's value there, twice the second divided difference (its acceleration), the
    closing sample's ``math.dist`` from it.
    """
    return _kernel.kept_parabola(stream.times, stream.values, stream.breaks, stream.aligned, k,
                                 max_gap)


def judging_noise(config: Any) -> float:
    """
    Return the noise (m, 1 sigma) a departure is judged against: ``tracker_noise``, 0 if auto.

    Under auto (``tracker_noise`` < 0) a stream's estimate takes in the residuals of the very
    frames being judged: with few of them (a ball tracked from 60 ms before the bat at 90 Hz:
    four residual windows, two holding a hit's look-ahead frames) a hit's own departure swells
    it (25 mm against 0.3 mm of noise: a chi-square bound of 0.51 m against a 0.50 m
    departure), and the hit was lost. Judged without it, the scatter of the intervals before
    the one judged (``SCATTER_RATIO``: the samples' own spread, never the frame judged) bounds
    the noise instead.

    :param config: the detector's configuration (``DetectorConfig``: its ``tracker_noise``).
    """
    return config.tracker_noise if config.tracker_noise >= 0.0 else 0.0


def leaves_flight(stream: Stream, k: int, noise: float, max_gap: float) -> Optional[Parabola]:
    """
    Return the free flight's parabola when sample k + 1 has departed from it, else None.

    Departed: more than ``DEPARTURE_FLOOR`` from the parabola, outside the noise's chi-square
    bound, and outside the scatter of the ``SCATTER_INTERVALS`` intervals before it (their own
    closing samples' misses, each scaled by its Lagrange weights, against
    ``SCATTER_RATIO``): samples noisier than the noise told (``tracker_noise`` 0 on a noisy
    tracker) scatter that much in free flight too. Not where sample k - 1 or k departed
    itself: a parabola through a departure (the frames just after a hit) is no free flight.
    The kernel's (``toi._kernel.leaves_flight``: the rules of the Python it replaced in its
    order, the scatter's mean square summed from 0.0).

    :param noise: the noise told (m, 1 sigma per coordinate; 0 for exact samples, and under
        ``tracker_noise`` auto: ``judging_noise``).
    """
    return _kernel.leaves_flight(stream.times, stream.values, stream.breaks, stream.aligned, k,
                                 noise, max_gap, _RULES)


def flight_path(stream: Stream, k: int, fitted: Parabola) -> PointPath:
    """Return the ball's path over interval k on the free flight's parabola (``parabola``)."""
    t2, t3 = stream.times[k:k + 2]
    opening, closing = _slopes(stream, k, fitted)
    return PointPath(t2, t3, stream.values[k], fitted[3], opening, closing)


def _slopes(stream: Stream, k: int, fitted: Parabola) -> Tuple[Vector, Vector]:
    """Return the parabola's slopes (m/s) at interval k's opening and closing stamps."""
    acceleration = fitted[4]
    t1, t2, t3 = stream.times[k - 1:k + 2]
    p1, p2 = stream.values[k - 1:k + 1]
    # the chord's slope is the parabola's at the chord's middle
    opening = tuple((b - a) / (t2 - t1) + 0.5 * c * (t2 - t1)
                    for a, b, c in zip(p1, p2, acceleration))
    return opening, tuple(v + c * (t3 - t2) for v, c in zip(opening, acceleration))


def glitch_path(stream: Stream, k: int, noise: float, max_gap: float,
                spread: float = 0.0) -> Optional[PointPath]:
    """
    Return the free flight over interval k when its opening sample k is a glitch, else None.

    A glitch: sample k left the free flight of the samples before it (``leaves_flight``), and
    sample k + 1, in its segment, is not where a hit would have taken the ball. A hit at t_c
    (after sample k - 1) changes the ball's velocity by some dv, so it leaves the flight (the
    parabola through samples k - 3 .. k - 1, continued) by dv (t - t_c): sample k + 1 is off it
    along the same line from the flight as sample k, and farther (by the ratio of the times
    since the contact, at least 1). A glitch (a mislabelled marker, a reflection: a frame off
    the ball) is not: its next sample is back nearer to the flight than it was, or off in
    another direction (a second bad frame, a hit's first frame after it), by more than
    ``hit_bend`` allows. The path is that parabola over [t_k, t_k+1], so sample k moves the
    ball nowhere; the sweep counts it as a ``ball_glitch`` drop and then forgets it (``Sweep``):
    the next of two bad frames in a row is then judged against the flight in turn.

    :param noise: the noise told (m; ``judging_noise``).
    :param spread: the stream's noise (m, 1 sigma per coordinate: told or estimated), which
        blurs where a hit's line runs (``hit_bend``); the flight's own scatter where that is
        larger (``scatter``: noise not told).
    """
    if k < 3 or k + 1 >= len(stream.times) or not stream.continuous(k, max_gap):
        return None
    departed = leaves_flight(stream, k - 1, noise, max_gap)
    if departed is None:
        return None
    # the parabola (``departed``: its value at t_k, its acceleration) continued over interval k
    opening, acceleration = departed[3], departed[4]
    slope = _slopes(stream, k - 1, departed)[1]
    times = stream.times
    h = times[k + 1] - times[k]
    closing = tuple(p + v * h + 0.5 * a * h * h for p, v, a in zip(opening, slope, acceleration))
    off = np.subtract(stream.values[k], opening)
    after = np.subtract(stream.values[k + 1], closing)
    if math.hypot(*after) >= departed[0]:  # (``departed[0]``: sample k's distance, ``off``'s)
        # the hit's line: sample k + 1 off the flight by ratio times sample k's offset
        ratio = max(1.0, float(after @ off) / float(off @ off))
        if math.hypot(*(after - ratio * off)) <= hit_bend(
                times[k - 3:k + 2], ratio, max(spread, scatter(stream, k - 1, max_gap))):
            return None
    return PointPath(times[k], times[k + 1], opening, closing, slope,
                     tuple(v + a * h for v, a in zip(slope, acceleration)))


FLIGHT_AFTER = 6
"""Ball samples after one of a segment's first three that judge it (``glitch_before_flight``):
the three whose free flight it is judged against, and three more whose closing samples'
misses give the scatter of three intervals (``FEW_SCATTER_RATIOS``)."""


def glitch_before_flight(stream: Stream, k: int, noise: float, max_gap: float,
                         spread: float = 0.0) -> bool:
    """
    Return whether sample k is a glitch judged by the free flight of the samples after it.

    For a segment's second and third samples, which have too few samples before them for
    ``glitch_path``: its rule with time run backwards, over samples k - 1 to k +
    ``FLIGHT_AFTER`` (those of them in k's segment, no others). Sample k left the free flight
    of samples k + 1 .. k + 3 continued back to it (``leaves_flight``: outside the scatter of
    the intervals after those), and sample k - 1 is not where a hit between samples k and
    k + 1 left the ball: a hit changes the ball's velocity by some dv at t_c, so every sample
    before the contact is off the flight after it by dv (t_c - t), along one line and farther
    the earlier it is (``hit_bend``). A hit's first frame after the contact is on the flight
    after it. False where fewer than three samples follow k in its segment, or none precedes
    it there.

    :param noise: the noise told (m; ``judging_noise``).
    :param spread: the stream's noise (m, 1 sigma per coordinate: told or estimated).
    """
    if k < 1 or not stream.continuous(k - 1, max_gap):
        return False
    backwards = _backwards(stream, k - 1, k + FLIGHT_AFTER, max_gap)
    return glitch_path(backwards, len(backwards.times) - 2, noise, max_gap, spread) is not None


def flight_before(stream: Stream, k: int, noise: float, max_gap: float) -> Optional[PointPath]:
    """
    Return the flight after sample k continued back over interval k, when k departed from it.

    For a segment's first sample (after a tracking gap, or a stream's first), which has no
    sample before it to tell a glitch from a hit (``glitch_path``, ``glitch_before_flight``):
    sample k left the free flight of samples k + 1 .. k + 3 continued back to it
    (``leaves_flight`` with time run backwards, outside the scatter of the intervals after
    those, of the samples up to k + ``FLIGHT_AFTER`` in its segment). A hit between samples k
    and k + 1 does that too: the flight after the contact, continued back, then touches the
    bat over the interval, which the caller tests (``Sweep``); a glitch on a miss does not.
    The path runs from that flight at t_k to sample k + 1 (the parabola through k + 1 .. k + 3,
    exact on it). None where fewer than three samples follow k in its segment, or sample k + 1
    or k + 2 departed from the flight after it (a hit later: no free flight to judge by).

    :param noise: the noise told (m; ``judging_noise``).
    """
    if k + 3 >= len(stream.times) or not stream.continuous(k, max_gap):
        return None
    backwards = _backwards(stream, k, k + FLIGHT_AFTER, max_gap)
    m = len(backwards.times) - 1  # (sample k)
    if m < 3:
        return None
    departed = leaves_flight(backwards, m - 1, noise, max_gap)
    if departed is None:
        return None
    opening, closing = _slopes(backwards, m - 1, departed)  # (at t_k+1 and t_k, time negated)
    return PointPath(stream.times[k], stream.times[k + 1], departed[3], stream.values[k + 1],
                     tuple(-v for v in closing), tuple(-v for v in opening))


CONTACT_TIME = 6e-4
"""s: how long a baseball stays on a bat (about 0.6 ms: Adair, *The Physics of Baseball*; the
force a half-sine): the push's middle, which the flight after the hit continued back runs
from, is half of it after the first contact (``HitApproach``)."""


FRICTION = 0.5
"""The most a bat's push turns from the contact normal: its part across the normal over its part
along it (Coulomb friction of a baseball on a bat, about 0.5 at most): ``Sweep._pushed``.
Measured (``bench_ball_gap.py``'s cases, rebound hits): a genuine push 0-0.32 across (0 exact:
the simulator has no friction; up to 0.32 with 1 mm of noise), a glitch's frame before the
flight after a hit 0.6-450 but for 7 of 150."""


class HitApproach:
    """
    Where the ball's centre is at a hit's first contact, were the hit at each instant.

    For a segment's first sample k before a hit and the flight after it (``flight_before``,
    continued back over interval k): a push dv over ``CONTACT_TIME`` from the contact t_c
    leaves the ball on the flight after it continued back (F) less dv (t - t_c - h), h half
    the push, so sample k is off F by D = dv (t_c + h - t_k), and at t_c the ball was at
    ``at(t_c)`` = F(t_c) + D h / (t_c - t_k + h). The first instant that point touches the bat
    is the contact (a sweep of it as a path: ``Sweep._hit_before_flight``); ``incoming`` is
    the ball's path from sample k to it. From sample k at t_k; F's acceleration (gravity,
    drag) is the incoming flight's too. The duck type of ``PointPath`` a sweep reads (``at``,
    ``deviation``, ``t0``, ``t1``).

    :param flight: F over interval k (``flight_before``); ``sample``: sample k (m).
    """

    __slots__ = ('flight', 'offset', 't0', 't1', 'h', 'size')

    def __init__(self, flight: PointPath, sample: Vector) -> None:
        self.flight, self.t0, self.t1 = flight, flight.t0, flight.t1
        self.offset = np.subtract(sample, flight.at(flight.t0))
        self.h = 0.5 * CONTACT_TIME
        self.size = math.hypot(*self.offset)

    def at(self, t: float) -> Vector:
        """Return the ball's centre (m) at a contact at t (s)."""
        share = self.h / (t - self.t0 + self.h)
        return tuple(p + share * d for p, d in zip(self.flight.at(t), self.offset.tolist()))

    def deviation(self, ta: float, tb: float) -> float:
        """Return a bound (m) on how far ``at`` leaves its chord over [ta, tb] (s)."""
        bend = self.size * self.h / (4.0 * (ta - self.t0 + self.h) ** 3)  # (D h / (s + h))''
        return self.flight.deviation(ta, tb) + bend * (tb - ta) ** 2

    def push(self, t: float) -> Vector:
        """Return the ball's change of velocity (m/s) a push from a contact at t (s) makes."""
        return tuple((self.offset / (t - self.t0 + self.h)).tolist())

    def incoming(self, t: float) -> PointPath:
        """Return the ball's path (m) from sample k to a contact at t (s): F - dv (t - t_c - h)."""
        change = self.offset / (t - self.t0 + self.h)
        rates = (np.subtract(self.flight.velocity(u), change).tolist() for u in (self.t0, t))
        return PointPath(self.t0, t, tuple(self.offset + self.flight.at(self.t0)), self.at(t),
                         *rates)


def back_miss(stream: Stream, k: int, max_gap: float) -> Optional[float]:
    """
    Return how far (m) sample k is from the parabola through samples k + 1 .. k + 3 at t_k.

    The flight after it continued back to it (Lagrange's weights, exact on a parabola), with
    no test of whether that is a free flight; None where fewer than three samples follow k
    in its segment.
    """
    if k + 3 >= len(stream.times) or not all(stream.continuous(j, max_gap)
                                             for j in range(k, k + 3)):
        return None
    times = stream.times
    weights = _weights(times[k + 1:k + 4], times[k])
    at = weights @ np.array(stream.values[k + 1:k + 4], dtype=float)
    return math.dist(stream.values[k], at)


def _backwards(stream: Stream, k: int, stop: int, max_gap: float) -> Stream:
    """
    Return samples k .. ``stop`` of k + 1's segment, the latest first, with time negated.

    Those up to the segment's end (or the stream's newest) where that comes first, stamps
    negated too: a stream whose parabolas and departures (``leaves_flight``) are the flight's
    with time run backwards.
    """
    last = k + 1
    while last < min(stop, len(stream.times) - 1) and \
            stream.continuous(last, max_gap):
        last += 1
    return reversed_excerpt(stream, k, last)


HIT_BEND = 200.0
"""m/s^2: the most a hit ball's path after the contact can bend from a straight departure
(the difference of its acceleration from the free flight's: drag on its new velocity and
spin, 10-50 m/s^2 for a batted ball; four times that)."""


def hit_bend(times: Sequence[float], ratio: float, spread: float) -> float:
    """
    Return how far (m) a hit's next frame may be off the hit's straight line from the flight.

    :param times: the stamps (s) of the flight's three samples, the departed one's and the
        next one's.
    :param ratio: how many times the departed sample's offset from the flight the next one's
        line takes.
    :param spread: the samples' noise (m, 1 sigma per coordinate).
    :returns: the bend (``HIT_BEND`` times the next step times the two steps since the
        flight's last sample, over 2: the most after a contact between those samples) plus the
        noise's ``DEPARTURE_CHI_SQUARE`` bound on the line's miss: the next offset less
        ``ratio`` times the departed one, each a sample less the parabola through the three
        continued to it (Lagrange's weights), so a hit's frame is off by more about once in
        10,000.
    """
    miss = _weights(times[:3], times[4]) - ratio * _weights(times[:3], times[3])
    noise = spread * math.sqrt(1.0 + ratio * ratio + float(miss @ miss))
    bend = 0.5 * HIT_BEND * (times[4] - times[3]) * (times[4] - times[2])
    return bend + math.sqrt(DEPARTURE_CHI_SQUARE) * noise


def scatter(stream: Stream, k: int, max_gap: float) -> float:
    """
    Return the noise (m, 1 sigma per coordinate) the free flight before interval k shows.

    From the closing samples' misses of its parabolas over the ``SCATTER_INTERVALS`` intervals
    before it (``parabola``: each miss squared has 3 sigma^2 times its noise gain for its mean,
    in free flight), as the departure's scatter test reads them: a noisy stream's own spread,
    whatever noise was told; 0 where there is none.
    """
    terms = [fitted[0] * fitted[0] / fitted[1]
             for fitted in (parabola(stream, j, max_gap)
                            for j in range(max(k - SCATTER_INTERVALS, 2), k))
             if fitted is not None]
    return math.sqrt(sum(terms) / (3.0 * len(terms))) if terms else 0.0


def _weights(flight: Sequence[float], at: float) -> np.ndarray:
    """Return Lagrange's weights of three samples stamped ``flight`` (s) at a stamp (s)."""
    return np.array([math.prod((at - flight[j]) / (flight[i] - flight[j])
                               for j in range(3) if j != i) for i in range(3)])


def departure_reach(stream: Stream, k: int, max_gap: float) -> float:
    """
    Return how far (m) the free flight's path over interval k can stray beyond its chord's.

    The closing sample's distance from the parabola (the path ends there instead) plus the
    parabola's bulge from its own chord (its acceleration times h^2 / 8); 0 where there is no
    parabola (``parabola``).
    """
    fitted = parabola(stream, k, max_gap)
    return 0.0 if fitted is None else fitted[0] + fitted[2]


def departure_reaches(points: np.ndarray, times: np.ndarray, k: np.ndarray,
                      closed: Optional[np.ndarray] = None) -> np.ndarray:
    """
    Return ``departure_reach`` over arrays of intervals, never below it.

    Every interval from the third sample on is given its parabola; with ``closed`` (each
    sample interval's ``Stream.continuous``), as the scalar function, only those whose samples
    k - 2 to k + 1 are one segment without a long gap (elsewhere 0); without it, across
    segments and gaps too (more than the scalar function gives). The compiled kernel's
    ``departure_reaches``, rounded as it rounds: a caller that must not fall below the scalar
    bound adds a tolerance. inf where the parabola is not finite.

    :param points: (n, 3) a stream's samples (m); ``times``: (n,) their times (s).
    :param k: the intervals (m,), each from the third sample on with a sample after it.
    :param closed: (n - 1,) booleans, or None.
    :raises ValueError: arrays of the wrong shapes, or an interval without a sample after it.
    """
    reach = np.empty(len(k))
    _kernel.departure_reaches(np.ascontiguousarray(points, dtype=float),
                              np.ascontiguousarray(times, dtype=float),
                              np.ascontiguousarray(k, dtype=np.int64),
                              None if closed is None else np.ascontiguousarray(closed, dtype=bool),
                              reach)
    return reach
