"""
The contact polynomials of a ball and a moving capsule: one copy for the scalar and batch paths.

Model: over one interval the ball centre ``B``, the bat tip (barrel end) ``E`` and the knob
``S`` each move linearly. The bat is the segment S-E thickened by a radius (a capsule: rounded
ends); with ``R`` the sum of both radii, ``u = E - S`` and ``w = B - S`` (both degree 1 in the
normalised time tau in [0, 1]: ``w = w0 + w1 tau``, ``u = u0 + u1 tau``):

* side of the bat (the projection ``lambda = w.u / u.u`` in [0, 1]):
  ``|w x u|^2 - R^2 |u|^2 = 0``, the seed derivation's quartic (its Eq. 15f);
* knob end (lambda < 0): ``|w|^2 - R^2 = 0``; tip end (lambda > 1): ``|w - u|^2 - R^2 = 0``.

The coefficients are formed here once, written against a small ``Algebra`` (dot, cross,
subtraction) so the same lines serve 3-tuples (``SCALAR``, geometry's hand-written tuple math)
and ``(N, 3)`` arrays (``BATCH``).
"""

import operator
from typing import Any, Callable, NamedTuple, Tuple

import numpy as np

from .. import geometry


class Algebra(NamedTuple):
    """The vector operations the coefficients are written with."""

    dot: Callable[[Any, Any], Any]
    cross: Callable[[Any, Any], Any]
    sub: Callable[[Any, Any], Any]


def _dot_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the row-wise dot products of (..., 3) arrays."""
    return np.einsum('...i,...i->...', a, b)


SCALAR = Algebra(geometry.dot, geometry.cross, geometry.sub)
"""Vectors as tuples of three floats."""

BATCH = Algebra(_dot_rows, np.cross, operator.sub)
"""Vectors as rows of (N, 3) arrays."""


def cap_quadratics(w0: Any, w1: Any, u0: Any, u1: Any, rr: Any,
                   ops: Algebra) -> Tuple[Tuple[Any, Any, Any], Tuple[Any, Any, Any]]:
    """
    Return the end caps' quadratics ``(a, b, c)``: ``a tau^2 + b tau + c = |p|^2 - R^2``.

    The knob cap's p is w, the tip cap's w - u; ``rr`` is R^2 (scaled units).
    """
    dot, _, sub = ops
    v0, v1 = sub(w0, u0), sub(w1, u1)
    return ((dot(w1, w1), 2.0 * dot(w0, w1), dot(w0, w0) - rr),
            (dot(v1, v1), 2.0 * dot(v0, v1), dot(v0, v0) - rr))


def side_quartic(w0: Any, w1: Any, u0: Any, u1: Any, rr: Any,
                 ops: Algebra) -> Tuple[Tuple[Any, ...], Tuple[Any, ...], Tuple[Any, ...]]:
    """
    Return the side's quartic and the two quadratics that say where along the axis it is.

    :returns: (coefficients of |w x u|^2 - rr |u|^2, the seed's Eq. 15f; of |u|^2; of w.u),
        lowest power first (the quadratics with three coefficients).
    """
    dot, cross, sub = ops
    c0 = cross(w0, u0)
    c1 = sub(cross(w0, u1), cross(u0, w1))
    c2 = cross(w1, u1)
    uu = (dot(u0, u0), 2.0 * dot(u0, u1), dot(u1, u1))
    quartic = (
        dot(c0, c0) - rr * uu[0],
        2.0 * dot(c0, c1) - rr * uu[1],
        dot(c1, c1) + 2.0 * dot(c0, c2) - rr * uu[2],
        2.0 * dot(c1, c2),
        dot(c2, c2),
    )
    wu = (dot(w0, u0), dot(w0, u1) + dot(w1, u0), dot(w1, u1))
    return quartic, uu, wu
