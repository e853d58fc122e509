"""What evaluating a solution costs: `designopt.evaluation.evaluate` (one CasADi function of the problem mapped over
the waypoints) against a numpy walk of the chain per waypoint (`DesignProblem.waypoint` on numbers, what
`evaluate` did until 2026-11-26), at random designs and joints, and the largest relative difference between the two.

    .venv/bin/python benchmarks/evaluate_speed.py [CONFIG ...] [--repeat 50]

Every solve of a search is evaluated once (an exploration solve of the main job costs about 80 ms, so a 4 ms
evaluation was 5 % of it). Prints per config and waypoint count (the exploration's 10 and the full path): ms per
call of each (the function's first call, which builds it, apart) and the difference. A cell's clearance check (its
own numpy and coal code, unchanged) is left out: each problem is timed without its cell.
"""

from __future__ import annotations

import argparse
import signal
import time
from dataclasses import replace

import numpy as np

from designopt.config import load_config
from designopt.costs import deformation_term, tracking_residual
from designopt.evaluation import evaluate
from designopt.problem import problem_from_config
from designopt.solve.strategies.coarse_to_fine import coarse_problem
from designopt.transcriptions.trajectory import PiecewiseLinear


def numpy_walk(problem, q_d, Q):
    """The per-waypoint numbers by numpy: deformation, position and axis error norms, stand-off, cost integrals."""
    tp = problem.toolpath
    states = [problem.waypoint(Q[k], q_d, tp.points_W[k], tp.force_W[k]) for k in range(tp.n)]
    residuals = [tracking_residual(w) for w in states]
    s_B = [w.T_BW[:3, :3] @ w.s_W + w.T_BW[:3, 3] for w in states]
    return {"deformation": np.array([deformation_term(w) for w in states]),
            "position_error": np.array([np.linalg.norm(r) for r, _ in residuals]),
            "axis_error": np.array([np.linalg.norm(z) for _, z in residuals]),
            "min_standoff": min(np.hypot(s[0], s[1]) for s in s_B),
            **{c.name: sum(wk * c.fn(w) for wk, w in zip(tp.weights, states, strict=True))
               for c in problem.waypoint_costs}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("configs", nargs="*", default=["configs/milling.yaml", "configs/circle_standoff.yaml"])
    parser.add_argument("--repeat", type=int, default=50)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    print("| config | waypoints | evaluate, first call | evaluate | numpy walk | largest relative difference |")
    print("|---|---|---|---|---|---|")
    for path in args.configs:
        full = replace(problem_from_config(load_config(path)), cell=None)
        for problem in (coarse_problem(full, 10), full):
            chain = problem.chain
            q_d = np.array([rng.uniform(j.lower, j.upper) if np.isfinite(j.upper - j.lower) else j.value + rng.normal()
                            for j in chain.design])
            Q = rng.uniform(-2, 2, (problem.toolpath.n, chain.n_moving))
            trajectory = PiecewiseLinear(problem.toolpath.t, Q)
            t0 = time.perf_counter()
            m = evaluate(problem, q_d, trajectory)
            first = time.perf_counter() - t0
            t0 = time.perf_counter()
            for _ in range(args.repeat):
                m = evaluate(problem, q_d, trajectory)
            fast = (time.perf_counter() - t0) / args.repeat
            t0 = time.perf_counter()
            for _ in range(max(1, args.repeat // 10)):
                ref = numpy_walk(problem, q_d, Q)
            slow = (time.perf_counter() - t0) / max(1, args.repeat // 10)
            got = {"deformation": m.deformation, "position_error": m.position_error, "axis_error": m.axis_error,
                   "min_standoff": m.min_standoff, **dict(m.costs)}
            diff = max(float(np.max(np.abs(np.asarray(got[k]) - np.asarray(v)) / np.maximum(np.abs(v), 1e-300)))
                       for k, v in ref.items())
            print(f"| {path} | {problem.toolpath.n} | {first * 1e3:.1f} ms | {fast * 1e3:.2f} ms | {slow * 1e3:.1f} ms "
                  f"| {diff:.1e} |")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
