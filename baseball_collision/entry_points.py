"""
The console scripts (``impact_node``, ``baseball-collision``): one BLAS thread from the start.

numpy's OpenBLAS starts a thread per core when numpy is imported, and those threads cost about
0.07-0.1 s of CPU at every start (BENCHMARKS.md, "One BLAS thread from the start"), although
:func:`~baseball_collision.threads.single_threaded_blas` then keeps the work on one. An
environment variable read by the BLAS library at load time avoids them, so it must be set
before numpy is first imported: these functions set it (unless the user did) and only then
import the node or the command line. Nothing here imports numpy.

The command line's imports (numpy, the core, the command line: some 60,000 objects that live as
long as the process) are made with the garbage collector paused and then frozen out of it
(:func:`frozen_imports`). ``baseball-collision analyze`` ends without the interpreter's
teardown when nothing would be lost (:func:`~baseball_collision.tools.ending.end_process`).
"""

from contextlib import contextmanager
import gc
import os
from typing import Iterator, List, MutableMapping, Optional

BLAS_THREAD_VARIABLES = ('OPENBLAS_NUM_THREADS', 'MKL_NUM_THREADS', 'BLIS_NUM_THREADS')
"""The variables numpy's BLAS libraries (OpenBLAS, MKL, BLIS) read for their thread count."""


def one_blas_thread_from_start(environment: Optional[MutableMapping[str, str]] = None) -> None:
    """
    Ask every BLAS library numpy may load for one thread, where the user did not say.

    :param environment: the variables to set (None: this process's, ``os.environ``; a child's
        environment to start it so).
    """
    environment = os.environ if environment is None else environment
    for variable in BLAS_THREAD_VARIABLES:
        environment.setdefault(variable, '1')


@contextmanager
def frozen_imports() -> Iterator[None]:
    """
    Within the block, no garbage collection; after it, every object alive is frozen out of it.

    An import makes objects that live as long as the process (modules, classes, functions):
    the collections that start-up's allocations set off walk them again and again, and so does
    every later collection of the older generations. Paused, then frozen (``gc.freeze``), they
    are never walked: about 10 ms less CPU at every start of ``analyze`` (BENCHMARKS.md,
    "Start-up and teardown"). The few hundred garbage cycles the imports leave (about 400
    objects) are kept. Collection is on again after the block (as it was before it, if off).

    The interpreter's teardown does not free what frozen objects hold (a module's global, say
    an open file, stays unflushed): a process that ends the ordinary way unfreezes them first
    (``gc.unfreeze``), as :func:`command_line` does.
    """
    was_on = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if was_on:
            gc.enable()


def impact_node(args: Optional[List[str]] = None) -> int:
    """Run the node (``baseball_collision.ros.node.main``); returns its exit code."""
    one_blas_thread_from_start()
    from .ros.node import main
    return main(args)


def command_line(argv: Optional[List[str]] = None) -> int:
    """
    Run ``baseball-collision`` (``baseball_collision.tools.cli.main``); its exit code.

    After ``analyze`` the process ends here unless something would be lost (``cli.main``'s
    ``end``).
    """
    one_blas_thread_from_start()
    with frozen_imports():
        from .tools.cli import main
    try:
        return main(argv, end=True)
    finally:  # (not reached when the process ended at once)
        gc.unfreeze()  # the ordinary exit then frees every object, the frozen ones too
