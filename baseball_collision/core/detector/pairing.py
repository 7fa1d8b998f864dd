"""
Knob and tip points paired into bat samples by stamp.

Trackers that report the bat as two points may stamp them differently. Every stamp of either
stream that both streams now cover becomes one bat sample: the point stamped there as is, the
other interpolated linearly between its samples around it (not across a gap longer than
``max_gap``, not before its first sample, and not across a frame of that stream that came
without a usable point).

A point that was not finite (an occluded marker) is dropped for it (``non_finite``), but its
frame still happened: its stream's interval around that stamp is one frame wider than the
tracker's spacing, and a point interpolated on the chord across it lies inside the real arc
(at 90 Hz mid-swing a tip 11 cm short of the bat's length, which the length check would then
drop as a second, wrong reason). So a stream's next sample after such a frame starts a new
segment of that stream (``Pairing.missed``, ``Pairing.append``), and the other point's
samples in the interval across it are not paired: the bat has no sample there, as with a
pose that was not finite, and the frame is one drop, for its own reason.
"""

from bisect import bisect_right
from typing import Dict, List, Optional, Tuple

from .streams import Stream
from ..geometry import Vector

Pair = Tuple[float, Vector, Vector]
"""(time in seconds, knob, tip) in metres."""


class Pairing:
    """
    The knob and tip streams, and the newest time (s) paired so far (``cursor``).

    :ivar missing: per stream name, the stamp (ns) of the earliest frame after the stream's
        newest sample that came without a usable point; its next sample after that stamp
        breaks from the one before.
    """

    __slots__ = ('knob', 'tip', 'cursor', 'missing')

    def __init__(self) -> None:
        self.knob = Stream('knob')
        self.tip = Stream('tip')
        self.cursor: Optional[float] = None
        self.missing: Dict[str, int] = {}

    def missed(self, stream: Stream, stamp: int) -> None:
        """
        Note a frame of ``stream`` (knob or tip) stamped ``stamp`` (ns) without a usable point.

        Only a frame after the stream's newest sample matters (one before it was already
        paired across, or is another clock's); the earliest such frame is kept.
        """
        newest = stream.newest()
        if newest is not None and stamp > newest:
            noted = self.missing.get(stream.name)
            if noted is None or stamp < noted:
                self.missing[stream.name] = stamp

    def append(self, stream: Stream, t: float, stamp: int, point: Vector) -> None:
        """
        Add a point to ``stream`` at t (s), stamped (ns), taken by the intake.

        It breaks from the stream's previous sample when a frame between them came without a
        usable point (``missed``): nothing is interpolated across that frame.
        """
        noted = self.missing.get(stream.name)
        if noted is not None and noted <= stamp:
            del self.missing[stream.name]
        stream.append(t, stamp, point, noted is not None and noted < stamp)

    def pairs(self, max_gap: float) -> List[Pair]:
        """Return (t, knob, tip) at every new time both streams cover, oldest first."""
        knob, tip = self.knob, self.tip
        if not knob.times or not tip.times:
            return []
        ready = min(knob.times[-1], tip.times[-1])
        pairs = []
        for t in _merged(_between(knob.times, self.cursor, ready),
                         _between(tip.times, self.cursor, ready)):
            self.cursor = t
            knob_point = _point_at(knob, t, max_gap)
            tip_point = _point_at(tip, t, max_gap) if knob_point is not None else None
            if tip_point is not None:
                pairs.append((t, knob_point, tip_point))
        return pairs

    def trim(self) -> None:
        """
        Forget what no future pair needs: all but a few samples before the cursor.

        When one end is silent (or never came) the other keeps only its last samples
        (``Stream.trim_beside``): its memory and the cost per sample stay flat.
        """
        self.knob.trim_beside(self.tip, self.cursor, 0.0)
        self.tip.trim_beside(self.knob, self.cursor, 0.0)


def _merged(a: List[float], b: List[float]) -> List[float]:
    """Return the sorted union of two sorted lists of times, without repeats (a merge walk)."""
    if not b:
        return a
    if not a:
        return b
    merged: List[float] = []
    i = j = 0
    while i < len(a) and j < len(b):
        x, y = a[i], b[j]
        if x <= y:
            merged.append(x)
            i += 1
            j += x == y
        else:
            merged.append(y)
            j += 1
    merged.extend(a[i:])
    merged.extend(b[j:])
    return merged


def _between(times: List[float], start: Optional[float], end: float) -> List[float]:
    """Return the sorted ``times`` in (start, end] (from the first when ``start`` is None)."""
    first = 0 if start is None else bisect_right(times, start)
    return times[first:bisect_right(times, end, first)]


def _point_at(stream: Stream, t: float, max_gap: float) -> Optional[Vector]:
    """
    Return the stream's point at time t (s): its sample, or interpolated; None if neither.

    Interpolated only within one segment of the stream no longer than ``max_gap``
    (``Stream.continuous``: not across a frame that came without a usable point).
    """
    k = stream.interval(t)
    if k < 0:
        return None
    times = stream.times
    if times[k] == t:
        return stream.values[k]
    if k + 1 < len(times) and stream.continuous(k, max_gap):
        s = (t - times[k]) / (times[k + 1] - times[k])
        a, b = stream.values[k], stream.values[k + 1]
        return tuple(p + (q - p) * s for p, q in zip(a, b))
    return None
