"""Homogeneous transforms, written once for numpy and CasADi.

Every function takes scalars that are either plain numbers (numpy arrays come back) or CasADi SX/MX
(symbolic matrices come back). Units: metres and radians.
"""

from __future__ import annotations

import casadi as ca
import numpy as np


def is_symbolic(*values) -> bool:
    """True if any value is a CasADi symbolic or DM matrix."""
    return any(isinstance(v, (ca.SX, ca.MX, ca.DM)) for v in values)


def _cos_sin(angle):
    if is_symbolic(angle):
        return ca.cos(angle), ca.sin(angle)
    return np.cos(angle), np.sin(angle)


def matrix(rows, symbolic: bool):
    """Build a matrix from nested lists of scalars, numerically or symbolically."""
    if symbolic:
        return ca.vertcat(*[ca.horzcat(*row) for row in rows])
    return np.array(rows, dtype=float)


def rot_x(angle):
    c, s = _cos_sin(angle)
    return matrix([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]], is_symbolic(angle))


def rot_y(angle):
    c, s = _cos_sin(angle)
    return matrix([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]], is_symbolic(angle))


def rot_z(angle):
    c, s = _cos_sin(angle)
    return matrix([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], is_symbolic(angle))


def trans(x, y, z):
    return matrix([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]], is_symbolic(x, y, z))


def axis_rotation(axis, angle):
    """Rotation by ``angle`` about the unit ``axis`` (Rodrigues), as a 4x4 transform."""
    c, s = _cos_sin(angle)
    x, y, z = (float(v) for v in axis)
    v = 1 - c
    return matrix([
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s, 0],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s, 0],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v, 0],
        [0, 0, 0, 1],
    ], is_symbolic(angle))


def dh_transform(theta, d, a, alpha):
    """Standard DH link transform T = Rz(theta) Tz(d) Tx(a) Rx(alpha), in closed form."""
    symbolic = is_symbolic(theta, d, a, alpha)
    ct, st = _cos_sin(theta)
    ca_, sa = _cos_sin(alpha)
    return matrix(
        [
            [ct, -st * ca_, st * sa, a * ct],
            [st, ct * ca_, -ct * sa, a * st],
            [0, sa, ca_, d],
            [0, 0, 0, 1],
        ],
        symbolic,
    )


def placement_transform(x, y, z, yaw, pitch, roll):
    """Pose of the workpiece frame W in the base frame B: Trans(x, y, z) Rz(yaw) Ry(pitch) Rx(roll)."""
    return trans(x, y, z) @ rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)


def inverse(T):
    """Inverse of a rigid transform, using R^T (exact, no matrix inversion)."""
    R, p = T[:3, :3], T[:3, 3]
    if is_symbolic(T):
        Rt = R.T
        return ca.vertcat(ca.horzcat(Rt, -Rt @ p), ca.horzcat(0, 0, 0, 1))
    out = np.eye(4)
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ p
    return out


def cross(u, v):
    return ca.cross(u, v) if is_symbolic(u, v) else np.cross(u, v)
