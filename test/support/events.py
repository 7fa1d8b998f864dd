"""Detector events of the shared swing (``scenes``), for tests of what the node makes of them."""

from dataclasses import replace
from typing import Any, List, Sequence, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, Event, Impact
from baseball_collision.core.detector.chunks import ROLE_CODES
from baseball_collision.core.detector.events import LateDrop
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np

from .scenes import BASE_NS, pitch, pose


def swing_events(height: float = 1.0, horizon: float = 0.0) -> List[Event]:
    """
    Return every event of the 360 Hz swing (bat pose) against a pitch at ``height`` (m).

    1.0 m hits the barrel, 1.09 m passes 2 cm over it; ``horizon`` (s) > 0 adds predictions.
    """
    detector = Detector(DetectorConfig(prediction_horizon=horizon))
    events: List[Event] = []
    for i in range(72):
        stamp = BASE_NS + int(round(i / 360.0 * 1e9))
        events += detector.add_ball(stamp, pitch(height)(i / 360.0), 'world')
        events += detector.add_bat_pose(stamp, *pose(i / 360.0), 'world')
    return events + detector.finish()


def detect(config: DetectorConfig, samples: Any) -> Tuple[Detector, List[Impact]]:
    """Return a detector fed every message of ``samples`` (``sim.sample``) and its impacts."""
    detector = Detector(config)
    events: List[Event] = []
    for stamp, role, values in samples.messages(config.bat_input):
        events += detector.add(role, stamp, values)
    events += detector.finish()
    return detector, [event for event in events if isinstance(event, Impact)]


def detect_late_drops(config: DetectorConfig, samples: Any) -> Tuple[List[Event],
                                                                     List[LateDrop]]:
    """Return the events of ``detect``'s run and every late drop it made, in order."""
    detector = Detector(config)
    events: List[Event] = []
    late: List[LateDrop] = []
    for stamp, role, values in samples.messages(config.bat_input):
        events += detector.add(role, stamp, values)
        late += detector.stats.late_drops
    events += detector.finish()
    return events, late + detector.stats.late_drops


def ball_lost_before(samples: Any, first: int, seconds: float = 0.2) -> Any:
    """Return ``samples`` (``sim.sample``) without the ball ``seconds`` (s) before sample first."""
    stamps = samples.ball_stamps_ns
    kept = (stamps < stamps[first] - round(seconds * 1e9)) | (stamps >= stamps[first])
    return samples.with_ball_kept(kept)


def hit_after_gap(seed: int, back: int, rate: float = 360.0) -> Tuple[Any, int]:
    """
    Return a rebound hit and the index of the ball's first sample after a tracking gap.

    The ball tracked again ``back`` frames before the contact's first frame after it (1: one
    frame before the contact), exact samples at ``rate`` (Hz).
    """
    rng = np.random.default_rng(seed)
    scenario = make_scenario('barrel', rng, family='rebound', lead_s=0.4, trail_s=0.1)
    samples = sample(scenario, rate, rng)
    after = int(np.searchsorted(samples.ball_stamps_ns, samples.start_ns + int(
        round(scenario.truth.time_s * 1e9))))
    lost = ball_lost_before(samples, after - back)
    return lost, int(np.searchsorted(lost.ball_stamps_ns, samples.ball_stamps_ns[after - back]))


def without_ball_frame(samples: Any, k: int) -> Any:
    """Return ``samples`` (``sim.sample``) without ball sample k."""
    return replace(samples, ball_stamps_ns=np.delete(samples.ball_stamps_ns, k),
                   ball_positions=np.delete(samples.ball_positions, k, axis=0))


def on_bat_axis(samples: Any, k: int, distance: float = 0.0) -> Any:
    """
    Return ``samples`` with ball sample k on the bat's axis (the nearest bat sample's).

    :param distance: or that far (m) from it, toward where the sample was.
    """
    j = int(np.argmin(np.abs(samples.bat_stamps_ns - samples.ball_stamps_ns[k])))
    knob, axis = samples.knobs[j], samples.tips[j] - samples.knobs[j]
    moved = replace(samples, ball_positions=samples.ball_positions.copy())
    along = np.clip((moved.ball_positions[k] - knob) @ axis / (axis @ axis), 0.0, 1.0)
    nearest = knob + along * axis
    offset = moved.ball_positions[k] - nearest
    moved.ball_positions[k] = nearest + distance * offset / np.linalg.norm(offset)
    return moved


Row = Tuple[str, int, Tuple[float, ...], str]
"""(role, stamp in ns, values, frame_id)."""


def glitched_pitch(kind: str, family: str, seed: int, rate: float, frame: int,
                   noise_m: float = 0.0, turn: float = 0.2,
                   stamp_off_s: float = 0.0) -> Tuple[List[Row], int]:
    """
    Return a pitch's rows with one bat frame turned toward the ball, and its closest stamp.

    The ``sim`` scenario of ``kind`` and ``family`` (``default_rng(1000 * seed + 17)``, lead
    0.4 s) sampled at ``rate`` (Hz) with ``noise_m`` (m) and 0.2 ms of jitter; the bat frame
    ``frame`` frames after the one nearest the contact (a miss: the closest approach) turned
    ``turn`` (m) at the tip toward the ball sample nearest it, or, with ``stamp_off_s`` (s),
    stamped that much off instead (its pose right).
    The stamp is ns.
    """
    rng = np.random.default_rng(1000 * seed + 17)
    scenario = make_scenario(kind, rng, lead_s=0.4, family=family)
    samples = sample(scenario, rate, rng, noise_m=noise_m, jitter_s=2e-4)
    truth = scenario.truth
    closest = samples.start_ns + int((truth.time_s if truth.contact else truth.min_gap_time_s)
                                     * 1e9)
    j = int(np.argmin(np.abs(samples.bat_stamps_ns - closest))) + frame
    nearest = np.abs(samples.ball_stamps_ns - samples.bat_stamps_ns[j])
    if stamp_off_s:
        stamps = samples.bat_stamps_ns.copy()
        stamps[j] += int(round(stamp_off_s * 1e9))
        glitched = replace(samples, bat_stamps_ns=stamps)
    else:
        glitched = samples.with_bat_frame_turned(
            j, samples.ball_positions[int(np.argmin(nearest))], turn)
    return [(role, stamp, values, 'world') for stamp, role, values in glitched.messages()], \
        closest


def lost_glitched_pitch(kind: str, family: str, seed: int, back: int, lost: int = 0,
                        segment: int = 0, turn: float = 0.1) -> Tuple[List[Row], List[Row], int]:
    """
    Return a 90 Hz pitch's rows with a bat glitch beside lost frames, without it, and the approach.

    As ``bench_prediction.py --faults``' glitch beside lost frames: the ``sim`` scenario of
    ``kind`` and ``family`` (``default_rng(seed)``, lead 0.4 s, exact, 0.2 ms of jitter), its
    bat frame ``back`` frames before the approach (the contact, or a miss's closest instant)
    turned ``turn`` (m) at the tip toward the ball sample nearest it, and the bat frame
    ``lost`` frames from it deleted (not 0), or the frames over 60 ms before the frame
    ``segment`` - 1 before it (it the ``segment``-th frame of its segment). The second rows:
    the same frames lost, and the glitch's frame deleted too. The approach's stamp is ns.
    """
    rng = np.random.default_rng(seed)
    scenario = make_scenario(kind, rng, lead_s=0.4, family=family)
    samples = sample(scenario, 90.0, rng, jitter_s=2e-4)
    truth = scenario.truth
    approach = samples.start_ns + int(round(
        (truth.time_s if truth.contact else truth.min_gap_time_s) * 1e9))
    j = int(np.flatnonzero(samples.bat_stamps_ns < approach)[-back])
    if lost:
        samples, j = samples.without_bat_frame(j + lost), j - (lost < 0)
    if segment:
        stamps = samples.bat_stamps_ns
        count = int(np.ceil(0.06 * (len(stamps) - 1) / ((stamps[-1] - stamps[0]) * 1e-9)))
        samples, j = samples.without_bat_frames(int(stamps[j - segment + 1]), count), j - count
    nearest = int(np.argmin(np.abs(samples.ball_stamps_ns - samples.bat_stamps_ns[j])))
    glitched = samples.with_bat_frame_turned(j, samples.ball_positions[nearest], turn)
    glitched_rows, deleted_rows = (
        [(role, stamp, values, 'world') for stamp, role, values in feed.messages()]
        for feed in (glitched, samples.without_bat_frame(j)))
    return glitched_rows, deleted_rows, approach


def arrays(rows: Sequence[Row]) -> Tuple[np.ndarray, np.ndarray, np.ndarray, List[str]]:
    """Return rows as ``add_chunk``'s arrays."""
    values = np.zeros((len(rows), 7))
    for r, row in enumerate(rows):
        values[r, :len(row[2])] = row[2]
    return (np.array([ROLE_CODES[row[0]] for row in rows], np.int8),
            np.array([row[1] for row in rows], np.int64), values, [row[3] for row in rows])
