"""
An indexed MCAP bag's messages, as ``AnyReader.messages`` gives them, at a fraction of the cost.

rosbags reads an MCAP chunk record by record through ``io.BytesIO`` objects (about 3 us per
message: more than the whole analysis of a quiet stretch of a session). Here each chunk is read
and decompressed by rosbags' own code (``storage_mcap.decompress``, the same checks), and its
messages are located without making a Python object per message: from the chunk's message
index (the records after the chunk list every message's offset), checked against the records
themselves, which must tile the chunk exactly (each record's length leading to the next);
where they do not (other records inside the chunk, a damaged index), the records are walked
one by one with ``struct.unpack_from``. The result is :class:`~.decode.Spans`: where each
message's bytes lie in the decompressed chunk, decoded in bulk by :func:`.decode.decode_spans`.

The messages and their order are rosbags': each chunk's messages with a log time in the chunk's
range, on the selected channels, sorted by log time (ties in file order), the chunks merged by
(log time, chunk offset). Where the selected chunks, ordered by their first log time, do not
overlap (the last key of each before the first of the next: what a recorder writes), that merge
is their concatenation, which is what is read here. Anything else returns None and the caller
uses rosbags' reader: bags without a chunk index, overlapping chunks, per-message compression,
ROS 1 bags, sqlite3 storage, several bags in one reader.
"""

import struct
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from rosbags.rosbag2 import ReaderError
from rosbags.rosbag2.reader import DirectoryReader
from rosbags.rosbag2.storage_mcap import decompress, McapReader, read_exact

from .decode import Spans

_LENGTH = struct.Struct('<Q')
_CRC = struct.Struct('<I')
_MESSAGE = struct.Struct('<HIQQ')  # channel id, sequence, log time, publish time
_INDEX = struct.Struct('<BQHI')  # a message index record: opcode, length, channel, size
_MESSAGE_OP, _INDEX_OP = 0x05, 0x07
_RECORD = 9  # a record's opcode and length before its body
_DATA = _RECORD + 22  # a message record's data after its channel, sequence and two times


def mcap_spans(reader: Any, connections: Sequence[Any]) -> Optional[Iterator[Spans]]:
    """
    Return each selected chunk's messages as spans, or None where rosbags must read the bag.

    Together the spans hold exactly ``reader.messages(connections=connections)``, in order.

    :param reader: an open ``rosbags.highlevel.AnyReader``.
    :param connections: some of ``reader.connections`` (not empty).
    :returns: None where the bag is not one indexed MCAP bag whose selected chunks do not
        overlap in time (see the module docstring). The iterator raises ``ReaderError`` (or
        what rosbags' ``decompress`` raises) for a damaged chunk.
    """
    sources = _sources(reader, connections)
    if sources is None:
        return None
    return _spans(sources, list(connections))


def storage_pairs(reader: Any, connections: Sequence[Any],
                  kind: type) -> Optional[List[Tuple[Any, Dict[int, Any]]]]:
    """
    Return each storage file of the reader's one ROS 2 bag with ``{its id: given connection}``.

    :param kind: the storage class every file must be (``McapReader``, ``Sqlite3Reader``).
    :returns: None for several bags, ROS 1, another storage, or per-message compression.
    """
    readers = getattr(reader, 'readers', None)
    if not getattr(reader, 'is2', False) or not readers or len(readers) != 1:
        return None
    storage = getattr(readers[0], 'storage', None)
    if isinstance(storage, kind):
        return [(storage, {c.id: c for c in connections})]
    if isinstance(storage, DirectoryReader) and \
            storage.metadata.compression_mode != 'message' and storage.storages and \
            all(isinstance(each, kind) for each in storage.storages):
        return [(each, _channel_map(each, connections)) for each in storage.storages]
    return None


def _sources(reader: Any, connections: Sequence[Any]) -> Optional[List[Tuple[Any, Dict, List]]]:
    """Return each MCAP storage with its channel map and its selected chunks in order, or None."""
    pairs = storage_pairs(reader, connections, McapReader)
    if pairs is None:
        return None
    sources = []
    for mcap, channels in pairs:
        if not channels:
            continue  # (rosbags skips a file without a selected connection)
        if not mcap.chunks or mcap.bio is None:
            return None  # unindexed: rosbags scans the file
        chunks = sorted(
            (c for c in mcap.chunks if any(c.channel_count.get(k, 0) for k in channels)),
            key=lambda c: (c.message_start_time, c.chunk_start_offset))
        for before, after in zip(chunks, chunks[1:]):
            if (before.message_end_time, before.chunk_start_offset) >= (
                    after.message_start_time, after.chunk_start_offset):
                return None  # overlapping chunks: rosbags merges them
        sources.append((mcap, channels, chunks))
    return sources


def _channel_map(storage: Any, connections: Sequence[Any]) -> Dict[int, Any]:
    """Return ``{channel id: connection}`` of one file of a bag directory (rosbags' rule)."""
    channels = {}
    for own in storage.connections:
        for given in connections:
            if given.topic == own.topic and given.msgtype == own.msgtype and \
                    given.ext == own.ext and (
                        not own.digest or not given.digest or given.digest == own.digest):
                channels[own.id] = given
                break
    return channels


def _spans(sources: List[Tuple[Any, Dict, List]], connections: List[Any]) -> Iterator[Spans]:
    """Yield the selected messages of each storage's chunks in turn (empty chunks skipped)."""
    code_of = {id(connection): code for code, connection in enumerate(connections)}
    for storage, channels, chunks in sources:
        lookup = np.full(max(channels) + 1, -1, np.int64)  # channel id -> connection code
        for channel, connection in channels.items():
            lookup[channel] = code_of[id(connection)]
        for chunk in chunks:
            spans = _chunk_spans(storage.bio, chunk, lookup, connections)
            if len(spans.codes):
                yield spans


def _chunk_spans(bio: Any, chunk: Any, lookup: np.ndarray, connections: List[Any]) -> Spans:
    """
    Return one chunk's selected messages sorted by log time (ties in file order).

    :raises ReaderError: a truncated or malformed record, or what rosbags' ``decompress``
        raises (an unknown compression, a size or checksum mismatch).
    """
    bio.seek(chunk.chunk_start_offset + _RECORD + 24)
    crc = _CRC.unpack(read_exact(bio, 4))[0]
    bio.seek(chunk.chunk_start_offset + _RECORD + 40 + len(chunk.compression))
    size = chunk.uncompressed_size
    data = decompress(read_exact(bio, chunk.compressed_size), chunk.compression, size, crc)
    buffer = np.frombuffer(data, np.uint8)
    records = _indexed(bio, chunk, buffer)
    if records is None:
        records = _walk(data)
    offsets, lengths, channels, log_times = records
    known = channels < len(lookup)
    codes = np.where(known, lookup[np.where(known, channels, 0)], -1)
    keep = (codes >= 0) & (log_times >= chunk.message_start_time) & (
        log_times <= chunk.message_end_time)
    offsets, lengths, codes, log_times = (offsets[keep], lengths[keep], codes[keep],
                                          log_times[keep])
    if len(log_times) > 1 and (log_times[1:] < log_times[:-1]).any():
        order = np.argsort(log_times, kind='stable')  # ties keep their file order
        offsets, lengths, codes, log_times = (offsets[order], lengths[order], codes[order],
                                              log_times[order])
    return Spans(buffer, connections, codes, offsets + _DATA, lengths - 22, log_times)


Records = Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""A chunk's message records in file order: offsets, body lengths, channels, log times."""


def _indexed(bio: Any, chunk: Any, buffer: np.ndarray) -> Optional[Records]:
    """
    Return the chunk's message records from its message index, or None if they do not tile it.

    Every index entry's offset must hold a message record, and those records, in offset order,
    must cover the chunk exactly from the first to its end, each ending where the next begins,
    after whole records that are not messages (a writer may put schemas and channels first):
    then the chunk holds those messages and no other, and rosbags' walk would find the same.
    Channel, log time and length come from the records themselves.
    """
    size = len(buffer)
    bio.seek(chunk.chunk_start_offset + chunk.chunk_length)
    index = bio.read(chunk.message_index_length)
    pos, found = 0, []
    while pos + _INDEX.size <= len(index):
        op, length, _, entries = _INDEX.unpack_from(index, pos)
        if op != _INDEX_OP or entries % 16 or _RECORD + 6 + entries > _RECORD + length or \
                pos + _RECORD + length > len(index):
            return None
        found.append(np.frombuffer(index, '<u8', entries // 8, pos + _INDEX.size)[1::2])
        pos += _RECORD + length
    if pos != len(index) or not found:
        return None
    # (each channel's entries in order: a stable sort merges their runs)
    offsets = np.sort(np.concatenate(found), kind='stable').astype(np.int64)
    if offsets[0] < 0 or offsets[-1] > size - _DATA or \
            not _no_messages(buffer[:offsets[0]].tobytes()):
        return None
    # each record's opcode, length, channel, sequence and log time: one row a record
    heads = sliding_window_view(buffer, _RECORD + 14)[offsets]
    lengths = _field(heads, 1, '<u8')
    if (lengths > size).any():
        return None
    lengths = lengths.astype(np.int64)
    ends = offsets + _RECORD + lengths
    if (heads[:, 0] != _MESSAGE_OP).any() or (lengths < 22).any() or \
            ends[-1] != size or (ends[:-1] != offsets[1:]).any():
        return None
    return (offsets, lengths, _field(heads, _RECORD, '<u2').astype(np.int64),
            _field(heads, _RECORD + 6, '<u8').astype(np.int64))


def _no_messages(prefix: bytes) -> bool:
    """Return whether a chunk's first bytes are whole records, none a message (schemas...)."""
    try:
        return not len(_walk(prefix)[0])
    except ReaderError:
        return False


def _field(rows: np.ndarray, at: int, kind: str) -> np.ndarray:
    """Return the little-endian integers of type ``kind`` at byte ``at`` of each uint8 row."""
    return rows[:, at:at + np.dtype(kind).itemsize].copy().view(kind)[:, 0]


def _walk(data: bytes) -> Records:
    """
    Return the chunk's message records by walking every record (``struct.unpack_from``).

    :raises ReaderError: a record running past the chunk, or a message record too short.
    """
    size = len(data)
    offsets: List[int] = []
    lengths: List[int] = []
    channels: List[int] = []
    log_times: List[int] = []
    unpack_length, unpack_message = _LENGTH.unpack_from, _MESSAGE.unpack_from
    pos = 0
    try:
        while pos < size:
            body = pos + _RECORD
            length = unpack_length(data, pos + 1)[0]
            if body + length > size:
                raise ReaderError(f'Truncated record at offset {pos} of a chunk')
            if data[pos] == _MESSAGE_OP:
                if length < 22:
                    raise ReaderError(f'Invalid message record length {length}.')
                channel, _, log_time, _ = unpack_message(data, body)
                offsets.append(pos)
                lengths.append(length)
                channels.append(channel)
                log_times.append(log_time)
            pos = body + length
    except struct.error as error:
        raise ReaderError(f'Truncated record at offset {pos} of a chunk') from error
    return (np.array(offsets, np.int64), np.array(lengths, np.int64),
            np.array(channels, np.int64), np.array(log_times, np.uint64).astype(np.int64))
