"""The continuous design problem (SPEC §5-6, claims C1-C3): three cases, three methods, one search each.

Cases differ only in which joints are design joints -- one mechanism (`adapters.CASES`):
  placement_only  the configured robot (PUMA-560) is fixed; the 6 placement joints are free
  design_only     the workpiece is fixed at placement.xyz/ypr; d, a, alpha of every link are free (18)
  combined        both (24)
Methods: ``to`` (collocation), ``fk`` (Whitman et al.), ``fk_continuous`` (FK with bounded joint steps). Every
(case, method) is one job of the config's search; the shipped config uses the ``paper`` preset, so every method
gets the same seeded starts, start for start.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.adapters import CASES, case_config, search_from_config
from designopt.experiments.runs import Executor, Progress, record_search
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import write_solution
from designopt.solve import Job, Search, run_search
from designopt.tables import best_table
from designopt.transcriptions import TRANSCRIPTIONS, transcription_named

METHODS = tuple(TRANSCRIPTIONS)


@dataclass(frozen=True)
class ContinuousResult:
    directory: RunDirectory
    summary: pd.DataFrame
    table: pd.DataFrame
    best: dict  # (case, method) -> Solution | None


def run_continuous(cfg: Config, out_root: Path, run_name: str | None = None, progress: Progress | None = None,
                   figures: bool = True, experiment: str = "continuous", resume: bool = False, jobs: int = -1,
                   cases: tuple[str, ...] = tuple(CASES), methods: tuple[str, ...] = METHODS,
                   search: Search | None = None) -> ContinuousResult:
    search = search or search_from_config(cfg)
    work = []
    for case in cases:
        problem = problem_from_config(case_config(cfg, case))
        work += [Job(case, problem, transcription_named(method)) for method in methods]
    run = RunDirectory.create(out_root, experiment, run_name, resume)  # only once the input is known good
    record_search(run, search)  # first: a resume with another search is refused before the run is touched
    run.write_config(dump_config(cfg))
    run.log(f"start continuous: {len(cases)} cases x {len(methods)} methods, search {search.describe()}")
    searched = run_search(work, search, Executor(run, experiment, jobs, resume, progress))
    best_pairs = {(s.job.case, s.job.transcription.name): s.best for s in searched}
    best = {key: sol for key, (_, sol) in best_pairs.items()}
    summary = run.mark_best({t.file_name for t, s in best_pairs.values() if s is not None})
    table = best_table({(s.job.case, s.job.transcription.name): [sol for _, sol in s.final] for s in searched})
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
