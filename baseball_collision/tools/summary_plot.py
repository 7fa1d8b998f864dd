"""
The session summary of ``analyze --plot``: one figure per bag, readable at a glance.

Three panels (:func:`summary_figure`): the bat drawn from its radius profile (knob left, tip
right) with each impact's contact spot on it, numbered and coloured by its zone, the zones
named along it; the sweet-spot speed of each impact (mph, its 1-sigma uncertainty as an error
bar); how close each near miss came (cm). The title names the bag and when it began (UTC).
Positions and zones are those of the records
(:func:`baseball_collision.core.records.event_record`), so the figure says what the JSON says.
"""

from typing import Any, Dict, List, Sequence, Tuple

import numpy as np

from .analyze import BagAnalysis
from .report import utc_text
from .truth import bag_name
from ..core.detector import DetectorConfig, MPS_TO_MPH
from ..core.records import bat_zone, event_record, SWEET_SPOT_HALF_WIDTH

ZONE_NAMES: Dict[str, str] = {'knob': 'knob', 'handle': 'handle', 'barrel': 'barrel',
                              'sweet_spot': 'sweet spot', 'end_cap': 'end cap'}
"""How a record's ``zone`` reads in a figure."""

ZONE_COLORS: Dict[str, str] = {'knob': 'tab:purple', 'handle': 'tab:red',
                               'barrel': 'tab:blue', 'sweet_spot': 'tab:green',
                               'end_cap': 'tab:orange'}
"""One colour per zone, the same in every panel."""


def _silhouette(config: DetectorConfig) -> Tuple[np.ndarray, np.ndarray]:
    """
    Return the bat's outline: distance from the knob (cm) and radius (cm) along it.

    The profile's round cones: the taper from station to station, the rounded caps at both
    ends.
    """
    profile = config.profile
    length = profile.length * 100.0
    segments = profile.segments()
    xs: List[float] = []
    radii: List[float] = []
    for start, end, radius_start, radius_end in segments:
        xs += [start * length, end * length]
        radii += [radius_start * 100.0, radius_end * 100.0]
    angles = np.linspace(0.0, 0.5 * np.pi, 24)
    knob_r, tip_r = radii[0], radii[-1]
    knob_x = xs[0] - knob_r * np.cos(angles)
    tip_x = xs[-1] + tip_r * np.cos(angles[::-1])
    return (np.concatenate([knob_x, xs, tip_x]),
            np.concatenate([knob_r * np.sin(angles), radii, tip_r * np.sin(angles[::-1])]))


def _side_zones(config: DetectorConfig) -> List[Tuple[str, float, float]]:
    """Return the side zones along the bat as ``(zone, start cm, end cm)`` from the knob."""
    length = config.profile.length
    fractions = np.linspace(0.0, 1.0, 401)
    names = [bat_zone(config.profile, 'side', f, (1.0 - f) * length, config.sweet_spot_from_tip)
             for f in fractions]
    zones: List[Tuple[str, float, float]] = []
    for fraction, name in zip(fractions, names):
        if zones and zones[-1][0] == name:
            zones[-1] = (name, zones[-1][1], fraction * length * 100.0)
        else:
            zones.append((name, fraction * length * 100.0, fraction * length * 100.0))
    return zones


def _clusters(xs: Sequence[float], numbers: Sequence[int],
              within_cm: float = 2.0) -> List[Tuple[float, str]]:
    """Return one label per group of spots closer than ``within_cm``: (mean x, '1, 8')."""
    groups: List[List[Tuple[float, int]]] = []
    for x, number in sorted(zip(xs, numbers)):
        if groups and x - groups[-1][-1][0] < within_cm:
            groups[-1].append((x, number))
        else:
            groups.append([(x, number)])
    return [(sum(x for x, _ in group) / len(group),
             ', '.join(str(n) for _, n in sorted(group, key=lambda item: item[1])))
            for group in groups]


def _bat_panel(axes: Any, analysis: BagAnalysis, records: Sequence[Dict[str, Any]]) -> None:
    """Draw the bat's silhouette, its zones and the contact spots."""
    config = analysis.config
    xs, radii = _silhouette(config)
    length = config.profile.length * 100.0
    axes.fill_between(xs, -radii, radii, color='burlywood', edgecolor='saddlebrown', lw=1.5,
                      label='bat (from its radius profile)')
    top = float(radii.max())
    for zone, start, end in _side_zones(config):
        axes.text(0.5 * (start + end), -top * 1.9, ZONE_NAMES[zone], ha='center', va='top',
                  fontsize=10, color=ZONE_COLORS[zone])
        axes.plot([start, end], [-top * 1.5] * 2, color=ZONE_COLORS[zone], lw=4)
    sweet = length - config.sweet_spot_from_tip * 100.0
    half = SWEET_SPOT_HALF_WIDTH * 100.0
    axes.axvspan(sweet - half, sweet + half, color=ZONE_COLORS['sweet_spot'], alpha=0.15,
                 label='sweet-spot zone')
    for zone in ZONE_NAMES:
        spots = [(n, r) for n, r in enumerate(records, 1) if r['zone'] == zone]
        if not spots:
            continue
        x = [length - r['distance_from_tip_m'] * 100.0 for _, r in spots]
        y = [0.0] * len(spots)
        axes.plot(x, y, 'o', ms=13, color=ZONE_COLORS[zone], mec='black', zorder=4,
                  label=f'contact: {ZONE_NAMES[zone]} ({len(spots)})')
        for xi, numbers in _clusters(x, [number for number, _ in spots]):
            axes.annotate(numbers, (xi, 0.0), xytext=(0, 13), textcoords='offset points',
                          ha='center', fontsize=10, fontweight='bold')
    axes.text(0.0, top * 1.6, 'knob', ha='left', fontsize=10)
    axes.text(length, top * 1.6, 'tip', ha='right', fontsize=10)
    axes.set_xlim(-2.0, length + 2.0)
    axes.set_ylim(-top * 3.2, top * 2.6)
    axes.set_xlabel('distance from the knob (cm)')
    axes.set_yticks([])
    axes.set_title(f'Where the ball met the bat ({len(records)} impacts, numbered in order)',
                   fontsize=12)
    axes.legend(loc='upper center', fontsize='small', ncol=3, framealpha=0.9)


def _speed_panel(axes: Any, records: Sequence[Dict[str, Any]]) -> None:
    """Draw each impact's sweet-spot speed (mph) as a bar coloured by its zone, +- 1 sigma."""
    numbers = list(range(1, len(records) + 1))
    speeds = [r['sweet_spot_speed_mps'] * MPS_TO_MPH for r in records]
    sigmas = [(r['sweet_spot_speed_uncertainty_mps'] or 0.0) * MPS_TO_MPH for r in records]
    bars = axes.bar(numbers, speeds, yerr=sigmas, capsize=6,
                    color=[ZONE_COLORS[r['zone']] for r in records], edgecolor='black')
    for bar, speed, sigma in zip(bars, speeds, sigmas):
        axes.annotate(f'{speed:.1f}', (bar.get_x() + bar.get_width() / 2, speed + sigma),
                      xytext=(0, 3), textcoords='offset points', ha='center', fontsize=9)
    if not records:
        axes.text(0.5, 0.5, 'no impacts', transform=axes.transAxes, ha='center')
    axes.set_xticks(numbers)
    axes.set_xlabel('impact number')
    axes.set_ylabel('sweet-spot speed (mph)')
    axes.set_ylim(0.0, max((v + e for v, e in zip(speeds, sigmas)), default=1.0) * 1.15)
    axes.set_title('Bat speed at the sweet spot, per impact (error bars: 1 sigma)', fontsize=12)
    axes.grid(True, axis='y', alpha=0.3)


def _miss_panel(axes: Any, analysis: BagAnalysis) -> None:
    """Draw how close each near miss came (cm), at its time in the bag (s)."""
    misses = analysis.near_misses
    times = [analysis.relative_s(m.stamp_ns) for m in misses]
    gaps = [m.gap_m * 100.0 for m in misses]
    axes.bar(range(1, len(misses) + 1), gaps, color='0.55', edgecolor='black')
    for number, (t, gap) in enumerate(zip(times, gaps), 1):
        axes.annotate(f'{gap:.1f} cm\nat {t:.1f} s', (number, gap), xytext=(0, 3),
                      textcoords='offset points', ha='center', fontsize=8)
    if not misses:
        axes.text(0.5, 0.5, 'no near misses', transform=axes.transAxes, ha='center')
    axes.set_xticks(range(1, len(misses) + 1))
    axes.set_xlabel('near miss number')
    axes.set_ylabel('closest gap between ball and bat (cm)')
    axes.set_ylim(0.0, max(gaps, default=1.0) * 1.3)
    axes.set_title('Near misses: how close the ball came', fontsize=12)
    axes.grid(True, axis='y', alpha=0.3)


def summary_figure(analysis: BagAnalysis) -> Any:
    """Return the session summary of one bag (a matplotlib ``Figure``, see the module)."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib.figure import Figure

    records = [event_record(impact, analysis.frame_id, analysis.config)
               for impact in analysis.impacts]
    figure = Figure(figsize=(15, 9), dpi=100)  # fixed margins: a layout engine costs seconds
    grid = figure.add_gridspec(2, 2, height_ratios=(1.0, 1.1), left=0.06, right=0.985,
                               bottom=0.07, top=0.9, hspace=0.3, wspace=0.18)
    _bat_panel(figure.add_subplot(grid[0, :]), analysis, records)
    _speed_panel(figure.add_subplot(grid[1, 0]), records)
    _miss_panel(figure.add_subplot(grid[1, 1]), analysis)
    began = '' if analysis.first_stamp_ns is None else (
        f", {utc_text(analysis.first_stamp_ns)[:16].replace('T', ' ')} UTC")
    figure.suptitle(f'Session summary: {bag_name(analysis.path)}{began} '
                    f'({len(analysis.impacts)} impacts, {len(analysis.near_misses)} near misses, '
                    f'{analysis.config.model} model)', fontsize=14)
    return figure
