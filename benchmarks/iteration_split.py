"""Where one IPOPT iteration goes (issue 24's "measure first"): per config, over seeded starts solved one at a
time on one core, the median ms per iteration split into functions (objective, constraints, their derivatives,
the Hessian) and the rest (mostly the linear solves), the iterations, and the share of iterations whose KKT
matrix needed an inertia correction (IPOPT's lg(rg) column is not '-': at least one extra factorisation).

    .venv/bin/python benchmarks/iteration_split.py configs/milling.yaml --starts 8
    .venv/bin/python benchmarks/iteration_split.py configs/gcode_pocket.yaml --starts 4 --waypoints 0

Times are CPU seconds (the functions from CasADi's t_proc_* timers, the whole solve from the process's CPU
clock), so another job on the machine inflates them less than wall time; compare two versions as a ratio in the
same run.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import statistics
import tempfile
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from designopt.config import load_config  # noqa: E402
from designopt.experiments.adapters import search_from_config  # noqa: E402
from designopt.initial_guess import initial_guess  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solve import local  # noqa: E402
from designopt.solve.strategies.coarse_to_fine import coarse_problem  # noqa: E402
from designopt.transcriptions import Collocation  # noqa: E402

FUNCTIONS = ("nlp_f", "nlp_g", "nlp_grad_f", "nlp_jac_g", "nlp_hess_l")
ITERATION = re.compile(r"^\s*(\d+)r?\s+\S+\s+\S+\s+\S+\s+\S+\s+\S+\s+(\S+)\s+\S+\s+\S+")


def corrected_share(log: str) -> tuple[int, int]:
    """(iterations with an inertia correction, iterations) from an IPOPT log at print level 5."""
    rows = [m for line in log.splitlines() if (m := ITERATION.match(line))]
    return sum(1 for m in rows if m.group(2) != "-"), len(rows)


def logged_solve(problem, search, start: int, log: Path):
    """Solve seeded start ``start`` with IPOPT's log of this solve written to ``log``: (built NLP, prepared solver,
    outcome, CPU seconds of the solve, share of inertia-corrected iterations, seconds spent building and
    preparing). IPOPT logs every start of one label (``log``'s name without its start number) to one file beside
    ``log`` (it appends), so that the starts share one prepared solver as a run's do: a log file per start was a
    solver per start, and with it the observers built anew (the degenerate watch's tracking Jacobian: 0.1 ms per
    iteration of the exploration that no run pays)."""
    shared = log.parent / f"ipopt-shared-{log.stem.rstrip('0123456789')}.log"
    profile = replace(search.profile, options=(*search.profile.options, ("ipopt.output_file", str(shared)),
                                               ("ipopt.file_print_level", 5)))
    built, solver, build_s = local.prepared(problem, Collocation(), profile)
    guess = initial_guess(problem, start, search.seed, search.perturbation, search.init)
    before = shared.stat().st_size if shared.exists() else 0
    cpu = time.process_time()
    outcome = solver.solve(built.pack(guess))
    total = time.process_time() - cpu
    with open(shared, "rb") as fh:
        fh.seek(before)
        text = fh.read().decode(errors="replace")
    log.write_text(text)
    corrected, counted = corrected_share(text)
    return built, solver, outcome, total, corrected / max(counted, 1), build_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", type=Path)
    parser.add_argument("--starts", type=int, default=8)
    parser.add_argument("--waypoints", type=int, default=0,
                        help="N of the path's waypoints, as the search's coarse stages take them (0: all)")
    args = parser.parse_args()
    cfg = load_config(args.config)
    problem, search = problem_from_config(cfg), search_from_config(cfg)
    if args.waypoints:
        problem = coarse_problem(problem, args.waypoints)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for start in range(args.starts):
            _, solver, outcome, total, corrected, build_s = logged_solve(problem, search, start,
                                                                         Path(tmp) / f"ipopt{start}.log")
            stats = solver.solver.stats()
            functions = sum(stats.get(f"t_proc_{name}", 0.0) for name in FUNCTIONS)
            n = max(outcome.iterations, 1)
            rows.append((start, outcome.status, outcome.iterations, 1e3 * total / n, 1e3 * functions / n,
                         1e3 * stats.get("t_proc_nlp_hess_l", 0.0) / n, 1e3 * (total - functions) / n,
                         corrected, build_s))
    nlp = solver.nlp
    print(f"{args.config} ({problem.toolpath.n} waypoints, {nlp.n_variables} variables, {nlp.n_constraints} rows)")
    print("start | status | iterations | ms/iter | functions | of which Hessian | rest (linear solves, ...) | "
          "inertia-corrected | build [s]")
    for r in rows:
        print(f"{r[0]} | {r[1]} | {r[2]} | {r[3]:.2f} | {r[4]:.2f} | {r[5]:.2f} | {r[6]:.2f} | {r[7]:.0%} | "
              f"{r[8]:.2f}")
    med = [statistics.median(r[k] for r in rows) for k in range(2, 8)]
    print(f"median | | {med[0]:.0f} | {med[1]:.2f} | {med[2]:.2f} | {med[3]:.2f} | {med[4]:.2f} | {med[5]:.0%} |")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
