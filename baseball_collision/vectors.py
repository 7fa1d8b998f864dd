"""
Small 3-vector helpers on plain float tuples.

The scalar hot paths (solver, motion models, detector) work on tuples of three floats: for
vectors this small, plain float arithmetic is several times faster than numpy's per-call
overhead.
"""

import math
from typing import Sequence, Tuple

Vector = Tuple[float, float, float]


def add(a: Sequence[float], b: Sequence[float]) -> Vector:
    """Return a + b."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a: Sequence[float], b: Sequence[float]) -> Vector:
    """Return a - b."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(a: Sequence[float], s: float) -> Vector:
    """Return a * s."""
    return (a[0] * s, a[1] * s, a[2] * s)


def advance(p0: Sequence[float], p1: Sequence[float], s: float) -> Vector:
    """Return p0 + p1 * s."""
    return (p0[0] + p1[0] * s, p0[1] + p1[1] * s, p0[2] + p1[2] * s)


def lerp(a: Sequence[float], b: Sequence[float], s: float) -> Vector:
    """Return a + (b - a) * s."""
    return (a[0] + (b[0] - a[0]) * s, a[1] + (b[1] - a[1]) * s, a[2] + (b[2] - a[2]) * s)


def dot(a: Sequence[float], b: Sequence[float]) -> float:
    """Return the dot product of two 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Sequence[float], b: Sequence[float]) -> Vector:
    """Return the cross product a x b."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a: Sequence[float]) -> float:
    """Return the Euclidean length of a 3-vector."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
