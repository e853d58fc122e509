"""A stage of finished runs (the screen or the refine) solved again with each of several solver variants (a linear
solver, IPOPT options), in one process, alternating: the CPU the stage costs with each, and what it ranks first.

A default run's screen lifts its 24 best distinct coarse optima to 40 waypoints, once per barrier of
``search.screen_mu_init``; its refine lifts the 4 best of those (each candidate's better screen) to the full path,
once per barrier of ``search.refine_mu_init``. For each RUN (a directory `search_seeds.py --out DIR` keeps,
DIR/<name>/s<seed>), this reads the solutions the stage starts from back (solution files, start order), builds the
same tasks with this checkout's search (`coarse_to_fine.lifted_tasks`) and solves each with every ``--solver`` in
turn (the order alternating from task to task), measuring the process's CPU per solve. A variant is a linear
solver, optionally followed by IPOPT options: ``mumps``, ``ldl``,
``mumps:ipopt.mumps_scaling=0,ipopt.mumps_permuting_scaling=0``. Per variant it prints the CPU of the stage (sum,
median per solve), its iterations, how many solves end tracking and how many converge (IPOPT's Solve_Succeeded),
and per run the stage's best cost (each start's better pass, as the search ranks them) and, for the screen, how
many of the top ``--refine`` candidates every variant shares.

    .venv/bin/python benchmarks/stage_solvers.py DIR/milling/s13* --solver mumps --solver ldl
    .venv/bin/python benchmarks/stage_solvers.py DIR/milling/s13* --stage refine --solver mumps \
        --solver "mumps:ipopt.mumps_scaling=0,ipopt.mumps_permuting_scaling=0"

What a changed screen would then refine to is `replay_stages.py`'s (a worktree with the variant as default).
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).parent))

import pandas as pd  # noqa: E402
from solver_options import parse_options  # noqa: E402

from designopt.config import load_config  # noqa: E402
from designopt.experiments.adapters import search_from_config  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solution import read_solution_for  # noqa: E402
from designopt.solve.optima import best_solution, distinct_best  # noqa: E402
from designopt.solve.search import Job  # noqa: E402
from designopt.solve.strategies.coarse_to_fine import (  # noqa: E402
    better_pass,
    coarse_problem,
    lifted_tasks,
    numbered_stage,
)
from designopt.solve.tasks import run_task  # noqa: E402
from designopt.tables import stage_kind  # noqa: E402


def solved(run: Path, job: Job, kind: str, waypoints: int) -> list[tuple[SimpleNamespace, object]]:
    """The run's solves of stage kind ``kind`` (explore: both rounds; screen: every pass) on ``waypoints`` of the
    path, as (task with its start number and stage, solution) pairs in start order."""
    summary = pd.read_csv(run / "summary.csv")
    rows = summary[summary["stage"].astype(str).map(stage_kind) == kind].sort_values("seed", kind="stable")
    coarse = coarse_problem(job.problem, waypoints)
    return [(SimpleNamespace(seed=int(seed), stage=stage), read_solution_for(coarse, job.transcription, run / f))
            for seed, stage, f in zip(rows["seed"], rows["stage"], rows["solution_file"], strict=True)]


def stage_tasks(run: Path, stage: str) -> tuple[list, object]:
    """The tasks of ``stage`` (screen or refine) as this checkout's search builds them from the run's earlier stage,
    and the search."""
    cfg = load_config(run / "config.yaml")
    search = search_from_config(cfg)
    job = Job("", problem_from_config(cfg))
    if stage == "screen":
        found = solved(run, job, "explore", search.explore_waypoints)
        return [t for i, (mu, solver) in enumerate(search.screen_passes)
                for t in lifted_tasks([job], [found], search.screen, numbered_stage("screen", i),
                                      search.screen_waypoints, search, search.screen_max_iter, mu_init=mu,
                                      linear_solver=solver)], search
    found = better_pass(solved(run, job, "screen", search.screen_waypoints))
    return [t for i, mu in enumerate(search.refine_mu_init)
            for t in lifted_tasks([job], [found], search.refine, numbered_stage("refine", i), None, search,
                                  mu_init=mu)], search


def variant(task, name: str):
    """The task solved by variant ``name`` (LINEAR[:KEY=VALUE,...])."""
    linear, _, options = name.partition(":")
    profile = task.profile.solved_by(linear)
    if options:
        profile = profile.with_options(**dict(parse_options(options.split(","))))
    return replace(task, profile=profile)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--solver", action="append", required=True,
                        help="LINEAR[:KEY=VALUE,...], e.g. mumps, ldl (repeat)")
    parser.add_argument("--stage", choices=("screen", "refine"), default="screen")
    parser.add_argument("--refine", type=int, default=4, help="top screen candidates compared between solvers")
    args = parser.parse_args()
    totals = {s: [] for s in args.solver}
    for run in args.runs:
        tasks, search = stage_tasks(run, args.stage)
        done = {s: [] for s in args.solver}
        for k, task in enumerate(tasks):
            order = args.solver if k % 2 == 0 else args.solver[::-1]
            for name in order:
                cpu = time.process_time()
                sol = run_task(variant(task, name))
                cpu = time.process_time() - cpu
                done[name].append((task, sol, cpu))
                totals[name].append((cpu, sol.raw.iterations, sol.metrics.tracks, sol.raw.status == "Solve_Succeeded"))
        line = []
        tops = {}
        for name in args.solver:
            better = better_pass([(task, sol) for task, sol, _ in done[name]])  # one per start, as the search ranks
            ranked = distinct_best([sol for _, sol in better], args.refine, search.distinct)
            tops[name] = {better[i][0].seed for i in ranked}
            best = best_solution([sol for _, sol in better])
            cost = best.metrics.design_cost if best is not None else float("nan")
            line.append(f"{name} {sum(c for *_, c in done[name]):.1f} s, best {cost:.6g}")
        shared = f"; top {args.refine} shared by all {len(set.intersection(*tops.values()))}" \
            if args.stage == "screen" else ""
        print(f"{run}: " + "; ".join(line) + shared, flush=True)
    for name, rows in totals.items():
        cpu = [r[0] for r in rows]
        print(f"{name}: {len(rows)} {args.stage} solves, CPU {sum(cpu):.1f} s (median {statistics.median(cpu):.3f} s), "
              f"{sum(r[1] for r in rows)} iterations, {sum(r[2] for r in rows)} tracking, "
              f"{sum(r[3] for r in rows)} converged")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
