"""Write a design known for the default job (configs/milling.yaml) to benchmarks/reference/, from scratch.

This reproduces how the first reference was found: start 4 of seed 0, solved with CasADi's own Hessian
(`hessian: auto`), which reaches 3.795e-4 where the structured Hessian takes the same start to 4.68e-4; then a warm
re-solve with the default (structured) transcription and a small barrier confirms it is a local minimum of the
default NLP. (The reference files only ever get better: a search that finds a better design replaces them.)

    .venv/bin/python benchmarks/reference_milling.py [--out benchmarks/reference/milling_best_known.json]
"""

from __future__ import annotations

import argparse
import signal
from pathlib import Path

from designopt.config import load_config
from designopt.problem import problem_from_config
from designopt.solution import write_solution
from designopt.solve import Lifted, Seeded, SolverProfile, solve_one
from designopt.transcriptions import Collocation
from designopt.verify import verify_file

ROOT = Path(__file__).resolve().parent.parent
WARM = SolverProfile(max_iter=1000, options=(("ipopt.mu_init", 1e-6), ("ipopt.bound_push", 1e-8),
                                             ("ipopt.bound_frac", 1e-8)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "reference" / "milling_best_known.json")
    args = parser.parse_args()
    problem = problem_from_config(load_config(ROOT / "configs" / "milling.yaml"))
    found = solve_one(problem, Seeded(0, 4), Collocation(hessian="auto"), SolverProfile(max_iter=1000))
    sol = solve_one(problem, Lifted(found), Collocation(), WARM)
    write_solution(sol, args.out)
    print(f"{args.out}: design cost {sol.metrics.design_cost:.6g}, tracks {sol.metrics.tracks}, "
          f"{sol.raw.status} after {sol.raw.iterations} warm iterations; verify: {verify_file(args.out) or 'ok'}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
