"""Probe for issue 24: do link frames as variables ("lifted" forward kinematics) change the inertia corrections?

The inertia corrections come from the tracking rows' curvature times their multipliers, coupled through the link
lengths every waypoint shares (docs/decisions.md, 2026-11-23). Lifting makes each link frame at each waypoint a
variable F_j (its rotation and origin, 12 numbers) tied to the one before it by F_j = F_{j-1} A_j(q, q_d): every
row is then bilinear in a frame and one link's transform, instead of a product of the whole chain. The same
problem, the same optimum: at a KKT point the reduced Hessian is the same (second-order conditions do not change
when equalities define new variables), but the iterates on the way there, and with them IPOPT's corrections, may.

Both forms here are plain CasADi graphs with CasADi's own exact Hessian (``Collocation(hessian="auto")`` for the
direct one; the lifted one is the same NLP with each waypoint's terms rebuilt while `designopt.kinematics.chain`'s
walk lifts every run of transforms that depends on a variable), solved by IPOPT with MUMPS from the same seeded
starts (the lifted frames started at their values there), with the exploration's options: nothing else differs.
Prints per start: status, iterations, the share of inertia-corrected iterations, ms per iteration, and the design
cost reached (evaluated on the joints and design joints alone, as every solution is). A probe, not a lever:
nothing in designopt uses it.

    .venv/bin/python benchmarks/lifted_probe.py configs/milling.yaml --waypoints 10 --starts 24 --first-start 100
    .venv/bin/python benchmarks/lifted_probe.py configs/milling.yaml --waypoints 0 --starts 4 --max-iter 1000
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import casadi as ca  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402
from iteration_split import corrected_share  # noqa: E402

import designopt.kinematics.chain as chain_module  # noqa: E402
from designopt.config import load_config  # noqa: E402
from designopt.evaluation import evaluate  # noqa: E402
from designopt.experiments.adapters import search_from_config  # noqa: E402
from designopt.initial_guess import initial_guess  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solve.backends import ipopt as ipopt_backend  # noqa: E402
from designopt.solve.profile import SolverProfile  # noqa: E402
from designopt.solve.strategies.coarse_to_fine import coarse_problem  # noqa: E402
from designopt.transcriptions import Collocation  # noqa: E402
from designopt.transcriptions.nlp import tracking, waypoint_inputs, y_indices  # noqa: E402
from designopt.transcriptions.quadratic import total  # noqa: E402

PlainWalk = chain_module.Walk


class Lifting:
    """The frames lifted while building one waypoint's terms: (symbols, their definitions), one 12-vector each
    (rotation column-major, then origin). A product met twice (the pose and the Jacobian walk the chain
    separately) is lifted once."""

    def __init__(self):
        self.symbols, self.definitions, self._seen = [], [], {}

    def lift(self, M):
        if not isinstance(M, ca.SX) or not ca.symvar(M):
            return M
        key = str(M)
        if key not in self._seen:
            L = ca.SX.sym(f"F{len(self.symbols)}", 12)
            self.symbols.append(L)
            self.definitions.append(ca.vertcat(ca.vec(M[:3, :3]), M[:3, 3]))
            self._seen[key] = ca.vertcat(ca.horzcat(ca.reshape(L[:9], 3, 3), L[9:]), ca.DM([[0, 0, 0, 1]]))
        return self._seen[key]


def lifted_walk(lifting: Lifting):
    """A `Walk` whose frame after every run of transforms is a lifted variable."""

    class LiftedWalk(PlainWalk):
        def __init__(self, ets, values):
            self.ets, self.values = ets, values
            self._start, self._at, previous = {}, {}, None
            for a, b, fn in chain_module._segments(ets):
                M = (fn(*[values[e.joint] for e in ets[a:b]]) if fn
                     else chain_module.et_matrix(ets[a], values[ets[a].joint]))
                previous = lifting.lift(M if previous is None else previous @ M)
                self._at[b] = previous
                self._start.update(dict.fromkeys(range(a, b), a))
            self._at[0] = chain_module._identity(previous)

    return LiftedWalk


def lifted_terms(problem):
    """(y, L, s_W, f_W, k_w) -> (phi, c, L - D(y, L)): `nlp.waypoint_terms` of hard tracking with the frames lifted,
    and the residual of the lifting's definitions; also the number of lifted entries. A copy of that function's
    body: its terms take the lifted frames as an input, which the library's cannot (no free symbols in a Function)."""
    chain, tp = problem.chain, problem.toolpath
    n_m, n_d = chain.n_moving, chain.n_design
    y = ca.SX.sym("y", n_m + n_d)
    s_W, f_W, k_w = ca.SX.sym("s_W", 3), ca.SX.sym("f_W", 3), ca.SX.sym("k_w", 2)
    lifting = Lifting()
    chain_module.Walk = lifted_walk(lifting)
    try:
        w = problem.waypoint(y[:n_m], y[n_m:], s_W, f_W)
    finally:
        chain_module.Walk = PlainWalk
    phi = 0
    for cost in problem.waypoint_costs:
        phi += k_w[0] * cost.weight * cost.fn(w)
    for cost in problem.design_costs:
        if not cost.quadratic:
            phi += cost(chain, y[n_m:]) / tp.n
    # the rows in the library's order; their bounds are the direct NLP's (`LiftedNLP`)
    _, c, _, _ = tracking(w, s_W, "hard", k_w[0] * problem.tracking_weight, True, 0.0)
    if problem.keep_out_radius > 0:
        s_B = w.T_BW[:3, :3] @ s_W + w.T_BW[:3, 3]
        c.append(s_B[0] ** 2 + s_B[1] ** 2)
    L, D = ca.vertcat(*lifting.symbols), ca.vertcat(*lifting.definitions)
    fn = ca.Function("lifted_terms", [y, L, s_W, f_W, k_w], [phi, ca.vertcat(*c), L - D])
    return fn, L.shape[0]


class LiftedNLP:
    """The direct NLP's decision vector followed by every waypoint's lifted frames; its tracking rows rebuilt on
    the frames, the lifting's definitions as equalities, its other rows (the midpoints' bounds) as they were."""

    def __init__(self, problem, direct):
        chain, tp = problem.chain, problem.toolpath
        n_m, n_d, N = chain.n_moving, chain.n_design, tp.n
        terms, self.n_lift = lifted_terms(problem)
        nlp = direct.nlp
        x_direct = nlp.x
        Lall = ca.SX.sym("L", self.n_lift, N)
        self.x = ca.vertcat(x_direct, ca.vec(Lall))
        self.y_index = y_indices(n_d, n_m, N, direct.n_state)  # x-indices of y_k = (q_k, q_d), one row a waypoint
        Y = ca.horzcat(*[x_direct[list(row)] for row in self.y_index])
        phi, C, R = terms.map(N)(Y, Lall, *waypoint_inputs(problem)[:3])
        self.f = ca.sum2(phi) + total(nlp.quadratic, x_direct)
        n_c = C.shape[0]
        rest = nlp.g[n_c * N :]
        self.g = ca.vertcat(ca.vec(C), ca.vec(R), rest)
        # the tracking rows' bounds as the direct NLP has them (rows held once, untracked waypoints freed)
        self.lbg = np.concatenate([nlp.lbg[: n_c * N], np.zeros(self.n_lift * N), nlp.lbg[n_c * N :]])
        self.ubg = np.concatenate([nlp.ubg[: n_c * N], np.zeros(self.n_lift * N), nlp.ubg[n_c * N :]])
        self.lbx = np.concatenate([nlp.lbx, -np.inf * np.ones(self.n_lift * N)])
        self.ubx = np.concatenate([nlp.ubx, np.inf * np.ones(self.n_lift * N)])
        self.N = N
        # the frames at a direct point: the definitions iterated to their fixed point (each frame depends on the
        # one before it, so as many passes as frames)
        y = ca.SX.sym("y", n_m + n_d)
        L = ca.SX.sym("L", self.n_lift)
        residual = terms(y, L, ca.DM.zeros(3), ca.DM.zeros(3), ca.DM.ones(2))[2]
        self._define = ca.Function("define", [y, L], [L - residual])
        self.n_c = n_c

    def lift(self, x0: np.ndarray) -> np.ndarray:
        """The decision vector of a direct point ``x0``, its frames at their values there."""
        frames = []
        for row in self.y_index:
            L = np.zeros(self.n_lift)
            for _ in range(self.n_lift // 12 + 1):
                L = np.asarray(self._define(x0[row], L)).ravel()
            frames.append(L)
        return np.concatenate([x0, np.concatenate(frames)])


class Form:
    """One form's IPOPT solver, built once with the exploration's options (MUMPS, cold, capped) and the ``extra``
    ones; IPOPT appends every solve's log to one file, and each solve reads its own part (as `iteration_split`)."""

    def __init__(self, nlp, max_iter: int, log: Path, extra: dict):
        self.nlp, self.log = nlp, log
        opts = ipopt_backend.options(SolverProfile(max_iter=max_iter, linear_solver="mumps"), nlp.x.shape[0]) | extra
        opts |= {"ipopt.output_file": str(log), "ipopt.file_print_level": 5, "ipopt.print_level": 0}
        self.solver = ca.nlpsol("probe", "ipopt", {"x": nlp.x, "f": nlp.f, "g": nlp.g}, opts)

    def solve(self, x0: np.ndarray):
        """(x, status, iterations, CPU seconds, share of inertia-corrected iterations) of a solve from ``x0``."""
        nlp, before = self.nlp, self.log.stat().st_size if self.log.exists() else 0
        cpu = time.process_time()
        sol = self.solver(x0=x0, lbx=nlp.lbx, ubx=nlp.ubx, lbg=nlp.lbg, ubg=nlp.ubg)
        seconds = time.process_time() - cpu
        with open(self.log, "rb") as fh:
            fh.seek(before)
            corrected, counted = corrected_share(fh.read().decode(errors="replace"))
        stats = self.solver.stats()
        return (np.asarray(sol["x"]).ravel(), stats["return_status"], stats["iter_count"], seconds,
                corrected / max(counted, 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("--waypoints", type=int, default=10, help="N of the path's waypoints (0: all)")
    parser.add_argument("--starts", type=int, default=8)
    parser.add_argument("--first-start", type=int, default=0)
    parser.add_argument("--max-iter", type=int, default=250)
    parser.add_argument("--option", action="append", default=[],
                        help="ipopt.NAME=VALUE for both forms' solves, e.g. ipopt.constr_mult_init_max=0")
    args = parser.parse_args()
    extra = {k: yaml.safe_load(v) for k, v in (o.split("=", 1) for o in args.option)}
    cfg = load_config(args.config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    if args.waypoints:
        problem = coarse_problem(problem, args.waypoints)
    direct = Collocation(hessian="auto").build(problem)
    nlp = direct.nlp
    lifted = LiftedNLP(problem, direct)
    print(f"{args.config}, {problem.toolpath.n} waypoints: direct {nlp.n_variables} variables / {nlp.n_constraints} "
          f"rows; lifted {lifted.x.shape[0]} / {lifted.g.shape[0]} ({lifted.n_lift} frame entries a waypoint)")
    # the same NLP: at a start with its frames lifted, the objective and the rows agree
    f_direct = ca.Function("fd", [nlp.x], [nlp.f, nlp.g])
    f_lifted = ca.Function("fl", [lifted.x], [lifted.f, lifted.g])
    rows = {"direct": [], "lifted": []}
    with tempfile.TemporaryDirectory() as tmp:
        forms = {name: Form(form, args.max_iter, Path(tmp) / f"{name}.log", extra)
                 for name, form in (("direct", nlp), ("lifted", lifted))}
        for start in range(args.first_start, args.first_start + args.starts):
            guess = initial_guess(problem, start, search.seed, search.perturbation, search.init)
            x0 = direct.pack(guess)
            xl0 = lifted.lift(x0)
            fd, gd = (np.asarray(v).ravel() for v in f_direct(x0))
            fl, gl = (np.asarray(v).ravel() for v in f_lifted(xl0))
            n = lifted.n_c * lifted.N
            definitions = gl[n : n + lifted.n_lift * lifted.N]
            other = np.concatenate([gl[:n], gl[n + lifted.n_lift * lifted.N :]])
            if not (np.isclose(fd[0], fl[0], rtol=1e-9, atol=1e-15) and np.allclose(gd, other, atol=1e-9)
                    and np.abs(definitions).max() < 1e-9):
                raise SystemExit(f"start {start}: the lifted NLP differs from the direct one at the start "
                                 f"(f {fd[0]:.6e} vs {fl[0]:.6e}, rows {np.abs(gd - other).max():.1e}, "
                                 f"definitions {np.abs(definitions).max():.1e})")
            for name, start_x in (("direct", x0), ("lifted", xl0)):
                x_end, status, iterations, seconds, corrected = forms[name].solve(start_x)
                q_d, trajectory, _ = direct.unpack(x_end[: nlp.n_variables])
                metrics = evaluate(problem, q_d, trajectory)
                rows[name].append((start, status, iterations, corrected, 1e3 * seconds / max(iterations, 1),
                                   metrics.design_cost, metrics.tracks))
                print(f"{name} start {start} | {status} | {iterations} iterations | {corrected:.0%} corrected | "
                      f"{1e3 * seconds / max(iterations, 1):.2f} ms/iter | design cost {metrics.design_cost:.4e} | "
                      f"tracks {metrics.tracks}", flush=True)
    print("form | converged (+ acceptable) | at the cap | median iterations | median corrected | median ms/iter | "
          "median s/solve | median design cost (tracking starts) | best")
    for name, rs in rows.items():
        ok = sum(r[1] == "Solve_Succeeded" for r in rs)
        acceptable = sum(r[1] == "Solved_To_Acceptable_Level" for r in rs)
        capped = sum(r[1] == "Maximum_Iterations_Exceeded" for r in rs)
        costs = [r[5] for r in rs if r[6]] or [float("nan")]
        print(f"{name} | {ok} (+ {acceptable}) of {len(rs)} | {capped} | {statistics.median(r[2] for r in rs):.0f} | "
              f"{statistics.median(r[3] for r in rs):.0%} | {statistics.median(r[4] for r in rs):.2f} | "
              f"{statistics.median(r[2] * r[4] / 1e3 for r in rs):.2f} | {statistics.median(costs):.4e} | "
              f"{min(costs):.4e}")
    print(f"the two forms agree at each of the {args.starts} starts (objective to 1e-9, rows and the frames' "
          f"definitions to 1e-9)")
    pairs = [(a[5], b[5]) for a, b in zip(rows["direct"], rows["lifted"], strict=True) if a[6] and b[6]]
    same = sum(1 for a, b in pairs if abs(a - b) <= 0.02 * min(a, b))
    print(f"both tracking: {len(pairs)} starts; the same design cost within 2 %: {same}; lifted lower by > 2 %: "
          f"{sum(1 for a, b in pairs if b < 0.98 * a)}; higher: {sum(1 for a, b in pairs if b > 1.02 * a)}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
