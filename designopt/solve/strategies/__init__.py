"""Strategies: which tasks a search solves, stage by stage, and `run_search`, which drives one.

A strategy module has ``plan(jobs, search)``, a generator that yields one stage's tasks for every job, receives
their (task, solution) pairs, and at the end returns one `Searched` per job. Adding a strategy is a module here
and a line in `STRATEGIES`. Four steps serve every strategy: `continuation` (finishing a solve stalled on a
degenerate design), then, after the strategy, `neighbours` (starts from a neighbouring structure's better design),
`hop` (restarts around the best full-path optima) and `reflect` (each best, or each optimum near it, reflected
across the length bounds it lies at).
"""

from __future__ import annotations

from collections.abc import Callable

from designopt.solution import Solution
from designopt.solve.search import Job, Search, Searched
from designopt.solve.strategies import coarse_to_fine, hop, multistart, neighbours, reflect
from designopt.solve.tasks import Task

STRATEGIES = {"multistart": multistart, "coarse_to_fine": coarse_to_fine}

Execute = Callable[[list[Task]], list[tuple[Task, Solution]]]


def run_search(jobs: list[Job], search: Search, execute: Execute) -> list[Searched]:
    """Search every job the way ``search`` says; every stage's tasks of all jobs go to ``execute`` together (so
    that workers stay busy), which returns their (task, solution) pairs -- the experiment's executor writes each
    solve as it finishes and resumes."""
    if search.strategy not in STRATEGIES:
        raise ValueError(f"strategy must be one of {tuple(STRATEGIES)}, got {search.strategy!r}")
    if len({job.identity for job in jobs}) < len(jobs):
        raise ValueError("two jobs of one search share case, method and structure")
    searched = _drive(STRATEGIES[search.strategy].plan(jobs, search), execute)
    if search.structure_neighbours:
        searched = _drive(neighbours.plan(searched, search), execute)
    if search.hop:
        searched = _drive(hop.plan(searched, search), execute)
    if search.reflect:
        searched = _drive(reflect.plan(searched, search), execute)
    return searched


def _drive(plan, execute: Execute):
    """Run a strategy's plan (a generator: yields a stage's tasks, receives their results, returns its answer)."""
    try:
        tasks = next(plan)
        while True:
            tasks = plan.send(execute(tasks) if tasks else [])
    except StopIteration as stop:
        return stop.value
