"""Metrics of a candidate solution, computed one way (numpy) for every method.

Whatever transcription produced (q_d, Q), the design cost, the tracking errors and the joint steps
reported are computed here, so TO and FK compare on one number.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designopt import costs
from designopt.clearance import Clearance, min_clearance
from designopt.costs import deformation_term, tracking_residual
from designopt.problem import DesignProblem


@dataclass(frozen=True)
class Metrics:
    """Per-solution figures. Lengths in metres; deformation per waypoint in the cost's units.

    ``costs`` holds every named term of the problem's objective before its weight (name -> value):
    integrals sum_k dt fn for waypoint terms, fn(q_d) for design terms. ``design_cost`` is the deformation
    integral sum_k dt L_d that every method is compared on; ``regularization`` is lambda_r times the
    regularisation term (its share of the objective).
    """

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
    costs: tuple[tuple[str, float], ...] = ()
    clearance: Clearance | None = None  # with a cell: the smallest clearance at knots and collocation points

    def row(self) -> dict:
        return {
            **{f"cost_{name}": value for name, value in self.costs},
            "design_cost": self.design_cost,
            "regularization": self.regularization,
            "max_position_error": self.max_position_error,
            "max_axis_error": self.max_axis_error,
            "max_joint_step": self.max_joint_step,
            "tracks": self.tracks,
            "min_standoff": self.min_standoff,
            **({"min_clearance": self.clearance.value, "clearance_link": self.clearance.link,
                "clearance_obstacle": self.clearance.obstacle} if self.clearance is not None else {}),
        }


def max_joint_step(Q: np.ndarray) -> float:
    """Largest |q_{k+1} - q_k| of any moving joint between consecutive waypoints (rad or m)."""
    Q = np.asarray(Q, dtype=float)
    if len(Q) < 2:
        return 0.0
    return float(np.max(np.abs(np.diff(Q, axis=0))))


def trajectory_clearance(problem: DesignProblem, q_d: np.ndarray, trajectory):
    """The cell's smallest clearance at the waypoints and at the trajectory's collocation points between them
    (time_index k + 0.5 for the point after waypoint k)."""
    Q = np.asarray(trajectory.Q, dtype=float)
    t_mid, Q_mid = trajectory.collocation_points()
    configurations = np.vstack([Q, Q_mid]) if len(Q_mid) else Q
    indices = np.concatenate([np.arange(len(Q), dtype=float), np.arange(len(Q_mid)) + 0.5])
    return min_clearance(problem.chain, problem.cell, q_d, configurations, indices)


def evaluate(problem: DesignProblem, q_d: np.ndarray, trajectory) -> Metrics:
    """Evaluate a design q_d (n_d) and a joint trajectory (`designopt.transcriptions.trajectory`; its knots are
    the waypoints) on the problem's toolpath; the clearance is checked at its collocation points too."""
    chain, tp = problem.chain, problem.toolpath
    q_d = np.asarray(q_d, dtype=float)
    Q = np.asarray(trajectory.Q, dtype=float)
    states = [problem.waypoint(Q[k], q_d, tp.points_W[k], tp.force_W[k]) for k in range(tp.n)]
    deform = np.array([deformation_term(w) for w in states])
    residuals = [tracking_residual(w) for w in states]
    pos_err = np.array([np.linalg.norm(r_p) for r_p, _ in residuals])
    axis_err = np.array([np.linalg.norm(r_z) for _, r_z in residuals])
    s_B = [w.T_BW[:3, :3] @ w.s_W + w.T_BW[:3, 3] for w in states]
    weights, tracked = tp.weights, tp.is_tracked
    values = {c.name: float(sum(wk * c.fn(w) for wk, w in zip(weights, states, strict=True)))
              for c in problem.waypoint_costs}
    values |= {c.name: float(c.fn(chain, q_d)) for c in problem.design_costs}
    regularization = sum(c.weight * values[c.name] for c in problem.design_costs if c.name == "regularization")
    # rapids (untracked waypoints) may leave the path: errors count where the tool cuts
    max_pos, max_axis = float(pos_err[tracked].max()), float(axis_err[tracked].max())
    return Metrics(
        design_cost=costs.design_cost(deform, weights),
        regularization=float(regularization),
        max_position_error=max_pos,
        max_axis_error=max_axis,
        max_joint_step=max_joint_step(Q),
        tracks=bool(max_pos <= problem.position_tol and max_axis <= problem.axis_tol),
        deformation=deform,
        position_error=pos_err,
        axis_error=axis_err,
        min_standoff=float(min(np.hypot(s[0], s[1]) for s in s_B)),
        costs=tuple(values.items()),
        clearance=trajectory_clearance(problem, q_d, trajectory) if problem.cell is not None else None,
    )
