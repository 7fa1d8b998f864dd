"""
The cost of ``tracker_noise: auto``: ``analyze`` under ``c2``, two estimators in turn.

This tree's estimator against another's, in one process, on the worst-case bag and a session.

Run: ``.venv/bin/python benchmarks/bench_noise_estimate.py --before OLD_NOISE_PY [--messages N]
[--bag-noise M]`` where OLD_NOISE_PY is an older ``core/detector/noise.py`` (``git show
REV:baseball_collision/core/detector/noise.py > /tmp/noise_old.py``); its relative imports of
``.streams`` and ``..toi`` are pointed at this tree's. Prints CPU msg/s, the ratio and whether
the impacts are the same (every field).
"""

import argparse
from pathlib import Path
import sys
import tempfile
import types

from baseball_collision.core.detector import detector as detector_module
from baseball_collision.threads import single_threaded_blas
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_analyze  # noqa: E402  (the benchmarks' bag writer and CPU clock)


def load_estimator(path: Path) -> type:
    """Return the ``NoiseEstimate`` class of an older ``noise.py`` (its imports made absolute)."""
    source = path.read_text().replace('from .streams import', 'from .detector.streams import')
    source = source.replace('from ..toi import', 'from .toi import').replace(
        'from .', 'from baseball_collision.core.')
    module = types.ModuleType('noise_before')
    exec(compile(source, str(path), 'exec'), module.__dict__)
    return module.NoiseEstimate


def main() -> None:
    """Time analyze under c2 with auto noise, the two estimators in turn."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--before', type=Path, required=True, metavar='OLD_NOISE_PY')
    parser.add_argument('--messages', type=int, default=30_000)
    parser.add_argument('--repeats', type=int, default=2)
    parser.add_argument('--bag-noise', type=float, default=0.0, metavar='M',
                        help='Gaussian noise on the bag points (m, 1 sigma; 0: exact)')
    args = parser.parse_args()
    single_threaded_blas()  # as the node and analyze run the detector (threads.py)
    estimators = {'before': load_estimator(args.before),
                  'now': detector_module.NoiseEstimate}
    options = AnalysisOptions(model='c2', parameters={'tracker_noise': -1.0})
    for every in (bench_analyze.WORST_SPACING_S, 10.0):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / 'bench.mcap'
            written, _ = bench_analyze.write_bag(path, args.messages, every, args.bag_noise)
            print(f'{bench_analyze.density(every)}: {written:,} messages')
            best, stamps = {}, {}
            for _ in range(args.repeats):
                for name, estimator in estimators.items():
                    detector_module.NoiseEstimate = estimator
                    cpu = bench_analyze.cpu_seconds()
                    result = analyze_bag(path, options)
                    rate = result.messages / (bench_analyze.cpu_seconds() - cpu)
                    best[name] = max(best.get(name, 0.0), rate)
                    stamps[name] = [repr(impact) for impact in result.impacts]
            detector_module.NoiseEstimate = estimators['now']
            print(f"  before {best['before']:8,.0f} msg/s CPU, now {best['now']:8,.0f}: "
                  f"{best['now'] / best['before']:.2f}x; {len(stamps['now'])} impacts, "
                  f"the same impacts: {stamps['now'] == stamps['before']}")


if __name__ == '__main__':
    main()
