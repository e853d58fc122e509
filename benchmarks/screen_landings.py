"""Where a search finds the best design's basin: which screened candidates land in it, and whether the refine keeps it.

A default run screens its 24 best distinct coarse optima on 40 waypoints (twice, `Search.screen_mu_init`) and
refines the best 4 of those. A screen *lands* when its design cost on the 40 waypoints is within ``--within`` of
the best design known (by default 1.05x). For each RUN (a directory `search_seeds.py --out DIR` keeps,
DIR/<name>/s<seed>), this reads the screened candidates back (their coarse optima: form, `leader_forms.forms`;
rank among the run's tracking coarse optima by cost; coarse cost over the best known; round,
`Search.second_round`) and prints, over all runs, the screens and landings per form, per coarse rank, per coarse
cost and per round, and the runs where a screen landed but the answer
did not (a landing the refine lost). Nothing is solved.

    .venv/bin/python benchmarks/screen_landings.py DIR/circle_standoff/s* \
        --reference benchmarks/reference/circle_standoff_best_known.json
"""

from __future__ import annotations

import argparse
import json
import signal
from pathlib import Path

import numpy as np
import pandas as pd
from leader_forms import forms, named

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.problem import problem_from_config
from designopt.tables import stage_kind

ROOT = Path(__file__).resolve().parent.parent


def screens(run: Path, known: float, within: float) -> pd.DataFrame:
    """One row per screen solve of ``run``: its start, whether it landed, its candidate's form, coarse rank, coarse
    cost over ``known`` and round; ``answer_landed`` whether the run's answer is within ``within`` of ``known`` too."""
    cfg = load_config(run / "config.yaml")
    search = search_from_config(cfg)
    chain = problem_from_config(cfg).chain
    summary = pd.read_csv(run / "summary.csv")
    kind = summary["stage"].astype(str).map(stage_kind)
    explored = summary[kind == "explore"].set_index("seed")
    tracking = explored[explored["tracks"].astype(bool)].sort_values("design_cost", kind="stable")
    rank = {int(s): k for k, s in enumerate(tracking.index)}
    screened = summary[kind == "screen"]
    seeds = [int(s) for s in screened["seed"]]
    # only the screened candidates' coarse optima are read (their design joints), not the whole exploration
    design = {s: named(json.loads((run / explored.loc[s, "solution_file"]).read_text())["design_joints"], chain)
              for s in set(seeds)}
    form = forms(np.array([design[s] for s in seeds]), chain) if seeds else []
    final = summary[(kind == "refine") & summary["tracks"].astype(bool)]
    answer = final["design_cost"].min() if len(final) else np.inf
    return pd.DataFrame({
        "run": run.name, "start": seeds, "form": form, "rank": [rank.get(s) for s in seeds],
        "coarse": explored.loc[seeds, "design_cost"].to_numpy() / known,
        "second_round": [bool(search.second_round(s)) for s in seeds],
        "landed": (screened["design_cost"] <= within * known).to_numpy() & screened["tracks"].astype(bool).to_numpy(),
        "answer_landed": answer <= within * known})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--reference", required=True, help="the best design known (a solution file)")
    parser.add_argument("--within", type=float, default=1.05, help="a landing: screened cost <= this x the best known")
    args = parser.parse_args()
    known = json.loads((ROOT / args.reference).read_text())["metrics"]["design_cost"]
    rows = pd.concat([screens(run, known, args.within) for run in args.runs], ignore_index=True)
    print(f"{len(rows)} screens of {len(args.runs)} runs, {int(rows['landed'].sum())} landed within {args.within}x "
          f"of the best known ({known:.4g}); runs with a landing: {rows.groupby('run')['landed'].any().sum()}")
    tally = lambda by: rows.groupby(by)["landed"].agg(landed="sum", screens="size")  # noqa: E731
    print("\nper form of the candidate (most screened first):")
    print(tally("form").sort_values("screens", ascending=False).to_string())
    print("\nper coarse rank of the candidate (among the run's tracking coarse optima, 0 the cheapest):")
    print(tally(pd.cut(rows["rank"], [-1, 3, 7, 15, 31, 10**6], labels=["0-3", "4-7", "8-15", "16-31", "32+"]))
          .to_string())
    print("\nper coarse cost of the candidate (its exploration optimum's design cost / the best known):")
    print(tally(pd.cut(rows["coarse"], [0, 1.1, 1.3, 1.6, 2, 3, np.inf])).to_string())
    print("\nper round of the exploration (True: the second, on new joint branches):")
    print(tally("second_round").to_string())
    # per candidate (any of its screens landed), ranked by coarse cost within its run and form, the landing forms only
    cand = rows.groupby(["run", "start"], as_index=False).agg(form=("form", "first"), rank=("rank", "first"),
                                                              landed=("landed", "any"))
    landing = cand.groupby("form")["landed"].sum()
    cand = cand[cand["form"].isin(landing[landing > 2].index)].copy()
    cand["within"] = cand.groupby(["run", "form"])["rank"].rank(method="first") - 1
    print(f"\ncandidates of the forms that landed more than twice ({', '.join(sorted(set(cand['form'])))}), per rank "
          "within their form and run (0 the cheapest):")
    print(cand.groupby(pd.cut(cand["within"], [-1, 0, 1, 3, 7, 10**6], labels=["0", "1", "2-3", "4-7", "8+"]))[
        "landed"].agg(landed="sum", candidates="size").to_string())
    lost = rows.groupby("run").agg(landed=("landed", "any"), answer=("answer_landed", "first"))
    lost = lost[lost["landed"] & ~lost["answer"]]
    print(f"\nruns whose screen landed but whose answer did not: {len(lost)} ({', '.join(lost.index) or 'none'})")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
