"""Metrics of a candidate solution, computed one way for every method.

Whatever transcription produced (q_d, Q), the design cost, the tracking errors and the joint steps
reported are computed here, so TO and FK compare on one number. The per-waypoint quantities come from the cost
definitions of `designopt.costs` (the same ones the NLPs are built from), evaluated numerically by one CasADi
function of the problem mapped over the waypoints (`waypoint_metrics`); the sums, norms and maxima are numpy's.
"""

from __future__ import annotations

import functools
import pickle
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


def waypoint_metrics(problem: DesignProblem, n: int):
    """(Q [n_moving x n], q_d [n_design], S_W [3 x n], F_W [3 x n]) -> (deformation L_d [1 x n], position error
    p_W - s_W [3 x n, m], axis error z_W - z* [3 x n], path point in B [3 x n, m], each of the problem's waypoint
    costs before its weight [n_costs x n]) at ``n`` waypoints: a CasADi function of the states
    `DesignProblem.waypoint` gives (column k: waypoint k; S_W, F_W the path points [m] and forces [N] in W), built
    once per chain, stiffness, deflection model, waypoint costs and n in a process. A numpy walk of the chain per
    waypoint took 3.7 ms on the exploration's 10 waypoints (this: 0.4 ms), about 5 % of an exploration solve, and
    28 ms on the main job's 80 (0.8 ms; benchmarks/evaluate_speed.py)."""
    key = pickle.dumps((problem.chain, problem.k_inv, problem.deflection, problem.waypoint_costs))
    return _waypoint_metrics(key, n)


@functools.lru_cache(maxsize=32)
def _waypoint_metrics(key: bytes, n: int):
    import casadi as ca

    chain, k_inv, deflection, waypoint_costs = pickle.loads(key)
    q, q_d = ca.SX.sym("q", chain.n_moving), ca.SX.sym("q_d", chain.n_design)
    s_W, f_W = ca.SX.sym("s_W", 3), ca.SX.sym("f_W", 3)
    w = costs.waypoint(chain, q, q_d, s_W, f_W, k_inv, deflection)
    deform = deformation_term(w)
    r_p, r_z = tracking_residual(w)
    s_B = w.T_BW[:3, :3] @ s_W + w.T_BW[:3, 3]
    values = [deform if c.fn is deformation_term else c.fn(w) for c in waypoint_costs]
    one = ca.Function("waypoint_metrics", [q, q_d, s_W, f_W],
                      [deform, r_p, r_z, s_B, ca.vertcat(*values) if values else ca.SX(0, 1)])
    return one.map(n)


def evaluate(problem: DesignProblem, q_d: np.ndarray, trajectory) -> Metrics:
    """Evaluate a design q_d (n_d) and a joint trajectory (`designopt.transcriptions.trajectory`; its knots are
    the waypoints) on the problem's toolpath; the clearance is checked at its collocation points too."""
    chain, tp = problem.chain, problem.toolpath
    q_d = np.asarray(q_d, dtype=float)
    Q = np.asarray(trajectory.Q, dtype=float)
    out = waypoint_metrics(problem, tp.n)(Q.T, q_d, np.asarray(tp.points_W, float).T,
                                          np.asarray(tp.force_W, float).T)
    deform, r_p, r_z, s_B, per_cost = (np.array(o, dtype=float) for o in out)
    deform = deform.ravel()
    pos_err, axis_err = np.linalg.norm(r_p, axis=0), np.linalg.norm(r_z, axis=0)
    weights, tracked = tp.weights, tp.is_tracked
    values = {c.name: float(np.sum(weights * per_cost[i])) for i, c in enumerate(problem.waypoint_costs)}
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
        min_standoff=float(np.min(np.hypot(s_B[0], s_B[1]))),
        costs=tuple(values.items()),
        clearance=trajectory_clearance(problem, q_d, trajectory) if problem.cell is not None else None,
    )
