"""
Higher-order window fits for ``c2``'s exact samples: quintic slopes and the quintic spline.

Run: ``.venv/bin/python benchmarks/bench_window_order.py [--per-kind N] [--rates R ...]
[--noises MM ...] [--families F ...]``.

Issue 11 suggests a not-a-knot cubic or quintic spline. ``c2`` fits each exact window (8 samples
up to the interval's closing frame plus its look-ahead) with the not-a-knot cubic spline, a
cubic Hermite per piece. Measured here against it, before any change to the detector:

* ``hermite5``: the same cubic Hermite pieces with the slopes of the not-a-knot quintic spline
  through the window (the degree-5 spline whose knots are the stamps but the second and third
  from either end), which are O(h^5) off: a change of the slopes only;
* ``quintic``: that quintic spline itself (O(h^6) in position): a new kind of path.

Part 1, smooth functions: the largest error inside the interval with 2, 1 and 0 samples after
it (look-ahead 2, 1, 0) in a window of 8 even steps, as a ratio to the cubic spline's, at 90 to
720 samples a second (the asymptotic order shows as the step shrinks). Part 2, the simulator's
swings (``--per-kind`` of each contact kind per family, 0.2 ms jitter on a 1 ms grid, the bat as
knob and tip with the noise per coordinate, the window's rows as the detector charts them,
``c2_rows``): at the true contact instant t* the model's bat against the true ball, the gap
over the gap's rate there: a time error (us) p50 / p99, told the samples are exact. The
quintic is solved by B-spline collocation in numpy here (de Boor's recurrence, a dense solve),
the fits compared as fits, apart from the detector (which since session 36 takes the quintic for
exact windows with a sample after the interval: ``motion.splines.not_a_knot_quintic_rows``).
"""

import argparse
import math
from typing import Callable, Dict, List, Sequence, Tuple

from baseball_collision.core.motion import BatSample, c2_rows, not_a_knot_slopes, rotate
from baseball_collision.core.motion import unit_axis
from baseball_collision.tools.sim import CLOSE_KINDS, FAMILIES, KINDS, make_scenario, sample
from baseball_collision.tools.sim.truth import segment_gaps
import numpy as np

DEGREE = 5
METHODS = ('cubic', 'hermite5', 'quintic')


def _basis(knots: np.ndarray, x: np.ndarray, derivative: bool = False) -> np.ndarray:
    """Return the degree-5 B-splines (len(x), n) on ``knots`` at x (or their derivatives)."""
    x = np.atleast_1d(np.asarray(x, dtype=float))
    spans = np.flatnonzero(np.diff(knots) > 0)
    table = np.zeros((len(x), len(knots) - 1))
    index = np.clip(np.searchsorted(knots, x, side='right') - 1, spans[0], spans[-1])
    table[np.arange(len(x)), index] = 1.0
    for d in range(1, DEGREE + 1):
        grown = np.zeros((len(x), len(knots) - 1 - d))
        for i in range(len(knots) - 1 - d):
            left, right = knots[i + d] - knots[i], knots[i + d + 1] - knots[i + 1]
            if derivative and d == DEGREE:
                grown[:, i] = (d * table[:, i] / left if left > 0 else 0.0) - (
                    d * table[:, i + 1] / right if right > 0 else 0.0)
            else:
                grown[:, i] = ((x - knots[i]) / left * table[:, i] if left > 0 else 0.0) + (
                    (knots[i + d + 1] - x) / right * table[:, i + 1] if right > 0 else 0.0)
        table = grown
    return table


def quintic_spline(times: np.ndarray, values: np.ndarray) -> Callable:
    """
    Return f(t, derivative=False): the not-a-knot quintic spline through (times, values).

    Its knots are the stamps but times[1], times[2], times[-3] and times[-2] (six or more).
    """
    knots = np.r_[[times[0]] * (DEGREE + 1), times[3:len(times) - 3], [times[-1]] * (DEGREE + 1)]
    coefficients = np.linalg.solve(_basis(knots, times), values)
    return lambda t, derivative=False: _basis(knots, t, derivative) @ coefficients


def _hermite(t0: float, t1: float, y0: np.ndarray, y1: np.ndarray, m0: np.ndarray,
             m1: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Return the cubic Hermite (values y, slopes m at t0 and t1) at times t: (len(t), columns)."""
    h = t1 - t0
    s = ((np.atleast_1d(t) - t0) / h)[:, None]
    return ((2 * s ** 3 - 3 * s ** 2 + 1) * y0 + (3 * s ** 2 - 2 * s ** 3) * y1
            + h * ((s ** 3 - 2 * s ** 2 + s) * m0 + (s ** 3 - s ** 2) * m1))


def window_fit(method: str, times: np.ndarray, values: np.ndarray, k: int) -> Callable:
    """Return the fit of a window's values over its interval k: f(t) -> (len(t), columns)."""
    if method == 'quintic':
        return quintic_spline(times, values)
    slopes = (quintic_spline(times, values)(times, True) if method == 'hermite5'
              else not_a_knot_slopes(times, values))
    return lambda t: _hermite(times[k], times[k + 1], values[k], values[k + 1], slopes[k],
                              slopes[k + 1], t)


FUNCTIONS: Dict[str, Callable[[np.ndarray], np.ndarray]] = {
    'sin(40 t)': lambda t: np.sin(40.0 * t),
    'exp(5 t)': lambda t: np.exp(5.0 * t),
    'swing angle (erf)': lambda t: np.array([math.erf((x - 0.21) / 0.04 / math.sqrt(2.0))
                                             for x in np.atleast_1d(t)]),
    '1 / (1 + 100 (t - 0.2)^2)': lambda t: 1.0 / (1.0 + (10.0 * (t - 0.2)) ** 2),
}


def function_rows(rates: Sequence[float]) -> None:
    """Print part 1: each method's largest error in the interval over the cubic's."""
    columns = [f'{m} / cubic, look-ahead {a}' for a in (2, 1, 0) for m in METHODS[1:]]
    print('| function | Hz | ' + ' | '.join(columns) + ' |')
    print('|---|---|' + '---|' * 6)
    for name, function in FUNCTIONS.items():
        for rate in rates:
            cells = []
            for look_ahead in (2, 1, 0):
                k = 6 - look_ahead
                times = 0.2 + (np.arange(8) - k) / rate
                values = function(times)[:, None]
                inside = np.linspace(times[k], times[k + 1], 81)
                truth = function(inside)[:, None]
                errors = {method: np.abs(window_fit(method, times, values, k)(inside)
                                         - truth).max() for method in METHODS}
                cells += [f"{errors[m] / errors['cubic']:.3g}" for m in METHODS[1:]]
            print(f'| {name} | {rate:g} | ' + ' | '.join(cells) + ' |')


def _bat_at(method: str, times: np.ndarray, samples: List[BatSample], k: int,
            t: float) -> Tuple[np.ndarray, np.ndarray]:
    """Return the knob and tip at t from the window's chart rows (``c2_rows``) fitted."""
    first, rows = c2_rows(samples, k)
    values = np.array(rows)
    row = window_fit(method, times[first:first + len(rows)], values, k - first)(t)[0]
    knob = row[:3]
    direction = np.array(rotate(unit_axis(samples[k]), tuple(row[3:6].tolist())))
    return knob, knob + row[6] * direction


def _gap(scenario, knob: np.ndarray, tip: np.ndarray, t: float) -> float:
    """Return the gap (m) of the scenario's true ball at t to a bat from knob to tip."""
    return float(segment_gaps(scenario.pitch.position(np.array([t])), knob[None], tip[None],
                              scenario.profile, scenario.ball_radius).min(axis=0)[0])


def _true_gap(scenario, t: float) -> float:
    """Return the true gap (m) at t."""
    knob, tip = scenario.swing.knob_tip(np.array([t]))
    return _gap(scenario, knob[0], tip[0], t)


def swing_rows(families: Sequence[str], rates: Sequence[float], noises: Sequence[float],
               per_kind: int) -> None:
    """Print part 2: the time error at the true contact of each method, look-ahead 0 and 2."""
    print('| family | Hz | noise mm | look-ahead | ' + ' | '.join(
        f'{m} time err p50 / p99 us' for m in METHODS) + ' |')
    print('|---|---|---|---|' + '---|' * len(METHODS))
    for family in families:
        rng = np.random.default_rng(7)
        scenarios = [make_scenario(kind, rng, family=family, lead_s=0.15)
                     for kind in KINDS + CLOSE_KINDS for _ in range(per_kind)]
        for rate in rates:
            for noise_mm in noises:
                errors: Dict[Tuple[int, str], List[float]] = {}
                for index, scenario in enumerate(scenarios):
                    truth = scenario.truth
                    if not truth.contact:
                        continue
                    samples = sample(scenario, rate, np.random.default_rng(index), jitter_s=2e-4,
                                     grid_s=1e-3, noise_m=noise_mm * 1e-3,
                                     marker_spread_m=0.3 if noise_mm else None)
                    times = (samples.bat_stamps_ns - samples.start_ns) * 1e-9
                    bats = [BatSample(tuple(knob), tuple(tip))
                            for knob, tip in zip(samples.knobs.tolist(), samples.tips.tolist())]
                    contact = truth.time_s
                    j = int(np.searchsorted(times, contact)) - 1
                    step = 1e-7
                    rate_of_gap = (_true_gap(scenario, contact + step)
                                   - _true_gap(scenario, contact - step)) / (2 * step)
                    for look_ahead in (0, 2):
                        last = min(j + 1 + look_ahead, len(times) - 1)
                        first = max(0, last - 7)
                        window = times[first:last + 1]
                        for method in METHODS:
                            knob, tip = _bat_at(method, window, bats[first:last + 1],
                                                j - first, contact)
                            model_gap = _gap(scenario, knob, tip, contact)
                            errors.setdefault((look_ahead, method), []).append(
                                abs(model_gap / rate_of_gap) * 1e6)
                for look_ahead in (0, 2):
                    cells = [f'{np.percentile(errors[look_ahead, m], 50):.2f} / '
                             f'{np.percentile(errors[look_ahead, m], 99):.2f}' for m in METHODS]
                    print(f'| {family} | {rate:g} | {noise_mm:g} | {look_ahead} | '
                          + ' | '.join(cells) + ' |', flush=True)


def main() -> None:
    """Print both parts."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--per-kind', type=int, default=8)
    parser.add_argument('--rates', type=float, nargs='+', default=[90.0, 180.0, 360.0])
    parser.add_argument('--noises', type=float, nargs='+', default=[0.0, 0.3], help='mm')
    parser.add_argument('--families', nargs='+', choices=FAMILIES,
                        default=['plane', 'tilted', 'jerky', 'braking'])
    args = parser.parse_args()
    function_rows([90.0, 180.0, 360.0, 720.0])
    print()
    swing_rows(args.families, args.rates, args.noises, args.per_kind)


if __name__ == '__main__':
    main()
