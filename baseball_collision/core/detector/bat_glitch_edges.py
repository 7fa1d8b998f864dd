"""
A bat frame at its segment's start or beside a hole: judged with the frames after it.

``bat_glitches.judged`` judges a bat frame against the frames before it: their continuation
and their scatter. A segment's first frames (the tracker re-acquired the bat) have too few
frames before them, and beside a hole over ``bat_glitches.LOST_HOLE`` (s) a swing's own frames
are off their continuation and their neighbours' spline by more than the frames before them
show. Those frames are judged reading frames after them (``late_rule`` picks the rule; the
sweep, ``Sweep._early_bat_glitch``, and the prediction, ``Predictor._late_verdict``, alike):

* a segment's 2nd to ``EARLY_FRAMES``-th frame (``early``): ``early_glitch``, ``judged`` with
  time run backwards on the ``EARLY_AFTER`` frames after it;
* its first (``segment_first``): ``first_frame_glitch``, by its departure (m) from the bat
  continued back from the frames after it, allowing for a bat that braked at a hit between
  them (``braked_departure``: up to ``BRAKE_LOST`` of its speed lost within a step);
* a frame beside a hole over ``LOST_HOLE`` (``beside_hole``): ``hole_glitch``, judged across
  the hole and off the bat continued back from the ``HOLE_AFTER`` frames after it.

Each reads exactly the frames it names (the same verdict however the detector is fed): None
where they have not all come (wait), False where the segment ends before them.
"""

import math
from typing import Callable, Optional, Tuple

from .bat_glitches import (
    departure, glitch_floor, isolated_without, ISOLATION_RATIO, judged, next_the_glitch,
    over_hole, REGULAR_STEP, SCATTER_FRAMES)
from .fitting import c2_bat_continued
from .streams import reversed_excerpt, Stream

EARLY_SCATTER = 4
"""Frames whose isolation measures the scatter a segment's early frame (``early``) is judged
against with time run backwards (``early_glitch``): one fewer than ``SCATTER_FRAMES``, so that
a hit near the bat's re-acquisition waits a bat frame less for the frames after it. Mirrored,
the frame's continuation and spline read fewer frames than forward (six or seven, not eight):
with three, a still bat with noise the detector was not told of (nor had estimated) had early
frames judged (1 in 28,000 with 8 mm of noise, 10 in 10,500 with 20 mm; forward, with three,
none in 10,500); with four, none (nor with five)."""

EARLY_AFTER = EARLY_SCATTER + 3
"""Frames after a segment's early frame (``early``) its judgment with time run backwards reads
(``early_glitch``): what ``judged`` reads before a frame with ``EARLY_SCATTER``, mirrored."""

EARLY_FRAMES = SCATTER_FRAMES + 3
"""A segment's first frames that ``judged`` cannot judge (fewer frames before them than it
reads): its second to ``EARLY_FRAMES``-th are judged with time run backwards instead."""

HOLE_AFTER = 3
"""Frames after a frame beside a hole over ``LOST_HOLE`` its judgment reads (``hole_glitch``):
two for ``judged``, three for its departure from the bat continued back from them."""

BRAKE_LOST = 0.5
"""The largest fraction of its speed a bat loses at a hit within a bat step (a segment's first
frame, ``first_frame_glitch``): measured bats lose 10-35 % within 1-3 ms of a hit. The frames
after a contact, continued back, reach the frame before it where the bat that lost this much
would be up to f / (1 - f) steps (one) further on; the ``c2`` continuation of a window with
the brake in it overshoots by as much (``braked_departure`` allows either way)."""

BRAKE_POINTS = 8
"""Shifts each way along the braked reach ``braked_departure`` tries first (evenly; the nearest
is then refined between its neighbours)."""


def early(stream: Stream, j: int, max_gap: float) -> bool:
    """
    Return whether bat frame j is among its segment's 2nd to ``EARLY_FRAMES``-th frames.

    Those have too few frames before them for ``judged`` (``judgeable``) but a neighbour on
    each side: ``early_glitch`` judges them against the frames after them.
    """
    start = j
    while start > 0 and j - start < EARLY_FRAMES and stream.continuous(start - 1, max_gap):
        start -= 1
    return 1 <= j - start < EARLY_FRAMES and (start > 0 or stream.breaks[0])


def frames_after(stream: Stream, j: int, count: int, max_gap: float) -> Optional[bool]:
    """
    Return whether the ``count`` frames after bat frame j have come, in its segment.

    True: frames j + 1 to j + count are in, each within ``max_gap`` (s) of the one before;
    None: the segment runs on to the stream's newest frame before them (they may still come);
    False: the segment ends before them.
    """
    n = len(stream.times)
    end = j
    while end < j + count and end < n - 1 and stream.continuous(end, max_gap):
        end += 1
    if end == j + count:
        return True
    return None if end == n - 1 else False


def early_glitch(stream: Stream, j: int, max_gap: float, size: int,
                 noise: float) -> Optional[bool]:
    """
    Return whether bat frame j, early in its segment (``early``), is a glitch; None: wait.

    The mirror of ``first_glitch``'s rule: ``judged`` on its segment up to ``EARLY_AFTER``
    frames after it with time run backwards (its departure from the bat continued back from the
    frames after it, its isolation against the ``EARLY_SCATTER`` frames' from three after it),
    and not where its previous frame stays isolated without it (the glitch is that one). Reads
    exactly those frames (the same verdict however the detector is fed). None where they have not
    all come (the segment's newest frame is the stream's newest); False where the segment ends
    before them.

    :param noise: the bat's noise (m, 1 sigma per coordinate: told or estimated).
    """
    come, end = frames_after(stream, j, EARLY_AFTER, max_gap), j + EARLY_AFTER
    if not come:
        return come
    start = j
    while start > 0 and stream.continuous(start - 1, max_gap):
        start -= 1
    backwards = reversed_excerpt(stream, start, end)
    backwards.noise = stream.noise
    k, last = end - j, end - start
    if not judged(backwards, k, max_gap, size, noise, last, EARLY_SCATTER):
        return False
    if k + 1 == last:  # (its previous frame the segment's first: the glitch may be that one)
        return not first_frame_glitch(stream, start, max_gap, size, noise)
    return not isolated_without(backwards, k, max_gap, size, noise, last)


def beside_hole(stream: Stream, j: int) -> bool:
    """
    Return whether bat frame j is beside lost frames across a hole over ``LOST_HOLE``.

    Up to ``LOST_NEAR`` frames lost from three before it (the steps ``departed`` reads: its
    continuation crosses them) to the one after it (``lost_about``; before it only where j is
    the newest sample), a step across them longer than ``LOST_HOLE``: neither ``judged`` nor,
    where its next frame has not come (the node's look-ahead 0), ``departed`` judges it there;
    ``hole_glitch`` does, reading three frames after it (a contact hanging on it waits for
    them: ``Sweep._early_bat_glitch``). With two before it, two frames lost 3 before a glitch
    at 120 Hz (25 ms) left the interval closing on it swept through it at the node: 30 of 480
    misses had an impact invented (``bench_glitches.py --rates 120 --lost -3 --lost-frames 2``).
    """
    return over_hole(stream, j, 1 if j + 1 < len(stream.times) else 0)


def hole_glitch(stream: Stream, j: int, max_gap: float, size: int,
                noise: float) -> Optional[bool]:
    """
    Return whether bat frame j beside a hole over ``LOST_HOLE`` is a glitch; None: wait.

    ``judged`` across the hole (``lost_about`` uncapped) from the samples up to two after it
    (with one, as at the sweep's horizon, a swing's own frame there read as a glitch; against
    ``EARLY_SCATTER`` frames where its segment has too few before the hole for
    ``SCATTER_FRAMES``), not where its next frame is the glitch (``next_the_glitch`` across the
    hole: a glitch right after two frames lost at 90 Hz, whose next frame stays isolated
    without it across the hole, was deferred to that one), and more than
    ``glitch_floor`` off the bat continued back from the ``HOLE_AFTER`` (3) frames after it
    (``departure`` with time run backwards: a frame after a contact lies on the path of the
    braked frames after it; a glitch does not). Reads exactly the samples up to ``HOLE_AFTER``
    after it (the same verdict however the detector is fed). None where those have not come;
    False where the segment ends before them.

    :param noise: the bat's noise (m, 1 sigma per coordinate: told or estimated).
    """
    come, end = frames_after(stream, j, HOLE_AFTER, max_gap), j + HOLE_AFTER
    if not come:
        return come
    last = j + 2
    if not judged(stream, j, max_gap, size, noise, last, hole=math.inf, fewer=EARLY_SCATTER) \
            or next_the_glitch(stream, j, max_gap, size, noise, last, True):
        return False
    backwards = reversed_excerpt(stream, j, end)
    backwards.noise = stream.noise
    return departure(backwards, end - j, max_gap, size, noise) > glitch_floor(noise)


def segment_first(stream: Stream, j: int, max_gap: float) -> bool:
    """
    Return whether bat frame j is its segment's first (the tracker re-acquired the bat).

    After a step over ``max_gap`` s, or the stream's first after a break. It has no neighbour
    before it: neither ``judged`` nor ``early_glitch`` can judge it; ``first_frame_glitch``
    does.
    """
    return not stream.continuous(j - 1, max_gap) if j > 0 else stream.breaks[0]


def first_frame_glitch(stream: Stream, j: int, max_gap: float, size: int,
                       noise: float) -> Optional[bool]:
    """
    Return whether bat frame j, its segment's first (``segment_first``), is a glitch; None: wait.

    Its departure (m) from the bat continued back from the ``EARLY_AFTER`` frames after it
    (``reversed_excerpt``, ``fitting.c2_bat_continued``), where a bat that lost up to
    ``BRAKE_LOST`` of its speed at a hit between them would be (``braked_departure``): more
    than ``glitch_floor`` and ``ISOLATION_RATIO`` times each of the ``EARLY_SCATTER`` frames'
    after it (theirs, continued back likewise: the stream's scatter; a departure alone drops
    it, so it is held to the ratio an isolation is); not where the frame after it departed by
    more than the floor too (the glitch may be that one: ``early_glitch``), nor where the step
    to that frame is over ``REGULAR_STEP`` times the median of the steps after it (frames
    lost: continued back across them, a swing's frame is off too). Reads exactly those frames
    (the same verdict however the detector is fed). None where they have not all come (the
    segment's newest frame is the stream's newest); False where the segment ends before them.

    :param noise: the bat's noise (m, 1 sigma per coordinate: told or estimated).
    """
    come, end = frames_after(stream, j, EARLY_AFTER, max_gap), j + EARLY_AFTER
    if not come:
        return come
    times = stream.times
    steps = sorted(b - a for a, b in zip(times[j + 1:end], times[j + 2:end + 1]))
    if times[j + 1] - times[j] > REGULAR_STEP * steps[len(steps) // 2]:
        return False  # (frames lost after it: continued back across them, a swing is off too)
    backwards = reversed_excerpt(stream, j, end)
    backwards.noise = stream.noise
    k = end - j
    found, floor = braked_departure(backwards, k, max_gap, size, noise), glitch_floor(noise)
    if found <= floor or departure(backwards, k - 1, max_gap, size, noise) > floor:
        return False  # (its next frame departed too: the glitch may be that one)
    return found > ISOLATION_RATIO * max(departure(backwards, i, max_gap, size, noise)
                                         for i in range(k - EARLY_SCATTER, k))


def braked_departure(stream: Stream, j: int, max_gap: float, size: int, noise: float) -> float:
    """
    Return how far (m) bat frame j is from the bat continued from the samples before it, braked.

    ``departure``, but from the nearest (the larger of the knob's and the tip's distance) of
    the continued bat within f / (1 - f) steps (f: ``BRAKE_LOST``) either way of its stamp: a
    bat that lost speed at a hit between frame j and the samples before it (time run
    backwards: the frame before a contact) lies further on, and the continuation of a window
    with the brake in it overshoots. 0 where there is no continuation.
    """
    if not (3 <= j < len(stream.times) and stream.continuous(j - 1, max_gap)):
        return 0.0
    continued = c2_bat_continued(stream, j - 1, max_gap, size, noise)
    if continued is None:
        return 0.0
    t, sample = stream.times[j], stream.values[j]
    reach = BRAKE_LOST / (1.0 - BRAKE_LOST) * (t - stream.times[j - 1])

    def off(shift: float) -> float:  # (m) the frame from the continued bat at t + shift (s)
        there = continued[1](t + shift)
        return max(math.dist(there.knob, sample.knob), math.dist(there.tip, sample.tip))

    best = min(range(-BRAKE_POINTS, BRAKE_POINTS + 1), key=lambda i: off(reach * i / BRAKE_POINTS))
    low = reach * max(best - 1, -BRAKE_POINTS) / BRAKE_POINTS
    high = reach * min(best + 1, BRAKE_POINTS) / BRAKE_POINTS
    for _ in range(24):  # (ternary search: about the nearest, the distance is unimodal)
        a, b = low + (high - low) / 3.0, high - (high - low) / 3.0
        low, high = (low, b) if off(a) <= off(b) else (a, high)
    return min(off(best * reach / BRAKE_POINTS), off(0.5 * (low + high)))


LateRule = Callable[[Stream, int, float, int, float], Optional[bool]]
"""A rule that judges a bat frame with frames after it: (stream, j, max_gap, size, noise) ->
True a glitch, False none, None the frames it reads have not all come."""


def late_rule(stream: Stream, j: int, max_gap: float) -> Optional[Tuple[LateRule, int]]:
    """
    Return the rule that judges bat frame j reading frames after it, and the last it reads.

    A segment's 2nd to 8th frame (``early``): ``early_glitch``, reading up to j + 1 (its own
    reach beyond is its own); its first (``segment_first``): ``first_frame_glitch``; a frame
    beside a hole over ``LOST_HOLE`` (``beside_hole``): ``hole_glitch``, reading up to j +
    ``HOLE_AFTER``. None: none of those (``judged`` judges it with the frames before it). The
    sweep (``Sweep._early_bat_glitch``) and the prediction (``Predictor._late_verdict``) pick
    alike.
    """
    if early(stream, j, max_gap):
        return early_glitch, j + 1
    if segment_first(stream, j, max_gap):
        return first_frame_glitch, j + 1
    if beside_hole(stream, j):
        return hole_glitch, j + HOLE_AFTER
    return None
