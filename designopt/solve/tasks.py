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
from designopt.solve.profile import SolverProfile


@dataclass(frozen=True, eq=False)
class Task:
    case: str
    stage: str
    problem: DesignProblem
    transcription: object
    profile: SolverProfile
    start: object  # designopt.solve.starts.Seeded | Lifted
    continuation: object | None = None  # e.g. designopt.solve.strategies.continuation.HoldDegenerate

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
    solution = solve_guess(task.problem, task.transcription, task.profile, task.start.guess(task.problem))
    if task.continuation is not None:
        solution = task.continuation.finish(task, solution)
    return solution


def _run(task: Task) -> tuple[Task, Solution]:
    return task, run_task(task)


def fan_out(tasks: list[Task], jobs: int | None) -> Iterator[tuple[Task, Solution]]:
    """Yield (task, solution) as tasks finish: in this process if jobs == 1, else joblib processes (jobs = -1:
    every core; None: joblib's active backend decides, e.g. a Dask cluster)."""
    if jobs == 1 or len(tasks) <= 1:
        for t in tasks:
            yield _run(t)
        return
    from joblib import Parallel, delayed

    yield from Parallel(n_jobs=jobs, return_as="generator_unordered")(delayed(_run)(t) for t in tasks)
