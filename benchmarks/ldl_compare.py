"""Two builds of the LDLᵀ behind IPOPT's ``ma27`` calls (`designopt.solve.backends.ldl`) on the same solves: this
checkout's and one built from the sources of git revision ``--against``. Each round runs, in one fresh process per
library (alternating, so that the machine's load falls on both alike), the exploration's seeded starts of
``--config`` on ``--waypoints`` waypoints as the search solves them (capped, watched, by the LDLᵀ:
`speed_table.setup`), and prints each process's CPU per IPOPT iteration, the iterations and a digest of the
objectives reached: equal digests mean the same solves to the bit. At the end, the median over the rounds of the
ratio this / against.

    .venv/bin/python benchmarks/ldl_compare.py --against HEAD~1 [--config configs/milling.yaml] [--starts 48]
        [--rounds 8] [--waypoints 10]
"""

from __future__ import annotations

import argparse
import hashlib
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LDL = "designopt/solve/backends/ldl"


def build_at(revision: str, out: Path) -> Path:
    """The LDLᵀ library compiled from ``revision``'s sources (the flags of this checkout's build)."""
    from designopt.solve.backends import ldl

    src = out / "src"
    src.mkdir()
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", revision, LDL], check=True, capture_output=True)
    subprocess.run(["tar", "-x", "-C", str(src)], input=archive.stdout, check=True)
    here = src / LDL
    sources = [here / "ma27.c", here / "qdldl.c", *sorted((here / "amd").glob("*.c"))]
    library = out / "ldl_against.so"
    subprocess.run(["gcc", *ldl.FLAGS, f"-I{here}", f"-I{here / 'amd'}", *map(str, sources), "-o", str(library),
                    "-lm"], check=True, capture_output=True)
    return library


def solve_with(library: str, config: str, waypoints: int, starts: int) -> None:
    """One process's measurement (``--child``): prints CPU ms per iteration, iterations and the objectives' digest."""
    import numpy as np

    import designopt.solve.backends.ldl as ldl

    ldl.library = lambda: Path(library)  # what `designopt.solve.backends.ipopt` loads
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from speed_table import setup

    from designopt.initial_guess import initial_guess
    from designopt.solve import local
    from designopt.transcriptions import Collocation

    problem, search = setup(config, waypoints, "explore")
    built, solver, _ = local.prepared(problem, Collocation(), search.profile)
    guesses = [built.pack(initial_guess(problem, s, search.seed, search.perturbation, search.init))
               for s in range(starts)]
    cpu, iterations, objectives = time.process_time(), 0, []
    for guess in guesses:
        outcome = solver.solve(guess)
        iterations += outcome.iterations
        objectives.append(outcome.objective)
    ms = 1000 * (time.process_time() - cpu) / max(iterations, 1)
    print(f"{ms:.4f} {iterations} {hashlib.sha256(np.array(objectives).tobytes()).hexdigest()[:12]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", help="git revision whose LDLᵀ sources to compare with")
    parser.add_argument("--config", default="configs/milling.yaml")
    parser.add_argument("--starts", type=int, default=48)
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--waypoints", type=int, default=10)
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        solve_with(args.child, args.config, args.waypoints, args.starts)
        return
    if not args.against:
        parser.error("--against REVISION is required")
    from designopt.solve.backends import ldl

    this = ldl.library()
    with tempfile.TemporaryDirectory() as tmp:
        against = build_at(args.against, Path(tmp))
        ratios, digests = [], set()
        for r in range(args.rounds):
            row = {}
            for name, library in (("against", against), ("this", this)):
                out = subprocess.run([sys.executable, __file__, "--child", str(library), "--config", args.config,
                                      "--starts", str(args.starts), "--waypoints", str(args.waypoints)],
                                     check=True, capture_output=True, text=True, cwd=ROOT).stdout.split()
                row[name] = (float(out[0]), int(out[1]), out[2])
                digests.add((out[1], out[2]))
            ratios.append(row["this"][0] / row["against"][0])
            print(f"round {r + 1}: {args.against} {row['against'][0]:.4f} ms/iter ({row['against'][1]} iterations, "
                  f"{row['against'][2]}), this {row['this'][0]:.4f} ({row['this'][1]}, {row['this'][2]}): "
                  f"{ratios[-1]:.3f}x", flush=True)
    same = "the same solves to the bit" if len(digests) == 1 else "solves differ"
    print(f"{args.config}, {args.starts} starts on {args.waypoints} waypoints, {args.rounds} rounds: this / "
          f"{args.against} per iteration {statistics.median(ratios):.3f}x median "
          f"({min(ratios):.3f}-{max(ratios):.3f}); {same}")


if __name__ == "__main__":
    main()
