"""The KKT solver `DESIGNOPT_LINEAR_SOLVER=ldl` selects (`designopt.solve.backends.ldl`: an AMD-ordered sparse LDLᵀ
without pivoting, loaded by IPOPT as its ``ma27``), checked against numpy on random KKT matrices, and its library's
path for IPOPT options.

    .venv/bin/python benchmarks/kkt_ldl.py check            # how often it factorises, its inertia, its accuracy
    .venv/bin/python benchmarks/kkt_ldl.py build            # build it (gcc -O2, ~1.5 s), print its path
    DESIGNOPT_LINEAR_SOLVER=ldl .venv/bin/python benchmarks/speed_table.py --starts 8 --json ldl.json
    DESIGNOPT_LINEAR_SOLVER=ldl .venv/bin/python benchmarks/search_seeds.py --first-seed 1181 --seeds 20

What it showed (docs/decisions.md, 2026-11-26): 0.45-0.71x the CPU per iteration, and without pivoting, with the
constraint block unregularised (IPOPT's first trial), a pivot can be exactly zero (reported as singular), small
(digits lost) or of the wrong sign (a wrong inertia).
"""

from __future__ import annotations

import argparse

import numpy as np

from designopt.solve.backends import ldl
from designopt.solve.backends.ldl.check import Ma27, random_kkt


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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=("build", "check"))
    args = parser.parse_args()
    if args.what == "build":
        print(ldl.library())
    else:
        check()


if __name__ == "__main__":
    main()
