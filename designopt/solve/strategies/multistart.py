"""Multistart: ``search.starts`` seeded cold starts of every problem on its full path; the answer is the best.

The paper's comparisons use it (preset ``paper``): every method gets the same starts, start for start. A cold start
that stops getting closer to the path is stopped (`designopt.solve.observers.StalledViolation`): on a long program
one that cannot track otherwise runs until IPOPT's restoration phase gives up, its cap or its time limit.
"""

from __future__ import annotations

from designopt.solve.search import Searched, by_job
from designopt.solve.strategies.steps import seeded_tasks

STAGE = "start"
# Only for transcriptions that track exactly (TO): their violation is the distance to the path. Of the cold starts
# traced (benchmarks/violation_traces.py: the pocket cell 16, the Kinova and the PUMA on the Button program 8 each, the
# main job 16, its placement-only case 8), none that went on to track would have been stopped with a patience above
# 60 iterations (docs/benchmarks.md "Stalled starts"); the FK baseline, whose starts were not traced, keeps IPOPT's
# own ending.
STALLED = "stalled_violation"


def plan(jobs, search):
    tasks = []
    for job in jobs:
        watched = search.profile.observing(STALLED) if job.tracks_exactly else None
        tasks += seeded_tasks(job, STAGE, job.problem, watched, search, search.starts)
    done = yield tasks
    return [Searched(job, [], final) for job, final in zip(jobs, by_job(jobs, done), strict=True)]
