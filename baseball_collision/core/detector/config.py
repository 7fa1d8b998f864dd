"""
The detector's configuration: every value it needs, checked once.

Pure Python: no rclpy, no rosbags. The node's parameters use the same names.
"""

from dataclasses import dataclass, field, fields
import math
from typing import Any, Mapping

from ..bat import BatProfile, PoseBatGeometry, SWEET_SPOT_FROM_TIP, WOOD_BAT_34
from ..geometry import Vector
from ..motion import check_model
from ...errors import CoreError


@dataclass(frozen=True)
class DetectorConfig:
    """
    Everything the detector needs to know; the node's parameters use the same names.

    :ivar model: motion model between samples: ``'linear'``, ``'rigid'`` or ``'spline'``.
    :ivar bat_input: ``'pose'`` (one pose stream) or ``'points'`` (knob and tip streams).
    :ivar ball_radius: metres.
    :ivar profile: the bat's radius profile (stations from the knob), scaled to knob-tip.
    :ivar geometry: where knob and tip sit in the bat's body frame (pose input).
    :ivar max_gap: longest time (s) between two samples of a stream that is interpolated.
    :ivar max_chord_error: largest distance (m) a curved path may leave the chords solved.
    :ivar rearm_distance: gap (m) the ball must clear after an impact before another.
    :ivar near_miss_threshold: a pass with a smallest gap (m) below this is a near miss.
    :ivar max_speed: fastest plausible speed (m/s) of any tracked point between samples.
    :ivar bat_length_tolerance: knob-tip length change (m) beyond which a bat sample is a jump.
    :ivar time_jump_reset: a stamp this far (s) behind its stream's newest resets the state.
    :ivar frame_id: frame every input must be in; empty: the first sample's frame.
    :ivar up_axis: unit vector up, for the attack angle.
    :ivar sweet_spot_from_tip: distance (m) from the barrel end of the sweet spot (Statcast: 6 in).
    :ivar velocity_window: span (s) of the samples before an impact that its velocities are
        fitted to (six samples at 90 Hz, twenty-two at 360 Hz).
    :ivar prediction_horizon: how far ahead (s) to predict the coming impact after every
        processed frame; 0 turns prediction off.
    :ivar prediction_window: span (s) of the latest samples the prediction's state is fitted to.
    :ivar ball_drag: the ball's quadratic drag, rho Cd A / (2 m) (1/m): deceleration
        ``ball_drag * |v| * v``; 0.0061 for a baseball, 0 for none.
    :ivar gravity: m/s^2, along -``up_axis``.
    :ivar velocity_degree: degree (1-6) of the fit to the bat's rotation and, at low rates (six
        samples or fewer in the window), to the hands; at higher rates the hands' fit uses at
        most 3 and the ball's always at most 2 (a parabola). The default interpolates at 90 Hz,
        which is exact for clean tracking but amplifies noise: for a noisy low-rate tracker
        lower it (e.g. 2) or lengthen the window.
    """

    model: str = 'rigid'
    bat_input: str = 'pose'
    ball_radius: float = 0.0366
    profile: BatProfile = WOOD_BAT_34
    geometry: PoseBatGeometry = field(default_factory=PoseBatGeometry)
    max_gap: float = 0.05
    max_chord_error: float = 0.0005
    rearm_distance: float = 0.1
    near_miss_threshold: float = 0.15
    max_speed: float = 150.0
    bat_length_tolerance: float = 0.05
    time_jump_reset: float = 1.0
    frame_id: str = ''
    up_axis: Vector = (0.0, 0.0, 1.0)
    sweet_spot_from_tip: float = SWEET_SPOT_FROM_TIP
    velocity_window: float = 0.061
    velocity_degree: int = 5
    prediction_horizon: float = 0.0
    prediction_window: float = 0.1
    ball_drag: float = 0.0061
    gravity: float = 9.80665

    def __post_init__(self) -> None:
        """
        Check every value.

        :raises CoreError: a value out of its range, naming the field.
        """
        try:
            check_model(self.model)
        except CoreError as error:
            raise CoreError(str(error)) from error
        if self.bat_input not in ('pose', 'points'):
            raise CoreError(f"bat_input must be 'pose' or 'points', got '{self.bat_input}'")
        positive = ('ball_radius', 'max_gap', 'max_chord_error', 'max_speed',
                    'bat_length_tolerance', 'time_jump_reset', 'velocity_window',
                    'prediction_window')
        non_negative = ('rearm_distance', 'near_miss_threshold', 'sweet_spot_from_tip',
                        'prediction_horizon', 'ball_drag', 'gravity')
        for name in positive + non_negative:
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0.0 \
                    or (name in positive and value == 0.0):
                bound = '> 0' if name in positive else '>= 0'
                raise CoreError(f'{name} must be a finite number {bound}, got {value!r}')
        if not isinstance(self.velocity_degree, int) or not 1 <= self.velocity_degree <= 6:
            raise CoreError(
                f'velocity_degree must be an integer in [1, 6], got {self.velocity_degree!r}')
        up = tuple(float(x) for x in self.up_axis)
        length = math.sqrt(sum(x * x for x in up)) if len(up) == 3 else 0.0
        if not (math.isfinite(length) and length > 0.0):
            raise CoreError(f'up_axis must be a non-zero 3-vector, got {self.up_axis!r}')
        object.__setattr__(self, 'up_axis', tuple(x / length for x in up))

    @classmethod
    def from_parameters(cls, parameters: Mapping[str, Any]) -> 'DetectorConfig':
        """
        Build a config from flat parameters, as in the node's YAML file.

        Keys are the field names, plus the bat description: ``bat_profile`` (flat list
        ``[distance_from_knob, radius, ...]`` in metres, empty for the default wood bat),
        ``bat_length`` (metres the profile was measured on), ``bat_radius`` (> 0 replaces the
        profile by a capsule of that radius), ``bat_axis`` (body axis from knob to tip: x, y, z,
        -x, -y, -z), ``knob_offset`` and ``tip_offset`` (signed distances along that axis, m).
        Unknown keys are ignored (the node has parameters of its own).

        :raises CoreError: a value of the wrong type or out of range, naming the key.
        """
        known = {f.name for f in fields(cls)} - {'profile', 'geometry'}
        values = {k: v for k, v in parameters.items() if k in known}
        try:
            for name in ('ball_radius', 'max_gap', 'max_chord_error', 'rearm_distance',
                         'near_miss_threshold', 'max_speed', 'bat_length_tolerance',
                         'time_jump_reset', 'sweet_spot_from_tip', 'velocity_window',
                         'prediction_horizon', 'prediction_window', 'ball_drag', 'gravity'):
                if name in values:
                    values[name] = float(values[name])
            if 'velocity_degree' in values:
                degree = values['velocity_degree']
                if isinstance(degree, float) and degree.is_integer():
                    degree = int(degree)
                values['velocity_degree'] = degree
            if 'up_axis' in values:
                values['up_axis'] = tuple(float(x) for x in values['up_axis'])
            profile = _profile_from_parameters(parameters)
            geometry = PoseBatGeometry.along_axis(
                str(parameters.get('bat_axis', 'z')),
                float(parameters.get('knob_offset', 0.0)),
                float(parameters.get('tip_offset', profile.length)))
        except (TypeError, ValueError, CoreError) as error:
            raise CoreError(f'bad bat or detector parameter: {error}') from error
        return cls(profile=profile, geometry=geometry, **values)


def _profile_from_parameters(parameters: Mapping[str, Any]) -> BatProfile:
    bat_radius = float(parameters.get('bat_radius', 0.0))
    flat = list(parameters.get('bat_profile', []) or [])
    length = float(parameters.get('bat_length', 0.0)) or (
        WOOD_BAT_34.length if not flat else float(flat[-2]))
    if bat_radius > 0.0:
        return BatProfile.constant(bat_radius, length)
    if not flat:
        return WOOD_BAT_34 if length == WOOD_BAT_34.length else BatProfile(
            stations=tuple((d * length / WOOD_BAT_34.length, r)
                           for d, r in WOOD_BAT_34.stations), length=length)
    if len(flat) % 2:
        raise CoreError('bat_profile must list pairs: distance_from_knob, radius')
    return BatProfile.from_sequence(list(zip(flat[::2], flat[1::2])), length)
