"""Cold full-path starts of a config, one per seeded start, with the stalled-design hold on or off (issue 12).

Prints one line per start (status, iterations, seconds, design cost, tracking, held joints) and a summary:
median (min-max) seconds and iterations, starts at the iteration cap, best and median design cost.

    .venv/bin/python benchmarks/cold_starts.py configs/design_only.yaml --starts 8            # hold on (default)
    .venv/bin/python benchmarks/cold_starts.py configs/design_only.yaml --starts 8 --no-hold
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import yaml
from joblib import Parallel, delayed

from designopt.config import parse_config
from designopt.experiments.adapters import multistart_from_config, transcription_for
from designopt.multistart import solve_start
from designopt.problem import problem_from_config


def solve_cold_starts(raw: dict, config: Path, starts: range, jobs: int = 2) -> list[tuple]:
    """Solve the given seeded starts of the config ``raw`` (read from ``config``) in parallel; one row per start:
    (index, status, iterations, seconds, design cost, tracks, held joints)."""
    cfg = parse_config(raw, config, config.parent)
    problem = problem_from_config(cfg, config.parent)
    transcription = transcription_for(cfg)

    def run(i):
        t0 = time.perf_counter()
        sol = solve_start(problem, transcription, multistart_from_config(cfg), i)
        return (i, sol.raw.status, sol.raw.iterations, time.perf_counter() - t0, sol.metrics.design_cost,
                sol.metrics.tracks, sol.raw.held)

    return Parallel(n_jobs=jobs)(delayed(run)(i) for i in starts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("--starts", type=int, default=8)
    parser.add_argument("--first", type=int, default=0, help="first start index")
    parser.add_argument("--max-iter", type=int, default=None, help="default: the config's solver.max_iter")
    parser.add_argument("--no-hold", action="store_true", help="solver.hold_degenerate: false")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    raw = yaml.safe_load(args.config.read_text())
    raw.setdefault("solver", {})["hold_degenerate"] = not args.no_hold
    if args.max_iter is not None:
        raw["solver"]["max_iter"] = args.max_iter
    rows = solve_cold_starts(raw, args.config, range(args.first, args.first + args.starts), args.jobs)
    for i, status, its, sec, cost, tracks, held in rows:
        print(f"start {i}: {status} {its} it {sec:.1f} s cost {cost:.5g} tracks={tracks}"
              + (f" held [{held}]" if held else ""), flush=True)
    its = np.array([r[2] for r in rows])
    sec = np.array([r[3] for r in rows])
    costs = np.array([r[4] for r in rows if r[5]])
    cap = sum(r[1] == "Maximum_Iterations_Exceeded" for r in rows)
    print(f"hold={not args.no_hold}: {np.median(sec):.2f} s median ({sec.min():.2f}-{sec.max():.2f}), "
          f"{np.median(its):.0f} iterations median (max {its.max()}), {cap} of {len(rows)} at the cap, "
          f"{len(costs)} track, best {costs.min() if len(costs) else np.nan:.5g}, "
          f"median {np.median(costs) if len(costs) else np.nan:.5g}, held on {sum(bool(r[6]) for r in rows)}")


if __name__ == "__main__":
    main()
