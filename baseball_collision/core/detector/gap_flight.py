"""
The ball's flight before a tracking gap: whether the samples after the gap lie on it.

A tracker that lost the ball (occluded) finds it again, a gap over ``max_gap`` later, near the
bat; the segment's first samples have too few before them for the departure test
(``departure``), so the sweep judges them by the flight the ball was on before the gap. Its
functions read the ball's stream (positions in m, times in s) and decide:

- ``on_gap_flight``: whether each of the segment's first samples (up to its third) lies on
  the parabola (``motion.flight``, one per coordinate) of the samples before the gap
  continued over it, and the parabola through both; from the samples before the gap still
  held (within ``kept_history`` of the interval visited), else from the flight kept when the
  gap ended (``GapFlight``, ``flight_before_gap``: the trim behind the walk took them);
- ``flight_across_gap``: that flight, as the ball's path into a contact after the segment's
  first or second sample (``sweep_ball.BallSamples._hit_before_flight``);
- ``off_gap_flight``: a segment's first sample off that flight while its second is on it (a
  glitch: ``BallSamples._early_glitch``);
- ``left_gap_flight``: the segment's first three samples on it and the fourth off it (a hit
  between the third and the fourth: ``BallSamples._solved_on_gap_flight``).

A sample lies on the flight within ``GAP_FLIGHT_SLACK`` (1 cm: drag and spin bend a free
flight about a millimetre from a parabola over 0.1-0.2 s; a glitch on the bat or a deflection
in the gap lies centimetres off) and the noise's ``DEPARTURE_CHI_SQUARE`` bound at the
continuation's gain. Over a longer gap, judged by the kept flight, the slack grows to the drift
a pitch's changing acceleration makes from a parabola (``gap_bias``): the drag ``k v^2`` (k =
rho Cd A / 2m = 0.0062 /m for Cd 0.35) decelerates a pitch at up to 47 m/s by up to 14 m/s^2
and changes by ``2 k v dv/dt`` = 8 m/s^3 as the ball slows; the drag's direction and a spin
force's (up to about 6 m/s^2) turn with the velocity at ``|g + a| / v`` = 0.4-0.5 rad/s, 6 and
3 m/s^3: ``GAP_FLIGHT_JERK``, 12 m/s^3, bounds their root sum of squares (10.5 m/s^3). Past a
drift of a ball's radius (``GAP_FLIGHT_BIAS``, 3.66 cm) a sample on the bat (at least a ball's
and a bat's radius, 7 cm, from a ball touching it) and the ball coming at it cannot be told
apart, and no flight is kept: with 0.15 s of flight before the gap, about 0.19 s after its
last sample.
"""

from bisect import bisect_left
import math
from typing import NamedTuple, Optional, Tuple

from .config import DetectorConfig
from .departure import DEPARTURE_CHI_SQUARE, DEPARTURE_FLOOR
from .fitting import flight_window, kept_history, stream_noise
from .streams import Stream
from ..geometry import Vector
from ..motion import PointPath
from ..motion.flight import fit_flight, FlightFit

GAP_FLIGHT_SLACK = 0.01
"""m: how far a ball's samples after a tracking gap may lie off the parabola of its samples
before it continued over the gap (``on_gap_flight``): a free flight's drag and spin change
bend it from a parabola by about a millimetre over 0.1-0.2 s; a glitch on the bat (its centre
at least a ball's and a bat's radius from a ball touching it) or a deflection in the gap lies
centimetres off."""


GAP_FLIGHT_SAMPLES = 4
"""Ball samples before a tracking gap at least that ``on_gap_flight`` and
``flight_before_gap`` fit (a parabola per coordinate and residuals to measure the noise by:
three degrees of freedom)."""


GAP_FLIGHT_JERK = 12.0
"""m/s^3: the most a pitch's acceleration changes per second, which a parabola leaves out
(``on_gap_flight`` over a gap longer than the samples held: ``gap_bias``): the drag's change
as the ball slows (8 m/s^3 at 47 m/s, 105 mph) and the drag's and a spin force's turn with the
velocity (6 and 3 m/s^3), about 10.5 m/s^3 in root sum of squares (the module docstring)."""


GAP_FLIGHT_BIAS = 0.0366
"""m: the most the flight before a long tracking gap may have drifted, by ``GAP_FLIGHT_JERK``,
from its parabola continued to the segment's samples after the gap (``gap_bias``) for
``on_gap_flight`` to judge them by it: a baseball's radius. A glitch on the bat lies at least
a ball's and a bat's radius (7 cm) from a ball touching it; past this a sample on the bat and
the ball coming at it cannot be told apart. With a 0.15 s flight before the gap the drift
reaches it about 0.19 s after the flight's last sample (2.2 cm at 0.15 s, 6.8 cm at 0.25 s,
21 cm at 0.4 s): a longer gap has no flight before it."""


class GapFlight(NamedTuple):
    """
    The ball's flight before a tracking gap, kept where its samples may be trimmed.

    ``flight_before_gap``: the parabola of its segment's last samples (``kept_history`` of its
    newest), fitted with a noise of 1 m (its ``chi_square`` the residuals' sum of squares,
    m^2), and the stamp (s) of its newest sample, before the gap.
    """

    fit: FlightFit
    end: float


Judged = Tuple[Tuple[bool, ...], FlightFit]
"""``on_gap_flight``'s answer: one flag a segment's sample (on the flight), and the parabola
through the flight and those samples."""


def flight_before_gap(ball: Stream, config: DetectorConfig) -> Optional[GapFlight]:
    """
    Return the ball's flight up to its newest sample, kept over the gap after it; or None.

    The parabola of the newest's segment's samples within ``kept_history`` of it
    (``motion.flight``, at least ``GAP_FLIGHT_SAMPLES``; None where there are fewer, or their
    stamps are too bunched for a fit): ``sweep_ball.BallSamples.note_gap`` keeps it before a
    sample after a gap is put in the stream.
    """
    window = flight_window(ball, len(ball.times) - 1, config.max_gap, kept_history(config))
    if len(window) < GAP_FLIGHT_SAMPLES:
        return None
    try:
        fit = fit_flight(ball.times[window.start:window.stop],
                         ball.values[window.start:window.stop], 1.0)
    except ValueError:  # (stamps too bunched for a fit)
        return None
    return GapFlight(fit, ball.times[window.stop - 1])


def on_gap_flight(ball: Stream, k: int, ta: float, config: DetectorConfig,
                  kept: Optional[GapFlight]) -> Optional[Judged]:
    """
    Return whether each of a ball segment's samples up to k lies on the flight before its gap.

    Sample k is its segment's first to third, after a gap longer than ``max_gap`` (not a
    jump the speed check took: ``gate.speed_check``); ta (s) opens the union interval
    visited. The samples before the gap that no trim can have taken (within
    ``kept_history`` of ta: the node's and ``analyze``'s streams hold them alike), at least
    ``GAP_FLIGHT_SAMPLES`` with no gap between them, are fitted with a parabola per
    coordinate (``motion.flight``); the segment's samples up to k lie on it continued over
    the gap where each is within ``GAP_FLIGHT_SLACK`` and the noise's
    ``DEPARTURE_CHI_SQUARE`` bound (the noise: the stream's, or the fit's own residuals'
    where larger: a noise not yet estimated) of it; a glitch, or a ball deflected in the
    gap, is not. Where too few are held (a longer gap), the flight kept before it
    (``kept``: ``flight_before_gap``) instead, each sample within the drift
    ``GAP_FLIGHT_JERK`` makes over the gap (``gap_bias``; at least ``GAP_FLIGHT_SLACK``)
    and the noise's bound; none where that drift exceeds ``GAP_FLIGHT_BIAS`` at the
    segment's first sample. One flag a sample from the segment's first, with the parabola
    through those samples (or that flight's) and the segment's up to k
    (``motion.flight.FlightFit``). None where there are too few such samples (or they are
    too bunched for a fit).
    """
    gap, reach = config.max_gap, ta - kept_history(config)
    first = k
    while first > max(k - 3, 0) and not segment_starts(ball, first, gap):
        first -= 1
    if first >= 1 and ball.times[first] - ball.times[first - 1] <= gap:
        return None  # (a segment the speed check started: another ball)
    before = range(bisect_left(ball.times, reach), first)
    if first < 1 or ball.times[first - 1] < reach or len(before) < GAP_FLIGHT_SAMPLES:
        return _on_kept_flight(ball, first, k, config, kept)
    if not all(ball.continuous(j, gap) for j in before[:-1]):
        return None
    sigma = stream_noise(ball, config)
    if not sigma > 0.0:
        sigma = DEPARTURE_FLOOR  # (the fit's coefficients do not depend on it)
    try:
        fit = fit_flight(ball.times[before.start:first], ball.values[before.start:first],
                         sigma)
        whole = fit_flight(ball.times[before.start:k + 1], ball.values[before.start:k + 1],
                           sigma)
    except ValueError:  # (stamps too bunched for a fit)
        return None
    noise = _flight_noise(stream_noise(ball, config), fit)
    return tuple(_on_flight(fit, noise, ball.times[j], ball.values[j], GAP_FLIGHT_SLACK)
                 for j in range(first, k + 1)), whole


def _on_kept_flight(ball: Stream, first: int, k: int, config: DetectorConfig,
                    kept: Optional[GapFlight]) -> Optional[Judged]:
    """
    Return ``on_gap_flight``'s answer from the flight kept before the gap (``kept``).

    That flight is the one before the gap that ends at the ball's sample ``first`` (its
    newest stamp before it, with no sample between them); the parabola through its samples
    and the segment's up to k is fitted on that flight's values at its samples' stamps in
    place of theirs (least squares of one polynomial space: the same coefficients), its
    residuals' sum added back. None where there is no such flight, or it drifts by more
    than ``GAP_FLIGHT_BIAS`` at sample ``first``.
    """
    times = ball.times
    if kept is None or first < 1 or not (
            times[first - 1] <= kept.end < times[first] - config.max_gap):
        return None
    if gap_bias(kept.fit, times[first]) > GAP_FLIGHT_BIAS:
        return None
    sigma = stream_noise(ball, config)
    if not sigma > 0.0:
        sigma = DEPARTURE_FLOOR
    fit = kept.fit
    fit = FlightFit(fit.centre, fit.scale, fit.coefficients, fit.times,
                    fit.chi_square / (sigma * sigma), fit.dof)
    try:
        whole = fit_flight(list(fit.times) + times[first:k + 1],
                           [fit.at(t) for t in fit.times] + ball.values[first:k + 1], sigma)
    except ValueError:  # (stamps too bunched for a fit)
        return None
    whole = FlightFit(whole.centre, whole.scale, whole.coefficients, whole.times,
                      whole.chi_square + fit.chi_square, whole.dof)
    noise = _flight_noise(stream_noise(ball, config), fit)
    return tuple(_on_flight(fit, noise, times[j], ball.values[j],
                            max(GAP_FLIGHT_SLACK, gap_bias(fit, times[j])))
                 for j in range(first, k + 1)), whole


def flight_across_gap(ball: Stream, k: int, ta: float, tb: float, config: DetectorConfig,
                      kept: Optional[GapFlight]) -> Optional[PointPath]:
    """
    Return the ball's free flight over [ta, tb] (s) from before its tracking gap, or None.

    Sample k is its segment's first or second (``BallSamples._hit_before_flight``) and its
    segment's samples up to it lie on the flight before the gap (``on_gap_flight``): the
    parabola of those samples and the flight's, the ball's path into a contact after sample
    k, its velocity from the whole flight (not from one sample). None where there is no such
    flight to judge by, or the segment's samples leave it.
    """
    judged = on_gap_flight(ball, k, ta, config, kept)
    if judged is None or not all(judged[0]):
        return None
    return _path_over(judged[1], ta, tb)


def off_gap_flight(ball: Stream, k: int, ta: float, config: DetectorConfig,
                   kept: Optional[GapFlight]) -> bool:
    """
    Return whether the ball's sample k, its segment's first, is off its flight alone.

    Off the flight before its tracking gap while its segment's next sample is on it
    (``on_gap_flight``; ta, s: the union interval visited): a hit or a deflection in the gap
    would leave both off it, a hit after sample k both on it. Judged before the samples
    after it (which a glitch as the one before them makes look off the flight after them);
    False where there is no flight before the gap to judge by.
    """
    if k + 1 >= len(ball.times) or not ball.continuous(k, config.max_gap):
        return False
    judged = on_gap_flight(ball, k + 1, ta, config, kept)
    return judged is not None and judged[0] == (False, True)


def left_gap_flight(ball: Stream, k: int, ta: float, tb: float, config: DetectorConfig,
                    kept: Optional[GapFlight]) -> Optional[PointPath]:
    """
    Return the flight before the gap over [ta, tb] (s) where the ball left it after sample k.

    Sample k is its segment's third. Where the segment's first three samples lie on the
    ball's flight before its tracking gap (``on_gap_flight``) and its fourth, sample
    k + 1, is off the parabola through that flight and those three continued to it (by more
    than ``DEPARTURE_FLOOR``, ``GAP_FLIGHT_SLACK`` and the noise's ``DEPARTURE_CHI_SQUARE``
    bound at that continuation's gain; the noise the stream's, or the fit's residuals' where
    larger), the ball left that flight between samples k and k + 1: that parabola over the
    union interval [ta, tb] (``BallSamples._solved_on_gap_flight`` solves the hit on it).
    None where the rule does not hold.
    """
    gap = config.max_gap
    if k < 2 or k + 1 >= len(ball.times) or not (
            ball.continuous(k, gap) and ball.continuous(k - 1, gap)
            and ball.continuous(k - 2, gap) and segment_starts(ball, k - 2, gap)):
        return None
    judged = on_gap_flight(ball, k, ta, config, kept)
    if judged is None or not all(judged[0]):
        return None
    whole = judged[1]
    noise = _flight_noise(stream_noise(ball, config), whole)
    if _on_flight(whole, noise, ball.times[k + 1], ball.values[k + 1],
                  DEPARTURE_FLOOR + GAP_FLIGHT_SLACK):
        return None
    return _path_over(whole, ta, tb)


def gap_bias(fit: FlightFit, t: float) -> float:
    """
    Return how far (m) a flight may drift from its parabola ``fit`` continued to t (s).

    ``GAP_FLIGHT_JERK`` (its acceleration changing at that rate the whole time): a cubic
    ``jerk (t - t_n)^3 / 6`` less the parabola's least-squares fit to it at the fit's
    stamps, at t (``FlightFit.weights``; t_n the newest stamp, for the conditioning).
    """
    newest = fit.times[-1]
    weights = fit.weights(t)[0]
    cubes = [(u - newest) ** 3 for u in fit.times]
    return GAP_FLIGHT_JERK / 6.0 * abs((t - newest) ** 3 - float(weights @ cubes))


def segment_starts(stream: Stream, k: int, max_gap: float) -> bool:
    """Return whether sample k starts a segment (the first kept one: where it was a start)."""
    return stream.breaks[k] if k == 0 else not stream.continuous(k - 1, max_gap)


def _path_over(fit: FlightFit, ta: float, tb: float) -> PointPath:
    """Return a flight fit over [ta, tb] (s) as a ball's path (its states at both ends)."""
    (p0, v0), (p1, v1) = fit.state(ta), fit.state(tb)
    return PointPath(ta, tb, p0, p1, v0, v1)


def _flight_noise(noise: float, fit: FlightFit) -> float:
    """
    Return the noise (m, 1 sigma) a flight fit's continuation is judged by (``_on_flight``).

    ``noise``, the stream's, or the fit's own residuals' where larger (a noise not estimated
    yet); the fit made with ``noise``, or ``DEPARTURE_FLOOR`` where that is not above 0.
    """
    return max(noise, (noise if noise > 0.0 else DEPARTURE_FLOOR) * math.sqrt(
        fit.chi_square / fit.dof))


def _on_flight(fit: FlightFit, noise: float, t: float, value: Vector, slack: float) -> bool:
    """
    Return whether a ball sample (``value``, m, at t s) lies on a flight fit continued to t.

    Within ``slack`` (m) and the ``DEPARTURE_CHI_SQUARE`` bound of ``noise`` (m,
    ``_flight_noise``) at the fit's gain there (``motion.flight.FlightFit.weights``).
    """
    weights = fit.weights(t)[0]
    return math.dist(fit.state(t)[0], value) <= slack + math.sqrt(
        DEPARTURE_CHI_SQUARE * (1.0 + float(weights @ weights))) * noise
