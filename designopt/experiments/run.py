"""``designopt run``: one config, one multistart TO solve, one run directory."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.adapters import multistart_from_config, transcription_for
from designopt.experiments.tasks import Progress, best_of, multistart_tasks, solve_tasks
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution, write_solution
from designopt.tables import best_so_far, solution_set


@dataclass(frozen=True)
class RunResult:
    directory: RunDirectory
    solutions: list[Solution]
    best: Solution | None
    summary: pd.DataFrame
    solution_set: pd.DataFrame  # the distinct local optima reached, best first (tables.solution_set)


def run_experiment(cfg: Config, base_dir: Path, out_root: Path, run_name: str | None = None,
                   progress: Progress | None = None, figures: bool = True, resume: bool = False) -> RunResult:
    """Solve the config's problem with multistart TO and write the run directory (``resume``: finish the
    named run, solving only the starts it has no solution for)."""
    problem = problem_from_config(cfg, base_dir)
    run = RunDirectory.create(out_root, cfg.name, run_name, resume)
    run.write_config(dump_config(cfg))
    run.log(f"start {cfg.name}: structure {problem.chain.structure}, {problem.chain.n_design} design joints, "
            f"{problem.toolpath.n} waypoints, {cfg.solver.multistart} starts")
    settings = multistart_from_config(cfg)
    tasks = multistart_tasks("", "to", problem, transcription_for(cfg), settings)
    done = solve_tasks(run, tasks, cfg.name, settings.jobs, resume, progress)
    best_task, best = best_of(done)
    summary = run.mark_best({best_task.file_name} if best is not None else set())
    solutions = [sol for _, sol in done]
    optima = solution_set(solutions)
    optima.to_csv(run.path / "solution_set.csv", index=False)
    if figures:
        from designopt import plots_experiments

        plots_experiments.search_progress_figure(best_so_far(summary), optima, run.figures)
    if best is not None:
        write_solution(best, run.path / "best.json")
        run.log(f"best: seed {best.raw.seed}, design cost {best.metrics.design_cost:.6g}; {len(optima)} distinct "
                f"optima among {len(solutions)} solves")
        if figures:
            from designopt import plots
            from designopt.view import write_view

            plots.solution_figures(best, run.figures)
            write_view(best, run.path / "view.html")
    else:
        run.log("no start tracks the path")
    return RunResult(run, solutions, best, summary, optima)
