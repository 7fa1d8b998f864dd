"""
A bat frame off the swing: one bad frame that would make a contact the swing does not.

A tracker sometimes reports one bat frame far from where the bat was: a marker swapped or
mislabelled, a rigid body solved onto the wrong markers, a frame stamped milliseconds off.
Near a ball passing a few centimetres from the bat, the bat's path through that frame sweeps
through the ball, and an impact is invented. Two distances judge a bat frame j, each the larger
of the knob's and the tip's (m):

* its *departure* (``departure``): from the bat continued from the samples before it (the
  ``c2`` window's spline continued one step: ``fitting.c2_bat_continued``). A swing's own frames
  land within 2 cm of it at 90 Hz (exact; 4-7 cm with 1-2 mm of noise, 18 cm at 60 Hz); a frame
  after a contact, which slows the bat within 1-3 ms, up to 47 cm.
* its *isolation* (``isolation``): from the ``c2`` spline through its neighbours without it,
  at its stamp. A swing's own frames lie within 0.1 cm of it at 90 Hz exact (1.5 cm with 2 mm
  of noise), frames beside a contact's brake within 3.3 cm (5 cm at 60 Hz); a frame turned
  10 cm at the tip, 6.7 cm or more (measured over the six swing families at 60-360 Hz,
  BENCHMARKS.md, "A bat frame off the swing").

A frame both departed and isolated by more than ``glitch_floor``, and isolated several times
as far as the frames before it (``judged``), is a glitch: neither the swing before it nor its
neighbours explain it. Among regular steps (``regular``; up to two frames lost three or more
frames before it only widen the scatter it is judged against), or beside up to two frames the
tracker lost across a hole of at most ``LOST_HOLE`` (``lost_about``: both distances are larger
there for a swing's own frames), against the frames before it with the same frames left out
(``_matched``; beside a longer hole, or up to three frames after one, with the three frames
after it: ``bat_glitch_edges.hole_glitch``); not in a segment's first frames (judged against
the frames after them: ``bat_glitch_edges``); nor where a frame just before it that could
not be judged so (``judgeable``) is the one off, which pulls this one's neighbours' spline
(``UNJUDGED_REACH``).

The sweep judges the frames an interval near the ball reads, while a contact would count
(``Sweep._bat_frames``): those up to its opening one, the oldest first (frames after a glitch
read it in their continuation and their spline), and the first glitch is dropped as
``bat_glitch`` and forgotten. A frame after the opening one (the closing one, the look-ahead's)
may not have its next frame yet (look-ahead 0): where it clearly departed (``departed``), the
interval is swept on the bat's path without it (``path_without``), and the frame is judged
once its next has come. Where both paths touch the ball (a hit: its contact comes before the
brake) it is solved on the path through the frame, unless their contacts are more than
``sweep_bat.CONTACT_APART`` apart: then the frame is judged first, the interval waiting for its
next frame where that has not come (``Sweep._closing_glitch``: one bat frame, for a glitch or
a bat that braked hard after a contact).
"""

import math
from typing import List, Optional, Tuple

from .fitting import c2_bat_ahead, c2_bat_continued, c2_bat_path, c2_window
from .streams import excerpt, Stream
from ..motion import BatPath

BAT_GLITCH_FLOOR = 0.05
"""m: a bat frame nearer than this to its continuation or to its neighbours' spline is no
glitch (a swing's frames beside a contact's brake: within 3.3 cm at 90 Hz, 5 cm at 60 Hz)."""

BAT_GLITCH_NOISE = 12.0
"""How many times the bat's noise (1 sigma per coordinate) the floor is at least: a swing's
frames lie within 7.5 sigma of their neighbours' spline with 2 mm of noise at 360 Hz."""

ISOLATION_RATIO = 4.0
"""How many times as isolated as each of the ``SCATTER_FRAMES`` frames before it a glitch is: a
swing's own noisy frames (0.5-2 mm, 90-360 Hz) are more so in 0.2 % of frames (0.4 % against
three frames), a still bat's (8 mm) in none of 4,000 (0.02 %); a frame turned 10 cm at 2 mm of
noise, 5.3 times at least."""

SCATTER_FRAMES = 5
"""Frames whose isolation measures a bat stream's scatter (``judged``): with three, a still bat
with 8 mm of noise the detector was not told of (nor had estimated yet) had a frame judged."""

NOISE_KEPT = 1.25
"""A departure kept for a noise serves up to this many times that noise (``departure``)."""

DEPARTURE_RATIO = 3.0
"""How many times as far off its continuation as each of the frames before it a departed frame
is (``departed``): a swing's own noisy frames, up to 2.4-4.8 times."""

REGULAR_STEP = 1.6
"""How many times their median the last ``STEADY_STEPS`` steps up to a judged frame's previous
one are at most (``regular``): a 360 Hz stream stamped on a 1 ms grid steps 2 and 3 ms; a lost
frame makes a step twice."""

STEADY_STEPS = 1
"""How many steps up to a judged frame's previous one, the last, are regular (``REGULAR_STEP``);
the steps before them may be lost frames' (``HOLE_STEPS`` times the median at most, not a
segment's start): a frame lost 3-7 before a glitch left it unjudged, and at 120-360 Hz the
bat's path through it made an impact on up to 12 of 36 misses passing over the bat. With none
(only the neighbours' ``PAIR_STEPS``), a glitch right after a lost frame, not judged, made the
frame after it read as one (a swing's frame dropped)."""

PAIR_STEPS = 2.5
"""How many times the median step a judged frame's neighbours are apart at most (``regular``):
two steps, jittered; a lost frame beside it makes three."""

LOST_NEAR = 2
"""Frames the tracker lost about a frame (from two before it to the one after it) that the frame
is judged beside at most (``lost_about``), against the frames before it with the same frames
left out (``_matched``)."""

HOLE_STEPS = LOST_NEAR + PAIR_STEPS - 1.0
"""How many times the median step the steps from ``SCATTER_FRAMES`` + 2 frames before a judged
frame up to the last ``STEADY_STEPS`` are at most (``regular``): up to ``LOST_NEAR`` frames
lost there, jittered (as ``PAIR_STEPS`` is two steps). Two frames lost 3-7 frames before a
glitch (at 120 Hz a 25 ms hole) left it unjudged, neither among regular steps nor beside the
hole (``lost_about`` reads the six steps before its two frames before it): 60 of 480 misses
had an impact invented at 120 Hz (``bench_glitches.py --lost -3 --lost-frames 2``)."""

LOST_HOLE = 0.02
"""s: the longest step across lost frames a frame beside them is judged at (``lost_about``): a
swing's own frames across a longer hole (one frame lost at 90 Hz, 22 ms; two at 120 Hz, 25 ms)
are off its spline by more than the frames before it, which turn slower, show across the same
hole (``_matched``), and braking frames after a contact read as glitches, judged with one
frame after them (the sweep's horizon). Beside a longer hole a frame a contact hangs on is
judged with three frames after it (``bat_glitch_edges.hole_glitch``)."""

UNJUDGED_REACH = 2
"""Frames before a judged one whose glitch, where it could not be judged itself (``judgeable``:
beside lost frames, a segment's first), pulls the judged one's neighbours' spline off
(``judged``): a glitch two frames before a genuine frame made it read as one."""

DEPARTURES = 'bat_departures'
"""The name of the bat stream's ``aligned`` list of its frames' departures (``departure``)."""

DEPARTURES_AHEAD = 'bat_departures_ahead'
"""The name of the bat stream's ``aligned`` list of departures made ahead of any judgment
(``departures_ahead``): (noise, m), each served once to ``departure`` at that very noise."""

AHEAD_FRAMES = 2
"""The newest bat frames whose departures ``departures_ahead`` makes, at most, per call."""

CLEAN = 'bat_clean'
"""The name of the bat stream's ``aligned`` list of the frames judged no glitch (``judged``)
with every sample the verdict reads (two after the frame): the noise (m) they were judged at,
else None (``Sweep._bat_frames``; a forgotten frame cuts back the verdicts that read it)."""


def glitch_floor(noise: float) -> float:
    """Return the distance (m) a glitch is off by at least, for the bat's noise (m, 1 sigma)."""
    return max(BAT_GLITCH_FLOOR, BAT_GLITCH_NOISE * noise)


def departure(stream: Stream, j: int, max_gap: float, size: int, noise: float) -> float:
    """
    Return how far (m) bat frame j is from the bat continued from the samples before it.

    The larger of the knob's and the tip's distance from ``fitting.c2_bat_continued`` (the window
    of ``size`` samples up to frame j - 1, continued; with ``noise``, m 1 sigma per coordinate,
    smoothed: a continuation through noisy samples swings by tens of sigma) at frame j's stamp; 0
    where there is no continuation (fewer than three samples before it in its segment, or a step
    over ``max_gap`` s to it). Kept per frame in ``stream.aligned`` (``DEPARTURES``: made from
    frame j and the samples before it, which a forgotten frame cuts back) with the noise it was
    made for, and made again where the noise is below that or more than ``NOISE_KEPT`` times it
    (``tracker_noise`` auto: an estimate that grows from 0 over a stream's first frames).
    """
    kept = stream.aligned.setdefault(DEPARTURES, [])
    found = kept[j] if j < len(kept) else None
    if found is not None and found[0] <= noise <= NOISE_KEPT * found[0]:
        return found[1]
    ahead = stream.aligned.get(DEPARTURES_AHEAD)
    made = ahead[j] if ahead is not None and j < len(ahead) else None
    if made is not None and made[0] == noise:  # (made ahead at this very noise: the same)
        value = made[1]
    else:
        value = _departure(stream, j, max_gap, size, noise)
    if len(kept) <= j:
        kept.extend([None] * (j + 1 - len(kept)))
    kept[j] = (noise, value)
    return value


def _departure(stream: Stream, j: int, max_gap: float, size: int, noise: float) -> float:
    """Return bat frame j's departure (m), made afresh (``departure``, which keeps it)."""
    if 3 <= j < len(stream.times) and stream.continuous(j - 1, max_gap):
        continued = c2_bat_continued(stream, j - 1, max_gap, size, noise)
        if continued is not None:
            there, sample = continued[1](stream.times[j]), stream.values[j]
            return max(math.dist(there.knob, sample.knob), math.dist(there.tip, sample.tip))
    return 0.0


def departures_ahead(stream: Stream, max_gap: float, size: int, noise: float) -> int:
    """
    Make the departures of the newest bat frames ahead of the judgments that read them.

    Up to ``AHEAD_FRAMES`` newest frames without a departure kept (``departure``) or made ahead
    already: each made now (the same function of frame j, the samples before it and ``noise``,
    m 1 sigma) and kept in ``DEPARTURES_AHEAD``, which ``departure`` reads only at the very
    same noise: every verdict and every kept departure stays what it was. For the node to call
    after its drain (``ImpactNode``), off the message's path: a frame's first judgment near the
    ball (the first sweep near it, the first prediction) otherwise makes a window's departures
    in one message. Returns how many it made.
    """
    times = stream.times
    kept = stream.aligned.setdefault(DEPARTURES, [])
    ahead = stream.aligned.setdefault(DEPARTURES_AHEAD, [])
    made = 0
    for j in range(max(len(times) - AHEAD_FRAMES, 3), len(times)):
        if (j < len(kept) and kept[j] is not None) or (j < len(ahead) and ahead[j] is not None):
            continue
        if len(ahead) <= j:
            ahead.extend([None] * (j + 1 - len(ahead)))
        ahead[j] = (noise, _departure(stream, j, max_gap, size, noise))
        made += 1
    return made


def isolation(stream: Stream, j: int, max_gap: float, size: int,
              last: Optional[int] = None) -> Tuple[float, float]:
    """
    Return how far (m) bat frame j's knob and tip are from the spline through its neighbours.

    Their distances, at its stamp, from the ``c2`` path without it over the interval its
    neighbours make (the window of ``size`` samples about it, up to two after it but none past
    sample ``last``, the newest by default, through the raw samples); (0, 0) without a
    neighbour on each side in its segment within ``max_gap`` s of it.
    """
    times = stream.times
    last = len(times) - 1 if last is None else last
    if j < 1 or j + 1 > last or not (stream.continuous(j - 1, max_gap)
                                     and stream.continuous(j, max_gap)):
        return 0.0, 0.0
    first = max(j - size, 0)
    without = excerpt(stream, first, min(j + 2, last))
    without.remove(j - first)
    k = j - 1 - first
    return _distances(c2_bat_path(without, k, c2_window(without, k, max_gap, 2, size)),
                      stream, j)


def departed(stream: Stream, j: int, max_gap: float, size: int, noise: float) -> bool:
    """
    Return whether bat frame j clearly left its continuation: a glitch or the bat braking.

    Its ``departure`` more than ``glitch_floor`` (for the noise, m 1 sigma per coordinate:
    told or estimated) and ``DEPARTURE_RATIO`` times each of the ``SCATTER_FRAMES`` frames'
    before it (the stream's own scatter: a swing's own frames at 90 Hz are 35-46 sigma off
    their smoothed continuation; not a frame after lost ones, continued across the hole:
    ``stepped``); among regular steps (``regular``), or beside frames the
    tracker lost (``lost_about``) against the frames before it with the same frames left out
    (``_matched``). Where its next
    frame has not come (``isolation`` cannot judge it), this alone says the bat's path should
    not go through it.
    """
    steady = regular(stream, j - 1)
    lost = () if steady else lost_about(stream, j, 3, 0)
    if not (steady or lost):
        return False
    found = departure(stream, j, max_gap, size, noise)
    if found <= glitch_floor(noise):
        return False
    if steady:
        return found > DEPARTURE_RATIO * max(departure(stream, i, max_gap, size, noise)
                                             for i in stepped(stream, j - SCATTER_FRAMES, j))
    matched = _matched(stream, j, lost, max_gap, size, noise)
    return matched is not None and found > DEPARTURE_RATIO * max(m[0] for m in matched)


def stepped(stream: Stream, first: int, end: int) -> List[int]:
    """
    Return bat frames ``first`` to ``end - 1`` but those a step over lost frames before.

    Those whose step from the frame before them is at most ``REGULAR_STEP`` times the median
    of the steps to them: their departures (``departure``) continue the bat one step, as a
    judged frame's does (``departed``). A frame after lost frames is continued across the
    hole, two or three steps: its departure is not of that scatter (at 120 Hz with 1 mm of
    noise, 7.8-11 cm after two lost frames, against 0.3-2 cm for the frames about it).
    """
    times = stream.times
    steps = [times[i] - times[i - 1] for i in range(first, end)]
    median = sorted(steps)[len(steps) // 2]
    return [i for i, step in zip(range(first, end), steps) if step <= REGULAR_STEP * median]


def judged(stream: Stream, j: int, max_gap: float, size: int, noise: float,
           last: Optional[int] = None, scatter: int = SCATTER_FRAMES,
           hole: float = LOST_HOLE, fewer: Optional[int] = None) -> bool:
    """
    Return whether bat frame j is a glitch, from the samples up to ``last`` (the newest).

    Among regular steps (``regular``), departed (``departure``) and isolated (``isolation``)
    by more than ``glitch_floor``, and isolated more than ``ISOLATION_RATIO`` times as far as
    any of the ``scatter`` frames from three before it (whose splines do not reach it):
    the stream's own scatter, where its noise is not known yet (``tracker_noise`` auto, in a
    stream's first frames). Beside frames the tracker lost (``lost_about``), the scatter is
    that of those frames with the same frames left out about each (``_matched``). No frame is
    judged without them (a segment's first frames), nor without the frame after it. The sweep
    passes the newest sample every way of feeding the detector has by then (the node's one
    message at a time, ``analyze``'s chunks): the same verdict in both.

    :param noise: the bat's noise (m, 1 sigma per coordinate: told or estimated).
    :param scatter: how many frames measure that scatter (``SCATTER_FRAMES``; a segment's early
        frame, judged with time run backwards: ``bat_glitch_edges.EARLY_SCATTER``).
    :param hole: the longest step across lost frames it is judged beside (s: ``LOST_HOLE``;
        ``bat_glitch_edges.hole_glitch``: any).
    :param fewer: beside lost frames, the frames matched where its segment has too few before
        them for ``scatter`` (``_matched``; None: not judged there).
    """
    floor = glitch_floor(noise)
    steady = regular(stream, j, last, scatter)
    lost = () if steady else lost_about(stream, j, 2, 1, last, hole)
    if not (steady or lost) or departure(stream, j, max_gap, size, noise) <= floor:
        return False
    isolated = max(isolation(stream, j, max_gap, size, last))
    if isolated <= floor:
        return False
    if steady:
        scattered = [max(isolation(stream, i, max_gap, size, last))
                     for i in range(j - 3, j - 3 - scatter, -1)
                     if i >= 1 and stream.continuous(i, max_gap)
                     and stream.continuous(i - 1, max_gap)]
        if len(scattered) < scatter or isolated <= ISOLATION_RATIO * max(scattered):
            return False
    else:  # beside frames the tracker lost: against the frames before it with the same lost
        matched = _matched(stream, j, lost, max_gap, size, noise, scatter)
        if matched is None and fewer is not None:
            matched = _matched(stream, j, lost, max_gap, size, noise, fewer)
        if matched is None or isolated <= ISOLATION_RATIO * max(m[1] for m in matched):
            return False
    # a frame just before it that could not be judged (``judgeable``: beside lost frames, a
    # segment's first) may be the one off, pulling this one's neighbours' spline: this one is
    # no glitch unless it stays isolated without it
    newest = len(stream.times) - 1 if last is None else last
    return all(judgeable(stream, i, max_gap, newest, scatter) or isolated_without(
        stream, i, max_gap, size, noise, newest, j - i) for i in range(j - UNJUDGED_REACH, j))


def judgeable(stream: Stream, j: int, max_gap: float, last: Optional[int] = None,
              scatter: int = SCATTER_FRAMES) -> bool:
    """
    Return whether bat frame j can be judged (``judged``), its next frame at most sample ``last``.

    Among regular steps (``regular``), with the ``scatter`` frames from three before it each
    beside its neighbours in its segment (within ``max_gap`` s): not a segment's first
    ``scatter`` + 3 frames.
    """
    return regular(stream, j, last, scatter) and all(
        i >= 1 and stream.continuous(i, max_gap) and stream.continuous(i - 1, max_gap)
        for i in range(j - 3, j - 3 - scatter, -1))


def isolated_without(stream: Stream, j: int, max_gap: float, size: int, noise: float,
                     last: int, after: int = 1) -> bool:
    """
    Return whether bat frame j + ``after`` is still isolated by more than the floor without j.

    A frame near a glitch reads as one too (the glitch pulls its neighbours' spline off,
    and where the bat braked after a contact it departed from its continuation as well): the
    glitch is the one that stays isolated without the other. Reads no sample past ``last``.
    """
    return isolation_without(stream, j, max_gap, size, last, after) > glitch_floor(noise)


def isolation_without(stream: Stream, j: int, max_gap: float, size: int, last: int,
                      after: int = 1) -> float:
    """
    Return how far (m) bat frame j + ``after`` is from its neighbours' spline without frame j.

    The larger of its knob's and tip's ``isolation`` in the stream without frame j, reading
    no sample past ``last``; ``after`` (not 0) may be negative (a frame before j).
    """
    first = max(j + min(after, 0) - size, 0)
    without = excerpt(stream, first, last)
    without.remove(j - first)
    return max(isolation(without, j + after - (after > 0) - first, max_gap, size,
                         last - 1 - first))


def regular(stream: Stream, j: int, last: Optional[int] = None,
            scatter: int = SCATTER_FRAMES) -> bool:
    """
    Return whether the steps about bat frame j are regular: what the floor was measured on.

    The steps from ``scatter`` + 2 frames before it (the frames ``judged`` reads its scatter
    from, ``SCATTER_FRAMES`` by default) up to the frame before it: the last
    ``STEADY_STEPS`` at most ``REGULAR_STEP`` times their median, the others at most
    ``HOLE_STEPS`` times it (up to ``LOST_NEAR`` frames lost: not a segment's start); and the
    frames on either side of it (the one after it at most sample ``last``, the newest by
    default) at most ``PAIR_STEPS`` times it apart. A frame beside frames the tracker lost is a
    whole step or more from a neighbour, and its continuation and its neighbours' spline miss
    it by far more than a swing's do (12 and 7 cm beside two lost frames at 90 Hz); frames
    lost further before it only widen the scatter it is judged against. A frame stamped a few
    milliseconds off leaves its neighbours two steps apart, and its position, which is not
    where the swing was at its stamp, is judged.
    """
    first = j - scatter - 2
    last = len(stream.times) - 1 if last is None else last
    if first < 0 or j + 1 > last:
        return False
    times = stream.times
    steps = [b - a for a, b in zip(times[first:j - 1], times[first + 1:j])]
    median = sorted(steps)[len(steps) // 2]
    return (max(steps) <= HOLE_STEPS * median
            and max(steps[-STEADY_STEPS:]) <= REGULAR_STEP * median
            and times[j + 1] - times[j - 1] <= PAIR_STEPS * median)


def lost_about(stream: Stream, j: int, before: int, after: int, last: Optional[int] = None,
               hole: float = LOST_HOLE) -> Optional[Tuple[int, ...]]:
    """
    Return the offsets from bat frame j of the frames the tracker lost about it, or None.

    The steps from ``before`` frames before it to ``after`` frames after it (that one at most
    sample ``last``, the newest by default) in whole steps of the median of the six steps
    before them (each of those at most ``PAIR_STEPS`` times it): a step of n medians lost n - 1
    frames. None where those steps are not so, more than ``LOST_NEAR`` frames were lost among
    them, or a step across lost frames is longer than ``LOST_HOLE``; () where none was lost
    (each step a median: a regular stream's jitter).
    """
    first = j - before - 6
    last = len(stream.times) - 1 if last is None else last
    if first < 0 or j + after > last:
        return None
    times = stream.times
    steps = [b - a for a, b in zip(times[first:j - before], times[first + 1:j - before + 1])]
    median = sorted(steps)[len(steps) // 2]
    if max(steps) > PAIR_STEPS * median:
        return None
    lost, virtual, at = [], 0, 0  # (whole steps from frame j - before; j's)
    for i in range(j - before, j + after):
        at = virtual if i == j else at
        whole = round((times[i + 1] - times[i]) / median)
        # more than LOST_NEAR lost is None: said before the list is made (a hostile stream's
        # step of 1e9 medians would be a list of 1e9 frames: a minute and gigabytes)
        if whole < 1 or len(lost) + whole - 1 > LOST_NEAR:
            return None
        lost += [virtual + n for n in range(1, whole)]
        virtual += whole
    at = virtual if after == 0 else at
    span = times[j - before:j + after + 1]
    if len(lost) > LOST_NEAR or lost and max(b - a for a, b in zip(span, span[1:])) > hole:
        return None
    return tuple(v - at for v in lost)


def over_hole(stream: Stream, j: int, after: int, last: Optional[int] = None) -> bool:
    """
    Return whether bat frame j is beside frames lost across a hole over ``LOST_HOLE``.

    Up to ``LOST_NEAR`` frames lost from three frames before it to ``after`` frames after it
    (``lost_about``; that one at most sample ``last``, the newest by default), a step across
    them longer than ``LOST_HOLE`` (s): a swing's own frame there is off its continuation and
    its neighbours' spline by more than the floor. False where those frames have not come.
    """
    return (lost_about(stream, j, 3, after, last) is None
            and bool(lost_about(stream, j, 3, after, last, math.inf)))


def _matched(stream: Stream, j: int, lost: Tuple[int, ...], max_gap: float, size: int,
             noise: float, scatter: int = SCATTER_FRAMES) -> Optional[List[Tuple[float, float]]]:
    """
    Return the departures and isolations (m) of the frames before bat frame j, lost like it.

    The ``scatter`` frames (``SCATTER_FRAMES`` by default) from three before j (further by the
    frames lost after it),
    each with the frames at the offsets ``lost`` from it (``lost_about``'s from j) left out, so
    that the steps about it are j's: the scatter a swing's own frames show across such a hole.
    Each frame's spline reads no frame from j on. None where they, with three frames before
    each, are not all in j's segment within ``max_gap`` of each other.
    """
    after = sum(v > 0 for v in lost)
    found = []
    for i in range(j - 3 - after, j - 3 - after - scatter, -1):
        low, end = i - 3 - (len(lost) - after), i + 2 + after  # (three frames before it)
        if low < 0 or not all(stream.continuous(k, max_gap) for k in range(low, end)):
            return None
        first = max(i - size - len(lost) - 2, 0)
        part = excerpt(stream, first, end)
        for v in sorted(lost, reverse=True):
            part.remove(i + v - first)
        k = i - first - sum(v < 0 for v in lost)
        found.append((departure(part, k, max_gap, size, noise),
                      max(isolation(part, k, max_gap, size))))
    return found


def first_glitch(stream: Stream, first: int, last: int, max_gap: float, size: int,
                 noise: float) -> Optional[int]:
    """
    Return the first glitch among bat frames ``first`` to ``last - 1``, judged up to ``last``.

    The oldest first, each against the frames before it, which are judged (``judged``): not a
    frame whose next is the glitch (``next_the_glitch``: it stays isolated without this one,
    which it pulled off its neighbours' spline). A frame judged no glitch with every sample its
    verdict reads (its next two frames in) is kept so in the stream's ``CLEAN`` list, for the
    noise (m) it was judged at and up to ``NOISE_KEPT`` times it, and not judged again: what
    the sweep (``Sweep._bat_frames``) and the predictor (``Predictor._bat_glitch_dropped``)
    each judge the other need not. Deferring to a next frame beside a hole over ``LOST_HOLE``
    wherever it passed the floor, two bat frames lost right after a glitch's next at 90 Hz
    with 1 mm of noise left 5 of 480 misses with an impact invented (``bench_glitches.py
    --rates 90 --lost 2 --lost-frames 2``); never deferring there, a braked frame before a
    glitch a frame was lost after (``--lost 1``) was dropped in its place. None: no glitch.
    """
    clean = stream.aligned.setdefault(CLEAN, [])
    for j in range(first, last):
        if j < len(clean) and clean[j] is not None and clean[j] <= noise <= NOISE_KEPT * clean[j]:
            continue  # (judged no glitch on every sample its verdict reads)
        if not judged(stream, j, max_gap, size, noise, last):
            if j + 2 <= last:
                clean.extend([None] * (j + 1 - len(clean)))
                clean[j] = noise
            continue
        if j + 1 >= last or not next_the_glitch(stream, j, max_gap, size, noise, last):
            return j
    return None


def next_the_glitch(stream: Stream, j: int, max_gap: float, size: int, noise: float,
                    last: int, across: bool = False) -> bool:
    """
    Return whether the glitch is bat frame j + 1 rather than frame j, judged one (``judged``).

    A frame next to a glitch reads as one too (the glitch pulls its neighbours' spline off):
    the glitch is the next frame where it stays isolated without frame j by more than
    ``glitch_floor`` (``isolation_without``, reading no sample past ``last``). Where that next
    frame is beside a hole over ``LOST_HOLE`` (``over_hole``), a swing's own frame is off its
    neighbours' spline by more than the floor (5.3-8.3 cm, two frames lost at 90 Hz): there
    frame j is the glitch where it is the more isolated of the two (its ``isolation`` up to
    ``last``).

    :param noise: the bat's noise (m, 1 sigma per coordinate: told or estimated).
    :param across: frame j judged across that hole too (``bat_glitch_edges.hole_glitch``),
        its own isolation as far off for a swing's own frame: it is the glitch where it is off
        by the floor beyond its next, whether that is left in (its ``isolation``) or out
        (``isolation_without`` frame j + 1). Left in, a frame right after the hole with a
        glitch next is pulled off by it (23 cm, the glitch 16 cm without it); a braked frame
        right after the hole is off 7-10 cm either way, a glitch 10 cm turned after it 6.6-8.3
        cm without it, and was dropped in its place without the floor beyond.
    """
    apart, floor = isolation_without(stream, j, max_gap, size, last), glitch_floor(noise)
    if apart <= floor or not over_hole(stream, j + 1, 1, last):
        return apart > floor
    if not across:
        return apart > max(isolation(stream, j, max_gap, size, last))
    return not (apart + floor < max(isolation(stream, j, max_gap, size, last))
                and apart + floor < isolation_without(stream, j + 1, max_gap, size, last, -1))


def path_without(stream: Stream, k: int, j: int, max_gap: float, size: int,
                 noise: float) -> Optional[BatPath]:
    """
    Return the bat's ``c2`` path over interval k without its frames from j (> k) on, or None.

    Frame j the interval's closing one: the bat continued from before the interval
    (``fitting.c2_bat_ahead``); a later one: the interval's window ended before it. With
    ``noise`` (m, 1 sigma per coordinate) smoothed as the sweep's paths are. None where there
    is no continuation.
    """
    if j == k + 1:
        return c2_bat_ahead(stream, k, max_gap, size, noise)
    window = c2_window(stream, k, max_gap, j - k - 2, size)
    return c2_bat_path(stream, k, window, noise, window.stop == k + 2)


def _distances(path: BatPath, stream: Stream, j: int) -> Tuple[float, float]:
    """Return the knob's and the tip's distances (m) of bat frame j from a path at its stamp."""
    knob, tip = path.at(stream.times[j])
    sample = stream.values[j]
    return math.dist(knob, sample.knob), math.dist(tip, sample.tip)
