"""How much a module assignment's screening cost depends on its number of starts: each assignment's modules-fixed
problem (placement and trajectory free, placement z over the lifts of its robot, as `designopt modular` screens it)
solved from K seeded starts moved until they reach the path, on each of some waypoint counts; prints the best of the
first 3 starts (what the screen uses), the best of all K, the median and how many track.

    .venv/bin/python benchmarks/module_screen_starts.py --seed 1077 --starts 30 --waypoints 10 40 \
        --assignments 451112 141144 115111

Assignments are module numbers per link (1-based, the catalogue of configs/modular.yaml). The placement starts from
the config's values, not from a continuous solution as in `designopt modular`.
"""

from __future__ import annotations

import argparse
import os
import signal
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from joblib import Parallel, delayed  # noqa: E402

from designopt.config import load_config  # noqa: E402
from designopt.experiments.adapters import case_config  # noqa: E402
from designopt.experiments.modular import catalogue_from_config, lifted_modules, module_screen  # noqa: E402
from designopt.initial_guess import initial_guess  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solve import preset  # noqa: E402
from designopt.solve.local import solve_guess  # noqa: E402
from designopt.solve.strategies.coarse_to_fine import coarse_problem  # noqa: E402
from designopt.transcriptions import Collocation  # noqa: E402


def solve_start(base, catalogue, placement, assignment: str, waypoints: int, start: int, screen) -> float:
    """Start ``start`` of the screen's search ``screen`` on one assignment's problem; its cost (inf: no tracking)."""
    problem = lifted_modules(base, [int(c) - 1 for c in assignment], catalogue, placement)
    problem = coarse_problem(problem, waypoints)
    guess = initial_guess(problem, start, screen.seed, screen.perturbation, screen.init)
    sol = solve_guess(problem, Collocation(), screen.profile, guess)
    return sol.metrics.design_cost if sol.metrics.tracks else np.inf


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", type=Path, default=Path("configs/modular.yaml"))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--starts", type=int, default=30)
    parser.add_argument("--waypoints", type=int, nargs="+", default=[10, 40])
    parser.add_argument("--assignments", nargs="+", required=True)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    cfg = load_config(args.config)
    base = problem_from_config(case_config(cfg, "combined"))
    catalogue = catalogue_from_config(cfg)
    placement = {j.name: j.value for j in base.chain.placement_joints}
    screen = module_screen(preset("default", seed=args.seed))  # the screen's starts and solver profile
    jobs = [(a, w, i) for a in args.assignments for w in args.waypoints for i in range(args.starts)]
    costs = Parallel(n_jobs=args.jobs)(delayed(solve_start)(base, catalogue, placement, a, w, i, screen)
                                       for a, w, i in jobs)
    for a in args.assignments:
        for w in args.waypoints:
            c = np.array([cost for (aa, ww, _), cost in zip(jobs, costs, strict=True) if aa == a and ww == w])
            print(f"{a} on {w} waypoints: best of the first 3 starts {c[:3].min():.4g}, of all {len(c)} "
                  f"{c.min():.4g}, median {np.median(c):.4g}, {int(np.isfinite(c).sum())} track")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
