"""
``analyze --plot``: one PNG per impact and a session summary per bag.

matplotlib is imported only when a figure is drawn (``analyze`` without ``--plot`` never loads
it), with the non-interactive Agg backend. An impact's figure (:func:`impact_figure`): the gap
between ball and bat against the time from the impact (ms), as the motion model that decided
the impact moves them between samples (:class:`ModelGap`; the straight-line gap beside it for
comparison when the model is not ``linear``), and a top and a side view around the contact
point (cm). The summary (:mod:`.summary_plot`): contact spots on a drawn bat, sweet-spot speed
per pitch and the near-miss gaps.
"""

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from .analyze import BagAnalysis, CHUNK
from .pool import in_pool
from .report import plot_files
from .summary_plot import summary_figure, ZONE_NAMES
from .truth import bag_name
from ..bags import BagReader
from ..core.detector import Detector, DetectorConfig, Impact, MPS_TO_MPH
from ..core.detector.chunks import ROLE_CODES
from ..core.geometry import Vector
from ..core.motion import BatSample
from ..core.records import event_record
from ..core.toi import profile_gap
from ..core.toi.batch import cores
from ..errors import BagError, ToolError

PLOT_WINDOW_S = 0.04
"""Half-width (s) of the time window each plot shows around an impact."""

HISTORY_S = 0.3
"""How far (s) before its window a plot's detector is fed (its fits' windows and noise estimates
reach back into it), and ``AHEAD_S`` after (its look-ahead frames)."""

AHEAD_S = 0.1

CURVE_POINTS = 300
"""Instants the gap curves are drawn at."""

ZOOM_MS = 1.0
"""Half-width (ms) of the gap panel's zoom on the impact."""

NORMAL_CM = 10.0
"""Length of the drawn contact normal (cm)."""


@dataclass
class PlotWindow:
    """
    Samples of a bag near one impact (lists filled after the read).

    The lists hold ``HISTORY_S`` before ``start_ns`` and ``AHEAD_S`` after ``end_ns`` too (what
    the plot's detector is fed); the figure shows [``start_ns``, ``end_ns``].
    """

    impact: Impact
    start_ns: int
    end_ns: int
    ball: List[Tuple[int, Sequence[float]]] = field(default_factory=list)
    bat: List[Tuple[int, Sequence[float]]] = field(default_factory=list)
    knob: List[Tuple[int, Sequence[float]]] = field(default_factory=list)
    tip: List[Tuple[int, Sequence[float]]] = field(default_factory=list)


def collect_windows(analysis: BagAnalysis) -> List[PlotWindow]:
    """
    Read the bag again and keep the samples within :data:`PLOT_WINDOW_S` of each impact.

    The bag is read a chunk of arrays at a time (``BagReader.chunks``) and each window takes
    its rows by a mask of the chunk's stamps: the samples ``BagReader.samples`` gives, in the
    bag's order, a bat pose's 7 values and any other sample's 3. (A Python loop over every
    sample and every window took about 2 s of CPU on a 500k-message bag with 48 impacts; the
    masks take 0.08 s.)

    :raises ToolError: the bag cannot be read again.
    """
    half = int(PLOT_WINDOW_S * 1e9)
    before, after = int(HISTORY_S * 1e9), int(AHEAD_S * 1e9)
    windows = [PlotWindow(impact, impact.stamp_ns - half, impact.stamp_ns + half)
               for impact in analysis.impacts]
    if not windows:
        return windows
    lists = {ROLE_CODES['ball']: 'ball', ROLE_CODES['bat_pose']: 'bat',
             ROLE_CODES['knob']: 'knob', ROLE_CODES['tip']: 'tip'}
    spans = [(window.start_ns - before, window.end_ns + after) for window in windows]
    try:
        with BagReader(analysis.path, analysis.selection) as bag:
            for chunk in bag.chunks(CHUNK):
                stamps = chunk.stamps_ns
                low, high = int(stamps.min()), int(stamps.max())
                for window, (start, end) in zip(windows, spans):
                    if end < low or start > high:
                        continue
                    rows = np.flatnonzero((stamps >= start) & (stamps <= end))
                    for role, stamp, values in zip(chunk.roles[rows].tolist(),
                                                   stamps[rows].tolist(),
                                                   chunk.values[rows].tolist()):
                        name = lists[role]
                        getattr(window, name).append(
                            (stamp, tuple(values if name == 'bat' else values[:3])))
    except BagError as error:
        raise ToolError(str(error)) from error
    return windows


def _as_vector(values: Any) -> Vector:
    return tuple(float(v) for v in values)


def shown(window: PlotWindow, samples: List[Tuple[int, Any]]) -> List[Tuple[int, Any]]:
    """Return the (stamp, values) among ``samples`` within the window the figure shows."""
    return [(stamp, values) for stamp, values in samples
            if window.start_ns <= stamp <= window.end_ns]


def bat_samples(window: PlotWindow, config: DetectorConfig) -> Tuple[List[int], List[BatSample]]:
    """
    Return the bat samples the figure shows: stamps (ns) and :class:`BatSample` s.

    Poses go through the configured bat geometry; knob and tip points are paired at the knob
    stamps (the tip interpolated linearly between its own samples).
    """
    if window.bat:
        samples = []
        bats = shown(window, window.bat)
        for _, values in bats:
            knob, tip = config.geometry.knob_and_tip(values[:3], values[3:])
            samples.append(BatSample(_as_vector(knob), _as_vector(tip), _as_vector(values[:3]),
                                     _as_vector(values[3:])))
        return [stamp for stamp, _ in bats], samples
    if not window.knob or not window.tip:
        return [], []
    tip_stamps = np.array([s for s, _ in window.tip], dtype=float)
    tips = np.array([v for _, v in window.tip], dtype=float).reshape(-1, 3)
    samples = []
    knobs = shown(window, window.knob)
    for stamp, knob in knobs:
        tip = [float(np.interp(stamp, tip_stamps, tips[:, i])) for i in range(3)]
        samples.append(BatSample(_as_vector(knob), tuple(tip)))
    return [stamp for stamp, _ in knobs], samples


class ModelGap:
    """
    The gap (m) between ball and bat surface as a motion model moves both between samples.

    A fresh :class:`~baseball_collision.core.detector.Detector` of the model (prediction off)
    is fed the window's samples, from ``HISTORY_S`` before it, and asked where it moves the
    ball and the bat (``Detector.positions_at``): the very paths it solves, `c2`'s window fits,
    smoothing under noise and a departed ball's free flight included, so the curve of the
    model that decided an impact touches 0 at it. Under ``tracker_noise`` auto its noise
    estimates start with that history, where the bag's analysis had the whole bag's. Times
    are seconds from an origin stamp.

    :param config: the detector configuration the impact was found with.
    :param model: the model to draw (``linear`` for the straight-line comparison).
    :param origin_ns: the stamp of time 0.
    :param window: the samples around the impact (:func:`collect_windows`).
    :param frame_id: the samples' frame.
    """

    def __init__(self, config: DetectorConfig, model: str, origin_ns: int,
                 window: PlotWindow, frame_id: str = '') -> None:
        self.config, self.model, self.origin_ns = config, model, origin_ns
        self.detector = Detector(config.variant(model=model, prediction_horizon=0.0))
        roles = {'ball': 'ball', 'bat': 'bat_pose', 'knob': 'knob', 'tip': 'tip'}
        feed = sorted(((stamp, order, roles[name], values)
                       for order, name in enumerate(roles)
                       for stamp, values in getattr(window, name)),
                      key=lambda sample: sample[:2])  # (never the values: a duplicate stamp)
        for stamp, _, role, values in feed:
            self.detector.add(role, stamp, values, frame_id)
        self.detector.finish()
        self.ball_t = [(s - origin_ns) * 1e-9 for s, _ in shown(window, window.ball)]
        bats = shown(window, window.bat or window.knob)
        self.bat_t = [(s - origin_ns) * 1e-9 for s, _ in bats]

    @property
    def span(self) -> Tuple[float, float]:
        """Return the times (s) both streams cover (empty when start >= end)."""
        if len(self.ball_t) < 2 or len(self.bat_t) < 2:
            return 0.0, 0.0
        return max(self.ball_t[0], self.bat_t[0]), min(self.ball_t[-1], self.bat_t[-1])

    def at(self, t: float) -> float:
        """Return the gap (m) at ``t`` (s from the origin); NaN outside a sampled interval."""
        start, end = self.span
        if not start <= t <= end:
            return float('nan')
        where = self.detector.positions_at(self.origin_ns + int(round(t * 1e9)))
        if where is None:
            return float('nan')
        ball, knob, tip = where
        return profile_gap(ball, knob, tip, self.config.ball_radius, self.config.profile)[0]

    def curve(self, times_s: Sequence[float]) -> np.ndarray:
        """Return the gap (m) at each time (s)."""
        return np.array([self.at(t) for t in times_s], dtype=float)


def _ms(nanoseconds: int) -> str:
    """Return a signed time in ms to the microsecond, +0.000 for what rounds to zero."""
    return f'{round(nanoseconds * 1e-6, 3) + 0.0:+.3f}'


def impact_title(analysis: BagAnalysis, impact: Impact, number: int,
                 true_stamp: Optional[int]) -> str:
    """Return an impact figure's two-line title (zone, speed; bag, time, model, truth)."""
    record = event_record(impact, analysis.frame_id, analysis.config)
    zone = ZONE_NAMES.get(record['zone'], record['zone'])
    line = (f"Impact {number}: {zone}, {record['distance_from_tip_m'] * 100:.1f} cm from the "
            f'tip, sweet spot {impact.sweet_spot_speed_mps * MPS_TO_MPH:.1f} mph')
    where = (f'{bag_name(analysis.path)}, {analysis.relative_s(impact.stamp_ns):.3f} s into the '
             f'bag, {analysis.config.model} model')
    if true_stamp is not None:
        where += f', {_ms(impact.stamp_ns - true_stamp)} ms from the true contact'
    return f'{line}\n{where}'


def impact_figure(window: PlotWindow, analysis: BagAnalysis, number: int,
                  true_stamp: Optional[int]) -> Any:
    """
    Return one impact's figure (matplotlib ``Figure``): gap panel, top view, side view.

    :param number: the impact's number in its bag (1, 2, ...), for the title.
    :param true_stamp: the matched true contact (ns), or None.
    """
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib.figure import Figure

    config, impact = analysis.config, window.impact
    figure = Figure(figsize=(17, 6), dpi=100)  # fixed margins: a layout engine costs seconds
    gap_axes, top_axes, side_axes = figure.subplots(
        1, 3, gridspec_kw={'width_ratios': (1.4, 1.0, 1.0), 'left': 0.045, 'right': 0.99,
                           'bottom': 0.09, 'top': 0.84, 'wspace': 0.2})
    figure.suptitle(impact_title(analysis, impact, number, true_stamp), fontsize=14)
    bat = bat_samples(window, config)
    balls = shown(window, window.ball)
    ball = ([s for s, _ in balls], [v for _, v in balls])
    _gap_panel(gap_axes, impact, config, window, analysis.frame_id, bat, true_stamp)
    for axes, plane, title in ((top_axes, (0, 1), 'Seen from above (x, y)'),
                               (side_axes, (1, 2), 'Seen from the side (y, z)')):
        _view_panel(axes, plane, title, ball, bat, impact, config)
    return figure


def _gap_panel(axes: Any, impact: Impact, config: DetectorConfig, window: PlotWindow,
               frame_id: str, bat: Tuple[List[int], List[BatSample]],
               true_stamp: Optional[int]) -> None:
    """Draw the gap (cm) against the time from the impact (ms)."""
    origin = impact.stamp_ns
    gap = ModelGap(config, config.model, origin, window, frame_id)
    straight = None if config.model == 'linear' else ModelGap(
        config, 'linear', origin, window, frame_id)
    start, end = gap.span
    low, high = -1.0, 10.0
    if end > start:
        times = np.linspace(start, end, CURVE_POINTS)
        curve = gap.curve(times) * 100.0
        at = np.array([t for t in gap.ball_t if start <= t <= end])
        axes.plot(times * 1e3, curve, color='tab:blue', lw=2.2, zorder=3,
                  label=f'gap, {config.model} model (used)')
        if straight is not None:
            lines = straight.curve(times) * 100.0
            axes.plot(times * 1e3, lines, color='black', lw=1.2, ls=(0, (4, 3)), zorder=4,
                      label='gap, straight lines (comparison)')
            curve = np.concatenate([curve, lines])
        axes.plot(at * 1e3, gap.curve(at) * 100.0, 'o', color='tab:blue', ms=6, zorder=4,
                  label='at ball samples')
        finite = curve[np.isfinite(curve)]
        if finite.size:
            low = min(-1.0, float(finite.min()) - 1.0)
            high = min(float(finite.max()), 40.0) + 2.0
        _zoom(axes, gap, straight, origin, true_stamp)
    axes.set_ylim(low, high)
    bat_ms = [(s - origin) * 1e-6 for s in bat[0]]
    axes.plot(bat_ms, [low + 0.04 * (high - low)] * len(bat_ms), '|', color='tab:orange',
              ms=18, mew=2, zorder=4, label='bat samples')
    if true_stamp is not None:
        axes.axvline((true_stamp - origin) * 1e-6, color='black', lw=4, alpha=0.3, zorder=1,
                     label=f'true contact ({_ms(true_stamp - origin)} ms)')
    axes.axvline(0.0, color='tab:red', lw=1.8, ls=(0, (5, 3)), zorder=5, label='impact found')
    axes.axhline(0.0, color='black', lw=0.8, zorder=1)
    axes.text(0.01, 0.0, ' touching', transform=axes.get_yaxis_transform(), va='bottom',
              fontsize=9, color='0.3')
    axes.set_title('Gap between ball and bat around the impact', fontsize=12)
    axes.set_xlabel('time from the impact (ms)')
    axes.set_ylabel('gap between ball and bat (cm)')
    axes.grid(True, alpha=0.3)
    axes.legend(loc='upper right', fontsize='small', framealpha=0.9)


def _zoom(axes: Any, gap: ModelGap, straight: Optional[ModelGap], origin: int,
          true_stamp: Optional[int]) -> None:
    """Draw an inset: the gap within :data:`ZOOM_MS` of the impact, where it crosses 0."""
    inset = axes.inset_axes((0.06, 0.45, 0.3, 0.38))
    start, end = gap.span
    times = np.linspace(max(start, -ZOOM_MS * 1e-3), min(end, ZOOM_MS * 1e-3), 100)
    inset.plot(times * 1e3, gap.curve(times) * 100.0, color='tab:blue', lw=2.2)
    if straight is not None:
        inset.plot(times * 1e3, straight.curve(times) * 100.0, color='black', lw=1.2,
                   ls=(0, (4, 3)))
    if true_stamp is not None:
        inset.axvline((true_stamp - origin) * 1e-6, color='black', lw=4, alpha=0.3)
    inset.axvline(0.0, color='tab:red', lw=1.8, ls=(0, (5, 3)))
    inset.axhline(0.0, color='black', lw=0.8)
    inset.set_xlim(-ZOOM_MS, ZOOM_MS)
    inset.set_ylim(-2.0, 4.0)
    inset.set_title(f'zoom: {ZOOM_MS:g} ms either side', fontsize=9)
    inset.tick_params(labelsize=8)
    inset.grid(True, alpha=0.3)


def _view_panel(axes: Any, plane: Tuple[int, int], title: str,
                ball: Tuple[List[int], List[Any]], bat: Tuple[List[int], List[BatSample]],
                impact: Impact, config: DetectorConfig) -> None:
    """Draw bat and ball samples, the bat and ball at impact, contact and normal (cm)."""
    from matplotlib.patches import Circle
    i, j = plane
    centre = np.array(impact.point, dtype=float)

    def cm(point: Any) -> Tuple[float, float]:
        offset = (np.asarray(point, dtype=float) - centre) * 100.0
        return float(offset[i]), float(offset[j])

    for index, sample in enumerate(bat[1]):
        (x0, y0), (x1, y1) = cm(sample.knob), cm(sample.tip)
        axes.plot([x0, x1], [y0, y1], color='tab:orange', alpha=0.55, lw=1.2,
                  label='bat at its samples' if index == 0 else None)
    (x0, y0), (x1, y1) = cm(impact.knob), cm(impact.tip)
    axes.plot([x0, x1], [y0, y1], color='saddlebrown', lw=5, solid_capstyle='round',
              label='bat at impact (knob to tip)')
    axes.plot([x1], [y1], 'o', color='saddlebrown', ms=7)
    if ball[1]:
        points = np.array([cm(v) for v in ball[1]])
        axes.plot(points[:, 0], points[:, 1], 'o-', color='tab:blue', ms=4, lw=1,
                  label='ball at its samples')
    bx, by = cm(impact.ball_position)
    axes.add_patch(Circle((bx, by), config.ball_radius * 100.0, fill=False, color='tab:blue',
                          lw=2, label='ball at impact'))
    nx, ny = (np.asarray(impact.normal, dtype=float) * NORMAL_CM)[[i, j]]
    axes.annotate('', xy=(nx, ny), xytext=(0.0, 0.0),
                  arrowprops={'arrowstyle': '->', 'color': 'goldenrod', 'lw': 2.5})
    axes.plot([], [], color='goldenrod', lw=2.5, label='contact normal (bat to ball)')
    axes.plot([0.0], [0.0], '*', color='tab:red', ms=16, zorder=5, label='contact point')
    axes.set_xlabel(f"{'xyz'[i]} from the contact point (cm)")
    axes.set_ylabel(f"{'xyz'[j]} from the contact point (cm)")
    axes.set_aspect('equal', adjustable='datalim')
    axes.set_title(title, fontsize=12)
    axes.grid(True, alpha=0.3)
    axes.legend(loc='best', fontsize='small', framealpha=0.9)


def plot_names(analyses: Sequence[BagAnalysis]) -> List[str]:
    """
    Return the PNG names ``--plot`` writes, bag by bag (:func:`.report.plot_files`' rule).

    ``<bag stem>_impact_<n>.png`` per impact, then ``<bag stem>_summary.png``; bags whose
    stems are the same get their position as a prefix.
    """
    return [name for names in plot_files(analyses) for name in names]


def _save(figure: Any, target: Path) -> None:
    figure.savefig(target, dpi=100)


def write_plots(analyses: Sequence[BagAnalysis], directory: Path, *, jobs: Optional[int] = 1,
                progress: bool = True) -> List[Path]:
    """
    Draw the PNGs of :func:`plot_names` into ``directory`` (which must exist).

    Each bag's figures are one task (:func:`draw_bag`): ``jobs`` bags at a time, each in its
    own process (:func:`~.pool.in_pool`; the figures' drawing is most of ``--plot``'s time:
    about 0.5 s a figure), the same files as one after another.

    :param jobs: processes (None: one per core this process may use; 1: this process).
    :param progress: show a bar of bags drawn on a terminal (with more than one process).
    :returns: the files written, in :func:`plot_names`' order.
    :raises ToolError: a bag cannot be read again.
    """
    tasks = [(analysis, names, directory)
             for analysis, names in zip(analyses, plot_files(analyses))]
    workers = min(cores() if jobs is None else jobs, len(tasks))
    if workers <= 1:
        drawn = [draw_bag(task) for task in tasks]
    else:
        drawn = in_pool(draw_bag, tasks, workers, progress=progress)
    return [path for paths in drawn for path in paths]


def draw_bag(task: Tuple[BagAnalysis, Sequence[str], Path]) -> List[Path]:
    """
    Draw one bag's figures: each impact's (its bag read again), then the summary.

    :param task: the analysis, its PNG names (:func:`.report.plot_files`: one per impact,
        then the summary's) and the directory to write them in.
    :returns: the files written.
    :raises ToolError: the bag cannot be read again.
    """
    analysis, names, directory = task
    truths = {id(impact): int(truth['stamp_ns'])
              for truth, impact in (analysis.truth.matched if analysis.truth else [])}
    written = []
    windows = collect_windows(analysis)
    for number, (window, name) in enumerate(zip(windows, names[:-1], strict=True), 1):
        target = directory / name
        _save(impact_figure(window, analysis, number, truths.get(id(window.impact))), target)
        written.append(target)
    target = directory / names[-1]
    _save(summary_figure(analysis), target)
    written.append(target)
    return written
