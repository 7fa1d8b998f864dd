"""
``tracker_noise: auto``: each stream's tracking noise estimated from its own samples.

A robust difference-based estimate over a sliding history (``HISTORY`` residuals per stream),
updated as samples arrive (the node and ``analyze`` see the same samples, so they estimate the
same noise to the bit):

* the ball (a point, or a pose's position): the residual of each sample against the cubic
  through its four neighbours in the segment (two before, two after), i.e. the fourth divided
  difference of five consecutive samples on their own, uneven stamps, divided by its noise
  gain (the root sum of squares of its weights), so that for pure noise of sigma per
  coordinate it is a normal variate of that sigma. A motion with a bounded fourth derivative
  adds about f'''' h^4 / 6: nothing on a ballistic path;
* a bat pose's position: the same four orders higher (``POSE_SPAN``), the residual against
  the polynomial of degree 7 through its eight neighbours (the eighth divided difference of
  nine samples over its gain): a bat circling at 90 Hz puts much of its motion into fourth
  differences (0.2 mm) and some micrometres into eighth ones. Its fourth differences are
  estimated beside them, and where they read more than ``EXACT_RATIO`` times the eighth ones
  (the swing's own motion dwarfs the noise) the pose is taken as exact;
* a bat as knob and tip points: the change of the knob-tip length between consecutive samples
  (a rigid bat's length is constant: the change is the noise along the bat of both ends, of
  variance 4 sigma^2), divided by 2. No motion enters it, at any rate. It cannot see noise the
  two points share (points computed from one rigid body's noisy pose keep their length), so
  where the length reads exact the knob's own eighth differences are the estimate, read as a
  pose's position is (with the same ``EXACT_RATIO`` guard), unless the tip's eighth differences
  read more than ``EXACT_RATIO`` times the knob's: shared noise moves both ends alike (their
  ratio 0.8-3.9 at 90-360 Hz and 0.1-1 mm), while a swing's own motion, which the knob's read
  on exact samples at 60 Hz, moves the tip's 6-9 times the knob's. (Always the larger of the
  length's and the knob's was measured worse: at 90 Hz the knob's read its motion too, and
  markers with their own noise were smoothed more than their noise asks; BENCHMARKS.md,
  session 48.)

The estimate is 1.4826 times the median absolute residual (the normal's scale from its median
absolute deviation: a few residuals spoilt by motion or a glitch do not move it), 0 until
``MIN_RESIDUALS`` residuals are in, and 0 below ``NOISE_FLOOR`` (exact samples: interpolated).

A bat pose's position has no rigid length to check, so its residuals hold some of its motion
too (measured, ``test_noise.py`` and BENCHMARKS.md, "A bat pose's noise from eighth
differences"): in a swing tracked from 0.15 s before the contact, the largest estimate at 90
Hz is 13 um (median; 30 at most) from eighth differences, against 0.2 mm from fourth ones
(the estimate before session 38) and 44 um from sixth ones; 1.5 um at 120 Hz, nothing from
180 Hz on. Where the noise is as small as the swing's eighth differences, the swing fills the
fourth differences many times over and the pose is taken as exact (``EXACT_RATIO``):
interpolating it is then at least as accurate.
"""

import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .streams import Stream
from ..toi import _kernel

HISTORY = 384
"""Residuals each stream's estimate is the median of (coordinates count singly)."""

BOUND_BLOCK = 256
"""Samples of a chunk that share one upper bound on the estimate (``NoiseEstimate.bounds``):
each block's bound is an order statistic of its windows' residuals and those of the
``HISTORY // 3`` samples before it (about 1,150), so a few hits' large residuals move it
little."""

MIN_RESIDUALS = 12
"""Fewer residuals than this: no estimate yet (0: the samples are interpolated)."""

REBUILD = 48
"""More residuals than this at once: the sorted list is made again (when an estimate next
needs it), not updated one by one."""

POINT_SPAN = 5
"""Samples of a point's residual window (the ball's): fourth differences."""

POSE_SPAN = 9
"""Samples of a bat pose position's residual window: eighth differences, which read a swing's
own motion 15-100 times less than fourth ones at 90-120 Hz (none at all from 180 Hz), and
real noise as well (BENCHMARKS.md, "A bat pose's noise from eighth differences")."""

SPANS = {'point': POINT_SPAN, 'pose': POSE_SPAN}
"""The residual window of each kind of point stream (samples)."""

EXACT_RATIO = 4.0
"""A bat pose is taken as exact where its estimate (``POSE_SPAN`` differences) is below its
fourth differences' estimate over this: its own motion then puts more than four times the
noise into the residual of each sample against the cubic through its neighbours, and
interpolating it is at least as accurate as smoothing it with that noise (measured on noise
told or not: the crossing at 30-100 um at 90 Hz, where the swing's fourth differences are
0.2 mm, 10-30 um at 120 Hz (57 um), 3-10 at 180 (11) and 1 at 360 (1): a quarter to a third;
BENCHMARKS.md, "A bat pose's noise from eighth differences"). A ball's or a knob-tip bat's
residuals hold no motion to compare with."""

ESTIMATES = 'noise'
"""The key of ``Stream.aligned``'s list of the estimate after each sample (m): what the sweep of
an interval reads, the estimate after its stream's sample ``samples_ahead`` past the interval's
closing frame (``Sweep.interval``), so that it does not depend on how far the stream has run
ahead of the other when the interval is swept (the node's two streams arrive skewed, a bag's in
its recorded order). Kept by ``record`` after each sample ``Detector.add`` takes, and by a
fast-forward for its run's samples after the cursor but the stream's ``samples_ahead`` first
there (the kernel's ``record_trailing``, one by one with ``update_at``); None for its others
(no sweep reads those: at the recording's end a sweep takes the estimator's own for the
newest). The kernel keeps it under this key too."""

MAD_TO_SIGMA = 1.4826
"""A normal variate's sigma over its median absolute value."""

NOISE_FLOOR = 1e-6
"""m: an estimate below this is 0 (the samples are exact and interpolated). Exact samples
estimate float rounding and their motion's own differences: up to 3e-9 m (a pitch's drag at
90 Hz), 8e-17 m (a knob-tip bat's length); a bat pose's 0.7-1.5 um at 360 Hz is its swing's own
motion (the limit below). A smoother told 1 um
is no more accurate than the interpolant on every family at 90 and 360 Hz, and its sigmas then
miss the interpolation's own error (BENCHMARKS.md, "`tracker_noise: auto` on exact samples")."""


def _guarded(median: '_kernel.NoiseMedian', motion: Optional['_kernel.NoiseMedian']) -> float:
    """Return a median's estimate (m), or 0 where ``motion``'s reads over ``EXACT_RATIO`` it."""
    sigma = median.sigma
    if motion is not None and EXACT_RATIO * sigma < motion.sigma:
        return 0.0
    return sigma


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

    :param kind: ``'point'`` (the ball: fourth differences of its points, or of a pose's
        positions), ``'pose'`` (a bat pose: eighth differences of its positions) or
        ``'length'`` (changes of a knob-tip bat's length).
    :ivar medians: the kernel's medians a point's residuals go to (its own; a pose's fourth
        differences' too), which a fast-forward feeds directly.
    :raises ValueError: another kind.
    """

    __slots__ = ('kind', '_median', '_motion', 'medians', '_knob', '_knob_motion', '_tip')

    def __init__(self, kind: str) -> None:
        if kind not in SPANS and kind != 'length':
            raise ValueError(f"kind must be 'point', 'pose' or 'length', not {kind!r}")
        self.kind = kind
        self._median = self._made(SPANS.get(kind, POINT_SPAN))
        # (a pose's fourth differences too: how much of its motion the cubic leaves)
        self._motion = self._made(POINT_SPAN) if kind == 'pose' else None
        # (every median a sample's residuals go to: what the kernel's fast-forward feeds)
        self.medians = (self._median,) if self._motion is None else (self._median, self._motion)
        # (a knob-tip bat's knob as a pose's position: the noise its two points share)
        self._knob = self._made(POSE_SPAN) if kind == 'length' else None
        self._knob_motion = self._made(POINT_SPAN) if kind == 'length' else None
        self._tip = self._made(POSE_SPAN) if kind == 'length' else None

    @staticmethod
    def _made(span: int) -> _kernel.NoiseMedian:
        return _kernel.NoiseMedian(HISTORY, MAD_TO_SIGMA, NOISE_FLOOR, MIN_RESIDUALS, REBUILD,
                                   span)

    @property
    def span(self) -> int:
        """Return the samples of a point residual's window (``POINT_SPAN`` or ``POSE_SPAN``)."""
        return self._median.span

    @property
    def sigma(self) -> float:
        """
        Return the estimate (m): 0 until ``MIN_RESIDUALS`` are in, and below the floor.

        The floor: ``NOISE_FLOOR``; for a pose, also its fourth differences' estimate over
        ``EXACT_RATIO`` (the swing's own motion there dwarfs the noise). For knob and tip
        points, the length's, or where that reads exact (noise the points share keeps it) the
        knob's, read as a pose's position is, where the tip's eighth differences read at most
        ``EXACT_RATIO`` times it (more: the swing's motion, not noise).
        """
        sigma = _guarded(self._median, self._motion)
        if self._knob is None or sigma > 0.0:
            return sigma
        knob = _guarded(self._knob, self._knob_motion)
        return 0.0 if EXACT_RATIO * knob < self._tip.sigma else knob

    @property
    def residuals(self) -> List[float]:
        """Return the kept residuals, oldest first (m; the newest ``HISTORY``)."""
        return self._median.residuals()

    @property
    def motion_residuals(self) -> List[float]:
        """Return a pose's kept fourth-difference residuals, oldest first (m; else none)."""
        return [] if self._motion is None else self._motion.residuals()

    def take(self, found: Sequence[float]) -> float:
        """Take residuals (m) in order; return the estimate from the newest ``HISTORY`` (m)."""
        self._median.take(found)
        return self.sigma

    def update(self, stream: Stream) -> float:
        """
        Take the residual(s) the stream's newest sample completes; return the estimate (m).

        A point's residual is that of the middle one of its ``span`` newest samples, so it
        needs that many samples of one segment (a pose's fourth differences, five); a length
        change needs two.
        """
        return self.update_at(stream, len(stream.times) - 1)

    def update_at(self, stream: Stream, last: int) -> float:
        """
        Take the residual(s) the stream's sample ``last`` completes; return the estimate (m).

        ``update`` as it was when ``last`` was the newest (the samples after it unread).
        """
        if self.kind == 'length':
            if last < 1 or stream.breaks[last]:
                return self.sigma
            old, new = stream.values[last - 1], stream.values[last]
            self._median.take((0.5 * (math.dist(new.tip, new.knob) -
                                      math.dist(old.tip, old.knob)),))
            first = last + 1 - POSE_SPAN
            if first >= 0:  # (the knob's window: the kernel reads the newest span samples)
                window = slice(first, last + 1)
                values = stream.values[window]
                times, breaks = stream.times[window], stream.breaks[window]
                knobs = [value.knob for value in values]
                for median in (self._knob, self._knob_motion):
                    median.take_stream(times, knobs, breaks)
                self._tip.take_stream(times, [value.tip for value in values], breaks)
            return self.sigma
        # (the kernel's: span samples of one segment, the values' points or poses' positions)
        for median in self.medians:
            median.take_stream(stream.times, stream.values, stream.breaks, last)
        return self.sigma

    def bounds(self, times: np.ndarray, points: np.ndarray, breaks: np.ndarray,
               pre: int) -> np.ndarray:
        """
        Return an upper bound (m) on the estimate after each of a chunk's samples.

        For a plan's far test (``plans``), which must clear an interval only where the sweep's
        own test will, whatever the estimate is by then. The estimate is ``MAD_TO_SIGMA``
        times a median of at least as many residuals as it holds now (and ``MIN_RESIDUALS``),
        so at most that times the matching order statistic of any set holding them: per
        ``BOUND_BLOCK`` samples, the residuals of every window of ``span`` from the sample
        where ``HISTORY`` residuals have surely come to the block's last (those without a
        possible break among their ``span - 1`` newest give three each), with the kept
        residuals where that reaches before the chunk. The kernel's (``NoiseMedian.bounds``).

        :param times, points: the stream's kept samples, then the chunk's (n,) s and (n, 3) m.
        :param breaks: (n,) where a segment starts, or may start (a sample the per-sample path
            takes: the plan cannot tell).
        :param pre: the kept samples.
        :returns: (n - pre,) bounds (m), inf where a residual is not a number.
        :raises ValueError: shapes that do not match, or a length stream's estimate.
        """
        if self.kind == 'length':
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

        What ``update`` does after each of them in turn, to the bit: each residual is that of
        its window of ``span`` samples, the kernel's (``_point_residuals``); of a run longer
        than ``HISTORY // 3`` samples (three residuals each) only the newest, as the others'
        would not be kept (the kernel's ``NoiseMedian.take_run``: its capacity over 3). The chunk
        path's fast-forward does the same from the kernel (each of ``medians``' ``take_run`` on
        the plan's arrays, already contiguous float64, then ``sigma``), without this method's
        conversions.

        :param before: the stream's newest samples before them (its windows reach the newest
            ``span - 1``): stamps (s), points (m) and whether each starts a segment.
        :param times: the new samples' stamps (s), none starting a segment; ``points`` (n, 3):
            contiguous float64 arrays (else copied).
        """
        if self.kind == 'length':
            raise ValueError('take_points is for point streams')
        old_times, old_points, old_breaks = before
        times = np.ascontiguousarray(times, float)
        points = np.ascontiguousarray(points, float)
        for median in self.medians:
            median.take_run(old_times, old_points, old_breaks, times, points)
        return self.sigma


def _point_residuals(times: Sequence[float], points: Sequence[Sequence[float]]
                     ) -> Tuple[List[float], List[bool]]:
    """
    Return the residuals (m) of the middle of an odd number of samples (s, m), which are small.

    One residual per coordinate; small: ``MAD_TO_SIGMA`` times it below ``NOISE_FLOOR``. The
    compiled kernel's (``toi._kernel.point_residuals``; ``NoiseMedian.take_points`` computes
    the same over a whole run): the window's highest divided difference's weights (each 1
    over the product of its stamp's differences from the others, multiplied in stamp order),
    each residual a sum added left to right from 0.0 about the middle sample (the weights sum
    to 0, so the motion cancels less), over the root sum of the squared weights. Five
    samples: the ball's fourth differences; nine: a bat pose's eighth.

    :raises ValueError: a window of an even number of samples, or of fewer than 3 or more than
        9.
    """
    return _kernel.point_residuals(times, points, 0, 1, MAD_TO_SIGMA, NOISE_FLOOR, len(times))


def record(stream: Stream) -> None:
    """Keep the stream's estimate (``noise``) as the one after its newest (``ESTIMATES``)."""
    kept = stream.aligned.setdefault(ESTIMATES, [])
    if len(kept) < len(stream.times) - 1:
        kept.extend([None] * (len(stream.times) - 1 - len(kept)))
    kept.append(stream.noise)
