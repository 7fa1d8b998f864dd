"""
The fault plan of the fault-injection soak: the faults of issue 12 in turn, good pitches between.

Used by ``benchmarks/bench_faults.py`` (minutes, the figures) and by the short
``test/ros/test_faults_soak.py``. A :class:`FaultPlan` is a ``support.soak.Injector``: the soak
harness (``support/soak.py``) runs the real node process and publishes the simulated pitches at
the rate; the plan alters or adds to what it sends, phase after phase (fractions of the run):

* ``stale publisher``: a second publisher on the ball topic sends each ball sample again,
  stamped ``STALE_BEHIND_NS`` behind (a replay left running);
* ``glitches``: in every contact pitch the sample just before the contact (ball and bat in
  turn) is stamped ``GLITCHES_NS`` ahead (30 ms to 1 s, in turn): a lone stamp glitch;
* ``dead bat``: the bat stream is silent (a fifth of the run: 2 minutes of 10), the ball goes on;
* ``burst``: ``BURST_FRAMES`` frames sent as fast as they go (reliable, more than the queue
  depth of 1000), then the schedule goes on from there.

The pitches are ``PITCH_GAP_NS`` apart in stamps, more than ``LOSS_GAP_MAX_NS``: the gaps between
pitches are pauses, not losses, for the node's loss estimate, so every message it estimates lost
is one the plan can compare with the messages published and received. Contacts in the dead-bat
and burst phases (a pitch overlapping one) are excused: neither expected nor false when found;
contacts under the stale publisher and the glitches are expected.
"""

from collections import Counter, defaultdict
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Tuple

from baseball_collision.core.health import LOSS_GAP_MAX_NS
from geometry_msgs.msg import PointStamped, PoseStamped
import numpy as np
from rclpy.qos import QoSProfile
from support.soak import Injector, Pitch, Soak

PITCH_GAP_NS = LOSS_GAP_MAX_NS + 200_000_000
"""Stamp gap between consecutive pitches: a pause for the loss estimate."""

STALE_BEHIND_NS = 3_000_000_000
"""How far behind the stale second ball publisher stamps its messages."""

GLITCHES_NS = (30_000_000, 100_000_000, 300_000_000, 1_000_000_000)
"""How far ahead the lone glitched samples are stamped, in turn."""

BURST_FRAMES = 5000
"""Frames (ball and bat: twice as many messages) of the burst, ten times the queue depth."""

PHASES = (('good', 0.0), ('stale publisher', 0.1), ('good', 0.25), ('glitches', 0.3),
          ('good', 0.45), ('dead bat', 0.5), ('good', 0.7), ('burst', 0.8), ('good', None))
"""Each phase's name and start (a fraction of the run); the burst's end is its frames'."""

EXCUSED = ('dead bat', 'burst')
"""Phases whose contacts cannot be found (the bat is silent, messages are lost)."""

MISTIMED_NS = 50_000_000
"""An impact this near (``max_gap``) a contact is that contact, mistimed by samples lost around
it (the contact counts as lost when it was expected), not an invented impact."""


@dataclass
class PhaseFigures:
    """What one phase's /diagnostics said, summed over the statuses that arrived in it."""

    statuses: int = 0
    lost: int = 0
    resets: int = 0
    dropped: int = 0
    processing_max_ms: float = 0.0


class FaultPlan(Injector):
    """
    The faults of issue 12 in turn over a run of ``seconds`` at ``rate_hz`` (see the module).

    :ivar windows: each phase as ``(name, start s, end s)``.
    :ivar phase_of: each contact's phase (an index of ``windows``), by its stamp (ns).
    :ivar injected: what was injected: ``stale`` messages, ``glitches``, ``silenced`` bat
        messages, ``burst`` frames.
    :ivar figures: per phase (index), what the /diagnostics statuses said.
    """

    def __init__(self, seconds: float, rate_hz: float, burst_frames: int = BURST_FRAMES) -> None:
        self.windows: List[Tuple[str, float, float]] = []
        for (name, start), (_, following) in zip(PHASES, PHASES[1:] + (('', 1.0),)):
            begin = self.windows[-1][2] if start is None else seconds * start
            end = begin + burst_frames / rate_hz if name == 'burst' else seconds * following
            self.windows.append((name, begin, end))
        self.phase_of: Dict[int, int] = {}
        self.injected: Counter = Counter()
        self.figures: Dict[int, PhaseFigures] = defaultdict(PhaseFigures)
        self.now = 0
        self._stale_pub: Any = None
        self._stale_msg = PointStamped()

    def phase(self, seconds: float) -> int:
        """Return the index in ``windows`` of the phase running ``seconds`` into the run."""
        for index, (_, start, end) in enumerate(self.windows):
            if start <= seconds < end:
                return index
        return len(self.windows) - 1

    def attach(self, node: Any, profile: QoSProfile) -> None:
        """Create the stale second publisher on the ball topic."""
        self._stale_pub = node.create_publisher(PointStamped, 'ball', profile)

    def expects(self, start_s: float, end_s: float, contact_ns: int) -> bool:
        """Return False for a pitch overlapping a dead-bat or burst phase (its contact)."""
        overlapped = [index for index, (name, start, end) in enumerate(self.windows)
                      if start < end_s and start_s < end and name in EXCUSED]
        self.phase_of[contact_ns] = overlapped[0] if overlapped else self.phase(start_s)
        return not overlapped

    def paced(self, seconds: float) -> bool:
        """Return False in the burst."""
        return self.windows[self.phase(seconds)][0] != 'burst'

    def frame(self, seconds: float, stamp_ns: int, pitch: Pitch, k: int, ball: PointStamped,
              bat: PoseStamped) -> Tuple[bool, bool, Counter]:
        """Inject the fault of the phase at ``seconds`` into (or beside) one frame."""
        self.now = self.phase(seconds)
        phase = self.windows[self.now][0]
        if phase == 'stale publisher':
            stale = self._stale_msg
            stale.header.frame_id, stale.point = ball.header.frame_id, ball.point
            sec, nanosec = divmod(stamp_ns - STALE_BEHIND_NS, 10**9)
            stale.header.stamp.sec, stale.header.stamp.nanosec = sec, nanosec
            self._stale_pub.publish(stale)
            self.injected['stale'] += 1
            return True, True, Counter(ball=1)
        if phase == 'glitches' and pitch.contact_ns is not None and \
                k + 1 == int(np.searchsorted(pitch.stamps, pitch.contact_ns)):
            count = self.injected['glitches']
            message = ball if count % 2 == 0 else bat
            sec, nanosec = divmod(stamp_ns + GLITCHES_NS[count // 2 % len(GLITCHES_NS)], 10**9)
            message.header.stamp.sec, message.header.stamp.nanosec = sec, nanosec
            self.injected['glitches'] += 1
        elif phase == 'dead bat':
            self.injected['silenced'] += 1
            return True, False, Counter()
        elif phase == 'burst':
            self.injected['burst'] += 1
        return True, True, Counter()

    def status(self, values: Dict[str, str]) -> None:
        """Add one /diagnostics status to the figures of the phase running."""
        figures = self.figures[self.now]
        figures.statuses += 1
        figures.lost += int(values.get('lost_in_period', 0))
        figures.resets += int(values.get('resets_in_period', 0))
        figures.dropped += int(values.get('dropped_in_period', 0))
        figures.processing_max_ms = max(figures.processing_max_ms,
                                        float(values.get('processing_max_ms', 0.0)))


@dataclass(frozen=True)
class Losses:
    """
    Messages lost on the way to the node, and what its /diagnostics said about them.

    :ivar published, received, estimated: per stream: sent, the node's ``<stream>_received``
        and ``<stream>_lost`` (from the publishers' sequence numbers, and stamps) in its last
        status.
    :ivar stale_lost: messages of the stale publisher lost (sent, less those the node
        dropped as ``stale_stamp``): included in ``lost`` (its sequence numbers show them).
    """

    published: Dict[str, int]
    received: Dict[str, int]
    estimated: Dict[str, int]
    stale_lost: int = 0

    @property
    def lost(self) -> int:
        """Return the messages published and never received, all streams."""
        return sum(self.published[s] - self.received.get(s, 0) for s in self.published)

    @property
    def reported(self) -> int:
        """Return the messages the node's diagnostics estimated lost, all streams."""
        return sum(self.estimated.values())


def losses(soak: Soak, plan: FaultPlan) -> Losses:
    """Return the losses of a run from its last /diagnostics status (after the publishing)."""
    last = soak.diagnostics[-1] if soak.diagnostics else {}
    streams = sorted(soak.published_by)
    return Losses(published={s: soak.published_by[s] for s in streams},
                  received={s: int(last.get(f'{s}_received', 0)) for s in streams},
                  estimated={s: int(last.get(f'{s}_lost', 0)) for s in streams},
                  stale_lost=plan.injected['stale'] - int(last.get('dropped_stale_stamp', 0)))


def false_impacts(soak: Soak, plan: FaultPlan,
                  tolerance_ns: int = 100_000) -> Tuple[List[int], List[int]]:
    """
    Return the impacts (ns) matching no contact within the tolerance: (false, mistimed).

    Mistimed: within ``MISTIMED_NS`` of a contact but not ``tolerance_ns`` (samples around it
    were lost); false: no contact that near (an invented impact) or a second impact within
    ``tolerance_ns`` of a contact another impact matched (a duplicate).
    """
    contacts = np.asarray(sorted(plan.phase_of), dtype=np.int64)
    false, mistimed = [], []
    for stamp in soak.false:
        near = _nearest(contacts, stamp)
        off = abs(near - stamp) if near is not None else MISTIMED_NS + 1
        (mistimed if tolerance_ns < off <= MISTIMED_NS else false).append(stamp)
    return false, mistimed


def phase_table(soak: Soak, plan: FaultPlan) -> List[str]:
    """Return one line per phase: time, contacts found / expected, diagnostics, the RSS."""
    lost, found_excused = set(soak.lost), set(soak.excused_found)
    known = set(soak.expected) | set(soak.excused)
    lines = []
    for index, (name, start, end) in enumerate(plan.windows):
        contacts = [t for t, phase in plan.phase_of.items() if phase == index and t in known]
        excused = name in EXCUSED
        found = sum(1 for t in contacts if (t in found_excused if excused else t not in lost))
        figures = plan.figures.get(index, PhaseFigures())
        rss = [kb for at, kb in soak.rss_kb if at <= end]
        lines.append(
            f'  {start:7.1f}-{end:7.1f} s  {name:<16} contacts {found:3d}/{len(contacts):<3d}'
            f"{' (excused)' if excused else '          '}  /diagnostics: lost "
            f'{figures.lost}, resets {figures.resets}, dropped {figures.dropped}, '
            f'processing max {figures.processing_max_ms:.2f} ms; node RSS at the end '
            f'{rss[-1] / 1024 if rss else float("nan"):.1f} MB')
    return lines


def misses(soak: Soak, plan: FaultPlan, tolerance_ns: int = 100_000) -> List[str]:
    """Return one line per contact lost and per false impact: its phase, the nearest other."""
    truths = np.asarray(sorted(plan.phase_of), dtype=np.int64)
    got = np.asarray(sorted(stamp for stamp, _ in soak.impacts), dtype=np.int64)
    lines = []
    false, mistimed = false_impacts(soak, plan, tolerance_ns)
    listed = (('false impact', false, truths), ('mistimed impact', mistimed, truths),
              ('lost contact', soak.lost, got))
    for what, stamps, others in listed:
        for stamp in stamps:
            nearest = _nearest(others, stamp)
            near = truths[np.argmin(np.abs(truths - stamp))] if len(truths) else stamp
            name, start, _ = plan.windows[plan.phase_of.get(int(near), 0)]
            lines.append(f'  {what} {stamp} in {name} (from {start:.1f} s): nearest '
                         f"{'impact' if others is got else 'contact'} "
                         f"{'none' if nearest is None else f'{(nearest - stamp) * 1e-3:+.1f} us'}")
    return lines


def _nearest(stamps: np.ndarray, stamp: int) -> Optional[int]:
    """Return the stamp of ``stamps`` nearest ``stamp`` (None if there is none)."""
    if not len(stamps):
        return None
    return int(stamps[np.argmin(np.abs(stamps - stamp))])
