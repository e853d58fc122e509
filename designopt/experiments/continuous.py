"""The continuous design problem (SPEC §5-6, claims C1-C3): three cases, three methods, multistart.

Cases differ only in which joints are design joints -- one mechanism:
  placement_only  the configured robot (PUMA-560) is fixed; the 6 placement joints are free
  design_only     the workpiece is fixed at placement.xyz/ypr; d, a, alpha of every link are free (18)
  combined        both (24)
Methods: ``to`` (collocation), ``fk`` (Whitman et al.), ``fk_continuous`` (FK with bounded joint steps).
Every (case, method, start) is one joblib task; each finished solve is written at once.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.run import best_of, multistart_from_config
from designopt.experiments.tasks import multistart_tasks, solve_tasks
from designopt.multistart import best_solution
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution, write_solution
from designopt.transcriptions import transcription_named

CASE_LABELS = {"placement_only": "placement only", "design_only": "design only", "combined": "design + placement"}


def case_config(cfg: Config, case: str) -> Config:
    """The config of one case: the same robot and cell with other joints marked as design joints."""
    robot, placement = cfg.robot, cfg.placement
    if robot.is_urdf:
        raise cfg.error("robot.urdf", "this experiment varies DH parameters and needs a DH robot (robot.structure, "
                                      "robot.dh); `designopt run` takes URDF robots")
    design = robot.design or ["d", "a", "alpha"]
    if case == "placement_only":
        robot, placement = robot.model_copy(update={"design": []}), placement.model_copy(update={"optimize": True})
    elif case == "design_only":
        robot, placement = robot.model_copy(update={"design": design}), placement.model_copy(update={"optimize": False})
    elif case == "combined":
        robot, placement = robot.model_copy(update={"design": design}), placement.model_copy(update={"optimize": True})
    else:
        raise ValueError(f"unknown case {case!r}")
    return cfg.model_copy(update={"robot": robot, "placement": placement})


def method_transcription(cfg: Config, method: str):
    s = cfg.solver
    options = {"max_iter": s.max_iter, "compile": s.compile, "ipopt": {"ipopt.max_wall_time": float(s.time_limit)}}
    if method == "to":
        options.update(kinematics=s.kinematics, tracking=s.tracking, degree=s.degree)
    return transcription_named(method, **options)


@dataclass(frozen=True)
class ContinuousResult:
    directory: RunDirectory
    summary: pd.DataFrame
    table: pd.DataFrame
    best: dict  # (case, method) -> Solution | None


def best_table(solutions: dict) -> pd.DataFrame:
    """One row per (case, method): the best tracking start and how many starts tracked."""
    rows = []
    for (case, method), sols in solutions.items():
        best = best_solution(sols)
        tracking = [s for s in sols if s.metrics.tracks]
        rows.append({
            "case": case, "method": method, "n_design_joints": sols[0].problem.chain.n_design,
            "design_cost": best.metrics.design_cost if best else float("nan"),
            "max_joint_step": best.metrics.max_joint_step if best else float("nan"),
            "max_position_error": best.metrics.max_position_error if best else float("nan"),
            "starts": len(sols), "tracking_starts": len(tracking),
            "median_cost_tracking": pd.Series([s.metrics.design_cost for s in tracking]).median(),
            "median_solve_time_s": pd.Series([s.raw.solve_time_s for s in sols]).median(),
            "median_iterations": pd.Series([s.raw.iterations for s in sols]).median(),
            "best_seed": best.raw.seed if best else None,
        })
    order = {c: i for i, c in enumerate(CASE_LABELS)}
    return pd.DataFrame(rows).sort_values(["case", "method"], key=lambda c: c.map(order) if c.name == "case" else c)


def run_continuous(cfg: Config, base_dir: Path, out_root: Path, run_name: str | None = None,
                   on_solution: Callable[[str, Solution], None] | None = None, figures: bool = True,
                   experiment: str = "continuous", resume: bool = False) -> ContinuousResult:
    settings = multistart_from_config(cfg)
    tasks = []
    for case in cfg.continuous.cases:
        problem = problem_from_config(case_config(cfg, case), base_dir)
        for method in cfg.continuous.methods:
            tasks += multistart_tasks(case, method, problem, method_transcription(cfg, method), settings)
    run = RunDirectory.create(out_root, experiment, run_name, resume)  # only once the input is known good
    run.write_config(dump_config(cfg))
    run.log(f"start continuous: {len(tasks)} solves ({len(cfg.continuous.cases)} cases x "
            f"{len(cfg.continuous.methods)} methods x {settings.count} starts)")
    done = solve_tasks(run, tasks, experiment, settings.jobs, resume,
                       on_solution=(lambda t, sol: on_solution(t.case, sol)) if on_solution else None)
    groups: dict = {}
    for task, sol in done:
        groups.setdefault((task.case, task.method), []).append((task, sol))
    best_pairs = {key: best_of(pairs) for key, pairs in groups.items()}
    best = {key: sol for key, (_, sol) in best_pairs.items()}
    summary = run.mark_best({t.file_name for t, s in best_pairs.values() if s is not None})
    table = best_table({key: [sol for _, sol in pairs] for key, pairs in groups.items()})
    table.to_csv(run.path / "table.csv", index=False)
    for (case, method), sol in best.items():
        if sol is not None:
            write_solution(sol, run.path / f"best-{case}-{method}.json")
    if figures:
        from designopt import plots_experiments

        plots_experiments.design_cost_figure(table, summary, run.figures)
        robots = {c: best.get((c, "to")) for c in ("design_only", "combined") if best.get((c, "to"))}
        if robots:
            plots_experiments.optimal_robots_figure(robots, run.figures)
    run.log("done")
    return ContinuousResult(run, summary, table, best)
