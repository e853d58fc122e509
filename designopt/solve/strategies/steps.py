"""What every strategy's tasks share: the profile and continuation of a job's solves, seeded starts, and the names
of a stage's passes."""

from __future__ import annotations

from designopt.solve.search import Job, Search
from designopt.solve.starts import Seeded
from designopt.solve.strategies.continuation import HoldDegenerate
from designopt.solve.tasks import Task


def solve_setup(job: Job, search: Search, profile=None):
    """(profile, continuation) of a job's solves: the search's profile (or ``profile``) watching for degenerate
    designs, and the continuation that finishes such a solve, when the search holds them and the job's
    transcription tracks exactly."""
    profile = profile or search.profile
    if search.hold_degenerate and job.tracks_exactly:
        return profile.observing(HoldDegenerate.observer), HoldDegenerate()
    return profile, None


def seeded_tasks(job: Job, stage: str, problem, profile, search: Search, count: int) -> list[Task]:
    """``count`` seeded starts of ``problem`` (the job's, or a coarser sampling of it)."""
    profile, continuation = solve_setup(job, search, profile)
    return [Task(job.case, stage, problem, job.transcription, profile,
                 Seeded(search.seed, i, search.perturbation_for(job.problem.chain.n_moving), search.init,
                        spread=search.spread), continuation)
            for i in range(count)]


def numbered_stage(stage: str, i: int) -> str:
    """The name of a stage's ``i``-th pass (0-based): screen, screen2, ... (one per `Search.screen_passes` or barrier
    of `Search.refine_mu_init`); reflect, reflect2, ... (rounds); neighbour, neighbour2, ... (passes)."""
    return stage if i == 0 else f"{stage}{i + 1}"
