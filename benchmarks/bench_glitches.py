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
interval closed (a hit waiting for the frame after its closing one: ``Sweep._closing_glitch``).

    .venv/bin/python benchmarks/bench_glitches.py [--seeds 2] [--rates 90 360]
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


def events_of(config: DetectorConfig, samples: Any,
              late: Optional[List[int]] = None) -> Tuple[Detector, List[Any]]:
    """
    Return a fresh detector fed ``samples`` one message at a time, and its events.

    :param late: when given, each impact's latency is appended to it: how long (ns) after its
        interval closed the message came whose ``add`` reported it (``finish``'s: the last).
    """
    detector, events = Detector(config), []
    for stamp, role, values in samples.messages(config.bat_input):
        found = detector.add(role, stamp, values)
        if late is not None:
            late += [stamp - event.interval_end_ns for event in of(found, Impact)]
        events += found
    return detector, events + detector.finish()


def of(events: List[Any], kind: type) -> List[Any]:
    """Return the events of one kind."""
    return [event for event in events if isinstance(event, kind)]


def run_cell(rate: float, noise_m: float, seeds: int) -> Dict[str, Any]:
    """Return one rate and noise level's counts and near-miss differences."""
    counts = dict.fromkeys(('misses', 'invented', 'hits', 'lost', 'moved', 'dropped',
                            'clean', 'clean_dropped', 'clean_hits', 'waited'), 0)
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
                for parameters in ({}, OFFLINE_PARAMETERS):
                    config = DetectorConfig(**{**parameters, 'bat_input': bat})
                    late: List[int] = []
                    detector, events = events_of(config, samples, late)
                    counts['clean'] += 1
                    counts['clean_dropped'] += detector.stats.dropped.get('bat_glitch', 0)
                    if not parameters:  # the node's look-ahead 0: reported as its interval closes
                        counts['clean_hits'] += len(late)
                        counts['waited'] += sum(wait > 0.5 * step_ns for wait in late)
                    for offset in OFFSETS:
                        j = middle + offset
                        _, deleted = events_of(config, samples.without_bat_frame(j))
                        for turn in TURNS_M:
                            glitched = samples.with_bat_frame_turned(
                                j, samples.ball_positions[min(j, len(samples.ball_positions)
                                                              - 1)], turn)
                            detector, events = events_of(config, glitched)
                            counts['dropped'] += detector.stats.dropped.get('bat_glitch', 0)
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
    args = parser.parse_args()
    for rate in args.rates:
        for noise_mm in args.noises:
            cell = run_cell(rate, noise_mm * 1e-3, args.seeds)
            gaps = np.array(cell['gaps']) * 1e3
            spread = (f'p50 {np.percentile(gaps, 50):.2f} mm, p99 {np.percentile(gaps, 99):.2f} '
                      f'mm, max {gaps.max():.2f} mm' if len(gaps) else '-')
            print(f"{rate:g} Hz, {noise_mm:g} mm: misses {cell['misses']}, invented "
                  f"{cell['invented']}; hits {cell['hits']}, lost {cell['lost']}, moved "
                  f"{cell['moved']}; bat_glitch drops {cell['dropped']}; near miss from the "
                  f"deleted frame's {spread}; without a glitch {cell['clean']} runs, "
                  f"bat_glitch drops {cell['clean_dropped']}, the node's hits reported a bat "
                  f"frame late {cell['waited']} of {cell['clean_hits']}", flush=True)


if __name__ == '__main__':
    main()
