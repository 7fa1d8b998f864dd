"""
Accuracy benchmark: motion models against continuous-time truth, per family, rate and noise.

Run: ``.venv/bin/python benchmarks/bench_accuracy.py [--quick] [--per-kind N] [--seed S]
[--families F ...] [--rates R ...] [--noises MM ...] [--methods M ...] [--bat points|pose]
[--noise-on both|ball|bat] [--shared-noise] [--lead S] [--ball-dropout FRAMES] [--ball-rate HZ]
[--pooled] [--worst N]``.

Scenarios: N of each kind (barrel, end-cap and handle hits, 1-10 mm grazes, misses over and
under, and the closest calls: contacts 0.1-1 mm deep and misses by 0.1-2 mm) for every swing
family (``sim.FAMILIES``: today's fixed plane, a tilting plane, jerky hands and angular jerk,
left-handed, braking after contact, and a real hit: braking, the ball leaving the bat), pitches
with gravity and drag, exact first contact by dense evaluation. Each is sampled at each rate
with 0.2 ms stamp jitter on a 1 ms stamp grid (uneven steps, as real mocap), and at each noise
level per coordinate (the ball; the bat as knob and tip markers with their own noise, or as a
pose with that position noise and noise / 0.3 m rad of orientation noise: a rigid-body solve
over markers 0.3 m apart); ``--noise-on`` keeps the noise to the ball or the bat (the other
exact, each body's draws the same as with both: an error budget); ``--shared-noise`` shakes
the bat with one draw instead, shared by pose, knob and tip (knob and tip points computed from
one rigid body's pose: their length exact). ``--lead`` is the tracked
time before the contact (s; 0.15 by default, the same scenes; a pitch is in flight for about
0.4 s); ``--ball-dropout`` drops 0.08 s of the ball's samples ending that many frames before the
contact's interval (the stream restarts there: a tracker that lost the ball); ``--ball-rate``
samples the ball at its own rate (cameras beside a bat tracked by mocap or a robot's joints at
``--rates``). Every method
sees the same samples. ``reference`` is the plain per-coordinate cubic
spline over the whole pitch (``tools.reference``: not-a-knot without noise, Reinsch's smoothing
spline with the known noise), across the contact; the detector's models keep to its rules.
``reference-rules`` is that spline held to the same rules (``tools.reference``'s
``within_rules``: fitted again up to the contact interval's closing frames, the velocities from
the samples before the contact).

Recall and precision count contacts and misses clearer than 0.1 mm without noise, 3 mm with;
errors are over every matched contact (absolute; ``bias`` is the signed mean time error);
``1s``/``2s`` say how often the time, spot (distance from the knob) and sweet-spot speed errors
stayed within one and two reported sigmas (the impacts' uncertainties). Prints
Markdown tables for BENCHMARKS.md.

``--worst N`` lists after each row its N contacts of the largest time error: the scenario's
index in the family's set, its kind, the time (us) and spot (mm) errors, where in its bat step
the true contact lies (0: the opening frame, 1: the closing one), and at a hit (the ball left
its flight) whether the bat was continued from before the interval
(``SweepImpact._bat_ahead``) and the closing frame's miss over the continuation's own miss at
the opening frame, whole and less that own miss carried over (``sweep_impact.braked_miss``:
the rule takes the continuation where the second is over ``BAT_DEPARTURE_RATIO``), or ``not
judged`` where the rule did not come to that (no departure, noise, no continuation).
"""

import argparse
import math
import time
from typing import Callable, Dict, List, Optional, Sequence, Tuple

from baseball_collision.core.detector import DetectorConfig, fitting, kinematics, sweep_impact
from baseball_collision.core.detector.sweep import Sweep
from baseball_collision.tools.accuracy import PitchResult, run_samples, summarize
from baseball_collision.tools.reference import reference_result
from baseball_collision.tools.sim import (
    CLOSE_KINDS, FAMILIES, KINDS, make_scenario, NOISE_ON, sample, Samples, Scenario)
import numpy as np

SMOOTHER, VELOCITIES = ('fitting', 'SMOOTHER'), ('kinematics', 'VELOCITIES')
FLIGHT = ('fitting', 'FLIGHT')
"""Keys of METHODS entries that set a module constant for the run (not config fields)."""

METHODS: Dict[object, Dict[object, object]] = {
    'linear': {'model': 'linear'},
    'rigid': {'model': 'rigid'},
    'rigid-auto': {'model': 'rigid', 'tracker_noise': -1.0},
    'spline': {'model': 'spline'},
    'spline-auto': {'model': 'spline', 'tracker_noise': -1.0},
    'c2': {'model': 'c2'},
    'c2-la1': {'model': 'c2', 'look_ahead': 1},
    'c2-la2': {'model': 'c2', 'look_ahead': 2},
    'c2-fits': {'model': 'c2', VELOCITIES: 'fits'},
    'c2-before': {'model': 'c2', VELOCITIES: 'before'},
    'c2-knot': {'model': 'c2', VELOCITIES: 'knot'},
    'c2-poly': {'model': 'c2', VELOCITIES: 'poly'},
    'c2-poly-noise': {'model': 'c2', VELOCITIES: 'poly'},
    'c2-window': {'model': 'c2', VELOCITIES: 'window'},
    'c2-window-noise': {'model': 'c2', VELOCITIES: 'window'},
    'c2-noise': {'model': 'c2'},
    'c2-auto': {'model': 'c2', 'tracker_noise': -1.0},
    'c2-la1-auto': {'model': 'c2', 'look_ahead': 1, 'tracker_noise': -1.0},
    'c2-la2-auto': {'model': 'c2', 'look_ahead': 2, 'tracker_noise': -1.0},
    'c2-jerk-noise': {'model': 'c2', SMOOTHER: ('jerk', 'likelihood')},
    'c2-jerk-auto': {'model': 'c2', 'tracker_noise': -1.0, SMOOTHER: ('jerk', 'likelihood')},
    'c2-la2-jerk-auto': {'model': 'c2', 'look_ahead': 2, 'tracker_noise': -1.0,
                         SMOOTHER: ('jerk', 'likelihood')},
    'c2-smoother-noise': {'model': 'c2', FLIGHT: None},
    'c2-smoother-auto': {'model': 'c2', 'tracker_noise': -1.0, FLIGHT: None},
}
METHODS.update({
    f'c2-flight{degree}{end_label}{span_label}-{told}': dict(
        {'model': 'c2', FLIGHT: (degree, span, end)},
        **({'tracker_noise': -1.0} if told == 'auto' else {}),
        **({'prediction_window': span / 1.5} if span > 0.15 else {}))
    for degree in (2, 3) for end, end_label in (('closing', ''), ('opening', '-open'))
    for span, span_label in ((0.15, ''), (0.3, '-long')) for told in ('noise', 'auto')})
"""Detector methods by label: DetectorConfig fields (plus ``reference``, ``reference-interp`` and
``reference-rules``, not detectors); a label ending in ``-noise`` is told the known noise
(``tracker_noise``),
``c2-auto`` estimates each stream's (``tracker_noise: auto``). The smoothers (``fitting.SMOOTHER``:
Reinsch's natural spline and weight rule, the not-a-knot penalty with the residual rules; the
``c2-[la2-]jerk-*`` labels: the Kalman/RTS smoother of a constant-jerk model) and the
other c2 velocity rules (``c2-fits``: the former least-squares fits; ``c2-window``: the window fits
reaching the closing frame; ``c2-knot``: with exact samples the bat's window before the impact
fitted with a knot at it; ``c2-poly``: with exact samples that window interpolated by one
polynomial of degree samples - 1) measured against the chosen ones are set by their module
constants for the run. ``c2-smoother-noise|auto``: the ball smoothed like the bat (no flight fit,
``fitting.FLIGHT`` None: the rule before it). ``c2-flightD[-open][-long]-noise|auto``: the ball's
flight fit (``fitting.FLIGHT``: a polynomial of degree D, its window ending at the interval's
closing frame or with ``-open`` its opening frame, over 0.15 s or with ``-long`` 0.3 s: the
streams' trim history, 0.15 s by default, bounds it, so ``-long`` raises ``prediction_window`` to
0.2 s)."""

COLUMNS = (
    ('recall', '{:.3f}'), ('precision', '{:.3f}'), ('time_error_us_p50', '{:.1f}'),
    ('time_error_us_p99', '{:.1f}'), ('time_error_us_mean', '{:+.1f}'),
    ('location_error_mm_p50', '{:.2f}'), ('location_error_mm_p99', '{:.2f}'),
    ('sweet_spot_speed_error_pct_p50', '{:.2f}'), ('sweet_spot_speed_error_pct_p99', '{:.2f}'),
    ('time_within_1_sigma', '{:.2f}'), ('time_within_2_sigma', '{:.2f}'),
    ('location_within_1_sigma', '{:.2f}'), ('location_within_2_sigma', '{:.2f}'),
    ('speed_within_1_sigma', '{:.2f}'), ('speed_within_2_sigma', '{:.2f}'),
    ('ball_speed_error_pct_p50', '{:.2f}'), ('ball_speed_error_pct_p99', '{:.2f}'))

HEADER = ('| family | rate Hz | noise mm | method | recall | precision | time err p50 us | '
          'p99 us | '
          'bias us | spot err p50 mm | p99 mm | speed err p50 % | p99 % | time 1s | 2s | '
          'spot 1s | 2s | speed 1s | 2s | ball speed err p50 % | p99 % |')


def _runner(label: str, bat: str, noise_m: float) -> Callable:
    """Return a function scoring one (scenario, samples) with a method."""
    if label == 'reference':
        return lambda scenario, samples: reference_result(scenario, samples, noise_m)
    if label == 'reference-interp':
        return lambda scenario, samples: reference_result(scenario, samples, 0.0)
    if label == 'reference-rules':
        return lambda scenario, samples: reference_result(scenario, samples, noise_m, True)
    # (a method interpolates unless it says otherwise: tracker_noise 0, not the default auto)
    noise = {'tracker_noise': noise_m if label.endswith('-noise') else 0.0}
    fields = {key: value for key, value in METHODS[label].items() if isinstance(key, str)}
    config = DetectorConfig(bat_input=bat, **{**noise, **fields})
    modules = {'fitting': fitting, 'kinematics': kinematics}
    constants = {key: getattr(modules[key[0]], key[1]) for key in (SMOOTHER, VELOCITIES, FLIGHT)}
    constants.update((key, value) for key, value in METHODS[label].items()
                     if not isinstance(key, str))

    def score(scenario, samples):
        saved = {key: getattr(modules[key[0]], key[1]) for key in constants}
        for key, value in constants.items():
            setattr(modules[key[0]], key[1], value)
        try:
            return run_samples(scenario, samples, config)[1]
        finally:
            for key, value in saved.items():
                setattr(modules[key[0]], key[1], value)
    return score


HIT_BATS: List[Dict[str, object]] = []
"""What ``--worst`` records of each hit's bat while a scenario is scored (``_recording``)."""


def _recording() -> None:
    """Wrap ``SweepImpact._bat_ahead`` and ``braked_miss``: record each hit's bat (``--worst``)."""
    bat_ahead, braked_miss = Sweep._bat_ahead, sweep_impact.braked_miss

    def recorded_miss(times, frames, missed, continued):  # type: ignore[no-untyped-def]
        miss, scale = braked_miss(times, frames, missed, continued)
        whole = max(map(math.dist, continued, (frames[1].knob, frames[1].tip)))
        HIT_BATS[-1].update(whole=whole / scale if scale else math.inf,
                            left=miss / scale if scale else math.inf)
        return miss, scale

    def recorded(self, interval, paths, hit=False):  # type: ignore[no-untyped-def]
        if self.bat_ahead is not None:  # (the uncertainty's re-solves)
            return bat_ahead(self, interval, paths, hit)
        HIT_BATS.append({'t0': interval[0], 't1': interval[1]})
        found = bat_ahead(self, interval, paths, hit)
        HIT_BATS[-1]['taken'] = found is not None
        return found
    Sweep._bat_ahead = recorded
    sweep_impact.braked_miss = recorded_miss


def _worst(scenarios: Sequence[Scenario], samples: Sequence[Samples], results, count: int,
           records: Sequence[List[Dict[str, object]]]) -> None:
    """Print the ``count`` contacts of the largest time error (``--worst``)."""
    found = [(abs(r.time_error_s), i) for i, r in enumerate(results)
             if r.time_error_s is not None]
    for _, i in sorted(found, reverse=True)[:count]:
        scenario, result = scenarios[i], results[i]
        stamps = (samples[i].bat_stamps_ns - samples[i].start_ns) * 1e-9
        k = int(np.searchsorted(stamps, scenario.truth.time_s)) - 1
        place = (scenario.truth.time_s - stamps[k]) / (stamps[k + 1] - stamps[k])
        # the hit's interval: the last one the rule judged (the sweep stops at the impact)
        hit = records[i][-1] if records[i] else {}
        judged = 'left' in hit
        bat = ('continued' if hit.get('taken') else 'through its frames') + (
            f", closing miss {hit['whole']:.2f} / {hit['left']:.2f} own" if judged
            else ', not judged')
        print(f'  {i:3d} {result.kind:8s} time {result.time_error_s * 1e6:+7.1f} us, spot '
              f'{result.location_error_m * 1e3:+6.2f} mm, at {place:.2f} of its step; '
              f"hit's bat: {bat}", flush=True)


def _row(family: str, rate: float, noise_mm: float, label: str, results) -> Dict:
    """Print one table row; return its summary."""
    summary = summarize(results, min_clearance_m=3e-3 if noise_mm else 1e-4)
    cells = [fmt.format(summary[key]) for key, fmt in COLUMNS]
    print(f'| {family} | {rate:g} | {noise_mm:g} | {label} | ' + ' | '.join(cells) + ' |',
          flush=True)
    return summary


DROPOUT_S = 0.08
"""s of ball samples ``--ball-dropout`` drops (longer than ``max_gap``: the stream restarts)."""


def dropped_ball(scenario: Scenario, samples: Samples, frames: int,
                 dropout_s: float = DROPOUT_S) -> Samples:
    """
    Return the samples without ``dropout_s`` of the ball's, ending ``frames`` before the contact.

    The ball's stream restarts ``frames`` samples before the opening sample of the interval
    holding the contact (or the closest approach of a miss): a tracker that lost the ball and
    found it again just before the bat.
    """
    times = (samples.ball_stamps_ns - samples.start_ns) * 1e-9
    truth = scenario.truth
    moment = truth.time_s if truth.time_s is not None else truth.min_gap_time_s
    end = max(int(np.searchsorted(times, moment)) - 1 - frames, 0)
    keep = ~((times > times[end] - dropout_s) & (np.arange(len(times)) < end))
    return samples.with_ball_kept(keep)


def run(families: Sequence[str], rates: Sequence[float], noises: Sequence[float],
        methods: Sequence[str], per_kind: int, seed: int, bat: str,
        pooled: bool = False, noise_on: str = 'both', lead_s: float = 0.15,
        dropout: Optional[int] = None, ball_rate: Optional[float] = None,
        shared: bool = False, worst: int = 0, spin: bool = False) -> List[Tuple]:
    """
    Print one row per family, rate, noise and method; return (key, summary) pairs.

    ``pooled``: one row per rate, noise and method over all the families instead;
    ``noise_on``: the bodies with noise (``sim.sample``); ``lead_s``: s tracked before contact;
    ``dropout``: the ball's stream restarting that many frames before the contact
    (``dropped_ball``), or None; ``ball_rate``: the ball's own rate (Hz), or None for each rate;
    ``shared``: one draw shakes the whole bat (no marker spread); ``worst``: list that many
    contacts of the largest time error after each row (``_worst``; not with ``pooled``);
    ``spin``: spinning pitches (``make_scenario``'s: the Magnus force across the flight).
    """
    if worst:
        _recording()
    rows = []
    pools: Dict[Tuple, List[PitchResult]] = {}
    for family in families:
        rng = np.random.default_rng(seed)
        scenarios = [make_scenario(kind, rng, family=family, lead_s=lead_s, spin=spin)
                     for kind in KINDS + CLOSE_KINDS for _ in range(per_kind)]
        for rate in rates:
            for noise_mm in noises:
                noise = noise_mm * 1e-3
                samples = [sample(s, rate, np.random.default_rng(i), jitter_s=2e-4, grid_s=1e-3,
                                  noise_m=noise,
                                  marker_spread_m=0.3 if noise and not shared else None,
                                  noise_on=noise_on, ball_rate_hz=ball_rate)
                           for i, s in enumerate(scenarios)]
                if dropout is not None:
                    samples = [dropped_ball(s, smp, dropout)
                               for s, smp in zip(scenarios, samples)]
                for label in methods:
                    score = _runner(label, bat, noise)
                    results: List[PitchResult] = []
                    records: List[List[Dict[str, object]]] = []
                    for s, smp in zip(scenarios, samples):
                        HIT_BATS.clear()
                        results.append(score(s, smp))
                        records.append(list(HIT_BATS))
                    if pooled:
                        pools.setdefault((rate, noise_mm, label), []).extend(results)
                        continue
                    rows.append(((family, rate, noise_mm, label),
                                 _row(family, rate, noise_mm, label, results)))
                    if worst:
                        _worst(scenarios, samples, results, worst, records)
    for (rate, noise_mm, label), results in pools.items():
        rows.append((('+'.join(families), rate, noise_mm, label),
                     _row('+'.join(families), rate, noise_mm, label, results)))
    return rows


def main() -> None:
    """Print the accuracy tables."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--quick', action='store_true',
                        help='one scenario per kind, 90 and 360 Hz, 0 and 1 mm (CI-sized)')
    parser.add_argument('--per-kind', type=int, default=6)
    parser.add_argument('--seed', type=int, default=7)
    parser.add_argument('--families', nargs='+', default=list(FAMILIES), choices=FAMILIES)
    parser.add_argument('--rates', nargs='+', type=float, default=[90.0, 120.0, 360.0])
    parser.add_argument('--noises', nargs='+', type=float, default=[0.0, 0.5, 1.0, 2.0],
                        help='mm per coordinate')
    references = ['reference', 'reference-interp', 'reference-rules']
    parser.add_argument('--methods', nargs='+',
                        default=list(METHODS) + ['reference', 'reference-rules'],
                        choices=list(METHODS) + references)
    parser.add_argument('--bat', choices=('points', 'pose'), default='points')
    parser.add_argument('--noise-on', choices=NOISE_ON, default='both',
                        help='the bodies with noise (an error budget: ball or bat only)')
    parser.add_argument('--shared-noise', action='store_true',
                        help='one draw shakes the whole bat: knob and tip share it')
    parser.add_argument('--lead', type=float, default=0.15,
                        help='s tracked before the contact (the pitch flies about 0.4 s)')
    parser.add_argument('--pooled', action='store_true',
                        help='one row per rate, noise and method over all the families')
    parser.add_argument('--ball-dropout', type=int, metavar='FRAMES',
                        help=f'drop {DROPOUT_S:g} s of ball samples ending FRAMES samples '
                        "before the contact's interval (the ball's stream restarts there)")
    parser.add_argument('--ball-rate', type=float, metavar='HZ',
                        help="the ball's own rate (the bat's are --rates)")
    parser.add_argument('--worst', type=int, default=0, metavar='N',
                        help='after each row, its N contacts of the largest time error and '
                        "what the hit's bat rule made of them")
    parser.add_argument('--spin', action='store_true',
                        help='spinning pitches: the Magnus force bends the flight 1-7 m/s^2')
    args = parser.parse_args()
    if args.quick:
        args.per_kind, args.rates, args.noises = 1, [90.0, 360.0], [0.0, 1.0]
    started = time.perf_counter()
    count = args.per_kind * len(KINDS + CLOSE_KINDS)
    print(f'{count} scenarios per family ({args.per_kind} of each of '
          f'{len(KINDS + CLOSE_KINDS)} kinds), seed {args.seed}, bat as {args.bat}, noise on '
          f"{args.noise_on}{' (the bat shaken as one body)' if args.shared_noise else ''}, "
          f'{args.lead:g} s before the contact'
          + ('' if args.ball_dropout is None else
             f', the ball lost {DROPOUT_S:g} s until {args.ball_dropout} frames before it')
          + ('' if args.ball_rate is None else f', the ball at {args.ball_rate:g} Hz')
          + (', spinning pitches' if args.spin else '') + '\n')
    print(HEADER)
    print('|' + '---|' * 19)
    run(args.families, args.rates, args.noises, args.methods, args.per_kind, args.seed,
        args.bat, args.pooled, args.noise_on, args.lead, args.ball_dropout, args.ball_rate,
        args.shared_noise, args.worst, args.spin)
    print(f'\n({time.perf_counter() - started:.0f} s)')


if __name__ == '__main__':
    main()
