"""
Bag benchmark: writing, reading (raw, deserialised, samples), skipped topics, unrelated messages.

Run: ``.venv/bin/python benchmarks/bench_bag_read.py [--messages N] [--storage S]
[--unrelated COUNTS] [--repeats R]``.

1. Writes a bag of ``N`` messages (default 1,000,000; half ball PointStamped, half bat
   PoseStamped, both at 360 Hz on a millisecond grid) with :class:`BagWriter` into a temporary
   directory (the writer's speed), then times in the same process: (a) ``AnyReader.messages()``
   alone (raw bytes), (b) (a) plus ``AnyReader.deserialize`` of every message, (c)
   :func:`baseball_collision.bags.read_samples` (open, select topics, decode, build samples),
   (d) ``BagReader.chunks`` (what ``analyze`` reads: 8,192 samples at a time as arrays, decoded
   in bulk), (e) the same chunks built from the per-message samples of (c) (how ``chunks``
   worked before the bulk decode), checked equal to (d), and (f) ``BagReader.chunks`` through
   rosbags' ``AnyReader.messages`` (how ``chunks`` read MCAP before ``bags/mcap.py`` and sqlite3
   before ``bags/sqlite.py``; ROS 1 reads so anyway). Wall time and CPU time: on a machine
   shared with other work the CPU rates and their ratios are the steadier figures.
   ``--repeats R`` runs (a)-(f) in turn R times and keeps each one's best wall and best CPU
   time. Last, ``decode_spans`` on the bag's spans (MCAP chunks, sqlite3 batches: read once,
   then decoded in turn, best of 5): each group read by the kernel where it lies
   (``_kernel.decode_group``, now) against numpy on its rows gathered from a sliding-window
   view (before), the same chunks.
2. A bag of 50,000 undecodable messages on another topic and 10 tracker samples: the time
   :class:`BagReader` takes to skip them (they are never read).
3. For each storage (MCAP, sqlite3, ROS 1): three simulated pitches interleaved with each count
   of unrelated ``std_msgs/String`` messages (``--unrelated``, default 20,000 and 200,000;
   10,000 and 60,000 for ROS 1): the time to write and to ``analyze`` it, and the peak of
   Python allocations while analysing (tracemalloc; it slows the analysis). The peak should not
   grow with the unrelated count; for ROS 1 it does (rosbags' ``rosbag1.Reader.open`` indexes
   every message of every connection).

Prints the figures; asserts nothing.
"""

import argparse
from contextlib import contextmanager
from functools import partial
import itertools
import math
from pathlib import Path
import resource
import shutil
import tempfile
import time
import tracemalloc
from typing import Any, Callable, Dict, Iterator, List, Sequence, Tuple
from unittest import mock

from baseball_collision.bags import BagReader, BagWriter, POINT_STAMPED, POSE_STAMPED, read_samples
from baseball_collision.bags import decode as decode_module, reader as reader_module
from baseball_collision.bags import sqlite as sqlite_module
from baseball_collision.bags.decode import chunk_samples, decode_spans, SampleChunk
from baseball_collision.core.detector.chunks import ROLE_CODES
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag
from baseball_collision.tools.sim import DEFAULT_START_NS, make_scenario, sample
import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
from rosbags.typesys import get_typestore, Stores

SUFFIXES = {'mcap': 'bench.mcap', 'sqlite3': 'bench.db3', 'rosbag1': 'bench.bag'}
TS2 = get_typestore(Stores.ROS2_JAZZY)
Row = Tuple[int, str, Tuple[float, ...]]


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


def timed_cpu(run: Callable[[], int]) -> Tuple[int, float, float]:
    """Return ``(messages, wall seconds, CPU seconds)`` of one run."""
    cpu = time.process_time()
    count, seconds = timed(run)
    return count, seconds, time.process_time() - cpu


def raw_read(path: Path) -> int:
    """Iterate the raw messages; return how many."""
    count = 0
    with AnyReader([path], default_typestore=TS2) as reader:
        for _ in reader.messages():
            count += 1
    return count


def deserialize_all(path: Path) -> int:
    """Deserialise every message with rosbags; return how many."""
    count = 0
    with AnyReader([path], default_typestore=TS2) as reader:
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


def bulk_chunks(path: Path) -> int:
    """Read every sample with ``BagReader.chunks`` (decoded in bulk); return how many."""
    with BagReader(path) as bag:
        return sum(len(chunk.stamps_ns) for chunk in bag.chunks())


def per_message_chunks(path: Path) -> int:
    """Read every sample as ``chunks`` did before the bulk decode; return how many."""
    with BagReader(path) as bag:
        return sum(len(chunk.stamps_ns) for chunk in chunk_samples(bag.samples(), 8192))


def rosbags_chunks(path: Path) -> int:
    """Read every sample with ``BagReader.chunks`` through rosbags' reader; return how many."""
    with rosbags_path():
        return bulk_chunks(path)


@contextmanager
def rosbags_path() -> Iterator[None]:
    """Make ``BagReader`` read every bag through ``AnyReader.messages`` (no spans)."""
    with mock.patch.object(reader_module, 'mcap_spans', lambda *a: None), \
            mock.patch.object(sqlite_module, 'sqlite_spans', lambda *a: None):
        yield


def numpy_rows(spans: decode_module.Spans, routes: Dict[int, Any], slow: Any) -> SampleChunk:
    """
    ``decode_spans`` as it read a group before the kernel did (baseline): numpy on its rows.

    Each group's messages gathered as rows of a sliding-window view of the buffer, its frame_id
    fields compared as opaque values, its stamps and float64s viewed from column copies and
    scattered into the chunk (session 41's ``_decode``); the rest one by one.
    """
    buffer, starts, lengths, which = spans.buffer, spans.starts, spans.lengths, spans.codes
    owners = [routes[id(connection)] for connection in spans.connections]
    n = len(which)
    roles, stamps = np.empty(n, np.int8), np.empty(n, np.int64)
    frames, values, done = np.empty(n, object), np.zeros((n, 7)), np.zeros(n, bool)
    for members in decode_module._groups(which * (int(lengths.max()) + 1) + lengths):
        route = owners[int(which[members[0]])]
        table = sliding_window_view(buffer, int(lengths[members[0]]))[starts[members]]
        try:
            frame_id, offset, end = decode_module._layout(route, table[0].tobytes())
        except ValueError:
            continue
        field = np.ascontiguousarray(table[:, 12:end]).view(f'V{end - 12}')[:, 0]
        rows = field == field[0]
        if route.cdr:
            rows &= (table[:, 0] == 0) & (table[:, 1] == 1)
        table, members = table[rows], members[rows]
        seconds = table[:, 4:8].copy().view('<i4' if route.cdr else '<u4')[:, 0]
        stamps[members] = seconds.astype(np.int64) * 1_000_000_000 + table[:, 8:12].copy().view(
            '<u4')[:, 0]
        values[members, :route.floats] = table[:, offset:offset + 8 * route.floats].copy().view(
            '<f8')
        roles[members], frames[members], done[members] = ROLE_CODES[route.role], frame_id, True
    rest = np.flatnonzero(~done)
    if len(rest):
        others = next(chunk_samples(decode_module.decode_samples(spans.messages(rest), routes,
                                                                 slow), len(rest)))
        roles[rest], stamps[rest] = others.roles, others.stamps_ns
        frames[rest], values[rest] = others.frame_ids, others.values
    return SampleChunk(roles, stamps, frames.tolist(), values, spans.log_times_ns)


def gather_figures(path: Path, rounds: int = 5) -> None:
    """Print ``decode_spans`` (the kernel's) against numpy on each group's rows, in turn."""
    with BagReader(path) as bag:
        reader = bag._open_reader()
        spans = bag._spans(reader, 8192)
        if spans is None:
            print('decode_spans: this bag is read through rosbags (no spans)')
            return
        spans = list(spans)
        slow = partial(bag._slow, reader)
        best = {}
        for _ in range(rounds):
            for name, run in (('now', decode_spans), ('before', numpy_rows)):
                start = time.process_time()
                chunks = [run(each, bag._routes, slow) for each in spans]
                seconds = time.process_time() - start
                best[name] = min(best.get(name, seconds), seconds)
                if name == 'now':
                    now = chunks
                else:
                    same = all(np.array_equal(a.values.view(np.int64), b.values.view(np.int64))
                               and np.array_equal(a.stamps_ns, b.stamps_ns)
                               and np.array_equal(a.roles, b.roles)
                               and a.frame_ids == b.frame_ids for a, b in zip(now, chunks))
    count = sum(len(each.codes) for each in spans)
    print(f'decode_spans, {count} messages in {len(spans)} spans, CPU best of {rounds}: '
          f'numpy rows (before) {best["before"]:.3f} s, the kernel (now) {best["now"]:.3f} s: '
          f'{best["before"] / best["now"]:.2f}x; the same chunks: {same}')


def same_chunks(path: Path) -> bool:
    """
    Return whether bulk and per-message chunks hold the same samples (values to the bit).

    Joined, not chunk by chunk: an MCAP bag's chunks follow the file's chunks.
    """
    with BagReader(path) as bag, BagReader(path) as other:
        joined = [SampleChunk(*(np.concatenate(column) if isinstance(column[0], np.ndarray)
                                else list(itertools.chain(*column)) for column in zip(*chunks)))
                  for chunks in (list(bag.chunks()), list(chunk_samples(other.samples(), 8192)))]
    a, b = joined
    return (np.array_equal(a.roles, b.roles) and a.frame_ids == b.frame_ids
            and np.array_equal(a.stamps_ns, b.stamps_ns)
            and np.array_equal(a.values.view(np.int64), b.values.view(np.int64))
            and np.array_equal(a.log_times_ns, b.log_times_ns))


def read_figures(directory: Path, messages: int, storage: str, repeats: int = 1) -> None:
    """Section 1: write the bag, time the readers (in turn, best of ``repeats``)."""
    path = directory / SUFFIXES[storage]
    seconds = write_bag(path, messages)
    size = path.stat().st_size / 1e6
    print(f'BagWriter: {messages} messages ({storage}, {size:.0f} MB) in {seconds:.1f} s: '
          f'{messages / seconds:,.0f} msg/s; peak RSS {peak_mb():.0f} MB')
    best: Dict[str, Tuple[int, float, float]] = {}
    for _ in range(repeats):
        for name, run in (('(a) rosbags raw messages()', raw_read),
                          ('(b) raw + reader.deserialize', deserialize_all),
                          ('(c) bags.read_samples', samples),
                          ('(d) BagReader.chunks (bulk)', bulk_chunks),
                          ('(e) chunks of (c), per message', per_message_chunks),
                          ("(f) chunks via rosbags' reader", rosbags_chunks)):
            count, seconds, cpu = timed_cpu(lambda: run(path))
            old = best.get(name, (count, seconds, cpu))
            best[name] = (count, min(old[1], seconds), min(old[2], cpu))
    results = {}
    for name, (count, seconds, cpu) in best.items():
        results[name] = count / seconds, count / cpu
        print(f'{name:32s} {count} msgs in {seconds:6.2f} s: {count / seconds:>10,.0f} msg/s; '
              f'CPU {cpu:6.2f} s: {count / cpu:>10,.0f} msg/s')
    (raw, raw_cpu), (deserialized, _), (ours, _), (bulk, bulk_cpu), (each, each_cpu), (
        before, before_cpu) = results.values()
    print(f'read_samples / raw = {ours / raw:.2f}, read_samples / deserialize = '
          f'{ours / deserialized:.2f}; peak RSS {peak_mb():.0f} MB')
    print(f'chunks / raw = {bulk / raw:.2f} (CPU: {bulk_cpu / raw_cpu:.2f}); per-message chunks '
          f'/ raw = {each / raw:.2f} (CPU: {each_cpu / raw_cpu:.2f}); bulk / per message = '
          f'{bulk / each:.2f}x (CPU: {bulk_cpu / each_cpu:.2f}x); the same samples: '
          f'{same_chunks(path)}')
    print(f"chunks (d) / chunks via rosbags' reader (f) = {bulk / before:.2f}x (CPU: "
          f'{bulk_cpu / before_cpu:.2f}x); (f) / raw = {before / raw:.2f} (CPU: '
          f'{before_cpu / raw_cpu:.2f})')
    gather_figures(path)


def skipped_figure(directory: Path, noise: int = 50_000) -> None:
    """Section 2: a reader skipping ``noise`` undecodable messages on another topic."""
    path = directory / 'noisy'
    garbage = b'\xff' * 40  # would make any deserialiser fail
    string = 'std_msgs/msg/String'
    types = TS2.types
    header = types['std_msgs/msg/Header']
    stamp_of = types['builtin_interfaces/msg/Time']
    with Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        other = writer.add_connection('/camera/info', string, typestore=TS2)
        ball = writer.add_connection('/ball', POINT_STAMPED, typestore=TS2)
        bat = writer.add_connection('/bat_pose', POSE_STAMPED, typestore=TS2)
        for i in range(noise):
            writer.write(other, i * 1000, garbage)
            if i % 10_000 == 5:
                stamp = header(stamp_of(0, i * 1000), 'w')
                point = types['geometry_msgs/msg/Point'](1.0, 2.0, 3.0)
                pose = types['geometry_msgs/msg/Pose'](
                    point, types['geometry_msgs/msg/Quaternion'](0.0, 0.0, 0.0, 1.0))
                writer.write(ball, i * 1000, TS2.serialize_cdr(
                    types[POINT_STAMPED](stamp, point), POINT_STAMPED))
                writer.write(bat, i * 1000 + 1, TS2.serialize_cdr(
                    types[POSE_STAMPED](stamp, pose), POSE_STAMPED))
    start = time.perf_counter()
    with BagReader(path) as bag:
        count = sum(1 for _ in bag.samples())
    seconds = time.perf_counter() - start
    print(f'BagReader past {noise:,} undecodable messages on another topic: {count} samples '
          f'in {seconds:.2f} s')
    shutil.rmtree(path)


def pitches(seed: int = 3) -> List[Row]:
    """Return three simulated pitches 20 s apart at 360 Hz as (stamp, role, values)."""
    rng = np.random.default_rng(seed)
    rows: List[Row] = []
    for k, kind in enumerate(('barrel', 'miss_over', 'handle')):
        start = DEFAULT_START_NS + (k + 1) * 20 * 10**9
        rows += sample(make_scenario(kind, rng), 360.0, rng, start_ns=start).messages('pose')
    return sorted(rows, key=lambda row: row[0])


def write_unrelated(path: Path, rows: Sequence[Row], unrelated: int,
                    span_s: float = 80.0) -> None:
    """Write tracker rows and ``unrelated`` String messages spread over ``span_s``."""
    with BagWriter(path) as bag:
        tick = bag.typestore.types['std_msgs/msg/String'](data='tick0001')
        step = int(span_s * 1e9) // max(unrelated, 1)
        k = 0
        for stamp, role, values in rows:
            while k < unrelated and DEFAULT_START_NS + k * step < stamp:
                bag.write_message('/chatter', tick, DEFAULT_START_NS + k * step)
                k += 1
            if role == 'ball':
                bag.write_point('/tracker/ball', stamp, 'world', values)
            else:
                bag.write_pose('/tracker/bat_pose', stamp, 'world', values[:3], values[3:])
        for k in range(k, unrelated):
            bag.write_message('/chatter', tick, DEFAULT_START_NS + k * step)


def unrelated_figures(directory: Path, storage: str, counts: Sequence[int]) -> None:
    """Section 3: write and analyze bags with each count of unrelated messages."""
    rows = pitches()
    peaks = []
    for count in counts:
        path = directory / (f'{storage}_{count}' + {'rosbag1': '.bag', 'sqlite3': '.db3'}.get(
            storage, '.mcap'))
        start = time.perf_counter()
        write_unrelated(path, rows, count)
        written = time.perf_counter() - start
        tracemalloc.start()
        start = time.perf_counter()
        try:
            analysis = analyze_bag(path, AnalysisOptions(), progress=False, use_truth=False)
            peak = tracemalloc.get_traced_memory()[1] / 1e6
        finally:
            tracemalloc.stop()
        seconds = time.perf_counter() - start
        peaks.append(peak)
        print(f'{storage:8s} {count:>9,} unrelated: written in {written:5.2f} s, analysed in '
              f'{seconds:5.2f} s (traced), peak traced {peak:5.2f} MB, '
              f'{len(analysis.impacts)} impacts, {analysis.messages} samples')
        path.unlink()
    if len(peaks) > 1:
        print(f'{storage:8s} peak growth from {counts[0]:,} to {counts[-1]:,} unrelated: '
              f'{peaks[-1] - peaks[0]:.2f} MB')


def main() -> None:
    """Run the three sections; print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--messages', type=int, default=1_000_000)
    parser.add_argument('--storage', choices=sorted(SUFFIXES), default='mcap')
    parser.add_argument('--repeats', type=int, default=1,
                        help="section 1's readers in turn this many times, best of each")
    parser.add_argument('--unrelated', default='20000,200000',
                        help='unrelated message counts of section 3, comma-separated ('
                        'ROS 1 uses 10000,60000 unless given); empty to skip the section')
    args = parser.parse_args()
    counts = [int(c) for c in args.unrelated.split(',') if c.strip()]
    with tempfile.TemporaryDirectory() as tmp:
        directory = Path(tmp)
        read_figures(directory, args.messages, args.storage, args.repeats)
        skipped_figure(directory)
        if counts:
            ros1 = counts if args.unrelated != '20000,200000' else [10_000, 60_000]
            for storage, each in (('mcap', counts), ('sqlite3', counts), ('rosbag1', ros1)):
                unrelated_figures(directory, storage, each)


if __name__ == '__main__':
    main()
