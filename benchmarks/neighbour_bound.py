"""A sweep's neighbour starts with objective traces, and what holding them to their bound sooner would have done.

``trace RUN --out COPY``: the neighbour and later stages of a finished sweep (RUN: its run directory) solved again in
this process, on a copy of the run without them (`designopt sweep-structures --resume` does the same: the
exploration and the refine are read back), with every observation of the bound recorded per start (every 5th
iteration: iterations, NLP objective, largest constraint violation, the bound); the copy's rows are the run's (the
same solves). ``rules COPY`` then replays stop rules on the traces: a start stopped at the first observation past
``k`` iterations that is feasible (violation <= 1e-3) and above ``F`` times its structure's best objective (the bound
is 3 times it), unless the bound in force (3x after 300) stops it sooner. Per (k, F): the starts it stops, the solver
seconds they would not have spent, those among them that beat their structure's refined best by more than 1 %, and
the structures whose final best rests on a stopped start (their best without it). What the later steps (the
second neighbour pass, the reflections) would have made of a stopped start is not predicted, and it decided both
judges of 2026-11-28 (docs/decisions.md, "Speed"):

    .venv/bin/python benchmarks/neighbour_bound.py trace results/structures/<run> --out /tmp/nb_copy   # ~400 s CPU
    .venv/bin/python benchmarks/neighbour_bound.py rules /tmp/nb_copy --after 150 200 --factor 3 10
"""

from __future__ import annotations

import argparse
import json
import shutil
import signal
from pathlib import Path

import numpy as np
import pandas as pd

from designopt.config import load_config
from designopt.experiments.sweep import run_sweep
from designopt.solve import observers, tasks
from designopt.solve.strategies.neighbours import BOUND_AFTER, BOUND_FACTOR

REPLAYED = ("neighbour", "reflect")  # stage prefixes solved again
FEASIBLE = 1e-3


def trace(run: Path, out: Path) -> None:
    cfg = load_config(run / "config.yaml")
    copy = out / cfg.name / run.name
    if copy.exists():
        raise SystemExit(f"{copy} exists")
    shutil.copytree(run, copy)
    summary = pd.read_csv(copy / "summary.csv")
    for name in summary[summary.stage.str.startswith(REPLAYED)].solution_file:
        (copy / name).unlink(missing_ok=True)
    summary[~summary.stage.str.startswith(REPLAYED)].to_csv(copy / "summary.csv", index=False)
    dofs = summary.structure.str.len()

    traces: dict[str, list] = {}
    current = {"key": ""}
    solve, observe = tasks.run_task, observers.AboveBound.observe

    def run_task(task):
        current["key"] = f"{task.stage}|{task.problem.chain.structure}|{task.seed}"
        return solve(task)

    def observed(self, iterate, iterations=1):
        stop = observe(self, iterate, iterations)
        bound = self.bound.objective if self.bound is not None else float("nan")
        traces.setdefault(current["key"], []).append((self.iterations, iterate.objective, iterate.violation, bound))
        return stop

    tasks.run_task, observers.AboveBound.observe = run_task, observed
    try:  # one process, so that the patched functions are the ones that run
        run_sweep(cfg, out, run.name, int(dofs.min()), int(dofs.max()), jobs=1, resume=True, figures=False)
    finally:
        tasks.run_task, observers.AboveBound.observe = solve, observe
    (copy / "bound_traces.json").write_text(json.dumps(traces))
    print(f"{len(traces)} starts traced into {copy / 'bound_traces.json'}")


def first_stop(points, after: int, factor: float) -> int | None:
    """The first observed iteration at which a rule (``after``, ``factor``) stops a start with these trace points:
    past ``after`` iterations, feasible and above ``factor`` times its structure's best objective (the bound logged
    is `BOUND_FACTOR` times it). None: never."""
    own = points[0][3] / BOUND_FACTOR
    return next((it for it, obj, v, _ in points if it >= after and v <= FEASIBLE and obj > factor * own), None)


def rules(copy: Path, afters: list[int], factors: list[float]) -> None:
    traces = {k: sorted(v) for k, v in json.loads((copy / "bound_traces.json").read_text()).items()}
    summary = pd.read_csv(copy / "summary.csv")
    full = summary[(summary.stage != "explore") & summary.tracks.astype(bool)]
    refined = full[full.stage == "refine"].groupby("structure").design_cost.min()
    final = full.groupby("structure").design_cost.min()
    starts = summary[summary.stage.str.startswith("neighbour")]
    keys = [f"{r.stage}|{r.structure}|{r.seed}" for r in starts.itertuples()]
    print(f"{copy}: {len(starts)} neighbour starts, {starts.solve_time_s.sum():.0f} s of the sweep's "
          f"{summary.solve_time_s.sum():.0f} s of solver time")
    for after in afters:
        for factor in factors:
            stopped, saved, beat = set(), 0.0, 0
            for r, key in zip(starts.itertuples(), keys, strict=True):
                points = traces.get(key)
                if not points or r.iterations <= 0:
                    continue
                now, rule = first_stop(points, BOUND_AFTER, BOUND_FACTOR), first_stop(points, after, factor)
                if rule is None or (now is not None and now <= rule):  # the bound in force stops it as soon
                    continue
                stopped.add((r.stage, r.structure, r.seed))
                saved += r.solve_time_s * max(0, r.iterations - rule) / r.iterations
                beat += bool(r.tracks and r.design_cost < 0.99 * refined.get(r.structure, np.inf))
            kept = full[[(s, st, sd) not in stopped for s, st, sd in zip(full.stage, full.structure, full.seed,
                                                                            strict=True)]]
            ratio = kept.groupby("structure").design_cost.min().reindex(final.index) / final
            lost = {s: round(float(v), 3) for s, v in ratio.items() if not v <= 1.001}
            print(f"after {after:4d}, above {factor:g}x: {len(stopped):3d} more stopped, {saved:6.0f} s saved, "
                  f"{beat:2d} that beat their refined best, final bests resting on them: {lost or 'none'}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=("trace", "rules"))
    parser.add_argument("path", type=Path, help="trace: a sweep's run directory; rules: the traced copy")
    parser.add_argument("--out", type=Path, help="trace: the results root the copy goes under")
    parser.add_argument("--after", type=int, nargs="+", default=[150, 200, 250])
    parser.add_argument("--factor", type=float, nargs="+", default=[3.0, 10.0])
    args = parser.parse_args()
    if args.what == "trace":
        if args.out is None:
            parser.error("trace needs --out")
        trace(args.path, args.out)
    else:
        rules(args.path, args.after, args.factor)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
