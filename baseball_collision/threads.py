"""
Threads in the package's own processes: one BLAS thread, and reading a bag ahead on another.

**One BLAS thread** in the node, ``analyze`` and its workers.

The detector's linear algebra is on small matrices (3-32 wide: the smoother's penalty, the
windows' fits). OpenBLAS splits even those over its threads, and with the cores busy (a robot
computer, two trackers, a pool of ``analyze`` workers) the threads wait for each other:
``numpy.linalg.eigh`` of a 32 x 32 matrix took 1.5-3.4 ms with the default threads and
0.11-0.14 ms with one on a loaded 2-core machine (BENCHMARKS.md, "One BLAS thread"). The answers
are the same to the bit. ``threadpoolctl`` (a small, well-kept library: scikit-learn's) sets the
limit at run time for whichever BLAS numpy loaded (OpenBLAS, MKL, BLIS; x86 or arm64), which an
environment variable cannot once numpy is imported. (The console scripts set those variables
before numpy loads too, ``entry_points``, which also spares OpenBLAS starting its threads.)

A program that makes a ``Detector`` in its own process keeps its own threads; it can call
:func:`single_threaded_blas` too.

**Reading ahead** (:class:`ReadAhead`): ``analyze`` reads a bag's next file chunk or batch (a
sqlite3 batch's query, an MCAP chunk's read, checksum and decompression) on a background thread
while the detector works on the chunk before. SQLite, file reads, checksums and decompression
run without the GIL, so on a machine with a spare core the two overlap; the chunks and their
order are the same, so are the events.
"""

import queue
import threading
from typing import Any, Iterable, Iterator, Optional, TypeVar

from threadpoolctl import threadpool_info, threadpool_limits

Item = TypeVar('Item')


def single_threaded_blas() -> None:
    """
    Limit every BLAS library loaded in this process to one thread, from now on.

    numpy is imported first, so its BLAS is loaded and limited even when nothing has imported
    numpy yet (a limit set before a library loads does not reach it). Libraries already on one
    thread are left alone: in a child forked from a limited process (a pool worker) setting the
    limit again made OpenBLAS start its thread pool anew, and the helper thread then spun for
    about 0.05-0.1 s of CPU beside the work, once a worker, taken from the other worker's
    core (BENCHMARKS.md, "--jobs 2: where the time goes"); the limit is inherited with the fork.
    """
    import numpy  # noqa: F401 (loads numpy's BLAS)
    if blas_threads() > 1:
        threadpool_limits(limits=1, user_api='blas')


def blas_threads(*_: object) -> int:
    """
    Return the most threads any BLAS library loaded in this process may use (0: none).

    Any arguments are ignored (so a process pool can ``map`` it).
    """
    return max((pool['num_threads'] for pool in threadpool_info()
                if pool.get('user_api') == 'blas'), default=0)


class ReadAhead(Iterator[Item]):
    """
    Iterate over ``items`` while a background thread takes up to ``depth`` of them ahead.

    The items come in their order; what taking one raises is raised by ``next`` in its place
    (the same exception object), after the items before it. The thread starts on the first
    ``next`` and ends with the items, at the first error, or on :meth:`close` (also the end of
    a ``with`` block), which stops it and waits for it: it takes no item after that, finishes
    the one it was taking, and closes ``items`` when it is a generator (its ``finally`` blocks
    run on that thread, before ``close`` returns). Close it before closing what ``items`` reads
    from; ``next`` after ``close`` raises ValueError (as a closed file does), so a reader cut
    short is not taken for one that ended. Memory: ``depth`` items waiting, and one being
    taken.

    :param items: any iterable; it is iterated on the background thread only.
    :param depth: items taken ahead (at least 1).
    :raises ValueError: ``depth`` below 1.
    """

    _ITEM, _END, _ERROR = range(3)

    def __init__(self, items: Iterable[Item], depth: int = 1) -> None:
        if depth < 1:
            raise ValueError(f'read ahead by at least 1 item, not {depth}')
        self._items = items
        self._queue: 'queue.Queue[Any]' = queue.Queue(maxsize=depth)
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None
        self._done = self._closed = False

    def __iter__(self) -> Iterator[Item]:
        """Return this iterator."""
        return self

    def __next__(self) -> Item:
        """
        Return the next item (taken ahead), starting the thread on the first call.

        :raises StopIteration: no more items.
        :raises ValueError: closed before the items ended.
        :raises Exception: what taking the item raised (then no more items).
        """
        if self._closed:
            raise ValueError('closed while reading ahead')
        if self._done:
            raise StopIteration
        if self._thread is None:
            self._thread = threading.Thread(target=self._take, name='read-ahead', daemon=True)
            self._thread.start()
        kind, value = self._queue.get()
        if kind == self._ITEM:
            return value
        self._done = True
        self._thread.join()
        if kind == self._ERROR:
            raise value
        raise StopIteration

    def _take(self) -> None:
        """Take the items into the queue until they end, one raises, or a stop (the thread)."""
        try:
            try:
                for item in self._items:
                    self._queue.put((self._ITEM, item))
                    if self._stop.is_set():
                        return
            finally:
                close = getattr(self._items, 'close', None)
                if close is not None:
                    close()  # (a generator left early: its finally blocks, on this thread)
            self._queue.put((self._END, None))
        except BaseException as error:  # noqa: B902 - handed to the reader, raised there
            self._queue.put((self._ERROR, error))

    def close(self) -> None:
        """Stop taking items and wait for the thread (idempotent; ``next`` refuses after it)."""
        self._closed = self._closed or not self._done
        self._done = True
        self._stop.set()
        thread = self._thread
        while thread is not None and thread.is_alive():
            self._drain()  # (room for the item it may be putting, so it sees the stop)
            thread.join(0.01)
        self._drain()

    def _drain(self) -> None:
        """Take whatever waits in the queue (nobody will read it)."""
        while True:
            try:
                self._queue.get_nowait()
            except queue.Empty:
                return

    def __enter__(self) -> 'ReadAhead[Item]':
        """Return this iterator."""
        return self

    def __exit__(self, *_: Any) -> None:
        """Close it."""
        self.close()
