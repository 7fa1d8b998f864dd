"""
The sweet-spot speed and its error bar when the bat's last frames before the contact are lost.

A marker occluded at the contact, samples dropped in transit: the speed is then carried from
the last bat frame over more than a step. Exact samples (the offline default: ``c2``,
look-ahead 2, auto noise), barrel hits of every family, the bat's last 0, 1 and 2 frames
before the true contact removed; prints the speed error (p50, p99) and how often it is within
1 and 2 of its sigmas.

    .venv/bin/python benchmarks/bench_lost_frames.py [--rates 90 120 360] [--seeds 8]
"""

import argparse
from typing import Any, List

from baseball_collision.core.detector import Detector, DetectorConfig, Impact
from baseball_collision.tools.parameters import OFFLINE_PARAMETERS
from baseball_collision.tools.sim import FAMILIES, make_scenario, sample
import numpy as np


def impacts_of(config: DetectorConfig, samples: Any) -> List[Impact]:
    """Return the impacts a fresh detector finds in ``samples`` (``sim.sample``)."""
    detector, events = Detector(config), []
    for stamp, role, values in samples.messages(config.bat_input):
        events += detector.add(role, stamp, values)
    events += detector.finish()
    return [event for event in events if isinstance(event, Impact)]


def main() -> None:
    """Print one line per rate and frames lost."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--rates', type=float, nargs='+', default=[90.0, 120.0, 360.0])
    parser.add_argument('--seeds', type=int, default=8, help='scenarios per family (8)')
    args = parser.parse_args()
    config = DetectorConfig(**OFFLINE_PARAMETERS)
    for rate in args.rates:
        for lost in (0, 1, 2):
            errors, ratios = [], []
            for family in FAMILIES:
                for seed in range(args.seeds):
                    rng = np.random.default_rng(seed)
                    scenario = make_scenario('barrel', rng, family=family)
                    samples = sample(scenario, rate, rng, jitter_s=2e-4, grid_s=1e-3)
                    contact_ns = samples.start_ns + int(scenario.truth.time_s * 1e9)
                    impacts = impacts_of(config, samples.without_bat_frames(contact_ns, lost))
                    if len(impacts) != 1:
                        continue
                    impact, truth = impacts[0], scenario.truth.sweet_spot_speed_mps
                    error = abs(impact.sweet_spot_speed_mps - truth)
                    errors.append(error / truth)
                    ratios.append(error / max(impact.sweet_spot_speed_uncertainty_mps, 1e-12))
            ratio = np.array(ratios)
            p50, p99 = (np.percentile(errors, q) * 100 for q in (50, 99))
            print(f'{rate:g} Hz, {lost} bat frames lost: {len(ratio)} impacts, speed error p50 '
                  f'{p50:.2f} % p99 {p99:.2f} %; within 1 / 2 sigma {np.mean(ratio <= 1):.2f} / '
                  f'{np.mean(ratio <= 2):.2f}')


if __name__ == '__main__':
    main()
