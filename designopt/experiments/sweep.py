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
from designopt.experiments.tasks import Progress, Searchable, search_problems
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
    with backend(backend_name, scheduler, jobs):
        # every structure gets the same search, stage by stage across all of them (workers stay busy)
        search_problems(run, searchables(cfg, base_dir, structures), multistart_from_config(cfg),
                        search_from_config(cfg), cfg.name, jobs=None, resume=resume, progress=progress)
    after = len(pd.read_csv(run.summary))
    summary = pd.read_csv(run.summary)
    table = structure_table(summary)
    table.to_csv(run.path / "table.csv", index=False)
    if figures:
        from designopt import plots_experiments

        plots_experiments.structure_figures(table, run.figures, summary)
    run.log("done")
    return SweepResult(run, table, best_per_dof(table), len(structures), after - before, before)
