"""How wide is the best design's basin in joint-branch space? Its design started on new branches, and on its own.

The best design known of a task (a solution file) is solved as the search's second round solves a leader: its design
joints kept, the first configuration drawn over the whole circle and walked along the path by IK
(`starts.Rebranched`, ``--branches`` of them). Then from the solution's own first configuration plus Gaussian noise
of each ``--sigma`` (rad or m per joint, ``--noisy`` starts each), walked the same way. Each on ``--waypoints`` of
the path's waypoints (0: the full path) by the exploration's solver settings (the full path: the search's profile
capped at 600 iterations). Prints per case the sorted design costs against the best design known's.

    .venv/bin/python benchmarks/posture_basin.py --config configs/circle_standoff.yaml \
        --reference benchmarks/reference/circle_standoff_best_known.json --waypoints 10 20 0
"""

from __future__ import annotations

import argparse
import signal
import time
from pathlib import Path

import numpy as np

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.initial_guess import HOME_PULL, ik_trajectory
from designopt.problem import problem_from_config
from designopt.solution import read_solution_for
from designopt.solve.local import solve_guess
from designopt.solve.starts import Rebranched
from designopt.solve.strategies.coarse_to_fine import coarse_problem
from designopt.transcriptions import Collocation
from designopt.transcriptions.base import InitialGuess

ROOT = Path(__file__).resolve().parent.parent


def cost(problem, profile, guess: InitialGuess, known: float) -> float:
    """The design cost of the solve from ``guess`` against ``known`` (inf when it does not track)."""
    sol = solve_guess(problem, Collocation(), profile, guess)
    return sol.metrics.design_cost / known if sol.metrics.tracks else np.inf


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="configs/circle_standoff.yaml")
    parser.add_argument("--reference", default="benchmarks/reference/circle_standoff_best_known.json")
    parser.add_argument("--waypoints", type=int, nargs="+", default=[10])
    parser.add_argument("--branches", type=int, default=16)
    parser.add_argument("--sigma", type=float, nargs="*", default=[0.1, 0.3, 1.0])
    parser.add_argument("--noisy", type=int, default=8)
    parser.add_argument("--seed", type=int, default=900, help="the branches' seed (their start numbers)")
    args = parser.parse_args()
    cfg = load_config(ROOT / args.config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    best = read_solution_for(problem, Collocation(), ROOT / args.reference)
    known, q_d = best.metrics.design_cost, np.asarray(best.raw.q_d, float)
    first = best.sample(problem.toolpath.t)[0]
    pull = HOME_PULL if search.init == "home" else 0.0
    rng = np.random.default_rng(7)
    for waypoints in args.waypoints:
        sampled = coarse_problem(problem, waypoints) if waypoints else problem
        profile = search.explore_profile if waypoints else search.profile.capped(600)
        t0 = time.perf_counter()
        drawn = [cost(sampled, profile, Rebranched(best, args.seed, i, init=search.init).guess(sampled), known)
                 for i in range(args.branches)]
        print(f"{waypoints or 'full path'} waypoints, {args.branches} branches drawn "
              f"({time.perf_counter() - t0:.0f} s): {np.round(np.sort(drawn), 2)}", flush=True)
        for sigma in args.sigma:
            costs = []
            for i in range(args.noisy):
                q0 = first + sigma * rng.standard_normal(first.shape)
                guess = InitialGuess(q_d=q_d, Q=ik_trajectory(sampled, q_d, q0, home_pull=pull), seed=i)
                costs.append(cost(sampled, profile, guess, known))
            print(f"  its own first configuration + N(0, {sigma}^2): {np.round(np.sort(costs), 2)}", flush=True)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
