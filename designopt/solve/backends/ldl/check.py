"""The library checked from Python: MA27's four calls as IPOPT makes them, and random KKT matrices shaped like the
transcription's, for comparing its factorisation with numpy's dense linear algebra (`tests/test_ldl.py`,
`benchmarks/kkt_ldl.py`).
"""

from __future__ import annotations

import ctypes

import numpy as np

from designopt.solve.backends.ldl import library

INT, DOUBLE = ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_double)


def _p(array, kind):
    return array.ctypes.data_as(kind)


def _int(value: int):
    return ctypes.byref(ctypes.c_int(value))


class Ma27:
    """The four calls as IPOPT makes them (its Ma27TSolverInterface): analyse once (here, for the lower-triangle
    triplets ``rows``, ``cols``, 0-based), then factorise and solve as often as wanted. INFO is MA27's: INFO(1)
    (``info[0]``) 0 on success, -5 for a singular matrix; INFO(15) (``info[14]``) the negative eigenvalues."""

    def __init__(self, n: int, rows, cols, path=None):
        self.lib = ctypes.CDLL(str(path or library()))  # ``path``: another copy of the library, loaded apart
        self.n, self.nz = n, len(rows)
        self.irn = np.ascontiguousarray(np.asarray(rows) + 1, dtype=np.int32)
        self.icn = np.ascontiguousarray(np.asarray(cols) + 1, dtype=np.int32)
        self.icntl, self.cntl = np.zeros(30, np.int32), np.zeros(5)
        self.lib.ma27id_(_p(self.icntl, INT), _p(self.cntl, DOUBLE))
        self.ikeep, info = np.zeros(3 * n, np.int32), np.zeros(20, np.int32)
        liw = 2 * (2 * self.nz + 3 * n + 1)
        iw, iw1 = np.zeros(liw, np.int32), np.zeros(2 * n, np.int32)
        nsteps, iflag, ops = ctypes.c_int(0), ctypes.c_int(0), ctypes.c_double(0)
        self.lib.ma27ad_(_int(n), _int(self.nz), _p(self.irn, INT), _p(self.icn, INT), _p(iw, INT), _int(liw),
                         _p(self.ikeep, INT), _p(iw1, INT), ctypes.byref(nsteps), ctypes.byref(iflag),
                         _p(self.icntl, INT), _p(self.cntl, DOUBLE), _p(info, INT), ctypes.byref(ops))
        if info[0] != 0:
            raise RuntimeError(f"ma27ad_ returned INFO(1) = {info[0]}")
        self.la, self.liw = 5 * int(info[4]), 5 * int(info[5])  # IPOPT's default init factors
        self.a, self.iw = np.zeros(self.la), np.zeros(self.liw, np.int32)

    def factorise(self, values) -> np.ndarray:
        """MA27's INFO after factorising the matrix with these triplet values."""
        self.a[: self.nz] = values
        info, iw1, maxfrt = np.zeros(20, np.int32), np.zeros(2 * self.n, np.int32), ctypes.c_int(0)
        self.lib.ma27bd_(_int(self.n), _int(self.nz), _p(self.irn, INT), _p(self.icn, INT), _p(self.a, DOUBLE),
                         _int(self.la), _p(self.iw, INT), _int(self.liw), _p(self.ikeep, INT), _int(1),
                         ctypes.byref(maxfrt), _p(iw1, INT), _p(self.icntl, INT), _p(self.cntl, DOUBLE), _p(info, INT))
        return info

    def solve(self, rhs) -> np.ndarray:
        """The solution of the last factorised matrix for ``rhs``."""
        x, w, iw1, info = np.array(rhs, dtype=float), np.zeros(1), np.zeros(1, np.int32), np.zeros(20, np.int32)
        self.lib.ma27cd_(_int(self.n), _p(self.a, DOUBLE), _int(self.la), _p(self.iw, INT), _int(self.liw),
                         _p(w, DOUBLE), _int(1), _p(x, DOUBLE), _p(iw1, INT), _int(1), _p(self.icntl, INT),
                         _p(info, INT))
        return x


def dense(n: int, rows, cols, values) -> np.ndarray:
    """The symmetric n x n matrix of (0-based) triplets from either triangle, duplicates summed, as MA27 reads them."""
    K = np.zeros((n, n))
    np.add.at(K, (np.asarray(rows), np.asarray(cols)), values)
    return K + K.T - np.diag(np.diag(K))


def random_kkt(rng, n_x: int = 30, n_c: int = 12, band: int = 3, border: int = 2, delta_c: float = 0.0,
               definite: bool = False):
    """A KKT matrix shaped like the transcription's: a banded Hessian block (indefinite) with ``border`` dense
    design columns, positive definite if ``definite`` (what IPOPT's inertia correction ends at); a sparse
    constraint Jacobian whose every row has a variable no other row has (as a waypoint's tracking rows have its
    joints) and two shared ones; -delta_c on the constraint block's diagonal (structurally present, as IPOPT passes
    it). Returns the dense matrix and its lower-triangle triplets (rows >= cols; every diagonal entry present)."""
    n = n_x + n_c
    K = np.zeros((n, n))
    for i in range(n_x):
        for j in range(max(0, i - band), i + 1):
            K[i, j] = K[j, i] = rng.normal()
        K[i, i] += rng.choice([-1.0, 3.0])
    for d in range(border):
        K[n_x - 1 - d, :n_x] = K[:n_x, n_x - 1 - d] = rng.normal(size=n_x)
    if definite:
        H = K[:n_x, :n_x]
        K[:n_x, :n_x] = H + np.eye(n_x) * (1.0 - np.linalg.eigvalsh(H).min())
    for c in range(n_c):
        cols = np.r_[c, n_c + rng.choice(n_x - n_c, size=2, replace=False)]
        K[n_x + c, cols] = K[cols, n_x + c] = rng.normal(size=3)
        K[n_x + c, n_x + c] = -delta_c
    rows, cols = np.nonzero(np.tril(K) + np.tril(np.eye(n)))
    return K, rows, cols
