"""
The ``c2`` model on the streams: each interval's window of samples, and its fitted paths.

An interval [times[k], times[k + 1]] is fitted over a window of its stream's segment: up to
``look_ahead`` samples after its closing frame (fewer where the segment or the stream ends),
back to ``spline_window`` samples in all (fewer at the segment's start). Nothing crosses a
segment break or a gap longer than ``max_gap``.
"""

from typing import Sequence

from .streams import Stream
from ..motion import C2BatPath, not_a_knot_slopes, PointPath


def c2_window(stream: Stream, k: int, max_gap: float, look_ahead: int, size: int) -> range:
    """Return the indices of the samples fitted for interval k (both of its ends included)."""
    times, breaks = stream.times, stream.breaks  # continuous(i): no break at i + 1, no long gap
    last, end = k + 1, min(k + 1 + look_ahead, len(times) - 1)
    while last < end and not breaks[last + 1] and times[last + 1] - times[last] <= max_gap:
        last += 1
    first, start = k, max(last - size + 1, 0)
    while first > start and not breaks[first] and times[first] - times[first - 1] <= max_gap:
        first -= 1
    return range(first, last + 1)


def _slopes(times: Sequence[float], rows: Sequence[Sequence[float]]) -> list:
    return not_a_knot_slopes(times, rows).tolist()


def c2_point_path(stream: Stream, k: int, window: range) -> PointPath:
    """Return the ball's ``c2`` path over interval k: its window spline's piece."""
    times = [stream.times[i] for i in window]
    slopes = _slopes(times, [stream.values[i] for i in window])
    j = k - window.start
    return PointPath(times[j], times[j + 1], stream.values[k], stream.values[k + 1],
                     tuple(slopes[j]), tuple(slopes[j + 1]))


def c2_bat_path(stream: Stream, k: int, window: range) -> C2BatPath:
    """Return the bat's ``c2`` path over interval k: knob, direction and length splines."""
    return C2BatPath.fitted([stream.times[i] for i in window],
                            [stream.values[i] for i in window], k - window.start)
