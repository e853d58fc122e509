"""How the constraint violation of a config's cold starts falls, iteration by iteration; and what a stall rule stops.

Solves seeded starts of a config on its full path (its search's seed, perturbation and profile, ``--option``s added)
and records, every 5th iteration, the largest constraint violation and the objective (a recording observer beside
the profile's own). Writes the traces to ``--out`` (JSON); with ``--replay`` reads them back instead of solving.
Then, for each ``--patience`` (iterations), it replays `designopt.solve.observers.StalledViolation` on every trace
and prints what the rule would have stopped: starts, the iterations and seconds saved, and the stopped starts that
went on to track (the rule's false stops); before that, the longest stall of a start that tracked (the largest
patience that would still have stopped one):

    .venv/bin/python benchmarks/violation_traces.py configs/gcode_pocket.yaml --starts 16 --out pocket.json
    .venv/bin/python benchmarks/violation_traces.py --replay pocket.json --patience 50 100 200
    .venv/bin/python benchmarks/violation_traces.py configs/milling.yaml --starts 80 --waypoints 10 --max-iter 250
"""

from __future__ import annotations

import argparse
import json
import signal
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from joblib import Parallel, delayed
from solver_options import parse_options

from designopt.solve.backends.ipopt import OBSERVE_EVERY
from designopt.solve.observers import Iterate, StalledViolation


class Recorder:
    """An observer that never stops a solve: it keeps (iterations, violation, objective) of every iterate it sees."""

    status = "never"

    def __init__(self, problem):
        self.reset()

    def reset(self, bound=None) -> None:
        self.trace, self.iterations, self.stopped = [], 0, False

    def observe(self, iterate: Iterate, iterations: int = 1) -> bool:
        self.iterations += iterations
        self.trace.append((self.iterations, iterate.violation, iterate.objective))
        return False


def trace_start(config: str, index: int, options: tuple, waypoints: int | None = None,
                max_iter: int | None = None) -> dict:
    """One seeded start of ``config`` solved on its full path (or on ``waypoints`` of them, as the search's
    exploration does) with a `Recorder` watching. The imports are the worker's own: a registry imported at module level
    would reach the worker as a pickled copy, and the recorder would be registered in the copy."""
    from designopt.config import load_config
    from designopt.experiments.adapters import search_from_config
    from designopt.problem import problem_from_config
    from designopt.solve.local import prepared, solve_guess
    from designopt.solve.observers import OBSERVERS
    from designopt.solve.starts import Seeded
    from designopt.solve.strategies.coarse_to_fine import coarse_problem
    from designopt.transcriptions import Collocation

    OBSERVERS["record"] = Recorder  # this worker's registry: the benchmark's observer beside the library's
    cfg = load_config(config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    if waypoints:
        problem = coarse_problem(problem, waypoints)
    profile = replace(search.profile, options=(*search.profile.options, *options)).observing("record")
    profile = profile.capped(max_iter)
    transcription = Collocation()
    start = Seeded(search.seed, index, search.perturbation, search.init, spread=search.spread)
    t0 = time.perf_counter()
    sol = solve_guess(problem, transcription, profile, start.guess(problem))
    recorder = prepared(problem, transcription, profile)[1].observers[-1]
    return {"start": index, "status": sol.raw.status, "iterations": sol.raw.iterations,
            "seconds": time.perf_counter() - t0, "tracks": bool(sol.metrics.tracks),
            "design_cost": sol.metrics.design_cost, "trace": recorder.trace}


def replay(trace: list, patience: int) -> int | None:
    """The iteration at which `StalledViolation` with ``patience`` would have stopped this trace (None: never)."""
    watch = StalledViolation(None, patience=patience)
    last = 0
    for iterations, violation, objective in trace:
        if watch.observe(Iterate(np.zeros(0), objective, violation), iterations - last):
            return iterations
        last = iterations
    return None


def longest_stall(trace: list) -> int:
    """The largest patience (a multiple of 5 iterations) at which `StalledViolation` would still have stopped this
    trace (0: none would): any patience above it lets the trace run on."""
    last = trace[-1][0] if trace else 0
    return max((p for p in range(5, last + 1, 5) if replay(trace, p) is not None), default=0)


def summarise(rows: list[dict], patience: int) -> str:
    stopped = [(r, at) for r in rows if (at := replay(r["trace"], patience)) is not None]
    saved_it = sum(r["iterations"] - at for r, at in stopped)
    saved_s = sum(r["seconds"] * (1 - at / max(r["iterations"], 1)) for r, at in stopped)
    false = [r["start"] for r, _ in stopped if r["tracks"]]
    total_s = sum(r["seconds"] for r in rows)
    where = ", ".join(f"{r['start']} at {at}" for r, at in stopped) or "none"
    return (f"patience {patience}: stops {len(stopped)} of {len(rows)} starts ({where}); saves {saved_it} iterations, "
            f"{saved_s:.0f} of {total_s:.0f} s; stopped starts that would have tracked: {false or 'none'}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", nargs="?")
    parser.add_argument("--starts", type=int, default=8)
    parser.add_argument("--first", type=int, default=0, help="first start index")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--option", action="append", default=[], help="a solver option KEY=VALUE (after the config's)")
    parser.add_argument("--waypoints", type=int, help="solve on this many of the path's waypoints (e.g. 10, the "
                        "exploration's)")
    parser.add_argument("--max-iter", type=int, help="cap the profile's iterations (e.g. 250, the exploration's)")
    parser.add_argument("--out", type=Path, help="write the traces here (JSON)")
    parser.add_argument("--replay", type=Path, help="read traces written by --out instead of solving")
    parser.add_argument("--patience", type=int, nargs="+", default=[StalledViolation.PATIENCE])
    args = parser.parse_args()
    if args.replay:
        rows = json.loads(args.replay.read_text())
    else:
        if not args.config:
            parser.error("a config, or --replay FILE")
        options = parse_options(args.option)
        rows = Parallel(n_jobs=args.jobs)(delayed(trace_start)(args.config, i, options, args.waypoints, args.max_iter)
                                          for i in range(args.first, args.first + args.starts))
        if args.out:
            args.out.write_text(json.dumps(rows))
    for r in rows:
        v = [t[1] for t in r["trace"]]
        print(f"start {r['start']}: {r['status']} {r['iterations']} it {r['seconds']:.1f} s tracks={r['tracks']} "
              f"violation first {v[0] if v else float('nan'):.3g} last {v[-1] if v else float('nan'):.3g} "
              f"(every {OBSERVE_EVERY} iterations)", flush=True)
    tracked = [longest_stall(r["trace"]) for r in rows if r["tracks"]]
    print(f"longest stall of a start that tracked: {max(tracked, default=0)} iterations "
          f"(of {len(tracked)} that tracked)")
    for p in args.patience:
        print(summarise(rows, p))


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
