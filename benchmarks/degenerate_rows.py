"""Which constraints go linearly dependent during a solve, and how large their multipliers grow.

Solves one seeded cold start of a config (its search's profile) for ``--stop`` iterations and prints, at that
iterate: the smallest singular values of the Jacobian of the active constraints (equalities and inequalities
within 1e-5 of a bound) on the variables off their bounds; for the smallest three, the rows that make up the
left singular vector (the dependent combination), each named by its block (waypoint and row: tracking position
x, y, z, axis x, y, z; clearance at a knot or a midpoint; the floor); the largest multipliers; and at the
waypoints involved, the smallest singular value of the tracking Jacobian d(p_W, z_x, z_y)/dq (the arm's own
singularity). Multipliers of 1e10 and more on dependent rows are what IPOPT's inertia corrections fight.

    .venv/bin/python benchmarks/degenerate_rows.py configs/gcode_pocket.yaml 2 --stop 70 \
        --option ipopt.perturb_always_cd=no      # without the production preset's regularisation
    .venv/bin/python benchmarks/degenerate_rows.py configs/gcode_pocket.yaml 2 --stop 40    # with it
"""

from __future__ import annotations

import argparse
import os
import signal
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import casadi as ca  # noqa: E402
import numpy as np  # noqa: E402
from solver_options import parse_options  # noqa: E402

from designopt.config import load_config  # noqa: E402
from designopt.experiments.adapters import search_from_config  # noqa: E402
from designopt.initial_guess import initial_guess  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solve import local  # noqa: E402
from designopt.transcriptions import Collocation  # noqa: E402
from designopt.transcriptions.degeneracy import tracking_jacobian  # noqa: E402

TRACKING_ROWS = ("position x", "position y", "position z", "axis x", "axis y", "axis z")


def row_names(nlp) -> tuple[np.ndarray, np.ndarray]:
    """(name, point) of every constraint row: its block's meaning and the point (waypoint or midpoint) it is at."""
    names, points = np.full(nlp.n_constraints, "other (collocation, bounds)", dtype=object), np.full(
        nlp.n_constraints, -1)
    kinds = ["tracking", "clearance at a knot", "clearance at a midpoint", "floor"]
    for b, kind in zip(nlp.blocks, kinds, strict=False):
        for r in range(b.mu_index.shape[1]):
            names[b.mu_index[:, r]] = TRACKING_ROWS[r] if kind == "tracking" and r < 6 else kind
            points[b.mu_index[:, r]] = np.arange(len(b.mu_index))
    return names, points


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("start", type=int)
    parser.add_argument("--stop", type=int, default=70, help="iterations before the iterate is examined")
    parser.add_argument("--option", action="append", default=[], help="an IPOPT option KEY=VALUE")
    args = parser.parse_args()
    cfg = load_config(args.config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    profile = replace(search.profile, max_iter=args.stop,
                      options=(*search.profile.options, *parse_options(args.option)))
    built, solver, _ = local.prepared(problem, Collocation(), profile)
    nlp = built.nlp
    guess = initial_guess(problem, args.start, search.seed, search.perturbation, search.init)
    x0 = np.clip(built.pack(guess), nlp.lbx, nlp.ubx)
    sol = solver.solver(x0=x0, lbx=nlp.lbx, ubx=nlp.ubx, lbg=nlp.lbg, ubg=nlp.ubg)
    stats = solver.solver.stats()
    x, lam = np.asarray(sol["x"]).ravel(), np.asarray(sol["lam_g"]).ravel()
    g, J = nlp.jacobian("none")(x, [])
    g, J = np.asarray(g).ravel(), np.asarray(ca.densify(J))
    lbg, ubg = np.asarray(nlp.lbg, float), np.asarray(nlp.ubg, float)
    active = (lbg == ubg) | (np.abs(g - lbg) < 1e-5) | (np.abs(g - ubg) < 1e-5)
    free = (np.abs(x - nlp.lbx) > 1e-6) & (np.abs(x - nlp.ubx) > 1e-6)
    rows = np.flatnonzero(active)
    U, s, _ = np.linalg.svd(J[np.ix_(active, free)], full_matrices=False)
    names, points = row_names(nlp)
    print(f"{args.config} start {args.start}: {stats['return_status']} after {stats['iter_count']} iterations; "
          f"{active.sum()} active rows, {free.sum()} of {len(x)} variables off their bounds")
    print("smallest singular values of the active Jacobian:", " ".join(f"{v:.2e}" for v in s[-6:]))
    involved = set()
    for k in (1, 2, 3):
        u = U[:, -k]
        top = np.argsort(-np.abs(u))[:6]
        print(f"  dependent combination {k} (singular value {s[-k]:.2e}):")
        for t in top:
            i = rows[t]
            if names[i] in TRACKING_ROWS:
                involved.add(int(points[i]))
            print(f"    row {i:5d}  {names[i]:28s} point {points[i]:4d}  weight {u[t]:+.3f}  multiplier {lam[i]:+.2e}")
    big = np.argsort(-np.abs(lam))[:6]
    print("largest multipliers:", ", ".join(f"{names[i]} at {points[i]} {lam[i]:+.1e}" for i in big))
    q_d, trajectory, _ = built.unpack(x)
    jac = tracking_jacobian(problem)
    for k in sorted(involved):
        sv = np.linalg.svd(np.asarray(jac(trajectory.Q[k], q_d))[:5], compute_uv=False)
        print(f"  waypoint {k}: q = {np.round(trajectory.Q[k], 3)}, tracking Jacobian singular values "
              f"{' '.join(f'{v:.3f}' for v in sv)}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
