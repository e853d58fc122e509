"""This checkout's library against git revision ``--against``'s on the same solves: the ratio of CPU per IPOPT
iteration, and whether the solves are the same to the bit.

The revision's ``designopt/`` is exported (``git archive``) to a temporary directory and imported from there
(``PYTHONPATH``) by the same venv, so a change to the Python library, to a compiled block or to the LDLᵀ's C sources
(built into the compile cache under their own key) is measured alike, without a second venv. Each round runs, in
one fresh process per checkout (alternating, in the order ABBA, so that the machine's load and which one runs
second fall on both alike), ``--starts`` seeded
starts of ``--config`` as the search solves them (``--waypoints`` > 0: the exploration's, capped, watched, by its
linear solver; 0: cold starts on the full path by the search's profile; `speed_table.setup`), and prints each
process's CPU per iteration, the iterations and a digest of the objectives and solutions reached: equal digests
mean the same solves to the bit. At the end, the median over the rounds of the ratio this / against.

    .venv/bin/python benchmarks/solve_compare.py --against HEAD [--config configs/milling.yaml] [--starts 48]
        [--rounds 8] [--waypoints 10]

With ``--build``, each process is instead `speed_table.py --build-only CONFIG`: it builds and prepares the config's
NLP (the full path, the search's profile) from the compile cache and prints its wall and CPU seconds; a first round,
not counted, fills the cache for both checkouts, so the rounds compare warm builds. At the end, the medians of each
checkout and their ratio.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def export(revision: str, out: Path) -> Path:
    """``revision``'s ``designopt/`` package under ``out`` (for PYTHONPATH)."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", revision, "designopt"], check=True,
                             capture_output=True)
    subprocess.run(["tar", "-x", "-C", str(out)], input=archive.stdout, check=True)
    return out


def measure(config: str, waypoints: int, starts: int) -> None:
    """One process's measurement (``--child``): CPU ms per iteration, iterations and the solves' digest."""
    import numpy as np

    sys.path.insert(0, str(ROOT / "benchmarks"))
    from speed_table import setup

    from designopt.initial_guess import initial_guess
    from designopt.solve import local
    from designopt.transcriptions import Collocation

    problem, search = setup(config, waypoints, "explore" if waypoints else "full")
    built, solver, _ = local.prepared(problem, Collocation(), search.profile)
    guesses = [built.pack(initial_guess(problem, s, search.seed, search.perturbation, search.init))
               for s in range(starts)]
    digest = hashlib.sha256()
    cpu, iterations = time.process_time(), 0
    for guess in guesses:
        outcome = solver.solve(guess)
        iterations += outcome.iterations
        digest.update(np.r_[outcome.objective, outcome.x].tobytes())
    ms = 1000 * (time.process_time() - cpu) / max(iterations, 1)
    print(f"{ms:.4f} {iterations} {digest.hexdigest()[:12]}")


def checkouts(against: str, tmp: str) -> tuple[tuple[str, dict], tuple[str, dict]]:
    """(name, environment) of ``against``'s library (exported under ``tmp``) and of this checkout's."""
    return (("against", {**os.environ, "PYTHONPATH": str(export(against, Path(tmp)))}),
            ("this", {**os.environ, "PYTHONPATH": str(ROOT)}))


def compare_builds(against: str, config: str, rounds: int) -> None:
    """Warm builds of ``config`` by ``against``'s library and this checkout's, a fresh process each, alternating."""
    command = [sys.executable, str(ROOT / "benchmarks" / "speed_table.py"), "--build-only", config]
    walls: dict[str, list[float]] = {"against": [], "this": []}
    with tempfile.TemporaryDirectory() as tmp:
        both = checkouts(against, tmp)
        for r in range(rounds + 1):  # round 0 fills the compile cache for both
            row = {}
            for name, env in (both if r % 2 == 0 else both[::-1]):
                out = subprocess.run(command, check=True, capture_output=True, text=True, cwd=ROOT, env=env)
                row[name] = tuple(float(v) for v in out.stdout.split()[-2:])
                if r:
                    walls[name].append(row[name][0])
            if r:
                print(f"round {r}: {against} {row['against'][0]:.3f} s (CPU {row['against'][1]:.3f}), this "
                      f"{row['this'][0]:.3f} s (CPU {row['this'][1]:.3f})", flush=True)
    a, b = statistics.median(walls["against"]), statistics.median(walls["this"])
    print(f"{config}, warm build, {rounds} rounds: {against} {a:.3f} s, this {b:.3f} s median wall "
          f"({min(walls['this']):.3f}-{max(walls['this']):.3f}): {b / a:.3f}x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", required=False, help="git revision to compare with")
    parser.add_argument("--config", default="configs/milling.yaml")
    parser.add_argument("--starts", type=int, default=48)
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--waypoints", type=int, default=10, help="0: the full path")
    parser.add_argument("--build", action="store_true", help="compare warm NLP builds instead of solves")
    parser.add_argument("--child", action="store_true",
                        help="measure this checkout in this process only (what each round runs; e.g. under perf)")
    args = parser.parse_args()
    if args.child:
        measure(args.config, args.waypoints, args.starts)
        return
    if not args.against:
        parser.error("--against REVISION is required")
    if args.build:  # each process speed_table.py's --build-only
        compare_builds(args.against, args.config, args.rounds)
        return
    command = [sys.executable, __file__, "--child", "--config", args.config, "--starts", str(args.starts),
               "--waypoints", str(args.waypoints)]
    with tempfile.TemporaryDirectory() as tmp:
        both = checkouts(args.against, tmp)
        ratios, digests = [], set()
        for r in range(args.rounds):
            row = {}
            for name, env in (both if r % 2 == 0 else both[::-1]):  # ABBA: neither checkout always runs second
                out = subprocess.run(command, check=True, capture_output=True, text=True, cwd=ROOT, env=env)
                ms, iterations, digest = out.stdout.split()[-3:]
                row[name] = (float(ms), int(iterations), digest)
                digests.add((iterations, digest))
            ratios.append(row["this"][0] / row["against"][0])
            print(f"round {r + 1}: {args.against} {row['against'][0]:.4f} ms/iter ({row['against'][1]} iterations, "
                  f"{row['against'][2]}), this {row['this'][0]:.4f} ({row['this'][1]}, {row['this'][2]}): "
                  f"{ratios[-1]:.3f}x", flush=True)
    where = f"{args.waypoints} waypoints" if args.waypoints else "the full path"
    same = "the same solves to the bit" if len(digests) == 1 else "the solves differ"
    print(f"{args.config}, {args.starts} starts on {where}, {args.rounds} rounds: this / {args.against} per "
          f"iteration {statistics.median(ratios):.3f}x median ({min(ratios):.3f}-{max(ratios):.3f}); {same}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
