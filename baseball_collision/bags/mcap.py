"""
An indexed MCAP bag's messages, as ``AnyReader.messages`` gives them, at a fraction of the cost.

rosbags reads an MCAP chunk record by record through ``io.BytesIO`` objects (about 3 us per
message: as much as the whole analysis of a quiet stretch of a session). Here each chunk is
read and decompressed by rosbags' own code (``storage_mcap.decompress``, the same checks), and
its message records are walked with ``struct.unpack_from`` on the decompressed bytes. The
output is the same: the same ``(connection, log time in ns, raw bytes)`` triplets in the same
order.

The order rosbags gives: each chunk's messages sorted by log time (ties in file order), the
chunks merged by (log time, chunk offset). Where the selected chunks, ordered by their first
log time, do not overlap (the last key of each before the first of the next: what a recorder
writes), that merge is their concatenation, which is what is read here. Anything else returns
None and the caller uses rosbags' reader: bags without a chunk index, overlapping chunks,
per-message compression, ROS 1 bags, sqlite3 storage, several bags in one reader.
"""

from operator import itemgetter
import struct
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple

from rosbags.rosbag2 import ReaderError
from rosbags.rosbag2.reader import DirectoryReader
from rosbags.rosbag2.storage_mcap import decompress, McapReader

RawMessage = Tuple[Any, int, bytes]
"""``(connection, log time in ns, raw bytes)``, as ``AnyReader.messages`` yields them."""

_LENGTH = struct.Struct('<Q')
_CRC = struct.Struct('<I')
_MESSAGE = struct.Struct('<HIQQ')  # channel id, sequence, log time, publish time
_MESSAGE_OP = 0x05
_CHUNK_HEADER = 9  # opcode and record length before a chunk record's fields
_LOG_TIME = itemgetter(1)


def mcap_messages(reader: Any, connections: Sequence[Any]) -> Optional[Iterator[RawMessage]]:
    """
    Return an iterator equal to ``reader.messages(connections=connections)``, or None.

    :param reader: an open ``rosbags.highlevel.AnyReader``.
    :param connections: some of ``reader.connections`` (not empty).
    :returns: None where the bag is not one indexed MCAP bag whose selected chunks do not
        overlap in time (see the module docstring): the caller reads it with rosbags.
    """
    sources = _sources(reader, connections)
    if sources is None:
        return None
    return _messages(sources)


def _sources(reader: Any, connections: Sequence[Any]) -> Optional[List[Tuple[Any, Dict, List]]]:
    """Return each MCAP storage with its channel map and its selected chunks in order, or None."""
    readers = getattr(reader, 'readers', None)
    if not getattr(reader, 'is2', False) or not readers or len(readers) != 1:
        return None
    storage = getattr(readers[0], 'storage', None)
    if isinstance(storage, McapReader):
        pairs = [(storage, {c.id: c for c in connections})]
    elif isinstance(storage, DirectoryReader) and \
            storage.metadata.compression_mode != 'message' and storage.storages and \
            all(isinstance(each, McapReader) for each in storage.storages):
        pairs = [(each, _channel_map(each, connections)) for each in storage.storages]
    else:
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


def _channel_map(storage: McapReader, connections: Sequence[Any]) -> Dict[int, Any]:
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


def _messages(sources: List[Tuple[Any, Dict, List]]) -> Iterator[RawMessage]:
    """Yield the messages of each storage's chunks in turn."""
    for storage, channels, chunks in sources:
        for chunk in chunks:
            yield from _chunk_messages(storage.bio, chunk, channels)


def _chunk_messages(bio: Any, chunk: Any, channels: Dict[int, Any]) -> List[RawMessage]:
    """
    Return one chunk's selected messages sorted by log time (ties in file order).

    :raises ReaderError: a truncated record, or what rosbags' ``decompress`` raises (an
        unknown compression, a size or checksum mismatch).
    """
    bio.seek(chunk.chunk_start_offset + _CHUNK_HEADER + 24)
    crc = _CRC.unpack(_read(bio, 4))[0]
    bio.seek(chunk.chunk_start_offset + _CHUNK_HEADER + 40 + len(chunk.compression))
    size = chunk.uncompressed_size
    data = decompress(_read(bio, chunk.compressed_size), chunk.compression, size, crc)
    start, stop = chunk.message_start_time, chunk.message_end_time + 1
    found: List[RawMessage] = []
    append, unpack_length, unpack_message = found.append, _LENGTH.unpack_from, \
        _MESSAGE.unpack_from
    pos = 0
    try:
        while pos < size:
            body = pos + 9
            end = body + unpack_length(data, pos + 1)[0]
            if end > size:
                raise ReaderError(f'Truncated record at offset {pos} of a chunk')
            if data[pos] == _MESSAGE_OP:
                if end - body < 22:
                    raise ReaderError(f'Invalid message record length {end - body}.')
                channel, _, log_time, _ = unpack_message(data, body)
                if start <= log_time < stop and channel in channels:
                    append((channels[channel], log_time, data[body + 22:end]))
            pos = end
    except struct.error as error:
        raise ReaderError(f'Truncated record at offset {pos} of a chunk') from error
    times = list(map(_LOG_TIME, found))
    if any(a > b for a, b in zip(times, times[1:])):
        found.sort(key=_LOG_TIME)  # stable: ties keep their file order
    return found


def _read(bio: Any, size: int) -> bytes:
    """Return exactly ``size`` bytes from ``bio``; :raises ReaderError: fewer."""
    data = bio.read(size)
    if len(data) != size:
        raise ReaderError(f'Truncated record: expected {size} bytes, got {len(data)}.')
    return data
