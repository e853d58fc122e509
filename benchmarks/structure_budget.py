"""Sweep structures searched alone (no neighbours) under variants of the config's search: cost against a reference.

Each (structure, seed, variant) is the search `designopt sweep-structures` gives a structure (the config's preset,
``solver.seed`` replaced), with the variant's fields of `designopt.solve.search.Search` replaced, solved in this
process; the solver CPU and the best design cost are written to ``--json`` as each finishes (resumable). The table
gives per variant how many runs end within 1.10x of the reference (``--references``, e.g. the sweep's kept
large-budget costs), the geometric mean of the ratios and the CPU:

    .venv/bin/python benchmarks/structure_budget.py RRRRRR RRRRR RRRR RRPRRR --seeds 0 1 2 3 4 5 \\
        --variant quick: --variant rebranch4:rebranch=4 --variant starts80:starts=80 --json budget.json
    .venv/bin/python benchmarks/structure_budget.py --table budget.json    # [STRUCTURES]: only those

A variant ``NAME:preset=P,...`` starts from preset P's search (`designopt.solve.search.PRESETS`) instead of the
config's, keeping the config's solver profile (the sweep's caps and IPOPT options), then sets the other fields.
``--save DIR`` also writes each run's best solution, ``DIR/<structure>_<seed>_<variant>.json`` (a solution file:
``python -m designopt.verify`` re-checks it). A structure of 4-6 joints takes 4-20 s of CPU per run. Alone, a
structure gets the preset's ``starts`` and ``screen``; in a sweep a smaller one gets more (`small_problem_starts`),
so to search it as a sweep does, set them (a 5-joint structure in the K = I sweep: ``starts=56,screen=17,
screen_waypoints=25,small_problem_starts=1``; 4 joints 84, 25, 32; 3 joints 139, 42, 40, where alone a screen on
all of a 40-waypoint path's waypoints is skipped while the sweep screens on the full path). Since `quick` gives an
arm of fewer than 5 joints twice its share (`Search.small_arm_starts`), such an arm's sweep starts are 168 (4 joints)
and 278 (3 joints), its screen as before: with ``starts`` set to its share (84, 139) the config's `quick` doubles it
as the sweep does, and ``small_arm_starts=1`` searches it with the share alone.
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import sys
from dataclasses import replace
from pathlib import Path

import pandas as pd

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.experiments.sweep import sweep_jobs
from designopt.solution import write_solution
from designopt.solve.search import preset
from designopt.solve.strategies import run_search
from designopt.solve.tasks import fan_out

sys.path.insert(0, str(Path(__file__).parent))
from solver_options import option_value  # noqa: E402


def variant(text: str) -> tuple[str, dict]:
    """NAME:field=value,field=value -> (NAME, {field: value as an int, a float or else the text})."""
    name, _, fields = text.partition(":")
    return name, {key: option_value(value) for key, value in
                  (item.split("=", 1) for item in filter(None, fields.split(",")))}


def run(config: Path, structures: list[str], seeds: list[int], variants: list[str], out: Path,
        save: Path | None = None) -> None:
    cfg = load_config(config)
    rows = json.loads(out.read_text()) if out.exists() else []
    if save is not None:
        save.mkdir(parents=True, exist_ok=True)
    have = {(r["structure"], r["seed"], r["variant"]) for r in rows}
    for seed in seeds:
        for structure in structures:
            for name, fields in map(variant, variants):
                if (structure, seed, name) in have:
                    continue
                search = search_from_config(cfg)
                # another preset's search, under the config's solver profile (`variant` parsed a fresh dict)
                if "preset" in fields:
                    search = replace(preset(str(fields.pop("preset"))), profile=search.profile)
                search = replace(search, seed=seed, structure_neighbours=False, **fields)
                cpu = 0.0

                def execute(tasks):
                    nonlocal cpu
                    done = list(fan_out(tasks, 1))
                    cpu += sum(s.raw.solve_time_s for _, s in done)
                    return done

                [searched] = run_search(sweep_jobs(cfg, [structure]), search, execute)
                best = searched.best[1]
                if save is not None and best is not None:
                    write_solution(best, save / f"{structure}_{seed}_{name}.json")
                rows.append({"structure": structure, "seed": seed, "variant": name, "solve_s": cpu,
                             "cost": float(best.metrics.design_cost) if best is not None else None})
                out.write_text(json.dumps(rows))
                print(structure, seed, name, rows[-1]["cost"], f"{cpu:.1f} s", flush=True)


def table(files: list[Path], references: Path, structures: list[str]) -> None:
    d = pd.concat(pd.DataFrame(json.loads(f.read_text())) for f in files)
    ref = pd.read_csv(references).set_index("structure").reference_cost
    d = d[d.structure.isin(structures or ref.index) & d.structure.isin(ref.index) & d.cost.notna()]
    d["ratio"] = d.cost / d.structure.map(ref)
    print("| variant | runs | within 1.10x | geometric mean | solver CPU |")
    print("|---|---|---|---|---|")
    for name, g in d.groupby("variant", sort=False):
        print(f"| {name} | {len(g)} | {(g.ratio <= 1.10).sum()} | {math.exp(g.ratio.map(math.log).mean()):.3f} | "
              f"{g.solve_s.sum():.0f} s |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structures", nargs="*")
    parser.add_argument("--config", type=Path, default=Path("configs/structures.yaml"))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--variant", action="append", default=[], metavar="NAME:FIELD=VALUE,...")
    parser.add_argument("--json", type=Path)
    parser.add_argument("--save", type=Path, help="write each run's best solution file into this directory")
    parser.add_argument("--table", type=Path, nargs="+", help="tabulate runs written with --json")
    parser.add_argument("--references", type=Path, default=Path("benchmarks/reference/sweep_structures_k_i.csv"))
    args = parser.parse_args()
    if args.table:
        table(args.table, args.references, args.structures)
    else:
        run(args.config, args.structures, args.seeds, args.variant or ["quick:"], args.json, args.save)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
