"""
Exact time of impact between a moving ball and a moving bat (capsules, profiled round cones).

A compiled kernel and numpy; no ROS imports. Units: metres and seconds. The modules:

* ``_kernel`` (``_kernel.c``, built by setup.py): the one implementation of the solver: the
  contact polynomials (end caps' quadratics, the side's quartic), the derivative chain and
  bracketed roots, the broad phase, the capsule and profile solvers, the batch over rows; and
  the hot per-window arithmetic of the motion models and the noise estimate (``c2``'s
  not-a-knot solve, bat chart, window and deviation bound; ``tracker_noise`` auto's residuals);
* ``result``: ``ImpactResult``, ``Feature`` and the tolerances (the kernel's);
* ``scalar``: ``time_of_impact``, ``time_of_impact_profile``, ``profile_contact`` (the hot
  paths' entry on checked tuples), ``closest_offset``, and the gap at one instant
  (``profile_gap``) and its lowest over a linear sub-step (``lowest_gap_place``): the kernel,
  with the argument errors;
* ``batch``: ``time_of_impact_batch`` (the kernel over rows, on every core) and ``distance``,
  the gap over time;
* ``seed``: the seed derivation's method and its infinite-line gap, kept for comparison.
"""

from .batch import distance, time_of_impact_batch
from .result import ArrayLike, Feature, ImpactResult, TOUCH_TOLERANCE
from .scalar import (
    closest_offset, lowest_gap_place, profile_contact, profile_gap, time_of_impact,
    time_of_impact_profile)
from .seed import line_distance, seed_time_of_impact

__all__ = [
    'TOUCH_TOLERANCE', 'ArrayLike', 'ImpactResult', 'closest_offset', 'time_of_impact',
    'time_of_impact_profile', 'profile_gap', 'line_distance', 'distance', 'seed_time_of_impact',
    'time_of_impact_batch', 'Feature', 'profile_contact', 'lowest_gap_place',
]
