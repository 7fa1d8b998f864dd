"""
Exact time of impact for N intervals at once (the compiled kernel on every core); the gap.

``time_of_impact_batch`` runs the scalar solver's kernel (``_kernel.c``, the one
implementation) over the rows, without the GIL, in chunks taken in turn by a pool of threads, one
per core: every row gets exactly the scalar path's answer. ``distance`` is the gap over time, in
numpy.
"""

import itertools
import os
from typing import List, Optional, Tuple, TYPE_CHECKING, Union

import numpy as np

from . import _kernel
from .result import ArrayLike
from ...errors import CoreError

if TYPE_CHECKING:  # (imported when a batch first needs its threads: 5 ms of every start-up)
    from concurrent.futures import ThreadPoolExecutor

CHUNK_ROWS = 8192
"""Fewest rows worth a thread of their own (a few ms of work on a contact-heavy set)."""

CHUNKS_PER_THREAD = 32
"""Chunks per thread, taken in turn: a thread slowed by other work on its core takes fewer, and
the last one to finish waits for at most a short chunk (a static split by threads waited for
the slowest half: 1.76x on two cores with load 0.5-0.9 from other processes)."""

_pool: Optional['ThreadPoolExecutor'] = None
_pool_pid = 0


def cores() -> int:
    """Return the cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _threads() -> 'ThreadPoolExecutor':
    """Return the pool (a new one in a forked child, where the parent's threads do not exist)."""
    global _pool, _pool_pid
    if _pool is None or _pool_pid != os.getpid():
        from concurrent.futures import ThreadPoolExecutor
        _pool = ThreadPoolExecutor(max_workers=cores(), thread_name_prefix='toi_batch')
        _pool_pid = os.getpid()
    return _pool


def _as_floats(name: str, value: Union[float, ArrayLike]) -> np.ndarray:
    """
    Return ``value`` as a float64 array.

    :raises CoreError: not numbers (a string, a ragged list, an object).
    """
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise CoreError(f'{name} must be numbers: {error}') from error


def _as_points(name: str, value: ArrayLike) -> np.ndarray:
    array = _as_floats(name, value)
    if array.ndim != 2 or array.shape[1] != 3:
        raise CoreError(f'{name} must have shape (N, 3), got {array.shape}')
    return array


def _as_column(name: str, value: Union[float, ArrayLike], n: int) -> np.ndarray:
    array = _as_floats(name, value)
    if array.ndim == 0:
        return np.full(n, float(array))
    if array.shape != (n,):
        raise CoreError(f'{name} must be a scalar or have shape ({n},), got {array.shape}')
    return np.ascontiguousarray(array)


def time_of_impact_batch(ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
                         knob0: ArrayLike, knob1: ArrayLike, ball_radius: Union[float, ArrayLike],
                         bat_radius: Union[float, ArrayLike],
                         dt: Union[float, ArrayLike] = 1.0, *,
                         threads: Optional[int] = None) -> np.ndarray:
    """
    ``time_of_impact`` for N intervals at once, on every core.

    :param ball0, ball1, tip0, tip1, knob0, knob1: arrays of shape (N, 3) (metres).
    :param ball_radius, bat_radius: scalars or (N,) (metres, >= 0).
    :param dt: scalar or (N,) (seconds, > 0).
    :param threads: threads to spread the rows over (None: one per core); a chunk of fewer
        than ``CHUNK_ROWS`` rows is not worth a thread.

    :returns: (N,) float64 seconds from each interval's start to first contact (the scalar
        path's ``time``, to the bit); NaN where there is no contact, and NaN for rows with
        non-finite values, negative radii or dt <= 0.

    :raises CoreError: arguments that are not numbers, or arrays of the wrong shape (rows are
        not checked by raising).
    """
    points = [_as_points(name, value) for name, value in (
        ('ball0', ball0), ('ball1', ball1), ('tip0', tip0), ('tip1', tip1),
        ('knob0', knob0), ('knob1', knob1))]
    n = points[0].shape[0]
    for name, array in zip(('ball1', 'tip0', 'tip1', 'knob0', 'knob1'), points[1:]):
        if array.shape[0] != n:
            raise CoreError(f'{name} has {array.shape[0]} rows but ball0 has {n}')
    points = [np.ascontiguousarray(p) for p in points]
    columns = [_as_column(name, value, n) for name, value in (
        ('ball_radius', ball_radius), ('bat_radius', bat_radius), ('dt', dt))]
    result = np.empty(n)
    workers = min(cores() if threads is None else threads, n // CHUNK_ROWS)
    if workers <= 1:
        _kernel.capsule_rows(*points, *columns, result, 0, n)
        return result
    chunks = min(n // CHUNK_ROWS, workers * CHUNKS_PER_THREAD)
    bounds = [n * k // chunks for k in range(chunks + 1)]
    taken = itertools.count()  # next() on it is atomic: each chunk goes to one thread

    def work() -> None:
        k = next(taken)
        while k < chunks:
            _kernel.capsule_rows(*points, *columns, result, bounds[k], bounds[k + 1])
            k = next(taken)

    tasks = [_threads().submit(work) for _ in range(workers - 1)]
    work()
    for task in tasks:
        task.result()
    return result


# ----------------------------------------------------------------------------------------------
# Objective 1: the gap as a function of time (vectorised over t)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the row-wise dot products of (..., 3) arrays."""
    return np.einsum('...i,...i->...', a, b)


def _segment_offsets(point: np.ndarray, start: np.ndarray,
                     axis: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return the fraction along each segment (clipped to [0, 1]) and the offset from it.

    The numpy sibling of the kernel's ``closest_on_segment``: rows of (..., 3) arrays, a segment
    from ``start`` along ``axis``; a zero-length segment is its start.
    """
    axis2 = _dot(axis, axis)
    with np.errstate(divide='ignore', invalid='ignore'):
        fraction = np.where(axis2 > 0.0, np.clip(_dot(point - start, axis) / axis2, 0.0, 1.0),
                            0.0)
    return fraction, point - (start + axis * fraction[..., None])


def positions_at(t: ArrayLike, dt: float, *pairs: ArrayLike) -> List[np.ndarray]:
    """Return each (start, end) pair of points moved linearly to times t (s) of dt: (..., 3)."""
    times = np.asarray(t, dtype=float)[..., None] / float(dt)
    out = []
    for start, end in zip(pairs[::2], pairs[1::2]):
        p0 = np.asarray(start, dtype=float)
        p1 = np.asarray(end, dtype=float)
        out.append(p0 + (p1 - p0) * times)
    return out


def distance(t: ArrayLike, ball0: ArrayLike, ball1: ArrayLike, tip0: ArrayLike, tip1: ArrayLike,
             knob0: ArrayLike, knob1: ArrayLike, ball_radius: float, bat_radius: float,
             dt: float) -> np.ndarray:
    """
    Signed gap between the ball and the capsule bat (segment knob-tip, rounded ends).

    Objective 1 for a finite bat: the distance from the ball centre to the nearest point of the
    segment, minus both radii. Negative means overlap.

    :param t: times in seconds from the interval start (any shape).
    :param ball0 ... dt: as for ``time_of_impact``.

    :returns: Gap in metres, same shape as t.
    """
    ball, tip, knob = positions_at(t, dt, ball0, ball1, tip0, tip1, knob0, knob1)
    _, offset = _segment_offsets(ball, knob, tip - knob)
    return np.linalg.norm(offset, axis=-1) - bat_radius - ball_radius
