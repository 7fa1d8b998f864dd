"""
A ROS 2 sqlite3 bag's messages, as ``AnyReader.messages`` gives them, with little Python each.

rosbags reads a sqlite3 bag with one query per file (``Sqlite3Reader.messages``) and hands each
row on through three generators (the storage's, the bag directory's and ``AnyReader``'s merge),
making a tuple and looking up a connection per message. Here, after rosbags has opened the bag
(and checked every file), each file's rows are read on its own open connection (rosbags' apsw
``dbconn``) a batch at a time: a batch's connection codes, log times and lengths become arrays
and its bytes one buffer, a :class:`~.decode.Spans` that :func:`.decode.decode_spans` decodes
in bulk. Memory stays one batch's whatever the bag's size.

A batch is one row of SQLite aggregates (:class:`_File`): rosbags' query from where the batch
before ended, its rows' bytes concatenated and their log times, codes and lengths as text, so
no Python object is made per row (a tuple, an int and a bytes object each took about 0.5 us).
Only where SQLite's plan of rosbags' own query (its text and arguments, :func:`query`) walks
the messages by one index without a sort, and the batches are made to walk that index the
same way; otherwise, and from any batch that cannot be read so, the rows of rosbags' query are
taken ``size`` at a time (``itertools.islice`` of the cursor, in C).

The messages, their connections and their order are rosbags': the rows come in the order
rosbags' query gives them, ties in time included; a bag directory's files are read one after
the other as rosbags reads them (it does not merge them), each file's topics mapped to the
given connections by rosbags' rule. Anything else returns None and the caller uses rosbags'
reader: per-message compression (each message is decompressed on its own), ROS 1 bags, MCAP
storage, several bags in one reader, or an empty selection (which rosbags takes as every
connection). A compressed file (``compression_mode`` file) is no exception: rosbags
decompresses it whole when it opens the bag, and its ``Sqlite3Reader`` reads that copy as it
reads any other.
"""
import itertools
from operator import itemgetter
import re
from typing import Any, Dict, Iterator, List, NamedTuple, Optional, Sequence, Tuple

import apsw  # (rosbags' SQLite driver: its connections are the files')
import numpy as np
from rosbags.rosbag2.storage_sqlite3 import Sqlite3Reader

from .decode import Spans
from .mcap import storage_pairs

_TOPIC, _LOG_TIME, _DATA = itemgetter(0), itemgetter(1), itemgetter(2)

Rows = List[Tuple[int, int, bytes]]
"""Rows of the query: ``(topic id, log time in ns, raw bytes)``."""


def query(ids: Sequence[int]) -> str:
    """
    Return rosbags' query of the messages on these topic ids (``Sqlite3Reader.messages``).

    The same text rosbags runs without a time range, so the same plan and the same order: by
    timestamp, ties as the plan gives them (a test checks the text against rosbags' own).
    """
    return ' '.join([
        'SELECT topics.id,messages.timestamp,messages.data',
        'FROM messages JOIN topics ON messages.topic_id=topics.id',
        f'WHERE topics.id IN ({",".join("?" for _ in ids)})',
        'ORDER BY timestamp'])


def sqlite_spans(reader: Any, connections: Sequence[Any],
                 size: int) -> Optional[Iterator[Spans]]:
    """
    Return the selected messages as spans of ``size`` (the last fewer), or None for rosbags.

    Together the spans hold exactly ``reader.messages(connections=connections)``, in order, cut
    where rosbags' messages cut in batches of ``size`` would be (across a bag's files too).

    :param reader: an open ``rosbags.highlevel.AnyReader``.
    :param connections: some of ``reader.connections``.
    :param size: messages a span (at least 1).
    :returns: None where the bag is not one ROS 2 sqlite3 bag rosbags reads query by query (see
        the module docstring). The iterator raises what apsw raises on a damaged file (rosbags'
        own reader raises the same from the same query).
    :raises ValueError: ``size`` below 1.
    """
    if size < 1:
        raise ValueError(f'spans of {size} messages')
    sources = _sources(reader, connections)
    if sources is None:
        return None
    return _spans(sources, list(connections), size)


def _sources(reader: Any, connections: Sequence[Any]) -> Optional[List[Tuple[Any, Dict]]]:
    """Return each sqlite3 file with ``{topic id: given connection}``, or None."""
    pairs = storage_pairs(reader, connections, Sqlite3Reader) if connections else None
    if pairs is None or any(each.dbconn is None for each, _ in pairs):
        return None
    return [(each, channels) for each, channels in pairs if channels]  # (as rosbags skips)


def _spans(sources: List[Tuple[Any, Dict]], connections: List[Any],
           size: int) -> Iterator[Spans]:
    """Yield the rows of every file in turn as spans of ``size`` (the last fewer)."""
    code_of = {id(connection): code for code, connection in enumerate(connections)}
    parts: List[Part] = []
    pending = 0
    for storage, channels in sources:
        ids = tuple(set(channels))  # (rosbags' arguments, in its order)
        rows = _File(storage.dbconn, ids, [code_of[id(channels[t])] for t in ids])
        while True:
            part = rows.take(size - pending)
            if part.count:
                parts.append(part)
                pending += part.count
            if pending < size:
                break  # fewer rows than asked for: the file is spent
            yield _joined(parts, connections)
            parts, pending = [], 0
    if parts:
        yield _joined(parts, connections)


class Part(NamedTuple):
    """
    Rows of one file, in the query's order: their connections' codes, log times, lengths, bytes.

    :ivar count: the rows; ``codes``, ``log_times``, ``lengths``: int64 arrays of that many.
    :ivar data: their raw bytes, one after the other.
    """

    count: int
    codes: np.ndarray
    log_times: np.ndarray
    lengths: np.ndarray
    data: bytes


BATCH_TIES = 65536
"""Most rows of one log time a batch skips (taken already by the batch before) before the rest
of the file goes row by row: skipping is a step a row, so a file of one log time is not read
in quadratic time."""

_LENGTH_BITS = 32  # (a row's code and length as one integer: SQLite's blobs are under 2**31)


class _File:
    """
    One file's selected rows, taken in order: in batches of one aggregate row, else row by row.

    Rosbags' query walks the file's timestamp index (``ORDER BY timestamp``: ties as the index
    keeps them). Where SQLite's plan shows that walk without a sort, both for rosbags' query and
    for the batch form below, and the file's text is UTF-8, a batch of up to ``count`` rows is
    one row of aggregates over rosbags' query from where the last batch ended (its last log
    time, less the rows of that time taken already), ``LIMIT count``: the rows' bytes
    concatenated, their log times and their codes and lengths as text. The same index walked
    from the same entry gives the same rows in the same order; a Python object per row is
    not made. A batch that cannot be read so leaves the rest of the file to the row path,
    rosbags' query from that place row by row (which raises what a damaged file raises): a
    damaged row (data not a blob; a log time not an integer: text or a blob, which the index
    sorts after every number, a real, whose text does not parse as an integer, a null, which
    makes the counts disagree), a batch too big for one SQLite string, an error, or more than
    ``BATCH_TIES`` rows of one log time to skip.

    :param connection: the file's open apsw connection (rosbags').
    :param topics: the selected topic ids; ``codes``: each one's connection code.
    """

    def __init__(self, connection: Any, topics: Sequence[int], codes: Sequence[int]) -> None:
        self.connection, self.topics = connection, list(topics)
        self.codes = np.array(codes, np.int64)
        order = np.argsort(np.array(self.topics, np.int64))  # (any int64: not an index)
        self.sorted = np.array(self.topics, np.int64)[order], self.codes[order]
        self.start: Optional[int] = None  # the rows left: those from this log time on (None:
        self.skip = 0                     # all), less the first ``skip`` of them
        self.cursor: Any = None
        self.index = _walked_index(connection, self.topics)
        self.batches = self.index is not None

    def take(self, count: int) -> Part:
        """
        Return the next ``count`` rows (fewer: the file is spent).

        :raises TypeError: a row whose log time or data is not an integer or bytes.
        """
        if self.cursor is None and self.batches:
            part = self._batch(count)
            if part is not None:
                return part
            self.batches = False
        if self.cursor is None:
            text, arguments = _from(self.topics, self.start, self.skip, self.index)
            self.cursor = self.connection.execute(text, arguments)
        return self._rows(list(itertools.islice(self.cursor, count)))

    def _batch(self, count: int) -> Optional[Part]:
        """Return the next rows as one batch, or None where they cannot be read so."""
        assert self.index is not None
        text, arguments = _batch_query(self.topics, self.start, self.skip, count, self.index)
        try:
            (n, last, data, times, mixed, kind), = self.connection.execute(text, arguments)
            if not n:
                return Part(0, *(np.zeros(0, np.int64),) * 3, b'')
            # a damaged row (data not a blob: 'blob' is the least type name; a log time not
            # an integer: the last in the index, or text that is not integers): the row path
            # raises as rosbags' rows would make it
            if kind != 'blob' or type(last) is not int or not isinstance(data, bytes):
                return None
            log_times = np.fromstring(times, np.int64, sep=',') + (self.start or 0)
            mixed = np.fromstring(mixed, np.int64, sep=',')
        except (apsw.Error, ValueError):  # (too big for one string, SQLite's error, log times
            return None                    # that do not parse as integers: the row path says)
        lengths = mixed & ((1 << _LENGTH_BITS) - 1)
        if len(log_times) != n or len(mixed) != n or int(lengths.sum()) != len(data):
            return None
        if self.start is not None and last == self.start:
            self.skip += n
        else:
            self.start, self.skip = last, int(np.count_nonzero(log_times == last))
        if self.skip > BATCH_TIES:
            self.batches = False
        return Part(n, self.codes[mixed >> _LENGTH_BITS], log_times, lengths, data)

    def _rows(self, rows: Rows) -> Part:
        """
        Return rows of the query as a part.

        :raises TypeError: a row whose time or data is not an integer or bytes (a damaged file).
        """
        n = len(rows)
        topics, codes = self.sorted
        codes = codes[np.searchsorted(topics, np.fromiter(map(_TOPIC, rows), np.int64, n))]
        log_times = np.fromiter(map(_LOG_TIME, rows), np.int64, n)
        data = list(map(_DATA, rows))
        return Part(n, codes, log_times, np.fromiter(map(len, data), np.int64, n),
                    b''.join(data))


def _where(topics: List[int], start: Optional[int], index: str) -> Tuple[str, List[int]]:
    """
    Return rosbags' FROM and WHERE as its plan walks them, from log time ``start`` on.

    The messages by ``index``, the outer loop (``INDEXED BY``, ``CROSS JOIN``): SQLite cannot
    pick another plan for other arguments (a small ``LIMIT`` or a late ``start`` would make
    it sort, ties then in the sort's order).
    """
    name = '"' + index.replace('"', '""') + '"'
    text = ' '.join([
        f'FROM messages INDEXED BY {name} CROSS JOIN topics ON messages.topic_id=topics.id',
        f'WHERE topics.id IN ({",".join("?" for _ in topics)})'])
    if start is None:
        return text, list(topics)
    return text + ' AND messages.timestamp>=?', list(topics) + [start]


def _from(topics: List[int], start: Optional[int], skip: int,
          index: Optional[str]) -> Tuple[str, List[int]]:
    """Return rosbags' query of the rows from a place (rosbags' own text from the start)."""
    if start is None and not skip:
        return query(topics), list(topics)
    assert index is not None  # (a place is only reached by batches)
    where, arguments = _where(topics, start, index)
    return (f'SELECT topics.id,messages.timestamp,messages.data {where} ORDER BY timestamp '
            'LIMIT -1 OFFSET ?', arguments + [skip])


def _batch_query(topics: List[int], start: Optional[int], skip: int, count: int,
                 index: str) -> Tuple[str, List[int]]:
    """
    Return the batch query of ``count`` rows from a place (see :class:`_File`).

    Its log times are given less ``start`` (shorter text; one too far off to subtract becomes
    a real, which does not parse as an integer).
    """
    where, arguments = _where(topics, start, index)
    cases = ' '.join(f'WHEN ? THEN {code}' for code in range(len(topics)))
    return ' '.join([
        "SELECT count(*),max(time),CAST(group_concat(data,'') AS BLOB),group_concat(time-?),",
        f'group_concat(code*{1 << _LENGTH_BITS}+length(data)),',
        'max(typeof(data)) FROM',
        f'(SELECT CASE topics.id {cases} END AS code,messages.timestamp AS time,',
        f'messages.data AS data {where} ORDER BY timestamp LIMIT ? OFFSET ?)']), (
        [start or 0] + list(topics) + arguments + [count, skip])


_WALK = re.compile(r'(?:SCAN|SEARCH) messages USING (?:COVERING )?INDEX (\S+)')


def _walked_index(connection: Any, topics: List[int]) -> Optional[str]:
    """
    Return the index rosbags' query walks the messages by, where batches give its rows.

    That is: the file's text is UTF-8 (the bytes concatenated as text are the bytes), SQLite's
    plan of rosbags' query (with its arguments) walks the messages by one index, in the
    index's order, and sorts nothing, and so do the batch query and the query from a place,
    made to walk that index (``_where``). None otherwise (the row path, rosbags' query).
    """
    try:
        (encoding,), = connection.execute('PRAGMA encoding')
        if encoding != 'UTF-8':
            return None
        index = _plan_walk(connection, query(topics), topics)
        if index is None:
            return None
        for text, arguments in (_batch_query(topics, None, 0, 1, index),
                                _batch_query(topics, 0, 1, 1, index),
                                _from(topics, 0, 1, index)):
            if _plan_walk(connection, text, arguments) != index:
                return None
        return index
    except apsw.Error:  # (a plan that cannot be made or read: the row path)
        return None


def _plan_walk(connection: Any, text: str, arguments: List[int]) -> Optional[str]:
    """Return the one index a query's plan walks the messages by without a sort, or None."""
    plan = connection.execute('EXPLAIN QUERY PLAN ' + text, arguments)
    details = [str(row[-1]) for row in plan]
    walks = [match.group(1) for match in map(_WALK.match, details) if match]
    if len(walks) != 1 or any('TEMP B-TREE' in detail for detail in details):
        return None
    return walks[0]


def _joined(parts: List[Part], connections: List[Any]) -> Spans:
    """Return parts (of one or more files) as one span."""
    sizes = np.concatenate([part.lengths for part in parts])
    data = [part.data for part in parts]
    buffer = np.frombuffer(b''.join(data) if len(data) > 1 else data[0], np.uint8)
    return Spans(buffer, connections, np.concatenate([part.codes for part in parts]),
                 np.cumsum(sizes) - sizes, sizes,
                 np.concatenate([part.log_times for part in parts]))
