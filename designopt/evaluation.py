"""Metrics of a candidate solution, computed one way (numpy) for every method.

Whatever transcription produced (q_d, Q), the design cost, the tracking errors and the joint steps
reported are computed here, so TO and FK compare on one number.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designopt import costs
from designopt.kinematics.chain import geometric_jacobian, placement_pose, tool_pose
from designopt.problem import DesignProblem


@dataclass(frozen=True)
class Metrics:
    """Per-solution figures. Lengths in metres; deformation per waypoint in the cost's units."""

    design_cost: float
    regularization: float
    max_position_error: float
    max_axis_error: float
    max_joint_step: float
    tracks: bool
    deformation: np.ndarray
    position_error: np.ndarray
    axis_error: np.ndarray
    min_standoff: float
    design_costs: tuple[tuple[str, float], ...] = ()

    def row(self) -> dict:
        return {
            **{f"cost_{name}": value for name, value in self.design_costs},
            "design_cost": self.design_cost,
            "regularization": self.regularization,
            "max_position_error": self.max_position_error,
            "max_axis_error": self.max_axis_error,
            "max_joint_step": self.max_joint_step,
            "tracks": self.tracks,
            "min_standoff": self.min_standoff,
        }


def max_joint_step(Q: np.ndarray) -> float:
    """Largest |q_{k+1} - q_k| of any moving joint between consecutive waypoints (rad or m)."""
    Q = np.asarray(Q, dtype=float)
    if len(Q) < 2:
        return 0.0
    return float(np.max(np.abs(np.diff(Q, axis=0))))


def evaluate(problem: DesignProblem, q_d: np.ndarray, Q: np.ndarray) -> Metrics:
    """Evaluate a design q_d (n_d) and joint waypoints Q (N x n_m) on the problem's toolpath."""
    chain, tp = problem.chain, problem.toolpath
    T_BW = placement_pose(chain, Q[0], q_d)
    R_BW, t_BW = T_BW[:3, :3], T_BW[:3, 3]
    z_target = R_BW @ np.array([0.0, 0.0, -1.0])
    k_inv = problem.k_inv
    deform, pos_err, axis_err, standoff = [], [], [], []
    for k in range(tp.n):
        T = tool_pose(chain, Q[k], q_d)
        s_B = R_BW @ tp.points_W[k] + t_BW
        pos_err.append(np.linalg.norm(T[:3, 3] - s_B))
        axis_err.append(np.linalg.norm(T[:3, 2] - z_target))
        J = geometric_jacobian(chain, Q[k], q_d)
        deform.append(costs.deformation(J, k_inv, R_BW @ tp.force_W[k], problem.deflection))
        standoff.append(np.hypot(s_B[0], s_B[1]))
    deform, pos_err, axis_err = np.array(deform), np.array(pos_err), np.array(axis_err)
    max_pos, max_axis = float(pos_err.max()), float(axis_err.max())
    return Metrics(
        design_cost=costs.design_cost(deform, tp.dt),
        regularization=costs.regularization(np.asarray(q_d)[problem.regularized], problem.regularization),
        max_position_error=max_pos,
        max_axis_error=max_axis,
        max_joint_step=max_joint_step(Q),
        tracks=bool(max_pos <= problem.position_tol and max_axis <= problem.axis_tol),
        deformation=deform,
        position_error=pos_err,
        axis_error=axis_err,
        min_standoff=float(min(standoff)),
        design_costs=tuple((c.name, float(c(chain, np.asarray(q_d, float)))) for c in problem.design_costs),
    )
