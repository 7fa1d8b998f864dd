"""
A chunk's plan under prediction: which of its frames must go through ``Predictor.predict``.

With prediction on, every step of a plan's walk that moves the cursor (a frame) is also a
frame of ``Predictor.predict``. :func:`prediction_stops` finds the due frames
(``prediction_due``, frame by frame), forecasts every due frame where the ball may reach the
bat on the plan's arrays, all in one kernel call (``prediction.forecast_outcomes``: the
predictor's fits and search, the same bits), and says which could make or clear a prediction
(stops) and the predictor's ``last_ns`` after each sample. Called by ``plans.plan_chunk``.
"""

from bisect import bisect_left
from typing import List, Optional, Tuple, TYPE_CHECKING

import numpy as np

from .bat_glitches import BAT_GLITCH_FLOOR, REGULAR_STEP
from .bat_window import newest_miss, PREDICTION_DEGREE
from .broadphase.arrays import rows, SLACK
from .config import DetectorConfig
from .predictor import Predictor
from .streams import MAX_HISTORY, Stream
from ..motion import BatSample
from ..prediction import forecast_outcomes, LIFT_MOST_SAMPLES, prediction_due
from ..toi import _kernel

if TYPE_CHECKING:  # (plans imports this module)
    from .plans import Arrays, Plan


def prediction_stops(config: DetectorConfig, plan: 'Plan', arrays: 'Arrays',
                     predictor: Predictor, origin: int, done: np.ndarray,
                     counts: List[np.ndarray], visited: np.ndarray
                     ) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return which samples must stop for the predictor and the due steps; set the due frames.

    ``done``, ``counts``, ``visited``: the walk's steps (``_walk``; a sample that takes a held
    one makes two, each a frame of the per-sample path where it moves the cursor). After each
    frame (a step that moves the cursor) ``Predictor.predict`` runs; on a due frame
    (``prediction_due``) it sets ``last_ns``, then forecasts when armed and ``_may_reach``
    holds, else clears a prediction in force. A frame between stops only visits far intervals,
    which arm: its due frame stops when a bat plan is set, or when the ball may reach the bat
    (``_may_reach`` from the newest two samples of each stream, decided here with ``SLACK`` to
    spare) and its forecasts may meet (``_forecasts_find``), or when the due frame before may
    have made a prediction (it makes another or clears it); the other due frames only move
    ``last_ns``. A due frame that reaches but finds nothing (nothing in force) still judges its
    newest bat frame after a hole or off the line through the two before it
    (``Predictor._bat_off``): it stops where that frame comes after a long step or off that
    line (``_off_line``) and is more than ``BAT_GLITCH_FLOOR`` (the least glitch floor) off the
    forecast of the frames before it (``_newest_may_be_off``, the predictor's own fit on the
    same samples), since there the predictor may suspect it. While a bat frame that held a
    prediction waits to be judged (``Predictor.suspect``) every due frame stops (a plan made
    with none is overturned where a stop leaves one: ``chunks._follow``). A prediction the
    predictor makes is one the plan allowed for (a forecast that meets is one
    ``forecast_outcomes`` finds on the same samples), so the due frame after it is a stop; a
    stop that leaves ``last_ns`` elsewhere, or a prediction in force before a due frame that is
    not a stop, overturns the plan (``_follow``).
    """
    n = plan.n
    steps = visited[1:int(done[-1]) + 1]  # the cursor's union index after each step
    moved = steps > np.concatenate(([1], steps[:-1]))
    cursors = plan.union[steps - 1]
    frames = np.flatnonzero(moved)
    # Clock.stamp over the frames: origin + int(round(t * 1e9)) (both round half to even)
    now = (origin + np.rint(cursors[frames] * 1e9).astype(np.int64)).tolist()
    due = _due_frames(now, predictor.last_ns, config.prediction_period)
    due_ns = [now[k] for k in due]
    due_steps = frames[due] + 1
    after = np.searchsorted(due_steps, done, 'right') - 1
    plan.last_due = [predictor.last_ns] + [predictor.last_ns if k < 0 else due_ns[k]
                                           for k in after.tolist()]
    due = np.searchsorted(done, due_steps)  # the sample that makes each due step
    plan.due = due.tolist()
    stops = np.zeros(n, bool)
    if not len(due):
        return stops, due_steps
    if predictor.plan is not None or predictor.suspect is not None:
        # (a plan may move the bat anywhere: _may_reach is True; a bat frame that held a
        # prediction is judged at the next forecast, whatever it finds)
        stops[due] = True
        return stops, due_steps
    ball, bat = counts[0][due_steps] - 1, counts[1][due_steps] - 1  # the newest of each
    ball_times, bat_times = arrays.times
    b0, b1 = rows(arrays.ball, ball - 1), rows(arrays.ball, ball)
    k0, k1 = rows(arrays.knobs, bat - 1), rows(arrays.knobs, bat)
    t0, t1 = rows(arrays.tips, bat - 1), rows(arrays.tips, bat)
    with np.errstate(all='ignore'):
        ball_speed = _norms(b1 - b0) / (ball_times[ball] - ball_times[ball - 1])
        bat_speed = np.maximum(_norms(k1 - k0), _norms(t1 - t0)) / (
            bat_times[bat] - bat_times[bat - 1])
        middle = k1 + (t1 - k1) * 0.5
        reach = (0.5 * _norms(t1 - k1) + config.ball_radius + config.profile.max_radius
                 + 2.0 * (ball_speed + bat_speed) * config.prediction_horizon)
        reaching = ~(_norms(b1 - middle) > reach * (1.0 + SLACK))
    finds = np.zeros(len(due), bool)
    reached = np.flatnonzero(reaching)
    if len(reached):
        finds[reached], windows = _forecasts_find(config, plan, arrays, predictor, counts,
                                                  due_steps[reached], cursors)
    # a due frame forecasts (a stop) when it may find a contact, or when the one before may
    # have (a prediction may be in force: it clears it)
    forecasts = finds | np.concatenate(([predictor.predicting], finds[:-1]))
    if len(reached):
        # one that finds nothing with nothing in force still judges its newest bat frame after
        # a hole or off the line through the two before it (``Predictor._bat_off``): a stop
        # where that frame may be off the swing
        quiet = np.flatnonzero(~forecasts[reached])
        if len(quiet):
            forecasts[reached[quiet]] = _newest_may_be_off(
                config, arrays, predictor.bat, windows[quiet, 2:4])
    stops[due] = forecasts
    return stops, due_steps


def _due_frames(now: List[int], last: Optional[int], period: float) -> List[int]:
    """
    Return which frames predict: ``prediction_due`` frame by frame, each due one the last.

    ``now``: the frames' stamps (ns), not decreasing (the cursor's, as a plan walks it), so
    after the first due frame the next is the first at least ``period`` after it: found by
    bisection, a step per due frame (every frame with a period of 0).
    """
    if not now:
        return []
    if round(period * 1e9) <= 0:
        return list(range(len(now)))
    k = 0 if prediction_due(last, now[0], period) else bisect_left(
        now, last + round(period * 1e9))  # (last is not None, and now[0] not before it)
    due = []
    while k < len(now):
        due.append(k)
        k = bisect_left(now, now[k] + round(period * 1e9), k + 1)
    return due


def _forecasts_find(config: DetectorConfig, plan: 'Plan', arrays: 'Arrays', predictor: Predictor,
                    counts: List[np.ndarray], due_steps: np.ndarray,
                    cursors: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return which due frames' forecasts may find a contact (the kernel's, all in one call).

    Each frame's windows are ``Stream.history``'s on the streams as that step of the walk
    leaves them (its counts, its trim's start: ``Plan.step_starts``), its time the cursor;
    the outcomes are
    ``prediction.forecast_outcomes``' (the predictor's own fits and search on the same
    samples: the same bits), and an undecided one (left to the predictor) may find. Also the
    windows: (frames, 5) rows of the ball's and the bat's (first, end) in the arrays and the
    first of the ball's lift (``Predictor._ball_forecast``'s ``lift_window``).
    """
    t0s = np.ascontiguousarray(cursors[due_steps - 1])
    windows = np.empty((len(due_steps), 5), np.int64)
    for s, window in ((0, config.prediction_window), (1, config.velocity_window)):
        windows[:, 2 * s:2 * s + 2] = _histories(
            arrays.times[s], arrays.breaks[s], plan.step_starts[s][due_steps],
            counts[s][due_steps], t0s, window)
    if config.lift_window > 0.0:
        windows[:, 4] = _histories(arrays.times[0], arrays.breaks[0],
                                   plan.step_starts[0][due_steps], counts[0][due_steps], t0s,
                                   config.lift_window, LIFT_MOST_SAMPLES)[:, 0]
    else:
        windows[:, 4] = windows[:, 1]
    outcomes = forecast_outcomes(
        (arrays.times[0], arrays.ball),
        (arrays.times[1], arrays.knobs, arrays.tips, arrays.quaternions), windows, t0s,
        predictor._gravity, config.ball_drag, min(config.velocity_degree, PREDICTION_DEGREE),
        config.prediction_horizon, config.ball_radius, config.profile, predictor._tolerance)
    return outcomes != 0, windows


def _newest_may_be_off(config: DetectorConfig, arrays: 'Arrays', bat: Stream,
                       windows: np.ndarray) -> np.ndarray:
    """
    Return which bat windows' newest frame may be off the swing by ``Predictor._bat_off``.

    ``windows``: (frames, 2) rows of (first, end) in the arrays' bat samples. A window of 3
    frames or more whose newest frame comes after a step over ``REGULAR_STEP`` times the one
    before (``Predictor._after_step``), or is more than ``BAT_GLITCH_FLOOR`` off the line
    through the two frames before it (``Predictor._off_line``; both decided with ``SLACK`` to
    spare: a screen that skips the fit on a swing's own frames), and, with 4 frames or more,
    is more than ``bat_glitches.BAT_GLITCH_FLOOR`` (the least ``glitch_floor``) from the
    forecast of the frames before it (``newest_miss``: the predictor's own fit on the same
    samples, the same bits); one of 3 frames is judged against the frames before its segment
    (``Predictor._third_across``), not screened further. The stream's kept samples (``bat``),
    then the chunk's made as the streams keep them (``BatSample``), only each such window's.
    """
    off = np.zeros(len(windows), bool)
    times = arrays.times[1]
    long = np.flatnonzero(windows[:, 1] - windows[:, 0] >= 3)
    last = windows[long, 1] - 1
    before, after = times[last - 1] - times[last - 2], times[last] - times[last - 1]
    long = long[(after > REGULAR_STEP * (1.0 - SLACK) * before) | _off_line(
        arrays, last, after, before, BAT_GLITCH_FLOOR * (1.0 - SLACK))]
    if not len(long):
        return off
    pre, degree = arrays.pre[1], min(config.velocity_degree, PREDICTION_DEGREE)
    for k in long.tolist():
        first, end = windows[k].tolist()
        if end - first == 3:  # (its newest judged by the frames before it: _third_across)
            off[k] = True
            continue
        # the window's own samples (the same bits from any list that holds them)
        values = bat.values[first:min(end, pre)]
        if end > pre:
            values += _kernel.bat_samples(BatSample, *arrays.new[1:], max(first - pre, 0),
                                          end - pre)
        off[k] = newest_miss(times[first:end].tolist(), values, [], 0, end - first,
                             degree) > BAT_GLITCH_FLOOR
    return off


def _off_line(arrays: 'Arrays', last: np.ndarray, after: np.ndarray, before: np.ndarray,
              floor: float) -> np.ndarray:
    """
    Return which bat samples ``last`` may be off the line through the two before them.

    ``Predictor._off_line``'s screen on the arrays' knobs and tips: more than ``floor`` (m)
    from where the step before (``before``, s), scaled to the sample's own (``after``),
    carries the sample before; True where the steps' ratio is not finite.
    """
    with np.errstate(divide='ignore', invalid='ignore'):
        ratio = (after / before)[:, None]
    off = ~np.isfinite(ratio[:, 0])
    ratio = np.where(np.isfinite(ratio), ratio, 0.0)
    for points in (arrays.knobs, arrays.tips):
        middle = points[last - 1]
        off |= _norms(points[last] - middle - (middle - points[last - 2]) * ratio) > floor
    return off


def _histories(times: np.ndarray, breaks: np.ndarray, starts: np.ndarray, counts: np.ndarray,
               t0s: np.ndarray, window: float, most: int = MAX_HISTORY) -> np.ndarray:
    """
    Return ``Stream.history(t0, window, most)`` of a stream's samples [start, count) per frame.

    As (first, end) rows in the arrays' indices (end - first < 3: too few for a forecast).
    ``times``: the stream's kept samples and the chunk's, increasing; ``breaks``: which start
    a segment.
    """
    k = np.minimum(np.searchsorted(times, t0s, 'right'), counts) - 1
    empty = k < starts
    k = np.where(empty, starts, k)
    # bisect_right(times, times[k] - window - 1e-9, max(k - most + 1, start), k)
    first = np.clip(np.searchsorted(times, times[k] - window - 1e-9, 'right'),
                    np.maximum(k - most + 1, starts), k)
    first = np.where(first > k - 1, np.where(k > starts, k - 1, starts), first)
    # within the segment: from its newest break in (first, k]
    newest_break = np.maximum.accumulate(np.where(breaks, np.arange(len(breaks)), -1))
    first = np.maximum(first, newest_break[k])
    return np.stack((first, np.where(empty, first, k + 1)), axis=1)


def _norms(rows: np.ndarray) -> np.ndarray:
    """Return the length of each row of an (m, 3) array."""
    return np.sqrt(np.einsum('ij,ij->i', rows, rows))
