"""Probe for issue 24: does a Gauss-Newton Hessian of the deformation term remove the inertia corrections?

L_d = h w |r(y)|^2 with r = C(q) w the deflection. The exact Hessian 2 h w (J_r^T J_r + sum r_i d2r_i) is
indefinite away from r = 0; Gauss-Newton keeps 2 h w J_r^T J_r (positive semidefinite) and the exact curvature of
the constraints. This script swaps the per-waypoint Hessian block for that one (the rest of the Lagrangian
exact) and solves the same seeded starts both ways, printing iterations, ms per iteration, the share of
inertia-corrected iterations and the design cost reached. A probe, not a lever: nothing in designopt uses it.

    .venv/bin/python benchmarks/gauss_newton_probe.py configs/milling.yaml --starts 8
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import tempfile
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import casadi as ca  # noqa: E402
from iteration_split import logged_solve  # noqa: E402

import designopt.transcriptions.nlp as nlp_module  # noqa: E402
from designopt.config import load_config  # noqa: E402
from designopt.costs import deflection, waypoint  # noqa: E402
from designopt.evaluation import evaluate  # noqa: E402
from designopt.experiments.adapters import search_from_config  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solve import local  # noqa: E402
from designopt.transcriptions.compiled import compiled  # noqa: E402

EXACT = nlp_module.block_hessian_function


def gauss_newton_blocks(problem):
    """A block_hessian_function whose deformation part is 2 h w J_r^T J_r (the tracking waypoint blocks only)."""
    n_m, n_d = problem.chain.n_moving, problem.chain.n_design
    index = [i for i, c in enumerate(problem.waypoint_costs) if c.name == "deformation"][0]

    def block(terms, n_y, n_c, compile_mode, used=None):
        if terms.name() != "terms" or n_y != n_m + n_d:
            return EXACT(terms, n_y, n_c, compile_mode, used)
        y, sigma, mu = ca.SX.sym("y", n_y), ca.SX.sym("sigma"), ca.SX.sym("mu", n_c)
        params = [ca.SX.sym(terms.name_in(i), terms.sparsity_in(i)) for i in range(1, terms.n_in())]
        s_W, f_W, k_w, k_inv, weights, rows = params  # `nlp.waypoint_terms`' inputs
        phi, c = terms(y, *params)
        w = waypoint(problem.chain, y[:n_m], y[n_m:], s_W, f_W, k_inv, rows)
        r = rows * deflection(w.J, k_inv, w.force)
        weight = weights[index]
        phi_def = k_w[0] * weight * ca.sumsqr(r)
        exact_rest = ca.hessian(sigma * (phi - phi_def) + (ca.dot(mu, c) if n_c else 0), y)[0]
        J_r = ca.jacobian(r, y)
        H = exact_rest + sigma * 2 * k_w[0] * weight * (J_r.T @ J_r)
        upper = ca.vertcat(*[H[a, b] for a in range(n_y) for b in range(a, n_y)])
        return compiled(ca.Function("waypoint_hessian_gn", [y, sigma, mu, *params], [upper]), compile_mode)

    return block


def run(problem, search, starts, tmp, label):
    rows = []
    for start in range(starts):
        built, _, outcome, total, corrected, _ = logged_solve(problem, search, start, Path(tmp) / f"{label}{start}.log")
        q_d, trajectory, _ = built.unpack(outcome.x)
        metrics = evaluate(problem, q_d, trajectory)
        rows.append((outcome.status, outcome.iterations, 1e3 * total / max(outcome.iterations, 1), corrected,
                     metrics.design_cost, metrics.tracks))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("--starts", type=int, default=8)
    args = parser.parse_args()
    cfg = load_config(args.config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    with tempfile.TemporaryDirectory() as tmp:
        exact = run(problem, search, args.starts, tmp, "exact")
        nlp_module.block_hessian_function = gauss_newton_blocks(problem)
        local._built.cache_clear()  # rebuild the NLP (its Hessian is cached with it) and its solvers
        local._prepared.cache_clear()
        gn = run(problem, search, args.starts, tmp, "gn")
    print("start | exact: status, iterations, ms/iter, corrected, cost | Gauss-Newton: same")
    for k, (e, g) in enumerate(zip(exact, gn, strict=True)):
        print(f"{k} | {e[0]} {e[1]} {e[2]:.1f} {e[3]:.0%} {e[4]:.4g}{'' if e[5] else ' (no track)'} | "
              f"{g[0]} {g[1]} {g[2]:.1f} {g[3]:.0%} {g[4]:.4g}{'' if g[5] else ' (no track)'}")
    for label, rows in (("exact", exact), ("Gauss-Newton", gn)):
        print(f"median {label}: {statistics.median(r[1] for r in rows):.0f} iterations, "
              f"{statistics.median(r[2] for r in rows):.1f} ms/iter, {statistics.median(r[3] for r in rows):.0%} "
              f"corrected, cost {statistics.median(r[4] for r in rows):.4g}, best {min(r[4] for r in rows):.4g}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
