"""
``ending.end_process``: a finished ``analyze`` ends without the teardown, losing nothing.

Every run is a child process (``os._exit`` would end the test's own). A module-level object of
the child's ``__main__`` says ``torn down`` on stderr when the interpreter's teardown frees it:
its absence shows the process ended at once, its presence that it ended the ordinary way.
"""

import json
import os
from pathlib import Path
import subprocess
import sys
import threading
from typing import List

from baseball_collision.tools.ending import end_process, open_for_writing, other_threads
import pytest
from rosbags.highlevel import AnyReader
from support import SIGNAL_AFTER_BAG
from support.bundled import bag_path

SENTINEL = """
import atexit, sys
class Sentinel:
    def __del__(self):
        sys.stderr.write('torn down\\n')
sentinel = Sentinel()
atexit.register(lambda: sys.stderr.write('atexit ran\\n'))
"""

TORN_DOWN = 'torn down\n'


def child(code: str, *args: str, **kwargs: object) -> subprocess.CompletedProcess:
    """Run ``code`` after the sentinel in a fresh interpreter (block-buffered stdout)."""
    env = {k: v for k, v in os.environ.items()
           if k not in ('PYTHONUNBUFFERED', 'RMW_IMPLEMENTATION')}
    return subprocess.run([sys.executable, '-c', SENTINEL + code, *args], capture_output=True,
                          text=True, env=env, timeout=120, **kwargs)


def test_a_done_process_ends_at_once_with_its_output_handlers_and_code() -> None:
    """Block-buffered stdout reaches the pipe, atexit handlers run, the code kept; no teardown."""
    done = child('from baseball_collision.tools.ending import end_process\n'
                 "print('x' * 100_000)\n"
                 "sys.stderr.write('line\\n')\n"
                 'end_process(3)\n'
                 "print('not reached')\n")
    assert done.returncode == 3
    assert done.stdout == 'x' * 100_000 + '\n'
    assert done.stderr == 'line\natexit ran\n'


@pytest.mark.parametrize('hold', [
    # a file still open for writing: its buffered text is written by the teardown
    "held = open(sys.argv[1], 'w')\nheld.write('kept')\n",
    "held = open(sys.argv[1], 'wb')\nheld.write(b'kept')\n",
    # a thread the ordinary exit waits for
    'import threading, time\n'
    "def late():\n    time.sleep(0.3)\n    open(sys.argv[1], 'w').write('kept')\n"
    'threading.Thread(target=late).start()\n',
])
def test_a_process_with_something_to_lose_ends_the_ordinary_way(
        tmp_path: Path, hold: str) -> None:
    """An open writable file or a live thread: end_process returns; nothing is lost."""
    target = tmp_path / 'held.txt'
    done = child(hold + 'from baseball_collision.tools.ending import end_process\n'
                 'sys.exit(end_process(4))\n', str(target))
    assert done.returncode == 4
    assert target.read_text() == 'kept'
    assert done.stderr == 'atexit ran\n' + TORN_DOWN


def test_a_closed_file_is_no_reason_to_wait(tmp_path: Path) -> None:
    """A written and closed file, a file open for reading: the process ends at once."""
    target = tmp_path / 'closed.txt'
    done = child("with open(sys.argv[1], 'w') as out:\n    out.write('kept')\n"
                 'reading = open(sys.argv[1])\n'
                 'from baseball_collision.tools.ending import end_process\n'
                 'end_process(0)\n', str(target))
    assert done.returncode == 0 and done.stderr == 'atexit ran\n'
    assert target.read_text() == 'kept'


def test_standard_output_that_cannot_be_flushed_is_reported_as_before() -> None:
    """Output to a full device: the ordinary exit's report and exit code 120, as without it."""
    codes = []
    for ending in ('end_process(0)\n', ''):
        done = child("sys.stdout = open('/dev/full', 'w')\nprint('x')\n"
                     'from baseball_collision.tools.ending import end_process\n' + ending)
        codes.append(done.returncode)
        assert 'No space left on device' in done.stderr and TORN_DOWN in done.stderr
    assert codes == [120, 120]


def test_in_this_process_nothing_is_to_be_waited_for(tmp_path: Path) -> None:
    """The checks themselves: a live thread and an open file are seen, then not once done."""
    # (another test in this worker may have left threads, e.g. the batch solver's pool)
    release = threading.Event()
    waiting = threading.Thread(target=release.wait)
    daemon = threading.Thread(target=release.wait, daemon=True)
    waiting.start()
    daemon.start()
    try:
        assert waiting in other_threads() and daemon not in other_threads()
    finally:
        release.set()
        waiting.join()
        daemon.join()
    assert waiting not in other_threads()
    with open(tmp_path / 'f', 'w') as out:
        assert any(found is out for found in open_for_writing())
    assert not any(found is out for found in open_for_writing())
    assert end_process('no code') == 'no code'  # (not an exit code: returned, nothing done)


ANALYZE = ('from baseball_collision.entry_points import command_line\n'
           'sys.exit(command_line(sys.argv[1:]))\n')


def analyze(*args: str) -> subprocess.CompletedProcess:
    """Run ``baseball-collision analyze ARGS`` as the console script does, with the sentinel."""
    return child(ANALYZE, 'analyze', *args, '--no-progress')


@pytest.mark.parametrize('jobs', ['1', '2'])
def test_analyze_ends_at_once_with_every_output(tmp_path: Path, run_cli, jobs: str) -> None:
    """--jobs 1 or 2, --json, --csv, --plot: the files and table of in-process, no teardown."""
    bags = [str(bag_path('pitches_90hz.mcap')), str(bag_path('pitches_240hz_noisy.bag'))]
    outputs: List[dict] = []
    for where in ('child', 'in-process'):
        folder = tmp_path / where
        folder.mkdir()
        argv = [*bags, '--jobs', jobs, '--json', str(folder / 'e.json'), '--csv',
                str(folder / 'e.csv'), '--plot', str(folder / 'plots')]
        if where == 'child':
            done = analyze(*argv)
            code, stdout, stderr = done.returncode, done.stdout, done.stderr
            assert stderr == 'atexit ran\n', stderr  # (no 'torn down': ended at once)
        else:
            code, stdout, stderr = run_cli(['analyze', *argv, '--no-progress'])
        assert code == 0, stderr
        document = json.loads((folder / 'e.json').read_text())
        outputs.append({'events': [(bag['impacts'], bag['near_misses'], bag['dropped'])
                                   for bag in document['bags']],
                        'csv': (folder / 'e.csv').read_text(),
                        'plots': sorted((p.name, p.read_bytes())
                                        for p in (folder / 'plots').iterdir()),
                        'table': [line for line in stdout.splitlines()
                                  if not line.startswith(('summary', 'total'))]})
        assert outputs[-1]['plots'], 'no figure drawn'
    assert outputs[0] == outputs[1]


def test_analyze_ends_at_once_with_its_output_bag_whole(tmp_path: Path, run_cli) -> None:
    """--out-bag: the MCAP is finished, with the messages of an in-process run's."""
    bag = str(bag_path('pitches_90hz.mcap'))
    done = analyze(bag, '--out-bag', str(tmp_path / 'child.mcap'), '--quiet')
    assert done.returncode == 0 and done.stderr == 'atexit ran\n', done.stderr
    code, _, stderr = run_cli(['analyze', bag, '--out-bag', str(tmp_path / 'here.mcap'),
                               '--quiet', '--no-progress'])
    assert code == 0, stderr
    written = []
    for name in ('child.mcap', 'here.mcap'):
        with AnyReader([tmp_path / name]) as reader:  # (a cut MCAP would not open)
            written.append([(connection.topic, stamp, bytes(data))
                            for connection, stamp, data in reader.messages()
                            if connection.topic != '/diagnostics'])  # (wall-clock timings)
    assert len(written[0]) > 1000 and written[0] == written[1]


def test_analyze_ends_at_once_after_an_error_too(tmp_path: Path) -> None:
    """A missing bag: its one line, exit code 2, nothing written, no teardown."""
    done = analyze(str(tmp_path / 'missing.mcap'), '--json', str(tmp_path / 'e.json'))
    assert done.returncode == 2 and done.stdout == ''
    assert done.stderr.startswith('baseball-collision: error: bag not found')
    assert done.stderr.endswith('\natexit ran\n') and done.stderr.count('\n') == 2
    assert list(tmp_path.iterdir()) == []


def test_analyze_into_a_closed_pipe_ends_as_it_always_did() -> None:
    """The table into a pipe no one reads: the ordinary exit's report, exit code 120."""
    read, write = os.pipe()
    env = {k: v for k, v in os.environ.items()
           if k not in ('PYTHONUNBUFFERED', 'RMW_IMPLEMENTATION')}
    child_process = subprocess.Popen(
        [sys.executable, '-c', SENTINEL + ANALYZE, 'analyze', str(bag_path('pitches_90hz.mcap')),
         '--no-progress'], stdout=write, stderr=subprocess.PIPE, text=True, env=env)
    os.close(write)
    os.close(read)
    _, stderr = child_process.communicate(timeout=120)
    assert child_process.returncode == 120
    assert 'BrokenPipeError' in stderr and stderr.endswith(TORN_DOWN)


def test_only_analyze_ends_at_once() -> None:
    """Other commands and options (``--version`` here) end the ordinary way."""
    done = child(ANALYZE, '--version')
    assert done.returncode == 0 and done.stderr == 'atexit ran\n' + TORN_DOWN


@pytest.mark.parametrize('name, code, said', [('SIGINT', 130, 'interrupted'),
                                              ('SIGTERM', 143, 'terminated by SIGTERM')])
def test_analyze_interrupted_ends_at_once_leaving_no_output(
        tmp_path: Path, name: str, code: int, said: str) -> None:
    """Ctrl-C or SIGTERM mid-run: the staged outputs deleted, its exit code, no teardown."""
    done = child(SIGNAL_AFTER_BAG.format(name=name) + ANALYZE, 'analyze',
                 str(bag_path('pitches_90hz.mcap')), '--out-bag', str(tmp_path / 'o.mcap'),
                 '--json', str(tmp_path / 'o.json'), '--quiet')
    assert done.returncode == code, done.stderr
    assert said in done.stderr and TORN_DOWN not in done.stderr
    assert list(tmp_path.iterdir()) == []


def test_the_frozen_imports_leave_no_file_open_for_writing() -> None:
    """What the console script freezes (its imports) holds no file open for writing."""
    code = ('import gc\n'
            'from baseball_collision.entry_points import frozen_imports\n'
            'with frozen_imports():\n'
            '    import baseball_collision.tools.cli, baseball_collision.tools.analyze\n'
            '    import baseball_collision.tools.report, baseball_collision.tools.many_bags\n'
            'frozen = gc.get_freeze_count()\n'
            'gc.unfreeze()\n'
            'from baseball_collision.tools.ending import open_for_writing\n'
            'print(frozen > 10_000, open_for_writing())\n')
    done = child(code)
    assert done.returncode == 0, done.stderr
    assert done.stdout == 'True []\n'
