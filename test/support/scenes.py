"""
Shared scenes and references for the core's tests.

A continuous swing and pitches with exact first contacts; the solver's shared vectors; and
brute-force references (dense sampling, refined by bisection).
"""

import json
import math
from typing import Callable, List, Optional, Sequence, Tuple

from baseball_collision.core.bat import BatProfile, WOOD_BAT_34
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample
from baseball_collision.core.toi import profile_gap
from hypothesis import strategies as st
import numpy as np
from support import REPO_ROOT

BASE_NS = 1_700_000_000_000_000_000  # an absolute epoch stamp: floats cannot hold it exactly
LENGTH = WOOD_BAT_34.length


def swing(t: float) -> Tuple[np.ndarray, np.ndarray]:
    """Return knob and tip of a bat turning about moving hands, accelerating (continuous)."""
    angle = -1.2 + 30.0 * t + 100.0 * t * t
    knob = np.array([0.0, 2.0 * t, 1.0])
    return knob, knob + LENGTH * np.array([math.cos(angle), math.sin(angle), 0.0])


def turning_bat(rate: float, count: int, turned: int = -1, off: float = 0.0) -> Stream:
    """Return a bat stream turning at 40 rad/s about its knob, frame ``turned`` moved ``off``."""
    bat = Stream('bat')
    for i in range(count):
        t = i / rate
        angle = 40.0 * t + 100.0 * t * t
        knob = (0.2 * t, 0.0, 1.0)
        tip = (knob[0] + 0.86 * math.cos(angle), 0.86 * math.sin(angle), 1.0 + (
            off if i == turned else 0.0))
        bat.append(t, int(round(t * 1e9)) + 1, BatSample(knob, tip), i == 0)
    return bat


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


# ----------------------------------------------------------------------------------------------
# The solver's shared vectors and brute-force references

VECTORS: List[dict] = json.loads(
    (REPO_ROOT.parent / 'shared' / 'vectors' / 'time_of_impact_linear.json').read_text())['cases']
"""The shared time-of-impact vectors (``../shared/vectors``): inputs and expected times."""

POINT_NAMES = ('ball0', 'ball1', 'tip0', 'tip1', 'knob0', 'knob1')


def vector_args(case: dict) -> tuple:
    """Return a vector's ``time_of_impact`` arguments."""
    return tuple(case[k] for k in POINT_NAMES) + (
        case['ball_radius'], case['bat_radius'], case['dt'])


def agrees(expected: Optional[float], got, dt: float) -> bool:
    """Return whether a solver's time (None or NaN: no contact) agrees with a vector's."""
    if expected is None or got is None or (isinstance(got, float) and math.isnan(got)):
        return expected is None and (got is None or math.isnan(got))
    return abs(expected - got) <= 1e-9 * dt + 1e-12


def reference_gap(tau: np.ndarray, ball0, ball1, tip0, tip1, knob0, knob1,
                  radius: float) -> np.ndarray:
    """Return the point-segment gap minus ``radius`` at normalised times tau, point by point."""
    tau = np.asarray(tau, dtype=float)[:, None]
    ball = np.asarray(ball0) + (np.asarray(ball1) - np.asarray(ball0)) * tau
    tip = np.asarray(tip0) + (np.asarray(tip1) - np.asarray(tip0)) * tau
    knob = np.asarray(knob0) + (np.asarray(knob1) - np.asarray(knob0)) * tau
    gaps = []
    for b, e, s in zip(ball, tip, knob):
        axis = e - s
        length2 = float(axis @ axis)
        lam = 0.0 if length2 == 0.0 else min(1.0, max(0.0, float((b - s) @ axis) / length2))
        gaps.append(math.dist(b, s + lam * axis) - radius)
    return np.array(gaps)


def sampling_decides(min_gap: float, ball0, ball1, tip0, tip1, knob0, knob1,
                     samples: int) -> bool:
    """
    Return whether dense sampling's smallest gap (m) decides contact over an interval.

    The gap changes with tau at most as fast as the ball plus the faster bat end move (every
    point of the segment moves at most as fast as its faster end), so between two of
    ``samples`` evenly spaced samples the true gap is within half a step times that of the
    sampled one: a gap nearer zero than that (and 0.1 mm) may hide a touch between samples.
    """
    speed = math.dist(ball0, ball1) + max(math.dist(tip0, tip1), math.dist(knob0, knob1))
    return abs(min_gap) > 1e-4 + 0.5 * speed / (samples - 1)


def reference_first_contact(ball0, ball1, tip0, tip1, knob0, knob1, radius: float,
                            samples: int = 4001) -> Tuple[Optional[float], float]:
    """Return (first contact tau or None, smallest sampled gap)."""
    tau = np.linspace(0.0, 1.0, samples)
    gaps = reference_gap(tau, ball0, ball1, tip0, tip1, knob0, knob1, radius)
    hits = np.flatnonzero(gaps <= 0.0)
    if hits.size == 0:
        return None, float(gaps.min())
    first = int(hits[0])
    if first == 0:
        return 0.0, float(gaps.min())
    lo, hi = tau[first - 1], tau[first]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        gap = reference_gap(np.array([mid]), ball0, ball1, tip0, tip1, knob0, knob1, radius)[0]
        lo, hi = (lo, mid) if gap <= 0.0 else (mid, hi)
    return hi, float(gaps.min())


def cone_reference_gap(ball: np.ndarray, start: np.ndarray, end: np.ndarray, r0: float,
                       r1: float) -> np.ndarray:
    """
    Return the gap (m) of points to a round cone, row by row, by ternary search.

    The round cone is the union of the spheres on start-end whose radius grows linearly from
    r0 to r1: the gap is the least over the fraction g of |ball - (start + g (end - start))|
    - r(g), convex in g, found by 100 ternary steps on [0, 1] (no closed form: the solver's own
    is what this checks). Rows: (N, 3) arrays.
    """
    lo, hi = np.zeros(len(ball)), np.ones(len(ball))

    def gap(g: np.ndarray) -> np.ndarray:
        return (np.linalg.norm(ball - start - g[:, None] * (end - start), axis=1)
                - (r0 + g * (r1 - r0)))
    for _ in range(100):
        a, b = lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0
        left = gap(a) <= gap(b)
        lo, hi = np.where(left, lo, a), np.where(left, b, hi)
    return np.minimum(gap(0.5 * (lo + hi)), np.minimum(gap(np.zeros(len(ball))),
                                                       gap(np.ones(len(ball)))))


def profile_reference(tau: np.ndarray, points: Sequence, ball_radius: float,
                      profile: BatProfile) -> np.ndarray:
    """Return the gap to the union of a profile's round cones at normalised times tau."""
    ball0, ball1, tip0, tip1, knob0, knob1 = (np.asarray(p, float) for p in points)
    tau = np.asarray(tau, dtype=float)[:, None]
    ball, tip, knob = (a + (b - a) * tau for a, b in ((ball0, ball1), (tip0, tip1),
                                                      (knob0, knob1)))
    gaps = [cone_reference_gap(ball, knob + f0 * (tip - knob), knob + f1 * (tip - knob), r0, r1)
            for f0, f1, r0, r1 in profile.segments()]
    return np.min(gaps, axis=0) - ball_radius


coordinate = st.floats(-1.0, 1.0, allow_nan=False, allow_infinity=False)
point = st.tuples(coordinate, coordinate, coordinate)
"""A point in the unit cube (m)."""


@st.composite
def swing_interval(draw):
    """Draw a bat turning about the hands by up to 0.5 rad and a ball crossing near it."""
    length = draw(st.floats(0.3, 1.0))
    angle0 = draw(st.floats(-math.pi, math.pi))
    turn = draw(st.floats(-0.5, 0.5))
    hands = np.array(draw(point)) * 0.2
    knob0 = hands
    knob1 = hands + np.array(draw(point)) * 0.02
    tip0 = knob0 + length * np.array([math.cos(angle0), math.sin(angle0), 0.0])
    tip1 = knob1 + length * np.array([math.cos(angle0 + turn), math.sin(angle0 + turn), 0.0])
    fraction = draw(st.floats(-0.2, 1.2))
    aim = knob0 + fraction * (tip0 - knob0) + np.array(draw(point)) * 0.1
    velocity = np.array(draw(point)) * 0.5
    ball0 = aim - 0.5 * velocity
    ball1 = aim + 0.5 * velocity
    return (ball0, ball1, tip0, tip1, knob0, knob1)
