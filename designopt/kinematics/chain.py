"""Forward kinematics and the geometric Jacobian: one walk along a chain's elementary transforms.

Frames: B is the robot base, W the workpiece (T_BW is the walk of ``chain.placement``), the tool frame is
the end of the ``chain.robot`` walk times ``chain.tool``. All results are expressed in B unless a name says
W. Works on numbers (numpy) and on CasADi symbols alike.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from designopt.kinematics.joints import ET, Chain, Role, X, Y, Z
from designopt.kinematics.transforms import (
    axis_rotation,
    cross,
    dh_transform,
    inverse,
    placement_transform,
    rot_x,
    rot_y,
    rot_z,
    trans,
)

_ROTATIONS = (rot_x, rot_y, rot_z)

# Runs of ETs with a closed form. The walk multiplies such a run as one matrix: fewer operations in the CasADi
# graph, and the same expressions (so the same IPOPT iterates) as the DH and placement transforms always had.
FUSED = (
    ((("rotate", Z), ("translate", Z), ("translate", X), ("rotate", X)), dh_transform),
    ((("translate", X), ("translate", Y), ("translate", Z), ("rotate", Z), ("rotate", Y), ("rotate", X)),
     placement_transform),
)


def et_matrix(et: ET, value):
    """The 4x4 transform of one ET at a joint value (closed form for x, y, z axes)."""
    basis = et.basis
    if et.motion == "rotate":
        return _ROTATIONS[basis](value) if basis is not None else axis_rotation(et.axis, value)
    if basis is not None:
        zero = 0 * value
        return trans(*[value if i == basis else zero for i in range(3)])
    return trans(*[a * value for a in et.axis])


def _identity(like):
    if isinstance(like, ca.SX):
        return ca.SX.eye(4)
    if isinstance(like, ca.MX):
        return ca.MX.eye(4)
    return np.eye(4)


def _segments(ets: tuple[ET, ...]) -> list[tuple[int, int, object]]:
    """(start, end, closed form or None) runs covering the ETs, longest closed forms first."""
    out, i = [], 0
    while i < len(ets):
        for pattern, fn in FUSED:
            if tuple((e.motion, e.axis) for e in ets[i : i + len(pattern)]) == pattern:
                out.append((i, i + len(pattern), fn))
                i += len(pattern)
                break
        else:
            out.append((i, i + 1, None))
            i += 1
    return out


class Walk:
    """One walk along ETs at given joint values: ``frame(k)`` is the frame before ET k (``frame(len)``, the
    end). Frames between the ETs of a fused run are computed only when asked for."""

    def __init__(self, ets: tuple[ET, ...], values: list):
        self.ets, self.values = ets, values
        self._start, self._at, previous = {}, {}, None
        for a, b, fn in _segments(ets):
            M = fn(*[values[e.joint] for e in ets[a:b]]) if fn else et_matrix(ets[a], values[ets[a].joint])
            previous = M if previous is None else previous @ M
            self._at[b] = previous
            self._start.update(dict.fromkeys(range(a, b), a))
        self._at[0] = _identity(previous)

    def frame(self, k: int):
        if k in self._at:
            return self._at[k]
        a = self._start[k]
        T = self._at[a]
        for e in self.ets[a:k]:
            T = T @ et_matrix(e, self.values[e.joint])
        return T

    @property
    def end(self):
        return self._at[len(self.ets)]


def _tool_matrix(chain: Chain, like):
    tool = np.array(chain.tool, dtype=float)
    if isinstance(like, ca.SX):
        return ca.SX(ca.DM(tool))
    if isinstance(like, ca.MX):
        return ca.MX(ca.DM(tool))
    return tool


def placement_pose(chain: Chain, q_m, q_d):
    """T_BW: pose of the workpiece frame in the base frame (4x4)."""
    return Walk(chain.placement, chain.values(q_m, q_d)).end


def link_frames(chain: Chain, q_m, q_d) -> list:
    """[T_B0, T_B1, ..., T_Bn]: base frame followed by every link frame (T_B0 = identity)."""
    walk = Walk(chain.robot, chain.values(q_m, q_d))
    return [walk.frame(0), *[walk.frame(k) for k in chain.frames]]


def tool_pose(chain: Chain, q_m, q_d):
    """T_BT: pose of the tool frame in the base frame (4x4)."""
    last = Walk(chain.robot, chain.values(q_m, q_d)).end
    return last @ _tool_matrix(chain, last)


def tool_in_workpiece(chain: Chain, q_m, q_d):
    """T_WT = T_BW^-1 T_BT: tool pose in the workpiece frame, where the toolpath is given."""
    return inverse(placement_pose(chain, q_m, q_d)) @ tool_pose(chain, q_m, q_d)


def geometric_jacobian(chain: Chain, q_m, q_d):
    """6 x n_moving geometric Jacobian of the tool frame in B, linear rows first.

    Columns exist for moving joints only: design joints are infinitely stiff and constant. With a the
    joint's axis and o the origin of the frame the ET acts in (both in B), a rotation's column is
    [a x (p - o); a], a translation's [a; 0].
    """
    walk = Walk(chain.robot, chain.values(q_m, q_d))
    p = (walk.end @ _tool_matrix(chain, walk.end))[:3, 3]
    columns = []
    for k, et in enumerate(chain.robot):
        if chain.joints[et.joint].role is not Role.MOVING:
            continue
        F = walk.frame(k)
        R, o = F[:3, :3], F[:3, 3]
        a = R[:, et.basis] if et.basis is not None else R @ np.array(et.axis)
        lin, ang = (cross(a, p - o), a) if et.motion == "rotate" else (a, 0 * a)
        columns.append((lin, ang))
    if isinstance(p, ca.SX | ca.MX):
        return ca.horzcat(*[ca.vertcat(lin, ang) for lin, ang in columns])
    return np.column_stack([np.concatenate([lin, ang]) for lin, ang in columns])
