"""
Detector throughput: samples per second through the scalar path, per motion model.

Run: ``.venv/bin/python benchmarks/bench_detector.py [--pitches N] [--rate HZ]``.

A session like a batting-practice recording: N simulated pitches (every kind), ball and bat
each tracked from 0.45 s before contact (about the release) to 0.2 s after, at 360 Hz with
0.2 ms stamp jitter, one pitch every 2 s; the bat as a pose and, separately, as knob and tip
points. Every sample
goes through ``Detector.add`` in stamp order, as the node and the bag tools feed it. The seed's
linear chord model is the baseline, run in the same process on the same samples.
"""

import argparse
import time
from typing import List, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, Impact
from baseball_collision.tools.sim import DEFAULT_START_NS, KINDS, make_scenario, sample
import numpy as np


def session(pitches: int, rate_hz: float, seed: int, bat: str) -> List[Tuple[int, str, tuple]]:
    """Return the messages (stamp_ns, role, values) of a session of ``pitches`` pitches."""
    rng = np.random.default_rng(seed)
    messages: List[Tuple[int, str, tuple]] = []
    for index in range(pitches):
        scenario = make_scenario(KINDS[index % len(KINDS)], rng, lead_s=0.45, trail_s=0.2)
        samples = sample(scenario, rate_hz, rng, jitter_s=2e-4,
                         start_ns=DEFAULT_START_NS + index * 2_000_000_000)
        messages += samples.messages(bat)
    return messages


def run(messages: List[Tuple[int, str, tuple]], model: str, bat: str) -> Tuple[float, int]:
    """Return (samples per second, impacts) of one pass through a fresh detector."""
    detector = Detector(DetectorConfig(model=model, bat_input=bat))
    impacts = 0
    start = time.perf_counter()
    for stamp, role, values in messages:
        for event in detector.add(role, stamp, values):
            impacts += isinstance(event, Impact)
    for event in detector.finish():
        impacts += isinstance(event, Impact)
    return len(messages) / (time.perf_counter() - start), impacts


def main() -> None:
    """Print samples per second per model and bat input, and the ratio to the seed model."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--pitches', type=int, default=60)
    parser.add_argument('--rate', type=float, default=360.0)
    parser.add_argument('--seed', type=int, default=3)
    args = parser.parse_args()
    print('| bat input | model | samples | samples/s (best of 3) | vs linear | impacts |')
    print('|---|---|---|---|---|---|')
    for bat in ('pose', 'points'):
        messages = session(args.pitches, args.rate, args.seed, bat)
        baseline = None
        for model in ('linear', 'rigid', 'spline'):
            rate, impacts = max(run(messages, model, bat) for _ in range(3))
            baseline = baseline or rate
            print(f'| {bat} | {model} | {len(messages)} | {rate:,.0f} | {rate / baseline:.2f} '
                  f'| {impacts} |')


if __name__ == '__main__':
    main()
