"""
``analyze --plot``: one PNG per impact, drawn from the bag's samples around it.

matplotlib is imported only when a figure is drawn (``analyze`` without ``--plot`` never loads
it), with the non-interactive Agg backend. Each figure: the gap versus time around the impact,
and a top and a side view of the bat and ball samples with the contact point.
"""

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from .analyze import BagAnalysis
from .truth import truth_path
from ..bags import BagReader
from ..core.detector import DetectorConfig, Impact, MPS_TO_MPH
from ..core.toi import profile_gap
from ..errors import BagError, ToolError

PLOT_WINDOW_S = 0.04
"""Half-width (s) of the time window each plot shows around an impact."""


@dataclass
class _Window:
    """Samples of a bag near one impact (arrays filled after the read)."""

    impact: Impact
    start_ns: int
    end_ns: int
    ball: List[Tuple[int, Sequence[float]]] = field(default_factory=list)
    bat: List[Tuple[int, Sequence[float]]] = field(default_factory=list)
    knob: List[Tuple[int, Sequence[float]]] = field(default_factory=list)
    tip: List[Tuple[int, Sequence[float]]] = field(default_factory=list)


def _collect_windows(analysis: BagAnalysis) -> List[_Window]:
    """
    Read the bag again and keep the samples within :data:`PLOT_WINDOW_S` of each impact.

    :raises ToolError: the bag cannot be read again.
    """
    half = int(PLOT_WINDOW_S * 1e9)
    windows = [_Window(impact, impact.stamp_ns - half, impact.stamp_ns + half)
               for impact in analysis.impacts]
    if not windows:
        return windows
    lists = {'ball': 'ball', 'bat_pose': 'bat', 'knob': 'knob', 'tip': 'tip'}
    try:
        with BagReader(analysis.path, analysis.selection) as bag:
            for role, stamp, _, values, _ in bag.samples():
                for window in windows:
                    if window.start_ns <= stamp <= window.end_ns:
                        getattr(window, lists[role]).append((stamp, values))
    except BagError as error:
        raise ToolError(str(error)) from error
    return windows


def _bat_ends(window: _Window,
              config: DetectorConfig) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return bat stamps (ns), knobs and tips (metres) of a window."""
    if window.bat:
        stamps = np.array([s for s, _ in window.bat], dtype=np.int64)
        ends = [config.geometry.knob_and_tip(v[:3], v[3:]) for _, v in window.bat]
        return stamps, np.array([k for k, _ in ends]), np.array([t for _, t in ends])
    knob_stamps = np.array([s for s, _ in window.knob], dtype=np.int64)
    knobs = np.array([v for _, v in window.knob], dtype=float).reshape(-1, 3)
    tip_stamps = np.array([s for s, _ in window.tip], dtype=np.int64)
    tips = np.array([v for _, v in window.tip], dtype=float).reshape(-1, 3)
    if len(tip_stamps) == 0 or len(knob_stamps) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3))
    return knob_stamps, knobs, _interp(knob_stamps, tip_stamps, tips)


def _interp(at: np.ndarray, stamps: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Interpolate (N, 3) values linearly in time at the stamps ``at`` (ns)."""
    x = (at - stamps[0]).astype(float)
    xp = (stamps - stamps[0]).astype(float)
    return np.stack([np.interp(x, xp, values[:, i]) for i in range(3)], axis=1)


def _plot_one(window: _Window, analysis: BagAnalysis, true_stamp: Optional[int],
              target: Path) -> None:
    """Draw one impact's figure to ``target`` (PNG)."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot

    config = analysis.config
    impact = window.impact
    origin = impact.stamp_ns
    ball_stamps = np.array([s for s, _ in window.ball], dtype=np.int64)
    balls = np.array([v for _, v in window.ball], dtype=float).reshape(-1, 3)
    bat_stamps, knobs, tips = _bat_ends(window, config)
    figure, (gap_axes, top_axes, side_axes) = pyplot.subplots(1, 3, figsize=(16, 5))
    figure.suptitle(f'{analysis.path.name}: impact at {analysis.relative_s(origin):.4f} s '
                    f'({origin} ns), {impact.distance_from_tip_m * 100:.1f} cm from the tip, '
                    f'sweet spot {impact.sweet_spot_speed_mps * MPS_TO_MPH:.1f} mph '
                    f'[{config.model}]')
    _gap_panel(gap_axes, origin, (ball_stamps, balls), (bat_stamps, knobs, tips), config,
               true_stamp)
    for axes, (i, j), title in ((top_axes, (0, 1), 'top view'), (side_axes, (1, 2), 'side view')):
        _view_panel(axes, (i, j), title, balls, knobs, tips, impact)
    figure.tight_layout()
    figure.savefig(target, dpi=80)
    pyplot.close(figure)


def _gap_panel(axes: Any, origin: int, ball: Tuple[np.ndarray, np.ndarray],
               bat: Tuple[np.ndarray, np.ndarray, np.ndarray], config: DetectorConfig,
               true_stamp: Optional[int]) -> None:
    """Draw the gap (cm) against the time from the impact at ``origin`` (ms)."""
    ball_stamps, balls = ball
    bat_stamps, knobs, tips = bat
    if len(ball_stamps) >= 2 and len(bat_stamps) >= 2:
        dense = np.linspace(max(ball_stamps[0], bat_stamps[0]),
                            min(ball_stamps[-1], bat_stamps[-1]), 400).astype(np.int64)
        gaps = _gaps(_interp(dense, ball_stamps, balls), _interp(dense, bat_stamps, knobs),
                     _interp(dense, bat_stamps, tips), config)
        axes.plot((dense - origin) * 1e-6, gaps * 100.0, color='0.6',
                  label='linear between samples')
        inside = (ball_stamps >= bat_stamps[0]) & (ball_stamps <= bat_stamps[-1])
        at_samples = _gaps(balls[inside], _interp(ball_stamps[inside], bat_stamps, knobs),
                           _interp(ball_stamps[inside], bat_stamps, tips), config)
        axes.plot((ball_stamps[inside] - origin) * 1e-6, at_samples * 100.0, 'o',
                  color='tab:blue', label='at ball samples')
        # zoom on the approach: contact is at 0, the far samples only squash the plot
        low = min(-3.0, float(np.min(gaps)) * 100.0 - 1.0)
        axes.set_ylim(low, min(float(np.max(gaps)) * 100.0, 40.0) + 2.0)
    for stamp in bat_stamps:
        axes.axvline((stamp - origin) * 1e-6, color='tab:orange', alpha=0.15, lw=0.8)
    axes.axvline(0.0, color='tab:red', label=f'impact ({config.model})')
    if true_stamp is not None:
        axes.axvline((true_stamp - origin) * 1e-6, color='black', ls='--', label='truth')
    axes.axhline(0.0, color='black', lw=0.8)
    axes.set_xlabel('time from impact (ms); orange lines: bat samples')
    axes.set_ylabel('gap ball to bat (cm)')
    axes.legend(loc='best', fontsize='small')


def _view_panel(axes: Any, plane: Tuple[int, int], title: str, balls: np.ndarray,
                knobs: np.ndarray, tips: np.ndarray, impact: Impact) -> None:
    """Draw the bat and ball samples and the contact point on two world axes (m)."""
    i, j = plane
    for knob, tip in zip(knobs, tips):
        axes.plot([knob[i], tip[i]], [knob[j], tip[j]], color='tab:orange', alpha=0.5)
    if len(balls):
        axes.plot(balls[:, i], balls[:, j], 'o-', color='tab:blue', ms=3, label='ball')
    axes.plot([impact.point[i]], [impact.point[j]], '*', color='tab:red', ms=14,
              label='contact point')
    axes.set_xlabel('xyz'[i] + ' (m)')
    axes.set_ylabel('xyz'[j] + ' (m)')
    axes.set_aspect('equal', adjustable='datalim')
    axes.set_title(f'{title}: bat samples (orange), ball samples (blue)')
    axes.legend(loc='best', fontsize='small')


def _gaps(balls: np.ndarray, knobs: np.ndarray, tips: np.ndarray,
          config: DetectorConfig) -> np.ndarray:
    """Return the ball-bat gap (m) per row."""
    return np.array([profile_gap(tuple(b), tuple(k), tuple(t), config.ball_radius,
                                 config.profile)[0] for b, k, t in zip(balls, knobs, tips)])


def plot_names(analyses: Sequence[BagAnalysis]) -> List[str]:
    """Return the PNG names ``--plot`` writes: ``<bag name>_impact_<n>.png`` per impact."""
    names = []
    for index, analysis in enumerate(analyses):
        stem = truth_path(analysis.path).name[:-len('.truth.json')]
        if sum(1 for a in analyses if a.path.name == analysis.path.name) > 1:
            stem = f'{index + 1}_{stem}'
        names.extend(f'{stem}_impact_{n}.png' for n in range(1, len(analysis.impacts) + 1))
    return names


def write_plots(analyses: Sequence[BagAnalysis], directory: Path) -> List[Path]:
    """
    Draw one PNG per impact into ``directory`` (which must exist).

    Each figure: the gap versus time around the impact (ball samples as dots, bat sample
    times as lines, the impact instant and the true one when known), and a top and a side view
    of the bat and ball samples around it with the contact point.

    :returns: the files written.
    :raises ToolError: the bag cannot be read again.
    """
    written = []
    names = iter(plot_names(analyses))
    for analysis in analyses:
        truths = {id(impact): int(truth['stamp_ns'])
                  for truth, impact in (analysis.truth.matched if analysis.truth else [])}
        for window in _collect_windows(analysis):
            target = directory / next(names)
            _plot_one(window, analysis, truths.get(id(window.impact)), target)
            written.append(target)
    return written
