"""``designopt run``: one config, one searched problem (`designopt.solve.search`), one run directory."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.adapters import search_from_config
from designopt.experiments.runs import Drawing, Executor, Progress, draw, record_search
from designopt.problem import DesignProblem, problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution, write_solution
from designopt.solve import Job, Search, Searched, run_search
from designopt.tables import best_so_far, solution_set


def searched_set(searched: Searched) -> pd.DataFrame:
    """The distinct optima a search reached (`tables.solution_set`): of the exploration when there was one, with
    the full-path cost of each optimum that was refined (``full_path_cost``, from the refine solve of its seed)."""
    if not searched.explore:
        return solution_set([sol for _, sol in searched.final])
    table = solution_set([sol for _, sol in searched.explore])
    refined: dict[int, float] = {}  # an optimum refined more than once (several barriers): its best refine
    for _, sol in searched.final:
        if sol.metrics.tracks:
            refined[sol.raw.seed] = min(sol.metrics.design_cost, refined.get(sol.raw.seed, float("inf")))
    table["full_path_cost"] = [min((refined[int(x)] for x in seeds.split() if int(x) in refined), default=float("nan"))
                               for seeds in table["seeds"].astype(str)]
    return table


def draw_bests(searched: Searched, search: Search) -> list[float]:
    """Each draw's best tracking full-path design cost (`Search.draws`, `Search.draw_of`; nan where a draw tracks
    nothing): how far the draws agree tells how settled the answer is."""
    best = [math.inf] * search.draws
    for task, sol in searched.final:
        if sol.metrics.tracks:
            k = search.draw_of(task.seed)
            best[k] = min(best[k], sol.metrics.design_cost)
    return [cost if cost < math.inf else math.nan for cost in best]


# a run's standard figures of its best solution (`designopt.plots.SOLUTION_FIGURES`; each drawn where it applies)
SOLUTION_FIGURES = ("robot", "joints", "deformation", "force_deflection")


@dataclass(frozen=True)
class RunResult:
    directory: RunDirectory
    problem: DesignProblem
    solutions: list[Solution]  # the solves on the full path (for coarse_to_fine: the refined optima)
    stages: list[str]  # the search stage of each of ``solutions`` (refine, refine2, neighbour, ...; final: multistart)
    explored: list[Solution]  # the exploration's solves on the coarse path (none for multistart)
    best: Solution | None
    summary: pd.DataFrame
    solution_set: pd.DataFrame  # the distinct local optima reached, best first (tables.solution_set)
    draw_bests: list[float]  # each draw's best design cost (one entry unless the search has several draws)


def run_experiment(cfg: Config, out_root: Path, run_name: str | None = None, progress: Progress | None = None,
                   figures: bool = True, resume: bool = False, jobs: int = -1,
                   search: Search | None = None) -> RunResult:
    """Search the config's problem (with the config's search, or ``search``) and write the run directory
    (``resume``: finish the named run, solving only the starts it has no solution for)."""
    problem = problem_from_config(cfg)
    search = search or search_from_config(cfg)
    run = RunDirectory.create(out_root, cfg.name, run_name, resume)
    record_search(run, search)  # first: a resume with another search is refused before the run is touched
    run.write_config(dump_config(cfg))
    run.log(f"start {cfg.name}: structure {problem.chain.structure}, {problem.chain.n_design} design joints, "
            f"{problem.toolpath.n} waypoints, search {search.describe()}")
    (searched,) = run_search([Job("", problem)], search, Executor(run, cfg.name, jobs, resume, progress))
    best_task, best = searched.best
    summary = run.mark_best({best_task.file_name} if best is not None else set())
    solutions = [sol for _, sol in searched.explore + searched.final]
    optima = searched_set(searched)
    optima.to_csv(run.path / "solution_set.csv", index=False)
    if best is not None:
        write_solution(best, run.path / "best.json")
        run.log(f"best: seed {best.raw.seed}, design cost {best.metrics.design_cost:.6g}; {len(optima)} distinct "
                f"optima among {len(solutions)} solves")
    else:
        run.log("no start tracks the path")
    bests = draw_bests(searched, search)
    if len(bests) > 1:
        run.log(f"each draw's best (seeds {', '.join(str(s) for s in search.draw_seeds)}): "
                f"{', '.join(f'{cost:.6g}' for cost in bests)}")
    if figures:
        explored = summary[summary["stage"] == "explore"] if searched.explore else summary
        drawings = [Drawing("designopt.plots_experiments", "search_progress_figure",
                            (best_so_far(explored.reset_index(drop=True)), optima, run.figures))]
        if best is not None:
            drawings += [Drawing("designopt.plots", "solution_figure", (best, run.figures, name))
                         for name in SOLUTION_FIGURES]
            drawings.append(Drawing("designopt.view", "write_view", (best, run.path / "view.html")))
        draw(drawings, jobs)
    return RunResult(run, problem, [sol for _, sol in searched.final], [task.stage for task, _ in searched.final],
                     [sol for _, sol in searched.explore], best, summary, optima, bests)
