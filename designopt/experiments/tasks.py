"""The one experiment machinery: tasks (one seeded start of one problem), fanned out, written as they finish,
and resumed.

Every experiment -- a run's multistart, the continuous comparison, the waypoint study, the modular stages
and the structure sweep -- is a list of `Task`s handed to `solve_tasks`. Each finished solve is written at
once (its solution file atomically, then its summary row), so a killed run keeps all it finished; with
``resume`` the tasks whose row and file exist are loaded instead of solved.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Protocol

from designopt.multistart import Multistart, best_solution, solve_guess, solve_start
from designopt.problem import DesignProblem
from designopt.results_io import RunDirectory
from designopt.search import WARM_IPOPT, Search, coarse_problem, distinct_best, lifted_guess
from designopt.solution import Solution, SolutionLoadError, read_solution_for, write_solution


@dataclass(frozen=True)
class Task:
    """Start ``index`` of a seeded multistart of ``problem`` with ``transcription``, labelled ``case``; with
    ``warm``, the start is that solution (of another sampling of the same task) lifted to ``problem``."""

    case: str
    method: str
    problem: DesignProblem
    transcription: object
    settings: Multistart
    index: int
    warm: Solution | None = None

    @property
    def seed(self) -> int:
        return self.settings.seed * 1000 + self.index

    @property
    def key(self) -> tuple[str, str, str, int]:
        """(case, method, structure, seed): what identifies a solve in summary.csv."""
        return self.case, self.method, self.problem.chain.structure, self.seed

    @property
    def file_name(self) -> str:
        stem = f"{self.method}-{self.problem.chain.structure}-s{self.seed}"
        return f"solutions/{self.case}-{stem}.json" if self.case else f"solutions/{stem}.json"


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


def multistart_tasks(case: str, method: str, problem: DesignProblem, transcription, settings: Multistart) -> list[Task]:
    return [Task(case, method, problem, transcription, settings, i) for i in range(settings.count)]


def _solve(task: Task) -> tuple[Task, Solution]:
    if task.warm is not None:
        return task, solve_guess(task.problem, task.transcription, lifted_guess(task.problem, task.warm), task.case)
    return task, solve_start(task.problem, task.transcription, task.settings, task.index, task.case)


def fan_out(tasks: list[Task], jobs: int | None) -> Iterator[tuple[Task, Solution]]:
    """Yield (task, solution) as tasks finish: in this process if jobs == 1, else joblib processes (jobs = -1:
    every core; None: joblib's active backend decides, e.g. a Dask cluster)."""
    if jobs == 1 or len(tasks) <= 1:
        for t in tasks:
            yield _solve(t)
        return
    from joblib import Parallel, delayed

    yield from Parallel(n_jobs=jobs, return_as="generator_unordered")(delayed(_solve)(t) for t in tasks)


def record(run: RunDirectory, task: Task, sol: Solution, experiment: str) -> None:
    """Write one solution file (atomically), then its summary row: a row always has its file."""
    write_solution(sol, run.path / task.file_name)
    run.append_row({"experiment": experiment, "case": task.case, **sol.row(), "solution_file": task.file_name})
    run.log(f"{task.case or 'run'} {sol.method} seed={sol.raw.seed} status={sol.raw.status} "
            f"iter={sol.raw.iterations} cost={sol.metrics.design_cost:.6g} tracks={sol.metrics.tracks}")


def solve_tasks(run: RunDirectory, tasks: list[Task], experiment: str, jobs: int | None = -1,
                resume: bool = False, progress: Progress | None = None,
                load_finished: bool = True) -> list[tuple[Task, Solution]]:
    """Solve every task, writing each as it finishes; return (task, solution) for all of them.

    With ``resume``, a task whose summary row and solution file exist is not solved again: its solution is
    loaded from the file (or skipped when ``load_finished`` is False, for sweeps that only need the table).
    A row whose file is gone or unreadable is dropped from summary.csv and solved again, so no solve is
    counted twice.
    """
    finished = run.resume() if resume else {}
    results, todo = [], []
    for task in tasks:
        row = finished.get(task.key)
        if row is None:
            todo.append(task)
            continue
        if not load_finished:
            continue
        try:
            results.append((task, read_solution_for(task.problem, task.method, run.path / row["solution_file"],
                                                    task.case)))
        except SolutionLoadError:
            run.drop_rows({task.key})
            todo.append(task)
    if finished:
        run.log(f"resume: {len(tasks) - len(todo)} solves already done, {len(todo)} to do")
    progress = progress or Silent()
    progress.planned(len(tasks), len(tasks) - len(todo))
    for task, sol in fan_out(todo, jobs):
        record(run, task, sol, experiment)
        results.append((task, sol))
        progress.solved(task, sol)
    return results


def best_of(done: list[tuple[Task, Solution]]) -> tuple[Task | None, Solution | None]:
    """(task, solution) of the tracking solution with the lowest design cost, or (None, None)."""
    best = best_solution([sol for _, sol in done])
    return next(((t, s) for t, s in done if s is best), (None, None))


@dataclass(frozen=True)
class Searched:
    """What a search of one problem solved: ``explore`` on the coarse path (empty for ``multistart``) and the
    ``final`` solves on the full path, the ones a result is chosen from."""

    explore: list[tuple[Task, Solution]]
    final: list[tuple[Task, Solution]]


def _stage(case: str, stage: str) -> str:
    return f"{case}-{stage}" if case else stage


def search_problem(run: RunDirectory, case: str, problem: DesignProblem, transcription, settings: Multistart,
                   search: Search, experiment: str, jobs: int | None = -1, resume: bool = False,
                   progress: Progress | None = None) -> Searched:
    """Search one problem the way ``search`` says (`designopt.search`), writing every solve to ``run``."""
    if search.strategy == "multistart":
        tasks = multistart_tasks(case, "to", problem, transcription, settings)
        return Searched([], solve_tasks(run, tasks, experiment, jobs, resume, progress))
    explore = multistart_tasks(_stage(case, "explore"), "to", coarse_problem(problem, search.explore_waypoints),
                               replace(transcription, max_iter=search.explore_max_iter),
                               replace(settings, count=search.explore_starts))
    explored = sorted(solve_tasks(run, explore, experiment, jobs, resume, progress), key=lambda d: d[0].index)
    picked = distinct_best([sol for _, sol in explored], search.refine, search.distinct)
    warm = replace(transcription, ipopt={**transcription.ipopt, **WARM_IPOPT})
    refine = [Task(_stage(case, "refine"), "to", problem, warm, settings, explored[i][0].index, explored[i][1])
              for i in picked]
    return Searched(explored, solve_tasks(run, refine, experiment, jobs, resume, progress))
