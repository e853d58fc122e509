"""Design twist bounds and IPOPT stalls (issue 12): solve starts 0..N-1 of a config with robot.bounds.angle set
to [-A, A], print status, iterations, seconds, design cost and tracking per start.

    .venv/bin/python benchmarks/angle_bounds.py configs/design_only.yaml 3.141592653589793 [--starts 8]
    .venv/bin/python benchmarks/angle_bounds.py configs/design_only.yaml 6.283185307179586 --max-iter 3000
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cold_starts import solve_cold_starts  # noqa: E402


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
    for i, status, its, sec, cost, tracks, _ in solve_cold_starts(raw, args.config, range(args.starts)):
        print(args.angle, (i, status, its, round(sec, 1), f"{cost:.4g}", tracks), flush=True)


if __name__ == "__main__":
    main()
