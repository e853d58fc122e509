"""FK: the forward-kinematics baseline of Whitman et al. (SPEC §4).

One independent joint vector q_k per waypoint plus the design joints; minimise the integrated deformation
(+ regularisation) subject to L_t(t_k) <= epsilon at every waypoint. Nothing ties q_k to q_{k+1}, so a
solution may jump between inverse-kinematics branches -- which no real trajectory can do; every result
reports max_joint_step. ``continuous=True`` is the fair variant `fk_continuous`: |q_{k+1} - q_k| is bounded
by the joint velocity limit TO uses, times the waypoint spacing. It is a relaxation of TO: TO's exact tracking
meets L_t <= epsilon, and TO's velocity bounds at both knots and the midpoint of a cubic imply the step bound
(the step is h (v_0 + 4 v_mid + v_1) / 6), so its best design can be below TO's (docs/results.md, C1).

epsilon defaults to (0.95 position_tol)^2, so an FK solution tracks within the same tolerances as TO (its
position error <= position_tol and axis error <= position_tol <= axis_tol).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

import designopt.transcriptions.quadratic as quadratic_terms
from designopt.problem import DesignProblem
from designopt.transcriptions.affine import Affine
from designopt.transcriptions.base import InitialGuess
from designopt.transcriptions.nlp import (
    NLP,
    BlockStructure,
    ConstraintList,
    deferred_terms,
    free_untracked,
    tracking_rows,
    waypoint_inputs,
    waypoint_terms,
    y_indices,
)
from designopt.transcriptions.trajectory import PiecewiseLinear


@dataclass(frozen=True)
class ForwardKinematics:
    """The FK baseline as a transcription of the same DesignProblem as TO. ``hessian``: ``structured`` (exact,
    from per-waypoint blocks) or ``auto`` (CasADi differentiates the whole graph)."""

    continuous: bool = False
    epsilon: float | None = None
    hessian: str = "structured"

    exact_tracking = False  # tracking within epsilon: nothing degenerates the way hard equalities do
    trajectory_kind = PiecewiseLinear.kind

    def __post_init__(self):
        if self.hessian not in ("structured", "auto"):
            raise ValueError(f"hessian must be structured or auto, got {self.hessian!r}")

    @property
    def name(self) -> str:
        return "fk_continuous" if self.continuous else "fk"

    def build(self, problem: DesignProblem) -> ForwardKinematicsNLP:
        return ForwardKinematicsNLP(problem, self)

    def trajectory(self, t, Q, V=None) -> PiecewiseLinear:
        """Joint values at the waypoints; straight lines between them are all the baseline defines."""
        return PiecewiseLinear(np.asarray(t, float), np.asarray(Q, float))


class ForwardKinematicsNLP:
    def __init__(self, problem: DesignProblem, scheme: ForwardKinematics):
        t0 = time.perf_counter()
        if problem.cell is not None:
            raise ValueError("the forward-kinematics baseline does not model the cell's clearance: use TO")
        self.problem, self.scheme = problem, scheme
        chain, tp = problem.chain, problem.toolpath
        n_m, n_d, N = chain.n_moving, chain.n_design, tp.n
        # (0.95 tol)^2: IPOPT accepts constraint violations of ~1e-8, which on L_t <= tol^2 alone would put
        # the position error just above tol (measured 1.0045 mm for tol = 1 mm).
        self.epsilon = scheme.epsilon if scheme.epsilon is not None else (0.95 * problem.position_tol) ** 2

        q_d = ca.SX.sym("q_d", n_d)
        Q = ca.SX.sym("Q", n_m, N)
        x = ca.vertcat(q_d, ca.vec(Q))
        terms, c_lo, c_hi = waypoint_terms(problem, "epsilon", epsilon=self.epsilon)
        q_index = n_d + np.arange(N)[:, None] * n_m + np.arange(n_m)[None, :]
        quadratic = (quadratic_terms.joint_regularization(problem, q_index, tp.weights),
                     *quadratic_terms.design_costs(problem, np.arange(n_d)))
        # the terms' graph over all waypoints: built only if the whole f or g is asked for, never for a solve
        objective, C = deferred_terms(terms, ca.vertcat(Q, ca.repmat(q_d, 1, N)), waypoint_inputs(problem),
                                      quadratic, x)

        cons = ConstraintList()
        n_c = terms.size1_out(1)
        cons.add(C, *free_untracked(problem, np.tile(c_lo[:, None], (1, N)), np.tile(c_hi[:, None], (1, N)),
                                 tracking_rows(problem, "epsilon")))
        if scheme.continuous:
            step = problem.max_steps.T
            # affine: the Jacobian stated, not derived (`transcriptions.affine`)
            cons.add(Affine(_step, x, (q_index.T[:, :-1], q_index.T[:, 1:])), -step, step)

        lo_m = [j.lower for j in chain.moving]
        hi_m = [j.upper for j in chain.moving]
        lbx = np.concatenate([[j.lower for j in chain.design], np.tile(lo_m, N)])
        ubx = np.concatenate([[j.upper for j in chain.design], np.tile(hi_m, N)])
        blocks = None if scheme.hessian == "auto" else [BlockStructure(
            terms, y_indices(n_d, n_m, N, n_m), np.arange(N * n_c).reshape(N, n_c))]
        self.nlp = NLP(problem, scheme.name, x, objective, quadratic, cons, lbx, ubx, blocks)
        self.build_time_s = time.perf_counter() - t0

    def pack(self, guess: InitialGuess) -> np.ndarray:
        """Design joints, then the joints at every waypoint (FK has no velocities)."""
        return np.concatenate([np.asarray(guess.q_d, float), np.asarray(guess.Q, float).ravel()])

    def unpack(self, x: np.ndarray) -> tuple[np.ndarray, PiecewiseLinear, float]:
        n_d, n_m, N = self.problem.chain.n_design, self.problem.chain.n_moving, self.problem.toolpath.n
        return x[:n_d], self.scheme.trajectory(self.problem.toolpath.t, x[n_d:].reshape(N, n_m)), 0.0


def _step(q0, q1):
    """The joints' step from one waypoint to the next: an `Affine` row's function."""
    return q1 - q0
