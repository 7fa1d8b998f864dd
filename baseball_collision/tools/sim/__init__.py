"""Simulated pitches and swings with continuous-time truth, and tracker sampling."""

from .simulation import (
    AIR_DENSITY, BALL_MASS, BALL_RADIUS, compute_truth, DEFAULT_START_NS, DRAG_COEFFICIENT,
    GRAVITY, KINDS, make_scenario, MPH, Pitch, sample, Samples, Scenario, Swing, TimeLike, Truth,
    truth_dict, TRUTH_GRID_S, TRUTH_TIME_TOLERANCE_S, Vector)

__all__ = [
    'GRAVITY', 'AIR_DENSITY', 'DRAG_COEFFICIENT', 'BALL_MASS', 'BALL_RADIUS', 'MPH', 'KINDS',
    'TRUTH_GRID_S', 'TRUTH_TIME_TOLERANCE_S', 'DEFAULT_START_NS', 'Vector', 'TimeLike', 'Pitch',
    'Swing', 'Truth', 'compute_truth', 'Scenario', 'make_scenario', 'Samples', 'sample',
    'truth_dict',
]
