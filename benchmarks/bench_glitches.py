"""
One bat frame off the swing near the ball: invented impacts, frames dropped, the pass reported.

A tracker's glitch (a rigid body solved onto the wrong markers, a swapped marker): one bat frame
turned about its knob so that its tip moves 10 or 20 cm toward the ball
(``Samples.with_bat_frame_turned``), at the frames around the closest approach (or contact) of
misses passing 3-15 cm from the bat and of hits, in every swing family, at 90 and 360 Hz,
exact and with 1 mm of noise, under the node's defaults and ``analyze``'s, the bat as a pose
and as knob and tip points by turns. The baseline in the same run: the same samples with that
frame deleted. Printed per rate and noise: invented impacts (on misses), hits lost or moved by
more than 0.1 ms from the deleted-frame run, ``bat_glitch`` drops, how far each near miss is
from the deleted-frame run's, ``bat_glitch`` drops on the same pitches without a glitch, and of
their hits under the node's defaults those reported more than half a bat step after their
interval closed (a hit waiting for the frame after its closing one: ``Sweep._closing_glitch``;
or, at a segment's start, for the frames after an early one: ``Sweep._early_bat_glitch``).

Beside frames the tracker lost: ``--lost K`` deletes the bat frame K frames from the glitch
(-2: two before it, 1: right after it) from both runs, the glitched and the baseline (one line
per K); with ``--lost-frames N``, N frames from there on away from the glitch (-1 with 2: the
two before it; at 120 Hz a hole of 25 ms, over ``bat_glitches.LOST_HOLE``). At a segment's
start: ``--segment N`` deletes the bat frames over ``max_gap`` (60 ms) before the glitch's
N - 1 frames before it, so that the glitch is its segment's Nth frame (1: its first).
``--offsets`` and ``--turns`` narrow the frames turned and how far (cm). ``--told``: the
detector is told the samples' noise (``tracker_noise``), not estimating it (auto, the node's
and ``analyze``'s default).

    .venv/bin/python benchmarks/bench_glitches.py [--seeds 2] [--rates 90 360]
    bench_glitches.py --rates 90 120 360 --lost -3 -2 -1 1 --offsets -1 0 1 --turns 10
    bench_glitches.py --rates 120 --lost -3 -2 -1 1 2 --lost-frames 2
    bench_glitches.py --rates 90 120 360 --segment 1 4 8 --offsets -1 0 1 --turns 10
    bench_glitches.py --rates 120 --noises 1 --segment 1 --told
"""

import argparse
from typing import Any, Dict, List, Optional, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, Impact, NearMiss
from baseball_collision.tools.parameters import OFFLINE_PARAMETERS
from baseball_collision.tools.sim import FAMILIES, make_scenario, sample
import numpy as np

OFFSETS = (-2, -1, 0, 1, 2)
"""Frames from the closest approach's (or the contact's) the turned frame is at."""

TURNS_M = (0.1, 0.2)
"""How far the turned frame's tip moves toward the ball (m)."""

MOVED_NS = 100_000
"""A hit more than this far (ns) from the deleted-frame run's is moved."""

SEGMENT_GAP_S = 0.06
"""s: the bat frames deleted before a segment's first frame (``--segment``): over ``max_gap``."""


def faulted(samples: Any, j: int, lost: Optional[int], segment: Optional[int],
            lost_frames: int = 1) -> Tuple[Any, int]:
    """
    Return the samples with the tracker's lost frames about bat frame j, and j's index then.

    :param lost: delete the frame this many frames from j (not 0), else None.
    :param lost_frames: with ``lost``, delete this many frames from that one on, away from j.
    :param segment: delete the frames over ``SEGMENT_GAP_S`` before the frame ``segment`` - 1
        before j (j its segment's ``segment``-th frame), else None.
    """
    if lost is not None:
        first = j + lost - (lost_frames - 1 if lost < 0 else 0)
        stamps = samples.bat_stamps_ns
        end = int(stamps[first + lost_frames]) if first + lost_frames < len(stamps) \
            else int(stamps[-1]) + 1
        return samples.without_bat_frames(end, lost_frames), j - lost_frames * (lost < 0)
    if segment is not None:
        stamps = samples.bat_stamps_ns
        count = int(np.ceil(SEGMENT_GAP_S * (len(stamps) - 1) / ((stamps[-1] - stamps[0]) * 1e-9)))
        return samples.without_bat_frames(int(stamps[j - segment + 1]), count), j - count
    return samples, j


def events_of(config: DetectorConfig, samples: Any, late: Optional[List[int]] = None,
              glitches: Optional[List[int]] = None) -> Tuple[Detector, List[Any]]:
    """
    Return a fresh detector fed ``samples`` one message at a time, and its events.

    :param late: when given, each impact's latency is appended to it: how long (ns) after its
        interval closed the message came whose ``add`` reported it (``finish``'s: the last).
    :param glitches: when given, the stamp (ns) of each bat frame dropped as ``bat_glitch`` is
        appended to it.
    """
    detector, events = Detector(config), []
    for stamp, role, values in samples.messages(config.bat_input):
        found = detector.add(role, stamp, values)
        if late is not None:
            late += [stamp - event.interval_end_ns for event in of(found, Impact)]
        if glitches is not None:
            glitches += [drop.stamp_ns for drop in detector.stats.late_drops
                         if drop.reason.value == 'bat_glitch']
        events += found
    found = detector.finish()
    if glitches is not None:
        glitches += [drop.stamp_ns for drop in detector.stats.late_drops
                     if drop.reason.value == 'bat_glitch']
    return detector, events + found


def of(events: List[Any], kind: type) -> List[Any]:
    """Return the events of one kind."""
    return [event for event in events if isinstance(event, kind)]


def run_cell(rate: float, noise_m: float, seeds: int, lost: Optional[int] = None,
             segment: Optional[int] = None, offsets: Tuple[int, ...] = OFFSETS,
             turns: Tuple[float, ...] = TURNS_M, lost_frames: int = 1,
             told: bool = False) -> Dict[str, Any]:
    """
    Return one rate and noise level's counts and near-miss differences.

    ``lost``, ``lost_frames`` and ``segment``: the tracker's lost frames about the glitch
    (``faulted``), in the runs without a glitch too; ``offsets``, ``turns``: the frames
    turned, how far (m); ``told``: ``tracker_noise`` the samples' noise (m), else auto.
    """
    counts = dict.fromkeys(('misses', 'invented', 'hits', 'lost', 'moved', 'dropped',
                            'wrong', 'clean', 'clean_dropped', 'clean_hits', 'waited'), 0)
    gaps: List[float] = []
    step_ns = 1e9 / rate
    for family in FAMILIES:
        for seed in range(seeds):
            for kind in ('miss_over', 'miss_under', 'barrel'):
                rng = np.random.default_rng(seed)
                scenario = make_scenario(kind, rng, family=family)
                samples = sample(scenario, rate, rng, noise_m=noise_m)
                closest = samples.start_ns + int(scenario.truth.min_gap_time_s * 1e9)
                middle = int(np.argmin(np.abs(samples.bat_stamps_ns - closest)))
                bat = ('pose', 'points')[seed % 2]
                if lost is not None or segment is not None:
                    clean_runs = [faulted(samples, middle + offset, lost, segment,
                                          lost_frames)[0]
                                  for offset in offsets]
                else:
                    clean_runs = [samples]
                for parameters in ({}, OFFLINE_PARAMETERS):
                    config = DetectorConfig(**{**parameters, 'bat_input': bat,
                                               **({'tracker_noise': noise_m} if told else {})})
                    for clean in clean_runs:
                        late: List[int] = []
                        detector, events = events_of(config, clean, late)
                        counts['clean'] += 1
                        counts['clean_dropped'] += detector.stats.dropped.get('bat_glitch', 0)
                        if not parameters:  # the node's look-ahead 0: reported as it closes
                            counts['clean_hits'] += len(late)
                            counts['waited'] += sum(wait > 0.5 * step_ns for wait in late)
                    for offset in offsets:
                        j = middle + offset
                        without, at = faulted(samples, j, lost, segment, lost_frames)
                        _, deleted = events_of(config, without.without_bat_frame(at))
                        for turn in turns:
                            toward = samples.ball_positions[min(
                                j, len(samples.ball_positions) - 1)]
                            glitched = faulted(samples.with_bat_frame_turned(j, toward, turn),
                                               j, lost, segment, lost_frames)[0]
                            drops: List[int] = []
                            detector, events = events_of(config, glitched, glitches=drops)
                            counts['dropped'] += detector.stats.dropped.get('bat_glitch', 0)
                            counts['wrong'] += sum(stamp != samples.bat_stamps_ns[j]
                                                   for stamp in drops)
                            if scenario.truth.contact:
                                counts['hits'] += 1
                                found, expected = of(events, Impact), of(deleted, Impact)
                                if not found:
                                    counts['lost'] += 1
                                elif expected and abs(found[0].stamp_ns
                                                      - expected[0].stamp_ns) > MOVED_NS:
                                    counts['moved'] += 1
                                continue
                            counts['misses'] += 1
                            counts['invented'] += bool(of(events, Impact))
                            passes, expected = of(events, NearMiss), of(deleted, NearMiss)
                            if passes and expected:
                                gaps.append(abs(min(p.gap_m for p in passes)
                                                - min(p.gap_m for p in expected)))
    return {**counts, 'gaps': gaps}


def main() -> None:
    """Print one line per rate and noise level."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--rates', type=float, nargs='+', default=[90.0, 360.0])
    parser.add_argument('--noises', type=float, nargs='+', default=[0.0, 1.0],
                        help='tracker noise (mm, 1 sigma per coordinate)')
    parser.add_argument('--seeds', type=int, default=2, help='scenarios per family and kind')
    parser.add_argument('--lost', type=int, nargs='+', default=[],
                        help='a bat frame lost this many frames from the glitch (one line each)')
    parser.add_argument('--lost-frames', type=int, default=1,
                        help='frames lost from there on, away from the glitch (with --lost)')
    parser.add_argument('--segment', type=int, nargs='+', default=[],
                        help="the glitch as its bat segment's Nth frame (one line each)")
    parser.add_argument('--offsets', type=int, nargs='+', default=list(OFFSETS),
                        help="the turned frame's, from the closest approach's")
    parser.add_argument('--turns', type=float, nargs='+', default=[t * 100 for t in TURNS_M],
                        help="how far the turned frame's tip moves (cm)")
    parser.add_argument('--told', action='store_true',
                        help="the detector told the samples' noise (tracker_noise), not auto")
    args = parser.parse_args()
    faults = ([('lost', k, None) for k in args.lost] + [('segment', None, n)
                                                        for n in args.segment]
              or [('', None, None)])
    for (name, lost, segment), rate, noise_mm in [
            (fault, rate, noise) for fault in faults for rate in args.rates
            for noise in args.noises]:
        cell = run_cell(rate, noise_mm * 1e-3, args.seeds, lost, segment,
                        tuple(args.offsets), tuple(t * 0.01 for t in args.turns),
                        args.lost_frames, args.told)
        frames = f' ({args.lost_frames} frames)' if args.lost_frames > 1 else ''
        label = {'lost': f'lost {lost}{frames}: ',
                 'segment': f'segment frame {segment}: '}.get(name, '')
        label += 'told: ' if args.told else ''
        gaps = np.array(cell['gaps']) * 1e3
        spread = (f'p50 {np.percentile(gaps, 50):.2f} mm, p99 {np.percentile(gaps, 99):.2f} '
                  f'mm, max {gaps.max():.2f} mm' if len(gaps) else '-')
        print(f"{label}{rate:g} Hz, {noise_mm:g} mm: misses {cell['misses']}, invented "
              f"{cell['invented']}; hits {cell['hits']}, lost {cell['lost']}, moved "
              f"{cell['moved']}; bat_glitch drops {cell['dropped']} (another frame "
              f"{cell['wrong']}); near miss from the "
              f"deleted frame's {spread}; without a glitch {cell['clean']} runs, "
              f"bat_glitch drops {cell['clean_dropped']}, the node's hits reported a bat "
              f"frame late {cell['waited']} of {cell['clean_hits']}", flush=True)


if __name__ == '__main__':
    main()
