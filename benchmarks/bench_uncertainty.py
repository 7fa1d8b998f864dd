"""
Cost of an impact's uncertainties: the re-solves at each impact, against the whole pitch.

Run: ``.venv/bin/python benchmarks/bench_uncertainty.py [--rates R ...] [--noises MM ...]
[--models M ...] [--families F ...] [--spread DRAWS [--look-ahead N] [--auto] [--bat pose
[--origin M]]]``.

One barrel hit per swing family (``sim.FAMILIES``, or those given: ``rebound`` alone is the cost
at a hit, whose bat's brake takes two more re-solves), knob and tip points, 0.2 ms stamp jitter on
a 1 ms grid. Per rate, noise and model: the median over the impacts of the best of 5 timings
of ``uncertainty.impact_uncertainty`` (with noise: under ``c2`` the linear propagation, plus
one re-solve with a look-ahead; under the other models 16 re-solves; without noise one
re-solve), and the ratio to
the best of 3 timings of the detector over the whole pitch without it (the cost per message
when there is no impact is unchanged: the uncertainties are measured only at an impact).

``--spread DRAWS``: instead, whether the time's sigma is the spread of its errors. Per family,
a barrel, an end-cap and a handle hit, each sampled ``DRAWS`` times with fresh noise (the same
stamps' jitter drawn again with it), under ``c2`` (``--look-ahead``, told the noise or with
``--auto`` estimating it), the bat as knob and tip points or (``--bat pose``) a pose whose
origin is ``--origin`` m along the bat from the knob: the time error's mean and standard
deviation over the draws, the median sigma reported, and how often the error was within it
(a Monte Carlo: no truth but the simulator's, no percentile over unlike swings); the same for
the sweet-spot speed.
"""

import argparse
import time
from typing import Callable, List

from baseball_collision.core.bat import PoseBatGeometry, WOOD_BAT_34
from baseball_collision.core.detector import Detector, DetectorConfig, Impact
from baseball_collision.threads import single_threaded_blas
from baseball_collision.tools.accuracy import run_samples
from baseball_collision.tools.sim import FAMILIES, make_scenario, sample
import numpy as np


def _best(run: Callable[[], object], repeats: int) -> float:
    """Return the shortest wall time (s) of ``repeats`` runs."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return min(times)


def _pitch(config: DetectorConfig, messages: List, measured: bool) -> Detector:
    """Run a fresh detector over the messages; without its uncertainties unless measured."""
    detector = Detector(config)
    if not measured:
        detector._sweep.measure = None
    for stamp, role, values in messages:
        detector.add(role, stamp, values)
    detector.finish()
    return detector


def spread_rows(rates: List[float], noises: List[float], families: List[str], draws: int,
                look_ahead: int, auto: bool, bat: str = 'points', origin: float = 0.0) -> None:
    """Print, per family, rate, noise and hit, the time errors' spread against their sigma."""
    length = WOOD_BAT_34.length
    geometry = PoseBatGeometry(knob_offset=(0.0, 0.0, -origin),
                               tip_offset=(0.0, 0.0, length - origin))
    print('| family | Hz | noise mm | hit | time error mean / sd us | sigma median us | '
          'within 1 sigma | speed error mean / sd % | sigma median % | within 1 sigma |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    for family in families:
        rng = np.random.default_rng(7)
        scenarios = [(kind, make_scenario(kind, rng, family=family, geometry=geometry))
                     for kind in ('barrel', 'end_cap', 'handle')]
        for rate in rates:
            for noise_mm in noises:
                config = DetectorConfig(bat_input=bat, model='c2', look_ahead=look_ahead,
                                        tracker_noise=-1.0 if auto else noise_mm * 1e-3,
                                        geometry=geometry)
                for kind, scenario in scenarios:
                    rows = []  # per draw: time error, its sigma (us), speed error, sigma (%)
                    for draw in range(draws):
                        samples = sample(scenario, rate, np.random.default_rng(1000 + draw),
                                         jitter_s=2e-4, grid_s=1e-3, noise_m=noise_mm * 1e-3,
                                         marker_spread_m=0.3)
                        result = run_samples(scenario, samples, config)[1]
                        if result.detected and result.time_sigma_s is not None:
                            rows.append((result.time_error_s * 1e6, result.time_sigma_s * 1e6,
                                         result.sweet_spot_speed_error * 100.0,
                                         result.speed_sigma * 100.0))
                    cells = []
                    for error, sigma in np.array(rows).T.reshape(2, 2, -1):
                        cells.append(f'{error.mean():+.2f} / {error.std(ddof=1):.2f} | '
                                     f'{np.median(sigma):.2f} | '
                                     f'{np.mean(np.abs(error) <= sigma):.2f}')
                    print(f'| {family} | {rate:g} | {noise_mm:g} | {kind} | ' + ' | '.join(cells)
                          + ' |', flush=True)


def main() -> None:
    """Print one line per rate, noise and model (or with ``--spread``, the sigmas' check)."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--rates', nargs='+', type=float, default=[90.0, 360.0])
    parser.add_argument('--noises', nargs='+', type=float, default=[0.0, 1.0])
    parser.add_argument('--models', nargs='+', default=['rigid', 'c2'])
    parser.add_argument('--families', nargs='+', default=list(FAMILIES), choices=FAMILIES)
    parser.add_argument('--spread', type=int, default=0, metavar='DRAWS')
    parser.add_argument('--look-ahead', type=int, default=0, choices=(0, 1, 2))
    parser.add_argument('--auto', action='store_true')
    parser.add_argument('--bat', choices=('points', 'pose'), default='points')
    parser.add_argument('--origin', type=float, default=0.0, metavar='M',
                        help="the pose's origin along the bat from the knob (m)")
    args = parser.parse_args()
    single_threaded_blas()  # as the node and analyze run the detector (threads.py)
    if args.spread:
        spread_rows(args.rates, [n for n in args.noises if n > 0.0] or [1.0], args.families,
                    args.spread, args.look_ahead, args.auto, args.bat, args.origin)
        return
    for rate in args.rates:
        for noise_mm in args.noises:
            for model in args.models:
                config = DetectorConfig(bat_input='points', model=model,
                                        tracker_noise=noise_mm * 1e-3)
                costs, ratios = [], []
                for family in args.families:
                    i = FAMILIES.index(family)
                    scenario = make_scenario('barrel', np.random.default_rng(i), family=family)
                    samples = sample(scenario, rate, np.random.default_rng(i), jitter_s=2e-4,
                                     grid_s=1e-3, noise_m=noise_mm * 1e-3,
                                     marker_spread_m=0.3 if noise_mm else None)
                    messages = list(samples.messages('points'))
                    detector = Detector(config)
                    measure, found = detector._measure, []
                    detector._sweep.measure = lambda impact: found.append(impact) or impact
                    for stamp, role, values in messages:
                        detector.add(role, stamp, values)
                    detector.finish()
                    pitch = _best(lambda: _pitch(config, messages, False), 3)
                    for impact in found:
                        if isinstance(impact, Impact):
                            cost = _best(lambda: measure(impact), 5)
                            costs.append(cost)
                            ratios.append(cost / pitch)
                print(f'{rate:g} Hz, {noise_mm:g} mm, {model}: {len(costs)} impacts, '
                      f'uncertainties {np.median(costs) * 1e3:.2f} ms per impact (median), '
                      f'{np.median(ratios):.2f} x the whole pitch without them', flush=True)


if __name__ == '__main__':
    main()
