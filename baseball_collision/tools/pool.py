"""
A process pool over tasks, results in task order: ``analyze``'s bags and ``--plot``'s figures.

:func:`in_pool` runs a module-level function over tasks in a pool of processes
(:func:`pool_context`: fork where it is safe, else a fork server) and gives the results back in
the order of the tasks; the first task that raises stops the pool. Each worker is set up by
:func:`start_worker` (its signals, one BLAS thread). The same per-task function maps over a
cluster with an existing engine (README, "Beyond one machine").
"""

import sys
from typing import Any, Callable, List, Sequence, TypeVar

from ..atomic import worker_signals
from ..threads import single_threaded_blas

Task = TypeVar('Task')
"""What one job of :func:`in_pool` is given."""

Done = TypeVar('Done')
"""What one job of :func:`in_pool` gives back."""


def start_worker() -> None:
    """Set a pool process up: its signals (``worker_signals``) and one BLAS thread."""
    worker_signals()
    single_threaded_blas()


def pool_context(preload: Sequence[str] = ()) -> Any:
    """
    Return fork with this process on one thread, else forkserver (preloaded), else spawn.

    A forked worker starts in milliseconds with what this process has imported; the fork
    server's first worker waits for its imports (about 0.3 s, against 0.4-0.6 s a 250k-message
    bag). But a child forked while another thread holds a lock (a progress bar's monitor, the
    batch solver's pool, an earlier pool's handlers) can deadlock before it runs a line, and with
    the parent's Python signal handlers it then ignores the SIGTERM that ends the pool:
    ``Pool.terminate`` waited for it forever (4 runs in 30 under load). So fork only from a
    process with no other thread (the command line's, before any bar); otherwise the fork
    server, a clean single-threaded process that imports the analysis once.

    :param preload: modules the fork server imports before it forks a worker (the tasks'
        function's module, by :func:`in_pool`).
    """
    import multiprocessing  # (only a pool needs it)
    import threading

    methods = multiprocessing.get_all_start_methods()
    if threading.active_count() == 1 and 'fork' in methods:
        return multiprocessing.get_context('fork')
    if 'forkserver' in methods:
        context = multiprocessing.get_context('forkserver')
        context.set_forkserver_preload(list(preload))
        return context
    return multiprocessing.get_context('spawn')


def in_pool(function: Callable[[Task], Done], tasks: Sequence[Task], workers: int, *,
            progress: bool = True, unit: str = 'bag') -> List[Done]:
    """
    Return ``function(task)`` for every task, computed by a pool of processes, in task order.

    Each task is one job of a pool of ``workers`` processes (:func:`pool_context`, each set up
    by :func:`start_worker`); the results come back in the order of the tasks, and the first
    task (in that order) that raises stops the pool and its error is raised here, as one
    task after another would. A run shows a bar of tasks done on a terminal.

    :param function: a module-level function (the workers get it by name).
    :param workers: processes (at least 1).
    :param progress: show the bar (only on a terminal).
    :param unit: what a task is, for the bar.
    :raises Exception: what the first failing task raised.
    """
    bar = None
    results: List[Done] = []
    try:
        # leaving the block on an error (or Ctrl-C) terminates the workers at once; done, they
        # are let go (close, join). The bar (and its monitor thread) only after the workers
        # are started: ``pool_context`` forks them only from a process with one thread.
        with pool_context((function.__module__,)).Pool(workers, initializer=start_worker) as pool:
            if progress and sys.stderr.isatty():
                from tqdm import tqdm
                bar = tqdm(total=len(tasks), unit=unit, desc=f'{workers} jobs',
                           file=sys.stderr, leave=False, dynamic_ncols=True)
            for result in pool.imap(function, tasks, chunksize=1):
                results.append(result)
                if bar is not None:
                    bar.update(1)
            pool.close()
            pool.join()
    finally:
        if bar is not None:
            bar.close()
    return results
