"""The continuous design problem (SPEC §5-6, claims C1-C3): three cases, three methods, multistart.

Cases differ only in which joints are design joints -- one mechanism:
  placement_only  the configured robot (PUMA-560) is fixed; the 6 placement joints are free
  design_only     the workpiece is fixed at placement.xyz/ypr; d, a, alpha of every link are free (18)
  combined        both (24)
Methods: ``to`` (collocation), ``fk`` (Whitman et al.), ``fk_continuous`` (FK with bounded joint steps).
Every (case, method, start) is one joblib task; each finished solve is written at once.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.adapters import case_config, multistart_from_config, transcription_for
from designopt.experiments.tasks import Progress, best_of, multistart_tasks, solve_tasks
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import write_solution
from designopt.tables import best_table


@dataclass(frozen=True)
class ContinuousResult:
    directory: RunDirectory
    summary: pd.DataFrame
    table: pd.DataFrame
    best: dict  # (case, method) -> Solution | None


def run_continuous(cfg: Config, base_dir: Path, out_root: Path, run_name: str | None = None,
                   progress: Progress | None = None, figures: bool = True, experiment: str = "continuous",
                   resume: bool = False) -> ContinuousResult:
    settings = multistart_from_config(cfg)
    tasks = []
    for case in cfg.continuous.cases:
        problem = problem_from_config(case_config(cfg, case), base_dir)
        for method in cfg.continuous.methods:
            tasks += multistart_tasks(case, method, problem, transcription_for(cfg, method), settings)
    run = RunDirectory.create(out_root, experiment, run_name, resume)  # only once the input is known good
    run.write_config(dump_config(cfg))
    run.log(f"start continuous: {len(tasks)} solves ({len(cfg.continuous.cases)} cases x "
            f"{len(cfg.continuous.methods)} methods x {settings.count} starts)")
    done = solve_tasks(run, tasks, experiment, settings.jobs, resume, progress)
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
