"""
A bag's impacts at lower rates, against the bag's own: what the rate costs on a real rig.

A recording with no truth (a real rig's) cannot say how far off its impacts are, but it can
say how far they move when the rig is slower. ``analyze --decimate K`` analyses the bag again
keeping every K-th frame of each input, once from each of its K phases (so every frame serves
once), and matches each impact found at the lower rate with the recorded rate's nearest
(within ``MATCH_WINDOW_S``): how many are found again, how many appear, how far each one's
instant, spot on the bat (distance from the knob) and sweet-spot speed moved, its mean shift
(a late or early bias), and the share of moves within 1 and 2 of their combined 1-sigma
uncertainties (both answers'): the error bars checked on the user's own recording. The issue
this answers measured a real swing so (360 Hz decimated to 180, 120 and 90 Hz).

What it measures is the lower rate's error only where the recorded rate's own is much smaller
(360 Hz against 90 Hz, the worst of the simulator's families: 6 times in the instant, 18 in the
spot; BENCHMARKS.md); on a simulated bag the truth comparison says both (``test_rates``).
"""

from bisect import bisect_left, bisect_right
from dataclasses import dataclass, field, replace
import math
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

MATCH_WINDOW_S = 0.02
"""Largest distance (s) between an impact at the lower rate and the recorded rate's it is
matched with (a pitch holds one contact; pitches are seconds apart)."""


@dataclass
class RateCheck:
    """
    The impacts found keeping every ``every``-th frame, against the recorded rate's.

    :ivar every: the factor K (the rate is the recorded one over K); ``phases``: K analyses.
    :ivar impacts: the recorded rate's impacts; ``compared``: those times the phases.
    :ivar found: of ``compared``, matched at the lower rate; ``extra``: impacts at the lower
        rate matched with none (a phase's false hits, or contacts the recorded rate missed).
    :ivar time_s, spot_m, speed: each match's move (lower rate minus recorded): instant (s),
        distance from the knob (m), sweet-spot speed (relative: over the recorded speed).
    :ivar time_z, spot_z, speed_z: each move over the combined 1 sigma (``hypot`` of both
        answers' ``*_uncertainty``); NaN where both are 0.
    """

    every: int
    phases: int
    impacts: int
    compared: int = 0
    found: int = 0
    extra: int = 0
    time_s: List[float] = field(default_factory=list)
    spot_m: List[float] = field(default_factory=list)
    speed: List[float] = field(default_factory=list)
    time_z: List[float] = field(default_factory=list)
    spot_z: List[float] = field(default_factory=list)
    speed_z: List[float] = field(default_factory=list)

    def add(self, lower: Any, recorded: Any) -> None:
        """Add the move of an impact at the lower rate from its match at the recorded rate."""
        self.found += 1
        speed = recorded.sweet_spot_speed_mps
        per_speed = 1.0 / speed if speed > 0.0 else math.nan  # (relative to the recorded)
        for moves, scores, value, sigma in (
                (self.time_s, self.time_z, (lower.stamp_ns - recorded.stamp_ns) * 1e-9,
                 math.hypot(lower.time_uncertainty_s, recorded.time_uncertainty_s)),
                (self.spot_m, self.spot_z,
                 lower.distance_from_knob_m - recorded.distance_from_knob_m,
                 math.hypot(lower.distance_from_knob_uncertainty_m,
                            recorded.distance_from_knob_uncertainty_m)),
                (self.speed, self.speed_z, (lower.sweet_spot_speed_mps - speed) * per_speed,
                 math.hypot(lower.sweet_spot_speed_uncertainty_mps,
                            recorded.sweet_spot_speed_uncertainty_mps) * per_speed)):
            moves.append(value)
            scores.append(abs(value) / sigma if sigma > 0.0 else math.nan)

    def summary(self) -> Dict[str, Any]:
        """
        Return the check as plain numbers (``--json``'s ``rates`` entries).

        ``time_s``, ``distance_from_knob_m``, ``sweet_spot_speed``: ``p50``, ``p99``, ``max``
        of the moves' size and their ``mean`` (signed: positive later, farther from the knob,
        faster), None without a match; ``within_1_sigma``, ``within_2_sigma``: the share of
        matches within that many combined sigmas, for each of the three (None without one).
        """
        document: Dict[str, Any] = {
            'every': self.every, 'phases': self.phases, 'impacts': self.impacts,
            'compared': self.compared, 'found': self.found, 'extra': self.extra}
        named = (('time_s', self.time_s, self.time_z),
                 ('distance_from_knob_m', self.spot_m, self.spot_z),
                 ('sweet_spot_speed', self.speed, self.speed_z))
        for key, moves, _ in named:
            document[key] = _spread(moves)
        for k in (1, 2):
            document[f'within_{k}_sigma'] = {key: _share(scores, k) for key, _, scores in named}
        return document


def _spread(moves: Sequence[float]) -> Optional[Dict[str, float]]:
    """Return ``p50``, ``p99``, ``max`` of the moves' size and their ``mean``, or None."""
    values = np.asarray([m for m in moves if math.isfinite(m)], float)
    if not len(values):
        return None
    size = np.abs(values)
    return {'p50': float(np.percentile(size, 50)), 'p99': float(np.percentile(size, 99)),
            'max': float(size.max()), 'mean': float(values.mean())}


def _share(scores: Sequence[float], k: int) -> Optional[float]:
    """Return the share (0-1) of the finite scores at most ``k``, or None for none."""
    finite = [z for z in scores if math.isfinite(z)]
    return sum(z <= k for z in finite) / len(finite) if finite else None


def match(lower: Sequence[Any], recorded: Sequence[Any],
          window_ns: int = int(MATCH_WINDOW_S * 1e9)) -> Tuple[List[Tuple[Any, Any]], int]:
    """
    Pair impacts at the lower rate with the recorded rate's, nearest stamps first, one to one.

    :returns: the pairs (lower, recorded), and how many at the lower rate were left without
        one within ``window_ns`` (ns).
    """
    order = sorted(range(len(recorded)), key=lambda j: recorded[j].stamp_ns)
    stamps = [recorded[j].stamp_ns for j in order]
    candidates = sorted(  # (each impact's neighbours within the window: a session's thousands)
        (abs(a.stamp_ns - stamps[k]), i, order[k]) for i, a in enumerate(lower)
        for k in range(bisect_left(stamps, a.stamp_ns - window_ns),
                       bisect_right(stamps, a.stamp_ns + window_ns)))
    used_lower, used_recorded, pairs = set(), set(), []
    for _, i, j in candidates:
        if i not in used_lower and j not in used_recorded:
            used_lower.add(i)
            used_recorded.add(j)
            pairs.append((lower[i], recorded[j]))
    return pairs, len(lower) - len(pairs)


def check_rates(analysis: Any, options: Any, read_ahead: int = 1) -> List[RateCheck]:
    """
    Return the bag's impacts at each of ``options.decimate``'s lower rates, against its own.

    :param analysis: the recorded rate's ``BagAnalysis`` (``analyze_bag``'s, of this bag with
        these options but ``decimate``).
    :param options: its ``AnalysisOptions``: each factor K analyses the bag K times more, every
        K-th frame from each phase (``every``, ``phase``), without prediction or truth.
    :raises ToolError: as ``analyze_bag``.
    """
    from .analyze import analyze_bag  # (this module is imported by analyze_bag)
    checks = []
    for every in options.decimate:
        check = RateCheck(every=every, phases=every, impacts=len(analysis.impacts))
        for phase in range(every):
            lower = analyze_bag(analysis.path, replace(
                options, every=every, phase=phase, decimate=(), prediction_horizon=0.0),
                progress=False, use_truth=False, read_ahead=read_ahead)
            pairs, extra = match(lower.impacts, analysis.impacts)
            check.compared += len(analysis.impacts)
            check.extra += extra
            for lower_impact, recorded in pairs:
                check.add(lower_impact, recorded)
        checks.append(check)
    return checks


def rate_lines(checks: Sequence[RateCheck]) -> List[str]:
    """Return the report's lines on the lower rates (none without a check)."""
    if not checks:
        return []
    lines = ["at lower rates, against this bag's own impacts (every K-th frame of each input, "
             "each of its K phases; the moves are the lower rate's error where the recorded "
             "rate's is much smaller):"]
    for check in checks:
        summary = check.summary()
        head = (f'  every {_ordinal(check.every)} frame: {check.found} of {check.compared} '
                f'impacts found again, {check.extra} more')
        if not check.found:
            lines.append(head)
            continue
        time, spot, speed = (summary[key] for key in (
            'time_s', 'distance_from_knob_m', 'sweet_spot_speed'))
        within = [summary[f'within_{k}_sigma'] for k in (1, 2)]
        lines.append(
            f"{head}; instant moved p50 {time['p50'] * 1e6:.1f} us, p99 {time['p99'] * 1e6:.1f}"
            f" us (mean {time['mean'] * 1e6:+.1f} us), spot p50 {spot['p50'] * 1e3:.2f} mm, "
            f"p99 {spot['p99'] * 1e3:.2f} mm, sweet-spot speed"
            + ('' if speed is None else
               f" p50 {speed['p50'] * 100:.2f} %, p99 {speed['p99'] * 100:.2f} %")
            + '; within 1 / 2 sigma: '
            + ', '.join(f'{name} {_percent(within[0][key])} / {_percent(within[1][key])}'
                        for name, key in (('instant', 'time_s'),
                                          ('spot', 'distance_from_knob_m'),
                                          ('speed', 'sweet_spot_speed'))))
    return lines


def _percent(share: Optional[float]) -> str:
    """Return a share as a whole percentage, or '-' for none."""
    return '-' if share is None else f'{share * 100:.0f} %'


def _ordinal(k: int) -> str:
    """Return 2nd, 3rd, 4th, 11th ... for the factor k."""
    suffix = 'th' if 10 <= k % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(k % 10, 'th')
    return f'{k}{suffix}'
