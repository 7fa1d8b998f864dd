"""
Noise error budget: impact errors pooled over swing families, with noise on the ball, bat or both.

Run: ``.venv/bin/python benchmarks/bench_noise_budget.py [--rate HZ] [--noise MM]
[--per-kind N] [--families F ...] [--noise-on both|ball|bat] [--methods M ...]``.

The scenarios, samples and methods of ``bench_accuracy.py`` (its runner, seed 7, 0.2 ms stamp
jitter on a 1 ms grid, the bat as knob and tip markers), pooled over the families so that a
p95 or p99 rests on a hundred contacts or more; ``--noise-on`` keeps the noise to one body
(``sim.sample``: the other exact, each body's draws the same as with both). Prints, per method,
the time (us), spot (mm) and sweet-spot speed (%) errors' p50 / p90 / p95 / p99 / rms over
every matched contact, how often the time and spot errors stayed within one and two reported
sigmas, and the time and spot statistics again over the contacts every method found (a method
that finds more of the closest calls is not charged for their ill-conditioned times).
"""

import argparse
from typing import Dict, List, Sequence, Tuple

from baseball_collision.tools.sim import (
    CLOSE_KINDS, FAMILIES, KINDS, make_scenario, NOISE_ON, sample)
from bench_accuracy import _runner, METHODS
import numpy as np


def _stats(values: Sequence[float]) -> str:
    """Return 'p50 / p90 / p95 / p99 / rms' of absolute values, '-' for none."""
    v = np.abs(np.asarray(values, dtype=float))
    if not len(v):
        return '-'
    digits = 1 if v.max() >= 50 else 2
    figures = (*np.percentile(v, [50, 90, 95, 99]), float(np.sqrt(np.mean(v * v))))
    return ' / '.join(f'{x:.{digits}f}' for x in figures)


def _share(flags: Sequence[bool]) -> str:
    """Return the fraction of true flags, 'nan' for none."""
    return f'{np.mean(flags):.2f}' if len(flags) else 'nan'


def run(rate: float, noise_mm: float, per_kind: int, families: Sequence[str], noise_on: str,
        methods: Sequence[str]) -> Dict[str, Dict[Tuple[str, int], Tuple]]:
    """Print the pooled tables; return per method {(family, scenario index): errors}."""
    found: Dict[str, Dict[Tuple[str, int], Tuple]] = {m: {} for m in methods}
    for family in families:
        rng = np.random.default_rng(7)
        scenarios = [make_scenario(kind, rng, family=family)
                     for kind in KINDS + CLOSE_KINDS for _ in range(per_kind)]
        samples = [sample(s, rate, np.random.default_rng(i), jitter_s=2e-4, grid_s=1e-3,
                          noise_m=noise_mm * 1e-3, marker_spread_m=0.3 if noise_mm else None,
                          noise_on=noise_on) for i, s in enumerate(scenarios)]
        for label in methods:
            score = _runner(label, 'points', noise_mm * 1e-3)
            for i, (scenario, taken) in enumerate(zip(scenarios, samples)):
                r = score(scenario, taken)
                if r.contact and r.detected:
                    found[label][family, i] = (
                        r.time_error_s * 1e6, r.location_error_m * 1e3,
                        r.sweet_spot_speed_error * 100.0,
                        None if r.time_sigma_s is None else (
                            abs(r.time_error_s) / r.time_sigma_s,
                            abs(r.knob_distance_error_m) / r.location_sigma_m))
    print(f'{rate:g} Hz, {noise_mm:g} mm on {noise_on}, {per_kind} per kind, pooled over '
          f'{" ".join(families)}\n')
    print('| method | contacts | time us | spot mm | speed % | time 1s / 2s | spot 1s / 2s |')
    print('|---|---|---|---|---|---|---|')
    for label, rows in found.items():
        errors = list(rows.values())
        ratios = [e[3] for e in errors if e[3] is not None]
        cells = [_stats([e[k] for e in errors]) for k in range(3)]
        print(f'| {label} | {len(errors)} | ' + ' | '.join(cells)
              + f' | {_share([t <= 1 for t, _ in ratios])} / {_share([t <= 2 for t, _ in ratios])}'
              + f' | {_share([s <= 1 for _, s in ratios])} / {_share([s <= 2 for _, s in ratios])}'
              + ' |')
    common: List = sorted(set.intersection(*(set(rows) for rows in found.values())))
    print(f'\nthe {len(common)} contacts every method found:\n')
    print('| method | time us | spot mm |')
    print('|---|---|---|')
    for label, rows in found.items():
        print(f'| {label} | {_stats([rows[k][0] for k in common])} | '
              f'{_stats([rows[k][1] for k in common])} |')
    return found


def main() -> None:
    """Print the pooled error tables."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--rate', type=float, default=90.0)
    parser.add_argument('--noise', type=float, default=1.0, help='mm per coordinate')
    parser.add_argument('--per-kind', type=int, default=6)
    parser.add_argument('--families', nargs='+', default=['plane', 'tilted', 'jerky', 'lefty'],
                        choices=FAMILIES)
    parser.add_argument('--noise-on', choices=NOISE_ON, default='both')
    parser.add_argument('--methods', nargs='+', default=['c2-smoother-auto', 'c2-auto'],
                        choices=list(METHODS) + ['reference', 'reference-interp'])
    args = parser.parse_args()
    run(args.rate, args.noise, args.per_kind, args.families, args.noise_on, args.methods)


if __name__ == '__main__':
    main()
