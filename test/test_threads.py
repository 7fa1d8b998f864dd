"""Tests for baseball_collision.threads: BLAS on one thread, and reading ahead on another."""

import os
import subprocess
import sys
import threading
import time
from typing import Any, Dict, Iterator, List

from baseball_collision.entry_points import BLAS_THREAD_VARIABLES
from baseball_collision.threads import ReadAhead
import pytest

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


@pytest.mark.skipif(not os.path.isdir('/proc/self/task'), reason='counts threads in /proc')
def test_a_forked_child_of_a_limited_process_starts_no_blas_thread() -> None:
    """
    Limited again in a child forked from a limited process: still one thread, none started.

    OpenBLAS loaded with two threads has a helper thread; a fork copies only the calling
    thread, and setting the limit again in the child made OpenBLAS start its pool anew (a
    second thread in the child, which spins beside the work).
    """
    script = ('import os, numpy\n'
              'from baseball_collision.threads import blas_threads, single_threaded_blas\n'
              'loaded = blas_threads()\n'
              'single_threaded_blas()\n'
              'numpy.linalg.eigh(numpy.eye(32))\n'
              'read, write = os.pipe()\n'
              'pid = os.fork()\n'
              'if pid == 0:\n'
              '    single_threaded_blas()\n'
              '    numpy.linalg.eigh(numpy.eye(32))\n'
              '    tasks = len(os.listdir("/proc/self/task"))\n'
              '    os.write(write, f"{blas_threads()} {tasks}".encode())\n'
              '    os._exit(0)\n'
              'os.waitpid(pid, 0)\n'
              'print(loaded, os.read(read, 100).decode())\n')
    found = subprocess.run([sys.executable, '-c', script], check=True, env=TWO_THREADS,
                           capture_output=True, text=True).stdout.split()
    assert found == ['2', '1', '1']  # (loaded with two; the child: one BLAS thread, one thread)


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


def _counted(count: int, taken: List[int], seen: Dict[str, Any]) -> Iterator[int]:
    """Yield 0 .. count - 1, noting each in ``taken`` and the thread and the end in ``seen``."""
    try:
        for item in range(count):
            seen['thread'] = threading.current_thread().name
            taken.append(item)
            yield item
    finally:
        seen['finally'] = threading.current_thread().name


@pytest.mark.parametrize('depth', [1, 2, 5])
def test_read_ahead_gives_every_item_in_order_taken_on_its_thread(depth: int) -> None:
    """The items come in order, taken on the ``read-ahead`` thread, which then ends."""
    taken: List[int] = []
    seen: Dict[str, Any] = {}
    assert list(ReadAhead(_counted(50, taken, seen), depth)) == list(range(50))
    assert seen == {'thread': 'read-ahead', 'finally': 'read-ahead'}
    assert not [t for t in threading.enumerate() if t.name == 'read-ahead']
    assert list(ReadAhead([], depth)) == []
    with pytest.raises(ValueError, match='at least 1'):
        ReadAhead([1], depth - depth)


def test_read_ahead_takes_at_most_its_depth_ahead() -> None:
    """With the reader waiting, the thread has taken the items given, ``depth`` and one more."""
    for depth in (1, 3):
        taken: List[int] = []
        ahead = ReadAhead(_counted(100, taken, {}), depth)
        assert next(ahead) == 0
        deadline = time.monotonic() + 5.0
        while len(taken) < depth + 2 and time.monotonic() < deadline:
            time.sleep(0.001)  # (until it is blocked: the queue full, one item in hand)
        time.sleep(0.05)
        assert len(taken) == depth + 2, (depth, taken)
        ahead.close()


def test_what_taking_an_item_raises_comes_in_its_place() -> None:
    """An error comes after the items before it, the same exception object; then the end."""
    error = KeyError('the fourth')

    def failing() -> Iterator[int]:
        yield from (1, 2, 3)
        raise error
    ahead = ReadAhead(failing(), 2)
    assert [next(ahead) for _ in range(3)] == [1, 2, 3]
    with pytest.raises(KeyError) as caught:
        next(ahead)
    assert caught.value is error
    assert list(ahead) == []


def test_closing_stops_the_thread_and_runs_the_generators_finally_on_it() -> None:
    """``close`` (or a ``with`` block's end) mid-way: the generator closed, the thread gone."""
    taken: List[int] = []
    seen: Dict[str, Any] = {}
    with ReadAhead(_counted(10_000, taken, seen), 2) as ahead:
        assert [next(ahead) for _ in range(3)] == [0, 1, 2]
    assert seen['finally'] == 'read-ahead' and len(taken) < 10
    assert not [t for t in threading.enumerate() if t.name == 'read-ahead']
    with pytest.raises(ValueError, match='closed while reading ahead'):
        next(ahead)
    ahead.close()  # (again: nothing)
    ended = ReadAhead(iter([1]), 1)
    assert list(ended) == [1]
    ended.close()  # (closed after its end: still just ended)
    assert list(ended) == []
