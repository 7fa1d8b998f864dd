"""
The cheap far test: ball and bat clearly apart over a union interval, from the raw samples.

Most intervals of a session have the ball metres from the bat. This decides them without
building a path: each body's path lies in a sphere around its chord's middle (and within the
hull of its end samples, for the finer bound ``hull_separation``), grown by a bound
on how far the motion model lets it bulge (none for chords; for a rigid turn, the sagitta is
at most half the chord of the rotating part; for the spline, ``bulge_bounds``; for ``c2``,
first ``c2_jump_bulge`` and ``c2_reach`` from numbers kept per sample, then ``c2_bulge`` and
``c2_bat_growth`` over the interval's window).

In four parts, one job each:

* ``scalar``: the test the node's sweep runs on one interval (:func:`clearly_apart`,
  :func:`hull_separation`, :func:`bulge_bounds`; under noise, ``c2``'s with the ball's own
  path, :func:`c2_path_apart`);
* ``c2``: the ``c2`` model's bulge bounds for it (cardinal weights, kept jumps, the window);
* ``arrays``: the same test over many intervals at once for ``analyze``'s chunks
  (:func:`apart_margins`, :func:`hull_separations`, ``c2``'s on arrays);
* ``paths``: the sweep's second far test over arrays (:func:`path_margins`).
"""

from .arrays import apart_margins, hull_separations
from .c2 import (
    c2_bat_growth, c2_bulge, C2_JUMP_BEFORE, c2_jump_bulge, c2_reach, C2_SAFETY, C2_STEP_RATIO,
    C2_WEIGHTS_AFTER, C2_WEIGHTS_BEFORE)
from .paths import path_margins
from .scalar import (
    bulge_bounds, c2_path_apart, clearly_apart, hull_separation, NOISE_REACH, Pick)

__all__ = ['apart_margins', 'bulge_bounds', 'c2_bat_growth', 'c2_bulge', 'c2_jump_bulge',
           'c2_path_apart',
           'C2_JUMP_BEFORE', 'c2_reach', 'C2_SAFETY', 'C2_STEP_RATIO', 'C2_WEIGHTS_AFTER',
           'C2_WEIGHTS_BEFORE', 'clearly_apart', 'hull_separation', 'hull_separations',
           'NOISE_REACH', 'path_margins', 'Pick']
