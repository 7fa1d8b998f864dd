"""
The sweep's judgment of bat frames near the ball: glitches dropped and forgotten.

A part of ``sweep.Sweep`` (its base, reading the sweep's streams, configuration and counters).
The frames an interval near the ball reads are judged by ``bat_glitches`` (``_bat_frames``);
a closing frame whose next has not come yet and that departed from its continuation is left
out of the interval's path, or, where a hit's contact hangs on it, judged first, the interval
waiting for its next frame (``_without_departed``, ``_closing_glitch``). A segment's first
and early frames, and frames beside a hole over ``bat_glitches.LOST_HOLE``, that a contact
hangs on are judged with the frames after them, the interval waiting for those
(``_early_bat_glitch``). A glitch is dropped as ``bat_glitch`` (a ``LateDrop``) and forgotten
(``Stream.remove``).
"""

from bisect import bisect_left
import math
from typing import Optional, Tuple

from . import bat_glitch_edges, bat_glitches
from .events import DropReason, Role
from .fitting import c2_bat_path, c2_window, stream_noise
from .noise import ESTIMATES
from .streams import excerpt
from ..motion import BatPath, Paths

CONTACT_APART = 1e-4
"""s: a hit's contacts on the bat's path through its newest frame, which departed, and on the
path without it, further apart than this, and the frame is judged before the hit is solved
(``Sweep._without_departed``)."""


class BatFrames:
    """The bat's frames judged near the ball: a base of ``sweep.Sweep`` (see there)."""

    __slots__ = ()

    def _bat_frames(self, interval: Tuple[float, float], bat_k: int,
                    paths: Paths) -> Optional[Paths]:
        """
        Judge the bat frames the path over bat interval bat_k reads; None: one was forgotten.

        The frames of its window from the first up to the one before the newest its path may
        read (``_horizon``: with their next frame) are judged, the oldest first
        (``bat_glitches.first_glitch``), and the first glitch is dropped and forgotten: None
        (the interval is to be located again, and the frames after it judged again without
        it). Else ``paths`` without a frame after its opening one that departed
        (``_without_departed``: at look-ahead 0 its closing frame's next has not come yet),
        which is judged once its next frame has (``bat_suspect``); None where a hit hangs on
        that frame, which was then a glitch, forgotten, or waits for its next frame
        (``held``: ``_closing_glitch``); None too where a contact hangs on a segment's early
        frame, a glitch or waiting for the frames after it (``_early_bat_glitch``).
        """
        bat, config = self.bat, self.config
        max_gap, size = config.max_gap, config.spline_window
        last = self._horizon(bat_k)
        glitch = bat_glitches.first_glitch(
            bat, c2_window(bat, bat_k, max_gap, 0, size).start, last, max_gap, size,
            stream_noise(bat, config))
        if glitch is not None:
            self._bat_glitch(glitch, last)
            return None
        without, departed = self._without_departed(interval, bat_k, paths)
        if without is not None and self._early_bat_glitch(interval, bat_k, without):
            return None
        if departed is not None:
            self.bat_suspect = departed
        return without

    def _early_bat_glitch(self, interval: Tuple[float, float], bat_k: int,
                          paths: Paths) -> bool:
        """
        Judge the bat frames a contact over bat interval bat_k hangs on that need later frames.

        Its window's frames up to ``_horizon``, the newest first, among a segment's first
        (``bat_glitch_edges.early``: judged against the frames after them with time run
        backwards, ``bat_glitch_edges.early_glitch``; the very first,
        ``bat_glitch_edges.segment_first``, by its departure from the seven after it,
        ``bat_glitch_edges.first_frame_glitch``) or beside a hole over
        ``bat_glitches.LOST_HOLE`` (``bat_glitch_edges.beside_hole``: judged with three frames
        after them, ``bat_glitch_edges.hole_glitch``), where ``paths`` (those to be swept: without
        a frame that departed) and the paths without the frame disagree over the union interval (s)
        (``_hangs_on``): the first glitch is dropped and forgotten (True: the interval is to be
        located again). True too where those frames have not all come and the recording goes
        on (``held``: the interval waits for them).
        """
        bat, config = self.bat, self.config
        max_gap, size = config.max_gap, config.spline_window
        noise, last = stream_noise(bat, config), self._horizon(bat_k)
        for j in range(last, c2_window(bat, bat_k, max_gap, 0, size).start - 1, -1):
            rule = bat_glitch_edges.late_rule(bat, j, max_gap)
            if rule is None:
                continue
            judge, reads = rule
            if not self._hangs_on(interval, j, last, paths):
                continue
            glitch = judge(bat, j, max_gap, size, noise)
            if glitch is None and not self.final:
                self.held = True
                return True
            if glitch:
                self._bat_glitch(j, min(max(last, reads), len(bat.times) - 1))
                return True
        return False

    def _hangs_on(self, interval: Tuple[float, float], j: int, last: int, paths: Paths) -> bool:
        """
        Return whether the contact over the union interval (s) hangs on bat frame j.

        The bat's ``c2`` path over the interval from its frames up to ``last`` without frame j
        (``bat_glitches.path_without`` where j is ``last``, after the interval: the bat
        continued; a bat path must move as a bat can, ``_plausible``), and ``paths``: one
        touches and the other does not, or their contacts are more than ``CONTACT_APART``
        apart. True under another model, or where there is no such path.
        """
        bat, config = self.bat, self.config
        if self.model != 'c2':
            return True
        max_gap, size = config.max_gap, config.spline_window
        first = max(bat.interval(interval[0]) - size - 2, 0)
        if j <= first:
            return True
        noise, k = stream_noise(bat, config), bat.interval(interval[0])
        if j == last > k:  # (the newest frame it may read: the bat continued without it)
            path = bat_glitches.path_without(bat, k, j, max_gap, size, noise) if k >= 2 else None
        else:
            without = excerpt(bat, first, last)
            without.remove(j - first)
            k = without.interval(interval[0])
            if k < 0 or k + 1 >= len(without.times) or not without.continuous(k, max_gap):
                return True
            window = c2_window(without, k, max_gap, config.look_ahead, size)
            path = c2_bat_path(without, k, window, noise, window.stop == k + 2)
        if path is None or not self._plausible(path):
            return True
        return _disagree(self._contact(interval, paths), self._contact(interval, (paths[0], path)))

    def _horizon(self, bat_k: int) -> int:
        """
        Return the newest bat sample a judgment at bat interval bat_k may read.

        The interval's closing frame and the model's look-ahead (``ahead``): what the walk
        waits for before it sweeps the interval, so the node (one message at a time) and
        ``analyze`` (chunks, whose streams may run further ahead) judge alike.
        """
        return min(bat_k + 1 + self.ahead, len(self.bat.times) - 1)

    def _without_departed(self, interval: Tuple[float, float], bat_k: int,
                          paths: Paths) -> Tuple[Optional[Paths], Optional[int]]:
        """
        Return the paths without a bat frame that departed after bat interval bat_k, its stamp.

        The frames its path reads after its opening one (its closing one, the look-ahead's), in
        turn: where one departed from its continuation (``bat_glitches.departed``: a glitch whose
        next frame may not have come yet, or the bat braking after a contact), the bat's path
        without it and the frames after it (``bat_glitches.path_without``), where a bat can move on
        it (``_plausible``), and the frame's stamp (ns), where neither path touches over the
        union interval (s). Where the frame is the newest the path may read (``_horizon``: the
        frames before it were judged) and the paths disagree (one touches and the other does
        not: a glitch turned toward the ball or away from a hit, or a bat that really stopped
        short of a ball its continuation would meet; or their contacts more than
        ``CONTACT_APART`` apart), the frame is judged first (``_closing_glitch``): None and None
        where it was a glitch, forgotten (the interval is to be located again), or where the
        interval waits for its next frame (``held``); else ``paths`` and None. Where both
        paths touch within that, a hit, whose contact comes before a brake: ``paths`` and
        None. An older frame (judged no glitch) where one path touches: the paths without it.
        """
        bat, config = self.bat, self.config
        max_gap, size = config.max_gap, config.spline_window
        noise, horizon = stream_noise(bat, config), self._horizon(bat_k)
        for j in range(bat_k + 1, horizon + 1):
            if not bat.continuous(j - 1, max_gap):
                break
            if bat_glitches.departed(bat, j, max_gap, size, noise):
                path = bat_glitches.path_without(bat, bat_k, j, max_gap, size, noise)
                if path is None or not self._plausible(path):
                    break
                without = paths[0], path
                through = self._contact(interval, paths)
                if through is None and j < horizon:
                    return without, bat.stamps[j]
                contact = self._contact(interval, without)
                if through is None and contact is None:
                    return without, bat.stamps[j]
                if j == horizon and _disagree(through, contact):  # (both None: above)
                    if self._closing_glitch(j):
                        return None, None
                    break  # (no glitch: the hit, or the miss, on the path through it)
                if contact is None:  # (an older frame, judged: its path touches, not without)
                    return without, bat.stamps[j]
                break
        return paths, None

    def _closing_glitch(self, j: int) -> bool:
        """
        Judge bat frame j, which a hit's contact hangs on, from its next frame; True: wait.

        True where it was a glitch (``bat_glitches.judged`` up to frame j + 1: dropped and
        forgotten, ``_bat_glitch``) or where its next frame has not come yet and the recording
        goes on (``held``: the interval waits for it, one bat frame). False where it is no
        glitch, or no frame comes after it (``final``, or one past ``max_gap``): the hit stands
        on the path through it.
        """
        bat, config = self.bat, self.config
        if j + 1 >= len(bat.times):
            self.held = not self.final
            return self.held
        if bat_glitches.judged(bat, j, config.max_gap, config.spline_window,
                               stream_noise(bat, config), j + 1):
            self._bat_glitch(j, j + 1)
            return True
        return False

    def _plausible(self, path: BatPath) -> bool:
        """
        Return whether a bat path continued past its samples moves as a bat can.

        Neither end moves, nor the path strays from its chord, by more than ``max_speed``
        allows over its interval: a continuation of samples a few microseconds apart, or of
        wild ones, can reach anywhere (and the sweep would cut it in as many sub-steps).
        """
        t0, t1 = path.t0, path.t1
        reach = self.config.max_speed * (t1 - t0)
        start, end = path.at(t0), path.at(t1)
        return (path.deviation(t0, t1) <= reach
                and max(math.dist(start[0], end[0]), math.dist(start[1], end[1])) <= reach)

    def _judge_suspect(self, bat_k: int) -> None:
        """
        Judge the departed bat frame ``bat_suspect`` once its next frame is within the horizon.

        At union intervals within bat interval bat_k (``_horizon``), near the ball or not.
        """
        bat, stamp = self.bat, self.bat_suspect
        j = bisect_left(bat.stamps, stamp)
        if j < len(bat.stamps) and bat.stamps[j] == stamp:
            last = self._horizon(bat_k)
            if j + 1 > last:
                return  # (its next frame still to come)
            config = self.config
            if bat_glitches.judged(bat, j, config.max_gap, config.spline_window,
                                   stream_noise(bat, config), last):
                self._bat_glitch(j, last)
        self.bat_suspect = None

    def _bat_glitch(self, j: int, last: int) -> None:
        """
        Drop bat frame j, a glitch (``bat_glitches``), and forget it.

        A late drop (``LateDrop``, reason ``bat_glitch``) under the input that was off: the
        pose, or whichever of the knob and the tip is farther from its neighbours' spline (up
        to sample ``last``: ``_horizon``).
        """
        bat, config = self.bat, self.config
        if config.bat_input == 'pose':
            role = Role.BAT_POSE
        else:
            knob, tip = bat_glitches.isolation(bat, j, config.max_gap, config.spline_window,
                                               last)
            role = Role.KNOB if knob > tip else Role.TIP
        self.stats.drop_late(role, DropReason.BAT_GLITCH, bat.stamps[j], self.frame_of() or '')
        del bat.aligned.get(bat_glitches.CLEAN, [])[max(j - 2, 0):]  # (they read frame j)
        bat.remove(j, (ESTIMATES,))


def _disagree(through: Optional[float], without: Optional[float]) -> bool:
    """
    Return whether two paths' contacts (s; None: none) disagree about a hit.

    One touches and the other does not, or their contacts are more than ``CONTACT_APART``
    apart (a frame a contact hangs on: ``_without_departed``, ``_hangs_on``).
    """
    if through is None or without is None:
        return (through is None) != (without is None)
    return abs(through - without) > CONTACT_APART
