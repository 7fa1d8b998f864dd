"""
Simulated pitches and swings with continuous-time truth, and tracker sampling.

One module per concern: :mod:`.pitches` (the ball's flight, RK4), :mod:`.swings` (the bat's
exact kinematics), :mod:`.profiles` (the swing angle over time), :mod:`.families` (today's
fixed-plane swing and the ways real swings differ: tilting planes, jerk, left-handed batters,
braking after a contact), :mod:`.truth` (first contact and smallest gap of the continuous
motion), :mod:`.scenarios` (pitch and swing drawn to make one kind of event), :mod:`.sampling`
(stamps, jitter and noise as a tracker reports them; the truth as JSON); :mod:`.common` holds
the argument checks. Pure Python + numpy; SI units throughout: metres, seconds, m/s, rad,
rad/s. World frame z up, the pitch toward -y, a right-handed batter unless the family says
otherwise; quaternions ``(x, y, z, w)``. Import the names below from here.
"""

from .common import TimeLike, Vector
from .families import check_family, FAMILIES
from .pitches import AIR_DENSITY, BALL_MASS, BALL_RADIUS, DRAG_COEFFICIENT, GRAVITY, MPH, Pitch
from .sampling import DEFAULT_START_NS, NOISE_ON, sample, Samples, truth_dict
from .scenarios import CLOSE_KINDS, KINDS, make_scenario, Scenario
from .swings import Swing
from .truth import compute_truth, Truth, TRUTH_GRID_S, TRUTH_TIME_TOLERANCE_S

__all__ = [
    'GRAVITY', 'AIR_DENSITY', 'DRAG_COEFFICIENT', 'BALL_MASS', 'BALL_RADIUS', 'MPH', 'KINDS',
    'TRUTH_GRID_S', 'TRUTH_TIME_TOLERANCE_S', 'DEFAULT_START_NS', 'Vector', 'TimeLike', 'Pitch',
    'Swing', 'Truth', 'compute_truth', 'Scenario', 'make_scenario', 'Samples', 'sample',
    'truth_dict', 'CLOSE_KINDS', 'FAMILIES', 'check_family', 'NOISE_ON',
]
