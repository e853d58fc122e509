"""Are a finished run's refine starts trajectories? Each refined screen optimum is lifted to the full path again
(`designopt.solve.starts.lifted_guess`, with this checkout's code) and its start checked against the full NLP's
own constraints, solving nothing:

    beyond reach   steps between neighbouring waypoints longer than the joints' velocity limits allow in the
                   time between them (no trajectory the collocation accepts makes them)
    midpoint v     collocation midpoints whose velocity bound is violated (rows of the NLP's g)
    off the path   waypoints with a per-waypoint row (tracking) violated by more than 1e-6
    clearance      knots and collocation midpoints inside an obstacle (a cell's rows of g, if it has a cell)

    .venv/bin/python benchmarks/lift_check.py RUN_DIR --config CONFIG

RUN_DIR is a `designopt run` directory of a search that screened (summary.csv has screen and refine rows), CONFIG
the config it ran.
"""

from __future__ import annotations

import argparse
import signal
from pathlib import Path

import casadi as ca
import numpy as np
import pandas as pd

from designopt.config import load_config
from designopt.problem import problem_from_config
from designopt.solution import read_solution_for
from designopt.solve.starts import lifted_guess
from designopt.solve.strategies.coarse_to_fine import coarse_problem
from designopt.transcriptions import Collocation
from designopt.transcriptions.collocation import CollocationNLP


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("--config", type=Path, required=True)
    parser.add_argument("--screen-waypoints", type=int, default=40)
    args = parser.parse_args()
    full = problem_from_config(load_config(args.config))
    screen = coarse_problem(full, args.screen_waypoints)
    built = CollocationNLP(full, Collocation())
    nlp = built.nlp
    g_of = ca.Function("g", [nlp.x], [nlp.g])
    n_m, N = full.chain.n_moving, full.toolpath.n
    n_terms = nlp.blocks[0].mu_index.size  # the per-waypoint rows come first (collocation.py), then q_mid, v_mid
    v_mid = slice(n_terms + n_m * (N - 1), n_terms + 2 * n_m * (N - 1))
    cell = [(name, b.mu_index) for name, b in zip(("knots", "midpoints"), nlp.blocks[1:3], strict=False)]
    runs = pd.read_csv(args.run / "summary.csv")
    print(f"{N} waypoints; per refined start: steps beyond reach (of {N - 1}), midpoints over their velocity bound, "
          "waypoints off the path" + (", knots / midpoints inside an obstacle" if cell else ""))
    for seed in runs[runs.stage == "refine"].seed:
        row = runs[(runs.stage == "screen") & (runs.seed == seed)].iloc[0]
        guess = lifted_guess(full, read_solution_for(screen, Collocation(), args.run / row.solution_file))
        x = built.pack(guess)
        g = np.asarray(g_of(x)).ravel()
        over = np.maximum(np.maximum(nlp.lbg - g, g - nlp.ubg), 0.0) > 1e-6  # IK stops at ~1e-7
        Q = np.asarray(guess.Q)
        reach = full.velocity_limits[None, :] * full.toolpath.h[:, None]
        line = (f"seed {seed}: {int(np.any(np.abs(np.diff(Q, axis=0)) > reach, axis=1).sum())} beyond reach, "
                f"{int(over[v_mid].reshape(N - 1, n_m).any(axis=1).sum())} midpoints over v, "
                f"{int(over[nlp.blocks[0].mu_index].any(axis=1).sum())} off the path")
        for name, rows in cell:
            line += f", {int(over[rows].any(axis=1).sum())} {name} inside"
        print(line, flush=True)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
