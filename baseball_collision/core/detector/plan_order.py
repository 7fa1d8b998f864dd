"""
A chunk's samples in order, for its plan: the intake's and the gate's order rules on arrays.

``plans.plan_chunk`` plans a chunk's samples as the per-sample path would take them, each as
if every sample before it were accepted. The rules of their order, here: where a stream's
sample behind the one before it ends the plan, and which are stamped as the one before it
(duplicates, in no stream: ``ordered``) and whose values pass the checks
(``duplicates_pass``); which pass the intake's stamp rules and the speed bound with room to
spare, and which start a segment after a gap that the intake holds for the stream's next
sample (``order_checks``: the kernel's); and where the first that fails ends the plan, but for
those held samples, each with the sample that takes it (``held_gaps``). Stamps in ns, times
in s, points in m.
"""

from typing import List, Optional, Tuple

import numpy as np

from .broadphase.arrays import SLACK
from .config import DetectorConfig
from .gate import HOLD_FACTOR
from .streams import Stream
from ..toi import _kernel


def held_gaps(ok: np.ndarray, gap: np.ndarray, is_ball: np.ndarray, is_bat: np.ndarray,
              stamps: np.ndarray, newest: int, followed: Optional[np.ndarray] = None
              ) -> Tuple[int, List[Tuple[int, int]]]:
    """
    Return where a plan ends, and its held samples with the sample that takes each.

    A stream's first sample after a gap waits (``gate.hold_ahead``) while no sample taken is
    as new (``newest``, ns: the intake's newest before the chunk, then the samples taken); its
    stream's next sample takes it, then itself. The plan follows that (``plan_chunk``: taken
    as planned, or through the per-sample path); it ends after its first sample that fails a
    check otherwise, or whose next does, or that a duplicate follows (``followed``: the
    duplicate would take it, then be dropped).
    """
    n = len(ok)
    failing = np.flatnonzero(~ok).tolist()
    if not failing:
        return n, []
    following = np.full(n, n)
    for mine in (is_ball, is_bat):
        own = np.flatnonzero(mine)
        following[own[:-1]] = own[1:]
    held: List[Tuple[int, int]] = []
    # the newest stamp of the samples before x that do not wait, kept as x goes on: only the
    # last held sample (where the scan stopped) waits among those not yet scanned
    top, scanned = newest, 0
    for x in failing:
        y = int(following[x])
        if not gap[x] or y >= n or not ok[y] or (followed is not None and followed[x]):
            return x + 1, held
        start = scanned + 1 if held and held[-1][0] == scanned else scanned
        if start < x:
            top = max(top, int(stamps[start:x].max()))
        scanned = x
        if stamps[x] <= top:
            return x + 1, held  # (taken at once: as new as a sample taken)
        held.append((x, y))
    return n, held


def ordered(stamps: np.ndarray, mine: np.ndarray,
            stream: Stream) -> Tuple[int, np.ndarray, np.ndarray]:
    """
    Return where a stream's samples (``mine``) end a chunk's plan, its duplicates before that.

    The chunk's length up to the stream's first sample behind the one before it; a stream's
    very first sample ends it too (the per-sample path starts the stream), and a chunk without
    a sample of the stream is not limited by it. Second, the samples before that stamped as
    the one before (duplicates, sorted); third, for each, the sample it repeats: the
    stream's newest before it that is no duplicate (-1: the stream's kept newest).
    """
    own_index = np.flatnonzero(mine)
    none = own_index[:0]
    if not len(own_index):
        return len(stamps), none, none
    if not len(stream.stamps):
        return int(own_index[0]), none, none
    own = stamps[own_index]
    before = np.concatenate((stream.stamps[-1:], own[:-1]))
    behind = np.flatnonzero(own < before)
    end = int(own_index[behind[0]]) if len(behind) else len(stamps)
    same = own == before
    if not same.any():
        return end, none, none
    position = np.arange(len(own))
    repeated = np.maximum.accumulate(np.where(same, -1, position))[same]
    duplicates = own_index[same]
    kept = duplicates < end
    return (end, duplicates[kept],
            np.where(repeated >= 0, own_index[np.maximum(repeated, 0)], -1)[kept])


def duplicates_pass(values: np.ndarray, points: np.ndarray) -> np.ndarray:
    """
    Return which duplicates' values pass the per-sample path's checks, with room to spare.

    Finite (``non_finite``); a bat pose's quaternion unit within ``SLACK`` less than the
    tolerance (``bad_quaternion``), its position not the origin (``lost_body``, as
    ``plan_rows`` checks it). ``values``: their (m, 7) rows; ``points``: which are points
    (the ball's: their first three columns).
    """
    finite = np.isfinite(values[:, :3]).all(axis=1)
    with np.errstate(all='ignore'):
        magnitude = np.sqrt(np.einsum('ij,ij->i', values[:, 3:], values[:, 3:]))
        pose = np.isfinite(values[:, 3:]).all(axis=1) & (
            np.abs(magnitude - 1.0) < 1e-3 * (1.0 - SLACK)) & (values[:, :3] != 0.0).any(axis=1)
    return finite & (points | pose)


def order_checks(config: DetectorConfig, stamps: np.ndarray, times: np.ndarray,
                 points: Tuple[np.ndarray, Optional[np.ndarray]],
                 pre: int) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return which of a stream's new samples (after ``pre`` kept ones) pass with room to spare.

    The intake's stamp rules (in order, no step ``gate.hold_ahead`` would hold) and the speed
    bound (``gate.speed_check``, within ``max_gap``) against the sample before, as if every
    sample before it were accepted. Second, which start a new segment after a gap longer than
    ``max_gap`` that ``gate.hold_ahead`` holds (a step over ``HOLD_FACTOR`` times the one
    before, under ``time_jump_reset``): the next sample takes them. The kernel's
    ``order_checks``, each bound less ``SLACK`` (more where it must be exceeded).

    :param points: the stream's points (the ball's, None), or the bat's knobs and tips.
    :raises ValueError: fewer than 3 kept samples.
    """
    if pre < 3:
        raise ValueError(f'order checks need 3 kept samples before the new, got {pre}')
    ok, gap = np.empty(len(stamps) - pre, bool), np.empty(len(stamps) - pre, bool)
    _kernel.order_checks(stamps, times, points[0], points[1], pre,
                         (float(round(config.time_jump_reset * 1e9)), HOLD_FACTOR,
                          config.max_gap, config.max_speed, SLACK), ok, gap)
    return ok, gap
