"""
``clearly_apart`` over arrays: the far test of many union intervals at once (``analyze``'s chunks).

The same bounds as the scalar test (:mod:`.scalar`, :mod:`.c2`), over numpy arrays of the raw
samples, computed with numpy's own rounding; ``c2``'s by the compiled kernel
(``toi._kernel.c2_margins``), with its own.
"""

import math
from typing import NamedTuple, Optional, Tuple, Union

import numpy as np

from .c2 import _AFTER_ONE, _AFTER_TWO, _WEIGHT_LIST, C2_JUMP_BEFORE, C2_STEP_RATIO
from ..departure import departure_reaches
from ...motion import MAX_CHART_ANGLE
from ...toi import _kernel


SLACK = 1e-9
"""Relative room a check must pass by to be decided on arrays: numpy's rounding differs from
the scalar code's by a few ulps, and only a sample well inside every bound skips it (the
chunk plans' checks, ``detector.plans``)."""


def apart_margins(ball: np.ndarray, bat_knob: np.ndarray, bat_tip: np.ndarray,
                  bat_position: Optional[np.ndarray], ball_k: np.ndarray,
                  bat_k: np.ndarray, ball_before: np.ndarray, ball_after: np.ndarray,
                  bat_before: np.ndarray, bat_after: np.ndarray, ball_times: np.ndarray,
                  bat_times: np.ndarray, model: str, look_ahead: int = 0,
                  size: int = 8, margin: float = math.inf,
                  closed: Optional[Tuple[np.ndarray, np.ndarray]] = None,
                  hull_reach: Optional[np.ndarray] = None) -> np.ndarray:
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
    test's do (:func:`_c2_margins`). Computed with numpy's (and for ``c2`` the kernel's) own
    rounding: a caller that must agree with the scalar test compares with a tolerance.

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
                           look_ahead, size, margin + reach, closed or (None, None),
                           hull_reach) - reach
    b0, b1 = rows(ball, ball_k), rows(ball, ball_k + 1)
    k0, k1 = rows(bat_knob, bat_k), rows(bat_knob, bat_k + 1)
    e0, e1 = rows(bat_tip, bat_k), rows(bat_tip, bat_k + 1)
    ends = _Ends(b0, b1, k0, e0, k1, e1)
    ball_bulge = bat_growth = 0.0
    if model == 'rigid':
        bat_growth = _rigid_growth(ends, bat_position, bat_k)
    elif model == 'spline':
        ball_bulge = _bulges(ball, _BulgeWeights(ball_times, ball_k, ball_before, ball_after),
                             b0, b1)
        bat_growth = _spline_growth(ends, bat_knob, bat_tip,
                                    _BulgeWeights(bat_times, bat_k, bat_before, bat_after))
    elif model != 'linear':
        raise ValueError(f'no vectorised far test for the {model} model')
    return _clearances(ends, ball_bulge, bat_growth, margin + reach) - reach


class _Ends(NamedTuple):
    """Each interval's end samples, rows (m, 3): ``hull_separations``' arguments, in order."""

    b0: np.ndarray  # the ball at k and k + 1
    b1: np.ndarray
    k0: np.ndarray  # the knob at k, the tip at k, the knob at k + 1, the tip at k + 1
    e0: np.ndarray
    k1: np.ndarray
    e1: np.ndarray


def _rigid_growth(ends: _Ends, bat_position: Optional[np.ndarray],
                  bat_k: np.ndarray) -> np.ndarray:
    """
    Return the ``rigid`` model's growth (m) of the bat's sphere and hull over each interval.

    Half the sum of the knob's or tip's larger move and a reference move: the pose origin's
    (``bat_position``, pose input) or the knob's plus twice the change of the knob-tip length.
    """
    _, _, k0, e0, k1, e1 = ends
    turning = np.maximum(_dist(k0, k1), _dist(e0, e1))
    if bat_position is not None:
        reference = _dist(rows(bat_position, bat_k), rows(bat_position, bat_k + 1))
    else:
        reference = _dist(k0, k1) + 2.0 * np.abs(_dist(k0, e0) - _dist(k1, e1))
    return 0.5 * (turning + reference)


def _spline_growth(ends: _Ends, bat_knob: np.ndarray, bat_tip: np.ndarray,
                   weights: '_BulgeWeights') -> np.ndarray:
    """
    Return the ``spline`` model's growth (m) of the bat's sphere and hull over each interval.

    The knob's bulge, the axis' turn and bulge, and the change of the knob-tip length;
    ``weights``: the bat's neighbours and weights.
    """
    _, _, k0, e0, k1, e1 = ends
    # the knob's and the axis' bulges share the bat's neighbours and weights; the axis'
    # rows at k and k + 1 are e - k (the same subtraction as the whole axis array's)
    axis0, axis1 = e0 - k0, e1 - k1
    return (_bulges(bat_knob, weights, k0, k1)
            + 0.25 * math.pi * _dist(axis0, axis1)
            + math.pi * _bulges(bat_tip - bat_knob, weights, axis0, axis1)
            + np.abs(_dist(k0, e0) - _dist(k1, e1)))


def _clearances(ends: _Ends, ball_bulge: Union[float, np.ndarray],
                bat_growth: Union[float, np.ndarray],
                margin: Union[float, np.ndarray]) -> np.ndarray:
    """
    Return the larger of ``clearly_apart``'s two lower bounds on each interval's clearance (m).

    The bounding spheres' gap (the ball's grown by ``ball_bulge``, the bat's by ``bat_growth``,
    m), and where that is not above ``margin`` (m) the hulls' separation less both
    (``hull_separations``).
    """
    b0, b1, k0, e0, k1, e1 = ends
    ball_centre = (b0 + b1) * 0.5
    ball_radius = 0.5 * _dist(b0, b1) + ball_bulge
    bat_centre = (k0 + e0 + k1 + e1) * 0.25
    bat_radius = np.maximum(np.maximum(_dist(k0, bat_centre), _dist(e0, bat_centre)),
                            np.maximum(_dist(k1, bat_centre), _dist(e1, bat_centre))) + bat_growth
    sphere = _dist(ball_centre, bat_centre) - ball_radius - bat_radius
    near = np.flatnonzero(~(sphere > margin))  # (the hulls only where the spheres do not clear)
    if len(near) == len(sphere):
        return np.maximum(sphere, hull_separations(*ends) - ball_bulge - bat_growth)
    if len(near):
        hull = hull_separations(*(rows(each, near) for each in ends))
        for growth in (ball_bulge, bat_growth):
            hull = hull - (growth[near] if isinstance(growth, np.ndarray) else growth)
        sphere[near] = np.maximum(sphere[near], hull)
    return sphere


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
                bat_times: np.ndarray, look_ahead: int, size: int, margin: np.ndarray,
                closed: Tuple[Optional[np.ndarray], Optional[np.ndarray]],
                hull_reach: Optional[np.ndarray] = None) -> np.ndarray:
    """
    ``apart_margins`` for ``c2``: the larger clearance of ``clearly_apart``'s two stages.

    The second only where the first is not above ``margin`` (m, one per interval). The
    compiled kernel's ``c2_margins``, every interval in one call (the numpy it replaced, some
    60 operations over a chunk's arrays, cost 7x more).

    Each over the samples a full window could hold (``size`` before the interval's closing
    frame, ``look_ahead`` after it): a superset of the scalar test's window and chart, and every
    bound grows with the samples it sums over. The bat's second-stage window is cut as its
    chart cuts it (a sample turned more than ``MAX_CHART_ANGLE`` from the interval's opening
    direction ends it there, ``c2_rows``), which cuts a superset where it cuts the scalar's
    window. Within each stream's segments (``closed``): the
    second stage's windows stop at a segment's ends, as ``c2_window``'s; the first stage's
    (``c2_jump_bulge``) sum over a window that ignores segments and takes ``c2_window``'s only
    where that one's steps are uneven, so a segment's end counts only where its step is more
    than ``C2_STEP_RATIO`` times the interval's own, or less than its fraction (every window
    holding both is then uneven: a pause between pitches at a tracker's rate), else the
    stream's own end. -inf where a window's steps are more uneven than ``C2_STEP_RATIO`` (the
    scalar test gives no bound).

    :raises ValueError: arrays of the wrong shapes or an interval outside its stream.
    """
    clearance = np.empty(len(ball_k))
    _kernel.c2_margins(np.ascontiguousarray(ball, dtype=float),
                       np.ascontiguousarray(bat_knob, dtype=float),
                       np.ascontiguousarray(bat_tip, dtype=float),
                       np.ascontiguousarray(ball_k, dtype=np.int64),
                       np.ascontiguousarray(bat_k, dtype=np.int64),
                       np.ascontiguousarray(ball_times, dtype=float),
                       np.ascontiguousarray(bat_times, dtype=float),
                       *(None if each is None else np.ascontiguousarray(each, dtype=bool)
                         for each in closed),
                       look_ahead, size,
                       np.ascontiguousarray(np.broadcast_to(margin, clearance.shape), dtype=float),
                       _C2_CONSTANTS, clearance,
                       None if hull_reach is None else np.ascontiguousarray(
                           np.broadcast_to(hull_reach, clearance.shape), dtype=float))
    return clearance


_C2_CONSTANTS = np.array([C2_STEP_RATIO, _AFTER_ONE, _AFTER_TWO, *C2_JUMP_BEFORE, *_WEIGHT_LIST,
                          MAX_CHART_ANGLE])
"""The ``c2`` bounds' constants as the kernel's ``c2_margins`` takes them (``.c2``)."""


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
