"""
``analyze --decimate``: how far a bag's impacts move at lower rates, against the truth.

Run: ``.venv/bin/python benchmarks/bench_rates.py [BAG:K[,K] ...]`` (default: the bundled bags,
360 Hz at 2 and 4, the noisy 240 Hz at 2 and 3, the 180 Hz rebound, 120 and 90 Hz at 2).

``--decimate K`` analyses a bag again keeping every K-th frame of each input, from each of its
K phases, and reports how far each impact moved from the recorded rate's (``rates``): on a
real rig, with no truth, the lower rate's error where the recorded rate's own is much smaller.
On a bundled bag this prints beside those moves (p50 / p99 of their size, and their mean:
positive later) the lower-rate analyses' own instant errors against the truth file and the
recorded rate's largest, so the claim can be checked; and the shares of moves within 1 and 2
combined sigmas (both answers' 1-sigma uncertainties) for the instant, the spot and the
sweet-spot speed.
"""

import json
from pathlib import Path
import sys
from typing import List, Sequence, Tuple

from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag
import numpy as np

BAGS = Path(__file__).resolve().parent.parent / 'bags'

DEFAULT = (('pitches_360hz.mcap', (2, 4)), ('pitches_240hz_noisy.bag', (2, 3)),
           ('pitches_180hz_rebound.mcap', (2,)), ('pitches_120hz_sqlite3', (2,)),
           ('pitches_90hz.mcap', (2,)))


def truth_errors_us(stamps: Sequence[int], truth: Sequence[int]) -> List[float]:
    """Return each stamp's distance (us) from the nearest true contact instant."""
    return [min(abs(s - t) for t in truth) / 1e3 for s in stamps]


def row(name: str, factors: Tuple[int, ...]) -> List[str]:
    """Return the table rows of one bag, a factor each."""
    bag = BAGS / name
    recorded = analyze_bag(bag, AnalysisOptions(decimate=factors), progress=False)
    truth_file = BAGS / (name.split('.')[0] + '.truth.json')
    truth = [p['stamp_ns'] for p in json.loads(truth_file.read_text())['pitches']
             if p['contact']]
    recorded_max = max(truth_errors_us([i.stamp_ns for i in recorded.impacts], truth))
    rows = []
    for check in recorded.rates:
        lower: List[float] = []
        for phase in range(check.every):
            analysis = analyze_bag(bag, AnalysisOptions(every=check.every, phase=phase),
                                   progress=False, use_truth=False)
            lower += truth_errors_us([i.stamp_ns for i in analysis.impacts], truth)
        s = check.summary()
        within = [s[f'within_{k}_sigma'] for k in (1, 2)]
        shares = ' | '.join(
            f'{within[0][key] * 100:.0f} / {within[1][key] * 100:.0f} %'
            for key in ('time_s', 'distance_from_knob_m', 'sweet_spot_speed'))
        rows.append(
            f'| {name} | {check.every} | {check.found} of {check.compared}, {check.extra} more | '
            f"{s['time_s']['p50'] * 1e6:.1f} / {s['time_s']['p99'] * 1e6:.1f} "
            f"({s['time_s']['mean'] * 1e6:+.1f}) | {np.percentile(lower, 50):.1f} / "
            f'{np.percentile(lower, 99):.1f} | {recorded_max:.1f} | '
            f"{s['distance_from_knob_m']['p99'] * 1e3:.2f} | "
            f"{s['sweet_spot_speed']['p99'] * 100:.2f} | {shares} |")
    return rows


def main(argv: Sequence[str]) -> int:
    """Print the table (markdown) for the bags given as BAG:K[,K], else the defaults."""
    chosen = [(text.split(':')[0], tuple(int(k) for k in text.split(':')[1].split(',')))
              for text in argv] or DEFAULT
    print('| bag | K | impacts found again | instant moved p50 / p99 us (mean) | lower rate '
          "against truth p50 / p99 us | recorded rate's largest us | spot moved p99 mm | "
          'speed moved p99 % | within 1 / 2 sigma: instant | spot | speed |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for name, factors in chosen:
        for line in row(name, factors):
            print(line)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
