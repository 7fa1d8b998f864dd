"""What the time-of-impact solvers return; the tolerances of the compiled kernel."""

from dataclasses import dataclass
import enum
from typing import Sequence, Union

import numpy as np

from ._kernel import DEGENERATE_AXIS, ROOT_SLACK, TOUCH_TOLERANCE
from ..geometry import Vector

# The tolerances are defined once, in the kernel (_kernel.c):
# TOUCH_TOLERANCE: a gap (metres) at or below which ball and bat count as touching (1e-9);
# DEGENERATE_AXIS: |u|^2 in scaled units below which the bat has no axis, a sphere (1e-24);
# ROOT_SLACK: scaled gap allowed at a side root for rounding, 0.1 nm on a 1 m scale (1e-10).
__all__ = ['ArrayLike', 'DEGENERATE_AXIS', 'Feature', 'ImpactResult', 'ROOT_SLACK',
           'TOUCH_TOLERANCE']

ArrayLike = Union[Sequence[float], np.ndarray]


class Feature(enum.StrEnum):
    """The part of the bat a ball touched (a ``str``: compares, prints and serialises as one)."""

    SIDE = 'side'
    KNOB_END = 'knob_end'
    TIP_END = 'tip_end'


@dataclass(frozen=True, slots=True)
class ImpactResult:
    """
    First contact between ball and bat within one interval.

    With ``__slots__``: the kernel fills them in directly (no instance dictionary to make).

    :ivar time: seconds from the interval start to first contact (0.0 when touching at the start).
    :ivar point: contact point on the bat surface, world frame (metres).
    :ivar normal: unit vector from the bat axis towards the ball centre at contact.
    :ivar bat_fraction: where along the bat axis, 0 at the knob and 1 at the tip: the contact
        point's place along it (on an end cap, that end's station).
    :ivar initially_overlapping: ball and bat were already touching or overlapping at time 0.
    :ivar gap: signed surface gap at ``time`` (metres): ~0 at a fresh contact, negative when
        overlapping at the start, within (0, TOUCH_TOLERANCE] for a graze.
    :ivar feature: the part of the bat that was hit: ``'side'``, ``'knob_end'`` or
        ``'tip_end'`` (a ``Feature``).
    """

    time: float
    point: Vector
    normal: Vector
    bat_fraction: float
    initially_overlapping: bool
    gap: float
    feature: Feature
