"""
Every prediction the detector makes on ``bench_prediction``'s scenarios: the behaviour record.

``python test/support/prediction_record.py --write`` records the predictions of the first
``RECORDED_PER_KIND`` scenarios of each kind into ``prediction_record.json`` beside this file;
``test/core/test_prediction_record.py`` checks that the detector still makes exactly these
(stamps to the nanosecond, every float to the bit). ``--per-kind 20 --out FILE`` writes the
whole benchmark set, for a one-off comparison (``--compare FILE``). Re-record only for an
intended change of behaviour, and say so in the commit.
"""

import argparse
import json
from pathlib import Path
import sys
from typing import Any, Dict, List

from baseball_collision.core.detector import Detector, DetectorConfig, Prediction
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np

RECORD = Path(__file__).with_name('prediction_record.json')
RECORDED_PER_KIND = 1
KINDS = ('barrel', 'end_cap', 'handle')
RATES = (90.0, 360.0)


def _plan(scenario, start_ns: int, rate_hz: float = 200.0):
    """Return ``bench_prediction.plan_of``: the swing as a 200 Hz commanded plan."""
    times = np.arange(0.0, scenario.t_end, 1.0 / rate_hz)
    positions, quaternions = scenario.swing.pose(times)
    stamps = [start_ns + int(round(t * 1e9)) for t in times]
    return stamps, positions.tolist(), quaternions.tolist()


def _as_record(prediction: Prediction) -> List[Any]:
    """Return a prediction's fields as a JSON list (floats round-trip exactly)."""
    return [prediction.stamp_ns, prediction.made_at_ns, prediction.lead_s,
            list(prediction.point), list(prediction.normal), prediction.bat_fraction,
            prediction.distance_from_tip_m, list(prediction.ball_position),
            list(prediction.ball_velocity), prediction.planned, prediction.time_uncertainty_s,
            prediction.distance_from_tip_uncertainty_m]


def predictions(per_kind: int, seed: int = 11, noise_m: float = 0.001) -> Dict[str, List]:
    """
    Return {scenario key: its predictions} on ``bench_prediction``'s scenarios.

    The first ``per_kind`` of each kind (the benchmark draws them in the same order from
    ``seed``), each at 90 and 360 Hz, with the bat extrapolated and planned.
    """
    rng = np.random.default_rng(seed)
    scenarios = [make_scenario(kind, rng, lead_s=0.4) for kind in KINDS for _ in range(20)]
    chosen = [(i, s) for i, s in enumerate(scenarios) if i % 20 < per_kind]
    out = {}
    for planned in (False, True):
        for rate in RATES:
            for index, scenario in chosen:
                samples = sample(scenario, rate, np.random.default_rng(index), jitter_s=2e-4,
                                 noise_m=noise_m)
                detector = Detector(DetectorConfig(model='rigid', prediction_horizon=0.3))
                if planned:
                    detector.set_bat_plan(*_plan(scenario, samples.start_ns))
                made = []
                for stamp, role, values in samples.messages('pose'):
                    made += [_as_record(e) for e in detector.add(role, stamp, values)
                             if isinstance(e, Prediction)]
                out[f"{'planned' if planned else 'extrapolated'}/{rate:g}/{index}"] = made
    return out


def _largest(differ: List, field: int) -> float:
    """Return the largest difference of a vector field over pairs of predictions."""
    return max((float(np.max(np.abs(np.subtract(a[field], b[field])))) for _, a, b in differ),
               default=0.0)


def main() -> None:
    """Record, write or compare the predictions."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--write', action='store_true', help=f'record into {RECORD.name}')
    parser.add_argument('--per-kind', type=int, default=RECORDED_PER_KIND)
    parser.add_argument('--out', type=Path, help='write the predictions here')
    parser.add_argument('--compare', type=Path, help='compare with predictions written before')
    args = parser.parse_args()
    made = predictions(args.per_kind)
    count = sum(len(v) for v in made.values())
    if args.write:
        RECORD.write_text(json.dumps(made, indent=None, separators=(',', ':')) + '\n')
    if args.out:
        args.out.write_text(json.dumps(made))
    if args.compare:
        before = json.loads(args.compare.read_text())
        differ = [(key, a, b) for key in before for a, b in zip(before[key], made[key])
                  if a != b]
        lengths = [key for key in before if len(before[key]) != len(made[key])]
        worst_ns = max((abs(a[0] - b[0]) for _, a, b in differ), default=0)
        print(f'{count} predictions; {len(differ)} differ (largest stamp difference '
              f'{worst_ns} ns, point {_largest(differ, 3) * 1e9:.3g} nm, ball velocity '
              f'{_largest(differ, 8) * 1e9:.3g} nm/s); {len(lengths)} scenarios with a '
              'different count')
        sys.exit(1 if worst_ns or lengths else 0)
    print(f'{count} predictions in {len(made)} runs')


if __name__ == '__main__':
    main()
