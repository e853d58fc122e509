"""Strategies: which tasks a search solves, stage by stage, and `run_search`, which drives one.

A strategy module has ``plan(jobs, search)``, a generator that yields one stage's tasks for every job, receives
their (task, solution) pairs, and at the end returns one `Searched` per job. Adding a strategy is a module here
and a line in `STRATEGIES`. Four steps serve every strategy: `continuation` (finishing a solve stalled on a
degenerate design), then, after the strategy, `neighbours` (starts from a neighbouring structure's better design),
`hop` (restarts around the best full-path optima) and `reflect` (each best, or each optimum near it, reflected
across the length bounds it lies at). A search of several independent draws (`Search.draws`) runs all of this per
draw, the draws' stages side by side.
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
    solve as it finishes and resumes. With ``search.draws`` > 1 each draw (`Search.drawn`) is searched alike, the
    draws' stages side by side, and each job's `Searched` holds every draw's solves (its best is the best of all)."""
    if search.strategy not in STRATEGIES:
        raise ValueError(f"strategy must be one of {tuple(STRATEGIES)}, got {search.strategy!r}")
    if len({job.identity for job in jobs}) < len(jobs):
        raise ValueError("two jobs of one search share case, method and structure")
    found = _drive([_steps(jobs, drawn) for drawn in search.drawn()], execute)
    if len(found) == 1:
        return found[0]
    return [Searched(job, _in_start_order(s.explore for s in each), _in_start_order(s.final for s in each))
            for job, each in zip(jobs, zip(*found, strict=True), strict=True)]


def _steps(jobs: list[Job], search: Search):
    """One draw's search as one plan: the strategy, then the neighbour, hop and reflect steps it asks for."""
    searched = yield from STRATEGIES[search.strategy].plan(jobs, search)
    if search.structure_neighbours:
        searched = yield from neighbours.plan(searched, search)
    if search.hop:
        searched = yield from hop.plan(searched, search)
    if search.reflect:
        searched = yield from reflect.plan(searched, search)
    return searched


def _in_start_order(lists) -> list[tuple[Task, Solution]]:
    return sorted((pair for pairs in lists for pair in pairs), key=lambda pair: pair[0].seed)


def _drive(plans: list, execute: Execute) -> list:
    """Run plans side by side (generators: each yields a stage's tasks, receives their results, returns its
    answer): every plan's current stage goes to ``execute`` in one call, and each plan gets back the results of its
    own tasks (told apart by `Task.key`, which the draws' seeds keep apart). Returns each plan's answer."""
    answers, current = [None] * len(plans), {}

    def advance(k: int, results) -> None:
        try:
            current[k] = plans[k].send(results)
        except StopIteration as stop:
            current.pop(k, None)
            answers[k] = stop.value

    for k in range(len(plans)):
        advance(k, None)
    while current:
        owner = {}
        for k, tasks in current.items():
            for task in tasks:
                if owner.setdefault(task.key, k) != k:
                    raise ValueError(f"two draws of one search share a solve: {task.key}")
        done = execute([task for tasks in current.values() for task in tasks]) if owner else []
        back = {k: [] for k in current}
        for task, sol in done:
            back[owner[task.key]].append((task, sol))
        for k in list(current):
            advance(k, back[k])
    return answers
