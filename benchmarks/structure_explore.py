"""A sweep's exploration of a few structures, under IPOPT options: the solves at the cap, CPU, and what they reach.

Each structure gets exactly the exploration tasks `designopt sweep-structures` gives it (the config's search,
``--starts`` seeded starts on the coarse path, capped, watched for degenerate designs, held ones finished), solved
on ``--jobs`` workers. Several runs (``--json`` each, then ``--compare``) are compared per structure with the best
exploration cost any of them found:

    .venv/bin/python benchmarks/structure_explore.py PRRP RPRP PRRPPP --seed 0 --json base.json --option none
    .venv/bin/python benchmarks/structure_explore.py PRRP RPRP PRRPPP --seed 0 --json cd.json \\
        --option ipopt.perturb_always_cd=yes
    .venv/bin/python benchmarks/structure_explore.py --compare base.json cd.json

``--option none`` takes the preset's profile without its own options (what the sweep solved before they were
set); any other ``--option KEY=VALUE`` is added to the profile's. A few hundred solves take about half a minute.
"""

from __future__ import annotations

import argparse
import json
import signal
from dataclasses import replace
from pathlib import Path

import pandas as pd
from solver_options import parse_options

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.experiments.sweep import sweep_jobs
from designopt.solve.strategies.coarse_to_fine import coarse_problem
from designopt.solve.strategies.steps import seeded_tasks
from designopt.solve.tasks import fan_out

CAPPED = "Maximum_Iterations_Exceeded"


def explore(config: Path, structures: list[str], seed: int, options: list[str], jobs: int) -> list[dict]:
    cfg = load_config(config)
    search = replace(search_from_config(cfg), seed=seed)
    given = parse_options([o for o in options if o != "none"])
    own = () if "none" in options else search.profile.options
    search = replace(search, profile=replace(search.profile, options=(*own, *given)))
    tasks = []
    for job in sweep_jobs(cfg, structures):
        tasks += seeded_tasks(job, "explore", coarse_problem(job.problem, search.explore_waypoints),
                              search.profile.capped(search.explore_max_iter), search, search.starts)
    return [{"structure": t.problem.chain.structure, "start": t.seed, "status": s.raw.status,
             "iterations": s.raw.iterations, "cpu_s": s.raw.solve_time_s, "tracks": bool(s.metrics.tracks),
             "cost": float(s.metrics.design_cost)} for t, s in fan_out(tasks, jobs)]


def compare(files: list[Path]) -> None:
    runs = {f.name: pd.DataFrame(json.loads(f.read_text())) for f in files}
    every = pd.concat(runs.values())
    best = every[every.tracks].groupby("structure").cost.min()
    print("| run | solve seconds | at the cap | converged | within 1.10x | best of each structure / best of all |")
    print("|---|---|---|---|---|---|")
    for name, d in runs.items():
        tracking = d[d.tracks]
        ratio = tracking.cost / tracking.structure.map(best)
        per = ratio.groupby(tracking.structure).min()
        print(f"| {name} | {d.cpu_s.sum():.1f} | {(d.status == CAPPED).sum()} of {len(d)} | "
              f"{(d.status == 'Solve_Succeeded').sum()} | {(ratio <= 1.10).sum()} | "
              + ", ".join(f"{s} {v:.2f}" for s, v in per.items()) + " |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structures", nargs="*")
    parser.add_argument("--config", type=Path, default=Path("configs/structures.yaml"))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                        help="an nlpsol option added to the profile's ('none': drop the profile's own options)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--json", type=Path, help="write the solves here")
    parser.add_argument("--compare", type=Path, nargs="+", help="compare runs written with --json")
    args = parser.parse_args()
    if args.compare:
        compare(args.compare)
        return
    rows = explore(args.config, args.structures, args.seed, args.option, args.jobs)
    if args.json:
        args.json.write_text(json.dumps(rows))
    solved = pd.DataFrame(rows)
    print(f"{len(rows)} solves, {solved.cpu_s.sum():.1f} s, {(solved.status == CAPPED).sum()} at the cap")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
