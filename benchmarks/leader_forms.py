"""Which kinematic forms a search's second round starts from, and where the best known design's form ranks.

A DH arm's form here is the pattern of its twists between consecutive joint axes (alpha_1 .. alpha_{n-1}, each
rounded to a multiple of pi/2: 0 parallel, 1 perpendicular): the best designs known differ from the common coarse
optima by their form as well as by their lengths. For each RUN (a directory `search_seeds.py --out DIR` keeps,
DIR/<name>/s<seed>, with a second round on new joint branches) this reads the first round's coarse optima back,
picks the second round's leaders as the search does (`optima.distinct_best`, the ``rebranch`` best distinct), and
prints the run's answer against the best design known, the answer's form, the leaders' forms, and the rank of the
best known design's form among the first round's distinct optima and among its distinct forms (each form ranked by
its cheapest optimum): where a search that picked its leaders one per form would have started from it.

    .venv/bin/python benchmarks/leader_forms.py DIR/circle_standoff/s* \
        --reference benchmarks/reference/circle_standoff_best_known.json
"""

from __future__ import annotations

import argparse
import json
import signal
from pathlib import Path

import numpy as np
import pandas as pd
from stage_solvers import solved

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.problem import problem_from_config
from designopt.solve.optima import design_forms, distinct_best, form_joints
from designopt.solve.search import Job
from designopt.tables import stage_kind

ROOT = Path(__file__).resolve().parent.parent


def forms(designs: np.ndarray, chain) -> list[str]:
    """Each design's form (`optima.design_forms` of the chain's `optima.form_joints`) as a string of 0 (parallel)
    and 1 (perpendicular)."""
    return ["".join(map(str, f)) for f in design_forms(np.atleast_2d(designs), form_joints(chain))]


def named(joints: dict[str, float], chain) -> np.ndarray:
    """A solution file's design joints (by name) as the chain's design vector."""
    return np.array([joints[j.name] for j in chain.design])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--reference", required=True, help="the best design known (a solution file)")
    args = parser.parse_args()
    reference = json.loads((ROOT / args.reference).read_text())
    known = reference["metrics"]["design_cost"]
    counts = {"optimum": 0, "form": 0}
    for run in args.runs:
        cfg = load_config(run / "config.yaml")
        search = search_from_config(cfg)
        problem = problem_from_config(cfg)
        chain = problem.chain
        (best_form,) = forms(named(reference["design_joints"], chain), chain)
        sols = [sol for task, sol in solved(run, Job("", problem), "explore", search.explore_waypoints)
                if not search.second_round(task.seed)]  # the first round's, in start order
        optima = distinct_best(sols, len(sols), search.distinct)
        ordered = forms(np.array([sols[i].raw.q_d for i in optima]), chain)
        by_form = list(dict.fromkeys(ordered))
        leaders = ordered[: search.rebranch]
        summary = pd.read_csv(run / "summary.csv")
        final = summary[(summary["stage"].astype(str).map(stage_kind) == "refine") & summary["tracks"].astype(bool)]
        answer = final.loc[final["design_cost"].idxmin()]
        answer_joints = json.loads((run / answer["solution_file"]).read_text())["design_joints"]
        (answer_form,) = forms(named(answer_joints, chain), chain)
        rank = ordered.index(best_form) if best_form in ordered else None
        form_rank = by_form.index(best_form) if best_form in by_form else None
        counts["optimum"] += rank is not None and rank < search.rebranch
        counts["form"] += form_rank is not None and form_rank < search.rebranch
        print(f"{run}: {answer['design_cost'] / known:.3f}x, answer's form {answer_form}; leaders "
              f"{' '.join(leaders)}; best known form {best_form}: optimum rank {rank}, form rank {form_rank} "
              f"(of {len(by_form)} forms)", flush=True)
    print(f"best known form among the leaders: {counts['optimum']} of {len(args.runs)} runs; among the "
          f"{search.rebranch} best forms: {counts['form']}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
