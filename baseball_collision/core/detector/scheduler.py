"""
The walk over the union of the ball's and the bat's sample times, up to the watermark.

Between two consecutive union times every stream is inside one of its own sample intervals, so
each body's motion model gives its path exactly by stamps, whatever the rates, jitter or uneven
steps. The walk stops at the watermark: the oldest of the streams' newest usable times (a model
that needs samples after an interval, the spline, waits for them until the recording ends), or
before an interval the sweep says waits for more samples (a ball segment's first samples near
the bat: ``Sweep.interval``).
"""

from bisect import bisect_right
import math
from typing import Callable, List, Optional

from .config import DetectorConfig
from .streams import Stream
from ..motion import samples_ahead

Visit = Callable[[float, float, List], Optional[bool]]
"""Called with each union interval (ta, tb) in seconds, and the event list to append to;
False: the interval waits for more samples (``Sweep.interval``), and the walk stops before
it."""


class Scheduler:
    """
    The cursor (s): everything up to it has been processed.

    :param config: the detector's configuration (``DetectorConfig``): its model says how many
        samples after an interval's end the walk waits for (``SAMPLES_AHEAD``); its fit windows
        how far back from the cursor the streams keep samples.
    :param ball, bat: the two streams walked.
    """

    __slots__ = ('config', 'ball', 'bat', 'ahead', 'cursor')

    def __init__(self, config: DetectorConfig, ball: Stream, bat: Stream) -> None:
        self.config, self.ball, self.bat = config, ball, bat
        self.ahead = samples_ahead(config.model, config.look_ahead)
        self.cursor: Optional[float] = None

    def advance(self, visit: Visit, events: List, final: bool = False) -> bool:
        """
        Visit every union interval in (cursor, watermark], then trim the streams.

        A visit may forget samples (a glitch: ``Stream.remove``); the walk then goes on from
        the interval's end in the streams as they are.

        :param visit: called with each interval in order, up to one that waits (``Visit``).
        :param final: the recording ended: every sample is usable.
        :returns: whether the cursor moved.
        """
        ball_times, bat_times = self.ball.times, self.bat.times
        ahead = 0 if final else self.ahead
        if len(ball_times) <= ahead or len(bat_times) <= ahead:
            self.trim()
            return False
        ready_ball, ready_bat = ball_times[-1 - ahead], bat_times[-1 - ahead]
        watermark = ready_ball if ready_ball < ready_bat else ready_bat
        cursor = self.cursor
        if cursor is None:
            cursor = self.cursor = max(ball_times[0], bat_times[0])
        if watermark <= cursor:
            self.trim()
            return False
        i = bisect_right(ball_times, cursor)
        j = bisect_right(bat_times, cursor)
        while True:
            a = ball_times[i] if i < len(ball_times) else math.inf
            b = bat_times[j] if j < len(bat_times) else math.inf
            t = a if a < b else b
            if t > watermark:
                break
            if a == t:
                i += 1
            if b == t:
                j += 1
            sizes = len(ball_times), len(bat_times)
            if visit(cursor, t, events) is False:
                break  # (visited again from the cursor by the next advance)
            if sizes != (len(ball_times), len(bat_times)) or (i and ball_times[i - 1] > t):
                # the visit forgot a glitch (``Stream.remove``; a sample set aside may have
                # been put back in its place: ``Stream.insert``): the indices moved
                i, j = bisect_right(ball_times, t), bisect_right(bat_times, t)
            cursor = t
        moved = cursor != self.cursor
        self.cursor = cursor
        self.trim()
        return moved

    def trim(self) -> None:
        """
        Forget samples no fit or interval needs any more (``Stream.trim_beside``).

        Behind the cursor by the fits' history; a stream beside a silent one by its own, so a
        dead tracker grows neither memory nor the cost of a sample.
        """
        ball, bat = self.ball, self.bat
        if len(ball.times) < 64 and len(bat.times) < 64:
            return  # (Stream.trim_beside would return at once)
        config = self.config  # how far back (s) the fits need samples
        history = 1.5 * max(config.velocity_window, config.prediction_window)
        ball.trim_beside(bat, self.cursor, history)
        bat.trim_beside(ball, self.cursor, history)
