"""
The ``c2`` model's bulge bounds for the scalar far test, from the raw samples.

The spline through a window (cubic or quintic: ``motion.c2``) is linear in its samples and
reproduces lines, so it leaves the chord by at most a weighted sum of the samples' distances
from the chord's line (``c2_bulge``); cheaper, from numbers kept per sample, ``c2_jump_bulge``
and ``c2_reach``; over the whole bat, ``c2_bat_growth``; the scalar far test of both stages,
``c2_clearly_apart``.
"""

import math
from typing import Optional, Sequence, Tuple

from ..fitting import c2_window
from ..streams import Stream
from ...geometry import Vector
from ...motion import BatSample, c2_rows
from ...toi import _kernel


C2_WEIGHTS_BEFORE = (4.8, 2.5, 0.67, 0.22, 0.1, 0.048, 0.019, 0.009, 0.0036, 0.0016, 0.0007,
                     0.0003, 0.00012)
"""Bounds of |l_i - chord| over interval k of the window spline's cardinal function l_i, for
samples i = k - 1, k - 2, ... (then 0.0001 each): measured over the cubic's windows of 2-16
samples with steps within a factor 4 of each other (the first three, and the cubic's 0.18,
0.048, 0.013, 0.0034, 0.0009, 0.0002 after them), and over the quintic's (``motion.c2``: 6-32
samples, a sample after k, steps within ``splines.QUINTIC_STEP_RATIO``: from k - 4 on its
weights reach further back, 0.195, 0.084, 0.040, 0.015, 0.0074, 0.0029, 0.0013, 0.00056,
0.00024, 0.00009 at most over 9,000 random windows), with about 20 % more
(test/core/detector/broadphase/test_c2.py re-measures both)."""

C2_WEIGHTS_AFTER = (3.4, 1.1)
"""The same for samples k + 2 and k + 3 (look-ahead 1 and 2; the quintic's 0.38 and 0.066)."""

C2_SAFETY = 1.25
"""Factor on the weights."""

C2_STEP_RATIO = 4.0
"""Windows whose longest step is more than this times the shortest get no far test."""


_FAR_OFFSET = 40
_WEIGHT_LIST = [C2_SAFETY * (C2_WEIGHTS_BEFORE[-o - 1] if -len(C2_WEIGHTS_BEFORE) <= o < 0
                             else 0.0001 if o < 0 else 0.0 if o < 2 else C2_WEIGHTS_AFTER[o - 2])
                for o in range(-_FAR_OFFSET, 2 + len(C2_WEIGHTS_AFTER))]
"""``C2_SAFETY`` times the cardinal weight of the sample at offset o, at o + ``_FAR_OFFSET``
(a window holds at most 32 + 2 samples)."""


def c2_bulge(times: Sequence[float], points: Sequence[Vector], j: int) -> float:
    """
    Bound (m) how far the ``c2`` spline through (times, points) leaves its chord over interval j.

    The spline is linear in its samples and reproduces lines, so it leaves the chord by at
    most sum_i |r_i| w_i: r_i each sample's distance from the chord's line extended, w_i the
    cardinal bound by its distance from the interval (``C2_WEIGHTS_*``), times
    ``C2_SAFETY``. Valid for steps within ``C2_STEP_RATIO`` of each other (the caller checks).
    The kernel's (``toi._kernel.window_bulge``: the terms added in the samples' order).
    """
    return _kernel.window_bulge(times, points, j, _WEIGHT_LIST, _FAR_OFFSET - j, 0, 3)


def _jump_coefficients() -> Tuple[float, ...]:
    """Return c_a = sum over o > a of W(o) (o - a): W(o) the safe weight o samples before."""
    weights = _WEIGHT_LIST[_FAR_OFFSET - 1::-1]  # W(1), W(2), ... W(_FAR_OFFSET)
    return tuple(sum(weight * (o - a) for o, weight in enumerate(weights, 1) if o > a)
                 for a in range(_FAR_OFFSET))


C2_JUMP_BEFORE = _jump_coefficients()
"""Coefficient of the chord-velocity jump at sample k - a in ``c2_jump_bulge`` (a = 0, 1, ...)."""

_AFTER_ONE, _AFTER_TWO = (C2_SAFETY * weight for weight in C2_WEIGHTS_AFTER)

_JUMP_CONSTANTS = (C2_STEP_RATIO, _AFTER_ONE, _AFTER_TWO, C2_JUMP_BEFORE)
"""What the kernel's ``c2_jump_bulge`` takes of the module's constants."""


def c2_jump_bulge(stream: Stream, k: int, look_ahead: int, size: int,
                  max_gap: float) -> Optional[float]:
    """
    Bound (m) how far the ``c2`` spline over interval k leaves its chord, from kept numbers.

    Of the ball; of the bat, its knob's bulge plus its length's. Never
    below ``c2_bulge``'s bound: a sample i before k is off the chord's line by
    r_i = sum over m = i..k-1 of (v_k - v_m) h_m, so |r_i| <= H sum over p = i..k-1 of
    (p - i + 1) J_p+1 (H the longest step, J_m = |v_m+1 - v_m| the chord-velocity jump at
    sample m); after k + 1, |r_k+2| <= H J_k+1 and |r_k+3| <= H (2 J_k+1 + J_k+2). With the
    weights, the bound is H (sum over a of ``C2_JUMP_BEFORE[a]`` J_k-a + the look-ahead
    terms): numbers kept per sample instead of a pass over the window per interval. Taken
    over the samples a full window could hold (``size`` up to k + 1 + ``look_ahead``): never
    fewer than ``c2_window``'s, so never a smaller bound; where their steps are uneven (a
    segment's start within them), over ``c2_window``'s own.

    The numbers are kept in ``stream.aligned`` (each computed once): ``steps[m]`` =
    times[m] - times[m - 1] (s) and ``jumps[m]`` = |v_m+1 - v_m| (m/s), v_m = (p_m - p_m-1) /
    steps[m] the chord velocity into sample m of the ball, or for the bat that of its knob plus
    the same of its knob-to-tip length (``math.dist``); index 0 holds 0 (never used); samples
    more than the window's reach before the newest asked for, not yet filled, hold NaN (no
    later window reaches them: a run the chunk path fast-forwarded). The kernel's
    (``toi._kernel.c2_jump_bulge``: the operations of the Python it replaced, in its order).

    :returns: the bound (m), or None: the window's steps are not within ``C2_STEP_RATIO`` of
        each other (no bound).
    """
    aligned = stream.aligned
    if 'steps' not in aligned:
        aligned['steps'], aligned['jumps'] = [], []
    values = stream.values
    return _kernel.c2_jump_bulge(stream.times, values, stream.breaks, aligned['steps'],
                                 aligned['jumps'], k, look_ahead, size, max_gap,
                                 values[0].__class__ is BatSample, _JUMP_CONSTANTS)


def c2_reach(stream: Stream, k: int, look_ahead: int, size: int,
             max_gap: float) -> Optional[Tuple[Vector, float]]:
    """
    Return a sphere (centre, radius in m) holding the whole ``c2`` bat over interval k.

    Cheap (no chart, no window): the knob's spline stays within its bulge B_k of its chord
    and every axis point within the length L(t) <= max(L_k, L_k+1) + B_L of the knob, so the
    sphere about the knob chord's middle of radius |chord| / 2 + B_k + max L + B_L holds the
    bat (B_k + B_L: ``c2_jump_bulge``). None: no bound (uneven steps).
    """
    bulge = c2_jump_bulge(stream, k, look_ahead, size, max_gap)
    if bulge is None:
        return None
    centre, half_chord, longest = _knob_sphere(stream.values[k], stream.values[k + 1])
    return centre, half_chord + bulge + longest


def _knob_sphere(s0: BatSample, s1: BatSample) -> Tuple[Vector, float, float]:
    """Return the knob chord's middle, half its length and the longer bat length (m)."""
    k0, k1 = s0.knob, s1.knob
    centre = ((k0[0] + k1[0]) * 0.5, (k0[1] + k1[1]) * 0.5, (k0[2] + k1[2]) * 0.5)
    return centre, 0.5 * math.dist(k0, k1), max(math.dist(s0.tip, k0), math.dist(s1.tip, k1))


def c2_clearly_apart(ball: Stream, bat: Stream, ball_k: int, bat_k: int,
                     spheres: Tuple[Vector, float, Vector, float], margin: float,
                     max_gap: float, look_ahead: int, size: int,
                     hull: float = -math.inf) -> bool:
    """
    Return whether the ``c2`` ball and bat stay more than ``margin`` (m) apart over the intervals.

    ``broadphase.clearly_apart``'s test for ``c2``: first from numbers kept per sample
    (``c2_jump_bulge`` of the ball, ``c2_reach`` of the bat), then from the windows' weights
    (``c2_bulge`` of the ball, ``c2_bat_growth``) around the spheres or the hulls. Every bulge
    bound is >= 0 (or None: no bound) and rounding is monotone, so where a stage's spheres and
    hulls are not apart by ``margin`` even without their bulges, the bulges cannot clear it:
    they are not computed (the same answer, measured: on the worst-case bench bag 86 % of the
    second stage's windows). The hulls: the ball's path leaves its chord by at most its bulge,
    and every axis point of the bat its own chord, which lies in the hull of the bat's four
    end points, by at most the bat's growth; a ball beside the bat, inside the bat's sphere,
    is often far from its hull.

    :param spheres: (ball chord's middle, half its length, the bat's four end points' centre,
        their largest distance from it) in m: ``clearly_apart``'s spheres before any bulge.
    :param hull: a lower bound (m) on the distance between the hull of the ball's two samples
        and that of the bat's four end points (``hull_separation``, less what smoothing may
        add); -inf: none.
    """
    ball_centre, ball_radius, bat_centre, bat_radius = spheres
    centre, half_chord, longest = _knob_sphere(bat.values[bat_k], bat.values[bat_k + 1])
    if math.dist(ball_centre, centre) - ball_radius - (half_chord + longest) > margin:
        quick = c2_jump_bulge(ball, ball_k, look_ahead, size, max_gap)
        reach = None if quick is None else c2_reach(bat, bat_k, look_ahead, size, max_gap)
        if reach is not None and (math.dist(ball_centre, reach[0]) - ball_radius - quick
                                  - reach[1] > margin):
            return True
    if not (math.dist(ball_centre, bat_centre) - ball_radius - bat_radius > margin
            or hull > margin):
        return False
    window = c2_window(ball, ball_k, max_gap, look_ahead, size)
    times = ball.times[window.start:window.stop]
    steps = [b - a for a, b in zip(times, times[1:])]
    if max(steps) > C2_STEP_RATIO * min(steps):
        return False
    bulge = c2_bulge(times, ball.values[window.start:window.stop], ball_k - window.start)
    ball_radius += bulge
    growth = c2_bat_growth(bat, bat_k, c2_window(bat, bat_k, max_gap, look_ahead, size))
    if growth is None:
        return False
    bat_radius += growth
    return (math.dist(ball_centre, bat_centre) - ball_radius - bat_radius > margin
            or hull - bulge - growth > margin)


def c2_bat_growth(stream: Stream, k: int, window: range) -> Optional[float]:
    """
    Bound (m) how far any axis point of the ``c2`` bat leaves its chord over interval k.

    With the bulges B_k, B_r, B_L of the knob's, the rotation vector's (``c2_rows``) and the
    length's splines, the angle theta between the end directions and the longer end length
    L: the direction (the rotation vector's exponential map, 1-Lipschitz) stays within B_r of
    the great-circle arc, itself within 1 - cos(theta / 2) of the chord, so any axis point
    within B_k + B_L + (L + B_L) (1 - cos(theta / 2) + B_r) + |dL| |du| / 4. None: no bound
    (uneven steps).
    """
    samples = stream.values[window.start:window.stop]
    j = k - window.start
    first, rows = c2_rows(samples, j)
    start = window.start + first
    # the kernel's, the same operations in the same order: the steps' spread, each group of
    # the rows' columns (knob, rotation vector, length: ``c2_bulge``'s bound), the unit axes'
    # math.dist
    return _kernel.bat_growth(stream.times[start:start + len(rows)], rows, j - first,
                              samples[j], samples[j + 1], _WEIGHT_LIST, _FAR_OFFSET,
                              C2_STEP_RATIO)
