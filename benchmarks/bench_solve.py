"""Time one TO solve of the default milling problem (configs/milling.yaml, N = 80).

Cases: placement only (fixed PUMA-560, 6 design joints), design only (fixed workpiece, 18), combined (24).
For each: NLP build time (cold = block function compiled, warm = loaded from the cache), and over several
seeded starts the median solve time and IPOPT iterations. Solves run one at a time on one core.

    .venv/bin/python benchmarks/bench_solve.py [--starts 6] [--ablation]

``--ablation`` also times the choices that got us here on the combined case (CasADi's own Hessian vs
the structured one, compiled or not, IK vs constant starts, soft vs hard tracking).
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from designopt.config import load_config  # noqa: E402
from designopt.experiments.adapters import case_config  # noqa: E402
from designopt.initial_guess import initial_guesses  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solution import solve_and_evaluate  # noqa: E402
from designopt.solve import SolverProfile  # noqa: E402
from designopt.solve.backends import backend_named  # noqa: E402
from designopt.transcriptions import Collocation  # noqa: E402
from designopt.transcriptions.base import RawResult  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def problems():
    cfg = load_config(ROOT / "configs" / "milling.yaml")
    return {name: problem_from_config(case_config(cfg, case)) for name, case in
            (("placement only", "placement_only"), ("design only", "design_only"), ("combined", "combined"))}


DEFAULT = SolverProfile(max_iter=1000)


def bench(name, problem, transcription, starts, init="ik", cold=True, profile=DEFAULT):
    def prepared():
        t0 = time.perf_counter()
        built = transcription.build(problem)
        solver = backend_named(profile.backend).prepare(built.nlp, profile)
        return built, solver, time.perf_counter() - t0

    if cold:
        os.environ["DESIGNOPT_CACHE"] = tempfile.mkdtemp()
        cold_build = prepared()[2]
    else:
        cold_build = float("nan")
    built, solver, warm_build = prepared()
    rows = []
    for guess in initial_guesses(problem, starts, seed=0, scale=0.3, mode=init):
        out = solver.solve(built.pack(guess))
        q_d, trajectory, _ = built.unpack(out.x)
        m = solve_and_evaluate(problem, "to", RawResult(q_d, trajectory, out.status, out.success, out.iterations,
                                                        out.solve_time_s, 0.0, out.objective, 0, 0)).metrics
        rows.append((out.solve_time_s, out.iterations, m.design_cost, m.tracks, out.status))
    times = [r[0] for r in rows]
    iters = [r[1] for r in rows]
    tracking = [r[2] for r in rows if r[3]]
    print(f"{name:<34} n_x={built.nlp.n_variables:5d} build cold {cold_build:5.2f}s warm {warm_build:5.2f}s | "
          f"solve median {statistics.median(times):6.2f}s (min {min(times):5.2f}, max {max(times):6.2f}) | "
          f"iter median {statistics.median(iters):6.0f} (max {max(iters)}) | tracks {len(tracking)}/{len(rows)} | "
          f"best cost {min(tracking) if tracking else float('nan'):.4g}", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--starts", type=int, default=5)
    parser.add_argument("--ablation", action="store_true")
    args = parser.parse_args()
    print(f"cores: {os.cpu_count()}, starts per case: {args.starts}, max_iter 1000, N = 80")
    cases = problems()
    for name, problem in cases.items():
        bench(name, problem, Collocation(), args.starts)
    if args.ablation:
        combined = cases["combined"]
        print("ablation on the combined case:")
        bench("  hessian=auto (CasADi AD)", combined, Collocation(hessian="auto"), args.starts)
        bench("  structured, interpreted", combined, Collocation(), args.starts,
              profile=SolverProfile(max_iter=1000, compile="none"))
        bench("  structured, gcc -O1", combined, Collocation(), args.starts,
              profile=SolverProfile(max_iter=1000, compile="O1"))
        bench("  constant-q starts (no IK)", combined, Collocation(), args.starts, init="constant", cold=False)
        bench("  soft tracking w=1e4 (paper)", combined, Collocation(tracking="soft"), min(args.starts, 2),
              cold=False, profile=SolverProfile(max_iter=3000))


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
