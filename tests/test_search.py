"""The search (designopt.search): the coarse path is a subset of the task, a solution lifted to another sampling
keeps its trajectory, distinct optima are told apart, and on a problem with a known optimum that a single start
misses, the search finds it."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

from designopt.config import parse_config
from designopt.experiments.adapters import multistart_from_config, search_from_config, transcription_for
from designopt.experiments.run import run_experiment
from designopt.multistart import solve_start
from designopt.problem import problem_from_config
from designopt.search import Search, coarse_problem, distinct_best, lifted_guess
from designopt.solution import solve_and_evaluate
from designopt.toolpaths import figure_eight, subsample

ROOT = Path(__file__).resolve().parent.parent


def test_the_config_and_the_library_share_the_search_defaults():
    # The defaults are written twice (pydantic validates the config, the library runs without one): a user who
    # leaves `solver.search` out must get what `Search()` documents.
    assert search_from_config(parse_config({})) == Search()
    changed = search_from_config(parse_config({"solver": {"search": {"screen": 5, "strategy": "multistart"}}}))
    assert (changed.screen, changed.strategy) == (5, "multistart")


def test_a_coarse_path_is_a_subset_of_the_task():
    tp = figure_eight(0.6, 0.3, 80, 1.0)
    coarse = subsample(tp, 10)
    assert coarse.n == 10 and coarse.t[0] == tp.t[0] and coarse.t[-1] == tp.t[-1]
    for k in range(coarse.n):  # every kept waypoint is one of the path's, with its time, tangent and force
        j = int(np.flatnonzero(tp.t == coarse.t[k])[0])
        assert np.array_equal(coarse.points_W[k], tp.points_W[j])
        assert np.array_equal(coarse.force_W[k], tp.force_W[j])
        assert np.array_equal(coarse.tangents_W[k], tp.tangents_W[j])
    assert coarse.weights.sum() == pytest.approx(tp.weights.sum() + coarse.h[-1] - tp.h[-1])
    assert subsample(tp, 200) is tp
    with pytest.raises(ValueError, match="at least 3"):
        subsample(tp, 2)


def test_the_velocity_of_a_sampled_trajectory_is_its_derivative(gantry_problem):
    rng = np.random.default_rng(3)
    from designopt.solution import Solution
    from designopt.transcriptions.base import RawResult

    n, m = gantry_problem.toolpath.n, gantry_problem.chain.n_moving
    raw = RawResult(np.zeros(gantry_problem.chain.n_design), rng.normal(size=(n, m)), rng.normal(size=(n, m)), "x",
                    True, 0, 0.0, 0.0, 0.0, 0, 0)
    sol = Solution(gantry_problem, "to", raw, None)
    t = rng.uniform(0.01, 0.99, 40)
    eps = 1e-6
    fd = (sol.sample(t + eps) - sol.sample(t - eps)) / (2 * eps)
    assert np.allclose(sol.sample_velocity(t), fd, atol=1e-5)
    # at the knots the spline's velocity is the knots' velocity
    assert np.allclose(sol.sample_velocity(gantry_problem.toolpath.t[:-1]), raw.V[:-1], atol=1e-9)


@pytest.fixture(scope="module")
def milling_12():
    cfg = yaml.safe_load((ROOT / "configs" / "milling.yaml").read_text())
    cfg["toolpath"]["waypoints"] = 12
    cfg["solver"] = {"max_iter": 300, "jobs": 1}
    return cfg


def test_a_lifted_solution_starts_where_it_ended(milling_12):
    """Lifting a coarse solution to the full path and back: the full path's guess passes through the coarse
    solution at the coarse waypoints (the spline is evaluated at times both paths share)."""
    cfg = parse_config(milling_12)
    full = problem_from_config(cfg)
    coarse = coarse_problem(full, 6)
    sol = solve_start(coarse, transcription_for(cfg), multistart_from_config(cfg), 0)
    guess = lifted_guess(full, sol)
    shared = np.flatnonzero(np.isin(full.toolpath.t, coarse.toolpath.t))
    assert len(shared) == coarse.toolpath.n
    assert np.allclose(guess.Q[shared], sol.raw.Q, atol=1e-12)
    assert np.allclose(guess.V[shared], sol.raw.V, atol=1e-9)
    assert np.array_equal(guess.q_d, sol.raw.q_d)


def test_distinct_best_takes_one_solution_per_optimum(milling_12):
    cfg = parse_config(milling_12)
    problem = problem_from_config(cfg)
    sol = solve_start(problem, transcription_for(cfg), multistart_from_config(cfg), 0)
    from dataclasses import replace

    def moved(cost, shift):
        raw = replace(sol.raw, q_d=sol.raw.q_d + shift)
        out = solve_and_evaluate(problem, "to", raw)
        return replace(out, metrics=replace(out.metrics, design_cost=cost, tracks=True))

    sols = [moved(3.0, 0.0), moved(1.0, 0.5), moved(2.0, 0.005), moved(0.5, 1.0)]
    # 0 and 2 are one optimum (5 mm apart), its best member is 2; order by cost: 3 (0.5), 1 (1.0), 2 (2.0)
    assert distinct_best(sols, 10, tol=0.02) == [3, 1, 2]
    assert distinct_best(sols, 2, tol=0.02) == [3, 1]
    assert distinct_best(sols, 10, tol=2.0) == [3]


def test_the_search_finds_the_optimum_a_single_start_misses(milling_12, tmp_path):
    """The PUMA-560 placed by its yaw alone: the optimum over yaw is known by an exhaustive grid (24 yaws, the
    workpiece fixed, 2 starts each); start 0 (the configured yaw) ends in a local optimum 28 % above it, the
    search (8 coarse starts, the best 2 refined) reaches it."""
    def config(**placement):
        c = copy.deepcopy(milling_12)
        c["robot"]["design"] = []
        c["placement"].update(placement)
        return parse_config(c)

    grid = []
    for yaw in np.linspace(-np.pi, np.pi, 25)[:-1]:
        cfg = config(optimize=False, ypr=[float(yaw), 0.0, 0.0])
        p, t, s = problem_from_config(cfg), transcription_for(cfg), multistart_from_config(cfg)
        grid += [x.metrics.design_cost for x in (solve_start(p, t, s, i) for i in range(2)) if x.metrics.tracks]
    known = min(grid)

    cfg = config(optimize=["yaw"])
    single = solve_start(problem_from_config(cfg), transcription_for(cfg), multistart_from_config(cfg), 0)
    assert single.metrics.design_cost > 1.2 * known  # one start misses it

    cfg = cfg.model_copy(update={"solver": cfg.solver.model_copy(update={"search": cfg.solver.search.model_copy(
        update={"explore_starts": 8, "explore_waypoints": 6, "refine": 2})})})
    result = run_experiment(cfg, ROOT / "configs", tmp_path, "s", figures=False)
    assert result.best is not None and result.best.metrics.tracks
    assert result.best.metrics.design_cost <= known * 1.001  # at least as good as the grid's best
    assert len(result.explored) == 8 and 1 <= len(result.solutions) <= 2


def test_each_stage_keeps_its_own_iteration_cap(milling_12, tmp_path):
    """Exploration within explore_max_iter, screening within screen_max_iter, refinement within solver.max_iter:
    a screening solve only ranks, so a stalling one must not take the full budget (design only stalls there)."""
    import pandas as pd

    cfg = copy.deepcopy(milling_12)
    cfg["solver"]["search"] = {"explore_starts": 4, "explore_waypoints": 6, "explore_max_iter": 100,
                               "screen_waypoints": 9, "screen": 3, "screen_max_iter": 25, "refine": 1}
    result = run_experiment(parse_config(cfg), ROOT / "configs", tmp_path, "s", figures=False)
    rows = pd.read_csv(result.directory.path / "summary.csv")
    caps = {"explore": 100, "screen": 25, "refine": 300}
    assert set(rows.case) == set(caps)
    for stage, cap in caps.items():
        assert rows[rows.case == stage].iterations.max() <= cap
    assert rows[rows.case == "screen"].iterations.max() == 25  # 25 iterations do not converge on a finer path
    assert rows[rows.case == "refine"].iterations.max() > 25
