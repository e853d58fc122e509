"""How close a start's design comes to losing a task direction (design-only cause 4, docs/decisions.md).

Solves the given seeded cold starts of a config one at a time and prints, at the point each solve stops, the
smallest singular value of the tracking Jacobian d(p_W, z_x, z_y)/dq (5 rows: tool position and the two tool
axis components the task constrains, against the moving joints) over the path's waypoints, and the full
spectrum and Jacobian at the middle waypoint. A singular value near 0 at *every* waypoint means the design has
made the tracking rows dependent (the constraints' linear independence fails along the whole path).

    .venv/bin/python benchmarks/tracking_rank.py configs/design_only.yaml 1 11 0
"""

from __future__ import annotations

import argparse
import signal
from pathlib import Path

import numpy as np

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.problem import problem_from_config
from designopt.solve import Seeded, solve_one
from designopt.transcriptions.degeneracy import tracking_jacobian


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("starts", type=int, nargs="+")
    args = parser.parse_args()
    cfg = load_config(args.config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    full = tracking_jacobian(problem)

    def jac(q, q_d):  # the 5 rows the task constrains: position and the axis's x, y
        return np.asarray(full(q, q_d))[:5]

    np.set_printoptions(precision=3, suppress=True, linewidth=150)
    for i in args.starts:
        sol = solve_one(problem, Seeded(search.seed, i, search.perturbation, search.init), profile=search.profile)
        Q = np.asarray(sol.raw.Q)
        sigma = np.array([np.linalg.svd(jac(Q[k], sol.raw.q_d), compute_uv=False)[-1]
                          for k in range(len(Q))])
        print(f"start {i}: {sol.raw.status}, {sol.raw.iterations} iterations, cost {sol.metrics.design_cost:.4g}; "
              f"smallest singular value over the path: min {sigma.min():.3g}, median {np.median(sigma):.3g}")
        k = len(Q) // 2
        J = jac(Q[k], sol.raw.q_d)
        print(f"  middle waypoint: singular values {np.linalg.svd(J, compute_uv=False)}")
        print("  " + str(J).replace("\n", "\n  "))
        print("  design: " + ", ".join(f"{j.name} {v:.4g}" for j, v in zip(problem.chain.design, sol.raw.q_d,
                                                                            strict=True)))


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
