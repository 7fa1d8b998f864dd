"""
One BLAS thread in the package's own processes: the node, ``analyze`` and its workers.

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
"""

from threadpoolctl import threadpool_info, threadpool_limits


def single_threaded_blas() -> None:
    """
    Limit every BLAS library loaded in this process to one thread, from now on.

    numpy is imported first, so its BLAS is loaded and limited even when nothing has imported
    numpy yet (a limit set before a library loads does not reach it).
    """
    import numpy  # noqa: F401 (loads numpy's BLAS)
    threadpool_limits(limits=1, user_api='blas')


def blas_threads(*_: object) -> int:
    """
    Return the most threads any BLAS library loaded in this process may use (0: none).

    Any arguments are ignored (so a process pool can ``map`` it).
    """
    return max((pool['num_threads'] for pool in threadpool_info()
                if pool.get('user_api') == 'blas'), default=0)
