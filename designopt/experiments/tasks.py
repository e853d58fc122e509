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

import numpy as np

from designopt.multistart import Multistart, best_solution, solve_guess, solve_start
from designopt.problem import DesignProblem
from designopt.results_io import RunDirectory
from designopt.search import WARM_IPOPT, Search, coarse_problem, distinct_best, lifted_guess
from designopt.solution import Solution, SolutionLoadError, read_solution_for, write_solution


@dataclass(frozen=True)
class Task:
    """Start ``index`` of a seeded multistart of ``problem`` with ``transcription``, labelled ``case``; with
    ``warm``, the start is that solution (of another sampling of the same task) lifted to ``problem``; with
    ``design``, the start's design is that one."""

    case: str
    method: str
    problem: DesignProblem
    transcription: object
    settings: Multistart
    index: int
    warm: Solution | None = None
    design: np.ndarray | None = None  # a start design (IK-initialised like every start) instead of the seeded one

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
    return task, solve_start(task.problem, task.transcription, task.settings, task.index, task.case, task.design)


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


@dataclass(frozen=True)
class Searchable:
    """One problem to search: its ``case`` label (stages append -explore, -screen, -refine) and transcription."""

    case: str
    problem: DesignProblem
    transcription: object


def _by_problem(items: list[Searchable], done: list[tuple[Task, Solution]], stage: str | None = None) -> list[list]:
    """Split one stage's (task, solution) pairs by the problem they belong to, each list in start order."""
    where = {(_stage(it.case, stage) if stage else it.case, it.problem.chain.structure): k
             for k, it in enumerate(items)}
    out = [[] for _ in items]
    for task, sol in done:
        out[where[task.case, task.problem.chain.structure]].append((task, sol))
    return [sorted(d, key=lambda d: d[0].index) for d in out]


def _lifted_tasks(items: list[Searchable], found: list[list], count: int, stage: str, waypoints: int | None,
                  settings: Multistart, search: Search, max_iter: int | None = None) -> list[Task]:
    """For every problem, its ``count`` best distinct solutions lifted to ``waypoints`` (None: the full path),
    each solved warm within ``max_iter`` iterations (None: the transcription's own cap)."""
    tasks = []
    for it, done in zip(items, found, strict=True):
        problem = it.problem if waypoints is None else coarse_problem(it.problem, waypoints)
        warm = replace(it.transcription, ipopt={**it.transcription.ipopt, **WARM_IPOPT})
        if max_iter is not None:
            warm = replace(warm, max_iter=min(max_iter, warm.max_iter))
        for i in distinct_best([sol for _, sol in done], count, search.distinct):
            tasks.append(Task(_stage(it.case, stage), "to", problem, warm, settings, done[i][0].index, done[i][1]))
    return tasks


def search_problems(run: RunDirectory, items: list[Searchable], settings: Multistart, search: Search,
                    experiment: str, jobs: int | None = -1, resume: bool = False,
                    progress: Progress | None = None) -> list[Searched]:
    """Search several problems the way ``search`` says (`designopt.search`), one stage at a time across all of
    them (so that workers stay busy), writing every solve to ``run``. Problems are told apart by case and
    structure."""
    if search.strategy == "multistart":
        tasks = [t for it in items for t in multistart_tasks(it.case, "to", it.problem, it.transcription, settings)]
        done = solve_tasks(run, tasks, experiment, jobs, resume, progress)
        return [Searched([], f) for f in _by_problem(items, done)]
    explore = [t for it in items for t in multistart_tasks(
        _stage(it.case, "explore"), "to", coarse_problem(it.problem, search.explore_waypoints),
        replace(it.transcription, max_iter=search.explore_max_iter), replace(settings, count=search.explore_starts))]
    explored = _by_problem(items, solve_tasks(run, explore, experiment, jobs, resume, progress), "explore")
    candidates = explored
    screened = [k for k, it in enumerate(items) if 0 < search.screen_waypoints < it.problem.toolpath.n]
    if screened:
        # rank the best distinct coarse optima again on a finer (still cheap) sampling before the full path
        sub = [items[k] for k in screened]
        tasks = _lifted_tasks(sub, [explored[k] for k in screened], search.screen, "screen", search.screen_waypoints,
                              settings, search, search.screen_max_iter)
        found = dict(zip(screened, _by_problem(sub, solve_tasks(run, tasks, experiment, jobs, resume, progress),
                                                "screen"), strict=True))
        candidates = [found.get(k, explored[k]) for k in range(len(items))]
    tasks = _lifted_tasks(items, candidates, search.refine, "refine", None, settings, search)
    final = _by_problem(items, solve_tasks(run, tasks, experiment, jobs, resume, progress), "refine")
    return [Searched(e, f) for e, f in zip(explored, final, strict=True)]


def search_problem(run: RunDirectory, case: str, problem: DesignProblem, transcription, settings: Multistart,
                   search: Search, experiment: str, jobs: int | None = -1, resume: bool = False,
                   progress: Progress | None = None) -> Searched:
    """Search one problem (`search_problems`)."""
    return search_problems(run, [Searchable(case, problem, transcription)], settings, search, experiment, jobs,
                           resume, progress)[0]
