"""
Bag read benchmark: rosbags raw iteration, rosbags deserialisation, and ``read_samples``.

Run: ``.venv/bin/python benchmarks/bench_bag_read.py [--messages N] [--storage S]``.

Writes a bag of ``N`` messages (default 1,000,000; half ball PointStamped, half bat
PoseStamped, both at 360 Hz on a millisecond grid) into a temporary directory, then times in the
same process: (a) ``AnyReader.messages()`` alone (raw bytes), (b) (a) plus
``AnyReader.deserialize`` of every message, (c) :func:`baseball_collision.bags.bag.read_samples`
(open, select topics, decode, build samples). Prints messages per second and ratios; asserts
nothing.
"""

import argparse
import math
from pathlib import Path
import resource
import tempfile
import time
from typing import Callable, Tuple

from baseball_collision.bags import BagWriter, read_samples
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores

SUFFIXES = {'mcap': 'bench.mcap', 'sqlite3': 'bench.db3', 'rosbag1': 'bench.bag'}


def write_bag(path: Path, messages: int) -> float:
    """Write the benchmark bag and return the seconds it took."""
    start = time.perf_counter()
    with BagWriter(path) as bag:
        stamp = 1_700_000_000_000_000_000
        for i in range(messages // 2):
            stamp += 3_000_000 if i % 3 == 2 else 2_000_000  # 360 Hz on a millisecond grid
            t = i / 360.0
            bag.write_point('/ball', stamp, 'world',
                            (18.0 - 38.0 * t % 19.0, 0.1 * math.sin(t), 1.0))
            angle = 30.0 * t
            bag.write_pose('/bat/pose', stamp + 150_000, 'mocap_world',
                           (0.0, 0.0, 1.0), (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)))
    return time.perf_counter() - start


def peak_mb() -> float:
    """Return the process's peak resident memory so far (MB, Linux units)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def timed(run: Callable[[], int]) -> Tuple[int, float]:
    """Return ``(messages, seconds)`` of one run."""
    start = time.perf_counter()
    count = run()
    return count, time.perf_counter() - start


def raw_read(path: Path) -> int:
    """Iterate the raw messages; return how many."""
    count = 0
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        for _ in reader.messages():
            count += 1
    return count


def deserialize_all(path: Path) -> int:
    """Deserialise every message with rosbags; return how many."""
    count = 0
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        deserialize = reader.deserialize
        for connection, _, raw in reader.messages():
            deserialize(raw, connection.msgtype)
            count += 1
    return count


def samples(path: Path) -> int:
    """Read every sample with read_samples; return how many."""
    count = 0
    for _ in read_samples(path):
        count += 1
    return count


def main() -> None:
    """Write the bag, time the three readers, print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--messages', type=int, default=1_000_000)
    parser.add_argument('--storage', choices=sorted(SUFFIXES), default='mcap')
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / SUFFIXES[args.storage]
        seconds = write_bag(path, args.messages)
        size = path.stat().st_size / 1e6
        print(f'wrote {args.messages} messages ({args.storage}, {size:.0f} MB) in '
              f'{seconds:.1f} s: {args.messages / seconds:,.0f} msg/s; '
              f'peak RSS {peak_mb():.0f} MB')
        results = {}
        for name, run in (('(a) rosbags raw messages()', raw_read),
                          ('(b) raw + reader.deserialize', deserialize_all),
                          ('(c) bag.read_samples', samples)):
            count, seconds = timed(lambda: run(path))
            results[name] = count / seconds
            print(f'{name:32s} {count} msgs in {seconds:6.2f} s: {count / seconds:>10,.0f} msg/s')
        raw, deserialized, ours = results.values()
        print(f'read_samples / raw = {ours / raw:.2f}, read_samples / deserialize = '
              f'{ours / deserialized:.2f}; peak RSS {peak_mb():.0f} MB')


if __name__ == '__main__':
    main()
