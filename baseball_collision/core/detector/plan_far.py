"""
Which union intervals of a chunk's plan are far from contact: the sweep's far tests on arrays.

``plans.plan_chunk`` walks a chunk's samples as if each were accepted (``plans._walk``: the
cursor's union index after each sample). Here, which of the union intervals that walk visits
the sweep's far tests clear with room to spare, all at once (the vectorised broad phase), and
so which samples visit one they do not (:func:`near_samples`: stops, sent through ``add``).

An interval is far when both streams are continuous over it (``Stream.continuous``:
:func:`_closed`, :func:`_continuous`) and the first test clears it (``broadphase.apart_margins``,
the scalar ``clearly_apart`` on arrays: bounding spheres and hulls of the raw samples) or,
where it does not, the second (``broadphase.path_margins``: the motion paths' spheres, as
``Sweep.interval`` builds them; ``rigid`` and ``spline`` only). Times in s, margins and
points in m.

Why it is exact: an interval is cleared only by a test the sweep itself would pass on it, by
``SLACK`` (relative, of the scene's size) more than the sweep's margin, so floating-point
differences between the array and scalar forms cannot clear one the sweep would solve; under
``c2`` with ``tracker_noise`` auto, the hulls' allowance for smoothing is the noise
estimators' bound (:func:`_hull_reaches`), at least what they may say when the sweep gets
there. Every interval not cleared makes the samples whose walk visits it stops: no interval
the one-at-a-time path would solve is skipped.
"""

from typing import Optional, Tuple, TYPE_CHECKING

import numpy as np

from .broadphase import apart_margins, NOISE_REACH, path_margins
from .broadphase.arrays import SLACK
from .config import DetectorConfig
from .departure import DEPARTURE_FLOOR, departure_reaches
from .noise import NoiseEstimate
from ..geometry import norm, Vector
from ..toi import _kernel

if TYPE_CHECKING:  # (plans imports this module)
    from .plans import Arrays, Plan


def near_samples(config: DetectorConfig, offsets: Tuple[Vector, Vector], plan: 'Plan',
                 arrays: 'Arrays', is_ball: np.ndarray, is_bat: np.ndarray, ok: np.ndarray,
                 noise: Optional[Tuple[NoiseEstimate, NoiseEstimate]]) -> np.ndarray:
    """
    Return the samples whose walk visits a union interval the far tests do not clear.

    The intervals the plan's walk visits (``Plan.union``, ``Plan.visited``), tested by
    :func:`_far_intervals` (``c2``'s hulls less :func:`_hull_reaches`).

    :param offsets: (knob, tip) in the bat's body frame (m).
    :param ok: which samples pass every check (``plan_chunk``'s; the others may start a
        segment, which the noise bound allows for).
    :param noise: the detector's noise estimators under ``tracker_noise`` auto, else None.
    :returns: the samples' indices (ascending, repeats possible).
    """
    n = plan.n
    starts = plan.union[:int(plan.visited[-1]) - 1] if n else plan.union[:0]
    far = _far_intervals(config, offsets, arrays, starts, _hull_reaches(
        config, plan, arrays, is_ball, is_bat, ok, len(starts), noise))
    return _visiting(plan.visited, np.flatnonzero(~far) + 1, n)


def _hull_reaches(config: DetectorConfig, plan: 'Plan', arrays: 'Arrays', is_ball: np.ndarray,
                  is_bat: np.ndarray, ok: np.ndarray, count: int,
                  noise: Optional[Tuple[NoiseEstimate, NoiseEstimate]]
                  ) -> Optional[np.ndarray]:
    """
    Return what ``c2``'s far test takes off the hulls for smoothing per union interval (m).

    The sweep's takes ``NOISE_REACH`` times the ball's and the bat's noise as they are when it
    sweeps the interval: ``tracker_noise`` when told; under auto, each stream's estimate after
    its newest sample at the step whose walk visits the interval (``_visiting``), at most its
    ``NoiseEstimate.bounds`` (every sample the plan does not take with room to spare may start
    a segment). None: no hulls (another model, or auto without the estimators).
    """
    if config.model != 'c2':
        return None
    if config.tracker_noise >= 0.0:
        return np.full(count, NOISE_REACH * 2.0 * config.tracker_noise)
    if noise is None:
        return None
    steps = np.minimum(np.searchsorted(plan.visited, np.arange(count) + 1, 'right'),
                       len(ok) - 1)  # (every interval up to the last is visited: ``_visiting``)
    reach = np.zeros(count)
    for s, (mine, points) in enumerate(((is_ball, arrays.ball), (is_bat, arrays.positions))):
        pre = arrays.pre[s]
        breaks = arrays.breaks[s].copy()
        breaks[pre:] |= ~ok[mine][:len(breaks) - pre]
        # (first the estimate now: after a kept sample, none of the chunk's taken yet)
        bounds = np.concatenate(([noise[s].sigma], noise[s].bounds(arrays.times[s], points,
                                                                   breaks, pre)))
        reach += bounds[np.asarray(plan.counts[s])[steps] - pre]
    return NOISE_REACH * reach


def _far_intervals(config: DetectorConfig, offsets: Tuple[Vector, Vector], arrays: 'Arrays',
                   starts: np.ndarray, hull_reach: Optional[np.ndarray] = None) -> np.ndarray:
    """
    Return which union intervals (by their start times, s) the sweep's far tests clear.

    Both streams without a gap over them, then the first test (``apart_margins``) or, where it
    does not clear, the second (``path_margins``), each by ``SLACK`` more than the sweep's
    margin. ``hull_reach``: ``c2``'s allowance for smoothing off the hulls (m, per interval;
    None: no hulls).
    """
    far = np.ones(len(starts), bool)
    located, segments = [], []
    # (the neighbours in a segment: the spline's bulges and the rigid and spline paths' spheres
    # read them; the linear and c2 far tests do not, and are given -1: none)
    neighbours = config.model in ('rigid', 'spline')
    for s in (0, 1):
        k = search_right(arrays.times[s], starts) - 1
        times, cut = arrays.times[s], arrays.breaks[s]
        closed = _closed(times, cut, config.max_gap)
        far &= _continuous(closed, k)
        if neighbours:
            before = np.where((k >= 1) & _continuous(closed, k - 1), k - 1, -1)
            after = np.where(_continuous(closed, k + 1), k + 2, -1)
        else:
            before = after = np.full(len(k), -1)
        located.append((k, before, after))
        segments.append(closed)
    if not len(starts):
        return far
    (ball_k, ball_before, ball_after), (bat_k, bat_before, bat_after) = located
    margin = (config.ball_radius + config.profile.max_radius + 1e-6
              + max(config.near_miss_threshold, config.rearm_distance))
    with np.errstate(all='ignore'):
        margin += SLACK * (1.0 + float(np.abs(arrays.ball).max(initial=0.0))
                           + float(np.abs(arrays.tips).max(initial=0.0)))
        clear = far & (apart_margins(
            arrays.ball, arrays.knobs, arrays.tips, arrays.positions, ball_k, bat_k,
            ball_before, ball_after, bat_before, bat_after, arrays.times[0], arrays.times[1],
            config.model, config.look_ahead, config.spline_window, margin,
            tuple(segments), hull_reach) > margin)
        # the sweep's second test (the motion paths' spheres) where the first did not clear
        # (c2's second stage is apart_margins' own)
        # (nor, for the spline, before a departure: its tangent there skips the sample after)
        near = np.flatnonzero(far & ~clear) if config.model not in ('linear', 'c2') else []
        if len(near):
            # the ball's free flight where it has left it (``departure``), as apart_margins
            reach = departure_reaches(arrays.ball, arrays.times[0], ball_k[near], segments[0])
            ahead = departure_reaches(arrays.ball, arrays.times[0], np.minimum(
                ball_k[near] + 1, len(arrays.times[0]) - 2), segments[0])
            clear[near] = (path_margins(
                arrays.ball, arrays.knobs, arrays.tips, arrays.quaternions, ball_k[near],
                bat_k[near], ball_before[near], ball_after[near], bat_before[near],
                bat_after[near], arrays.times[0], arrays.times[1], config.model,
                max(map(norm, offsets))) - reach > margin)
            if config.model == 'spline':
                clear[near] &= ~(ahead > DEPARTURE_FLOOR)
    return clear


def _visiting(visited: np.ndarray, intervals: np.ndarray, n: int) -> np.ndarray:
    """Return the samples whose walk visits the given intervals (m: the m-th union time)."""
    steps = np.searchsorted(visited, intervals, 'right')
    return steps[steps < n]


def _closed(times: np.ndarray, breaks: np.ndarray, max_gap: float) -> np.ndarray:
    """``Stream.continuous`` over each of a stream's sample intervals (i, i + 1)."""
    return ~breaks[1:] & (times[1:] - times[:-1] <= max_gap)


def _continuous(closed: np.ndarray, k: np.ndarray) -> np.ndarray:
    """``Stream.continuous`` over many k (False where k or k + 1 is out of range)."""
    inside = (k >= 0) & (k < len(closed))
    if not len(closed):
        return inside
    return inside & closed[np.where(inside, k, 0)]


def search_right(times: np.ndarray, keys: np.ndarray) -> np.ndarray:
    """
    Return ``np.searchsorted(times, keys, 'right')`` (int64), for ascending times and keys (s).

    The kernel's ``sorted_search``: a walk from each key's place to the next (a binary search
    each cost 4x more on a chunk's thousands of keys), the same indices.
    """
    found = np.empty(len(keys), np.int64)
    _kernel.sorted_search(np.ascontiguousarray(times, dtype=float),
                          np.ascontiguousarray(keys, dtype=float), True, found)
    return found
