"""Tests of ``tools/pool.py``: the process pool ``analyze`` and ``--plot`` run their tasks in."""

import subprocess
import sys

from baseball_collision.threads import blas_threads
from baseball_collision.tools.pool import in_pool, pool_context, start_worker


def test_the_pool_forks_only_from_a_process_with_one_thread() -> None:
    """Fork (workers in ms) from a single-threaded process; the fork server once a thread runs."""
    script = ('import threading\n'
              'from baseball_collision.tools.pool import pool_context\n'
              'print(pool_context().get_start_method())\n'
              'stop = threading.Event()\n'
              'thread = threading.Thread(target=stop.wait)\n'
              'thread.start()\n'
              'print(pool_context().get_start_method())\n'
              'stop.set()\n'
              'thread.join()\n')
    methods = subprocess.run([sys.executable, '-c', script], check=True, capture_output=True,
                             text=True).stdout.split()
    assert methods == ['fork', 'forkserver']


def test_a_pool_worker_runs_blas_on_one_thread() -> None:
    """``analyze``'s workers set one BLAS thread as they start, as its own process does."""
    with pool_context().Pool(2, initializer=start_worker) as pool:
        assert pool.map(blas_threads, range(2)) == [1, 1]


def test_in_pool_gives_results_in_task_order_and_the_first_error() -> None:
    """Results in the order of the tasks; the first task (in that order) that raises is raised."""
    assert in_pool(abs, [-3, 2, -1, 0], 2, progress=False) == [3, 2, 1, 0]
    try:
        in_pool(int, ['1', 'x', '2', 'y'], 2, progress=False)
    except ValueError as error:
        assert "'x'" in str(error)
    else:
        raise AssertionError('in_pool swallowed a failing task')
