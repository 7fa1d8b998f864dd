"""
The ``c2`` model: a not-a-knot cubic spline per coordinate over a window of each stream.

Over the last W samples of a continuous stream segment up to the interval's closing frame plus
a look-ahead of 0, 1 or 2 frames, each coordinate is interpolated by the not-a-knot cubic
spline (``splines.not_a_knot_slopes``): the ball's centre; the bat's knob, its length, and its
knob-to-tip direction in a local chart: each sample's direction as the rotation vector (axis
times angle, across the bat) that turns the interval's opening direction onto it. The spline
of the rotation vector is mapped back by Rodrigues' formula, so the bat stays rigid and turns
about whatever axis its samples say, the axis changing within and between intervals (no fixed
axis per interval: a tilting swing plane is followed); a turn about a fixed axis is then just a
spline of its angle, a smooth function even when the bat turns half a radian a frame. Samples
more than ``MAX_CHART_ANGLE`` from the opening direction leave the window (the chart holds to
pi). From poses the knob and tip the pose carries are fitted the same way (a round bat's roll
does not move its axis).

Error order: a spline through samples of a motion with a bounded fourth derivative is O(h^4)
off in position (the chart is smooth, so the order carries over to the direction) and O(h^3)
in velocity, on uneven stamps and in the window's end pieces too
(not-a-knot), so halving the step divides the position error by about 16. With look-ahead 0
the fit ends at the interval's closing frame: frames after it (the bat braking after a
contact) cannot bend the interval.

The bat's (and the ball's: ``detector.fitting.c2_point_path``) exact windows with a sample
after the interval (look-ahead 1 or 2), six samples or more and steps within a factor 2
(``splines.quintic_window``) take the not-a-knot *quintic* spline instead
(``splines.not_a_knot_quintic_rows``; each piece a quintic Hermite through the spline's values,
slopes and second derivatives at its ends, which is the spline's own piece): O(h^6) in position
and O(h^5) in velocity for a motion with a bounded sixth derivative (BENCHMARKS.md, "The quintic
spline for ``c2``'s exact windows"). A window's last piece takes it only where the caller says
(``continued``): the bat's own path over an interval that ends its window (look-ahead 0:
``detector.sweep.Sweep.paths``) and a hit's bat continued from before its interval; the ball's
last piece, and the velocities extrapolated from before an impact, stay cubic, where the
quintic's end weights would amplify untold noise most. Each path is a ``MotionPath`` over one
interval;
``C2BatPath.deviation`` bounds how far any bat axis point leaves its chord from the second
derivative of knob + length * direction.
"""

from operator import is_
from typing import List, Optional, Sequence, Tuple

from .base import BatSample, PathKind
from .bat_paths import BatPath, Ends
from .points import AngleCubic, PointPath
from .splines import not_a_knot_quintic_rows, not_a_knot_slope_rows, quintic_window
from ..geometry import Vector
from ..toi import _kernel


MAX_CHART_ANGLE = 2.5
"""Largest turn (rad) of a window sample's direction from the interval's opening direction."""


def unit_axis(sample: BatSample) -> Vector:
    """Return the unit knob-to-tip direction of a bat sample."""
    return axis_and_length(sample)[0]


def axis_and_length(sample: BatSample) -> Tuple[Vector, float]:
    """
    Return a bat sample's unit knob-to-tip direction and its length (m), kept per sample.

    The kernel's (``toi._kernel.bat_axis``: (tip - knob) over its norm, and
    ``math.dist(tip, knob)``, as the window's chart takes them). Kept: the two are made once
    per sample object (samples are never changed) and kept in ``_AXES`` by identity
    (the entry holds the sample, so its id cannot be reused while it is there; at most
    ``_AXES_KEPT`` entries, then it starts again).
    """
    found = _AXES.get(id(sample))
    if found is not None and found[0] is sample:
        return found[1], found[2]
    direction, length = _kernel.bat_axis(sample)
    if len(_AXES) >= _AXES_KEPT:
        _AXES.clear()
    _AXES[id(sample)] = (sample, direction, length)
    return direction, length


_AXES: dict = {}
"""``axis_and_length``'s answers: id(sample) -> (sample, direction, length)."""

_AXES_KEPT = 4096
"""Most samples ``_AXES`` holds."""


def rotation_to(reference: Vector, direction: Vector) -> Vector:
    """
    Return the rotation vector (rad, across ``reference``) turning it onto ``direction``.

    Both unit. The kernel's (``toi._kernel.rotation_to``, as the window's chart takes it):
    the axis reference x direction scaled by atan2(its norm, their dot product) over its norm;
    (0, 0, 0) where that norm is below 1e-15.
    """
    return _kernel.rotation_to(reference, direction)


def rotate(reference: Vector, rotation: Vector) -> Vector:
    """
    Return ``reference`` turned by a rotation vector across it (Rodrigues), unit.

    The kernel's (``toi._kernel.rotate``): the angle |rotation|, then
    ``cos(angle) reference + sin(angle) / angle (rotation x reference)``; ``reference`` itself
    below 1e-15 rad.
    """
    return _kernel.rotate(reference, rotation)


_LAST_ROWS: list = [None]
"""The last ``c2_rows`` call: (its samples, j, answer). The far test and the path of one
interval chart the same window: the second gets the first's rows. Every sample is compared
(by identity), not only the window's ends and j-th: a window of a stream's excerpt without
a frame (``Sweep._hangs_on``) can share those with a window of the stream that holds the frame
and not another, and got that window's rows (the chunk path's impact then differed from the
node's, on a bat glitch beside a lost frame with noise)."""


def c2_rows(samples: Sequence[BatSample], j: int) -> Tuple[int, List[Tuple[float, ...]]]:
    """
    Return the window's rows for the interval from samples[j] to samples[j + 1].

    Charted by the kernel (``toi._kernel.c2_chart``: each sample's direction and length as
    ``axis_and_length`` makes them, its rotation vector as ``rotation_to``). The same samples
    (each by identity: a stream's samples are never changed) and j as the last call give its
    answer again (the rows are shared: read them only).

    :returns: (the first sample kept, its rows onward): per sample the 7 fitted coordinates
        knob (m), rotation vector from samples[j]'s direction (rad), length (m). Samples before
        j (or after j + 1) turned more than ``MAX_CHART_ANGLE`` from it end the window there.
    """
    last_call = _LAST_ROWS[0]
    if (last_call is not None and last_call[1] == j and len(last_call[0]) == len(samples)
            and all(map(is_, last_call[0], samples))):
        return last_call[2]
    found = _kernel.c2_chart(samples, j, MAX_CHART_ANGLE)
    _LAST_ROWS[0] = (tuple(samples), j, found)
    return found


class C2BatPath(BatPath):
    """
    ``c2``: knob, direction (a rotation vector's spline) and length, each a spline piece.

    :param knob_slopes: (start, end) velocities (m/s) of the knob, from the window's spline.
    :param turn_slopes: (start, end) rates (rad/s) of the rotation vector from the opening
        direction (which it turns onto the closing one).
    :param length_slopes: (start, end) rates of the knob-to-tip length (m/s).
    :param seconds: None (cubic pieces), or the (start, end) second derivatives of the knob
        (m/s^2), the rotation vector (rad/s^2) and the length (m/s^2): quintic pieces.
    """

    __slots__ = ('knob', 'turn', 'length', 'reference', 'spread')
    kind = PathKind.C2

    def __init__(self, t0: float, t1: float, sample0: BatSample, sample1: BatSample,
                 knob_slopes: Tuple[Vector, Vector], turn_slopes: Tuple[Vector, Vector],
                 length_slopes: Tuple[float, float],
                 seconds: Optional[Tuple[Tuple[Vector, Vector], Tuple[Vector, Vector],
                                         Tuple[float, float]]] = None) -> None:
        # in the kernel (``toi._kernel.c2_path_init``, the same operations in this order): the
        # ``BatPath`` part (the four ends' mean, the largest ``math.dist`` from it); the knob a
        # ``PointPath`` of the samples' knobs; the reference direction and both lengths the
        # samples' ``axis_and_length``; the turn a ``PointPath`` from (0, 0, 0) to the rotation
        # vector onto sample1's direction (``rotation_to``); the length an ``AngleCubic``; the
        # lever the longer length, the angle the turn's norm; the spread ``_deviation`` over
        # [t0, t1], added to the radius. With ``seconds`` each piece is a quintic
        _kernel.c2_path_init(self, PointPath, AngleCubic, t0, t1, sample0, sample1,
                             knob_slopes, turn_slopes, length_slopes, seconds)

    def deviation(self, ta: float, tb: float) -> float:
        """
        Return a bound (m) on how far any axis point leaves its chord over [ta, tb].

        Over the whole interval the one computed when the path was made (``spread``); else
        ``_deviation``'s.
        """
        if ta == self.t0 and tb == self.t1 and self.spread is not None:
            return self.spread
        return self._deviation(ta, tb)

    @classmethod
    def fitted(cls, times: Sequence[float], samples: Sequence[BatSample], k: int,
               continued: bool = False) -> 'C2BatPath':
        """
        Return the path over [times[k], times[k + 1]] from the window's splines.

        Cubic, or quintic where ``splines.quintic_window`` takes the (charted) window.

        :param times, samples: the window (seconds, bat samples); k: the interval in it.
        :param continued: the path is to be continued past the window's end
            (``splines.quintic_window``'s).
        """
        first, rows = c2_rows(samples, k)
        window = times[first:first + len(rows)]
        seconds = None
        if quintic_window(window, k - first, continued):
            slopes, bends = not_a_knot_quintic_rows(window, rows, k - first)
            g0, g1 = bends[:2]
            seconds = ((g0[:3], g1[:3]), (g0[3:6], g1[3:6]), (g0[6], g1[6]))
            s0, s1 = slopes[:2]
        else:
            s0, s1 = not_a_knot_slope_rows(window, rows, k - first)[:2]
        return cls(times[k], times[k + 1], samples[k], samples[k + 1],
                   (tuple(s0[:3]), tuple(s1[:3])), (tuple(s0[3:6]), tuple(s1[3:6])),
                   (s0[6], s1[6]), seconds)

    def _inside(self, t: float) -> Ends:
        # the kernel's (``toi._kernel.c2_inside``, these operations in this order): the knob
        # piece at t; the reference turned by the turn piece at t (``rotate``), d; the tip
        # knob + length(t) d
        return _kernel.c2_inside(self, t)

    def _deviation(self, ta: float, tb: float) -> float:
        """
        Return ``deviation``'s bound, computed.

        An axis point is p = knob + f L u (0 <= f <= 1) and leaves its chord by at most
        max |p''| (tb - ta)^2 / 8, with |p''| <= |knob''| + |L''| + 2 |L'| |u'| + L |u''|;
        u is the rotation vector r mapped onto the sphere (its exponential map, whose first
        derivative is at most 1 and second at most 2 in norm): |u'| <= |r'| and
        |u''| <= |r''| + 2 |r'|^2. Each bound from the pieces' power-basis coefficients: a
        second derivative at an end of [ta, tb] (it is linear), a first at ta plus the second's
        bound times the span, |L| at an end plus |L''| (tb - ta)^2 / 8. Computed by the kernel
        (``toi._kernel.c2_deviation``).
        """
        return _kernel.c2_deviation(self.knob, self.turn, self.length, ta, tb)
