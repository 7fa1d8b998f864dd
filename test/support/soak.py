"""
The soak harness: impact_node at a high rate for a while; memory, processing, backlog, truth.

Used by ``test/ros/test_soak.py`` (a short run, functional assertions) and by
``benchmarks/bench_soak.py`` (minutes, the figures). Run as a script with ``--serve`` it is
the node process.

Two processes. A child (this file with ``--serve``) runs ``ImpactNode`` with its default
parameters (rigid model, markers on) plus one hook: every message callback's wall time goes
into a fixed 1 us histogram (constant memory, so it cannot hide a leak); its RSS is read from
``/proc/<pid>/status`` every half second. This process publishes the ball (PointStamped) and
the bat (PoseStamped) at the rate per stream, paced on the monotonic clock, and listens to
``~/impact`` and ``/diagnostics``.

The stream is a sequence of simulated pitches (``make_scenario`` of every kind, 0.25 s each,
sampled by ``sample`` at the rate), cycled and shifted in time: consecutive pitches are 0.1 s
apart in stamps (more than ``max_gap``: each pitch is a new segment) while the messages keep
flowing at the rate. Truth: each contact pitch's exact first contact, shifted like its samples.

Figures:

* memory: the node's RSS when publishing starts, at the end, the largest sample and VmHWM;
* processing: p50 / p99 / p99.9 / max of the callback wall time (conversion, detector,
  publishing), and the largest ``processing_max_ms`` of the /diagnostics periods;
* backlog: messages received by the node (its own counters) against published; per impact,
  the latency from the publish of the sample that completes the interval holding it to the
  reception of ``~/impact``, first tenth of the run against the last; the most samples ever
  published beyond the node's ``watermark_stamp`` when a /diagnostics status arrived;
* truth: impacts expected, received, matched (within ``tolerance_us``), lost and false.
"""

import bisect
from collections import Counter
from dataclasses import dataclass, field
import json
import math
import os
from pathlib import Path
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from typing import Any, Dict, List, Optional, Sequence, Tuple

from baseball_collision.ros.node import ImpactNode
from baseball_collision.tools.sim import DEFAULT_START_NS, KINDS, make_scenario, sample
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PointStamped, PoseStamped
import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions

PITCH_GAP_NS = 100_000_000
"""Stamp gap between consecutive pitches (s): longer than max_gap, so each is a new segment."""

HISTOGRAM_BINS = 100_000
"""Callback-time histogram: 1 us bins up to 100 ms (the last bin holds everything longer)."""

SCENARIOS = 48
"""Distinct simulated pitches, cycled (eight of every kind)."""


# ----------------------------------------------------------------------------------------------
# the node process


class SoakNode(ImpactNode):
    """ImpactNode whose message callback times go into a fixed-size histogram (1 us bins)."""

    def __init__(self) -> None:
        self.histogram = np.zeros(HISTOGRAM_BINS, dtype=np.int64)
        self.slowest = 0.0
        super().__init__()

    def _record_processing(self, elapsed_s: float) -> None:
        self.histogram[min(int(elapsed_s * 1e6), HISTOGRAM_BINS - 1)] += 1
        if elapsed_s > self.slowest:
            self.slowest = elapsed_s
        super()._record_processing(elapsed_s)


def histogram_percentiles(histogram: np.ndarray, slowest_s: float) -> Dict[str, float]:
    """Return count, p50, p99, p99.9 (upper bin edges, ms) and max (ms) of a 1 us histogram."""
    count = int(histogram.sum())
    if count == 0:
        return {'count': 0, 'p50': math.nan, 'p99': math.nan, 'p999': math.nan,
                'max': math.nan}
    cumulative = np.cumsum(histogram)

    def at(q: float) -> float:
        return (int(np.searchsorted(cumulative, q * count)) + 1) * 1e-3
    return {'count': count, 'p50': at(0.5), 'p99': at(0.99), 'p999': at(0.999),
            'max': slowest_s * 1e3}


def serve() -> int:
    """
    Run the node until SIGINT; print its processing histogram figures and counters (JSON).

    SIGINT only sets a flag the spin loop checks: a KeyboardInterrupt raised while rclpy
    converted a message came out as pybind's RuntimeError ("Unable to convert call argument")
    when the node was always busy (a loaded machine, a full queue), and no figures printed.
    """
    rclpy.init(args=sys.argv, signal_handler_options=SignalHandlerOptions.NO)
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    node = SoakNode()
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.1)
    except ExternalShutdownException:
        pass
    stats = node.detector.stats
    figures = histogram_percentiles(node.histogram, node.slowest)
    figures.update(received=dict(node.tally.arrivals), impacts=stats.impacts,
                   dropped=dict(stats.dropped), resets=stats.resets, gaps=stats.gaps,
                   lost=dict(node.tally.lost()))
    print(json.dumps(figures), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


# ----------------------------------------------------------------------------------------------
# the stream and its truth


@dataclass
class Pitch:
    """One simulated pitch sampled at the rate: relative stamps (ns), values, truth (ns)."""

    stamps: np.ndarray
    balls: np.ndarray
    positions: np.ndarray
    quaternions: np.ndarray
    contact_ns: Optional[int]
    span_ns: int


def make_pitches(rate_hz: float, seed: int, count: int = SCENARIOS,
                 gap_ns: int = PITCH_GAP_NS) -> List[Pitch]:
    """Return ``count`` pitches of every kind, ``gap_ns`` apart (stamps relative to each start)."""
    rng = np.random.default_rng(seed)
    pitches = []
    for index in range(count):
        scenario = make_scenario(KINDS[index % len(KINDS)], rng)
        samples = sample(scenario, rate_hz, rng, start_ns=0)
        assert np.array_equal(samples.ball_stamps_ns, samples.bat_stamps_ns)
        truth = scenario.truth
        pitches.append(Pitch(
            stamps=samples.ball_stamps_ns.astype(np.int64), balls=samples.ball_positions,
            positions=samples.bat_positions, quaternions=samples.bat_quaternions,
            contact_ns=int(round(truth.time_s * 1e9)) if truth.contact else None,
            span_ns=int(samples.ball_stamps_ns[-1]) + gap_ns))
    return pitches


class Injector:
    """
    What a run sends besides its plain frames: the base sends nothing else (a plain soak).

    ``support/faults.py`` derives the fault plan of ``benchmarks/bench_faults.py`` from it.
    Times ``seconds`` are the frame's scheduled time into the run (frame / rate).
    """

    def attach(self, node: Any, profile: QoSProfile) -> None:
        """Create any extra publishers on the publishing ``node`` (inputs' ``profile``)."""

    def expects(self, start_s: float, end_s: float, contact_ns: int) -> bool:
        """Return whether the contact (ns) of a pitch sent from ``start_s`` to ``end_s`` counts."""
        return True

    def paced(self, seconds: float) -> bool:
        """Return whether the frame at ``seconds`` waits for its time (False: a burst)."""
        return True

    def frame(self, seconds: float, stamp_ns: int, pitch: Pitch, k: int, ball: PointStamped,
              bat: PoseStamped) -> Tuple[bool, bool, Counter]:
        """
        Alter frame ``k`` of ``pitch`` (messages filled in, stamped ``stamp_ns``) or add to it.

        :returns: whether to send the ball and the bat message, and the extra messages this
            published, per stream.
        """
        return True, True, Counter()

    def status(self, values: Dict[str, str]) -> None:
        """Take one /diagnostics status of the node (its key/values) as it arrives."""


@dataclass
class Soak:
    """Everything one soak run measured (see the module docstring)."""

    seconds: float
    rate_hz: float
    qos: str
    published: int = 0
    published_by: Counter = field(default_factory=Counter)
    frames: int = 0
    pitches: int = 0
    lateness_max_ms: float = 0.0
    rss_kb: List[Tuple[float, int]] = field(default_factory=list)
    hwm_kb: int = 0
    node: Dict[str, Any] = field(default_factory=dict)
    diagnostics: List[Dict[str, str]] = field(default_factory=list)
    watermark_lag_max: int = 0
    impacts: List[Tuple[int, int]] = field(default_factory=list)
    expected: List[int] = field(default_factory=list)
    excused: List[int] = field(default_factory=list)
    excused_found: List[int] = field(default_factory=list)
    latencies_ms: List[float] = field(default_factory=list)
    matched_error_us_max: float = 0.0
    lost: List[int] = field(default_factory=list)
    false: List[int] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)

    @property
    def rss_start_mb(self) -> float:
        """Return the node's RSS (MB) when publishing started."""
        return self.rss_kb[0][1] / 1024.0

    @property
    def rss_end_mb(self) -> float:
        """Return the node's RSS (MB) at the end of publishing."""
        return self.rss_kb[-1][1] / 1024.0

    @property
    def rss_max_mb(self) -> float:
        """Return the largest RSS sample (MB)."""
        return max(kb for _, kb in self.rss_kb) / 1024.0

    @property
    def growth_mb(self) -> float:
        """Return RSS end - start (MB)."""
        return self.rss_end_mb - self.rss_start_mb

    def latency_tenths(self) -> Tuple[float, float]:
        """Return the median latency (ms) of the first and of the last tenth of the impacts."""
        values = self.latencies_ms
        tenth = max(1, len(values) // 10)
        return float(np.median(values[:tenth])), float(np.median(values[-tenth:]))

    def report(self) -> str:
        """Return the figures as text."""
        processing = self.node
        first, last = self.latency_tenths() if self.latencies_ms else (math.nan, math.nan)
        received = sum(self.node.get('received', {}).values())
        diag_max = max((float(d['processing_max_ms']) for d in self.diagnostics), default=0.0)
        lat = np.asarray(self.latencies_ms) if self.latencies_ms else np.array([math.nan])
        return '\n'.join([
            f'impact_node soak: {self.seconds:.0f} s at {self.rate_hz:.0f} Hz per stream '
            f'(ball PointStamped + bat PoseStamped), qos {self.qos}, model rigid, markers on; '
            f'{self.pitches} pitches, {self.frames} frames',
            f'  memory (node RSS): start {self.rss_start_mb:.1f} MB, end {self.rss_end_mb:.1f}'
            f' MB, max {self.rss_max_mb:.1f} MB (VmHWM {self.hwm_kb / 1024.0:.1f} MB); growth '
            f'{self.growth_mb:+.2f} MB',
            f"  processing per message ({processing.get('count', 0)} callbacks): "
            f"p50 {processing.get('p50', math.nan):.3f} ms, p99 "
            f"{processing.get('p99', math.nan):.3f} ms, p99.9 "
            f"{processing.get('p999', math.nan):.3f} ms, max "
            f"{processing.get('max', math.nan):.2f} ms; /diagnostics processing_max_ms "
            f'largest {diag_max:.2f} ms',
            f'  backlog: published {self.published}, received by the node {received}; '
            f'most samples past the watermark at a /diagnostics: {self.watermark_lag_max}; '
            f'publisher late by at most {self.lateness_max_ms:.1f} ms',
            f'  impact latency (completing publish -> ~/impact received, {len(self.latencies_ms)}'
            f' impacts): median {np.nanmedian(lat):.2f} ms, p99 '
            f'{np.nanpercentile(lat, 99):.2f} ms, max {np.nanmax(lat):.2f} ms; median first '
            f'tenth {first:.2f} ms, last tenth {last:.2f} ms',
            f'  truth: {len(self.expected)} impacts expected, {len(self.impacts)} received, '
            f'{len(self.expected) - len(self.lost)} matched (largest error '
            f'{self.matched_error_us_max:.1f} us), {len(self.lost)} lost, {len(self.false)} '
            f"false; node: {processing.get('impacts')} impacts, dropped "
            f"{processing.get('dropped')}, {processing.get('gaps')} gaps, "
            f"{processing.get('resets')} resets; {len(self.warnings)} warnings logged"])


# ----------------------------------------------------------------------------------------------
# the run


def _rss_kb(pid: int) -> Tuple[int, int]:
    """Return (VmRSS, VmHWM) of a process in kB."""
    values = {}
    for line in Path(f'/proc/{pid}/status').read_text().splitlines():
        key, _, rest = line.partition(':')
        if key in ('VmRSS', 'VmHWM'):
            values[key] = int(rest.split()[0])
    return values['VmRSS'], values['VmHWM']


def _environment() -> Dict[str, str]:
    """Return the environment for both processes: one random domain, host-only discovery."""
    os.environ.pop('RMW_IMPLEMENTATION', None)
    os.environ.setdefault('ROS_DOMAIN_ID', str(random.SystemRandom().randint(1, 101)))
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    env = dict(os.environ)
    env['PYTHONUNBUFFERED'] = '1'
    return env


def run_soak(seconds: float, rate_hz: float = 1000.0, qos: str = 'reliable', seed: int = 7,
             tolerance_us: float = 100.0, progress: bool = False,
             injector: Optional[Injector] = None, gap_ns: int = PITCH_GAP_NS) -> Soak:
    """
    Run the node and publish for ``seconds``; return what was measured.

    :param injector: faults to inject (none by default); ``gap_ns``: the stamp gap between
        pitches. Contacts the injector excuses are in ``Soak.excused``: neither expected nor,
        when found, false.

    :raises RuntimeError: the node did not come up or did not stop.
    """
    env = _environment()
    pitches = make_pitches(rate_hz, seed, gap_ns=gap_ns)
    injector = injector or Injector()
    soak = Soak(seconds=seconds, rate_hz=rate_hz, qos=qos)
    log = tempfile.NamedTemporaryFile('w+', prefix='soak_node_', suffix='.log', delete=False)
    child = subprocess.Popen(
        [sys.executable, __file__, '--serve', '--ros-args', '-p', f'qos:={qos}',
         '-p', 'qos_depth:=1000', '-p', 'diagnostics_period:=1.0'],
        env=env, stdout=subprocess.PIPE, stderr=log, text=True)
    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node('soak_publisher', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    lock = threading.Lock()
    watermark_lag = [0]
    published_stamps: List[int] = []  # bat stamps in publish order (for the watermark lag)
    published_at: List[int] = []  # monotonic ns of each frame's bat publish

    def on_impact(message: PointStamped) -> None:
        with lock:
            soak.impacts.append((message.header.stamp.sec * 10**9 + message.header.stamp.nanosec,
                                 time.monotonic_ns()))

    def on_diagnostics(array: DiagnosticArray) -> None:
        for status in array.status:
            if not status.name.startswith('impact_node'):
                continue
            values = {kv.key: kv.value for kv in status.values}
            soak.diagnostics.append(values)
            injector.status(values)
            if values.get('watermark_stamp'):
                sec, _, nanosec = values['watermark_stamp'].partition('.')
                watermark = int(sec) * 10**9 + int(nanosec)
                with lock:
                    done = bisect.bisect_right(published_stamps, watermark)
                    beyond = len(published_stamps) - done
                watermark_lag[0] = max(watermark_lag[0], beyond)

    reliability = ReliabilityPolicy.RELIABLE if qos == 'reliable' \
        else ReliabilityPolicy.BEST_EFFORT
    profile = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000, reliability=reliability,
                         durability=DurabilityPolicy.VOLATILE)
    events = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                        reliability=ReliabilityPolicy.RELIABLE)
    impact_sub = node.create_subscription(PointStamped, '/impact_node/impact', on_impact,
                                          events)
    node.create_subscription(DiagnosticArray, '/diagnostics', on_diagnostics, events)
    ball_pub = node.create_publisher(PointStamped, 'ball', profile)
    bat_pub = node.create_publisher(PoseStamped, 'bat_pose', profile)
    injector.attach(node, profile)
    spinner.start()
    try:
        deadline = time.monotonic() + 60.0
        while not (ball_pub.get_subscription_count() and bat_pub.get_subscription_count()
                   and impact_sub.get_publisher_count()):
            if time.monotonic() > deadline or child.poll() is not None:
                raise RuntimeError('the impact node did not come up (see ' + log.name + ')')
            time.sleep(0.05)
        time.sleep(0.5)  # both ends of every connection matched
        soak.rss_kb.append((0.0, _rss_kb(child.pid)[0]))
        _publish(soak, pitches, (ball_pub, bat_pub, injector), child.pid, lock,
                 published_stamps, published_at, progress)
        time.sleep(2.0)  # let the node process and publish the tail
        soak.rss_kb.append((seconds + 2.0, _rss_kb(child.pid)[0]))
        soak.hwm_kb = _rss_kb(child.pid)[1]
    finally:
        child.send_signal(signal.SIGINT)
        try:
            out, _ = child.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            child.kill()
            out, _ = child.communicate()
        executor.shutdown(timeout_sec=2.0)
        spinner.join(timeout=5.0)
        node.destroy_node()
        rclpy.shutdown(context=context)
        log.seek(0)
        logged = log.read().splitlines()
        soak.warnings = [line for line in logged if '[WARN]' in line or 'ERROR' in line]
        log.close()
        os.unlink(log.name)
    lines = out.strip().splitlines()
    if not lines:
        raise RuntimeError(f'the impact node printed no figures (exit code {child.returncode}); '
                           'its log ended:\n' + '\n'.join(logged[-15:]))
    soak.node = json.loads(lines[-1])
    soak.watermark_lag_max = watermark_lag[0]
    _compare(soak, np.asarray(published_stamps), np.asarray(published_at), tolerance_us)
    return soak


def _publish(soak: Soak, pitches: Sequence[Pitch], senders: Tuple[Any, Any, Injector],
             pid: int, lock: threading.Lock, published_stamps: List[int],
             published_at: List[int], progress: bool) -> None:
    """Publish frames at the rate for the run's seconds; sample the node's RSS meanwhile."""
    ball_pub, bat_pub, injector = senders
    step_ns = int(round(1e9 / soak.rate_hz))
    total = int(soak.seconds * soak.rate_hz)
    ball_msg, bat_msg = PointStamped(), PoseStamped()
    ball_msg.header.frame_id = bat_msg.header.frame_id = 'world'
    start = time.monotonic_ns()
    next_rss = start + 500_000_000
    offset = DEFAULT_START_NS
    frame = 0
    index = 0
    while frame < total:
        pitch = pitches[index % len(pitches)]
        if pitch.contact_ns is not None:
            expects = injector.expects(frame / soak.rate_hz,
                                       (frame + len(pitch.stamps)) / soak.rate_hz,
                                       offset + pitch.contact_ns)
            (soak.expected if expects else soak.excused).append(offset + pitch.contact_ns)
        soak.pitches += 1
        for k in range(len(pitch.stamps)):
            if frame >= total:
                break
            seconds = frame / soak.rate_hz
            target = start + frame * step_ns
            now = time.monotonic_ns()
            if not injector.paced(seconds):
                start = now - frame * step_ns  # a burst: the schedule goes on from its end
            elif target > now:
                time.sleep((target - now) * 1e-9)
            else:
                soak.lateness_max_ms = max(soak.lateness_max_ms, (now - target) * 1e-6)
            stamp = offset + int(pitch.stamps[k])
            sec, nanosec = divmod(stamp, 10**9)
            for message in (ball_msg, bat_msg):
                message.header.stamp.sec, message.header.stamp.nanosec = sec, nanosec
            point = ball_msg.point
            point.x, point.y, point.z = (float(v) for v in pitch.balls[k])
            position, orientation = bat_msg.pose.position, bat_msg.pose.orientation
            position.x, position.y, position.z = (float(v) for v in pitch.positions[k])
            (orientation.x, orientation.y, orientation.z,
             orientation.w) = (float(v) for v in pitch.quaternions[k])
            send_ball, send_bat, extra = injector.frame(seconds, stamp, pitch, k, ball_msg,
                                                        bat_msg)
            sent = extra + Counter(ball=int(send_ball), bat_pose=int(send_bat))
            if send_ball:
                ball_pub.publish(ball_msg)
            if send_bat:
                bat_pub.publish(bat_msg)
            with lock:
                published_stamps.append(stamp)
                published_at.append(time.monotonic_ns())
            soak.published_by.update(sent)
            soak.published += sum(sent.values())
            frame += 1
            if published_at[-1] >= next_rss:
                soak.rss_kb.append(((published_at[-1] - start) * 1e-9, _rss_kb(pid)[0]))
                next_rss += 500_000_000
                if progress and len(soak.rss_kb) % 60 == 0:
                    print(f'  {frame / soak.rate_hz:6.0f} s: node RSS '
                          f'{soak.rss_kb[-1][1] / 1024:.1f} MB, {len(soak.impacts)} impacts',
                          flush=True)
        offset += pitch.span_ns
        index += 1
    if soak.expected and soak.expected[-1] >= published_stamps[-1]:
        soak.expected.pop()  # the run ended before the sample after that contact was sent
    soak.frames = frame


def _compare(soak: Soak, stamps: np.ndarray, sent_at: np.ndarray,
             tolerance_us: float) -> None:
    """Match received impacts to the truth; compute latencies."""
    received = sorted(soak.impacts)
    got = np.asarray([stamp for stamp, _ in received], dtype=np.int64)
    used = np.zeros(len(got), dtype=bool)
    for truth, excused in [(t, False) for t in soak.expected] + [(t, True) for t in soak.excused]:
        index = int(np.searchsorted(got, truth))
        best = None
        for j in (index - 1, index):
            if 0 <= j < len(got) and not used[j] and abs(int(got[j]) - truth) <= \
                    tolerance_us * 1e3 and (best is None or abs(int(got[j]) - truth) <
                                            abs(int(got[best]) - truth)):
                best = j
        if best is None:
            if not excused:
                soak.lost.append(truth)
        elif excused:
            used[best] = True
            soak.excused_found.append(truth)
        else:
            used[best] = True
            soak.matched_error_us_max = max(soak.matched_error_us_max,
                                            abs(int(got[best]) - truth) * 1e-3)
    soak.false = [int(stamp) for stamp, hit in zip(got, used) if not hit]
    for stamp, arrived in received:
        index = int(np.searchsorted(stamps, stamp, side='left'))
        if index < len(stamps):
            soak.latencies_ms.append((arrived - int(sent_at[index])) * 1e-6)


if __name__ == '__main__':
    if sys.argv[1:2] != ['--serve']:
        sys.exit(f'usage: {sys.argv[0]} --serve --ros-args ... (the node process of a soak; '
                 'run benchmarks/bench_soak.py for a soak)')
    sys.exit(serve())
