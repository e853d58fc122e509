"""Neighbour starts: one more start per problem from each neighbouring structure that found a better design.

Two problems of one search are neighbours when they share their case and their structures differ in one joint's
type (R <-> P). A structure whose neighbour found a cheaper design was stuck in a worse basin, and the neighbour's
design -- its placement and every link parameter of the same name -- is a good guess for it. The starts are solved
on the full path (stage ``neighbour``) and join each problem's final solves. Problems without neighbours (every
search of a single structure) get no task.
"""

from __future__ import annotations

from designopt.initial_guess import design_from
from designopt.solve.search import Searched, by_job
from designopt.solve.starts import Seeded
from designopt.solve.strategies.steps import solve_setup
from designopt.solve.tasks import Task

STAGE = "neighbour"


def neighbours(structure: str, structures: list[str]) -> list[str]:
    """The structures among ``structures`` that differ from ``structure`` in one joint's type (R <-> P)."""
    return [s for s in structures
            if len(s) == len(structure) and sum(a != b for a, b in zip(s, structure, strict=True)) == 1]


def plan(searched, search):
    jobs = [s.job for s in searched]
    best = {(s.job.case, s.job.problem.chain.structure): (s.job, s.best[1]) for s in searched}
    tasks = []
    for s in searched:
        job, own = s.job, s.best[1]
        same_case = [st for case, st in best if case == job.case]
        for j, other in enumerate(neighbours(job.problem.chain.structure, same_case)):
            other_job, theirs = best[job.case, other]
            if theirs is None or (own is not None and theirs.metrics.design_cost >= own.metrics.design_cost):
                continue
            design = design_from(job.problem, other_job.problem, theirs.raw.q_d)
            profile, continuation = solve_setup(job, search)
            tasks.append(Task(job.case, STAGE, job.problem, job.transcription, profile,
                              Seeded(search.seed, j, search.perturbation, search.init, design), continuation))
    if not tasks:
        return searched
    more = by_job(jobs, (yield tasks))
    return [Searched(s.job, s.explore, s.final + m) for s, m in zip(searched, more, strict=True)]
