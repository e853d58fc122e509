"""Which of a run's screen candidates are the same arm placed elsewhere, and what the screen takes without them.

For each RUN (a directory `search_seeds.py --out DIR` keeps, DIR/<name>/s<seed>) this reads the exploration's
coarse optima back (both rounds), picks the screen's candidates (`optima.distinct_best`, its config's search) with
designs compared joint by joint (``same_arm_cost`` None) and with ``--same-arm-cost`` (`Search.same_arm_cost`: two
optima whose arms lie within ``distinct`` and whose costs within that fraction of the cheaper's are one), and
prints: how many of the joint-by-joint candidates repeat a cheaper candidate's arm at such a cost (copies), the
start numbers the merge brings in and leaves out, and the rank of the candidate the run's answer came from in both
lists (an answer from a reflect start is not traced back). Run on a run of a search that merged already, the first
list is what it would have screened without.

    .venv/bin/python benchmarks/same_arm.py DIR/circle_standoff/s* --same-arm-cost 0.002
"""

from __future__ import annotations

import argparse
import signal
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
from stage_solvers import solved

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.problem import problem_from_config
from designopt.solve.optima import arm_joints, cluster_designs, distinct_best
from designopt.solve.search import Job
from designopt.tables import stage_kind


def copies(sols: list, picked: list[int], search, same_arm_cost: float) -> int:
    """How many of the ``picked`` solutions (distinct designs, cheapest first) the merge of ``same_arm_cost`` joins
    to a cheaper one (`optima.cluster_designs`)."""
    if not picked:
        return 0
    chain = sols[picked[0]].problem.chain
    angle = np.array([j.kind == "angle" for j in chain.design], dtype=bool)
    labels = cluster_designs(np.array([sols[i].raw.q_d for i in picked]),
                             np.array([sols[i].metrics.design_cost for i in picked]), angle, search.distinct,
                             arm_joints(chain), same_arm_cost)
    return len(picked) - len(set(labels))


def rank(origin: int | None, ranked: list[int], starts: list[int]) -> str:
    """The answer's start number ``origin`` in ``ranked``: its rank, "out", or "not traced" when it was no
    exploration start (a reflect start)."""
    if origin not in starts:
        return "not traced"
    return str(ranked.index(origin)) if origin in ranked else "out"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--same-arm-cost", type=float, default=0.002, help="the fraction (Search.same_arm_cost)")
    args = parser.parse_args()
    for run in args.runs:
        cfg = load_config(run / "config.yaml")
        search = search_from_config(cfg)
        problem = problem_from_config(cfg)
        found = solved(run, Job("", problem), "explore", search.explore_waypoints)
        starts = [task.seed for task, _ in found]
        sols = [sol for _, sol in found]
        merged = replace(search, same_arm_cost=args.same_arm_cost)
        before = [starts[i] for i in distinct_best(sols, search.screen, search.distinct)]
        after = [starts[i] for i in distinct_best(sols, merged.screen, merged.distinct,
                                                  same_arm_cost=merged.same_arm_cost)]
        picked = [starts.index(s) for s in before]
        summary = pd.read_csv(run / "summary.csv")
        final = summary[summary["stage"].astype(str).map(stage_kind).isin(["refine", "reflect"])
                        & summary["tracks"].astype(bool)]
        origin = int(final.loc[final["design_cost"].idxmin(), "seed"]) if len(final) else None
        print(f"{run}: {copies(sols, picked, search, args.same_arm_cost)} of {len(before)} candidates copies; "
              f"merged in {[s for s in after if s not in before]}, out {[s for s in before if s not in after]}; "
              f"answer's candidate rank {rank(origin, before, starts)} -> {rank(origin, after, starts)}", flush=True)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
