"""
``clearly_apart`` over arrays: the far test of many union intervals at once (``analyze``'s chunks).

The same bounds as the scalar test (:mod:`.scalar`, :mod:`.c2`), over numpy arrays of the raw
samples, computed with numpy's own rounding.
"""

import math
from typing import Optional, Tuple

import numpy as np

from .c2 import _AFTER_ONE, _AFTER_TWO, _FAR_OFFSET, _WEIGHT_LIST, C2_JUMP_BEFORE, C2_STEP_RATIO
from ..departure import departure_reaches


def apart_margins(ball: np.ndarray, bat_knob: np.ndarray, bat_tip: np.ndarray,
                  bat_position: Optional[np.ndarray], ball_k: np.ndarray,
                  bat_k: np.ndarray, ball_before: np.ndarray, ball_after: np.ndarray,
                  bat_before: np.ndarray, bat_after: np.ndarray, ball_times: np.ndarray,
                  bat_times: np.ndarray, model: str, look_ahead: int = 0,
                  size: int = 8, margin: float = math.inf,
                  closed: Optional[Tuple[np.ndarray, np.ndarray]] = None) -> np.ndarray:
    """
    Return ``clearly_apart``'s clearance (m) for many intervals at once.

    The same bounds as :func:`clearly_apart` for the ``linear``, ``rigid`` and ``spline``
    models, over arrays: the clearance is the larger of its two lower bounds (the bounding
    spheres' gap, the hulls' separation less both growths); ``clearly_apart`` says True where
    it exceeds ``margin``. For ``c2``, the clearance of its first stage (``c2_jump_bulge`` and
    ``c2_reach``) with the jumps and steps of every sample a full window could hold, counted
    from the arrays' first sample, then of its second (``c2_bulge``, ``c2_bat_growth``) where
    the first does not clear: never above the scalar test's, as long as the arrays start at or
    before the stream's first kept sample (-inf where the steps are too uneven: the scalar
    test decides). With ``closed``, each window stops at its segment's ends as the scalar
    test's do (:func:`_segments`). Computed with numpy's own rounding: a caller that must agree
    with the scalar test compares with a tolerance.

    :param ball: ball samples (n_ball, 3); ``bat_knob``, ``bat_tip``: bat samples (n_bat, 3).
    :param bat_position: pose origins (n_bat, 3) for pose input, else None.
    :param ball_k, bat_k: each interval's sample interval in the streams (m,).
    :param ball_before, ball_after, bat_before, bat_after: the neighbour samples of each
        interval in its segment (``Stream.neighbours``), -1 for none (spline only).
    :param ball_times, bat_times: the samples' times (s) (spline only).
    :param model: ``linear``, ``rigid``, ``spline`` or ``c2``.
    :param look_ahead, size: the ``c2`` model's look-ahead and window (samples).
    :param margin: intervals whose first bound clears this (m) skip the second: ``c2``'s
        second stage, the other models' hulls (their clearance is then the spheres' alone,
        which already clears it).
    :param closed: per stream (ball, bat), whether each sample interval (i, i + 1) is
        continuous (``Stream.continuous``: no break at i + 1, no gap over ``max_gap``): for
        ``c2``'s windows, and for the ball's departure reach, which then stops at its segment's
        ends as the scalar test's; None: neither takes a segment into account (as if the
        streams were one segment each; bounds as large or larger).
    :returns: the clearance of each interval (m,), less the ball's ``departure_reaches``
        (the scalar test's margin grows by its ``departure_reach``).
    :raises ValueError: an unknown model.
    """
    reach = departure_reaches(ball, ball_times, ball_k, None if closed is None else closed[0])
    if model == 'c2':
        return _c2_margins(ball, bat_knob, bat_tip, ball_k, bat_k, ball_times, bat_times,
                           look_ahead, size, margin + reach, closed or (None, None)) - reach
    margin = margin + reach
    b0, b1 = rows(ball, ball_k), rows(ball, ball_k + 1)
    k0, k1 = rows(bat_knob, bat_k), rows(bat_knob, bat_k + 1)
    e0, e1 = rows(bat_tip, bat_k), rows(bat_tip, bat_k + 1)
    ball_centre = (b0 + b1) * 0.5
    ball_radius = 0.5 * _dist(b0, b1)
    bat_centre = (k0 + e0 + k1 + e1) * 0.25
    bat_radius = np.maximum(np.maximum(_dist(k0, bat_centre), _dist(e0, bat_centre)),
                            np.maximum(_dist(k1, bat_centre), _dist(e1, bat_centre)))
    ball_bulge = bat_growth = 0.0
    if model == 'rigid':
        turning = np.maximum(_dist(k0, k1), _dist(e0, e1))
        if bat_position is not None:
            reference = _dist(rows(bat_position, bat_k), rows(bat_position, bat_k + 1))
        else:
            reference = _dist(k0, k1) + 2.0 * np.abs(_dist(k0, e0) - _dist(k1, e1))
        bat_growth = 0.5 * (turning + reference)
    elif model == 'spline':
        ball_bulge = _bulges(ball, _BulgeWeights(ball_times, ball_k, ball_before, ball_after),
                             b0, b1)
        # the knob's and the axis' bulges share the bat's neighbours and weights; the axis'
        # rows at k and k + 1 are e - k (the same subtraction as the whole axis array's)
        weights = _BulgeWeights(bat_times, bat_k, bat_before, bat_after)
        axis0, axis1 = e0 - k0, e1 - k1
        bat_growth = (_bulges(bat_knob, weights, k0, k1)
                      + 0.25 * math.pi * _dist(axis0, axis1)
                      + math.pi * _bulges(bat_tip - bat_knob, weights, axis0, axis1)
                      + np.abs(_dist(k0, e0) - _dist(k1, e1)))
    elif model != 'linear':
        raise ValueError(f'no vectorised far test for the {model} model')
    ball_radius = ball_radius + ball_bulge
    bat_radius = bat_radius + bat_growth
    sphere = _dist(ball_centre, bat_centre) - ball_radius - bat_radius
    near = np.flatnonzero(~(sphere > margin))  # (the hulls only where the spheres do not clear)
    if len(near) == len(sphere):
        return np.maximum(sphere, hull_separations(b0, b1, k0, e0, k1, e1) - ball_bulge
                          - bat_growth) - reach
    if len(near):
        hull = hull_separations(*(rows(each, near) for each in (b0, b1, k0, e0, k1, e1)))
        for growth in (ball_bulge, bat_growth):
            hull = hull - (growth[near] if isinstance(growth, np.ndarray) else growth)
        sphere[near] = np.maximum(sphere[near], hull)
    return sphere - reach


def rows(points: np.ndarray, index: np.ndarray) -> np.ndarray:
    """
    Return ``points[index]``: the rows of an (n, c) array at an index array of any shape.

    ``np.take`` along the first axis: the same copy as fancy indexing (the same rows, negative
    indices from the end), 3-5x cheaper on (n, 3) rows.

    :raises IndexError: an index out of range.
    """
    return np.take(points, index, axis=0)


def hull_separations(b0: np.ndarray, b1: np.ndarray, k0: np.ndarray, e0: np.ndarray,
                     k1: np.ndarray, e1: np.ndarray) -> np.ndarray:
    """:func:`hull_separation` over rows of (m, 3) arrays (NaN rounds to no bound: -inf)."""
    centre = (b0 + b1) * 0.5
    middle = (k0 + k1) * 0.5
    axis = (e0 + e1) * 0.5 - middle
    along = np.einsum('ij,ij->i', axis, axis)
    with np.errstate(all='ignore'):
        s = np.where(along > 0.0, np.einsum('ij,ij->i', centre - middle, axis) / along, 0.0)
    s = np.clip(s, 0.0, 1.0)
    n = centre - middle - s[:, None] * axis
    length = np.sqrt(np.einsum('ij,ij->i', n, n))
    with np.errstate(all='ignore'):
        n = n / length[:, None]
        separation = (np.minimum(np.einsum('ij,ij->i', n, b0), np.einsum('ij,ij->i', n, b1))
                      - np.maximum(np.maximum(np.einsum('ij,ij->i', n, k0),
                                              np.einsum('ij,ij->i', n, e0)),
                                   np.maximum(np.einsum('ij,ij->i', n, k1),
                                              np.einsum('ij,ij->i', n, e1))))
    return np.where(length > 0.0, separation, -np.inf)


def _c2_margins(ball: np.ndarray, bat_knob: np.ndarray, bat_tip: np.ndarray,
                ball_k: np.ndarray, bat_k: np.ndarray, ball_times: np.ndarray,
                bat_times: np.ndarray, look_ahead: int, size: int, margin: float,
                closed: Tuple[Optional[np.ndarray], Optional[np.ndarray]]) -> np.ndarray:
    """
    ``apart_margins`` for ``c2``: the larger clearance of ``clearly_apart``'s two stages.

    The second only where the first is not above ``margin`` (m).

    Each over the samples a full window could hold (``size`` before the interval's closing
    frame, ``look_ahead`` after it, within the ends :func:`_segments` gives each stage): a
    superset of the scalar test's window and chart, and every bound grows with the samples it
    sums over.
    """
    lengths = _dist(bat_tip, bat_knob)
    quick = _c2_jump_bulges(ball, None, ball_times, ball_k, look_ahead, size,
                            _segments(ball_times, closed[0], ball_k, True))
    bulge = _c2_jump_bulges(bat_knob, lengths, bat_times, bat_k, look_ahead, size,
                            _segments(bat_times, closed[1], bat_k, True))
    b0, b1 = rows(ball, ball_k), rows(ball, ball_k + 1)
    k0, k1 = rows(bat_knob, bat_k), rows(bat_knob, bat_k + 1)
    ball_centre, ball_radius = (b0 + b1) * 0.5, 0.5 * _dist(b0, b1)
    reach = 0.5 * _dist(k0, k1) + bulge + np.maximum(lengths[bat_k], lengths[bat_k + 1])
    first = _dist(ball_centre, (k0 + k1) * 0.5) - ball_radius - quick - reach
    near = np.flatnonzero(~(first > margin))
    if len(near) == len(first):
        return np.fmax(first, _c2_window_margins(ball, bat_knob, bat_tip, lengths, ball_k,
                                                 bat_k, ball_times, bat_times, look_ahead,
                                                 size, closed))
    if len(near):
        first[near] = np.fmax(first[near], _c2_window_margins(
            ball, bat_knob, bat_tip, lengths, ball_k[near], bat_k[near], ball_times, bat_times,
            look_ahead, size, closed))
    return first


def _segments(times: np.ndarray, closed: Optional[np.ndarray], k: np.ndarray,
              uneven: bool) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return the first and the last sample a ``c2`` window over each interval k may hold.

    Without ``uneven``, its segment's (no step that is not ``closed`` inside): the bounds of
    ``c2_window``, which the scalar test's second stage fits. With ``uneven``, those of
    ``c2_jump_bulge``, which sums over a window that ignores segments and takes
    ``c2_window``'s only where that one's steps are uneven: a segment's end counts only where
    its step is more than ``C2_STEP_RATIO`` times the interval's own, or less than its
    fraction, so that every window holding both is uneven (the same comparison in the same
    floats as the scalar test's: a pause between pitches at a tracker's rate), else the
    stream's own end.

    :param closed: whether each sample interval (i, i + 1) is continuous, or None (no
        segments: the stream's ends).
    :returns: (first, last) sample indices, k's shape.
    """
    n = len(times)
    first, last = np.zeros(len(k), np.int64), np.full(len(k), n - 1, np.int64)
    if closed is None:
        return first, last
    ends = np.flatnonzero(~closed) + 1  # samples whose step in crosses a segment's end
    if not len(ends):
        return first, last
    before = np.searchsorted(ends, k, 'right') - 1
    after = np.searchsorted(ends, k + 2, 'left')
    cut = before >= 0
    first = np.where(cut, ends[np.maximum(before, 0)], 0)
    stop = after < len(ends)
    last = np.where(stop, ends[np.minimum(after, len(ends) - 1)] - 1, n - 1)
    if uneven:
        h = times[k + 1] - times[k]
        step = times[first] - times[np.maximum(first - 1, 0)]
        cut &= (step > C2_STEP_RATIO * h) | (h > C2_STEP_RATIO * step)
        step = times[np.minimum(last + 1, n - 1)] - times[last]
        stop &= (step > C2_STEP_RATIO * h) | (h > C2_STEP_RATIO * step)
        first, last = np.where(cut, first, 0), np.where(stop, last, n - 1)
    return first, last


def _c2_window_margins(ball: np.ndarray, bat_knob: np.ndarray, bat_tip: np.ndarray,
                       lengths: np.ndarray, ball_k: np.ndarray, bat_k: np.ndarray,
                       ball_times: np.ndarray, bat_times: np.ndarray, look_ahead: int,
                       size: int,
                       closed: Tuple[Optional[np.ndarray], Optional[np.ndarray]]) -> np.ndarray:
    """Return the clearance (m) of ``clearly_apart``'s second ``c2`` stage over many intervals."""
    ball_k, ball_of = np.unique(ball_k, return_inverse=True)
    bat_k, bat_of = np.unique(bat_k, return_inverse=True)
    # the window's weights (``c2_bulge``, ``c2_bat_growth``), once per sample interval
    ball_window = _Windows(ball_times, ball_k, look_ahead, size,
                           _segments(ball_times, closed[0], ball_k, False))
    ball_bulge = ball_window.bulges(rows(ball, ball_window.index))[ball_of]
    ball_uneven = ball_window.uneven[ball_of]
    bat_window = _Windows(bat_times, bat_k, look_ahead, size,
                          _segments(bat_times, closed[1], bat_k, False))
    index = bat_window.index
    axes = (bat_tip - bat_knob) / lengths[:, None]
    origin = rows(axes, bat_k)
    rotations = _rotations_to(origin[:, None], rows(axes, index))
    knob = bat_window.bulges(rows(bat_knob, index))
    turn = bat_window.bulges(rotations)
    stretch = bat_window.bulges(lengths[index][:, :, None])
    half_cos = np.cos(0.5 * np.sqrt((rotations[:, size - 1] ** 2).sum(1)))
    length0, length1 = lengths[bat_k], lengths[bat_k + 1]
    growth = (knob + stretch + (np.maximum(length0, length1) + stretch) * (1.0 - half_cos + turn)
              + 0.25 * np.abs(length1 - length0) * _dist(origin, rows(axes, bat_k + 1)))[bat_of]
    ball_k, bat_k = ball_k[ball_of], bat_k[bat_of]
    b0, b1 = rows(ball, ball_k), rows(ball, ball_k + 1)
    k0, k1 = rows(bat_knob, bat_k), rows(bat_knob, bat_k + 1)
    e0, e1 = rows(bat_tip, bat_k), rows(bat_tip, bat_k + 1)
    ball_centre, ball_radius = (b0 + b1) * 0.5, 0.5 * _dist(b0, b1)
    bat_centre = (k0 + e0 + k1 + e1) * 0.25
    bat_radius = np.maximum(np.maximum(_dist(k0, bat_centre), _dist(e0, bat_centre)),
                            np.maximum(_dist(k1, bat_centre), _dist(e1, bat_centre)))
    second = _dist(ball_centre, bat_centre) - ball_radius - ball_bulge - bat_radius - growth
    second[ball_uneven | bat_window.uneven[bat_of]] = -np.inf
    return np.nan_to_num(second, nan=-np.inf)


def _rotations_to(reference: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """``c2.rotation_to`` over rows (rad, (..., 3)), the rows broadcast."""
    ax, ay, az = reference[..., 0], reference[..., 1], reference[..., 2]
    bx, by, bz = direction[..., 0], direction[..., 1], direction[..., 2]
    turn = np.stack((ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx), axis=-1)
    sine = np.sqrt((turn * turn).sum(-1))
    cosine = ax * bx + ay * by + az * bz
    with np.errstate(all='ignore'):
        angle = np.where(sine < 1e-15, 0.0, np.arctan2(sine, cosine) / sine)
    return turn * angle[..., None]


class _Windows:
    """
    The samples a full ``c2`` window could hold, for many intervals k of one stream.

    From ``size`` samples before each interval's closing frame (not before the first of
    ``bounds``) to ``look_ahead`` after it (not past the last of ``bounds``).

    :ivar index: (m, W) the sample k + o of each interval, o from 2 - ``size`` to
        ``look_ahead`` + 1 (clipped into the stream); ``weights``: (m, W) ``C2_SAFETY`` times
        its cardinal weight, 0 outside the window.
    :ivar uneven: where the window's steps are more uneven than ``C2_STEP_RATIO`` (the scalar
        test gives no bound).
    """

    def __init__(self, times: np.ndarray, k: np.ndarray, look_ahead: int, size: int,
                 bounds: Tuple[np.ndarray, np.ndarray]) -> None:
        n = len(times)
        offsets = np.arange(2 - size, look_ahead + 2)
        m = k[:, None] + offsets
        first = np.maximum(k + 2 - size, bounds[0])[:, None]
        inside = (m >= first) & (m <= np.minimum(k + 1 + look_ahead, bounds[1])[:, None])
        self.index = np.minimum(np.maximum(m, 0), n - 1)
        self.weights = np.where(inside, np.array(_WEIGHT_LIST)[_FAR_OFFSET + offsets], 0.0)
        self.centre = size - 2  # the column of offset 0
        self.k, self.times = k, times
        steps = np.zeros(n)
        steps[1:] = times[1:] - times[:-1]
        step = steps[self.index]
        within = inside & (m > first)
        longest = np.where(within, step, 0.0).max(1)
        shortest = np.where(within, step, np.inf).min(1)
        self.uneven = longest > C2_STEP_RATIO * shortest

    def bulges(self, values: np.ndarray) -> np.ndarray:
        """
        ``c2_bulge`` over the windows (the values' units).

        :param values: (m, W, c): each interval's window values (``index``).
        """
        c = self.centre
        p0 = values[:, c]
        t0 = self.times[self.k]
        dt = self.times[self.index] - t0[:, None]
        rate = (values[:, c + 1] - p0) / dt[:, c + 1, None]
        d = values - p0[:, None] - rate[:, None] * dt[:, :, None]
        return (self.weights * np.sqrt((d * d).sum(2))).sum(1)


def _c2_jump_bulges(points: np.ndarray, lengths: Optional[np.ndarray], times: np.ndarray,
                    k: np.ndarray, look_ahead: int, size: int,
                    bounds: Tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """
    ``c2_jump_bulge`` over many intervals k of one stream (m; inf where it gives no bound).

    Over every sample a full window could hold within ``bounds`` (each interval's first and
    last sample, :func:`_segments`), counted from the arrays' first sample: the sum over the
    jumps is taken for every sample at once (the jumps before the first sample are 0, as the
    first's own), then read at k; the few windows ``bounds`` cut shorter (a pitch's first
    and last after a pause) are summed again over their own samples.

    :param points: the ball's samples or the bat's knobs (n, 3); ``lengths``: the bat's
        knob-to-tip lengths (n,), None for the ball; ``times``: (n,) s.
    """
    n = len(times)
    steps = np.zeros(n)
    steps[1:] = times[1:] - times[:-1]
    jumps = np.zeros(n + look_ahead + 2)
    if n >= 3:
        h0, h1 = steps[1:-1, None], steps[2:, None]
        a, b, c = points[:-2], points[1:-1], points[2:]
        jumps[1:n - 1] = np.sqrt((((c - b) / h1 - (b - a) / h0) ** 2).sum(1))
        if lengths is not None:
            la, lb, lc = lengths[:-2], lengths[1:-1], lengths[2:]
            jumps[1:n - 1] += np.abs((lc - lb) / h1[:, 0] - (lb - la) / h0[:, 0])
    # per sample m: the weighted jumps before it, the longest and shortest step in its window
    # reaching the stream's ends only, then read at k
    padded = np.concatenate((np.zeros(size), jumps[:n]))
    before = np.zeros(n)
    for a in range(size - 2):
        before += C2_JUMP_BEFORE[a] * padded[size - a:size - a + n]
    high = np.concatenate((np.full(size, -np.inf), [-np.inf], steps[1:],
                           np.full(look_ahead + 2, -np.inf)))
    low = np.concatenate((np.full(size, np.inf), [np.inf], steps[1:],
                          np.full(look_ahead + 2, np.inf)))
    longest, shortest = np.full(n, -np.inf), np.full(n, np.inf)
    for o in range(3 - size, look_ahead + 2):
        longest = np.maximum(longest, high[size + o:size + o + n])
        shortest = np.minimum(shortest, low[size + o:size + o + n])
    bound, longest, shortest = before[k], longest[k], shortest[k]
    last = np.minimum(k + 1 + look_ahead, n - 1)
    # the windows ``bounds`` cut shorter: their own sums (the same terms, those inside)
    first = np.maximum(k + 2 - size, bounds[0])
    cut = np.flatnonzero((first > k + 2 - size) & (first > 0) | (bounds[1] < last))
    if len(cut):
        i, first = k[cut], first[cut]
        last[cut] = end = np.minimum(last[cut], bounds[1][cut])
        back = i[:, None] - np.arange(size - 2)  # (the samples k - a, a = 0 .. size - 3)
        bound[cut] = np.where(back > first[:, None], np.array(C2_JUMP_BEFORE[:size - 2])
                              * jumps[np.maximum(back, 0)], 0.0).sum(1)
        into = i[:, None] + np.arange(3 - size, look_ahead + 2)  # (the steps into them)
        inside = (into > first[:, None]) & (into <= end[:, None])
        step = steps[np.clip(into, 0, n - 1)]
        longest[cut] = np.where(inside, step, -np.inf).max(1)
        shortest[cut] = np.where(inside, step, np.inf).min(1)
    after = last - k
    bound = bound + np.where(after > 1, _AFTER_ONE * jumps[k + 1], 0.0)
    bound = bound + np.where(after > 2, _AFTER_TWO * (2.0 * jumps[k + 1] + jumps[k + 2]), 0.0)
    return np.where(longest > C2_STEP_RATIO * shortest, np.inf, longest * bound)


def _dist(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the row-wise distances between two (m, 3) arrays."""
    d = a - b
    return np.sqrt(np.einsum('ij,ij->i', d, d))


class _BulgeWeights:
    """
    ``bulge_bounds``' neighbours and weights over many intervals k of one stream.

    What its bound over any point picked from the stream's samples shares: the step, the
    neighbour before (after) each interval where there is one (-1: none) and its weight
    ``0.885 h / step`` (``0.635 h / step``), the same operations in the same order.
    """

    __slots__ = ('has_before', 'before', 'before_weight', 'has_after', 'after', 'after_weight')

    def __init__(self, times: np.ndarray, k: np.ndarray, before: np.ndarray,
                 after: np.ndarray) -> None:
        h = times[k + 1] - times[k]
        self.has_before = has = before >= 0
        self.before = b = np.where(has, before, k)
        self.before_weight = 0.885 * h / np.where(has, times[k] - times[b], 1.0)
        self.has_after = has = after >= 0
        self.after = a = np.where(has, after, k + 1)
        self.after_weight = 0.635 * h / np.where(has, times[a] - times[k + 1], 1.0)


def _bulges(points: np.ndarray, weights: _BulgeWeights, here: np.ndarray,
            there: np.ndarray) -> np.ndarray:
    """
    ``bulge_bounds`` of one picked point over many intervals (``weights``' k).

    :param points: the point over the stream's samples (n, 3); ``here``, ``there``: its rows at
        each interval's k and k + 1 (m, 3).
    """
    bound = 3.04 * _dist(here, there)
    bound = bound + np.where(weights.has_before, weights.before_weight
                             * _dist(rows(points, weights.before), here), 0.0)
    return bound + np.where(weights.has_after, weights.after_weight
                            * _dist(there, rows(points, weights.after)), 0.0)
