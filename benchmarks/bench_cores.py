"""
What two busy cores cost each process on this machine: the ceiling of ``analyze --jobs 2``.

Run: ``.venv/bin/python benchmarks/bench_cores.py [--messages N] [--rounds R]``.

Each work runs alone in one process, then in two processes at once (forked, nothing shared but
the machine), ``--rounds`` times: a pure-Python loop, a loop of small-array numpy operations
(the detector's kind of work), a memory-bound numpy loop (32 MB arrays), and ``analyze`` as a
whole process on a session bag (``bench_analyze.write_bag``, one pitch every 10 s). Printed: the
wall time alone, each process's wall time with both at once and its ratio to alone; for
``analyze`` the throughput of two at once against one (2.0: the two cores cost nothing).
"""

import argparse
import multiprocessing
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import time
from typing import Callable, Dict, List

from bench_analyze import write_bag
import numpy as np


def pure_python(n: int = 6_000_000) -> int:
    """Return an integer hash over n steps: interpreter work only."""
    x = 0
    for i in range(n):
        x = (x * 31 + i) & 0xFFFFFFFF
    return x


def small_arrays(n: int = 60_000) -> float:
    """Return a sum over n rounds of numpy calls on arrays of a few floats."""
    a = np.arange(7.0)
    total = 0.0
    for _ in range(n):
        total += float((np.take(a, [1, 3, 5]) * 1.5 + a[:3]).sum())
    return total


def memory_bound(n: int = 40) -> float:
    """Return a sum over n passes over a 32 MB array: memory bandwidth."""
    a = np.random.default_rng(0).random(4_000_000)
    return sum(float((a * 1.0001).sum()) for _ in range(n))


WORKS: Dict[str, Callable[[], object]] = {
    'pure Python': pure_python, 'small arrays': small_arrays, 'memory bound': memory_bound}


def _child(name: str, queue: 'multiprocessing.Queue[float]') -> None:
    start = time.perf_counter()
    WORKS[name]()
    queue.put(time.perf_counter() - start)


def at_once(name: str, count: int) -> List[float]:
    """Return the wall times (s) of ``count`` forked processes running one work at once."""
    queue: 'multiprocessing.Queue[float]' = multiprocessing.Queue()
    processes = [multiprocessing.Process(target=_child, args=(name, queue))
                 for _ in range(count)]
    for process in processes:
        process.start()
    times = [queue.get() for _ in processes]
    for process in processes:
        process.join()
    return times


def analyze_at_once(bag: Path, count: int) -> float:
    """Return the wall time (s) of ``count`` ``analyze`` processes on ``bag`` at once."""
    start = time.perf_counter()
    command = [sys.executable, '-m', 'baseball_collision.tools.cli', 'analyze', str(bag),
               '--quiet', '--no-progress', '--no-truth', '--jobs', '1']
    processes = [subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                 for _ in range(count)]
    for process in processes:
        process.wait()
    return time.perf_counter() - start


def main() -> None:
    """Print each work alone and two at once, per round."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--messages', type=int, default=250_000)
    parser.add_argument('--rounds', type=int, default=3)
    args = parser.parse_args()
    multiprocessing.set_start_method('fork')
    print(f'load average {os.getloadavg()[0]:.2f}; {os.cpu_count()} cores')
    for name in WORKS:
        for _ in range(args.rounds):
            (alone,), both = at_once(name, 1), at_once(name, 2)
            print(f'{name:13s} alone {alone:.3f} s; two at once ' + ', '.join(
                f'{t:.3f} s (x{t / alone:.2f})' for t in both), flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / 'session.mcap'
        written, _ = write_bag(bag, args.messages, 10.0)
        for _ in range(args.rounds):
            one, two = analyze_at_once(bag, 1), analyze_at_once(bag, 2)
            print(f'analyze ({written:,} messages, whole process) alone {one:.3f} s; two at once '
                  f'{two:.3f} s (x{two / one:.2f} a bag): {2.0 * one / two:.2f}x the throughput',
                  flush=True)


if __name__ == '__main__':
    main()
