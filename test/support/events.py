"""Detector events of the shared swing (``scenes``), for tests of what the node makes of them."""

from typing import Any, List, Sequence, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, Event, Impact
from baseball_collision.core.detector.chunks import ROLE_CODES
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


Row = Tuple[str, int, Tuple[float, ...], str]
"""(role, stamp in ns, values, frame_id)."""


def arrays(rows: Sequence[Row]) -> Tuple[np.ndarray, np.ndarray, np.ndarray, List[str]]:
    """Return rows as ``add_chunk``'s arrays."""
    values = np.zeros((len(rows), 7))
    for r, row in enumerate(rows):
        values[r, :len(row[2])] = row[2]
    return (np.array([ROLE_CODES[row[0]] for row in rows], np.int8),
            np.array([row[1] for row in rows], np.int64), values, [row[3] for row in rows])
