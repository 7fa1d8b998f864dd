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
0.2 mm into them (0.7-1.5 um at 360 Hz). The median reads that only while the swing is most of
the history: with the bat tracked 0.35 s or more before the contact (its stance and load), an
exact pose at 90 Hz estimates 0 again on every family (BENCHMARKS.md, "A pose bat's phantom
noise"). For a pose bat whose stream starts with the swing, tell ``tracker_noise``.
"""

import math
from typing import List, Sequence, Tuple

import numpy as np

from .streams import Stream
from ..toi import _kernel

HISTORY = 384
"""Residuals each stream's estimate is the median of (coordinates count singly)."""

KEPT_SAMPLES = HISTORY // 3
"""Points whose residuals (three each) the estimate keeps: a longer run's older ones are not
computed (``take_points``)."""

BOUND_BLOCK = 256
"""Samples of a chunk that share one upper bound on the estimate (``NoiseEstimate.bounds``):
each block's bound is an order statistic of its windows' residuals and those of the
``KEPT_SAMPLES`` before it (about 1,150), so a few hits' large residuals move it little."""

MIN_RESIDUALS = 12
"""Fewer residuals than this: no estimate yet (0: the samples are interpolated)."""

REBUILD = 48
"""More residuals than this at once: the sorted list is made again (when an estimate next
needs it), not updated one by one."""

MAD_TO_SIGMA = 1.4826
"""A normal variate's sigma over its median absolute value."""

NOISE_FLOOR = 1e-6
"""m: an estimate below this is 0 (the samples are exact and interpolated). Exact samples
estimate float rounding and their motion's own differences: up to 3e-9 m (a pitch's drag at
90 Hz), 8e-17 m (a knob-tip bat's length); a bat pose's 0.7-1.5 um at 360 Hz is its swing's own
motion (the limit below). A smoother told 1 um
is no more accurate than the interpolant on every family at 90 and 360 Hz, and its sigmas then
miss the interpolation's own error (BENCHMARKS.md, "`tracker_noise: auto` on exact samples")."""


class NoiseEstimate:
    """
    One stream's noise estimate (m, 1 sigma per coordinate), from its newest samples.

    The median is kept, not recomputed, by the kernel (``toi._kernel.NoiseMedian``): the
    residuals' absolute values stay sorted as they come and go (``HISTORY`` of them), so a
    sample costs a bisection and a short move, not a sort. Where more than half the residuals
    are so small that the median cannot reach ``NOISE_FLOOR`` (``MAD_TO_SIGMA`` times one is
    below it: exact samples), the estimate is 0 without it: they are counted as they come and
    go, and the values are sorted again only when an estimate needs them (the same estimate,
    to the bit). More than ``REBUILD`` residuals at once (a fast-forward) are sorted again
    when next needed.

    :param kind: ``'point'`` (fourth differences of the values, or of a pose's position) or
        ``'length'`` (changes of a knob-tip bat's length).
    """

    __slots__ = ('kind', '_median')

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self._median = _kernel.NoiseMedian(HISTORY, MAD_TO_SIGMA, NOISE_FLOOR, MIN_RESIDUALS,
                                           REBUILD)

    @property
    def sigma(self) -> float:
        """Return the estimate (m): 0 until ``MIN_RESIDUALS`` are in, and below the floor."""
        return self._median.sigma

    @property
    def residuals(self) -> List[float]:
        """Return the kept residuals, oldest first (m; the newest ``HISTORY``)."""
        return self._median.residuals()

    def take(self, found: Sequence[float]) -> float:
        """Take residuals (m) in order; return the estimate from the newest ``HISTORY`` (m)."""
        return self._median.take(found)

    def update(self, stream: Stream) -> float:
        """
        Take the residual(s) the stream's newest sample completes; return the estimate (m).

        A point's residual is that of its third-newest sample, so it needs five samples of one
        segment; a length change needs two.
        """
        if self.kind == 'length':
            if len(stream.times) < 2 or stream.breaks[-1]:
                return self._median.sigma
            old, new = stream.values[-2:]
            return self._median.take(
                (0.5 * (math.dist(new.tip, new.knob) - math.dist(old.tip, old.knob)),))
        # (the kernel's: five samples of one segment, the values' points or poses' positions)
        return self._median.take_stream(stream.times, stream.values, stream.breaks)

    def bounds(self, times: np.ndarray, points: np.ndarray, breaks: np.ndarray,
               pre: int) -> np.ndarray:
        """
        Return an upper bound (m) on the estimate after each of a chunk's samples.

        For a plan's far test (``plans``), which must clear an interval only where the sweep's
        own test will, whatever the estimate is by then. The estimate is ``MAD_TO_SIGMA``
        times a median of at least as many residuals as it holds now (and ``MIN_RESIDUALS``),
        so at most that times the matching order statistic of any set holding them: per
        ``BOUND_BLOCK`` samples, the residuals of every window of five from the sample where
        ``HISTORY`` residuals have surely come to the block's last (those without a possible
        break among their four newest give three each), with the kept residuals where that
        reaches before the chunk. The kernel's (``NoiseMedian.bounds``).

        :param times, points: the stream's kept samples, then the chunk's (n,) s and (n, 3) m.
        :param breaks: (n,) where a segment starts, or may start (a sample the per-sample path
            takes: the plan cannot tell).
        :param pre: the kept samples.
        :returns: (n - pre,) bounds (m), inf where a residual is not a number.
        :raises ValueError: shapes that do not match, or a length stream's estimate.
        """
        if self.kind != 'point':
            raise ValueError('bounds are for point streams')
        out = np.empty(len(times) - pre)
        self._median.bounds(np.ascontiguousarray(times, float),
                            np.ascontiguousarray(points, float),
                            np.ascontiguousarray(breaks, bool), pre, BOUND_BLOCK, out)
        return out

    def take_points(self, before: Tuple[Sequence[float], Sequence[Sequence[float]],
                                        Sequence[bool]],
                    times: np.ndarray, points: np.ndarray) -> float:
        """
        Take the residuals of new samples of one segment's points at once; return the estimate.

        What ``update`` does after each of them in turn, to the bit (the chunk path's
        fast-forwards): each residual is that sample's window of five, the kernel's
        (``_point_residuals``); of a run longer than ``KEPT_SAMPLES`` only the newest, as the
        others' would not be kept.

        :param before: the stream's newest samples before them (up to four): stamps (s),
            points (m) and whether each starts a segment.
        :param times: the new samples' stamps (s), none starting a segment; ``points`` (n, 3):
            contiguous float64 arrays (else copied).
        """
        if self.kind != 'point':
            raise ValueError('take_points is for point streams')
        old_times, old_points, old_breaks = before
        old_times, old_points = list(old_times)[-4:], list(old_points)[-4:]
        old_breaks = list(old_breaks)[-4:]
        last_break = max((i for i, broken in enumerate(old_breaks) if broken), default=-1)
        # sample i of all (the old then the new) has a residual when i >= 4 and none of i-3..i
        # starts a segment: the new ones from the fourth after the old's last break
        first = max(4 - len(old_times), last_break + 4 - len(old_times), 0)
        if first >= len(times):
            return self._median.sigma
        start = len(old_times) + first - 4  # the first residual's window's oldest sample
        count = len(old_times) + len(times) - 4 - start
        if count > KEPT_SAMPLES:  # (the older ones' residuals would leave at once: not made)
            start, count = start + count - KEPT_SAMPLES, KEPT_SAMPLES
        return self._median.take_points(
            old_times, old_points, np.ascontiguousarray(times, float),
            np.ascontiguousarray(points, float), start, count)


def _point_residuals(times: Sequence[float], points: Sequence[Sequence[float]]
                     ) -> Tuple[List[float], List[bool]]:
    """
    Return the residuals (m) of the middle of five samples (s, m) and which are small.

    One residual per coordinate; small: ``MAD_TO_SIGMA`` times it below ``NOISE_FLOOR``. The
    compiled kernel's (``toi._kernel.point_residuals``; ``NoiseMedian.take_points`` computes
    the same over a whole run): the fourth divided difference's weights (each 1 over the
    product of its stamp's differences from the other four, multiplied in stamp order), each
    residual a sum added left to right from 0.0 about the middle sample (the weights sum to 0,
    so the motion cancels less), over the root sum of the squared weights.
    """
    return _kernel.point_residuals(times, points, 0, 1, MAD_TO_SIGMA, NOISE_FLOOR)
