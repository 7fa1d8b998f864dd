"""
The detector's cost on the fuzz suite's seeded fault streams: CPU and peak memory per stream.

Run: ``.venv/bin/python benchmarks/bench_fault_streams.py [--streams 60] [--show 5] [--no-peak]``.

``test/core/test_fuzz.py``'s ``random_stream`` draws a stream of every fault (stamps out of
order, repeated, ahead, far apart and microseconds apart, values not finite, lost frames, glitches,
bad quaternions, ...) beside simulated pitches, seed by seed; each is fed one sample at a time
into a new ``Detector`` and finished (``feed_stream``), as the test does. Printed: the streams'
total CPU (thread time, s), the slowest streams (seed, model, samples, CPU s, us a sample), and
the largest peak memory any one held (tracemalloc, bytes; that run is a second pass, since
tracemalloc slows Python; ``--no-peak`` leaves it out). A hostile stream should cost what an
ordinary one does.
"""

import argparse
from pathlib import Path
import sys
import time
import tracemalloc

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'test'))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'test' / 'core'))
from test_fuzz import feed_stream, random_stream  # noqa: E402, I100


def main() -> None:
    """Print the fault streams' CPU and peak memory."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--streams', type=int, default=60)
    parser.add_argument('--show', type=int, default=5)
    parser.add_argument('--no-peak', action='store_true')
    args = parser.parse_args()
    rows, peaks = [], []
    for seed in range(args.streams):
        config, offers = random_stream(seed)
        start = time.thread_time()
        feed_stream(config, offers)
        rows.append((time.thread_time() - start, seed, config.model, len(offers)))
    for seed in range(0 if args.no_peak else args.streams):
        config, offers = random_stream(seed)
        tracemalloc.start()
        feed_stream(config, offers)
        peaks.append((tracemalloc.get_traced_memory()[1], seed))
        tracemalloc.stop()
    print(f'{args.streams} fault streams, {sum(r[3] for r in rows)} samples: '
          f'{sum(r[0] for r in rows):.2f} s CPU')
    print('| seed | model | samples | CPU s | us a sample |')
    print('|---|---|---|---|---|')
    for cpu, seed, model, count in sorted(rows, reverse=True)[:args.show]:
        print(f'| {seed} | {model} | {count} | {cpu:.3f} | {cpu / count * 1e6:.0f} |')
    if peaks:
        peak, seed = max(peaks)
        print(f'largest peak memory: {peak} bytes (seed {seed})')


if __name__ == '__main__':
    main()
