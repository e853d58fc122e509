"""Is the sweep's best per structure close to what a large budget finds?

For each named structure, a run of the sweep's config with that structure and a large search budget (default:
240 coarse starts, the best 8 distinct optima refined, another seed than the sweep's), then the ratio of the
sweep's best (its table.csv) to that reference. A ratio below 1 means the sweep found the better design.

    .venv/bin/python benchmarks/sweep_reference.py results/structures/<run> RRR RPR RRRR ... [--starts 240]
"""

from __future__ import annotations

import argparse
import tempfile
import time
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
    parser.add_argument("structures", nargs="+")
    parser.add_argument("--starts", type=int, default=240)
    parser.add_argument("--refine", type=int, default=8)
    parser.add_argument("--seed", type=int, default=100)
    args = parser.parse_args()
    sweep = Path(args.sweep)
    table = pd.read_csv(sweep / "table.csv").set_index("structure")
    base = parse_config(yaml.safe_load((sweep / "config.yaml").read_text()), sweep / "config.yaml", sweep)
    search = replace(search_from_config(base), starts=args.starts, refine=args.refine, seed=args.seed)
    ratios = []
    with tempfile.TemporaryDirectory() as tmp:
        for structure in args.structures:
            t0 = time.perf_counter()
            result = run_experiment(structure_config(base, structure), Path(tmp), structure, figures=False,
                                    search=search)
            best = result.best.metrics.design_cost
            swept = float(table.loc[structure, "design_cost"])
            ratios.append(swept / best)
            print(f"{structure:7s} sweep {swept:.6g}  large budget {best:.6g}  ratio {swept / best:.3f}  "
                  f"({time.perf_counter() - t0:.0f} s)", flush=True)
    print(f"within 1.10x: {sum(r <= 1.10 for r in ratios)} of {len(ratios)}; worst {max(ratios):.3f}x")


if __name__ == "__main__":
    main()
