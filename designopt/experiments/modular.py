"""The modular design problem (SPEC §5, claim C7): continuous TO with L_mod -> round -> re-solve.

Stages, each written to summary.csv as a ``case``:
  continuous          plain TO, design + placement (the reference continuous cost)
  continuous_modular  TO with weight * L_mod added: links are pulled toward catalogue modules
  rounded             every link replaced by its nearest module, evaluated on the stage-2 trajectory
  modular             modules fixed; placement and trajectory re-solved (the modular design)
  neighbourhood       beyond the paper: a search over module assignments, coarse to fine like the continuous one -- a
                      local search (a step: one link's module changed or two neighbouring links' modules exchanged;
                      `--no-swaps`: changes only) from the cheapest of the rounded assignment and a seeded sample spread
                      over the catalogue (every module equally often on every link), each candidate screened on a coarse
                      sampling of the path (cases sc-<modules>; a neighbour of the incumbent also warm from the
                      incumbent's screening optimum); the best distinct screened optima searched on the full path with
                      the default search at `REFINE_STARTS` coarse starts (cases nb-<modules>). One assignment per
                      robot: assignments that differ by a lift along base z are solved once, with the placement z free
                      over all of their boxes, and the best reported as the assignment whose placement z lies in the box
  fk                  the FK baseline on the continuous problem, for comparison (C7)

Every stage of the paper's method is a search of one problem with the config's search (the shipped config uses
the ``paper`` preset); the neighbourhood stage screens and refines with its own (`module_screen`, `module_refine`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd

from designopt.config import Config, dump_config
from designopt.costs import DesignCost
from designopt.evaluation import evaluate
from designopt.experiments.adapters import case_config, search_from_config, with_waypoints
from designopt.experiments.runs import Executor, Progress, record
from designopt.kinematics.joints import Role
from designopt.modular import (
    Catalogue,
    check_catalogue,
    lifted_range,
    lifts_absorbed,
    link_vectors,
    modular_cost,
    nearest_modules,
    neighbourhood_search,
    same_robot,
    screened_candidates,
    within_box,
)
from designopt.problem import DesignProblem, problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution, write_solution
from designopt.solve import Job, Search, Seeded, SolverProfile, Task, best_solution, preset, run_search
from designopt.solve.search import by_job
from designopt.solve.strategies.coarse_to_fine import coarse_problem, lifted_tasks
from designopt.transcriptions import ForwardKinematics

STAGES = ("continuous", "continuous_modular", "rounded", "modular", "neighbourhood", "fk")
WEIGHT = 1.0e-3  # L_mod's weight in the objective
WEIGHT_STUDY = (1.0e-4, 1.0e-3, 1.0e-2)
NEIGHBOURHOOD_BUDGET = 300  # module assignments the neighbourhood search may screen
NEIGHBOURHOOD_SAMPLE = 1 / 6  # share of the budget: spread assignments screened with the rounded one, to start from
NEIGHBOURHOOD_REFINE = 8  # best distinct screening optima re-solved on the full path
SCREEN_WAYPOINTS = 10  # the screening's sampling of the path
REFINE_STARTS = 160  # coarse starts of each best screened assignment's full-path search
NEIGHBOURHOOD_SWAPS = True  # a step also exchanges two neighbouring links' modules (decisions.md, "Modular design")
# w_lin (1/m^2) and w_ang of the similarity distance (SPEC §3)
LINEAR_WEIGHT, ANGULAR_WEIGHT = 1.0, 0.25


def catalogue_from_config(cfg: Config) -> Catalogue:
    """The config's modules as a catalogue of revolute links (d, a, alpha; theta moves)."""
    return Catalogue("R", tuple((row.d, row.a, row.alpha) for row in cfg.modules), LINEAR_WEIGHT, ANGULAR_WEIGHT)


def with_modular_cost(problem: DesignProblem, catalogue: Catalogue, weight: float) -> DesignProblem:
    return problem.with_cost(DesignCost("modular", weight, partial(modular_cost, catalogue=catalogue)))


def module_values(problem: DesignProblem, assignment: list[int], catalogue: Catalogue) -> dict[str, float]:
    """DH values of every link under a module assignment."""
    values = {}
    for i, k in enumerate(assignment):
        for param, v in zip(catalogue.params(), catalogue.modules[k], strict=True):
            values[f"link{i + 1}.{param}"] = float(v)
    return values


def fix_modules(problem: DesignProblem, assignment: list[int], catalogue: Catalogue,
                placement: dict[str, float]) -> DesignProblem:
    """The problem with every link fixed to its module; only placement (and trajectory) stay free."""
    values = module_values(problem, assignment, catalogue)
    chain = problem.chain.with_roles(dict.fromkeys(values, Role.FIXED), {**values, **placement})
    return replace(problem, chain=chain).without_cost("modular")


def lifted_modules(problem: DesignProblem, assignment: list[int], catalogue: Catalogue,
                   placement: dict[str, float]) -> DesignProblem:
    """`fix_modules`, with the placement z free over every value at which an assignment of the same robot keeps
    it in the box (`lifted_range`): one solve answers for all of them."""
    fixed = fix_modules(problem, assignment, catalogue, placement)
    z = fixed.chain.joint("placement.z")
    lower, upper = lifted_range(tuple(assignment), catalogue, (z.lower, z.upper))
    joints = tuple(replace(j, lower=lower, upper=upper, value=min(max(j.value, lower), upper)) if j is z else j
                   for j in fixed.chain.joints)
    return replace(fixed, chain=replace(fixed.chain, joints=joints))


def rounded_solution(sol: Solution, assignment: list[int], catalogue: Catalogue) -> Solution:
    """The stage-2 solution with its links snapped to modules, evaluated on the same joint trajectory."""
    names = [j.name for j in sol.problem.chain.design]
    values = module_values(sol.problem, assignment, catalogue)
    q_d = np.array([values.get(n, v) for n, v in zip(names, sol.raw.q_d, strict=True)])
    raw = replace(sol.raw, q_d=q_d, status="rounded", success=False, iterations=0, solve_time_s=0.0)
    return Solution(sol.problem, "rounded", raw, evaluate(sol.problem, q_d, sol.raw.trajectory))


@dataclass(frozen=True)
class ModularResult:
    directory: RunDirectory
    table: pd.DataFrame
    assignment: list[int]


def _stage(setup, problem, case, transcription=None) -> Solution | None:
    """One stage: the search of one problem, written (and resumed) like every experiment; its best solution."""
    job = Job(case, problem) if transcription is None else Job(case, problem, transcription)
    (searched,) = run_search([job], setup.search, setup.execute)
    return searched.best[1]


@dataclass(frozen=True)
class _Setup:
    catalogue: Catalogue
    run: RunDirectory
    search: Search
    execute: Executor
    combined: Config
    base: DesignProblem


def _setup(cfg: Config, out_root: Path, experiment: str, run_name: str | None, resume: bool, jobs: int,
           progress, search: Search | None) -> _Setup:
    """Catalogue (checked against the structure), run directory and the combined design + placement problem."""
    catalogue = catalogue_from_config(cfg)
    try:
        check_catalogue(cfg.robot.structure, catalogue)
    except ValueError as exc:
        raise cfg.error("robot.structure", str(exc)) from None
    combined = case_config(cfg, "combined")
    base = problem_from_config(combined)
    run = RunDirectory.create(out_root, experiment, run_name, resume)
    run.write_config(dump_config(cfg))
    return _Setup(catalogue, run, search or search_from_config(cfg), Executor(run, experiment, jobs, resume, progress),
                  combined, base)


def run_modular(cfg: Config, out_root: Path, run_name: str | None = None, progress: Progress | None = None,
                figures: bool = True, resume: bool = False, jobs: int = -1, weight: float = WEIGHT,
                neighbourhood_budget: int = NEIGHBOURHOOD_BUDGET, search: Search | None = None,
                neighbourhood_refine: int = NEIGHBOURHOOD_REFINE,
                neighbourhood_swaps: bool = NEIGHBOURHOOD_SWAPS,
                neighbourhood_refine_starts: int = REFINE_STARTS) -> ModularResult:
    s = _setup(cfg, out_root, "modular", run_name, resume, jobs, progress, search)
    catalogue, run, base = s.catalogue, s.run, s.base
    best = {"continuous": _stage(s, base, "continuous")}
    best["fk"] = _stage(s, base, "fk", ForwardKinematics())
    continuous, assignment, modular, placement = _round_and_resolve(s, base, catalogue, weight, "")
    best["continuous_modular"], best["modular"] = continuous, modular
    searched = assignment
    if continuous is not None and neighbourhood_budget:  # also when no start of the rounded assignment tracked
        searched, best["neighbourhood"], screened = _module_search(s, base, catalogue, placement, assignment, modular,
                                                                    neighbourhood_budget, refine=neighbourhood_refine,
                                                                    swaps=neighbourhood_swaps,
                                                                    refine_starts=neighbourhood_refine_starts)
        run.log(f"neighbourhood search: {screened} robots screened, best {[k + 1 for k in searched]}")
    if continuous is not None:
        best["rounded"] = rounded_solution(continuous, assignment, catalogue)
        # not a solve: derived from the stage-2 best, so it is recorded once and recomputed on resume
        rounded_task = Task("rounded", "", base, _Rounded(), SolverProfile(), Seeded(0, continuous.raw.seed))
        if not resume or rounded_task.key not in run.resume():
            record(run, rounded_task, best["rounded"], "modular")
        run.log(f"modules per link: {[k + 1 for k in assignment]}")
    rows = []
    for stage in STAGES:
        sol = best.get(stage)
        rows.append({"stage": stage, "design_cost": sol.metrics.design_cost if sol else np.nan,
                     "tracks": bool(sol and sol.metrics.tracks),
                     "max_position_error": sol.metrics.max_position_error if sol else np.nan,
                     "max_joint_step": sol.metrics.max_joint_step if sol else np.nan,
                     "modules": " ".join(f"m{k + 1}" for k in (searched if stage == "neighbourhood" else assignment))
                     if stage in ("rounded", "modular", "neighbourhood") else ""})
        if sol is not None:
            write_solution(sol, run.path / f"best-{stage}.json")
    table = pd.DataFrame(rows)
    table.to_csv(run.path / "table.csv", index=False)
    if figures and continuous is not None:
        from designopt import plots_experiments

        vectors = np.array(link_vectors(continuous.problem.chain, continuous.raw.q_d, catalogue), float)
        plots_experiments.module_pca_figure(vectors, np.array(catalogue.modules), assignment, run.figures)
    run.log("done")
    return ModularResult(run, table, assignment)


class _Rounded:
    """The rounded stage is no solve; its row names this method."""

    name = "rounded"


def _round_and_resolve(setup, base, catalogue, weight, tag):
    """Stages 2-4 for one L_mod weight; returns (continuous best, assignment, modular best, placement)."""
    continuous = _stage(setup, with_modular_cost(base, catalogue, weight), f"{tag}continuous_modular")
    if continuous is None:
        return None, [], None, {}
    assignment = nearest_modules(continuous.problem.chain, continuous.raw.q_d, catalogue)
    placed = {j.name for j in base.chain.placement_joints}
    placement = {j.name: float(v) for j, v in zip(base.chain.design, continuous.raw.q_d, strict=True)
                 if j.name in placed}
    modular = _stage(setup, fix_modules(base, assignment, catalogue, placement), f"{tag}modular")
    return continuous, assignment, modular, placement


def module_screen(search: Search) -> Search:
    """How the neighbourhood search screens an assignment: 3 seeded starts (the search's seed) on
    `SCREEN_WAYPOINTS` of the path, moved until they reach it (``init: reach``), capped at 250 iterations,
    derivative blocks interpreted (each shape is solved three times: compiling would cost more than it saves)."""
    profile = SolverProfile(max_iter=250, compile="none")
    return preset("paper", starts=3, seed=search.seed, init="reach", profile=profile)


def module_refine(search: Search, starts: int = REFINE_STARTS) -> Search:
    """How the neighbourhood search solves its best screened assignments on the full path: the default search (coarse to
    fine; the search's seed) with ``starts`` coarse starts (`REFINE_STARTS` unless a run asks for fewer), moved until
    they reach the path (no second round on new joint branches, MUMPS in the exploration too, 12 screened once and one
    refine per candidate: none of these measured on modular robots), as the enumeration that found the best modular
    robot known solved its candidates (`benchmarks/modular_enumeration.py`). Every other setting is the default's as it
    stands (`Search.describe` prints them); the default's additions of 2026-12-04 (the prescreen, the prescreened
    candidates screened both ways, distinct arms refined, the relaxed pass for the best) were measured on modular robots
    after they came in: the same spread over 20 fresh seeds as the search before them (docs/results.md, C7). The
    config's own search (the ``paper`` preset's 4 cold starts in the shipped config) lost 1.3-1.5x on assignments it
    shares with the enumeration; 80 coarse starts missed an assignment's own best on 3 of 7 evaluation seeds (1.24-1.41x
    where 160 starts reach 1.05x: docs/decisions.md)."""
    return preset("default", seed=search.seed, init="reach", starts=starts, rebranch=0, screen=12,
                  explore_linear_solver=None, screen_mu_init=(None,), refine_mu_init=(None,))


def _module_search(setup, base, catalogue, placement, rounded, modular, budget, refine=NEIGHBOURHOOD_REFINE,
                   swaps=NEIGHBOURHOOD_SWAPS, refine_starts=REFINE_STARTS):
    """The neighbourhood stage: a local search over assignments on screening costs within ``budget`` screened robots,
    from the cheapest of the rounded assignment and a sample spread over the catalogue (a `NEIGHBOURHOOD_SAMPLE` share
    of the budget) on (``swaps``: a step also exchanges two neighbouring links' modules); then the ``refine`` best
    distinct screening optima searched on the full path (`module_refine`, ``refine_starts`` coarse starts each). When
    the placement z is free and absorbs lifts (`lifts_absorbed`), the assignments that build one robot up to a lift
    along base z are one robot: screened once, solved with the placement z any of them could take (`lifted_range`), and
    reported as the one whose placement lies in the box (`within_box`). Returns (best assignment, its solution, robots
    screened); never worse than the rounded assignment's re-solve ``modular`` (None when none of its starts tracked:
    then the full-path search may solve the rounded assignment again, if it is among the best screened)."""
    z = base.chain.joint("placement.z")
    absorbed = z.role is Role.DESIGN and lifts_absorbed(catalogue, (z.lower, z.upper))
    same = partial(same_robot, catalogue=catalogue) if absorbed else None
    screen = ModuleCosts(setup, base, catalogue, placement, "sc-", module_screen(setup.search), SCREEN_WAYPOINTS,
                         absorbed)
    ranked, evaluated = screened_candidates(tuple(rounded), len(catalogue.modules), screen, budget,
                                            round(budget * NEIGHBOURHOOD_SAMPLE), refine, setup.search.seed, same,
                                            swaps)
    full = ModuleCosts(setup, base, catalogue, placement, "nb-", module_refine(setup.search, refine_starts),
                       absorbed=absorbed)
    if modular is not None:
        full.best[tuple(rounded)] = modular  # already solved: the modular stage
    full(ranked)
    solved = {a: sol for a, sol in full.best.items() if sol is not None and sol.metrics.tracks}
    if not solved:
        return list(rounded), modular, len(evaluated)
    best = min(solved, key=lambda a: solved[a].metrics.design_cost)
    if not absorbed:
        return list(best), solved[best], len(evaluated)
    member, built = as_built(solved[best], best, base, catalogue, placement)
    return list(member), built, len(evaluated)


def as_built(sol: Solution, assignment, base, catalogue, placement) -> tuple[tuple[int, ...], Solution]:
    """``sol`` (of ``assignment``, its placement z maybe outside the box) as the assignment of the same robot whose
    placement z lies in the box (`within_box`): that assignment's `fix_modules` problem, its placement z moved by
    the difference of lifts, the same joint trajectory; metrics evaluated afresh on that problem."""
    z = base.chain.joint("placement.z")  # its box: fix_modules keeps it
    index = [j.name for j in sol.problem.chain.design].index("placement.z")
    member, z_member = within_box(tuple(assignment), catalogue, float(sol.raw.q_d[index]), (z.lower, z.upper))
    if member == tuple(assignment):
        return member, sol
    target = fix_modules(base, list(member), catalogue, placement)
    q_d = np.array(sol.raw.q_d, float)
    q_d[index] = z_member
    raw = replace(sol.raw, q_d=q_d)
    return member, Solution(target, sol.method, raw, evaluate(target, q_d, raw.trajectory))


def _digits(assignment) -> str:
    return "".join(str(k + 1) for k in assignment)


class ModuleCosts:
    """``evaluate(assignments, incumbent=None) -> costs`` for `neighbourhood_search`: every assignment's
    modules-fixed problem (placement and trajectory free, from the rounded stage's placement; on ``waypoints`` of
    the path, None: all) searched with ``search`` (None: the experiment's, like the ``modular`` stage), all of a
    batch in one search (cases ``<tag><module numbers>``); the neighbours of an ``incumbent`` also get one warm
    start from the incumbent's best solution (stage ``warm``): a module changed on one link (or two exchanged)
    moves the best placement and trajectory little, so a basin one family member found is tried on its
    neighbours. NaN when no start tracks. ``absorbed``: the placement z is free over the range of every
    assignment of the same robot (`lifted_modules`). ``best`` keeps each evaluated assignment's best solution."""

    def __init__(self, setup, base, catalogue, placement, tag, search: Search | None = None,
                 waypoints: int | None = None, absorbed: bool = False):
        self.setup, self.base, self.catalogue, self.placement, self.tag = setup, base, catalogue, placement, tag
        self.search, self.waypoints, self.absorbed = search or setup.search, waypoints, absorbed
        self.best: dict[tuple[int, ...], Solution | None] = {}

    def problem(self, assignment) -> DesignProblem:
        fixed = (lifted_modules if self.absorbed else fix_modules)(self.base, list(assignment), self.catalogue,
                                                                  self.placement)
        return fixed if self.waypoints is None else coarse_problem(fixed, self.waypoints)

    def __call__(self, batch, incumbent=None):
        todo = [a for a in batch if a not in self.best]  # known already: e.g. the rounded assignment's re-solve
        jobs = [Job(f"{self.tag}{_digits(a)}", self.problem(a)) for a in todo]
        found = [searched.best[1] for searched in run_search(jobs, self.search, self.setup.execute)]
        warm = self.best.get(incumbent)  # None for a start, or an incumbent that did not track
        if warm is not None and jobs:
            tasks = lifted_tasks(jobs, [[(None, warm)]] * len(jobs), 1, "warm", None, self.search)
            done = by_job(jobs, self.setup.execute(tasks))
            found = [best_solution([*([f] if f is not None else []), *(sol for _, sol in d)])
                     for f, d in zip(found, done, strict=True)]
        self.best.update(zip(todo, found, strict=True))
        return [self.best[a].metrics.design_cost if self.best[a] is not None else np.nan for a in batch]


@dataclass(frozen=True)
class ModularStudyResult:
    directory: RunDirectory
    weights: pd.DataFrame  # one row per L_mod weight
    enumeration: pd.DataFrame  # every assignment of the small catalogue, ranked; rounding's pick marked


def run_modular_study(cfg: Config, out_root: Path, run_name: str | None = None, progress: Progress | None = None,
                      resume: bool = False, jobs: int = -1, weights: tuple[float, ...] = WEIGHT_STUDY,
                      weight: float = WEIGHT, enumeration_modules: tuple[int, ...] = (2, 5),
                      enumeration_waypoints: int = 40,
                      neighbourhood_budget: int = NEIGHBOURHOOD_BUDGET,
                      search: Search | None = None) -> ModularStudyResult:
    """Beyond the paper: (a) how the L_mod weight changes the result; (b) on a small catalogue where every
    assignment can be solved (``enumeration_modules``, 1-based, on ``enumeration_waypoints`` waypoints), how far
    rounding lands from the best assignment."""
    import itertools

    if any(not 1 <= k <= len(cfg.modules) for k in enumeration_modules):
        raise cfg.error("modules", f"the enumeration uses modules {list(enumeration_modules)}; the catalogue has "
                                   f"{len(cfg.modules)}")
    s = _setup(cfg, out_root, "modular_study", run_name, resume, jobs, progress, search)
    catalogue, run, base = s.catalogue, s.run, s.base

    rows = []
    for w in weights:
        cont, assignment, mod, _ = _round_and_resolve(s, base, catalogue, w, f"w{w:g}-")
        rows.append({"weight": w, "continuous_cost": cont.metrics.design_cost if cont else np.nan,
                     "L_mod": modular_cost(base.chain, cont.raw.q_d, catalogue) if cont else np.nan,
                     "modules": " ".join(f"m{k + 1}" for k in assignment),
                     "modular_cost": mod.metrics.design_cost if mod else np.nan})
    weight_table = pd.DataFrame(rows)
    weight_table.to_csv(run.path / "weight_study.csv", index=False)

    # (b) enumeration on a sub-catalogue and a shorter path
    subset = [k - 1 for k in enumeration_modules]
    small = replace(catalogue, modules=tuple(catalogue.modules[k] for k in subset))
    small_base = problem_from_config(with_waypoints(s.combined, enumeration_waypoints))
    _, rounded_assignment, rounded_best, _ = _round_and_resolve(s, small_base, small, weight, "enum-")
    placement = {j.name: j.value for j in small_base.chain.placement_joints if j.role is Role.DESIGN}
    assignments = list(itertools.product(range(len(subset)), repeat=small_base.chain.n_links))
    found = run_search([Job("enum-" + "".join(str(subset[k] + 1) for k in a),
                            fix_modules(small_base, list(a), small, placement)) for a in assignments],
                       s.search, s.execute)
    rows = [{"assignment": " ".join(f"m{subset[k] + 1}" for k in a),
             "design_cost": f.best[1].metrics.design_cost if f.best[1] else np.nan,
             "rounding_picked": list(a) == rounded_assignment} for a, f in zip(assignments, found, strict=True)]
    enum = pd.DataFrame(rows).sort_values("design_cost", na_position="last").reset_index(drop=True)
    enum["rank"] = np.arange(1, len(enum) + 1)
    # the neighbourhood search from the rounded assignment, on the same solves (every assignment is enumerated)
    by_assignment = {tuple(int(k) for k in a): r["design_cost"] for a, r in zip(assignments, rows, strict=True)}
    enum["neighbourhood_picked"] = False
    if rounded_assignment and neighbourhood_budget:
        picked, _, evaluated = neighbourhood_search([tuple(rounded_assignment)], len(subset),
                                                    lambda batch, _: [by_assignment[a] for a in batch],
                                                    neighbourhood_budget)
        label = " ".join(f"m{subset[k] + 1}" for k in picked)
        enum["neighbourhood_picked"] = enum["assignment"] == label
        run.log(f"neighbourhood search from the rounded assignment: {label} after {len(evaluated)} of "
                f"{len(enum)} assignments, rank {int(enum.loc[enum['neighbourhood_picked'], 'rank'].iloc[0])}")
    enum.to_csv(run.path / "enumeration.csv", index=False)
    run.log(f"rounding picked {rounded_assignment}, its re-solve cost "
            f"{rounded_best.metrics.design_cost if rounded_best else float('nan')}")
    return ModularStudyResult(run, weight_table, enum)
