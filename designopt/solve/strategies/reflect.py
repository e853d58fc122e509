"""The reflect step: each problem's best full-path solution reflected across the length bounds it lies at.

A DH arm is the same arm when one of its lengths changes sign and the twists beside it turn by pi
(`designopt.kinematics.reflections`). With design lengths bounded below by 0 (SPEC), a design whose cost falls as a
length goes below 0 stops at the bound: a local optimum of the parametrisation, not of the arm. Its reflection is
the same arm with the length free to grow on the other side. After the strategy (and the neighbour step), up to
``search.reflect`` rounds (stages ``reflect``, ``reflect2``, ...): each problem's best full-path solution, reflected
across each length within ``WITHIN`` of its bound of 0 and pushed ``search.distinct`` across (`starts.Reflected`),
is solved warm on the full path from barrier ``MU_INIT``; the next round reflects each new best, while a round
lowers some problem's best design cost by more than ``GAIN`` (a fraction). With ``search.reflect_within`` set, the
first round reflects every distinct full-path optimum within that factor of the best (`leading`): a runner-up held at
a bound is often a better arm than the best once reflected. The step only adds solves: an answer
can only fall. Problems with nothing at a bound get no task.
"""

from __future__ import annotations

from designopt.kinematics.reflections import at_bound
from designopt.solve.optima import best_solution, distinct_best
from designopt.solve.search import Searched, by_job
from designopt.solve.starts import Reflected
from designopt.solve.strategies.steps import numbered_stage, solve_setup
from designopt.solve.tasks import Task

STAGE = "reflect"
# A length within WITHIN (m) of its lower bound of 0 is reflected, each reflected start solved warm from barrier
# MU_INIT (it stays in the basin it is given, as a refine from 1e-6 does), rounds going on while the best design cost
# falls by more than GAIN. Over 330 reflect solves of 40 runs (main job and physical stiffness, lengths within 0.01
# m reflected): of the lengths within 1e-5 m of the bound 17 of 17 gained (up to 9 %), within 1e-5-1e-4 m 18 of 68,
# further out 14 of 247, mostly by < 0.2 % (a length that sits near 0 by the arm's own symmetry, at about 7e-4 m,
# comes back to it): 1e-4 m keeps a quarter of the solves and the gains that matter (docs/decisions.md)
WITHIN = 1e-4
MU_INIT = 1e-6
GAIN = 1e-3
FIRST_START = 900  # the first start index of a reflect stage's starts, unless the exploration's reach it (first_start)
LEADER_STRIDE = 100  # the start indices of the j-th optimum a round reflects: from first_start + j * LEADER_STRIDE


def first_start(search) -> int:
    """The first start index of a reflect stage's starts: ``FIRST_START``, or the first multiple of
    ``LEADER_STRIDE`` past every index the exploration and the hop step can use (`Search.last_start`) when those
    reach it, so that every start of a run has its own number."""
    return max(FIRST_START, -(-search.last_start // LEADER_STRIDE) * LEADER_STRIDE)


def plan(searched: list[Searched], search):
    """Up to ``search.reflect`` rounds over every problem's best full-path solution (the first round over its
    `leading` optima; a generator, as a strategy's plan: yields a round's tasks, receives their solutions); returns
    ``searched`` with the rounds' solves added to each problem's final solves."""
    jobs = [s.job for s in searched]
    final = [list(s.final) for s in searched]
    looked_at = [None] * len(jobs)  # per job, the best solution the last round reflected
    for i in range(search.reflect):
        bests = [best_solution([sol for _, sol in done]) for done in final]
        within = search.reflect_within if i == 0 else None  # later rounds: the new best alone
        tasks = reflected_tasks([(job, leading([sol for _, sol in done], best, within, search))
                                 for job, done, best, last in zip(jobs, final, bests, looked_at, strict=True)
                                 if best is not None and best is not last], numbered_stage(STAGE, i), search)
        if not tasks:
            break
        more = by_job(jobs, (yield tasks))
        final = [done + new for done, new in zip(final, more, strict=True)]
        looked_at = bests
        gained = [best_solution([sol for _, sol in done]) for done in final]
        if not any(b is not None and g.metrics.design_cost < (1 - GAIN) * b.metrics.design_cost
                   for b, g in zip(bests, gained, strict=True)):
            break
    return [Searched(s.job, s.explore, f) for s, f in zip(searched, final, strict=True)]


def leading(solutions, best, within: float | None, search) -> list:
    """The optima a round reflects: ``best`` (the best of ``solutions``) alone when ``within`` is None, else every
    distinct optimum among ``solutions`` (`optima.distinct_best`: ``search.distinct`` apart, the same arm within
    ``search.same_arm_cost`` of a cheaper one's cost one optimum) whose design cost is within that factor of
    ``best``'s, cheapest first (``best`` among them)."""
    if within is None:
        return [best]
    optima = [solutions[k] for k in distinct_best(solutions, len(solutions), search.distinct,
                                                  same_arm_cost=search.same_arm_cost)]
    return [s for s in optima if s.metrics.design_cost <= within * best.metrics.design_cost]


def reflected_tasks(leaders, stage_name: str, search) -> list[Task]:
    """For every (job, its optima to reflect, cheapest first), a task per length of each optimum within ``WITHIN``
    of its bound of 0 whose reflection keeps the motion within the joints' bounds (`kinematics.reflections.at_bound`),
    starting from the solution reflected and pushed ``search.distinct`` across (`Reflected`), solved warm on the
    full path from barrier ``MU_INIT``. The j-th optimum's start indices from ``first_start(search) + j *
    LEADER_STRIDE`` on (the best's from `first_start`)."""
    warm = search.profile.warmed().with_options(**{"ipopt.mu_init": MU_INIT})
    tasks, begin = [], first_start(search)
    for job, optima in leaders:
        chain = job.problem.chain
        profile, continuation = solve_setup(job, search, warm)
        for j, best in enumerate(optima):
            Q = best.sample(job.problem.toolpath.t)
            for k, reflection in enumerate(at_bound(chain, best.raw.q_d, WITHIN)):
                if reflection.joints(chain, Q) is None:
                    continue
                start = Reflected(best, reflection, search.distinct, search.seed, begin + j * LEADER_STRIDE + k)
                tasks.append(Task(job.case, stage_name, job.problem, job.transcription, profile, start, continuation))
    return tasks
