"""Tests for baseball_collision.threads: the package's processes run BLAS on one thread."""

import os
import subprocess
import sys

from baseball_collision.entry_points import BLAS_THREAD_VARIABLES

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


def test_single_threaded_blas_before_numpy_is_imported_still_limits_it() -> None:
    """Called before anything imports numpy, the limit still reaches numpy's BLAS."""
    script = ('import sys; from baseball_collision.threads import blas_threads, '
              'single_threaded_blas; before = "numpy" in sys.modules; single_threaded_blas(); '
              'import numpy; print(before, blas_threads())')
    found = subprocess.run([sys.executable, '-c', script], check=True, env=TWO_THREADS,
                           capture_output=True, text=True).stdout.split()
    assert found == ['False', '1']


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


def test_importing_the_package_loads_neither_numpy_nor_the_core() -> None:
    """``import baseball_collision`` is light; its public names import on first use."""
    script = ('import sys, baseball_collision as package\n'
              'light = "numpy" not in sys.modules\n'
              'print(light, package.Detector.__name__, "numpy" in sys.modules, '
              'sorted(set(package.__all__) - set(dir(package))))\n')
    found = subprocess.run([sys.executable, '-c', script], check=True, capture_output=True,
                           text=True).stdout.split()
    assert found == ['True', 'Detector', 'True', '[]']


def test_the_console_scripts_start_numpy_with_one_blas_thread() -> None:
    """Through ``entry_points`` numpy's BLAS has one thread before any run-time limit."""
    environment = {name: value for name, value in TWO_THREADS.items()
                   if name not in BLAS_THREAD_VARIABLES}  # OpenBLAS then reads OMP_NUM_THREADS
    script = ('import contextlib, io\n'
              'from baseball_collision import threads\n'
              'seen = []\n'
              'threads.single_threaded_blas = lambda: seen.append(threads.blas_threads())\n'
              '{entry}\n'
              'with contextlib.redirect_stdout(io.StringIO()):\n'
              '    try:\n'
              '        main({args})\n'
              '    except SystemExit:\n'
              '        pass\n'
              'print(*seen)\n')
    node = "['--ros-args', '-p', 'model:=nonsense']"
    runs = {
        ('from baseball_collision.entry_points import impact_node as main', node): '1',
        ('from baseball_collision.entry_points import command_line as main', "['--help']"): '1',
        # the control: the same mains entered directly start numpy's BLAS with two threads
        ('from baseball_collision.ros.node import main', node): '2',
        ('from baseball_collision.tools.cli import main', "['--help']"): '2',
    }
    for (entry, args), expected in runs.items():
        found = subprocess.run([sys.executable, '-c', script.format(entry=entry, args=args)],
                               check=True, env=environment, capture_output=True,
                               text=True).stdout.split()
        assert found[-1:] == [expected], (entry, found)
