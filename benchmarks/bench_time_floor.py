"""
How close the impact time can come with tracking noise: the best local fits' floor.

Run: ``.venv/bin/python benchmarks/bench_time_floor.py [--per-kind N] [--rates R ...]
[--families F ...] [--noise MM] [--draws D] [--detector-draws D]``.

Issue 11 asks for the impact time within 45 us (p99) at 1 mm of noise per coordinate. On
``bench_accuracy.py``'s scenarios (knob and tip markers, each with its own noise), this prints
for each family and rate, over the deep contacts (barrel, end cap and handle hits), the p50 / p99
of |time error| of:

* the detector, ``c2`` with ``tracker_noise`` auto at look-ahead 0 (the node's default) and 2
  (``analyze``'s), over ``--detector-draws`` noise draws of each contact;
* an oracle of local fits: least-squares polynomials of the ball's centre (degree 1-3) and of
  the bat's axis point at the contact's place along it (degree 1-4, in ``c2``'s rigid chart,
  ``bench_speed_floor.fitted_speeds``' coordinates), each over the last W frames before the
  contact and up to 2 frames after it, evaluated at the contact instant. For each contact it
  picks the ball's and the bat's degree, window and frames after with the least rms error along
  the contact normal (knowing the truth; picked on one set of ``--draws`` draws, scored on
  another), and turns the two errors into a time error over the true closing speed along the
  normal (to first order). Frames after the contact only where they are unbent: the bat's where
  it does not brake (not ``braking`` or ``rebound``), the ball's where it flies on (not
  ``rebound``);

and the shallow contacts (grazes, ticks and shaves: the detector alone). There the gap closes
slowly, so a tenth of a millimetre moves the time by tens of microseconds and the first-order
error the oracle uses does not hold: it bounds nothing there.

Where the detector's deep-contact p99 is at the oracle's, no local fit of the same frames does
better on those contacts; where it is well above it, the detector leaves something a per-contact
choice of fit would find (which the samples alone may not show).
"""

import argparse
from typing import Dict, List, Tuple

from baseball_collision.core.detector import DetectorConfig
from baseball_collision.tools.accuracy import run_samples
from baseball_collision.tools.sim import FAMILIES, sample
from bench_speed_floor import bat_chart, family_scenarios, fit_rows, rotated
import numpy as np

DETECTORS = {
    'c2, look-ahead 0, auto': DetectorConfig(model='c2', look_ahead=0, tracker_noise=-1.0,
                                             bat_input='points'),
    'c2, look-ahead 2, auto': DetectorConfig(model='c2', look_ahead=2, tracker_noise=-1.0,
                                             bat_input='points'),
}
"""The node's default and ``analyze``'s, knob and tip points."""

DEEP = ('barrel', 'end_cap', 'handle')
"""The contact kinds whose time the first-order error holds for (tens of mm deep)."""

AFTER = (0, 1, 2)
"""The frames after the contact the oracle's fits may take where they are unbent."""

Fits = Dict[Tuple[int, int, int], np.ndarray]
"""(degree, frames before, frames after) -> one error (m, along the normal) per draw."""


def weights_at(times: np.ndarray, t: float, degree: int) -> np.ndarray:
    """Return the weights that give a least-squares polynomial's value at t from its samples."""
    return fit_rows(times, t, max(abs(times[0] - t), abs(times[-1] - t), 1e-9), degree)[0]


def axis_points(times: np.ndarray, knobs: np.ndarray, tips: np.ndarray, t: float, degree: int,
                fraction: float) -> np.ndarray:
    """
    Return the bat's axis point at ``fraction`` from knob to tip at t (s), one per draw (m).

    Least squares of ``degree`` in the bat's chart: the knob, and the rotation vector turning
    the window's last direction onto each; ``knobs``, ``tips``: (draws, frames, 3).
    """
    weights = weights_at(times, t, degree)
    lengths, reference, chart = bat_chart(knobs, tips)
    turn = np.einsum('w,mwc->mc', weights, chart)
    knob = np.einsum('w,mwc->mc', weights, knobs)
    return knob + rotated(turn, reference[:, 0, :]) * lengths.mean(axis=1) * fraction


def normal_errors(times: np.ndarray, t: float, truth: np.ndarray, normal: np.ndarray,
                  degrees: Tuple[int, ...], after: Tuple[int, ...],
                  estimate) -> Tuple[Fits, Fits]:
    """
    Return every fit's errors along the normal (m) over the picking and the scoring draws.

    :param times: the body's frame times (s); ``estimate(window, degree, draw_set)`` gives its
        estimates at t (draws, 3) from frames ``window``; ``after``: the frames after t allowed.
    """
    before = int(np.searchsorted(times, t))
    picked: Fits = {}
    scored: Fits = {}
    for degree in degrees:
        for later in after:
            stop = min(before + later, len(times))
            for frames in range(1, before + 1):
                window = slice(before - frames, stop)
                if stop - window.start < degree + 2:
                    continue
                key = (degree, frames, later)
                picked[key] = (estimate(window, degree, 0) - truth) @ normal
                scored[key] = (estimate(window, degree, 1) - truth) @ normal
    return picked, scored


def oracle_errors(scenario, family: str, exact, noise_m: float, draws: int,
                  rng: np.random.Generator) -> np.ndarray:
    """
    Return the oracle's time errors (s, one per scored draw) of a contact.

    :param family: the scenario's swing family (which bodies are unbent after the contact);
        ``exact``: its exact samples (the noisy ones' stamps).
    """
    truth = scenario.truth
    t, fraction = truth.time_s, truth.bat_fraction
    normal = np.asarray(truth.normal)
    closing = float(normal @ (scenario.pitch.velocity(np.array([t]))[0]
                              - scenario.swing.point_velocity(np.array([t]), fraction)[0]))
    ball_times = (exact.ball_stamps_ns - exact.start_ns) * 1e-9
    balls = np.asarray(exact.ball_positions)
    ball_noise = [rng.normal(0.0, noise_m, (draws,) + balls.shape) for _ in range(2)]
    bat_times = (exact.bat_stamps_ns - exact.start_ns) * 1e-9
    knobs, tips = np.asarray(exact.knobs), np.asarray(exact.tips)
    bat_noise = [rng.normal(0.0, noise_m, (draws, len(bat_times), 2, 3)) for _ in range(2)]

    def ball(window: slice, degree: int, draw_set: int) -> np.ndarray:
        noisy = balls[window][None] + ball_noise[draw_set][:, window]
        return np.einsum('w,mwc->mc', weights_at(ball_times[window], t, degree), noisy)

    def bat(window: slice, degree: int, draw_set: int) -> np.ndarray:
        noise = bat_noise[draw_set][:, window]
        return axis_points(bat_times[window], knobs[window][None] + noise[..., 0, :],
                           tips[window][None] + noise[..., 1, :], t, degree, fraction)

    fits = []
    for times, where, degrees, after, estimate in (
            (ball_times, scenario.pitch.position(np.array([t]))[0], (1, 2, 3),
             AFTER if family != 'rebound' else (0,), ball),
            (bat_times, scenario.swing.point(np.array([t]), fraction)[0], (1, 2, 3, 4),
             AFTER if family not in ('braking', 'rebound') else (0,), bat)):
        picked, scored = normal_errors(times, t, where, normal, degrees, after, estimate)
        best = min(picked, key=lambda key: float(np.mean(picked[key] ** 2)))
        fits.append(scored[best])
    return -(fits[0] - fits[1]) / closing


def main() -> None:
    """Print one row per family, rate and depth: the detectors and the oracle."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--per-kind', type=int, default=4)
    parser.add_argument('--seed', type=int, default=7)
    parser.add_argument('--rates', nargs='+', type=float, default=[90.0, 360.0])
    parser.add_argument('--families', nargs='+', default=list(FAMILIES), choices=FAMILIES)
    parser.add_argument('--noise', type=float, default=1.0, help='mm per coordinate')
    parser.add_argument('--draws', type=int, default=200,
                        help="noise draws a contact for each of the oracle's fits")
    parser.add_argument('--detector-draws', type=int, default=10,
                        help='noise draws a contact for the detectors')
    args = parser.parse_args()
    noise = args.noise * 1e-3
    print(f'{args.per_kind} scenarios of each kind per family, seed {args.seed}, {args.noise:g} '
          f'mm per coordinate; |time error| p50 / p99 (us)\n')
    print('| family | rate Hz | contacts | ' + ' | '.join(DETECTORS)
          + ' | oracle of local fits |')
    print('|---|---|---|' + '---|' * (len(DETECTORS) + 1))
    for family in args.families:
        scenarios = family_scenarios(family, args)
        for rate in args.rates:
            found: Dict[Tuple[str, bool], List[float]] = {}
            oracle: List[np.ndarray] = []
            for i, scenario in enumerate(scenarios):
                if not scenario.truth.contact:
                    continue
                deep = scenario.kind in DEEP
                for draw in range(args.detector_draws):
                    noisy = sample(scenario, rate, np.random.default_rng(i + 1000 * draw),
                                   jitter_s=2e-4, grid_s=1e-3, noise_m=noise,
                                   marker_spread_m=0.3)
                    for name, config in DETECTORS.items():
                        result = run_samples(scenario, noisy, config)[1]
                        if result.detected and result.time_error_s is not None:
                            found.setdefault((name, deep), []).append(
                                abs(result.time_error_s) * 1e6)
                if deep:
                    exact = sample(scenario, rate, np.random.default_rng(i), jitter_s=2e-4,
                                   grid_s=1e-3, noise_m=0.0, marker_spread_m=0.3)
                    oracle.append(np.abs(oracle_errors(
                        scenario, family, exact, noise, args.draws,
                        np.random.default_rng(2000 + i))) * 1e6)
            for deep in (True, False):
                cells = [found.get((name, deep), []) for name in DETECTORS]
                cells.append(np.concatenate(oracle) if deep and oracle else [])
                text = [f'{np.percentile(c, 50):.1f} / {np.percentile(c, 99):.1f}'
                        if len(c) else '-' for c in cells]
                print(f"| {family} | {rate:g} | {'deep' if deep else 'shallow'} | "
                      + ' | '.join(text) + ' |', flush=True)


if __name__ == '__main__':
    main()
