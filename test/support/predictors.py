"""A predictor over ball and bat streams of given points, for the predictor's tests."""

from typing import Optional, Sequence, Tuple

from baseball_collision.core.detector import DetectorConfig
from baseball_collision.core.detector.gate import Clock
from baseball_collision.core.detector.predictor import Predictor
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample

BASE_NS = 1_700_000_000_000_000_000
"""ns: the clock's origin; sample i is stamped ``BASE_NS + i``."""
STILL = ((0.0, 0.0, 1.0), (0.0, 0.86, 1.0))
"""(knob, tip), m: a bat standing still."""
Point = Tuple[float, float, float]
OFFSETS = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.86))
"""(knob, tip) in the bat's body frame, m: a plan's poses."""


def predictor_of(ball_points: Sequence[Point], bat_points: Sequence[Tuple[Point, Point]],
                 plan: Optional[Tuple] = None) -> Predictor:
    """
    Return a predictor (``prediction_horizon`` 0.3 s) over streams of the points given (m).

    Sample i of each at 0.005 i s on the clock, stamped ``BASE_NS + i``; a bat point is
    (knob, tip); ``plan``: ``Predictor.set_plan``'s arguments, set if given.
    """
    clock = Clock()
    clock.origin = BASE_NS
    ball, bat = Stream('ball'), Stream('bat')
    for i, (p, (knob, tip)) in enumerate(zip(ball_points, bat_points)):
        t = 0.005 * i
        ball.append(t, BASE_NS + i, p, False)
        bat.append(t, BASE_NS + i, BatSample(knob, tip), False)
    predictor = Predictor(DetectorConfig(prediction_horizon=0.3), clock, ball, bat, OFFSETS)
    if plan is not None:
        predictor.set_plan(*plan)
    return predictor
