"""Kinematic structure sweep (SPEC §5, claims C4-C6): every structure over {R, P} with n joints.

Each structure gets its continuous design joints (R link: d, a, alpha; P link: theta, a, alpha) plus the
six placement joints, and is solved by TO with multistart. Every (structure, start) is one task, fanned
out with joblib (loky processes, or a dask.distributed cluster); each finished solve is written at once,
so a killed sweep keeps what it finished and ``resume`` solves only the rest.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from designopt.config import Config, dump_config
from designopt.experiments.run import multistart_from_config, transcription_from_config
from designopt.experiments.tasks import Task, multistart_tasks, solve_tasks
from designopt.problem import problem_from_config
from designopt.results_io import RunDirectory
from designopt.solution import Solution


def enumerate_structures(min_dof: int = 1, max_dof: int = 6) -> list[str]:
    """All strings over {R, P} with min_dof..max_dof letters: by length, then R before P at each place.
    1..6 gives 2 + 4 + ... + 64 = 126."""
    return ["".join(s) for n in range(min_dof, max_dof + 1) for s in itertools.product("RP", repeat=n)]


def structure_config(cfg: Config, structure: str) -> Config:
    """The sweep's config for one structure: generic start design, every link's d/theta, a, alpha free."""
    if cfg.robot.is_urdf:
        raise cfg.error("robot.urdf", "the structure sweep builds DH robots; a URDF robot has one structure")
    robot = cfg.robot.model_copy(update={"structure": structure, "dh": "generic", "design": ["d", "a", "alpha"]})
    return cfg.model_copy(update={"robot": robot})


@dataclass(frozen=True)
class SweepPlan:
    structures: list[str]
    tasks: list[Task]
    skipped: int


def plan(cfg: Config, base_dir: Path, structures: list[str], done: set) -> SweepPlan:
    """Every (structure, start) task of the sweep; ``tasks`` are those not in ``done`` (finished keys)."""
    settings = multistart_from_config(cfg)
    tasks = []
    for structure in structures:
        c = structure_config(cfg, structure)
        tasks += multistart_tasks("sweep", "to", problem_from_config(c, base_dir), transcription_from_config(c),
                                  settings)
    todo = [t for t in tasks if t.key not in done]
    return SweepPlan(structures, todo, len(tasks) - len(todo))


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


def run_sweep(cfg: Config, base_dir: Path, out_root: Path, run_name: str | None, min_dof: int = 1,
              max_dof: int = 6, jobs: int = -1, resume: bool = False, backend_name: str = "loky",
              scheduler: str | None = None, on_plan: Callable[[SweepPlan], None] | None = None,
              on_solution: Callable[[Solution], None] | None = None, figures: bool = True) -> RunDirectory:
    run = RunDirectory.create(out_root, cfg.name, run_name, resume)  # results/<config name>/<run>, like every run
    run.write_config(dump_config(cfg))
    sweep_plan = plan(cfg, base_dir, enumerate_structures(min_dof, max_dof), set(run.resume()) if resume else set())
    run.log(f"sweep {min_dof}..{max_dof} DOF: {len(sweep_plan.structures)} structures, {len(sweep_plan.tasks)} "
            f"solves to do, {sweep_plan.skipped} already done")
    if on_plan:
        on_plan(sweep_plan)
    if sweep_plan.tasks:
        with backend(backend_name, scheduler, jobs):
            # the plan already left out finished solves; their rows stay, and the table reads them
            solve_tasks(run, sweep_plan.tasks, cfg.name, jobs=None,
                        on_solution=(lambda _t, sol: on_solution(sol)) if on_solution else None)
    table = structure_table(pd.read_csv(run.summary))
    table.to_csv(run.path / "table.csv", index=False)
    if figures:
        from designopt import plots_experiments

        plots_experiments.structure_figures(table, run.figures)
    run.log("done")
    return run


def best_per_dof(table: pd.DataFrame) -> pd.DataFrame:
    """The lowest-cost tracking structure for each number of joints."""
    tracking = table.dropna(subset=["design_cost"]).sort_values("design_cost")
    return tracking.groupby("dof").head(1).sort_values("dof")


def structure_table(summary: pd.DataFrame) -> pd.DataFrame:
    """One row per structure: best tracking start (cost NaN if none tracks), starts, statuses."""
    rows = []
    for structure, group in summary.groupby("structure", sort=False):
        tracking = group[group["tracks"].astype(str) == "True"]
        best = tracking.loc[tracking["design_cost"].idxmin()] if len(tracking) else None
        rows.append({
            "structure": structure, "dof": len(structure), "n_prismatic": structure.count("P"),
            "design_cost": best["design_cost"] if best is not None else float("nan"),
            "tracking_starts": len(tracking), "starts": len(group),
            "statuses": ";".join(sorted(set(group["status"]))),
            "best_solution": best["solution_file"] if best is not None else "",
            "median_solve_time_s": group["solve_time_s"].median(),
        })
    table = pd.DataFrame(rows)
    order = {s: i for i, s in enumerate(enumerate_structures(1, 12))}
    return table.sort_values("structure", key=lambda c: c.map(order)).reset_index(drop=True)
