"""Named cost terms: a per-waypoint term defined here, outside the library, is one function and one
registration line -- and the optimizer, the exact structured Hessian, the metrics, summary.csv and the solution
file all carry it."""

from __future__ import annotations

import json

import casadi as ca
import numpy as np
import pandas as pd
import pytest
from test_objective_truth import SCARA_LAMBDA, scara_problem

from designopt.costs import WaypointCost, sumsqr
from designopt.experiments.runs import Executor
from designopt.initial_guess import initial_guess
from designopt.results_io import RunDirectory
from designopt.solve import Job, SolverProfile, preset, run_search, solve_guess
from designopt.solve.local import prepared
from designopt.transcriptions import Collocation
from designopt.verify import verify_file


def joint_centring(w):
    """Keep the joints near zero: |q|^2 at the waypoint (rad^2 and m^2)."""
    return sumsqr(w.q)


WEIGHT = 0.05


@pytest.fixture
def problems(tmp_path):
    base = scara_problem(tmp_path, smoothness=0.0, joint_regularization=0.0)
    return base, base.with_cost(WaypointCost("joint_centring", WEIGHT, joint_centring))  # the registration line


def solve(problem):
    return solve_guess(problem, Collocation(), SolverProfile(max_iter=500, compile="none"),
                       initial_guess(problem, 1, 0, 0.3))


def test_the_term_enters_the_objective_and_the_metrics(problems):
    base, extended = problems
    plain, sol = solve(base), solve(extended)
    assert sol.raw.success and sol.metrics.tracks
    costs = dict(sol.metrics.costs)
    h, Q = extended.toolpath.dt, sol.raw.Q
    assert costs["joint_centring"] == pytest.approx(h * float(np.sum(Q**2)), rel=1e-12)
    assert costs["deformation"] == pytest.approx(sol.metrics.design_cost, rel=1e-12)
    expected = costs["deformation"] + SCARA_LAMBDA * costs["regularization"] + WEIGHT * costs["joint_centring"]
    assert sol.raw.objective == pytest.approx(expected, rel=1e-9)
    # it changes the answer: the design moves, and the joints come closer to zero
    assert not np.allclose(sol.raw.q_d, plain.raw.q_d, atol=1e-3)
    assert costs["joint_centring"] < dict(plain.metrics.costs).get("joint_centring", h * np.sum(plain.raw.Q**2))


def test_structured_hessian_carries_the_term(problems, rng):
    _, extended = problems
    _, ours, _ = prepared(extended, Collocation(hessian="structured"), SolverProfile(compile="none"))
    _, ref, _ = prepared(extended, Collocation(hessian="auto"), SolverProfile())
    H_ours, H_ref, ours = ours.solver.get_function("nlp_hess_l"), ref.solver.get_function("nlp_hess_l"), ours.nlp
    for _ in range(3):
        x, lam_g = rng.normal(size=ours.n_variables), rng.normal(size=ours.n_constraints)
        np.testing.assert_allclose(np.triu(np.array(ca.DM(H_ours(x, [], 1.3, lam_g)))),
                                   np.triu(np.array(ca.DM(H_ref(x, [], 1.3, lam_g)))), rtol=1e-9, atol=1e-9)


def test_a_problem_without_a_waypoint_term_builds_its_blocks(problems, rng):
    """Every per-waypoint term dropped (the terms' weights input then has no rows): the compiled structured Hessian
    is still CasADi's own."""
    base, _ = problems
    bare = base.without_cost("deformation")
    assert not bare.waypoint_costs
    _, ours, _ = prepared(bare, Collocation(hessian="structured"), SolverProfile(compile="O0"))
    _, ref, _ = prepared(bare, Collocation(hessian="auto"), SolverProfile())
    H_ours, H_ref = ours.solver.get_function("nlp_hess_l"), ref.solver.get_function("nlp_hess_l")
    for _ in range(2):
        x, lam_g = rng.normal(size=ours.nlp.n_variables), rng.normal(size=ours.nlp.n_constraints)
        np.testing.assert_allclose(np.triu(np.array(ca.DM(H_ours(x, [], 1.3, lam_g)))),
                                   np.triu(np.array(ca.DM(H_ref(x, [], 1.3, lam_g)))), rtol=1e-9, atol=1e-9)


def test_the_term_is_a_column_and_a_file_metric(problems, tmp_path):
    _, extended = problems
    run = RunDirectory(tmp_path / "run")
    search = preset("paper", starts=2, profile=SolverProfile(max_iter=500, compile="none"))
    (searched,) = run_search([Job("", extended)], search, Executor(run, "custom", jobs=1))
    done = searched.final
    summary = pd.read_csv(run.summary)
    assert "cost_joint_centring" in summary.columns and "cost_deformation" in summary.columns
    for (task, sol), (_, row) in zip(sorted(done, key=lambda d: d[1].raw.seed), summary.sort_values("seed").iterrows(),
                                     strict=True):
        assert row["cost_joint_centring"] == pytest.approx(dict(sol.metrics.costs)["joint_centring"], rel=1e-12)
        data = json.loads((run.path / task.file_name).read_text())
        assert data["metrics"]["costs"]["joint_centring"] == pytest.approx(row["cost_joint_centring"], rel=1e-12)
        assert data["metrics"]["cost_weights"]["joint_centring"] == WEIGHT
        assert verify_file(run.path / task.file_name) == []
