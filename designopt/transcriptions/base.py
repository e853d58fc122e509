"""Pieces shared by every transcription: the per-waypoint kinematics function, guesses and raw results."""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from designopt.problem import DesignProblem
from designopt.transcriptions.trajectory import HermiteCubic, PiecewiseLinear


@dataclass(frozen=True)
class InitialGuess:
    """A starting point: design joints q_d (n_d), waypoint joints Q (N x n_m), velocities V (N x n_m)."""

    q_d: np.ndarray
    Q: np.ndarray
    V: np.ndarray | None = None
    seed: int = 0


@dataclass(frozen=True)
class RawResult:
    """What a solver returned, before any metric is computed: the design joints and the joint trajectory (the
    transcription's own kind, `designopt.transcriptions.trajectory`). Times in seconds."""

    q_d: np.ndarray
    trajectory: HermiteCubic | PiecewiseLinear
    status: str
    success: bool
    iterations: int
    solve_time_s: float
    build_time_s: float
    objective: float
    n_variables: int
    n_constraints: int
    seed: int = 0
    kinematic_drift: float = 0.0
    held: str = ""  # design joints held on a degenerate design to finish the solve (solve.strategies.continuation)

    @property
    def Q(self) -> np.ndarray:
        """Joint values at the waypoints (N x n_m)."""
        return self.trajectory.Q

    @property
    def V(self) -> np.ndarray | None:
        """Joint velocities at the waypoints (N x n_m), when the trajectory has them."""
        return self.trajectory.V


def waypoint_function(problem: DesignProblem) -> ca.Function:
    """Kinematics at one waypoint, as a CasADi SX function.

    Inputs: q (n_m), q_d (n_d), s_W (3, waypoint in W), f_W (3, force in W).
    Outputs, all in the workpiece frame W so that the targets are constants:
      p_W (3) tool position, z_W (3) tool axis, rho2 squared distance of the waypoint from the base z-axis
      (for the keep-out stand-off), Jv_W (3 x n_m) linear Jacobian in W.
    """
    chain = problem.chain
    q = ca.SX.sym("q", chain.n_moving)
    q_d = ca.SX.sym("q_d", chain.n_design)
    s_W = ca.SX.sym("s_W", 3)
    f_W = ca.SX.sym("f_W", 3)
    w = problem.waypoint(q, q_d, s_W, f_W)
    R_BW, t_BW = w.T_BW[:3, :3], w.T_BW[:3, 3]
    s_B = R_BW @ s_W + t_BW
    return ca.Function(
        "waypoint", [q, q_d, s_W, f_W], [w.p_W, w.z_W, s_B[0] ** 2 + s_B[1] ** 2, R_BW.T @ w.J[:3, :]],
        ["q", "q_d", "s_W", "f_W"], ["p_W", "z_W", "rho2", "Jv_W"],
    )
