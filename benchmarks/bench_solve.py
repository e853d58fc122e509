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
import statistics
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from designopt.config import load_config  # noqa: E402
from designopt.evaluation import evaluate  # noqa: E402
from designopt.initial_guess import initial_guesses  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.transcriptions import Collocation  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def problems():
    cfg = load_config(ROOT / "configs" / "milling.yaml")
    combined = problem_from_config(cfg, ROOT / "configs")
    placement = problem_from_config(cfg.model_copy(update={"robot": cfg.robot.model_copy(update={"design": []})}))
    design = problem_from_config(cfg.model_copy(update={"placement": cfg.placement.model_copy(
        update={"optimize": False})}))
    return {"placement only": placement, "design only": design, "combined": combined}


def bench(name, problem, transcription, starts, init="ik", cold=True):
    if cold:
        os.environ["DESIGNOPT_CACHE"] = tempfile.mkdtemp()
        t0 = time.perf_counter()
        transcription.build(problem)
        cold_build = time.perf_counter() - t0
    else:
        cold_build = float("nan")
    nlp = transcription.build(problem)
    rows = []
    for guess in initial_guesses(problem, starts, seed=0, scale=0.3, mode=init):
        raw = nlp.solve(guess)
        m = evaluate(problem, raw.q_d, raw.Q)
        rows.append((raw.solve_time_s, raw.iterations, m.design_cost, m.tracks, raw.status))
    times = [r[0] for r in rows]
    iters = [r[1] for r in rows]
    tracking = [r[2] for r in rows if r[3]]
    print(f"{name:<34} n_x={nlp.n_variables:5d} build cold {cold_build:5.2f}s warm {nlp.build_time_s:5.2f}s | "
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
        bench(name, problem, Collocation(max_iter=1000), args.starts)
    if args.ablation:
        combined = cases["combined"]
        print("ablation on the combined case:")
        bench("  hessian=auto (CasADi AD)", combined, Collocation(max_iter=1000, hessian="auto"), args.starts)
        bench("  structured, interpreted", combined, Collocation(max_iter=1000, compile="none"), args.starts)
        bench("  structured, gcc -O1", combined, Collocation(max_iter=1000, compile="O1"), args.starts)
        bench("  constant-q starts (no IK)", combined, Collocation(max_iter=1000), args.starts, init="constant",
              cold=False)
        bench("  soft tracking w=1e4 (paper)", combined, Collocation(max_iter=3000, tracking="soft"),
              min(args.starts, 2), cold=False)


if __name__ == "__main__":
    main()
