"""Waypoint study: how the number of waypoints N changes design cost, tracking and solve time (TO, combined).

Hard tracking is exact at the waypoints; what N controls is the path *between* them. The solution's
trajectory (`Solution.sample`) is checked at every interval midpoint against the path sampled there.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.adapters import case_config, multistart_from_config, transcription_for, with_waypoints
from designopt.experiments.tasks import Progress, multistart_tasks, solve_tasks
from designopt.kinematics.chain import placement_pose, tool_pose
from designopt.multistart import best_solution
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution


@dataclass(frozen=True)
class WaypointResult:
    directory: RunDirectory
    table: pd.DataFrame  # one row per N


def midpoint_errors(sol: Solution, cfg: Config, base_dir: Path) -> np.ndarray:
    """Position error (m) of the solution's trajectory at every interval midpoint."""
    tp = sol.problem.toolpath
    fine = problem_from_config(with_waypoints(cfg, 2 * tp.n - 1), base_dir).toolpath
    chain, none = sol.chain, np.zeros(0)
    Q_mid = sol.sample(0.5 * (tp.t[:-1] + tp.t[1:]))
    T_BW = placement_pose(chain, Q_mid[0], none)
    s_B = fine.points_W[1::2] @ T_BW[:3, :3].T + T_BW[:3, 3]
    return np.array([np.linalg.norm(tool_pose(chain, q, none)[:3, 3] - s) for q, s in zip(Q_mid, s_B, strict=True)])


def run_waypoint_study(cfg: Config, base_dir: Path, out_root: Path, run_name: str | None = None,
                       progress: Progress | None = None, figures: bool = True,
                       resume: bool = False) -> WaypointResult:
    base = case_config(cfg, "combined")
    problem_from_config(base, base_dir)  # bad input stops here, before a run directory exists
    run = RunDirectory.create(out_root, "waypoints", run_name, resume)
    run.write_config(dump_config(cfg))
    rows = []
    for n in cfg.continuous.waypoint_study:
        c = with_waypoints(base, n)
        problem, settings = problem_from_config(c, base_dir), multistart_from_config(c)
        done = solve_tasks(run, multistart_tasks(f"N{n}", "to", problem, transcription_for(c), settings), "waypoints",
                           settings.jobs, resume, progress)
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
            "build_time_s": max(s.raw.build_time_s for s in sols),  # the start that built the NLP
        })
    table = pd.DataFrame(rows)
    table.to_csv(run.path / "table.csv", index=False)
    if figures:
        from designopt import plots_experiments

        plots_experiments.waypoint_figure(table, run.figures)
    run.log("done")
    return WaypointResult(run, table)
