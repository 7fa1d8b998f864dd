"""The MCAP chunks read in place give rosbags' messages in rosbags' order, or decline."""

from pathlib import Path
import shutil
from typing import Any, List, Optional, Sequence, Tuple

from baseball_collision.bags import BagReader, POSE_STAMPED
from baseball_collision.bags import mcap, reader as reader_module
from baseball_collision.bags.decode import decode_chunk, decode_spans
from baseball_collision.bags.mcap import mcap_spans
from baseball_collision.errors import BagError
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer
from rosbags.typesys import get_typestore, Stores

from support.bagfiles import reference_message

REPO = Path(__file__).resolve().parents[2]
TS2 = get_typestore(Stores.ROS2_JAZZY)
T0 = 1_700_000_000_000_000_000
MESSAGES = 14000  # 70-94 bytes a record, 1 MB a chunk: two chunks


def _write(path: Path, log_times: Sequence[int], mode: CompressionMode = CompressionMode.NONE,
           frames: Sequence[str] = ('world',)) -> None:
    """Write poses on /bat and points on /ball (alternating) with these log times (ns)."""
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    if mode != CompressionMode.NONE:
        writer.set_compression(mode, CompressionFormat.ZSTD)
    with writer:
        bat = writer.add_connection('/bat', POSE_STAMPED, typestore=TS2)
        ball = writer.add_connection('/ball', 'geometry_msgs/msg/PointStamped', typestore=TS2)
        for k, log_time in enumerate(log_times):
            frame = frames[k % len(frames)]
            if k % 2:
                message = reference_message(TS2, 'geometry_msgs/msg/PointStamped', log_time,
                                            frame, (k, 1.0, 2.0))
                writer.write(ball, log_time, TS2.serialize_cdr(message, message.__msgtype__))
            else:
                message = reference_message(TS2, POSE_STAMPED, log_time, frame,
                                            (k, 1.0, 2.0, 0.0, 0.0, 0.0, 1.0))
                writer.write(bat, log_time, TS2.serialize_cdr(message, message.__msgtype__))


def _both(path: Path, topics: Optional[Sequence[str]] = None) -> Tuple[Any, List[Any]]:
    """Return (the spans' messages as a list, or None where declined; rosbags' list)."""
    with AnyReader([path]) as reader:
        connections = [c for c in reader.connections if topics is None or c.topic in topics]
        spans = mcap_spans(reader, connections)
        fast = None if spans is None else [
            message for each in spans for message in each.messages(range(len(each.codes)))]
        expected = list(reader.messages(connections=connections))
        return fast, expected


def _same(fast: List[Any], expected: List[Any]) -> None:
    """Assert the same triplets, the very same connection objects, in the same order."""
    assert [(m[1], m[2]) for m in fast] == [(m[1], m[2]) for m in expected]
    assert all(a[0] is b[0] for a, b in zip(fast, expected))


@pytest.mark.parametrize('mode', [CompressionMode.NONE, CompressionMode.STORAGE,
                                  CompressionMode.FILE])
def test_a_bag_directory_of_several_chunks(tmp_path: Path, mode: CompressionMode) -> None:
    """Uncompressed, zstd chunks, a compressed file: rosbags' messages; ties in file order."""
    times = [T0 + (k // 3) * 1_000_000 for k in range(MESSAGES)]  # threes share a log time
    _write(tmp_path / 'bag', times, mode, frames=('world', 'map', ''))
    fast, expected = _both(tmp_path / 'bag')
    assert fast is not None and len(expected) == MESSAGES
    _same(fast, expected)
    with AnyReader([tmp_path / 'bag']) as reader:
        assert len(list(reader.readers[0].storage.storages[0].chunks)) >= 2


def test_a_bare_file_one_topic_and_a_chunk_out_of_order_inside(tmp_path: Path) -> None:
    """A bare .mcap, one topic selected, a chunk whose records are not in log-time order."""
    times = [T0 + k * 1_000_000 for k in range(MESSAGES)]
    times[10], times[11], times[12] = times[12], times[10], times[11]  # within the first chunk
    _write(tmp_path / 'bag', times)
    bare = tmp_path / 'bare.mcap'
    shutil.copy(tmp_path / 'bag' / 'bag.mcap', bare)
    for topics in (None, ['/bat']):
        fast, expected = _both(bare, topics)
        assert fast is not None
        _same(fast, expected)
    assert [m[1] for m in expected] == sorted(m[1] for m in expected)


def test_the_bundled_mcap_bags() -> None:
    """Both bundled MCAP bags: the same messages; the others are not MCAP: declined."""
    for name in ('pitches_90hz.mcap', 'pitches_360hz.mcap'):
        fast, expected = _both(REPO / 'bags' / name)
        assert fast is not None and len(fast) > 1000
        _same(fast, expected)
    for name in ('pitches_120hz_sqlite3', 'pitches_240hz_noisy.bag'):
        assert _both(REPO / 'bags' / name)[0] is None


def test_overlapping_chunks_and_per_message_compression_are_left_to_rosbags(
        tmp_path: Path) -> None:
    """Chunks that overlap in time, or messages compressed one by one: declined; same samples."""
    half = MESSAGES // 2
    times = [T0 + k * 1_000_000 for k in range(half)] + [
        T0 + k * 1_000_000 + 500_000 for k in range(half)]  # the second half goes back
    _write(tmp_path / 'overlap', times)
    _write(tmp_path / 'message', times[:1000], CompressionMode.MESSAGE)
    for name in ('overlap', 'message'):
        fast, expected = _both(tmp_path / name)
        assert fast is None
        with BagReader(tmp_path / name) as bag:  # (through rosbags' reader)
            log_times = np.concatenate([c.log_times_ns for c in bag.chunks(4096)])
        assert log_times.tolist() == [m[1] for m in expected]
    with AnyReader([tmp_path / 'overlap']) as reader:
        chunks = list(reader.readers[0].storage.storages[0].chunks)
    assert max(c.message_start_time for c in chunks) < chunks[0].message_end_time  # overlap


def test_the_reader_chunks_equal_its_samples_through_the_fast_source(tmp_path: Path) -> None:
    """``BagReader.chunks`` (the fast source) gives what ``samples`` (rosbags) gives."""
    _write(tmp_path / 'bag', [T0 + (k // 2) * 2_777_777 for k in range(MESSAGES)],
           CompressionMode.STORAGE)
    with BagReader(tmp_path / 'bag') as bag:
        chunks = list(bag.chunks(4096))
    with BagReader(tmp_path / 'bag') as bag:
        samples = list(bag.samples())
    assert np.concatenate([c.stamps_ns for c in chunks]).tolist() == [
        s.stamp_ns for s in samples]
    assert np.concatenate([c.values for c in chunks])[:, 0].tolist() == [
        s.values[0] for s in samples]


def test_a_damaged_chunk_is_a_bag_error(tmp_path: Path) -> None:
    """A record whose length runs past its chunk: a BagError naming the bag, not a crash."""
    _write(tmp_path / 'bag', [T0 + k * 1_000_000 for k in range(200)])
    path = tmp_path / 'bag' / 'bag.mcap'
    data = bytearray(path.read_bytes())
    with AnyReader([path]) as reader:
        chunk = reader.readers[0].storage.chunks[0]
    # the chunk's records start after its header: opcode, length, 3 x u64, u32 crc, compression
    # string (4 + 0 bytes), u64 size; the first record's length field follows its opcode
    first = chunk.chunk_start_offset + 9 + 28 + 4 + 8
    data[first + 1:first + 9] = (10**9).to_bytes(8, 'little')
    path.write_bytes(bytes(data))
    with BagReader(path) as bag, pytest.raises(BagError, match='bag.mcap'):
        list(bag.chunks())


def test_the_walk_and_a_damaged_index_give_the_same_messages(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Records walked one by one, or an index that does not tile its chunk: the same."""
    _write(tmp_path / 'bag', [T0 + (k // 2) * 1_000_000 for k in range(4000)],
           frames=('world', 'mocap'))
    path = tmp_path / 'bag' / 'bag.mcap'
    indexed, expected = _both(path)
    _same(indexed, expected)
    with AnyReader([path]) as reader:
        chunk = reader.readers[0].storage.chunks[0]
    data = bytearray(path.read_bytes())
    entry = chunk.chunk_start_offset + chunk.chunk_length + 15 + 8 + 16  # 2nd entry's offset
    data[entry:entry + 8] = (int.from_bytes(data[entry:entry + 8], 'little') + 1).to_bytes(
        8, 'little')
    damaged = tmp_path / 'damaged.mcap'
    damaged.write_bytes(bytes(data))
    taken = []
    indexed_records = mcap._indexed
    monkeypatch.setattr(mcap, '_indexed', lambda *a: taken.append(indexed_records(*a)))
    for each in (path, damaged):  # (the spy returns None: both walked)
        walked, again = _both(each)
        _same(walked, again)
        assert len(walked) == 4000
    assert taken[0] is not None and taken[1] is None  # the damaged index did not tile


def test_spans_decode_as_their_messages_do() -> None:
    """decode_spans gives decode_chunk's chunk of the same messages, for every bundled bag."""
    for name in ('pitches_90hz.mcap', 'pitches_360hz.mcap'):
        with BagReader(REPO / 'bags' / name) as bag:
            reader = bag._open_reader()
            spans = next(mcap_spans(reader, bag._connections))
            messages = spans.messages(range(len(spans.codes)))
            pieces = (decode_spans(spans, bag._routes, lambda *a: bag._slow(reader, *a)),
                      decode_chunk(messages, bag._routes, lambda *a: bag._slow(reader, *a)))
        for a, b in zip(*pieces):
            assert np.array_equal(np.asarray(a), np.asarray(b))


def test_samples_of_an_mcap_bag_are_rosbags_path_samples(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``samples`` by chunks (MCAP) gives the per-message path's samples, field for field."""
    _write(tmp_path / 'bag', [T0 + (k // 2) * 2_777_777 for k in range(3000)],
           frames=('world', '', 'mocap_world_frame_with_a_long_name'))
    bags = [tmp_path / 'bag', REPO / 'bags' / 'pitches_90hz.mcap']
    by_chunks = []
    for path in bags:
        with BagReader(path) as bag:
            by_chunks.append(list(bag.samples()))
    monkeypatch.setattr(reader_module, 'mcap_spans', lambda *a: None)  # rosbags' reader
    for path, samples in zip(bags, by_chunks):
        with BagReader(path) as bag:
            expected = list(bag.samples())
        assert len(samples) == len(expected) > 500
        assert samples == expected
        assert all(type(a.stamp_ns) is int and len(a.values) == len(b.values)
                   for a, b in zip(samples, expected))
