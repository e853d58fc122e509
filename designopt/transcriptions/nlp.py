"""The part every transcription shares: per-waypoint terms in y_k = (q_k, q_d) and the backend-neutral `NLP` whose
objective, constraints and their derivatives (the exact Hessian, the constraint Jacobian, the gradient) are
assembled from per-waypoint blocks.

A transcription decides the decision vector layout, the objective and the constraints; `NLP` holds them for a
backend (`designopt.solve.backends`) to solve.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np

from designopt.costs import DesignCost, WaypointCost, deflection_rows, tracking_residual, waypoint
from designopt.problem import DesignProblem
from designopt.transcriptions.affine import Affine
from designopt.transcriptions.compiled import built_together, compiled_as, level
from designopt.transcriptions.degeneracy import q_independent_rows
from designopt.transcriptions.hessian import (
    assemble_hessian,
    block_hessian_function,
    block_symbols,
    derivation_identity,
    per_point,
)
from designopt.transcriptions.jacobian import (
    assemble_gradient,
    assemble_jacobian,
    block_gradient_function,
    block_jacobian_function,
    unclaimed_rows,
)
from designopt.transcriptions.quadratic import QuadraticTerm, compiled_terms, constant_hessian, gradient_groups, total


@dataclass(frozen=True)
class Deferred:
    """An expression built only when asked for (`value`, once): the per-point terms' graph inlined over all points
    (e.g. ``terms.map(N)`` called on SX), which a solve never needs -- its values and derivatives come from the
    blocks -- and which took 70 % of a 1,208-waypoint program's build. ``rows``: its number of entries."""

    build: Callable[[], ca.SX]
    rows: int

    @functools.cached_property
    def value(self) -> ca.SX:
        """The expression as a column, built on first use."""
        expr = ca.vec(self.build())
        if expr.shape[0] != self.rows:
            raise ValueError(f"a deferred expression has {expr.shape[0]} rows, declared {self.rows}")
        return expr


def deferred_terms(terms: ca.Function, y, inputs: tuple, quadratic: tuple[QuadraticTerm, ...], x
                   ) -> tuple[Deferred, Deferred]:
    """(objective, constraints) of per-point ``terms`` (y, *inputs) -> (phi, c) at the points ``y`` (one column per
    point), both `Deferred`: the objective is the points' phi summed plus the ``quadratic`` terms at ``x``, the
    constraints every point's c, point by point. The terms' graph over all points is built once, when either is
    first asked for."""
    n = y.shape[1]
    graph = functools.cache(lambda: terms.map(n)(y, *inputs))
    return (Deferred(lambda: ca.sum2(graph()[0]) + total(quadratic, x), 1),
            Deferred(lambda: graph()[1], terms.size1_out(1) * n))


def _built(expr):
    """An entry of a `ConstraintList` as SX: a `Deferred` one built, an `Affine` one's expression."""
    if isinstance(expr, Affine):
        return expr.expression
    return expr.value if isinstance(expr, Deferred) else expr


@dataclass
class ConstraintList:
    """Constraints and their bounds, stacked in the order added (CasADi's column-major vec); an entry may be
    `Deferred`, or `Affine` (its constant Jacobian stated, `constant_jacobian`)."""

    def __post_init__(self):
        self.g, self.lo, self.hi = [], [], []

    def add(self, expr, lo, hi) -> None:
        expr = expr if isinstance(expr, (Deferred, Affine)) else ca.vec(expr)
        rows = expr.rows if isinstance(expr, Deferred) else expr.size if isinstance(expr, Affine) else expr.shape[0]
        self.g.append(expr)
        self.lo.append(np.broadcast_to(np.ravel(lo, order="F"), rows))
        self.hi.append(np.broadcast_to(np.ravel(hi, order="F"), rows))

    @property
    def _starts(self) -> np.ndarray:
        """The first row of each entry in g, then the number of rows."""
        return np.cumsum([0, *(len(lo) for lo in self.lo)])

    @property
    def size(self) -> int:
        """Rows so far: the lam_g index of the next row added."""
        return sum(len(lo) for lo in self.lo)

    def rows(self, index: np.ndarray):
        """The rows ``index`` of g as one SX column, building only the deferred entries they fall in."""
        index = np.asarray(index, dtype=int)
        starts = self._starts
        parts, taken = [], []
        for k, expr in enumerate(self.g):
            inside = index[(index >= starts[k]) & (index < starts[k + 1])]
            if inside.size:
                parts.append(_built(expr)[ca.DM((inside - starts[k]).tolist())])
                taken.append(inside)
        if not parts:
            return ca.SX(0, 1)
        where = {int(row): i for i, row in enumerate(np.concatenate(taken))}
        return ca.vertcat(*parts)[ca.DM([where[int(row)] for row in index])]

    def constant_jacobian(self, index: np.ndarray) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], np.ndarray]:
        """((rows, cols, values), others): the Jacobian of the rows ``index`` of g that lie in `Affine` entries, as
        triplets with rows numbered in g, and the rows of ``index`` that do not (ascending)."""
        index = np.asarray(index, dtype=int)
        starts = self._starts
        wanted = np.zeros(starts[-1], dtype=bool)
        wanted[index] = True
        affine = np.zeros(starts[-1], dtype=bool)
        rows, cols, values = [np.zeros(0, int)], [np.zeros(0, int)], [np.zeros(0)]
        for k, expr in enumerate(self.g):
            if isinstance(expr, Affine) and wanted[starts[k]:starts[k + 1]].any():
                r, c, v = expr.jacobian
                keep = wanted[starts[k] + r]
                rows.append(starts[k] + r[keep])
                cols.append(c[keep])
                values.append(v[keep])
                affine[starts[k]:starts[k + 1]] = True
        return tuple(np.concatenate(a) for a in (rows, cols, values)), np.flatnonzero(wanted & ~affine)

    def stacked(self):
        """(g, lower bounds, upper bounds), every deferred entry built."""
        return (ca.vertcat(*(_built(e) for e in self.g)), *self.bounds())

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return np.concatenate(self.lo), np.concatenate(self.hi)


@dataclass(frozen=True)
class BlockStructure:
    """Where per-point terms sit: x indices of each y_k and lam_g indices of each c_k; ``inputs`` are the terms'
    constant inputs after y (one column per point; None: the problem's `waypoint_inputs`)."""

    terms: ca.Function
    y_index: np.ndarray
    mu_index: np.ndarray
    inputs: tuple | None = None


class NLP:
    """A transcribed problem, backend-neutral: decision vector ``x``, objective ``f``, constraints ``g`` (CasADi SX)
    and their bounds, plus where the per-point nonlinear terms sit (``blocks``), from which `hessian` assembles
    the exact Hessian of the Lagrangian; ``quadratic`` are the terms of ``f`` whose Hessian is constant
    (`designopt.transcriptions.quadratic`).

    Built once per problem shape; a backend (`designopt.solve.backends`) turns it into a solver. The design
    joints come first in ``x`` (x[:n_design])."""

    def __init__(self, problem: DesignProblem, name: str, x, objective, quadratic: tuple[QuadraticTerm, ...],
                 constraints: ConstraintList,
                 lbx, ubx, blocks: list[BlockStructure] | None):
        self.problem, self.name = problem, name
        self.x, self._objective, self.constraints = x, objective, constraints
        self.lbg, self.ubg = constraints.bounds()
        self.lbx, self.ubx = np.asarray(lbx, float), np.asarray(ubx, float)
        self.n_variables, self.n_constraints = x.shape[0], constraints.size
        self.n_equalities = int(np.sum(self.lbg == self.ubg))
        self.n_design = problem.chain.n_design
        self.blocks, self.quadratic = blocks, quadratic
        self._hessians: dict[str, object] = {}
        self._jacobians: dict[tuple[str, bool], object] = {}
        self._gradients: dict[tuple[str, bool], object] = {}
        self._values: dict[str, tuple[ca.Function, ca.Function]] = {}
        self._tiered: dict[str, list] = {}  # per compile mode: the tiered libraries its block functions loaded

    @functools.cached_property
    def f(self) -> ca.SX:
        """The objective as one SX expression of ``x`` (built on first use: with blocks, a solve does not need it)."""
        return _built(self._objective)

    @functools.cached_property
    def g(self) -> ca.SX:
        """The constraints as one SX column of ``x`` (built on first use: with blocks, a solve needs only the rows
        in no block, `ConstraintList.rows`)."""
        return self.constraints.stacked()[0]

    def violation(self, x: np.ndarray) -> float:
        """The largest amount by which the decision vector ``x`` lies outside its bounds or a constraint row outside
        its bounds (in the row's own units: m, rad, rad/s; 0 for a feasible point). The rows are the solver's own
        values function (`functions`, interpreted), not a graph built here."""
        x = np.asarray(x, float)
        g = np.asarray(self.functions("none")[1](x), float).ravel()
        over = [self.lbx - x, x - self.ubx, self.lbg - g, g - self.ubg]
        return float(max(0.0, *(np.max(v, initial=0.0) for v in over)))

    @staticmethod
    def _level(block: BlockStructure, compile_mode: str) -> str:
        """The compile mode of a block's functions under the profile's ``compile_mode`` (`compiled.level`)."""
        return level(compile_mode, len(block.y_index))

    def _used(self, compile_mode: str) -> list:
        """Where the block functions built under ``compile_mode`` note the tiered libraries they load."""
        return self._tiered.setdefault(compile_mode, [])

    def tiered_libraries(self, compile_mode: str) -> tuple:
        """This NLP's tiered block functions under ``compile_mode``: the compile cache's -O0 libraries that tier up
        to -O1 once solved with long enough (`designopt.transcriptions.compiled.record_work`), and the markers of
        blocks interpreted while their -O0 library is built (`compiled.interpreted_at`); empty once all are at
        -O1, or for any mode but ``auto``."""
        return tuple(dict.fromkeys(self._tiered.get(compile_mode, ())))

    def _inputs(self, block: BlockStructure) -> list:
        """A block's constant inputs, one column per point (the problem's `waypoint_inputs` unless it has its own)."""
        return list(waypoint_inputs(self.problem) if block.inputs is None else block.inputs)

    def hessian(self, compile_mode: str):
        """hess_lag(x, p, lam_f, lam_g) from the per-point blocks (each block function compiled per
        ``compile_mode``: `designopt.transcriptions.compiled`), or None when the NLP has no block structure."""
        if self.blocks is None:
            return None
        if compile_mode not in self._hessians:
            groups = [(block_hessian_function(b.terms, b.y_index.shape[1], b.mu_index.shape[1],
                                              self._level(b, compile_mode), self._used(compile_mode)),
                       b.y_index, self._inputs(b), b.mu_index) for b in self.blocks]
            self._hessians[compile_mode] = assemble_hessian(self.n_variables, self.n_constraints, groups,
                                                            self._constant_hessian)
        return self._hessians[compile_mode]

    def jacobian(self, compile_mode: str, values: bool = True):
        """jac_g(x, p) -> (g, dg/dx) with the per-point blocks' rows from their (compiled) block Jacobians
        (`designopt.transcriptions.jacobian`), or None when the NLP has no block structure. ``values`` False: g is
        not computed (NaN; what IPOPT is given, `jacobian.not_computed`); True: that function with g added."""
        if self.blocks is None:
            return None
        if (compile_mode, values) not in self._jacobians:
            if values:
                jacobian = _with_value(self.jacobian(compile_mode, False), self.functions(compile_mode)[1])
            else:
                groups = [(*block_jacobian_function(b.terms, self._level(b, compile_mode), self._used(compile_mode)),
                           b.y_index, self._inputs(b), b.mu_index)
                          for b in self.blocks]
                jacobian = assemble_jacobian(self.x, self.n_constraints, self.constraints.rows, None, groups,
                                             self.constraints.constant_jacobian)
            self._jacobians[compile_mode, values] = jacobian
        return self._jacobians[compile_mode, values]

    def functions(self, compile_mode: str) -> tuple[ca.Function, ca.Function]:
        """(x -> f, x -> g), shared by the oracle, grad_f and jac_g. With blocks, both are assembled from the
        blocks' own terms (each compiled per ``compile_mode``), mapped over their points, plus the quadratic terms
        (compiled alike) and the constraint rows in no block (`assemble_values`): CasADi's virtual machine
        interpreting the whole SX graph instead was a fifth of a cell problem's iteration. Without blocks, SX
        functions of f and g."""
        if compile_mode not in self._values:
            if self.blocks is None:
                self._values[compile_mode] = (ca.Function("nlp_f", [self.x], [self.f]),
                                              ca.Function("nlp_g", [self.x], [self.g]))
            else:
                groups = [(*compiled_split_terms(b.terms, self._level(b, compile_mode), self._used(compile_mode)),
                           b.y_index, self._inputs(b), b.mu_index) for b in self.blocks]
                self._values[compile_mode] = assemble_values(
                    self.x, self.n_constraints, self.constraints.rows, groups,
                    compiled_terms(self.quadratic, compile_mode, self._used(compile_mode)))
        return self._values[compile_mode]

    def gradient(self, compile_mode: str, values: bool = True):
        """grad_f(x, p) -> (f, df/dx): the blocks' dphi/dy scattered, plus the gradient of the quadratic terms
        (`designopt.transcriptions.jacobian.assemble_gradient`; a reverse sweep of the whole objective cost 0.13 s
        of the main job's 0.35 s build), or None when the NLP has no block structure. ``values`` False: f is not
        computed (NaN; what IPOPT is given, `jacobian.not_computed`); True: that function with f added."""
        if self.blocks is None:
            return None
        if (compile_mode, values) not in self._gradients:
            if values:
                gradient = _with_value(self.gradient(compile_mode, False), self.functions(compile_mode)[0])
            else:
                groups = [(block_gradient_function(b.terms, self._level(b, compile_mode), self._used(compile_mode)),
                           b.y_index, self._inputs(b)) for b in self.blocks]
                quadratic = gradient_groups(self.quadratic, compile_mode, self._used(compile_mode))
                gradient = assemble_gradient(self.n_variables, None, groups + quadratic)
            self._gradients[compile_mode, values] = gradient
        return self._gradients[compile_mode, values]

    @functools.cached_property
    def _constant_hessian(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The quadratic terms' Hessian as triplets (`designopt.transcriptions.quadratic.constant_hessian`), shared
        by the hess_lag of every compile mode."""
        return constant_hessian(self.quadratic)

    def _oracle(self, compile_mode: str) -> dict:
        """The NLP for nlpsol as calls of `functions`."""
        X = ca.MX.sym("x", self.n_variables)
        f_of, g_of = self.functions(compile_mode)
        return {"x": X, "f": f_of(X), "g": g_of(X)}

    def derivatives(self, compile_mode: str) -> tuple[dict, dict]:
        """(the NLP for nlpsol, the derivative functions for its options): with blocks, hess_lag, jac_g and
        grad_f are given and the NLP is f and g assembled from the blocks (`functions`), so that nlpsol derives
        nothing itself (it otherwise spends seconds on the SX graph of a cell problem: 6.5 s of the pocket cell's
        7.3 s build, benchmarks/speed_table.py); jac_g and grad_f without their values, which IPOPT never reads
        (`jacobian.not_computed`); without blocks the SX NLP, for nlpsol to differentiate. Every piece is built once
        per NLP and compile mode and shared by the solvers of all its profiles."""
        if self.blocks is None:
            return {"x": self.x, "f": self.f, "g": self.g}, {}
        with built_together() as batch:  # the blocks the cache lacks are compiled together, on leaving
            pieces = self._pieces(compile_mode)
        if batch.here:  # made with interpreted stand-ins for them: made again, they load the new libraries
            self._forget(compile_mode)
            pieces = self._pieces(compile_mode)
        return pieces

    def _pieces(self, compile_mode: str) -> tuple[dict, dict]:
        return self._oracle(compile_mode), {"hess_lag": self.hessian(compile_mode),
                                            "jac_g": self.jacobian(compile_mode, values=False),
                                            "grad_f": self.gradient(compile_mode, values=False)}

    def _forget(self, compile_mode: str) -> None:
        """Drop the functions built under ``compile_mode`` (they are built again on next use)."""
        for memo in (self._hessians, self._values):
            memo.pop(compile_mode, None)
        for memo in (self._jacobians, self._gradients):
            for values in (False, True):
                memo.pop((compile_mode, values), None)


def _with_value(derivative: ca.Function, value_of: ca.Function) -> ca.Function:
    """A gradient or Jacobian (x, p) -> (NaN, derivative) as (x, p) -> (value, derivative), ``value_of``: x -> the
    value: the blocks' derivatives derived once for both."""
    X, P = (ca.MX.sym(derivative.name_in(i), derivative.sparsity_in(i)) for i in range(2))
    return ca.Function(derivative.name(), [X, P], [value_of(X), derivative(X, P)[1]], derivative.name_in(),
                       derivative.name_out())


def split_terms(terms: ca.Function) -> tuple[ca.Function | None, ca.Function | None]:
    """A block's (y, *inputs) -> (phi, c) as two functions, (y, *inputs) -> phi and (y, *inputs) -> c, so that
    evaluating f does not evaluate c nor g phi; None for an output that is structurally zero (a clearance block's
    phi) or empty."""
    y, params = block_symbols(terms)
    phi, c = terms(y, *params)
    return (None if phi.is_zero() else ca.Function(f"{terms.name()}_phi", [y, *params], [phi]),
            ca.Function(f"{terms.name()}_c", [y, *params], [c]) if c.numel() else None)


def compiled_split_terms(terms: ca.Function, compile_mode: str,
                         used: list | None = None) -> tuple[ca.Function | None, ca.Function | None]:
    """`split_terms` compiled per ``compile_mode``, each found in the cache by ``terms`` and the split (not by its
    own serialised graph, which a warm build would otherwise serialise again); ``used``:
    `designopt.transcriptions.compiled.compiled_as`."""
    return tuple(None if fn is None else compiled_as(fn.name(), derivation_identity(terms, split_terms, part),
                                                     lambda fn=fn: fn, compile_mode, used)
                 for part, fn in enumerate(split_terms(terms)))


def assemble_values(x, n_g: int, g_rows: Callable[[np.ndarray], ca.SX],
                    groups: list[tuple[ca.Function | None, ca.Function | None, np.ndarray, list, np.ndarray]],
                    quadratic: tuple[QuadraticTerm, ...]) -> tuple[ca.Function, ca.Function]:
    """(x -> f, x -> g) of an NLP whose nonlinear terms sit in per-point blocks, as MX functions.

    ``x``: the NLP's SX decision vector; ``n_g`` its number of constraints and ``g_rows`` (row indices -> SX) their
    own expressions, of which only the rows in no block are asked for (small ones, e.g. the collocation's). Each
    group is (phi, c, y_index, block_inputs, mu_index): a block's (y, *inputs) -> phi and (y, *inputs) -> c
    (`split_terms`; None: none), ``y_index`` (N x n_y) the position in x of each block variable, ``block_inputs``
    its constant extra inputs (mapped) and ``mu_index`` (N x n_c) the position in g of each row of c. f = the
    blocks' phi summed over their points + the ``quadratic`` terms; every row of g comes from exactly one block
    or from ``g_rows``.
    """
    n_x = x.shape[0]
    X = ca.MX.sym("x", n_x)
    f, values, rows = total(quadratic, X), [], []
    for phi, c, y_index, block_inputs, mu_index in groups:
        at = per_point(X, y_index)
        if phi is not None:
            f += ca.sum2(phi.map(y_index.shape[0])(at, *block_inputs))
        if c is not None and mu_index.size:
            values.append(ca.vec(c.map(y_index.shape[0])(at, *block_inputs)))  # point by point, as mu_index
            rows.append(mu_index.ravel())
    rest = unclaimed_rows(n_g, rows)
    if rest.size:
        values.append(ca.Function("g_rest", [x], [g_rows(rest)])(X))
        rows.append(rest)
    position = np.empty(n_g, dtype=int)
    position[np.concatenate([*rows, np.zeros(0, int)])] = np.arange(n_g)
    G = ca.vertcat(*values)[position.tolist()] if n_g else ca.MX(0, 1)
    return ca.Function("nlp_f", [X], [f]), ca.Function("nlp_g", [X], [G])


def y_indices(n_d: int, n_m: int, N: int, stride: int) -> np.ndarray:
    """x-indices of y_k = (q_k, q_d) when x = (q_d, z_0, ..., z_{N-1}) with q_k first in each z_k."""
    q_index = n_d + np.arange(N)[:, None] * stride + np.arange(n_m)[None, :]
    return np.hstack([q_index, np.tile(np.arange(n_d), (N, 1))])


def waypoint_inputs(problem: DesignProblem):
    """The constant inputs of `waypoint_terms`, one column per waypoint: the path's s_W (3 x N), f_W (3 x N) and
    (w_k, tracked_k) (2 x N: quadrature weight, whether the tool must follow the path there), then the model's
    `model_inputs`, the same in every column."""
    toolpath = problem.toolpath
    k_w = np.vstack([toolpath.weights, toolpath.is_tracked.astype(float)])
    model = [ca.DM(np.tile(np.asarray(v, dtype=float)[:, None], (1, toolpath.n))) for v in model_inputs(problem)]
    return ca.DM(toolpath.points_W.T), ca.DM(toolpath.force_W.T), ca.DM(k_w), *model


def model_inputs(problem: DesignProblem) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What `waypoint_terms` takes as inputs rather than constants, so that its compiled blocks serve every
    stiffness model, deflection mode and weighting of the same robot and path: K^-1 of the moving joints
    (rad/(N*m) or m/N), the weight of each `WaypointCost` and each non-quadratic `DesignCost`, and the weights of
    the deflection's six rows (`costs.deflection_rows`)."""
    weights = np.array([cost.weight for cost in weighted_terms(problem)], dtype=float)
    return problem.k_inv, weights, deflection_rows(problem.deflection)


def weighted_terms(problem: DesignProblem) -> tuple[WaypointCost | DesignCost, ...]:
    """The terms `waypoint_terms` carries, in the order of its ``weights`` input: every `WaypointCost`, then every
    non-quadratic `DesignCost` (spread over the waypoints; the quadratic ones have a constant Hessian of their own)."""
    return (*problem.waypoint_costs, *(cost for cost in problem.design_costs if not cost.quadratic))


def free_untracked(problem: DesignProblem, lo: np.ndarray, hi: np.ndarray, rows: np.ndarray):
    """Bounds (n_c x N) of the per-waypoint constraints with the tracking ``rows`` freed at untracked
    waypoints (rapids): the rows stay in the NLP, so its shape and Hessian pattern do not depend on the path."""
    lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
    free = ~problem.toolpath.is_tracked
    lo[np.ix_(rows, free)], hi[np.ix_(rows, free)] = -np.inf, np.inf
    return lo, hi


TRACKING_ACTIVATIONS = ("hard", "soft", "epsilon")


def tracking(w, s_W, activation: str, weight_h: float, position: bool = True, epsilon: float = 0.0):
    """The tracking residual r = (p_W - s_W, z_W - z*) at one waypoint under an activation.

    ``hard``: r = 0 as equalities (the axis held as z_W = (0, 0, <= 0), whose sign excludes z = -z*);
    ``soft``: weight_h * |r|^2 in the objective (the paper); ``epsilon``: |r|^2 <= epsilon (the FK baseline).
    ``position`` False leaves the position out (differential kinematics tracks it as a state).
    Returns (objective part, constraints, lower bounds, upper bounds).
    """
    r_p, r_z = tracking_residual(w)
    if activation == "epsilon":
        return 0, [ca.sumsqr(r_p) + ca.sumsqr(r_z)], [-np.inf], [epsilon]
    if activation == "soft":
        return weight_h * (ca.sumsqr(r_z) + (ca.sumsqr(r_p) if position else 0)), [], [], []
    if activation != "hard":
        raise ValueError(f"tracking must be one of {TRACKING_ACTIVATIONS}, got {activation!r}")
    c, lo, hi = ([r_p], [0.0] * 3, [0.0] * 3) if position else ([], [], [])
    return 0, [*c, w.z_W], [*lo, 0.0, 0.0, -np.inf], [*hi, 0.0, 0.0, 0.0]


def waypoint_terms(problem: DesignProblem, activation: str, position_in_terms: bool = True, epsilon: float = 0.0):
    """Cost phi_k and constraints c_k at one waypoint as a function of y_k = (q_k, q_d).

    phi_k holds every `WaypointCost` (w_k * weight * fn), every non-quadratic `DesignCost` spread evenly over
    the waypoints (so that the per-waypoint blocks, and with them the exact structured Hessian, carry it) and,
    when soft, the tracking penalty (zero where the waypoint is not tracked). Returns the CasADi function
    (y, s_W, f_W, k_w, k_inv, weights, rows) -> (phi, c), with k_w = (w_k, tracked_k) and the model's constants
    (`waypoint_inputs`, `model_inputs`), and the bounds of c. Its first `tracking_rows` rows are the tracking
    constraints. The position enters only when p = FK(q); in differential mode it is a state. With the model's
    constants as inputs the block's values are those of the same terms with them as numbers, to the bit (a product
    by 1 or a sum with 0 is exact), and its compiled blocks are shared by every model of one robot and path.
    """
    chain, tp = problem.chain, problem.toolpath
    n_m, n_d = chain.n_moving, chain.n_design
    y = ca.SX.sym("y", n_m + n_d)
    s_W, f_W, k_w = ca.SX.sym("s_W", 3), ca.SX.sym("f_W", 3), ca.SX.sym("k_w", 2)
    k_inv, rows = ca.SX.sym("k_inv", n_m), ca.SX.sym("rows", 6)
    terms = weighted_terms(problem)
    weights = ca.SX.sym("weights", len(terms))
    h, tracked = k_w[0], k_w[1]
    w = waypoint(chain, y[:n_m], y[n_m:], s_W, f_W, k_inv, rows)
    phi = 0
    for i, cost in enumerate(terms):
        if isinstance(cost, WaypointCost):
            phi += h * weights[i] * cost.fn(w)
        else:
            phi += weights[i] * cost.fn(chain, y[n_m:]) / tp.n
    penalty, c, lo, hi = tracking(w, s_W, activation, h * problem.tracking_weight, position_in_terms, epsilon)
    phi += tracked * penalty if activation == "soft" and not tp.is_tracked.all() else penalty
    if problem.keep_out_radius > 0:
        s_B = w.T_BW[:3, :3] @ s_W + w.T_BW[:3, 3]
        c.append(s_B[0] ** 2 + s_B[1] ** 2)
        lo.append(problem.keep_out_radius**2)
        hi.append(np.inf)
    fn = ca.Function("terms", [y, s_W, f_W, k_w, k_inv, weights, rows], [phi, ca.vertcat(*c) if c else ca.SX(0, 1)],
                     ["y", "s_W", "f_W", "k_w", "k_inv", "weights", "rows"], ["phi", "c"])
    return fn, np.array(lo), np.array(hi)


def tracking_rows(problem: DesignProblem, activation: str, position_in_terms: bool = True) -> np.ndarray:
    """Indices of the tracking constraints among the rows of `waypoint_terms`' c."""
    if activation == "epsilon":
        return np.array([0])
    if activation == "soft":
        return np.zeros(0, dtype=int)
    return np.arange(6 if position_in_terms else 3)


def clearance_terms(problem: DesignProblem) -> ca.Function:
    """y = (q, q_d) -> (phi = 0, c >= 0): the cell's clearance constraints at one configuration
    (`designopt.clearance`), shaped like `waypoint_terms` so that the structured Hessian covers them."""
    from designopt.clearance import constraint_terms

    chain = problem.chain
    y = ca.SX.sym("y", chain.n_moving + chain.n_design)
    c = ca.vertcat(*constraint_terms(chain, problem.cell, y[: chain.n_moving], y[chain.n_moving :]))
    return ca.Function("clearance", [y], [ca.SX(0), c], ["y"], ["phi", "c"])


def floor_terms(problem: DesignProblem) -> ca.Function:
    """q_d -> (phi = 0, c >= 0): the block stands on or above the floor (`designopt.clearance`)."""
    from designopt.clearance import block_above_floor

    q_d = ca.SX.sym("q_d", problem.chain.n_design)
    c = ca.vertcat(*block_above_floor(problem.chain, problem.cell, q_d))
    return ca.Function("block_floor", [q_d], [ca.SX(0), c], ["y"], ["phi", "c"])


def once_only_rows(problem: DesignProblem, tracking: str) -> np.ndarray:
    """Rows of c_k that need holding at one waypoint only: the tracking rows that do not depend on the moving
    joints (`designopt.transcriptions.degeneracy.q_independent_rows`).

    When no moving joint turns the tool (a PPP gantry, or a DH arm whose twists are held at 0 or pi), the
    tool-axis equalities are the same function of the design joints at every waypoint: 2N equations of rank 2,
    which breaks IPOPT's constraint qualification (measured: PPP stalled at max_iter). They are then imposed once.
    """
    if tracking != "hard":
        return np.zeros(0, dtype=int)
    return q_independent_rows(problem)
