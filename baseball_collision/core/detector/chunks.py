"""
A chunk of samples at once: the common case (far from any contact) with numpy.

``Detector.add_chunk`` takes the samples a bag (or a subscription) delivered, in arrival
order, and has them planned (``plans.plan_chunk``: which samples are stops, where the walk
goes after each). A run of samples between stops is fast-forwarded (:func:`fast_forward`):
appended to the streams, the cursor moved, the intervals counted and the episodes told
"far", the streams trimmed exactly as the per-sample path trims them; the duplicates among
them (a message sent twice) counted as dropped, as ``add`` drops them. Every stop goes through
the per-sample path (``Detector.add``), so each rule keeps its one implementation; when it
did not end as the plan assumed (dropped, held, reset, trimmed otherwise) the rest of the
chunk is planned again (:func:`feed_chunk`, the detector's ``add_chunk``). A plan taken whole
doubles the next one's length (``PLAN_MAX`` up to ``PLAN_LONGEST``), and only the samples a
fast-forward keeps after its trim become the streams' Python lists.

With prediction on, a fast-forward moves the predictor's ``last_ns``; a stop for the
predictor alone (a due frame whose forecasts may meet, by the plan's, or that may clear a
prediction) is taken by the run before it, then ``Predictor.predict`` (its walk is the
plan's, far).

Identical output to feeding the samples one at a time is the contract
(test/core/detector/test_chunks.py).
"""

from bisect import bisect_left
from collections import Counter
import math
import time
from typing import Any, List, Optional, Sequence, Tuple, TYPE_CHECKING

import numpy as np

from .episodes import EpisodeTracker
from .events import DetectorStats, DropReason, Event, Role
from .intake import Offer
from .noise import NoiseEstimate
from .plans import BALL, BAT_POSE, Plan, plan_chunk, plannable, ROLE_CODES, usable
from .scheduler import Scheduler
from .streams import Stream
from ..motion import BatSample
from ..toi import _kernel
from ...errors import CoreError

if TYPE_CHECKING:  # (the detector imports this module)
    from .detector import Detector

__all__ = ['CHUNK_MIN', 'fast_forward', 'feed_chunk', 'PLAN_LONGEST', 'PLAN_MAX', 'ROLE_CODES']

PLAN_MAX = 512
"""Samples planned at once after a plan was overturned: a plan the per-sample path overturns
(a drop) is made again for the rest, so a bound keeps that cost flat."""

PLAN_WORTH = 64
"""A plan that took fewer samples than this (overturned, or ended by a sample it could not
take) cost more than taking them through ``add`` (its fixed numpy calls, about a
millisecond, against about 15 us a sample): after such a plan the next
``Detector._unplanned_after`` samples go through ``add``, and that doubles up to
``PLAN_MAX`` while plans keep ending so early, back to ``UNPLANNED_AFTER_EARLY`` once a plan
goes further. Such plans come in runs: at each pitch's start the plans' checks turn away a
few samples in a row (steps the intake may hold: 134 of 295 plans on the worst-case bench
bag took one sample). (A stream sent twice by a relay, every other sample a duplicate, ended
a plan at each: 118 s for 300k messages, 7 s with this rule; the plans now drop duplicates
themselves, ``plans.Plan.duplicates``.) Either path gives the same events (the contract)."""

UNPLANNED_AFTER_EARLY = 16
"""Samples taken through ``add`` after the first short plan in a row (``PLAN_WORTH``)."""

PLAN_LONGEST = 8192
"""Samples planned at once at most: each plan taken whole doubles the next one's length from
``PLAN_MAX`` up to this (far from contacts a plan is rarely overturned, and its fixed cost of
numpy calls is shared by more samples); the length carries over to the next chunk
(``Detector._plan_length``), and goes back to ``PLAN_MAX`` when a plan is overturned."""


def fast_forward(plan: Plan, pos: int, end: int, ball: Stream, bat: Stream,
                 scheduler: Scheduler, episodes: EpisodeTracker, stats: DetectorStats,
                 events: List[Event], walk: bool = True,
                 noise: Optional[Tuple[NoiseEstimate, NoiseEstimate]] = None,
                 stop: bool = False, drops: Optional[Counter] = None) -> int:
    """
    Take samples pos..end-1 of a plan (none a stop) as the per-sample path would.

    Its duplicates (``Plan.duplicates``) are dropped as ``duplicate_stamp``: counted as
    received and dropped (in ``drops`` too, when given), the drop reason of the last sample
    when it is one.

    :param walk: False: only append them (a near stop's sample, whose walk the caller makes
        with the scheduler: the intervals, then the trim, then the prediction).
    :param stop: also append sample ``end`` after the run's walk and trim (a near stop that
        passes every check, whose own walk the caller makes): one
        append, one trim and one bulk estimate instead of two of each, the same state.
    :param noise: under ``tracker_noise`` auto, the ball's and the bat's estimators: each
        takes the run's samples as ``Detector.add`` updates them after each sample (at once,
        ``NoiseEstimate.take_points``' ``take_run`` of each of its ``medians``, a bat pose's
        positions; a run of one sample appended,
        ``NoiseEstimate.update`` itself, after the append) and sets the stream's ``noise``;
        those after the cursor (the run's, when it walks) but each stream's first
        ``scheduler.ahead`` there one by one, each estimate kept as ``Detector.add`` keeps it
        (``noise.ESTIMATES``): the sweeps of the intervals after the cursor read them.
    :returns: the newest stamp taken (ns).
    """
    if walk:
        before = plan.visited[pos - 1] if pos else 1
        after = plan.visited[end - 1]
        cursor = plan.union[after - 1]
    else:
        cursor = scheduler.cursor if scheduler.cursor is not None else -math.inf
    # each stream in turn (the kernel's): its run's samples appended but those the trim after
    # the run drops at once (never made), the estimate taken of those up to the cursor (one
    # sample appended: after the append, as ``Detector.add`` does, ``update``; else every
    # sample of the run before it, each median's ``take_run``: the same numbers), then the
    # trim, then those after the cursor one by one (``update_at``), each estimate kept
    newest, ball_taken, bat_taken = _kernel.fast_forward_streams(
        plan, pos, end, ball, bat, walk, stop, noise, BatSample, cursor, scheduler.ahead)
    ball_repeated, bat_repeated = plan.duplicates_in(pos, end)
    ball_taken += ball_repeated
    bat_taken += bat_repeated
    if ball_taken:
        stats.received[Role.BALL] += ball_taken
    if bat_taken:
        stats.received[Role.BAT_POSE] += bat_taken
    if ball_repeated or bat_repeated:
        stats.dropped[DropReason.DUPLICATE_STAMP] += ball_repeated + bat_repeated
        if drops is not None:
            for role, repeated in ((Role.BALL, ball_repeated), (Role.BAT_POSE, bat_repeated)):
                if repeated:
                    drops[role, DropReason.DUPLICATE_STAMP] += repeated
    if walk:
        scheduler.cursor = cursor
        if after > before:
            stats.intervals += after - before
            episodes.far(events, plan.union[after - 2])
    stats.calls += end - pos + stop
    stats.last_drop_reason = DropReason.DUPLICATE_STAMP if (
        (ball_repeated or bat_repeated) and not stop and plan.is_duplicate(end - 1)) else None
    if stats.late_drops:
        stats.late_drops = []
    if stats.newest_stamp_ns is None or newest > stats.newest_stamp_ns:
        stats.newest_stamp_ns = newest
    return newest


CHUNK_MIN = 16
"""Chunks (or what is left of one) shorter than this go sample by sample: numpy's set-up
costs more than it saves."""


def feed_chunk(detector: 'Detector', roles: Sequence[int], stamps_ns: Sequence[int],
               values: Any, frame_ids: Sequence[str],
               drops: Optional[Counter]) -> List[Event]:
    """
    ``Detector.add_chunk``: plan runs of samples, fast-forward them, the rest through ``add``.

    The detector's own chunk path: it reads the detector's current parts (streams, scheduler,
    intake, clock), which a reset mid-chunk replaces. Arguments and errors as ``add_chunk``.
    """
    given_roles, given_stamps = np.asarray(roles), np.asarray(stamps_ns)
    if given_roles.ndim != 1 or given_stamps.ndim != 1:
        raise CoreError('a chunk takes one role code and one stamp per sample (1-d arrays), got '
                        f'arrays of shape {given_roles.shape} and {given_stamps.shape}')
    if given_roles.dtype.kind not in 'iu' or given_stamps.dtype.kind not in 'iu':
        raise CoreError('a chunk takes integer role codes (Detector.ROLES: 0 ball, 1 bat_pose, '
                        '2 knob, 3 tip) and integer stamps in ns, got arrays of '
                        f'{given_roles.dtype} and {given_stamps.dtype}')
    if len(given_roles) and (given_roles.min() < 0 or given_roles.max() >= len(detector.ROLES)):
        raise CoreError(f'role codes must be 0-{len(detector.ROLES) - 1}')
    if frame_ids is None or isinstance(frame_ids, str) or not hasattr(frame_ids, '__len__'):
        raise CoreError('frame_ids: one frame_id per sample (a sequence of str), not '
                        f'{frame_ids!r}')
    if given_stamps.dtype == np.uint64 and len(given_stamps) and \
            given_stamps.max() > np.iinfo(np.int64).max:
        raise CoreError('stamps beyond int64 nanoseconds (after the year 2262)')
    roles = given_roles.astype(np.int8, copy=False)
    stamps = given_stamps.astype(np.int64, copy=False)
    try:
        values = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as error:
        raise CoreError(f'a chunk takes (n, 7) numbers as values: {error}') from error
    n = len(stamps)
    if len(roles) != n or len(frame_ids) != n or values.shape != (n, 7):
        raise CoreError(f'a chunk of {n} stamps needs as many roles, frames and rows of 7 '
                        f'values, got {len(roles)}, {len(frame_ids)}, {values.shape}')
    chunk = (roles, stamps, values, frame_ids)
    events: List[Event] = []
    # samples whose own stamp or values drop them change nothing but the counters: through
    # ``add`` first, the last sample last, and the rest planned without them (each ended a
    # plan: 1 % of a bat's frames lost as NaN made a session 8.6 times slower). Not where
    # nothing is planned (knob and tip points, whose lost frame ``add`` notes against its
    # stream: ``Pairing.missed``): there every sample goes through ``add`` in turn
    last = None
    if not plannable(detector.config):
        _planned(detector, chunk, n, events, drops)
        return events
    dropped = _dropped_alone(roles, stamps, values)
    if dropped.any():
        for k in np.flatnonzero(dropped).tolist():
            if k == n - 1:
                last = chunk
            else:
                _one(detector, chunk, k, events, drops)
        kept = np.flatnonzero(~dropped)
        roles, stamps, values = roles[kept], stamps[kept], values[kept]
        frame_ids = [frame_ids[k] for k in kept.tolist()]
        chunk, n = (roles, stamps, values, frame_ids), len(kept)
    _planned(detector, chunk, n, events, drops)
    if last is not None:
        _one(detector, last, len(last[1]) - 1, events, drops)
    return events


def _dropped_alone(roles: np.ndarray, stamps: np.ndarray, values: np.ndarray) -> np.ndarray:
    """
    Return which samples ``add`` drops for their own stamp or values, whatever came before.

    A stamp not after 0 (``bad_stamp``), or a value that is not finite in the sample's
    columns (three, seven for a bat pose): ``add`` drops it before the intake (as
    ``bad_stamp``, ``unexpected_input`` or ``non_finite``), so the detector's state is what it
    was but for its counters (with a bat pose: a knob or tip point lost changes the pairing,
    and is never planned).
    """
    finite = np.isfinite(values[:, :3]).all(axis=1)
    finite &= (roles != BAT_POSE) | np.isfinite(values[:, 3:]).all(axis=1)
    return (stamps <= 0) | ~finite


def _planned(detector: 'Detector', chunk: Tuple[Any, ...], n: int, events: List[Event],
             drops: Optional[Counter]) -> None:
    """Take a chunk's n samples in plans and through ``add`` (``feed_chunk``)."""
    roles, stamps, values, frame_ids = chunk
    i, length, unplanned = 0, detector._plan_length, 0
    while i < n:
        if n - i < CHUNK_MIN or not plannable(detector.config):
            for k in range(i, n):
                _one(detector, chunk, k, events, drops)
            break
        if unplanned:  # (after a short plan: ``PLAN_WORTH``)
            _one(detector, chunk, i, events, drops)
            i += 1
            unplanned -= 1
            continue
        intake = detector._intake
        waiting = intake.held or intake.jumps.candidates or intake.pending or \
            detector._sweep.aside  # (a ball sample set aside: ``Sweep.set_aside``)
        if not usable(detector.config, detector._clock.origin, detector._ball, detector._bat,
                      detector._scheduler.cursor, bool(waiting)):
            # (a held sample is settled by the next one or two: plan again as soon as it is)
            _one(detector, chunk, i, events, drops)
            i += 1
            continue
        if intake.votes.frame is None and _blank_unnoted(
                detector, roles, frame_ids, i, min(i + length, n)):
            # (a stream's first empty frame before a frame is agreed: the intake notes it)
            _one(detector, chunk, i, events, drops)
            i += 1
            continue
        first = roles[i]
        stream = detector._ball if first == BALL else detector._bat if first == BAT_POSE else None
        if stream is not None and (not stream.stamps or stamps[i] <= stream.stamps[-1]):
            # not after its stream's newest, or its first: the per-sample path says why (a
            # plan would end before it, or start with a duplicate: ``plan_order.ordered``)
            _one(detector, chunk, i, events, drops)
            i += 1
            continue
        j = i + length
        plan = plan_chunk(detector.config, detector._offsets, detector._clock.origin,
                          intake.votes.frame, detector._ball, detector._bat,
                          detector._scheduler.cursor, roles[i:j], stamps[i:j], values[i:j],
                          frame_ids[i:j], detector._predictor
                          if detector.config.prediction_horizon > 0.0 else None,
                          detector._noise, intake.newest)
        if plan.n == 0:  # its first sample fails a check: the per-sample path says why
            _one(detector, chunk, i, events, drops)
            i += 1
            continue
        taken = _follow(detector, plan, chunk, i, events, drops)
        i += taken
        if taken < plan.n:  # overturned
            length = PLAN_MAX
        elif taken == length:
            length = min(2 * length, PLAN_LONGEST)
        detector._plan_length = length  # (kept for the next chunk: a bag comes in many)
        if taken >= PLAN_WORTH or i >= n:
            detector._unplanned_after = UNPLANNED_AFTER_EARLY
        else:  # a short plan, overturned or cut short by a sample it could not take
            unplanned = max(unplanned, detector._unplanned_after)
            detector._unplanned_after = min(2 * detector._unplanned_after, PLAN_MAX)


def _follow(detector: 'Detector', plan: Plan, chunk: Tuple[Any, ...], i: int,
            events: List[Event], drops: Optional[Counter]) -> int:
    """
    Take a plan of the chunk's samples from i: runs fast-forwarded, each stop as ``add`` would.

    :returns: the samples taken: all the plan's, or up to the first stop that did not end as
        planned (dropped, held, reset, trimmed otherwise, its walk stopped before an interval
        that waits for samples, a prediction made or cleared, the predictor's last frame
        another: the rest is planned again).
    """
    stats = detector.stats
    predictor, last_due = detector._predictor, plan.last_due
    pos, resets = 0, stats.resets
    # (a plan made with no bat frame suspect stops at a due frame only where it may forecast)
    unsuspected = predictor is None or predictor.suspect is None
    while True:
        end = plan.next_stop(pos)
        # a stop for the predictor alone is taken with the run, then predicts
        forecast = end < plan.n and plan.forecasts is not None and plan.forecasts[end]
        stop = end + 1 if forecast else end
        # a near stop that passes every check is appended with the run before it
        joined = stop > pos and end < plan.n and not forecast and plan.checked[end]
        if stop > pos:
            start = time.perf_counter()
            _fast_forward(detector, plan, pos, stop, events, walk=True, stop=joined,
                          drops=drops)
            if last_due is not None:
                predictor.last_ns = last_due[end]  # (a stop's frame predicts from there)
            if forecast:
                predictor.predict(detector._scheduler.cursor, detector._episodes.armed, events)
            _time(stats, start, stop - pos)
            if forecast and stats.late_drops:  # a bat glitch the prediction judged
                for late in stats.late_drops if drops is not None else ():
                    drops[late.role, late.reason] += 1
                return _overturned(detector, plan, chunk, i, stop, resets)
        if end >= plan.n:
            return plan.n
        pos = end + 1
        if not forecast:
            if plan.checked[end]:
                # it passes every check: append it as planned, walk as add would
                start = time.perf_counter()
                if not joined:
                    _fast_forward(detector, plan, end, end + 1, events, walk=False)
                detector._advance(events)
                if drops is not None:  # a ball glitch its sweep judged (``Sweep._glitch``)
                    for late in stats.late_drops:
                        drops[late.role, late.reason] += 1
                _time(stats, start, 1)
            else:
                _one(detector, chunk, i + end, events, drops)
            if stats.resets != resets or stats.last_drop_reason is not None or \
                    stats.late_drops or not plan.held(
                        end, detector._ball, detector._bat, detector._scheduler.cursor):
                return _overturned(detector, plan, chunk, i, pos, resets)
        if last_due is not None and (predictor.last_ns != last_due[pos] or (
                predictor.predicting and not _clears(plan, end)) or (
                unsuspected and predictor.suspect is not None)):
            # (a bat frame the predictor now suspects: every due frame stops while one is,
            # ``plan_prediction.prediction_stops``)
            return _overturned(detector, plan, chunk, i, pos, resets)


def _overturned(detector: 'Detector', plan: Plan, chunk: Tuple[Any, ...], i: int, pos: int,
                resets: int) -> int:
    """
    Return pos: the plan's samples taken before an overturn; leave its held samples waiting.

    A held sample before pos whose taker is not (``Plan.holds``) waits in the intake, as the
    per-sample path left it (its values checked as ``add`` checks them, counted as received),
    unless the detector was reset since the plan began (which forgot it).
    """
    if detector.stats.resets == resets:
        _, stamps, _, frame_ids = chunk
        for x, y in plan.holds:
            if x < pos <= y:
                role, row = _row(detector, chunk, i + x)
                check = (detector._check_point if role is Role.BALL  # (pose input: planned)
                         else detector._check_pose_values)
                frame = frame_ids[i + x]
                detector._intake.held[role] = Offer(role, int(stamps[i + x]), check(role, row),
                                                    frame if frame is not None else '')
                detector.stats.received[role] += 1
    return pos


def _clears(plan: Plan, j: int) -> bool:
    """Return whether the plan's next due frame after sample j is a stop (or there is none)."""
    k = bisect_left(plan.due, j + 1)
    return k == len(plan.due) or plan.stops_at(plan.due[k])


def _fast_forward(detector: 'Detector', plan: Plan, first: int, end: int,
                  events: List[Event], walk: bool, stop: bool = False,
                  drops: Optional[Counter] = None) -> None:
    """Take plan samples [first, end) (and ``stop``: end) as planned; note the newest."""
    newest = fast_forward(plan, first, end, detector._ball, detector._bat,
                          detector._scheduler, detector._episodes, detector.stats, events,
                          walk=walk, noise=detector._noise, stop=stop, drops=drops)
    intake = detector._intake
    if intake.newest is None or newest > intake.newest:
        intake.newest = newest


def _one(detector: 'Detector', chunk: Tuple[Any, ...], k: int, events: List[Event],
         drops: Optional[Counter]) -> None:
    """Add sample k of a chunk through ``Detector.add``; count its drops."""
    role, row = _row(detector, chunk, k)
    _, stamps, _, frame_ids = chunk
    events.extend(detector.add(role, int(stamps[k]), row, frame_ids[k]))
    if drops is not None:
        stats = detector.stats
        if stats.last_drop_reason is not None:
            drops[role, stats.last_drop_reason] += 1
        for late in stats.late_drops:
            drops[late.role, late.reason] += 1


def _blank_unnoted(detector: 'Detector', roles: np.ndarray, frame_ids: Sequence[str], i: int,
                   j: int) -> bool:
    """
    Return whether samples [i, j) hold an empty frame of a role the frame vote has not noted.

    Before a frame is agreed, ``Intake.offer`` notes each role that sends an empty frame
    (``FrameVote.blank``: it then holds no adoption up); a plan would take such a sample
    without the note, so the first of each role goes through ``add``.
    """
    votes = detector._intake.votes
    if len(votes.blank) >= len(votes.roles):
        return False
    names = detector.ROLES
    return any(not frame_ids[k] and names[roles[k]] not in votes.blank for k in range(i, j))


def _row(detector: 'Detector', chunk: Tuple[Any, ...], k: int) -> Tuple[Role, List[float]]:
    """Return sample k of a chunk as ``add`` takes it: its role and its values (3 or 7)."""
    roles, _, values, _ = chunk
    role = detector.ROLES[roles[k]]
    return role, values[k, :7 if role == Role.BAT_POSE else 3].tolist()


def _time(stats: DetectorStats, start: float, samples: int) -> None:
    """Count the wall time since ``start`` (s) spent on ``samples`` fast-forwarded."""
    elapsed = time.perf_counter() - start
    stats.last_processing_s = elapsed / samples
    stats.total_processing_s += elapsed
    if stats.last_processing_s > stats.max_processing_s:
        stats.max_processing_s = stats.last_processing_s
