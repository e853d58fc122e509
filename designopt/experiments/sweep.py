"""Kinematic structure sweep (SPEC §5, claims C4-C6): every structure over {R, P} with n joints.

Each structure gets its continuous design joints (R link: d, a, alpha; P link: theta, a, alpha) plus the six
placement joints, and the config's search (`designopt.solve.search`), with the structure-neighbour starts: a
structure whose neighbour (one joint type changed, or one joint fewer) found a better design gets a start from
it. Each stage's solves of all structures are fanned out together with joblib (loky processes, or a
dask.distributed cluster); each finished solve is written at once, so a killed sweep keeps what it finished and
``resume`` solves only the rest.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.adapters import enumerate_structures, search_from_config, structure_config
from designopt.experiments.runs import Executor, Progress, record_search
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solve import Job, Search, run_search
from designopt.tables import best_per_dof, structure_table


def sweep_jobs(cfg: Config, structures: list[str]) -> list[Job]:
    """Every structure's problem (generic start design, d/theta, a, alpha of every link and the placement free)."""
    return [Job("sweep", problem_from_config(structure_config(cfg, s))) for s in structures]


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


def run_sweep(cfg: Config, out_root: Path, run_name: str | None, min_dof: int = 1, max_dof: int = 6, jobs: int = -1,
              resume: bool = False, backend_name: str = "loky", scheduler: str | None = None,
              progress: Progress | None = None, figures: bool = True, search: Search | None = None) -> SweepResult:
    """Every structure with min_dof..max_dof joints, searched (the config's search, or ``search``), into
    results/<config name>/<run>."""
    if min_dof > max_dof:
        raise cfg.error("--min-dof", f"{min_dof} is above --max-dof {max_dof}")
    structures = enumerate_structures(min_dof, max_dof)
    sweep_jobs(cfg, structures[:1])  # bad input stops here, before a run directory exists
    search = search or search_from_config(cfg)
    run = RunDirectory.create(out_root, cfg.name, run_name, resume)
    record_search(run, search)  # first: a resume with another search is refused before the run is touched
    run.write_config(dump_config(cfg))
    before = len(run.resume()) if resume else 0
    run.log(f"sweep {min_dof}..{max_dof} DOF: {len(structures)} structures, search {search.describe()}; "
            f"{before} solves already done")
    work = sweep_jobs(cfg, structures)
    with backend(backend_name, scheduler, jobs):
        # every structure gets the same search, stage by stage across all of them (workers stay busy)
        run_search(work, search, Executor(run, cfg.name, None, resume, progress))
    summary = pd.read_csv(run.summary)
    table = structure_table(summary)
    table.to_csv(run.path / "table.csv", index=False)
    if figures:
        from designopt import plots_experiments

        plots_experiments.structure_figures(table, run.figures, summary)
    run.log("done")
    return SweepResult(run, table, best_per_dof(table), len(structures), len(summary) - before, before)
