"""Kinematic structure sweep (SPEC §5, claims C4-C6): every structure over {R, P} with n joints.

Each structure gets its continuous design joints (R link: d, a, alpha; P link: theta, a, alpha) plus the
six placement joints, and the same search (`designopt.search`, `solver.search`). Each stage's solves of all
structures are fanned out together with joblib (loky processes, or a dask.distributed cluster); each finished
solve is written at once, so a killed sweep keeps what it finished and ``resume`` solves only the rest.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.adapters import (
    describe_search,
    enumerate_structures,
    multistart_from_config,
    search_from_config,
    structure_config,
    transcription_for,
)
from designopt.experiments.tasks import Progress, Searchable, Searched, Task, best_of, search_problems, solve_tasks
from designopt.initial_guess import design_from
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.tables import best_per_dof, structure_table


def searchables(cfg: Config, base_dir: Path, structures: list[str]) -> list[Searchable]:
    """Every structure's problem (generic start design, d/theta, a, alpha of every link and the placement free)."""
    items = []
    for structure in structures:
        c = structure_config(cfg, structure)
        items.append(Searchable("sweep", problem_from_config(c, base_dir), transcription_for(c)))
    return items


def neighbours(structure: str, structures: list[str]) -> list[str]:
    """The structures among ``structures`` that differ from ``structure`` in one joint's type (R <-> P)."""
    return [s for s in structures
            if len(s) == len(structure) and sum(a != b for a, b in zip(s, structure, strict=True)) == 1]


def neighbour_tasks(items: list[Searchable], searched: list[Searched], settings) -> list[Task]:
    """One start per (structure, neighbouring structure that has a better design): the neighbour's best design
    (placement and every link parameter of the same name) as the start design, on the full path. A structure
    whose neighbour found a cheaper design was stuck in a worse basin, and the neighbour's design is a good
    guess for it: the two differ in one joint's type only."""
    best = {it.problem.chain.structure: (it, best_of(s.final)[1]) for it, s in zip(items, searched, strict=True)}
    structures = list(best)
    tasks = []
    for it in items:
        own = best[it.problem.chain.structure][1]
        for j, other in enumerate(neighbours(it.problem.chain.structure, structures)):
            theirs = best[other][1]
            if theirs is None or (own is not None and theirs.metrics.design_cost >= own.metrics.design_cost):
                continue
            design = design_from(it.problem, best[other][0].problem, theirs.raw.q_d)
            tasks.append(Task(f"{it.case}-neighbour", "to", it.problem, it.transcription, settings, j, design=design))
    return tasks


@contextmanager
def backend(name: str, scheduler: str | None, jobs: int):
    """joblib's parallel backend: loky processes, or dask.distributed (a LocalCluster without an address)."""
    from joblib import parallel_config

    if name == "loky":
        with parallel_config(backend="loky", n_jobs=jobs):
            yield
        return
    if name != "dask":
        raise ValueError(f"backend must be loky or dask, got {name!r}")
    from dask.distributed import Client, LocalCluster

    cluster = None
    if scheduler is None:
        n = jobs if jobs > 0 else None
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    else:
        client = Client(scheduler)
    try:
        with parallel_config(backend="dask", n_jobs=-1):
            yield
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


@dataclass(frozen=True)
class SweepResult:
    directory: RunDirectory
    table: pd.DataFrame  # one row per structure
    best_per_dof: pd.DataFrame
    structures: int
    solved_now: int
    already_done: int


def run_sweep(cfg: Config, base_dir: Path, out_root: Path, run_name: str | None, min_dof: int = 1,
              max_dof: int = 6, jobs: int = -1, resume: bool = False, backend_name: str = "loky",
              scheduler: str | None = None, progress: Progress | None = None, figures: bool = True) -> SweepResult:
    """Every structure with min_dof..max_dof joints, solved with multistart TO into results/<config name>/<run>."""
    if min_dof > max_dof:
        raise cfg.error("--min-dof", f"{min_dof} is above --max-dof {max_dof}")
    structures = enumerate_structures(min_dof, max_dof)
    searchables(cfg, base_dir, structures[:1])  # bad input stops here, before a run directory exists
    run = RunDirectory.create(out_root, cfg.name, run_name, resume)
    run.write_config(dump_config(cfg))
    before = len(run.resume()) if resume else 0
    run.log(f"sweep {min_dof}..{max_dof} DOF: {len(structures)} structures, search {describe_search(cfg)}; "
            f"{before} solves already done")
    items, settings = searchables(cfg, base_dir, structures), multistart_from_config(cfg)
    with backend(backend_name, scheduler, jobs):
        # every structure gets the same search, stage by stage across all of them (workers stay busy)
        searched = search_problems(run, items, settings, search_from_config(cfg), cfg.name, jobs=None, resume=resume,
                                   progress=progress)
        if cfg.solver.search.structure_neighbours:
            solve_tasks(run, neighbour_tasks(items, searched, settings), cfg.name, jobs=None, resume=resume,
                        progress=progress)
    after = len(pd.read_csv(run.summary))
    summary = pd.read_csv(run.summary)
    table = structure_table(summary)
    table.to_csv(run.path / "table.csv", index=False)
    if figures:
        from designopt import plots_experiments

        plots_experiments.structure_figures(table, run.figures, summary)
    run.log("done")
    return SweepResult(run, table, best_per_dof(table), len(structures), after - before, before)
