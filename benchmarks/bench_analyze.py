"""
``analyze`` throughput on a large simulated bag, beside rosbags' raw read rate on the same file.

Run: ``.venv/bin/python benchmarks/bench_analyze.py [--messages N] [--storage S] [--model M]
[--profile]``, or ``--whole`` for whole processes, or ``--jobs K`` for the process pool alone.

Writes (into a temporary directory) a bag of at least ``N`` messages (default 1,000,000) with
``baseball-collision simulate``'s writer: 360 Hz on a millisecond grid, the ball and the bat
pose only (every message is one the detector reads), pitches of all kinds 0.5 s apart (24
distinct draws repeated): the worst case. ``--pitch-every SECONDS`` (more than 0.5) writes a
session instead: the same pitches that many seconds apart, ball and bat tracked between them
(:func:`write_session_bag`; batting practice throws one every 8-15 s). Then, in the same
process, times:

(a) rosbags ``AnyReader.messages()`` alone (raw bytes, no decode): the floor;
(b) ``BagReader.samples()``: raw read + decode into samples;
(c) the analyze loop (:func:`analyze.run_detector_chunks`: the analysis as the only sink, the
    bag a chunk at a time) over (b) with a no-op detector: analyze's own ceiling;
(d) ``analyze_bag`` end to end (open, select, decode, ``Detector.add_chunk`` per chunk,
    ``finish``);
(e) the detector one sample at a time (``Detector.add``, as analyze ran before chunks): the
    baseline in the same run, which must find the same events;

and splits (d) into read + decode (b), the analyze loop ((c) - (b)), the detector's own timer
(``stats.total_processing_s``: wall time inside ``Detector.add``'s handler and the chunks'
fast-forwards) and the rest (planning the chunks, the dispatch and bookkeeping outside that
timer, the progress bar). ``--profile``
adds a cProfile of (d) (top functions by own time). Prints figures; asserts nothing. The goal
is >= 100,000 messages/s end to end.

``--whole``: instead, the goal of issue 13 as a user meets it: the whole ``baseball-collision
analyze BAG --quiet`` process (interpreter start-up, imports, the kernel's load included) against
a whole process that only iterates rosbags' raw messages of the same bag (the two in turn,
``--repeats`` pairs: each pair's ratio is printed too), and against (a) in this process, best
of ``--repeats`` each, wall time and the processes' CPU time (steadier on a shared machine)
(goal: analyze >= 0.5 of the raw read rate). With ``--before DIR`` (a source tree of another
commit with its kernel built, e.g. a ``git worktree`` and ``setup.py build_ext
--inplace``), ``python -m baseball_collision.tools.cli analyze`` also runs from DIR and from this
tree in turn, on the bag and on a bag of 300 messages (the start-up: interpreter, imports, opening
a bag), best wall and best CPU time (the child's user + system) of each. With ``--split``,
each process again with a CPU timer per stage (``time.process_time``: the raw read's imports,
typestore, open and ``messages()``; analyze's imports (the console script's and the reader's,
then the modules the ``analyze`` command imports when it runs), open, the reader's rows and batch
arrays, decode, and the detector with its chunk planning; the bag read in turn, without
``analyze``'s reading thread: each stage's CPU, not the wall time that thread overlaps), best of
``--repeats`` per stage; with ``--before DIR`` too, analyze's stages from both trees in turn,
and per tree the start-up S (interpreter and imports), a bag's work B and the bound they set
on issue 13's ``--jobs 2`` over two such bags, ``(S + 2B) / (S + B)``.

``--against M --pairs P``: instead, ``--model`` against model ``M`` in this one process on one
bag: P pairs of (d) back to back (``M`` first), CPU time and wall time of each, the ratio of
each pair's throughputs and the best-of ratio (issue 11's goal for a new default model: it
keeps >= 0.8 of the old one's throughput); both models' events are listed. With ``--split``:
where each model's CPU time goes instead, per part of the detector (process-time timers
around the sweep's far test, paths, sub-steps, impact velocities, uncertainty, the noise
estimate, the chunks' fast-forwards and plans, ...), best of ``--repeats``.

``--look-ahead`` and ``--tracker-noise`` set ``c2``'s parameters in every mode (``--profile``
and (d), (e) included); ``--bag-noise M`` writes the worst case with M m of tracking noise
per coordinate (``simulate --noise``; a session too, between its pitches as well), where
``tracker_noise`` > 0 or auto smooths;
``--steady-clock`` stamps it as a tracker stamping its own frames does (no jitter, no grid).

``--interleave``: instead, (a), (d) and (e) in turn, ``--repeats`` times on one bag (default
30,000 messages), each figure the best CPU time (``time.process_time``) and the best wall
time: on a machine shared with other work, CPU time moves less than wall time.

``--jobs K``: writes K bags of ``N`` messages (default 250,000 each) and times
:func:`many_bags.analyze_bags` over them with one job, with K jobs (a process pool) and with one
job that does not read ahead, in turn in the same process, ``--repeats`` rounds; prints each
one's median and best wall time, CPU time, and the cores the host's other processes used
meanwhile (``/proc/stat``: on a shared machine a run beside a busy process has one core),
the speed-up of the medians and of the bests (goal for two bags on two cores: >= 1.7x) and
checks the runs found the same events. With ``--whole`` too: whole ``baseball-collision
analyze BAG ... --jobs 1`` and ``--jobs K`` processes in turn instead (as a user runs them:
start-up and the pool's start included), beside the ceiling the host allows: K ``analyze
BAG`` processes started at once (as a shell starts them: no pool, each its own start-up), and
one alone; with ``--before DIR`` too, every case also from the source tree DIR, in turn, and
a bundled 90 Hz bag's whole ``analyze`` (start-up and teardown) from each tree, then the two
trees' medians side by side (``--no-bytecode-cache``: the children compile the package at every
start, as with ``PYTHONDONTWRITEBYTECODE`` set; by default they keep a bytecode cache, as a
user's second run does). ``--wait-quiet S`` waits up to S seconds before each run for a quiet
host. The
in-process pool forks from this process, whose numpy started OpenBLAS's threads; the command
line starts numpy with one (``entry_points``): run ``OPENBLAS_NUM_THREADS=1 ... --jobs K`` to
measure the pool as the command line runs it.
"""

import argparse
import cProfile
from functools import partial
import math
import os
from pathlib import Path
import pstats
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from typing import Dict, List, Optional, Tuple

from baseball_collision.bags import BagReader, BagWriter, POINT_STAMPED, POSE_STAMPED
from baseball_collision.core.detector import Detector, DetectorConfig
from baseball_collision.threads import single_threaded_blas
from baseball_collision.tools.analyze import (
    AnalysisOptions, analyze_bag, BagAnalysis, CHUNK, run_detector, run_detector_chunks)
from baseball_collision.tools.many_bags import analyze_bags
from baseball_collision.tools.parameters import build_config
from baseball_collision.tools.recording import RecordingSpec, write_recording
from baseball_collision.tools.sim import DEFAULT_START_NS, KINDS, make_scenario, sample
from bench_bag_read import raw_read
import numpy as np

GOAL = 100_000
WORST_SPACING_S = 0.5
"""Seconds between pitches in the worst case (nothing between them)."""
PITCH_GAP_S = 0.1
"""A session's pause in tracking after each pitch (s; the worst case's gap between pitches)."""
SUFFIXES = {'mcap': 'bench.mcap', 'sqlite3': 'bench.db3', 'rosbag1': 'bench.bag'}
MESSAGES_PER_PITCH = 290  # 0.4 s at 360 Hz, ball + bat pose


def write_bag(path: Path, messages: int, pitch_every: float = WORST_SPACING_S,
              noise: float = 0.0, steady: bool = False) -> Tuple[int, float]:
    """
    Write the benchmark bag; return (messages written, seconds).

    :param pitch_every: seconds from one pitch to the next: ``WORST_SPACING_S`` (the worst
        case: ``simulate``'s recording, nothing between pitches), or more (a session:
        :func:`write_session_bag`).
    :param noise: the tracking noise (m per coordinate, ``simulate --noise``; 0: exact
        samples), of the worst case or of a session.
    :param steady: the worst case's stamps on a steady clock (a tracker stamping its frames:
        no jitter, no millisecond grid) instead of 0.2 ms of jitter on a millisecond grid.
    :raises ValueError: a steady clock asked of a session.
    """
    start = time.perf_counter()
    if pitch_every > WORST_SPACING_S:
        if steady:
            raise ValueError('--steady-clock writes the worst case only (--pitch-every 0.5)')
        written = write_session_bag(path, messages, pitch_every, noise)
        return written, time.perf_counter() - start
    spec = RecordingSpec(count=messages // MESSAGES_PER_PITCH + 1, rate_hz=360.0,
                         grid_s=None if steady else 0.001, jitter_s=0.0 if steady else 0.0002,
                         bat='pose', spacing_s=WORST_SPACING_S, unique=24, seed=1,
                         noise_m=noise)
    document = write_recording(path, spec)
    return document['messages'], time.perf_counter() - start


def density(pitch_every: float) -> str:
    """Return what a bag of pitches ``pitch_every`` s apart stands for, honestly labelled."""
    if pitch_every > WORST_SPACING_S:
        return (f'a session: a pitch every {pitch_every:g} s, ball and bat tracked in between '
                '(batting practice)')
    return ('the worst case: a pitch every 0.5 s, nothing tracked between pitches (every '
            'message within 0.25 s of one)')


def write_session_bag(path: Path, messages: int, pitch_every: float,
                      noise: float = 0.0) -> int:
    """
    Write a batting-practice session of at least ``messages`` messages; return how many.

    The worst case's pitches (the same 24 draws, 0.4 s each, ball + bat pose at 360 Hz on a
    millisecond grid), one every ``pitch_every`` s, with tracking continuous between them: a
    ``PITCH_GAP_S`` pause after each pitch (the ball leaves the volume, as in the worst case),
    then ball and bat at 360 Hz until the next pitch, the ball waiting at its release point
    and the bat held where the swing starts, swaying 3 mm at 0.5 Hz. With ``noise`` (m), every
    position, in the pitches and between them, has Gaussian noise of that much per
    coordinate (as ``simulate --noise``: one draw per pose, the orientation exact).
    """
    rng = np.random.default_rng(1)
    pool = [make_scenario(KINDS[i % len(KINDS)], rng, lead_s=0.25, trail_s=0.15)
            for i in range(24)]
    step_ns = 1_000_000_000 / 360.0
    written, index, idle_from = 0, 0, None
    with BagWriter(path) as writer:
        for topic, msgtype in (('/ball', POINT_STAMPED), ('/bat_pose', POSE_STAMPED)):
            writer.add_topic(topic, msgtype)
        while written < messages:
            start = DEFAULT_START_NS + int(round(index * pitch_every * 1e9))
            pitch = sample(pool[index % len(pool)], 360.0, rng, jitter_s=0.0002, grid_s=0.001,
                           noise_m=noise, start_ns=start).messages('pose')
            ball = next(values for _, role, values in pitch if role == 'ball')
            bat = next(values for _, role, values in pitch if role == 'bat_pose')
            k = 0
            while idle_from is not None:
                stamp = idle_from + int(round(k * step_ns / 1e6)) * 1_000_000
                if stamp >= pitch[0][0]:
                    break
                sway = 0.003 * math.sin(math.pi * (stamp - start) * 1e-9)
                shake = rng.normal(0.0, noise, 6) if noise else np.zeros(6)
                writer.write_point('/ball', stamp, 'world', np.asarray(ball) + shake[:3])
                writer.write_pose('/bat_pose', stamp, 'world',
                                  (bat[0] + sway + shake[3], bat[1] + shake[4],
                                   bat[2] + sway + shake[5]), bat[3:])
                written, k = written + 2, k + 1
            for stamp, role, values in pitch:
                if role == 'ball':
                    writer.write_point('/ball', stamp, 'world', values)
                else:
                    writer.write_pose('/bat_pose', stamp, 'world', values[:3], values[3:])
                written += 1
            idle_from = pitch[-1][0] + int(round(PITCH_GAP_S * 1e9))
            index += 1
    return written


def decode(path: Path) -> int:
    """Read every sample with BagReader; return how many."""
    count = 0
    with BagReader(path) as bag:
        for _ in bag.samples():
            count += 1
    return count


class NullDetector:
    """A detector that does nothing, to time the analyze loop alone."""

    config = DetectorConfig()

    def add(self, role: str, stamp_ns: int, values: Tuple[float, ...], frame_id: str) -> list:
        """Return no events."""
        return []

    def add_chunk(self, roles, stamps_ns, values, frame_ids, drops=None) -> list:
        """Return no events."""
        return []

    def finish(self) -> list:
        """Return no events."""
        return []


def null_loop(path: Path) -> int:
    """Run the analyze loop (a chunk at a time) with a no-op detector; return the messages fed."""
    with BagReader(path) as bag:
        result = BagAnalysis(path=path, selection=bag.selection, config=DetectorConfig())
        result.messages, result.first_stamp_ns = run_detector_chunks(
            bag.chunks(CHUNK), NullDetector(), [result])
    return result.messages


def per_sample(path: Path, model: str, parameters: Optional[dict] = None) -> BagAnalysis:
    """
    Run the detector one sample at a time (``Detector.add``, analyze before chunks).

    :param parameters: node parameters (``model_parameters``), as ``AnalysisOptions`` takes.
    """
    options = AnalysisOptions(model=named_model(model))
    with options.reader(path) as bag:
        config = build_config(parameters or {}, bat_input=bag.selection.bat_mode,
                              model=named_model(model))
        result = BagAnalysis(path=path, selection=bag.selection, config=config)
        detector = Detector(config)
        result.messages, result.first_stamp_ns = run_detector(
            bag.samples(), detector, [result], None, result.drops_by_role)
    result.stats = detector.stats
    return result


def named_model(model: str) -> Optional[str]:
    """Return ``--model``'s name for ``analyze``: None for 'default' (its offline default)."""
    return None if model == 'default' else model


def model_parameters(model: str, look_ahead: int, tracker_noise: float) -> dict:
    """Return the node parameters ``--look-ahead`` and ``--tracker-noise`` set (``c2`` only)."""
    return {'look_ahead': look_ahead, 'tracker_noise': tracker_noise} if model == 'c2' else {}


def timed(run, *args) -> Tuple[object, float]:
    """Return (result, seconds) of one call."""
    start = time.perf_counter()
    result = run(*args)
    return result, time.perf_counter() - start


RAW_READ_PROCESS = """
from pathlib import Path
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
with AnyReader([Path({bag!r})], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
    print(sum(1 for _ in reader.messages()))
"""
"""The raw-read peer as a process: rosbags alone (the same loop as bench_bag_read.raw_read)."""


SPLIT_START = """
import resource, time
clock = time.process_time
marks = [('interpreter start-up', clock())]


def mark(label):
    marks.append((label, clock()))


def report():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    total = usage.ru_utime + usage.ru_stime
    named = dict((label, b - a) for (_, a), (label, b) in zip([('', 0.0)] + marks, marks))
    named.update(extra)
    named['process (user + system)'] = total
    print(repr(named))


extra = {{}}
COMMAND_IMPORTS = {command_imports!r}
"""

RAW_SPLIT = SPLIT_START + """
from pathlib import Path
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
mark('imports')
store = get_typestore(Stores.ROS2_JAZZY)
mark('the Jazzy typestore')
reader = AnyReader([Path({bag!r})], default_typestore=store)
reader.open()
mark('open (rosbags)')
count = sum(1 for _ in reader.messages())
mark('read: messages()')
reader.close()
report()
"""
"""The raw-read process with a CPU timer per stage (the same work as RAW_READ_PROCESS)."""

ANALYZE_SPLIT = SPLIT_START + """
from pathlib import Path
from baseball_collision.entry_points import one_blas_thread_from_start
one_blas_thread_from_start()  # as the console script does, before numpy loads
from baseball_collision.tools import cli  # (the console script's imports)
from baseball_collision.bags import BagReader
from baseball_collision.bags.decode import decode_spans
from baseball_collision.core.detector import chunks, Detector
from baseball_collision.tools.parameters import build_config
mark('imports')
import baseball_collision.tools.analyze, baseball_collision.tools.many_bags  # (the command's)
import baseball_collision.tools.report
mark(COMMAND_IMPORTS)
planned = chunks.plan_chunk


def plan(*arguments):
    start = clock()
    try:
        return planned(*arguments)
    finally:
        extra['  of it: planning chunks'] = extra.get('  of it: planning chunks', 0.0) + (
            clock() - start)


chunks.plan_chunk = plan
bag = BagReader(Path({bag!r}))
bag.open()
reader = bag._open_reader()
detector = Detector(build_config({{}}, bat_input=bag.selection.bat_mode, model={model!r}))
mark('open (rosbags) and set-up')
spans = bag._spans(reader, 8192)
took = dict.fromkeys(('read: rows and batch arrays', 'decode', 'detector'), 0.0)
while True:
    start = clock()
    each = next(spans, None)
    took['read: rows and batch arrays'] += clock() - start
    if each is None:
        break
    for first in range(0, len(each.codes), 8192):
        start = clock()
        chunk = decode_spans(each.piece(first, first + 8192), bag._routes, None)
        middle = clock()
        detector.add_chunk(chunk.roles, chunk.stamps_ns, chunk.values, chunk.frame_ids, None)
        took['decode'] += middle - start
        took['detector'] += clock() - middle
start = clock()
detector.finish()
took['detector'] += clock() - start
bag.close()
marks.extend((label, marks[-1][1] + seconds) for label, seconds in took.items())
report()
"""
"""analyze's work on a sqlite3 or indexed MCAP bag with a CPU timer per stage (its chunks read
as ``BagReader.chunks`` reads them, by the reader's spans)."""


COMMAND_IMPORTS = "imports: the analyze command's modules"
"""The split's stage of the modules ``cli`` imports for ``analyze`` when it runs (lazily)."""

START_UP_STAGES = ('interpreter start-up', 'imports', COMMAND_IMPORTS)
"""The split's stages every process pays once whatever its bags: the serial start-up S."""

BAG_STAGES = ('open (rosbags) and set-up', 'read: rows and batch arrays', 'decode', 'detector')
"""The split's stages of one bag's work: B."""


def stage_figures(path: Path, model: str, repeats: int, before: Optional[Path] = None) -> None:
    """
    Print where the raw-read process's and analyze's CPU time goes, best of each stage.

    With ``before`` (a source tree), analyze's stages also from that tree, the trees in turn,
    and per tree the start-up S (:data:`START_UP_STAGES`), a bag's work B
    (:data:`BAG_STAGES`) and the bound they set on ``--jobs 2`` over two such bags, as
    processes on two free cores: ``(S + 2 B) / (S + B)``.
    """
    model_argument = named_model(model)  # build_config's offline default
    here = Path(__file__).resolve().parents[1]
    runs = [('rosbags raw read', RAW_SPLIT, here)]
    trees = {'analyze': here} if before is None else {
        f'analyze, before ({before})': before, 'analyze, now': here}
    runs += [(name, ANALYZE_SPLIT, tree) for name, tree in trees.items()]
    best: Dict[str, dict] = {name: {} for name, _, _ in runs}
    environment = {k: v for k, v in os.environ.items()
                   if k not in ('PYTHONDONTWRITEBYTECODE', 'PYTHONPATH')}
    for _ in range(repeats):
        for name, script, tree in runs:  # (in turn: a load that comes and goes meets each)
            code = script.format(bag=str(path), model=model_argument,
                                 command_imports=COMMAND_IMPORTS)
            output = subprocess.run([sys.executable, '-c', code], check=True, cwd=tree,
                                    capture_output=True, text=True, env=environment).stdout
            for label, seconds in eval(output.strip().splitlines()[-1]).items():  # noqa: S307
                best[name][label] = min(best[name].get(label, math.inf), seconds)
    for name, _, _ in runs:
        print(f'{name}, CPU s by stage (best of {repeats} each):')
        for label, seconds in best[name].items():
            print(f'  {label:42s} {seconds:6.3f}')
    for name in trees:
        start_up = sum(best[name][label] for label in START_UP_STAGES)
        bag = sum(best[name][label] for label in BAG_STAGES)
        bound = (start_up + 2 * bag) / (start_up + bag)
        print(f'{name}: start-up S {start_up:.3f} s, a bag B {bag:.3f} s; bound on --jobs 2 '
              f'over two such bags (S + 2B) / (S + B) = {bound:.3f}')


def process_times(command: list, cwd: Optional[Path] = None) -> Tuple[float, float]:
    """
    Return (wall s, CPU s: user + system) of one run of a command (which must succeed).

    The child may write its bytecode cache (``PYTHONDONTWRITEBYTECODE`` is dropped from its
    environment) as an installed package has one: rosbags' modules come compiled from pip, and
    without the cache the package's 300 modules would be compiled again at every start-up
    (0.3 s of CPU, measured), which no user's second run pays. Best-of figures are cached runs.
    """
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    environment = {k: v for k, v in os.environ.items() if k != 'PYTHONDONTWRITEBYTECODE'}
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, cwd=cwd, env=environment)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def before_after_processes(path: Path, written: int, model: str, repeats: int,
                           before: Path) -> None:
    """Print analyze from the tree ``before`` and from this one, in turn, on two bags."""
    tiny = path.with_name('tiny_' + path.name)
    small, _ = write_bag(tiny, 300)
    trees = {f'before ({before})': before, 'now': Path(__file__).resolve().parents[1]}
    best = {}
    for _ in range(repeats):
        for name, tree in trees.items():
            for bag in (tiny, path):
                command = [sys.executable, '-m', 'baseball_collision.tools.cli', 'analyze',
                           str(bag), *model_flag(model), '--quiet', '--no-progress']
                times = process_times(command, cwd=tree)
                old = best.get((name, bag), (float('inf'),) * 2)
                best[name, bag] = tuple(min(a, b) for a, b in zip(old, times))
    print(f'python -m baseball_collision.tools.cli analyze, in turn, best of {repeats}:')
    for name in trees:
        (tiny_wall, tiny_cpu), (wall, cpu) = best[name, tiny], best[name, path]
        print(f'  {name:40s} {small} messages: {tiny_wall:5.2f} s wall, {tiny_cpu:5.2f} s CPU; '
              f'{written:,}: {wall:6.2f} s wall, {cpu:6.2f} s CPU ({written / wall:,.0f} msg/s)')


def model_flag(model: str) -> List[str]:
    """Return ``analyze``'s model flag: none for 'default' (the offline default)."""
    return [] if model == 'default' else ['--model', model]


def whole_process_figures(messages: int, storage: str, model: str, repeats: int,
                          pitch_every: float = WORST_SPACING_S,
                          before: Optional[Path] = None, split: bool = False,
                          bag_noise: float = 0.0) -> None:
    """Print analyze as a whole process against a raw-read process on one bag, the ratios."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / SUFFIXES[storage]
        written, _ = write_bag(path, messages, pitch_every, bag_noise)
        raw_in = min(timed(raw_read, path)[1] for _ in range(repeats))
        # the two processes in turn, so a load that comes and goes meets both alike
        cli = str(Path(sys.executable).with_name('baseball-collision'))
        runs = [(process_times([sys.executable, '-c', RAW_READ_PROCESS.format(bag=str(path))]),
                 process_times([cli, 'analyze', str(path), *model_flag(model), '--quiet',
                                '--no-progress'])) for _ in range(repeats)]
        raw_process, raw_cpu = (min(raw[k] for raw, _ in runs) for k in (0, 1))
        analyze_process, analyze_cpu = (min(mine[k] for _, mine in runs) for k in (0, 1))
        print(f'{written:,} messages ({storage}), best of {repeats} each, in turn')
        for label, seconds in (('rosbags raw read, in this process (a)', raw_in),
                               ('rosbags raw read, whole process', raw_process),
                               ('rosbags raw read, whole process, CPU time', raw_cpu),
                               (f'baseball-collision analyze --model {model}, whole process',
                                analyze_process),
                               ('baseball-collision analyze, whole process, CPU time',
                                analyze_cpu)):
            print(f'{label:58s} {seconds:7.2f} s {written / seconds:>10,.0f} msg/s')
        for label, seconds, mine in (('(a)', raw_in, analyze_process),
                                     ('the raw-read process', raw_process, analyze_process),
                                     ('the raw-read process, CPU', raw_cpu, analyze_cpu)):
            ratio = seconds / mine
            print(f'analyze process / {label:26s} = {ratio:.2f} of its rate '
                  f"[goal >= 0.5: {'met' if ratio >= 0.5 else 'NOT met'}]")
        for k, what in ((0, 'wall'), (1, 'CPU')):
            pairs = sorted(raw[k] / mine[k] for raw, mine in runs)
            print(f'  each pair in turn, by {what}: ' + ', '.join(f'{r:.2f}' for r in pairs)
                  + f' (median {pairs[len(pairs) // 2]:.2f})')
        if before is not None:
            before_after_processes(path, written, model, repeats, before)
        if split:
            stage_figures(path, model, repeats, before)


def against_figures(messages: int, storage: str, model: str, baseline: str, pairs: int,
                    look_ahead: int, pitch_every: float = WORST_SPACING_S,
                    tracker_noise: float = 0.0, bag_noise: float = 0.0,
                    steady: bool = False) -> None:
    """Print (d) for ``baseline`` and ``model`` in pairs on one bag, the throughput ratios."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / SUFFIXES[storage]
        written, _ = write_bag(path, messages, pitch_every, bag_noise, steady)
        print(f'{written:,} messages ({storage}); {pairs} pairs, {baseline} first; '
              f'{model} with look_ahead {look_ahead}, tracker_noise {tracker_noise:g}')
        best = {baseline: (0.0, 0.0), model: (0.0, 0.0)}
        ratios = []
        for pair in range(pairs):
            rates = {}
            for name in (baseline, model):
                options = AnalysisOptions(model=named_model(name), parameters=model_parameters(
                    name, look_ahead, tracker_noise))
                cpu = cpu_seconds()
                result, wall = timed(analyze_bag, path, options)
                cpu = cpu_seconds() - cpu
                rates[name] = (result.messages / wall, result.messages / cpu)
                best[name] = tuple(max(a, b) for a, b in zip(best[name], rates[name]))
                print(f'  pair {pair + 1} {name:6s}: {rates[name][0]:>8,.0f} msg/s wall, '
                      f'{rates[name][1]:>8,.0f} msg/s CPU; detector '
                      f'{result.stats.total_processing_s / result.messages * 1e6:6.2f} us/msg; '
                      f'{len(result.impacts)} impacts, {len(result.near_misses)} near misses')
            ratios.append(tuple(m / b for m, b in zip(rates[model], rates[baseline])))
            print(f'  pair {pair + 1} {model} / {baseline}: {ratios[-1][0]:.2f} wall, '
                  f'{ratios[-1][1]:.2f} CPU')
        wall, cpu = (best[model][i] / best[baseline][i] for i in (0, 1))
        verdict = 'met' if cpu >= 0.8 else 'NOT met'
        print(f'best of {pairs}: {model} / {baseline} = {wall:.2f} wall, {cpu:.2f} CPU '
              f'[goal >= 0.8: {verdict}]; pairs (CPU) '
              + ', '.join(f'{r[1]:.2f}' for r in ratios))


SPLIT_PARTS = (
    ('detector.sweep', 'clearly_apart', 'far test (scalar, the sweep)'),
    ('detector.sweep.Sweep', 'paths', 'paths (window fits, path objects)'),
    ('detector.sweep.Sweep', '_gap_at', 'sub-step end gaps'),
    ('detector.sweep.Sweep', '_substep', 'sub-step solves, episodes'),
    ('detector.sweep.Sweep', '_impact', 'impact velocities'),
    ('detector.detector.Detector', '_measure', 'uncertainty (its own re-solves apart)'),
    ('detector.episodes.EpisodeTracker', 'close', 'near misses closed (lowest gap)'),
    ('detector.noise.NoiseEstimate', 'take_points', 'noise estimate (auto)'),
    ('detector.noise.NoiseEstimate', 'update', 'noise estimate (auto)'),
    ('detector.chunks', 'fast_forward', 'chunk fast-forwards'),
    ('detector.chunks', 'plan_chunk', 'chunk plans'),
    ('detector.sweep.Sweep', 'interval', 'the rest of the sweep (locate, far, walk)'),
    ('detector.detector.Detector', '_advance', 'the rest of the walk (scheduler)'),
    ('detector.detector.Detector', 'add', 'the rest of Detector.add (stops)'),
)
"""``--split``'s parts: (module or class under ``baseball_collision.core``, function, label).
Each part's own time (its callees among the parts counted in theirs)."""


def split_figures(messages: int, storage: str, model: str, baseline: str, repeats: int,
                  parameters: dict, pitch_every: float = WORST_SPACING_S,
                  bag_noise: float = 0.0, steady: bool = False) -> None:
    """
    Print where ``analyze_bag``'s CPU time goes for ``baseline`` and ``model``, per part.

    Each of ``SPLIT_PARTS`` is wrapped in a process-time timer for the run (put back after),
    and charged its own time only (a part called inside another counts in its own line); the
    timers' own cost (about 1 us a call) is in the figures. Best of ``repeats`` per model
    (by total), run in turn.
    """
    import importlib
    own: dict = {}
    calls: dict = {}
    stack: list = []
    clock = time.process_time

    def timer(function, label):
        def timed_part(*args, **kwargs):
            now = clock()
            if stack:
                own[stack[-1][0]] = own.get(stack[-1][0], 0.0) + now - stack[-1][1]
            stack.append([label, now])
            calls[label] = calls.get(label, 0) + 1
            try:
                return function(*args, **kwargs)
            finally:
                now = clock()
                label_, start = stack.pop()
                own[label_] = own.get(label_, 0.0) + now - start
                if stack:
                    stack[-1][1] = now
        return timed_part

    wrapped = []
    for owner_name, name, label in SPLIT_PARTS:
        module_name, _, rest = owner_name.rpartition('.')
        if rest[0].isupper():
            owner = getattr(importlib.import_module(f'baseball_collision.core.{module_name}'),
                            rest)
        else:
            owner = importlib.import_module(f'baseball_collision.core.{owner_name}')
        original = owner.__dict__[name]
        wrapped.append((owner, name, original))
        setattr(owner, name, timer(original, label))
    best: dict = {}
    try:
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / SUFFIXES[storage]
            written, _ = write_bag(path, messages, pitch_every, bag_noise, steady)
            for _ in range(repeats):
                for name in (baseline, model):
                    options = AnalysisOptions(model=named_model(name), parameters=parameters
                                              if name == model else {})
                    own.clear()
                    calls.clear()
                    start = clock()
                    analyze_bag(path, options)
                    total = clock() - start
                    if name not in best or total < best[name][0]:
                        best[name] = (total, dict(own), dict(calls))
    finally:
        for owner, name, original in wrapped:
            setattr(owner, name, original)
    print(f'{written:,} messages ({storage}); CPU s per part (calls), best of {repeats}; '
          f'{model} with {parameters or "its defaults"}')
    labels = list(dict.fromkeys(label for _, _, label in SPLIT_PARTS))
    print(f"  {'part':44s} {baseline:>16s} {model:>16s} {'extra':>8s}")
    rows = [('whole analyze_bag', best[baseline][0], best[model][0], '', '')]
    for label in labels:
        rows.append((label, best[baseline][1].get(label, 0.0), best[model][1].get(label, 0.0),
                     best[baseline][2].get(label, 0), best[model][2].get(label, 0)))
    parts = sum(row[1] for row in rows[1:]), sum(row[2] for row in rows[1:])
    rows.append(('outside the parts (read, decode, the loop)', best[baseline][0] - parts[0],
                 best[model][0] - parts[1], '', ''))
    for label, a, b, n_a, n_b in rows:
        print(f'  {label:44s} {a:7.3f} {str(n_a):>8s} {b:7.3f} {str(n_b):>8s} {b - a:+8.3f}')


def cpu_seconds() -> float:
    """Return the CPU time (s) of this process and its finished children (the pool's workers)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(
        resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def write_bags(folder: Path, bags: int, messages: int, storage: str,
               pitch_every: float) -> Tuple[List[Path], int]:
    """Write ``bags`` bags of ``messages`` in ``folder``; return their paths, messages each."""
    paths = []
    for k in range(bags):
        paths.append(folder / f'{k}_{SUFFIXES[storage]}')
        written, seconds = write_bag(paths[-1], messages, pitch_every)
    print(f'wrote {bags} bags of {written:,} messages ({storage}), the last in {seconds:.1f} s')
    return paths, written


def host_busy_s() -> Optional[float]:
    """Return the CPU time (s) every process on this host has used since boot (None: no /proc)."""
    try:
        with open('/proc/stat') as stat:
            ticks = [int(field) for field in stat.readline().split()[1:]]
    except OSError:
        return None
    return (sum(ticks) - ticks[3] - ticks[4]) / os.sysconf('SC_CLK_TCK')  # (not idle, iowait)


def wait_for_quiet_host(limit_s: float) -> None:
    """Wait up to ``limit_s`` for a 0.3 s span in which the host's cores were >= 93 % idle."""
    start = time.perf_counter()
    while time.perf_counter() - start < limit_s:
        busy, begun = host_busy_s(), time.perf_counter()
        if busy is None:
            return
        time.sleep(0.3)
        used = host_busy_s() - busy
        if used < 0.07 * (os.cpu_count() or 1) * (time.perf_counter() - begun):
            return


class Run:
    """
    One timed run: wall time, this process's and its children's CPU, the rest of the host's.

    Use as a context manager around the run. ``others`` is the cores the host's other
    processes kept busy meanwhile (from ``/proc/stat``; None without it): a figure taken while
    they used a core is a figure of a one-core machine.
    """

    def __enter__(self) -> 'Run':
        """Start the clocks."""
        self.busy, self.cpu, self.start = host_busy_s(), cpu_seconds(), time.perf_counter()
        return self

    def __exit__(self, *_: object) -> None:
        """Stop the clocks (the children must have been waited for)."""
        self.wall = time.perf_counter() - self.start
        self.cpu = cpu_seconds() - self.cpu
        busy = host_busy_s()
        self.others = None if busy is None else max(busy - self.busy - self.cpu, 0.0) / self.wall


def run_summary(runs: List[Run]) -> str:
    """Return a case's median and best wall time, median CPU and the others' median cores."""
    walls = [run.wall for run in runs]
    others = [run.others for run in runs if run.others is not None]
    return (f'median {statistics.median(walls):5.2f} s wall (best {min(walls):5.2f}), '
            f'{statistics.median(run.cpu for run in runs):5.2f} s CPU'
            + (f'; other processes on {statistics.median(others):.2f} cores meanwhile (median, '
               f'max {max(others):.2f})' if others else ''))


def jobs_summary(runs: Dict[str, List[Run]], one: str, many: str, goal: bool = True) -> str:
    """Return the speed-up of case ``many`` over ``one``: of the medians and of the bests."""
    ratio = (statistics.median(run.wall for run in runs[one])
             / statistics.median(run.wall for run in runs[many]))
    best = min(run.wall for run in runs[one]) / min(run.wall for run in runs[many])
    text = f'{ratio:.2f}x of the medians ({best:.2f}x of the bests)'
    if goal:
        met = 'met' if ratio >= 1.7 else 'NOT met'
        text += f' [goal >= 1.7x for two bags on two cores: {met}]'
    return text


def jobs_figures(bags: int, messages: int, storage: str, model: str, repeats: int,
                 pitch_every: float = WORST_SPACING_S, quiet_s: float = 0.0) -> None:
    """
    Write ``bags`` bags; print analyze_bags with one job and with ``bags`` jobs, the ratio.

    The two (and one job not reading ahead) in turn, ``repeats`` rounds; each run after up to
    ``quiet_s`` of waiting for a quiet host.
    """
    with tempfile.TemporaryDirectory() as tmp:
        paths, written = write_bags(Path(tmp), bags, messages, storage, pitch_every)
        options = AnalysisOptions(model=named_model(model))
        cases = {'--jobs 1': partial(analyze_bags, paths, options, jobs=1, progress=False),
                 f'--jobs {bags}': partial(analyze_bags, paths, options, jobs=bags,
                                           progress=False),
                 # one job that does not read ahead on the spare core (the pool's workers do not)
                 'one job not reading ahead': lambda: [
                     analyze_bag(path, options, progress=False, read_ahead=0) for path in paths]}
        runs: Dict[str, List[Run]] = {case: [] for case in cases}
        found, overlap = {}, {}
        for _ in range(repeats):
            for case, analyse in cases.items():
                wait_for_quiet_host(quiet_s)
                with Run() as run:
                    analyses = analyse()
                runs[case].append(run)
                found[case] = [(a.messages, a.impacts, a.near_misses) for a in analyses]
                # the bags' own times over the wall time: how many ran at once (1.0: one after
                # another; near 2.0: two cores each busy with a bag)
                overlap.setdefault(case, []).append(sum(a.seconds for a in analyses) / run.wall)
        total = bags * written
        for case, timed_runs in runs.items():
            print(f'analyze_bags, {case}: {total:,} msgs, {run_summary(timed_runs)}; bag time / '
                  f'wall time {statistics.median(overlap[case]):.2f} ({repeats} runs in turn)')
        many = f'--jobs {bags}'
        print(f'{many} / --jobs 1 speed-up: {jobs_summary(runs, "--jobs 1", many)}; same '
              f'events: {found["--jobs 1"] == found[many]}')
        print(f'{many} / one job not reading ahead: '
              f'{jobs_summary(runs, "one job not reading ahead", many)}; same events: '
              f'{found["one job not reading ahead"] == found["--jobs 1"]}')


def processes_at_once(commands: List[list],
                      environment: Optional[Dict[str, str]] = None) -> None:
    """
    Run commands as processes started at once; wait for all (each must succeed).

    :param environment: the children's (None: this process's without
        ``PYTHONDONTWRITEBYTECODE``: :func:`process_times`).
    """
    if environment is None:
        environment = {k: v for k, v in os.environ.items() if k != 'PYTHONDONTWRITEBYTECODE'}
    children = [subprocess.Popen(command, stdout=subprocess.DEVNULL, env=environment)
                for command in commands]
    for child, command in zip(children, commands):
        if child.wait() != 0:
            raise subprocess.CalledProcessError(child.returncode, command)


def tree_environment(tree: Path, bytecode_cache: bool) -> Dict[str, str]:
    """
    Return the environment of a child running the package from source tree ``tree``.

    ``PYTHONPATH`` is the tree (ahead of the installed package); with ``bytecode_cache`` False
    the child writes no bytecode cache (``PYTHONDONTWRITEBYTECODE=1``; remove the tree's caches
    first: :func:`remove_bytecode_caches`), else it may write one.
    """
    environment = {k: v for k, v in os.environ.items() if k != 'PYTHONDONTWRITEBYTECODE'}
    environment['PYTHONPATH'] = str(tree)
    if not bytecode_cache:
        environment['PYTHONDONTWRITEBYTECODE'] = '1'
    return environment


def remove_bytecode_caches(tree: Path) -> int:
    """Remove the ``__pycache__`` directories of ``tree``'s package; return how many."""
    caches = list((tree / 'baseball_collision').rglob('__pycache__'))
    for cache in caches:
        shutil.rmtree(cache)
    return len(caches)


def whole_jobs_figures(bags: int, messages: int, storage: str, model: str, repeats: int,
                       pitch_every: float = WORST_SPACING_S, quiet_s: float = 0.0,
                       before: Optional[Path] = None, bytecode_cache: bool = True) -> None:
    """
    Print whole ``analyze --jobs 1`` and ``--jobs K`` processes over K bags, in turn.

    Beside them, the ceiling the host allows: K ``analyze BAG`` processes started at once (as
    a shell starts them: each its own start-up, no pool), and one of them alone. Each run
    after up to ``quiet_s`` of waiting for a quiet host (``PYTHONDONTWRITEBYTECODE`` is
    dropped: :func:`process_times`).

    With ``before`` (a source tree of another commit, its kernel built): every case also
    runs the package from that tree, and both trees (``PYTHONPATH``) run the bundled 90 Hz bag
    too (start-up and teardown: ``analyze`` of 860 messages), each case from each tree in turn;
    then the medians of the two trees side by side. ``bytecode_cache`` False: the children
    start without the package's bytecode cache (each tree's caches removed first,
    ``PYTHONDONTWRITEBYTECODE=1``: every package module compiled at every start, as in a
    sandbox that sets it); True: with it (a user's second run).
    """
    here = Path(__file__).resolve().parents[1]
    trees = {'': None} if before is None else {' (before)': before.resolve(), ' (now)': here}
    if not bytecode_cache:
        removed = sum(remove_bytecode_caches(tree) for tree in trees.values() if tree)
        print(f'without bytecode caches ({removed} __pycache__ directories removed)')
    with tempfile.TemporaryDirectory() as tmp:
        paths, written = write_bags(Path(tmp), bags, messages, storage, pitch_every)
        cli = str(Path(sys.executable).with_name('baseball-collision'))
        flags = [*model_flag(model), '--quiet', '--no-progress']
        cases = {'--jobs 1': [[cli, 'analyze', *map(str, paths), *flags, '--jobs', '1']],
                 f'--jobs {bags}': [[cli, 'analyze', *map(str, paths), *flags, '--jobs',
                                     str(bags)]],
                 f'{bags} processes at once': [[cli, 'analyze', str(path), *flags]
                                               for path in paths],
                 'one bag alone': [[cli, 'analyze', str(paths[0]), *flags]]}
        if before is not None:
            cases['the bundled 90 Hz bag'] = [[cli, 'analyze', str(
                here / 'bags' / 'pitches_90hz.mcap'), *flags]]
        runs: Dict[str, List[Run]] = {case + label: [] for case in cases for label in trees}
        for _ in range(repeats):
            for case, commands in cases.items():
                for label, tree in trees.items():
                    environment = None if tree is None else tree_environment(tree,
                                                                             bytecode_cache)
                    wait_for_quiet_host(quiet_s)
                    with Run() as run:
                        processes_at_once(commands, environment)
                    runs[case + label].append(run)
        for case, timed_runs in runs.items():
            what = (f'{bags} bags {case}' if case.startswith('--') else
                    f'BAG, {case}')
            print(f'baseball-collision analyze {what}, whole processes: '
                  f'{run_summary(timed_runs)} ({repeats} runs in turn)')
        for label in trees:
            print(f'--jobs {bags} / --jobs 1 speed-up, whole processes{label}: '
                  f'{jobs_summary(runs, "--jobs 1" + label, f"--jobs {bags}" + label)}')
            print(f'the ceiling the host allows, --jobs 1 / {bags} processes at once{label}: '
                  + jobs_summary(runs, '--jobs 1' + label, f'{bags} processes at once{label}',
                                 goal=False))
        if before is not None:
            print('now / before, medians of each case (wall; CPU):')
            for case in cases:
                old, new = runs[case + ' (before)'], runs[case + ' (now)']
                print(f'  {case:24s} '
                      f'{statistics.median(r.wall for r in new) * 1e3:7.1f} / '
                      f'{statistics.median(r.wall for r in old) * 1e3:7.1f} ms; '
                      f'{statistics.median(r.cpu for r in new) * 1e3:7.1f} / '
                      f'{statistics.median(r.cpu for r in old) * 1e3:7.1f} ms')


def interleaved_figures(messages: int, storage: str, model: str, repeats: int,
                        pitch_every: float = WORST_SPACING_S) -> None:
    """Print (a), (d) and (e) run in turn ``repeats`` times: best CPU and wall time, ratios."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / SUFFIXES[storage]
        written, _ = write_bag(path, messages, pitch_every)
        runs = (('raw', raw_read, (path,)),
                ('chunks', partial(analyze_bag, progress=False),
                 (path, AnalysisOptions(model=named_model(model)))),
                ('one', per_sample, (path, model)))
        best, found = {}, {}
        for _ in range(repeats):
            for name, run, args in runs:
                cpu, start = time.process_time(), time.perf_counter()
                found[name] = run(*args)
                cpu, wall = time.process_time() - cpu, time.perf_counter() - start
                old = best.get(name, (float('inf'), float('inf')))
                best[name] = (min(old[0], cpu), min(old[1], wall))
        chunks, one = found['chunks'], found['one']
        same = (chunks.impacts, chunks.near_misses, chunks.drops_by_role, chunks.stats.intervals,
                chunks.stats.substeps) == (one.impacts, one.near_misses, one.drops_by_role,
                                           one.stats.intervals, one.stats.substeps)
        print(f'{written:,} messages ({storage}), --model {model}, best of {repeats} '
              f'interleaved runs: {len(chunks.impacts)} impacts, {chunks.stats.intervals:,} '
              f'intervals, {chunks.stats.substeps:,} sub-steps')
        for name, label in (('raw', '(a) rosbags raw read'), ('chunks', '(d) analyze, chunks'),
                            ('one', '(e) analyze, one sample at a time')):
            cpu, wall = best[name]
            print(f'  {label:36s} CPU {cpu:7.2f} s {written / cpu:>10,.0f} msg/s   '
                  f'wall {wall:7.2f} s {written / wall:>10,.0f} msg/s')
        for what, i in (('CPU', 0), ('wall', 1)):
            raw, fast, slow = (best[name][i] for name in ('raw', 'chunks', 'one'))
            print(f'  {what:4s}: (d) / raw read = {raw / fast:.3f}, (e) / raw read = '
                  f'{raw / slow:.3f}, (d) / (e) speed-up = {slow / fast:.2f}x')
        print(f'  same events, drops and counters: {same}')


def main() -> None:
    """Write the bag, time the readers and analyze, print the figures and the split."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--messages', type=int, default=None,
                        help='messages per bag (1,000,000; with --jobs 250,000)')
    parser.add_argument('--storage', choices=sorted(SUFFIXES), default='mcap')
    parser.add_argument('--model', choices=('linear', 'rigid', 'spline', 'c2', 'default'),
                        default='spline', help='default: the offline default of analyze (no '
                        '--model flag; with --whole and --jobs only)')
    parser.add_argument('--profile', action='store_true', help='cProfile the analyze run')
    parser.add_argument('--jobs', type=int, default=None, metavar='K',
                        help='time the process pool over K bags instead')
    parser.add_argument('--whole', action='store_true',
                        help='time whole processes instead: analyze against a raw read')
    parser.add_argument('--against', choices=('linear', 'rigid', 'spline', 'c2'), default=None,
                        help='compare --model against this model in this process instead')
    parser.add_argument('--pairs', type=int, default=3, help='pairs with --against (3)')
    parser.add_argument('--look-ahead', type=int, default=0, help='c2 look_ahead (0)')
    parser.add_argument('--tracker-noise', type=float, default=0.0, metavar='M',
                        help="c2's tracker_noise (0; -1: auto)")
    parser.add_argument('--bag-noise', type=float, default=0.0, metavar='M',
                        help='the bag with this tracking noise (m; 0: exact)')
    parser.add_argument('--steady-clock', action='store_true',
                        help="the worst case's stamps on a steady clock (no jitter, no grid)")
    parser.add_argument('--split', action='store_true',
                        help='with --against: where the time goes, per part (process-time '
                        'timers), best of --repeats per model; with --whole: CPU time by '
                        'stage in each process (timers)')
    parser.add_argument('--repeats', type=int, default=3,
                        help='runs per --jobs, --whole or --interleave figure (3)')
    parser.add_argument('--pitch-every', type=float, default=WORST_SPACING_S, metavar='SECONDS',
                        help='seconds between pitches: 0.5, the worst case (nothing between '
                        'pitches, every message near one), or more: a session tracked '
                        'throughout (batting practice: 8-15)')
    parser.add_argument('--before', type=Path, default=None, metavar='DIR',
                        help='with --whole: also analyze from this source tree, in turn')
    parser.add_argument('--no-bytecode-cache', action='store_true',
                        help='with --whole --jobs --before: the children start without the '
                        "package's bytecode cache (the trees' caches removed, "
                        'PYTHONDONTWRITEBYTECODE=1)')
    parser.add_argument('--wait-quiet', type=float, default=0.0, metavar='SECONDS',
                        help='with --jobs: before each run, wait up to SECONDS for a quiet host '
                        '(other processes on less than 7 %% of its cores for 0.3 s; 0: no wait)')
    parser.add_argument('--interleave', action='store_true',
                        help='(a), (d), (e) in turn --repeats times: best CPU and wall time')
    args = parser.parse_args()
    # the analyses in this process on one BLAS thread, as ``baseball-collision analyze`` runs
    # them (cli.main): OpenBLAS's threads on the smoother's 32-wide matrices cost 10x
    single_threaded_blas()
    print(f'bag: {density(args.pitch_every)}')
    if args.interleave:
        interleaved_figures(args.messages or 30_000, args.storage, args.model, args.repeats,
                            args.pitch_every)
        return
    if args.whole and args.jobs:
        whole_jobs_figures(args.jobs, args.messages or 250_000, args.storage, args.model,
                           args.repeats, args.pitch_every, args.wait_quiet, args.before,
                           not args.no_bytecode_cache)
        return
    if args.whole:
        whole_process_figures(args.messages or 500_000, args.storage, args.model, args.repeats,
                              args.pitch_every, args.before, args.split, args.bag_noise)
        return
    if args.against and args.split:
        split_figures(args.messages or 30_000, args.storage, args.model, args.against,
                      args.repeats, model_parameters(args.model, args.look_ahead,
                                                     args.tracker_noise),
                      args.pitch_every, args.bag_noise, args.steady_clock)
        return
    if args.against:
        against_figures(args.messages or 30_000, args.storage, args.model, args.against,
                        args.pairs, args.look_ahead, args.pitch_every, args.tracker_noise,
                        args.bag_noise, args.steady_clock)
        return
    if args.jobs:
        jobs_figures(args.jobs, args.messages or 250_000, args.storage, args.model,
                     args.repeats, args.pitch_every, args.wait_quiet)
        return
    args.messages = args.messages or 1_000_000
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / SUFFIXES[args.storage]
        written, seconds = write_bag(path, args.messages, args.pitch_every, args.bag_noise,
                                     args.steady_clock)
        size = path.stat().st_size / 1e6
        print(f'wrote {written:,} messages ({args.storage}, {size:.0f} MB) in {seconds:.1f} s')
        raw, raw_s = timed(raw_read, path)
        decoded, decode_s = timed(decode, path)
        print(f'(a) rosbags raw messages()   {raw:>9,} msgs in {raw_s:6.2f} s: '
              f'{raw / raw_s:>9,.0f} msg/s')
        print(f'(b) BagReader.samples()      {decoded:>9,} msgs in {decode_s:6.2f} s: '
              f'{decoded / decode_s:>9,.0f} msg/s')
        looped, loop_s = timed(null_loop, path)
        print(f'(c) analyze loop, no detector {looped:>9,} msgs in {loop_s:6.2f} s: '
              f'{looped / loop_s:>9,.0f} msg/s')
        parameters = model_parameters(args.model, args.look_ahead, args.tracker_noise)
        options = AnalysisOptions(model=named_model(args.model), parameters=parameters)
        profiler = cProfile.Profile() if args.profile else None
        if profiler is not None:
            profiler.enable()
        result, total_s = timed(analyze_bag, path, options)
        if profiler is not None:
            profiler.disable()
        n = result.messages
        rate = n / total_s
        print(f'(d) analyze, {args.model:6s} model  {n:>9,} msgs in {total_s:6.2f} s: '
              f"{rate:>9,.0f} msg/s  [goal {GOAL:,}: {'met' if rate >= GOAL else 'NOT met'}]")
        print(f'    found {len(result.impacts)} impacts, {len(result.near_misses)} near misses, '
              f'{sum(result.stats.dropped.values())} dropped, {result.stats.intervals:,} '
              f'intervals, {result.stats.substeps:,} sub-steps')
        detector_s = result.stats.total_processing_s
        loop_only = max(loop_s - decode_s, 0.0)
        rest_s = max(total_s - decode_s - loop_only - detector_s, 0.0)
        print('    where the time of (d) goes:')
        for label, part in (('read + decode (b)', decode_s),
                            ('analyze loop (c) - (b)', loop_only),
                            ('detector, own timer', detector_s),
                            ('planning chunks, rest', rest_s)):
            print(f'      {label:28s} {part:6.2f} s  {part / total_s * 100:5.1f} %  '
                  f'{part / n * 1e6:6.2f} us/msg')
        print(f'    analyze / raw read = {rate / (raw / raw_s):.2f}; analyze without the detector '
              f'(c) = {looped / loop_s / (raw / raw_s):.2f} of the raw read rate')
        before, before_s = timed(per_sample, path, args.model, parameters)
        same = (before.impacts, before.near_misses, before.drops_by_role, before.stats.intervals,
                before.stats.substeps) == (result.impacts, result.near_misses,
                                           result.drops_by_role, result.stats.intervals,
                                           result.stats.substeps)
        before_rate = before.messages / before_s
        print(f'(e) one sample at a time     {before.messages:>9,} msgs in {before_s:6.2f} s: '
              f'{before_rate:>9,.0f} msg/s = {before_rate / (raw / raw_s):.2f}'
              f' of the raw read rate; chunks (d) are {before_s / total_s:.2f}x faster; '
              f'same events, drops and counters: {same}')
        if profiler is not None:
            print('\ncProfile of (d), top 25 by own time (timings include the profiling '
                  'overhead):')
            stats = pstats.Stats(profiler)
            stats.sort_stats('tottime').print_stats(25)


if __name__ == '__main__':
    main()
