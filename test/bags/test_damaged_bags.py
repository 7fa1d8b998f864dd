"""
Bag tools against damaged and hostile files: what the other bag tests and test_cli.py do not cover.

Already covered there: missing paths, text files, a foreign sqlite3 file (reader), a bare
folder, empty bags, MCAP and ROS 1 bags cut in half, an MCAP record or payload damaged in a
later chunk (reader), zero-byte and random files, a damaged ROS 1 chunk and sqlite3 pages, a
bag without tracker topics (CLI). Here: sqlite3 files and bag directories damaged in other
ways, MCAP footers, zstd-compressed chunks, damage found after the outputs were started (all
outputs at once), records lost silently inside an uncompressed chunk, and hundreds of
thousands of messages on an unrelated topic (their time and memory are figures of
``benchmarks/bench_bag_read.py``).
"""

import errno
from pathlib import Path
import shutil
import sqlite3
import struct
import tempfile
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from baseball_collision.bags import (
    BagReader, count_messages, POINT_STAMPED, POSE_STAMPED, RawBag, read_samples)
from baseball_collision.errors import BagError
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag
from baseball_collision.tools.cli import main
from baseball_collision.tools.sim import DEFAULT_START_NS, make_scenario, sample
import numpy as np
import pytest
from rosbags.interfaces import Connection
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import storage_mcap, StoragePlugin, Writer as Writer2
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
from rosbags.typesys import get_typestore, Stores
from support import REPO_ROOT
from support.bundled import time_bound_ns

BAGS = REPO_ROOT / 'bags'
TS2 = get_typestore(Stores.ROS2_JAZZY)
TS1 = get_typestore(Stores.ROS1_NOETIC)
STRING = 'std_msgs/msg/String'
NO_HASH = 'RIHS01_' + '0' * 64  # (a type hash for a schema that is not ROS)


# ----------------------------------------------------------------------------------------------
# writing test bags


def _header(store: object, stamp: int, frame: str, ros1: bool) -> object:
    fields = {'stamp': store.types['builtin_interfaces/msg/Time'](
        sec=stamp // 10**9, nanosec=stamp % 10**9), 'frame_id': frame}
    if ros1:
        fields['seq'] = 0
    return store.types['std_msgs/msg/Header'](**fields)


def _serialize(store: object, role: str, stamp: int, frame: str, values: Sequence[float],
               ros1: bool) -> bytes:
    """Return a ball PointStamped or bat PoseStamped serialised for the store."""
    types = store.types
    point = types['geometry_msgs/msg/Point']
    header = _header(store, stamp, frame, ros1)
    serialize = store.serialize_ros1 if ros1 else store.serialize_cdr
    if role == 'ball':
        return serialize(types[POINT_STAMPED](header=header, point=point(
            x=values[0], y=values[1], z=values[2])), POINT_STAMPED)
    pose = types['geometry_msgs/msg/Pose'](
        position=point(x=values[0], y=values[1], z=values[2]),
        orientation=types['geometry_msgs/msg/Quaternion'](
            x=values[3], y=values[4], z=values[5], w=values[6]))
    return serialize(types[POSE_STAMPED](header=header, pose=pose), POSE_STAMPED)


def pitches(kinds: Sequence[str] = ('barrel', 'miss_over', 'handle'),
            seed: int = 3) -> Tuple[List[Tuple[int, str, Tuple[float, ...]]], List[int]]:
    """Return simulated pitches 20 s apart at 360 Hz as (stamp, role, values), and the truth."""
    rng = np.random.default_rng(seed)
    rows: List[Tuple[int, str, Tuple[float, ...]]] = []
    truth = []
    for k, kind in enumerate(kinds):
        scenario = make_scenario(kind, rng)
        start = DEFAULT_START_NS + (k + 1) * 20 * 10**9
        rows += sample(scenario, 360.0, rng, start_ns=start).messages('pose')
        if scenario.truth.contact:
            truth.append(start + int(round(scenario.truth.time_s * 1e9)))
    return sorted(rows, key=lambda row: row[0]), truth


def write_bag(path: Path, storage: str, rows: Sequence[Tuple[int, str, Tuple[float, ...]]],
              unrelated: int = 0, span_s: float = 80.0, compress: bool = False,
              frames: Optional[Dict[int, str]] = None) -> None:
    """
    Write tracker rows (/tracker/ball, /tracker/bat_pose) and unrelated /chatter messages.

    The ``unrelated`` small std_msgs/String messages are spread evenly over ``span_s`` from
    the simulation's start, interleaved in time with the rows.

    :param storage: ``'mcap'``, ``'sqlite3'`` or ``'rosbag1'``.
    :param compress: zstd chunk compression (MCAP).
    :param frames: frame_id of some rows by index (others: 'world').
    """
    ros1 = storage == 'rosbag1'
    store = TS1 if ros1 else TS2
    if ros1:
        writer = Writer1(path)
    else:
        writer = Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP
                         if storage == 'mcap' else StoragePlugin.SQLITE3)
        if compress:
            writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    writer.open()
    chatter = writer.add_connection('/chatter', STRING, typestore=store)
    topics = {'ball': writer.add_connection('/tracker/ball', POINT_STAMPED, typestore=store),
              'bat_pose': writer.add_connection('/tracker/bat_pose', POSE_STAMPED,
                                                typestore=store)}
    serialize = store.serialize_ros1 if ros1 else store.serialize_cdr
    tick = serialize(store.types[STRING](data='tick0001'), STRING)
    step = int(span_s * 1e9) // max(unrelated, 1)
    k = 0
    for i, (stamp, role, values) in enumerate(rows):
        while k < unrelated and DEFAULT_START_NS + k * step < stamp:
            writer.write(chatter, DEFAULT_START_NS + k * step, tick)
            k += 1
        frame = (frames or {}).get(i, 'world')
        writer.write(topics[role], stamp, _serialize(store, role, stamp, frame, values, ros1))
    for k in range(k, unrelated):
        writer.write(chatter, DEFAULT_START_NS + k * step, tick)
    writer.close()


def _filler(rows: List[Tuple[int, str, Tuple[float, ...]]],
            count: int) -> List[Tuple[int, str, Tuple[float, ...]]]:
    """Return rows followed by ``count`` frames of a ball resting 10 m from a resting bat."""
    last = rows[-1][0]
    more = []
    for i in range(1, count + 1):
        stamp = last + i * 2_777_778
        more.append((stamp, 'ball', (0.0, 10.0, 1.0)))
        more.append((stamp, 'bat_pose', (0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)))
    return rows + more


def session_bag(path: Path, compress: bool = False) -> Tuple[Path, int]:
    """
    Write 3 pitches then 12000 far-apart frames (three MCAP chunks); one late ball 'MARKER'.

    :returns: the MCAP file, and the file offset of the MARKER message's record.
    """
    rows, _ = pitches()
    rows = _filler(rows, 12_000)
    marker = next(i for i in range(len(rows) - 2_000, len(rows)) if rows[i][1] == 'ball')
    write_bag(path, 'mcap', rows, compress=compress, frames={marker: 'MARKER'})
    mcap = path / f'{path.name}.mcap'
    data = mcap.read_bytes()
    if compress:
        return mcap, -1
    offset = data.index(b'MARKER\x00') - 16 - 22 - 8 - 1  # CDR head, record fields, length, op
    assert data[offset] == 0x05
    return mcap, offset


def _chunks(data: bytes) -> List[Tuple[int, int]]:
    """Return (start of the compressed data, its size) of every MCAP chunk record."""
    position, found = 8, []
    while position < len(data) - 8:
        opcode = data[position]
        length = struct.unpack_from('<Q', data, position + 1)[0]
        if opcode == 0x06:
            name_length = struct.unpack_from('<I', data, position + 9 + 28)[0]
            body = position + 9 + 32 + name_length + 8
            found.append((body, struct.unpack_from('<Q', data, body - 8)[0]))
        elif opcode in (0x02, 0x0F):  # data end, footer
            break
        position += 9 + length
    return found


# ----------------------------------------------------------------------------------------------
# the CLI: one line, exit 2, nothing written


def run_cli(argv: List[str], capsys: pytest.CaptureFixture) -> Tuple[int, str, str]:
    """Run the CLI in-process; return (exit code, stdout, stderr)."""
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def all_outputs(directory: Path) -> List[str]:
    """Return every output flag of analyze, aimed into ``directory``."""
    return ['--json', str(directory / 'o.json'), '--csv', str(directory / 'o.csv'),
            '--plot', str(directory / 'plots'), '--out-bag', str(directory / 'o.mcap')]


def listing(directory: Path) -> List[str]:
    """Return every path under directory (relative), sorted."""
    return sorted(str(p.relative_to(directory)) for p in directory.rglob('*'))


def refused(bag: Path, directory: Path, capsys: pytest.CaptureFixture,
            extra: Sequence[str] = (), outputs: int = 8) -> str:
    """
    Analyze with every output: assert exit 2, one error line, nothing written; return it.

    :param extra: bags analysed before ``bag``.
    :param outputs: how many of ``all_outputs`` to pass (4: JSON and CSV only).
    """
    before = listing(directory)
    code, out, err = run_cli(['analyze', *extra, str(bag), '--no-progress']
                             + all_outputs(directory)[:outputs], capsys)
    assert code == 2, (code, err)
    assert err.count('\n') == 1 and err.startswith('baseball-collision: error: '), err
    assert 'Traceback' not in err and out == ''
    assert listing(directory) == before  # not even a hidden temporary
    return err


def _sqlite_bag(directory: Path) -> Path:
    target = directory / 'bag'
    shutil.copytree(BAGS / 'pitches_120hz_sqlite3', target)
    return target


def _foreign_db(path: Path) -> None:
    connection = sqlite3.connect(path)
    connection.execute('CREATE TABLE people (name TEXT)')
    connection.commit()
    connection.close()


def _foreign_db3(d: Path) -> Path:
    _foreign_db(d / 'people.db3')
    return d / 'people.db3'


def _truncated_db3(d: Path) -> Path:
    data = (BAGS / 'pitches_120hz_sqlite3' / 'pitches_120hz_sqlite3.db3').read_bytes()
    (d / 'cut.db3').write_bytes(data[:len(data) // 2])
    return d / 'cut.db3'


def _garbage_db3(d: Path) -> Path:
    (d / 'garbage.db3').write_bytes(bytes(range(256)) * 32)
    return d / 'garbage.db3'


def _metadata(text: str) -> Callable[[Path], Path]:
    def make(d: Path) -> Path:
        bag = _sqlite_bag(d)
        (bag / 'metadata.yaml').write_text(text)
        return bag
    return make


def _database_missing(d: Path) -> Path:
    bag = _sqlite_bag(d)
    (bag / 'pitches_120hz_sqlite3.db3').unlink()
    return bag


def _database_foreign(d: Path) -> Path:
    bag = _sqlite_bag(d)
    (bag / 'pitches_120hz_sqlite3.db3').unlink()
    _foreign_db(bag / 'pitches_120hz_sqlite3.db3')
    return bag


def _mcap_tail(span: slice, data: bytes) -> Callable[[Path], Path]:
    def make(d: Path) -> Path:
        damaged = bytearray((BAGS / 'pitches_360hz.mcap').read_bytes())
        damaged[span] = data
        (d / 'damaged.mcap').write_bytes(damaged)
        return d / 'damaged.mcap'
    return make


def _mcap_cut(fraction: float, directory: bool = False) -> Callable[[Path], Path]:
    """Return a maker of a crashed recording: its MCAP file ends early (no footer, summary)."""
    def make(d: Path) -> Path:
        data = (BAGS / 'pitches_360hz.mcap').read_bytes()
        if not directory:
            (d / 'crashed.mcap').write_bytes(data[:int(len(data) * fraction)])
            return d / 'crashed.mcap'
        bag = d / 'crashed'
        write_bag(bag, 'mcap', pitches(('barrel',))[0])
        inner = bag / 'crashed.mcap'
        inner.write_bytes(inner.read_bytes()[:int(inner.stat().st_size * fraction)])
        return bag
    return make


DAMAGED = {
    'sqlite3_not_a_bag': (_foreign_db3, 'missing tables'),
    'sqlite3_cut_in_half': (_truncated_db3, 'malformed'),
    'sqlite3_header_garbage': (_garbage_db3, 'not a database'),
    'metadata_garbage': (_metadata('rosbag2_bagfile_information: [unclosed\n  - : :'),
                         'metadata.yaml'),
    'metadata_empty': (_metadata(''), 'metadata'),
    'metadata_database_missing': (_database_missing, 'missing'),
    'metadata_database_foreign': (_database_foreign, 'missing tables'),
    'mcap_footer_damaged': (_mcap_tail(slice(-30, -8), b'\xff' * 22), 'footer'),
    'mcap_end_magic_damaged': (_mcap_tail(slice(-8, None), b'\x00' * 8), 'magic'),
    'mcap_crashed_recording': (_mcap_cut(0.95), 'crashed.mcap is an unfinished MCAP recording: '
                               'it ends without the footer a recorder writes when it stops'),
    'mcap_crashed_in_a_directory': (_mcap_cut(0.5, directory=True),
                                    "crashed/crashed.mcap -o recovered.mcap'"),
}


@pytest.mark.parametrize('case', sorted(DAMAGED))
def test_damaged_files_are_refused_in_one_line(case: str, tmp_path: Path,
                                               capsys: pytest.CaptureFixture) -> None:
    """sqlite3 files, bag directories and MCAP ends damaged: one line naming the bag, exit 2."""
    make, words = DAMAGED[case]
    bag = make(tmp_path)
    err = refused(bag, tmp_path, capsys)
    assert words in err and bag.name in err, err


def test_damage_found_after_the_outputs_started_leaves_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """
    A late chunk damaged (zstd data, a message payload): exit 2 after the impacts were found.

    The JSON, CSV, plots and output bag were under way (the output bag receives every sample as
    it is read): none is left, not even a temporary.
    """
    compressed, _ = session_bag(tmp_path / 'zstd', compress=True)
    data = bytearray(compressed.read_bytes())
    body, _ = _chunks(bytes(data))[-1]
    data[body:body + 16] = bytes(16)  # the zstd frame header
    compressed.write_bytes(bytes(data))
    plain, record = session_bag(tmp_path / 'plain')
    data = bytearray(plain.read_bytes())
    length = record + 9 + 22 + 12  # CDR head: encapsulation, sec, nanosec, then the length
    data[length:length + 4] = struct.pack('<I', 0x7FFFFFF0)
    plain.write_bytes(bytes(data))
    outputs = tmp_path / 'out'
    outputs.mkdir()
    for bag, words in ((compressed, 'decompress'), (plain, 'corrupt')):
        seen = 0
        with pytest.raises(BagError):
            for _ in read_samples(bag):
                seen += 1
        assert seen > 10_000, 'the damage should be met late, after the pitches'
        assert words in refused(bag, outputs, capsys)


def test_a_corrupt_message_error_names_the_bag(tmp_path: Path,
                                               capsys: pytest.CaptureFixture) -> None:
    """
    The error line for a message that cannot be decoded names the bag it is in.

    ``BagReader._slow`` raises ``corrupt <type> message on the <role> topic: ...`` without
    the path: with several bags analysed, the line does not say which one is damaged.
    """
    plain, record = session_bag(tmp_path / 'plain')
    data = bytearray(plain.read_bytes())
    data[record + 43:record + 47] = struct.pack('<I', 0x7FFFFFF0)
    plain.write_bytes(bytes(data))
    err = refused(plain, tmp_path, capsys, extra=[str(BAGS / 'pitches_90hz.mcap')], outputs=4)
    assert 'corrupt' in err and plain.name in err, err


def test_records_lost_inside_a_chunk_are_an_error(tmp_path: Path,
                                                  capsys: pytest.CaptureFixture) -> None:
    """
    A message record damaged inside an uncompressed chunk must not vanish silently.

    rosbags' MCAP reader skips a record whose opcode is not a message's, a message whose
    channel id is unknown and one whose log time is outside its chunk's range, without an
    error (rosbags writes no chunk CRC to catch it). The bag's index still counts the message:
    reading fewer samples than ``count_messages`` announced is damage, and ``analyze`` must
    not exit 0 with a partial result (here one message of 24,546 is lost; a damaged record
    length in a bag of one chunk loses the rest of the chunk the same way).
    """
    damaged = []
    for name, offset, value in (('opcode', 0, b'\x0a'), ('channel', 9, b'\x4d\x00'),
                                ('log_time', 15, struct.pack('<Q', 2**62))):
        bag, record = session_bag(tmp_path / name)
        data = bytearray(bag.read_bytes())
        data[record + offset:record + offset + len(value)] = value
        bag.write_bytes(bytes(data))
        damaged.append(bag)
    expected = count_messages(damaged[0])
    for bag in damaged:
        try:
            seen = sum(1 for _ in read_samples(bag))
        except BagError:
            continue
        assert seen == expected, f'{bag.name}: {seen} of {expected} messages read, no error'
    outputs = tmp_path / 'out'
    outputs.mkdir()
    refused(damaged[0], outputs, capsys)


# ----------------------------------------------------------------------------------------------
# many messages on an unrelated topic (their time and memory: benchmarks/bench_bag_read.py)


@pytest.mark.parametrize('storage, unrelated', [('mcap', 200_000), ('sqlite3', 200_000),
                                                ('rosbag1', 60_000)])
def test_unrelated_messages_are_skipped(storage: str, unrelated: int, tmp_path: Path) -> None:
    """Hundreds of thousands of unrelated messages interleaved with three pitches: all found."""
    rows, truth = pitches()
    bag = tmp_path / ('bag.bag' if storage == 'rosbag1' else 'bag')
    write_bag(bag, storage, rows, unrelated=unrelated)
    analysis = analyze_bag(bag, AnalysisOptions(), progress=False, use_truth=False)
    assert [impact.stamp_ns for impact in analysis.impacts] == pytest.approx(
        truth, abs=time_bound_ns(360.0))
    assert analysis.messages == len(rows) == count_messages(bag)


def test_a_damaged_footer_is_not_called_an_unfinished_recording(
        tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """The file ends as an MCAP (its end magic there), its footer damaged: rosbags' words only."""
    err = refused(_mcap_tail(slice(-30, -8), b'\xff' * 22)(tmp_path), tmp_path, capsys)
    assert 'unfinished' not in err and 'mcap recover' not in err


# ----------------------------------------------------------------------------------------------
# channels that are not ROS, sqlite3 write-ahead logs


@pytest.fixture
def foreign_schemas(monkeypatch: pytest.MonkeyPatch) -> Dict[str, Tuple[str, bytes]]:
    """
    Let rosbags' MCAP writer record some types with a schema that is not ROS.

    Fill the returned ``{type name: (schema encoding, schema data)}``: rosbags writes a
    ``ros2msg`` schema for every type; these get the encoding and data of a Foxglove SDK's or
    bridge's recording instead (a JSON schema, a protobuf descriptor).
    """
    foreign: Dict[str, Tuple[str, bytes]] = {}
    own = storage_mcap.McapWriter.add_msgtype

    def add_msgtype(self: storage_mcap.McapWriter, connection: Connection) -> None:
        if connection.msgtype not in foreign:
            own(self, connection)
            return
        encoding, data = foreign[connection.msgtype]
        self.schemas.append(storage_mcap.Schema(len(self.schemas) + 1, connection.msgtype,
                                                encoding, data.decode('latin-1')))
        storage_mcap.write_schema(self.chunk.bio, self.schemas[-1])

    monkeypatch.setattr(storage_mcap.McapWriter, 'add_msgtype', add_msgtype)
    return foreign


def test_json_and_protobuf_channels_are_skipped_with_a_note(
        tmp_path: Path, foreign_schemas: Dict[str, Tuple[str, bytes]],
        capsys: pytest.CaptureFixture) -> None:
    """A /foxglove/log in JSON and a protobuf channel: the bag is read all the same, with notes."""
    foreign_schemas.update({'foxglove.Log': ('jsonschema', b'{"type": "object"}'),
                            'foxglove.SceneUpdate': ('protobuf', b'\x0a\x00')})
    rows, truth = pitches(('barrel',))
    bag = tmp_path / 'foxglove'
    write_bag(bag, 'mcap', rows)
    plain = analyze_bag(bag, AnalysisOptions(), progress=False, use_truth=False)
    shutil.rmtree(bag)
    writer = Writer2(bag, version=9, storage_plugin=StoragePlugin.MCAP)
    with writer:
        tracker = {role: writer.add_connection(topic, msgtype, typestore=TS2) for role, topic,
                   msgtype in (('ball', '/tracker/ball', POINT_STAMPED),
                               ('bat_pose', '/tracker/bat_pose', POSE_STAMPED))}
        log = writer.add_connection('/foxglove/log', 'foxglove.Log', msgdef='', rihs01=NO_HASH,
                                    serialization_format='json')
        scene = writer.add_connection('/scene', 'foxglove.SceneUpdate', msgdef='', rihs01=NO_HASH,
                                      serialization_format='protobuf')
        for i, (stamp, role, values) in enumerate(rows):
            writer.write(tracker[role], stamp, _serialize(TS2, role, stamp, 'world', values,
                                                          False))
            if i % 10 == 0:
                writer.write(log, stamp, b'{"message": "hi"}')
                writer.write(scene, stamp, b'\x0a\x00')
    with pytest.raises(BagError, match=r'its metadata.yaml lists topics that are not ROS CDR: '
                       r'/foxglove/log \(json\), /scene \(protobuf\), .* analyse its file '
                       r'\S+/foxglove/foxglove.mcap instead, where they are skipped'):
        read_samples(bag).__next__()  # (rosbags refuses such a bag directory)
    bag = bag / 'foxglove.mcap'  # (a Foxglove SDK or bridge writes bare MCAP files)
    with BagReader(bag) as reader:
        assert reader.notes == [
            '/foxglove/log not read: json messages (schema foxglove.Log), not ROS CDR',
            '/scene not read: protobuf messages (schema foxglove.SceneUpdate), not ROS CDR']
        assert '/foxglove/log' not in reader.topics
    with RawBag(bag) as raw:
        assert set(raw.skipped) == {'/foxglove/log', '/scene'} and '/scene' not in raw.topics
    analysis = analyze_bag(bag, AnalysisOptions(), progress=False, use_truth=False)
    assert [i.stamp_ns for i in analysis.impacts] == [i.stamp_ns for i in plain.impacts]
    assert len(analysis.impacts) == len(truth) == 1 and analysis.messages == len(rows)
    assert analysis.notes == reader.notes
    code, stdout, stderr = run_cli(['analyze', str(bag), '--no-progress', '--out-bag',
                                    str(tmp_path / 'out.mcap')], capsys)
    assert code == 0 and stderr == ''
    assert 'note: --out-bag: /foxglove/log not copied (json messages (schema foxglove.Log), ' \
        'not ROS CDR)' in stdout.splitlines()


def test_a_json_channel_on_the_ball_topic_leaves_its_ros_channel_read(
        tmp_path: Path, foreign_schemas: Dict[str, Tuple[str, bytes]],
        capsys: pytest.CaptureFixture) -> None:
    """
    A Foxglove bridge's JSON /tracker/ball recorded beside the CDR one: the CDR one is read.

    Channels are left out one by one, not by topic name (which took the CDR /tracker/ball too:
    'no ball topic found'); the note names the channel left out.
    """
    foreign_schemas.update({'foxglove.PointInFrame': ('jsonschema', b'{"type": "object"}')})
    rows, truth = pitches(('barrel',))
    directory = tmp_path / 'bridge'
    writer = Writer2(directory, version=9, storage_plugin=StoragePlugin.MCAP)
    with writer:
        json_ball = writer.add_connection('/tracker/ball', 'foxglove.PointInFrame', msgdef='',
                                          rihs01=NO_HASH, serialization_format='json')
        tracker = {role: writer.add_connection(topic, msgtype, typestore=TS2) for role, topic,
                   msgtype in (('ball', '/tracker/ball', POINT_STAMPED),
                               ('bat_pose', '/tracker/bat_pose', POSE_STAMPED))}
        for stamp, role, values in rows:
            writer.write(tracker[role], stamp, _serialize(TS2, role, stamp, 'world', values,
                                                          False))
            if role == 'ball':
                writer.write(json_ball, stamp, b'{"x": 0}')
    bag = directory / 'bridge.mcap'
    note = ('/tracker/ball: its channel 1 not read: json messages (schema '
            'foxglove.PointInFrame), not ROS CDR (its ROS CDR channel is read)')
    with BagReader(bag) as reader:
        assert reader.notes == [note]
        assert reader.selection.topics == {'ball': '/tracker/ball',
                                           'bat_pose': '/tracker/bat_pose'}
        assert reader.topics['/tracker/ball'] == POINT_STAMPED
    with RawBag(bag) as raw:
        assert raw.skipped == {}
        balls = raw.topics['/tracker/ball'].message_count
    assert balls == sum(row[1] == 'ball' for row in rows)
    analysis = analyze_bag(bag, AnalysisOptions(), progress=False, use_truth=False)
    assert [i.stamp_ns for i in analysis.impacts] == pytest.approx(truth, abs=time_bound_ns(360))
    assert analysis.messages == len(rows) and analysis.notes == [note]
    out = tmp_path / 'out.mcap'
    code, stdout, stderr = run_cli(['analyze', str(bag), '--no-progress', '--no-truth',
                                    '--out-bag', str(out)], capsys)
    assert code == 0 and stderr == '' and f'note: {note}' in stdout.splitlines()
    with RawBag(out) as copied:
        assert copied.topics['/tracker/ball'].msgtype == POINT_STAMPED
        assert copied.topics['/tracker/ball'].message_count == balls


def _wal_session(bag: Path, db3: Path) -> sqlite3.Connection:
    """
    Turn a sqlite3 bag file into a recording still being written in WAL mode; return its writer.

    Half of its messages are moved past the last checkpoint: they are in ``<db3>-wal`` only
    while the returned connection (the recorder) stays open.
    """
    recorder = sqlite3.connect(db3)
    assert recorder.execute('PRAGMA journal_mode=WAL').fetchone() == ('wal',)
    recorder.execute('PRAGMA wal_autocheckpoint=0')
    half = recorder.execute('SELECT count(*) FROM messages').fetchone()[0] // 2
    rows = recorder.execute('SELECT * FROM messages WHERE id > ?', (half,)).fetchall()
    recorder.execute('DELETE FROM messages WHERE id > ?', (half,))
    recorder.commit()
    recorder.execute('PRAGMA wal_checkpoint(TRUNCATE)')
    recorder.executemany(f"INSERT INTO messages VALUES ({','.join('?' * len(rows[0]))})", rows)
    recorder.commit()
    assert Path(f'{db3}-wal').stat().st_size > 0
    return recorder


def _files(directory: Path) -> Dict[str, bytes]:
    return {str(path.relative_to(directory)): path.read_bytes()
            for path in sorted(directory.rglob('*')) if path.is_file()}


@pytest.mark.parametrize('layout', ['directory', 'bare'])
def test_a_sqlite3_write_ahead_log_is_read_through_a_checkpointed_copy(
        tmp_path: Path, layout: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A recording in WAL mode (rosbag2's resilient preset) still being written, or crashed.

    rosbags opens the file immutable and would read half of it; read through a checkpointed
    temporary copy, every message is there, with a note; the bag is not changed, the copy
    removed.
    """
    original = analyze_bag(BAGS / 'pitches_120hz_sqlite3', AnalysisOptions(), progress=False,
                           use_truth=False)
    bag = _sqlite_bag(tmp_path)
    db3 = bag / 'pitches_120hz_sqlite3.db3'
    if layout == 'bare':
        db3 = db3.rename(tmp_path / 'session.db3')
        bag = db3
    scratch = tmp_path / 'tmp'
    scratch.mkdir()
    monkeypatch.setattr(tempfile, 'tempdir', str(scratch))
    recorder = _wal_session(bag, db3)
    try:
        before = _files(tmp_path / 'bag' if layout == 'directory' else tmp_path)
        analysis = analyze_bag(bag, AnalysisOptions(), progress=False, use_truth=False)
        after = _files(tmp_path / 'bag' if layout == 'directory' else tmp_path)
    finally:
        recorder.close()
    assert analysis.messages == original.messages
    assert [i.stamp_ns for i in analysis.impacts] == [i.stamp_ns for i in original.impacts]
    assert len(analysis.notes) == 1 and analysis.notes[0].startswith(f'{db3.name}-wal (')
    assert 'read through a temporary copy with the log checkpointed' in analysis.notes[0]
    assert before == after and list(scratch.iterdir()) == []
    assert analyze_bag(bag, AnalysisOptions(), progress=False).notes == []  # (checkpointed)


def test_a_write_ahead_log_that_cannot_be_copied_says_how_to_checkpoint(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """No room for the copy: an error naming the log and the sqlite3 command, no half read."""
    bag = _sqlite_bag(tmp_path)
    recorder = _wal_session(bag, bag / 'pitches_120hz_sqlite3.db3')

    def full(*args: Any, **kwargs: Any) -> None:
        raise OSError(errno.ENOSPC, 'No space left on device')
    monkeypatch.setattr(shutil, 'copytree', full)
    try:
        with pytest.raises(BagError, match=r'pitches_120hz_sqlite3.db3-wal holds messages not '
                           r'yet checkpointed .* \(No space left on device\); checkpoint a copy '
                           r'by hand \(cp -r the bag, then sqlite3 COPY/FILE.db3 .PRAGMA '
                           r'wal_checkpoint.\)'):
            read_samples(bag).__next__()
    finally:
        recorder.close()
