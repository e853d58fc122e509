"""The sparse LDLᵀ behind MA27's calls (`designopt.solve.backends.ldl`) against numpy's dense linear algebra: the
solution of KKT systems, the number of negative eigenvalues IPOPT's inertia correction reads, a singular matrix
reported as such; and IPOPT through it reaching a problem's known optimum."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest
from conftest import gantry_config, solve_from

from designopt.config import parse_config
from designopt.initial_guess import initial_guesses
from designopt.problem import problem_from_config
from designopt.solve.backends import ipopt as ipopt_backend
from designopt.solve.backends import ldl
from designopt.solve.profile import SolverProfile

INT = ctypes.POINTER(ctypes.c_int)
DOUBLE = ctypes.POINTER(ctypes.c_double)


def _ints(values):
    return np.ascontiguousarray(values, dtype=np.int32)


def _p(array, kind):
    return array.ctypes.data_as(kind)


class Ma27:
    """The four calls as IPOPT makes them (Ma27TSolverInterface): analyse once, then factorise and solve."""

    def __init__(self, n: int, rows, cols):
        self.lib = ctypes.CDLL(str(ldl.library()))
        self.n, self.nz = n, len(rows)
        self.irn, self.icn = _ints(np.asarray(rows) + 1), _ints(np.asarray(cols) + 1)
        self.icntl, self.cntl = np.zeros(30, np.int32), np.zeros(5)
        self.lib.ma27id_(_p(self.icntl, INT), _p(self.cntl, DOUBLE))
        self.ikeep, info = np.zeros(3 * n, np.int32), np.zeros(20, np.int32)
        liw = 2 * (2 * self.nz + 3 * n + 1)
        iw, iw1 = np.zeros(liw, np.int32), np.zeros(2 * n, np.int32)
        nsteps, iflag, ops = ctypes.c_int(0), ctypes.c_int(0), ctypes.c_double(0)
        self.lib.ma27ad_(ctypes.byref(ctypes.c_int(n)), ctypes.byref(ctypes.c_int(self.nz)), _p(self.irn, INT),
                         _p(self.icn, INT), _p(iw, INT), ctypes.byref(ctypes.c_int(liw)), _p(self.ikeep, INT),
                         _p(iw1, INT), ctypes.byref(nsteps), ctypes.byref(iflag), _p(self.icntl, INT),
                         _p(self.cntl, DOUBLE), _p(info, INT), ctypes.byref(ops))
        assert info[0] == 0
        self.la, self.liw = 5 * int(info[4]), 5 * int(info[5])  # IPOPT's default init factors
        self.a, self.iw = np.zeros(self.la), np.zeros(self.liw, np.int32)

    def factorise(self, values) -> np.ndarray:
        """INFO after factorising the matrix with these triplet values."""
        self.a[: self.nz] = values
        info, iw1 = np.zeros(20, np.int32), np.zeros(2 * self.n, np.int32)
        maxfrt = ctypes.c_int(0)
        self.lib.ma27bd_(ctypes.byref(ctypes.c_int(self.n)), ctypes.byref(ctypes.c_int(self.nz)), _p(self.irn, INT),
                         _p(self.icn, INT), _p(self.a, DOUBLE), ctypes.byref(ctypes.c_int(self.la)), _p(self.iw, INT),
                         ctypes.byref(ctypes.c_int(self.liw)), _p(self.ikeep, INT), ctypes.byref(ctypes.c_int(1)),
                         ctypes.byref(maxfrt), _p(iw1, INT), _p(self.icntl, INT), _p(self.cntl, DOUBLE), _p(info, INT))
        return info

    def solve(self, rhs) -> np.ndarray:
        x = np.array(rhs, dtype=float)
        w, iw1, info = np.zeros(1), np.zeros(1, np.int32), np.zeros(20, np.int32)
        self.lib.ma27cd_(ctypes.byref(ctypes.c_int(self.n)), _p(self.a, DOUBLE), ctypes.byref(ctypes.c_int(self.la)),
                         _p(self.iw, INT), ctypes.byref(ctypes.c_int(self.liw)), _p(w, DOUBLE),
                         ctypes.byref(ctypes.c_int(1)), _p(x, DOUBLE), _p(iw1, INT), ctypes.byref(ctypes.c_int(1)),
                         _p(self.icntl, INT), _p(info, INT))
        return x


def _kkt(rng, n_x: int, n_c: int, band: int = 3, border: int = 2, delta_c: float = 0.0, definite: bool = False):
    """A KKT matrix shaped like the transcription's: a banded Hessian block (indefinite) with ``border`` dense
    design columns, a sparse constraint Jacobian whose every row has a variable no other row has, and -delta_c on
    the constraint block's diagonal (structurally present, as IPOPT passes it). Returns the dense matrix and its
    lower-triangle triplets (rows >= cols)."""
    n = n_x + n_c
    K = np.zeros((n, n))
    for i in range(n_x):
        for j in range(max(0, i - band), i + 1):
            K[i, j] = K[j, i] = rng.normal()
        K[i, i] += rng.choice([-1.0, 3.0])
    for d in range(border):
        K[n_x - 1 - d, :n_x] = K[:n_x, n_x - 1 - d] = rng.normal(size=n_x)
    if definite:  # the Hessian block made positive definite (what IPOPT's inertia correction ends at)
        H = K[:n_x, :n_x]
        K[:n_x, :n_x] = H + np.eye(n_x) * (1.0 - np.linalg.eigvalsh(H).min())
    for c in range(n_c):  # a variable of its own (as a waypoint's tracking rows have its joints), two shared
        cols = np.r_[c, n_c + rng.choice(n_x - n_c, size=2, replace=False)]
        K[n_x + c, cols] = K[cols, n_x + c] = rng.normal(size=3)
        K[n_x + c, n_x + c] = -delta_c
    rows, cols = np.nonzero(np.tril(K) + np.tril(np.eye(n)))  # every diagonal entry present, zero or not
    return K, rows, cols


@pytest.mark.parametrize("seed", range(12))
def test_the_inertia_of_regularised_indefinite_kkt_systems_is_numpys(seed):
    """With an indefinite Hessian block and the constraint block regularised (delta_c = 1e-8, as IPOPT has it
    once it has seen a singular matrix) the negative eigenvalues reported are numpy's count: what IPOPT's inertia
    correction reads. (The solution is not asserted, and with delta_c = 0 neither is the inertia: without pivoting
    a small pivot can lose digits or flip a sign where MUMPS would pivot; `benchmarks/kkt_ldl.py check` counts
    how often, docs/decisions.md.)"""
    rng = np.random.default_rng(100 + seed)
    K, rows, cols = _kkt(rng, n_x=30, n_c=12, delta_c=1e-8)
    info = Ma27(K.shape[0], rows, cols).factorise(K[rows, cols])
    assert info[0] == 0
    assert info[14] == int(np.sum(np.linalg.eigvalsh(K) < 0))


@pytest.mark.parametrize("seed", range(12))
def test_kkt_solves_and_inertia_match_dense_linear_algebra(seed):
    """Random quasi-definite KKT systems (a positive definite Hessian block, the constraint block regularised by
    delta_c = 1e-8): the solution agrees with numpy's to 1e-8 relative to its size, and the negative eigenvalues
    reported are numpy's count (one per constraint). The same analysis serves a second matrix of the same pattern
    (its cached pattern reused). With delta_c = 0 this holds only when every constraint row follows an eliminated
    variable of its own: rows that share their only eliminated variable leave a pivot of exactly zero (reported as
    singular, next test) or a tiny one."""
    rng = np.random.default_rng(seed)
    K, rows, cols = _kkt(rng, n_x=30, n_c=12, delta_c=1e-8, definite=True)
    solver = Ma27(K.shape[0], rows, cols)
    for again in range(2):
        if again:
            K = K + np.diag(np.r_[rng.uniform(0, 2, 30), np.zeros(12)])  # another iteration's Hessian
        info = solver.factorise(K[rows, cols])
        assert info[0] == 0
        assert info[14] == int(np.sum(np.linalg.eigvalsh(K) < 0))
        b = rng.normal(size=K.shape[0])
        x = solver.solve(b)
        expected = np.linalg.solve(K, b)
        assert np.linalg.norm(x - expected) <= 1e-8 * max(1.0, np.linalg.norm(expected))


def test_duplicate_and_upper_triangle_triplets_are_summed_as_ma27_does():
    """Triplets given twice are summed, and an entry may come from either triangle."""
    rng = np.random.default_rng(11)
    K, rows, cols = _kkt(rng, n_x=12, n_c=4, delta_c=1e-8, definite=True)
    split = np.r_[rows, rows[:5]], np.r_[cols, cols[:5]]
    values = np.r_[K[rows, cols], np.zeros(5)]
    values[:5] *= 0.25
    values[-5:] = 0.75 * K[rows[:5], cols[:5]]
    flipped = (split[1], split[0])  # the same entries, given as (col, row)
    for r, c in (split, flipped):
        solver = Ma27(K.shape[0], r, c)
        assert solver.factorise(values)[0] == 0
        b = rng.normal(size=K.shape[0])
        np.testing.assert_allclose(solver.solve(b), np.linalg.solve(K, b), rtol=1e-8, atol=1e-10)


def test_a_singular_matrix_is_reported_singular():
    """A constraint row with no variable (a zero row and column): the zero pivot is reported as MA27's
    singular-matrix flag, which IPOPT answers by regularising the constraint block."""
    rng = np.random.default_rng(3)
    K, rows, cols = _kkt(rng, n_x=10, n_c=3)
    K[-1, :] = K[:, -1] = 0.0
    solver = Ma27(K.shape[0], rows, cols)
    assert solver.factorise(K[rows, cols])[0] == -5


def test_ipopt_through_the_ldl_reaches_the_known_optimum(monkeypatch):
    """The gantry's design cost alpha^2 N / (N - 1) (tests/test_transcriptions.py), with IPOPT factorising its
    KKT systems here instead of MUMPS."""
    monkeypatch.setenv("DESIGNOPT_LINEAR_SOLVER", "ldl")
    assert ipopt_backend.linear_solver(SolverProfile()) == "ldl"
    problem = problem_from_config(parse_config(gantry_config()))
    sol = solve_from(problem, initial_guesses(problem, 1, 0, 0.3, "constant")[0], max_iter=300)
    N = problem.toolpath.n
    assert sol.raw.success and sol.metrics.tracks
    assert sol.metrics.design_cost == pytest.approx(4.0 * N / (N - 1), rel=1e-9)


def test_the_linear_solver_is_chosen_by_name(monkeypatch):
    """A profile names it, ``DESIGNOPT_LINEAR_SOLVER`` overrides every profile; an unknown name is refused; ldl
    falls back to MUMPS without a compiler."""
    monkeypatch.delenv("DESIGNOPT_LINEAR_SOLVER", raising=False)
    assert "ipopt.linear_solver" not in ipopt_backend.options(SolverProfile(), 100)
    opts = ipopt_backend.options(SolverProfile(linear_solver="ldl"), 1000)
    assert opts["ipopt.linear_solver"] == "ma27" and opts["ipopt.hsllib"] == str(ldl.library())
    assert "ipopt.mumps_pivot_order" not in opts
    with pytest.raises(ValueError, match="linear_solver"):
        SolverProfile(linear_solver="pardiso")
    monkeypatch.setenv("DESIGNOPT_LINEAR_SOLVER", "mumps")
    assert "ipopt.linear_solver" not in ipopt_backend.options(SolverProfile(linear_solver="ldl"), 100)
    monkeypatch.setenv("DESIGNOPT_LINEAR_SOLVER", "ldl")
    assert ipopt_backend.options(SolverProfile(), 1000)["ipopt.linear_solver"] == "ma27"
    monkeypatch.setenv("DESIGNOPT_LINEAR_SOLVER", "pardiso")
    with pytest.raises(ValueError, match="DESIGNOPT_LINEAR_SOLVER"):
        ipopt_backend.linear_solver(SolverProfile())
    monkeypatch.setenv("DESIGNOPT_LINEAR_SOLVER", "ldl")
    monkeypatch.setattr(ldl, "library", lambda: None)
    assert ipopt_backend.linear_solver(SolverProfile()) == "mumps"
