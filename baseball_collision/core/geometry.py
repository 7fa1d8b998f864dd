"""
Geometry on plain float tuples: vectors, rotations, poses, rigid bodies.

One copy of each building block for the whole package. The scalar hot paths (solver, motion
models, detector) work on tuples of three floats: for vectors this small, plain float arithmetic
is several times faster than numpy's per-call overhead. Quaternions are in ROS order
``(x, y, z, w)``; angles in radians.

* vectors: ``add``, ``sub``, ``scale``, ``advance``, ``lerp``, ``dot``, ``cross``, ``norm``;
* rotations: ``slerp_vectors``, ``slerp_quaternions``, ``quaternion_angle``, ``rotate``,
  ``swing_rotation``, ``quaternion_to_matrix``, ``quaternion_from_z``, ``turn_about``
  (Rodrigues), ``rotation_between`` (two orientations as a rotation vector);
* batches of quaternions (numpy): ``quaternion_multiply``, ``axis_angle_quaternions``,
  ``matrix_to_quaternion``;
* poses and rigid bodies: ``pose_point``, ``interpolate_pose``, ``rigid_point_velocity``;
* argument checks: ``finite_vector``, ``finite_number`` (raising the caller's layer's error).

The distance of a ball to a bat's profile (its round cones) is the compiled kernel's
(``toi.profile_gap``).
"""

import math
from typing import Optional, Sequence, Tuple

import numpy as np

from ..errors import CoreError

Vector = Tuple[float, float, float]
Quaternion = Tuple[float, float, float, float]


def add(a: Sequence[float], b: Sequence[float]) -> Vector:
    """Return a + b."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a: Sequence[float], b: Sequence[float]) -> Vector:
    """Return a - b."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(a: Sequence[float], s: float) -> Vector:
    """Return a * s."""
    return (a[0] * s, a[1] * s, a[2] * s)


def advance(p0: Sequence[float], p1: Sequence[float], s: float) -> Vector:
    """Return p0 + p1 * s."""
    return (p0[0] + p1[0] * s, p0[1] + p1[1] * s, p0[2] + p1[2] * s)


def lerp(a: Sequence[float], b: Sequence[float], s: float) -> Vector:
    """Return a + (b - a) * s."""
    return (a[0] + (b[0] - a[0]) * s, a[1] + (b[1] - a[1]) * s, a[2] + (b[2] - a[2]) * s)


def dot(a: Sequence[float], b: Sequence[float]) -> float:
    """Return the dot product of two 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Sequence[float], b: Sequence[float]) -> Vector:
    """Return the cross product a x b."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a: Sequence[float]) -> float:
    """Return the Euclidean length of a 3-vector."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


# ----------------------------------------------------------------------------------------------
# rotations


def _dot4(a: Sequence[float], b: Sequence[float]) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]


def slerp_vectors(d0: Vector, d1: Vector, s: float) -> Vector:
    """Interpolate unit vectors on the great circle (constant angular rate) at fraction s."""
    cos_angle = max(-1.0, min(1.0, dot(d0, d1)))
    angle = math.acos(cos_angle)
    if angle < 1e-9:
        d = lerp(d0, d1, s)
        length = norm(d)
        return (d[0] / length, d[1] / length, d[2] / length)
    sin_angle = math.sin(angle)
    w0 = math.sin((1.0 - s) * angle) / sin_angle
    w1 = math.sin(s * angle) / sin_angle
    return (w0 * d0[0] + w1 * d1[0], w0 * d0[1] + w1 * d1[1], w0 * d0[2] + w1 * d1[2])


def slerp_quaternions(q0: Quaternion, q1: Quaternion, s: float) -> Quaternion:
    """Interpolate unit quaternions (x, y, z, w) along the shorter arc at fraction s."""
    cosine = _dot4(q0, q1)
    if cosine < 0.0:
        q1 = (-q1[0], -q1[1], -q1[2], -q1[3])
        cosine = -cosine
    if cosine > 1.0 - 1e-12:
        q = tuple(a + (b - a) * s for a, b in zip(q0, q1))
    else:
        angle = math.acos(cosine)
        sin_angle = math.sin(angle)
        w0 = math.sin((1.0 - s) * angle) / sin_angle
        w1 = math.sin(s * angle) / sin_angle
        q = tuple(w0 * a + w1 * b for a, b in zip(q0, q1))
    length = math.sqrt(_dot4(q, q))
    return (q[0] / length, q[1] / length, q[2] / length, q[3] / length)


def quaternion_angle(q0: Quaternion, q1: Quaternion) -> float:
    """Return the rotation angle (radians, in [0, pi]) between two unit quaternions."""
    return 2.0 * math.acos(min(1.0, abs(_dot4(q0, q1))))


def rotate(q: Quaternion, v: Vector) -> Vector:
    """Rotate vector v by unit quaternion q (x, y, z, w)."""
    x, y, z, w = q
    # v + 2 w (q_v x v) + 2 q_v x (q_v x v)
    cx = y * v[2] - z * v[1]
    cy = z * v[0] - x * v[2]
    cz = x * v[1] - y * v[0]
    return (v[0] + 2.0 * (w * cx + y * cz - z * cy),
            v[1] + 2.0 * (w * cy + z * cx - x * cz),
            v[2] + 2.0 * (w * cz + x * cy - y * cx))


def swing_rotation(u: Vector, v: Vector) -> Vector:
    """Return the rotation (axis times angle, radians) turning direction u onto direction v."""
    turn = cross(u, v)
    sine = norm(turn)
    return scale(turn, math.atan2(sine, dot(u, v)) / sine) if sine > 0.0 else (0.0, 0.0, 0.0)


def quaternion_to_matrix(quaternion: Sequence[float]) -> np.ndarray:
    """
    Return the 3x3 rotation matrix of a unit quaternion ``(x, y, z, w)`` (ROS order).

    :raises CoreError: non-finite, or norm further than 1e-3 from 1 (a malformed pose).
    """
    x, y, z, w = (float(q) for q in quaternion)
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if not math.isfinite(norm) or abs(norm - 1.0) > 1e-3:
        raise CoreError(f'quaternion must be unit length, got norm {norm!r}')
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def quaternion_from_z(direction: Sequence[float]) -> Quaternion:
    """
    Return the unit quaternion (x, y, z, w) of the shortest rotation turning +z onto a direction.

    :param direction: a unit 3-vector; straight down (-z) gives the half turn about x.
    """
    x, y, z = direction
    if z < -1.0 + 1e-9:
        return (1.0, 0.0, 0.0, 0.0)
    q = (-y, x, 0.0, 1.0 + z)
    length = math.sqrt(_dot4(q, q))
    return (q[0] / length, q[1] / length, q[2] / length, q[3] / length)


def turn_about(vector: Vector, axis: Vector, angle: float) -> Vector:
    """Rotate ``vector`` about the unit ``axis`` by ``angle`` (rad), by Rodrigues' formula."""
    if angle == 0.0:
        return vector
    cosine, sine = math.cos(angle), math.sin(angle)
    along = dot(axis, vector) * (1.0 - cosine)
    across = cross(axis, vector)
    return (vector[0] * cosine + across[0] * sine + axis[0] * along,
            vector[1] * cosine + across[1] * sine + axis[1] * along,
            vector[2] * cosine + across[2] * sine + axis[2] * along)


def rotation_between(q0: Quaternion, q1: Quaternion) -> Optional[Vector]:
    """
    Return the world-frame rotation from unit quaternion q0 to q1 as axis times angle (rad).

    The rotation is q1 conj(q0), taken along the shorter arc; None when there is none to speak
    of (q0 and q1 equal up to sign: no axis).
    """
    x0, y0, z0, w0 = q0
    x1, y1, z1, w1 = q1
    w = w1 * w0 + x1 * x0 + y1 * y0 + z1 * z0
    x = -w1 * x0 + x1 * w0 - y1 * z0 + z1 * y0
    y = -w1 * y0 + y1 * w0 - z1 * x0 + x1 * z0
    z = -w1 * z0 + z1 * w0 - x1 * y0 + y1 * x0
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    vector_part = math.sqrt(x * x + y * y + z * z)
    if vector_part == 0.0:
        return None
    return scale((x, y, z), 2.0 * math.atan2(vector_part, w) / vector_part)


# ----------------------------------------------------------------------------------------------
# batches of quaternions (numpy arrays, (x, y, z, w) in the last axis)


def quaternion_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the Hamilton products a b of quaternions (..., 4) in (x, y, z, w) order."""
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack([
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ], axis=-1)


def axis_angle_quaternions(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Return quaternions (N, 4) turning by ``angles`` (N,) rad about the unit ``axis`` (3,)."""
    half = 0.5 * angles
    return np.concatenate([np.sin(half)[:, None] * axis[None, :], np.cos(half)[:, None]], axis=1)


def matrix_to_quaternion(matrix: np.ndarray) -> np.ndarray:
    """
    Return the unit quaternion (x, y, z, w) of a 3x3 rotation matrix (Shepperd's method).

    The inverse of :func:`quaternion_to_matrix` (up to the quaternion's sign).
    """
    m = matrix
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s]
    quaternion = np.array(q)
    return quaternion / np.linalg.norm(quaternion)


# ----------------------------------------------------------------------------------------------
# poses and rigid bodies


def pose_point(position: Vector, quaternion: Quaternion, offset: Vector) -> Vector:
    """Return where the body-frame point ``offset`` (m) is for a pose (position, quaternion)."""
    arm = rotate(quaternion, offset)
    return (position[0] + arm[0], position[1] + arm[1], position[2] + arm[2])


def interpolate_pose(position0: Vector, quaternion0: Quaternion, position1: Vector,
                     quaternion1: Quaternion, s: float) -> Tuple[Vector, Quaternion]:
    """Return the pose at fraction s between two poses: position LERP, orientation SLERP."""
    return lerp(position0, position1, s), slerp_quaternions(quaternion0, quaternion1, s)


def rigid_point_velocity(pivot_velocity: Vector, angular_velocity: Vector, pivot: Vector,
                         point: Vector) -> Vector:
    """Return the velocity (m/s) of a rigid body's point: v_pivot + omega x (point - pivot)."""
    return add(pivot_velocity, cross(angular_velocity, sub(point, pivot)))


# ----------------------------------------------------------------------------------------------
# argument checks (the error type is the caller's layer's)


def finite_vector(name: str, value: Sequence[float], unit: str = '',
                  error: type = CoreError) -> Vector:
    """
    Return ``value`` as 3 finite floats.

    :param name: what the value is, for the message.
    :param unit: shown after "3 numbers" in the message, e.g. ``' (metres)'``.
    :param error: the exception type to raise (a layer's error).
    :raises error: not 3 numbers, or not all finite.
    """
    try:
        x, y, z = (float(v) for v in value)
    except (TypeError, ValueError) as cause:
        raise error(f'{name} must be 3 numbers{unit}, got {value!r}') from cause
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
        raise error(f'{name} must be finite, got {value!r}')
    return (x, y, z)


def finite_number(name: str, value: float, error: type = CoreError) -> float:
    """
    Return ``value`` as a finite float.

    :param name: what the value is, for the message.
    :param error: the exception type to raise (a layer's error).
    :raises error: not a number, or not finite.
    """
    try:
        number = float(value)
    except (TypeError, ValueError) as cause:
        raise error(f'{name} must be a number, got {value!r}') from cause
    if not math.isfinite(number):
        raise error(f'{name} must be finite, got {value!r}')
    return number
