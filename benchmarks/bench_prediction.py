"""
Prediction benchmark: predicted impact time and contact point error versus lead time.

Run: ``.venv/bin/python benchmarks/bench_prediction.py [--per-kind N] [--seed S] [--period S]``.

Scenarios: N of each contact kind (barrel, end cap, handle) from ``simulation.make_scenario``,
tracked from 0.4 s before contact (about the release). Each is sampled at 90 and 360 Hz with
timestamp jitter and 1 mm position noise and fed to a detector with a 0.3 s prediction horizon.
For each lead time L the prediction scored is the one in force L before the true contact (the
last made, unless a ``PredictionCleared`` came since: what the node publishes; none counts as
not predicted). Errors: the
predicted impact stamp minus the true one (ms), and the distance (cm) from the predicted to the
true contact point.

Two bat sources: ``extrapolated`` (the tracked bat's current state, as for a human swing) and
``planned`` (a robot arm's commanded bat trajectory at 200 Hz, given to ``set_bat_plan``).

Then the cost: wall time per ``Detector.add`` at 1 kHz per stream (ball + bat pose) over a
pitch tracked from 0.45 s before contact, without and with a 0.3 s horizon (every frame, and
with ``prediction_period`` 5 and 10 ms, and at 10 ms without the ball's lift and with the
arm's plan; each prediction's error bars measured at once), in one process;
``--cost-only`` prints only that. ``--spin``: spinning pitches; ``--no-lift``: the predictions
with ``lift_window`` 0 (gravity and drag alone). ``--arm-glitch`` prints only what one ball
glitch costs an arm's predictions (``arm_glitches``); ``--faults --ball-only`` only a ball
glitch's fault table (``ball_cell``).
``--changes`` prints only how much consecutive predictions 10 ms apart move, per swing family.
``--calibration`` prints only how often a planned prediction's error is within its 1 and 2
sigma (``calibration``), ``--calibration --extrapolated`` an extrapolated bat's, every family;
both measured at once, as ``analyze`` does (the node measures the same after sending each).

``--faults`` prints only what bat-tracker faults cost the prediction, each run beside the same
pitch without the fault (every swing family x ``--seeds`` seeds x barrel, graze, miss over and
under; tracked from 0.4 s before the approach; 90 and 360 Hz; exact and 1 mm of noise; the
node's defaults and ``analyze --predict``'s, the bat as a pose): one bat frame turned 10 or 20
cm toward the ball (``Samples.with_bat_frame_turned``), or stamped 2 or 4 ms early or late (its
pose right), the 1st, 2nd or 4th frame before the approach (the contact, or a miss's closest
instant). Counted: hits whose prediction in force 20 ms ahead (``FAULT_LEAD_S``) is within 5
ms of the contact (``FAULT_OFF_S``) in the clean run and not in the faulted one (lost), and the
reverse (gained); misses with a prediction where the clean run made none (false predictions),
and those predicted at a frame where the clean run had none in force (a near miss's false
prediction the clean run withdrew sooner); of the hits lost, those the pitch without the
faulted frame (``Samples.without_bat_frame``) loses too (a rule that leaves the frame out keeps
the rest at best; a frame stamped off has its pose right, though); the chunk path
(``Detector.add_chunk``) against one sample at a time on every faulted run (runs whose events
differ). Then a ball tracker that
pauses (``pauses``): how often ``~/impact_predicted`` goes off and on again under the node's
rule (``ros/prediction_watch.py``) on the messages' arrivals, and off before a hit's contact
(by pause length), the node's defaults and ``analyze --predict``'s detector; and a ball lost for
good (``gone``): that the flag goes off, and how long after the predicted instant (the cost of
holding it through a silence the ball's flight holds, ``predictor.kept_flight_span``).
``--pauses-only``: only that.

Between them, a glitch beside the bat tracker's lost frames (``lost_cell``): the frame turned 10
or 20 cm toward the ball as above (the 1st, 2nd or 4th before the approach), made its bat
segment's 1st, 2nd, 3rd or 4th frame (the tracker re-acquires the bat after the frames over
``max_gap`` before it are lost: ``bench_glitches.faulted``'s ``--segment``, ``LOST_SEGMENT``),
or with the frame two or one before it or the one after it lost (``--lost``, ``LOST_BESIDE``:
at 90 Hz a hole over ``bat_glitches.LOST_HOLE``); the clean run is the pitch with the same
frames lost, the deleted one without the glitch's frame too; scored as above.
``--lost-only``: only that table. ``--fault-lead`` scores the hits at another lead than
``FAULT_LEAD_S`` (s; 0.01: what a rule that judges a frame from the frames after it keeps).
``--score-sent``: a prediction counts from when it is sent (the newest input stamp fed when
the detector returned it: the node's message, or the chunk's newest), not from the detector's
cursor it was made at (``made_at_ns``), which lags it where the sweep holds an interval (not
with ``--chunks``, whose chunks send later than one sample at a time). Its node rows are the
ones to read: ``analyze``'s look-ahead of two frames sends every prediction two frames late
by design, so its clean pitches lose their 20 ms lead at 90 Hz too.

    .venv/bin/python benchmarks/bench_prediction.py --faults [--seeds 2] [--chunks]
    .venv/bin/python benchmarks/bench_prediction.py --faults --lost-only [--chunks]
    .venv/bin/python benchmarks/bench_prediction.py --faults --lost-only --fault-lead 0.01
    .venv/bin/python benchmarks/bench_prediction.py --faults --lost-only --score-sent
"""

import argparse
from dataclasses import replace
import time
from typing import Any, Callable, Dict, Iterator, List, NamedTuple, Optional, Tuple

from baseball_collision.core.detector import DEFAULTS, Detector, DetectorConfig, Prediction
from baseball_collision.core.detector.chunks import ROLE_CODES
from baseball_collision.core.detector.events import PredictionCleared
from baseball_collision.core.detector.predictor import kept_flight_span
from baseball_collision.ros.prediction_watch import PredictionWatch
from baseball_collision.threads import single_threaded_blas
from baseball_collision.tools.parameters import build_config
from baseball_collision.tools.sim import (
    FAMILIES, make_scenario, sample, Samples, Scenario, truth_dict)
from baseball_collision.tools.truth import LEADS_S, PredictionIndex
import bench_glitches  # noqa: I100  (the tracker's lost frames about a glitch)
import numpy as np

FAULT_LEAD_S = 0.02
"""s: the lead at which ``--faults`` scores a hit's prediction."""

SCORE_SENT = False
"""``--faults`` scores a prediction from when it was sent, not made (``predictions_of``)."""

FAULT_OFF_S = 0.005
"""s: a prediction further than this from the contact counts as none (``--faults``)."""

FAULT_FRAMES = (1, 2, 4)
"""The faulted bat frame: this many frames before the approach (``--faults``)."""

CHUNK_SIZES = (7, 50, 400)
"""Chunk sizes, in turn, of ``--faults --chunks``'s chunk path."""

FAULT_KINDS = ('barrel', 'graze', 'miss_over', 'miss_under')
"""The pitches of ``--faults``: hits and misses."""

LOST_SEGMENT = (1, 2, 3, 4)
"""The glitch as its bat segment's Nth frame (``lost_cell``: ``bench_glitches``' ``--segment``)."""

LOST_BESIDE = (-2, -1, 1)
"""The bat frame lost this many frames from the glitch (``lost_cell``: ``--lost``)."""

SMOOTH_PLANS = ('plane', 'tilted', 'jerky', 'lefty')
"""The swing families whose plan (``plan_of``, poses 5 ms apart) moves smoothly through the
contact (``--calibration``'s first table)."""

BRAKING_PLANS = ('braking', 'rebound')
"""The swing families whose plan brakes 1-3 ms after the contact, within one of its steps
(``--calibration``'s second table: an arm's plan follows through)."""

LOST_TURNS_M = (0.1, 0.2)
"""m: how far the glitch beside lost frames turns the tip toward the ball (``lost_cell``)."""


def plan_of(scenario: Scenario, start_ns: int, rate_hz: float = 200.0):
    """Return a commanded plan (stamps, positions, quaternions) of the scenario's swing."""
    times = np.arange(0.0, scenario.t_end, 1.0 / rate_hz)
    positions, quaternions = scenario.swing.pose(times)
    stamps = [start_ns + int(round(t * 1e9)) for t in times]
    return stamps, positions.tolist(), quaternions.tolist()


def errors(scenario: Scenario, rate_hz: float, noise_m: float, planned: bool,
           seed: int, period: float = 0.0,
           lift_window: float = DEFAULTS['lift_window']
           ) -> Dict[float, Optional[Tuple[float, float]]]:
    """
    Return {lead: (time error ms, point error cm) or None} for one scenario.

    With ``prediction_period`` ``period`` (s) and ``lift_window`` (s; 0: the ball's forecast
    of gravity and drag alone); a lead scores the prediction in force then.
    """
    samples = sample(scenario, rate_hz, np.random.default_rng(seed), jitter_s=2e-4,
                     noise_m=noise_m)
    scored = scored_predictions(scenario, samples, DetectorConfig(
        model='rigid', prediction_horizon=0.3, prediction_period=period,
        lift_window=lift_window), planned)
    return {lead: None if error is None else (error[0] * 1e3, error[1] * 100.0)
            for lead, error in scored.items()}


def scored_predictions(scenario: Scenario, samples: Samples, config: DetectorConfig,
                       planned: bool) -> Dict[float, Optional[Tuple[float, float]]]:
    """
    Return {lead: (time error s, point error m) or None} of a fresh detector on ``samples``.

    One sample at a time, with the scenario's swing as the arm's plan where ``planned``
    (``plan_of``); a lead scores the prediction in force then (``PredictionIndex.errors``).
    """
    detector = Detector(config)
    if planned:
        detector.set_bat_plan(*plan_of(scenario, samples.start_ns))
    predictions: List[Prediction] = []
    cleared: List[int] = []
    for stamp, role, values in samples.messages('pose'):
        for event in detector.add(role, stamp, values):
            if isinstance(event, Prediction):
                predictions.append(event)
            elif isinstance(event, PredictionCleared):
                cleared.append(event.made_at_ns)
    truth = truth_dict(scenario, samples.start_ns)
    return PredictionIndex(predictions, cleared).errors(truth['stamp_ns'], truth['point'])


def cost(seed: int, repeats: int = 3) -> None:
    """
    Print the per-message cost of prediction at 1 kHz (median, p99, mean) and the ratios.

    Each configuration runs ``repeats`` times; the run with the least CPU time is kept (its
    wall-clock median, p99 and mean per message, and its CPU time per message: the mean from
    the process's clock, p99 and max from this thread's, which other work on the machine
    inflates less than wall time, since time the thread waits for a core is not counted).
    """
    scenario = make_scenario('barrel', np.random.default_rng(seed), lead_s=0.45, trail_s=0.2)
    samples = sample(scenario, 1000.0, np.random.default_rng(seed), jitter_s=1e-4)
    messages = samples.messages()
    print('\n| prediction | median us/msg | p99 us/msg | mean us/msg | CPU mean us/msg (best of '
          f'{repeats}) | CPU p99 us/msg | CPU max us/msg |')
    print('|---|---|---|---|---|---|---|')
    cpu_means = []
    lift = DEFAULTS['lift_window']
    for horizon, period, window, planned in (
            (0.0, 0.0, lift, False), (0.3, 0.0, lift, False), (0.3, 0.005, lift, False),
            (0.3, 0.01, lift, False), (0.3, 0.01, 0.0, False), (0.3, 0.01, lift, True)):
        best = None
        for _ in range(repeats):
            detector = Detector(DetectorConfig(prediction_horizon=horizon,
                                               prediction_period=period, lift_window=window))
            if planned:
                detector.set_bat_plan(*plan_of(scenario, samples.start_ns))
            spent, spent_cpu = [], []
            cpu = time.process_time()
            for stamp, role, values in messages:
                start, start_cpu = time.perf_counter(), time.thread_time()
                detector.add(role, stamp, values)
                spent_cpu.append(time.thread_time() - start_cpu)
                spent.append(time.perf_counter() - start)
            cpu = (time.process_time() - cpu) / len(messages)
            if best is None or cpu < best[0]:
                best = (cpu, np.array(spent) * 1e6, np.array(spent_cpu) * 1e6)
        cpu, us, us_cpu = best
        cpu_means.append(cpu * 1e6)
        name = 'off' if horizon == 0.0 else f'{horizon:g} s horizon' + (
            f', every {period * 1e3:g} ms' if period else ', every frame') + (
            '' if window else ', no lift (lift_window 0)') + (
            ", the arm's plan (error bars)" if planned else '')
        print(f'| {name} | {np.median(us):.1f} | {np.percentile(us, 99):.1f} | {us.mean():.1f} '
              f'| {cpu * 1e6:.1f} | {np.percentile(us_cpu, 99):.1f} | {us_cpu.max():.1f} |')
    print(f'\nCPU time: prediction adds {cpu_means[1] - cpu_means[0]:.1f} us per message '
          f'(every frame), {cpu_means[2] - cpu_means[0]:.1f} (every 5 ms), '
          f'{cpu_means[3] - cpu_means[0]:.1f} (every 10 ms); goal <= 30 us; the lift '
          f'{cpu_means[3] - cpu_means[4]:.1f} of it (every 10 ms); with the plan '
          f'{cpu_means[5] - cpu_means[0]:.1f} (every 10 ms)')


def changes(seed: int = 5, per_family: int = 6, rate_hz: float = 360.0,
            period: float = 0.01) -> None:
    """
    Print how much consecutive predictions move, per swing family and bat source.

    ``per_family`` scenarios of each family (kinds in turn), sampled at ``rate_hz`` with 0.2 ms
    jitter and 1 mm noise, predicted every ``period`` s (0.3 s horizon): the median change of
    the predicted instant (ms) and point (mm) between one prediction and the next, and the
    share of pairs within 0.1 ms and 1 mm (what publishing only material changes would skip).
    """
    rng = np.random.default_rng(seed)
    print(f'\nconsecutive predictions, {rate_hz:g} Hz, every {period * 1e3:g} ms\n')
    print('| family | bat | pairs | time change p50 ms | point change p50 mm | within 0.1 ms '
          'and 1 mm |')
    print('|---|---|---|---|---|---|')
    for family in FAMILIES:
        for planned in (False, True):
            steps_ms, moves_mm = [], []
            for i in range(per_family):
                scenario = make_scenario(('barrel', 'end_cap', 'handle')[i % 3], rng, lead_s=0.4,
                                         family=family)
                samples = sample(scenario, rate_hz, np.random.default_rng(i), jitter_s=2e-4,
                                 noise_m=0.001)
                detector = Detector(DetectorConfig(model='rigid', prediction_horizon=0.3,
                                                   prediction_period=period))
                if planned:
                    detector.set_bat_plan(*plan_of(scenario, samples.start_ns))
                made = [e for stamp, role, values in samples.messages('pose')
                        for e in detector.add(role, stamp, values) if isinstance(e, Prediction)]
                for a, b in zip(made, made[1:]):
                    steps_ms.append(abs(b.stamp_ns - a.stamp_ns) * 1e-6)
                    moves_mm.append(float(np.linalg.norm(np.subtract(b.point, a.point))) * 1e3)
            steps, moves = np.array(steps_ms), np.array(moves_mm)
            small = float(np.mean((steps < 0.1) & (moves < 1.0))) if steps.size else float('nan')
            print(f"| {family} | {'planned' if planned else 'extrapolated'} | {steps.size} | "
                  f'{np.median(steps):.3f} | {np.median(moves):.2f} | {small:.0%} |')


def node_configs() -> Dict[str, DetectorConfig]:
    """Return the node's defaults (prediction on) and ``analyze --predict``'s, by name."""
    return {'node': DetectorConfig(prediction_horizon=0.3, prediction_period=0.01),
            'analyze': build_config({}, bat_input='pose', prediction_horizon=0.3)}


def faulted(samples: Samples, j: int, fault: Tuple[str, float]) -> Samples:
    """
    Return the samples with bat frame j faulted.

    ``('turn', m)``: turned so that its tip moves m toward the ball (its nearest sample);
    ``('stamp', s)``: its stamp moved by s (its pose right; one that leaves the stamp order is
    delivered in stamp order, as a tracker's message would be, and dropped as out of order).
    """
    kind, size = fault
    if kind == 'turn':
        near = int(np.argmin(np.abs(samples.ball_stamps_ns - samples.bat_stamps_ns[j])))
        return samples.with_bat_frame_turned(j, samples.ball_positions[near], size)
    stamps = samples.bat_stamps_ns.copy()
    stamps[j] += int(round(size * 1e9))
    return replace(samples, bat_stamps_ns=stamps)


def predictions_of(config: DetectorConfig, samples: Samples,
                   chunked: bool = False) -> Tuple[PredictionIndex, List[Any]]:
    """
    Return a fresh detector's predictions (indexed) and all its events, fed one sample at a time.

    ``chunked``: fed in chunks of ``CHUNK_SIZES`` samples in turn (``Detector.add_chunk``)
    instead.
    """
    detector, events = Detector(config), []
    messages = samples.messages('pose')
    sent: List[int] = []  # (each event's: the newest stamp fed when it was returned)
    if chunked:
        roles = np.array([ROLE_CODES[role] for _, role, _ in messages], np.int8)
        stamps = np.array([stamp for stamp, _, _ in messages], np.int64)
        values = np.zeros((len(messages), 7))
        for row, (_, _, value) in enumerate(messages):
            values[row, :len(value)] = value
        start, turn = 0, 0
        while start < len(messages):
            end = start + CHUNK_SIZES[turn % len(CHUNK_SIZES)]
            events += detector.add_chunk(roles[start:end], stamps[start:end],
                                         values[start:end], ['world'] * len(roles[start:end]))
            sent += [int(stamps[:end].max())] * (len(events) - len(sent))
            start, turn = end, turn + 1
    else:
        for stamp, role, values in messages:
            events += detector.add(role, stamp, values, 'world')
            sent += [max(stamp, sent[-1] if sent else stamp)] * (len(events) - len(sent))
    events += detector.finish()
    sent += [max(stamp for stamp, _, _ in messages)] * (len(events) - len(sent))  # (finish)
    if SCORE_SENT:
        events = [replace(e, made_at_ns=max(e.made_at_ns, at))
                  if isinstance(e, (Prediction, PredictionCleared)) else e
                  for e, at in zip(events, sent)]
    predictions = [e for e in events if isinstance(e, Prediction)]
    cleared = [e.made_at_ns for e in events if isinstance(e, PredictionCleared)]
    return PredictionIndex(predictions, cleared), events


def scored(index: PredictionIndex, contact_ns: int, point: Any) -> bool:
    """Return whether the prediction in force ``FAULT_LEAD_S`` before a contact is on it."""
    error = index.errors(contact_ns, point, (FAULT_LEAD_S,))[FAULT_LEAD_S]
    return error is not None and abs(error[0]) <= FAULT_OFF_S


def _fault_pitches(rate: float, noise_m: float, seeds: int) -> Iterator[Tuple[Any, ...]]:
    """
    Yield the fault tables' clean pitches: every family, seed and ``FAULT_KINDS`` kind.

    Each as (``Samples`` at ``rate`` Hz with ``noise_m`` m of noise, its truth
    (``truth_dict``), whether it is a hit, the contact's or closest approach's stamp (ns), the
    indices of its bat frames before that stamp).
    """
    for family in FAMILIES:
        for seed in range(seeds):
            for kind in FAULT_KINDS:
                rng = np.random.default_rng(seed)
                scenario = make_scenario(kind, rng, lead_s=0.4, family=family)
                samples = sample(scenario, rate, rng, jitter_s=2e-4, noise_m=noise_m)
                truth = truth_dict(scenario, samples.start_ns)
                hit = scenario.truth.contact
                approach = truth['stamp_ns'] if hit else samples.start_ns + int(
                    round(scenario.truth.min_gap_time_s * 1e9))
                yield (samples, truth, hit, approach,
                       np.flatnonzero(samples.bat_stamps_ns < approach))


CELL_COUNTS = ('hits', 'lost', 'gained', 'clean_hits', 'misses', 'false', 'longer',
               'chunk_differs', 'deleted_too')
"""What a fault table's cell counts (``_tally`` and ``_tally_faulted``)."""


def fault_cell(rate: float, noise_m: float, config: DetectorConfig, seeds: int,
               chunks: bool) -> Dict[str, Dict[str, int]]:
    """Return one rate, noise and configuration's counts per fault kind (turn, stamp)."""
    faults = {'turn': [('turn', 0.1), ('turn', 0.2)],
              'stamp': [('stamp', s) for s in (-0.004, -0.002, 0.002, 0.004)]}
    counts = {name: dict.fromkeys(CELL_COUNTS, 0) for name in faults}
    for samples, truth, hit, approach, before in _fault_pitches(rate, noise_m, seeds):
        clean, _ = predictions_of(config, samples)
        clean_ok = hit and scored(clean, approach, truth['point'])
        for back in FAULT_FRAMES:
            # (the pitch without the frame: what judging the fault could keep at best)
            without = hit and clean_ok and scored(predictions_of(
                config, samples.without_bat_frame(int(before[-back])))[0], approach,
                truth['point'])
            for name, cases in faults.items():
                cell = counts[name]
                for fault in cases:
                    _tally_faulted(cell, config, faulted(samples, int(before[-back]), fault),
                                   chunks, clean, hit and (clean_ok, without), approach,
                                   truth['point'])
    return counts


def _tally_faulted(cell: Dict[str, int], config: DetectorConfig, bad: Samples, chunks: bool,
                   clean: Any, hit: Any, approach: int, point: Any) -> None:
    """
    Make a faulted pitch's predictions (``bad``) and count them in ``cell`` (``_tally``).

    ``chunks``: the chunk path's events too, a run whose differ from one sample at a time's
    counted (``chunk_differs``); the other arguments ``_tally``'s.
    """
    index, events = predictions_of(config, bad)
    if chunks and predictions_of(config, bad, True)[1] != events:
        cell['chunk_differs'] += 1
    _tally(cell, index, clean, hit, approach, point)


def _tally(cell: Dict[str, int], index: Any, clean: Any, hit: Any, approach: int,
           point: Any) -> None:
    """
    Count one faulted pitch's predictions (``index``) against its clean pitch's in ``cell``.

    ``hit``: False for a miss, else (whether the clean pitch's prediction 20 ms ahead scored,
    whether the pitch without the faulted frame's did); ``approach`` the contact's or closest
    approach's stamp (ns), ``point`` the true contact point (m).
    """
    if hit:
        clean_ok, without = hit
        ok = scored(index, approach, point)
        cell['hits'] += 1
        cell['clean_hits'] += clean_ok
        cell['lost'] += clean_ok and not ok
        cell['deleted_too'] += clean_ok and not ok and not without
        cell['gained'] += ok and not clean_ok
        return
    cell['misses'] += 1
    later = any(clean.in_force(int(made)) is None for made in index.made)
    cell['false'] += later and not len(clean.made)
    cell['longer'] += later and len(clean.made) > 0


BALL_GLITCH_BEFORE_S = (0.03, 0.06, 0.09)
"""s: the ball sample nearest this long before the approach is the glitch (``ball_cell``)."""

BALL_GLITCH_M = ((0.0, 0.0, 0.05), (0.0, 0.0, 0.1), (0.0, 0.0, -0.2))
"""m: how far the glitch moves the ball sample (``ball_cell``)."""


def ball_cell(rate: float, noise_m: float, config: DetectorConfig, seeds: int,
              chunks: bool) -> Dict[str, Dict[str, int]]:
    """
    Return one rate, noise and configuration's counts per placement of a ball glitch.

    The ball sample nearest ``BALL_GLITCH_BEFORE_S`` before the approach moved by each of
    ``BALL_GLITCH_M`` (``Samples.with_ball_frame_moved``); the counts as ``fault_cell``'s,
    against the clean pitch and the one without that sample (deleted).
    """
    counts = {f'{before * 1e3:g} ms before': dict.fromkeys(CELL_COUNTS, 0)
              for before in BALL_GLITCH_BEFORE_S}
    for samples, truth, hit, approach, _ in _fault_pitches(rate, noise_m, seeds):
        clean, _ = predictions_of(config, samples)
        clean_ok = hit and scored(clean, approach, truth['point'])
        for before, cell in zip(BALL_GLITCH_BEFORE_S, counts.values()):
            j = int(np.argmin(np.abs(samples.ball_stamps_ns - (approach - before * 1e9))))
            keep = np.ones(len(samples.ball_stamps_ns), bool)
            keep[j] = False
            without = hit and clean_ok and scored(predictions_of(
                config, samples.with_ball_kept(keep))[0], approach, truth['point'])
            for offset in BALL_GLITCH_M:
                _tally_faulted(cell, config, samples.with_ball_frame_moved(j, offset), chunks,
                               clean, hit and (clean_ok, without), approach, truth['point'])
    return counts


def lost_cell(rate: float, noise_m: float, config: DetectorConfig, seeds: int,
              chunks: bool) -> Dict[str, Dict[str, int]]:
    """
    Return one rate, noise and configuration's counts per placement of a glitch by lost frames.

    Placements ``segment N`` (``LOST_SEGMENT``) and ``lost K`` (``LOST_BESIDE``), made by
    ``bench_glitches.faulted``; the counts as ``fault_cell``'s, each against the pitch with the
    same frames lost (clean) and that without the glitch's frame too (deleted).
    """
    placements = [(f'segment {n}', None, n) for n in LOST_SEGMENT] + [
        (f'lost {k}', k, None) for k in LOST_BESIDE]
    counts = {name: dict.fromkeys(CELL_COUNTS, 0) for name, _, _ in placements}
    for samples, truth, hit, approach, before in _fault_pitches(rate, noise_m, seeds):
        for back in FAULT_FRAMES:
            for name, lost, segment in placements:
                cell = counts[name]
                base, at = bench_glitches.faulted(samples, int(before[-back]), lost,
                                                  segment)
                clean, _ = predictions_of(config, base)
                clean_ok = hit and scored(clean, approach, truth['point'])
                without = clean_ok and scored(predictions_of(
                    config, base.without_bat_frame(at))[0], approach, truth['point'])
                for turn in LOST_TURNS_M:
                    _tally_faulted(cell, config, faulted(base, at, ('turn', turn)), chunks,
                                   clean, hit and (clean_ok, without), approach, truth['point'])
    return counts


PAUSE_LAGS_S = (0.0, 0.06)
"""s: how far the ball tracker's messages come behind the bat's (``pauses``)."""

PAUSE_STARTS_S = (0.06, 0.04, 0.02)
"""s: how long before the approach the ball tracker pauses (``pauses``)."""

PAUSE_LENGTHS_S = (0.06, 0.1, 0.15)
"""s: how long the ball tracker pauses (``pauses``)."""

ARRIVAL_S = 0.0005
"""s: how long after its stamp a bat message is taken (a ball's: that plus its lag)."""

PAUSE_TRAIL_S = 0.5
"""s: how long the pitches of ``pauses`` are tracked after the approach: the bat streams on past
the flag's withdrawal (``kept_flight_span`` after the ball's last sample), as in a session (the
fault tables' pitches end 0.1 s after it, where a hold would outlast the bat's stream)."""


class FlagRun(NamedTuple):
    """What the node's ``~/impact_predicted`` did on one run (``flag_of``)."""

    withdrawn: int  # the watch's withdrawals
    flips: int  # withdrawals the flag came back on after
    first: Optional[float]  # the arrival (s) of the first withdrawal
    solved: Optional[float]  # the arrival (s) of the message that solved the first contact
    instant: Optional[float]  # the instant (s, stamps' clock) the first withdrawal withdrew
    raised: bool  # whether the flag was ever on
    on_at_end: bool  # whether it was on after the last message


def flag_of(config: DetectorConfig, samples: Samples, lag: float,
            pause: Tuple[int, Optional[int]], flushed: bool) -> FlagRun:
    """
    Return what the node's ``~/impact_predicted`` does on a ball tracker that pauses.

    The node's rule (``ImpactNode._take``): messages taken in arrival order (the bat's
    ``ARRIVAL_S`` after their stamps, the ball's ``lag`` later), the flag on at a prediction
    (not one made before a contact solved in the same ``add``), off at a contact, at a
    ``PredictionCleared``, or once ``PredictionWatch.passed`` says the prediction has passed
    (its flight span ``kept_flight_span`` of ``prediction_window``). The ball's samples
    stamped in ``pause`` [start, end) ns come at once after it (``flushed``: a tracker that
    caught up) or never (lost); an end of None: the ball lost for good from start on.
    """
    start, end = pause
    arrivals = []
    for stamp, role, values in samples.messages('pose'):
        taken = (stamp - samples.start_ns) * 1e-9 + ARRIVAL_S
        if role == 'ball':
            if start <= stamp and (end is None or stamp < end):
                if not flushed or end is None:
                    continue
                taken = (end - samples.start_ns) * 1e-9 + ARRIVAL_S
            taken += lag
        arrivals.append((taken, stamp, role, values))
    arrivals.sort(key=lambda row: row[0])
    contact_ns: List[Optional[int]] = [None]
    detector = Detector(config, on_contact=lambda stamp_ns, point: contact_ns.__setitem__(
        0, stamp_ns))
    watch = PredictionWatch(('ball', 'bat_pose'))
    span = kept_flight_span(config.prediction_window)
    last_arrival: Dict[str, float] = {}
    previous: Dict[str, int] = {}
    flag, raised, withdrawn, flips, first, solved, instant = (
        False, False, 0, 0, None, None, None)
    for taken, stamp, role, values in arrivals:
        contact_ns[0] = None
        last_arrival[role] = taken
        events = detector.add(role, stamp, values, 'world')
        if detector.stats.last_drop_reason is None:
            watch.accepted(role, stamp, previous.get(role), taken)
            previous[role] = stamp
        if contact_ns[0] is not None:
            flag, solved = False, taken if solved is None else solved
        for event in events:
            if isinstance(event, Prediction):
                if (contact_ns[0] is None or event.made_at_ns >= contact_ns[0]) and (
                        watch.raises(event.stamp_ns, config.max_gap)):
                    if not flag and withdrawn > flips and first is not None:
                        flips += 1
                    flag, raised, watch.instant_ns = True, True, event.stamp_ns
            elif isinstance(event, PredictionCleared):
                flag = False
        if flag and watch.passed(taken, last_arrival, config.max_gap, span):
            flag, withdrawn = False, withdrawn + 1
            if first is None:
                first, instant = taken, (watch.instant_ns - samples.start_ns) * 1e-9
    return FlagRun(withdrawn, flips, first, solved, instant, raised, flag)


def pauses(seeds: int) -> None:
    """
    Print how often a ball tracker's pause turns ``~/impact_predicted`` off, and on again.

    Every swing family x ``seeds`` x ``FAULT_KINDS``, 90 and 360 Hz, exact and 1 mm, the node's
    defaults and ``analyze --predict``'s detector; the ball ``PAUSE_LAGS_S`` behind the bat,
    pausing ``PAUSE_STARTS_S`` before the approach for ``PAUSE_LENGTHS_S``, its samples then
    flushed or lost (``flag_of``; tracked ``PAUSE_TRAIL_S`` past the approach). Counted: runs
    whose flag the watch turned off, those it came back on after (flips), and hits whose flag
    it turned off before their contact was solved (from the samples after the pause), in all
    and by pause length. Then the ball lost for good from those starts (``gone``): runs
    whose flag was on, those it stayed on to the end (never withdrawn: must be 0), and how long
    after the predicted instant the watch withdrew it (median and largest, ms: the cost of
    holding it through a silence).
    """
    print('\n| ball paused | rate Hz | noise mm | parameters | runs | flag withdrawn | of which '
          'on again (flips) | hits withdrawn before their contact was solved | by pause '
          + ' / '.join(f'{length * 1e3:g}' for length in PAUSE_LENGTHS_S) + ' ms |')
    print('|---|---|---|---|---|---|---|---|---|')
    for flushed in (True, False):
        for rate in (90.0, 360.0):
            for noise_m in (0.0, 0.001):
                for name, config in node_configs().items():
                    runs = withdrawn = flipped = 0
                    early = dict.fromkeys(PAUSE_LENGTHS_S, 0)
                    for samples, hit, approach in _long_pitches(rate, noise_m, seeds):
                        for lag in PAUSE_LAGS_S:
                            for before in PAUSE_STARTS_S:
                                for length in PAUSE_LENGTHS_S:
                                    start = approach - int(round(before * 1e9))
                                    run = flag_of(config, samples, lag,
                                                  (start, start + int(round(length * 1e9))),
                                                  flushed)
                                    runs += 1
                                    withdrawn += run.withdrawn > 0
                                    flipped += run.flips > 0
                                    early[length] += hit and run.first is not None and (
                                        run.solved is not None and run.first < run.solved)
                    print(f"| {'flushed' if flushed else 'lost'} | {rate:g} | "
                          f'{noise_m * 1e3:g} | {name} | {runs} | {withdrawn} | {flipped} | '
                          f'{sum(early.values())} | '
                          + ' / '.join(str(count) for count in early.values()) + ' |',
                          flush=True)
    print('\n| ball lost for good | rate Hz | noise mm | parameters | runs | flag raised | never '
          'withdrawn | withdrawn after the predicted instant, p50 / max ms |')
    print('|---|---|---|---|---|---|---|---|')
    for rate in (90.0, 360.0):
        for noise_m in (0.0, 0.001):
            for name, config in node_configs().items():
                runs = raised = stayed = 0
                late: List[float] = []
                for samples, _, approach in _long_pitches(rate, noise_m, seeds):
                    for lag in PAUSE_LAGS_S:
                        for before in PAUSE_STARTS_S:
                            run = flag_of(config, samples, lag,
                                          (approach - int(round(before * 1e9)), None), False)
                            runs += 1
                            raised += run.raised
                            stayed += run.on_at_end
                            if run.first is not None:
                                late.append((run.first - run.instant) * 1e3)
                spread = f'{np.median(late):.0f} / {max(late):.0f}' if late else '-'
                print(f'| gone | {rate:g} | {noise_m * 1e3:g} | {name} | {runs} | {raised} | '
                      f'{stayed} | {spread} |', flush=True)


def _long_pitches(rate: float, noise_m: float,
                  seeds: int) -> Iterator[Tuple[Samples, bool, int]]:
    """
    Yield ``_fault_pitches``' pitches tracked ``PAUSE_TRAIL_S`` past the approach instead.

    Each as (``Samples``, whether it is a hit, the contact's or closest approach's stamp, ns).
    """
    for family in FAMILIES:
        for seed in range(seeds):
            for kind in FAULT_KINDS:
                rng = np.random.default_rng(seed)
                scenario = make_scenario(kind, rng, lead_s=0.4, family=family,
                                         trail_s=PAUSE_TRAIL_S)
                samples = sample(scenario, rate, rng, jitter_s=2e-4, noise_m=noise_m)
                truth = truth_dict(scenario, samples.start_ns)
                hit = scenario.truth.contact
                yield samples, hit, (truth['stamp_ns'] if hit else (
                    samples.start_ns + int(round(scenario.truth.min_gap_time_s * 1e9))))


def faults(seeds: int, chunks: bool, lost_only: bool = False, ball_only: bool = False) -> None:
    """
    Print what tracker faults cost the prediction (see the module), one row a cell.

    The turned and stamped frames (``fault_cell``), then the glitch beside lost frames
    (``lost_cell``), one row a cell and placement; ``lost_only``: only that; ``ball_only``:
    only a ball glitch's (``ball_cell``).
    """
    if ball_only:
        _cells_table('ball glitch', ball_cell, seeds, chunks)
        return
    if not lost_only:
        _cells_table('fault', fault_cell, seeds, chunks)
    _cells_table('glitch beside lost frames', lost_cell, seeds, chunks)


def _cells_table(first_column: str, cells_of: Callable[..., Dict[str, Dict[str, int]]],
                 seeds: int, chunks: bool) -> None:
    """Print ``cells_of``'s counts (``fault_cell``'s) a row each, at 90 and 360 Hz, 0 and 1 mm."""
    print(f'\n| {first_column} | rate Hz | noise mm | parameters | hits lost '
          f'{FAULT_LEAD_S * 1e3:g} ms ahead (clean '
          'had it) | of them lost without the frame too | gained | misses with a false '
          'prediction (clean none) | misses predicted at a frame clean was not | chunk path '
          'differs |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    for rate in (90.0, 360.0):
        for noise_m in (0.0, 0.001):
            for name, config in node_configs().items():
                for label, cell in cells_of(rate, noise_m, config, seeds, chunks).items():
                    print(f"| {label} | {rate:g} | {noise_m * 1e3:g} | {name} | "  # noqa: Q000
                          f"{cell['lost']} of {cell['hits']} ({cell['clean_hits']}) | "
                          f"{cell['deleted_too']} | {cell['gained']} | "
                          f"{cell['false']} of {cell['misses']} | {cell['longer']} | "
                          f"{cell['chunk_differs'] if chunks else '-'} |", flush=True)


ARM_GLITCH_BEFORE_S = (0.15, 0.1, 0.06)
"""s: ``--arm-glitch`` moves the ball sample nearest this long before the contact."""

ARM_GLITCH_M = ((0.0, 0.0, 0.1), (0.0, 0.0, -0.03))
"""m: how far ``--arm-glitch`` moves it (up 10 cm, down 3 cm); also it and the next one both
up 10 cm (two glitches side by side)."""


def calibration(per_family: int, seed: int, period: float, spin: bool,
                families: Tuple[str, ...], planned: bool = True) -> None:
    """
    Print how often a prediction's error is within its 1 and 2 sigma, by noise and lead.

    ``per_family`` pitches of each swing family of ``families`` (barrel, end cap and handle hits
    in turn), the arm's plan at 200 Hz (``plan_of``) where ``planned``, else the bat
    extrapolated from its frames (its own lead bands: such predictions come 0-120 ms ahead),
    sampled at 90 and 360 Hz with 0.2 ms of jitter and 0,
    0.5, 1 and 2 mm of noise, the node's defaults but ``prediction_period`` ``period``
    (``tracker_noise`` auto: the ball's own estimate). Every prediction made from 0.4 s before
    the contact on is scored: its instant's and its spot's (distance from the tip) error over
    their sigmas (``time_uncertainty_s``, ``distance_from_tip_uncertainty_m``), pooled in lead
    bands; a calibrated sigma has 68 % within 1 and 95 % within 2. Beside them the sigmas'
    median and the errors' rms (of the band). A prediction without a time sigma (none closes) is
    counted beside them.
    """
    bands = ((0.0, 0.05), (0.05, 0.15), (0.15, 0.3)) if planned else (
        (0.0, 0.015), (0.015, 0.03), (0.03, 0.06), (0.06, 0.3))
    rng = np.random.default_rng(seed)
    scenarios = [make_scenario(('barrel', 'end_cap', 'handle')[i % 3], rng, lead_s=0.4,
                               family=family, spin=spin)
                 for family in families for i in range(per_family)]
    print(f"\n{len(scenarios)} {'planned' if planned else 'extrapolated'} contacts "
          f'({per_family} a family: '
          f"{', '.join(families)}), every {period * 1e3:g} ms"
          f"{', spinning pitches' if spin else ''}\n")
    print('| rate Hz | noise mm | lead ms | predictions | time within 1 / 2 sigma | sigma p50 '
          'us | error rms us | spot within 1 / 2 sigma | sigma p50 mm | error rms mm |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    for rate in (90.0, 360.0):
        for noise in (0.0, 0.0005, 0.001, 0.002):
            rows: List[Tuple[float, float, float, float, float]] = []
            without = 0
            for i, scenario in enumerate(scenarios):
                samples = sample(scenario, rate, np.random.default_rng(1000 + i),
                                 jitter_s=2e-4, noise_m=noise)
                detector = Detector(DetectorConfig(prediction_horizon=0.3,
                                                   prediction_period=period))
                if planned:
                    detector.set_bat_plan(*plan_of(scenario, samples.start_ns))
                truth = truth_dict(scenario, samples.start_ns)
                for stamp, role, values in samples.messages('pose'):
                    for event in detector.add(role, stamp, values):
                        if not isinstance(event, Prediction) or event.made_at_ns >= \
                                truth['stamp_ns']:
                            continue
                        if event.time_uncertainty_s is None:
                            without += 1
                        else:
                            rows.append((
                                event.lead_s, (event.stamp_ns - truth['stamp_ns']) * 1e-9,
                                event.time_uncertainty_s,
                                event.distance_from_tip_m - truth['distance_from_tip_m'],
                                event.distance_from_tip_uncertainty_m))
            table = np.array(rows).reshape(-1, 5)
            for low, high in bands:
                band = table[(table[:, 0] >= low) & (table[:, 0] < high)]
                if not len(band):
                    continue
                cells = []
                for error, sigma, unit in ((band[:, 1], band[:, 2], 1e6),
                                           (band[:, 3], band[:, 4], 1e3)):
                    z = np.abs(error) / np.maximum(sigma, 1e-15)
                    cells.append(f'{np.mean(z <= 1):.0%} / {np.mean(z <= 2):.0%} | '
                                 f'{np.median(sigma) * unit:.1f} | '
                                 f'{np.sqrt(np.mean(error ** 2)) * unit:.1f}')
                print(f'| {rate:g} | {noise * 1e3:g} | {low * 1e3:g}-{high * 1e3:g} | '
                      f'{len(band)} | ' + ' | '.join(cells) + ' |')
            if without:
                print(f'| {rate:g} | {noise * 1e3:g} | (no time sigma) | {without} | |||||')


def arm_glitches(per_kind: int, seed: int, period: float) -> None:
    """
    Print what one ball glitch costs an arm's predictions (the bat its commanded plan).

    The accuracy table's hits (``per_kind`` of each kind, 1 mm of noise) at 90 and 360 Hz, each
    clean and with one ball sample moved (``ARM_GLITCH_M``, the sample nearest each of
    ``ARM_GLITCH_BEFORE_S`` before the contact, or it and the next; the positions replaced in
    place, so the tree before ``Samples.with_ball_frame_moved`` runs it too): per lead, the
    hits with a prediction in force and its point's error p50 / max (cm).
    """
    rng = np.random.default_rng(seed)
    scenarios = [make_scenario(kind, rng, lead_s=0.4) for kind in ('barrel', 'end_cap', 'handle')
                 for _ in range(per_kind)]
    print(f"\n{len(scenarios)} hits, 1 mm, the arm's plan, prediction_period {period:g} s\n")
    print('| rate Hz | ball glitch | ' + ' | '.join(f'{lead * 1e3:g} ms ahead' for lead in LEADS_S)
          + ' |')
    print('|---|---|' + '---|' * len(LEADS_S))
    for rate in (90.0, 360.0):
        cases = [('none', None, None, 0)] + [
            (f'{offset[2] * 100:+g} cm {before * 1e3:g} ms before', before, offset, 1)
            for before in ARM_GLITCH_BEFORE_S for offset in ARM_GLITCH_M] + [
            (f'two side by side +10 cm {before * 1e3:g} ms before', before, ARM_GLITCH_M[0], 2)
            for before in ARM_GLITCH_BEFORE_S]
        for label, before, offset, count in cases:
            scored = {lead: [] for lead in LEADS_S}
            for i, scenario in enumerate(scenarios):
                samples = sample(scenario, rate, np.random.default_rng(i), jitter_s=2e-4,
                                 noise_m=0.001)
                if offset is not None:
                    stamps = samples.ball_stamps_ns - samples.start_ns
                    j = int(np.argmin(np.abs(stamps * 1e-9 - scenario.truth.time_s + before)))
                    positions = samples.ball_positions.copy()
                    positions[j:j + count] += offset
                    samples = replace(samples, ball_positions=positions)
                config = DetectorConfig(model='rigid', prediction_horizon=0.3,
                                        prediction_period=period)
                for lead, error in scored_predictions(scenario, samples, config, True).items():
                    if error is not None:
                        scored[lead].append(error[1] * 100.0)
            print(f'| {rate:g} | {label} | ' + ' | '.join(
                f'{len(got)}/{len(scenarios)}, {np.median(got):.1f} / {max(got):.1f}'
                if got else f'0/{len(scenarios)}' for got in scored.values()) + ' |', flush=True)


def main() -> None:
    """Print the prediction table."""
    global FAULT_LEAD_S, SCORE_SENT  # (``scored`` and ``predictions_of`` read them)
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[1].strip())
    parser.add_argument('--per-kind', type=int, default=20)
    parser.add_argument('--seed', type=int, default=11)
    parser.add_argument('--noise', type=float, default=0.001)
    parser.add_argument('--cost-only', action='store_true', help='only the cost table')
    parser.add_argument('--spin', action='store_true', help='spinning pitches (the Magnus '
                        "force: make_scenario's spin)")
    parser.add_argument('--no-lift', action='store_true', help='the ball forecast of gravity '
                        'and drag alone, without its lift (before session 62)')
    parser.add_argument('--period', type=float, default=0.0,
                        help='prediction_period of the accuracy table (s; 0: every frame)')
    parser.add_argument('--changes', action='store_true',
                        help='only how much consecutive predictions move (every 10 ms)')
    parser.add_argument('--calibration', action='store_true',
                        help="only how well a planned prediction's sigmas cover its errors")
    parser.add_argument('--extrapolated', action='store_true',
                        help='--calibration: of the bat extrapolated (no plan), every family')
    parser.add_argument('--arm-glitch', action='store_true',
                        help="only one ball glitch's cost to an arm's predictions (the plan)")
    parser.add_argument('--ball-only', action='store_true',
                        help='with --faults: only a ball glitch (ball_cell)')
    parser.add_argument('--faults', action='store_true',
                        help='only what bat-tracker faults cost the prediction')
    parser.add_argument('--seeds', type=int, default=2, help='pitches a family and kind '
                        '(--faults)')
    parser.add_argument('--pauses-only', action='store_true',
                        help='--faults: only the ball tracker that pauses')
    parser.add_argument('--chunks', action='store_true',
                        help='--faults: also compare the chunk path with one sample at a time')
    parser.add_argument('--lost-only', action='store_true',
                        help='--faults: only the glitch beside lost frames')
    parser.add_argument('--fault-lead', type=float, default=FAULT_LEAD_S,
                        help='--faults: the lead (s) the hits are scored at')
    parser.add_argument('--score-sent', action='store_true',
                        help='--faults: score a prediction from when it is sent, not made')
    args = parser.parse_args()
    if args.score_sent and args.chunks:
        parser.error('--score-sent scores one sample at a time: not with --chunks')
    FAULT_LEAD_S, SCORE_SENT = args.fault_lead, args.score_sent
    single_threaded_blas()  # as the node and analyze run the detector (threads.py)
    if args.faults or args.pauses_only:
        if not args.pauses_only:
            faults(args.seeds, args.chunks, args.lost_only, args.ball_only)
        if not (args.lost_only or args.ball_only):
            pauses(args.seeds)
        return
    if args.cost_only:
        cost(args.seed)
        return
    if args.calibration:
        if args.extrapolated:
            calibration(args.per_kind, args.seed, args.period or 0.01, args.spin, FAMILIES,
                        planned=False)
            return
        for families in (SMOOTH_PLANS, BRAKING_PLANS):
            calibration(args.per_kind, args.seed, args.period or 0.01, args.spin, families)
        return
    if args.arm_glitch:
        arm_glitches(args.per_kind, args.seed, args.period)
        return
    if args.changes:
        changes()
        return
    rng = np.random.default_rng(args.seed)
    scenarios = [make_scenario(kind, rng, lead_s=0.4, spin=args.spin)
                 for kind in ('barrel', 'end_cap', 'handle') for _ in range(args.per_kind)]
    print(f'{len(scenarios)} contacts, noise {args.noise * 1e3:g} mm, seed {args.seed}, '
          f"prediction_period {args.period:g} s{', spinning pitches' if args.spin else ''}"
          f"{', no lift' if args.no_lift else ''}\n")
    print('| bat | rate Hz | lead ms | predicted | time err p50 ms | p90 ms | max ms | '
          'point err p50 cm | p90 cm | max cm |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    for planned in (False, True):
        for rate in (90.0, 360.0):
            runs = [errors(s, rate, args.noise, planned, i, args.period,
                           0.0 if args.no_lift else DEFAULTS['lift_window'])
                    for i, s in enumerate(scenarios)]
            for lead in LEADS_S:
                got = [r[lead] for r in runs if r[lead] is not None]
                times = np.abs([g[0] for g in got]) if got else np.array([np.nan])
                points = np.array([g[1] for g in got]) if got else np.array([np.nan])
                print(f"| {'planned' if planned else 'extrapolated'} | {rate:g} | "
                      f'{lead * 1e3:g} | {len(got)}/{len(runs)} | {np.median(times):.2f} | '
                      f'{np.percentile(times, 90):.2f} | {times.max():.2f} | '
                      f'{np.median(points):.1f} | {np.percentile(points, 90):.1f} | '
                      f'{points.max():.1f} |')
    cost(args.seed)


if __name__ == '__main__':
    main()
