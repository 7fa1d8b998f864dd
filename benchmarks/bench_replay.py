"""
Replay pacing benchmark: what waiting for acknowledgements costs, and what it buys.

Run: ``.venv/bin/python benchmarks/bench_replay.py [--count 30] [--rate 30] [--qos reliable_all]``.

A dense bag (``simulate --count N --spacing 0.45 --bat pose --seed 4``: 360 Hz, ball and bat
pose) is replayed by :class:`~baseball_collision.ros.replay.BagPlayer` at ``--rate`` into a real
``impact_node`` process (``--qos``: ``reliable_all`` keeps every message; ``reliable`` keeps the
newest ``qos_depth``, 100 by default), twice in the same process against the same node:

* paced: the player as shipped (after ``depth // 2`` messages of a topic it waits for the
  subscribers' acknowledgements, so its keep-last queue never overwrites an unreceived message);
* baseline: no wait during the playback (one at the end), as before.

Printed per run: wall time of the playback, acknowledgement waits and their time, messages the
node received (its ``/diagnostics``: ``<stream>_received`` after it caught up) and estimated
lost (``<stream>_lost``), and the paced/baseline time ratio.
"""

import argparse
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import threading
import time
from typing import Dict, List, Optional, Tuple

from baseball_collision.ros.listener import RosSession
from baseball_collision.ros.replay import BagPlayer
from baseball_collision.tools.demo import (
    bundled, DEMO_PARAMS, isolated_environment, node_command, stop_node, wait_for_node)
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.qos import QoSProfile, ReliabilityPolicy

STREAMS = ('ball', 'bat_pose')


def make_bag(folder: Path, count: int) -> Tuple[Path, int]:
    """Simulate the dense bag; return it and its message count."""
    bag = folder / 'dense.mcap'
    script = Path(sys.executable).parent / 'baseball-collision'
    done = subprocess.run([str(script), 'simulate', str(bag), '--count', str(count),
                           '--spacing', '0.45', '--bat', 'pose', '--seed', '4'],
                          capture_output=True, text=True, check=True)
    messages = int(done.stdout.split('messages')[0].split(':')[-1].replace(',', '').strip())
    return bag, messages


def node_counts(statuses: List[Dict[str, str]], settle_s: float = 3.0,
                limit_s: float = 300.0) -> Dict[str, int]:
    """Wait until the node's received counts stop changing; return received and lost."""
    last: Optional[Tuple[int, ...]] = None
    since = time.monotonic()
    deadline = since + limit_s
    while time.monotonic() < deadline:
        time.sleep(0.2)
        status = statuses[-1] if statuses else {}
        now = tuple(int(status.get(f'{s}_received', 0)) for s in STREAMS)
        if now != last:
            last, since = now, time.monotonic()
        elif time.monotonic() - since >= settle_s:
            break
    status = statuses[-1] if statuses else {}
    return {'received': sum(int(status.get(f'{s}_received', 0)) for s in STREAMS),
            'lost': sum(int(status.get(f'{s}_lost', 0)) for s in STREAMS)}


def main(argv: Optional[List[str]] = None) -> int:
    """Run the two replays against one node and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--count', type=int, default=30, help='pitches (30)')
    parser.add_argument('--rate', type=float, default=30.0, help='replay speed (30)')
    parser.add_argument('--qos', default='reliable_all', help="the node's qos (reliable_all)")
    args = parser.parse_args(argv)
    env = isolated_environment()
    os.environ.update({k: env[k] for k in ('ROS_DOMAIN_ID', 'ROS_AUTOMATIC_DISCOVERY_RANGE')})
    with tempfile.TemporaryDirectory() as folder:
        bag, messages = make_bag(Path(folder), args.count)
        command = node_command(bundled(DEMO_PARAMS))
        command = command[:command.index('--params-file') + 2] + [
            '-p', f'qos:={args.qos}', '-p', 'diagnostics_period:=0.5']  # no sim time
        process = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        figures = []
        try:
            with RosSession('bench_replay') as session:
                statuses: List[Dict[str, str]] = []
                lock = threading.Lock()

                def on_status(array: DiagnosticArray) -> None:
                    with lock:
                        statuses.extend({kv.key: kv.value for kv in status.values}
                                        for status in array.status
                                        if status.name.startswith('impact_node'))
                session.node.create_subscription(
                    DiagnosticArray, '/diagnostics', on_status,
                    QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
                for name in ('paced', 'baseline'):
                    before = node_counts(statuses, settle_s=1.0)
                    with BagPlayer(session.node, bag, rate=args.rate, clock_hz=0.0) as player:
                        problem = wait_for_node(process, player, ['/ball', '/bat_pose'],
                                                lambda: bool(statuses), 60.0)
                        if problem:
                            print(problem)
                            return 1
                        if name == 'baseline':
                            player.window = 10**12  # no wait during the playback
                        result = player.play()
                    after = node_counts(statuses)
                    figures.append((name, result, after['received'] - before['received'],
                                    after['lost'] - before['lost']))
        finally:
            stop_node(process)
    print(f'replay of {messages:,} messages ({args.count} pitches, 360 Hz, ball + bat pose) at '
          f'{args.rate:g}x into impact_node (qos {args.qos})')
    for name, result, received, lost in figures:
        print(f'  {name:<8}: playback {result.seconds:6.2f} s, {result.ack_waits} '
              f'acknowledgement waits ({result.ack_wait_s:.2f} s, {result.ack_timeouts} timed '
              f'out), published {result.messages:,}; node received {received:,} '
              f'({messages - received:,} missing), estimated lost {lost:,}')
    paced, baseline = figures[0][1].seconds, figures[1][1].seconds
    print(f'  pacing cost: paced / baseline playback time = {paced / baseline:.2f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
