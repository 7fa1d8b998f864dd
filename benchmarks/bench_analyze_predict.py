"""
``analyze --predict`` against plain ``analyze`` on one large bag, and its report steps alone.

Run: ``.venv/bin/python benchmarks/bench_analyze_predict.py [--messages N] [--model M]
[--period S] [--pitch-every SECONDS] [--repeats R]``.

Writes (into a temporary directory) the bag of ``bench_analyze`` (default 2,880,000 messages:
360 Hz, ball and bat pose, pitches 0.5 s apart, a truth file beside it; ``--pitch-every``
more than 0.5: a session tracked between pitches), then in the same process, in turn
``--repeats`` times, times ``analyze_bag`` plain, with prediction (``--predict``: 0.3 s
horizon) planned in chunks (new), and with prediction one sample at a time (old: as before
chunks were planned with prediction on, ``chunks.plannable`` false); then the report steps
of the predicting run on their own: the truth comparison (``truth.compare_truth``), the
prediction scores (``BagAnalysis.prediction_scores``) and the JSON document
(``report.to_json``). Prints the times, the ratios predict / plain (issue 13's goal: at most
2) and old / new, in wall time and in this process's CPU time (which other work on a shared
machine inflates less), whether old and new found the same events, and how many samples the
chunk path took as stops (through the per-sample path) with and without prediction; asserts
nothing.
"""

import argparse
from pathlib import Path
import tempfile
import time

from baseball_collision.core.detector import chunks
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag
from baseball_collision.tools.report import to_json
from baseball_collision.tools.truth import compare_truth, load_truth, truth_path
from bench_analyze import density, named_model, WORST_SPACING_S, write_bag


def _timed(function, *args, **kwargs):
    start = time.perf_counter()
    result = function(*args, **kwargs)
    return result, time.perf_counter() - start


def _timed_cpu(function, *args, **kwargs):
    """Return (result, wall s, this process's CPU s: what other work on the machine leaves)."""
    cpu = time.process_time()
    result, seconds = _timed(function, *args, **kwargs)
    return result, seconds, time.process_time() - cpu


class StopCount:
    """
    Counts the samples the chunk path fast-forwards in runs and takes as stops.

    Stops through the per-sample path (``Detector.add`` or the scheduler's walk), and stops
    for the predictor alone (taken with the run before them, then ``Predictor.predict``).
    """

    def __init__(self) -> None:
        self.runs = self.stops = self.forecasts = 0
        self._fast_forward, self._one = chunks.fast_forward, chunks._one

    def __enter__(self) -> 'StopCount':
        def fast_forward(plan, pos, end, *args, walk=True, **kwargs):
            if not walk:
                self.stops += end - pos  # a stop that passes every check
            elif plan.forecasts is not None and plan.forecasts[end - 1]:
                self.forecasts += 1
                self.runs += end - pos - 1
            else:
                self.runs += end - pos
            return self._fast_forward(plan, pos, end, *args, walk=walk, **kwargs)

        def one(*args, **kwargs):
            self.stops += 1
            return self._one(*args, **kwargs)
        chunks.fast_forward, chunks._one = fast_forward, one
        return self

    def __exit__(self, *exc) -> None:
        chunks.fast_forward, chunks._one = self._fast_forward, self._one

    def __str__(self) -> str:
        total = self.runs + self.stops + self.forecasts
        return (f'stops: {self.stops:,} per sample ({self.stops / total:.1%}), '
                f'{self.forecasts:,} for the predictor alone ({self.forecasts / total:.1%}); '
                f'{self.runs:,} of {total:,} samples fast-forwarded')


def _one_at_a_time(path: Path, options: AnalysisOptions):
    """``analyze_bag`` with prediction taken one sample at a time, as before this change."""
    plannable = chunks.plannable
    chunks.plannable = lambda config: (plannable(config)
                                       and config.prediction_horizon <= 0.0)
    try:
        return analyze_bag(path, options, progress=False)
    finally:
        chunks.plannable = plannable


def _same(a, b) -> bool:
    """Return whether two analyses found the same events and drops."""
    return (a.impacts == b.impacts and a.near_misses == b.near_misses
            and a.predictions == b.predictions and a.drops_by_role == b.drops_by_role
            and a.stats.dropped == b.stats.dropped)


def main() -> None:
    """Write the bag, time the runs in turn and the report steps, print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--messages', type=int, default=2_880_000)
    parser.add_argument('--model', default='spline',
                        choices=('linear', 'rigid', 'spline', 'c2', 'default'),
                        help="motion model (default spline; 'default': analyze's own)")
    parser.add_argument('--period', type=float, default=0.0,
                        help='prediction_period of the predicting run (s; default 0)')
    parser.add_argument('--pitch-every', type=float, default=WORST_SPACING_S, metavar='SECONDS',
                        help='seconds between pitches (default 0.5, the worst case; more: a '
                        'session tracked between pitches)')
    parser.add_argument('--repeats', type=int, default=1,
                        help='rounds of plain, new, old in turn (default 1)')
    parser.add_argument('--no-old', action='store_true',
                        help='skip the one-sample-at-a-time predicting run')
    args = parser.parse_args()
    print(f'bag: {density(args.pitch_every)}')
    with tempfile.TemporaryDirectory() as directory:
        path = Path(directory) / 'bench.mcap'
        written, seconds = write_bag(path, args.messages, args.pitch_every)
        print(f'bag: {written:,} messages written in {seconds:.1f} s')
        model = named_model(args.model)
        plain_options = AnalysisOptions(model=model)
        options = AnalysisOptions(model=model, prediction_horizon=0.3,
                                  parameters={'prediction_period': args.period})
        for round_ in range(args.repeats):
            with StopCount() as plain_stops:
                plain, plain_s, plain_cpu = _timed_cpu(analyze_bag, path, plain_options,
                                                       progress=False)
            print(f'[{round_ + 1}] analyze:               {plain_s:7.1f} s, CPU '
                  f'{plain_cpu:6.1f} s ({plain.messages / plain_s:,.0f} msg/s), '
                  f'{len(plain.impacts)} impacts; {plain_stops}')
            with StopCount() as stops:
                predicted, predict_s, predict_cpu = _timed_cpu(analyze_bag, path, options,
                                                               progress=False)
            print(f'[{round_ + 1}] --predict, planned:    {predict_s:7.1f} s, CPU '
                  f'{predict_cpu:6.1f} s, {len(predicted.predictions):,} predictions; {stops}')
            print(f'[{round_ + 1}]   ratio new / plain: {predict_s / plain_s:.2f} wall, '
                  f'{predict_cpu / plain_cpu:.2f} CPU')
            if not args.no_old:
                old, old_s, old_cpu = _timed_cpu(_one_at_a_time, path, options)
                print(f'[{round_ + 1}] --predict, one at a time: {old_s:7.1f} s, CPU '
                      f'{old_cpu:6.1f} s, {len(old.predictions):,} predictions; the same '
                      f'events: {_same(old, predicted)}')
                print(f'[{round_ + 1}]   ratio old / plain: {old_s / plain_s:.2f} wall, '
                      f'{old_cpu / plain_cpu:.2f} CPU; old / new: {old_s / predict_s:.2f} '
                      f'wall, {old_cpu / predict_cpu:.2f} CPU')
        truth_file = truth_path(path)
        if truth_file.exists():  # (a session bag has none)
            truth = load_truth(truth_file)
            _, compare_s = _timed(compare_truth, predicted.impacts, predicted.near_misses,
                                  truth, truth_file)
            print(f'compare_truth {compare_s:.3f} s ({len(truth["pitches"]):,} pitches)')
        _, scores_s = _timed(predicted.prediction_scores)
        _, json_s, json_cpu = _timed_cpu(to_json, [predicted])
        print(f'report steps: prediction_scores {scores_s:.3f} s, to_json {json_s:.3f} s')
        print(f'ratio predict (new, last round) with its JSON / plain: '
              f'{(predict_s + json_s) / plain_s:.2f} (goal <= 2); in CPU time '
              f'{(predict_cpu + json_cpu) / plain_cpu:.2f}')


if __name__ == '__main__':
    main()
