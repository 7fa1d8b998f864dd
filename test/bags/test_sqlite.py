"""A sqlite3 bag's rows read in batches give rosbags' messages in rosbags' order, or decline."""

from pathlib import Path
import shutil
import sqlite3
from typing import Any, Dict, List, Optional, Sequence, Tuple

import apsw
from baseball_collision.bags import BagReader, POINT_STAMPED, POSE_STAMPED
from baseball_collision.bags import sqlite as sqlite_module
from baseball_collision.bags.decode import decode_chunk, decode_spans, SampleChunk
from baseball_collision.bags.sqlite import query, sqlite_spans
from baseball_collision.errors import BagError
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer
from rosbags.typesys import get_typestore, Stores
from support.bagfiles import reference_message
import yaml

REPO = Path(__file__).resolve().parents[2]
TS2 = get_typestore(Stores.ROS2_JAZZY)
T0 = 1_700_000_000_000_000_000
Written = Tuple[str, int, Sequence[float]]  # topic, log time, values (the stamp is the log time)


def _message(topic: str, log_time: int, values: Sequence[float], frame: str = 'world') -> bytes:
    """Return a CDR PoseStamped (on /bat) or PointStamped (any other topic)."""
    msgtype = POSE_STAMPED if topic == '/bat' else POINT_STAMPED
    values = tuple(values) + (0.0, 0.0, 0.0, 1.0) if msgtype == POSE_STAMPED else values
    return TS2.serialize_cdr(reference_message(TS2, msgtype, log_time, frame, values), msgtype)


def _write(path: Path, messages: Sequence[Written], mode: CompressionMode = CompressionMode.NONE,
           frames: Sequence[str] = ('world',), raw: Optional[Dict[int, bytes]] = None) -> None:
    """
    Write a sqlite3 bag of these messages in this order (rowid order).

    Topics: /bat (poses), /ball, /chatter (``std_msgs/String``) and /empty (points, none
    written). ``raw``: bytes to write instead, by the message's index.
    """
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.SQLITE3)
    if mode != CompressionMode.NONE:
        writer.set_compression(mode, CompressionFormat.ZSTD)
    with writer:
        connections = {
            '/bat': writer.add_connection('/bat', POSE_STAMPED, typestore=TS2),
            '/ball': writer.add_connection('/ball', POINT_STAMPED, typestore=TS2),
            '/chatter': writer.add_connection('/chatter', 'std_msgs/msg/String', typestore=TS2),
            '/empty': writer.add_connection('/empty', POINT_STAMPED, typestore=TS2)}
        for k, (topic, log_time, values) in enumerate(messages):
            if raw is not None and k in raw:
                data = raw[k]
            elif topic == '/chatter':
                data = b'\xff' * 40  # not even CDR: never to be decoded
            else:
                data = _message(topic, log_time, values, frames[k % len(frames)])
            writer.write(connections[topic], log_time, data)


def _pairs(count: int, step: int = 1_000_000, tie: int = 1) -> List[Written]:
    """Return bat and ball messages in turn, ``tie`` of them at each log time."""
    return [('/bat' if k % 2 == 0 else '/ball', T0 + (k // tie) * step, (float(k), 1.0, 2.0))
            for k in range(count)]


def _both(path: Path, topics: Optional[Sequence[str]] = None,
          size: int = 4096) -> Tuple[Optional[List[Any]], List[Any], List[int]]:
    """Return (the spans' messages, or None where declined; rosbags' list; span lengths)."""
    with AnyReader([path]) as reader:
        connections = [c for c in reader.connections if topics is None or c.topic in topics]
        spans = sqlite_spans(reader, connections, size)
        fast, lengths = None, []
        if spans is not None:
            fast = []
            for each in spans:
                fast += each.messages(range(len(each.codes)))
                lengths.append(len(each.codes))
        expected = list(reader.messages(connections=connections))
        return fast, expected, lengths


def _same(fast: Optional[List[Any]], expected: List[Any]) -> None:
    """Assert the same triplets, the very same connection objects, in the same order."""
    assert fast is not None
    assert [(m[1], m[2]) for m in fast] == [(m[1], m[2]) for m in expected]
    assert all(a[0] is b[0] for a, b in zip(fast, expected))


def _cut(lengths: List[int], total: int, size: int) -> None:
    """Assert spans of ``size`` messages, the last fewer (none empty)."""
    assert sum(lengths) == total
    assert lengths == [size] * (total // size) + ([total % size] if total % size else [])


def _rosbags_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make ``BagReader`` read through rosbags' ``AnyReader.messages`` (the path before)."""
    monkeypatch.setattr(sqlite_module, 'sqlite_spans', lambda *a: None)


def _chunks_and_samples(path: Path, size: int = 4096) -> Tuple[List[SampleChunk], List[Any]]:
    """Return ``BagReader.chunks(size)`` and ``BagReader.samples()`` of a bag."""
    with BagReader(path) as bag:
        chunks = list(bag.chunks(size))
    with BagReader(path) as bag:
        samples = list(bag.samples())
    return chunks, samples


def _same_chunks(got: List[SampleChunk], expected: List[SampleChunk]) -> None:
    """Assert two lists of chunks hold the same samples, values to the bit, cut alike."""
    assert [len(c.stamps_ns) for c in got] == [len(c.stamps_ns) for c in expected]
    for a, b in zip(got, expected):
        assert a.roles.dtype == b.roles.dtype and np.array_equal(a.roles, b.roles)
        assert np.array_equal(a.stamps_ns, b.stamps_ns) and a.frame_ids == b.frame_ids
        assert np.array_equal(a.values.view(np.int64), b.values.view(np.int64))
        assert np.array_equal(a.log_times_ns, b.log_times_ns)


def _as_rosbags_reads(path: Path, size: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """Assert ``chunks`` and ``samples`` equal what they give through rosbags' reader."""
    chunks, samples = _chunks_and_samples(path, size)
    with monkeypatch.context() as patch:
        _rosbags_path(patch)
        expected_chunks, expected_samples = _chunks_and_samples(path, size)
    _same_chunks(chunks, expected_chunks)
    assert samples == expected_samples and len(samples) > 0
    assert all(type(a.stamp_ns) is int and len(a.values) == len(b.values)
               for a, b in zip(samples, expected_samples))


@pytest.mark.parametrize('mode', [CompressionMode.NONE, CompressionMode.FILE])
@pytest.mark.parametrize('size', [1, 7, 4096])
def test_a_bag_directory_and_its_bare_file(tmp_path: Path, mode: CompressionMode,
                                           size: int) -> None:
    """A directory (uncompressed, a compressed file) and its bare .db3: rosbags' messages."""
    count = 9000 if size > 1 else 300
    _write(tmp_path / 'bag', _pairs(count, tie=3), mode, frames=('world', 'map', ''))
    fast, expected, lengths = _both(tmp_path / 'bag', size=size)
    _same(fast, expected)
    _cut(lengths, count, size)
    if mode == CompressionMode.NONE:
        bare = tmp_path / 'bare.db3'
        shutil.copy(tmp_path / 'bag' / 'bag.db3', bare)
        for topics in (None, ['/bat']):
            fast, expected, lengths = _both(bare, topics, size)
            _same(fast, expected)
            _cut(lengths, len(expected), size)


class _Spy:
    """
    A file's apsw connection, recording what is executed on it (and failing batches).

    :param fail_batches: the error every batch query raises (None: none fails).
    """

    def __init__(self, connection: Any, fail_batches: Optional[Exception] = None) -> None:
        self.connection, self.executed, self.fail = connection, [], fail_batches

    def execute(self, text: str, arguments: Any = ()) -> Any:
        self.executed.append((text, tuple(arguments)))
        if self.fail is not None and text.startswith('SELECT count(*)'):
            raise self.fail
        return self.connection.execute(text, arguments)


Executed = List[Tuple[str, Any]]


def _spied(path: Path, size: int,
           fail_batches: Optional[Exception] = None) -> Tuple[List[Any], List[Any], Executed]:
    """Return (the spans' messages, rosbags' messages, what the spans ran on the file)."""
    with AnyReader([path]) as reader:
        storage = reader.readers[0].storage.storages[0]
        spy = storage.dbconn = _Spy(storage.dbconn, fail_batches)
        selected = [c for c in reader.connections if c.topic in ('/bat', '/ball')]
        try:
            fast = [m for each in sqlite_spans(reader, selected, size)
                    for m in each.messages(range(len(each.codes)))]
        finally:  # (rosbags closes its own connection)
            storage.dbconn = spy.connection
        rosbags = list(reader.messages(connections=selected))
    return fast, rosbags, spy.executed


def test_the_query_is_rosbags_own(tmp_path: Path) -> None:
    """
    What runs on the file's connection is rosbags' query, or its batches checked against it.

    The plan of rosbags' own text with its arguments is read first; the batches walk the index
    it walks; with batches declined (no timestamp index: rosbags' plan sorts) the query run
    is rosbags' text and arguments, once.
    """
    _write(tmp_path / 'bag', _pairs(50) + [('/chatter', T0, ())])
    with AnyReader([tmp_path / 'bag']) as reader:
        storage = reader.readers[0].storage.storages[0]
        spy = storage.dbconn = _Spy(storage.dbconn)
        selected = [c for c in reader.connections if c.topic in ('/bat', '/ball')]
        rosbags = list(reader.messages(connections=selected))
        storage.dbconn = spy.connection
    (text, arguments), = spy.executed
    assert text == query(arguments)
    fast, expected, executed = _spied(tmp_path / 'bag', 16)
    _same(fast, expected)
    assert [(m[1], m[2]) for m in fast] == [(m[1], m[2]) for m in rosbags]
    assert ('EXPLAIN QUERY PLAN ' + text, arguments) in executed
    batches = [each for each in executed if each[0].startswith('SELECT count(*)')]
    assert len(batches) == 4 and all('INDEXED BY "timestamp_idx"' in t for t, _ in batches)
    assert not any(t == text for t, _ in executed)  # (the rows never taken one by one)
    with sqlite3.connect(tmp_path / 'bag' / 'bag.db3') as db:
        db.execute('DROP INDEX timestamp_idx')
    fast, expected, executed = _spied(tmp_path / 'bag', 16)
    _same(fast, expected)
    assert [each for each in executed if not each[0].startswith(('EXPLAIN', 'PRAGMA'))] == [
        (text, arguments)]


@pytest.mark.parametrize('size', [1, 5, 64])
def test_ties_across_batches_and_a_batch_that_fails(tmp_path: Path, size: int,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Log times shared by many rows, cut by batches anywhere: rosbags' rows, cut alike.

    Ties longer than a batch (a batch of one log time after another), longer than
    ``BATCH_TIES`` (the rest row by row from there), and every batch failing (row by row).
    """
    messages = _pairs(120, tie=40) + _pairs(30, tie=1)[::-1] + _pairs(9, tie=3)
    messages = [(topic, log_time + (k >= 120) * 10**9, values)
                for k, (topic, log_time, values) in enumerate(messages)]
    _write(tmp_path / 'bag', messages)
    for ties in (sqlite_module.BATCH_TIES, 50, 0):
        monkeypatch.setattr(sqlite_module, 'BATCH_TIES', ties)
        fast, expected, lengths = _both(tmp_path / 'bag', ['/bat', '/ball'], size)
        _same(fast, expected)
        _cut(lengths, len(messages), size)
    fast, expected, executed = _spied(tmp_path / 'bag', size,
                                      fail_batches=apsw.TooBigError('string or blob too big'))
    _same(fast, expected)
    assert sum(t.startswith('SELECT count(*)') for t, _ in executed) == 1  # then row by row


def test_a_bug_on_the_fast_path_is_raised_not_read_around(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Only SQLite's errors (and log times that do not parse) send a file to the row path.

    Anything else raised while a batch or the plan is read is a bug: it comes out, not the
    rows read another way.
    """
    _write(tmp_path / 'bag', _pairs(50))
    with pytest.raises(RuntimeError, match='a bug in the batch'):
        _spied(tmp_path / 'bag', 16, fail_batches=RuntimeError('a bug in the batch'))

    def broken_plan(*args: Any) -> None:
        raise KeyError('a bug in the plan')
    monkeypatch.setattr(sqlite_module, '_plan_walk', broken_plan)
    with pytest.raises(KeyError, match='a bug in the plan'):
        _spied(tmp_path / 'bag', 16)


def test_ties_across_topics_come_in_rosbags_order(tmp_path: Path) -> None:
    """Log times shared across topics, written out of time order: rosbags' order, rowid order."""
    messages = []
    for k in range(600):  # in each group of 6: three log times, each on both topics
        log_time = T0 + (k // 6) * 1_000_000 + (5 - k % 6) // 2 * 1000
        messages.append(('/ball' if k % 3 else '/bat', log_time, (float(k), 0.0, 0.0)))
    _write(tmp_path / 'bag', messages)
    fast, expected, _ = _both(tmp_path / 'bag', size=100)
    _same(fast, expected)
    log_times = [m[1] for m in expected]
    assert log_times == sorted(log_times) and len(set(log_times)) == 300
    # each tie as written (rosbags' query walks the timestamp index: ties by rowid)
    order = sorted(range(600), key=lambda k: (messages[k][1], k))
    assert [m[2] for m in expected] == [_message(*messages[k]) for k in order]
    assert [m[0].topic for m in fast] == [messages[k][0] for k in order]


def test_unrelated_topics_and_an_empty_selection(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """Unrelated messages are never read; a topic without messages: nothing; none: declined."""
    messages = []
    for k, each in enumerate(_pairs(400)):
        messages += [each, ('/chatter', each[1] + 10, ())] * (1 + k % 2)
    _write(tmp_path / 'bag', messages)
    fast, expected, lengths = _both(tmp_path / 'bag', ['/ball', '/bat'], 128)
    _same(fast, expected)
    _cut(lengths, 400 + 200, 128)
    fast, expected, lengths = _both(tmp_path / 'bag', ['/empty'])
    assert fast == expected == [] and lengths == []
    with AnyReader([tmp_path / 'bag']) as reader:
        assert sqlite_spans(reader, [], 64) is None  # (rosbags reads every topic then)
        with pytest.raises(ValueError):
            sqlite_spans(reader, reader.connections, 0)
    _as_rosbags_reads(tmp_path / 'bag', 100, monkeypatch)


def _split(directory: Path, parts: Sequence[Path]) -> None:
    """Make a bag directory of several bags' .db3 files, in this order (one metadata.yaml)."""
    directory.mkdir()
    metadata: Any = None
    for k, part in enumerate(parts):
        shutil.copy(part / f'{part.name}.db3', directory / f'{directory.name}_{k}.db3')
        info = yaml.safe_load((part / 'metadata.yaml').read_text())[
            'rosbag2_bagfile_information']
        if metadata is None:
            metadata = info
            metadata['relative_file_paths'] = []
            metadata['files'] = []
        else:
            metadata['message_count'] += info['message_count']
            for mine, theirs in zip(metadata['topics_with_message_count'],
                                    info['topics_with_message_count']):
                assert mine['topic_metadata']['name'] == theirs['topic_metadata']['name']
                mine['message_count'] += theirs['message_count']
        metadata['relative_file_paths'].append(f'{directory.name}_{k}.db3')
    with (directory / 'metadata.yaml').open('w') as out:
        yaml.safe_dump({'rosbag2_bagfile_information': metadata}, out)


def test_a_bag_split_over_several_files(tmp_path: Path,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """Files read one after the other as rosbags does (not merged), spans across files."""
    _write(tmp_path / 'late', _pairs(3001, step=2_000_000))
    _write(tmp_path / 'early', [(topic, log_time - 10**9, values)  # earlier: not merged
                                for topic, log_time, values in _pairs(1500, tie=2)])
    _write(tmp_path / 'none', [('/chatter', T0, ())])  # no selected message: skipped
    _split(tmp_path / 'split', [tmp_path / 'late', tmp_path / 'none', tmp_path / 'early'])
    for size in (1000, 4096):
        fast, expected, lengths = _both(tmp_path / 'split', ['/ball', '/bat'], size)
        _same(fast, expected)
        _cut(lengths, 4501, size)
    assert expected[3001][1] < expected[0][1] < expected[3000][1]  # the files in turn
    _as_rosbags_reads(tmp_path / 'split', 1000, monkeypatch)


def test_per_message_compression_ros1_and_mcap_are_left_to_rosbags(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Messages compressed one by one, a ROS 1 bag, MCAP: declined; the same samples."""
    _write(tmp_path / 'message', _pairs(600, tie=2), CompressionMode.MESSAGE)
    assert _both(tmp_path / 'message')[0] is None
    _as_rosbags_reads(tmp_path / 'message', 256, monkeypatch)
    for name in ('pitches_240hz_noisy.bag', 'pitches_90hz.mcap'):
        assert _both(REPO / 'bags' / name)[0] is None


def _converted(source: Path, target: Path) -> Path:
    """Write a bag's raw messages (in rosbags' order) into a sqlite3 bag directory."""
    with AnyReader([source]) as reader, Writer(
            target, version=9, storage_plugin=StoragePlugin.SQLITE3) as writer:
        added = {c.id: writer.add_connection(c.topic, c.msgtype, typestore=TS2)
                 for c in reader.connections}
        for connection, log_time, raw in reader.messages():
            writer.write(added[connection.id], log_time, raw)
    return target


@pytest.mark.parametrize('name', ['pitches_120hz_sqlite3', 'pitches_90hz.mcap',
                                  'pitches_360hz.mcap'])
def test_the_bundled_bags_as_sqlite3(tmp_path: Path, name: str,
                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """The bundled sqlite3 bag and the MCAP ones converted: rosbags' messages and samples."""
    path = REPO / 'bags' / name
    if name.endswith('.mcap'):
        path = _converted(path, tmp_path / 'converted')
    fast, expected, lengths = _both(path, size=1000)
    _same(fast, expected)
    _cut(lengths, len(expected), 1000)
    with BagReader(path) as bag:  # (the selected topics only)
        reader = bag._open_reader()
        spans = next(sqlite_spans(reader, bag._connections, 8192))
        pieces = (decode_spans(spans, bag._routes, lambda *a: bag._slow(reader, *a)),
                  decode_chunk(spans.messages(range(len(spans.codes))), bag._routes,
                               lambda *a: bag._slow(reader, *a)))
    for a, b in zip(*pieces):
        assert np.array_equal(np.asarray(a), np.asarray(b))
    _as_rosbags_reads(path, 8192, monkeypatch)


@pytest.mark.parametrize('cut', [True, False])
def test_a_corrupt_message_is_rosbags_paths_bag_error(tmp_path: Path, cut: bool,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A message that does not deserialise: the same BagError as through rosbags' reader.

    Cut short (a length of its own), or its frame_id's length past its end inside a group of
    its length (decoded in bulk but for it).
    """
    messages = _pairs(200)
    damaged = bytearray(_message(*messages[40]))
    if cut:
        damaged = damaged[:30]
    else:
        damaged[12:16] = (10**6).to_bytes(4, 'little')
    _write(tmp_path / 'bag', messages, raw={40: bytes(damaged)})
    errors = []
    for fast in (True, False):
        with monkeypatch.context() as patch:
            if not fast:
                _rosbags_path(patch)
            with BagReader(tmp_path / 'bag') as bag, pytest.raises(BagError) as caught:
                list(bag.chunks(128))
        errors.append(str(caught.value))
    assert errors[0] == errors[1] and 'corrupt' in errors[0] and 'bag' in errors[0]


def _outcome(path: Path, size: int) -> Any:
    """Return a bag's chunks, or the BagError reading them raised (its message)."""
    try:
        with BagReader(path) as bag:
            return list(bag.chunks(size))
    except BagError as error:
        return str(error)


@pytest.mark.parametrize('column, value', [('data', 5), ('data', 'text'), ('timestamp', 2.5),
                                           ('timestamp', 'late'), ('timestamp', b'\x00\x01')])
@pytest.mark.parametrize('row', [7, 90])
def test_a_damaged_file_reads_as_row_by_row(tmp_path: Path, column: str, value: Any,
                                            row: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A row whose data is not a blob or log time not an integer (a foreign writer's).

    In the first batch or a later one: the batch that holds it leaves the rest to the row
    path, so the outcome is the row path's throughout (batches declined): a BagError naming
    the bag for data that is not bytes, or the same chunks.
    """
    _write(tmp_path / 'bag', _pairs(100))
    with sqlite3.connect(tmp_path / 'bag' / 'bag.db3') as db:
        db.execute(f'UPDATE messages SET {column} = ? WHERE id = ?', (value, row))
    got = _outcome(tmp_path / 'bag', 16)
    with monkeypatch.context() as patch:
        patch.setattr(sqlite_module, '_walked_index', lambda *a: None)
        expected = _outcome(tmp_path / 'bag', 16)
    if column == 'data':
        assert isinstance(got, str) and 'bag' in got
    if isinstance(expected, str):
        assert got == expected
    else:
        _same_chunks(got, expected)


def test_topic_ids_of_any_size(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Topic ids far apart or negative (a foreign writer's): mapped, not used as an index."""
    _write(tmp_path / 'bag', _pairs(300, tie=2))
    with sqlite3.connect(tmp_path / 'bag' / 'bag.db3') as db:
        for old, new in ((1, 2**40), (2, -5)):
            db.execute('UPDATE topics SET id = ? WHERE id = ?', (new, old))
            db.execute('UPDATE messages SET topic_id = ? WHERE topic_id = ?', (new, old))
    bare = tmp_path / 'bare.db3'
    shutil.copy(tmp_path / 'bag' / 'bag.db3', bare)
    for path in (tmp_path / 'bag', bare):
        fast, expected, lengths = _both(path, ['/ball', '/bat'], 64)
        _same(fast, expected)
        assert len(expected) == 300 and {m[0].topic for m in expected} == {'/ball', '/bat'}
        _as_rosbags_reads(path, 64, monkeypatch)


def test_log_times_too_far_apart_for_a_difference(tmp_path: Path) -> None:
    """
    Log times too far apart to subtract: the rest row by row, rosbags' rows still.

    A batch's log times are sent less the last batch's: one too far off (past int64) is a
    real in SQLite, which does not parse as an integer.
    """
    _write(tmp_path / 'bag', _pairs(100))
    with sqlite3.connect(tmp_path / 'bag' / 'bag.db3') as db:
        for k in range(20):
            db.execute('UPDATE messages SET timestamp = ? WHERE id = ?', (-2**63 + k, k + 1))
    fast, expected, lengths = _both(tmp_path / 'bag', ['/bat', '/ball'], 16)
    _same(fast, expected)
    _cut(lengths, 100, 16)
    assert expected[0][1] == -2**63 and expected[-1][1] > 0
