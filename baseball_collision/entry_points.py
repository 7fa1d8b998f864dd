"""
The console scripts (``impact_node``, ``baseball-collision``): one BLAS thread from the start.

numpy's OpenBLAS starts a thread per core when numpy is imported, and those threads cost about
0.07-0.1 s of CPU at every start (BENCHMARKS.md, "One BLAS thread from the start"), although
:func:`~baseball_collision.threads.single_threaded_blas` then keeps the work on one. An
environment variable read by the BLAS library at load time avoids them, so it must be set
before numpy is first imported: these functions set it (unless the user did) and only then
import the node or the command line. Nothing here imports numpy.
"""

import os
from typing import List, MutableMapping, Optional

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


def impact_node(args: Optional[List[str]] = None) -> int:
    """Run the node (``baseball_collision.ros.node.main``); returns its exit code."""
    one_blas_thread_from_start()
    from .ros.node import main
    return main(args)


def command_line(argv: Optional[List[str]] = None) -> int:
    """Run ``baseball-collision`` (``baseball_collision.tools.cli.main``); its exit code."""
    one_blas_thread_from_start()
    from .tools.cli import main
    return main(argv)
