"""Would a sweep that screens fewer coarse optima refine the same ones? Read back from finished sweeps, nothing solved.

The `quick` preset screens each structure's ``screen`` best distinct coarse optima on ``screen_waypoints`` and
refines the ``refine`` best of those (`coarse_to_fine.plan`). A smaller screen takes the first K of the same
candidates (the cheapest coarse optima), so its screen solves are a subset of the run's, and its refine
candidates are `optima.distinct_best` of that subset. For each RUN (a `designopt sweep-structures` run directory)
and each K of ``--screen``, this counts per structure: the same refine candidates (the structure's refine then the
same solves), and whether the candidate of the structure's best refine is still among them (its refine then no
worse). What the later stages (neighbour starts, reflections) would give, and the refines of candidates that only
the smaller screen picks, need solving: a replay (`sweep-structures --resume` of a copy with the exploration's
rows only, in a worktree with the preset changed; docs/decisions.md, "Search"). Also printed: the screen's solver
time and how many of its solves reached the iteration cap.

    .venv/bin/python benchmarks/sweep_screen_subset.py results/structures/RUN --screen 6 8 10
"""

from __future__ import annotations

import argparse
import signal
from pathlib import Path

import pandas as pd

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.experiments.sweep import sweep_jobs
from designopt.solution import read_solution_for
from designopt.solve.optima import distinct_best
from designopt.solve.strategies.coarse_to_fine import coarse_problem
from designopt.tables import stage_kind


def refine_candidates(screened: list, ranked: list[int], k: int, count: int, tol: float) -> set[int]:
    """Start numbers of the refine's candidates when only the first ``k`` of the screen's candidates (``ranked``:
    start numbers, cheapest coarse optimum first) are screened; ``screened``: (start, solution) in start order, as
    the search passes them on."""
    first = set(ranked[:k])
    kept = [(s, sol) for s, sol in screened if s in first]
    return {kept[i][0] for i in distinct_best([sol for _, sol in kept], count, tol)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--screen", nargs="+", type=int, default=[6, 8, 10], help="candidates screened (K)")
    args = parser.parse_args()
    for run in args.runs:
        cfg = load_config(run / "config.yaml")
        search = search_from_config(cfg)
        summary = pd.read_csv(run / "summary.csv")
        kind = summary["stage"].astype(str).map(stage_kind)
        screen_rows = summary[kind == "screen"]
        capped = int((screen_rows["iterations"] >= search.screen_max_iter).sum())
        print(f"{run}: screen {len(screen_rows)} solves, {screen_rows['solve_time_s'].sum():.0f} s of solver time, "
              f"{capped} at the {search.screen_max_iter}-iteration cap")
        jobs = {job.problem.chain.structure: job for job in sweep_jobs(cfg, sorted(set(screen_rows["structure"])))}
        same = {k: 0 for k in args.screen}
        kept = {k: 0 for k in args.screen}
        lost: dict[int, list[str]] = {k: [] for k in args.screen}
        n = 0
        for structure, rows in screen_rows.groupby("structure"):
            job = jobs[structure]
            explore = summary[(kind == "explore") & (summary["structure"] == structure)].set_index("seed")
            rows = rows.assign(coarse=explore.loc[rows["seed"], "design_cost"].to_numpy())
            ranked = [int(s) for s in rows.sort_values(["coarse", "seed"], kind="stable")["seed"]]
            rows = rows.sort_values("seed", kind="stable")
            problem = coarse_problem(job.problem, search.screen_waypoints)
            screened = [(int(s), read_solution_for(problem, job.transcription, run / f))
                        for s, f in zip(rows["seed"], rows["solution_file"], strict=True)]
            refines = summary[(kind == "refine") & (summary["structure"] == structure)]
            full = refine_candidates(screened, ranked, len(ranked), search.refine, search.distinct)
            if full != {int(s) for s in refines["seed"]}:
                raise SystemExit(f"{run} {structure}: the refine's candidates are not read back as the search picked")
            tracking = refines[refines["tracks"].astype(bool)]
            answer = int(tracking.loc[tracking["design_cost"].idxmin(), "seed"]) if len(tracking) else None
            n += 1
            for k in args.screen:
                picked = refine_candidates(screened, ranked, k, search.refine, search.distinct)
                same[k] += picked == full
                if answer is None or answer in picked:
                    kept[k] += 1
                else:
                    lost[k].append(structure)
        for k in args.screen:
            print(f"  screen {k}: the same refine on {same[k]} of {n} structures, the refine's best candidate kept on "
                  f"{kept[k]}; lost on {', '.join(lost[k]) or 'none'}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
