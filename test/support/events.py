"""Detector events of the shared swing (``scenes``), for tests of what the node makes of them."""

from typing import Any, List, Tuple

from baseball_collision.core.detector import Detector, DetectorConfig, Event, Impact

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
