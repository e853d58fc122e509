"""``designopt run``: one config, one multistart TO solve, one run directory."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.tasks import multistart_tasks, solve_tasks
from designopt.multistart import Multistart, best_solution
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution, write_solution
from designopt.transcriptions import Collocation


@dataclass(frozen=True)
class RunResult:
    directory: RunDirectory
    solutions: list[Solution]
    best: Solution | None
    summary: pd.DataFrame


def transcription_from_config(cfg: Config) -> Collocation:
    s = cfg.solver
    return Collocation(
        kinematics=s.kinematics, tracking=s.tracking, degree=s.degree, max_iter=s.max_iter, compile=s.compile,
        ipopt={"ipopt.max_wall_time": float(s.time_limit)},
    )


def multistart_from_config(cfg: Config) -> Multistart:
    s = cfg.solver
    return Multistart(count=s.multistart, seed=s.seed, scale=s.perturbation, init=s.init, jobs=s.jobs)


def run_experiment(
    cfg: Config,
    base_dir: Path,
    out_root: Path,
    run_name: str | None = None,
    on_solution: Callable[[Solution], None] | None = None,
    figures: bool = True,
    resume: bool = False,
) -> RunResult:
    """Solve the config's problem with multistart TO and write the run directory (``resume``: finish the
    named run, solving only the starts it has no solution for)."""
    problem = problem_from_config(cfg, base_dir)
    run = RunDirectory.create(out_root, cfg.name, run_name, resume)
    run.write_config(dump_config(cfg))
    run.log(f"start {cfg.name}: structure {cfg.robot.structure}, {problem.chain.n_design} design joints, "
            f"{problem.toolpath.n} waypoints, {cfg.solver.multistart} starts")
    settings = multistart_from_config(cfg)
    tasks = multistart_tasks("", "to", problem, transcription_from_config(cfg), settings)
    done = solve_tasks(run, tasks, cfg.name, settings.jobs, resume,
                       on_solution=(lambda _t, sol: on_solution(sol)) if on_solution else None)
    solutions = [sol for _, sol in done]
    best_task, best = best_of(done)
    summary = run.mark_best({best_task.file_name} if best is not None else set())
    if best is not None:
        write_solution(best, run.path / "best.json")
        run.log(f"best: seed {best.raw.seed}, design cost {best.metrics.design_cost:.6g}")
        if figures:
            from designopt import plots

            plots.solution_figures(best, run.figures)
    else:
        run.log("no start tracks the path")
    return RunResult(run, solutions, best, summary)


def best_of(done: list) -> tuple:
    """(task, solution) of the tracking solution with the lowest design cost, or (None, None)."""
    best = best_solution([sol for _, sol in done])
    return next(((t, s) for t, s in done if s is best), (None, None))


__all__ = ["RunResult", "run_experiment", "transcription_from_config", "multistart_from_config", "best_of"]
