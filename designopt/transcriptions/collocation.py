"""TO: direct collocation of the design problem (the paper's method, SPEC §4).

Moving joints follow C^1 piecewise-cubic (Hermite) trajectories with knots at the waypoints: the knot
states are (q_k, v_k = dq/dt), so position and velocity are continuous by construction and one cubic
spans each interval. Design joints are degree-0: one decision variable each for the whole task. Joint
position and velocity bounds hold at the knots and at every interval midpoint (the collocation points).

Tracking is ``hard`` (position and tool axis as equality constraints at every waypoint; default) or
``soft`` (the paper's penalty w * L_t). Kinematics is ``forward`` (p = FK(q)) or ``differential``
(p is a state with dp/dt = J(q) dq/dt, integrated by Simpson's rule over each interval, p_0 = FK(q_0)).

The NLP is built once per problem shape and solved by any backend from any number of initial guesses
(`designopt.solve`); the trajectory between the knots is `HermiteCubic`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

import designopt.transcriptions.quadratic as quadratic_terms
from designopt.problem import DesignProblem
from designopt.transcriptions.affine import Affine
from designopt.transcriptions.base import InitialGuess, waypoint_function
from designopt.transcriptions.nlp import (
    NLP,
    BlockStructure,
    ConstraintList,
    Deferred,
    clearance_terms,
    deferred_terms,
    floor_terms,
    free_untracked,
    once_only_rows,
    tracking_rows,
    waypoint_inputs,
    waypoint_terms,
    y_indices,
)
from designopt.transcriptions.trajectory import HermiteCubic, hermite_midpoint


@dataclass(frozen=True)
class Collocation:
    """The TO transcription: swap it for another transcription of the same DesignProblem.

    ``hessian``: ``structured`` assembles the exact Hessian from per-waypoint blocks (forward kinematics
    only), ``auto`` lets the backend differentiate the whole graph.
    """

    kinematics: str = "forward"
    tracking: str = "hard"
    degree: int = 3
    hessian: str = "structured"

    name = "to"
    trajectory_kind = HermiteCubic.kind

    @property
    def exact_tracking(self) -> bool:
        """Whether the tool's position and axis are equality constraints of the design joints and the joints at
        every waypoint (hard tracking, forward kinematics): the rows `designopt.transcriptions.degeneracy`
        analyses."""
        return self.tracking == "hard" and self.kinematics == "forward"

    def __post_init__(self):
        if self.degree != 3:
            raise ValueError("only degree 3 (C^1 cubic Hermite) collocation is implemented")
        if self.kinematics not in ("forward", "differential"):
            raise ValueError(f"kinematics must be forward or differential, got {self.kinematics!r}")
        if self.tracking not in ("hard", "soft"):
            raise ValueError(f"tracking must be hard or soft, got {self.tracking!r}")
        if self.hessian not in ("structured", "auto"):
            raise ValueError(f"hessian must be structured or auto, got {self.hessian!r}")

    def build(self, problem: DesignProblem) -> CollocationNLP:
        return CollocationNLP(problem, self)

    def size(self, problem: DesignProblem) -> tuple[int, int]:
        """(variables, constraints) of the NLP `build` would make, counted without building it (a program of
        thousands of waypoints takes minutes to build and milliseconds to count)."""
        n_m, n_d, N = problem.chain.n_moving, problem.chain.n_design, problem.toolpath.n
        differential = self.kinematics == "differential"
        n_state = 2 * n_m + (3 if differential else 0)
        n_mid = n_m * (N - 1) if problem.cell is not None else 0
        per_waypoint = len(tracking_rows(problem, self.tracking, position_in_terms=not differential))
        per_waypoint += problem.keep_out_radius > 0
        rows = N * per_waypoint + 2 * n_m * (N - 1)  # per waypoint; the joint and velocity bounds at the midpoints
        if differential:
            rows += 3 * N + (3 * N if self.tracking == "hard" else 0)  # p_0 = FK(q_0), Simpson steps; P = S
        if problem.cell is not None:
            # the midpoints' joints tied to the cubic, one clearance row per configuration, the block's 4 corners
            rows += n_mid + (2 * N - 1) + 4
        return n_d + N * n_state + n_mid, rows

    def trajectory(self, t, Q, V) -> HermiteCubic:
        """The joint trajectory the knots (q_k, v_k) define."""
        return HermiteCubic(np.asarray(t, float), np.asarray(Q, float), np.asarray(V, float))


class CollocationNLP:
    """The built NLP of one problem (`nlp`), and how guesses and answers map onto its decision vector."""

    def __init__(self, problem: DesignProblem, scheme: Collocation):
        t0 = time.perf_counter()
        self.problem, self.scheme = problem, scheme
        chain, tp = problem.chain, problem.toolpath
        n_m, n_d, N = chain.n_moving, chain.n_design, tp.n
        # one step for a uniform path keeps its expressions (and results) as they were; else one per interval
        h = tp.dt if tp.uniform else ca.DM(np.tile(tp.h, (n_m, 1)))
        differential = scheme.kinematics == "differential"
        self.n_state = 2 * n_m + (3 if differential else 0)

        q_d = ca.SX.sym("q_d", n_d)
        Z = ca.SX.sym("Z", self.n_state, N)  # column k: (q_k, v_k[, p_k])
        # With a cell, the collocation points' joints are variables too (M, tied to the cubic by linear
        # equalities), so that the clearance there is a per-point term the structured Hessian covers.
        self.n_mid = n_m * (N - 1) if problem.cell is not None else 0
        M = ca.SX.sym("M", n_m, N - 1) if self.n_mid else None
        x = ca.vertcat(q_d, ca.vec(Z), *([ca.vec(M)] if self.n_mid else []))
        Q, V = Z[:n_m, :], Z[n_m : 2 * n_m, :]
        inputs = waypoint_inputs(problem)
        S, F = inputs[0], inputs[1]

        terms, c_lo, c_hi = waypoint_terms(problem, scheme.tracking, position_in_terms=not differential)

        q_index = n_d + np.arange(N)[:, None] * self.n_state + np.arange(n_m)[None, :]
        # The smoothness term must stay small against the design cost: the figure-eight needs joint
        # accelerations of ~100 rad per unit task time squared, so 1e-6 already outweighed L_d (measured).
        quadratic = (*quadratic_terms.design_costs(problem, np.arange(n_d)),
                     quadratic_terms.smoothness(problem, q_index, q_index + n_m,
                                                np.full(N - 1, tp.dt) if tp.uniform else tp.h),
                     quadratic_terms.joint_regularization(problem, q_index, tp.weights))
        # the terms' graph over all waypoints: built only if the whole f or g is asked for, never for a solve
        objective, C = deferred_terms(terms, ca.vertcat(Q, ca.repmat(q_d, 1, N)), inputs, quadratic, x)

        cons = ConstraintList()
        n_c = terms.size1_out(1)
        C_lo, C_hi = np.tile(c_lo[:, None], (1, N)), np.tile(c_hi[:, None], (1, N))
        once = once_only_rows(problem, scheme.tracking) if not differential else np.zeros(0, dtype=int)
        others = np.arange(N) != int(np.argmax(tp.is_tracked))  # held at the first tracked waypoint only
        C_lo[np.ix_(once, others)], C_hi[np.ix_(once, others)] = -np.inf, np.inf
        C_lo, C_hi = free_untracked(problem, C_lo, C_hi,
                                    tracking_rows(problem, scheme.tracking, position_in_terms=not differential))
        cons.add(C, C_lo, C_hi)  # first, so that its multipliers are 0 .. n_c N

        if differential:
            P = Z[2 * n_m :, :]
            wp = waypoint_function(problem)
            p_W, _, _, Jv = wp.map(N)(Q, ca.repmat(q_d, 1, N), S, F)
            h3 = tp.dt if tp.uniform else ca.DM(np.tile(tp.h, (3, 1)))
            Q_mid, V_mid = hermite_midpoint(Q[:, :-1], V[:, :-1], Q[:, 1:], V[:, 1:], h)
            _, _, _, Jv_mid = wp.map(N - 1)(Q_mid, ca.repmat(q_d, 1, N - 1), S[:, :-1], F[:, :-1])
            pdot, pdot_mid = _pdot(Jv, V, n_m, N), _pdot(Jv_mid, V_mid, n_m, N - 1)
            cons.add(P[:, 0] - p_W[:, 0], 0.0, 0.0)
            cons.add(P[:, 1:] - P[:, :-1] - h3 / 6.0 * (pdot[:, :-1] + 4 * pdot_mid + pdot[:, 1:]), 0.0, 0.0)
            tracked = tp.is_tracked
            if scheme.tracking == "hard":
                bound = np.where(tracked, 0.0, np.inf)[None, :].repeat(3, axis=0)
                cons.add(P - S, -bound, bound)
            else:
                weight = ca.DM((tp.weights * tracked)[None, :])
                penalty, rest = problem.tracking_weight * ca.sum2(weight * ca.sum1((P - S) ** 2)), objective
                objective = Deferred(lambda: rest.value + penalty, 1)
            self._drift = ca.Function("drift", [x], [ca.mmax(ca.sqrt(ca.sum1((P - p_W) ** 2)))])

        lo_m = np.array([j.lower for j in chain.moving])
        hi_m = np.array([j.upper for j in chain.moving])
        vmax = np.tile(problem.velocity_limits[:, None], (1, N - 1))
        # the midpoint rows are affine in the knots: their Jacobian stated, not derived (`transcriptions.affine`)
        q_at, v_at = q_index.T, (q_index + n_m).T  # n_m x N, as Q and V
        knots = (q_at[:, :-1], v_at[:, :-1], q_at[:, 1:], v_at[:, 1:])
        steps = (tp.dt if tp.uniform else np.tile(tp.h, (n_m, 1)),)  # as h above
        cons.add(Affine(_mid_q, x, knots, steps),
                 np.tile(lo_m[:, None], (1, N - 1)), np.tile(hi_m[:, None], (1, N - 1)))
        cons.add(Affine(_mid_v, x, knots, steps), -vmax, vmax)
        cell_blocks = []
        if problem.cell is not None:
            mid_index = (n_d + N * self.n_state + np.arange(N - 1)[:, None] * n_m + np.arange(n_m)[None, :])
            cons.add(Affine(_mid_tie, x, (mid_index.T, *knots), steps), 0.0, 0.0)
            clear = clearance_terms(problem)
            n_cl = clear.size1_out(1)
            for points, at, count in ((Q, y_indices(n_d, n_m, N, self.n_state), N),
                                      (M, np.hstack([mid_index, np.tile(np.arange(n_d), (N - 1, 1))]), N - 1)):
                first = cons.size
                cons.add(Deferred(lambda points=points, count=count:
                                  clear.map(count)(ca.vertcat(points, ca.repmat(q_d, 1, count)))[1], count * n_cl),
                         0.0, np.inf)
                cell_blocks.append(BlockStructure(clear, at, first + np.arange(count * n_cl).reshape(count, n_cl), ()))
            floor = floor_terms(problem)
            first = cons.size
            cons.add(floor(q_d)[1], 0.0, np.inf)
            cell_blocks.append(BlockStructure(floor, np.arange(n_d)[None, :],
                                              first + np.arange(floor.size1_out(1))[None, :], ()))

        n_free = self.n_state - 2 * n_m
        state_lo = np.concatenate([lo_m, -problem.velocity_limits, -np.inf * np.ones(n_free)])
        state_hi = np.concatenate([hi_m, problem.velocity_limits, np.inf * np.ones(n_free)])
        mid_lo, mid_hi = np.tile(lo_m, N - 1)[: self.n_mid], np.tile(hi_m, N - 1)[: self.n_mid]
        lbx = np.concatenate([[j.lower for j in chain.design], np.tile(state_lo, N), mid_lo])
        ubx = np.concatenate([[j.upper for j in chain.design], np.tile(state_hi, N), mid_hi])
        blocks = None
        if scheme.hessian == "structured" and not differential:
            blocks = [BlockStructure(terms, y_indices(n_d, n_m, N, self.n_state), np.arange(N * n_c).reshape(N, n_c)),
                      *cell_blocks]
        elif problem.cell is not None:
            raise ValueError("clearance constraints need the structured Hessian and forward kinematics")
        self.nlp = NLP(problem, "to", x, objective, quadratic, cons, lbx, ubx, blocks)
        self.build_time_s = time.perf_counter() - t0

    def pack(self, guess: InitialGuess) -> np.ndarray:
        """The decision vector of a guess: design joints, knot states (q_k, v_k[, p_k]), collocation points."""
        p = self.problem
        Q = np.asarray(guess.Q, dtype=float)
        V = np.gradient(Q, p.toolpath.t, axis=0) if guess.V is None else np.asarray(guess.V, dtype=float)
        V = np.clip(V, -p.velocity_limits, p.velocity_limits)
        blocks = [Q, V]
        if self.scheme.kinematics == "differential":
            blocks.append(np.asarray(p.toolpath.points_W))
        Z = np.hstack(blocks)  # row k = column k of the symbolic Z
        mid = []
        if self.n_mid:
            h = p.toolpath.h[:, None]
            mid = [hermite_midpoint(Q[:-1], V[:-1], Q[1:], V[1:], h)[0].ravel()]  # row k = column k of M
        return np.concatenate([np.asarray(guess.q_d, dtype=float), Z.ravel(), *mid])

    def unpack(self, x: np.ndarray) -> tuple[np.ndarray, HermiteCubic, float]:
        """(design joints, joint trajectory, kinematic drift in m) of a decision vector."""
        n_d, n_m, N = self.problem.chain.n_design, self.problem.chain.n_moving, self.problem.toolpath.n
        Z = x[n_d : n_d + N * self.n_state].reshape(N, self.n_state)
        drift = float(self._drift(x)) if self.scheme.kinematics == "differential" else 0.0
        return x[:n_d], self.scheme.trajectory(self.problem.toolpath.t, Z[:, :n_m], Z[:, n_m : 2 * n_m]), drift


def _mid_q(q0, v0, q1, v1, h):
    """The joints at an interval's midpoint (`hermite_midpoint`): an `Affine` row's function."""
    return hermite_midpoint(q0, v0, q1, v1, h)[0]


def _mid_v(q0, v0, q1, v1, h):
    """The joint velocities at an interval's midpoint (`hermite_midpoint`): an `Affine` row's function."""
    return hermite_midpoint(q0, v0, q1, v1, h)[1]


def _mid_tie(m, q0, v0, q1, v1, h):
    """A collocation point's joint variable tied to the cubic: an `Affine` row's function."""
    return m - hermite_midpoint(q0, v0, q1, v1, h)[0]


def _pdot(Jv_W, V, n_m: int, n: int):
    """dp/dt = Jv(q) v at n points, from the horizontally stacked 3 x (n_m n) Jacobians of a map."""
    return ca.horzcat(*[Jv_W[:, k * n_m : (k + 1) * n_m] @ V[:, k] for k in range(n)])
