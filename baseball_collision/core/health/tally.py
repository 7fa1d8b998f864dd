"""
What the node counts for its diagnostics: arrivals, callback times per period, messages lost.

Pure Python (no ROS): the node counts each message into a :class:`Tally`; once a period
``core.health.status.take_snapshot`` copies it. Times are seconds on any monotonic clock.
"""

from collections import Counter
from dataclasses import dataclass, field
from typing import Dict, Optional

from .gaps import PublisherGaps, StampGaps


@dataclass
class Period:
    """
    Counters at the start of a diagnostics period, and the callback times inside it.

    :ivar start: monotonic s the period started.
    :ivar arrivals: messages received per stream since start-up, when it started.
    :ivar dropped: samples dropped since start-up, when it started.
    :ivar count, total_s, max_s: message callbacks in the period and their wall times (s).
    :ivar resets: the detector's state resets since start-up, when it started.
    :ivar failures: the node's own failures since start-up, when it started (``Tally``).
    :ivar lost: messages estimated lost per stream since start-up, when it started.
    """

    start: float
    arrivals: Counter
    dropped: int
    resets: int = 0
    lost: Counter = field(default_factory=Counter)
    failures: int = 0
    count: int = 0
    total_s: float = 0.0
    max_s: float = 0.0

    def record(self, elapsed_s: float) -> None:
        """Account the wall time (s) one message took in its callback."""
        self.count += 1
        self.total_s += elapsed_s
        if elapsed_s > self.max_s:
            self.max_s = elapsed_s


@dataclass
class Tally:
    """
    What the node counts for its diagnostics (times: monotonic s).

    :ivar started: when the node started.
    :ivar arrivals: messages received per stream since start-up.
    :ivar last_arrival: when each stream last received a message.
    :ivar period: the diagnostics period running.
    :ivar incompatible: QoS or type incompatibilities seen; ``incompatible_reported``: as many
        as the last status reported.
    :ivar last_impact_ns: the stamp of the last impact published.
    :ivar failures: the package's own failures (bugs: an exception out of its code) the node
        logged and went on after since start-up.
    :ivar gaps: each stream's :class:`StampGaps` (messages estimated lost from the stamps of
        messages without a sequence number).
    :ivar publishers: each stream's :class:`PublisherGaps` (messages lost, from the
        publishers' sequence numbers and stamps).
    """

    started: float
    arrivals: Counter = field(default_factory=Counter)
    last_arrival: Dict[str, float] = field(default_factory=dict)
    period: Optional[Period] = None
    incompatible: int = 0
    incompatible_reported: int = 0
    last_impact_ns: Optional[int] = None
    failures: int = 0
    gaps: Dict[str, StampGaps] = field(default_factory=dict)
    publishers: Dict[str, PublisherGaps] = field(default_factory=dict)

    def __post_init__(self) -> None:
        """Start the first period at start-up."""
        if self.period is None:
            self.period = Period(self.started, Counter(), 0)

    def arrived(self, stream: str, now: float) -> None:
        """Count a message on ``stream`` received at ``now``."""
        self.arrivals[stream] += 1
        self.last_arrival[stream] = now

    def stamped(self, stream: str, stamp_ns: int, sequence: Optional[int] = None,
                sent_ns: Optional[int] = None) -> None:
        """
        Take a message's header stamp (ns) on ``stream``, for the loss estimate.

        :param sequence: its publication sequence number when the RMW gives one (exact
            per-publisher accounting, :class:`PublisherGaps`); None: the stamps alone
            (:class:`StampGaps`).
        :param sent_ns: its writer's send time (ns) when the RMW gives it: it tells the
            publishers apart (:class:`PublisherGaps`).
        """
        if sequence is not None:
            publishers = self.publishers.get(stream)
            if publishers is None:
                publishers = self.publishers[stream] = PublisherGaps()
            publishers.take(sequence, stamp_ns, sent_ns)
            return
        gaps = self.gaps.get(stream)
        if gaps is None:
            gaps = self.gaps[stream] = StampGaps()
        gaps.take(stamp_ns)

    def lost(self) -> Counter:
        """Return the messages estimated lost per stream since start-up."""
        lost = Counter({stream: gaps.lost for stream, gaps in self.gaps.items()})
        lost.update({stream: each.lost for stream, each in self.publishers.items()})
        return lost

    def next_period(self, now: float, dropped: int, resets: int = 0) -> Period:
        """
        Start a new period at ``now``; return the one that ends.

        :param dropped: samples dropped since start-up, now; ``resets``: state resets.
        """
        ended, self.period = self.period, Period(now, Counter(self.arrivals), dropped, resets,
                                                 self.lost(), failures=self.failures)
        return ended
