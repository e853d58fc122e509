"""What a variant's runs cost against the base runs they were replayed from, by stage, whatever the machine's load.

For the runs of BASE (a directory `search_seeds.py --out DIR` keeps, DIR/<name>/s<seed>) and the same runs in
VARIANT (`replay_stages.py --out`), this prints per stage (the exploration's two rounds apart,
`Search.second_round`) the solves and iterations of both, and the variant's solve time estimated as its iterations
at the base's own time per iteration in each stage: on a shared machine the solve times of two runs made at
different moments are not comparable, their iterations are, and a stage's time per iteration does not depend on
the variant when its problems are the same.

    .venv/bin/python benchmarks/stage_cost.py DIR/milling REPLAY/milling
"""

from __future__ import annotations

import argparse
import signal
from pathlib import Path

import pandas as pd

from designopt.experiments.runs import search_of_run
from designopt.tables import is_coarse


def stages(run: Path) -> pd.DataFrame:
    """A run's solves, iterations and solve time (s) per stage; ``explore2`` the exploration's second round."""
    summary = pd.read_csv(run / "summary.csv")
    search = search_of_run(run)
    stage = summary["stage"].astype(str).where(
        (summary["stage"] != "explore") | ~search.second_round(summary["seed"]), "explore2")
    return summary.groupby(stage).agg(solves=("iterations", "size"), iterations=("iterations", "sum"),
                                      seconds=("solve_time_s", "sum"))


def common_runs(base: Path, variant: Path) -> list[str]:
    """The runs (s<seed>) both directories hold."""
    return sorted(p.name for p in base.glob("s*") if (variant / p.name / "summary.csv").exists())


def compared(base: Path, variant: Path, runs: list[str]) -> tuple[pd.DataFrame, float]:
    """Per stage, the solves and iterations of ``runs`` in ``base`` and ``variant`` and the base's ms per
    iteration; and the variant's solve time estimated at those times per iteration, over the base's. A full-path
    stage the base does not have (a variant's new one, e.g. ``reflect``) is priced at the base's refine (the same
    problem, solved warm); a coarse one (e.g. ``prescreen``) at the variant's own time per iteration in it, times
    the base's over the variant's in the screen (both solved the screen's problems: the machine's load between
    the two runs taken out)."""
    b, v = (pd.concat([stages(d / r) for r in runs]).groupby(level=0).sum() for d in (base, variant))
    new = [s for s in v.index if s not in b.index]
    index = list(b.index) + new
    b, v = b.reindex(index, fill_value=0), v.reindex(index, fill_value=0)
    own = v["seconds"] / v["iterations"]
    per_iteration = (b["seconds"] / b["iterations"]).where(~b.index.isin(new), b.at["refine", "seconds"]
                                                           / b.at["refine", "iterations"])
    coarse = [s for s in new if is_coarse(s)]
    if coarse:
        if "screen" not in b.index or not (b.at["screen", "iterations"] and v.at["screen", "iterations"]):
            raise ValueError(f"both need a screen to price the variant's {coarse} by")
        load = (b.at["screen", "seconds"] / b.at["screen", "iterations"]) / own["screen"]
        per_iteration[coarse] = own[coarse] * load
    table = pd.DataFrame({"solves": b["solves"], "variant solves": v["solves"], "iterations": b["iterations"],
                          "variant iterations": v["iterations"], "ms per iteration": 1e3 * per_iteration})
    return table, float((v["iterations"] * per_iteration).sum() / b["seconds"].sum())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base", type=Path)
    parser.add_argument("variant", type=Path)
    args = parser.parse_args()
    runs = common_runs(args.base, args.variant)
    table, ratio = compared(args.base, args.variant, runs)
    print(f"{len(runs)} runs")
    print(table.to_string(float_format=lambda v: f"{v:.2f}"))
    print(f"variant's solve time estimated at the base's time per iteration: {ratio:.3f}x the base's")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
