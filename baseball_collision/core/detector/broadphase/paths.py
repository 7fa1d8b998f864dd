"""
The sweep's second far test over arrays: the motion paths' bounding spheres, without the paths.

``PointPath``'s and ``BatPath``'s centres and radii as ``Sweep.interval`` builds them, for the
intervals the first test (:mod:`.arrays`) does not clear.
"""

from typing import Tuple

import numpy as np

from .arrays import _dist


def path_margins(ball: np.ndarray, bat_knob: np.ndarray, bat_tip: np.ndarray,
                 bat_quaternion: np.ndarray, ball_k: np.ndarray, bat_k: np.ndarray,
                 ball_before: np.ndarray, ball_after: np.ndarray, bat_before: np.ndarray,
                 bat_after: np.ndarray, ball_times: np.ndarray, bat_times: np.ndarray,
                 model: str, lever: float) -> np.ndarray:
    """
    Return the sweep's second far test over many intervals: the motion paths' spheres' gap (m).

    ``PointPath.centre``/``radius`` of the ball and ``BatPath.centre``/``radius`` of the bat
    (``rigid`` from poses, ``spline``; ``linear``: the chords, the first test's spheres) as
    ``Sweep.interval`` builds them, over arrays, without building the paths; the sweep calls an
    interval far where this exceeds its margin. Arguments as :func:`apart_margins`, with the
    bat's unit quaternions (n_bat, 4) and, for ``rigid``, ``lever``: the longer body offset
    (m). Computed with numpy's own rounding: compare with a tolerance
    (test/core/detector/broadphase/test_paths.py checks it against the paths).

    :raises ValueError: ``c2`` (its windows are not vectorised).
    """
    b0, b1 = ball[ball_k], ball[ball_k + 1]
    k0, k1 = bat_knob[bat_k], bat_knob[bat_k + 1]
    e0, e1 = bat_tip[bat_k], bat_tip[bat_k + 1]
    bat_centre = 0.25 * (k0 + e0 + k1 + e1)
    bat_radius = np.maximum(np.maximum(_dist(k0, bat_centre), _dist(e0, bat_centre)),
                            np.maximum(_dist(k1, bat_centre), _dist(e1, bat_centre)))
    ball_radius = 0.5 * _dist(b0, b1)
    if model == 'rigid':
        cosine = np.abs(np.einsum('ij,ij->i', bat_quaternion[bat_k], bat_quaternion[bat_k + 1]))
        angle = 2.0 * np.arccos(np.minimum(1.0, cosine))
        bat_radius = bat_radius + lever * angle * angle / 8.0
    elif model == 'spline':
        ball_radius = ball_radius + _cubic_bulges(ball, ball_times, ball_k, ball_before,
                                                  ball_after)
        bat_radius = (bat_radius + _cubic_bulges(bat_knob, bat_times, bat_k, bat_before,
                                                 bat_after)
                      + _turn_growth(bat_knob, bat_tip, bat_times, bat_k, bat_before, bat_after))
    elif model != 'linear':
        raise ValueError(f'no vectorised path test for the {model} model')
    return _dist(b0 + (b1 - b0) * 0.5, bat_centre) - ball_radius - bat_radius


def _slopes(t_prev: np.ndarray, v_prev: np.ndarray, t: np.ndarray, v: np.ndarray,
            t_next: np.ndarray, v_next: np.ndarray, has_prev: np.ndarray,
            has_next: np.ndarray) -> np.ndarray:
    """``motion.base.hermite_tangent`` (and ``hermite_slope``: 1-d values) over rows."""
    h0, h1 = t - t_prev, t_next - t
    if v.ndim == 2:
        h0, h1, t_next, t_prev, t = (x[:, None] for x in (h0, h1, t_next, t_prev, t))
        has_prev, has_next = has_prev[:, None], has_next[:, None]
    with np.errstate(all='ignore'):
        w_prev = h1 / (h0 * (h0 + h1))
        w_next = h0 / (h1 * (h0 + h1))
        both = w_next * v_next + (w_prev - w_next) * v - w_prev * v_prev
        forward = (v_next - v) * (1.0 / (t_next - t))
        backward = (v - v_prev) * (1.0 / (t - t_prev))
    return np.where(has_prev & has_next, both, np.where(
        has_next, forward, np.where(has_prev, backward, 0.0)))


def _hermite_bulge(h: np.ndarray, chord: np.ndarray, m0: np.ndarray,
                   m1: np.ndarray) -> np.ndarray:
    """``PointPath.bulge`` (``AngleCubic.bulge``: 1-d) of cubics with end rates m0, m1."""
    if chord.ndim == 2:
        h = h[:, None]
    b, e = h * m0, h * m1
    c = 3.0 * chord - 2.0 * b - e
    d = b + e - 2.0 * chord
    if chord.ndim == 2:
        return 0.25 * np.sqrt(np.einsum('ij,ij->i', c, c)) + 0.38491 * np.sqrt(
            np.einsum('ij,ij->i', d, d))
    return 0.25 * np.abs(c) + 0.38491 * np.abs(d)


def _cubic_bulges(points: np.ndarray, times: np.ndarray, k: np.ndarray, before: np.ndarray,
                  after: np.ndarray) -> np.ndarray:
    """``PointPath.build('spline', ...).bulge`` over many intervals k (-1 neighbours: none)."""
    has_before, has_after = before >= 0, after >= 0
    b, a = np.where(has_before, before, k), np.where(has_after, after, k + 1)
    t0, t1 = times[k], times[k + 1]
    p0, p1 = points[k], points[k + 1]
    true = np.ones(len(k), bool)
    m0 = _slopes(times[b], points[b], t0, p0, t1, p1, has_before, true)
    m1 = _slopes(t0, p0, t1, p1, times[a], points[a], true, has_after)
    return _hermite_bulge(t1 - t0, p1 - p0, m0, m1)


def _swing_angles(u: np.ndarray, v: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return ``geometry.swing_rotation``'s (cross, sine, angle) over rows."""
    turn = np.cross(u, v)
    sine = np.sqrt(np.einsum('ij,ij->i', turn, turn))
    return turn, sine, np.arctan2(sine, np.einsum('ij,ij->i', u, v))


def _turn_growth(knobs: np.ndarray, tips: np.ndarray, times: np.ndarray, k: np.ndarray,
                 before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """
    ``SplineBatPath``'s growth beyond the knob's bulge over many intervals k (m).

    lever * ((angle + 2 bulge)^2 / 8 + 2 bulge): the turn between the directions and its
    cubic's (``AngleCubic.through``) bulge, the neighbours' swings projected on its axis.
    """
    axes = tips - knobs
    lengths = np.sqrt(np.einsum('ij,ij->i', axes, axes))
    directions = axes / lengths[:, None]
    d0, d1 = directions[k], directions[k + 1]
    turn, sine, angle = _swing_angles(d0, d1)
    turning = sine >= 1e-12
    with np.errstate(all='ignore'):
        axis = turn / sine[:, None]
    has_before, has_after = before >= 0, after >= 0
    b, a = np.where(has_before, before, k), np.where(has_after, after, k + 1)
    ones = np.ones(len(k), bool)

    def projected(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        cross, s, theta = _swing_angles(u, v)
        with np.errstate(all='ignore'):
            rotation = cross * (theta / s)[:, None]
        return np.where(s > 0.0, np.einsum('ij,ij->i', rotation, axis), 0.0)
    previous = -projected(axes[b], axes[k])
    following = angle + projected(axes[k + 1], axes[a])
    t0, t1 = times[k], times[k + 1]
    zero = np.zeros(len(k))
    m0 = _slopes(times[b], previous, t0, zero, t1, angle, has_before, ones)
    m1 = _slopes(t0, zero, t1, angle, times[a], following, ones, has_after)
    bulge = np.where(turning, _hermite_bulge(t1 - t0, angle, m0, m1), 0.0)
    lever = np.maximum(lengths[k], lengths[k + 1])
    return lever * ((angle + 2.0 * bulge) ** 2 / 8.0 + 2.0 * bulge)
