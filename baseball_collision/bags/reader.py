"""
Ball and bat samples from a bag, streaming, in log-time order: the analysis' input.

Reads ROS 2 bags (a bag directory, or a bare ``.mcap`` / ``.db3`` file) and ROS 1 ``.bag``
files through :class:`rosbags.highlevel.AnyReader`. Only the connections of the selected topics
(:mod:`.selection`) are read, so other topics are never deserialised; their messages are decoded
at fixed offsets (:mod:`.decode`).

Errors
    Every failure is a :class:`BagError` with a one-line message, raised ``from`` its cause,
    including errors met lazily while iterating (a corrupt chunk, records a damaged chunk lost).
"""

from contextlib import contextmanager
from functools import partial
import itertools
import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Tuple, Union

from rosbags.highlevel import AnyReader

from .common import BagFile, first_line
from .decode import (
    chunk_rows, decode_chunk, decode_samples, decode_spans, Route, Sample, SampleChunk, Spans,
    values_from_message)
from .mcap import mcap_spans
from .plans import PlanMessage, read_plans
from .selection import (
    check_selection, given_words, ROLES, select_topics, topic_types, TopicSelection)
from ..errors import BagError
from ..threads import ReadAhead


CHUNK_SIZE = 8192
"""Samples decoded at a time when :meth:`BagReader.samples` reads by chunks (MCAP, sqlite3)."""


class BagReader(BagFile):
    """
    Read ball and bat samples from a bag, streaming, in log-time order across topics.

    Use as a context manager::

        with BagReader('run.mcap') as bag:
            total = bag.message_count          # for a progress bar
            for sample in bag.samples():
                ...

    :param path: ROS 2 bag directory, bare ``.mcap`` or ``.db3`` file, or ROS 1 ``.bag`` file.
    :param selection: topics to read; None to select them with :func:`select_topics`.
    :param ball: explicit ball topic (only without ``selection``).
    :param bat_pose: explicit bat pose topic (only without ``selection``).
    :param knob: explicit knob topic (only without ``selection``).
    :param tip: explicit tip topic (only without ``selection``).
    :param prefer_bat: ``'pose'`` or ``'points'``: the bat to auto-select when the bag has both
        (see :func:`select_topics`).
    :param named: how errors name the topics given, by role (default: by their flags:
        ``--ball-topic '/x'``; ``selection.given_words``).
    :raises BagError: both a selection and topic names given.
    """

    def __init__(self, path: Union[str, os.PathLike], selection: Optional[TopicSelection] = None,
                 *, ball: Optional[str] = None, bat_pose: Optional[str] = None,
                 knob: Optional[str] = None, tip: Optional[str] = None,
                 prefer_bat: str = 'pose', named: Optional[Mapping[str, str]] = None) -> None:
        overrides = {'ball': ball, 'bat_pose': bat_pose, 'knob': knob, 'tip': tip}
        if selection is not None and any(v is not None for v in overrides.values()):
            raise BagError('pass either a TopicSelection or topic names, not both')
        super().__init__(path)
        self._given = selection
        self._overrides = overrides
        self._prefer_bat = prefer_bat
        self._named = named
        self._selection: Optional[TopicSelection] = None
        self._connections: List[Any] = []
        self._routes: Dict[int, Route] = {}
        self._types: Dict[str, Tuple[str, ...]] = {}
        self._ahead: List[ReadAhead[SampleChunk]] = []

    def _setup(self, reader: AnyReader) -> None:
        """
        Select topics and prepare the decoders of an open reader.

        :raises BagError: empty bag, or topics that cannot be selected.
        """
        try:
            total = reader.message_count
            connections = list(reader.connections)
        except Exception as error:
            raise BagError(f'cannot read bag {self.path}: {first_line(error)}') from error
        self._types = topic_types(connections)
        if total == 0:
            raise BagError(f'bag {self.path} contains no messages')
        if self._given is None:
            selection = select_topics(connections, **self._overrides,
                                      prefer_bat=self._prefer_bat, named=self._named)
        else:
            selection = self._given
            check_selection(selection, self._types)
        role_of = {topic: role for role, topic in selection.topics.items()}
        chosen = [c for c in connections if c.topic in role_of]
        for role, topic in selection.topics.items():
            if sum(max(int(c.msgcount), 0) for c in chosen if c.topic == topic) == 0:
                how = given_words(role, topic, self._named) if self._given is not None or \
                    self._overrides.get(role) else \
                    f"the {role} topic (found by name and type) '{topic}'"
                counts = {each.topic: 0 for each in connections}
                for each in connections:
                    counts[each.topic] += max(int(each.msgcount), 0)
                listed = ', '.join(f'{name} ({count})' for name, count in counts.items())
                raise BagError(
                    f'{how} has no messages in bag {self.path} (the tracker sent '
                    f'nothing on it while recording); messages by topic: {listed}')
        routes = {}
        for connection in chosen:
            role = role_of[connection.topic]
            # A ball pose is read as its position: the first 3 float64s of a Pose.
            routes[id(connection)] = Route(
                role, reader.is2, 7 if role == 'bat_pose' else 3, connection.msgtype)
        self._selection = selection
        self._connections = chosen
        self._routes = routes

    @property
    def selection(self) -> TopicSelection:
        """
        Return the selected topics.

        :raises BagError: the bag is not open.
        """
        self._open_reader()
        assert self._selection is not None
        return self._selection

    @property
    def topics(self) -> Dict[str, str]:
        """
        Return all topics of the bag as ``{topic: msgtype}`` (types joined by `` | `` if mixed).

        :raises BagError: the bag is not open.
        """
        self._open_reader()
        return {topic: ' | '.join(msgtypes) for topic, msgtypes in self._types.items()}

    @property
    def message_count(self) -> int:
        """
        Return the number of messages on the selected topics (what :meth:`samples` yields).

        From the bag's index/metadata, no scan.

        :raises BagError: the bag is not open.
        """
        self._open_reader()
        return sum(max(int(c.msgcount), 0) for c in self._connections)

    def samples(self) -> Iterator[Sample]:
        """
        Yield the selected topics' messages as samples, in the bag's log-time order.

        Streams (memory does not grow with the bag). Only the selected topics' connections are
        read. An indexed MCAP bag or a sqlite3 bag is decoded a chunk at a time (:meth:`chunks`)
        and its samples taken from the arrays (:func:`.decode.chunk_rows`): the same samples.

        :returns: an iterator of :class:`Sample`.
        :raises BagError: the bag is not open, or is corrupt (raised while iterating).
        """
        reader = self._open_reader()
        return self._samples(reader)

    def chunks(self, size: int = CHUNK_SIZE, read_ahead: int = 0) -> Iterator[SampleChunk]:
        """
        Yield the samples of :meth:`samples` as arrays, at most ``size`` at a time.

        Each chunk's messages are decoded in bulk (:func:`.decode.decode_chunk`): the same
        samples. An indexed MCAP bag is read a chunk of the file at a time, each cut into
        pieces of ``size`` (the last of each fewer), its messages decoded where they lie
        (:mod:`.mcap`, :func:`.decode.decode_spans`); a sqlite3 bag's rows are taken ``size``
        at a time from rosbags' own query (:mod:`.sqlite`, the last fewer) and decoded the same
        way; any other bag ``size`` at a time through rosbags' reader (the last fewer). Memory
        stays one chunk's whatever the bag's size.

        With ``read_ahead`` > 0 an MCAP or sqlite3 bag's next file chunks or batches (that
        many) are read on a background thread while the chunk before is decoded and used
        (:class:`~..threads.ReadAhead`): the same chunks, and what reading raises comes in its
        place. The thread reads the file, decompresses, checks and queries (SQLite), which
        release the GIL, so on a spare core the reading overlaps the caller's work; the decode
        stays on the caller's thread (it holds the GIL: on that thread it would only contend).
        Memory: that many file chunks or batches more. Other bags are read as without it.
        :meth:`close` stops the thread before it closes the bag.

        :raises BagError: as :meth:`samples`; ``read_ahead`` below 0.
        """
        if read_ahead < 0:
            raise BagError(f'read ahead by 0 or more batches, not {read_ahead}')
        reader = self._open_reader()
        return self._chunks(reader, size, read_ahead)

    def plans(self, topic: str) -> Optional[List[PlanMessage]]:
        """
        Return the bat plans on ``topic`` in log-time order, or None: the bag has no such topic.

        Read in a pass of their own (:func:`.plans.read_plans`), beside the samples.

        :raises BagError: the bag is not open, the topic is not ``nav_msgs/msg/Path``, or a
            plan cannot be read.
        """
        return read_plans(self._open_reader(), topic, str(self.path))

    def close(self) -> None:
        """Stop any chunks read ahead (waiting for their thread), then close the bag."""
        for ahead in self._ahead:
            ahead.close()
        self._ahead.clear()
        super().close()

    @contextmanager
    def _reading(self) -> Iterator[None]:
        """Turn what reading raises into a BagError naming the bag."""
        try:
            yield
        except BagError:
            raise
        except Exception as error:
            raise BagError(f'cannot read bag {self.path}: {first_line(error)}') from error

    def _check_count(self, count: int, expected: int) -> None:
        """
        Refuse a bag that gave fewer messages than its index lists (``expected``).

        :raises BagError: fewer (rosbags skips records it cannot place in a damaged chunk
            without an error; the bag's own index still counts them).
        """
        if count < expected:
            raise BagError(f'bag {self.path} is damaged: read {count} of the {expected} '
                           'messages its index lists on the selected topics')

    def _samples(self, reader: AnyReader) -> Iterator[Sample]:
        """Yield samples (the generator behind :meth:`samples`): MCAP's and sqlite3's by chunks."""
        spans = self._spans(reader, CHUNK_SIZE)
        if spans is not None:
            for chunk in self._span_chunks(reader, spans, CHUNK_SIZE):
                yield from chunk_rows(chunk)
            return
        expected = self.message_count

        slow = partial(self._slow, reader)
        with self._reading():
            count = yield from decode_samples(
                reader.messages(connections=self._connections), self._routes, slow)
        self._check_count(count, expected)

    def _chunks(self, reader: AnyReader, size: int, read_ahead: int = 0) -> Iterator[SampleChunk]:
        """Yield chunks (the generator behind :meth:`chunks`)."""
        spans = self._spans(reader, size)
        if spans is not None:  # MCAP chunks' messages in place, sqlite3 rows in batches
            if read_ahead == 0:
                yield from self._span_chunks(reader, spans, size)
                return
            ahead = ReadAhead(spans, read_ahead)
            self._ahead.append(ahead)
            with ahead:
                yield from self._span_chunks(reader, ahead, size)
            return
        expected = self.message_count

        slow = partial(self._slow, reader)
        count = 0
        with self._reading():
            messages = reader.messages(connections=self._connections)
            while True:
                batch = list(itertools.islice(messages, size))
                if not batch:
                    break
                count += len(batch)
                yield decode_chunk(batch, self._routes, slow)
        self._check_count(count, expected)

    def _spans(self, reader: AnyReader, size: int) -> Optional[Iterator[Spans]]:
        """
        Return the selected messages as spans (:mod:`.mcap`, :mod:`.sqlite`), or None.

        None: the bag is read through rosbags' ``AnyReader.messages`` (ROS 1, per-message
        compression, ...). ``size``: the messages of a sqlite3 bag's spans.

        :mod:`.sqlite` is imported here, for a bag that is not MCAP: analysing an MCAP bag never
        loads it.

        :raises BagError: the bag's index cannot be read.
        """
        with self._reading():
            spans = mcap_spans(reader, self._connections)
            if spans is None:
                from .sqlite import sqlite_spans
                spans = sqlite_spans(reader, self._connections, size)
        return spans

    def _span_chunks(self, reader: AnyReader, spans: Iterator[Spans],
                     size: int) -> Iterator[SampleChunk]:
        """Yield spans' chunks (MCAP file chunks, sqlite3 batches) in pieces of ``size``."""
        expected = self.message_count

        slow = partial(self._slow, reader)
        count = 0
        with self._reading():
            for each in spans:
                for first in range(0, len(each.codes), size):
                    piece = each.piece(first, first + size)
                    count += len(piece.codes)
                    yield decode_spans(piece, self._routes, slow)
        self._check_count(count, expected)

    def _slow(self, reader: AnyReader, route: Route,
              raw: bytes) -> Tuple[int, str, Tuple[float, ...]]:
        """
        Decode one message with the rosbags deserialiser (big-endian or unusual data).

        :raises BagError: the message cannot be deserialised (corrupt); names the bag.
        """
        try:
            message: Any = reader.deserialize(raw, route.msgtype)
            stamp = message.header.stamp
            stamp_ns = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)  # (as decode's)
            return stamp_ns, str(message.header.frame_id), values_from_message(route.role, message)
        except Exception as error:
            raise BagError(
                f'corrupt {route.msgtype} message on the {route.role} topic of bag '
                f'{self.path}: {first_line(error)}') from error


def read_samples(path: Union[str, os.PathLike], selection: Optional[TopicSelection] = None,
                 **overrides: Optional[str]) -> Iterator[Sample]:
    """
    Yield the ball and bat samples of a bag, in log-time order (see :class:`BagReader`).

    The bag is opened on the first ``next()`` and closed when the iterator is exhausted or
    closed. Use :class:`BagReader` to get the selection and message count first.

    :param path: ROS 2 bag directory, bare ``.mcap``/``.db3`` file, or ROS 1 ``.bag`` file.
    :param selection: topics to read; None to select them with :func:`select_topics`.
    :param overrides: explicit topics ``ball``, ``bat_pose``, ``knob``, ``tip``.
    :returns: an iterator of :class:`Sample`.
    :raises BagError: see :meth:`BagReader.open` and :meth:`BagReader.samples`; an unknown
        override name.
    """
    unknown = set(overrides) - set(ROLES)
    if unknown:
        raise BagError(f'unknown topic roles: {", ".join(sorted(unknown))}')
    with BagReader(path, selection, **overrides) as bag:
        yield from bag.samples()


def count_messages(path: Union[str, os.PathLike], selection: Optional[TopicSelection] = None,
                   **overrides: Optional[str]) -> int:
    """
    Return how many samples :func:`read_samples` will yield (from the bag index, no scan).

    :raises BagError: see :meth:`BagReader.open`.
    """
    with BagReader(path, selection, **overrides) as bag:
        return bag.message_count
