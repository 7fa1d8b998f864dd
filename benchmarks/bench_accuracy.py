"""
Accuracy benchmark: every motion model against continuous-time truth, per tracker rate.

Run: ``.venv/bin/python benchmarks/bench_accuracy.py [--per-kind N] [--seed S]``.

Scenarios: N of each kind (barrel, end-cap and handle hits, foul-tip grazes, clean misses over
and under) from ``simulation.make_scenario``: rigid swings about moving hands with an
accelerating angular speed, pitches with gravity and drag, exact first contact by dense
evaluation. Each is sampled at 90, 120, 240 and 360 Hz with 0.2 ms timestamp jitter on a 1 ms
stamp grid (uneven steps, as real mocap), bat as a pose, and run through a fresh detector per
model. ``linear`` is the seed's chord model (solved exactly). The last rows add 1 mm of
position noise, and show the spline with ``velocity_degree: 3``, the setting for a noisy
low-rate tracker. Prints a Markdown table for BENCHMARKS.md.
"""

import argparse
import time

from baseball_collision.core.detector import DetectorConfig
from baseball_collision.tools.accuracy import run_scenario, summarize
from baseball_collision.tools.sim import KINDS, make_scenario
import numpy as np

COLUMNS = (
    ('recall', '{:.3f}'), ('precision', '{:.3f}'), ('time_error_us_p50', '{:.1f}'),
    ('time_error_us_p99', '{:.1f}'), ('time_error_us_max', '{:.1f}'),
    ('location_error_mm_p99', '{:.2f}'), ('location_error_mm_max', '{:.2f}'),
    ('sweet_spot_speed_error_pct_p99', '{:.2f}'), ('sweet_spot_speed_error_pct_max', '{:.2f}'))


def main() -> None:
    """Print the accuracy table."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--per-kind', type=int, default=30)
    parser.add_argument('--seed', type=int, default=7)
    args = parser.parse_args()
    started = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    scenarios = [make_scenario(kind, rng) for kind in KINDS for _ in range(args.per_kind)]
    contacts = sum(s.truth.contact for s in scenarios)
    print(f'{len(scenarios)} scenarios ({contacts} contacts), seed {args.seed}\n')
    print('| rate Hz | noise mm | model | recall | precision | time err p50 us | p99 us | '
          'max us | spot err p99 mm | max mm | sweet-spot speed err p99 % | max % |')
    print('|---|---|---|---|---|---|---|---|---|---|---|---|')
    cases = [(rate, 0.0) for rate in (90, 120, 240, 360)] + [(90, 1e-3), (360, 1e-3)]
    models = [('linear', 5), ('rigid', 5), ('spline', 5)]
    for rate, noise in cases:
        for model, degree in models + ([('spline', 3)] if noise else []):
            config = DetectorConfig(model=model, velocity_degree=degree)
            results = [run_scenario(s, rate, config, np.random.default_rng(i), jitter_s=2e-4,
                                    grid_s=1e-3, noise_m=noise)[1]
                       for i, s in enumerate(scenarios)]
            summary = summarize(results)
            cells = [fmt.format(summary[key]) for key, fmt in COLUMNS]
            label = model if degree == 5 else f'{model} (velocity_degree {degree})'
            print(f'| {rate} | {noise * 1e3:g} | {label} | ' + ' | '.join(cells) + ' |')
    print(f'\n({time.perf_counter() - started:.0f} s)')


if __name__ == '__main__':
    main()
