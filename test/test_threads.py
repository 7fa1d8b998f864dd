"""Tests for baseball_collision.threads: the package's processes run BLAS on one thread."""

import os
import subprocess
import sys

TWO_THREADS = dict(os.environ, OPENBLAS_NUM_THREADS='2', OMP_NUM_THREADS='2')
"""A child's environment in which numpy's BLAS starts with two threads, whatever the cores."""


def test_single_threaded_blas_limits_numpys_blas_in_a_fresh_process() -> None:
    """In a fresh process numpy's BLAS starts with two threads (as told), then has one."""
    script = ('import numpy, sys; from baseball_collision.threads import blas_threads, '
              'single_threaded_blas; before = blas_threads(); single_threaded_blas(); '
              'print(before, blas_threads())')
    before, after = subprocess.run([sys.executable, '-c', script], check=True, env=TWO_THREADS,
                                   capture_output=True, text=True).stdout.split()
    assert (int(before), int(after)) == (2, 1)


def test_the_node_and_the_command_line_limit_blas_at_start() -> None:
    """``impact_node``'s and ``baseball-collision``'s main set it before anything else."""
    script = ('import contextlib, io, sys\n'
              'from baseball_collision.threads import blas_threads\n'
              'from baseball_collision.{module} import main\n'
              'with contextlib.redirect_stdout(io.StringIO()):\n'
              '    try:\n'
              '        main({args})\n'
              '    except SystemExit:\n'
              '        pass\n'
              'print(blas_threads())\n')
    # the node refuses a bad model and exits; the command line prints its help and exits
    for module, args in (('ros.node', "['--ros-args', '-p', 'model:=nonsense']"),
                         ('tools.cli', "['--help']")):
        found = subprocess.run([sys.executable, '-c', script.format(module=module, args=args)],
                               check=True, env=TWO_THREADS, capture_output=True,
                               text=True).stdout.split()
        assert found[-1] == '1', (module, found)
