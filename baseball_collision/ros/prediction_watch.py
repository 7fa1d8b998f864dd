"""
When a predicted impact has passed without its contact: the rule behind ``~/impact_predicted``.

The detector clears a prediction only at its next frame that predicts, so when the frames stop
short of the instant (the tracker lost the ball) or run past it without a contact, the node
itself must turn the flag false. :class:`PredictionWatch` keeps what that takes from the
accepted messages, in plain Python (no rclpy: the node calls it under its lock), and says when:

* every input stream has taken two samples more than ``max_gap`` past the predicted instant.
  Every stream, because one stream's stamps say nothing of another's: a ball tracker whose
  messages come 60-100 ms after the bat's (a camera beside mocap) still brings the contact after
  the bat passed the instant (a rule on one stream alone withdrew the flag before that
  ``~/impact``, and the late ball's next prediction raised it again). The second sample,
  because a lone stamp glitched ahead waits for the next one (``stamp_ahead``) and is no proof;
* or the bat streams have, and the ball has been silent longer than its own lag behind the bat
  plus ``max_gap``: a ball lost for good (its tracker lost it, the bat streaming on) is told
  from a late one by that silence. Its lag: how much later than the bat's newest message of the
  same stamp each of its last ``BALL_LAGS`` messages was taken (arrival less stamp, less the
  bat's; the clocks' difference cancels), the largest, so a camera's bursts are in it. But not
  while the flight before the silence still holds: until the bat streams took two samples
  more than the flight's span (``predictor.kept_flight_span`` of ``prediction_window``, 0.215 s
  by default) past the ball's newest stamp, and the ball has been silent that long since its
  last arrival (its lag behind the bat in it), a pitch unseen since may have drifted from the
  forecast of its samples before by less than its radius, and a tracker that paused that long
  and catches up still brings the contact (a silence of its lag plus ``max_gap`` withdrew the
  flag before 109-135 of 864 paused hits' contacts a cell, ``bench_prediction.py --faults``; 0
  now), at the cost of a ball lost for good's flag going off 202-214 ms after the instant
  (p50), not 78-89: after the instant + ``max_gap`` either way.
  ``analyze --predict``, on the stamps, ends the prediction in force across a ball gap by the
  same rule (``tools.truth.silence_clearings``; the detector's own frames wait for the ball's
  next sample, then clear or replace it).

A ball that was only paused (its tracker caught up, its samples flushed after the flag went
false for its silence) brings predictions made before the instant withdrawn: each turned the
flag on again, and the contact off (a flip). So after such a withdrawal, until the ball's
samples pass that instant + ``max_gap``, a prediction of an instant the bat streams have
passed as far does not turn it on (:meth:`PredictionWatch.raises`); one still ahead of the bat
does.

A stream silent beyond ``stale_timeout`` is the node's own check (its input tally).
"""

from collections import deque
import math
from typing import Deque, Dict, Mapping, Optional, Sequence

BALL = 'ball'
"""The ball's stream name; every other stream is the bat's (its pose, or knob and tip)."""

BALL_LAGS = 256
"""Accepted ball messages whose lag behind the bat's is kept: the largest of them is the ball's
lag (a camera's bursts included), about 0.7-2.8 s of messages at 90-360 Hz."""


class PredictionWatch:
    """The streams' stamps and arrivals that tell a passed prediction (see the module)."""

    __slots__ = ('streams', 'instant_ns', 'before_newest', 'silenced_ns', '_offsets',
                 '_ball_lags', 'ball_newest_ns')

    def __init__(self, streams: Sequence[str]) -> None:
        """Watch ``streams``: the node's input stream names (``BALL`` and the bat's)."""
        self.streams = tuple(streams)
        self.instant_ns = 0  # the instant (ns) of the prediction in force
        self.before_newest: Dict[str, int] = {}  # each stream's sample before its newest (ns)
        self.ball_newest_ns: Optional[int] = None  # the ball's newest accepted stamp (ns)
        # a prediction withdrawn for the ball's silence: its instant + max_gap (ns), until the
        # ball's samples pass it (``raises``)
        self.silenced_ns: Optional[int] = None
        # each stream's newest accepted message: its arrival less its stamp (s), and the last
        # ``BALL_LAGS`` ball messages' lags behind the bat's (s)
        self._offsets: Dict[str, float] = {}
        self._ball_lags: Deque[float] = deque(maxlen=BALL_LAGS)

    def accepted(self, stream: str, stamp_ns: int, previous_ns: Optional[int],
                 arrival: float) -> None:
        """
        Note a message the detector accepted.

        :param stamp_ns: its stamp (ns).
        :param previous_ns: the stamp (ns) of the stream's message accepted before it (None: its
            first).
        :param arrival: when it was taken (s, the steady clock ``passed`` is given).
        """
        if previous_ns is not None:
            self.before_newest[stream] = previous_ns
        offsets = self._offsets
        offset = offsets[stream] = arrival - stamp_ns * 1e-9
        if stream == BALL:
            self.ball_newest_ns = stamp_ns
            bats = [offsets[each] for each in self.streams if each != BALL and each in offsets]
            if bats:
                self._ball_lags.append(offset - min(bats))

    def passed(self, now: float, last_arrival: Mapping[str, float], max_gap: float,
               flight_span: float) -> bool:
        """
        Return whether the prediction at ``instant_ns`` has passed without its contact at ``now``.

        Passed for the ball's silence (``ball_lost``, and the flight's span past the ball's
        newest stamp on the bat streams' stamps and past its last arrival: a tracker that lags
        the bat brings the samples of that span that much later), that instant + ``max_gap``
        is kept (``silenced_ns``: see ``raises``).

        :param now: the steady-clock time (s).
        :param last_arrival: each stream's last arrival (s, the same clock; a stream missing
            has sent nothing).
        :param max_gap: the detector's ``max_gap`` (s; a threshold that may change at runtime).
        :param flight_span: how long (s) the ball's flight holds unseen after its newest sample
            (``predictor.kept_flight_span`` of ``prediction_window``; may change at runtime).
        """
        passed = self.instant_ns + round(max_gap * 1e9)
        if not self._bat_passed(passed):
            return False
        if self.before_newest.get(BALL, passed) > passed:
            return True
        if not self.ball_lost(now, last_arrival, max_gap):
            return False
        if now - last_arrival.get(BALL, -math.inf) <= flight_span or (
                self.ball_newest_ns is not None and not self._bat_passed(
                    self.ball_newest_ns + round(flight_span * 1e9))):
            return False  # (the flight before the silence still holds)
        self.silenced_ns = passed
        return True

    def raises(self, instant_ns: int, max_gap: float) -> bool:
        """
        Return whether a prediction of ``instant_ns`` may turn the flag on.

        Not where a prediction was withdrawn for the ball's silence (``silenced_ns``) that the
        ball's samples have not passed yet (its tracker paused and flushed its samples since:
        their predictions came after the bat) and the bat streams took two samples more than
        ``max_gap`` (s) past this instant too (one still ahead of the bat may).
        """
        silenced = self.silenced_ns
        if silenced is None:
            return True
        if self.before_newest.get(BALL, silenced) > silenced:
            self.silenced_ns = None  # (the ball is back past it)
            return True
        return not self._bat_passed(instant_ns + round(max_gap * 1e9))

    def _bat_passed(self, stamp_ns: int) -> bool:
        """Return whether every bat stream's sample before its newest is after a stamp (ns)."""
        newest = self.before_newest
        return all(newest.get(stream, stamp_ns) > stamp_ns for stream in self.streams
                   if stream != BALL)

    def ball_lost(self, now: float, last_arrival: Mapping[str, float], max_gap: float) -> bool:
        """
        Return whether the ball has been silent longer than its lag behind the bat + ``max_gap``.

        Its lag: the largest of its last ``BALL_LAGS`` messages' (none below 0). A ball tracker
        60-100 ms behind the bat still streams within that; one that lost the ball has sent
        nothing since.
        """
        lag = max(max(self._ball_lags, default=0.0), 0.0)
        return now - last_arrival.get(BALL, -math.inf) > lag + max_gap

    def clear(self) -> None:
        """Forget the streams (after a state reset); the instant stays until the next one."""
        self.before_newest.clear()
        self.ball_newest_ns = self.silenced_ns = None
        self._offsets.clear()
        self._ball_lags.clear()
