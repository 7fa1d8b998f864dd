"""Tests for baseball_collision.bags reading: samples from real bags, streaming, errors."""

import ast
from pathlib import Path
import sqlite3
import struct
import subprocess
import sys
import threading
from typing import Any, List

from baseball_collision.bags import (
    BagReader, BagWriter, count_messages, POINT_STAMPED, POSE_STAMPED, read_samples,
    TopicSelection)
from baseball_collision.bags import reader as reader_module
from baseball_collision.bags.decode import chunk_samples, SampleChunk
from baseball_collision.errors import BagError
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
from support.bagfiles import (
    expected_samples, reference_bag, reference_message, tracker_rows, TS2)
from support.bundled import bag_path, BAGS


def test_module_imports_neither_rclpy_nor_the_tools() -> None:
    """The bags layer is I/O on rosbags and the core: usable without ROS."""
    code = ('import sys, baseball_collision.bags; '
            'print(sorted(m for m in sys.modules if m.split(".")[0] in '
            '("rclpy", "baseball_collision")))')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         check=True, timeout=60)
    loaded = set(ast.literal_eval(out.stdout.strip()))
    assert 'baseball_collision.bags' in loaded
    assert not any(m.startswith(('rclpy', 'baseball_collision.ros', 'baseball_collision.tools'))
                   for m in loaded), loaded


def test_bare_files_read_like_directories(tmp_path: Path) -> None:
    """The storage file inside a bag directory reads on its own (bare .mcap and .db3)."""
    rows = tracker_rows(8)
    roles = {'/ball': 'ball', '/bat/pose': 'bat_pose'}
    for name, suffix in (('dir_mcap', '.mcap'), ('dir_sqlite3', '.db3')):
        reference_bag(tmp_path / name, rows)
        bare = tmp_path / name / f'{name}{suffix}'
        assert list(read_samples(bare)) == expected_samples(rows, roles)


@pytest.mark.parametrize('name', ['dir_mcap', 'dir_sqlite3', 'ros1.bag'])
def test_samples_come_in_log_time_order_with_header_stamps(tmp_path: Path, name: str) -> None:
    """Order is the bag's log time across topics (as a node would receive), stamps are headers."""
    knob = [('/bat/knob', POINT_STAMPED, 5_000 + i, 'w', (0.0, 0.0, float(i)), 100 + 30 * i)
            for i in range(5)]
    tip = [('/bat/tip', POINT_STAMPED, 9_000 + i, 'w', (1.0, 0.0, float(i)), 110 + 30 * i)
           for i in range(5)]
    ball = [('/ball', POINT_STAMPED, 1_000 + i, 'w', (2.0, 0.0, float(i)), 95 + 10 * i)
            for i in range(15)]
    rows = ball + knob + tip  # written topic by topic, not in time order
    reference_bag(tmp_path / name, rows)
    samples = list(read_samples(tmp_path / name))
    assert [s.log_time_ns for s in samples] == sorted(r[5] for r in rows)
    assert samples == expected_samples(
        rows, {'/ball': 'ball', '/bat/knob': 'knob', '/bat/tip': 'tip'})
    assert [s.role for s in samples[:4]] == ['ball', 'knob', 'ball', 'tip']


@pytest.mark.parametrize('size', [1, 4, 7, 1000])
def test_chunks_are_the_samples_as_arrays(tmp_path: Path, size: int) -> None:
    """``BagReader.chunks`` gives every sample of ``samples``, in order, as arrays."""
    reference_bag(tmp_path / 'dir_mcap', tracker_rows(24))  # points and poses mixed
    with BagReader(tmp_path / 'dir_mcap') as bag:
        samples = list(bag.samples())
    with BagReader(tmp_path / 'dir_mcap') as bag:
        chunks = list(bag.chunks(size))
    assert [len(chunk.stamps_ns) for chunk in chunks[:-1]] == [size] * (len(chunks) - 1)
    codes = {'ball': 0, 'bat_pose': 1, 'knob': 2, 'tip': 3}
    rebuilt = [(codes[s.role], s.stamp_ns, s.frame_id, s.values + (0.0,) * (7 - len(s.values)),
                s.log_time_ns) for s in samples]
    columns = [zip(chunk.roles, chunk.stamps_ns, chunk.frame_ids, chunk.values.tolist(),
                   chunk.log_times_ns) for chunk in chunks]
    assert [(int(role), int(stamp), frame, tuple(row), int(log))
            for rows in columns for role, stamp, frame, row, log in rows] == rebuilt


def _same_chunks(got: List[SampleChunk], expected: List[SampleChunk]) -> None:
    """Assert two lists of chunks hold the same samples, values to the bit."""
    assert len(got) == len(expected)
    for a, b in zip(got, expected):
        assert a.roles.dtype == b.roles.dtype and a.values.dtype == b.values.dtype
        assert np.array_equal(a.roles, b.roles) and np.array_equal(a.stamps_ns, b.stamps_ns)
        assert a.frame_ids == b.frame_ids and all(type(f) is str for f in a.frame_ids)
        assert np.array_equal(a.values.view(np.int64), b.values.view(np.int64))
        assert np.array_equal(a.log_times_ns, b.log_times_ns)


def _per_message(path: Path, size: int) -> List[SampleChunk]:
    """Return the chunks of the per-message decoder (``samples``) for a bag."""
    with BagReader(path) as bag:
        return list(chunk_samples(bag.samples(), size))


@pytest.mark.parametrize('name', ['dir_mcap', 'dir_sqlite3', 'ros1.bag', 'big_endian'])
@pytest.mark.parametrize('size', [1, 5, 1000])
def test_bulk_chunks_equal_the_per_message_decoder(tmp_path: Path, name: str,
                                                   size: int) -> None:
    """
    ``chunks``, decoded in bulk, gives the per-message decoder's samples.

    Frames of every CDR padding, stamps at the int32 edge, points and poses, one long run of
    one layout, and big-endian CDR (the fallback).
    """
    path = tmp_path / name
    rows = tracker_rows(40) + [('/ball', POINT_STAMPED, 5 * i, 'w', (1.0, 2.0, float(i)),
                                900_000 + i) for i in range(30)]  # one layout: one group
    reference_bag(path, rows, little_endian=name != 'big_endian')
    with BagReader(path) as bag:
        got = list(bag.chunks(size))
    _same_chunks(got, _per_message(path, size))
    assert sum(len(chunk.stamps_ns) for chunk in got) == len(rows)


def test_one_layout_is_decoded_without_the_per_message_decoder(
        tmp_path: Path, monkeypatch: Any) -> None:
    """A chunk of one frame_id per topic is read from the joined bytes alone."""
    _multi_chunk_bag(tmp_path / 'ok.mcap', 3000)  # one frame_id: no 'MARKER' below 9000
    expected = _per_message(tmp_path / 'ok.mcap', 1024)

    def refuse(*args: Any) -> None:
        raise AssertionError('the per-message decoder was used')
    monkeypatch.setattr('baseball_collision.bags.decode.decode_samples', refuse)
    with BagReader(tmp_path / 'ok.mcap') as bag:
        _same_chunks(list(bag.chunks(1024)), expected)


@pytest.mark.parametrize('name', sorted(BAGS))
def test_bulk_chunks_of_the_bundled_bags(name: str) -> None:
    """Every bundled bag (MCAP, sqlite3, ROS 1) reads the same in bulk as message by message."""
    with BagReader(bag_path(name)) as bag:
        got = list(bag.chunks(8192))
    _same_chunks(got, _per_message(bag_path(name), 8192))
    with BagReader(bag_path(name)) as bag:  # (and read ahead, in small chunks)
        _same_chunks(list(bag.chunks(500, read_ahead=2)), _per_message(bag_path(name), 500))


def _reading_threads() -> List[threading.Thread]:
    """Return the live read-ahead threads."""
    return [thread for thread in threading.enumerate() if thread.name == 'read-ahead']


@pytest.mark.parametrize('name', ['dir_mcap', 'dir_sqlite3', 'ros1.bag'])
def test_chunks_read_ahead_are_the_same_chunks(tmp_path: Path, name: str,
                                               monkeypatch: Any) -> None:
    """
    ``chunks(read_ahead=k)`` gives the chunks of ``chunks()``, reading on another thread.

    MCAP file chunks and sqlite3 batches are read on the read-ahead thread (the decode on the
    caller's); a ROS 1 bag is read as without it. The thread is gone once the chunks end.
    """
    path = tmp_path / name
    _multi_chunk_bag(path) if name == 'dir_mcap' else reference_bag(path, tracker_rows(900))
    with BagReader(path) as bag:
        expected = list(bag.chunks(100))
    decoded_on = set()
    decode = reader_module.decode_spans

    def watched(*args: Any) -> SampleChunk:
        decoded_on.add(threading.current_thread().name)
        return decode(*args)
    monkeypatch.setattr(reader_module, 'decode_spans', watched)
    spans_on = set()
    spans = reader_module.BagReader._spans

    def watched_spans(self: BagReader, *args: Any) -> Any:
        found = spans(self, *args)
        if found is None:
            return None

        def taken() -> Any:
            for each in found:
                spans_on.add(threading.current_thread().name)
                yield each
        return taken()
    monkeypatch.setattr(reader_module.BagReader, '_spans', watched_spans)
    for depth in (1, 3):
        with BagReader(path) as bag:
            _same_chunks(list(bag.chunks(100, read_ahead=depth)), expected)
            assert not _reading_threads()
    if name == 'ros1.bag':
        assert not spans_on and not decoded_on
    else:
        assert spans_on == {'read-ahead'} and decoded_on == {threading.current_thread().name}
    with BagReader(path) as bag, pytest.raises(BagError, match='not -1'):
        bag.chunks(100, read_ahead=-1)


@pytest.mark.parametrize('name', ['dir_mcap', 'dir_sqlite3'])
def test_closing_a_bag_stops_its_read_ahead(tmp_path: Path, name: str) -> None:
    """A bag closed with chunks still unread stops the read-ahead thread first, then closes."""
    path = tmp_path / name
    _multi_chunk_bag(path) if name == 'dir_mcap' else reference_bag(path, tracker_rows(900))
    bag = BagReader(path)
    bag.open()
    chunks = bag.chunks(10, read_ahead=2)
    first = next(chunks)
    assert len(first.stamps_ns) == 10 and _reading_threads()
    bag.close()
    assert not _reading_threads()
    with pytest.raises(BagError, match='closed while reading ahead'):
        list(chunks)  # (the file chunk or batch in hand, then not taken for the bag's end)


def test_the_jazzy_typestore_is_built_only_for_a_bag_without_definitions(
        tmp_path: Path) -> None:
    """A bag with type definitions opens without it; one without them reads through it."""
    code = ('import sys; from baseball_collision.bags import read_samples; '
            'n = sum(1 for _ in read_samples(sys.argv[1])); '
            'print(n, "rosbags.typesys.stores.ros2_jazzy" in sys.modules)')
    rows = tracker_rows(6)
    reference_bag(tmp_path / 'dir_sqlite3', rows)
    expected = expected_samples(rows, {'/ball': 'ball', '/bat/pose': 'bat_pose'})
    out = subprocess.run([sys.executable, '-c', code, str(tmp_path / 'dir_sqlite3')],
                         capture_output=True, text=True, check=True, timeout=60)
    assert out.stdout.split() == [str(len(expected)), 'False']
    with sqlite3.connect(next((tmp_path / 'dir_sqlite3').glob('*.db3'))) as db:
        db.execute('DELETE FROM message_definitions')  # as a bag from before Iron
    out = subprocess.run([sys.executable, '-c', code, str(tmp_path / 'dir_sqlite3')],
                         capture_output=True, text=True, check=True, timeout=60)
    assert out.stdout.split() == [str(len(expected)), 'True']
    assert list(read_samples(tmp_path / 'dir_sqlite3')) == expected


def test_unrelated_topics_are_never_decoded(tmp_path: Path, monkeypatch: Any) -> None:
    """50k messages on another topic are skipped undecoded (they are not even valid CDR)."""
    path = tmp_path / 'noisy'
    garbage = b'\xff' * 40  # would make any deserialiser fail
    with Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        noise = writer.add_connection('/camera/info', 'std_msgs/msg/String', typestore=TS2)
        ball = writer.add_connection('/ball', POINT_STAMPED, typestore=TS2)
        bat = writer.add_connection('/bat_pose', POSE_STAMPED, typestore=TS2)
        for i in range(50_000):
            writer.write(noise, i * 1000, garbage)
            if i % 10_000 == 5:
                stamp = i * 1000
                writer.write(ball, stamp, TS2.serialize_cdr(reference_message(
                    TS2, POINT_STAMPED, stamp, 'w', (1.0, 2.0, 3.0)), POINT_STAMPED))
                writer.write(bat, stamp + 1, TS2.serialize_cdr(
                    reference_message(TS2, POSE_STAMPED, stamp, 'w', (0, 0, 0, 0, 0, 0, 1.0)),
                    POSE_STAMPED))
    requested = []
    original, spans = AnyReader.messages, reader_module.mcap_spans

    def spy(self: AnyReader, connections: Any = (), *args: Any, **kwargs: Any) -> Any:
        requested.append(sorted(c.topic for c in connections))
        return original(self, connections, *args, **kwargs)

    def spans_spy(reader: AnyReader, connections: Any) -> Any:
        requested.append(sorted(c.topic for c in connections))
        return spans(reader, connections)

    monkeypatch.setattr(AnyReader, 'messages', spy)
    monkeypatch.setattr(reader_module, 'mcap_spans', spans_spy)  # the MCAP chunks in place
    with BagReader(path) as bag:
        assert bag.message_count == 10
        samples = list(bag.samples())
    assert requested == [['/ball', '/bat_pose']]
    assert [s.role for s in samples] == ['ball', 'bat_pose'] * 5
    requested.clear()
    monkeypatch.setattr(reader_module, 'mcap_spans', lambda *a: None)  # rosbags' reader
    with BagReader(path) as bag:
        assert [s.role for s in bag.samples()] == ['ball', 'bat_pose'] * 5
    assert requested == [['/ball', '/bat_pose']]


def test_message_count_matches_what_is_read(tmp_path: Path) -> None:
    """message_count / count_messages (from the index) equal the number of samples."""
    rows = tracker_rows(9)
    reference_bag(tmp_path / 'b.bag', rows, extra_topics=[('/other', 'std_msgs/msg/String')])
    assert count_messages(tmp_path / 'b.bag') == len(rows) == len(list(
        read_samples(tmp_path / 'b.bag')))


def test_selection_from_another_bag_and_explicit_topics(tmp_path: Path) -> None:
    """A ready-made selection is checked against the bag; names and a selection don't mix."""
    rows = tracker_rows(3)
    reference_bag(tmp_path / 'a', rows)
    with BagReader(tmp_path / 'a') as bag:
        selection = bag.selection
        assert bag.topics == {'/ball': POINT_STAMPED, '/bat/pose': POSE_STAMPED}
        assert bag.start_time_ns == 1
    assert len(list(read_samples(tmp_path / 'a', selection))) == len(rows)
    assert len(list(read_samples(tmp_path / 'a', ball='/ball', bat_pose='/bat/pose'))) == 6
    other = TopicSelection(ball='/ball', bat_pose='/somewhere/else')
    with pytest.raises(BagError, match="--bat-pose-topic '/somewhere/else' is not in the bag"):
        list(read_samples(tmp_path / 'a', other))
    with pytest.raises(BagError, match='not both'):
        BagReader(tmp_path / 'a', selection, ball='/ball')
    with pytest.raises(BagError, match='unknown topic roles: bat'):
        list(read_samples(tmp_path / 'a', bat='/bat/pose'))
    with pytest.raises(BagError, match='is not open'):
        BagReader(tmp_path / 'a').samples()


# --- bad inputs -----------------------------------------------------------------------------

def _raises_one_line(path: Path, **kwargs: Any) -> str:
    with pytest.raises(BagError) as caught:
        for _ in read_samples(path, **kwargs):
            pass
    message = str(caught.value)
    assert message and '\n' not in message
    return message


def test_bad_paths_and_non_bags(tmp_path: Path) -> None:
    """Missing path, text files, a foreign sqlite3 file, a bare directory: one-line BagError."""
    assert 'not found' in _raises_one_line(tmp_path / 'missing.mcap')
    (tmp_path / 'notes.txt').write_text('not a bag\n')
    _raises_one_line(tmp_path / 'notes.txt')
    (tmp_path / 'fake.mcap').write_text('not a bag\n')
    assert 'no .mcap recording' in _raises_one_line(tmp_path / 'fake.mcap')  # (not the magic)
    (tmp_path / 'fake.bag').write_text('not a bag\n')
    assert 'no .bag recording' in _raises_one_line(tmp_path / 'fake.bag')
    connection = sqlite3.connect(tmp_path / 'other.db3')
    connection.execute('CREATE TABLE people (name TEXT)')
    connection.commit()
    connection.close()
    _raises_one_line(tmp_path / 'other.db3')
    (tmp_path / 'folder').mkdir()
    _raises_one_line(tmp_path / 'folder')


@pytest.mark.parametrize('name', ['dir_mcap', 'e.db3', 'e.bag'])
def test_empty_bags(tmp_path: Path, name: str) -> None:
    """A bag without messages, or whose selected topic has none, is refused."""
    with BagWriter(tmp_path / name) as bag:
        bag.add_topic('/ball', POINT_STAMPED)
        bag.add_topic('/bat', POSE_STAMPED)
    assert 'no messages' in _raises_one_line(tmp_path / name)
    with BagWriter(tmp_path / f'half_{name}') as bag:
        bag.add_topic('/bat', POSE_STAMPED)
        bag.write_point('/ball', 5, 'w', (0.0, 0.0, 0.0))
    said = _raises_one_line(tmp_path / f'half_{name}')
    assert "the bat_pose topic (found by name and type) '/bat' has no messages" in said
    assert said.endswith('messages by topic: /bat (0), /ball (1)') or \
        said.endswith('messages by topic: /ball (1), /bat (0)')
    with pytest.raises(BagError, match="^--bat-pose-topic '/bat' has no messages"):
        list(read_samples(tmp_path / f'half_{name}', bat_pose='/bat'))


def _multi_chunk_bag(path: Path, count: int = 12_000) -> None:
    """Write ~2.5 MB (three MCAP chunks); message 9000 has the frame_id 'MARKER'."""
    with BagWriter(path) as bag:
        for i in range(count):
            frame = 'MARKER' if i == 9000 else 'world_frame'
            bag.write_point('/ball', i * 1000, frame, (1.0, 2.0, 3.0))
            bag.write_pose('/bat', i * 1000 + 1, 'world_frame', (0, 0, 0), (0, 0, 0, 1))


def test_truncated_mcap_is_refused(tmp_path: Path) -> None:
    """An MCAP cut mid-chunk (e.g. a recorder killed) raises BagError, not a rosbags error."""
    _multi_chunk_bag(tmp_path / 'full.mcap', 4000)
    data = (tmp_path / 'full.mcap').read_bytes()
    (tmp_path / 'cut.mcap').write_bytes(data[:len(data) // 2])
    assert 'cannot read bag' in _raises_one_line(tmp_path / 'cut.mcap')
    reference_bag(tmp_path / 'r.bag', tracker_rows(40))
    data = (tmp_path / 'r.bag').read_bytes()
    (tmp_path / 'cut.bag').write_bytes(data[:len(data) // 2])
    _raises_one_line(tmp_path / 'cut.bag')


def test_corruption_found_while_iterating_is_a_bag_error(tmp_path: Path) -> None:
    """Damage inside a later chunk surfaces lazily, after good samples, as BagError."""
    _multi_chunk_bag(tmp_path / 'ok.mcap')
    data = bytearray((tmp_path / 'ok.mcap').read_bytes())
    marker = data.index(b'MARKER\x00')
    length_field = marker - 4  # uint32 frame_id length in the CDR header

    bad_payload = bytearray(data)
    bad_payload[length_field:length_field + 4] = struct.pack('<I', 0x7FFFFFF0)
    (tmp_path / 'payload.mcap').write_bytes(bad_payload)

    record_start = marker - 16 - 22 - 8 - 1  # CDR head, message record fields, length, opcode
    assert data[record_start] == 0x05
    bad_record = bytearray(data)
    bad_record[record_start + 1:record_start + 9] = struct.pack('<Q', 2**40)
    (tmp_path / 'record.mcap').write_bytes(bad_record)

    for name, words in (('payload.mcap', 'corrupt'), ('record.mcap', 'cannot read bag')):
        seen = 0
        with pytest.raises(BagError) as caught:
            for _ in read_samples(tmp_path / name):
                seen += 1
        assert seen > 1000, 'the error should come lazily, after the intact chunks'
        assert words in str(caught.value) and '\n' not in str(caught.value)
        for size, ahead in ((1000, 0), (8192, 0), (1000, 2)):  # the bad message inside a
            seen = 0  # chunk's group or first in it; read ahead on another thread
            with pytest.raises(BagError) as caught, BagReader(tmp_path / name) as bag:
                for chunk in bag.chunks(size, read_ahead=ahead):
                    seen += len(chunk.stamps_ns)
            assert seen >= 1000 and words in str(caught.value)
            assert not _reading_threads()
