"""
What the simulator's modules share: time arguments, argument checks, constants of the Gaussians.

Time inside the simulator is float seconds relative to the scenario start; every kinematic
method takes a float time or an array of times (:data:`TimeLike`).
"""

import math
from typing import Optional, Sequence, Tuple, Union

import numpy as np

from ...core.geometry import finite_number, finite_vector, Vector
from ...errors import ToolError

TimeLike = Union[float, Sequence[float], np.ndarray]

SQRT_HALF_PI = math.sqrt(0.5 * math.pi)
SQRT_TWO = math.sqrt(2.0)
SQRT_TWO_PI = math.sqrt(2.0 * math.pi)

__all__ = ['TimeLike', 'Vector', 'check_vector', 'check_number', 'unit', 'as_times', 'erf',
           'cubic_hermite']


def check_vector(name: str, value: Sequence[float]) -> Vector:
    """
    Return ``value`` as 3 finite floats.

    :raises ToolError: not 3 finite numbers.
    """
    return finite_vector(name, value, error=ToolError)


def check_number(name: str, value: float, minimum: Optional[float] = None,
                 positive: bool = False) -> float:
    """
    Return ``value`` as a finite float, optionally > 0 or >= ``minimum``.

    :raises ToolError: not a finite number, or out of range.
    """
    number = finite_number(name, value, error=ToolError)
    if positive and number <= 0.0:
        raise ToolError(f'{name} must be > 0, got {value!r}')
    if minimum is not None and number < minimum:
        raise ToolError(f'{name} must be >= {minimum}, got {value!r}')
    return number


def unit(name: str, value: np.ndarray) -> np.ndarray:
    """
    Return ``value`` scaled to unit length.

    :raises ToolError: a (near) zero vector.
    """
    norm = float(np.linalg.norm(value))
    if not norm > 1e-12:
        raise ToolError(f'{name} must not be a zero vector, got {value!r}')
    return value / norm


def as_times(t: TimeLike) -> Tuple[np.ndarray, Tuple[int, ...]]:
    """
    Return times flattened to (N,) float64 and the input shape.

    :raises ToolError: non-finite times.
    """
    array = np.asarray(t, dtype=float)
    if not np.all(np.isfinite(array)):
        raise ToolError('times must be finite seconds')
    return array.reshape(-1), array.shape


def erf(x: np.ndarray) -> np.ndarray:
    """Return the error function of every element of x (numpy has none)."""
    return np.fromiter((math.erf(v) for v in x), dtype=float, count=x.size)


def cubic_hermite(s: np.ndarray, p0: np.ndarray, p1: np.ndarray, m0: np.ndarray,
                  m1: np.ndarray, step: Union[float, np.ndarray],
                  derivative: bool) -> np.ndarray:
    """
    Return cubic Hermite pieces (or their derivatives) at fractions of them: (n, columns).

    The simulator's pitches and the reference splines evaluate their pieces with it.

    :param s: (n, 1) where along each piece (0 at its start, 1 at its end).
    :param p0, p1: (n, columns) the values at the pieces' ends.
    :param m0, m1: (n, columns) the slopes at the ends times the pieces' lengths (per unit s).
    :param step: the pieces' lengths (s): a number or (n, 1).
    :param derivative: True: the rates (per second) instead of the values.
    """
    s2 = s * s
    if derivative:
        return ((6.0 * s2 - 6.0 * s) * (p0 - p1) + (3.0 * s2 - 4.0 * s + 1.0) * m0
                + (3.0 * s2 - 2.0 * s) * m1) / step
    s3 = s2 * s
    return ((2.0 * s3 - 3.0 * s2 + 1.0) * p0 + (s3 - 2.0 * s2 + s) * m0
            + (3.0 * s2 - 2.0 * s3) * p1 + (s3 - s2) * m1)
