"""
A ROS 2 sqlite3 bag's messages, as ``AnyReader.messages`` gives them, with little Python each.

rosbags reads a sqlite3 bag with one query per file (``Sqlite3Reader.messages``) and hands each
row on through three generators (the storage's, the bag directory's and ``AnyReader``'s merge),
making a tuple and looking up a connection per message. Here, after rosbags has opened the bag
(and checked every file), the same query is run on each file's own open connection (rosbags'
apsw ``dbconn``) and its rows are taken a batch at a time (``itertools.islice`` of the cursor,
in C): a batch's topic ids, log times and lengths become arrays and its bytes one buffer, a
:class:`~.decode.Spans` that :func:`.decode.decode_spans` decodes in bulk. Memory stays one
batch's whatever the bag's size (the cursor streams).

The messages, their connections and their order are rosbags': the query is rosbags' own text
(:func:`query`), so the rows come in the order rosbags' query gives them, ties in time
included; a bag directory's files are read one after the other as rosbags reads them (it does
not merge them), each file's topics mapped to the given connections by rosbags' rule. Anything
else returns None and the caller uses rosbags' reader: per-message compression (each message is
decompressed on its own), ROS 1 bags, MCAP storage, several bags in one reader, or an empty
selection (which rosbags takes as every connection). A compressed file (``compression_mode``
file) is no exception: rosbags decompresses it whole when it opens the bag, and its
``Sqlite3Reader`` reads that copy as it reads any other.
"""

import itertools
from operator import itemgetter
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple

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
    parts: List[Tuple[Tuple[np.ndarray, np.ndarray], Rows]] = []
    pending = 0
    for storage, channels in sources:
        topics = np.array(sorted(channels), np.int64)  # (any int64: not an index)
        lookup = (topics, np.array([code_of[id(channels[t])] for t in topics.tolist()], np.int64))
        ids = tuple(set(channels))
        cursor = storage.dbconn.execute(query(ids), ids)
        while True:
            rows = list(itertools.islice(cursor, size - pending))
            if rows:
                parts.append((lookup, rows))
                pending += len(rows)
            if pending < size:
                break  # fewer rows than asked for: the cursor is spent
            yield _batch(parts, connections)
            parts, pending = [], 0
    if parts:
        yield _batch(parts, connections)


def _batch(parts: List[Tuple[Tuple[np.ndarray, np.ndarray], Rows]],
           connections: List[Any]) -> Spans:
    """
    Return rows (of one or more files, each with its topic lookup) as one span.

    :param parts: each file's rows with ``(its selected topic ids sorted, their codes)``.
    :raises TypeError: a row whose time or data is not an integer or bytes (a damaged file).
    """
    codes, log_times, lengths, pieces = [], [], [], []
    for (topics, topic_codes), rows in parts:
        n = len(rows)
        codes.append(topic_codes[np.searchsorted(topics, np.fromiter(map(_TOPIC, rows),
                                                                     np.int64, n))])
        log_times.append(np.fromiter(map(_LOG_TIME, rows), np.int64, n))
        data = list(map(_DATA, rows))
        lengths.append(np.fromiter(map(len, data), np.int64, n))
        pieces.append(b''.join(data))
    sizes = np.concatenate(lengths)
    buffer = np.frombuffer(b''.join(pieces) if len(pieces) > 1 else pieces[0], np.uint8)
    return Spans(buffer, connections, np.concatenate(codes), np.cumsum(sizes) - sizes, sizes,
                 np.concatenate(log_times))
