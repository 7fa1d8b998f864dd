"""
The sample buffer of one body: times, stamps, values and segment breaks, newest last.

A stream keeps only what the detector still needs: ``trim`` forgets samples that are both
older than the fits' history and more than a few samples behind the cursor. Samples form
segments: a new segment starts after a long gap or a jump the speed check accepted (the body
really moved); nothing is interpolated across a segment break or a gap longer than ``max_gap``.
"""

from bisect import bisect_right
from typing import Any, Collection, Dict, List, Optional, Tuple

from ..motion import BatSample
from ..toi import _kernel

Turn = Tuple[float, float, float, float]
"""Cumulative (swing x, y, z, roll) turn of a bat sample since its segment's first (rad)."""

MAX_HISTORY = 64
"""Samples at most in a velocity fit's history."""

SILENT_AFTER = 1.0
"""A stream whose newest sample is this far (s) behind the other's (and ``SILENT_KEEP``
samples of the other) is silent: the other keeps only its own history."""

SILENT_KEEP = 2048
"""Samples a stream keeps after a silent one's newest before it trims to its own history: a
stream that only lags (a live subscription behind the other under load, a replay at a high
rate) catches up within them, so nothing it will still pair with is dropped; the memory stays
bounded (about 0.4 MB) when the other is dead."""

TRIM_LEAVES = 8
"""Samples a trim leaves at least: with the next sample, the nine of a bat pose's noise window
(``noise.POSE_SPAN``), however short the fits' history is, so that the node (one sample at a
time, trimmed between them) and ``analyze``'s fast-forwards (trimmed after a run) estimate
the same. With the fits' usual history a trim leaves many more (it binds only where the
history holds fewer than three samples)."""

_ZERO_TURN = (0.0, 0.0, 0.0, 0.0)


class Stream:
    """
    Accepted samples of one body: times (s, detector clock), stamps (ns), values, breaks.

    :ivar name: ``'ball'``, ``'bat'``, ``'knob'`` or ``'tip'`` (a ``StreamGap``'s stream).
    :ivar values: points (tuples, m) or ``BatSample``.
    :ivar breaks: True where a sample does not continue the previous one.
    :ivar turns: bat only: cumulative turns (``Turn``), filled in on demand by ``turn``.
    :ivar speed_drops: samples dropped in a row by the speed check.
    :ivar path_key, path: the motion path last built on this stream, by its end stamps.
    :ivar reported_gap: the stamp of the last gap reported (reported once).
    :ivar aligned: per-sample values the detector's parts compute once and keep (by name, each
        a list aligned with the samples from the first, possibly shorter); trimmed with them.
        Valid because a sample never changes once appended (a copy with other values is a new
        ``Stream``, which starts with none).
    """

    __slots__ = ('name', 'times', 'stamps', 'values', 'breaks', 'speed_drops', 'path_key',
                 'path', 'reported_gap', 'turns', 'aligned', 'noise')

    def __init__(self, name: str) -> None:
        self.name = name
        self.times: List[float] = []
        self.stamps: List[int] = []
        self.values: List[Any] = []
        self.breaks: List[bool] = []
        self.turns: List[Optional[Turn]] = []
        self.speed_drops = 0
        self.path_key: Optional[Tuple[int, int]] = None
        self.path: Any = None
        self.reported_gap: Optional[int] = None
        self.aligned: Dict[str, List[Any]] = {}
        self.noise = 0.0  # m, 1 sigma: the estimate under tracker_noise auto (noise.py)

    def newest(self) -> Optional[int]:
        """Return the newest stamp (ns), None when empty."""
        return self.stamps[-1] if self.stamps else None

    def append(self, t: float, stamp: int, value: Any, new_segment: bool) -> None:
        """Add a sample at time t (s), stamped (ns); ``new_segment``: it breaks from the last."""
        self.times.append(t)
        self.stamps.append(stamp)
        self.values.append(value)
        self.breaks.append(new_segment or len(self.times) == 1)
        if isinstance(value, BatSample):
            self.turns.append(_ZERO_TURN if self.breaks[-1] else None)

    def trim(self, before: float, history: float, keep: int = 4) -> None:
        """
        Forget samples more than ``history`` s and ``keep`` samples before time ``before``.

        At least the newest ``TRIM_LEAVES`` stay.
        """
        if len(self.times) < 64:
            return
        index = min(min(bisect_right(self.times, before - history),
                        bisect_right(self.times, before)) - 1 - keep,
                    len(self.times) - TRIM_LEAVES)
        if index > 0:
            for buffer in (self.times, self.stamps, self.values, self.breaks, self.turns,
                           *self.aligned.values()):
                del buffer[:index]
            self.path_key = None

    def remove(self, k: int, facts: Collection[str] = ()) -> None:
        """
        Forget sample k, as if it had never come (a glitch: ``Sweep``).

        Its neighbours join up (a segment it started starts at the next sample). Each
        ``aligned`` list named in ``facts`` (a value per sample that stays what it was: the
        noise estimate after it) loses its entry k; the others (numbers each made from a few
        samples about theirs: a ball's parabolas, the far test's steps and jumps) are cut back
        to k - 1, to be made again from the stream without it; a bat's cumulative turns after
        it are summed again (``turn``).
        """
        breaks = self.breaks
        if breaks[k] and k + 1 < len(breaks):
            breaks[k + 1] = True
        for buffer in (self.times, self.stamps, self.values, breaks):
            del buffer[k]
        turns = self.turns
        if turns:  # (a bat's cumulative turns after it were summed through it)
            del turns[k]
            turns[k:] = [_ZERO_TURN if broken else None for broken in breaks[k:]]
        for name, kept in self.aligned.items():
            if name in facts:
                del kept[k:k + 1]
            else:
                del kept[max(k - 1, 0):]
        self.path_key = None

    def insert(self, t: float, stamp: int, value: Any, max_gap: float,
               facts: Collection[str] = ()) -> int:
        """
        Put a point sample at time t (s), stamped (ns), back among the samples; return its index.

        A sample set aside that is judged again once the sample it was judged against was
        forgotten (``Sweep``): it starts a segment after a gap longer than ``max_gap`` (s) or
        at the stream's start, else continues the sample before it, and the sample after it
        continues it unless a gap parts them. Each ``aligned`` list named in ``facts`` takes
        the entry of the sample before it (the estimate as it stood); the others are cut back
        to the sample before it, as ``remove`` cuts them.
        """
        times, breaks = self.times, self.breaks
        k = bisect_right(times, t)
        times.insert(k, t)
        self.stamps.insert(k, stamp)
        self.values.insert(k, value)
        breaks.insert(k, k == 0 or t - times[k - 1] > max_gap)
        if k + 1 < len(times):
            breaks[k + 1] = times[k + 1] - t > max_gap
        for name, kept in self.aligned.items():
            if name not in facts:
                del kept[max(k - 1, 0):]
            elif k <= len(kept):
                kept.insert(k, kept[k - 1] if k else kept[0])
        self.path_key = None
        return k

    def trim_beside(self, other: 'Stream', cursor: Optional[float], history: float) -> None:
        """
        Forget what no future interval needs, beside the ``other`` stream it is walked with.

        Normally what is ``history`` s and a few samples behind ``cursor`` (s); when the other
        stream is empty or silent (its newest ``SILENT_AFTER`` s and ``SILENT_KEEP`` samples
        behind this one's), what is ``history`` behind this stream's own newest, so one dead
        stream does not grow the other without bound.
        """
        times = self.times
        if len(times) < 64:
            return
        if other.times:
            last = other.times[-1]
            silent = times[-1] - last > SILENT_AFTER and \
                len(times) - bisect_right(times, last) > SILENT_KEEP
        else:
            silent = times[-1] - times[0] > SILENT_AFTER and len(times) > SILENT_KEEP
        if silent:
            self.trim(times[-1], history)
        elif cursor is not None:
            self.trim(cursor, history)

    def interval(self, t: float) -> int:
        """Return k of the sample interval [times[k], times[k+1]] holding t (-1 before)."""
        return bisect_right(self.times, t) - 1

    def continuous(self, k: int, max_gap: float) -> bool:
        """Return whether samples k and k+1 are one segment no longer than ``max_gap``."""
        return not self.breaks[k + 1] and self.times[k + 1] - self.times[k] <= max_gap

    def neighbours(self, k: int, max_gap: float) -> Tuple[Optional[int], Optional[int]]:
        """Return the samples before k and after k + 1 in the same segment (or None)."""
        before = k - 1 if k >= 1 and self.continuous(k - 1, max_gap) else None
        after = k + 2 if k + 2 < len(self.times) and self.continuous(k + 1, max_gap) else None
        return before, after

    def history(self, t: float, window: float, most: int = MAX_HISTORY) -> range:
        """
        Return indices of samples at or before t in t's segment, ``window`` s back from the last.

        At least the last two samples of the segment (when it has them), at most ``most``: a
        contiguous range (no list made).
        """
        times = self.times
        k = bisect_right(times, t) - 1
        if k < 0:
            return range(0)
        first = bisect_right(times, times[k] - window - 1e-9, max(k - most + 1, 0), k)
        if first > k - 1:
            first = k - 1 if k else 0
        breaks = self.breaks
        if True in breaks[first + 1:k + 1]:  # stay within the segment
            for i in range(k, first, -1):
                if breaks[i]:
                    first = i
                    break
        return range(first, k + 1)

    def turn(self, k: int) -> Turn:
        """
        Return the cumulative turn of bat sample k, summing the missing steps once.

        ``motion.turn_between``'s steps from the last turn known at or before k, summed in
        order in the kernel (``_kernel.fill_turns``; at an impact the steps since the last one
        known, hundreds on a session; a forecast sums its own window's instead, from the
        stream's ``step_rows``: ``prediction.bat_window_numbers``); where none is known from the
        stream's first sample on (trimmed past its segment's start), that sample becomes the new
        zero reference (only differences of turns are ever used).
        """
        turns = self.turns
        found = turns[k]
        return found if found is not None else _kernel.fill_turns(
            self.values, turns, 0, k if k >= 0 else k + len(turns))


def excerpt(stream: Stream, first: int, last: int) -> Stream:
    """
    Return a new stream of samples first..last of ``stream`` (a segment starts at first).

    A bat's cumulative turns come along where the stream has summed them from first on (one
    reference: only their differences are used), so a re-solve does not sum them again;
    otherwise the copy starts from zero at first.
    """
    copy = Stream(stream.name)
    copy.times = stream.times[first:last + 1]
    copy.stamps = stream.stamps[first:last + 1]
    copy.values = stream.values[first:last + 1]
    copy.breaks = [True] + stream.breaks[first + 1:last + 1]
    copy.noise = stream.noise
    if copy.values and isinstance(copy.values[0], BatSample):
        if stream.turns[first] is not None:
            copy.turns = stream.turns[first:last + 1]
        else:
            copy.turns = [_ZERO_TURN if broken else None for broken in copy.breaks]
    return copy


def reversed_excerpt(stream: Stream, first: int, last: int) -> Stream:
    """
    Return a new stream of samples last..first of ``stream``, the latest first (one segment).

    Times and stamps negated: the samples with time run backwards, whose departures and
    splines are those of the motion run backwards (a segment judged from its end). Its noise is
    left unset (the caller's to say).
    """
    backwards = Stream(stream.name)
    for j in range(last, first - 1, -1):
        backwards.append(-stream.times[j], -stream.stamps[j], stream.values[j], False)
    return backwards
