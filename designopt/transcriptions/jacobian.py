"""Constraint Jacobian and objective gradient assembled from per-point blocks, as the Hessian is
(`designopt.transcriptions.hessian`).

Every nonlinear constraint row of a transcribed problem is a row of some c_k(y_k) at one point (a waypoint, a
collocation point) with y_k = (q_k, q_d); the other rows (collocation ties, midpoint bounds) are linear or small.
So dg/dx is the small Jacobians dc/dy of one (optionally compiled) block function, evaluated at N points and
scattered into one sparse matrix, plus the Jacobian of the remaining rows, which CasADi derives from their own,
small expressions. Deriving it from the whole SX graph instead colours the dense design-joint columns: most of
the NLP's build time (0.17 s of the main job's, 4.1 s of the pocket cell's; benchmarks/speed_table.py).
Likewise the objective f(x) = sum_k phi_k(y_k) + the quadratic terms (`designopt.transcriptions.quadratic`, each
also a sum over points): its gradient is the blocks' and the quadratic terms' d/dy scattered and added, instead
of a reverse sweep of the whole graph.
"""

from __future__ import annotations

from collections.abc import Callable

import casadi as ca
import numpy as np

from designopt.transcriptions.compiled import compiled_as
from designopt.transcriptions.hessian import block_symbols, ccs_sparsity, derivation_identity, per_point


def block_jacobian_function(terms: ca.Function, compile_mode: str,
                            used: list | None = None) -> tuple[ca.Function, np.ndarray, np.ndarray]:
    """(function (y, *inputs) -> the structural nonzeros of dc/dy as one column, their rows in c, their columns
    in y). ``terms`` is a block's (y, *inputs) -> (phi, c); ``used``: `compiled.compiled_as`. Compiled, the function
    is found in the cache by ``terms`` and this derivation, so that a warm build derives nothing; its nonzeros'
    pattern is ``terms``' own Jacobian sparsity of c in y (checked whenever it is derived)."""
    pattern = terms.jac_sparsity(1, 0)

    def derive() -> ca.Function:
        y, params = block_symbols(terms)
        _, c = terms(y, *params)
        J = ca.jacobian(c, y)
        if J.sparsity() != pattern:
            raise AssertionError(f"the Jacobian of {terms.name()}'s c has other nonzeros than its sparsity says")
        # vertcat of the nonzeros, not nz[:]: the generated C (so its bits) is the one the solves were checked with
        return ca.Function("block_jacobian", [y, *params], [ca.vertcat(*J.nonzeros()) if J.nnz() else ca.SX(0, 1)])

    rows, cols = pattern.get_triplet()
    fn = compiled_as("block_jacobian", derivation_identity(terms, block_jacobian_function), derive, compile_mode, used)
    return fn, np.asarray(rows, int), np.asarray(cols, int)


def unclaimed_rows(n_g: int, mu_indices: list[np.ndarray]) -> np.ndarray:
    """The rows of g (of ``n_g``) in no block, given each block's ``mu_index`` (its rows in g); ValueError when two
    blocks claim one row."""
    claimed = np.zeros(n_g, dtype=bool)
    for mu_index in mu_indices:
        if np.any(claimed[mu_index.ravel()]):
            raise ValueError("two blocks claim the same constraint row")
        claimed[mu_index.ravel()] = True
    return np.flatnonzero(~claimed)


def none_constant(rows: np.ndarray) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], np.ndarray]:
    """The ``constant_rows`` of `assemble_jacobian` for rows with no stated Jacobian: none covered."""
    return (np.zeros(0, int), np.zeros(0, int), np.zeros(0)), rows


def assemble_jacobian(x, n_g: int, g_rows: Callable[[np.ndarray], ca.SX], g_of: ca.Function | None,
                      groups: list[tuple[ca.Function, np.ndarray, np.ndarray, np.ndarray, list, np.ndarray]],
                      constant_rows: Callable[[np.ndarray], tuple[tuple, np.ndarray]] = none_constant
                      ) -> ca.Function:
    """jac_g(x, p) -> (g, dg/dx), for nlpsol's ``jac_g`` option.

    ``x``: the NLP's SX decision vector; ``n_g`` its number of constraints and ``g_rows`` (row indices -> SX) their
    own expressions (only the rows in no group are asked for); ``g_of``: x -> g as a function, or None for a
    Jacobian whose g output is NaN (`not_computed`). Each group is
    (block, rows, cols, y_index, block_inputs, mu_index) with ``block``, ``rows``, ``cols`` from
    `block_jacobian_function`, ``y_index`` (N x n_y) the position in x of each block variable, ``mu_index``
    (N x n_c) the position in g of each block row and ``block_inputs`` the block's constant extra inputs (mapped).
    Rows of g in no group are differentiated from their own expressions, except those whose constant Jacobian
    ``constant_rows`` states (row indices -> ((rows, cols, values) with rows in g, the rows it does not cover):
    `ConstraintList.constant_jacobian`).
    """
    n_x = x.shape[0]
    triplets = [(mu_index[:, rows].ravel(), y_index[:, cols].ravel())  # point by point, as map stacks them
                for _, rows, cols, y_index, _, mu_index in groups]
    rest = unclaimed_rows(n_g, [mu_index for *_, mu_index in groups])
    (a_rows, a_cols, a_values), rest = constant_rows(rest)
    triplets.append((a_rows, a_cols))
    J_rest = ca.jacobian(g_rows(rest) if rest.size else ca.SX(0, 1), x)
    r_rows, r_cols = (np.asarray(a, int) for a in J_rest.sparsity().get_triplet())
    triplets.append((rest[r_rows], r_cols))
    all_rows = np.concatenate([t[0] for t in triplets])
    all_cols = np.concatenate([t[1] for t in triplets])
    order = np.lexsort((all_rows, all_cols))  # CasADi stores nonzeros column by column
    keys = all_cols[order] * n_g + all_rows[order]
    if np.any(keys[1:] == keys[:-1]):
        raise ValueError("two blocks claim the same constraint row")
    sp = ccs_sparsity(n_g, n_x, all_rows[order], all_cols[order])

    X = ca.MX.sym("x", n_x)
    P = ca.MX.sym("p", 0, 1)
    values = []
    for block, _, _, y_index, block_inputs, _ in groups:
        values.append(ca.vec(block.map(y_index.shape[0])(per_point(X, y_index), *block_inputs)))
    if a_rows.size:
        values.append(ca.MX(ca.DM(a_values)))
    # its nonzeros as one column by slicing (`nz[:]`, a row when J_rest is one row, hence vec): vertcat of the
    # Python list of SX scalars was a fifth of a 1,208-waypoint program's warm build
    rest_fn = ca.Function("jac_rest", [x], [ca.vec(J_rest.nz[:]) if J_rest.nnz() else ca.SX(0, 1)])
    values.append(rest_fn(X))
    nz = ca.vertcat(*values)[order.tolist()] if order.size else ca.MX(0, 1)
    g = not_computed(n_g) if g_of is None else g_of(X)
    return ca.Function("jac_g", [X, P], [g, ca.MX(sp, nz)], ["x", "p"], ["g", "jac_g_x"])


def not_computed(n: int) -> ca.MX:
    """The value output (f or g) of a gradient or Jacobian that only IPOPT reads: NaN.

    nlpsol wants grad_f -> (f, df/dx) and jac_g -> (g, dg/dx), but IPOPT's interface asks for the derivative
    alone, while an MX function evaluates every node whatever its caller asks for: f and g assembled from the
    blocks were computed again in every gradient and Jacobian, about 5 % of an exploration iteration
    (docs/decisions.md, 2026-11-30). NaN, not 0, so that a reader that did use it fails loudly."""
    return ca.MX(ca.DM.nan(n, 1))


def block_gradient_function(terms: ca.Function, compile_mode: str, used: list | None = None) -> ca.Function | None:
    """(y, *inputs) -> dphi/dy as a dense column, for a block's (y, *inputs) -> (phi, c); None when phi does not
    depend on y (a clearance block). ``used``: `designopt.transcriptions.compiled.compiled_as`; found in the cache
    by ``terms`` and this derivation, as `block_jacobian_function` is."""
    if not terms.jac_sparsity(0, 0).nnz():
        return None

    def derive() -> ca.Function:
        y, params = block_symbols(terms)
        phi, _ = terms(y, *params)
        return ca.Function("block_gradient", [y, *params], [ca.densify(ca.gradient(phi, y))])

    return compiled_as("block_gradient", derivation_identity(terms, block_gradient_function), derive, compile_mode,
                       used)


def assemble_gradient(n_x: int, f_of: ca.Function | None,
                      groups: list[tuple[ca.Function | None, np.ndarray, list]]) -> ca.Function:
    """grad_f(x, p) -> (f, df/dx), for nlpsol's ``grad_f`` option, of f(x) = the sum over the groups' points of
    each group's term at y_k (the per-waypoint phi_k(y_k), the quadratic terms).

    ``n_x``: the length of x; ``f_of``: x -> f, or None for a gradient whose f output is NaN (`not_computed`).
    Each group is (block, y_index, block_inputs) with ``block`` the
    term's gradient (y, *inputs) -> d/dy (`block_gradient_function`,
    `designopt.transcriptions.quadratic.gradient_groups`; None: no objective term), ``y_index`` (N x n_y) the
    position in x of each block variable and ``block_inputs`` the block's constant extra inputs (mapped).
    Contributions to one entry add up.
    """
    X = ca.MX.sym("x", n_x)
    P = ca.MX.sym("p", 0, 1)
    values, rows = [], []
    for block, y_index, block_inputs in groups:
        if block is not None:
            values.append(ca.vec(block.map(y_index.shape[0])(per_point(X, y_index), *block_inputs)))
            rows.append(y_index.ravel())  # point by point, as map stacks the blocks' outputs
    rows = np.concatenate([*rows, np.zeros(0, int)])
    # one 1 per column: block entry e adds to entry rows[e] of the gradient
    scatter = ca.DM(ccs_sparsity(n_x, len(rows), rows, np.arange(len(rows))), 1.0)
    # dense: nlpsol hands IPOPT grad_f's nonzeros as the whole gradient, so an entry no term touches must be a
    # stored 0 (given a structurally sparse one, IPOPT solved another problem: the pocket cell's starts went to
    # the iteration cap; tests/test_collocation.py has the smallest case)
    grad = ca.densify(ca.mtimes(scatter, ca.vertcat(*values)) if len(rows) else ca.MX(n_x, 1))
    f = not_computed(1) if f_of is None else f_of(X)
    return ca.Function("grad_f", [X, P], [f, grad], ["x", "p"], ["f", "grad_f_x"])
