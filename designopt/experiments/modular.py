"""The modular design problem (SPEC §5, claim C7): continuous TO with L_mod -> round -> re-solve.

Stages, each written to summary.csv as a ``case``:
  continuous          plain TO, design + placement (the reference continuous cost)
  continuous_modular  TO with weight * L_mod added: links are pulled toward catalogue modules
  rounded             every link replaced by its nearest module, evaluated on the stage-2 trajectory
  modular             modules fixed; placement and trajectory re-solved (the modular design)
  neighbourhood       beyond the paper: a local search over module assignments from the rounded one (one link's
                      module changed at a time, each candidate re-solved like ``modular``; cases nb-<modules>)
  fk                  the FK baseline on the continuous problem, for comparison (C7)
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
from designopt.experiments.adapters import case_config, multistart_from_config, transcription_for, with_waypoints
from designopt.experiments.tasks import Progress, Task, multistart_tasks, record, solve_tasks
from designopt.kinematics.joints import Role
from designopt.modular import (
    Catalogue,
    check_catalogue,
    link_vectors,
    modular_cost,
    nearest_modules,
    neighbourhood_search,
)
from designopt.multistart import best_solution
from designopt.problem import DesignProblem, problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution, write_solution

STAGES = ("continuous", "continuous_modular", "rounded", "modular", "neighbourhood", "fk")


def catalogue_from_config(cfg: Config) -> Catalogue:
    m = cfg.modular
    offset = "d" if m.joint_type == "R" else "theta"
    modules = tuple((getattr(row, offset), row.a, row.alpha) for row in m.modules)
    return Catalogue(m.joint_type, modules, m.linear_weight, m.angular_weight)


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


def rounded_solution(sol: Solution, assignment: list[int], catalogue: Catalogue) -> Solution:
    """The stage-2 solution with its links snapped to modules, evaluated on the same joint trajectory."""
    names = [j.name for j in sol.problem.chain.design]
    values = module_values(sol.problem, assignment, catalogue)
    q_d = np.array([values.get(n, v) for n, v in zip(names, sol.raw.q_d, strict=True)])
    raw = replace(sol.raw, q_d=q_d, status="rounded", success=False, iterations=0, solve_time_s=0.0)
    return Solution(sol.problem, "rounded", raw, evaluate(sol.problem, q_d, sol.raw.Q), "rounded")


@dataclass(frozen=True)
class ModularResult:
    directory: RunDirectory
    table: pd.DataFrame
    assignment: list[int]


def _stage(run, problem, transcription, settings, case, progress, resume) -> Solution | None:
    """One stage: a multistart of one problem, written (and resumed) like every experiment."""
    tasks = multistart_tasks(case, transcription.name, problem, transcription, settings)
    done = solve_tasks(run, tasks, "modular", settings.jobs, resume, progress)
    return best_solution([sol for _, sol in done])


@dataclass(frozen=True)
class _Setup:
    catalogue: Catalogue
    run: RunDirectory
    settings: object
    combined: Config
    base: DesignProblem
    to: object


def _setup(cfg: Config, base_dir: Path, out_root: Path, experiment: str, run_name: str | None,
           resume: bool) -> _Setup:
    """Catalogue (checked against the structure), run directory and the combined design + placement problem."""
    catalogue = catalogue_from_config(cfg)
    try:
        check_catalogue(cfg.robot.structure, catalogue)
    except ValueError as exc:
        raise cfg.error("robot.structure", str(exc)) from None
    combined = case_config(cfg, "combined")
    base = problem_from_config(combined, base_dir)
    run = RunDirectory.create(out_root, experiment, run_name, resume)
    run.write_config(dump_config(cfg))
    return _Setup(catalogue, run, multistart_from_config(cfg), combined, base, transcription_for(combined))


def run_modular(cfg: Config, base_dir: Path, out_root: Path, run_name: str | None = None,
                progress: Progress | None = None, figures: bool = True, resume: bool = False) -> ModularResult:
    s = _setup(cfg, base_dir, out_root, "modular", run_name, resume)
    catalogue, run, settings, combined_cfg, base, to = s.catalogue, s.run, s.settings, s.combined, s.base, s.to
    best = {"continuous": _stage(run, base, to, settings, "continuous", progress, resume)}
    best["fk"] = _stage(run, base, transcription_for(combined_cfg, "fk"), settings, "fk", progress, resume)
    continuous, assignment, modular, placement = _round_and_resolve(run, base, to, settings, catalogue,
                                                                    cfg.modular.weight, "", progress, resume)
    best["continuous_modular"], best["modular"] = continuous, modular
    searched = assignment
    if modular is not None and cfg.modular.neighbourhood_budget:
        evaluate = ModuleCosts(run, base, to, settings, catalogue, placement, "nb-", progress, resume)
        evaluate.best[tuple(assignment)] = modular  # the start is the modular stage, already solved
        searched, _, evaluated = neighbourhood_search([tuple(assignment)], len(catalogue.modules), evaluate,
                                                      cfg.modular.neighbourhood_budget)
        best["neighbourhood"] = evaluate.best[tuple(searched)]
        run.log(f"neighbourhood search: {len(evaluated)} assignments evaluated, best {[k + 1 for k in searched]}")
    if continuous is not None:
        best["rounded"] = rounded_solution(continuous, assignment, catalogue)
        # not a solve: derived from the stage-2 best, so it is recorded once and recomputed on resume
        rounded_task = Task("rounded", "rounded", base, None, settings, continuous.raw.seed - settings.seed * 1000)
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


def _round_and_resolve(run, base, to, settings, catalogue, weight, tag, progress, resume):
    """Stages 2-4 for one L_mod weight; returns (continuous best, assignment, modular best)."""
    continuous = _stage(run, with_modular_cost(base, catalogue, weight), to, settings, f"{tag}continuous_modular",
                        progress, resume)
    if continuous is None:
        return None, [], None, {}
    assignment = nearest_modules(continuous.problem.chain, continuous.raw.q_d, catalogue)
    placed = {j.name for j in base.chain.placement_joints}
    placement = {j.name: float(v) for j, v in zip(base.chain.design, continuous.raw.q_d, strict=True)
                 if j.name in placed}
    modular = _stage(run, fix_modules(base, assignment, catalogue, placement), to, settings, f"{tag}modular",
                     progress, resume)
    return continuous, assignment, modular, placement


def _digits(assignment) -> str:
    return "".join(str(k + 1) for k in assignment)


class ModuleCosts:
    """``evaluate(assignments) -> costs`` for `neighbourhood_search`: every assignment's modules-fixed problem
    (placement and trajectory free, from the rounded stage's placement) solved like the ``modular`` stage, all
    of a batch in one fan-out (cases ``<tag><module numbers>``); NaN when no start tracks. ``best`` keeps each
    evaluated assignment's best solution."""

    def __init__(self, run, base, to, settings, catalogue, placement, tag, progress, resume):
        self.args = run, base, to, settings, catalogue, placement
        self.tag, self.progress, self.resume = tag, progress, resume
        self.best: dict[tuple[int, ...], Solution | None] = {}

    def __call__(self, batch):
        run, base, to, settings, catalogue, placement = self.args
        todo = [a for a in batch if a not in self.best]  # known already: e.g. the rounded assignment's re-solve
        tasks = []
        for a in todo:
            tasks += multistart_tasks(f"{self.tag}{_digits(a)}", to.name, fix_modules(base, list(a), catalogue,
                                                                                      placement), to, settings)
        done = solve_tasks(run, tasks, "modular", settings.jobs, self.resume, self.progress)
        for a in todo:
            self.best[a] = best_solution([sol for t, sol in done if t.case == f"{self.tag}{_digits(a)}"])
        return [self.best[a].metrics.design_cost if self.best[a] is not None else np.nan for a in batch]


@dataclass(frozen=True)
class ModularStudyResult:
    directory: RunDirectory
    weights: pd.DataFrame  # one row per L_mod weight
    enumeration: pd.DataFrame  # every assignment of the small catalogue, ranked; rounding's pick marked


def run_modular_study(cfg: Config, base_dir: Path, out_root: Path, run_name: str | None = None,
                      progress: Progress | None = None, resume: bool = False) -> ModularStudyResult:
    """Beyond the paper: (a) how the L_mod weight changes the result; (b) on a small catalogue where every
    assignment can be solved, how far rounding lands from the best assignment."""
    import itertools

    s = _setup(cfg, base_dir, out_root, "modular_study", run_name, resume)
    catalogue, run, settings, combined_cfg, base, to = s.catalogue, s.run, s.settings, s.combined, s.base, s.to

    weights = []
    for w in cfg.modular.weight_study:
        cont, assignment, mod, _ = _round_and_resolve(run, base, to, settings, catalogue, w, f"w{w:g}-", progress,
                                                      resume)
        weights.append({"weight": w, "continuous_cost": cont.metrics.design_cost if cont else np.nan,
                        "L_mod": modular_cost(base.chain, cont.raw.q_d, catalogue) if cont else np.nan,
                        "modules": " ".join(f"m{k + 1}" for k in assignment),
                        "modular_cost": mod.metrics.design_cost if mod else np.nan})
    weight_table = pd.DataFrame(weights)
    weight_table.to_csv(run.path / "weight_study.csv", index=False)

    # (b) enumeration on a sub-catalogue and a shorter path
    subset = [k - 1 for k in cfg.modular.enumeration_modules]
    small = replace(catalogue, modules=tuple(catalogue.modules[k] for k in subset))
    n = cfg.modular.enumeration_waypoints
    small_cfg = with_waypoints(combined_cfg, n)
    small_base = problem_from_config(small_cfg, base_dir)
    small_to = transcription_for(small_cfg)
    _, rounded_assignment, rounded_best, _ = _round_and_resolve(run, small_base, small_to, settings, small,
                                                                cfg.modular.weight, "enum-", progress, resume)
    placement = {j.name: j.value for j in small_base.chain.placement_joints if j.role is Role.DESIGN}
    rows = []
    for assignment in itertools.product(range(len(subset)), repeat=small_base.chain.n_links):
        best = _stage(run, fix_modules(small_base, list(assignment), small, placement), small_to, settings,
                      "enum-" + "".join(str(subset[k] + 1) for k in assignment), progress, resume)
        rows.append({"assignment": " ".join(f"m{subset[k] + 1}" for k in assignment),
                     "design_cost": best.metrics.design_cost if best else np.nan,
                     "rounding_picked": list(assignment) == rounded_assignment})
    enum = pd.DataFrame(rows).sort_values("design_cost", na_position="last").reset_index(drop=True)
    enum["rank"] = np.arange(1, len(enum) + 1)
    # the neighbourhood search from the rounded assignment, on the same solves (every assignment is enumerated)
    by_assignment = {tuple(int(k) for k in a): c for a, c in zip(
        itertools.product(range(len(subset)), repeat=small_base.chain.n_links), [r["design_cost"] for r in rows],
        strict=True)}
    enum["neighbourhood_picked"] = False
    if rounded_assignment and cfg.modular.neighbourhood_budget:
        found, _, evaluated = neighbourhood_search([tuple(rounded_assignment)], len(subset),
                                                   lambda batch: [by_assignment[a] for a in batch],
                                                   cfg.modular.neighbourhood_budget)
        label = " ".join(f"m{subset[k] + 1}" for k in found)
        enum["neighbourhood_picked"] = enum["assignment"] == label
        run.log(f"neighbourhood search from the rounded assignment: {label} after {len(evaluated)} of "
                f"{len(enum)} assignments, rank {int(enum.loc[enum['neighbourhood_picked'], 'rank'].iloc[0])}")
    enum.to_csv(run.path / "enumeration.csv", index=False)
    run.log(f"rounding picked {rounded_assignment}, its re-solve cost "
            f"{rounded_best.metrics.design_cost if rounded_best else float('nan')}")
    return ModularStudyResult(run, weight_table, enum)
