"""Is the sweep's best per structure close to what a large budget finds?

For each named structure, a run of the sweep's config with that structure and a large search budget (default:
240 coarse starts, the best 8 distinct optima refined, another seed than the sweep's), then the ratio of the
sweep's best (its table.csv) to that reference. A ratio below 1 means the sweep found the better design.

    .venv/bin/python benchmarks/sweep_reference.py results/structures/<run> RRR RPR RRRR ... [--starts 240]
    .venv/bin/python benchmarks/sweep_reference.py results/structures/<run> --references FILE.csv
    .venv/bin/python benchmarks/sweep_reference.py results/structures/<run> RRPRRR --seed 100 --keep DIR

``--save FILE.csv`` keeps the large-budget costs (structure, reference_cost, seconds); ``--references FILE.csv``
compares a sweep with kept ones instead of searching again (the structures: the file's), keeping per structure
the lower of a kept reference and the sweep's own best when ``--save`` names the same file. ``--keep DIR`` writes
each large-budget run's directory (its solution files, `python -m designopt.verify` re-checks them) under DIR
instead of a temporary directory.
"""

from __future__ import annotations

import argparse
import signal
import tempfile
import time
from contextlib import nullcontext
from dataclasses import replace
from pathlib import Path

import pandas as pd
import yaml

from designopt.config import parse_config
from designopt.experiments.adapters import search_from_config, structure_config
from designopt.experiments.run import run_experiment


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sweep", help="a sweep's run directory (with table.csv and config.yaml)")
    parser.add_argument("structures", nargs="*")
    parser.add_argument("--references", type=Path, help="kept large-budget costs to compare with (no search)")
    parser.add_argument("--save", type=Path, help="write the large-budget costs here")
    parser.add_argument("--starts", type=int, default=240)
    parser.add_argument("--refine", type=int, default=8)
    parser.add_argument("--seed", type=int, default=100)
    parser.add_argument("--keep", type=Path, help="write each large-budget run's directory here (default: dropped)")
    args = parser.parse_args()
    sweep = Path(args.sweep)
    table = pd.read_csv(sweep / "table.csv").set_index("structure")
    base = parse_config(yaml.safe_load((sweep / "config.yaml").read_text()), sweep / "config.yaml", sweep)
    search = replace(search_from_config(base), starts=args.starts, refine=args.refine, seed=args.seed)
    kept = pd.read_csv(args.references).set_index("structure") if args.references else None
    structures = args.structures or (list(kept.index) if kept is not None else [])
    if not structures:
        parser.error("name the structures, or --references")
    ratios, rows = [], []
    with nullcontext(args.keep) if args.keep else tempfile.TemporaryDirectory() as tmp:
        for structure in structures:
            t0 = time.perf_counter()
            if kept is not None:
                best = float(kept.loc[structure, "reference_cost"])
            else:
                result = run_experiment(structure_config(base, structure), Path(tmp), structure, figures=False,
                                        search=search)
                best = result.best.metrics.design_cost
            swept = float(table.loc[structure, "design_cost"])
            ratios.append(swept / best)
            rows.append({"structure": structure, "reference_cost": min(best, swept) if kept is not None else best,
                         "seconds": round(time.perf_counter() - t0, 1)})
            print(f"{structure:7s} sweep {swept:.6g}  large budget {best:.6g}  ratio {swept / best:.3f}  "
                  f"({time.perf_counter() - t0:.0f} s)", flush=True)
    print(f"within 1.10x: {sum(r <= 1.10 for r in ratios)} of {len(ratios)}; worst {max(ratios):.3f}x")
    if args.save:
        pd.DataFrame(rows).to_csv(args.save, index=False)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
