"""How an experiment's solves become a run directory: each written as it finishes, resumable, with progress.

Every experiment hands its problems to a search (`designopt.solve.search.run_search`) with an `Executor` of its
run: the executor fans a stage's tasks out (`designopt.solve.tasks.fan_out`), writes each finished solve at once
(its solution file atomically, then its summary row), so a killed run keeps all it finished, and with ``resume``
loads the tasks whose row and file exist instead of solving them.
"""

from __future__ import annotations

import importlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from designopt.config import load_config
from designopt.errors import InputError
from designopt.experiments.adapters import search_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution, SolutionLoadError, read_solution_for, write_solution
from designopt.solve.search import Search, search_from_dict, search_to_dict
from designopt.solve.tasks import Task, fan_out


class Progress(Protocol):
    """What an experiment reports while it works (the CLI draws it; experiments never print)."""

    def planned(self, solves: int, finished: int = 0) -> None:
        """``solves`` more solves are planned, ``finished`` of them already done (resumed)."""

    def solved(self, task: Task, solution: Solution) -> None:
        """One solve finished and was written."""


class Silent:
    """A Progress that reports nothing."""

    def planned(self, solves: int, finished: int = 0) -> None:
        pass

    def solved(self, task: Task, solution: Solution) -> None:
        pass


@dataclass(frozen=True)
class Drawing:
    """One figure to draw: ``function`` of module ``module`` called with ``args`` (it writes its own files). Named,
    not imported, so that the process that plans a run's figures never imports matplotlib (0.5 s)."""

    module: str
    function: str
    args: tuple

    def __call__(self):
        return getattr(importlib.import_module(self.module), self.function)(*self.args)


def draw(drawings: list[Drawing], jobs: int | None) -> None:
    """Figures drawn side by side, on this machine's cores as `fan_out` would use them (``jobs`` -1: every core), or
    one after the other here (``jobs`` 1 or None: a cluster's workers would write the files on their own
    machines)."""
    if jobs in (None, 1) or len(drawings) <= 1:
        for drawing in drawings:
            drawing()
        return
    from joblib import Parallel, delayed, effective_n_jobs

    Parallel(n_jobs=min(len(drawings), effective_n_jobs(jobs)), backend="loky")(delayed(d)() for d in drawings)


def record_search(run: RunDirectory, search: Search) -> None:
    """Write the run's search.json: every setting of the search it makes (a preset's name alone says less once the
    preset changes). A run resumed with another search than it was started with is refused (its solves would be of
    two searches): one line naming the file, exit code 2."""
    path = run.path / "search.json"
    if path.is_file():
        try:
            same = search_from_dict(json.loads(path.read_text())) == search
        except (ValueError, TypeError):  # unreadable, or of another version
            same = False
        if not same:
            raise InputError(path, "--resume", "the run was started with another search (another config, or a preset "
                                               "that has changed since): finish it as it was started, or use another "
                                               "--name")
    run.write_search(json.dumps(search_to_dict(search), indent=1) + "\n")


def search_of_run(path: Path) -> Search:
    """The search a run directory's solves were made by: its search.json (`record_search`), or, for a run written
    before runs had one, its config's search with this checkout's presets (`adapters.search_from_config`)."""
    if (path / "search.json").is_file():
        return search_from_dict(json.loads((path / "search.json").read_text()))
    return search_from_config(load_config(path / "config.yaml"))


def record(run: RunDirectory, task: Task, sol: Solution, experiment: str) -> None:
    """Write one solution file (atomically), then its summary row: a row always has its file."""
    write_solution(sol, run.path / task.file_name)
    run.append_row({"experiment": experiment, "case": task.case, "stage": task.stage, **sol.row(),
                    "solution_file": task.file_name})
    run.log(f"{task.case or 'run'} {task.stage} {sol.method} seed={sol.raw.seed} status={sol.raw.status} "
            f"iter={sol.raw.iterations} cost={sol.metrics.design_cost:.6g} tracks={sol.metrics.tracks}")


class Executor:
    """``execute(tasks) -> [(task, solution)]`` for a search: solves (or, resuming, loads) every task and writes each
    as it finishes to ``run``. ``jobs``: worker processes (-1: every core; None: joblib's active backend, e.g. a
    Dask cluster). ``load_finished`` False skips loading resumed solves (a sweep that only needs the table)."""

    def __init__(self, run: RunDirectory, experiment: str, jobs: int | None = -1, resume: bool = False,
                 progress: Progress | None = None, load_finished: bool = True):
        self.run, self.experiment, self.jobs, self.resume = run, experiment, jobs, resume
        self.progress, self.load_finished = progress or Silent(), load_finished

    def __call__(self, tasks: list[Task]) -> list[tuple[Task, Solution]]:
        """A row whose file is gone or unreadable is dropped from summary.csv and solved again, so no solve is
        counted twice."""
        finished = self.run.resume() if self.resume else {}
        results, todo = [], []
        for task in tasks:
            row = finished.get(task.key)
            if row is None:
                todo.append(task)
                continue
            if not self.load_finished:
                continue
            try:
                results.append((task, read_solution_for(task.problem, task.transcription,
                                                        self.run.path / row["solution_file"])))
            except SolutionLoadError:
                self.run.drop_rows({task.key})
                todo.append(task)
        if finished:
            self.run.log(f"resume: {len(tasks) - len(todo)} solves already done, {len(todo)} to do")
        self.progress.planned(len(tasks), len(tasks) - len(todo))
        for task, sol in fan_out(todo, self.jobs):
            record(self.run, task, sol, self.experiment)
            results.append((task, sol))
            self.progress.solved(task, sol)
        return results
