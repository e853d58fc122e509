"""Claims C4-C6 side by side over sweep runs of different search seeds: a markdown table.

    .venv/bin/python benchmarks/sweep_seeds_table.py RUN0/table.csv RUN1/table.csv [...]

Each argument is the table.csv of one `designopt sweep-structures` run (one search seed); prints the best 6-DOF
cost per number of prismatic joints, the best structure per number of joints, the best 3R3P and PPPRRR against
it, how many 3R3P are within 2 % of the
best, PPP's rank among 3-DOF structures, and the spread (max/min) between runs.
"""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

import pandas as pd


def fmt(x) -> str:
    return f"{x:.4g}" if isinstance(x, float) else str(x)


def line(name: str, values: list) -> None:
    spread = f" {max(values) / min(values):.2f}x |" if all(isinstance(v, float) for v in values) else " |"
    print(f"| {name} | " + " | ".join(fmt(v) for v in values) + " |" + spread)


def main(paths: list[str]) -> None:
    missing = [p for p in paths if not Path(p).is_file()]
    if missing:
        print(f"error: {missing[0]}: no such file (the table.csv of a sweep run)", file=sys.stderr)
        sys.exit(2)
    tables = [pd.read_csv(p) for p in paths]
    tables = [t[t.design_cost.notna()] for t in tables]
    print("| | " + " | ".join(f"seed {i}" for i in range(len(tables))) + " | spread (max/min) |")
    print("|---" * (len(tables) + 2) + "|")
    for k in range(7):
        line(f"best 6-DOF, {k} P", [float(t[(t.dof == 6) & (t.n_prismatic == k)].design_cost.min()) for t in tables])
    for d in (2, 3, 4, 5, 6):
        line(f"best {d}-DOF", [float(t[t.dof == d].design_cost.min()) for t in tables])
        line(f"best {d}-DOF structure", [t.loc[t[t.dof == d].design_cost.idxmin()].structure for t in tables])
    three = [t[(t.dof == 6) & (t.n_prismatic == 3)].sort_values("design_cost") for t in tables]
    line("best 3R3P", [f"{r.iloc[0].structure} {fmt(float(r.iloc[0].design_cost))}" for r in three])
    line("PPPRRR / best 3R3P", [float(r[r.structure == "PPPRRR"].design_cost.min() / r.iloc[0].design_cost)
                                for r in three])
    line("3R3P within 2 % of the best 3R3P", [int((r.design_cost <= 1.02 * r.iloc[0].design_cost).sum())
                                              for r in three])
    line("PPP rank among 3-DOF", [list(t[t.dof == 3].sort_values("design_cost").structure).index("PPP") + 1
                                  for t in tables])
    line("structures that track", [len(t) for t in tables])


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly, as a shell tool does
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("tables", nargs="+", help="table.csv of each sweep run")
    main(parser.parse_args().tables)
