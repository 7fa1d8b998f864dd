"""
A scenario as a tracker reports it, and its truth as JSON.

``sample``: nominal rate, timestamp jitter, a stamp grid, position noise; sample stamps are
integer nanoseconds, ``start_ns + round(t * 1e9)``. ``truth_dict``: the truth as JSON for a
truth file beside a bag.
"""

from dataclasses import dataclass, replace
import math
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from .common import check_number
from .scenarios import Scenario
from ..choices import NOISE_ON  # the command line's options read them without the simulator
from ...core.geometry import axis_angle_quaternions, quaternion_multiply, quaternion_to_matrix
from ...errors import ToolError

DEFAULT_START_NS = 1_700_000_000_000_000_000
"""Default absolute stamp (ns since the epoch) of the scenario start in ``sample``."""

AXIS_TOLERANCE = 1e-9
"""A point this far (a fraction of the bat's length) from the bat's axis is on it, for
``Samples.with_bat_frame_turned``: the part left of a point on the axis once its part along
the bat is taken out is rounding, whose direction is noise (measured: 1e-17 m on an AMD EPYC,
where a turn about it came out 0.2 % short of a unit quaternion)."""


@dataclass(frozen=True)
class Samples:
    """
    A scenario as trackers report it.

    Stamps are absolute int64 nanoseconds, strictly increasing; the scenario time of a stamp is
    ``(stamp - start_ns) * 1e-9`` s. Positions are the truth at the stamped instant plus noise.

    :ivar ball_stamps_ns: (N,) int64.
    :ivar ball_positions: (N, 3) ball centres (m).
    :ivar bat_stamps_ns: (M,) int64.
    :ivar bat_positions: (M, 3) bat pose positions (m).
    :ivar bat_quaternions: (M, 4) bat pose orientations, unit (x, y, z, w).
    :ivar knobs: (M, 3) knobs (m): ``geometry.knob_and_tip`` of the (noisy) pose, or markers
        with noise of their own (``marker_spread_m``).
    :ivar tips: (M, 3) tips (m), likewise.
    :ivar start_ns: absolute stamp of the scenario start (ns).
    """

    ball_stamps_ns: np.ndarray
    ball_positions: np.ndarray
    bat_stamps_ns: np.ndarray
    bat_positions: np.ndarray
    bat_quaternions: np.ndarray
    knobs: np.ndarray
    tips: np.ndarray
    start_ns: int

    def without_bat_frames(self, before_ns: int, count: int) -> 'Samples':
        """
        Return these samples without the bat's last ``count`` frames stamped before a stamp.

        Frames a tracker lost: a marker occluded at the contact, samples dropped in transit.

        :param before_ns: the stamp (ns; e.g. the true contact's).
        """
        before = np.flatnonzero(self.bat_stamps_ns < before_ns)
        keep = np.ones(len(self.bat_stamps_ns), bool)
        keep[before[len(before) - count:]] = False
        return self.with_bat_kept(keep)

    def without_bat_frame(self, index: int) -> 'Samples':
        """Return these samples without bat frame ``index`` (a glitch's frame deleted)."""
        keep = np.ones(len(self.bat_stamps_ns), bool)
        keep[index] = False
        return self.with_bat_kept(keep)

    def with_ball_kept(self, keep: np.ndarray) -> 'Samples':
        """Return these samples with the ball samples where ``keep`` (N,) is True."""
        return replace(self, ball_stamps_ns=self.ball_stamps_ns[keep],
                       ball_positions=self.ball_positions[keep])

    def with_bat_kept(self, keep: np.ndarray) -> 'Samples':
        """Return these samples with the bat frames where ``keep`` (M,) is True."""
        return replace(self, bat_stamps_ns=self.bat_stamps_ns[keep],
                       bat_positions=self.bat_positions[keep],
                       bat_quaternions=self.bat_quaternions[keep], knobs=self.knobs[keep],
                       tips=self.tips[keep])

    def with_ball_frame_moved(self, index: int, offset: Sequence[float]) -> 'Samples':
        """
        Return these samples with ball sample ``index`` moved by ``offset`` (m): a glitch.

        A tracker's mislabelled or reflected blob, off the ball's flight; its stamp kept.

        :raises ToolError: an index outside the samples.
        """
        if not -len(self.ball_stamps_ns) <= index < len(self.ball_stamps_ns):
            raise ToolError(f'no ball sample {index} among {len(self.ball_stamps_ns)}')
        positions = self.ball_positions.copy()
        positions[index] += np.asarray(offset, dtype=float)
        return replace(self, ball_positions=positions)

    def with_bat_frame_turned(self, index: int, toward: Sequence[float],
                              distance: float) -> 'Samples':
        """
        Return these samples with one bat frame turned about its knob: a tracker's glitch.

        A rigid body solved onto the wrong markers, a swapped marker: frame ``index``'s bat is
        turned about its knob, its length kept, so that its tip moves ``distance`` (m) toward
        the point ``toward`` (m; across the bat: its part along the bat is left out; a point
        within ``AXIS_TOLERANCE`` of the bat's length of its axis is on it). The pose
        (position and orientation) and the knob and tip markers turn alike.

        :raises ToolError: an index outside the frames, or a point on the bat's axis.
        """
        if not -len(self.bat_stamps_ns) <= index < len(self.bat_stamps_ns):
            raise ToolError(f'no bat frame {index} among {len(self.bat_stamps_ns)}')
        knob, tip = self.knobs[index], self.tips[index]
        along = (tip - knob) / np.linalg.norm(tip - knob)
        across = np.asarray(toward, dtype=float) - knob
        across -= (across @ along) * along
        if not np.linalg.norm(across) > AXIS_TOLERANCE * np.linalg.norm(tip - knob):
            raise ToolError("the point to turn toward is on the bat's axis")
        axis = np.cross(along, across / np.linalg.norm(across))
        angle = 2.0 * math.asin(min(1.0, 0.5 * distance / np.linalg.norm(tip - knob)))
        turn = axis_angle_quaternions(axis, np.array([angle]))[0]
        matrix = quaternion_to_matrix(turn)
        arrays = {name: getattr(self, name).copy()
                  for name in ('bat_positions', 'bat_quaternions', 'knobs', 'tips')}
        for name in ('bat_positions', 'tips'):
            arrays[name][index] = knob + matrix @ (arrays[name][index] - knob)
        arrays['bat_quaternions'][index] = quaternion_multiply(
            turn, arrays['bat_quaternions'][index])
        return replace(self, **arrays)

    def messages(self, bat: str = 'pose') -> List[Tuple[int, str, Tuple[float, ...]]]:
        """
        Return the samples as a tracker publishes them: ``(stamp_ns, role, values)``.

        In stamp order; at equal stamps the ball comes first, then the bat pose, knob, tip.
        Roles and values are those of ``Detector.add``.

        :param bat: ``'pose'`` (bat poses), ``'points'`` (knob and tip) or ``'both'``.
        :raises ToolError: an unknown ``bat``.
        """
        if bat not in ('pose', 'points', 'both'):
            raise ToolError(f"bat must be 'pose', 'points' or 'both', got '{bat}'")
        rows = [(s, 0, 'ball', tuple(p)) for s, p in zip(self.ball_stamps_ns.tolist(),
                                                         self.ball_positions.tolist())]
        stamps = self.bat_stamps_ns.tolist()
        if bat in ('pose', 'both'):
            rows += [(s, 1, 'bat_pose', tuple(p + q)) for s, p, q in zip(
                stamps, self.bat_positions.tolist(), self.bat_quaternions.tolist())]
        if bat in ('points', 'both'):
            rows += [(s, 2, 'knob', tuple(p)) for s, p in zip(stamps, self.knobs.tolist())]
            rows += [(s, 3, 'tip', tuple(p)) for s, p in zip(stamps, self.tips.tolist())]
        rows.sort(key=lambda row: (row[0], row[1]))
        return [(stamp, role, values) for stamp, _, role, values in rows]


def _stamps(t_end: float, rate_hz: float, rng: np.random.Generator, jitter_s: float,
            grid_s: Optional[float], offset_s: float) -> np.ndarray:
    """Return relative stamps (ns, int64, strictly increasing, within [0, t_end])."""
    count = int(math.floor(t_end * rate_hz)) + 2
    nominal = offset_s + np.arange(count) / rate_hz
    if jitter_s > 0.0:
        nominal = nominal + rng.normal(0.0, jitter_s, count)
    relative = np.rint(nominal * 1e9).astype(np.int64)
    if grid_s is not None:
        step = int(round(grid_s * 1e9))
        relative = np.rint(relative / step).astype(np.int64) * step
    end_ns = int(math.floor(t_end * 1e9))
    relative = relative[(relative >= 0) & (relative <= end_ns)]
    return np.unique(relative)


def sample(scenario: Scenario, rate_hz: float, rng: np.random.Generator, *,
           jitter_s: float = 0.0, grid_s: Optional[float] = None, noise_m: float = 0.0,
           start_ns: int = DEFAULT_START_NS, bat_offset_s: float = 0.0,
           marker_spread_m: Optional[float] = None, noise_on: str = 'both',
           ball_rate_hz: Optional[float] = None) -> Samples:
    """
    Sample a scenario as a tracker would.

    Sample ``k`` is nominally at ``k / rate_hz`` seconds (plus ``bat_offset_s`` for the bat; the
    ball's at ``k / ball_rate_hz`` when given: a ball tracked by cameras beside a bat tracked by
    mocap or by a robot's own kinematics), plus Gaussian jitter of ``jitter_s``, rounded to the
    nanosecond and then to ``grid_s`` when given (``grid_s=0.001`` at 360 Hz gives the 2 and 3 ms
    steps of real mocap). Stamps outside [0, t_end] and repeats are dropped, so stamps strictly
    increase. Positions are the truth at the stamped instant, plus Gaussian noise of ``noise_m``
    per axis: one draw per ball sample, one per bat sample added to the pose position and so to
    knob and tip alike (knob and tip stay those of the pose). With ``marker_spread_m`` the bat is
    tracked as a motion-capture rigid body is: knob and tip are markers with their own noise of
    ``noise_m`` each, and the pose has ``noise_m`` on its position and ``noise_m /
    marker_spread_m`` rad per axis on its orientation (a small random rotation, applied in the
    world frame), the noise of a rigid-body solve over markers that far apart. With
    ``bat_offset_s == 0`` and one rate the bat has the ball's stamps. ``noise_on`` keeps the noise
    to one body (``'ball'`` or ``'bat'``; the other is exact): every draw is still made, so each
    body's noise is the one it has with ``'both'`` (an error budget compares like with like).

    :param scenario: what to sample.
    :param rate_hz: nominal sample rate (Hz, > 0).
    :param rng: the random source for jitter and noise (not drawn from when both are 0).
    :param jitter_s: standard deviation of the timestamp jitter (s, >= 0).
    :param grid_s: stamp grid (s, > 0), or None for nanosecond stamps.
    :param noise_m: standard deviation of the position noise per axis (m, >= 0).
    :param start_ns: absolute stamp (ns) of the scenario start.
    :param bat_offset_s: shift (s) of the bat stream's nominal times.
    :param marker_spread_m: the markers' spread (m, > 0; 0.3 for a bat), or None for one
        position noise shared by pose, knob and tip.
    :param noise_on: ``'both'``, ``'ball'`` or ``'bat'``: the bodies whose samples get the
        noise.
    :param ball_rate_hz: the ball's nominal sample rate (Hz, > 0), or None for ``rate_hz``.

    :returns: The samples.

    :raises ToolError: a rate, jitter, grid, noise or spread out of range, or an unknown
        ``noise_on``.
    """
    rate_hz = check_number('rate_hz', rate_hz, positive=True)
    ball_rate_hz = rate_hz if ball_rate_hz is None else check_number(
        'ball_rate_hz', ball_rate_hz, positive=True)
    jitter_s = check_number('jitter_s', jitter_s, minimum=0.0)
    noise_m = check_number('noise_m', noise_m, minimum=0.0)
    bat_offset_s = check_number('bat_offset_s', bat_offset_s)
    if noise_on not in NOISE_ON:
        raise ToolError(f"noise_on must be one of {', '.join(NOISE_ON)}, got {noise_on!r}")
    if marker_spread_m is not None:
        marker_spread_m = check_number('marker_spread_m', marker_spread_m, positive=True)
    if grid_s is not None:
        grid_s = check_number('grid_s', grid_s, positive=True)
        if round(grid_s * 1e9) < 1:
            raise ToolError(f'grid_s must be at least 1 ns, got {grid_s!r}')
    try:
        start = int(start_ns)
    except (TypeError, ValueError) as error:
        raise ToolError(f'start_ns must be an integer, got {start_ns!r}') from error
    ball_rel = _stamps(scenario.t_end, ball_rate_hz, rng, jitter_s, grid_s, 0.0)
    if bat_offset_s == 0.0 and ball_rate_hz == rate_hz:
        bat_rel = ball_rel
    else:
        bat_rel = _stamps(scenario.t_end, rate_hz, rng, jitter_s, grid_s, bat_offset_s)
    ball = scenario.pitch.position(ball_rel * 1e-9)
    bat_times = bat_rel * 1e-9
    position, quaternion = scenario.swing.pose(bat_times)
    knobs, tips = scenario.swing.knob_tip(bat_times)
    exact = ball, position, quaternion, knobs, tips
    if noise_m > 0.0 and marker_spread_m is not None:
        ball = ball + rng.normal(0.0, noise_m, ball.shape)
        position, quaternion = _shaken_pose(position, quaternion, noise_m,
                                            noise_m / marker_spread_m, rng)
        knobs = knobs + rng.normal(0.0, noise_m, knobs.shape)
        tips = tips + rng.normal(0.0, noise_m, tips.shape)
    elif noise_m > 0.0:
        ball = ball + rng.normal(0.0, noise_m, ball.shape)
        shake = rng.normal(0.0, noise_m, position.shape)
        position, knobs, tips = position + shake, knobs + shake, tips + shake
    if noise_on == 'bat':
        ball = exact[0]
    elif noise_on == 'ball':
        position, quaternion, knobs, tips = exact[1:]
    return Samples(
        ball_stamps_ns=np.int64(start) + ball_rel, ball_positions=ball,
        bat_stamps_ns=np.int64(start) + bat_rel, bat_positions=position,
        bat_quaternions=quaternion, knobs=knobs, tips=tips, start_ns=start)


def _shaken_pose(position: np.ndarray, quaternion: np.ndarray, noise_m: float, noise_rad: float,
                 rng: np.random.Generator) -> Tuple[np.ndarray, np.ndarray]:
    """Return poses (N, 3), (N, 4) with position noise and a small random rotation each."""
    position = position + rng.normal(0.0, noise_m, position.shape)
    turn = rng.normal(0.0, noise_rad, position.shape)
    angle = np.linalg.norm(turn, axis=1)
    safe = np.where(angle > 0.0, angle, 1.0)
    shake = np.concatenate([np.sin(0.5 * angle)[:, None] * turn / safe[:, None],
                            np.cos(0.5 * angle)[:, None]], axis=1)
    quaternion = quaternion_multiply(shake, quaternion)
    return position, quaternion / np.linalg.norm(quaternion, axis=1, keepdims=True)


def truth_dict(scenario: Scenario, start_ns: int = DEFAULT_START_NS) -> Dict[str, object]:
    """
    Return the scenario's truth as a JSON-serialisable dict (for a truth file beside a bag).

    Times are given both as scenario seconds and as absolute stamps
    (``start_ns + round(time_s * 1e9)``); vectors are lists; absent values are None.

    :param scenario: the scenario.
    :param start_ns: absolute stamp (ns) of the scenario start.

    :returns: The dict.
    """
    truth = scenario.truth
    start = int(start_ns)

    def stamp(seconds: Optional[float]) -> Optional[int]:
        return None if seconds is None else start + int(round(seconds * 1e9))

    def listed(vector: Optional[Sequence[float]]) -> Optional[List[float]]:
        return None if vector is None else [float(v) for v in vector]

    return {
        'name': scenario.name,
        'kind': scenario.kind,
        'start_ns': start,
        'end_ns': stamp(scenario.t_end),
        't_end_s': float(scenario.t_end),
        'contact': bool(truth.contact),
        'time_s': truth.time_s,
        'stamp_ns': stamp(truth.time_s),
        'point': listed(truth.point),
        'normal': listed(truth.normal),
        'bat_fraction': truth.bat_fraction,
        'distance_from_knob_m': truth.distance_from_knob_m,
        'distance_from_tip_m': truth.distance_from_tip_m,
        'feature': truth.feature,
        'sweet_spot_speed_mps': truth.sweet_spot_speed_mps,
        'ball_speed_mps': truth.ball_speed_mps,
        'bat_speed_at_contact_mps': truth.bat_speed_at_contact_mps,
        'min_gap_m': truth.min_gap_m,
        'min_gap_time_s': truth.min_gap_time_s,
        'min_gap_stamp_ns': stamp(truth.min_gap_time_s),
        'min_gap_vector': listed(truth.min_gap_vector),
        'min_gap_fraction': truth.min_gap_fraction,
        'ball_radius_m': float(scenario.ball_radius),
        'bat_length_m': scenario.swing.length,
        'bat_profile': {'length_m': scenario.profile.length,
                        'stations': [[d, r] for d, r in scenario.profile.stations]},
        'bat_geometry': {'knob_offset': listed(scenario.swing.geometry.knob_offset),
                         'tip_offset': listed(scenario.swing.geometry.tip_offset)},
    }
