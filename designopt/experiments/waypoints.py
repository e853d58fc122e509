"""Waypoint study: how the number of waypoints N changes design cost, tracking and solve time (TO, combined).

Hard tracking is exact at the waypoints; what N controls is the path *between* them. The trajectory is
the C^1 cubic Hermite interpolant, so the tracking error is measured at every interval midpoint against
the path sampled there.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.continuous import case_config
from designopt.experiments.run import multistart_from_config, transcription_from_config
from designopt.experiments.tasks import multistart_tasks, solve_tasks
from designopt.kinematics.chain import placement_pose, tool_pose
from designopt.multistart import best_solution
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution
from designopt.transcriptions.collocation import hermite_midpoint


def midpoint_errors(sol: Solution, cfg: Config, base_dir: Path) -> np.ndarray:
    """Position error (m) of the interpolated trajectory at every interval midpoint."""
    N = sol.problem.toolpath.n
    fine = problem_from_config(cfg.model_copy(update={"toolpath": cfg.toolpath.model_copy(
        update={"waypoints": 2 * N - 1})}), base_dir).toolpath
    Q, V, h = sol.raw.Q, sol.raw.V, sol.problem.toolpath.dt
    Q_mid, _ = hermite_midpoint(Q[:-1], V[:-1], Q[1:], V[1:], h)
    chain = sol.chain
    T_BW = placement_pose(chain, Q[0], np.zeros(0))
    errors = []
    for k, q in enumerate(Q_mid):
        s_B = T_BW[:3, :3] @ fine.points_W[2 * k + 1] + T_BW[:3, 3]
        errors.append(np.linalg.norm(tool_pose(chain, q, np.zeros(0))[:3, 3] - s_B))
    return np.array(errors)


def run_waypoint_study(cfg: Config, base_dir: Path, out_root: Path, run_name: str | None = None,
                       on_solution: Callable[[int, Solution], None] | None = None,
                       figures: bool = True, resume: bool = False) -> pd.DataFrame:
    base = case_config(cfg, "combined")
    problem_from_config(base, base_dir)  # bad input stops here, before a run directory exists
    run = RunDirectory.create(out_root, "waypoints", run_name, resume)
    run.write_config(dump_config(cfg))
    rows = []
    for n in cfg.continuous.waypoint_study:
        c = base.model_copy(update={"toolpath": base.toolpath.model_copy(update={"waypoints": n})})
        problem, settings = problem_from_config(c, base_dir), multistart_from_config(c)
        tasks = multistart_tasks(f"N{n}", "to", problem, transcription_from_config(c), settings)
        done = solve_tasks(run, tasks, "waypoints", settings.jobs, resume,
                           on_solution=(lambda _t, sol, n=n: on_solution(n, sol)) if on_solution else None)
        sols = [sol for _, sol in done]
        best = best_solution(sols)
        mid = midpoint_errors(best, c, base_dir) if best else np.array([np.nan])
        rows.append({
            "waypoints": n,
            "design_cost": best.metrics.design_cost if best else np.nan,
            "max_waypoint_error": best.metrics.max_position_error if best else np.nan,
            "max_midpoint_error": float(mid.max()),
            "tracking_starts": sum(s.metrics.tracks for s in sols), "starts": len(sols),
            "median_solve_time_s": float(np.median([s.raw.solve_time_s for s in sols])),
            "median_iterations": float(np.median([s.raw.iterations for s in sols])),
            "build_time_s": sols[0].raw.build_time_s,
        })
    table = pd.DataFrame(rows)
    table.to_csv(run.path / "table.csv", index=False)
    if figures:
        from designopt import plots_experiments

        plots_experiments.waypoint_figure(table, run.figures)
    run.log("done")
    return table
