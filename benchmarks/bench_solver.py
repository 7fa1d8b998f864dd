"""
Solver benchmark: scalar time_of_impact against the seed's method, and batch throughput.

Run: ``.venv/bin/python benchmarks/bench_solver.py [--cases N] [--seed S]``.

Cases are swing-like intervals at 90-360 Hz: a bat turning about the hands, and a pitched ball
aimed near it (about half of them make contact). Every method runs on the same cases in the same
process; the figures are medians over the cases of the per-query time.
"""

import argparse
import math
import time
from typing import List, Tuple

from baseball_collision.core.toi import seed_time_of_impact, time_of_impact, time_of_impact_batch
import numpy as np


def generate_cases(count: int, seed: int) -> List[Tuple]:
    """Return ``count`` intervals (ball0, ball1, tip0, tip1, knob0, knob1, rb, rt, dt)."""
    rng = np.random.default_rng(seed)
    cases = []
    for _ in range(count):
        dt = 1.0 / rng.choice([90.0, 120.0, 240.0, 360.0])
        omega = rng.uniform(20.0, 45.0)  # rad/s
        angle0 = rng.uniform(-math.pi, math.pi)
        length = 0.8636
        hands0 = rng.normal(0.0, 0.05, 3)
        hands1 = hands0 + rng.normal(0.0, 2.0, 3) * dt
        direction0 = np.array([math.cos(angle0), math.sin(angle0), 0.0])
        angle1 = angle0 + omega * dt
        direction1 = np.array([math.cos(angle1), math.sin(angle1), 0.0])
        knob0, knob1 = hands0, hands1
        tip0, tip1 = hands0 + length * direction0, hands1 + length * direction1
        aim = knob0 + rng.uniform(0.3, 1.05) * (tip1 - knob0) + rng.normal(0.0, 0.05, 3)
        velocity = rng.normal(0.0, 1.0, 3)
        velocity *= rng.uniform(30.0, 45.0) / np.linalg.norm(velocity)
        ball0 = aim - velocity * dt * rng.uniform(0.2, 0.8)
        ball1 = ball0 + velocity * dt
        cases.append((ball0, ball1, tip0, tip1, knob0, knob1, 0.0366, 0.0331, dt))
    return cases


def per_query_median_us(function, cases: List[Tuple], repeats: int = 3) -> float:
    """Median over cases of the best-of-``repeats`` time of one call, in microseconds."""
    samples = []
    clock = time.perf_counter
    for case in cases:
        best = math.inf
        for _ in range(repeats):
            start = clock()
            function(*case)
            best = min(best, clock() - start)
        samples.append(best)
    return float(np.median(samples) * 1e6)


def main() -> None:
    """Print the solver figures for BENCHMARKS.md."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0].strip())
    parser.add_argument('--cases', type=int, default=20000)
    parser.add_argument('--seed', type=int, default=1)
    args = parser.parse_args()
    cases = generate_cases(args.cases, args.seed)
    # warm up both paths
    for case in cases[:200]:
        time_of_impact(*case)
        seed_time_of_impact(*case)
    exact_us = per_query_median_us(time_of_impact, cases)
    seed_us = per_query_median_us(seed_time_of_impact, cases)
    contacts = sum(time_of_impact(*case) is not None for case in cases)
    columns = [np.array([case[i] for case in cases]) for i in range(6)]
    dts = np.array([case[8] for case in cases])
    best = math.inf
    for _ in range(5):
        start = time.perf_counter()
        batch = time_of_impact_batch(*columns, 0.0366, 0.0331, dts)
        best = min(best, time.perf_counter() - start)
    print(f'cases: {len(cases)} (contacts: {contacts}, batch agrees on contact: '
          f'{int(np.count_nonzero(~np.isnan(batch)))})')
    print(f'time_of_impact        median {exact_us:8.2f} us/query')
    print(f'seed_time_of_impact   median {seed_us:8.2f} us/query')
    print(f'ratio seed/exact      {seed_us / exact_us:8.2f}x')
    print(f'time_of_impact_batch  {len(cases) / best:12,.0f} queries/s (best of 5)')


if __name__ == '__main__':
    main()
