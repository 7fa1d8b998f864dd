"""
Simulated recordings: pitches and swings (``simulation``) written as a bag plus a truth file.

No rclpy. What ``baseball-collision simulate`` writes:

* One bag with the ball as ``geometry_msgs/PointStamped`` on ``/ball`` and the bat as a
  ``PoseStamped`` on ``/bat_pose`` and/or as knob and tip ``PointStamped`` on ``/bat_knob`` and
  ``/bat_tip``: the ``impact_node``'s default topics, so a replay reaches the node without
  remapping. Every message has the same ``frame_id`` (``world``); log time = header stamp.
* Pitch ``i`` (kinds cycling through ``kinds``) starts at ``start_ns + i * spacing_s``: its
  samples cover ``[0, lead_s + trail_s]`` of scenario time and nothing is published between two
  pitches (each pitch is a fresh tracking episode; the detector reports a stream gap).
* Beside the bag, ``<name>.truth.json`` (see :func:`.truth.truth_path`): the settings and, per
  pitch, :func:`simulation.truth_dict` (exact first-contact stamp, contact spot, speeds, ...).
"""

from dataclasses import asdict, dataclass
import json
import math
import os
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from .choices import BAT_CHOICES, FAMILIES, KINDS, MAX_RATE_HZ, MAX_SEED, NOISE_ON
from .outputs import Outputs
from .sim import DEFAULT_START_NS, make_scenario, sample, Scenario, truth_dict
from .truth import TRUTH_FORMAT, truth_path
from ..bags import path_message, POINT_STAMPED, POSE_STAMPED
from ..errors import BagError, ToolError

TOPICS = {'ball': '/ball', 'bat_pose': '/bat_pose', 'knob': '/bat_knob', 'tip': '/bat_tip'}
"""Topic per role: the ``impact_node``'s default ``*_topic`` parameters, resolved."""

PLAN_TOPIC = '/bat_plan'
"""The topic of a recording's arm plans (``RecordingSpec.plan_hz``)."""

MAX_STAMP_NS = (2 ** 31 - 1) * 1_000_000_000
"""Latest stamp a ROS header holds (its ``sec`` is an int32: 2038-01-19T03:14:07Z)."""


@dataclass(frozen=True)
class RecordingSpec:
    """
    What to simulate and how to sample it.

    :ivar count: number of pitches (>= 1).
    :ivar kinds: scenario kinds, cycled (``simulation.KINDS``).
    :ivar rate_hz: nominal tracker rate (Hz).
    :ivar jitter_s: standard deviation of the stamp jitter (s).
    :ivar grid_s: stamp grid (s; e.g. 0.001 for a millisecond mocap clock), None for none.
    :ivar noise_m: position noise per axis (m).
    :ivar marker_spread_m: None: the bat's noise one draw shared by pose, knob and tip (its
        knob-tip length exact); else knob and tip markers with their own noise each, and the
        pose's orientation noise of a rigid-body solve over markers this far apart (m, > 0;
        ``sim.sample``'s).
    :ivar noise_on: the bodies it is on (``'both'``, ``'ball'``, ``'bat'``: ``NOISE_ON``; an
        arm's bat from its joints is exact beside a camera-tracked ball).
    :ivar spacing_s: time between two pitch starts (s); more than ``lead_s + trail_s``.
    :ivar seed: random seed: the recording is a function of the spec.
    :ivar frame_id: every message's frame.
    :ivar bat: ``'both'``, ``'pose'`` or ``'points'`` (see :data:`BAT_CHOICES`).
    :ivar start_ns: stamp of the first pitch start (ns).
    :ivar lead_s: time from a pitch start to (about) the contact (s).
    :ivar trail_s: time tracked after it (s).
    :ivar unique: draw only this many scenarios and cycle them (a large benchmark bag); None:
        every pitch is drawn.
    :ivar family: the swing family (``sim.FAMILIES``: ``'plane'``, today's fixed-plane swing;
        ``'rebound'`` a real hit, the bat braking and the ball leaving it).
    :ivar ball_rate_hz: the ball's own nominal rate (Hz; cameras beside a bat tracked by mocap
        or a robot's joints at ``rate_hz``), None for ``rate_hz``.
    :ivar spin: spinning pitches (``make_scenario``'s ``spin``: the Magnus force bends each
        flight by 1-7 m/s^2 across it); else none.
    :ivar plan_hz: a robot arm's commanded swing on ``PLAN_TOPIC`` (``nav_msgs/Path``, what
        the node takes on ``bat_plan_topic``): one plan a pitch, its poses this often (Hz)
        over the pitch's span, logged right after the pitch's first message of every input
        (tracking runs: the node checks a plan's frame against the trackers'; at that log time,
        where ``analyze`` takes it too, after the samples); None: none.
    """

    count: int = 12
    kinds: Tuple[str, ...] = KINDS
    rate_hz: float = 360.0
    jitter_s: float = 0.0002
    grid_s: Optional[float] = None
    noise_m: float = 0.0
    spacing_s: float = 2.0
    seed: int = 0
    frame_id: str = 'world'
    bat: str = 'both'
    start_ns: int = DEFAULT_START_NS
    lead_s: float = 0.25
    trail_s: float = 0.15
    unique: Optional[int] = None
    family: str = 'plane'
    ball_rate_hz: Optional[float] = None
    noise_on: str = 'both'
    marker_spread_m: Optional[float] = None
    spin: bool = False
    plan_hz: Optional[float] = None

    def check(self) -> None:
        """
        Check the values can make a recording.

        :raises ToolError: a value out of range, naming it.
        """
        if self.count < 1:
            raise ToolError(f'count must be >= 1, got {self.count}')
        if not self.kinds:
            raise ToolError('kinds must name at least one kind')
        unknown = [kind for kind in self.kinds if kind not in KINDS]
        if unknown:
            raise ToolError(
                f"unknown kind(s) {', '.join(unknown)}; choose from {', '.join(KINDS)}")
        if self.family not in FAMILIES:
            raise ToolError(
                f"family must be one of {', '.join(FAMILIES)}, got {self.family!r}")
        spread = self.marker_spread_m
        if spread is not None and not (math.isfinite(spread) and spread > 0.0):
            raise ToolError(f'marker_spread_m must be a finite number > 0, got {spread}')
        if self.noise_on not in NOISE_ON:
            raise ToolError(
                f"noise_on must be one of {', '.join(NOISE_ON)}, got {self.noise_on!r}")
        if self.plan_hz is not None and not (
                math.isfinite(self.plan_hz) and 0.0 < self.plan_hz <= MAX_RATE_HZ):
            raise ToolError(f'plan_hz must be above 0 and at most {MAX_RATE_HZ:g} Hz, got '
                            f'{self.plan_hz}')
        if self.bat not in BAT_CHOICES:
            raise ToolError(f"bat must be one of {', '.join(BAT_CHOICES)}, got {self.bat}")
        for name in ('rate_hz', 'spacing_s', 'lead_s', 'trail_s'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ToolError(f'{name} must be a finite number > 0, got {value}')
        for name in ('jitter_s', 'noise_m'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ToolError(f'{name} must be a finite number >= 0, got {value}')
        if self.grid_s is not None and not (math.isfinite(self.grid_s) and self.grid_s >= 1e-9):
            raise ToolError(f'grid_s must be at least 1 ns, got {self.grid_s}')
        if self.spacing_s <= self.lead_s + self.trail_s + 0.01:
            raise ToolError(
                f'spacing_s ({self.spacing_s} s) must exceed one pitch '
                f'({self.lead_s + self.trail_s:.2f} s) by more than 0.01 s')
        if self.unique is not None and self.unique < 1:
            raise ToolError(f'unique must be >= 1, got {self.unique}')
        for name in ('rate_hz', 'ball_rate_hz'):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and 0.0 < value <= MAX_RATE_HZ):
                raise ToolError(
                    f'{name} must be a finite number > 0 and at most {MAX_RATE_HZ:,.0f} Hz, '
                    f'got {value:g}')
        if not 0 <= self.seed <= MAX_SEED:
            raise ToolError(f'seed must be a whole number from 0 to 2^64 - 1, got {self.seed}')
        end_ns = self.start_ns + (self.count - 1) * self.spacing_s * 1e9 + (
            self.lead_s + self.trail_s + 1.0) * 1e9
        if end_ns > MAX_STAMP_NS:
            raise ToolError(
                f'{self.count} pitches {self.spacing_s:g} s apart would end after the latest '
                'stamp a ROS header holds (2038-01-19, int32 seconds): lower spacing or count')


def _scenarios(spec: RecordingSpec, rng: np.random.Generator) -> List[Scenario]:
    """Draw the scenarios of a recording (``unique`` of them at most, cycled)."""
    drawn = spec.count if spec.unique is None else min(spec.unique, spec.count)
    pool = [make_scenario(spec.kinds[i % len(spec.kinds)], rng, lead_s=spec.lead_s,
                          trail_s=spec.trail_s, family=spec.family, spin=spec.spin)
            for i in range(drawn)]
    return [pool[i % drawn] for i in range(spec.count)]


def _plan(scenario: Scenario, start_ns: int, rate_hz: float, frame_id: str, store: Any) -> Any:
    """Return the scenario's swing as an arm's plan: its poses ``rate_hz`` over its span."""
    times = np.arange(0.0, scenario.t_end, 1.0 / rate_hz)
    positions, quaternions = scenario.swing.pose(times)
    return path_message([start_ns + int(round(t * 1e9)) for t in times], positions.tolist(),
                        quaternions.tolist(), frame_id, store)


def write_recording(path: os.PathLike, spec: RecordingSpec, storage: Optional[str] = None,
                    command: str = '') -> Dict[str, Any]:
    """
    Simulate ``spec`` and write the bag at ``path`` and its truth file beside it, atomically.

    :param path: the bag: ``*.mcap``/``*.db3`` a bare file, ``*.bag`` ROS 1, else a ROS 2 bag
        directory in ``storage``.
    :param spec: what to simulate.
    :param storage: ``'mcap'``, ``'sqlite3'`` or ``'rosbag1'``; None: from the name (MCAP for
        a directory).
    :param command: the command line that made it (recorded in the truth file).
    :returns: the truth document written.
    :raises ToolError: bad settings, an existing output (bag or truth file), or a write
        failure; nothing is left behind.
    """
    spec.check()
    path = Path(path)
    rng = np.random.default_rng(spec.seed)
    try:
        with Outputs(bag=path, truth=truth_path(path)) as outputs:
            writer = outputs.bag_writer('bag', storage)
            types = {'ball': POINT_STAMPED, 'bat_pose': POSE_STAMPED, 'knob': POINT_STAMPED,
                     'tip': POINT_STAMPED}
            used = ['ball'] + (['bat_pose'] if spec.bat != 'points' else []) + (
                ['knob', 'tip'] if spec.bat != 'pose' else [])
            for role in used:
                writer.add_topic(TOPICS[role], types[role])
            pitches = []
            messages = 0
            for index, scenario in enumerate(_scenarios(spec, rng)):
                start = spec.start_ns + int(round(index * spec.spacing_s * 1e9))
                samples = sample(scenario, spec.rate_hz, rng, jitter_s=spec.jitter_s,
                                 grid_s=spec.grid_s, noise_m=spec.noise_m, start_ns=start,
                                 ball_rate_hz=spec.ball_rate_hz, noise_on=spec.noise_on,
                                 marker_spread_m=spec.marker_spread_m)
                waiting = set(used) if spec.plan_hz is not None else set()
                for stamp, role, values in samples.messages(spec.bat):
                    if role == 'bat_pose':
                        writer.write_pose(TOPICS[role], stamp, spec.frame_id, values[:3],
                                          values[3:])
                    else:
                        writer.write_point(TOPICS[role], stamp, spec.frame_id, values)
                    messages += 1
                    if role in waiting:
                        waiting.discard(role)
                        if not waiting:  # once every input has sent (its frame is known)
                            writer.write_message(PLAN_TOPIC, _plan(
                                scenario, start, spec.plan_hz, spec.frame_id,
                                writer.typestore), stamp)
                pitches.append({'index': index, **truth_dict(scenario, start)})
            plans = {} if spec.plan_hz is None else {'bat_plan': PLAN_TOPIC}
            document = {
                'format': TRUTH_FORMAT, 'bag': path.name, 'command': command,
                'messages': messages,
                'topics': {**{role: TOPICS[role] for role in used}, **plans},
                'spec': {**asdict(spec), 'kinds': list(spec.kinds)}, 'pitches': pitches}
            outputs.stage_text('truth', json.dumps(document, indent=2, allow_nan=False) + '\n')
            outputs.commit()
    except BagError as error:
        raise ToolError(str(error)) from error
    return document
