"""Where the negative curvature that makes IPOPT correct the inertia lives (issue 24): a start is stopped after
k iterations, and the Hessian of the Lagrangian there, reduced to the null space of the equality constraints'
Jacobian, is decomposed; each negative eigenvector is split by the variable groups it moves (design lengths,
design angles, knot joints q, knot velocities v).

    .venv/bin/python benchmarks/curvature_probe.py configs/milling.yaml --start 0 --iterations 10 30 60 100

The reduced Hessian ignores the inequalities (none is active on the main job's path) and IPOPT's barrier terms
(positive), so a negative eigenvalue here is one IPOPT must correct. Results: docs/decisions.md "Speed (issue 24)".
"""

from __future__ import annotations

import argparse
import signal
from dataclasses import replace
from pathlib import Path

import casadi as ca
import numpy as np

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.initial_guess import initial_guess
from designopt.problem import problem_from_config
from designopt.solve import local
from designopt.transcriptions import Collocation


def reduced_spectrum(nlp, x, lam_g):
    """(eigenvalues, eigenvectors in x) of the Lagrangian's Hessian on the null space of the equalities' Jacobian."""
    H = np.array(ca.DM(nlp.hessian("O0")(x, ca.DM(0, 1), 1.0, lam_g)))
    H = np.triu(H) + np.triu(H, 1).T
    J = np.array(ca.DM(nlp.jacobian("O0")(x, ca.DM(0, 1))[1]))[nlp.lbg == nlp.ubg]
    _, s, Vt = np.linalg.svd(J)
    Z = Vt[int(np.sum(s > 1e-9 * s[0])):].T
    w, V = np.linalg.eigh(Z.T @ H @ Z)
    return w, Z @ V


def groups(problem, n_state: int) -> dict[str, np.ndarray]:
    chain, N = problem.chain, problem.toolpath.n
    n_d, n_m = chain.n_design, chain.n_moving
    kinds = np.array([j.kind for j in chain.design])
    knots = n_d + np.arange(N)[:, None] * n_state
    return {"design lengths": np.flatnonzero(kinds == "length"), "design angles": np.flatnonzero(kinds == "angle"),
            "q": (knots + np.arange(n_m)).ravel(), "v": (knots + n_m + np.arange(n_m)).ravel()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("--start", type=int, default=0)
    parser.add_argument("--iterations", type=int, nargs="+", default=[10, 30, 60, 100])
    parser.add_argument("--show", type=int, default=4, help="negative eigenvalues shown per iterate")
    args = parser.parse_args()
    cfg = load_config(args.config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    for k in args.iterations:
        built, solver, _ = local.prepared(problem, Collocation(), replace(search.profile, max_iter=k))
        nlp = built.nlp
        guess = initial_guess(problem, args.start, search.seed, search.perturbation, search.init)
        x0 = np.clip(built.pack(guess), nlp.lbx, nlp.ubx)
        sol = solver.solver(x0=x0, lbx=nlp.lbx, ubx=nlp.ubx, lbg=nlp.lbg, ubg=nlp.ubg)
        w, V = reduced_spectrum(nlp, np.asarray(sol["x"]).ravel(), np.asarray(sol["lam_g"]).ravel())
        negative = np.flatnonzero(w < -1e-8 * max(np.abs(w).max(), 1.0))
        print(f"after {k} iterations ({solver.solver.stats()['return_status']}): reduced Hessian {len(w)} x {len(w)}, "
              f"{len(negative)} negative eigenvalues, near zero (|w| < 1e-6): {int(np.sum(np.abs(w) < 1e-6))}")
        for i in negative[: args.show]:
            share = {name: float(np.sum(V[idx, i] ** 2)) for name, idx in groups(problem, built.n_state).items()}
            print(f"  {w[i]:.2e}: " + ", ".join(f"{name} {s:.2f}" for name, s in share.items()))


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
