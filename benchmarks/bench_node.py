"""
impact_node benchmark: processing time per message and end-to-end impact latency at 1 kHz.

Run: ``.venv/bin/python benchmarks/bench_node.py [--pitches N] [--rate HZ] [--qos Q]
[--predict SECONDS] [--period SECONDS] [--model M] [--look-ahead N] [--tracker-noise M]
[--breakdown] [--consumers] [--no-freeze] [--fifo PRIORITY]``, ``--in-process RUNS [--idle US]``
for the node alone in this process, or ``--startup RUNS`` for the start-up time alone.

Three processes, as in a deployment: this one publishes the ball (PointStamped) and the bat
(PoseStamped) at ``--rate`` per stream; a child (this file with ``--serve``) runs ``ImpactNode``
and records the wall time of every message callback (conversion, detector, publishing); a
second child (``--listen``) records when each ``/impact_node/impact`` arrives. The node's child
starts numpy with one BLAS thread, as the ``impact_node`` script does (``entry_points``). Each
pitch is a swing that hits the ball; between pitches both streams pause longer than
``max_gap``.

* processing: median, mean, p99 and max over every message of the wall time inside the
  node's handling of that one message (``ImpactNode._take``: the stamp and the tally, the
  detector with its prediction, the messages of its events and their publications, the drop
  warnings; not rclpy's take and deserialisation, nor the executor's wait), and of the callback
  thread's CPU time over the same span, which a loaded machine inflates less; and the first
  three messages' (no compile pause: the kernel is compiled ahead of time). The
  ``~/impact_report`` records are made and sent after the drain, outside any message's
  processing, and so are an impact's error bars, INFO line and markers (its ``~/impact`` and
  ``~/impact_velocity`` go out in its message): their cost is printed per flush beside it,
  the flushes that completed an impact apart.
  ``--predict 0.3``: with ``prediction_horizon`` 0.3 s (issue 13's goal: p99 <= 0.3 ms,
  prediction <= 30 us per message mean: the mean with it minus the mean without it);
  ``--period S``: with ``prediction_period`` S (predict at most every S seconds).
* the slowest 1 % (by wall and by CPU time): how many of those messages predicted, published
  a prediction, made an impact, ran a garbage collection, came after more than 0.5 ms idle, or
  were ball messages (against how many of all messages were), and the p99 of the messages
  that were not of each kind; and every garbage collection in the node process (in a message
  or between), by generation, with its CPU time.
* breakdown (``--breakdown``): where a message that predicts spends its CPU time (the
  callback thread's clock): the detector (of which the prediction), building the messages of
  its events, each publication and the rest of the callback; median and p90 over the
  messages that predicted, and over those that published a prediction; the same phases'
  wall time beside (``wall ...``).
* ``--fifo P``: the node's process, all its threads, under ``SCHED_FIFO`` priority P
  (``chrt -f P``; a real-time deployment: ``ros2 run --prefix``), the others at normal
  priority.
* ``--consumers``: the listener also subscribes to ``~/predicted_impact`` and
  ``~/impact_report`` (a batting arm's controller and a recorder), so the node makes and sends
  every prediction's record; without it nobody subscribes to them.
* in this process (``--in-process RUNS``): the node alone, its callback fed the same
  messages directly (no DDS, no other process), CPU time per message, each message's least
  over RUNS fresh runs (what a quiet machine would give; ``in_process``). ``--idle US``: the
  thread sleeps US microseconds before each message, as the node waits for its next one when
  deployed (at 1 kHz a stream, about 500 us): what a core left idle between messages costs
  the next one (its caches).
* start-up (``--startup``): from starting ``.venv/bin/impact_node --ros-args --params-file
  config/impact_node.yaml`` to its "listening" line on stderr (imports, parameters, I/O).
* prediction latency (``--consumers``): from the publish of the message that made each
  prediction to the listener's reception of its ``~/predicted_impact``, and the node's part of
  it (callback entry -> publish).
* latency: from the publish of the message that completes the interval holding the impact
  (the bat pose at the first stamp after the impact, published after the ball) to the
  reception of ``~/impact`` by the listener; both on the system-wide monotonic clock.
"""

import argparse
from array import array
import gc
import json
import math
import os
from pathlib import Path
import random
import signal
import struct
import subprocess
import sys
import tempfile
import time
from typing import Any, Dict, List, Optional, Sequence, Tuple

from baseball_collision.core.detector import DEFAULTS, PendingUncertainty
from baseball_collision.core.detector.predictor import Predictor
from baseball_collision.entry_points import one_blas_thread_from_start
from baseball_collision.ros import node as node_module
from baseball_collision.ros.node import ImpactNode
from geometry_msgs.msg import PointStamped, PoseStamped
import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

BASE_NS = 1_700_000_000_000_000_000
LENGTH = 0.8636
SWING_S = 0.2
PAUSE_S = 0.08  # > max_gap (0.05 s): each pitch starts a new segment


def swing_pose(t: float) -> Tuple[Tuple[float, ...], Tuple[float, ...]]:
    """Return the bat pose (knob position, quaternion x y z w; tip along body +z) at t."""
    angle = -1.2 + 30.0 * t + 100.0 * t * t
    # +z turned onto the horizontal direction (cos a, sin a, 0): 90 deg about (-sin a, cos a, 0)
    half = math.sqrt(0.5)
    return (0.0, 2.0 * t, 1.0), (-math.sin(angle) * half, math.cos(angle) * half, 0.0, half)


def set_swing_pose(message: Any, t: float) -> None:
    """Write the bat pose at t (``swing_pose``) into a geometry_msgs/PoseStamped, in place."""
    (x, y, z), (qx, qy, qz, qw) = swing_pose(t)
    position, orientation = message.pose.position, message.pose.orientation
    position.x, position.y, position.z = x, y, z
    orientation.x, orientation.y, orientation.z, orientation.w = qx, qy, qz, qw


def ball(t: float) -> Tuple[float, float, float]:
    """Return where the pitched ball is at t: 40 m/s along -y, 1 m high."""
    return (0.6, 2.9 - 40.0 * t, 1.0)


def percentiles(samples: List[float]) -> Dict[str, float]:
    """Return count, median, p99 and max of samples (same unit)."""
    array = np.asarray(samples, dtype=float)
    if array.size == 0:
        return {'count': 0, 'median': math.nan, 'p99': math.nan, 'max': math.nan}
    return {'count': int(array.size), 'median': float(np.median(array)),
            'p99': float(np.percentile(array, 99)), 'max': float(array.max())}


# ----------------------------------------------------------------------------------------------
# the node process


def completes_an_impact(node: ImpactNode) -> bool:
    """Return whether the node's next completion (after the drain) measures an impact."""
    return any(event.__class__ is PendingUncertainty for event, _, _ in node._to_complete)


class TimedImpactNode(ImpactNode):
    """
    ImpactNode that keeps every per-message processing time (s) and an impact timeline.

    ``timeline``: per impact, (impact stamp, callback entry, ``~/impact`` publish call) in
    monotonic ns.
    """

    def __init__(self) -> None:
        self.times: List[float] = []
        self.cpu_times: List[float] = []  # this thread's CPU time per message (s)
        self.timeline: List[Tuple[int, int, int]] = []
        # per prediction published: (the stamp of the message that made it, callback entry,
        # ``~/predicted_impact`` publish returned) in monotonic ns
        self.prediction_timeline: List[Tuple[int, int, int]] = []
        self._taking_ns = 0
        self.report_times: List[Tuple[float, float]] = []  # per flush of reports: wall, CPU (s)
        self.impact_times: List[Tuple[float, float]] = []  # per flush completing an impact
        self.reports_made = 0
        self._entry_ns = 0
        # per message, six numbers in a row: predicted, published a prediction, made an impact,
        # the oldest generation a garbage collection in it collected (-1: none), idle before it
        # (s), ball 1 / bat 0 (an array: recording them must make no garbage to collect)
        self.kinds = array('d')
        self._gc: List[int] = []  # the generations collected during the current message
        self._gc_started = 0.0
        self.collections: List[Tuple[int, float]] = []
        self._left = time.monotonic()  # when the previous message's handling ended
        super().__init__()
        self._watched = self.detector._predictor  # the benchmark looks inside
        gc.callbacks.append(self._on_gc)
        published = self._outputs['predicted_impact'].publish
        self.predictions_sent = 0

        def counted_prediction(message: PointStamped) -> None:
            self.predictions_sent += 1
            published(message)
            self.prediction_timeline.append((self._taking_ns, self._entry_ns,
                                             time.monotonic_ns()))
        self._outputs['predicted_impact'] = _Wrapped(self._outputs['predicted_impact'],
                                                     counted_prediction)
        publish = self._outputs['impact'].publish

        def timed_publish(message: bytes) -> None:  # (a PointStamped's CDR: its stamp at 4)
            sec, nanosec = struct.unpack_from('<iI', message, 4)
            self.timeline.append((sec * 10**9 + nanosec, self._entry_ns, time.monotonic_ns()))
            publish(message)
        self._outputs['impact'] = _Wrapped(self._outputs['impact'], timed_publish)
        report = self._outputs['impact_report'].publish

        def counted_report(message: String) -> None:
            self.reports_made += 1
            report(message)
        self._outputs['impact_report'] = _Wrapped(self._outputs['impact_report'], counted_report)

    def _on_gc(self, phase: str, info: Dict[str, int]) -> None:
        if phase == 'start':
            self._gc.append(info['generation'])
            self._gc_started = time.thread_time()
        else:  # every collection in the process, inside a message or not: (generation, CPU s)
            self.collections.append((info['generation'], time.thread_time() - self._gc_started))

    def _take(self, *args: object, **kwargs: object) -> None:
        self._entry_ns = time.monotonic_ns()
        stamp = args[1].stamp  # (stream, header, ...)
        self._taking_ns = stamp.sec * 10**9 + stamp.nanosec
        idle = self._entry_ns * 1e-9 - self._left
        before, impacts = self._watched.last_ns, self.detector.stats.impacts
        sent, self._gc = self.predictions_sent, []
        cpu = time.thread_time()
        super()._take(*args, **kwargs)  # (sequence number, send time: keywords)
        self.cpu_times.append(time.thread_time() - cpu)
        self._left = time.monotonic()
        self.kinds.extend((self._watched.last_ns != before, self.predictions_sent > sent,
                           self.detector.stats.impacts > impacts, max(self._gc, default=-1),
                           idle, args[0] == 'ball'))

    def _record_processing(self, elapsed_s: float) -> None:
        self.times.append(elapsed_s)
        super()._record_processing(elapsed_s)

    def _complete_events(self) -> None:
        if not self._to_complete:
            return
        made = self.reports_made
        impacts = completes_an_impact(self)
        start, cpu = time.perf_counter(), time.thread_time()
        super()._complete_events()
        spent = (time.perf_counter() - start, time.thread_time() - cpu)
        if impacts:
            self.impact_times.append(spent)
        elif self.reports_made > made:  # made for a subscriber, not dropped for nobody
            self.report_times.append(spent)


class BrokenDownImpactNode(TimedImpactNode):
    """
    TimedImpactNode that also splits each message's CPU time into phases (``--breakdown``).

    ``phases``: per message, {phase: CPU s}: ``total``, ``detector`` (``Detector.add_*``),
    ``prediction`` (``Predictor.predict``, inside the detector's), ``messages``
    (``event_output``, and the node's ``StampedCdr``: the events' messages),
    ``publish <output>``; ``predicted`` and ``published`` say whether it predicted (was due)
    and published a prediction.
    """

    def __init__(self) -> None:
        self.phases: List[Dict[str, float]] = []
        self._phase: Dict[str, float] = {}
        self._walls: Dict[str, float] = {}  # the same phases' wall time (s)
        super().__init__()
        for name in list(self._outputs):
            self._outputs[name] = _Wrapped(self._outputs[name], self._timed(
                f'publish {name}', self._outputs[name].publish))
        self._predictor = self.detector._predictor  # the benchmark looks inside
        if hasattr(self, '_point_cdr'):  # a prediction's (or an impact's) bytes: 'messages'
            self._point_cdr = self._timed('messages', self._point_cdr)

    def _timed(self, phase: str, function: object) -> object:
        def timed(*args: object, **kwargs: object) -> object:
            cpu, wall = time.thread_time(), time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                self._phase[phase] = self._phase.get(phase, 0.0) + time.thread_time() - cpu
                self._walls[phase] = self._walls.get(phase, 0.0) + time.perf_counter() - wall
        return timed

    def _complete_events(self) -> None:
        self._phase = {}  # the reports' publications are not a message's phases
        super()._complete_events()

    def _take(self, stream: str, header: object, add_sample: object, *values: object,
              **kwargs: object) -> None:
        self._phase, self._walls = {}, {}
        before = self._predictor.last_ns
        super()._take(stream, header, self._timed('detector', add_sample), *values, **kwargs)
        phase = self._phase
        phase['total'] = self.cpu_times[-1]
        phase.update({f'wall {name}': value for name, value in self._walls.items()})
        phase['wall total'] = self.times[-1]
        phase['predicted'] = float(self._predictor.last_ns != before)
        phase['published'] = float('publish predicted_impact' in phase)
        self.phases.append(phase)


KIND_NAMES = ('predicted', 'published a prediction', 'made an impact', 'ran a GC collection',
              'came after > 0.5 ms idle', 'ball')


def top_percent(times_s: List[float], kinds: Sequence[float],
                share: float = 0.01) -> Dict[str, Any]:
    """
    Return what the slowest ``share`` of the messages were, and the p99 without each kind.

    ``kinds``: six numbers per message in a row, as ``TimedImpactNode.kinds`` keeps them.
    Returns {'count': messages in the top, 'threshold_us': the least time among them, 'kinds':
    {name: [in the top, of all messages]}, 'p99_without_us': {name: p99 (us) of the messages
    not of that kind}}.
    """
    times = np.asarray(times_s) * 1e6
    if not times.size:
        return {'count': 0, 'threshold_us': math.nan, 'kinds': {}, 'p99_without_us': {}}
    array = np.asarray(kinds, dtype=float).reshape(-1, len(KIND_NAMES))
    flags = np.stack([array[:, 0] > 0, array[:, 1] > 0, array[:, 2] > 0, array[:, 3] >= 0,
                      array[:, 4] > 0.5e-3, array[:, 5] > 0], axis=1)
    count = max(1, int(round(share * times.size)))
    top = np.argsort(times, kind='stable')[-count:]
    return {'count': count, 'threshold_us': float(times[top].min()),
            'kinds': {name: [int(flags[top, i].sum()), int(flags[:, i].sum())]
                      for i, name in enumerate(KIND_NAMES)},
            'p99_without_us': {name: float(np.percentile(times[~flags[:, i]], 99))
                               for i, name in enumerate(KIND_NAMES) if (~flags[:, i]).any()}}


def breakdown(phases: List[Dict[str, float]]) -> Dict[str, Dict[str, List[float]]]:
    """Return {messages that predicted / published: {phase: [median, p90] us}}."""
    result = {}
    for kind in ('predicted', 'published'):
        chosen = [p for p in phases if p.get(kind)]
        names = sorted({name for p in chosen for name in p} - {'predicted', 'published'})
        table = {}
        for name in names + ['rest']:
            if name == 'rest':  # the callback outside the detector, messages and publishing
                values = [p['total'] - sum(v for k, v in p.items() if k not in (
                    'total', 'prediction', 'predicted', 'published')
                    and not k.startswith('wall')) for p in chosen]
            else:
                values = [p.get(name, 0.0) for p in chosen]
            values_us = np.asarray(values) * 1e6
            table[name] = [float(np.median(values_us)), float(np.percentile(values_us, 90))]
        result[f'{kind} ({len(chosen)} messages)'] = table
    return result


class _Wrapped:
    """A publisher whose ``publish`` is replaced; everything else passes through."""

    def __init__(self, publisher: object, publish: object) -> None:
        self._publisher = publisher
        self.publish = publish

    def __getattr__(self, name: str) -> object:
        return getattr(self._publisher, name)


_NODE: List[ImpactNode] = []
"""The served node (for ``_phase_timed``)."""


def _phase_timed(phase: str, function: object) -> object:
    """Return ``function`` adding its CPU time to the served node's current phase."""
    def timed(*args: object, **kwargs: object) -> object:
        if not _NODE or not isinstance(_NODE[0], BrokenDownImpactNode):
            return function(*args, **kwargs)
        return _NODE[0]._timed(phase, function)(*args, **kwargs)
    return timed


def serve() -> int:
    """Run the timed node until SIGINT; print the processing figures (us) as JSON."""
    rclpy.init(args=sys.argv)
    broken_down = os.environ.get('BENCH_NODE_BREAKDOWN') == '1'
    if broken_down:  # time the prediction and the messages' building inside the callback
        Predictor.predict = _phase_timed('prediction', Predictor.predict)
        node_module.event_output = _phase_timed('messages', node_module.event_output)
    node = BrokenDownImpactNode() if broken_down else TimedImpactNode()
    if os.environ.get('BENCH_NODE_NO_FREEZE') != '1':  # as impact_node's main does
        node_module.freeze_start_up()
        node.collections.clear()  # its own collection is start-up's, not the messages'
    _NODE[:] = [node]
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    figures = percentiles([t * 1e6 for t in node.times])
    # the first messages' cost: a compile or warm-up pause would show here (the kernel is C)
    figures['first'] = [t * 1e6 for t in node.times[:3]]
    figures['mean'] = float(np.mean(node.times) * 1e6) if node.times else math.nan
    figures['cpu'] = percentiles([t * 1e6 for t in node.cpu_times])
    figures['cpu']['mean'] = float(np.mean(node.cpu_times) * 1e6) if node.cpu_times else math.nan
    figures['reports'] = {'wall': percentiles([w * 1e6 for w, _ in node.report_times]),
                          'cpu': percentiles([c * 1e6 for _, c in node.report_times]),
                          'made': node.reports_made}
    figures['completed'] = {'wall': percentiles([w * 1e6 for w, _ in node.impact_times]),
                            'cpu': percentiles([c * 1e6 for _, c in node.impact_times])}
    figures['top'] = {'wall': top_percent(node.times, node.kinds),
                      'cpu': top_percent(node.cpu_times, node.kinds)}
    figures['collections'] = {
        generation: [len(cpu), float(np.median(cpu) * 1e6), float(np.max(cpu) * 1e6)]
        for generation in range(3)
        for cpu in [[c for g, c in node.collections if g == generation]] if cpu}
    figures['impacts'] = node.detector.stats.impacts
    figures['dropped'] = sum(node.detector.stats.dropped.values())
    figures['timeline'] = node.timeline
    figures['prediction_timeline'] = node.prediction_timeline
    if broken_down:
        figures['breakdown'] = breakdown(node.phases)
    print(json.dumps(figures), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


def listen() -> int:
    """
    Record (impact stamp, monotonic ns at reception) until SIGINT; print them as JSON.

    With the consumers, each ``~/predicted_impact``'s reception too (monotonic ns, in order).
    """
    rclpy.init(args=sys.argv)
    node = rclpy.create_node('bench_listener')
    received: List[Tuple[int, int]] = []
    predictions: List[int] = []
    node.create_subscription(
        PointStamped, '/impact_node/impact',
        lambda m: received.append((m.header.stamp.sec * 10**9 + m.header.stamp.nanosec,
                                   time.monotonic_ns())),
        QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
    if os.environ.get('BENCH_NODE_CONSUMERS') == '1':  # an arm's controller and a recorder
        counted = {'predicted_impact': 0, 'impact_report': 0}

        def count(name: str) -> object:
            def received_one(message: object) -> None:
                counted[name] += 1
                if name == 'predicted_impact':
                    predictions.append(time.monotonic_ns())
            return received_one
        node.create_subscription(PointStamped, '/impact_node/predicted_impact',
                                 count('predicted_impact'), 100)
        node.create_subscription(String, '/impact_node/impact_report', count('impact_report'),
                                 QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    print(json.dumps({'impacts': received, 'predictions': predictions}), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


# ----------------------------------------------------------------------------------------------
# the publishing process


def _child(mode: str, env: Dict[str, str], *ros_args: str,
           prefix: Sequence[str] = ()) -> subprocess.Popen:
    """
    Start this file in a child mode (``--serve``, ``--listen``) with ROS arguments.

    :param prefix: a command the child runs under (e.g. ``chrt -f 50``).
    """
    log = tempfile.TemporaryFile('w+')  # its stderr (a pipe read only at the end could fill)
    child = subprocess.Popen([*prefix, sys.executable, __file__, mode, '--ros-args', *ros_args],
                             env=env, stdout=subprocess.PIPE, stderr=log, text=True)
    child.log = log
    return child


def _stop(child: subprocess.Popen) -> object:
    """
    Stop a child with SIGINT and return the JSON it printed last.

    :raises RuntimeError: it printed none (its exit status and the end of its stderr said).
    """
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=30)
    lines = out.strip().splitlines()
    if not lines:
        child.log.seek(0)
        raise RuntimeError(f'{child.args[2]} printed no figures (exit status {child.returncode})'
                           f': {child.log.read()[-2000:]}')
    return json.loads(lines[-1])


def print_prediction_latency(timeline: List[List[int]], arrivals: List[int],
                             published: Dict[int, int]) -> None:
    """
    Print how long predictions took to reach the arm's controller (the listener), in ms.

    From the publish of the message that made each (the bat's, published after the ball's) to
    the reception of its ``~/predicted_impact``, and the part from the node's callback entry to
    its publish: the i-th published with the i-th received (reliable, in order; not when some
    were lost).

    :param timeline: per prediction published: (its message's stamp, callback entry, publish
        returned), monotonic ns; ``arrivals``: each reception, monotonic ns; ``published``:
        stamp -> monotonic ns of that stamp's publish.
    """
    if len(timeline) != len(arrivals):
        print(f'  predictions: {len(timeline)} published, {len(arrivals)} received: latency '
              'not paired')
        return
    total = percentiles([(arrived - published[stamp]) * 1e-6
                         for (stamp, _, _), arrived in zip(timeline, arrivals)])
    inside = percentiles([(out - entry) * 1e-6 for _, entry, out in timeline])
    print(f"  prediction latency ({total['count']} published and received): the predicting "
          f"sample published -> ~/predicted_impact received median {total['median']:.3f} ms, "
          f"p99 {total['p99']:.3f} ms; of it callback -> published median "
          f"{inside['median']:.3f} ms, p99 {inside['p99']:.3f} ms")


def run(pitches: int, rate: float, qos_name: str, markers: bool, horizon: float,
        period: float = 0.0, model: str = DEFAULTS['model'], look_ahead: int = 0,
        broken_down: bool = False, consumers: bool = False, freeze: bool = True,
        fifo: int = 0, tracker_noise: Optional[float] = None) -> None:
    """
    Start the node and listener processes, publish the pitches, print the figures.

    :param fifo: > 0: the node's process (all its threads) under SCHED_FIFO at this priority.
    :param tracker_noise: the node's ``tracker_noise`` (m; -1 auto), None for its default.
    """
    os.environ.pop('RMW_IMPLEMENTATION', None)
    os.environ.setdefault('ROS_DOMAIN_ID', str(random.SystemRandom().randint(1, 101)))
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    env = dict(os.environ, BENCH_NODE_BREAKDOWN='1' if broken_down else '0',
               BENCH_NODE_NO_FREEZE='1' if not freeze else '0',
               BENCH_NODE_CONSUMERS='1' if consumers else '0')
    # the node's process starts numpy as the impact_node script does (entry_points)
    served = dict(env)
    one_blas_thread_from_start(served)
    server = _child('--serve', served, '-p', f'qos:={qos_name}', '-p', 'qos_depth:=1000',
                    '-p', f'publish_markers:={str(markers).lower()}',
                    '-p', f'prediction_horizon:={horizon}', '-p', f'prediction_period:={period}',
                    '-p', f'model:={model}', '-p', f'look_ahead:={look_ahead}',
                    *(() if tracker_noise is None else ('-p', f'tracker_noise:={tracker_noise}')),
                    prefix=('chrt', '-f', str(fifo)) if fifo else ())
    listener = _child('--listen', env)
    rclpy.init()
    node = rclpy.create_node('bench_publisher')
    reliability = ReliabilityPolicy.RELIABLE if qos_name == 'reliable' \
        else ReliabilityPolicy.BEST_EFFORT
    qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000, reliability=reliability,
                     durability=DurabilityPolicy.VOLATILE)
    ball_pub = node.create_publisher(PointStamped, 'ball', qos)
    bat_pub = node.create_publisher(PoseStamped, 'bat_pose', qos)
    deadline = time.monotonic() + 30.0
    while not (ball_pub.get_subscription_count() and bat_pub.get_subscription_count()
               and node.count_subscribers('/impact_node/impact')
               and (not consumers or node.count_subscribers('/impact_node/impact_report'))):
        if time.monotonic() > deadline:
            raise SystemExit('the impact node or the listener did not come up')
        time.sleep(0.05)
    time.sleep(1.0)  # let the listener match the node's publisher too

    step_ns = int(round(1e9 / rate))
    per_pitch = int(SWING_S * rate)
    pitch_ns = per_pitch * step_ns + int(PAUSE_S * 1e9)
    published: Dict[int, int] = {}  # stamp -> monotonic ns of the bat message's publish
    ball_msg, bat_msg = PointStamped(), PoseStamped()
    ball_msg.header.frame_id = bat_msg.header.frame_id = 'world'
    start = time.monotonic_ns()
    for k in range(pitches):
        for i in range(per_pitch):
            wait = start + k * pitch_ns + i * step_ns - time.monotonic_ns()
            if wait > 0:
                time.sleep(wait * 1e-9)
            stamp = BASE_NS + k * pitch_ns + i * step_ns
            t = i * step_ns * 1e-9
            sec, nanosec = divmod(stamp, 10**9)
            for message in (ball_msg, bat_msg):
                message.header.stamp.sec, message.header.stamp.nanosec = sec, nanosec
            p = ball_msg.point
            p.x, p.y, p.z = ball(t)
            set_swing_pose(bat_msg, t)
            ball_pub.publish(ball_msg)
            bat_pub.publish(bat_msg)
            published[stamp] = time.monotonic_ns()
    time.sleep(1.0)
    node.destroy_node()
    rclpy.try_shutdown()
    processing = _stop(server)
    listened = _stop(listener)
    received = listened['impacts']

    stamps = np.array(sorted(published))

    def completing_publish(impact_ns: int) -> Optional[int]:
        index = int(np.searchsorted(stamps, impact_ns, side='left'))
        return published[int(stamps[index])] if index < len(stamps) else None

    latencies = []
    for impact_ns, arrived in received:
        sent = completing_publish(impact_ns)
        if sent is not None:
            latencies.append((arrived - sent) * 1e-6)
    latency = percentiles(latencies)
    to_node, in_node, to_listener = [], [], []
    arrivals = dict(map(tuple, received))
    for impact_ns, entry, out in processing['timeline']:
        sent = completing_publish(impact_ns)
        if sent is not None:
            to_node.append((entry - sent) * 1e-6)
            in_node.append((out - entry) * 1e-6)
        if impact_ns in arrivals:
            to_listener.append((arrivals[impact_ns] - out) * 1e-6)
    to_node, in_node = percentiles(to_node), percentiles(in_node)
    to_listener = percentiles(to_listener)
    print(f'impact_node at {rate:.0f} Hz per stream (ball PointStamped + bat PoseStamped), '
          f'qos {qos_name}, model {model} (look_ahead {look_ahead}, tracker_noise '
          f"{DEFAULTS['tracker_noise'] if tracker_noise is None else tracker_noise:g}), "
          f"markers {'on' if markers else 'off'}, "
          f'prediction_horizon {horizon} s, prediction_period {period} s, {pitches} pitches'
          + (', subscribers on ~/predicted_impact and ~/impact_report' if consumers else '')
          + ('' if freeze else ', start-up objects not frozen'))
    print(f"  processing per message (callback wall time, {processing['count']} messages): "
          f"median {processing['median']:.1f} us, mean {processing['mean']:.1f} us, "
          f"p99 {processing['p99']:.1f} us, max {processing['max']:.1f} us; the first three "
          f"{', '.join(f'{t:.0f}' for t in processing['first'])} us")
    cpu = processing['cpu']
    print(f"  the same, this thread's CPU time (time waiting for a core not counted): median "
          f"{cpu['median']:.1f} us, mean {cpu['mean']:.1f} us, p99 {cpu['p99']:.1f} us, max "
          f"{cpu['max']:.1f} us")
    reports = processing['reports']
    if reports['made']:
        print(f"  ~/impact_report: {reports['made']} records made and sent after the drain, "
              f"{reports['cpu']['count']} flushes without an impact (not in the processing "
              f"above): CPU per flush median {reports['cpu']['median']:.1f} us, p99 "
              f"{reports['cpu']['p99']:.1f} us, max {reports['cpu']['max']:.1f} us; wall "
              f"median {reports['wall']['median']:.1f} us, p99 {reports['wall']['p99']:.1f} us")
    completed = processing['completed']
    if completed['cpu']['count']:
        print(f"  the {completed['cpu']['count']} flushes that completed an impact (its error "
              f'bars, line, markers, and the reports): CPU median '
              f"{completed['cpu']['median']:.1f} us, max {completed['cpu']['max']:.1f} us; wall "
              f"median {completed['wall']['median']:.1f} us, max "
              f"{completed['wall']['max']:.1f} us")
    print(f"  impacts: {processing['impacts']} detected, {len(received)} received, "
          f"{processing['dropped']} samples dropped")
    print(f"  end-to-end latency, completing publish -> ~/impact received ({latency['count']} "
          f"impacts): median {latency['median']:.3f} ms, p99 {latency['p99']:.3f} ms, "
          f"max {latency['max']:.3f} ms")
    if consumers:
        print_prediction_latency(processing['prediction_timeline'], listened['predictions'],
                                 published)
    print('  garbage collections in the node process (in a message or not): '
          + (', '.join(f'generation {g}: {n}, CPU median {m:.0f} us, max {x:.0f} us'
                       for g, (n, m, x) in processing['collections'].items()) or 'none'))
    for clock, top in processing['top'].items():
        print(f"  the slowest 1 % by {clock} time ({top['count']} messages, from "
              f"{top['threshold_us']:.1f} us), of them / of all: "
              + ', '.join(f'{name} {a} / {b}' for name, (a, b) in top['kinds'].items()))
        print(f'    {clock} p99 of the messages that did not ...: '
              + ', '.join(f'{name.split()[0]} {v:.1f} us'
                          for name, v in top['p99_without_us'].items()))
    for kind, table in processing.get('breakdown', {}).items():
        print(f'  CPU time of the messages that {kind}, median / p90 us: '
              + ', '.join(f'{name} {m:.1f} / {p90:.1f}' for name, (m, p90) in table.items()))
    for name, figures in (('publish -> node callback', to_node),
                          ('callback -> ~/impact published', in_node),
                          ('~/impact published -> received', to_listener)):
        print(f"    {name}: median {figures['median']:.3f} ms, p99 {figures['p99']:.3f} ms")


def in_process(runs: int, pitches: int, rate: float, horizon: float, period: float,
               model: str = DEFAULTS['model'], freeze: bool = True, look_ahead: int = 0,
               tracker_noise: Optional[float] = None, idle_s: float = 0.0) -> None:
    """
    Print the node's CPU time per message fed straight to its callback, least of ``runs`` runs.

    No DDS and no other process: each run makes a fresh ``ImpactNode`` in this process and
    hands it the benchmark's messages (``ImpactNode._take``, as its subscriptions do), timing
    each on the thread's CPU clock; each message's least time over the runs filters out the
    other work on a shared machine. Percentiles over all messages, and medians over those
    that predicted and those that published a prediction (no subscriber: no reports made).
    After each message, as after a drain, the completions and the bat's departures made ahead
    (``_departures_ahead``), timed apart.
    After each run, the CPU time of a full garbage collection (``gc.collect()``) with the node
    and its messages alive; ``freeze``: the start-up objects frozen after the first node is made
    (``node.freeze_start_up``, as ``impact_node`` does), else not. ``idle_s``: seconds slept
    before each message (not timed).
    """
    os.environ.pop('RMW_IMPLEMENTATION', None)
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'OFF'
    rclpy.init()
    step_ns = int(round(1e9 / rate))
    per_pitch = int(SWING_S * rate)
    pitch_ns = per_pitch * step_ns + int(PAUSE_S * 1e9)
    overrides = [Parameter('prediction_horizon', value=horizon),
                 Parameter('prediction_period', value=period), Parameter('model', value=model),
                 Parameter('look_ahead', value=look_ahead)]
    if tracker_noise is not None:
        overrides.append(Parameter('tracker_noise', value=tracker_noise))
    cpu_runs, completed_runs, ahead_runs, predicted, published, full = [], [], [], [], [], []
    for run in range(runs):
        node = ImpactNode(parameter_overrides=overrides)
        if freeze and not run:
            node_module.freeze_start_up()
        predictor = node.detector._predictor  # the benchmark looks inside
        ball_msg, bat_msg = PointStamped(), PoseStamped()
        ball_msg.header.frame_id = bat_msg.header.frame_id = 'world'
        cpu, predicted, published, completed, ahead = [], [], [], [], []
        for k in range(pitches):
            for i in range(per_pitch):
                stamp = BASE_NS + k * pitch_ns + i * step_ns
                t = i * step_ns * 1e-9
                for message in (ball_msg, bat_msg):
                    message.header.stamp.sec, message.header.stamp.nanosec = divmod(
                        stamp, 10**9)
                position, orientation = swing_pose(t)
                for stream, message, add, values in (
                        ('ball', ball_msg, node.detector.add_ball, (ball(t),)),
                        ('bat_pose', bat_msg, node.detector.add_bat_pose,
                         (position, orientation))):
                    before = predictor.last_ns
                    if idle_s:
                        time.sleep(idle_s)
                    start = time.thread_time()
                    node._take(stream, message.header, add, *values)
                    cpu.append(time.thread_time() - start)
                    impact = completes_an_impact(node)
                    start = time.thread_time()
                    node._complete_events()  # as after a drain (no subscriber: none made)
                    if impact:  # its error bars, line and markers
                        completed.append(time.thread_time() - start)
                    start = time.thread_time()
                    node._departures_ahead()  # then the bat's newest departures
                    ahead.append(time.thread_time() - start)
                    predicted.append(predictor.last_ns != before)
                    published.append(predicted[-1] and predictor.predicting)
        cpu_runs.append(cpu)
        completed_runs.append(completed)
        ahead_runs.append(ahead)
        start = time.thread_time()
        gc.collect()
        full.append(time.thread_time() - start)
        node.destroy_node()
    rclpy.try_shutdown()
    least = np.min(np.array(cpu_runs), axis=0) * 1e6
    predicted, published = np.array(predicted), np.array(published)
    noise = DEFAULTS['tracker_noise'] if tracker_noise is None else tracker_noise
    print(f'impact_node in this process at {rate:.0f} Hz per stream, model {model} '
          f'(look_ahead {look_ahead}, tracker_noise {noise:g}), prediction_horizon {horizon} s, '
          f'prediction_period {period} s, {pitches} pitches'
          + (f', {idle_s * 1e6:g} us idle before each message' if idle_s else '')
          + f': CPU per message, least of {runs} runs')
    print(f'  all {least.size} messages: median {np.median(least):.1f} us, mean '
          f'{least.mean():.1f} us, p99 {np.percentile(least, 99):.1f} us')
    for name, chosen in (('predicted', predicted), ('published a prediction', published),
                         ('did not predict', ~predicted)):
        if chosen.any():
            print(f'  the {chosen.sum()} that {name}: median {np.median(least[chosen]):.1f} us, '
                  f'p90 {np.percentile(least[chosen], 90):.1f} us')
    after = np.min(np.array(completed_runs), axis=0) * 1e6
    if after.size:
        print(f'  after the drain, the {after.size} impacts completed (error bars, line, '
              f'markers): median {np.median(after):.1f} us, max {after.max():.1f} us')
    ahead = np.min(np.array(ahead_runs), axis=0) * 1e6
    print(f"  after the drain, the bat's departures made ahead: mean {ahead.mean():.1f} us, "
          f'p99 {np.percentile(ahead, 99):.1f} us, max {ahead.max():.1f} us')
    print('  a full garbage collection after each run (start-up objects '
          f"{'frozen' if freeze else 'not frozen'}): "
          + ', '.join(f'{t * 1e3:.2f}' for t in full) + ' ms CPU')


def startup(runs: int) -> None:
    """Print the median, min and max time (ms) from starting impact_node to its first line."""
    script = Path(sys.executable).parent / 'impact_node'
    command = [str(script)] if script.exists() else [
        sys.executable, '-m', 'baseball_collision.ros.node']
    params = Path(__file__).resolve().parent.parent / 'config' / 'impact_node.yaml'
    env = dict(os.environ, PYTHONUNBUFFERED='1', ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    env.pop('RMW_IMPLEMENTATION', None)
    times = []
    for _ in range(runs):
        start = time.monotonic()
        child = subprocess.Popen(command + ['--ros-args', '--params-file', str(params)],
                                 env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                 text=True)
        for line in child.stderr:
            if 'listening' in line:
                times.append((time.monotonic() - start) * 1e3)
                break
        child.send_signal(signal.SIGINT)
        child.communicate(timeout=30)
    figures = percentiles(times)
    print(f"impact_node start-up (start -> 'listening' line, {figures['count']} runs): "
          f"median {figures['median']:.0f} ms, min {min(times):.0f} ms, "
          f"max {figures['max']:.0f} ms")


def main(argv: Optional[List[str]] = None) -> int:
    """Parse the command line and run the benchmark (or a child: --serve, --listen)."""
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == '--serve':
        return serve()
    if argv and argv[0] == '--listen':
        return listen()
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--pitches', type=int, default=100, help='swings that hit (100)')
    parser.add_argument('--rate', type=float, default=1000.0, help='Hz per stream (1000)')
    parser.add_argument('--qos', choices=('reliable', 'sensor_data'), default='reliable')
    parser.add_argument('--no-markers', action='store_true', help='publish_markers:=false')
    parser.add_argument('--predict', type=float, default=0.0, metavar='SECONDS',
                        help='prediction_horizon (0: off, the default; 0.3 for the goal)')
    parser.add_argument('--period', type=float, default=0.0, metavar='SECONDS',
                        help='prediction_period (0: every frame, the default)')
    parser.add_argument('--model', choices=('linear', 'rigid', 'spline', 'c2'),
                        default=DEFAULTS['model'], help=f"motion model ({DEFAULTS['model']})")
    parser.add_argument('--look-ahead', type=int, default=0, help='c2 look_ahead (0)')
    parser.add_argument('--tracker-noise', type=float, metavar='METRES', default=None,
                        help="the node's tracker_noise (m; -1: auto; default: the node's, "
                        f"{DEFAULTS['tracker_noise']:g})")
    parser.add_argument('--consumers', action='store_true',
                        help='the listener also subscribes to ~/predicted_impact and '
                        '~/impact_report (an arm controller and a recorder)')
    parser.add_argument('--no-freeze', action='store_true',
                        help='the node process does not freeze its start-up objects out of the '
                        'garbage collector (as impact_node does: node.freeze_start_up)')
    parser.add_argument('--fifo', type=int, metavar='PRIORITY', default=0,
                        help="run the node's process under SCHED_FIFO at this priority (chrt -f; "
                        'a real-time deployment; needs the right to)')
    parser.add_argument('--breakdown', action='store_true',
                        help="split the predicting messages' CPU time into phases")
    parser.add_argument('--in-process', type=int, metavar='RUNS', default=0,
                        help='feed the node in this process, no DDS: CPU per message, least '
                        'of RUNS runs')
    parser.add_argument('--idle', type=float, metavar='US', default=0.0,
                        help='with --in-process: sleep US microseconds before each message')
    parser.add_argument('--startup', type=int, metavar='RUNS', default=0,
                        help='only time the start-up, over RUNS runs')
    args = parser.parse_args(argv)
    if args.startup:
        startup(args.startup)
        return 0
    if args.in_process:
        in_process(args.in_process, args.pitches, args.rate, args.predict, args.period,
                   args.model, not args.no_freeze, args.look_ahead, args.tracker_noise,
                   args.idle * 1e-6)
        return 0
    run(args.pitches, args.rate, args.qos, not args.no_markers, args.predict, args.period,
        args.model, args.look_ahead, args.breakdown, args.consumers, not args.no_freeze,
        args.fifo, args.tracker_noise)
    return 0


if __name__ == '__main__':
    sys.exit(main())
