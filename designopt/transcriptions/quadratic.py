"""The objective's quadratic terms: each a sum over points j of q(y_j; p_j), with q quadratic in its point's few
variables y_j (entries of x) and p_j the point's constant parameters.

Three of them: the smoothness term (per joint and interval, y = (q_k, v_k, q_k+1, v_k+1), p = the interval's
length), the joint regularisation (per waypoint, y = q_k, p = its quadrature weight) and the quadratic design
costs (one point, y = q_d). Their Hessian is constant: `constant_hessian` derives it once per term on the term's
own variables, evaluates it at the points' parameters and scatters it, instead of a symbolic Hessian of the
whole sum over x (0.03 s of the main job's 0.14 s warm build). Their gradient is the terms' dq/dy at every point,
scattered like the per-waypoint blocks' (`gradient_groups`, for
`designopt.transcriptions.jacobian.assemble_gradient`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import casadi as ca
import numpy as np

from designopt.problem import DesignProblem
from designopt.transcriptions.compiled import compiled, level
from designopt.transcriptions.hessian import block_symbols, per_point
from designopt.transcriptions.trajectory import hermite_acceleration_integral


@dataclass(frozen=True)
class QuadraticTerm:
    """sum_j fn(y_j, *p_j) in the objective's units. ``fn``: (y, *params) -> scalar, quadratic in y;
    ``y_index`` (P points x n_y): the x-indices of each point's y; ``inputs``: the parameters, one column per
    point (each a DM of fn's parameter size x P)."""

    fn: ca.Function
    y_index: np.ndarray
    inputs: tuple = ()

    def value(self, x):
        """The term's value as an expression of the decision vector ``x`` (SX or MX)."""
        return ca.sum2(self.fn.map(self.y_index.shape[0])(per_point(x, self.y_index), *self.inputs))


def smoothness(problem: DesignProblem, q_index: np.ndarray, v_index: np.ndarray, h: np.ndarray) -> QuadraticTerm:
    """smoothness * the integral of |q''|^2 over the path's cubic Hermite segments, per joint and interval.
    ``q_index``, ``v_index`` (N x n_m): x-indices of the joints [rad or m] and their velocities at each waypoint;
    ``h`` (N - 1): the intervals' lengths in the path's time unit."""
    y, step = ca.SX.sym("y", 4), ca.SX.sym("h")
    fn = ca.Function("smoothness", [y, step],
                     [problem.smoothness * hermite_acceleration_integral(y[0], y[1], y[2], y[3], step)])
    y_index = np.stack([q_index[:-1], v_index[:-1], q_index[1:], v_index[1:]], axis=-1)  # interval, joint, 4
    n_m = q_index.shape[1]
    return QuadraticTerm(fn, y_index.reshape(-1, 4), (ca.DM(np.repeat(np.asarray(h, float), n_m)[None, :]),))


def joint_regularization(problem: DesignProblem, q_index: np.ndarray, weights: np.ndarray) -> QuadraticTerm:
    """sum_k w_k * joint_regularization * |q_k|^2: removes exact null directions (a constant joint offset against
    the placement yaw; rotation about the tool axis) that otherwise stall IPOPT. Its weight
    (costs.joint_regularization) is small enough to stay well below 1 % of the design cost on the default
    problem. ``q_index`` (N x n_m): x-indices of the moving joints at each waypoint; ``weights``: the N
    quadrature weights."""
    q, w = ca.SX.sym("q", q_index.shape[1]), ca.SX.sym("w")
    fn = ca.Function("joint_regularization", [q, w], [problem.joint_regularization * w * ca.sumsqr(q)])
    return QuadraticTerm(fn, q_index, (ca.DM(np.asarray(weights, float)[None, :]),))


def design_costs(problem: DesignProblem, design_index: np.ndarray) -> tuple[QuadraticTerm, ...]:
    """The quadratic design costs (e.g. L_r) on the design joints at x-indices ``design_index``: one point, or
    none when no design cost is quadratic or there are no design joints."""
    quadratic = [cost for cost in problem.design_costs if cost.quadratic]
    if not quadratic or not len(design_index):
        return ()
    q_d = ca.SX.sym("q_d", len(design_index))
    fn = ca.Function("design_costs", [q_d], [sum(cost(problem.chain, q_d) for cost in quadratic)])
    return (QuadraticTerm(fn, np.asarray(design_index)[None, :]),)


def total(terms: tuple[QuadraticTerm, ...], x):
    """The sum of the quadratic terms as an expression of ``x`` (0 when there are none)."""
    return sum((term.value(x) for term in terms), ca.SX(0) if isinstance(x, ca.SX) else ca.MX(0))


def constant_hessian(terms: tuple[QuadraticTerm, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Hessian of the terms' sum with respect to x as upper-triangular triplets (rows, cols, values), one per
    place (the points' entries at one place added up), exact zeros left out.
    Raises ValueError when a term's Hessian depends on its variables (the term is not quadratic)."""
    rows, cols, values = [np.zeros(0, int)], [np.zeros(0, int)], [np.zeros(0)]
    for term in terms:
        y, params = block_symbols(term.fn)
        H = ca.triu(ca.hessian(term.fn(y, *params), y)[0])
        if ca.depends_on(H, y):
            raise ValueError(f"the objective term {term.fn.name()!r} is not quadratic in its variables")
        a, b = H.sparsity().get_triplet()
        at_points = ca.Function("hessian_values", params, [ca.vertcat(*H.nonzeros())])
        n_points = term.y_index.shape[0]
        v = np.array(at_points.map(n_points)(*term.inputs) if params else ca.repmat(at_points()["o0"], 1, n_points))
        i, j = term.y_index[:, a], term.y_index[:, b]  # points x entries
        rows.append(np.minimum(i, j).ravel())
        cols.append(np.maximum(i, j).ravel())
        values.append(v.reshape(len(a), n_points).T.ravel())
    rows, cols, values = np.concatenate(rows), np.concatenate(cols), np.concatenate(values)
    if not len(rows):
        return rows, cols, values
    order = np.lexsort((rows, cols))  # stable: a place's contributions add up in the order of the terms' points
    rows, cols, values = rows[order], cols[order], values[order]
    first = np.flatnonzero(np.r_[True, (rows[1:] != rows[:-1]) | (cols[1:] != cols[:-1])])
    rows, cols, values = rows[first], cols[first], np.add.reduceat(values, first)
    keep = values != 0  # entries that cancel (a joint's velocity against its position, on a uniform path) are none
    return rows[keep], cols[keep], values[keep]


def gradient_groups(terms: tuple[QuadraticTerm, ...], compile_mode: str = "none",
                    used: list | None = None) -> list[tuple[ca.Function, np.ndarray, list]]:
    """(y, *params -> dq/dy, y_index, inputs) per term: the groups `assemble_gradient` scatters, each gradient
    compiled as a block of as many points would be (`compiled.level` of ``compile_mode``; ``used``:
    `compiled.compiled_as`)."""
    groups = []
    for term in terms:
        y, params = block_symbols(term.fn)
        gradient = ca.Function("quadratic_gradient", [y, *params], [ca.densify(ca.gradient(term.fn(y, *params), y))])
        groups.append((compiled(gradient, level(compile_mode, len(term.y_index)), used), term.y_index,
                       list(term.inputs)))
    return groups


def compiled_terms(terms: tuple[QuadraticTerm, ...], compile_mode: str,
                   used: list | None = None) -> tuple[QuadraticTerm, ...]:
    """The terms with their functions compiled as blocks of as many points would be (`compiled.level` of
    ``compile_mode``), for evaluating f: interpreted, they and their gradients were most of what CasADi's virtual
    machine still ran in a solve (the same values to the bit, docs/decisions.md, 2026-11-30)."""
    return tuple(replace(term, fn=compiled(term.fn, level(compile_mode, len(term.y_index)), used)) for term in terms)
