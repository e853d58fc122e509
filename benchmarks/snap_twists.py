"""Do a run's answers sit off the lattice of twists because a solve stopped short? Each answer's twists snapped to
the nearest multiple of pi/2 and solved warm.

For each RUN (a directory `search_seeds.py --out DIR` keeps, DIR/<name>/s<seed>) this takes the best ``--top``
distinct full-path answers (refine and reflect stages), sets every twist (``linkN.alpha``) to the nearest multiple
of pi/2 within its bounds, moves each waypoint onto the path with that design (`initial_guess.projected`) and solves
the full path warm from barrier ``--mu`` (as the reflect step does). Prints each answer's cost before and after
against the best design known, how far its twists moved, and the runs' answers with the snapped solves added.

    .venv/bin/python benchmarks/snap_twists.py DIR/circle_standoff/s* \
        --reference benchmarks/reference/circle_standoff_best_known.json
"""

from __future__ import annotations

import argparse
import json
import signal
import time
from pathlib import Path

import numpy as np
import pandas as pd

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.initial_guess import projected
from designopt.modular import distinct_optima
from designopt.problem import problem_from_config
from designopt.solution import read_solution_for
from designopt.solve.local import solve_guess
from designopt.transcriptions import Collocation
from designopt.transcriptions.base import InitialGuess

ROOT = Path(__file__).resolve().parent.parent


def snapped(chain, q_d: np.ndarray) -> tuple[np.ndarray, float]:
    """The design vector with every twist at its nearest multiple of pi/2 (within its bounds), and the largest move
    (rad)."""
    q = np.array(q_d, dtype=float)
    moved = 0.0
    for k, joint in enumerate(chain.design):
        if joint.name.endswith(".alpha"):
            lattice = float(np.clip(np.round(q[k] / (np.pi / 2)) * (np.pi / 2), joint.lower, joint.upper))
            moved = max(moved, abs(lattice - q[k]))
            q[k] = lattice
    return q, moved


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--reference", required=True, help="the best design known (a solution file)")
    parser.add_argument("--top", type=int, default=1, help="distinct answers per run (costs 0.1 %% apart)")
    parser.add_argument("--mu", type=float, default=1e-6, help="the warm solve's initial barrier")
    args = parser.parse_args()
    known = json.loads((ROOT / args.reference).read_text())["metrics"]["design_cost"]
    rows = []
    for run in args.runs:
        cfg = load_config(run / "config.yaml")
        problem = problem_from_config(cfg)
        profile = search_from_config(cfg).profile.warmed().with_options(**{"ipopt.mu_init": args.mu})
        summary = pd.read_csv(run / "summary.csv")
        final = summary[summary.tracks & summary.stage.str.startswith(("refine", "reflect"))]
        for i in distinct_optima(list(final.design_cost.items()), args.top, rel_tol=1e-3):
            row = final.loc[i]
            sol = read_solution_for(problem, Collocation(), run / row.solution_file)
            q_d, moved = snapped(problem.chain, sol.raw.q_d)
            t = problem.toolpath.t
            after, seconds = np.nan, 0.0
            if moved >= 1e-3:
                t0 = time.perf_counter()
                guess = InitialGuess(q_d=q_d, Q=projected(problem, q_d, sol.sample(t)),
                                     V=sol.sample_velocity(t), seed=0)
                new = solve_guess(problem, Collocation(), profile, guess)
                after = new.metrics.design_cost / known if new.metrics.tracks else np.nan
                seconds = time.perf_counter() - t0
            rows.append((run.name, row.stage, row.design_cost / known, after, moved, seconds))
            print(f"{run}: {row.stage} {row.design_cost / known:.3f} -> {after:.3f}x the best known "
                  f"(twists moved up to {moved:.3f} rad, {seconds:.1f} s)", flush=True)
    df = pd.DataFrame(rows, columns=["run", "stage", "before", "after", "moved", "seconds"])
    before = df.groupby("run").before.min()
    with_snap = df.assign(best=np.fmin(df.before, df.after.fillna(np.inf))).groupby("run").best.min()
    print("answers:          ", np.round(np.sort(before.values), 3))
    print("with snapped ones:", np.round(np.sort(with_snap.values), 3), f"({df.seconds.sum():.0f} s of solves)")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
