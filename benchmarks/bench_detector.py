"""
Detector throughput: samples per second through the scalar path, per motion model.

Run: ``.venv/bin/python benchmarks/bench_detector.py [--pitches N] [--rate HZ]
[--per-message [--noise MM] [--predict HORIZON PERIOD]]``.

A session like a batting-practice recording: N simulated pitches (every kind), ball and bat
each tracked from 0.45 s before contact (about the release) to 0.2 s after, at 360 Hz with
0.2 ms stamp jitter, one pitch every 2 s; the bat as a pose and, separately, as knob and tip
points. Every sample
goes through ``Detector.add`` in stamp order, as the node and the bag tools feed it. The seed's
linear chord model is the baseline, run in the same process on the same samples.

``--per-message`` (with ``--rate 1000`` for the node's goal): instead, the CPU time of every
``Detector.add`` (thread CPU time, so time the process waited for a core under load does not
count) per model, bat as a pose: median, p99 and max, best of 3 passes for each figure; the
node's callback adds the message conversion and publishing to it, the same for every model.
``--noise MM`` puts tracking noise on the samples and ``--predict HORIZON PERIOD`` predicts as
the node does (its defaults: 0.3 0.01); the ``c2 auto`` row smooths (``tracker_noise`` -1).
"""

import argparse
import time
from typing import List, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, Impact
from baseball_collision.threads import single_threaded_blas
from baseball_collision.tools.sim import DEFAULT_START_NS, KINDS, make_scenario, sample
import numpy as np


def session(pitches: int, rate_hz: float, seed: int, bat: str,
            noise_m: float = 0.0) -> List[Tuple[int, str, tuple]]:
    """Return the messages (stamp_ns, role, values) of a session of ``pitches`` pitches."""
    rng = np.random.default_rng(seed)
    messages: List[Tuple[int, str, tuple]] = []
    for index in range(pitches):
        scenario = make_scenario(KINDS[index % len(KINDS)], rng, lead_s=0.45, trail_s=0.2)
        samples = sample(scenario, rate_hz, rng, jitter_s=2e-4, noise_m=noise_m,
                         start_ns=DEFAULT_START_NS + index * 2_000_000_000)
        messages += samples.messages(bat)
    return messages


def run(messages: List[Tuple[int, str, tuple]], model: str, bat: str) -> Tuple[float, int]:
    """Return (samples per second, impacts) of one pass through a fresh detector."""
    detector = Detector(DetectorConfig(model=model, bat_input=bat, tracker_noise=0.0))
    impacts = 0
    start = time.perf_counter()
    for stamp, role, values in messages:
        for event in detector.add(role, stamp, values):
            impacts += isinstance(event, Impact)
    for event in detector.finish():
        impacts += isinstance(event, Impact)
    return len(messages) / (time.perf_counter() - start), impacts


PER_MESSAGE_MODELS = {'rigid': {'model': 'rigid', 'tracker_noise': 0.0},
                      'spline': {'model': 'spline', 'tracker_noise': 0.0},
                      'c2': {'model': 'c2', 'tracker_noise': 0.0},
                      'c2 auto': {'model': 'c2', 'tracker_noise': -1.0}}
"""The per-message rows: the node's models, interpolating (``tracker_noise`` 0), and ``c2 auto``
(the node's default: ``tracker_noise`` -1, each stream's noise estimated and smoothed)."""


def per_message(messages: List[Tuple[int, str, tuple]], model: str,
                prediction: Tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """
    Return the CPU time (us) of every ``Detector.add`` of one pass through a fresh detector.

    :param model: a row of ``PER_MESSAGE_MODELS``; ``prediction``: (horizon, period) in s.
    """
    detector = Detector(DetectorConfig(bat_input='pose', prediction_horizon=prediction[0],
                                       prediction_period=prediction[1],
                                       **PER_MESSAGE_MODELS[model]))
    clock = time.thread_time
    spent = np.empty(len(messages))
    for index, (stamp, role, values) in enumerate(messages):
        start = clock()
        detector.add(role, stamp, values)
        spent[index] = clock() - start
    return spent * 1e6


def main() -> None:
    """Print samples per second per model and bat input, and the ratio to the seed model."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--pitches', type=int, default=60)
    parser.add_argument('--rate', type=float, default=360.0)
    parser.add_argument('--seed', type=int, default=3)
    parser.add_argument('--per-message', action='store_true',
                        help='CPU time per Detector.add per model instead (bat as a pose)')
    parser.add_argument('--noise', type=float, default=0.0, metavar='MM',
                        help='tracking noise on the samples (mm per coordinate; --per-message)')
    parser.add_argument('--predict', type=float, nargs=2, default=(0.0, 0.0),
                        metavar=('HORIZON', 'PERIOD'),
                        help='predict this far ahead at most this often (s; --per-message)')
    args = parser.parse_args()
    single_threaded_blas()  # as the node and analyze run the detector (threads.py)
    if args.per_message:
        messages = session(args.pitches, args.rate, args.seed, 'pose', args.noise * 1e-3)
        print(f'| model | CPU per Detector.add, {args.rate:.0f} Hz per stream, {len(messages)} '
              f'messages, {args.noise:g} mm, prediction {args.predict[0]:g} s every '
              f'{args.predict[1]:g} s: median us | p99 us | max us |')
        print('|---|---|---|---|')
        for model in PER_MESSAGE_MODELS:
            runs = [per_message(messages, model, args.predict) for _ in range(3)]
            median, p99, top = (min(float(f(run)) for run in runs) for f in (
                np.median, lambda run: np.percentile(run, 99), np.max))
            print(f'| {model} | {median:.1f} | {p99:.1f} | {top:.0f} |')
        return
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
