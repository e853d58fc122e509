"""A sweep's exploration with objective traces, and what holding its second half to a bound would have done.

Each structure gets the exploration `designopt sweep-structures` gives it (the config's search, seeded starts on
the coarse path, capped, watched for degenerate designs), solved in this process, with the NLP objective and the
largest constraint violation recorded every 5 iterations. ``--simulate`` then replays a rule offline: the first
half of the starts solved freely, a start of the second half stopped at the first recorded iterate past ``after``
iterations that is feasible (violation <= 1e-3) and above F times the first half's best objective. It prints, per
(after, F): the solver CPU the stopped solves would not have spent, how many were stopped, the structures whose
best coarse optimum (the lowest tracking design cost) would be lost (and the worst ratio of what is left to it),
and those whose two best distinct optima, the refinement's candidates, would otherwise differ:

    .venv/bin/python benchmarks/explore_bound.py --seed 1 --json traces_s1.json      # every 3-6 joint structure
    .venv/bin/python benchmarks/explore_bound.py --simulate traces_s1.json

A stopped solve is left out of the pool (conservative: stopped, it would still rank, higher). About 13 minutes of
CPU per seed for the 120 structures of 3-6 joints.
"""

from __future__ import annotations

import argparse
import json
import signal
from dataclasses import replace
from pathlib import Path

import numpy as np

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.experiments.sweep import enumerate_structures, sweep_jobs
from designopt.solve import observers
from designopt.solve.observers import Bound
from designopt.solve.optima import cluster_designs
from designopt.solve.strategies.coarse_to_fine import coarse_problem
from designopt.solve.strategies.steps import seeded_tasks
from designopt.solve.tasks import fan_out

TRACES: dict[int, list] = {}


class Trace:
    """Records (iterations, objective, violation) of the solve whose task index the bound's ``after`` carries (its
    objective is inf: no `AboveBound` is in the profile, and none would stop on it)."""

    status, stopped = "never", False

    def __init__(self, problem):
        self.key = None

    def reset(self, bound=None):
        self.key, self.iterations = (bound.after if bound is not None else None), 0
        if self.key is not None:
            TRACES[self.key] = []

    def observe(self, iterate, iterations=1):
        self.iterations += iterations
        if self.key is not None:
            TRACES[self.key].append((self.iterations, float(iterate.objective), float(iterate.violation)))
        return False


def traces(config: Path, structures: list[str], seed: int, out: Path) -> None:
    observers.OBSERVERS["trace"] = Trace
    cfg = load_config(config)
    search = replace(search_from_config(cfg), seed=seed)
    profile = search.profile.capped(search.explore_max_iter).observing("trace")
    done = json.loads(out.read_text()) if out.exists() else {}
    for structure in structures:
        if structure in done:
            continue
        [job] = sweep_jobs(cfg, [structure])
        tasks = seeded_tasks(job, "explore", coarse_problem(job.problem, search.explore_waypoints), profile, search,
                             search.starts)
        TRACES.clear()
        tasks = [replace(t, bound=Bound(float("inf"), i)) for i, t in enumerate(tasks)]
        done[structure] = [{"start": t.seed, "trace": TRACES.get(t.bound.after, []), "status": s.raw.status,
                            "objective": s.raw.objective, "iterations": s.raw.iterations,
                            "cpu_s": s.raw.solve_time_s, "tracks": bool(s.metrics.tracks),
                            "cost": float(s.metrics.design_cost), "q_d": [float(v) for v in s.raw.q_d],
                            "angle": [j.kind == "angle" for j in t.problem.chain.design]}
                           for t, s in fan_out(tasks, 1)]
        out.write_text(json.dumps(done))
        print(structure, f"{sum(r['cpu_s'] for r in done[structure]):.1f} s", flush=True)


def leaders(rows: list[dict], count: int = 2, tol: float = 0.02) -> list[int]:
    """Start numbers of the ``count`` best distinct tracking optima (as `designopt.solve.optima.distinct_best`)."""
    tracking = [r for r in rows if r["tracks"]]
    if not tracking:
        return []
    costs = np.array([r["cost"] for r in tracking])
    labels = cluster_designs(np.array([r["q_d"] for r in tracking]), costs, np.array(tracking[0]["angle"]), tol)
    best = {}
    for k in np.argsort(costs, kind="stable"):
        best.setdefault(labels[k], tracking[k])
    return [r["start"] for r in list(best.values())[:count]]


def stopped_at(row: dict, bound: float, after: int) -> int | None:
    return next((it for it, objective, violation in row["trace"]
                 if it >= after and violation <= 1e-3 and objective > bound), None)


def simulate(files: list[Path], afters=(50, 100, 150), factors=(3.0, 5.0, 10.0)) -> None:
    runs = [json.loads(f.read_text()) for f in files]
    total = sum(r["cpu_s"] for run in runs for rows in run.values() for r in rows)
    print(f"{sum(len(run) for run in runs)} structure-seeds, exploration solver CPU {total:.0f} s")
    print("| after | F | CPU saved | stopped | best changed (worst ratio) | second changed |")
    print("|---|---|---|---|---|---|")
    for after in afters:
        for factor in factors:
            saved, stopped, best_changed, second_changed, worst = 0.0, 0, 0, 0, 1.0
            for run in runs:
                for rows in run.values():
                    half = (len(rows) + 1) // 2
                    first = [r for r in rows[:half] if r["tracks"]]
                    if not first:
                        continue
                    bound = factor * min(first, key=lambda r: r["cost"])["objective"]
                    kept = list(rows[:half])
                    for r in rows[half:]:
                        it = stopped_at(r, bound, after)
                        if it is None:
                            kept.append(r)
                        else:
                            stopped += 1
                            saved += r["cpu_s"] * (1 - it / max(r["iterations"], 1))
                    before, now = leaders(rows), leaders(kept)
                    cost = {r["start"]: r["cost"] for r in rows}
                    if before and (not now or cost[now[0]] > 1.0001 * cost[before[0]]):
                        best_changed += 1
                        worst = max(worst, cost[now[0]] / cost[before[0]] if now else np.inf)
                    elif before != now:
                        second_changed += 1
            print(f"| {after} | {factor:g} | {saved:.0f} s ({saved / total:.0%}) | {stopped} | {best_changed} "
                  f"({worst:.2f}x) | {second_changed} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structures", nargs="*", help="default: every structure of 3-6 joints")
    parser.add_argument("--config", type=Path, default=Path("configs/structures.yaml"))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", type=Path, help="write (and resume) the traces here")
    parser.add_argument("--simulate", type=Path, nargs="+", help="replay the rule on traces written with --json")
    args = parser.parse_args()
    if args.simulate:
        simulate(args.simulate)
    else:
        traces(args.config, args.structures or enumerate_structures(3, 6), args.seed, args.json)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
