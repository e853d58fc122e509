"""Coarse to fine: explore many cheap starts on a coarse sampling of the path, refine the best distinct optima.

A start's objective after a few hundred IPOPT iterations barely predicts where it ends; the same problem on fewer
waypoints does: a design optimal for a coarse sampling of the path lies, more often than not, in the basin of a
design optimal for the full path. Stages, each across every problem:

1. ``explore``: ``search.starts`` cold seeded starts (a smaller problem of several more: `exploration_starts`) of
   the *coarse problem* -- the same robot, placement, costs and
   cell on ``explore_waypoints`` of the path's waypoints (`coarse_problem`) -- each capped at
   ``explore_max_iter``. A coarse solve costs about a tenth of a full one. Then the ``rebranch`` best distinct
   coarse optima (at most ``rebranch_per_form`` of one form, when set; and the cheapest of up to
   ``rebranch_new_forms`` forms not among them) are each started again ``starts //
   rebranch`` times with their design on a new joint branch
   (first joints over the whole circle, `Rebranched`), explored alike and pooled with the first round: a start lands in
   the best basin only when its design and its branch both fit, and good designs are where to look for branches.
   With ``rebranch_rounds`` > 1 the rounds on new joint branches share those starts, each round from the best
   distinct optima of every round before it; with ``rebranch_pool`` > 1 a leader's starts are drawn that many times
   over and those kept spread over the branches their walks reach first; with ``rebranch_extra`` > 0 (the default's
   30) a leader's drawn starts all stay and that many more join them, spread over the branches they miss.
2. ``prescreen`` (with ``search.prescreen`` > 0, on fewer waypoints than the screen's): the ``prescreen`` best
   distinct coarse optima after those the screen takes, lifted to ``prescreen_waypoints`` and solved warm as the
   screen's first pass solves (a smaller problem's more, as for the screen); the ``prescreen_keep`` best of them
   join the screen's candidates (`best_prescreened`): coarse optima the exploration's few waypoints rank low but
   more waypoints rank high, for a fraction of the screen's cost per candidate. With ``screen_prescreened``
   "prescreened" the screen lifts their prescreened optima, not their coarse optima (the way 10 -> 20 -> 40
   waypoints keeps a basin that a lift straight from 10 waypoints can leave, and leaves one that it keeps); with
   "both" it lifts both, the prescreened optima in passes of their own (stages after the screen's passes, e.g.
   ``screen3``, ``screen4``), and `better_pass` keeps each candidate's best.
3. ``screen`` (when the path has more than ``screen_waypoints`` waypoints): the ``screen`` best distinct coarse
   optima (at most ``screen_per_form`` of one form before other forms, when set; a smaller problem of several more,
   on more waypoints: `screening`), and the prescreen's, lifted to ``screen_waypoints`` waypoints, solved warm within
   ``screen_max_iter`` and ranked again there: the coarse ranking alone often puts a design that lifts badly ahead
   of one that lifts well. Once per barrier of ``screen_mu_init`` and linear solver of ``screen_linear_solver``
   (stages ``screen``, ``screen2``, ...: `Search.screen_passes`; a small arm the first pass only, when
   ``small_arm_screens_once``), each candidate ranked by its better pass.
4. ``refine``: the ``refine`` best distinct screened (or coarse) optima (with ``refine_distinct_arms``, the same
   arm written another way, e.g. two twists turned by pi about offsets of 0, one candidate) lifted to the full
   path (design as is, trajectory sampled from the coarser solution's) and solved warm, so that each stays in the
   basin it was given;
   once per barrier of ``refine_mu_init`` (stages ``refine``, ``refine2``, ...), and with ``refine_relaxed`` the
   best that many once more through velocity limits relaxed to fit their lift, and with ``refine_from_coarse``
   once more from each one's coarse optimum lifted straight to the full path (the next stage: its screened
   solution fits the screen's waypoints and may lift badly), the best of all kept.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from designopt.problem import DesignProblem
from designopt.solve.optima import best_solution, distinct_best
from designopt.solve.search import Searched, by_job
from designopt.solve.starts import Lifted, Rebranched, first_configurations_of, lifted_guess, spread_branches
from designopt.solve.strategies.steps import numbered_stage, seeded_tasks, solve_setup
from designopt.solve.tasks import Task
from designopt.toolpaths import subsample


def coarse_problem(problem: DesignProblem, waypoints: int) -> DesignProblem:
    """The same problem on ``waypoints`` of its path's waypoints (first and last kept)."""
    return replace(problem, toolpath=subsample(problem.toolpath, waypoints))


def exploration_starts(problems: list[DesignProblem], search) -> list[int]:
    """Exploration starts per problem: its share of the batch (`shares`), ``search.small_arm_starts`` times it for a
    small arm (`Search.starts_for`)."""
    counts = shares(problems, search)
    return [search.starts_for(p.chain.n_moving, share) for p, share in zip(problems, counts, strict=True)]


def shares(problems: list[DesignProblem], search) -> list[int]:
    """Each problem's share of a batch's exploration starts: ``search.starts`` each; with
    ``search.small_problem_starts`` above 1, a problem with fewer unknowns n than the largest of ``problems`` gets
    starts x (n_max / n)^2, rounded, at most ``small_problem_starts`` x starts. n counts the exploration problem's
    joints (moving joints x ``explore_waypoints``) and design joints. A start's CPU grows about as n^2 (iterations
    and their cost both grow with n; a K = I sweep: 0.038, 0.069, 0.097, 0.144 s per start of its 3-, 4-, 5- and
    6-joint structures, where (n_max / n)^2 predicts 3.5, 2.1, 1.4 and 1 times the last), so each problem's
    exploration costs about the largest one's: a small structure, whose starts are cheap and whose basins its
    `starts` miss, gets more of them."""
    if search.small_problem_starts <= 1:
        return [search.starts] * len(problems)
    size = _unknowns(problems, search.explore_waypoints)
    largest = max(size, default=1)
    return [round(search.starts * min(search.small_problem_starts, (largest / n) ** 2)) for n in size]


def screening(problems: list[DesignProblem], search) -> list[tuple[int, int | None]]:
    """(candidates, waypoints) of each problem's screen: ``search.screen`` on ``search.screen_waypoints`` each; with
    ``search.small_problem_starts`` above 1, a problem with a larger share of the starts (`shares`) screens as
    many times more candidates, on as many waypoints w as keep its screen problem the size of the largest one's
    (m w + d = n_max for m moving and d design joints; at least ``screen_waypoints``; None, the full path, once w
    reaches the path's count). A small structure's optima often tie on a coarse sampling and part only on the full
    path (a K = I sweep's RRR: one 20-waypoint optimum lifts to 0.0218 or 0.0243), and its finer screen costs
    about what the largest structure's screen does."""
    if search.small_problem_starts <= 1:
        return [(search.screen, search.screen_waypoints)] * len(problems)
    largest = max(_unknowns(problems, search.screen_waypoints), default=1)
    out = []
    for problem, starts in zip(problems, shares(problems, search), strict=True):
        chain = problem.chain
        waypoints = max(search.screen_waypoints, round((largest - chain.n_design) / max(chain.n_moving, 1)))
        full = waypoints >= problem.toolpath.n
        out.append((round(search.screen * starts / search.starts), None if full else waypoints))
    return out


def _unknowns(problems: list[DesignProblem], waypoints: int) -> list[int]:
    """Each problem's unknowns on (at most) ``waypoints`` of its waypoints: moving joints x waypoints + design
    joints."""
    return [p.chain.n_moving * min(waypoints, p.toolpath.n) + p.chain.n_design for p in problems]


def lifted_tasks(jobs, found, count: int, stage: str, waypoints: int | None, search, max_iter: int | None = None,
                 mu_init: float | None = None, per_form: int | None = None, linear_solver: str | None = None,
                 new_leaders: int = 0):
    """For every job, its ``count`` best distinct solutions (at most ``per_form`` of one form before other forms,
    `optima.distinct_best`; None: by cost alone; then the best of each of up to ``new_leaders`` second-round leaders'
    starts with none among them, `Search.leader_of`) lifted to ``waypoints`` (None: the full path), each solved warm
    within ``max_iter`` iterations (None: the profile's own cap), from barrier parameter ``mu_init`` (None: the warm
    start's own), its KKT systems by ``linear_solver`` (None: the profile's)."""
    return [task for job, done in zip(jobs, found, strict=True)
            for task in lifted(job, [done[i][1] for i in picked(done, count, search, per_form, new_leaders)], stage,
                               waypoints, search, max_iter, mu_init, linear_solver)]


def lifted(job, solutions, stage: str, waypoints: int | None, search, max_iter: int | None = None,
           mu_init: float | None = None, linear_solver: str | None = None) -> list[Task]:
    """A task of ``stage`` per solution of ``solutions`` (``job``'s task on another sampling of its path) lifted
    to ``waypoints`` (None: the full path) and solved warm, as `lifted_tasks` solves them."""
    warm = search.profile.warmed().capped(max_iter).solved_by(linear_solver)
    if mu_init is not None:
        warm = warm.with_options(**{"ipopt.mu_init": mu_init})
    problem = job.problem if waypoints is None else coarse_problem(job.problem, waypoints)
    profile, continuation = solve_setup(job, search, warm)
    return [Task(job.case, stage, problem, job.transcription, profile, Lifted(sol), continuation) for sol in solutions]


def step_ratio(problem: DesignProblem, solution) -> float:
    """The largest joint step of ``solution`` lifted to ``problem``'s path (`lifted_guess`) over what the velocity
    limits allow between its waypoints (v_max h): above 1, no trajectory within the limits starts there."""
    guess = lifted_guess(problem, solution)
    return float((np.abs(np.diff(guess.Q, axis=0)) / problem.max_steps).max())


def relaxed_problem(problem: DesignProblem, scale: float) -> DesignProblem:
    """``problem`` with every joint's velocity limit (rad/s or m/s) times ``scale``."""
    return replace(problem, joint_velocity=tuple(float(v) for v in problem.velocity_limits * scale))


def coarse_optima(explored, refined) -> list:
    """The coarse optima (solutions of ``explored``, a job's (task, solution) pairs) that the screened solutions
    ``refined`` were lifted from: the same start numbers."""
    numbers = {sol.raw.seed for sol in refined}
    return [sol for task, sol in explored if task.seed in numbers]


def picked(done, count: int, search, per_form: int | None = None, new_leaders: int = 0,
           any_axis_direction: bool = False) -> list[int]:
    """Indices into ``done`` ((task, solution) pairs) of the solutions `lifted_tasks` lifts: `optima.distinct_best`
    with the search's ``distinct`` and ``same_arm_cost``, each solution's lineage its second-round leader; the same
    arm recognised whichever way its joint axes point with ``any_axis_direction``."""
    lineages = [search.leader_of(task.seed) for task, _ in done] if new_leaders else None
    return distinct_best([sol for _, sol in done], count, search.distinct, per_form,
                         same_arm_cost=search.same_arm_cost, lineages=lineages, new_lineages=new_leaders,
                         any_axis_direction=any_axis_direction)


def best_prescreened(explored, prescreened, keep: int, own: bool = False) -> list:
    """The explored (task, solution) pairs of the ``keep`` prescreened candidates (``prescreened``: (task, solution)
    of each, its task's start the coarse optimum) whose prescreened optima track at the lowest design cost; with
    ``own``, their prescreened pairs themselves (the screen then lifts the prescreened optima)."""
    tracking = sorted((d for d in prescreened if d[1].metrics.tracks), key=lambda d: d[1].metrics.design_cost)
    if own:
        return tracking[:keep]
    by_seed = {task.seed: (task, sol) for task, sol in explored}
    return [by_seed[task.seed] for task, _ in tracking[:keep]]


def better_pass(done: list[tuple[Task, object]]) -> list[tuple[Task, object]]:
    """One (task, solution) per start of a stage solved in several passes (`numbered_stage`; the same starts): the
    pass whose solution tracks at the lowest design cost (the first pass's when none tracks), in start order. A
    candidate screened twice is one candidate, with its better screen as its start: the refine gets distinct
    coarse optima, each refined once per barrier (a solve's files are named by stage and start)."""
    passes: dict[int, list[tuple[Task, object]]] = {}
    for task, sol in done:
        passes.setdefault(task.seed, []).append((task, sol))
    out = []
    for seed in sorted(passes):
        kept = best_solution([sol for _, sol in passes[seed]])
        out.append(next((pair for pair in passes[seed] if pair[1] is kept), passes[seed][0]))
    return out


def rebranched_tasks(found, search, round_: int = 0) -> list[Task]:
    """For every job's exploration (its (task, solution) pairs), its ``search.rebranch`` best distinct coarse optima
    (at most ``search.rebranch_per_form`` of one form before other forms: `optima.distinct_best`), and the
    cheapest of each of up to ``search.rebranch_new_forms`` forms not among them, each started
    ``search.leader_starts(rank)`` (``starts // rebranch`` unless ``rebranch_shares``) times on a new joint branch,
    as the task that found it (the same coarse problem, profile and continuation); start indices follow the
    exploration's, in a block per leader and round (`Search.leader_start`: a leader's starts keep their numbers
    whatever the count of leaders after it). With ``search.rebranch_pool`` > 1 a leader's starts are drawn that
    many times over (the indices of its block) and the ones taken spread over the branches where their walks reach
    the first waypoint (`starts.spread_branches`; the first drawn always among them), in index order; the others are
    never solved and their numbers stay unused. With ``search.rebranch_extra`` > 0 each leader gets that many
    starts more, spread over the branches its starts miss: taken farthest from them (and from each other) out of
    ``search.rebranch_extra_pool`` drawn from `Search.more_start`, after its own starts, in index order, their
    designs moved around the leader's by ``search.rebranch_extra_perturbation`` (`Rebranched.perturbation`). With
    ``search.rebranch_moved`` > 0 that many more again, their designs moved by ``search.rebranch_moved_perturbation``,
    spread likewise over the branches every start before them misses, out of ``search.rebranch_moved_pool`` drawn
    from `Search.more_start` (one loop over `Search.more_blocks`)."""
    tasks = []
    for done in found:
        leaders = distinct_best([sol for _, sol in done], search.rebranch, search.distinct, search.rebranch_per_form,
                                search.rebranch_new_forms, search.same_arm_cost)
        for k, i in enumerate(leaders):
            first, sol = done[i]
            n = search.leader_starts(k)
            index = search.leader_start(round_, k)
            drawn = range(index, index + n * search.rebranch_pool)
            pool = [Rebranched(sol, search.seed, j, search.init) for j in drawn]
            angle = np.array([joint.kind == "angle" for joint in first.problem.chain.moving], dtype=bool)
            if search.rebranch_pool > 1 or any(count > 0 for count, *_ in search.more_blocks):
                firsts = first_configurations_of(first.problem, pool)
            if search.rebranch_pool > 1:
                chosen = sorted(spread_branches(firsts, n, angle))
                pool, firsts = [pool[j] for j in chosen], firsts[chosen]
            for block, (count, size, perturbation, snapped) in enumerate(search.more_blocks):
                if count > 0:
                    begin = search.more_start(block, round_, k)
                    more = [Rebranched(sol, search.seed, j, search.init, perturbation, snapped)
                            for j in range(begin, begin + size)]
                    pool, firsts = _spread_more(pool, firsts, more, count, angle, first.problem)
            tasks += [replace(first, start=start) for start in pool]
    return tasks


def _spread_more(pool, firsts, more, count: int, angle, problem) -> tuple[list, np.ndarray]:
    """``pool`` (its walks' first configurations ``firsts``) and ``count`` of the starts ``more`` spread over the
    branches it misses (`spread_branches`, ``pool`` kept), in index order; and the first configurations of all."""
    firsts = np.vstack([firsts, first_configurations_of(problem, more)])
    taken = sorted(spread_branches(firsts, len(pool) + count, angle, kept=len(pool))[len(pool):])
    return pool + [more[j - len(pool)] for j in taken], firsts[list(range(len(pool))) + taken]


def plan(jobs, search):
    explore = []
    for job, starts in zip(jobs, exploration_starts([job.problem for job in jobs], search), strict=True):
        coarse = coarse_problem(job.problem, search.explore_waypoints)
        explore += seeded_tasks(job, "explore", coarse, search.explore_profile, search, starts)
    explored = by_job(jobs, (yield explore))
    if search.rebranch:
        for r in range(search.rebranch_rounds):  # each round from the best distinct optima of every round before it
            again = by_job(jobs, (yield rebranched_tasks(explored, search, r)))
            explored = [first + more for first, more in zip(explored, again, strict=True)]
    candidates = explored
    screened = [k for k, job in enumerate(jobs) if 0 < search.screen_waypoints < job.problem.toolpath.n]
    if screened:
        sub = [jobs[k] for k in screened]
        screens = screening([job.problem for job in jobs], search)
        choose = {"per_form": search.screen_per_form, "new_leaders": search.screen_new_leaders}
        extra = {k: [] for k in screened}  # prescreened coarse optima that join the screen's candidates
        own = {k: [] for k in screened}  # their prescreened optima, screened in passes of their own ("both")
        pre = [k for k in screened if search.prescreen
               and search.prescreen_waypoints < (screens[k][1] or jobs[k].problem.toolpath.n)]
        if pre:  # the next coarse optima re-ranked on more waypoints, as the screen's first pass solves
            first_mu, first_solver = search.screen_passes[0]
            tasks = []
            for k in pre:
                count, more = screens[k][0], round(search.prescreen * screens[k][0] / search.screen)
                taken = {explored[k][i][0].seed for i in picked(explored[k], count, search, **choose)}
                tasks += [t for t in lifted_tasks([jobs[k]], [explored[k]], count + more, "prescreen",
                                                  search.prescreen_waypoints, search, search.screen_max_iter,
                                                  mu_init=first_mu, per_form=search.screen_per_form,
                                                  linear_solver=first_solver)
                          if t.seed not in taken][:more]
            for k, done in zip(pre, by_job([jobs[k] for k in pre], (yield tasks)), strict=True):
                keep = round(search.prescreen_keep * screens[k][0] / search.screen)
                extra[k] = best_prescreened(explored[k], done, keep, search.screen_prescreened == "prescreened")
                if search.screen_prescreened == "both":
                    own[k] = best_prescreened(explored[k], done, keep, own=True)
        own_pass = len(search.screen_passes)  # the prescreened optima's passes are numbered after the screen's
        tasks = [task for i, (screen_mu, solver) in enumerate(search.screen_passes) for k in screened
                 if i < len(search.passes_for(jobs[k].problem.chain.n_moving))
                 for found, count, how, first in ((explored[k], screens[k][0], choose, 0),
                                                  (extra[k], len(extra[k]), {}, 0), (own[k], len(own[k]), {}, own_pass))
                 for task in lifted_tasks([jobs[k]], [found], count, numbered_stage("screen", first + i),
                                          screens[k][1], search, search.screen_max_iter, mu_init=screen_mu,
                                          linear_solver=solver, **how)]
        found = dict(zip(screened, [better_pass(d) for d in by_job(sub, (yield tasks))], strict=True))
        candidates = [found.get(k, explored[k]) for k in range(len(jobs))]
    chosen = [[done[i][1] for i in picked(done, search.refine, search, any_axis_direction=search.refine_distinct_arms)]
              for done in candidates]
    refines = [task for i, refine_mu in enumerate(search.refine_mu_init) for job, sols in zip(jobs, chosen, strict=True)
               for task in lifted(job, sols, numbered_stage("refine", i), None, search, mu_init=refine_mu)]
    passes = len(search.refine_mu_init)
    if search.refine_from_coarse:  # each refined candidate refined again from its coarse optimum
        stage = numbered_stage("refine", passes)
        passes += 1
        for k in screened:
            refines += lifted(jobs[k], coarse_optima(explored[k], chosen[k]), stage, None, search)
    if search.refine_relaxed:  # and through velocity limits relaxed to fit its lifted start
        ratios = [[step_ratio(job.problem, sol) for sol in sols[:search.refine_relaxed]]
                  for job, sols in zip(jobs, chosen, strict=True)]
        relaxed = [(k, sol, r) for k, (sols, rs) in enumerate(zip(chosen, ratios, strict=True))
                   for sol, r in zip(sols, rs, strict=False) if r > 1.0]  # rs: the best sols'
        done = []
        for i, exponent in enumerate((1.0, 0.5) if relaxed else ()):
            tasks = [lifted(replace(jobs[k], problem=relaxed_problem(jobs[k].problem, (1.05 * r) ** exponent)),
                            [sol], numbered_stage("relax", i), None, search, mu_init=None if i == 0 else 1e-6)[0]
                     for (k, _, r), sol in zip(relaxed, done or [sol for _, sol, _ in relaxed], strict=True)]
            solved = {task.key: sol for task, sol in (yield tasks)}
            done = [solved[task.key] for task in tasks]
        stage = numbered_stage("refine", passes)
        refines += [lifted(jobs[k], [sol], stage, None, search, mu_init=1e-6)[0]
                    for (k, _, _), sol in zip(relaxed, done, strict=True)]
    final = by_job(jobs, (yield refines))
    return [Searched(job, e, f) for job, e, f in zip(jobs, explored, final, strict=True)]

