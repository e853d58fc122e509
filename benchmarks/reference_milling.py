"""Write the best design known for the default job (configs/milling.yaml) to benchmarks/reference/.

Issue 11 measures a search against "the best design you know for that problem". This reproduces it: start 4
of seed 0, solved with CasADi's own Hessian (`hessian: auto`), which reaches 3.795e-4 where the structured
Hessian takes the same start to 4.68e-4 (docs/benchmarks.md, "Search groundwork"); then a warm re-solve with
the default (structured) transcription and a warm barrier confirms it is a local minimum of the default NLP.

    .venv/bin/python benchmarks/reference_milling.py
"""

from __future__ import annotations

from pathlib import Path

from designopt.config import load_config
from designopt.experiments.adapters import transcription_for
from designopt.initial_guess import initial_guess
from designopt.problem import problem_from_config
from designopt.solution import solve_and_evaluate, write_solution
from designopt.transcriptions import Collocation, InitialGuess
from designopt.verify import verify_file

ROOT = Path(__file__).resolve().parent.parent
WARM = {"ipopt.mu_init": 1e-6, "ipopt.bound_push": 1e-8, "ipopt.bound_frac": 1e-8}


def main() -> None:
    cfg = load_config(ROOT / "configs" / "milling.yaml")
    problem = problem_from_config(cfg, ROOT / "configs")
    found = Collocation(max_iter=1000, hessian="auto").build(problem).solve(initial_guess(problem, 4, 0, 0.3))
    default = transcription_for(cfg)
    warm = Collocation(max_iter=1000, compile=default.compile, ipopt={**default.ipopt, **WARM})
    raw = warm.build(problem).solve(InitialGuess(found.q_d, found.Q, found.V, found.seed))
    sol = solve_and_evaluate(problem, "to", raw)
    path = ROOT / "benchmarks" / "reference" / "milling_best_known.json"
    write_solution(sol, path)
    print(f"{path}: design cost {sol.metrics.design_cost:.6g}, tracks {sol.metrics.tracks}, "
          f"{raw.status} after {raw.iterations} warm iterations; verify: {verify_file(path) or 'ok'}")


if __name__ == "__main__":
    main()
