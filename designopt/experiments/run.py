"""``designopt run``: one config, one multistart TO solve, one run directory."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.multistart import Multistart, best_solution, run_multistart
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


def solution_id(sol: Solution) -> str:
    return f"{sol.method}-{sol.problem.chain.structure}-s{sol.raw.seed}"


def record(run: RunDirectory, sol: Solution, experiment: str, case: str) -> str:
    """Write one solution file and its summary row; return the file name."""
    name = f"{solution_id(sol)}.json" if not case else f"{case}-{solution_id(sol)}.json"
    write_solution(sol, run.solutions / name)
    run.append_row({"experiment": experiment, "case": case, **sol.row(),
                    "solution_file": f"solutions/{name}"})
    run.log(f"{case or 'run'} {sol.method} seed={sol.raw.seed} status={sol.raw.status} "
            f"iter={sol.raw.iterations} cost={sol.metrics.design_cost:.6g} tracks={sol.metrics.tracks}")
    return name


def run_experiment(
    cfg: Config,
    base_dir: Path,
    out_root: Path,
    run_name: str | None = None,
    on_solution: Callable[[Solution], None] | None = None,
    figures: bool = True,
) -> RunResult:
    """Solve the config's problem with multistart TO and write the run directory."""
    problem = problem_from_config(cfg, base_dir)
    run = RunDirectory.create(out_root, cfg.name, run_name)
    run.write_config(dump_config(cfg))
    run.log(f"start {cfg.name}: structure {cfg.robot.structure}, {problem.chain.n_design} design joints, "
            f"{problem.toolpath.n} waypoints, {cfg.solver.multistart} starts")
    transcription = transcription_from_config(cfg)
    solutions = []
    for sol in run_multistart(problem, transcription, multistart_from_config(cfg)):
        record(run, sol, cfg.name, "")
        solutions.append(sol)
        if on_solution:
            on_solution(sol)
    best = best_solution(solutions)
    summary = run.mark_best({f"solutions/{solution_id(best)}.json"} if best is not None else set())
    if best is not None:
        write_solution(best, run.path / "best.json")
        run.log(f"best: seed {best.raw.seed}, design cost {best.metrics.design_cost:.6g}")
        if figures:
            from designopt import plots

            plots.solution_figures(best, run.figures)
    else:
        run.log("no start tracks the path")
    return RunResult(run, solutions, best, summary)


__all__ = ["RunResult", "run_experiment", "transcription_from_config", "multistart_from_config"]
