"""The hop step: restarts around each problem's best full-path optima (basin hopping).

The exploration finds basins through a coarse proxy of the path, and the best basins of a problem often have no
coarse optimum that lifts into them; they lie a few centimetres or a fraction of a radian from the optima the
refine reached, on another joint branch. After the strategy (and the neighbour step), each problem's
``search.hop_incumbents`` best distinct full-path optima are each started again ``search.hop`` times on a new joint
branch with the design moved around theirs by ``search.hop_perturbation`` (`starts.Rebranched`: x 0.5 m for lengths,
x pi rad for angles), solved on the screen's sampling of the path (`coarse_to_fine.screening`; stage ``hop``, at
most ``search.screen_max_iter`` iterations), and the ``search.hop_refine`` best distinct of those lifted to the
full path and solved warm, joining the problem's final solves, where the reflect step finds them. A problem whose
path has no more waypoints than the screen's solves its hops on the full path. The step's full-path solves are stage
``hop_full``. The step only adds solves: an answer can only fall.
"""

from __future__ import annotations

from designopt.solve.optima import distinct_best
from designopt.solve.search import Searched, by_job
from designopt.solve.starts import Rebranched
from designopt.solve.strategies.coarse_to_fine import coarse_problem, lifted_tasks, screening
from designopt.solve.strategies.steps import solve_setup
from designopt.solve.tasks import Task

STAGE = "hop"
FULL_STAGE = "hop_full"  # the hop step's solves on the full path


def plan(searched: list[Searched], search):
    """The hop step over every problem (a generator, as a strategy's plan: yields a stage's tasks, receives their
    solutions); returns ``searched`` with the full-path solves it adds joined to each problem's final solves."""
    jobs = [s.job for s in searched]
    sizes = [w if w is not None and 0 < w < job.problem.toolpath.n else None  # None: hops on the full path
             for job, (_, w) in zip(jobs, screening([job.problem for job in jobs], search), strict=True)]
    tasks = [task for s, waypoints in zip(searched, sizes, strict=True) for task in hop_tasks(s, waypoints, search)]
    hops = by_job(jobs, (yield tasks))
    coarse = [k for k, waypoints in enumerate(sizes) if waypoints is not None]
    refined = by_job(jobs, (yield [task for k in coarse for task in lifted_tasks(
        [jobs[k]], [hops[k]], search.hop_refine, FULL_STAGE, None, search)]))
    final = [list(s.final) + (refined[k] if k in coarse else hops[k]) for k, s in enumerate(searched)]
    return [Searched(s.job, s.explore, f) for s, f in zip(searched, final, strict=True)]


def hop_tasks(searched: Searched, waypoints: int | None, search) -> list[Task]:
    """The hops of one problem: ``search.hop`` starts around each of its ``search.hop_incumbents`` best distinct
    tracking full-path optima (`optima.distinct_best`, the same arm placed elsewhere one optimum with
    ``search.same_arm_cost``), solved on ``waypoints`` of the path (None: the full path), numbered from
    `Search.hop_start` of the optimum's rank; stage ``hop``, or ``hop_full`` on the full path."""
    job = searched.job
    final = [sol for _, sol in searched.final]
    incumbents = [final[i] for i in distinct_best(final, search.hop_incumbents, search.distinct,
                                                  same_arm_cost=search.same_arm_cost)]
    problem = job.problem if waypoints is None else coarse_problem(job.problem, waypoints)
    stage = STAGE if waypoints is not None else FULL_STAGE
    profile, continuation = solve_setup(job, search, search.profile.capped(search.screen_max_iter))
    return [Task(job.case, stage, problem, job.transcription, profile,
                 Rebranched(incumbent, search.seed, search.hop_start(rank) + j, search.init, search.hop_perturbation),
                 continuation)
            for rank, incumbent in enumerate(incumbents) for j in range(search.hop)]
