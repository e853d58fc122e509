"""The Solve layer's extension points, used from outside the library the way docs/architecture.md shows: a second
backend (CasADi's SQP method instead of IPOPT) and a new strategy are each one class or module and one registry
line, and everything above them -- tasks, searches, experiments, files -- works with them unchanged."""

from __future__ import annotations

import time
from types import SimpleNamespace

import casadi as ca
import numpy as np
import pytest
from conftest import gantry_config

from designopt.config import parse_config
from designopt.problem import problem_from_config
from designopt.solve import Job, Search, Seeded, SolverProfile, run_search, run_task, solve_one
from designopt.solve.backends import BACKENDS
from designopt.solve.backends.base import Outcome
from designopt.solve.search import Searched, by_job
from designopt.solve.strategies import STRATEGIES
from designopt.solve.strategies.steps import seeded_tasks


class Sqp:
    """A backend: CasADi's SQP method (QPs by qpOASES) on the transcription's NLP, its Hessian by CasADi."""

    name = "sqp"

    def prepare(self, nlp, profile):
        t0 = time.perf_counter()
        opts = {"qpsol": "qpoases", "max_iter": profile.max_iter, "print_header": False, "print_iteration": False,
                "print_status": False, "print_time": False,
                "qpsol_options": {"printLevel": "none", "error_on_fail": False}, "error_on_fail": False}
        solver = ca.nlpsol("sqp", "sqpmethod", {"x": nlp.x, "f": nlp.f, "g": nlp.g}, opts)

        def solve(x0, bound=None):  # no observers here, so nothing to hold a solve to its bound
            t = time.perf_counter()
            sol = solver(x0=np.clip(x0, nlp.lbx, nlp.ubx), lbx=nlp.lbx, ubx=nlp.ubx, lbg=nlp.lbg, ubg=nlp.ubg)
            stats = solver.stats()
            return Outcome(np.asarray(sol["x"]).ravel(), float(sol["f"]), str(stats["return_status"]),
                           bool(stats["success"]), int(stats["iter_count"]), time.perf_counter() - t)

        return SimpleNamespace(solve=solve, prepare_time_s=time.perf_counter() - t0)


def test_a_second_backend_is_a_class_and_a_registry_line(monkeypatch):
    monkeypatch.setitem(BACKENDS, Sqp.name, Sqp)
    problem = problem_from_config(parse_config(gantry_config()))
    start = Seeded(0, 1)  # a perturbed design: offsets a of 0.02-0.12 m
    sol = solve_one(problem, start, profile=SolverProfile(backend="sqp", max_iter=100), hold_degenerate=False)
    N = problem.toolpath.n
    assert sol.raw.success and sol.metrics.tracks, sol.raw.status
    # the gantry's known optimum (tests/test_collocation.py): alpha^2 N / (N - 1) whatever the design (alpha = 2),
    # and the offsets a, which only pay regularisation, at their bound 0
    assert sol.metrics.design_cost == pytest.approx(4.0 * N / (N - 1), rel=1e-9)
    assert np.all(start.guess(problem).q_d > 0.01) and np.all(sol.raw.q_d < 1e-3)
    ipopt = solve_one(problem, start, hold_degenerate=False)
    assert sol.metrics.design_cost == pytest.approx(ipopt.metrics.design_cost, rel=1e-9)


def first_start_plan(jobs, search):
    """A strategy: the configured design's start only, on the full path."""
    done = yield [t for job in jobs for t in seeded_tasks(job, "first", job.problem, None, search, 1)]
    return [Searched(job, [], final) for job, final in zip(jobs, by_job(jobs, done), strict=True)]


def test_a_new_strategy_is_a_module_and_a_registry_line(monkeypatch):
    monkeypatch.setitem(STRATEGIES, "first_start", SimpleNamespace(plan=first_start_plan))
    problem = problem_from_config(parse_config(gantry_config()))
    ran = []

    def execute(tasks):
        ran.extend(tasks)
        return [(t, run_task(t)) for t in tasks]

    (searched,) = run_search([Job("", problem)], Search(strategy="first_start", starts=50), execute)
    assert [(t.stage, t.seed) for t in ran] == [("first", 0)]
    assert searched.best[1] is not None and searched.best[1].metrics.tracks
    with pytest.raises(ValueError, match="strategy must be one of"):
        run_search([Job("", problem)], Search(strategy="nowhere"), execute)
