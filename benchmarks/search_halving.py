"""Does racing many cheap starts beat solving a few to the end? (issue 11, lever 1)

For each search seed: K cold starts of the default job each get ``race`` IPOPT iterations; the ``keep`` best
(lowest objective among those whose tool is already within 10 mm of the path) are solved again from the same
start with the full iteration budget (IPOPT is deterministic, so this is the uninterrupted solve of that start:
only the first ``race`` iterations are repeated). Compared with today's default: 4 starts solved to the end.

    .venv/bin/python benchmarks/search_halving.py [--seeds 5] [--candidates 16] [--race 80] [--keep 3]

Prints one line per seed and the ratios to the best design known (benchmarks/reference).
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

from joblib import Parallel, delayed

from designopt.config import load_config
from designopt.experiments.adapters import multistart_from_config, transcription_for
from designopt.multistart import solve_start
from designopt.problem import problem_from_config

ROOT = Path(__file__).resolve().parent.parent


def _solve(problem, transcription, settings, index):
    t0 = time.perf_counter()
    sol = solve_start(problem, transcription, settings, index)
    return index, sol, time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--candidates", type=int, default=16)
    parser.add_argument("--race", type=int, default=80)
    parser.add_argument("--keep", type=int, default=3)
    parser.add_argument("--baseline", action="store_true", help="also run today's 4 full starts per seed")
    args = parser.parse_args()
    cfg = load_config(ROOT / "configs" / "milling.yaml")
    problem = problem_from_config(cfg, ROOT / "configs")
    full = transcription_for(cfg)
    race = replace(full, max_iter=args.race)
    best_known = json.loads((ROOT / "benchmarks/reference/milling_best_known.json").read_text())["metrics"][
        "design_cost"]
    pool = Parallel(n_jobs=2)
    for seed in range(args.seeds):
        settings = replace(multistart_from_config(cfg), seed=seed)
        t0 = time.perf_counter()
        raced = pool(delayed(_solve)(problem, race, settings, i) for i in range(args.candidates))
        near = [(sol.raw.objective, i) for i, sol, _ in raced if sol.metrics.max_position_error <= 1e-2]
        chosen = [i for _, i in sorted(near)[: args.keep]]
        finals = pool(delayed(_solve)(problem, full, settings, i) for i in chosen)
        wall = time.perf_counter() - t0
        tracking = [sol.metrics.design_cost for _, sol, _ in finals if sol.metrics.tracks]
        best = min(tracking) if tracking else float("nan")
        cpu = sum(t for *_, t in raced) + sum(t for *_, t in finals)
        line = (f"seed {seed}: halving best {best:.4g} ({best / best_known:.2f}x best known), kept {chosen}, "
                f"{wall:.1f} s wall, {cpu:.1f} s in solves")
        if args.baseline:
            t1 = time.perf_counter()
            plain = pool(delayed(_solve)(problem, full, settings, i) for i in range(4))
            costs = [sol.metrics.design_cost for _, sol, _ in plain if sol.metrics.tracks]
            line += (f"; 4 full starts: best {min(costs):.4g} ({min(costs) / best_known:.2f}x), "
                     f"{time.perf_counter() - t1:.1f} s wall")
        print(line, flush=True)


if __name__ == "__main__":
    main()
