"""Multistart: ``search.starts`` seeded cold starts of every problem on its full path; the answer is the best.

The paper's comparisons use it (preset ``paper``): every method gets the same starts, start for start.
"""

from __future__ import annotations

from designopt.solve.search import Searched, by_job
from designopt.solve.strategies.steps import seeded_tasks

STAGE = "start"


def plan(jobs, search):
    done = yield [t for job in jobs for t in seeded_tasks(job, STAGE, job.problem, None, search, search.starts)]
    return [Searched(job, [], final) for job, final in zip(jobs, by_job(jobs, done), strict=True)]
