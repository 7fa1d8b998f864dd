"""
What one log line costs the node's thread: rclpy's logger against ``ros.logger.DirectLogger``.

Run: ``.venv/bin/python benchmarks/bench_logger.py [--lines N] [--depth D] [--rounds R]``.

Both hand the same line to the same rcutils call; rclpy's ``RcutilsLogger`` first finds its
caller with ``inspect.getframeinfo`` (which reads the source file's lines) on each frame from its
own up to the caller's. The lines are an impact's INFO line (``describe_impact``'s length),
logged by a node's logger (each line also a ``/rosout`` record, as the node's) from ``D``
nested calls (an executor callback's depth), stderr sent to /dev/null (the console's own write
is in both). Each round times N lines with each logger in turn (the thread's
CPU clock and the wall clock); printed: the median and p90 per line over all rounds, and the
ratio of the medians (rclpy's / direct).
"""

import argparse
import os
import time
from typing import Callable, Dict, List

from baseball_collision.ros.logger import DirectLogger
import numpy as np
import rclpy
from rclpy.logging import get_logger
from rclpy.node import Node

LINE = ('impact at 1700000005.374344183 s: 2.0 cm from the tip (tip_end), sweet-spot speed '
        '30.6 m/s (68.4 mph), bat at contact 36.0 m/s (80.5 mph), ball 40.0 m/s (89.5 mph), '
        'attack angle -0.0 deg, closing speed 71.0 m/s, 0.344 ms into a 1.000 ms interval (c2); '
        '1 sigma: time 0.1 us, spot 0.00 cm, sweet-spot speed 0.00 m/s')
"""An impact's INFO line as the node logs it."""


def _nested(depth: int, call: Callable[[], object]) -> object:
    """Call ``call`` from ``depth`` nested frames."""
    return call() if depth <= 1 else _nested(depth - 1, call)


def _timed(log: Callable[[str], object], lines: int, depth: int) -> Dict[str, List[float]]:
    """Return the thread CPU and wall time (s) of each of ``lines`` lines."""
    cpu, wall = [], []
    for _ in range(lines):
        c0, w0 = time.thread_time(), time.perf_counter()
        _nested(depth, lambda: log(LINE))
        cpu.append(time.thread_time() - c0)
        wall.append(time.perf_counter() - w0)
    return {'cpu': cpu, 'wall': wall}


def main() -> None:
    """Time both loggers in turn and print their figures."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0].strip())
    parser.add_argument('--lines', type=int, default=200, help='lines per logger per round')
    parser.add_argument('--depth', type=int, default=8, help='nested calls above the line')
    parser.add_argument('--rounds', type=int, default=5)
    args = parser.parse_args()
    os.environ.pop('RMW_IMPLEMENTATION', None)
    rclpy.init()
    node = Node('bench_logger')  # its logger's lines go to /rosout too, as the node's
    name = node.get_logger().name
    loggers = {'rclpy': get_logger(name).info, 'direct': DirectLogger(name).info}
    figures: Dict[str, Dict[str, List[float]]] = {
        name: {'cpu': [], 'wall': []} for name in loggers}
    saved = os.dup(2)
    quiet = os.open(os.devnull, os.O_WRONLY)
    os.dup2(quiet, 2)
    try:
        for _ in range(args.rounds):
            for name, log in loggers.items():
                for clock, times in _timed(log, args.lines, args.depth).items():
                    figures[name][clock].extend(times)
    finally:
        os.dup2(saved, 2)
        os.close(quiet)
        os.close(saved)
        node.destroy_node()
        rclpy.shutdown()
    print(f'one INFO line ({len(LINE)} characters, {args.depth} calls deep, stderr to '
          f'/dev/null), {args.rounds} rounds of {args.lines} lines each, loggers in turn:')
    medians = {}
    for name, clocks in figures.items():
        cpu, wall = (np.array(clocks[c]) * 1e6 for c in ('cpu', 'wall'))
        medians[name] = float(np.median(cpu))
        print(f'  {name:7s} CPU median {np.median(cpu):7.1f} us, p90 {np.percentile(cpu, 90):7.1f}'
              f' us; wall median {np.median(wall):7.1f} us, p90 {np.percentile(wall, 90):7.1f} us')
    print(f"  rclpy's logger / direct (CPU medians): {medians['rclpy'] / medians['direct']:.1f}x")


if __name__ == '__main__':
    main()
