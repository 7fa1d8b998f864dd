"""
A chunk's plan: what its samples do if each is accepted, computed on arrays.

:func:`plan_chunk` looks at a chunk's samples (in arrival order) all at once, as if each were
accepted: which pass every check with room to spare (the value checks, the frame, the
intake's stamp rules, the speed bound), where the watermark and the cursor go after each,
which union intervals that walk visits, and which of those the sweep's far tests clear with
room to spare (``plan_far``: the first, ``broadphase.apart_margins``, then where it does not,
the second, ``broadphase.path_margins``); and how each step trims the streams. Every other
sample (a drop, a held or voted one, one that makes a near interval decidable) is a *stop*.
A sample stamped as its stream's sample before it (a duplicate: a relay sending a message
twice), whose values and frame pass, is planned as the per-sample path drops it
(``duplicate_stamp``: its stream, the walk and the intake stay as they were): in no stream,
no stop (``Plan.duplicates``); unless the sample before it is held (below), which the
duplicate would take. A stream's first sample after a
gap is planned as the intake takes it: held until the stream's next sample, which takes both (a
pause between pitches does not end a plan); neither is a stop (the fast-forward that takes
the second appends both, the first starting a segment), unless the second is one, or with
prediction on its held sample's step is a due frame.

With prediction on, every step of the walk that moves the cursor (a frame) is also a frame
of ``Predictor.predict``: the plan forecasts every due frame where the ball may reach the bat
on its arrays, all in one kernel call (``prediction.forecast_outcomes``: the predictor's fits
and search, the same bits), and says which could make or clear a prediction
(``plan_prediction.prediction_stops``: stops) and the predictor's ``last_ns`` after each sample.

``chunks`` takes the plan: runs between stops fast-forwarded, stops through the per-sample
path. Only pose input with the ``linear``, ``rigid``, ``spline`` and ``c2`` models is planned
(:func:`plannable`).

The passes over a chunk's thousands of samples are numpy's, and the compiled kernel's
(``toi._kernel``) where numpy took many passes for one rule: the chunk's rows and value
checks (``plan_rows``), the order checks, the trims, the searches of ascending keys
(``plan_far.search_right``) and the ``c2`` far test (``broadphase.arrays``).
"""

from bisect import bisect_left
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from .broadphase.arrays import SLACK
from .config import DetectorConfig
from .events import Role
from .gate import FAR_AHEAD_NS
from .noise import NoiseEstimate
from .plan_far import near_samples, search_right
from .plan_order import duplicates_pass, held_gaps, order_checks, ordered
from .plan_prediction import prediction_stops
from .predictor import Predictor
from .streams import SILENT_KEEP, Stream, TRIM_LEAVES
from ..geometry import Vector
from ..motion import samples_ahead
from ..toi import _kernel

ROLE_CODES = {role.value: code for code, role in enumerate(Role)}
"""A role's code in ``add_chunk``'s ``roles`` array (the order of ``Role``)."""

BALL, BAT_POSE = ROLE_CODES['ball'], ROLE_CODES['bat_pose']
FAST_MODELS = ('linear', 'rigid', 'spline', 'c2')
"""Models whose far test is vectorised (``c2``: its first stage, ``broadphase.apart_margins``;
the far tests read no noise, so under ``tracker_noise`` auto too: a fast-forward gives the
estimators the run's samples in bulk, ``chunks.fast_forward``)."""

TRIM_FROM = 64
"""``Stream.trim`` leaves streams shorter than this alone."""

TRIM_KEEP = 5
"""``Stream.trim`` keeps this many samples before its cut (``keep`` + 1)."""


class Plan:
    """
    What a chunk does if every sample in it is accepted (arrays over its n samples).

    :ivar n: the samples planned.
    :ivar stops: indices of the samples that must go through the per-sample path, sorted.
    :ivar checked: which samples pass every check (a stop among them only makes a near
        interval decidable: it is appended as planned, then walked by the scheduler).
    :ivar counts: per stream (ball, bat), the stream's sample count after each sample,
        counted from the stream's first kept sample when planned (a held sample counts from
        the sample that takes it).
    :ivar starts: per stream, the index of its first kept sample after each sample's trim;
        ``step_starts``: after each step of the walk (from 0, none taken; an array).
    :ivar union: the cursor, then every union time after it (s).
    :ivar visited: after each sample, how many of ``union`` the cursor has reached.
    :ivar times, stamps: per stream, the kept samples then the chunk's (s, ns; arrays).
    :ivar breaks: per stream, which of them starts a segment (bool arrays, as ``times``): a
        held sample taken with the one that takes it (``holds``), none of the others taken.
    :ivar holds: (held sample, the sample that takes it), both in the plan and taken as planned.
    :ivar values: the chunk's ball points (n_ball, 3), and its bat samples' knob, tip,
        position and quaternion arrays.
    :ivar pre: per stream, samples it held when planned.
    :ivar duplicates: per stream, the samples dropped as ``duplicate_stamp`` (sorted lists):
        stamped as the stream's sample before them, which is taken as planned.
    :ivar last_due: with prediction on (else None), the predictor's ``last_ns`` before the
        plan, then after each sample (n + 1); ``due``: the due frames (samples, sorted);
        ``forecasts``: per sample, whether it stops for the predictor alone (it passes every
        check and only visits far intervals).

    The stops are a Python list once planned; the other per-sample indices and the union are
    read as Python numbers one at a time (:func:`items`: a run reads a few of its thousands);
    the samples stay arrays, and only those a fast-forward keeps after its trim become the
    streams' lists and tuples.
    """

    __slots__ = ('n', 'stops', 'checked', 'counts', 'starts', 'step_starts', 'union', 'visited',
                 'times', 'stamps', 'breaks', 'holds', 'values', 'pre', 'duplicates',
                 'last_due', 'due', 'forecasts')

    def duplicates_in(self, pos: int, end: int) -> Tuple[int, int]:
        """Return how many of samples pos..end-1 are duplicates: the ball's, the bat's."""
        ball, bat = self.duplicates
        return (bisect_left(ball, end) - bisect_left(ball, pos),
                bisect_left(bat, end) - bisect_left(bat, pos))

    def is_duplicate(self, j: int) -> bool:
        """Return whether sample j is one of the duplicates (dropped as ``duplicate_stamp``)."""
        for own in self.duplicates:
            k = bisect_left(own, j)
            if k < len(own) and own[k] == j:
                return True
        return False

    def next_stop(self, pos: int) -> int:
        """Return the first stop at or after sample ``pos`` (``n`` for none)."""
        k = bisect_left(self.stops, pos)
        return self.stops[k] if k < len(self.stops) else self.n

    def stops_at(self, j: int) -> bool:
        """Return whether sample j is a stop."""
        k = bisect_left(self.stops, j)
        return k < len(self.stops) and self.stops[k] == j

    def held(self, j: int, ball: Stream, bat: Stream, cursor: Optional[float]) -> bool:
        """Return whether the state after the per-sample path took sample j is the planned one."""
        for s, stream in enumerate((ball, bat)):
            count = self.counts[s][j]
            if len(stream.times) != count - self.starts[s][j] or \
                    stream.stamps[-1] != self.stamps[s].item(count - 1) or stream.breaks[-1]:
                return False
        return cursor == self.union[self.visited[j] - 1]


def items(array: np.ndarray) -> Sequence[Any]:
    """
    Return a 1-D array read as a list of Python numbers: item j is ``array.item(j)``.

    What a plan reads a few of per run (``fast_forward``): the same ``int``, ``float`` and
    ``bool`` values a ``tolist()`` would give, without making the list. A memoryview of the
    array (made contiguous): its items are read in C, negative j from the end, IndexError out
    of range.

    :param array: the values (not copied when contiguous: left unchanged).
    """
    return memoryview(np.ascontiguousarray(array))


def plannable(config: DetectorConfig) -> bool:
    """Return whether chunks are ever planned under a configuration (else one at a time)."""
    return config.bat_input == 'pose' and config.model in FAST_MODELS


def usable(config: DetectorConfig, origin: Optional[int], ball: Stream, bat: Stream,
           cursor: Optional[float], waiting: bool) -> bool:
    """Return whether a chunk can be planned now (else its samples go one at a time)."""
    return (plannable(config) and origin is not None and cursor is not None
            and not waiting and 3 <= len(ball.times) <= SILENT_KEEP // 2
            and 3 <= len(bat.times) <= SILENT_KEEP // 2)


class Arrays:
    """
    Both streams' kept samples, then a chunk's, as arrays (``plan_chunk``'s working set).

    :ivar pre: per stream, samples it held when planned.
    :ivar times, stamps, breaks: per stream (s, ns, bool).
    :ivar ball: ball points (m_ball, 3); ``knobs``, ``tips``, ``positions``: (m_bat, 3);
        ``quaternions``: (m_bat, 4) unit.
    :ivar new: the chunk's own: ball points, then the bat's knob, tip, position, quaternion.
    """

    __slots__ = ('pre', 'times', 'stamps', 'breaks', 'ball', 'knobs', 'tips', 'positions',
                 'quaternions', 'new')

    def cut(self, m_ball: int, m_bat: int) -> None:
        """Keep each stream's first m_ball and m_bat samples (the chunk's first samples)."""
        self.times = (self.times[0][:m_ball], self.times[1][:m_bat])
        self.stamps = (self.stamps[0][:m_ball], self.stamps[1][:m_bat])
        self.breaks = (self.breaks[0][:m_ball], self.breaks[1][:m_bat])
        self.ball = self.ball[:m_ball]
        self.knobs, self.tips = self.knobs[:m_bat], self.tips[:m_bat]
        self.positions, self.quaternions = self.positions[:m_bat], self.quaternions[:m_bat]
        k = m_bat - self.pre[1]
        self.new = (self.new[0][:m_ball - self.pre[0]],) + tuple(column[:k]
                                                                 for column in self.new[1:])


def plan_chunk(config: DetectorConfig, offsets: Tuple[Vector, Vector], origin: int,
               frame: Optional[str], ball: Stream, bat: Stream, cursor: float,
               roles: np.ndarray, stamps: np.ndarray, values: np.ndarray,
               frames: Sequence[str], predictor: Optional[Predictor] = None,
               noise: Optional[Tuple[NoiseEstimate, NoiseEstimate]] = None,
               newest: Optional[int] = None) -> Plan:
    """
    Plan a chunk (see the module): which samples are stops, where the walk goes after each.

    In steps: where the streams' order ends the plan, and its duplicates (``_in_order``);
    the samples as arrays and their checks (``_arrays``); where the first that fails one ends
    it, but for held samples (``_checked_end``); the walk (``_walk``); the stops of the far
    tests and the trims (``_far_stops``), of the ball's gaps and the held samples
    (``_gap_stops``), and with prediction on of the due frames (``_prediction_stops``); the
    plan's indices made lists (``_listed``).

    :param offsets: (knob, tip) in the bat's body frame (m).
    :param origin: the clock's origin (ns); ``frame``: the tracking frame (None: none yet).
    :param cursor: the scheduler's cursor (s).
    :param roles: role codes (``ROLE_CODES``); ``stamps``: int64 ns; ``values``: (n, 7)
        float64, a point in the first 3 columns; ``frames``: each sample's frame_id.
    :param predictor: the detector's, when prediction is on (``prediction_horizon`` > 0).
    :param noise: the detector's noise estimators under ``tracker_noise`` auto (``c2``'s far
        test bounds what they may say by then: ``plan_far``).
    :param newest: the intake's newest stamp taken (ns; ``Intake.newest``, which a sample
        after a gap must pass to be held; None: the streams' newest).
    """
    n, duplicates, is_ball, is_bat, duplicate, followed = _in_order(roles, stamps, ball, bat)
    arrays, ok, gap = _arrays(config, offsets, origin, ball, bat, is_ball, is_bat, roles[:n],
                              stamps[:n], values[:n], frame, frames[:n], duplicate)
    newest = max(ball.stamps[-1], bat.stamps[-1]) if newest is None else newest
    n, is_ball, is_bat, ok, held = _checked_end(arrays, ok, gap, is_ball, is_bat, stamps[:n],
                                                newest, followed)
    plan = Plan()
    plan.n, plan.pre = n, arrays.pre
    plan.duplicates = tuple(own[own < n].tolist() for own in duplicates)
    # a held sample and the one that takes it are taken as planned (the run that takes the
    # second appends both, the first starting a segment: ``Plan.breaks``); when the second is
    # past the plan's end, the first through the per-sample path, and both when the second is
    # a stop (``_gap_stops``)
    plan.holds = [(x, y) for x, y in held if y < n]
    for x, y in held:
        ok[x] = y < n
    done, counts, visited = _walk(config, plan, arrays, is_ball, is_bat, cursor, held)
    stops = _far_stops(config, offsets, plan, arrays, is_ball, is_bat, ok, noise, done, counts,
                       visited)
    _gap_stops(config, plan, arrays, is_ball, ok, stops)
    plan.last_due = plan.due = plan.forecasts = None
    if predictor is not None and n:
        _prediction_stops(config, plan, arrays, predictor, origin, ok, stops, done, counts,
                          visited)
    _listed(plan, arrays, ok, stops)
    return plan


def _in_order(roles: np.ndarray, stamps: np.ndarray, ball: Stream, bat: Stream) -> Tuple[
        int, Tuple[np.ndarray, np.ndarray], np.ndarray, np.ndarray, Optional[np.ndarray],
        Optional[np.ndarray]]:
    """
    Return how many of a chunk's samples its streams' order lets a plan reach, and its duplicates.

    The plan ends before the first sample behind its stream's last (dropped, held or a jump
    back: nothing after it can be planned until it is settled: ``plan_order.ordered``); one
    stamped as the last is a duplicate, in no stream. Second, the ball's and the bat's
    duplicates (sorted, some maybe past the end); third and fourth, which of the samples up
    to the end are the ball's and the bat's (no duplicate); then, where there are duplicates
    (else None), which of those samples are duplicates, and which a duplicate follows (it
    repeats their stamp).
    """
    ball_end, ball_duplicates, ball_before = ordered(stamps, roles == BALL, ball)
    bat_end, bat_duplicates, bat_before = ordered(stamps, roles == BAT_POSE, bat)
    n = min(ball_end, bat_end)
    duplicate = followed = None
    if len(ball_duplicates) or len(bat_duplicates):
        duplicate, followed = np.zeros(n, bool), np.zeros(n, bool)
        for own, before in ((ball_duplicates, ball_before), (bat_duplicates, bat_before)):
            duplicate[own[own < n]] = True
            followed[before[(before >= 0) & (before < n)]] = True
    is_ball, is_bat = roles[:n] == BALL, roles[:n] == BAT_POSE
    if duplicate is not None:
        is_ball &= ~duplicate
        is_bat &= ~duplicate
    return n, (ball_duplicates, bat_duplicates), is_ball, is_bat, duplicate, followed


def _checked_end(arrays: Arrays, ok: np.ndarray, gap: np.ndarray, is_ball: np.ndarray,
                 is_bat: np.ndarray, stamps: np.ndarray, newest: int,
                 followed: Optional[np.ndarray]) -> Tuple[
                     int, np.ndarray, np.ndarray, np.ndarray, List[Tuple[int, int]]]:
    """
    Return where the checks end a plan (its arrays cut there), and its held samples.

    The plan ends at its first sample that fails a check (the per-sample path will most
    likely drop it, hold it or break its stream there, and what follows be planned again),
    except a stream's first sample after a gap, held until its next takes it (``held_gaps``;
    ``newest``, ns: the intake's newest stamp before the chunk). The samples planned, which
    are the ball's and the bat's and which pass every check (``is_ball``, ``is_bat``, ``ok``
    cut to them), and the held samples with the sample that takes each.
    """
    n = len(ok)
    end, held = held_gaps(ok, gap, is_ball, is_bat, stamps, newest, followed)
    if end < n:
        n = end
        is_ball, is_bat, ok = is_ball[:n], is_bat[:n], ok[:n]
        arrays.cut(arrays.pre[0] + int(is_ball.sum()), arrays.pre[1] + int(is_bat.sum()))
    return n, is_ball, is_bat, ok, held


def _far_stops(config: DetectorConfig, offsets: Tuple[Vector, Vector], plan: Plan,
               arrays: Arrays, is_ball: np.ndarray, is_bat: np.ndarray, ok: np.ndarray,
               noise: Optional[Tuple[NoiseEstimate, NoiseEstimate]], done: np.ndarray,
               counts: List[np.ndarray], visited: np.ndarray) -> np.ndarray:
    """
    Return the stops of the checks, the far tests and the trims (a bool a sample).

    A sample that fails a check (``ok``), one whose walk visits a union interval the far
    tests do not clear (``plan_far.near_samples``), and one that makes a step
    whose trim may leave a stream silent (``_trim_starts``, which sets the plan's trims).
    """
    stops = ~ok
    stops[near_samples(config, offsets, plan, arrays, is_ball, is_bat, ok, noise)] = True
    stops |= _trim_starts(config, plan, arrays, done, counts, visited)
    return stops


def _gap_stops(config: DetectorConfig, plan: Plan, arrays: Arrays, is_ball: np.ndarray,
               ok: np.ndarray, stops: np.ndarray) -> None:
    """
    Make the ball's samples after a gap over ``max_gap`` stops, and held pairs that stop.

    A ball sample after such a gap goes through ``add`` (``_ball_restarts``). A held sample
    that stops makes its taker stop; a taker that stops walks and trims once for its held
    sample's step and its own, the per-sample path twice (a trim leaves a short stream
    alone): both through it (``_through``).
    """
    stops[_ball_restarts(config, arrays, is_ball)] = True
    for x, y in plan.holds:
        stops[y] |= stops[x]
    _through(plan, ok, stops, [(x, y) for x, y in plan.holds if stops[y]])


def _ball_restarts(config: DetectorConfig, arrays: Arrays, is_ball: np.ndarray) -> np.ndarray:
    """
    Return the chunk's ball samples after a gap over ``max_gap`` (indices, ascending).

    Each goes through ``add``, which keeps the flight before the gap (``Sweep.note_gap``)
    from samples a run's trim would drop unmade. Held samples among them (``Plan.holds``)
    then go through it with their takers (``_gap_stops``).
    """
    own = np.flatnonzero(is_ball)
    after_gap = np.diff(arrays.times[0][max(arrays.pre[0] - 1, 0):]) > config.max_gap
    return own[len(own) - len(after_gap):][after_gap]


def _prediction_stops(config: DetectorConfig, plan: Plan, arrays: Arrays, predictor: Predictor,
                      origin: int, ok: np.ndarray, stops: np.ndarray, done: np.ndarray,
                      counts: List[np.ndarray], visited: np.ndarray) -> None:
    """
    Make the samples that may make or clear a prediction stops (``prediction_stops``).

    A taker whose held sample's step is a due frame: the per-sample path predicts after that
    step (and after its own), a fast-forward after its last only: both through it
    (``_through``). Sets ``Plan.forecasts`` (and ``prediction_stops`` the plan's ``last_due``
    and ``due``).
    """
    forecasts, due_steps = prediction_stops(config, plan, arrays, predictor, origin, done,
                                            counts, visited)
    if plan.holds:
        takers = np.array([y for _, y in plan.holds], dtype=np.int64)
        due_held = np.isin(done[takers] - 1, due_steps).tolist()
        _through(plan, ok, stops, [hold for hold, due in zip(plan.holds, due_held) if due])
    forecasts &= ~stops
    stops |= forecasts
    plan.forecasts = forecasts.tolist()


def _listed(plan: Plan, arrays: Arrays, ok: np.ndarray, stops: np.ndarray) -> None:
    """
    Set the plan's stops, checks, counts and walk as lists, and its samples (``Plan``).

    The indices as lists for ``fast_forward``; the samples stay arrays, made lists (the
    streams' own values) only for those a fast-forward keeps.
    """
    plan.stops = np.flatnonzero(stops).tolist()
    plan.checked = items(ok)
    plan.counts = [items(counts) for counts in plan.counts]
    plan.visited, plan.union = items(plan.visited), items(plan.union)
    plan.times, plan.stamps, plan.breaks = arrays.times, arrays.stamps, arrays.breaks
    new_ball, knob, tip, position, quaternion = arrays.new
    plan.values = (new_ball, (knob, tip, position, quaternion))


def _through(plan: Plan, ok: np.ndarray, stops: np.ndarray,
             pairs: Sequence[Tuple[int, int]]) -> None:
    """Send held samples and their takers (``pairs`` of ``Plan.holds``) through ``add``."""
    for x, y in pairs:
        ok[x] = ok[y] = False
        stops[x] = stops[y] = True
    if pairs:
        plan.holds = [hold for hold in plan.holds if not stops[hold[1]]]


def _arrays(config: DetectorConfig, offsets: Tuple[Vector, Vector], origin: int, ball: Stream,
            bat: Stream, is_ball: np.ndarray, is_bat: np.ndarray, roles: np.ndarray,
            stamps: np.ndarray, values: np.ndarray, frame: Optional[str],
            frames: Sequence[str], duplicate: Optional[np.ndarray] = None
            ) -> Tuple[Arrays, np.ndarray, np.ndarray]:
    """
    Return the streams' kept samples and the chunk's (its poses made knob and tip), and checks.

    The chunk's rows are the kernel's ``plan_rows`` (the per-sample path's operations in its
    order: the same bits), which also checks each sample's values and stamp. Second, which
    samples pass every check with room to spare (values, frame, order; a ``duplicate``, in no
    stream: its values and frame, ``duplicates_pass``); third, which pass every check but
    the order's as the first sample after a gap that the intake holds for its stream's next
    (``plan_order.order_checks``).
    """
    arrays = Arrays()
    pre = arrays.pre = (len(ball.times), len(bat.times))
    m_ball = pre[0] + int(np.count_nonzero(is_ball))
    m_bat = pre[1] + int(np.count_nonzero(is_bat))
    arrays.ball, arrays.knobs, arrays.tips, arrays.positions = (
        np.empty((m, 3)) for m in (m_ball, m_bat, m_bat, m_bat))
    arrays.quaternions = np.empty((m_bat, 4))
    arrays.times = (np.empty(m_ball), np.empty(m_bat))
    arrays.stamps = (np.empty(m_ball, np.int64), np.empty(m_bat, np.int64))
    # the kept samples (a few dozen): from the streams' lists
    arrays.ball[:pre[0]] = np.array(ball.values, dtype=float).reshape(-1, 3)
    kept = np.array([(*s.knob, *s.tip, *s.position, *s.quaternion) for s in bat.values],
                    dtype=float).reshape(-1, 13)  # (the bat's kept samples: one conversion)
    for column, (first, end) in zip((arrays.knobs, arrays.tips, arrays.positions,
                                     arrays.quaternions), ((0, 3), (3, 6), (6, 9), (9, 13))):
        column[:pre[1]] = kept[:, first:end]
    for s, stream in enumerate((ball, bat)):
        arrays.times[s][:pre[s]] = stream.times
        arrays.stamps[s][:pre[s]] = stream.stamps
    ok = np.empty(len(stamps), bool)
    if duplicate is not None:  # (rows of no stream: the kernel leaves them out)
        repeated_points = roles[duplicate] != BAT_POSE
        roles = np.where(duplicate, np.int8(-1), roles).astype(np.int8)
    _kernel.plan_rows(roles, stamps, values, origin, (BALL, BAT_POSE), offsets,
                      (1e-3 * (1.0 - SLACK), FAR_AHEAD_NS), arrays.times[0], arrays.stamps[0],
                      arrays.ball, arrays.times[1], arrays.stamps[1], arrays.knobs, arrays.tips,
                      arrays.positions, arrays.quaternions, pre, ok)
    arrays.new = (arrays.ball[pre[0]:], arrays.knobs[pre[1]:], arrays.tips[pre[1]:],
                  arrays.positions[pre[1]:], arrays.quaternions[pre[1]:])
    if duplicate is not None:
        ok[duplicate] = duplicates_pass(values[duplicate], repeated_points)
    arrays.breaks = (
        np.concatenate((np.array(ball.breaks, dtype=bool), np.zeros(m_ball - pre[0], bool))),
        np.concatenate((np.array(bat.breaks, dtype=bool), np.zeros(m_bat - pre[1], bool))))
    n = len(stamps)
    if frames.count(frame or '') != n:  # (the common case: one frame throughout)
        ok &= np.fromiter((not f or f == frame for f in frames), bool, n)
    gap = ok.copy()
    for s, mine, points in ((0, is_ball, (arrays.ball, None)),
                            (1, is_bat, (arrays.knobs, arrays.tips))):
        in_order, after_gap = order_checks(config, arrays.stamps[s], arrays.times[s], points,
                                           pre[s])
        own = np.flatnonzero(mine)  # (once for both)
        ok[own] &= in_order
        gap[own] &= after_gap
    return arrays, ok, gap


def _walk(config: DetectorConfig, plan: Plan, arrays: Arrays, is_ball: np.ndarray,
          is_bat: np.ndarray, cursor: float,
          held: Sequence[Tuple[int, int]] = ()
          ) -> Tuple[np.ndarray, List[np.ndarray], np.ndarray]:
    """
    Set the plan's counts, union times and cursor steps: the watermark after each sample.

    The walk is made of steps, each sample taken: in arrival order, but a held sample is taken
    just before the sample that takes it (``held_gaps``), and starts a new segment.

    :param held: (sample, the sample that takes it).
    :returns: per sample, the steps taken after it (``done``); per stream, the count after each
        step from 0 (none taken); the cursor's union index after each step (from 0).
    """
    n = len(is_ball)
    order = np.arange(n)
    done = order + 1
    if held:
        pending = np.zeros(n + 1, np.int64)
        key = order.astype(float)
        before = [np.concatenate(([0], np.cumsum(mine))) for mine in (is_ball, is_bat)]
        for x, y in held:
            pending[x] += 1
            pending[min(y, n)] -= 1
            key[x] = y - 0.5  # just before y (y past the plan's end: never taken in it)
            s = 0 if is_ball[x] else 1  # (its stream's samples before it: before[s][x])
            arrays.breaks[s][arrays.pre[s] + int(before[s][x])] = True
        done -= np.cumsum(pending[:n])
        order = np.argsort(key, kind='stable')[:int(done[-1])]
    counts = [arrays.pre[s] + np.concatenate(([0], np.cumsum(mine[order] if held else mine)))
              for s, mine in ((0, is_ball), (1, is_bat))]
    # (nothing held: each sample one step, ``done`` every step from the first)
    plan.counts = (counts[0][done], counts[1][done]) if held else (counts[0][1:], counts[1][1:])
    ahead = samples_ahead(config.model, config.look_ahead)
    watermark = np.minimum(arrays.times[0][counts[0] - 1 - ahead],
                           arrays.times[1][counts[1] - 1 - ahead])
    # np.union1d of two sorted arrays: merged (a stable sort of two runs), then deduplicated
    union = np.sort(np.concatenate(arrays.times), kind='stable')
    union = union[np.concatenate(([True], union[1:] != union[:-1]))]
    plan.union = union = np.concatenate(([cursor], union[union > cursor]))
    visited = np.maximum(search_right(union, watermark), 1)
    plan.visited = visited[done] if held else visited[1:]
    return done, counts, visited


def _trim_starts(config: DetectorConfig, plan: Plan, arrays: Arrays, done: np.ndarray,
                 counts: List[np.ndarray], visited: np.ndarray) -> np.ndarray:
    """
    Set the plan's trims (as the per-sample path makes them after each step of ``_walk``).

    :returns: which samples must stop: a stream that may be silent trims on its own.
    """
    history = 1.5 * max(config.velocity_window, config.prediction_window)
    cursors = plan.union[visited[1:] - 1]
    plan.starts, plan.step_starts = [], [None, None]
    silent = np.zeros(len(visited), bool)
    for s in (0, 1):
        cuts = np.minimum(search_right(arrays.times[s], cursors - history) - TRIM_KEEP,
                          counts[s][1:] - TRIM_LEAVES)
        starts, lengths = _trims(counts[s][1:], cuts)
        plan.step_starts[s] = np.concatenate(([0], starts))
        plan.starts.append(items(plan.step_starts[s][done]))
        silent[1:] |= lengths > SILENT_KEEP
    # a sample stops where a step it makes (its own, or a held sample's it takes) is silent
    made = np.cumsum(silent)
    return made[done] > made[np.concatenate(([0], done[:-1]))]


def _trims(counts: np.ndarray, cuts: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return a stream's first kept sample after each sample's trim, and its length before it.

    ``Stream.trim`` after each sample: a stream of ``TRIM_FROM`` samples or more drops those
    before its cut (the kernel's ``trims``, one pass).

    :param counts: the stream's samples after each sample; ``cuts``: where its trim would cut.
    """
    after, lengths = np.empty(len(counts), np.int64), np.empty(len(counts), np.int64)
    _kernel.trims(np.ascontiguousarray(counts, dtype=np.int64),
                  np.ascontiguousarray(cuts, dtype=np.int64), TRIM_FROM, after, lengths)
    return after, lengths
