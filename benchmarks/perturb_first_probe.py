"""Probe for issue 24: does IPOPT save its unperturbed factorisation if it perturbs the Hessian first?

IPOPT factorises an iteration's KKT matrix first as it is and, when the inertia is wrong (85 % of the main job's
iterations: the design problem's negative curvature, docs/decisions.md), again with delta_w I added. It skips the
first trial -- trying max(delta_min, delta_last / 3) at once -- after it has found the Hessian structurally
singular in three iterations (IPOPT's PDPerturbationHandler, "hess_degenerate"). One free variable that neither
the objective nor the constraints touch makes it so, and changes nothing else of the problem. This probe solves
the same seeded starts with the NLP as it is and with that variable, alternating, one at a time on one core:

    .venv/bin/python benchmarks/perturb_first_probe.py configs/milling.yaml --starts 24
    .venv/bin/python benchmarks/perturb_first_probe.py configs/milling.yaml --waypoints 10 --cap 250 --starts 48

Prints per start (iterations, CPU s, cost, status) for both, then medians: CPU ms per iteration, iterations,
converged starts, best and median cost. CPU seconds of the process (time.process_time).
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import casadi as ca  # noqa: E402
import numpy as np  # noqa: E402

from designopt.config import load_config  # noqa: E402
from designopt.experiments.adapters import search_from_config  # noqa: E402
from designopt.initial_guess import initial_guess  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solve import local  # noqa: E402
from designopt.solve.backends.ipopt import options  # noqa: E402
from designopt.solve.strategies.coarse_to_fine import coarse_problem  # noqa: E402
from designopt.transcriptions import Collocation  # noqa: E402


def with_free_variable(problem: dict, derivatives: dict) -> tuple[dict, dict]:
    """The NLP (x, f, g) and its hess_lag / jac_g / grad_f with one more variable, last, that neither f nor g
    depends on: a structurally zero gradient entry, Jacobian column and Hessian row."""
    x = problem["x"]
    n = x.numel()
    xa = type(x).sym("x", n + 1)
    f, g = ca.Function("nlp", [x], [problem["f"], problem["g"]])(xa[:n])
    H, J, G = derivatives["hess_lag"], derivatives["jac_g"], derivatives["grad_f"]
    p, lam_f, lam_g = (ca.MX.sym(name, H.sparsity_in(i)) for i, name in ((1, "p"), (2, "lam_f"), (3, "lam_g")))
    xm = ca.MX.sym("x", n + 1)
    g_val, jac = J(xm[:n], p)
    f_val, grad = G(xm[:n], p)
    return {"x": xa, "f": f, "g": g}, {
        "hess_lag": ca.Function("hess_lag", [xm, p, lam_f, lam_g], [ca.diagcat(H(xm[:n], p, lam_f, lam_g),
                                                                                ca.MX(1, 1))],
                                ["x", "p", "lam_f", "lam_g"], ["hess"]),
        "jac_g": ca.Function("jac_g", [xm, p], [g_val, ca.horzcat(jac, ca.MX(jac.size1(), 1))], ["x", "p"],
                             ["g", "jac_g_x"]),
        # dense: nlpsol copies the gradient's nonzeros as if it were, and a structural zero leaves an entry
        # unwritten (now and then NaN: Invalid_Number_Detected)
        "grad_f": ca.Function("grad_f", [xm, p], [f_val, ca.densify(ca.vertcat(grad, ca.MX(1, 1)))], ["x", "p"],
                              ["f", "grad_f_x"])}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("--waypoints", type=int, default=0, help="the path's N as the search's coarse stages take it")
    parser.add_argument("--cap", type=int, default=1000, help="iteration cap")
    parser.add_argument("--starts", type=int, default=8)
    args = parser.parse_args()
    cfg = load_config(args.config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    if args.waypoints:
        problem = coarse_problem(problem, args.waypoints)
    profile = replace(search.profile, max_iter=args.cap)
    built, prepared, _ = local.prepared(problem, Collocation(), profile)
    nlp = prepared.nlp
    nlp_problem, derivatives = nlp.derivatives(profile.compile)
    free_problem, free_derivatives = with_free_variable(nlp_problem, derivatives)
    solvers = {"as it is": (ca.nlpsol("plain", "ipopt", nlp_problem, {**options(profile, nlp.n_variables),
                                                                       **derivatives}), 0),
               "free variable": (ca.nlpsol("free", "ipopt", free_problem, {**options(profile, nlp.n_variables + 1),
                                                                            **free_derivatives}), 1)}
    rows = {name: [] for name in solvers}
    for start in range(args.starts):
        guess = initial_guess(problem, start, search.seed, search.perturbation, search.init)
        x0 = np.clip(built.pack(guess), nlp.lbx, nlp.ubx)
        for name in list(solvers)[:: 1 if start % 2 == 0 else -1]:  # alternate which goes first
            solver, extra = solvers[name]
            pad = [0.0] * extra
            cpu = time.process_time()
            sol = solver(x0=np.r_[x0, pad], lbx=np.r_[nlp.lbx, [-np.inf] * extra],
                         ubx=np.r_[nlp.ubx, [np.inf] * extra], lbg=nlp.lbg, ubg=nlp.ubg)
            cpu = time.process_time() - cpu
            stats = solver.stats()
            rows[name].append((stats["iter_count"], cpu, float(sol["f"]), stats["return_status"]))
        print(start, " | ".join(f"{name}: {r[-1][0]} it, {r[-1][1]:.2f} s, {r[-1][2]:.4g}, {r[-1][3]}"
                                for name, r in rows.items()), flush=True)
    med = statistics.median
    for name, r in rows.items():
        print(f"{name}: ms/iter {med(1e3 * c / max(k, 1) for k, c, _, _ in r):.3f}, iterations "
              f"{med(k for k, *_ in r):.0f}, CPU {sum(c for _, c, _, _ in r):.1f} s, converged "
              f"{sum(s == 'Solve_Succeeded' for *_, s in r)} of {len(r)}, best {min(f for _, _, f, _ in r):.4g}, "
              f"median {med(f for _, _, f, _ in r):.4g}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
