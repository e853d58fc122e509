"""The KKT solver `DESIGNOPT_LINEAR_SOLVER=ldl` selects (`designopt.solve.backends.ldl`: an AMD-ordered sparse LDLᵀ
without pivoting, loaded by IPOPT as its ``ma27``), checked against numpy on random KKT matrices, and its library's
path for IPOPT options.

    .venv/bin/python benchmarks/kkt_ldl.py check            # how often it factorises, its inertia, its accuracy
    .venv/bin/python benchmarks/kkt_ldl.py build            # build it (gcc -O2, ~1.5 s), print its path
    DESIGNOPT_LINEAR_SOLVER=ldl .venv/bin/python benchmarks/speed_table.py --starts 8 --json ldl.json
    DESIGNOPT_LINEAR_SOLVER=ldl .venv/bin/python benchmarks/search_seeds.py --first-seed 1181 --seeds 20

On the matrices IPOPT really factorises: ``record`` solves one task of a finished run's stage (`search_seeds.py --out
DIR` keeps runs as DIR/<name>/s<seed>; the task as `stage_solvers.py` builds it) by the LDLᵀ, through a shim that
writes every matrix to ``--out`` first (`benchmarks/kkt_record.c`); ``replay`` factorises them again, one analysis as
IPOPT makes it (the first matrix orders it), with this library or another build (``--library``), and counts the
factorisations whose inertia or solution is not numpy's:

    .venv/bin/python benchmarks/kkt_ldl.py record DIR/milling/s1482 --task 30 --out kkt/   # a screen solve
    .venv/bin/python benchmarks/kkt_ldl.py replay kkt/ --every 5

What it showed (docs/decisions.md, 2026-11-26): 0.45-0.71x the CPU per iteration, and without pivoting, with the
constraint block unregularised (IPOPT's first trial), a pivot can be exactly zero (reported as singular), small
(digits lost) or of the wrong sign (a wrong inertia).
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np

from designopt.solve.backends import ldl
from designopt.solve.backends.ldl.check import Ma27, dense, random_kkt


def check(seeds: int = 50) -> None:
    """Over random KKT matrices (indefinite and positive definite Hessian blocks, delta_c 0 and 1e-8): how often
    the factorisation succeeds, reports numpy's inertia, and solves to 1e-8 (relative)."""
    for definite in (False, True):
        for delta_c in (0.0, 1e-8):
            ok = inertia = accurate = 0
            for seed in range(seeds):
                rng = np.random.default_rng(seed)
                K, rows, cols = random_kkt(rng, delta_c=delta_c, definite=definite)
                solver = Ma27(K.shape[0], rows, cols)
                info = solver.factorise(K[rows, cols])
                if info[0] != 0:
                    continue
                ok += 1
                inertia += int(info[14] == np.sum(np.linalg.eigvalsh(K) < 0))
                b = rng.normal(size=K.shape[0])
                expected = np.linalg.solve(K, b)
                accurate += int(np.linalg.norm(solver.solve(b) - expected) <= 1e-8 * max(1, np.linalg.norm(expected)))
            print(f"Hessian block {'positive definite' if definite else 'indefinite'}, delta_c {delta_c:g}: "
                  f"{ok} of {seeds} factorised, {inertia} with numpy's inertia, {accurate} solved to 1e-8")


def record(run: Path, stage: str, task: int, out: Path) -> None:
    """Solve task ``task`` of ``stage`` of ``run`` by the LDLᵀ, every matrix IPOPT factorises written to ``out``."""
    sys.path.insert(0, str(Path(__file__).parent))
    from stage_solvers import stage_tasks, variant

    from designopt.solve.tasks import run_task

    out.mkdir(parents=True, exist_ok=True)
    shim = out / "kkt_record.so"
    source = Path(__file__).with_name("kkt_record.c")
    subprocess.run([os.environ.get("CC", "gcc"), "-O2", "-fPIC", "-shared", str(source), "-o", str(shim), "-ldl"],
                   check=True)
    os.environ["KKT_RECORD_LIB"], os.environ["KKT_RECORD_DIR"] = str(ldl.library()), str(out)
    tasks, _ = stage_tasks(run, stage)
    sol = run_task(variant(tasks[task], f"ldl:ipopt.hsllib={shim}"))
    print(f"{stage} task {task}: {sol.raw.status}, {sol.raw.iterations} iterations, design cost "
          f"{sol.metrics.design_cost:.6g}; {len(list(out.glob('k*.bin')))} matrices in {out}")


def _matrix(path: Path):
    data = path.read_bytes()
    n, nz = (int(v) for v in np.frombuffer(data[:8], np.int32))
    rows = np.frombuffer(data[8 : 8 + 4 * nz], np.int32) - 1
    cols = np.frombuffer(data[8 + 4 * nz : 8 + 8 * nz], np.int32) - 1
    return n, rows, cols, np.frombuffer(data[8 + 8 * nz : 8 + 16 * nz], np.float64)


def replay(folder: Path, every: int, library: Path | None) -> None:
    """Factorise the recorded matrices again in one analysis (the first one orders it), every ``every``-th checked
    against numpy: its negative eigenvalues and the solution of a random right-hand side."""
    files = sorted(folder.glob("k*.bin"))
    n, rows, cols, values = _matrix(files[0])
    solver = Ma27(n, rows, cols, path=library)
    solver.la, solver.liw = 3 * solver.la, 3 * solver.liw  # room for the order the first matrix sets
    solver.a, solver.iw = np.zeros(solver.la), np.zeros(solver.liw, np.int32)
    rng, checked, wrong, worst = np.random.default_rng(0), 0, 0, 0.0
    for k, path in enumerate(files):
        n_k, rows_k, cols_k, values = _matrix(path)
        if (n_k, len(rows_k)) != (n, len(rows)) or not (np.array_equal(rows_k, rows) and np.array_equal(cols_k, cols)):
            raise SystemExit(f"{path}: another pattern than {files[0]}'s")
        info = solver.factorise(values)
        if k % every:
            continue
        K = dense(n, rows, cols, values)
        negative, b = int(np.sum(np.linalg.eigvalsh(K) < 0)), rng.normal(size=n)
        residual = np.linalg.norm(K @ solver.solve(b) - b) / np.linalg.norm(b) if info[0] == 0 else np.inf
        checked, worst = checked + 1, max(worst, residual)
        if info[0] != 0 or info[14] != negative:
            wrong += 1
            print(f"{path.name}: INFO(1) {info[0]}, {info[14]} negative pivots, numpy {negative}; "
                  f"residual {residual:.1e}")
    print(f"{checked} of {len(files)} matrices checked ({n} rows): {wrong} with another inertia than numpy's or not "
          f"factorised; largest relative residual {worst:.1e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=("build", "check", "record", "replay"))
    parser.add_argument("path", nargs="?", type=Path, help="record: a run directory; replay: the matrices' folder")
    parser.add_argument("--stage", choices=("screen", "refine"), default="screen")
    parser.add_argument("--task", type=int, default=0, help="record: the stage's task (start order)")
    parser.add_argument("--out", type=Path, help="record: where the matrices go")
    parser.add_argument("--every", type=int, default=1, help="replay: check every n-th matrix against numpy")
    parser.add_argument("--library", type=Path, help="replay: another build of the library")
    args = parser.parse_args()
    if args.what == "build":
        print(ldl.library())
    elif args.what == "check":
        check()
    elif args.path is None or (args.what == "record" and args.out is None):
        parser.error(f"{args.what} needs a path{' and --out' if args.what == 'record' else ''}")
    elif args.what == "record":
        record(args.path, args.stage, args.task, args.out)
    else:
        replay(args.path, args.every, args.library)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
