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
import ctypes

import numpy as np

from designopt.solve.backends import ldl

INT, DOUBLE = ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_double)


def _p(array, kind):
    return array.ctypes.data_as(kind)


def _int(value: int):
    return ctypes.byref(ctypes.c_int(value))


class Ma27:
    """The four calls as IPOPT makes them (its Ma27TSolverInterface): analyse once, then factorise and solve."""

    def __init__(self, lib, n: int, rows, cols):
        self.lib, self.n, self.nz = lib, n, len(rows)
        self.irn = np.ascontiguousarray(np.asarray(rows) + 1, dtype=np.int32)
        self.icn = np.ascontiguousarray(np.asarray(cols) + 1, dtype=np.int32)
        self.icntl, self.cntl = np.zeros(30, np.int32), np.zeros(5)
        lib.ma27id_(_p(self.icntl, INT), _p(self.cntl, DOUBLE))
        self.ikeep, info = np.zeros(3 * n, np.int32), np.zeros(20, np.int32)
        liw = 2 * (2 * self.nz + 3 * n + 1)
        iw, iw1 = np.zeros(liw, np.int32), np.zeros(2 * n, np.int32)
        nsteps, iflag, ops = ctypes.c_int(0), ctypes.c_int(0), ctypes.c_double(0)
        lib.ma27ad_(_int(n), _int(self.nz), _p(self.irn, INT), _p(self.icn, INT), _p(iw, INT), _int(liw),
                    _p(self.ikeep, INT), _p(iw1, INT), ctypes.byref(nsteps), ctypes.byref(iflag), _p(self.icntl, INT),
                    _p(self.cntl, DOUBLE), _p(info, INT), ctypes.byref(ops))
        assert info[0] == 0, info[0]
        self.la, self.liw = 5 * int(info[4]), 5 * int(info[5])  # IPOPT's default init factors
        self.a, self.iw = np.zeros(self.la), np.zeros(self.liw, np.int32)

    def factorise(self, values) -> np.ndarray:
        self.a[: self.nz] = values
        info, iw1, maxfrt = np.zeros(20, np.int32), np.zeros(2 * self.n, np.int32), ctypes.c_int(0)
        self.lib.ma27bd_(_int(self.n), _int(self.nz), _p(self.irn, INT), _p(self.icn, INT), _p(self.a, DOUBLE),
                         _int(self.la), _p(self.iw, INT), _int(self.liw), _p(self.ikeep, INT), _int(1),
                         ctypes.byref(maxfrt), _p(iw1, INT), _p(self.icntl, INT), _p(self.cntl, DOUBLE), _p(info, INT))
        return info

    def solve(self, rhs) -> np.ndarray:
        x, w, iw1, info = np.array(rhs, dtype=float), np.zeros(1), np.zeros(1, np.int32), np.zeros(20, np.int32)
        self.lib.ma27cd_(_int(self.n), _p(self.a, DOUBLE), _int(self.la), _p(self.iw, INT), _int(self.liw),
                         _p(w, DOUBLE), _int(1), _p(x, DOUBLE), _p(iw1, INT), _int(1), _p(self.icntl, INT),
                         _p(info, INT))
        return x


def kkt(rng, n_x: int = 30, n_c: int = 12, delta_c: float = 0.0, definite: bool = False):
    """A KKT matrix shaped like the transcription's: a banded Hessian block with two dense design columns
    (positive definite if ``definite``), a constraint Jacobian whose every row has a variable of its own and two
    shared ones, -delta_c on the constraint block's diagonal (present, as IPOPT passes it). Returns the matrix and
    its lower-triangle triplets."""
    n = n_x + n_c
    K = np.zeros((n, n))
    for i in range(n_x):
        for j in range(max(0, i - 3), i + 1):
            K[i, j] = K[j, i] = rng.normal()
        K[i, i] += rng.choice([-1.0, 3.0])
    for d in range(2):
        K[n_x - 1 - d, :n_x] = K[:n_x, n_x - 1 - d] = rng.normal(size=n_x)
    if definite:
        K[:n_x, :n_x] += np.eye(n_x) * (1.0 - np.linalg.eigvalsh(K[:n_x, :n_x]).min())
    for c in range(n_c):
        cols = np.r_[c, n_c + rng.choice(n_x - n_c, size=2, replace=False)]
        K[n_x + c, cols] = K[cols, n_x + c] = rng.normal(size=3)
        K[n_x + c, n_x + c] = -delta_c
    rows, cols = np.nonzero(np.tril(K) + np.tril(np.eye(n)))
    return K, rows, cols


def check(seeds: int = 50) -> None:
    """Over random KKT matrices (indefinite and positive definite Hessian blocks, delta_c 0 and 1e-8): how often
    the factorisation succeeds, reports numpy's inertia, and solves to 1e-8 (relative)."""
    lib = ctypes.CDLL(str(ldl.library()))
    for definite in (False, True):
        for delta_c in (0.0, 1e-8):
            ok = inertia = accurate = 0
            for seed in range(seeds):
                rng = np.random.default_rng(seed)
                K, rows, cols = kkt(rng, delta_c=delta_c, definite=definite)
                solver = Ma27(lib, K.shape[0], rows, cols)
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
