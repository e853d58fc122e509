"""Would a cheaper second screen refine the same candidates? Read back from finished runs, nothing solved.

A default run screens its 24 best distinct coarse optima twice (`Search.screen_mu_init`: from the warm start's
barrier and from 1e-6) and refines the best distinct of them, each ranked by its better screen
(`coarse_to_fine.better_pass`). For each RUN (a directory `search_seeds.py --out DIR` keeps, DIR/<name>/s<seed>)
and each K of ``--second``, this takes the second screen of the K candidates the screen puts first (the cheapest
coarse optima) and only the first screen of the rest, picks the refine's candidates as the search does
(`optima.distinct_best`), and counts the runs where they are the same candidates from the same passes (the answer
then the same), and the runs where the candidate and pass the answer was refined from is still among them (the
answer then no worse). A solve is deterministic given its start, so both counts are exact; what a run whose
candidates change would answer is `replay_stages.py`'s (a worktree with the variant as default).

    .venv/bin/python benchmarks/screen_subset.py DIR/milling/s13* --second 8 12 16
"""

from __future__ import annotations

import argparse
import signal
from pathlib import Path

import pandas as pd
from stage_solvers import solved

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.problem import problem_from_config
from designopt.solve.optima import distinct_best
from designopt.solve.search import Job
from designopt.solve.strategies.coarse_to_fine import better_pass, numbered_stage
from designopt.tables import stage_kind


def refined(pairs: list, order: list[int], k: int, count: int, tol: float) -> set[tuple[int, str]]:
    """The (start, pass) the refine starts from when only the first ``k`` candidates of ``order`` (start numbers)
    have their later screens; ``pairs``: (task with seed and stage, solution) of every screen pass."""
    second = set(order[:k])
    kept = [(t, s) for t, s in pairs if t.stage == numbered_stage("screen", 0) or t.seed in second]
    found = better_pass(kept)
    return {(found[i][0].seed, found[i][0].stage) for i in distinct_best([s for _, s in found], count, tol)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--second", nargs="+", type=int, default=[8, 12, 16],
                        help="how many candidates get the later screens")
    args = parser.parse_args()
    same = {k: 0 for k in args.second}
    answer_kept = {k: 0 for k in args.second}
    for run in args.runs:
        cfg = load_config(run / "config.yaml")
        search = search_from_config(cfg)
        job = Job("", problem_from_config(cfg))
        summary = pd.read_csv(run / "summary.csv")
        kind = summary["stage"].astype(str).map(stage_kind)
        explored = summary[kind == "explore"].set_index("seed")["design_cost"]
        pairs = solved(run, job, "screen", search.screen_waypoints)
        order = sorted({t.seed for t, _ in pairs}, key=lambda s: explored[s])  # the screen's candidate order
        full = refined(pairs, order, len(order), search.refine, search.distinct)
        refines = summary[kind == "refine"]
        if {s for s, _ in full} != {int(s) for s in refines["seed"]}:
            raise SystemExit(f"{run}: the refine's candidates are not read back as the search picked them")
        best = refines[refines["tracks"].astype(bool)]
        answer_seed = int(best.loc[best["design_cost"].idxmin(), "seed"]) if len(best) else None
        answer = next(((s, p) for s, p in full if s == answer_seed), None)
        line = []
        for k in args.second:
            picked = refined(pairs, order, k, search.refine, search.distinct)
            same[k] += picked == full
            answer_kept[k] += answer in picked
            lost = "" if answer in picked else ", answer lost"
            line.append(f"K={k}: {'same' if picked == full else 'changed'}{lost}")
        print(f"{run}: " + "; ".join(line), flush=True)
    for k in args.second:
        print(f"second screen for the first {k}: the same refine in {same[k]} of {len(args.runs)} runs, the answer's "
              f"candidate kept in {answer_kept[k]}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
