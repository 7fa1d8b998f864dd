"""
The ball tracked again one to three frames before the contact: hits found, invented, glitches.

A tracker that lost the ball (occluded) finds it again just before the bat: ``DROPOUT_S`` of the
ball's samples are deleted, ending 1, 2 or 3 frames before the contact (the stream restarts
there, a gap over ``max_gap``: ``bench_accuracy.dropped_ball``). Barrel, end-cap and handle hits
of every swing family (``rebound``: the ball leaves the bat; the others fly on through it), and
misses passing 2-15 cm over and under the bat, at each rate, exact and with 1 mm of noise (the
bat a pose, as a rigid body over markers 0.3 m apart), under the node's defaults (``c2``,
look-ahead 0, ``tracker_noise`` auto; ``--told``: the noise told, 0 or 1 mm) and ``analyze``'s
(``OFFLINE_PARAMETERS``: look-ahead 2, auto noise). Printed per rate and noise:

- hits: found (an impact within ``FOUND_NS`` of the truth) of all, the time error against the
  truth (p50 / p99 / max, us; how many within two of their reported sigmas), and against the
  same run without the gap (runs more than 1 us off, of those found in both; and the largest);
- misses with an impact invented;
- the segment's first sample a glitch (moved onto the bat's axis, or 6 cm from it toward where
  it was): misses with an impact invented, hits found (against the run with that frame
  deleted), and ``ball_glitch`` drops;
- with ``--chunks``, runs whose events differ fed through ``add_chunk`` (chunks of 7, 50 and
  400 messages) from one message at a time.

``--contact-ms``: the simulated rebound's contact lasts that long (``Pitch.rebound_duration``,
0.6 ms by default; the detector is not told: ``departure.CONTACT_TIME`` stays 0.6 ms).

``--gap-ms``: the dropout lasts that long instead of ``DROPOUT_S`` (80 ms), one block per
length; the ball is then tracked from ``--before-ms`` (150 ms: the fits' kept history) before
the gap (the scenario's ``lead_s``: the gap, that and the frames back before the contact; a
pitch flies about 0.42 s from a 16.5-17 m release at 76-94 mph, so a gap with 150 ms before it
over about 250 ms is longer than a real pitch tracked from its release allows).

    .venv/bin/python benchmarks/bench_ball_gap.py [--seeds 2] [--rates 90 120 360] [--chunks]
        [--noises 0 1] [--families rebound ...] [--told] [--contact-ms 0.4]
        [--gap-ms 150 250 400] [--before-ms 150]
"""

import argparse
from collections import Counter
from dataclasses import replace
from pathlib import Path
import sys
from typing import Any, Dict, List, Optional, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, Impact
from baseball_collision.core.detector.chunks import ROLE_CODES
from baseball_collision.core.detector.events import DropReason
from baseball_collision.tools.parameters import OFFLINE_PARAMETERS
from baseball_collision.tools.sim import FAMILIES, make_scenario, sample, Samples, Scenario
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'test'))
from bench_accuracy import DROPOUT_S, dropped_ball  # noqa: E402, I100
from support.events import on_bat_axis  # noqa: E402, I100

HITS = ('barrel', 'end_cap', 'handle')
MISSES = ('miss_over', 'miss_under')
BACK = (1, 2, 3)
"""Ball frames before the contact (or the closest approach) after the gap."""

FOUND_NS = 2_000_000
"""An impact this near (ns) the true contact finds it; any other is invented."""

GLITCH_M = (0.0, 0.06, 0.1)
"""How far (m) from the bat's axis the glitched first sample is put."""

CHUNKS = (7, 50, 400)


def configs(noise_m: float, told: bool = False) -> Dict[str, DetectorConfig]:
    """
    Return the node's and ``analyze``'s configurations for one noise level.

    The node's defaults (``c2``, look-ahead 0, ``tracker_noise`` auto), or with ``told`` the
    noise told (``noise_m``); ``analyze``'s (``OFFLINE_PARAMETERS``: look-ahead 2, auto).
    """
    node = DetectorConfig(bat_input='pose', **({'tracker_noise': noise_m} if told else {}))
    return {'node': node, 'analyze': DetectorConfig(bat_input='pose', **OFFLINE_PARAMETERS)}


def run(config: DetectorConfig, samples: Samples,
        chunks: bool = False) -> Tuple[List[Any], Counter, Optional[bool]]:
    """
    Return a fresh detector's events and drops (by reason) fed ``samples`` one at a time.

    With ``chunks``, also whether ``add_chunk`` gave the same events and drops (else None).
    """
    messages = samples.messages(config.bat_input)
    detector, events, drops = Detector(config), [], Counter()
    for stamp, role, values in messages:
        events += detector.add(role, stamp, values)
        if detector.stats.last_drop_reason is not None:
            drops[detector.stats.last_drop_reason] += 1
        drops.update(late.reason for late in detector.stats.late_drops)
    events += detector.finish()
    drops.update(late.reason for late in detector.stats.late_drops)
    same = None
    if chunks:
        chunked, chunk_events, chunk_drops, i, k = Detector(config), [], Counter(), 0, 0
        while i < len(messages):
            part = messages[i:i + CHUNKS[k % len(CHUNKS)]]
            values = np.zeros((len(part), 7))
            for row, (_, _, value) in enumerate(part):
                values[row, :len(value)] = value
            tally: Counter = Counter()
            chunk_events += chunked.add_chunk([ROLE_CODES[role] for _, role, _ in part],
                                              [stamp for stamp, _, _ in part], values,
                                              ['world'] * len(part), tally)
            chunk_drops.update({reason: n for (_, reason), n in tally.items()})
            i, k = i + len(part), k + 1
        chunk_events += chunked.finish()
        chunk_drops.update(late.reason for late in chunked.stats.late_drops)
        same = chunk_events == events and chunk_drops == drops
    return events, drops, same


def impact_stamps(events: List[Any]) -> List[int]:
    """Return the impacts' stamps (ns)."""
    return [event.stamp_ns for event in events if isinstance(event, Impact)]


def moment_ns(scenario: Scenario, samples: Samples) -> int:
    """Return the true contact's stamp (ns), or a miss's closest approach's."""
    truth = scenario.truth
    moment = truth.time_s if truth.time_s is not None else truth.min_gap_time_s
    return samples.start_ns + int(round(moment * 1e9))


def first_after_gap(samples: Samples, gapped: Samples) -> int:
    """Return the index in ``gapped`` of its ball's first sample after the deleted ones."""
    steps = np.diff(gapped.ball_stamps_ns)
    return int(np.argmax(steps)) + 1


def without_ball(samples: Samples, k: int) -> Samples:
    """Return ``samples`` without ball sample k."""
    keep = np.ones(len(samples.ball_stamps_ns), bool)
    keep[k] = False
    return samples.with_ball_kept(keep)


def found(stamps: List[int], truth_ns: int) -> Optional[int]:
    """Return the impact stamp (ns) within ``FOUND_NS`` of the truth, or None."""
    near = [s for s in stamps if abs(s - truth_ns) <= FOUND_NS]
    return min(near, key=lambda s: abs(s - truth_ns)) if near else None


def cell(rate: float, noise_m: float, seeds: int, chunks: bool,
         families: Tuple[str, ...] = FAMILIES, told: bool = False,
         contact_s: Optional[float] = None, gap_s: Optional[float] = None,
         before_s: float = 0.15) -> Dict[str, Any]:
    """
    Return one rate and noise level's figures over the swing ``families`` (``configs``).

    ``contact_s``: how long (s) a rebound's push lasts (``Pitch.rebound_duration``), or None
    for the simulator's; ``gap_s``: how long (s) the ball is lost (None: ``DROPOUT_S``, the
    scenario's default lead), tracked ``before_s`` (s) before that.
    """
    dropout_s = DROPOUT_S if gap_s is None else gap_s
    lead = {} if gap_s is None else {'lead_s': gap_s + before_s + 0.05}
    tally: Counter = Counter()
    errors: List[float] = []
    moved: List[float] = []
    by_family: Counter = Counter()
    for family in families:
        for kind in HITS + MISSES:
            for seed in range(seeds):
                rng = np.random.default_rng(1000 * seed + 7)
                scenario = make_scenario(kind, rng, family=family, **lead)
                if contact_s is not None:
                    scenario = replace(scenario, pitch=replace(scenario.pitch,
                                                               rebound_duration=contact_s))
                samples = sample(scenario, rate, rng, jitter_s=2e-4, grid_s=1e-3, noise_m=noise_m,
                                 marker_spread_m=0.3 if noise_m else None)
                truth_ns = moment_ns(scenario, samples)
                hit = kind in HITS
                for label, config in configs(noise_m, told).items():
                    reference = found(impact_stamps(run(config, samples)[0]), truth_ns)
                    for back in BACK:
                        gapped = dropped_ball(scenario, samples, back - 1, dropout_s)
                        events, drops, same = run(config, gapped, chunks)
                        tally['chunks differ'] += same is False
                        stamps = impact_stamps(events)
                        at = found(stamps, truth_ns) if hit else None
                        sigma = {event.stamp_ns: event.time_uncertainty_s * 1e9
                                 for event in events if isinstance(event, Impact)}
                        tally['invented'] += len(stamps) - (at is not None)
                        tally['good frames dropped'] += drops[DropReason.BALL_GLITCH]
                        if hit:
                            tally[f'hits {back}'] += 1
                            if at is not None:
                                tally[f'found {back}'] += 1
                                by_family[family, back] += 1
                                errors.append(abs(at - truth_ns) * 1e-3)
                                tally['within 2 sigma'] += abs(at - truth_ns) <= 2 * sigma[at]
                                if reference is not None:
                                    moved.append(abs(at - reference) * 1e-3)
                        k = first_after_gap(samples, gapped)
                        for distance in GLITCH_M:
                            bad = on_bat_axis(gapped, k, distance)
                            events, drops, same = run(config, bad, chunks)
                            tally['chunks differ'] += same is False
                            stamps = impact_stamps(events)
                            tally['glitch runs'] += 1
                            tally['glitch dropped'] += drops[DropReason.BALL_GLITCH] > 0
                            if not hit:
                                tally['glitch misses'] += 1
                                tally['glitch invented'] += bool(stamps)
                                tally[f'glitch invented at {distance:g} m'] += bool(stamps)
                                continue
                            deleted = found(impact_stamps(run(config, without_ball(gapped, k))[0]),
                                            truth_ns)
                            at = found(stamps, truth_ns)
                            tally['glitch hits'] += 1
                            tally['glitch hits invented'] += len(stamps) - (at is not None)
                            tally['glitch found'] += at is not None
                            tally['glitch deleted found'] += deleted is not None
    return {'tally': tally, 'errors': errors, 'moved': moved, 'by_family': by_family}


def main() -> None:
    """Print one block per rate and noise level."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=2, help='scenarios per family and kind')
    parser.add_argument('--rates', type=float, nargs='+', default=[90.0, 120.0, 360.0])
    parser.add_argument('--noises', type=float, nargs='+', default=[0.0, 1.0], help='mm')
    parser.add_argument('--chunks', action='store_true', help='compare add_chunk too')
    parser.add_argument('--families', nargs='+', default=list(FAMILIES), choices=FAMILIES)
    parser.add_argument('--told', action='store_true',
                        help="the node told the noise (default: the node's auto)")
    parser.add_argument('--contact-ms', type=float,
                        help="how long a rebound's contact lasts (ms; the simulator's: 0.6)")
    parser.add_argument('--gap-ms', type=float, nargs='+',
                        help=f'how long the ball is lost (ms; default {DROPOUT_S * 1e3:g}), a '
                        'block each')
    parser.add_argument('--before-ms', type=float, default=150.0,
                        help='with --gap-ms: how long the ball is tracked before the gap (ms)')
    args = parser.parse_args()
    contact_s = None if args.contact_ms is None else args.contact_ms * 1e-3
    for gap_ms in args.gap_ms or [None]:
        if gap_ms is not None:
            print(f'gap {gap_ms:g} ms, the ball tracked {args.before_ms:g} ms before it',
                  flush=True)
        block(args, contact_s, None if gap_ms is None else gap_ms * 1e-3, args.before_ms * 1e-3)


def block(args: argparse.Namespace, contact_s: Optional[float], gap_s: Optional[float],
          before_s: float) -> None:
    """Print one block of rows (a rate and noise level each) for one gap length (s)."""
    for rate in args.rates:
        for noise_mm in args.noises:
            figures = cell(rate, noise_mm * 1e-3, args.seeds, args.chunks, tuple(args.families),
                           args.told, contact_s, gap_s, before_s)
            tally, errors, moved = figures['tally'], figures['errors'], figures['moved']
            found_text = ', '.join(f'{back} back {tally[f"found {back}"]}/{tally[f"hits {back}"]}'
                                   for back in BACK)
            error = (np.percentile(errors, [50, 99]).round(1).tolist() + [round(max(errors), 1)]
                     if errors else [])
            print(f'{rate:g} Hz, {noise_mm:g} mm: hits found {found_text}; time error us '
                  f'p50/p99/max {error}, within 2 sigma {tally["within 2 sigma"]}; off the run '
                  f'without the gap by > 1 us '
                  f'{sum(m > 1.0 for m in moved)}/{len(moved)} (max '
                  f'{max(moved, default=0.0):.1f} us); invented {tally["invented"]}; '
                  f'ball_glitch drops {tally["good frames dropped"]}')
            at = '/'.join(str(tally[f'glitch invented at {d:g} m']) for d in GLITCH_M)
            print(f'  first sample a glitch: misses invented {tally["glitch invented"]} ({at} '
                  f'at {"/".join(f"{d * 100:g}" for d in GLITCH_M)} cm from the axis) '
                  f'(of {tally["glitch misses"]}); hits: found {tally["glitch found"]} of '
                  f'{tally["glitch hits"]} (frame deleted: {tally["glitch deleted found"]}), '
                  f'impacts invented {tally["glitch hits invented"]}; '
                  f'runs with a ball_glitch drop {tally["glitch dropped"]}/{tally["glitch runs"]}'
                  + (f'; chunks differ {tally["chunks differ"]}' if args.chunks else ''))
            per_family = ', '.join(
                f'{family} ' + '/'.join(str(figures['by_family'][family, back]) for back in BACK)
                for family in args.families)
            print(f'  found by family (1/2/3 back): {per_family}', flush=True)


if __name__ == '__main__':
    main()
