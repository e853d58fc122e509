"""A kept design re-solved from itself at a tighter tolerance: the local optimum it sits near, to more digits.

A solution file is read as a solution of its task's problem (``--config``, with the file's structure when it is a
sweep structure's), and solved again warm from its own design, joints and velocities, by IPOPT at ``--tol``
(the library's solves stop at 1e-8, scaled; a design found at that tolerance is up to about 1e-4 away from the
design cost of the optimum it converges to, relatively, either way: docs/decisions.md, Search, 2026-12-06).
Prints the file's design cost and the re-solve's, and with ``--out`` writes the re-solved solution when it tracks;
whether it replaces a best design known is the caller's decision (its cost is what `python -m designopt.verify`
checks).

    .venv/bin/python benchmarks/polish_reference.py --config configs/structures.yaml \
        benchmarks/reference/structures_k_i_RRPRRR_best_known.json --tol 1e-10
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from designopt.config import load_config
from designopt.experiments.adapters import structure_config
from designopt.problem import problem_from_config
from designopt.solution import read_solution_for, write_solution
from designopt.solve.local import solve_guess
from designopt.solve.profile import SolverProfile
from designopt.transcriptions import Collocation
from designopt.transcriptions.base import InitialGuess


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("solution", type=Path, help="a solution file of the config's task")
    parser.add_argument("--config", type=Path, required=True, help="the task's config (a sweep's: its base config)")
    parser.add_argument("--tol", type=float, default=1e-10, help="IPOPT's tol and acceptable_tol")
    parser.add_argument("--max-iter", type=int, default=3000)
    parser.add_argument("--out", type=Path, help="write the re-solved solution here (only if it tracks)")
    args = parser.parse_args()
    data = json.loads(args.solution.read_text())
    cfg = load_config(args.config)
    problem = problem_from_config(structure_config(cfg, data["structure"]))
    transcription = Collocation()
    kept = read_solution_for(problem, transcription, args.solution)  # raises for a file of another problem
    guess = InitialGuess(q_d=kept.raw.q_d, Q=data["q"], V=data["v"])
    profile = SolverProfile(max_iter=args.max_iter).warmed().with_options(
        **{"ipopt.tol": args.tol, "ipopt.acceptable_tol": args.tol})
    sol = solve_guess(problem, transcription, profile, guess)
    before, after = data["metrics"]["design_cost"], sol.metrics.design_cost
    print(f"{args.solution.name}: file {before!r}; re-solved at tol {args.tol:g}: {after!r} ({after / before:.7f}x), "
          f"{sol.raw.status}, {sol.raw.iterations} iterations, tracks {sol.metrics.tracks}")
    if args.out and sol.metrics.tracks:
        write_solution(sol, args.out)
        print(f"written: {args.out}")


if __name__ == "__main__":
    main()
