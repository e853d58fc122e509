"""Cold full-path starts of a config, one per seeded start, with the stalled-design hold on or off.

Prints one line per start (status, iterations, seconds, design cost, tracking, held joints) and a summary:
median (min-max) seconds and iterations, starts at the iteration cap, best and median design cost.

    .venv/bin/python benchmarks/cold_starts.py configs/design_only.yaml --starts 8            # hold on (default)
    .venv/bin/python benchmarks/cold_starts.py configs/design_only.yaml --starts 8 --no-hold
    .venv/bin/python benchmarks/cold_starts.py configs/gcode_pocket.yaml --starts 16 --option ipopt.perturb_always_cd=no
"""

from __future__ import annotations

import argparse
import signal
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from joblib import Parallel, delayed
from solver_options import parse_options

from designopt.config import load_config
from designopt.experiments.adapters import search_from_config
from designopt.problem import problem_from_config
from designopt.solve import Seeded, solve_one


def solve_cold_starts(config: Path, starts: range, jobs: int = 2, hold: bool = True,
                      max_iter: int | None = None, options: tuple = ()) -> list[tuple]:
    """Solve the given seeded starts of a config in parallel (its search's seed, perturbation and profile, with
    ``options``, (name, value) pairs of the backend, added last); one row per start: (index, status, iterations,
    seconds, design cost, tracks, held joints)."""
    cfg = load_config(config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    profile = search.profile if max_iter is None else replace(search.profile, max_iter=max_iter)
    profile = replace(profile, options=(*profile.options, *options))

    def run(i):
        t0 = time.perf_counter()
        sol = solve_one(problem, Seeded(search.seed, i, search.perturbation, search.init), profile=profile,
                        hold_degenerate=hold)
        return (i, sol.raw.status, sol.raw.iterations, time.perf_counter() - t0, sol.metrics.design_cost,
                sol.metrics.tracks, sol.raw.held)

    return Parallel(n_jobs=jobs)(delayed(run)(i) for i in starts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("--starts", type=int, default=8)
    parser.add_argument("--first", type=int, default=0, help="first start index")
    parser.add_argument("--max-iter", type=int, default=None, help="default: the config's search profile's")
    parser.add_argument("--no-hold", action="store_true", help="do not finish stalled solves held")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--option", action="append", default=[], help="a solver option KEY=VALUE, e.g. "
                        "ipopt.perturb_always_cd=no (added after the config's own)")
    args = parser.parse_args()
    options = parse_options(args.option)
    rows = solve_cold_starts(args.config, range(args.first, args.first + args.starts), args.jobs, not args.no_hold,
                             args.max_iter, options)
    for i, status, its, sec, cost, tracks, held in rows:
        print(f"start {i}: {status} {its} it {sec:.1f} s cost {cost:.5g} tracks={tracks}"
              + (f" held [{held}]" if held else ""), flush=True)
    its = np.array([r[2] for r in rows])
    sec = np.array([r[3] for r in rows])
    costs = np.array([r[4] for r in rows if r[5]])
    cap = sum(r[1] == "Maximum_Iterations_Exceeded" for r in rows)
    print(f"hold={not args.no_hold}: {np.median(sec):.2f} s median ({sec.min():.2f}-{sec.max():.2f}, "
          f"{sec.sum():.1f} in all), "
          f"{np.median(its):.0f} iterations median (max {its.max()}), {cap} of {len(rows)} at the cap, "
          f"{len(costs)} track, best {costs.min() if len(costs) else np.nan:.5g}, "
          f"median {np.median(costs) if len(costs) else np.nan:.5g}, held on {sum(bool(r[6]) for r in rows)}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
