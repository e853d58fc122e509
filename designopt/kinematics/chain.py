"""Forward kinematics and the geometric Jacobian of a design-joint chain.

Frames: B is the robot base, W the workpiece (its pose T_BW is given by the placement joints), the tool
frame is the last DH frame times ``chain.tool``. All results are expressed in B unless a name says W.
Works on numbers (numpy) and on CasADi symbols alike.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from designopt.kinematics.joints import Chain
from designopt.kinematics.transforms import cross, dh_transform, inverse, is_symbolic, placement_transform


def _tool_matrix(chain: Chain, like):
    tool = np.array(chain.tool, dtype=float)
    if isinstance(like, ca.SX):
        return ca.SX(ca.DM(tool))
    if isinstance(like, ca.MX):
        return ca.MX(ca.DM(tool))
    return tool


def placement_pose(chain: Chain, q_m, q_d):
    """T_BW: pose of the workpiece frame in the base frame (4x4)."""
    return placement_transform(*chain.placement_values(q_m, q_d))


def link_frames(chain: Chain, q_m, q_d) -> list:
    """[T_B0, T_B1, ..., T_Bn]: base frame followed by every DH frame (T_B0 = identity)."""
    links = chain.link_values(q_m, q_d)
    first = dh_transform(*links[0])
    eye = ca.SX.eye(4) if isinstance(first, ca.SX) else (ca.MX.eye(4) if isinstance(first, ca.MX) else np.eye(4))
    frames = [eye]
    for params in links:
        frames.append(frames[-1] @ dh_transform(*params))
    return frames


def tool_pose(chain: Chain, q_m, q_d):
    """T_BT: pose of the tool frame in the base frame (4x4)."""
    last = link_frames(chain, q_m, q_d)[-1]
    return last @ _tool_matrix(chain, last)


def tool_in_workpiece(chain: Chain, q_m, q_d):
    """T_WT = T_BW^-1 T_BT: tool pose in the workpiece frame, where the toolpath is given."""
    return inverse(placement_pose(chain, q_m, q_d)) @ tool_pose(chain, q_m, q_d)


def geometric_jacobian(chain: Chain, q_m, q_d):
    """6 x n_moving geometric Jacobian of the tool frame in B, linear rows first.

    Columns exist for moving joints only: design joints are infinitely stiff and constant. A revolute
    column is [z_{i-1} x (p - o_{i-1}); z_{i-1}], a prismatic one [z_{i-1}; 0].
    """
    frames = link_frames(chain, q_m, q_d)
    p = (frames[-1] @ _tool_matrix(chain, frames[-1]))[:3, 3]
    columns = []
    for i, link_type in enumerate(chain.structure):
        if chain.joints[6 + 4 * i + (0 if link_type == "R" else 1)].role.value != "moving":
            continue
        z, o = frames[i][:3, 2], frames[i][:3, 3]
        if link_type == "R":
            lin, ang = cross(z, p - o), z
        else:
            lin, ang = z, 0 * z
        columns.append((lin, ang))
    if is_symbolic(p):
        return ca.horzcat(*[ca.vertcat(lin, ang) for lin, ang in columns])
    return np.column_stack([np.concatenate([lin, ang]) for lin, ang in columns])
