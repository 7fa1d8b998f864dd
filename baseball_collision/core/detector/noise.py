"""
``tracker_noise: auto``: each stream's tracking noise estimated from its own samples.

A robust difference-based estimate over a sliding history (``HISTORY`` residuals per stream),
updated as samples arrive (the node and ``analyze`` see the same samples, so they estimate the
same noise to the bit):

* a point (the ball, a bat pose's position): the residual of each sample against the cubic
  through its four neighbours in the segment (two before, two after), i.e. the fourth divided
  difference of five consecutive samples on their own, uneven stamps, divided by its noise
  gain (the root sum of squares of its weights), so that for pure noise of sigma per
  coordinate it is a normal variate of that sigma. A motion with a bounded fourth derivative
  adds about f'''' h^4 / 6: nothing on a ballistic path, much on a bat circling at 90 Hz;
* a bat as knob and tip points: the change of the knob-tip length between consecutive samples
  (a rigid bat's length is constant: the change is the noise along the bat of both ends, of
  variance 4 sigma^2), divided by 2. No motion enters it, at any rate.

The estimate is 1.4826 times the median absolute residual (the normal's scale from its median
absolute deviation: a few residuals spoilt by motion or a glitch do not move it), 0 until
``MIN_RESIDUALS`` residuals are in, and 0 below ``NOISE_FLOOR`` (exact samples: interpolated).

Limit (measured, ``test_noise.py``): a bat pose's position has no rigid length to
check, so its residuals are fourth differences, and at 90 Hz a swing's own motion puts about
0.2 mm into them (0.7-1.5 um at 360 Hz): tell ``tracker_noise`` for pose bats at low rates.
"""

from bisect import bisect_left, insort
from collections import deque
import math
from typing import Deque, List, Optional, Sequence

from .streams import Stream

HISTORY = 384
"""Residuals each stream's estimate is the median of (coordinates count singly)."""

MIN_RESIDUALS = 12
"""Fewer residuals than this: no estimate yet (0: the samples are interpolated)."""

MAD_TO_SIGMA = 1.4826
"""A normal variate's sigma over its median absolute value."""

NOISE_FLOOR = 1e-6
"""m: an estimate below this is 0 (the samples are exact and interpolated). Exact samples
estimate float rounding and their motion's own differences: up to 3e-9 m (a pitch's drag at
90 Hz), 8e-17 m (a knob-tip bat's length); a bat pose's 0.7-1.5 um at 360 Hz is its swing's own
motion (the limit below). A smoother told 1 um
is no more accurate than the interpolant on every family at 90 and 360 Hz, and its sigmas then
miss the interpolation's own error (BENCHMARKS.md, "`tracker_noise: auto` on exact samples")."""


def divided_difference_weights(times: Sequence[float]) -> List[float]:
    """
    Return the weights of the divided difference over ``times`` (s, distinct), unscaled.

    In plain floats, each weight 1 / prod over the other stamps of (t_i - t_j), multiplied in
    stamp order: the same on every machine (no BLAS kernel in the way).
    """
    weights = []
    for i, ti in enumerate(times):
        product = 1.0
        for j, tj in enumerate(times):
            if j != i:
                product *= ti - tj
        weights.append(1.0 / product)
    return weights


class NoiseEstimate:
    """
    One stream's noise estimate (m, 1 sigma per coordinate), from its newest samples.

    The median is kept, not recomputed: the residuals' absolute values stay sorted as they come
    and go (``HISTORY`` of them), so a sample costs a bisection and a short move, not a sort.

    :param kind: ``'point'`` (fourth differences of the values, or of a pose's position) or
        ``'length'`` (changes of a knob-tip bat's length).
    """

    __slots__ = ('kind', 'residuals', 'sigma', '_sorted')

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self.residuals: Deque[float] = deque(maxlen=HISTORY)
        self.sigma = 0.0
        self._sorted: List[float] = []  # the residuals' absolute values, ascending

    def update(self, stream: Stream) -> float:
        """
        Take the residual(s) the stream's newest sample completes; return the estimate (m).

        A point's residual is that of its third-newest sample, so it needs five samples of one
        segment; a length change needs two.
        """
        found = self._residuals(stream)
        if found:
            residuals, ordered = self.residuals, self._sorted
            for residual in found:
                if len(residuals) == HISTORY:
                    del ordered[bisect_left(ordered, abs(residuals[0]))]
                residuals.append(residual)
                insort(ordered, abs(residual))
            count = len(ordered)
            if count >= MIN_RESIDUALS:
                middle = count // 2
                median = (ordered[middle] if count % 2
                          else (ordered[middle - 1] + ordered[middle]) / 2.0)
                sigma = MAD_TO_SIGMA * median
                self.sigma = sigma if sigma >= NOISE_FLOOR else 0.0
        return self.sigma

    def _residuals(self, stream: Stream) -> Optional[Sequence[float]]:
        """Return the residuals (m) the newest sample completes, or None."""
        count = 2 if self.kind == 'length' else 5
        if len(stream.times) < count or any(stream.breaks[-count + 1:]):
            return None
        values = stream.values[-count:]
        if self.kind == 'length':
            old, new = values
            return (0.5 * (math.dist(new.tip, new.knob) - math.dist(old.tip, old.knob)),)
        weights = divided_difference_weights(stream.times[-count:])
        points = [getattr(value, 'position', value) for value in values]
        middle = points[2]  # the weights sum to 0: taken about it, the motion cancels less
        gain = math.sqrt(_dot(weights, weights))
        return [_dot(weights, [point[axis] - middle[axis] for point in points]) / gain
                for axis in range(3)]


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    """Return sum(a_i b_i) added left to right (``sum`` compensates from Python 3.12 on)."""
    total = 0.0
    for x, y in zip(a, b):
        total += x * y
    return total
