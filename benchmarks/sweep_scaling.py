"""Does a structure sweep scale to more workers? Its strong-scaling curve, replayed from a finished run.

A sweep's stages (explore, refine, neighbour) end in a barrier: a stage's tasks all depend on the stage before.
Within a stage, `designopt.solve.tasks.units` groups the tasks into the units joblib (or Dask) hands to
workers. This replays a finished run with W workers: every stage's tasks, in the order the sweep submits them
(structures in the table's order, starts by seed), cut into units by the library's own `units`, each unit given
to the worker free first; a task lasts its solve in the run (summary.csv), plus a build of its NLP when its
worker has not built that problem yet: the largest build the run recorded for it the first time any worker
builds it (the compile), the smallest later (the compile cache is shared). Refine and neighbour solves share
their full-path NLP; the exploration's coarse NLP is another.
It prints, per W, the replayed wall time, the speed-up over one worker and the efficiency, and per stage the
replayed wall time against the run's own (from run.log's timestamps) for the W the run used, so that the
replay's error is on the page.

    .venv/bin/python benchmarks/sweep_scaling.py results/structures/paper [--workers 1 2 4 8 16 32 64] [--ran-with 2]

The replay leaves out what no summary records (process start-up, the time between a task's end and the next
unit's dispatch, a larger machine's memory bandwidth), so it is an upper bound on the speed-up.
"""

from __future__ import annotations

import argparse
import heapq
import signal
from datetime import datetime
from pathlib import Path
from types import SimpleNamespace

import pandas as pd

from designopt.solve.tasks import units

STAGES = ("explore", "screen", "refine", "neighbour")


def stage_tasks(summary: pd.DataFrame, order: list[str]) -> dict[str, list[SimpleNamespace]]:
    """Per stage, the run's tasks as objects `units` can group (one problem object per structure and stage)."""
    rank = {s: i for i, s in enumerate(order)}
    out = {}
    for stage in [s for s in STAGES if s in set(summary.stage)]:
        rows = summary[summary.stage == stage].copy()
        rows["_order"] = rows.structure.map(rank)
        rows = rows.sort_values(["_order", "seed"])
        problems = {s: object() for s in rows.structure.unique()}
        out[stage] = [SimpleNamespace(problem=problems[r.structure], transcription=r.method, profile=stage,
                                      nlp=(r.structure, stage == "explore"), seconds=float(r.solve_time_s))
                      for r in rows.itertuples()]
    return out


def build_costs(summary: pd.DataFrame) -> dict[tuple, tuple[float, float]]:
    """Per NLP (structure, coarse or not): (first build anywhere, a later build), from the builds recorded."""
    built = summary[summary.build_time_s > 0]
    keys = zip(built.structure, built.stage == "explore", strict=True)
    out: dict[tuple, list[float]] = {}
    for key, seconds in zip(keys, built.build_time_s, strict=True):
        out.setdefault(key, []).append(float(seconds))
    return {k: (max(v), min(v)) for k, v in out.items()}


def replay(tasks: dict[str, list[SimpleNamespace]], builds: dict, workers: int) -> dict[str, float]:
    """Wall seconds of each stage on ``workers`` workers: units in order, each to the worker free first; a
    worker builds an NLP before its first task of it."""
    has = [set() for _ in range(workers)]
    anywhere: set = set()
    walls = {}
    for stage, stage_tasks_ in tasks.items():
        free = [(0.0, w) for w in range(workers)]
        end = 0.0
        for unit in units(stage_tasks_, workers):
            start, w = heapq.heappop(free)
            seconds = 0.0
            for t in unit:
                if t.nlp not in has[w]:
                    first, later = builds.get(t.nlp, (0.0, 0.0))
                    seconds += later if t.nlp in anywhere else first
                    has[w].add(t.nlp)
                    anywhere.add(t.nlp)
                seconds += t.seconds
            heapq.heappush(free, (start + seconds, w))
            end = max(end, start + seconds)
        walls[stage] = end
    return walls


def logged_stage_walls(log: Path) -> dict[str, float]:
    """Each stage's wall seconds from run.log: from the first to the last line of that stage's solves."""
    first, last = {}, {}
    for line in log.read_text().splitlines():
        parts = line.split()
        if len(parts) > 2 and parts[2] in STAGES:
            t = datetime.fromisoformat(parts[0])
            first.setdefault(parts[2], t)
            last[parts[2]] = t
    return {s: (last[s] - first[s]).total_seconds() for s in first}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a sweep's run directory (summary.csv, table.csv, run.log)")
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2, 4, 8, 16, 32, 64])
    parser.add_argument("--ran-with", type=int, default=2, help="workers of the run itself")
    args = parser.parse_args()
    summary = pd.read_csv(args.run / "summary.csv")
    table = args.run / "table.csv"
    order = list(pd.read_csv(table).structure) if table.exists() else list(summary.structure.unique())
    tasks = stage_tasks(summary, order)
    builds = build_costs(summary)
    solves = sum(t.seconds for ts in tasks.values() for t in ts)
    longest = max(t.seconds for ts in tasks.values() for t in ts)
    print(f"{args.run}: {sum(map(len, tasks.values()))} solves, {solves:.0f} s of solves (longest {longest:.1f} s), "
          f"{len(builds)} NLPs; stages {', '.join(f'{s} {len(ts)}' for s, ts in tasks.items())}")
    logged = logged_stage_walls(args.run / "run.log") if (args.run / "run.log").exists() else {}
    if logged:
        ran = replay(tasks, builds, args.ran_with)
        print(f"with {args.ran_with} workers, replayed / logged wall per stage: " + ", ".join(
            f"{s} {ran[s]:.0f} / {logged.get(s, float('nan')):.0f} s" for s in tasks))
    one = sum(replay(tasks, builds, 1).values())
    print("| workers | wall [s] | speed-up | efficiency | per stage [s] |")
    print("|---|---|---|---|---|")
    for w in args.workers:
        per = replay(tasks, builds, w)
        wall = sum(per.values())
        print(f"| {w} | {wall:.0f} | {one / wall:.1f} | {one / wall / w:.0%} | "
              + ", ".join(f"{s} {v:.0f}" for s, v in per.items()) + " |")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
