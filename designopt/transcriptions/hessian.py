"""Exact Hessian of the Lagrangian, assembled from per-waypoint blocks.

Every nonlinear term of the transcribed problems lives at one waypoint and depends only on
y_k = (q_k, q_d): the waypoint's moving joints and the design joints. The Lagrangian is therefore
    L(x) = sum_k [sigma phi_k(y_k) + mu_k . c_k(y_k)] + sigma * (quadratic terms),
and its Hessian is a sum of dense (n_m + n_d)^2 blocks scattered into one sparse matrix plus a constant (the
quadratic terms', `designopt.transcriptions.quadratic.constant_hessian`).
Evaluating one small (optionally compiled) block function N times is far cheaper than CasADi's generic
Hessian of the whole graph, which must colour the dense design-joint columns.
"""

from __future__ import annotations

import functools
import linecache
import types

import casadi as ca
import numpy as np

from designopt.transcriptions.compiled import compiled_as


def per_point(v: ca.MX, index: np.ndarray) -> ca.MX:
    """The entries of ``v`` at ``index`` (N points x n entries) as an n x N matrix, one column per point: the
    argument a block function mapped over the N points takes."""
    n_points, n = index.shape
    if not index.size:
        return ca.MX(n, n_points)
    # a list of ints, not a DM of them: SWIG reads ints into an index directly, half the time of a DM of doubles
    return ca.reshape(v[index.T.ravel(order="F").tolist()], n, n_points)


def ccs_sparsity(n_rows: int, n_cols: int, rows: np.ndarray, cols: np.ndarray) -> ca.Sparsity:
    """The sparsity of distinct (row, col) pairs given column by column (cols ascending, rows ascending within a
    column), built from its compressed columns (Sparsity.triplet sorts and checks tens of thousands of Python
    ints: a tenth of a second on the main job)."""
    colind = np.searchsorted(cols, np.arange(n_cols + 1))
    return ca.Sparsity(n_rows, n_cols, colind.tolist(), np.asarray(rows).tolist())


def sorted_distinct(a: np.ndarray) -> np.ndarray:
    """The distinct entries of ``a``, ascending: ``np.unique(a)`` by a sort and a mask (numpy 2.4's unique hashes
    first: 0.07 s of a 1,208-waypoint program's warm build under a profiler, 40x a sort on 400,000 integers)."""
    ordered = np.sort(a)
    return ordered[np.concatenate([[True], ordered[1:] != ordered[:-1]])] if ordered.size else ordered


def block_symbols(terms: ca.Function) -> tuple[ca.SX, list[ca.SX]]:
    """Symbols for a block's (y, *inputs) -> (phi, c): y and the constant inputs, to derive its blocks from."""
    y = ca.SX.sym("y", terms.sparsity_in(0))
    return y, [ca.SX.sym(terms.name_in(i), terms.sparsity_in(i)) for i in range(1, terms.n_in())]


def block_hessian_function(terms: ca.Function, n_y: int, n_c: int, compile_mode: str,
                           used: list | None = None) -> ca.Function:
    """Upper-triangular entries (row-major over a <= b) of d2/dy2 [sigma phi(y) + mu . c(y)]. Compiled, it is
    found in the cache by ``terms`` and this derivation, so that a warm build derives nothing (``used``:
    `designopt.transcriptions.compiled.compiled_as`)."""

    def derive() -> ca.Function:
        y, params = block_symbols(terms)
        sigma = ca.SX.sym("sigma")
        mu = ca.SX.sym("mu", n_c)
        phi, c = terms(y, *params)
        lagrangian = sigma * phi + (ca.dot(mu, c) if n_c else 0)
        H = ca.hessian(lagrangian, y)[0]
        upper = ca.vertcat(*[H[a, b] for a in range(n_y) for b in range(a, n_y)])
        return ca.Function("waypoint_hessian", [y, sigma, mu, *params], [upper])

    return compiled_as("waypoint_hessian", derivation_identity(terms, block_hessian_function, n_y, n_c), derive,
                       compile_mode, used)


def derivation_identity(terms: ca.Function, derivation, *args) -> str:
    """What determines a block function derived from ``terms`` by ``derivation`` (its source code) with ``args``:
    the compile cache's key for it (`compiled_as`)."""
    return f"{_serialised(terms)}|{_source(derivation)}|{args}"


@functools.lru_cache(maxsize=64)
def _serialised(terms: ca.Function) -> str:
    """``terms.serialize()``, once per block function in a process: a block's Hessian, Jacobian, gradient and split
    terms are each keyed by it (a cell's clearance block, 0.33 MB, takes 3 ms a time)."""
    return terms.serialize()


@functools.lru_cache(maxsize=16)
def _source(derivation) -> str:
    """The source lines of ``derivation``, from its ``def`` to the last line any of its instructions (or its nested
    functions') comes from: `inspect.getsource`'s text up to a closing bracket, without tokenising the module
    (the main job's warm build 0.105 -> 0.096 s for its four derivations, f631c21)."""
    code = derivation.__code__
    lines = linecache.getlines(code.co_filename)
    return "".join(lines[code.co_firstlineno - 1:max(_code_lines(code))])


def _code_lines(code: types.CodeType):
    """The line numbers of a code object's instructions and of its nested code objects'."""
    yield code.co_firstlineno
    yield from (line for *_, line in code.co_lines() if line is not None)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            yield from _code_lines(const)


def assemble_hessian(
    n_x: int,
    n_g: int,
    groups: list[tuple[ca.Function, np.ndarray, list, np.ndarray]],
    constant: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> ca.Function:
    """hess_lag(x, p, lam_f, lam_g) -> triu Hessian, for nlpsol's ``hess_lag`` option.

    Each group is (block, y_index, block_inputs, mu_index): a block Hessian function evaluated at N points,
    ``y_index`` (N x n_y) the position in x of each block variable, ``mu_index`` (N x n_c) the position in
    lam_g of each block multiplier, ``block_inputs`` the block's constant extra inputs (mapped). ``constant``
    is the upper-triangular Hessian of the quadratic terms as triplets (rows, cols, values), scaled by lam_f.
    Contributions to one entry add up.
    """
    rows, cols = [], []
    for _, y_index, _, _ in groups:
        a, b = np.triu_indices(y_index.shape[1])  # row-major over a <= b, as the block lists its entries
        i, j = y_index[:, a], y_index[:, b]  # point by point, as map stacks the blocks' outputs
        rows.append(np.minimum(i, j).ravel())
        cols.append(np.maximum(i, j).ravel())
    rows, cols = np.concatenate([*rows, np.zeros(0, int)]), np.concatenate([*cols, np.zeros(0, int)])
    c_rows, c_cols, c_values = (np.asarray(a) for a in constant)
    # CasADi stores nonzeros column by column: a key col * n_x + row orders the (row, col) pairs the same way.
    block_keys, const_keys = cols * n_x + rows, c_cols.astype(int) * n_x + c_rows.astype(int)
    keys = sorted_distinct(np.concatenate([block_keys, const_keys]))
    sp = ccs_sparsity(n_x, n_x, keys % n_x, keys // n_x)
    block_nz, const_nz = np.searchsorted(keys, block_keys), np.searchsorted(keys, const_keys)
    # one 1 per column: block entry e adds to nonzero block_nz[e] of the Hessian
    scatter = ca.DM(ccs_sparsity(sp.nnz(), len(block_nz), block_nz, np.arange(len(block_nz))), 1.0)
    const_vals = np.zeros(sp.nnz())
    np.add.at(const_vals, const_nz, c_values)

    x = ca.MX.sym("x", n_x)
    p = ca.MX.sym("p", 0, 1)
    lam_f = ca.MX.sym("lam_f")
    lam_g = ca.MX.sym("lam_g", n_g)
    values = []
    for block, y_index, block_inputs, mu_index in groups:
        N = y_index.shape[0]
        values.append(ca.vec(block.map(N)(per_point(x, y_index), lam_f, per_point(lam_g, mu_index), *block_inputs)))
    nz = ca.mtimes(scatter, ca.vertcat(*values)) + lam_f * ca.DM(const_vals)
    H = ca.MX(sp, nz)
    return ca.Function("hess_lag", [x, p, lam_f, lam_g], [H], ["x", "p", "lam_f", "lam_g"], ["hess"])
