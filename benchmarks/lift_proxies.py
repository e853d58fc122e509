"""Which coarse optima are worth screening? Every coarse optimum of a finished run's exploration is screened (solved
warm on the screen's waypoints, as the search's screen stage solves its best few), and the screen's costs are
compared with the ranking the search uses (the coarse cost) and with three cheap predictions of how a coarse optimum
lifts, none of which solves anything:

    interp  the coarse trajectory sampled at the finer waypoints (what the screen starts from), its design cost there
    proj    that trajectory projected onto the path waypoint by waypoint (damped least-squares IK), its design cost
    walk    the IK walk along the finer path from the coarse trajectory's first configuration, its design cost

    .venv/bin/python benchmarks/search_seeds.py --first-seed 7 --seeds 1 --set search.starts=160 --out DIR
    .venv/bin/python benchmarks/lift_proxies.py DIR/milling/s7

Prints, per ranking, its Spearman correlation with the screen's cost, where the screen's best (within 5 %) ranks,
and the best screen cost among the first 12 and 24 of the ranking (the default search screens 12); with
``--reference``, how many coarse optima screen within 1.10 / 1.20 / 1.50x of it (the exploration's reach), for the
seeded starts and the rebranched ones (`designopt.solve.starts.Rebranched`) apart.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from joblib import Parallel, delayed  # noqa: E402

from designopt.config import load_config  # noqa: E402
from designopt.evaluation import evaluate  # noqa: E402
from designopt.experiments.adapters import search_from_config  # noqa: E402
from designopt.initial_guess import ik_trajectory, residual_function  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solution import read_solution_for  # noqa: E402
from designopt.solve.search import Job  # noqa: E402
from designopt.solve.starts import lifted_guess  # noqa: E402
from designopt.solve.strategies.coarse_to_fine import coarse_problem, lifted_tasks  # noqa: E402
from designopt.solve.tasks import run_task  # noqa: E402
from designopt.transcriptions import Collocation  # noqa: E402
from designopt.transcriptions.trajectory import trajectory  # noqa: E402

RANKINGS = ("coarse", "interp", "proj", "walk")


def projected(problem, q_d: np.ndarray, Q: np.ndarray, iterations: int = 20) -> np.ndarray:
    """Each row of Q moved onto the path at its own waypoint by damped least-squares IK (no walk between them)."""
    fn, points, out = residual_function(problem), problem.toolpath.points_W, []
    for k, q in enumerate(np.array(Q, float)):
        for _ in range(iterations):
            r, J, _ = fn(q, q_d, points[k])
            r, J = np.array(r).ravel(), np.array(J)
            if r @ r < 1e-14:
                break
            q = q + np.linalg.solve(J.T @ J + 1e-3 * np.eye(len(q)), -J.T @ r)
        out.append(q)
    return np.array(out)


def predictions_and_screen(task) -> dict:
    """A screen task's coarse optimum (``task.start``): its three predictions on the screen's waypoints, then the
    task solved as the screen stage solves it."""
    sol, fine = task.start.solution, task.problem
    guess = lifted_guess(fine, sol)
    t = fine.toolpath.t
    interp = evaluate(fine, guess.q_d, trajectory(t, guess.Q, guess.V)).design_cost
    proj = evaluate(fine, guess.q_d, trajectory(t, projected(fine, guess.q_d, guess.Q))).design_cost
    walk = evaluate(fine, guess.q_d, trajectory(t, ik_trajectory(fine, guess.q_d, guess.Q[0]))).design_cost
    screened = run_task(task)
    return {"coarse": sol.metrics.design_cost, "interp": interp, "proj": proj, "walk": walk,
            "screen": screened.metrics.design_cost if screened.metrics.tracks else np.inf, "seed": int(sol.raw.seed),
            "design": [float(v) for v in sol.raw.q_d], "screened_design": [float(v) for v in screened.raw.q_d]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a finished run's directory (its solutions/explore-*.json)")
    parser.add_argument("--config", type=Path, help="the run's config (default: the run's own config.yaml, whose "
                        "solver.seed numbers its starts; without one, configs/milling.yaml)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--dump", type=Path, help="write every coarse optimum's row (costs, designs) as JSON here")
    parser.add_argument("--reference", type=float, help="a design cost on the screen's waypoints to count against "
                        "(e.g. the best design known solved there)")
    args = parser.parse_args()
    own = args.run / "config.yaml"
    cfg = load_config(args.config or (own if own.exists() else Path("configs/milling.yaml")))
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    coarse = coarse_problem(problem, search.explore_waypoints)
    files = sorted(args.run.glob("solutions/explore-*.json"))
    sols = [s for s in (read_solution_for(coarse, Collocation(), f) for f in files) if s.metrics.tracks]
    # the screen stage's own tasks, for every coarse optimum (distinct 0: none merged)
    tasks = lifted_tasks([Job("lift_proxies", problem)], [[(None, s) for s in sols]], len(sols), "screen",
                         search.screen_waypoints, replace(search, distinct=0.0), search.screen_max_iter)
    rows = Parallel(n_jobs=args.jobs)(delayed(predictions_and_screen)(task) for task in tasks)
    if args.dump:
        args.dump.write_text(json.dumps(rows, default=float))
    screen = np.array([r["screen"] for r in rows])
    best, ok = screen.min(), np.isfinite(screen)
    print(f"{len(files)} coarse optima, {len(rows)} track; best screen cost {best:.4g}, "
          f"{int((screen <= 1.05 * best).sum())} within 5 % of it")
    if args.reference:
        # the exploration's two rounds apart: seeded starts (index < starts) and rebranched ones
        second = np.array([search.second_round(r["seed"]) for r in rows])
        for name, part in (("", np.ones_like(second)), ("  seeded starts", ~second), ("  rebranched starts", second)):
            if part.any():
                print(f"{name or 'screened'} ({int(part.sum())}) within 1.10x / 1.20x / 1.50x of {args.reference:.4g}: "
                      + " / ".join(str(int((screen[part] <= f * args.reference).sum())) for f in (1.1, 1.2, 1.5)))
    for name in RANKINGS:
        value = np.array([r[name] for r in rows])
        order = np.argsort(value)
        where = sorted(int(np.flatnonzero(order == i)[0]) + 1 for i in np.flatnonzero(screen <= 1.05 * best))
        rho = np.corrcoef(np.argsort(np.argsort(value[ok])), np.argsort(np.argsort(screen[ok])))[0, 1]  # Spearman
        print(f"{name:7s} Spearman {rho:5.2f}; the screen's best at rank {where}; best screen cost among the first "
              f"12: {screen[order[:12]].min():.4g}, 24: {screen[order[:24]].min():.4g}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
