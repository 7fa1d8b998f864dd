"""
impact_node intake: the highest message rate it takes in without loss, beside a bare subscriber.

Run: ``.venv/bin/python benchmarks/bench_intake.py [--rates 500,1000,1500] [--seconds 5]
[--kinds bare,node,plain]`` (``BENCH_INTAKE_PROFILE=FILE``: the subscriber's cProfile to FILE).

The load is the fault benchmark's stale-publisher phase: per rate R, three publishers send at R
each (the ball, a second ball publisher stamped 3 s behind, whose samples the node drops as
``stale_stamp``, and the bat pose), reliable QoS, keep last 1000 at both ends, so 3R messages
per second in all. Each kind of subscriber runs in turn in its own child process (this file with
``--serve KIND``) for ``--seconds`` per rate:

* ``bare``: an rclpy node with the same three subscriptions whose callbacks only count (the
  ceiling rclpy itself allows on this machine);
* ``node``: ``ImpactNode`` under rclpy's ``SingleThreadedExecutor`` (as ``impact_node``
  spins it);
* ``plain``: the same without the intake's round-robin take (one message per executor
  callback, as before it; drop warnings throttled cheaply in both);
* ``events``: ``ImpactNode`` under ``rclpy.experimental.EventsExecutor`` (rclpy 7.1: fails on
  the first message, ``SystemError: null argument to internal routine``, as it does for any
  callback that takes the message info, which the node needs for the sequence numbers; and its
  ``spin`` cannot be stopped from another thread: printed as a failure, not measured).

Printed per rate and kind: messages published, received (the subscriber's own count) and lost,
the callbacks' CPU share and the received fraction against the bare subscriber's in the same run;
then per kind the highest rate with no loss. Wall-clock figures of this machine: run it on a
quiet machine for the numbers, or say how loaded it was.
"""

import argparse
import json
import os
from pathlib import Path
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from typing import Dict, List, Optional

from geometry_msgs.msg import PointStamped, PoseStamped
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_node import ball, BASE_NS, PAUSE_S, set_swing_pose, SWING_S  # noqa: E402, I100

STALE_NS = 3_000_000_000
"""How far behind the second ball publisher stamps its messages (as in the fault benchmark)."""

KINDS = ('bare', 'node', 'plain', 'events')

_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                  reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)


# ----------------------------------------------------------------------------------------------
# the subscriber process


def serve(kind: str) -> int:
    """Run one kind of subscriber until SIGINT; print what it received as JSON."""
    rclpy.init(args=sys.argv, signal_handler_options=SignalHandlerOptions.NO)
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    counts: Dict[str, int] = {'ball': 0, 'bat_pose': 0}
    if kind == 'bare':
        node = rclpy.create_node('impact_node')

        def count(stream: str):  # noqa: ANN202
            def callback(message: object) -> None:
                counts[stream] += 1
            return callback
        node.create_subscription(PointStamped, 'ball', count('ball'), _QOS)
        node.create_subscription(PoseStamped, 'bat_pose', count('bat_pose'), _QOS)
    else:
        from baseball_collision.ros.node import ImpactNode
        node = ImpactNode()
        if kind == 'plain':
            node._intake._limit = 0  # the executor alone takes the messages
    if kind == 'events':
        from rclpy.experimental import EventsExecutor
        executor = EventsExecutor()
    else:
        executor = SingleThreadedExecutor()
    executor.add_node(node)
    cpu = time.process_time()
    print('ready', flush=True)
    profile = None
    if os.environ.get('BENCH_INTAKE_PROFILE'):
        import cProfile
        profile = cProfile.Profile()
        profile.enable()
    while not stop.is_set():  # the soak harness's loop: EventsExecutor.spin cannot be stopped
        executor.spin_once(timeout_sec=0.1)  # from another thread (it hangs), spin_once can
    if profile is not None:
        profile.disable()
        profile.dump_stats(os.environ['BENCH_INTAKE_PROFILE'])
    cpu = time.process_time() - cpu
    if kind != 'bare':
        counts = dict(node.tally.arrivals)
        counts['dropped'] = dict(node.detector.stats.dropped)
    counts['cpu_s'] = cpu
    print(json.dumps(counts), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


# ----------------------------------------------------------------------------------------------
# the publishing process


def _environment() -> Dict[str, str]:
    """Return the children's environment: one random domain unless set, host-only discovery."""
    os.environ.pop('RMW_IMPLEMENTATION', None)
    os.environ.setdefault('ROS_DOMAIN_ID', str(random.SystemRandom().randint(1, 101)))
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return dict(os.environ)


def measure(node: object, kind: str, rate: float, seconds: float,
            publishers: tuple) -> Dict[str, object]:
    """Start one subscriber, publish ``seconds`` at ``rate`` per publisher, return its counts."""
    log = tempfile.TemporaryFile('w+')
    child = subprocess.Popen(
        [sys.executable, __file__, '--serve', kind, '--ros-args', '-p', 'qos:=reliable',
         '-p', 'qos_depth:=1000', '-p', 'publish_markers:=false'],
        env=_environment(), stdout=subprocess.PIPE, stderr=log, text=True)
    try:
        if child.stdout.readline().strip() != 'ready':
            raise RuntimeError(f'the {kind} subscriber did not start')
        ball_pub, stale_pub, bat_pub = publishers
        deadline = time.monotonic() + 30.0
        while ball_pub.get_subscription_count() < 1 or bat_pub.get_subscription_count() < 1:
            if time.monotonic() > deadline:
                raise RuntimeError(f'the {kind} subscriber did not match')
            time.sleep(0.05)
        time.sleep(1.0)
        sent = _publish(rate, seconds, publishers)
        time.sleep(2.0)  # the tail
    finally:
        child.send_signal(signal.SIGINT)
        out, _ = child.communicate(timeout=30)
    lines = out.strip().splitlines()
    if not lines:
        log.seek(0)
        raise RuntimeError(f'the {kind} subscriber printed nothing (exit code '
                           f'{child.returncode}); its log ended:\n' + log.read()[-2000:])
    figures = json.loads(lines[-1])
    figures['sent'] = sent
    return figures


def _publish(rate: float, seconds: float, publishers: tuple) -> Dict[str, int]:
    """Publish pitches at ``rate`` per publisher for ``seconds``; return messages sent."""
    ball_pub, stale_pub, bat_pub = publishers
    step_ns = int(round(1e9 / rate))
    per_pitch = int(SWING_S * rate)
    frames = int(seconds * rate)
    ball_msg, stale_msg, bat_msg = PointStamped(), PointStamped(), PoseStamped()
    for message in (ball_msg, stale_msg, bat_msg):
        message.header.frame_id = 'world'
    start = time.monotonic_ns()
    for n in range(frames):
        k, i = divmod(n, per_pitch)
        wait = start + n * step_ns - time.monotonic_ns()
        if wait > 0:
            time.sleep(wait * 1e-9)
        stamp = BASE_NS + k * (per_pitch * step_ns + int(PAUSE_S * 1e9)) + i * step_ns
        t = i * step_ns * 1e-9
        ball_msg.header.stamp.sec, ball_msg.header.stamp.nanosec = divmod(stamp, 10**9)
        bat_msg.header.stamp = ball_msg.header.stamp
        stale_msg.header.stamp.sec, stale_msg.header.stamp.nanosec = divmod(stamp - STALE_NS,
                                                                            10**9)
        p = ball_msg.point
        p.x, p.y, p.z = ball(t)
        stale_msg.point = ball_msg.point
        set_swing_pose(bat_msg, t)
        ball_pub.publish(ball_msg)
        stale_pub.publish(stale_msg)
        bat_pub.publish(bat_msg)
    elapsed = (time.monotonic_ns() - start) * 1e-9
    return {'ball': 2 * frames, 'bat_pose': frames, 'seconds': elapsed}


def run(rates: List[float], seconds: float, kinds: List[str]) -> None:
    """Measure every kind at every rate; print the table and each kind's lossless rate."""
    _environment()
    rclpy.init()
    node = rclpy.create_node('bench_intake_publisher')
    publishers = (node.create_publisher(PointStamped, 'ball', _QOS),
                  node.create_publisher(PointStamped, 'ball', _QOS),
                  node.create_publisher(PoseStamped, 'bat_pose', _QOS))
    print(f'intake: 3 publishers (ball, a ball publisher {STALE_NS / 1e9:.0f} s behind, bat '
          f'pose) at R each, reliable keep-last 1000, {seconds:.0f} s per run; '
          f'load average {os.getloadavg()[0]:.1f} at the start', flush=True)
    lossless: Dict[str, float] = {}
    for rate in rates:
        bare_received: Optional[int] = None
        for kind in kinds:
            try:
                figures = measure(node, kind, rate, seconds, publishers)
            except RuntimeError as error:
                print(f'  R {rate:6.0f} Hz {kind:>6}: failed: {str(error).splitlines()[-1]}')
                continue
            sent = figures['sent']
            total = sent['ball'] + sent['bat_pose']
            received = figures.get('ball', 0) + figures.get('bat_pose', 0)
            if kind == 'bare':
                bare_received = received
            lost = total - received
            if lost <= 0:
                lossless[kind] = max(lossless.get(kind, 0.0), rate)
            ratio = f', {received / bare_received:.3f} of bare' if bare_received else ''
            cpu_us = figures['cpu_s'] / max(received, 1) * 1e6
            print(f'  R {rate:6.0f} Hz ({3 * rate:.0f} msg/s) {kind:>6}: sent {total} in '
                  f"{sent['seconds']:.2f} s, received {received}, lost {lost} "
                  f'({lost / total:.1%}){ratio}; CPU {cpu_us:.0f} us '
                  f'per message received; load average {os.getloadavg()[0]:.1f}', flush=True)
    for kind in kinds:
        best = lossless.get(kind)
        print(f'  {kind}: highest rate without loss '
              + (f'R {best:.0f} Hz ({3 * best:.0f} msg/s)' if best else 'none of those tried'))
    node.destroy_node()
    rclpy.try_shutdown()


def main(argv: Optional[List[str]] = None) -> int:
    """Parse the command line and run the benchmark (or a child: --serve KIND)."""
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == '--serve':
        return serve(argv[1])
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--rates', default='500,1000,1500',
                        help='rates per publisher, Hz, comma-separated (500,1000,1500)')
    parser.add_argument('--seconds', type=float, default=5.0, help='per run (5)')
    parser.add_argument('--kinds', default='bare,node,plain',
                        help=f"comma-separated, of {', '.join(KINDS)} (bare,node,plain)")
    args = parser.parse_args(argv)
    kinds = args.kinds.split(',')
    if set(kinds) - set(KINDS):
        parser.error(f'--kinds: one of {KINDS}')
    run([float(r) for r in args.rates.split(',')], args.seconds, kinds)
    return 0


if __name__ == '__main__':
    sys.exit(main())
