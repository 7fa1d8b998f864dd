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

from bisect import bisect_left, insort
from collections import deque
from itertools import islice
import math
from typing import Deque, List, Optional, Sequence, Tuple

import numpy as np

from .streams import Stream
from ..toi import _kernel

HISTORY = 384
"""Residuals each stream's estimate is the median of (coordinates count singly)."""

KEPT_SAMPLES = HISTORY // 3
"""Points whose residuals (three each) the estimate keeps: a longer run's older ones are not
computed (``take_points``)."""

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

    The median is kept, not recomputed: the residuals' absolute values stay sorted as they come
    and go (``HISTORY`` of them), so a sample costs a bisection and a short move, not a sort.
    Where more than half the residuals are so small that the median cannot reach
    ``NOISE_FLOOR`` (``_small``: exact samples), the estimate is 0 without it: they are
    counted as they come and go, and the sorted list is made again only when an estimate
    needs it (the same estimate, to the bit).

    :param kind: ``'point'`` (fourth differences of the values, or of a pose's position) or
        ``'length'`` (changes of a knob-tip bat's length).
    """

    __slots__ = ('kind', 'residuals', 'sigma', '_sorted', '_small', '_below')

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self.residuals: Deque[float] = deque(maxlen=HISTORY)
        self.sigma = 0.0
        # the residuals' absolute values, ascending (None: not kept, made when an estimate first
        # needs it: exact samples never do, and then no residual is sorted in)
        self._sorted: Optional[List[float]] = None
        self._small: Deque[bool] = deque(maxlen=HISTORY)  # each residual's ``_small``
        self._below = 0  # how many residuals are small

    def update(self, stream: Stream) -> float:
        """
        Take the residual(s) the stream's newest sample completes; return the estimate (m).

        A point's residual is that of its third-newest sample, so it needs five samples of one
        segment; a length change needs two.
        """
        found = self._residuals(stream)
        if found:
            self._take(*found)
        return self.sigma

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
        :param times: the new samples' stamps (s), none starting a segment; ``points`` (n, 3).
        """
        if self.kind != 'point':
            raise ValueError('take_points is for point streams')
        old_times, old_points, old_breaks = before
        old_times, old_points = list(old_times)[-4:], [tuple(p) for p in old_points][-4:]
        old_breaks = list(old_breaks)[-4:]
        last_break = max((i for i, broken in enumerate(old_breaks) if broken), default=-1)
        # sample i of all (the old then the new) has a residual when i >= 4 and none of i-3..i
        # starts a segment: the new ones from the fourth after the old's last break
        first = max(4 - len(old_times), last_break + 4 - len(old_times), 0)
        if first >= len(times):
            return self.sigma
        start = len(old_times) + first - 4  # the first residual's window's oldest sample
        count = len(old_times) + len(times) - 4 - start
        if count > KEPT_SAMPLES:  # (the older ones' residuals would leave at once: not made)
            start, count = start + count - KEPT_SAMPLES, KEPT_SAMPLES
        # the samples from ``start`` on (old, then new), as floats
        new = max(start - len(old_times), 0)
        t = [float(x) for x in old_times[start:]] + np.asarray(times[new:], float).tolist()
        p = old_points[start:] + np.asarray(points[new:], float).tolist()
        self._take(*_kernel.point_residuals(t, p, 0, count, MAD_TO_SIGMA, NOISE_FLOOR))
        return self.sigma

    def _take(self, found: Sequence[float], small: Optional[Sequence[bool]] = None) -> None:
        """
        Take residuals (m) in order; set the estimate from the newest ``HISTORY``.

        :param small: whether each is small (``_small``), when the caller knows (the same
            comparison on arrays).
        """
        residuals, flags, ordered = self.residuals, self._small, self._sorted
        if small is None:
            small = [MAD_TO_SIGMA * abs(residual) < NOISE_FLOOR for residual in found]
        if len(found) <= REBUILD:  # one by one, the oldest leaving as each comes
            below = self._below
            for residual, flag in zip(found, small):
                if len(residuals) == HISTORY:
                    below -= flags[0]
                    if ordered is not None:
                        del ordered[bisect_left(ordered, abs(residuals[0]))]
                residuals.append(residual)
                flags.append(flag)
                below += flag
                if ordered is not None:
                    insort(ordered, abs(residual))
        else:  # many at once (a fast-forward): the sorted list made again when needed
            leaving = min(len(residuals) + len(found) - HISTORY, len(residuals))
            below = self._below + sum(small[-HISTORY:]) - (
                sum(islice(flags, leaving)) if leaving > 0 else 0)
            residuals.extend(found)
            flags.extend(small)
            ordered = self._sorted = None
        self._below = below
        count = len(residuals)
        if count < MIN_RESIDUALS:
            return
        middle = count // 2
        if below > middle:  # (the median is at most the middle-th smallest: small)
            self.sigma = 0.0
            return
        if ordered is None:
            ordered = self._sorted = sorted(map(abs, residuals))
        median = (ordered[middle] if count % 2
                  else (ordered[middle - 1] + ordered[middle]) / 2.0)
        sigma = MAD_TO_SIGMA * median
        self.sigma = sigma if sigma >= NOISE_FLOOR else 0.0

    def _residuals(self, stream: Stream) -> Optional[Tuple[Sequence[float], Sequence[bool]]]:
        """Return the residuals (m) the newest sample completes and which are small, or None."""
        count = 2 if self.kind == 'length' else 5
        if len(stream.times) < count or any(stream.breaks[-count + 1:]):
            return None
        values = stream.values[-count:]
        if self.kind == 'length':
            old, new = values
            residual = 0.5 * (math.dist(new.tip, new.knob) - math.dist(old.tip, old.knob))
            return (residual,), (_small(residual),)
        return _point_residuals(stream.times[-count:],
                                [getattr(value, 'position', value) for value in values])


def _small(residual: float) -> bool:
    """
    Return whether a residual (m) is too small for a median to reach ``NOISE_FLOOR``.

    ``MAD_TO_SIGMA`` times it is below the floor: a median no larger (it is at most the
    middle-th smallest residual, and rounding is monotone) gives an estimate of 0.
    """
    return MAD_TO_SIGMA * abs(residual) < NOISE_FLOOR


def _point_residuals(times: Sequence[float], points: Sequence[Sequence[float]]
                     ) -> Tuple[List[float], List[bool]]:
    """
    Return the residuals (m) of the middle of five samples (s, m) and which are small.

    One residual per coordinate; small as ``_small`` says. The compiled kernel's
    (``toi._kernel.point_residuals``, which ``take_points`` runs over a whole run): the fourth
    divided difference's weights (each 1 over the product of its stamp's differences from the
    other four, multiplied in stamp order), each residual a sum added left to right from 0.0
    about the middle sample (the weights sum to 0, so the motion cancels less), over the root
    sum of the squared weights.
    """
    return _kernel.point_residuals(times, points, 0, 1, MAD_TO_SIGMA, NOISE_FLOOR)
