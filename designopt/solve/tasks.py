"""Tasks: one start of one problem, typed -- what a strategy emits and a worker solves.

A task names the problem it belongs to (``case``: which problem of the experiment), the strategy step that made it
(``stage``), the problem and its transcription, the solver profile, where it starts, and what to do if the solve
stops on a design it cannot finish (``continuation``). ``key`` identifies the solve in a run's files.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from designopt.problem import DesignProblem
from designopt.solution import Solution
from designopt.solve.local import solve_guess
from designopt.solve.observers import Bound
from designopt.solve.profile import SolverProfile


@dataclass(frozen=True, eq=False)
class Task:
    case: str
    stage: str
    problem: DesignProblem
    transcription: object
    profile: SolverProfile
    start: object  # designopt.solve.starts.Seeded | Lifted | Rebranched
    continuation: object | None = None  # e.g. designopt.solve.strategies.continuation.HoldDegenerate
    bound: Bound | None = None  # what the solve is held to, if its profile observes "above_bound"

    @property
    def method(self) -> str:
        return self.transcription.name

    @property
    def seed(self) -> int:
        return self.start.number

    @property
    def key(self) -> tuple[str, str, str, str, int]:
        """(case, stage, method, structure, seed): what identifies a solve in summary.csv."""
        return self.case, self.stage, self.method, self.problem.chain.structure, self.seed

    @property
    def file_name(self) -> str:
        stem = "-".join(p for p in (self.case, self.stage, self.method, self.problem.chain.structure) if p)
        return f"solutions/{stem}-s{self.seed}.json"


def run_task(task: Task) -> Solution:
    """Solve one task (and its continuation, when the solve stopped where the continuation takes over)."""
    solution = solve_guess(task.problem, task.transcription, task.profile, task.start.guess(task.problem), task.bound)
    if task.continuation is not None:
        solution = task.continuation.finish(task, solution)
    return solution


def _run(task: Task) -> tuple[Task, Solution]:
    return task, run_task(task)


def _run_all(unit: list[Task]) -> list[tuple[Task, Solution]]:
    return [_run(t) for t in unit]


def units(tasks: list[Task], workers: int) -> list[list[Task]]:
    """How tasks go to workers. The starts of one problem (the same problem object, transcription and profile) go
    together, in pieces of at most len(tasks) / (4 workers) tasks: every worker gets about four units, no unit is a
    long tail, and a worker builds and prepares the NLPs of a few problems instead of every worker every
    problem's (a sweep's structures, a modular enumeration's assignments; on 64 workers a 126-structure sweep's
    exploration went 75 -> 36 s against a task per unit, replayed by benchmarks/sweep_scaling.py). A stage of one
    problem goes out a task per unit: every worker builds that problem whatever the units, and single starts
    balance best."""
    groups: dict[tuple, list[Task]] = {}
    for t in tasks:
        groups.setdefault((id(t.problem), t.transcription, t.profile), []).append(t)
    if len(groups) == 1:
        return [[t] for t in tasks]
    most = max(1, len(tasks) // (4 * workers))
    return [group[i : i + most] for group in groups.values() for i in range(0, len(group), most)]


def fan_out(tasks: list[Task], jobs: int | None) -> Iterator[tuple[Task, Solution]]:
    """Yield (task, solution) as tasks finish: in this process if jobs == 1, else joblib processes (jobs = -1:
    every core; None: joblib's active backend decides, e.g. a Dask cluster), the tasks dispatched in `units`."""
    if jobs == 1 or len(tasks) <= 1:
        for t in tasks:
            yield _run(t)
        return
    from joblib import Parallel, delayed, effective_n_jobs

    dispatched = units(tasks, effective_n_jobs(jobs))
    for done in Parallel(n_jobs=jobs, return_as="generator_unordered")(delayed(_run_all)(u) for u in dispatched):
        yield from done
