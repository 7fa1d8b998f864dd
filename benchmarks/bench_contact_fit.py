"""
Contact-aware fits: the bat's sweet-spot velocity at a contact, with a break at the contact.

Run: ``.venv/bin/python benchmarks/bench_contact_fit.py [--per-kind N] [--rates R ...]
[--noises MM ...] [--families F ...] [--after N ...] [--poly D/N ...]``.

Issue 11's idea, measured before wiring it into the detector: at the true first contact t*
of each simulated hit (barrel, end-cap and handle hits, ``--per-kind`` of each, every swing
family, 0.2 ms stamp jitter on a 1 ms grid, the bat as knob and tip markers with the noise per
coordinate), the bat's ``c2`` chart rows (knob, rotation vector, length: ``c2_rows``) are
fitted over the window the detector would use (8 samples up to the last one at or before t*,
with noise reaching 0.09 s back, up to 32) plus N samples after t*, and the sweet spot's
velocity at t* is read from:

* ``left``: the not-a-knot spline through the samples up to t* (smoothed with the noise:
  ``fitting.SMOOTHER``), its last cubic continued to t*: what the detector's ``c2`` does today
  (``kinematics.c2_velocities``, the window fits ending at the interval's opening frame);
* ``break+N``: ``motion.broken.broken_fit``, the fit broken at t* with N samples after it,
  the left-limit rate (N < 4 leaves the right side free: the same as ``break+1``);
* ``across+N``: the not-a-knot spline (smoothed with the noise) through the same samples and N
  after t*, without a break, its rate at t*: crossing the contact (the rule forbids it; the
  whole-stream ``reference`` of bench_accuracy does this);
* ``poly D/N`` (``--poly D/N ...``): a least-squares polynomial of degree D through the last N
  samples up to t*, its rate at t* (a fit that averages noise without a spline).

Prints Markdown rows: per family, rate and noise, the sweet-spot speed error p50 / p99 (%) and
the sweet spot's position error at t* p99 (mm) of each fit, and the median cost of the broken
fits at one contact (the three column groups, the largest N; CPU time), and per rate the CPU
cost of ``kinematics.knot_bat_rates`` (bench_accuracy's ``c2-knot``) against the default rule's
continued path, in the same process. No detector runs here: the impact instant is the
truth, so the figures are the fits' own.
"""

import argparse
import time
from typing import Dict, List, Optional, Sequence, Tuple

from baseball_collision.core.bat import SWEET_SPOT_FROM_TIP
from baseball_collision.core.detector.fitting import (
    bat_variances, c2_bat_path, c2_window, NOISE_SPAN, SMOOTHER, swing_rate)
from baseball_collision.core.detector.kinematics import knot_bat_rates
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample, c2_rows, end_state, not_a_knot_slopes
from baseball_collision.core.motion import rotate, unit_axis
from baseball_collision.core.motion.broken import broken_fit
from baseball_collision.core.motion.smoothing import smooth
from baseball_collision.threads import single_threaded_blas
from baseball_collision.tools.sim import FAMILIES, make_scenario, sample
import numpy as np

GROUPS = (slice(0, 3), slice(3, 6), slice(6, 7))
"""The chart rows' column groups sharing a smoothing weight: knob, rotation vector, length."""


def sweet_state(reference: Sequence[float], row: np.ndarray, rate: np.ndarray,
                reach: float) -> Tuple[np.ndarray, np.ndarray]:
    """Return the sweet spot's position (m) and velocity (m/s) from a chart row and its rate."""
    turn, turning = row[3:6], rate[3:6]
    direction = np.array(rotate(tuple(reference), tuple(turn.tolist())))
    speed = float(np.linalg.norm(turning))
    bending = np.zeros(3)
    if speed > 0.0:
        step = 1e-4 / speed
        ahead = rotate(tuple(reference), tuple((turn + step * turning).tolist()))
        behind = rotate(tuple(reference), tuple((turn - step * turning).tolist()))
        bending = (np.array(ahead) - np.array(behind)) / (2.0 * step)
    return row[:3] + reach * direction, rate[:3] + reach * bending


def _smoothed(times: np.ndarray, rows: np.ndarray, variances: Sequence[float],
              noisy: bool) -> Tuple[np.ndarray, np.ndarray]:
    """Return the window's (values, slopes): smoothed per column group, or interpolated."""
    if not noisy:
        return rows, not_a_knot_slopes(times, rows)
    values, slopes = np.empty_like(rows), np.empty_like(rows)
    for group in GROUPS:
        values[:, group], slopes[:, group] = smooth(times, rows[:, group], variances[group],
                                                    *SMOOTHER)
    return values, slopes


def _true_sweet(scenario, t: float, reach: float) -> Tuple[np.ndarray, np.ndarray]:
    """Return the sweet spot's true position (m) and velocity (m/s, central difference)."""
    def at(time_s: float) -> np.ndarray:
        knob, tip = (np.asarray(end, dtype=float) for end in scenario.swing.knob_tip(time_s))
        return knob + reach * (tip - knob) / float(np.linalg.norm(tip - knob))
    step = 1e-7
    return at(t), (at(t + step) - at(t - step)) / (2.0 * step)


def fits_at_contact(scenario, samples, noise_m: float, after: Sequence[int],
                    poly: Sequence[Tuple[int, int]] = (),
                    costs: Optional[List[float]] = None,
                    diagnose: bool = False) -> Dict[str, Tuple[float, float]]:
    """
    Return each fit's (relative speed error, position error in m) at the true contact.

    :param poly: (degree, samples) of the least-squares polynomials to try (degree = samples
        - 1: the interpolating polynomial).
    :param diagnose: also ``left@last`` (left's spline at its last sample, against the truth
        there), ``cartesian`` (the sweet spot's points splined, no chart) and ``truth-fd``
        (the truth's central difference at t* against the scenario's sweet-spot speed).
    :param costs: where to append the CPU time (s) of the broken fits with the most samples.
    """
    t = (samples.bat_stamps_ns - samples.start_ns) * 1e-9
    bats = [BatSample(tuple(k), tuple(e)) for k, e in zip(samples.knobs.tolist(),
                                                          samples.tips.tolist())]
    length = float(np.mean(np.linalg.norm(samples.tips - samples.knobs, axis=1)))
    reach = length - SWEET_SPOT_FROM_TIP
    contact = scenario.truth.time_s
    knob, tip = (np.asarray(end, dtype=float) for end in scenario.swing.knob_tip(contact))
    true_sweet = knob + reach * (tip - knob) / float(np.linalg.norm(tip - knob))
    true_speed = scenario.truth.sweet_spot_speed_mps
    j = int(np.searchsorted(t, contact, side='right')) - 1
    first = j - 7
    while noise_m and first > 0 and t[j] - t[first - 1] <= NOISE_SPAN and j - first < 31:
        first -= 1
    first = max(first, 0)
    variances = np.asarray(bat_variances(bats[j], noise_m))
    reference = unit_axis(bats[j])
    found: Dict[str, Tuple[float, float]] = {}

    def score(label: str, row: np.ndarray, rate: np.ndarray) -> None:
        position, velocity = sweet_state(reference, row, rate, reach)
        found[label] = (float(np.linalg.norm(velocity)) / true_speed - 1.0,
                        float(np.linalg.norm(position - true_sweet)))

    def window(count: int) -> Tuple[np.ndarray, np.ndarray]:
        start, rows = c2_rows(bats[first:j + 1 + count], j - first)
        return t[first + start:first + start + len(rows)], np.asarray(rows, dtype=float)

    times, rows = window(1)
    values, _ = _smoothed(times[:-1], rows[:-1], variances, noise_m > 0.0)
    score('left', *end_state(times[:-1], values, contact))
    if diagnose:
        # where left's error comes from: the same spline read at its last sample (no
        # extrapolation) against the truth there; the sweet spot's own points splined in
        # Cartesian coordinates (no direction chart) and continued to t*
        last = float(times[-2])
        position, velocity = sweet_state(reference, *end_state(times[:-1], values, last), reach)
        truth_at = _true_sweet(scenario, last, reach)
        found['left@last'] = (float(np.linalg.norm(velocity) / np.linalg.norm(truth_at[1]))
                              - 1.0, float(np.linalg.norm(position - truth_at[0])))
        spots = samples.knobs + reach * ((samples.tips - samples.knobs) / np.linalg.norm(
            samples.tips - samples.knobs, axis=1)[:, None])
        point, rate = end_state(t[first:j + 1], spots[first:j + 1], contact)
        found['cartesian'] = (float(np.linalg.norm(rate)) / true_speed - 1.0,
                              float(np.linalg.norm(point - true_sweet)))
        truth_at = _true_sweet(scenario, contact, reach)
        found['truth-fd'] = (float(np.linalg.norm(truth_at[1])) / true_speed - 1.0,
                             float(np.linalg.norm(truth_at[0] - true_sweet)))
    for degree, count in poly:
        start, rows = c2_rows(bats[max(j - count + 1, 0):j + 1], min(j, count - 1))
        times = t[j + 1 - len(rows):j + 1]
        vandermonde = np.vander(times - contact, min(degree, len(times) - 1) + 1,
                                increasing=True)
        coefficients = np.linalg.lstsq(vandermonde, np.asarray(rows), rcond=None)[0]
        score(f'poly {degree}/{count}', coefficients[0], coefficients[1])
    for count in after:
        times, rows = window(count)
        started = time.process_time()
        ends = [broken_fit(times, rows[:, group], variances[group], contact, SMOOTHER[1])
                for group in GROUPS]
        if costs is not None and count == max(after):
            costs.append(time.process_time() - started)
        score(f'break+{count}', np.concatenate([e[1][-1] for e in ends]),
              np.concatenate([e[2][-1] for e in ends]))
        values, slopes = _smoothed(times, rows, variances, noise_m > 0.0)
        m = int(np.searchsorted(times, contact, side='right')) - 1
        h = times[m + 1] - times[m]
        s = (contact - times[m]) / h
        row = ((2 * s ** 3 - 3 * s ** 2 + 1) * values[m]
               + (s ** 3 - 2 * s ** 2 + s) * h * slopes[m]
               + (3 * s ** 2 - 2 * s ** 3) * values[m + 1] + (s ** 3 - s ** 2) * h * slopes[m + 1])
        rate = ((6 * s * s - 6 * s) * (values[m] - values[m + 1]) / h
                + (3 * s * s - 4 * s + 1) * slopes[m] + (3 * s * s - 2 * s) * slopes[m + 1])
        score(f'across+{count}', row, rate)
    return found


def velocity_costs(samples, contact: float) -> Tuple[float, float]:
    """
    Return the CPU time (s, best of 5) of two exact-sample bat velocity rules of the detector.

    ``kinematics.knot_bat_rates`` (the window up to the opening frame fitted with a knot at
    the contact) and the default (``c2_velocities``' 'before'): that window's ``c2`` path
    (``fitting.c2_bat_path``) continued to the contact, its knob rate and ``swing_rate``.
    """
    stream = Stream('bat')
    for i, (stamp, knob, tip) in enumerate(zip(samples.bat_stamps_ns.tolist(),
                                               samples.knobs.tolist(), samples.tips.tolist())):
        stream.append((stamp - samples.start_ns) * 1e-9, stamp, BatSample(tuple(knob),
                                                                          tuple(tip)), i == 0)
    k = stream.interval(contact)
    window = c2_window(stream, k - 1, 0.05, 0, 8)

    def knot() -> None:
        knot_bat_rates(stream, window, contact)

    def before() -> None:
        path = c2_bat_path(stream, k - 1, window)
        path.knob.velocity(contact), swing_rate(path, contact)

    best = []
    for run in (knot, before):
        times = []
        for _ in range(5):
            started = time.process_time()
            run()
            times.append(time.process_time() - started)
        best.append(min(times))
    return best[0], best[1]


def main() -> None:
    """Print one Markdown row per family, rate and noise."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--per-kind', type=int, default=4)
    parser.add_argument('--seed', type=int, default=7)
    parser.add_argument('--families', nargs='+', default=list(FAMILIES), choices=FAMILIES)
    parser.add_argument('--rates', nargs='+', type=float, default=[90.0, 360.0])
    parser.add_argument('--noises', nargs='+', type=float, default=[0.0, 1.0, 2.0])
    parser.add_argument('--after', nargs='+', type=int, default=[1, 4, 6])
    parser.add_argument('--poly', nargs='*', default=[], metavar='D/N',
                        help='least-squares polynomials: degree / samples up to the contact')
    parser.add_argument('--diagnose', action='store_true',
                        help="also left@last, cartesian and truth-fd (where left's error is)")
    args = parser.parse_args()
    single_threaded_blas()  # as the node and analyze run the detector (threads.py)
    poly = [tuple(int(x) for x in item.split('/')) for item in args.poly]
    started = time.perf_counter()
    labels = (['left'] + (['left@last', 'cartesian', 'truth-fd'] if args.diagnose else [])
              + [f'poly {d}/{n}' for d, n in poly]
              + [f'{kind}+{n}' for n in args.after for kind in ('break', 'across')])
    costs: List[float] = []
    rules: Dict[float, List[Tuple[float, float]]] = {}
    print('| family | Hz | noise mm | contacts | ' + ' | '.join(labels) + ' |')
    print('|' + '---|' * (4 + len(labels)))
    for family in args.families:
        rng = np.random.default_rng(args.seed)
        scenarios = [make_scenario(kind, rng, family=family)
                     for kind in ('barrel', 'end_cap', 'handle') for _ in range(args.per_kind)]
        scenarios = [s for s in scenarios if s.truth.contact]
        for rate in args.rates:
            for noise_mm in args.noises:
                errors: Dict[str, List[Tuple[float, float]]] = {}
                for i, scenario in enumerate(scenarios):
                    samples = sample(scenario, rate, np.random.default_rng(i), jitter_s=2e-4,
                                     grid_s=1e-3, noise_m=noise_mm * 1e-3,
                                     marker_spread_m=0.3 if noise_mm else None)
                    for label, error in fits_at_contact(scenario, samples, noise_mm * 1e-3,
                                                        args.after, poly, costs,
                                                        args.diagnose).items():
                        errors.setdefault(label, []).append(error)
                    if noise_mm == 0.0:
                        rules.setdefault(rate, []).append(
                            velocity_costs(samples, scenario.truth.time_s))
                cells = []
                for label in labels:
                    speed = np.abs([e[0] for e in errors[label]]) * 100.0
                    place = np.array([e[1] for e in errors[label]]) * 1e3
                    cells.append(f'{np.percentile(speed, 50):.2f} / '
                                 f'{np.percentile(speed, 99):.2f} % / '
                                 f'{np.percentile(place, 99):.2f} mm')
                print(f'| {family} | {rate:g} | {noise_mm:g} | {len(scenarios)} | '
                      + ' | '.join(cells) + ' |', flush=True)
    print(f'\nbroken fit at one contact (3 column groups, {max(args.after)} samples after): '
          f'median {np.median(costs) * 1e3:.2f} ms CPU over {len(costs)} contacts')
    for rate, pairs in rules.items():
        knot, before = np.median(np.array(pairs), axis=0)
        print(f'{rate:g} Hz, exact: knot_bat_rates {knot * 1e3:.2f} ms CPU per impact (median), '
              f'the default continued path {before * 1e3:.2f} ms: {knot / before:.2f}x')
    print(f'({time.perf_counter() - started:.0f} s)')


if __name__ == '__main__':
    main()
