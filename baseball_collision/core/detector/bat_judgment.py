"""
The judgment of the bat frames a prediction's forecast reads: ``Predictor``'s fault rules.

The predictor forecasts from the bat's newest frames at once, while the sweep judges a frame
only once the ball is near it: a tracker's glitch, a frame stamped milliseconds off or one
after frames lost would bend every forecast through it, showing, moving or withdrawing a
contact the pitch does not have. So before a frame's forecast is used:

- the newest frame is judged against the forecast of the frames before it
  (``BatJudgment._bat_off``: ``NEWEST`` holds the prediction in force and makes the frame
  ``suspect``; ``BEFORE`` forecasts without the frame before it; ``ACROSS``, after a hole,
  forecasts from the frames before it and lets the frame after it say which it was,
  ``_followed``), where the frame would change what is shown, or after a hole or off the line
  through the two frames before it (``_after_step``, ``_off_line``);
- the window's newest frames are judged by the sweep's rule and a glitch dropped as the sweep
  drops it (``_bat_glitch_dropped``); a suspect that rule cannot judge yet waits for the
  sweep's rule for it, left out of the forecast meanwhile (``_late_verdict``); a window of a
  segment's first four frames whose newest would be held is told whether its 2nd frame is off
  instead by the frames before the tracking gap (``_second_across``), else by the frame after
  it (``_second_instead``): then the 2nd is the suspect left out.

A chunk's plan stops at the frames these rules may judge (``plan_prediction``).

``BatJudgment`` is ``Predictor``'s base: the rules are the predictor's methods, read the
predictor's streams and window, and keep their state (``suspect``) on it. What each rule is for
and what it was measured against: docs/faults.md, "With prediction on", "The prediction under
a bat fault" and "... beside the tracker's lost frames".
"""

from bisect import bisect_left
import math
from statistics import median
from typing import Callable, List, Optional, Tuple, Union

import numpy as np

from .bat_glitch_edges import late_rule, segment_first
from .bat_glitches import BAT_GLITCH_FLOOR, first_glitch, glitch_floor, REGULAR_STEP
from .bat_window import newest_miss, noise_gain, PREDICTION_DEGREE, STEP_ROWS
from .config import DetectorConfig
from .fitting import c2_window, stream_noise
from .streams import Stream
from ..motion.c2 import c2_rows, rotate, unit_axis
from ..prediction import bat_window_numbers, states_of
from ..toi import ImpactResult

BAT_CHECK_MOVE = 0.002
"""s: a prediction in force whose instant a frame moves by less than this is not checked for a
bat frame off the swing (``Predictor._bat_off``, 9 us at 1 kHz): consecutive predictions
10 ms apart move by a median 0.4-0.7 ms on a tracked swing at 360 Hz with 1 mm of noise."""

BEFORE_OFF = 1.5
"""How many times nearer the forecast without the frame before it than the one through it a
bat frame off the latter lands where that frame before is taken as off (``Predictor._bat_off``;
``bench_prediction.py --faults``: 2 lost 20 ms ahead that the pitch without the frame keeps,
of 252 hits at 90 Hz with 1 mm of noise, against 7 at 2 times and 15 at 3)."""

NEWEST, BEFORE, ACROSS = 'newest', 'before', 'across'
"""``Predictor._bat_off``'s verdicts: the newest bat frame is off the swing, the one before, or
the newest after a step over ``REGULAR_STEP`` times the one before (a frame lost between)."""

SECOND = 'second'
"""``Predictor._newest_judged``'s verdict where ``_bat_off``'s ``NEWEST`` on a window of its
segment's first four frames is the segment's 2nd frame off instead (``_second_across``)."""

PREVIOUS_FRAMES = 3
"""Frames of the bat's segment before a tracking gap that ``BatJudgment._second_across`` reads
with a window of the next segment's first four frames (a degree-3 fit then has two frames to
spare: it can tell which frame is off)."""

PREVIOUS_HOLE_S = 0.25
"""s: the longest tracking gap ``BatJudgment._second_across`` fits across (measured to 0.21 s:
``bench_prediction.py --faults``' ``segment 2`` and ``segment 4`` with the frames lost before
the segment over 0.1 and 0.2 s, not one 4th frame taken for the 2nd)."""

THIRD_FIT_RATIO = 1.3
"""How many times farther the fits without a segment's 1st and without its 2nd frame leave their
frames than the fit without its 3rd leaves its own where ``BatJudgment._third_across`` holds the
3rd as off (``bench_prediction.py --faults``' segments, 90 Hz: of 288 3rd frames turned 10-20 cm
278 over it and over the glitch floor exact, 276 with 1 mm of noise; of 1008 genuine 3rd frames
with the 1st or 2nd turned or none, 0 exact and 7 with 1 mm, all with the 1st turned)."""

NOT_LATE = 'not late'
"""``Predictor._late_verdict``'s answer for a frame the window's judgment (``first_glitch``)
judges."""

Found = Optional[Tuple[float, ImpactResult]]
"""A forecast's search result (``prediction.contact_of``): the contact's instant (s) and
point, or None."""


class BatJudgment:
    """
    The judgment of the newest bat frames a forecast reads; the base of ``Predictor``.

    Keeps what the judgment carries from frame to frame (``drop_bat``, ``suspect``, the frame
    left out) and reads the predictor's: its bat stream (``bat``) and configuration, the last
    extrapolated bat's frames (``_bat_window``, [first, end)) and the prediction in force
    (``predicting``, its instant ``_instant`` in s).
    """

    __slots__ = ('drop_bat', 'suspect', '_left_out')

    bat: Stream
    _config: DetectorConfig
    _bat_window: Tuple[int, int]
    predicting: bool
    _instant: float

    def __init__(self) -> None:
        # drops and forgets bat frame j, a glitch judged from the samples up to a last one
        # (the sweep's ``_bat_glitch``); None: the forecast's frames are not judged
        self.drop_bat: Optional[Callable[[int, int], None]] = None
        # the time (s) of a newest bat frame that held a prediction (``_bat_off``), not
        # judged yet: the frames after it judge it whatever they show (``_bat_glitch_dropped``)
        self.suspect: Optional[float] = None
        # the suspect's frame where the sweep's rule for it (a segment's first frames, beside a
        # long hole: ``_late_verdict``) awaits later frames or judged it a glitch: the bat is
        # forecast without it
        self._left_out: Optional[int] = None

    def _newest_judged(self, found: Found) -> Optional[str]:
        """
        Return ``_bat_off``'s verdict on the newest bat frames; make a newest frame off suspect.

        ``NEWEST``, ``ACROSS``: the newest frame is ``suspect``, judged by the frames after it
        (``_bat_glitch_dropped``). ``SECOND``: ``NEWEST`` on a window of its segment's first
        four frames whose 2nd frame is off instead (``_second_across``), which is ``suspect``
        then. The predictor then holds the prediction in force (``NEWEST``), or where
        something is shown forecasts the bat without the frame off (``BEFORE``, ``ACROSS``,
        ``SECOND``: ``_numbers_without``); where nothing is shown either way it
        forecasts nothing without it (that gave near misses false predictions). ``found``:
        ``contact_of``'s result.
        """
        off = self._bat_off(found)
        first, end = self._bat_window
        if off is None and end - first == 3 and self._third_across(first, end):
            off = NEWEST  # (a segment's 3rd frame off the frames before the tracking gap)
        if off is NEWEST and end - first == 4 and self._second_across(first, end):
            off = SECOND
            self.suspect = self.bat.times[first + 1]
        elif off is NEWEST or off is ACROSS:  # (the newest: judged by the frames after it)
            self.suspect = self.bat.times[end - 1]
        return off

    def _numbers_without(self, off: str) -> Optional[Tuple[float, ...]]:
        """
        Return the bat forecast without the frame ``_bat_off``'s verdict ``off`` says is off.

        ``BEFORE``: without the frame before the newest; ``SECOND``: without the window's 2nd;
        else without the newest (the forecast of the frames before it). As ``_bat_numbers``:
        None, a rank-deficient fit.
        """
        first, end = self._bat_window
        if off is SECOND:
            return self._bat_numbers(first, end, first + 1)
        return self._bat_numbers(first, end, end - 2) if off is BEFORE else \
            self._bat_numbers(first, end - 1)

    def _bat_glitch_dropped(self, found: Found) -> bool:
        """
        Judge the extrapolated bat's frames as the sweep does; True: a glitch was dropped.

        Where the frame would change what is shown (``_shown_changes``; ``found``:
        ``contact_of``'s result, a contact or one in force), or a newest frame held the
        prediction since the last judgment (``suspect``, forgotten once a judgment reads its
        next frame or it left the window, or at a due frame that forecasts nothing: the ball
        out of reach, disarmed, too few samples): the forecast window's frames with
        their next frame in it that the sweep judges for an interval closing at its newest
        (``fitting.c2_window``: up to ``spline_window`` frames), the oldest first, by the
        sweep's rule (``bat_glitches.first_glitch`` from the window's samples, the verdicts
        kept with the sweep's), and the first glitch is dropped and forgotten (``drop_bat``:
        the sweep's ``bat_glitch`` drop), so that the prediction reads the frames the detection
        path reads; the sweep judges a frame only once an interval near the ball reads it. A
        frame's first verdict costs a smoothed continuation with noise
        (``bat_glitches.departure``), hence only where the frame would change what is shown.
        A suspect that rule cannot judge is judged first (``_suspect_judged``), and not
        dropped here.
        """
        first, end = self._bat_window
        suspect = self.suspect
        self._left_out = None
        if self.drop_bat is None or (suspect is None and (
                (found is None and not self.predicting) or not self._shown_changes(found))):
            return False
        bat, config = self.bat, self._config
        gap, size, last = config.max_gap, config.spline_window, end - 1
        times, noise = bat.times, stream_noise(bat, config)
        if suspect is not None:
            self._suspect_judged(suspect, first, end)
        first = max(first, c2_window(bat, last - 1, gap, 0, size).start)
        if suspect is not None and self._left_out is None and (
                times[first] > suspect or suspect < times[last]):
            self.suspect = None  # judged now (its next frame in), or out of the window
        glitch = first_glitch(bat, first, last, gap, size, noise)
        if glitch is None:
            return False
        if glitch == self._left_out:
            return False  # (left out already, till the sweep's rule for it can judge it)
        self.drop_bat(glitch, last)
        self.suspect = self._left_out = None
        return True

    def _suspect_judged(self, suspect: float, first: int, end: int) -> None:
        """
        Judge the suspect (its time ``suspect``, s) where the window's judgment cannot.

        Where it is among the extrapolated bat's frames [first, end) before the newest: a
        suspect that ``first_glitch`` cannot judge (a segment's first frames, a frame beside a
        hole over ``bat_glitches.LOST_HOLE``) is judged by the sweep's rule for it once the
        frames after it that the rule reads have come (``_late_verdict``): a frame judged no
        glitch is forgotten as a suspect, and so is one after a hole (``_bat_off``: ``ACROSS``)
        whose next frame goes on from it (``_followed``) meanwhile; till then, or judged a
        glitch (``_left_out``), and while it is in the forecast's window, the bat is forecast
        without it (``Predictor._search``). A segment's 4th frame held for its 2nd
        (``_second_instead``, told by the frame after it) hands the suspicion to the 2nd, judged
        so in its place. Not dropped here: the sweep drops it where a
        contact hangs on it, and a drop here, at another frame than the sweep's, made the chunk
        path's impacts differ from one sample at a time's (``bench_prediction.py --faults
        --chunks``: 7 of 288 runs, 90 Hz, 1 mm).
        """
        times = self.bat.times
        if not (first <= (j := bisect_left(times, suspect, first, end)) < end - 1
                and times[j] == suspect):
            return
        if self._second_instead(first, j):
            j -= 2
            self.suspect = times[j]  # (the segment's 2nd frame bent the forecast that held j)
        verdict = self._late_verdict(j)
        if verdict is None and self._across_hole(j) and self._followed(j):
            verdict = False  # (its next frame goes on from it: the swing's own)
        if verdict is None or verdict is True:  # (waits, or a glitch: forecast without it)
            self._left_out = j
        elif verdict is not NOT_LATE:
            self.suspect = None  # (judged no glitch by the sweep's rule)

    def _second_across(self, first: int, end: int) -> bool:
        """
        Return whether bat frames [first, end), its segment's first four, have their 2nd off.

        The window held its newest (``_bat_off``: ``NEWEST``), but from four frames the
        forecast cannot tell a glitch there from one at the 2nd frame (``_second_instead``).
        The ``PREVIOUS_FRAMES`` frames before the tracking gap (over ``max_gap``, up to
        ``PREVIOUS_HOLE_S``; one segment) can: each of the 2nd and the 4th frame against the
        fit of the others and those (``_miss_without``), the 2nd the farther off. A glitch at
        the 4th left the 2nd 0.09-0.59 times as far off as the 4th, one at the 2nd 0.49-19.6
        times, across gaps of 0.08-0.21 s (``bench_prediction.py --faults``' ``segment 4`` and
        ``segment 2``, 90 Hz). False where those frames are not in the stream.
        """
        start = first - PREVIOUS_FRAMES
        if not self._across_gap(first):
            return False
        return self._miss_without(start, end, first + 1) > self._miss_without(
            start, end, end - 1)

    def _across_gap(self, first: int) -> bool:
        """
        Return whether bat frame ``first`` comes after a tracking gap with frames before it.

        The gap over ``max_gap`` and up to ``PREVIOUS_HOLE_S``, the ``PREVIOUS_FRAMES`` frames
        before it one segment (``_second_across``, ``_third_across``).
        """
        start = first - PREVIOUS_FRAMES
        bat, gap = self.bat, self._config.max_gap
        return start >= 0 and gap < bat.times[first] - bat.times[first - 1] <= PREVIOUS_HOLE_S \
            and all(bat.continuous(i, gap) for i in range(start, first - 1))

    def _third_across(self, first: int, end: int) -> bool:
        """
        Return whether bat frames [first, end), its segment's first three, have their 3rd off.

        Three frames cannot judge their newest (``_bat_off``: fewer than 4), and their forecast
        through a glitch there shows a contact the pitch does not have, or misses the one it
        has. The ``PREVIOUS_FRAMES`` frames before the tracking gap (``_across_gap``) tell
        which of the three is off, each measured against the fit of the other five in a chart
        of their own (``_chart_misses``): the 3rd, where it is more than ``glitch_floor`` of
        the stream's noise off that fit and the fits without the 1st and without the 2nd
        (each through the 3rd) leave their frames ``THIRD_FIT_RATIO`` times farther off than
        the fit without the 3rd leaves its own. A glitch among five frames bends their fit,
        whichever it is: with the 3rd turned 10-20 cm that ratio was 1.19-4.31 exact and
        1.09-4.35 with 1 mm of noise, with the 1st or the 2nd turned 0.09-1.87, with none
        0.45-1.42 (``bench_prediction.py --faults``' ``segment 1..3``, 90 Hz; the scatter
        without a glitch is the chart's own: a cubic over some 120 ms of swing). False where
        those frames are not in the stream, or the window does not begin its segment among
        regular steps (``_segment_start``).
        """
        if not self._across_gap(first) or not self._segment_start(first, end):
            return False
        misses = self._chart_misses(first - PREVIOUS_FRAMES, end, first)
        if misses is None:
            return False
        (_, first_fit), (_, second_fit), (third, third_fit) = misses
        return third > glitch_floor(stream_noise(self.bat, self._config)) and min(
            first_fit, second_fit) > THIRD_FIT_RATIO * third_fit

    def _chart_misses(self, start: int, end: int,
                      first: int) -> Optional[List[Tuple[float, float]]]:
        """
        Return how far each of bat frames [first, end) is off the fit of frames [start, end).

        Per frame j, the fit of the others (a cubic in time per coordinate of the rigid chart
        ``motion.c2`` fits: knob, rotation vector from frame ``first``'s direction, length,
        ``c2_rows``): (frame j's distance from it, the farthest of the others' distances), m,
        each the larger of the knob's and the tip's. None where the chart does not hold all
        the frames (turned over ``MAX_CHART_ANGLE`` from frame ``first``'s direction) or a
        fit would read fewer than 5 frames.
        """
        bat = self.bat
        if end - start < 6:
            return None
        kept, rows = c2_rows(bat.values[start:end], first - start)
        if kept != 0 or len(rows) != end - start:
            return None
        chart = np.array(rows)
        times = np.array(bat.times[start:end]) - bat.times[first]
        reference = unit_axis(bat.values[first])
        misses = []
        for j in range(first - start, end - start):
            others = [i for i in range(end - start) if i != j]
            weights = np.linalg.lstsq(np.vander(times[others], 4), chart[others],
                                      rcond=None)[0]
            fitted = np.vander(times, 4) @ weights
            distances = []
            for row, frame in zip(fitted, bat.values[start:end]):
                knob = tuple(row[:3])
                tip = tuple(k + row[6] * d for k, d in zip(knob, rotate(reference,
                                                                        tuple(row[3:6]))))
                distances.append(max(math.dist(knob, frame.knob), math.dist(tip, frame.tip)))
            misses.append((distances[j], max(distances[i] for i in others)))
        return misses

    def _miss_without(self, first: int, end: int, j: int) -> float:
        """
        Return how far (m) bat frame j is from the fit of frames [first, end) but j.

        The larger of the knob's and the tip's distances from ``_bat_numbers``' forecast at its
        stamp (s); 0 where that fit is rank deficient.
        """
        numbers = self._bat_numbers(first, end, j)
        if numbers is None:
            return 0.0
        knob, tip = states_of(None, numbers, self.bat.times[j])[2:]
        frame = self.bat.values[j]
        return max(math.dist(knob, frame.knob), math.dist(tip, frame.tip))

    def _second_instead(self, first: int, j: int) -> bool:
        """
        Return whether the suspect bat frame j, its segment's 4th, was held for its 2nd frame.

        A window of its segment's first four frames may hold its newest (``_bat_off``), but
        from four frames the forecast cannot tell a glitch at the newest from one at the 2nd
        frame, which bends the forecast through it by about the same (the newest off it by 2-3
        times the 2nd frame's distance from the forecast of the other three, either way:
        ``bench_prediction.py --faults``' ``segment 2`` and ``segment 4``). Its next frame
        tells: True where frame j + 1 (in the window [first, ...)) leaves the forecast of the
        four frames (``_bat_leaves``) and lands within ``glitch_floor`` of their forecast
        without the 2nd (``_bat_miss``): a glitch at frame j bends that one too, by more.
        Then the 2nd frame is the suspect, judged by the sweep's rule for it and left out of
        the forecast till then (``_suspect_judged``), and frame j is taken.
        """
        start = j - 3
        if start < first or not self._segment_start(start, j + 1):
            return False
        return self._bat_leaves(start, j + 2) and self._bat_miss(
            start, j + 2, start + 1) <= glitch_floor(stream_noise(self.bat, self._config))

    def _late_verdict(self, j: int) -> Union[None, bool, str]:
        """
        Return the sweep's verdict on bat frame j where ``first_glitch`` cannot judge it.

        A segment's 2nd to 8th frame (``bat_glitch_edges.early``: ``early_glitch``), its first
        (``segment_first``: ``first_frame_glitch``), a frame beside a hole over ``LOST_HOLE``
        (``beside_hole``: ``hole_glitch``), picked as the sweep picks them
        (``bat_glitch_edges.late_rule``): True, a glitch; False, none; None, the frames after it
        that the rule reads have not all come. ``NOT_LATE``: none of those (``first_glitch``
        judges it).
        """
        bat, config = self.bat, self._config
        rule = late_rule(bat, j, config.max_gap)
        if rule is None:
            return NOT_LATE
        return rule[0](bat, j, config.max_gap, config.spline_window, stream_noise(bat, config))

    def _shown_changes(self, found: Found) -> bool:
        """
        Return whether a frame's search result changes what is shown by more than a little.

        A contact where none is in force, none where one is, or an instant ``BAT_CHECK_MOVE``
        or more from the one in force (``found``: ``contact_of``'s result).
        """
        return found is None or not self.predicting or \
            abs(found[0] - self._instant) >= BAT_CHECK_MOVE

    def _bat_off(self, found: Found) -> Optional[str]:
        """
        Return which of the extrapolated bat's newest frames is off the swing, if one is.

        ``NEWEST``: the newest frame, and not the one before, left the swing: it is more than a
        bat glitch's least distance (``bat_glitches.glitch_floor`` of the stream's noise: 5 cm
        or more) from the bat forecast from the frames before it (the forecast's own fit, one
        frame shorter; knob or tip), and no nearer the forecast without the frame before
        (below). A swing's own frames land within 2.8 cm of it at 90 Hz and 3.6 cm at 360 Hz
        with 1 mm of noise, a frame turned 10 cm at the tip 8.3 cm or more away. Not where the
        frame before left it too: the fit through that one misses the newest (the sweep judges
        a bat frame only near the ball, so a glitch may stay in the window for tens of
        milliseconds). Only after a step at most ``bat_glitches.REGULAR_STEP`` times the step
        before it. Judged only where the frame would change what is shown (``_shown_changes``;
        ``found``: ``contact_of``'s result; a frame after a hole, or off the line through the
        two before it, that finds nothing with nothing in force is judged so too,
        ``Predictor._search``).

        ``ACROSS``: as ``NEWEST``, but the newest frame comes after a hole, off the hole's own
        floor (``_across_verdict``).

        ``BEFORE``: the frame before the newest is off, the newest not: the newest is that far
        from the forecast through it, and ``BEFORE_OFF`` times nearer the forecast from the
        frames before them both (a frame stamped milliseconds off, its pose right, or a glitch
        not judged yet, bends the first and not the second). Judged where the frame would
        change what is shown, or where one of the two steps about the frame before is more than
        ``REGULAR_STEP`` times the other (a stamp off the stream's cadence), with 6 frames or
        more in the window.

        None: neither (or fewer than 5 frames; 4 where they begin their segment among regular
        steps, ``_segment_start``: a glitch among a segment's first frames, which the window's
        judgment cannot judge, is held so and then left out, ``_bat_glitch_dropped``).
        """
        first, end = self._bat_window
        times = self.bat.times
        if end - first < 4 or end - first == 4 and not self._segment_start(first, end):
            return None
        before, after = times[end - 2] - times[end - 3], times[end - 1] - times[end - 2]
        shown = self._shown_changes(found)
        if not shown and max(before, after) <= REGULAR_STEP * min(before, after):
            return None
        miss = self._bat_miss(first, end)
        if miss <= glitch_floor(stream_noise(self.bat, self._config)):
            return None
        if end - first >= 6 and BEFORE_OFF * self._bat_miss(first, end, end - 2) < miss:
            return BEFORE
        if not shown or self._bat_leaves(first, end - 1):
            return None
        if after <= REGULAR_STEP * before:
            return NEWEST
        return self._across_verdict(first, end, miss)

    def _across_verdict(self, first: int, end: int, miss: float) -> Optional[str]:
        """
        Return ``ACROSS`` where bat frame end - 1, after a hole, is off the swing; else None.

        The frame comes after a hole (``_across_hole``: frames lost or dropped right before
        it), where the forecast reaches over two steps or more and a swing's own frame lands
        centimetres off it: ``ACROSS`` where it is more than the hole's floor off
        (``_across_floor``, from the window's own one-step miss and the fit's noise gain;
        ``miss``, m: its distance from the forecast of frames [first, end - 1)), and not
        ``BEFORE_OFF`` times nearer the forecast without the frame before it (a frame stamped
        off before the hole bent the forecast: ``BEFORE``'s case; after a genuine frame dropped
        beside it a hit lost its prediction). The frame predicts from the forecast of the
        frames before it (not held, not bent) and is ``suspect``: the frame after it says which
        it was (``_bat_glitch_dropped``: ``_followed``).
        """
        if not self._across_hole(end - 1) or miss <= self._across_floor(first, end):
            return None
        # (not where the frame before the hole bent the forecast: one stamped off, ``BEFORE``;
        # with 6 frames or more ``_bat_off``'s test said so already)
        return None if end - first < 6 and BEFORE_OFF * self._bat_miss(
            first, end, end - 2) < miss else ACROSS

    def _across_floor(self, first: int, end: int) -> float:
        """
        Return the distance (m) bat frame end - 1, after a hole, is off the swing beyond.

        ``glitch_floor`` of the stream's noise, or the frame before it off the forecast of the
        frames before that (``_bat_miss``: the window's one-step miss, its noise and the swing's
        own turn) times how much more the forecast of frames [first, end - 1) carries at frame
        end - 1's stamp on the same noise (``noise_gain``, from the stamps and the fit's degree:
        across one frame lost at 90 Hz 6.1 times; a still bat with 1 mm of noise: 35 mm at
        the median, 67 mm p99), if more: across a hole the forecast, not the frame, may be that
        far off.
        """
        times = self.bat.times
        degree = min(self._config.velocity_degree, PREDICTION_DEGREE)
        ratio = noise_gain(times[first:end - 1], times[end - 1], degree) / noise_gain(
            times[first:end - 2], times[end - 2], degree)
        return max(glitch_floor(stream_noise(self.bat, self._config)),
                   ratio * self._bat_miss(first, end - 1))

    def _after_step(self, end: int) -> bool:
        """
        Return whether bat frame end - 1's step is over ``REGULAR_STEP`` times the one before.

        Of ``_across_hole``'s tests the one from three stamps (a frame lost or dropped before
        it, or one stamped early: ``_bat_off`` tells which); False with fewer than 3 frames.
        """
        times = self.bat.times
        return end >= 3 and times[end - 1] - times[end - 2] > REGULAR_STEP * (
            times[end - 2] - times[end - 3])

    def _off_line(self, end: int) -> bool:
        """
        Return whether bat frame end - 1 is off the line through the two frames before it.

        Knob or tip more than ``glitch_floor`` of the stream's noise (m) from where the step
        from frame end - 3 to end - 2, scaled by the ratio of their steps (s), carries frame
        end - 2: a screen no fit reads (a swing's own frames between the ball's forecasts land
        within it; a frame turned 10 cm or more off a slow bat does not). False with fewer
        than 3 frames; True where the two frames before are stamped alike.
        """
        times, values = self.bat.times, self.bat.values
        if end < 3:
            return False
        before = times[end - 2] - times[end - 3]
        if before <= 0.0:
            return True
        ratio = (times[end - 1] - times[end - 2]) / before
        oldest, middle, newest = values[end - 3], values[end - 2], values[end - 1]
        off = 0.0
        for (ax, ay, az), (bx, by, bz), c in ((oldest.knob, middle.knob, newest.knob),
                                              (oldest.tip, middle.tip, newest.tip)):
            off = max(off, math.dist(c, (bx + (bx - ax) * ratio, by + (by - ay) * ratio,
                                         bz + (bz - az) * ratio)))
        # (the least floor first: the stream's noise only where it may matter)
        return off > BAT_GLITCH_FLOOR and off > glitch_floor(stream_noise(self.bat, self._config))

    def _across_hole(self, j: int) -> bool:
        """
        Return whether bat frame j comes after a hole: frames lost (or dropped) right before it.

        Its step over ``REGULAR_STEP`` times the step before it and the median step of the
        frames before it in its forecast's window (``velocity_window`` back from it): not the
        frame after one stamped early (``BEFORE``'s case), whose step is long only beside it.
        """
        bat = self.bat
        times, start = bat.times, bat.history(bat.times[j], self._config.velocity_window)[0]
        if j - start < 3:
            return False
        step = times[j] - times[j - 1]
        return step > REGULAR_STEP * max(times[j - 1] - times[j - 2], median(
            [b - a for a, b in zip(times[start:j - 1], times[start + 1:j])]))

    def _followed(self, j: int) -> bool:
        """
        Return whether bat frame j + 1 goes on from frame j: on the forecast through it.

        Frame j + 1 within ``glitch_floor`` of the forecast of frame j's window (the frames
        ``_bat_off`` judged it with, ``velocity_window`` back from it) and frame j, extrapolated
        from frame j itself (``_bat_leaves``): a glitch puts that forecast about its own
        distance off the swing, a swing's own frame does not. The window is frame j's, so every
        forecast that judges it reads the same verdict.
        """
        bat = self.bat
        if j + 1 >= len(bat.times):
            return False
        start = bat.history(bat.times[j], self._config.velocity_window)[0]
        return not self._bat_leaves(start, j + 2)

    def _segment_start(self, first: int, end: int) -> bool:
        """
        Return whether bat frames [first, end) begin their segment, among regular steps.

        Frame ``first`` its segment's first (``bat_glitch_edges.segment_first``: the tracker
        re-acquired the bat), each step at most ``REGULAR_STEP`` times another: a window short
        for the segment's sake, not across frames lost.
        """
        times = self.bat.times
        steps = [b - a for a, b in zip(times[first:end - 1], times[first + 1:end])]
        return segment_first(self.bat, first, self._config.max_gap) and \
            max(steps) <= REGULAR_STEP * min(steps)

    def _bat_leaves(self, first: int, end: int) -> bool:
        """Return whether bat frame end - 1 left the forecast of frames [first, end - 1)."""
        return self._bat_miss(first, end) > glitch_floor(stream_noise(self.bat, self._config))

    def _bat_miss(self, first: int, end: int, without: Optional[int] = None) -> float:
        """
        Return how far (m) bat frame end - 1 is from the forecast of frames [first, end - 1).

        The larger of the knob's and the tip's distances; ``without``: the forecast of those
        frames but that one (``_bat_numbers``). 0 where the fit is rank deficient or would read
        fewer than 3 frames.
        """
        bat = self.bat
        if without is None:
            return newest_miss(bat.times, bat.values, bat.aligned.setdefault(STEP_ROWS, []),
                               first, end, min(self._config.velocity_degree, PREDICTION_DEGREE))
        if end - 2 - first < 3:
            return 0.0
        before = self._bat_numbers(first, end - 1, without)
        if before is None:
            return 0.0
        knob, tip = states_of(None, before, bat.times[end - 1])[2:]
        newest = bat.values[end - 1]
        return max(math.dist(knob, newest.knob), math.dist(tip, newest.tip))

    def _bat_numbers(self, first: int, end: int,
                     without: Optional[int] = None) -> Optional[Tuple[float, ...]]:
        """
        Return the bat forecast from frames [first, end), but frame ``without`` if given.

        As the kernel's 21 numbers (``prediction.bat_window_numbers``; the frames but one
        fitted from lists of their own, their steps made afresh); None: a rank-deficient fit.
        """
        bat = self.bat
        degree = min(self._config.velocity_degree, PREDICTION_DEGREE)
        if without is None:
            return bat_window_numbers(bat.times, bat.values, bat.aligned[STEP_ROWS], first, end,
                                      degree)
        kept = [i for i in range(first, end) if i != without]
        return bat_window_numbers([bat.times[i] for i in kept], [bat.values[i] for i in kept],
                                  [], 0, len(kept), degree)
