"""A continuous swing and pitches with exact first contacts: the scene many tests share."""

import math
from typing import Callable, Optional, Tuple

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.toi import profile_gap
import numpy as np

BASE_NS = 1_700_000_000_000_000_000  # an absolute epoch stamp: floats cannot hold it exactly
LENGTH = WOOD_BAT_34.length


def swing(t: float) -> Tuple[np.ndarray, np.ndarray]:
    """Return knob and tip of a bat turning about moving hands, accelerating (continuous)."""
    angle = -1.2 + 30.0 * t + 100.0 * t * t
    knob = np.array([0.0, 2.0 * t, 1.0])
    return knob, knob + LENGTH * np.array([math.cos(angle), math.sin(angle), 0.0])


def pose(t: float) -> Tuple[np.ndarray, np.ndarray]:
    """Return the swing as a pose: knob at the body origin, tip along body +z."""
    knob, tip = swing(t)
    direction = (tip - knob) / LENGTH
    # rotation taking +z to direction (direction is horizontal here)
    axis = np.cross([0.0, 0.0, 1.0], direction)
    angle = math.acos(np.clip(direction[2], -1.0, 1.0))
    axis = axis / np.linalg.norm(axis)
    quaternion = np.concatenate([axis * math.sin(angle / 2), [math.cos(angle / 2)]])
    return knob, quaternion


def pitch(height: float = 1.0) -> Callable[[float], np.ndarray]:
    """Return a ball crossing the zone at 40 m/s at a given height."""
    return lambda t: np.array([0.6, 2.9 - 40.0 * t, height])


def first_contact(ball: Callable[[float], np.ndarray]) -> Optional[float]:
    """Exact first contact of the continuous motion (dense scan, then bisection)."""
    def gap(t: float) -> float:
        knob, tip = swing(t)
        return profile_gap(tuple(ball(t)), tuple(knob), tuple(tip), 0.0366, WOOD_BAT_34)[0]
    times = np.arange(0.0, 0.2, 2e-5)
    for lo, hi in zip(times[:-1], times[1:]):
        if gap(hi) <= 0.0:
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                lo, hi = (lo, mid) if gap(mid) <= 0.0 else (mid, hi)
            return hi
    return None
