"""
Fast decoding of tracker messages: fixed offsets into the raw bytes, no deserialiser.

PointStamped and PoseStamped are decoded from the raw bytes with ``struct.unpack_from`` at
offsets cached per frame_id: CDR (4-byte encapsulation header, int32 sec, uint32 nanosec, uint32
length incl. NUL, frame_id, padding to 8 bytes counted from the end of the encapsulation header,
float64s) and ROS 1 (uint32 seq, uint32 secs, uint32 nsecs, uint32 length, frame_id without NUL,
float64s unaligned). Anything else (big-endian CDR, malformed data) goes to a slow decoder the
caller passes (the reader's: rosbags' ``AnyReader.deserialize``, which raises on corrupt data).
ROS 1 seconds are read as uint32 as ROS 1 defines them (rosbags' deserialiser reads them as
int32, so the two differ only for stamps after 2038).

A chunk of raw messages is decoded in bulk (:func:`decode_chunk`): the messages of one
connection with one length and one frame_id field have one layout, so the compiled kernel reads
their stamps and float64s at its offsets where they lie (``_kernel.decode_group``, no
per-message Python); every other message goes through :func:`decode_samples`, the same samples.

Measured by ``benchmarks/bench_bag_read.py``: keep the loop of :func:`decode_samples` flat.
"""

import itertools
from operator import itemgetter
import struct
from typing import (
    Any, Callable, Dict, Generator, Iterable, Iterator, List, NamedTuple, Sequence, Tuple)

import numpy as np

from .common import FRAME_CACHE_LIMIT
from ..core.detector.chunks import ROLE_CODES
from ..core.toi import _kernel


class Sample(NamedTuple):
    """
    One tracker message, decoded.

    A NamedTuple rather than a dataclass: the reader makes one per message and a tuple is the
    cheapest typed record to build.

    :ivar role: ``'ball'``, ``'bat_pose'``, ``'knob'`` or ``'tip'``.
    :ivar stamp_ns: ``header.stamp`` as integer nanoseconds (``sec * 10**9 + nanosec``).
    :ivar frame_id: ``header.frame_id``.
    :ivar values: ``(x, y, z)`` metres for points and the ball (a ball pose gives its position);
        ``(px, py, pz, qx, qy, qz, qw)`` for a bat pose.
    :ivar log_time_ns: time the message was recorded in the bag (integer nanoseconds).
    """

    role: str
    stamp_ns: int
    frame_id: str
    values: Tuple[float, ...]
    log_time_ns: int


# Raw layouts. In both CDR and ROS 1, bytes 0-3 are the CDR encapsulation header (ROS 1: seq),
# then sec, nanosec and the frame_id length sit at bytes 4, 8 and 12, and frame_id starts at 16.
_CDR_HEAD = struct.Struct('<BBxxiII').unpack_from
_ROS1_HEAD = struct.Struct('<BBxxIII').unpack_from


def _cdr_frame(field: bytes) -> Tuple[str, int]:
    """
    Return ``(frame_id, offset of the first float64)`` for a CDR frame_id field.

    :param field: bytes 12 onwards up to the end of the string: uint32 length (including the
        terminating NUL), then the string and its NUL.
    :raises ValueError: no terminating NUL, or not UTF-8.
    """
    if len(field) < 5 or field[-1] != 0:
        raise ValueError('CDR string without terminating NUL')
    end = 12 + len(field)
    return bytes(field[4:-1]).decode(), 4 + ((end - 4 + 7) & ~7)


def _ros1_frame(field: bytes) -> Tuple[str, int]:
    """
    Return ``(frame_id, offset of the first float64)`` for a ROS 1 frame_id field.

    :param field: bytes 12 onwards up to the end of the string: uint32 length, then the string.
    :raises ValueError: not UTF-8.
    """
    return bytes(field[4:]).decode(), 12 + len(field)


class Route:
    """
    How to decode one connection's raw messages (mutable: it remembers the last frame_id).

    :param role: the topic's role (the samples' ``role``).
    :param cdr: True for CDR (ROS 2), False for ROS 1 serialisation.
    :param floats: how many float64s follow the header (3 for a point or a ball, 7 for a pose).
    :param msgtype: the connection's message type (for the slow decoder and its errors).
    :ivar field: the last frame_id field seen (length + string bytes, see :func:`_cdr_frame`).
    :ivar hit: ``(frame_id, float64 offset)`` for ``field``.
    :ivar cache: every frame_id field seen (bounded), for topics that alternate frames.
    """

    __slots__ = ('role', 'cdr', 'head', 'floats', 'values', 'frame', 'field', 'hit', 'cache',
                 'msgtype')

    def __init__(self, role: str, cdr: bool, floats: int, msgtype: str) -> None:
        self.role = role
        self.cdr = cdr
        self.head = _CDR_HEAD if cdr else _ROS1_HEAD
        self.floats = floats
        self.values = struct.Struct(f'<{floats}d').unpack_from
        self.frame = _cdr_frame if cdr else _ros1_frame
        # Before the first lookup: a length of 2**32 - 1 that, if ever matched by a malformed
        # message, points the float64s out of range so the message takes the checked slow path.
        self.field = b'\xff\xff\xff\xff'
        self.hit: Tuple[str, int] = ('', 2**62)
        self.cache: Dict[bytes, Tuple[str, int]] = {}
        self.msgtype = msgtype

    def lookup(self, field: bytes) -> Tuple[str, int]:
        """
        Return ``(frame_id, float64 offset)`` for a frame_id field and remember it.

        :raises ValueError: a malformed field.
        """
        hit = self.cache.get(field)
        if hit is None:
            if int.from_bytes(field[:4], 'little') != len(field) - 4:
                raise ValueError('frame_id runs past the end of the message')
            hit = self.frame(field)
            if len(self.cache) >= FRAME_CACHE_LIMIT:
                self.cache.clear()
            self.cache[field] = hit
        self.field = field
        self.hit = hit
        return hit


SlowDecoder = Callable[[Route, bytes], Tuple[int, str, Tuple[float, ...]]]
"""``(route, raw) -> (stamp_ns, frame_id, values)`` for what the fast path cannot read."""


def values_from_message(role: str, message: Any) -> Tuple[float, ...]:
    """Return a deserialised PointStamped or PoseStamped's values tuple for its role."""
    if hasattr(message, 'pose'):
        p, q = message.pose.position, message.pose.orientation
        if role == 'ball':
            return (float(p.x), float(p.y), float(p.z))
        return (float(p.x), float(p.y), float(p.z),
                float(q.x), float(q.y), float(q.z), float(q.w))
    p = message.point
    return (float(p.x), float(p.y), float(p.z))


def decode_samples(messages: Iterable[Tuple[Any, int, bytes]], routes: Dict[int, Route],
                   slow: SlowDecoder) -> Generator[Sample, None, int]:
    """
    Yield a sample per raw message; return how many messages were read.

    :param messages: ``(connection, log time in ns, raw bytes)`` as ``AnyReader.messages``
        yields them.
    :param routes: the route of every connection, by ``id(connection)``.
    :param slow: the decoder for messages the fixed offsets cannot read.
    :returns: (the generator's return value) the number of messages read.
    :raises Exception: whatever ``messages`` or ``slow`` raise.
    """
    new = tuple.__new__
    count = 0
    for connection, log_time, raw in messages:
        count += 1
        route = routes[id(connection)]
        try:
            b0, b1, sec, nanosec, length = route.head(raw, 0)
            if route.cdr and (b0 or b1 != 1):
                raise ValueError('not little-endian CDR')
            if raw.startswith(route.field, 12):
                frame_id, offset = route.hit
            else:
                frame_id, offset = route.lookup(raw[12:16 + length])
            values = route.values(raw, offset)
            stamp = sec * 1_000_000_000 + nanosec
        except (ValueError, struct.error, AttributeError):
            stamp, frame_id, values = slow(route, raw)
        yield new(Sample, (route.role, stamp, frame_id, values, log_time))
    return count


class SampleChunk(NamedTuple):
    """
    Consecutive samples as arrays (what ``Detector.add_chunk`` takes), in the bag's order.

    :ivar roles: int8 role codes (``chunks.ROLE_CODES``: 0 ball, 1 bat_pose, 2 knob, 3 tip).
    :ivar stamps_ns: int64 header stamps (ns).
    :ivar frame_ids: each sample's ``header.frame_id``.
    :ivar values: (n, 7) float64: a point's (x, y, z) in the first three columns (the rest 0),
        a bat pose's (px, py, pz, qx, qy, qz, qw).
    :ivar log_times_ns: int64 record times (ns).
    """

    roles: np.ndarray
    stamps_ns: np.ndarray
    frame_ids: List[str]
    values: np.ndarray
    log_times_ns: np.ndarray


def chunk_rows(chunk: SampleChunk) -> Iterator[Sample]:
    """
    Yield a chunk's samples one by one: what :func:`chunk_samples` made the chunk of.

    A bat pose's values are its 7 floats, any other sample's its 3.
    """
    new = tuple.__new__
    for code, stamp, frame_id, row, log_time in zip(
            chunk.roles.tolist(), chunk.stamps_ns.tolist(), chunk.frame_ids,
            chunk.values.tolist(), chunk.log_times_ns.tolist()):
        role = _ROLE_NAMES[code]
        yield new(Sample, (role, stamp, frame_id, tuple(row if role == 'bat_pose' else row[:3]),
                           log_time))


_ROLE_NAMES = {code: role for role, code in ROLE_CODES.items()}


def chunk_samples(samples: Iterable[Sample], size: int) -> Iterator[SampleChunk]:
    """
    Yield ``samples`` as chunks of at most ``size`` (the last may be shorter; none empty).

    Memory is one chunk's, whatever the bag's size.
    """
    iterator = iter(samples)
    codes = ROLE_CODES.__getitem__
    while True:
        batch = list(itertools.islice(iterator, size))
        if not batch:
            return
        n = len(batch)
        roles, stamps, frames, values, logs = zip(*batch)
        codes_array = np.fromiter(map(codes, roles), np.int8, n)
        widths = np.fromiter(map(len, values), np.int64, n)
        flat = np.fromiter(itertools.chain.from_iterable(values), float, int(widths.sum()))
        rows = np.zeros((n, 7))
        if (widths == widths[0]).all():  # one kind of sample (or a chunk of one)
            rows[:, :widths[0]] = flat.reshape(n, widths[0])
        else:
            starts = np.cumsum(widths) - widths
            for column in range(7):
                has = widths > column
                rows[has, column] = flat[starts[has] + column]
        yield SampleChunk(codes_array, np.array(stamps, dtype=np.int64), list(frames), rows,
                          np.array(logs, dtype=np.int64))


RawMessage = Tuple[Any, int, bytes]
"""``(connection, log time in ns, raw bytes)``, as ``AnyReader.messages`` yields them."""

_CONNECTION, _LOG_TIME, _RAW = itemgetter(0), itemgetter(1), itemgetter(2)

BULK_GROUP = 16
"""Fewest messages of one layout decoded in bulk: a group costs about 20 numpy calls (tens of
microseconds), a message through :func:`decode_samples` one to two, so a chunk of many small
groups (frame_ids of many lengths) is not made slower than message by message."""


def _layout(route: Route, first: bytes) -> Tuple[str, int, int]:
    """
    Return ``(frame_id, float64 offset, frame_id field end)`` of a group's first message.

    The layout the group's messages of the same length are read with where their frame_id
    field is the first's byte for byte (and, in CDR, their header little-endian): exactly as
    :func:`decode_samples` would read them (``_kernel.decode_group``).

    :raises ValueError: the first message's header or frame_id field is malformed, or its
        float64s would run past its end.
    """
    length = len(first)
    if length < 16:
        raise ValueError('shorter than a header')
    end = 16 + int.from_bytes(first[12:16], 'little')
    if end > length:
        raise ValueError('frame_id runs past the end of the message')
    frame_id, offset = route.lookup(first[12:end])
    if offset + 8 * route.floats > length:
        raise ValueError('float64s past the end of the message')
    return frame_id, offset, end


class Spans(NamedTuple):
    """
    Raw messages lying in one buffer (an MCAP chunk's decompressed records), in the bag's order.

    :ivar buffer: the bytes, as uint8.
    :ivar connections: the connections the codes index.
    :ivar codes: int64 per message: its connection, as an index into ``connections``.
    :ivar starts: int64 per message: where its raw bytes start in ``buffer``.
    :ivar lengths: int64 per message: how many bytes.
    :ivar log_times_ns: int64 per message: its record time (ns).
    """

    buffer: np.ndarray
    connections: Sequence[Any]
    codes: np.ndarray
    starts: np.ndarray
    lengths: np.ndarray
    log_times_ns: np.ndarray

    def piece(self, first: int, end: int) -> 'Spans':
        """Return messages ``first`` to ``end`` (excluded), in the same buffer."""
        return self._replace(codes=self.codes[first:end], starts=self.starts[first:end],
                             lengths=self.lengths[first:end],
                             log_times_ns=self.log_times_ns[first:end])

    def messages(self, indices: Sequence[int]) -> List[RawMessage]:
        """Return the given messages as ``(connection, log time, raw bytes)`` triplets."""
        return [(self.connections[int(self.codes[k])], int(self.log_times_ns[k]),
                 self.buffer[self.starts[k]:self.starts[k] + self.lengths[k]].tobytes())
                for k in indices]


def decode_chunk(messages: Sequence[RawMessage], routes: Dict[int, Route],
                 slow: SlowDecoder) -> SampleChunk:
    """
    Return the samples of ``messages`` (not empty) as one chunk, in their order.

    The messages of one connection and one length (at least :data:`BULK_GROUP` of them) are
    decoded together from their joined bytes where they share the first one's frame_id field
    (and, in CDR, are little-endian); the rest go through :func:`decode_samples`. The chunk equals
    ``next(chunk_samples(decode_samples(messages, routes, slow), len(messages)))``.

    :param routes: the route of every connection, by ``id(connection)``.
    :param slow: the decoder for messages the fixed offsets cannot read.
    :raises Exception: whatever ``slow`` raises.
    """
    n = len(messages)
    raws = list(map(_RAW, messages))  # (zip(*messages) costs 5x as much)
    owners, which = np.unique(np.fromiter(map(id, map(_CONNECTION, messages)), np.int64, n),
                              return_inverse=True)

    def group(members: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        joined = np.frombuffer(b''.join(itemgetter(*members)(raws)), np.uint8)
        return joined, np.arange(len(members), dtype=np.int64) * (len(joined) // len(members))
    return _decode([routes[int(owner)] for owner in owners], which,
                   np.fromiter(map(len, raws), np.int64, n), group,
                   lambda rest: [messages[k] for k in rest],
                   np.fromiter(map(_LOG_TIME, messages), np.int64, n), routes, slow)


def decode_spans(spans: Spans, routes: Dict[int, Route], slow: SlowDecoder) -> SampleChunk:
    """
    Return the samples of the messages in ``spans`` (not empty): :func:`decode_chunk`'s.

    The same chunk as ``decode_chunk(spans.messages(range(n)), routes, slow)``, without making
    the messages: a group of one layout is read where it lies in the buffer.

    :raises Exception: whatever ``slow`` raises.
    """
    buffer, starts = spans.buffer, spans.starts
    return _decode([routes[id(connection)] for connection in spans.connections], spans.codes,
                   spans.lengths, lambda members: (buffer, starts[members]), spans.messages,
                   spans.log_times_ns, routes, slow)


def _decode(owners: Sequence[Route], which: np.ndarray, lengths: np.ndarray,
            group_of: Callable[[np.ndarray], Tuple[np.ndarray, np.ndarray]],
            messages_of: Callable[[np.ndarray], Sequence[RawMessage]], log_times: np.ndarray,
            routes: Dict[int, Route], slow: SlowDecoder) -> SampleChunk:
    """
    Decode a chunk: groups of one connection and one length in bulk, the rest one by one.

    :param owners: the route of each connection code; ``which``: each message's code.
    :param lengths: each message's length in bytes.
    :param group_of: a group's messages (indices, all of one length) as a uint8 buffer and
        where each starts in it (int64); ``messages_of``: messages (indices) as triplets, for
        :func:`decode_samples`.
    """
    n = len(which)
    roles = np.empty(n, np.int8)
    stamps = np.empty(n, np.int64)
    frames = np.empty(n, object)
    values = np.zeros((n, 7))
    done = np.zeros(n, bool)
    named = set()  # the frame_ids of the groups decoded in bulk
    read = []  # (members, frame_id, role code) of each group read in bulk
    for members in _groups(which * (int(lengths.max()) + 1) + lengths):
        route = owners[int(which[members[0]])]
        buffer, starts = group_of(members)
        length = int(lengths[members[0]])
        try:
            frame_id, offset, end = _layout(
                route, buffer[int(starts[0]):int(starts[0]) + length].tobytes())
        except ValueError:
            continue  # each through decode_samples (and its checks)
        named.add(frame_id)
        # its messages of the first's layout: stamps, float64s and done, in the kernel
        _kernel.decode_group(buffer, starts, members, length, end, offset, route.floats,
                             route.cdr, stamps, values, done)
        read.append((members, frame_id, ROLE_CODES[route.role]))
    rest = np.flatnonzero(~done)
    for members, frame_id, role in read:
        mine = members[done[members]]
        roles[mine] = role
        if len(rest) or len(named) > 1:  # (else one frame_id throughout: no array needed)
            frames[mine] = frame_id
    if len(rest):
        others = next(chunk_samples(decode_samples(messages_of(rest), routes, slow), len(rest)))
        roles[rest] = others.roles
        stamps[rest] = others.stamps_ns
        frames[rest] = others.frame_ids
        values[rest] = others.values
    elif len(named) == 1:  # (the common case: one frame_id throughout, the same list)
        return SampleChunk(roles, stamps, [named.pop()] * n, values, log_times)
    return SampleChunk(roles, stamps, frames.tolist(), values, log_times)


GROUPS_PICKED = 8
"""Most groups :func:`_groups` picks out one at a time before it sorts the rest."""


def _groups(keys: np.ndarray) -> List[np.ndarray]:
    """
    Return the indices of each group of equal keys of at least ``BULK_GROUP``, by key.

    Each group's indices ascending. A chunk holds a few groups (a connection and a length
    each): they are picked out one at a time (a comparison each), a sort only for more than
    ``GROUPS_PICKED``.
    """
    found = {}
    rest, left = np.arange(len(keys)), keys
    while len(rest) and len(found) < GROUPS_PICKED:
        mine = left == left[0]
        found[int(left[0])] = rest[mine]
        rest, left = rest[~mine], left[~mine]
    if len(rest):
        _, group_of = np.unique(left, return_inverse=True)
        order = np.argsort(group_of, kind='stable')  # each group's together, in order
        sizes = np.bincount(group_of)
        for first, size in zip((np.cumsum(sizes) - sizes).tolist(), sizes.tolist()):
            members = rest[order[first:first + size]]
            found[int(left[order[first]])] = members
    return [found[key] for key in sorted(found) if len(found[key]) >= BULK_GROUP]
