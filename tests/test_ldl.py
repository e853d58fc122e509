"""The sparse LDLᵀ behind MA27's calls (`designopt.solve.backends.ldl`) against numpy's dense linear algebra: the
solution of KKT systems, the number of negative eigenvalues IPOPT's inertia correction reads, a singular matrix
reported as such; and IPOPT through it reaching a problem's known optimum."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import gantry_config, solve_from

from designopt.config import parse_config
from designopt.initial_guess import initial_guesses
from designopt.problem import problem_from_config
from designopt.solve.backends import ipopt as ipopt_backend
from designopt.solve.backends import ldl
from designopt.solve.backends.ldl.check import Ma27, dense, random_kkt
from designopt.solve.profile import SolverProfile


@pytest.mark.parametrize("seed", range(12))
def test_the_inertia_of_regularised_indefinite_kkt_systems_is_numpys(seed):
    """With an indefinite Hessian block and the constraint block regularised (delta_c = 1e-8, as IPOPT has it
    once it has seen a singular matrix) the negative eigenvalues reported are numpy's count: what IPOPT's inertia
    correction reads. (The solution is not asserted, and with delta_c = 0 neither is the inertia: without pivoting
    a small pivot can lose digits or flip a sign where MUMPS would pivot; `benchmarks/kkt_ldl.py check` counts
    how often, docs/decisions.md.)"""
    rng = np.random.default_rng(100 + seed)
    K, rows, cols = random_kkt(rng, n_x=30, n_c=12, delta_c=1e-8)
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
    K, rows, cols = random_kkt(rng, n_x=30, n_c=12, delta_c=1e-8, definite=True)
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


def test_a_kkt_system_near_convergence_keeps_its_digits():
    """A KKT matrix IPOPT factorised near the end of a 40-waypoint screen solve of the main job (mu = 1e-9; 1,720
    rows: 504 variables, 508 slacks, 708 multipliers; `tests/data/kkt_screen_late.npz`, written by a copy of the
    library that saved every matrix it was given). When each waypoint's tracking rows waited for any eliminated
    neighbour, four of five rows shared one joint, their pivots fell to -delta_c and the design joints' pivots
    lost their digits: 709 negative pivots reported and a relative residual of 0.13. Each row waiting for a
    neighbour of its own keeps them: numpy's inertia and solution."""
    data = np.load(Path(__file__).parent / "data" / "kkt_screen_late.npz")
    n, rows, cols, values = int(data["n"]), data["rows"].astype(int), data["cols"].astype(int), data["values"]
    K = dense(n, rows, cols, values)
    lib = Ma27(n, rows, cols)
    info = lib.factorise(values)
    assert info[0] == 0
    assert info[14] == np.sum(np.linalg.eigvalsh(K) < 0) == 708  # the multipliers' count: the inertia IPOPT wants
    b = np.random.default_rng(0).standard_normal(n)
    x = lib.solve(b)
    assert np.linalg.norm(K @ x - b) <= 1e-8 * np.linalg.norm(b)
    assert np.allclose(x, np.linalg.solve(K, b), rtol=0, atol=1e-8 * np.linalg.norm(x))


def test_duplicate_and_upper_triangle_triplets_are_summed_as_ma27_does():
    """Triplets given twice are summed, and an entry may come from either triangle."""
    rng = np.random.default_rng(11)
    K, rows, cols = random_kkt(rng, n_x=12, n_c=4, delta_c=1e-8, definite=True)
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


def test_a_new_analysis_builds_its_own_pattern_whatever_its_workspace_holds(tmp_path):
    """IPOPT allocates IW anew for each analysis and does not clear it, so a new analysis may be handed a block an
    earlier one filled (the allocator gives freed memory back), and a library loaded again counts from the start.
    Here the second analysis, in a second copy of the library, is handed the first one's workspace with everything
    after its two-int header zeroed: it must still factorise and solve its own matrix. Until 2026-11-27 the library
    trusted a header that matched and scattered the values through the stale map: a screen solve's segfault."""
    rng = np.random.default_rng(5)
    K, rows, cols = random_kkt(rng, n_x=30, n_c=12, delta_c=1e-8, definite=True)
    copies = [tmp_path / f"copy{i}.so" for i in range(2)]
    for copy in copies:
        shutil.copyfile(ldl.library(), copy)
    first = Ma27(K.shape[0], rows, cols, path=copies[0])
    assert first.factorise(K[rows, cols])[0] == 0
    second = Ma27(K.shape[0], rows, cols, path=copies[1])
    assert second.liw == first.liw
    second.iw = first.iw.copy()
    second.iw[2:] = 0
    assert second.factorise(K[rows, cols])[0] == 0
    b = rng.normal(size=K.shape[0])
    np.testing.assert_allclose(second.solve(b), np.linalg.solve(K, b), rtol=1e-8, atol=1e-10)


def _hessian_block_made_negative(K: np.ndarray, n_x: int) -> np.ndarray:
    """K with twice its largest Hessian diagonal entry taken off every Hessian diagonal entry: many more negative
    eigenvalues than constraints."""
    return K - np.diag(np.r_[np.full(n_x, 2.0 * np.abs(np.diag(K)[:n_x]).max()), np.zeros(K.shape[0] - n_x)])


@pytest.mark.parametrize("seed", range(6))
def test_a_factorisation_with_more_negative_pivots_than_ipopt_solved_with_stops_at_one_more(seed):
    """Once a factorisation has been solved with (IPOPT accepted its inertia: one negative pivot per constraint),
    a later one of the same analysis with more negative eigenvalues stops at one negative pivot more than that and
    reports it: the wrong inertia of the same kind (too many) that the full count, numpy's, would have reported.
    Solving with a stopped factorisation finishes it first: the same solution, to the bit, as a new analysis that
    factorised the matrix in full. A matrix with the accepted inertia is then factorised in full again."""
    rng = np.random.default_rng(200 + seed)
    K, rows, cols = random_kkt(rng, n_x=30, n_c=12, delta_c=1e-8, definite=True)
    solver = Ma27(K.shape[0], rows, cols)
    assert solver.factorise(K[rows, cols])[14] == 12
    b = rng.normal(size=K.shape[0])
    solver.solve(b)  # accepted: 12 negative pivots
    indefinite = _hessian_block_made_negative(K, 30)
    expected = int(np.sum(np.linalg.eigvalsh(indefinite) < 0))
    assert expected > 13
    info = solver.factorise(indefinite[rows, cols])
    assert info[0] == 0 and info[14] == 13
    full = Ma27(K.shape[0], rows, cols)
    full_info = full.factorise(indefinite[rows, cols])
    assert full_info[0] == 0 and full_info[14] == expected
    np.testing.assert_array_equal(solver.solve(b), full.solve(b))
    again = K + np.diag(np.r_[rng.uniform(0, 2, 30), np.zeros(12)])
    assert solver.factorise(again[rows, cols])[14] == 12
    x, expected_x = solver.solve(b), np.linalg.solve(again, b)
    assert np.linalg.norm(x - expected_x) <= 1e-8 * max(1.0, np.linalg.norm(expected_x))


def test_a_vanished_constraint_row_is_reported_singular_not_stopped():
    """A constraint row whose values are all zero has a zero pivot whatever the order: the factorisation must reach
    it and report the matrix singular (which IPOPT answers by regularising the constraint block), even when the
    matrix also has more negative pivots than the last one solved with (which IPOPT answers by perturbing the
    Hessian block)."""
    rng = np.random.default_rng(9)
    K, rows, cols = random_kkt(rng, n_x=30, n_c=12, delta_c=0.0, definite=True)
    K[-1, -1] = -1e-8
    solver = Ma27(K.shape[0], rows, cols)
    assert solver.factorise(K[rows, cols])[14] == 12
    solver.solve(rng.normal(size=K.shape[0]))
    vanished = _hessian_block_made_negative(K, 30)
    vanished[-1, :] = vanished[:, -1] = 0.0
    assert solver.factorise(vanished[rows, cols])[0] == -5


def test_a_singular_matrix_is_reported_singular():
    """A constraint row with no variable (a zero row and column): the zero pivot is reported as MA27's
    singular-matrix flag, which IPOPT answers by regularising the constraint block."""
    rng = np.random.default_rng(3)
    K, rows, cols = random_kkt(rng, n_x=10, n_c=3)
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


def test_a_long_programs_hessian_perturbation_is_bounded_under_mumps(monkeypatch):
    """From `BOUNDED_PERTURBATION_FROM` variables on, MUMPS's solves hold IPOPT's Hessian perturbation below 1e8 (a
    perturbation of 1e10 kept MUMPS in one factorisation past the start's time limit); smaller problems keep IPOPT's
    own limit, and a profile's options still win."""
    monkeypatch.delenv("DESIGNOPT_LINEAR_SOLVER", raising=False)
    big = ipopt_backend.BOUNDED_PERTURBATION_FROM
    assert ipopt_backend.options(SolverProfile(), big)["ipopt.max_hessian_perturbation"] == 1e8
    assert "ipopt.max_hessian_perturbation" not in ipopt_backend.options(SolverProfile(), big - 1)
    if ldl.library() is not None:  # the LDLᵀ's factors have a fixed pattern: nothing to bound
        assert "ipopt.max_hessian_perturbation" not in ipopt_backend.options(SolverProfile(linear_solver="ldl"), big)
    own = SolverProfile(options=(("ipopt.max_hessian_perturbation", 1e12),))
    assert ipopt_backend.options(own, big)["ipopt.max_hessian_perturbation"] == 1e12


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


def test_an_objective_scaled_while_ipopt_iterates_reaches_the_same_optimum_reported_unscaled(monkeypatch):
    """`SolverProfile.objective_scale`: IPOPT iterates on s x f (``obj_scaling_factor``, set only when s != 1), and
    the solution it returns is the NLP's own: the gantry's known design cost alpha^2 N / (N - 1) at s = 1 and at s =
    100 alike. A scale of 0 or below is refused."""
    monkeypatch.delenv("DESIGNOPT_LINEAR_SOLVER", raising=False)
    assert "ipopt.obj_scaling_factor" not in ipopt_backend.options(SolverProfile(), 100)
    assert ipopt_backend.options(SolverProfile().scaled(100), 100)["ipopt.obj_scaling_factor"] == 100.0
    with pytest.raises(ValueError, match="objective_scale"):
        SolverProfile(objective_scale=0.0)
    problem = problem_from_config(parse_config(gantry_config()))
    N = problem.toolpath.n
    objectives = []
    for scale in (1.0, 100.0):
        sol = solve_from(problem, initial_guesses(problem, 1, 0, 0.3, "constant")[0], max_iter=300,
                         objective_scale=scale)
        assert sol.raw.success and sol.metrics.tracks
        assert sol.metrics.design_cost == pytest.approx(4.0 * N / (N - 1), rel=1e-9)
        objectives.append(sol.raw.objective)
    assert objectives[1] == pytest.approx(objectives[0], rel=1e-6)  # reported as the NLP's, not 100x


def test_the_library_build_writes_its_temporary_files_in_its_own_directory(temp_keeping_compiler):
    """gcc's temporary files of the KKT solver's build go into the build's directory in the cache, which goes with
    it: none reach the process's own ``TMPDIR``, and the library lands."""
    cache, own_tmp = temp_keeping_compiler
    built = ldl.library.__wrapped__()
    assert built is not None and built.parent == cache and built.exists()
    assert not list(own_tmp.iterdir()) and not list(cache.rglob("cckept*")) and not list(cache.glob("build-*"))
