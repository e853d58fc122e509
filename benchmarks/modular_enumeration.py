"""Every assignment of the paper's five modules to the six links: the best modular robot, found exhaustively.

Each assignment is a robot with every link fixed to a module; what is left to design is its placement (and the
trajectory). Stage 1 *screens* all 5^6 = 15,625 of them on a coarse sampling of the path (10 of the 80 waypoints,
``--starts`` seeded starts each, initialised with `init: reach` -- the placement moved until the start reaches
the path -- and capped at 250 iterations). Stage 2 *refines* the ``--refine`` best by screening cost, each with
the default search on the full path. Stage 3 measures the screening's error on ``--sample`` assignments drawn at
random among all (not the best): their full-path cost from the same full search, against their screening rank.

Everything is written as it finishes into one run directory (``--out``), so the script resumes where it stopped
(``--resume``). Prints the best assignments found, where the screening ranked them, and the screening error; writes
the best design to ``--reference`` (a solution file) when it is better than the one there.

    .venv/bin/python benchmarks/modular_enumeration.py --out /path/to/runs [--resume] [--starts 3]
        [--refine 200] [--sample 60] [--jobs 2]
"""

from __future__ import annotations

import argparse
import itertools
import json
import signal
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from designopt import tables
from designopt.config import load_config
from designopt.experiments.adapters import case_config
from designopt.experiments.modular import catalogue_from_config, fix_modules
from designopt.experiments.runs import Executor
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solve import Job, SolverProfile, preset, run_search
from designopt.solve.strategies.coarse_to_fine import coarse_problem
from designopt.verify import verify_file

ROOT = Path(__file__).resolve().parent.parent
BATCH = 250  # assignments per search call: bounds what the executor holds in memory


def label(assignment) -> str:
    return "".join(str(k + 1) for k in assignment)


def best_per_case(summary: pd.DataFrame, prefix: str, full_path: bool = False) -> pd.Series:
    """The best tracking cost of each assignment (cases named prefix + digits); ``full_path``: of full-path solves
    only (not a search's coarse stages, nor its solves with relaxed velocity limits: `tables.full_path`)."""
    rows = summary[summary["case"].astype(str).str.startswith(prefix) & (summary["tracks"].astype(str) == "True")]
    if full_path:
        rows = tables.full_path(rows)
    return rows.groupby("case")["design_cost"].min()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default=str(ROOT / "configs" / "modular.yaml"))
    parser.add_argument("--out", required=True)
    parser.add_argument("--name", default="enumeration")
    parser.add_argument("--resume", action="store_true")
    parser.add_argument("--starts", type=int, default=3)
    parser.add_argument("--refine", type=int, default=200)
    parser.add_argument("--sample", type=int, default=60)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--compile", default="O0", help="the screening's derivative blocks (SolverProfile.compile)")
    parser.add_argument("--reference", default=str(ROOT / "benchmarks" / "reference" / "modular_best_known.json"))
    parser.add_argument("--limit", type=int, default=None, help="only the first N assignments (a trial run)")
    args = parser.parse_args()

    cfg = load_config(args.config)
    base = problem_from_config(case_config(cfg, "combined"))
    catalogue = catalogue_from_config(cfg)
    placement = {j.name: j.value for j in base.chain.placement_joints}
    assignments = list(itertools.product(range(len(catalogue.modules)), repeat=base.chain.n_links))[: args.limit]
    run = RunDirectory.create(Path(args.out), "modular_enumeration", args.name, args.resume)
    # screening needs only summary.csv; the full searches need the solutions of their earlier stages on resume
    execute = Executor(run, "modular_enumeration", args.jobs, resume=True, load_finished=False)
    execute_full = Executor(run, "modular_enumeration", args.jobs, resume=True)

    # 1. screen every assignment on the coarse path
    profile = SolverProfile(max_iter=250, compile=args.compile)
    screen = preset("paper", starts=args.starts, init="reach", profile=profile)
    for first in range(0, len(assignments), BATCH):
        batch = assignments[first:first + BATCH]
        jobs = [Job(f"s{label(a)}", coarse_problem(fix_modules(base, list(a), catalogue, placement), 10))
                for a in batch]
        run_search(jobs, screen, execute)
        run.log(f"screened {first + len(batch)} of {len(assignments)}")
    screened = best_per_case(pd.read_csv(run.summary), "s")
    screened.index = screened.index.str[1:]
    ranked = screened.sort_values()
    print(f"screened: {len(assignments)} assignments, {len(screened)} track on the coarse path", flush=True)

    # 2. refine the best by screening, 3. and a random sample, each with the default search on the full path
    rng = np.random.default_rng(2026)
    sample = [label(assignments[i]) for i in rng.choice(len(assignments), min(args.sample, len(assignments)),
                                                        replace=False)]
    chosen = list(dict.fromkeys([*ranked.index[: args.refine], *sample]))
    if not chosen:  # --refine 0 --sample 0: a screening run only
        print(ranked.head(15).to_string(), flush=True)
        return
    full = replace(preset("default"), init="reach")
    for first in range(0, len(chosen), BATCH // 10):
        batch = chosen[first:first + BATCH // 10]
        jobs = [Job(f"f{digits}", fix_modules(base, [int(c) - 1 for c in digits], catalogue, placement))
                for digits in batch]
        run_search(jobs, full, execute_full)
    summary = pd.read_csv(run.summary)
    refined = best_per_case(summary, "f", full_path=True)
    refined.index = refined.index.str[1:]
    rank = {digits: k + 1 for k, digits in enumerate(ranked.index)}
    table = pd.DataFrame({"assignment": refined.index, "full_path_cost": refined.values,
                          "screening_cost": [screened.get(d, np.nan) for d in refined.index],
                          "screening_rank": [rank.get(d, np.nan) for d in refined.index],
                          "in_sample": [d in sample for d in refined.index]}).sort_values("full_path_cost")
    table.to_csv(run.path / "enumeration.csv", index=False)
    print(table.head(15).to_string(index=False))
    best = table.iloc[0]
    print(f"best assignment {' '.join('m' + c for c in best['assignment'])}: {best['full_path_cost']:.6g} "
          f"(screening rank {int(best['screening_rank'])} of {len(screened)})")
    top = table[~table["in_sample"] | (table["screening_rank"] <= args.refine)]
    print(f"refined {len(top)}: the best full-path cost's screening rank {int(best['screening_rank'])}; "
          f"ranks of the 10 best: {sorted(int(r) for r in table['screening_rank'].head(10))}")
    drawn = table[table["in_sample"]]
    if len(drawn):
        worse = (drawn["full_path_cost"] < best["full_path_cost"]).sum()
        corr = drawn[["screening_cost", "full_path_cost"]].rank().corr().iloc[0, 1]
        print(f"random sample of {len(drawn)}: {worse} better than the best refined; Spearman rank correlation of "
              f"screening and full-path cost {corr:.3f}; full/screening cost ratio median "
              f"{np.nanmedian(drawn['full_path_cost'] / drawn['screening_cost']):.3f}")

    # the best design as a solution file, when it beats the one kept
    tracked = summary[(summary["case"] == f"f{best['assignment']}") & (summary["tracks"].astype(str) == "True")]
    row = tables.full_path(tracked)
    path = run.path / row.sort_values("design_cost").iloc[0]["solution_file"]
    reference = Path(args.reference)
    kept = json.loads(reference.read_text())["metrics"]["design_cost"] if reference.exists() else np.inf
    if best["full_path_cost"] < kept:
        reference.write_text(path.read_text())
        print(f"{reference}: replaced ({kept:.6g} -> {best['full_path_cost']:.6g}); verify: "
              f"{verify_file(reference) or 'ok'}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
