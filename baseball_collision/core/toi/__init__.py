"""Exact time of impact between a moving ball and a moving bat (capsules and profiles)."""

from .solver import (
    ArrayLike, closest_offset, distance, ImpactResult, line_distance, profile_gap,
    seed_time_of_impact, time_of_impact, time_of_impact_batch, time_of_impact_profile,
    TOUCH_TOLERANCE)

__all__ = [
    'TOUCH_TOLERANCE', 'ArrayLike', 'ImpactResult', 'closest_offset', 'time_of_impact',
    'time_of_impact_profile', 'profile_gap', 'line_distance', 'distance', 'seed_time_of_impact',
    'time_of_impact_batch',
]
