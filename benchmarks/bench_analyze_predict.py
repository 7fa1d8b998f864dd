"""
``analyze --predict`` against plain ``analyze`` on one large bag, and its report steps alone.

Run: ``.venv/bin/python benchmarks/bench_analyze_predict.py [--messages N] [--model M]
[--period S]``.

Writes (into a temporary directory) the bag of ``bench_analyze`` (default 2,880,000 messages:
360 Hz, ball and bat pose, pitches 0.5 s apart, a truth file beside it), then in the same
process times ``analyze_bag`` without and with prediction (``--predict``: 0.3 s horizon), and
the report steps of the predicting run on their own: the truth comparison
(``truth.compare_truth``), the prediction scores (``BagAnalysis.prediction_scores``) and the
JSON document (``report.to_json``). Prints the times and the ratio predict / plain (issue 13's
goal: at most 2), in wall time and in this process's CPU time (which other work on a shared
machine inflates less); asserts nothing.
"""

import argparse
from pathlib import Path
import tempfile
import time

from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag
from baseball_collision.tools.report import to_json
from baseball_collision.tools.truth import compare_truth, load_truth, truth_path
from bench_analyze import write_bag


def _timed(function, *args, **kwargs):
    start = time.perf_counter()
    result = function(*args, **kwargs)
    return result, time.perf_counter() - start


def _timed_cpu(function, *args, **kwargs):
    """Return (result, wall s, this process's CPU s: what other work on the machine leaves)."""
    cpu = time.process_time()
    result, seconds = _timed(function, *args, **kwargs)
    return result, seconds, time.process_time() - cpu


def main() -> None:
    """Write the bag, time both runs and the report steps, print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--messages', type=int, default=2_880_000)
    parser.add_argument('--model', default='spline', choices=('linear', 'rigid', 'spline'))
    parser.add_argument('--period', type=float, default=0.0,
                        help='prediction_period of the predicting run (s; default 0)')
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as directory:
        path = Path(directory) / 'bench.mcap'
        written, seconds = write_bag(path, args.messages)
        print(f'bag: {written:,} messages written in {seconds:.1f} s')
        plain, plain_s, plain_cpu = _timed_cpu(analyze_bag, path,
                                               AnalysisOptions(model=args.model),
                                               progress=False)
        print(f'analyze:           {plain_s:8.1f} s ({plain.messages / plain_s:,.0f} msg/s), '
              f'CPU {plain_cpu:.1f} s, {len(plain.impacts)} impacts')
        options = AnalysisOptions(model=args.model, prediction_horizon=0.3,
                                  parameters={'prediction_period': args.period})
        predicted, predict_s, predict_cpu = _timed_cpu(analyze_bag, path, options,
                                                       progress=False)
        print(f'analyze --predict: {predict_s:8.1f} s ({predicted.messages / predict_s:,.0f} '
              f'msg/s), CPU {predict_cpu:.1f} s, {len(predicted.predictions):,} predictions; '
              f'detector {predicted.stats.total_processing_s:.1f} s')
        truth = load_truth(truth_path(path))
        _, compare_s = _timed(compare_truth, predicted.impacts, predicted.near_misses, truth,
                              truth_path(path))
        _, scores_s = _timed(predicted.prediction_scores)
        _, json_s, json_cpu = _timed_cpu(to_json, [predicted])
        print(f'report steps: compare_truth {compare_s:.3f} s ({len(truth["pitches"]):,} '
              f'pitches), prediction_scores {scores_s:.3f} s, to_json {json_s:.3f} s')
        print(f'ratio predict / plain: {(predict_s + json_s) / plain_s:.2f} (goal <= 2); in CPU '
              f'time {(predict_cpu + json_cpu) / plain_cpu:.2f}')


if __name__ == '__main__':
    main()
