"""Replay a finished sweep's refine stage: would another way of refining its coarse optima have done better?

Every refine of the sweep (its summary.csv's ``refine`` rows) is solved again from the explore solution it started
from (its file in the run's ``solutions/``), lifted to the full path as the search lifts it, once per variant:

- ``as_is``: the sweep's own profile (reproduces the run's refine costs: a check of the replay);
- ``options:KEY=VALUE;KEY=VALUE``: the profile with these IPOPT options instead of its own (``options:`` alone:
  none beyond the backend's);
- ``via:N``: lifted to N waypoints first (solved warm), then to the full path.

    .venv/bin/python benchmarks/refine_replay.py results/structures_physical/<run> --out replay.csv \\
        --variant as_is --variant options: --variant "options:ipopt.alpha_for_y=min-dual-infeas" --variant via:20

It prints, per variant against ``as_is``: how many structures' best refine is lower or higher by more than 1 %, the
geometric mean and worst ratio, tracking refines, CPU; and how many of the run's final structure bests (after its
neighbour stage) that variant's refines would lower by more than 1 %. The sweep's search is the run's
``config.yaml``'s; the replay uses two worker processes.
"""

from __future__ import annotations

import argparse
import signal
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from joblib import Parallel, delayed
from solver_options import parse_options

from designopt.config import parse_config
from designopt.experiments.adapters import search_from_config
from designopt.experiments.sweep import sweep_jobs
from designopt.solution import read_solution_for
from designopt.solve.strategies.coarse_to_fine import coarse_problem, lifted_tasks
from designopt.solve.tasks import run_task


def refine(job, search, solution, variant: str):
    """The refine of ``solution`` (a coarse optimum of ``job``) the way ``variant`` says: (solution, iterations)."""
    lift = lifted_tasks([job], [[(None, solution)]], 1, "refine", None, search)
    if not lift:
        return None, 0
    task, before = lift[0], 0
    if variant.startswith("via:"):
        middle = lifted_tasks([job], [[(None, solution)]], 1, "screen", int(variant[4:]), search)[0]
        done = run_task(middle)
        before = done.raw.iterations
        task = (lifted_tasks([job], [[(None, done)]], 1, "refine", None, search) or [task])[0]
    elif variant.startswith("options:"):
        items = [item for item in variant[8:].split(";") if item]
        task = replace(task, profile=replace(task.profile, options=parse_options(items)))
    elif variant != "as_is":
        raise ValueError(f"unknown variant {variant!r}")
    done = run_task(task)
    return done, before + done.raw.iterations


def replay_one(run: Path, base, structure: str, seed: int, variants: list[str]) -> list[dict]:
    search = search_from_config(base)
    job = sweep_jobs(base, [structure])[0]
    coarse = coarse_problem(job.problem, search.explore_waypoints)
    start = read_solution_for(coarse, job.transcription, run / f"solutions/sweep-explore-to-{structure}-s{seed}.json")
    rows = []
    for variant in variants:
        t0 = time.process_time()
        done, iterations = refine(job, search, start, variant)
        rows.append(dict(structure=structure, seed=seed, variant=variant,
                         cost=done.metrics.design_cost if done else np.nan,
                         tracks=bool(done and done.metrics.tracks), status=done.raw.status if done else "none",
                         iterations=iterations, cpu=time.process_time() - t0))
    return rows


def report(df: pd.DataFrame, table: pd.Series) -> None:
    def best(variant):
        rows = df[(df.variant == variant) & df.tracks]
        return rows.groupby("structure").cost.min().reindex(table.index)

    base = best("as_is")
    for variant in dict.fromkeys(df.variant):
        b, rows = best(variant), df[df.variant == variant]
        r = (b / base).dropna()
        final = np.fmin(table, b) / table
        print(f"{variant}: refine best lower {int((r < 0.99).sum())}, higher {int((r > 1.01).sum())} of {len(r)} "
              f"(geometric mean {np.exp(np.log(r).mean()):.3f}x, worst {r.max():.2f}x); "
              f"tracking {int(rows.tracks.sum())} of {len(rows)}; CPU {rows.cpu.sum():.0f} s; "
              f"final bests lowered {int((final < 0.99).sum())}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a sweep's run directory (summary.csv, config.yaml, solutions/)")
    parser.add_argument("--variant", action="append", default=[], help="as_is, options:K=V;K=V or via:N")
    parser.add_argument("--out", type=Path, help="write every replayed refine here (CSV)")
    parser.add_argument("--structures", help="only these (comma-separated; default: every structure refined)")
    args = parser.parse_args()
    variants = list(dict.fromkeys(["as_is", *args.variant]))
    config = args.run / "config.yaml"
    base = parse_config(yaml.safe_load(config.read_text()), config, args.run)
    summary = pd.read_csv(args.run / "summary.csv")
    refines = summary[summary.stage == "refine"]
    if args.structures:
        refines = refines[refines.structure.isin(args.structures.split(","))]
    rows = Parallel(n_jobs=2)(delayed(replay_one)(args.run, base, r.structure, int(r.seed), variants)
                              for r in refines.itertuples())
    df = pd.DataFrame([row for one in rows for row in one])
    if args.out:
        df.to_csv(args.out, index=False)
    again = df[df.variant == "as_is"].set_index(["structure", "seed"]).cost
    ran = refines.set_index(["structure", "seed"]).design_cost.reindex(again.index)
    print(f"as_is reproduces {int(np.isclose(again, ran, rtol=1e-6, equal_nan=True).sum())} of {len(again)} refines")
    table = pd.read_csv(args.run / "table.csv").set_index("structure").design_cost
    report(df, table[table.index.isin(refines.structure)])


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
