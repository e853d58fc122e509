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
from designopt.experiments.adapters import case_config, search_from_config, with_waypoints
from designopt.experiments.runs import Executor, Progress, record_search
from designopt.kinematics.chain import placement_pose, tool_pose
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution
from designopt.solve import Job, Search, run_search

WAYPOINTS = (20, 40, 80, 160, 320)


@dataclass(frozen=True)
class WaypointResult:
    directory: RunDirectory
    table: pd.DataFrame  # one row per N


def midpoint_errors(sol: Solution, cfg: Config) -> np.ndarray:
    """Position error (m) of the solution's trajectory at every interval midpoint."""
    tp = sol.problem.toolpath
    fine = problem_from_config(with_waypoints(cfg, 2 * tp.n - 1)).toolpath
    chain, none = sol.chain, np.zeros(0)
    Q_mid = sol.sample(0.5 * (tp.t[:-1] + tp.t[1:]))
    T_BW = placement_pose(chain, Q_mid[0], none)
    s_B = fine.points_W[1::2] @ T_BW[:3, :3].T + T_BW[:3, 3]
    return np.array([np.linalg.norm(tool_pose(chain, q, none)[:3, 3] - s) for q, s in zip(Q_mid, s_B, strict=True)])


def run_waypoint_study(cfg: Config, out_root: Path, run_name: str | None = None, progress: Progress | None = None,
                       figures: bool = True, resume: bool = False, jobs: int = -1,
                       waypoints: tuple[int, ...] = WAYPOINTS, search: Search | None = None) -> WaypointResult:
    base = case_config(cfg, "combined")  # bad input stops here, before a run directory exists
    configs = {n: with_waypoints(base, n) for n in waypoints}
    search = search or search_from_config(cfg)
    run = RunDirectory.create(out_root, "waypoints", run_name, resume)
    record_search(run, search)  # first: a resume with another search is refused before the run is touched
    run.write_config(dump_config(cfg))
    run.log(f"start waypoint study: N = {', '.join(map(str, waypoints))}, search {search.describe()}")
    searched = run_search([Job(f"N{n}", problem_from_config(c)) for n, c in configs.items()], search,
                          Executor(run, "waypoints", jobs, resume, progress))
    rows = []
    for n, s in zip(waypoints, searched, strict=True):
        sols = [sol for _, sol in s.final]
        best = s.best[1]
        mid = midpoint_errors(best, configs[n]) if best else np.array([np.nan])
        rows.append({
            "waypoints": n,
            "design_cost": best.metrics.design_cost if best else np.nan,
            "max_waypoint_error": best.metrics.max_position_error if best else np.nan,
            "max_midpoint_error": float(mid.max()),
            "tracking_starts": sum(x.metrics.tracks for x in sols), "starts": len(sols),
            "median_solve_time_s": float(np.median([x.raw.solve_time_s for x in sols])),
            "median_iterations": float(np.median([x.raw.iterations for x in sols])),
            "build_time_s": max(x.raw.build_time_s for x in sols),  # the start that built the NLP
        })
    table = pd.DataFrame(rows)
    table.to_csv(run.path / "table.csv", index=False)
    if figures:
        from designopt import plots_experiments

        plots_experiments.waypoint_figure(table, run.figures)
    run.log("done")
    return WaypointResult(run, table)
