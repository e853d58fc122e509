"""Where a finished run's refines end against what their screen found: does the lift to the full path keep a
screened optimum's cost?

    .venv/bin/python benchmarks/refine_loss.py RUN [RUN ...] --config configs/physical_stiffness.yaml \
        --reference 1.7428669603586052e-12

RUN: a run directory of the default search (its summary.csv and solutions/), e.g. the per-seed directories
`search_seeds.py --out DIR` keeps (DIR/<name>/s<seed>). For every refine: its screened start's cost (40 waypoints),
the lifted start on the full path (`designopt.solve.starts.lifted_guess`: design as screened, waypoints moved onto
the path by IK) -- its cost, whether it tracks, and its largest joint step over what the velocity limits allow
(v_max h) -- and where the refine ended, all over ``--reference`` (the best design known). Then per run: the best
screened cost against the run's answer.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from designopt.config import load_config
from designopt.evaluation import evaluate
from designopt.problem import problem_from_config
from designopt.solution import read_solution_for
from designopt.solve.starts import lifted_guess
from designopt.solve.strategies.coarse_to_fine import coarse_problem
from designopt.transcriptions import Collocation
from designopt.transcriptions.trajectory import trajectory


def refines(run: Path, full, screen_waypoints: int, ref: float) -> list[dict]:
    d = pd.read_csv(run / "summary.csv")
    screened = d[d.stage == "screen"].set_index("seed")
    rows = []
    for _, r in d[d.stage == "refine"].iterrows():
        path = next(run.glob(f"solutions/screen-*-s{r.seed}.json"), None)
        if path is None:  # a refine from a coarse optimum (the path had no more waypoints than the screen's)
            continue
        sol = read_solution_for(coarse_problem(full, screen_waypoints), Collocation(), path)
        guess = lifted_guess(full, sol)
        start = evaluate(full, guess.q_d, trajectory(full.toolpath.t, guess.Q, guess.V))
        rows.append({"run": run.name, "seed": int(r.seed), "screen": screened.loc[r.seed, "design_cost"] / ref,
                     "lifted_start": start.design_cost / ref, "start_tracks": start.tracks,
                     "step_over_limit": float((np.abs(np.diff(guess.Q, axis=0)) / full.max_steps).max()),
                     "refine": r.design_cost / ref, "refine_tracks": bool(r.tracks)})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--config", default="configs/milling.yaml")
    parser.add_argument("--reference", type=float, required=True, help="the best design cost known (full path)")
    parser.add_argument("--screen-waypoints", type=int, default=40)
    args = parser.parse_args()
    full = problem_from_config(load_config(args.config))
    table = pd.DataFrame([row for run in args.runs for row in refines(run, full, args.screen_waypoints,
                                                                      args.reference)])
    table["loss"] = table.refine / table.screen
    print(table.drop(columns="tracked", errors="ignore").to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    lost, over = table.loss > 1.2, table.step_over_limit > 1.001
    print(f"\n{len(table)} refines: {int(lost.sum())} end above 1.2x their screened cost; lifted starts that track "
          f"{int(table.start_tracks.sum())}, with a step over the velocity limits {int(over.sum())}")
    table["tracked"] = table.refine.where(table.refine_tracks, np.inf)
    per_run = table.groupby("run").agg(screened=("screen", "min"), answer=("tracked", "min"))
    above = int((per_run.answer > 1.1 * per_run.screened).sum())
    print(f"runs whose answer is above 1.1x their best screened cost: {above} of {len(per_run)}")


if __name__ == "__main__":
    main()
