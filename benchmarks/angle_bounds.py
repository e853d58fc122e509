"""Design twist bounds and IPOPT stalls (issue 12): solve starts 0..N-1 of a config with robot.bounds.angle set
to [-A, A], print status, iterations, seconds, design cost and tracking per start.

    .venv/bin/python benchmarks/angle_bounds.py configs/design_only.yaml 3.141592653589793 [--starts 8]
    .venv/bin/python benchmarks/angle_bounds.py configs/design_only.yaml 6.283185307179586 --max-iter 3000
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import yaml
from joblib import Parallel, delayed

from designopt.config import parse_config
from designopt.experiments.adapters import multistart_from_config, transcription_for
from designopt.multistart import solve_start
from designopt.problem import problem_from_config


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("angle", type=float)
    parser.add_argument("--starts", type=int, default=8)
    parser.add_argument("--max-iter", type=int, default=3000)
    args = parser.parse_args()
    raw = yaml.safe_load(args.config.read_text())
    raw["robot"]["bounds"] = {**raw["robot"].get("bounds", {}), "angle": [-args.angle, args.angle]}
    raw["solver"]["max_iter"] = args.max_iter
    cfg = parse_config(raw, args.config, args.config.parent)
    problem = problem_from_config(cfg, args.config.parent)
    transcription = transcription_for(cfg)

    def run(i):
        t0 = time.perf_counter()
        sol = solve_start(problem, transcription, multistart_from_config(cfg), i)
        return (i, sol.raw.status, sol.raw.iterations, round(time.perf_counter() - t0, 1),
                f"{sol.metrics.design_cost:.4g}", sol.metrics.tracks)

    for row in Parallel(n_jobs=2)(delayed(run)(i) for i in range(args.starts)):
        print(args.angle, row, flush=True)


if __name__ == "__main__":
    main()
