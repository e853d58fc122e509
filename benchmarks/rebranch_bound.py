"""Would a bound stop the exploration's second round early without losing what the search goes on with?

The default search explores in two rounds: ``starts`` seeded starts on the coarse path, then its ``rebranch`` best
distinct coarse optima started again on new joint branches (`designopt.solve.strategies.coarse_to_fine`). The
second round's tasks are made after the first has finished, so a bound is known when they start: its best
objective. This runs both rounds of a config's default search for each seed, the second with a recording observer
(every 5th iteration: violation and objective), and replays `designopt.solve.observers.AboveBound` on the traces
for each rule ``FACTOR@AFTER`` (a feasible iterate above FACTOR x the first round's best NLP objective, AFTER
iterations in, stops the start). For each rule it prints the second round's iterations saved and what the stopped
starts would have ended as: among the ``screen`` best distinct coarse optima of both rounds (what the search
screens), the best coarse optimum of the seed, within 1.10x of it.

    .venv/bin/python benchmarks/rebranch_bound.py [--config configs/milling.yaml] [--first-seed 0] [--seeds 4]
        [--rule 3@50 --rule 2@100 ...] [--out traces.json | --replay traces.json] [--jobs 2]
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
from joblib import Parallel, delayed

sys.path.insert(0, str(Path(__file__).parent))
from violation_traces import Recorder  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def solve_recorded(task) -> dict:
    """One task solved in this worker with a `Recorder` watching (registered in the worker's own registry)."""
    from designopt.solve.local import prepared
    from designopt.solve.observers import OBSERVERS
    from designopt.solve.tasks import run_task

    OBSERVERS["record"] = Recorder
    task = replace(task, profile=task.profile.observing("record"))
    sol = run_task(task)
    recorder = prepared(task.problem, task.transcription, task.profile)[1].observers[-1]
    return {"seed": sol.raw.seed, "iterations": sol.raw.iterations, "objective": sol.raw.objective,
            "design_cost": sol.metrics.design_cost, "tracks": bool(sol.metrics.tracks),
            "q_d": [float(v) for v in sol.raw.q_d], "trace": recorder.trace}


def run_seed(config: Path, seed: int, jobs: int) -> dict:
    from designopt.config import load_config
    from designopt.problem import problem_from_config
    from designopt.solve import Job, fan_out, preset
    from designopt.solve.search import by_job
    from designopt.solve.strategies.coarse_to_fine import coarse_problem, rebranched_tasks
    from designopt.solve.strategies.steps import seeded_tasks

    search = preset("default", seed=seed)
    job = Job("", problem_from_config(load_config(config)))
    coarse = coarse_problem(job.problem, search.explore_waypoints)
    first = list(fan_out(seeded_tasks(job, "explore", coarse, search.explore_profile, search, search.starts), jobs))
    (first,) = by_job([job], first)
    again = rebranched_tasks([first], search)
    second = Parallel(n_jobs=jobs)(delayed(solve_recorded)(t) for t in again)
    rows = [{"seed": s.raw.seed, "iterations": s.raw.iterations, "objective": s.raw.objective,
             "design_cost": s.metrics.design_cost, "tracks": bool(s.metrics.tracks),
             "q_d": [float(v) for v in s.raw.q_d]} for _, s in first]
    return {"seed": seed, "screen": search.screen, "distinct": search.distinct, "first": rows, "second": second}


def stop_at(trace: list, objective: float, after: int, tol: float = 1e-3) -> int | None:
    """The iteration `AboveBound` would stop this trace at, or None."""
    for iterations, violation, value in trace:
        if iterations >= after and violation <= tol and value > objective:
            return iterations
    return None


def distinct_ranks(rows: list[dict], count: int, distinct: float, angle: np.ndarray) -> set[int]:
    """Indices of the ``count`` best distinct tracking rows, as `designopt.solve.optima.distinct_best` picks them."""
    from designopt.solve.optima import cluster_designs

    tracking = [k for k, r in enumerate(rows) if r["tracks"]]
    costs = np.array([rows[k]["design_cost"] for k in tracking])
    labels = cluster_designs(np.array([rows[k]["q_d"] for k in tracking]), costs, angle, distinct)
    leaders: dict[int, int] = {}
    for i in np.argsort(costs, kind="stable"):
        leaders.setdefault(int(labels[i]), tracking[i])
    return set(list(leaders.values())[:count])


def judge(runs: list[dict], rules: list[tuple[float, int]], angle: np.ndarray) -> list[str]:
    lines = []
    for factor, after in rules:
        saved = total = lost_screen = lost_best = lost_near = stopped = 0
        for run in runs:
            first, second = run["first"], run["second"]
            bound = factor * min(r["objective"] for r in first if r["tracks"])
            pooled = first + second
            screened = distinct_ranks(pooled, run["screen"], run["distinct"], angle)
            best = min(r["design_cost"] for r in pooled if r["tracks"])
            for k, r in enumerate(second):
                total += r["iterations"]
                at = stop_at(r["trace"], bound, after)
                if at is None:
                    continue
                stopped += 1
                saved += r["iterations"] - at
                lost_screen += (len(first) + k) in screened
                lost_best += bool(r["tracks"] and r["design_cost"] <= best)
                lost_near += bool(r["tracks"] and r["design_cost"] <= 1.10 * best)
        lines.append(f"  {factor:g}x after {after}: stops {stopped} of {sum(len(r['second']) for r in runs)} starts, "
                     f"saves {saved} of {total} second-round iterations ({100 * saved / total:.0f} %); of the "
                     f"stopped: {lost_screen} among the screened, {lost_best} a seed's best, {lost_near} within "
                     f"1.10x of it")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="configs/milling.yaml")
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--rule", action="append", default=[], metavar="FACTOR@AFTER")
    parser.add_argument("--out", type=Path)
    parser.add_argument("--replay", type=Path)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    rules = [(float(f), int(a)) for f, a in (r.split("@") for r in args.rule or
                                             ["2@50", "3@50", "3@25", "5@25", "3@100", "10@25"])]

    from designopt.config import load_config
    from designopt.problem import problem_from_config

    problem = problem_from_config(load_config(ROOT / args.config))
    angle = np.array([j.kind == "angle" for j in problem.chain.design])
    if args.replay:
        runs = json.loads(args.replay.read_text())
    else:
        seeds = range(args.first_seed, args.first_seed + args.seeds)
        runs = [run_seed(ROOT / args.config, s, args.jobs) for s in seeds]
        if args.out:
            args.out.write_text(json.dumps(runs))
    print(f"{args.config}: seeds {runs[0]['seed']}-{runs[-1]['seed']}, the default search's two exploration rounds; "
          "a rule FACTOR x the first round's best objective, AFTER iterations in:")
    print("\n".join(judge(runs, rules, angle)))


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
