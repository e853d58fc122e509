"""Issue 24's speed table in one command: per problem, the NLP build (cold: empty compile cache, new process;
warm: cache filled, new process), and over seeded starts solved one at a time on one core, ms per iteration
(functions / rest), iterations, the share of inertia-corrected iterations, CPU per solve and the costs reached.

    .venv/bin/python benchmarks/speed_table.py --starts 8 --json new.json
    .venv/bin/python benchmarks/speed_table.py --compare old.json new.json     # side by side, as ratios
    .venv/bin/python benchmarks/speed_table.py --build benchmarks/configs/aluminum_button.yaml   # one build

Compare two versions by running this in both (a `git worktree` of the previous commit with its own venv) in the
same session, then --compare; the machine's load moves both alike. Times are CPU seconds (IPOPT's functions
from CasADi's t_proc_* timers); builds are wall seconds of a fresh process.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

sys.path.insert(0, str(Path(__file__).parent))
from iteration_split import FUNCTIONS, logged_solve  # noqa: E402
from solver_options import parse_options  # noqa: E402

from designopt.config import load_config  # noqa: E402
from designopt.experiments.adapters import search_from_config  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solve.strategies.coarse_to_fine import coarse_problem  # noqa: E402

# name: (config, waypoints (0: all), how the search solves it there: "explore" capped and watched, else "full")
PROBLEMS = {
    "main job (80 wp)": ("configs/milling.yaml", 0, "full"),
    "exploration (10 wp)": ("configs/milling.yaml", 10, "explore"),
    "sweep structure (40 wp)": ("configs/structures.yaml", 0, "full"),
    "pocket cell (35 wp)": ("configs/gcode_pocket.yaml", 0, "full"),
}


def setup(config: str, waypoints: int, stage: str, options: tuple = (), compile_mode: str | None = None):
    cfg = load_config(Path(config))
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    if waypoints:
        problem = coarse_problem(problem, waypoints)
    if stage == "explore":  # as the search explores: capped, watched, by the exploration's linear solver
        search = replace(search, profile=search.explore_profile.observing("degenerate"))
    if options:
        search = replace(search, profile=replace(search.profile, options=(*search.profile.options, *options)))
    if compile_mode:
        search = replace(search, profile=replace(search.profile, compile=compile_mode))
    return problem, search


def build_seconds(name: str, cache: str, compile_mode: str | None) -> tuple[float, float]:
    """(wall, CPU) seconds a new process spends building and preparing problem ``name`` with compile cache
    ``cache``."""
    env = {**os.environ, "DESIGNOPT_CACHE": cache}
    mode = ["--compile", compile_mode] if compile_mode else []
    out = subprocess.run([sys.executable, __file__, "--build-only", name, *mode], env=env, check=True,
                         capture_output=True, text=True).stdout
    wall, cpu = out.strip().splitlines()[-1].split()
    return float(wall), float(cpu)


def landed(cache: str, seconds: float = 600.0) -> None:
    """Wait until the compile cache ``cache`` has no build under way (a cold build leaves its blocks' -O0 builds
    running in the background: a warm build is one that finds their libraries)."""
    deadline = time.time() + seconds
    while time.time() < deadline and any(Path(cache).glob("*.lock")):
        time.sleep(0.1)


def measure(name: str, starts: int, options: tuple = (), compile_mode: str | None = None) -> dict:
    problem, search = setup(*PROBLEMS[name], options, compile_mode)
    with tempfile.TemporaryDirectory() as cache:
        cold, _ = build_seconds(name, cache, compile_mode)
        landed(cache)
        warm, _ = build_seconds(name, cache, compile_mode)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for start in range(starts):
            built, solver, outcome, total, corrected, _ = logged_solve(problem, search, start,
                                                                       Path(tmp) / f"{start}.log")
            stats = solver.solver.stats()
            functions = sum(stats.get(f"t_proc_{f}", 0.0) for f in FUNCTIONS)
            rows.append({"status": outcome.status, "iterations": outcome.iterations, "cpu_s": total,
                         "functions_s": functions, "corrected": corrected, "cost": outcome.objective})
    # ``auto`` compiles a block tiered: -O1 when the compile cache already has it (a block solved with long enough),
    # else -O0 -- the table says which ran (pin it with --compile O0 or O1)
    tiered = "O0" if built.nlp.tiered_libraries(search.profile.compile) else "O1 or fixed"
    return {"build_cold_s": cold, "build_warm_s": warm, "starts": rows, "tiered_level": tiered}


def summary(m: dict) -> dict:
    rows = m["starts"]
    n = [max(r["iterations"], 1) for r in rows]
    med = statistics.median
    costs = sorted(r["cost"] for r in rows)
    return {"build cold [s]": m["build_cold_s"], "build warm [s]": m["build_warm_s"],
            "ms/iter": med(1e3 * r["cpu_s"] / k for r, k in zip(rows, n, strict=True)),
            "functions ms/iter": med(1e3 * r["functions_s"] / k for r, k in zip(rows, n, strict=True)),
            "iterations": med(r["iterations"] for r in rows),
            "corrected": med(r["corrected"] for r in rows),
            "CPU/solve [s]": med(r["cpu_s"] for r in rows), "CPU all [s]": sum(r["cpu_s"] for r in rows),
            "converged": sum(r["status"] == "Solve_Succeeded" for r in rows) / len(rows),
            "best cost": costs[0], "median cost": med(costs)}


def print_table(results: dict, other: dict | None = None) -> None:
    names = list(results)
    print("tiered blocks ran at: " + ", ".join(f"{n} {results[n].get('tiered_level', '?')}" for n in names))
    keys = list(summary(results[names[0]]))
    head = "| what | " + " | ".join(names) + " |"
    print(head)
    print("|---" * (len(names) + 1) + "|")
    for key in keys:
        cells = []
        for name in names:
            new = summary(results[name])[key]
            if other is None or name not in other:
                cells.append(f"{new:.4g}")
            else:
                old = summary(other[name])[key]
                ratio = f" ({new / old:.2f}x)" if old else ""
                cells.append(f"{old:.4g} -> {new:.4g}{ratio}")
        print(f"| {key} | " + " | ".join(cells) + " |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--starts", type=int, default=8)
    parser.add_argument("--only", action="append", help="a problem name (repeatable; default: all)")
    parser.add_argument("--json", type=Path, help="write the raw measurements here")
    parser.add_argument("--compare", type=Path, nargs=2, metavar=("OLD", "NEW"),
                        help="print two JSON files side by side")
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                        help="an nlpsol option for every solve, e.g. ipopt.mumps_pivot_order=5 (a lever to measure)")
    parser.add_argument("--compile", help="the solver profile's compile mode (none, O0, O1, O2; default: the config's)")
    parser.add_argument("--build", metavar="CONFIG", help="only the build (cold, warm) of this config's full problem")
    parser.add_argument("--repeat", type=int, default=1, help="warm builds to take the median of (with --build)")
    parser.add_argument("--build-only", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.build_only:
        from designopt.solve import local
        from designopt.transcriptions import Collocation
        spec = PROBLEMS.get(args.build_only, (args.build_only, 0, "full"))  # a name, or any config's path
        problem, search = setup(*spec, compile_mode=args.compile)
        t0, c0 = time.perf_counter(), time.process_time()
        local.prepared(problem, Collocation(), search.profile)
        print(time.perf_counter() - t0, time.process_time() - c0)
        return
    if args.build:
        with tempfile.TemporaryDirectory() as cache:
            cold = build_seconds(args.build, cache, args.compile)
            landed(cache)
            warms = [build_seconds(args.build, cache, args.compile) for _ in range(args.repeat)]
        wall, cpu = statistics.median(w for w, _ in warms), statistics.median(c for _, c in warms)
        print(f"{args.build}: build cold {cold[0]:.2f} s (CPU {cold[1]:.3f} s), warm {wall:.2f} s (CPU {cpu:.3f} s; "
              f"median of {args.repeat}; a new process each)")
        return
    if args.compare:
        old, new = (json.loads(p.read_text()) for p in args.compare)
        print(f"{args.compare[0]} -> {args.compare[1]}")
        print_table(new, old)
        return
    options = parse_options(args.option)
    results = {name: measure(name, args.starts, options, args.compile) for name in (args.only or PROBLEMS)}
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))
    print_table(results)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
