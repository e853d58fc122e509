"""The search (designopt.solve): the coarse path is a subset of the task, a solution lifted to another sampling
keeps its trajectory, distinct optima are told apart, and on a problem with a known optimum that a single start
misses, the search finds it."""

from __future__ import annotations

import copy
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from conftest import solve
from hypothesis import example, given, settings
from hypothesis import strategies as st

from designopt.config import load_config, parse_config
from designopt.costs import tracking_residual
from designopt.experiments.adapters import search_from_config, structure_config
from designopt.experiments.run import draw_bests
from designopt.initial_guess import (
    _moved_onto_path,
    beyond_reach,
    first_configuration,
    ik_trajectory,
    initial_guess,
    projected,
    residual_function,
    start_index,
    start_number,
)
from designopt.problem import problem_from_config
from designopt.solution import solve_and_evaluate
from designopt.solve import (
    PRESETS,
    Job,
    Search,
    Searched,
    Seeded,
    SolverProfile,
    Task,
    distinct_best,
    lifted_guess,
    preset,
    run_search,
    run_task,
    solve_guess,
    solve_one,
)
from designopt.solve.optima import arm_joints, cluster_designs, design_forms, form_joints, snapped_design
from designopt.solve.search import DRAW_STRIDE
from designopt.solve.starts import Rebranched, first_configurations_of, spread_branches
from designopt.solve.strategies import _drive, coarse_to_fine, hop, reflect
from designopt.solve.strategies.coarse_to_fine import (
    coarse_problem,
    exploration_starts,
    rebranched_tasks,
    screening,
    shares,
)
from designopt.solve.strategies.steps import seeded_tasks
from designopt.solve.tasks import units
from designopt.toolpaths import figure_eight, subsample
from designopt.transcriptions import Collocation, InitialGuess

ROOT = Path(__file__).resolve().parent.parent


def test_the_config_names_a_preset_and_every_knob_reaches_the_search():
    # a config without `search` gets the library's default search; its three keys each change what runs
    assert search_from_config(parse_config({})) == PRESETS["default"]
    assert PRESETS["default"] == Search(starts=160, screen=24, init="home", explore_linear_solver="ldl",
                                        screen_mu_init=(None, 1e-6), refine_mu_init=(None, 1e-6),
                                        rebranch_new_forms=4, reflect=3, reflect_within=1.05, rebranch_extra=30,
                                        rebranch_extra_pool=50, same_arm_cost=0.002, rebranch_moved=10, prescreen=48,
                                        refine_relaxed=1, screen_prescreened="both", refine_distinct_arms=True)
    for name in PRESETS:
        assert search_from_config(parse_config({"search": {"preset": name}})) == PRESETS[name]
    changed = search_from_config(parse_config({"search": {"preset": "paper", "seed": 7, "starts": 3}}))
    assert (changed.strategy, changed.seed, changed.starts) == ("multistart", 7, 3)
    assert changed.profile == PRESETS["paper"].profile
    assert changed.spread == "perturb"
    boxed = search_from_config(parse_config({"search": {"spread": "box"}}))
    assert boxed == replace(PRESETS["default"], spread="box")
    (task, *_) = seeded_tasks(Job("", coarse_problem(problem_from_config(parse_config({})), 10)), "explore",
                              None, None, boxed, 2)
    assert (task.start.spread, task.start.init) == ("box", "home")
    assert "pulled towards the first waypoint's configuration" in PRESETS["default"].describe()
    assert "drawn from the task's box" in boxed.describe() and "box" not in PRESETS["default"].describe()
    assert "every other one drawn from the task's box" in replace(PRESETS["paper"], spread="mixed").describe()
    assert preset("quick", seed=2) == Search(starts=40, rebranch=0, screen=12, screen_waypoints=20, refine=4,
                                             reflect=3, small_problem_starts=4, seed=2, explore_linear_solver="ldl",
                                             screen_linear_solver=("ldl", "mumps"), small_arm_screens_once=True,
                                             small_arm_perturbation=0.6, small_arm_starts=2,
                                             profile=PRESETS["quick"].profile)
    # a stage's own linear solver is named in the search's words, the profile's is not
    quick = PRESETS["quick"].describe()
    assert ("20 waypoints (<= 300 iterations, each candidate once with KKT systems by ldl and once by mumps; an arm of "
            "fewer than 5 joints the first pass only, if") in quick and quick.count("KKT systems by ldl") == 2
    assert "re-ranked on 40 waypoints (<= 300 iterations, each from barrier the warm start's and 1e-06, if" in (
        PRESETS["default"].describe())


def test_a_profiles_options_reach_ipopt_and_the_production_preset_regularises():
    """A profile's options reach IPOPT itself (a cap of 2 iterations given as an option stops a solve after 2), and
    the production preset is the paper's multistart on 4 starts with IPOPT's constraint block regularised."""
    problem = problem_from_config(parse_config({"toolpath": {"kind": "figure_eight", "waypoints": 6}}))
    capped = replace(PRESETS["paper"].profile, options=(("ipopt.max_iter", 2),))
    sol = solve_one(problem, profile=capped)
    assert (sol.raw.status, sol.raw.iterations) == ("Maximum_Iterations_Exceeded", 2)
    assert solve_one(problem, profile=PRESETS["paper"].profile).raw.iterations > 2
    production = search_from_config(parse_config({"search": {"preset": "production"}}))
    regularised = replace(PRESETS["paper"].profile, options=(("ipopt.perturb_always_cd", "yes"),))
    assert production == replace(PRESETS["paper"], starts=4, profile=regularised)
    assert "IPOPT options perturb_always_cd yes" in production.describe()
    assert "IPOPT" not in PRESETS["default"].describe()


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
    from designopt.transcriptions.trajectory import HermiteCubic

    n, m = gantry_problem.toolpath.n, gantry_problem.chain.n_moving
    trajectory = HermiteCubic(gantry_problem.toolpath.t, rng.normal(size=(n, m)), rng.normal(size=(n, m)))
    raw = RawResult(np.zeros(gantry_problem.chain.n_design), trajectory, "x", True, 0, 0.0, 0.0, 0.0, 0, 0)
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
    return cfg


@pytest.fixture(scope="module")
def milling_12_slow(milling_12):
    """The 12-waypoint main job with joint velocity limits it never reaches (100 per unit task time)."""
    cfg = copy.deepcopy(milling_12)
    cfg["robot"]["joint_velocity"] = 100.0
    return cfg


def test_a_lifted_solution_starts_where_it_ended(milling_12_slow):
    """Lifting a coarse solution to the full path and back: the full path's guess passes through the coarse
    solution at the coarse waypoints (the spline is evaluated at times both paths share; no step of this path
    comes near its velocity limits, so `projected` has no change of branch to walk past)."""
    cfg = parse_config(milling_12_slow)
    full = problem_from_config(cfg)
    coarse = coarse_problem(full, 6)
    sol = solve(coarse, max_iter=300)
    guess = lifted_guess(full, sol)
    shared = np.flatnonzero(np.isin(full.toolpath.t, coarse.toolpath.t))
    assert len(shared) == coarse.toolpath.n
    assert np.allclose(guess.Q[shared], sol.raw.Q, atol=1e-12)
    assert np.allclose(guess.V[shared], sol.raw.V, atol=1e-9)
    assert np.array_equal(guess.q_d, sol.raw.q_d)


def test_a_lifted_start_is_on_the_path_between_the_coarse_knots(milling_12):
    """Between a coarse solution's knots its trajectory leaves the path; the lifted start's waypoints are moved
    onto it (`initial_guess.projected`) wherever the coarse design reaches: never further from it than the
    trajectory (or than the projection's tolerance, 1e-3, where it walked past a change of branch), and most of
    them on it."""
    full = problem_from_config(parse_config(milling_12))
    sol = solve(coarse_problem(full, 6), max_iter=300)
    assert sol.metrics.tracks
    guess = lifted_guess(full, sol)
    tp = full.toolpath

    def errors(Q):  # the tracking residual at each waypoint (m and axis components together)
        return np.array([np.linalg.norm(np.concatenate(tracking_residual(
            full.waypoint(Q[k], guess.q_d, tp.points_W[k], tp.force_W[k])))) for k in range(tp.n)])

    sampled, lifted = errors(sol.sample(tp.t)), errors(guess.Q)
    assert np.median(sampled) > 0.1  # the spline between 6 knots leaves the path
    assert np.all(lifted <= np.maximum(sampled, 1e-3) + 1e-12)
    assert np.sum(lifted < 1e-6) >= tp.n - 1


CIRCLE_12 = {"name": "circle_12", "toolpath": {"kind": "circle", "radius": 0.15, "waypoints": 12, "force": 1.0},
             "robot": {"structure": "RRRRRR", "dh": "puma560"}, "placement": {"xyz": [0.5, 0.0, -0.2]}}


def test_the_home_walk_ends_where_it_began_around_a_closed_path():
    """Perturbed starts of a 6R arm (twists off the lattice, so the arm turns about more than its last joint to
    keep the tool on the path: redundant by one for a tool whose spin is free), walked around a closed circle.
    The ``ik`` walk's minimum-norm steps end elsewhere on the self-motion than they began on almost every start
    (the pseudoinverse is not repeatable); ``home``, pulled towards the first configuration, ends where it began on
    every walk that stays on the path (every waypoint within 1e-6), and stays on it as often."""
    problem = problem_from_config(parse_config(CIRCLE_12))
    tp = problem.toolpath
    fn = residual_function(problem)
    assert np.abs(tp.points_W[0] - tp.points_W[-1]).max() < 1e-12  # the premise: a closed path

    def walked(mode):  # (on the path, gap between the last and first configurations) per start
        out = []
        for i in range(1, 41):
            guess = initial_guess(problem, i, 11, 0.3, mode)
            Q = guess.Q
            on = max(np.linalg.norm(np.array(fn(Q[k], guess.q_d, tp.points_W[k])[0])) for k in range(tp.n)) < 1e-6
            out.append((on, np.abs(Q[-1] - Q[0]).max()))
        return np.array(out)

    free, pulled = walked("ik"), walked("home")
    on_free, on_pulled = free[:, 0] > 0, pulled[:, 0] > 0
    assert on_free.sum() >= 15 and (free[on_free, 1] > 1e-3).sum() >= 0.8 * on_free.sum()  # the ik walk drifts
    assert on_pulled.sum() >= on_free.sum()
    assert pulled[on_pulled, 1].max() < 1e-3


def test_an_arm_without_self_motion_walks_home_as_ik_does():
    """The PUMA-560 as configured: its only self-motion for a tool whose spin is free is its last joint turning
    about the tool axis, which no walk moves; the pull has nothing to act on, and ``home`` is the ``ik`` walk to
    the bit, from any first configuration."""
    problem = problem_from_config(parse_config(CIRCLE_12))
    for seed in range(5):  # start 0 keeps the configured design
        assert np.array_equal(initial_guess(problem, 0, seed, 0.3, "home").Q, initial_guess(problem, 0, seed, 0.3).Q)


def test_projection_moves_joints_onto_the_path_and_keeps_their_branch(milling_12_slow):
    """Joints on an IK trajectory, disturbed by 0.05 rad, return to the path near where they were (the arm is
    redundant for a tool whose spin is free, so not to the same joints); rows already on the path do not move."""
    problem = problem_from_config(parse_config(milling_12_slow))
    tp = problem.toolpath
    q_d = np.array([j.value for j in problem.chain.design])
    on_path = ik_trajectory(problem, q_d, np.full(problem.chain.n_moving, 0.3))
    fn = residual_function(problem)

    def residuals(Q):
        return np.array([np.linalg.norm(np.array(fn(Q[k], q_d, tp.points_W[k])[0])) for k in range(tp.n)])

    assert residuals(on_path).max() < 1e-7
    disturbed = on_path + np.random.default_rng(5).normal(0.0, 0.05, on_path.shape)
    disturbed[::3] = on_path[::3]
    assert residuals(disturbed)[1::3].min() > 1e-3
    back = projected(problem, q_d, disturbed)
    assert residuals(back).max() < 1e-7
    assert np.abs(back - on_path).max() < 0.2
    assert np.array_equal(back[::3], on_path[::3])


def test_projection_walks_where_the_ik_would_change_branch(milling_12):
    """Rows 3-5 of an IK trajectory replaced by another IK branch's (2.3-2.7 rad away), disturbed off the path:
    projected on their own they land on that branch, a step at rows 2-3 that no trajectory within the velocity
    limits can make; `projected` walks along the path from row 2 instead, so that no step is longer than the
    limits allow or than the first branch's own (where the path asks for more than the limits), and the rows
    end on the path on the first branch."""
    problem = problem_from_config(parse_config(milling_12))
    tp = problem.toolpath
    q_d = np.array([j.value for j in problem.chain.design])
    first = ik_trajectory(problem, q_d, np.full(problem.chain.n_moving, 0.3))
    other = ik_trajectory(problem, q_d, np.array([0.3, -1.5, 2.0, 0.3, 0.3, 0.3]))
    fn = residual_function(problem)

    def residuals(Q):
        return np.array([np.linalg.norm(np.array(fn(Q[k], q_d, tp.points_W[k])[0])) for k in range(tp.n)])

    def steps(Q):  # each step over what the velocity limits allow in its time
        return (np.abs(np.diff(Q, axis=0)) / (problem.velocity_limits[None, :] * tp.h[:, None])).max(axis=1)

    assert residuals(first).max() < 1e-7 and residuals(other).max() < 1e-7
    assert np.abs(first - other)[3:6].max(axis=1).min() > 2.0
    mixed = first.copy()
    mixed[3:6] = other[3:6] + np.random.default_rng(2).normal(0.0, 0.05, (3, problem.chain.n_moving))
    alone, _ = _moved_onto_path(problem, q_d, mixed, np.arange(tp.n), 30)
    assert steps(alone)[2] > 1.0  # the premise: on its own the IK keeps the other branch
    back = projected(problem, q_d, mixed)
    assert residuals(back).max() < 1e-7
    assert np.all(steps(back) <= np.maximum(steps(first), 1.0) + 1e-9)
    assert np.abs(back - first).max() < 0.2
    assert np.array_equal(back[6:], first[6:])


@settings(max_examples=40, deadline=None)
@given(st.floats(0.2, 2.0).filter(lambda r: abs(r - 1.0) > 1e-6), st.integers(0, 10), st.integers(0, 5),
       st.sampled_from([-1.0, 1.0]))
def test_a_step_is_beyond_reach_when_no_cubic_within_the_limits_makes_it(milling_12, ratio, k, joint, sign):
    """`beyond_reach` against the collocation's own cubic: a step of ``ratio`` times v_max h in one joint between
    waypoints k and k + 1 is beyond reach exactly when no knot velocities within +-v_max give the cubic (its
    coefficients solved from the Hermite conditions) a midpoint velocity within +-v_max."""
    problem = problem_from_config(parse_config(milling_12))
    h, v_max = problem.toolpath.h[k], problem.velocity_limits[joint]
    dq = sign * ratio * v_max * h
    Q = np.zeros((2, problem.chain.n_moving))
    Q[1, joint] = dq

    def midpoint_velocity(v0, v1):  # q(t) = c0 + c1 t + c2 t^2 + c3 t^3 through (0, 0, v0) and (h, dq, v1)
        A = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [1, h, h**2, h**3], [0, 1, 2 * h, 3 * h**2]], float)
        c = np.linalg.solve(A, [0.0, v0, dq, v1])
        return c[1] + 2 * c[2] * (h / 2) + 3 * c[3] * (h / 2) ** 2

    ends = sorted(midpoint_velocity(v, v) for v in (-v_max, v_max))  # linear in v0 + v1: these bound it
    reachable = ends[0] <= v_max and ends[1] >= -v_max
    assert bool(beyond_reach(problem, Q, k)[0]) == (not reachable)


def test_distinct_best_takes_one_solution_per_optimum(milling_12):
    cfg = parse_config(milling_12)
    problem = problem_from_config(cfg)
    sol = solve(problem, max_iter=300)
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


def test_an_arms_form_is_the_pattern_of_its_joint_axes():
    """`design_forms`: each twist between two joint axes 0 (parallel: a multiple of pi, either sign) or 1
    (perpendicular: an odd multiple of pi/2), whatever the lengths; `form_joints` marks the twists between the
    first and the last moving joint -- not the placement's angles, nor the last link's twist (the tool's)."""
    chain = problem_from_config(parse_config({})).chain
    form = form_joints(chain)
    names = [j.name for j in chain.design]
    assert [n for n, f in zip(names, form, strict=True) if f] == [f"link{i}.alpha" for i in range(1, 6)]
    q = chain.design_values.copy()
    q[form] = [0.0, np.pi - 0.01, -np.pi / 2 + 0.2, 3 * np.pi / 2, -np.pi]
    other = q + np.where(form, 0.0, 0.37)  # lengths, placement and the last twist moved
    assert design_forms(np.array([q, other]), form) == [(0, 0, 1, 1, 0)] * 2
    assert not form_joints(problem_from_config(parse_config({"design": ["placement"]})).chain).any()


def _optimum(problem, cost: float, pattern: tuple[int, ...], shift: float):
    """A tracking solution stand-in: the default design with these twists (multiples of pi/2) and link 2's length
    moved by ``shift``, at design cost ``cost``."""
    chain = problem.chain
    q = chain.design_values.copy()
    q[form_joints(chain)] = np.array(pattern) * np.pi / 2
    q[[j.name for j in chain.design].index("link2.a")] += shift
    return SimpleNamespace(problem=problem, metrics=SimpleNamespace(tracks=True, design_cost=cost),
                           raw=SimpleNamespace(q_d=q))


def _numbered_optima(problem, costs, pattern: tuple[int, ...], numbers) -> list:
    """`_optimum` stand-ins at these design costs (link 2 moved 0.1 m further each, so all distinct), each with the
    start number of the task it answers."""
    out = [_optimum(problem, cost, pattern, 0.1 * k) for k, cost in enumerate(costs)]
    for sol, number in zip(out, numbers, strict=True):
        sol.raw.seed = number
    return out


def test_the_second_rounds_leaders_are_capped_per_form():
    """``per_form``: the distinct optima in order of cost, at most that many of one form before those of other
    forms, then the rest by cost; None, or a design space without form joints: by cost alone. The second round
    (`rebranched_tasks`) starts from the leaders so chosen (`Search.rebranch_per_form`)."""
    problem = problem_from_config(parse_config({}))
    a, b, c = (0, 0, 1, 0, 1), (0, 0, 1, 0, 0), (1, 0, 1, 0, 1)
    sols = [_optimum(problem, cost, form, shift) for cost, form, shift in
            ((1.0, a, 0.0), (2.0, a, 0.1), (3.0, a, 0.2), (4.0, b, 0.0), (5.0, a, 0.3), (6.0, c, 0.0))]
    assert distinct_best(sols, 4) == [0, 1, 2, 3]
    assert distinct_best(sols, 4, per_form=2) == [0, 1, 3, 5]
    assert distinct_best(sols, 4, per_form=1) == [0, 3, 5, 1]
    assert distinct_best(sols, 10, per_form=1) == [0, 3, 5, 1, 2, 4]

    placed = problem_from_config(parse_config({"design": ["placement"]}))
    chain = placed.chain
    assert distinct_best([SimpleNamespace(problem=placed, metrics=s.metrics,
                                          raw=SimpleNamespace(q_d=chain.design_values + 0.1 * k))
                          for k, s in enumerate(sols)], 3, per_form=1) == [0, 1, 2]

    task = Task("", "explore", problem, Collocation(), SolverProfile(), Seeded(0, 0))
    search = Search(starts=6, rebranch=3, rebranch_per_form=1)
    tasks = rebranched_tasks([[(task, s) for s in sols]], search)
    assert [t.start.solution for t in tasks[:: search.rebranch_starts]] == [sols[0], sols[3], sols[5]]
    assert [t.start.number for t in tasks] == list(range(6, 6 + 3 * search.rebranch_starts))
    assert "at most 1 of one form" in search.describe()


def test_the_second_round_adds_the_best_of_forms_its_leaders_lack():
    """``new_forms``: after the ``count`` leaders (unchanged, in order), the cheapest optimum of each form not among
    them, cheapest first, at most that many; none when the leaders hold every form. The second round
    (`Search.rebranch_new_forms`) starts them after the leaders' starts, which stay what they were: their drawn,
    extra and moved starts the same numbers and designs (`Search.leader_start`)."""
    problem = problem_from_config(parse_config({}))
    a, b, c = (0, 0, 1, 0, 1), (0, 0, 1, 0, 0), (1, 0, 1, 0, 1)
    sols = [_optimum(problem, cost, form, shift) for cost, form, shift in
            ((1.0, a, 0.0), (2.0, a, 0.1), (3.0, b, 0.0), (4.0, b, 0.2), (5.0, a, 0.3), (6.0, c, 0.0))]
    assert distinct_best(sols, 2, new_forms=1) == [0, 1, 2]
    assert distinct_best(sols, 2, new_forms=2) == [0, 1, 2, 5]
    assert distinct_best(sols, 2, new_forms=5) == [0, 1, 2, 5]
    assert distinct_best(sols, 3, new_forms=2) == [0, 1, 2, 5]
    assert distinct_best(sols, 6, new_forms=2) == [0, 1, 2, 3, 4, 5]

    task = Task("", "explore", problem, Collocation(), SolverProfile(), Seeded(0, 0))
    plain, added = Search(starts=4, rebranch=2), Search(starts=4, rebranch=2, rebranch_new_forms=2)
    before = rebranched_tasks([[(task, s) for s in sols]], plain)
    after = rebranched_tasks([[(task, s) for s in sols]], added)
    assert [(t.start.solution, t.start.number) for t in after[:len(before)]] == [
        (t.start.solution, t.start.number) for t in before]
    assert [t.start.solution for t in after[len(before)::added.rebranch_starts]] == [sols[2], sols[5]]
    assert [t.start.number for t in after] == list(range(4, 4 + 4 * added.rebranch_starts))
    assert "up to 2 forms not among them" in added.describe()
    more = replace(plain, init="home", rebranch_extra=1, rebranch_extra_pool=3, rebranch_moved=1, rebranch_moved_pool=2)
    before = rebranched_tasks([[(task, s) for s in sols]], more)
    after = rebranched_tasks([[(task, s) for s in sols]], replace(more, rebranch_new_forms=2))
    assert len(before) == 2 * 4 and len(after) == 4 * 4
    for t, u in zip(after, before, strict=False):
        assert t.start.number == u.start.number and t.start.solution is u.start.solution
        assert np.array_equal(t.start.design(problem), u.start.design(problem))
    assert min(t.start.number for t in after[len(before):]) == 4 + 2 * (2 + 3 + 2)
    # a start's number tells the rounds apart, as the benchmarks read them back from a run's files
    added = replace(added, seed=7)
    seeded = seeded_tasks(Job("", problem), "explore", problem, SolverProfile(), added, added.starts)
    rebranched = rebranched_tasks([[(task, s) for s in sols]], added)
    assert not any(added.second_round(t.seed) for t in seeded)
    assert all(added.second_round(t.seed) for t in rebranched)
    assert list(added.second_round(np.array([t.seed for t in seeded + rebranched]))) == (
        [False] * len(seeded) + [True] * len(rebranched))


def test_the_screen_adds_the_best_of_leaders_whose_starts_it_lacks():
    """``new_lineages``: after the ``count`` distinct optima, the cheapest optimum of each lineage not among them,
    cheapest first, at most that many; a solution of no lineage (None) never added. `Search.leader_of` tells a
    second-round start's leader by its number (None for the first round and past the exploration), and the screen
    (`Search.screen_new_leaders`) adds the best of each leader's starts it lacks. Driven through the plan."""
    problem = problem_from_config(parse_config({}))
    a, b = (0, 0, 1, 0, 1), (0, 0, 1, 0, 0)
    sols = [_optimum(problem, cost, form, shift) for cost, form, shift in
            ((1.0, a, 0.0), (2.0, a, 0.1), (3.0, b, 0.0), (4.0, a, 0.2), (5.0, b, 0.3), (6.0, a, 0.4))]
    lineages = [0, None, 0, 1, None, 2]
    assert distinct_best(sols, 2, lineages=lineages) == [0, 1]
    assert distinct_best(sols, 1, lineages=lineages, new_lineages=1) == [0, 3]
    assert distinct_best(sols, 1, lineages=lineages, new_lineages=5) == [0, 3, 5]
    assert distinct_best(sols, 3, lineages=lineages, new_lineages=5) == [0, 1, 2, 3, 5]
    twin = _optimum(problem, 0.5, a, 0.001)  # a cheaper solve of optimum 0, of lineage 3, stands for it
    assert distinct_best(sols + [twin], 1, lineages=lineages + [3], new_lineages=5) == [6, 2, 3, 5]

    search = Search(starts=4, rebranch=2, rebranch_new_forms=1, init="home", rebranch_extra=1, rebranch_extra_pool=3,
                    seed=2, screen=2, screen_new_leaders=3)
    assert search.leader_width == 2 + 3 and search.last_exploration_start == 4 + 3 * 5
    assert [search.leader_of(start_number(2, i)) for i in (0, 3, 4, 8, 9, 18, 19, 100)] == [
        None, None, 0, 0, 1, 2, None, None]
    plan = coarse_to_fine.plan([Job("", problem)], search)
    explore = next(plan)
    first = [_optimum(problem, cost, form, shift) for cost, form, shift in
             ((1.0, a, 0.0), (1.5, a, 0.1), (1.8, a, 0.2), (1.9, b, 0.9))]
    rebranched = plan.send(list(zip(explore, first, strict=True)))
    assert [t.start.solution for t in rebranched] == [first[0]] * 3 + [first[1]] * 3 + [first[3]] * 3
    assert [search.leader_of(t.seed) for t in rebranched] == [0] * 3 + [1] * 3 + [2] * 3
    assert all(search.leader_of(t.seed) is None for t in explore)
    second = [_optimum(problem, cost, form, shift) for cost, form, shift in
              ((2.0, b, 0.0), (2.5, b, 0.1), (3.0, a, 0.3), (7.0, a, 0.5), (4.0, b, 0.4), (8.0, b, 0.6),
               (9.0, a, 0.7), (9.5, a, 0.8), (5.0, b, 0.7))]
    screen = plan.send(list(zip(rebranched, second, strict=True)))
    assert {t.stage for t in screen} == {"screen"}
    # the best 2 distinct (the first round's), then each leader's starts' cheapest (the first round's 1.8 and 1.9
    # are of no leader's starts)
    assert [t.start.solution for t in screen] == first[:2] + [second[0], second[4], second[8]]
    assert "the best of up to 3 second-round leaders' starts not among them" in search.describe()
    assert "second-round leaders" not in replace(search, screen_new_leaders=0).describe()


def test_only_the_explorations_solves_scale_the_objective():
    """``explore_objective_scale``: both rounds of the exploration solve with the objective scaled
    (`SolverProfile.objective_scale`); the screen (as the refine, warm solves alike) solves the NLP's own objective.
    Driven through the plan; 1 (the field's default) scales nothing and says nothing."""
    problem = problem_from_config(parse_config({}))
    a, b = (0, 0, 1, 0, 1), (0, 0, 1, 0, 0)
    search = Search(starts=4, rebranch=2, seed=2, screen=2, refine=1, explore_objective_scale=30.0)
    plan = coarse_to_fine.plan([Job("", problem)], search)
    explore = next(plan)
    first = [_optimum(problem, cost, form, shift) for cost, form, shift in
             ((1.0, a, 0.0), (1.5, b, 0.1), (1.8, a, 0.2), (1.9, b, 0.9))]
    rebranched = plan.send(list(zip(explore, first, strict=True)))
    assert rebranched and {t.profile.objective_scale for t in explore + rebranched} == {30.0}
    second = [_optimum(problem, 2.0 + k, a, 0.3 + 0.1 * k) for k in range(len(rebranched))]
    screen = plan.send(list(zip(rebranched, second, strict=True)))
    assert {t.stage for t in screen} == {"screen"} and {t.profile.objective_scale for t in screen} == {1.0}
    assert "the objective scaled by 30" in search.describe()
    plain = replace(search, explore_objective_scale=1.0)
    assert {t.profile.objective_scale for t in next(coarse_to_fine.plan([Job("", problem)], plain))} == {1.0}
    assert "scaled" not in plain.describe()


def test_the_second_rounds_leaders_get_their_starts_by_rank():
    """``rebranch_shares``: the second round's leader of rank k starts the k-th entry's number of times, a leader past
    the entries (a new form's) ``rebranch_starts``; the start numbers run on from ``most_starts``, each leader's in a
    block as wide as the most any leader has (`Search.leader_width`), all of the second round. Without shares every
    leader starts ``rebranch_starts`` times."""
    problem = problem_from_config(parse_config({}))
    a, b, c = (0, 0, 1, 0, 1), (0, 0, 1, 0, 0), (1, 0, 1, 0, 1)
    sols = [_optimum(problem, cost, form, shift) for cost, form, shift in
            ((1.0, a, 0.0), (2.0, a, 0.1), (3.0, b, 0.0), (4.0, b, 0.2), (5.0, a, 0.3), (6.0, c, 0.0))]
    task = Task("", "explore", problem, Collocation(), SolverProfile(), Seeded(0, 0))
    shared = Search(starts=4, rebranch=2, rebranch_new_forms=1, rebranch_shares=(3, 1), seed=5)
    tasks = rebranched_tasks([[(task, s) for s in sols]], shared)
    assert shared.rebranch_starts == 2 and [shared.leader_starts(k) for k in range(3)] == [3, 1, 2]
    assert [t.start.solution for t in tasks] == [sols[0]] * 3 + [sols[1]] + [sols[2]] * 2
    assert shared.leader_width == 3 and [t.start.index for t in tasks] == [4, 5, 6, 7, 10, 11]
    assert all(shared.second_round(t.seed) for t in tasks)
    assert "restarted 3, 1 times by rank" in shared.describe()
    even = rebranched_tasks([[(task, s) for s in sols]], replace(shared, rebranch_shares=None))
    assert [t.start.solution for t in even] == [sols[0]] * 2 + [sols[1]] * 2 + [sols[2]] * 2
    assert "restarted 2 times each" in replace(shared, rebranch_shares=None).describe()


def test_a_walks_first_configuration_is_its_first_row_to_the_bit():
    """`initial_guess.first_configuration` walks the first waypoint alone: the first row of the whole walk to the bit,
    for plain and pulled walks, seeded and rebranched starts (independent truth: the walk itself)."""
    problem = coarse_problem(problem_from_config(parse_config({})), 6)
    design = problem.chain.design_values + 0.05
    for mode in ("ik", "home"):
        for index in range(4):
            rebranched = Rebranched(SimpleNamespace(raw=SimpleNamespace(q_d=design)), 3, index, mode)
            assert np.array_equal(rebranched.first_configuration(problem), rebranched.guess(problem).Q[0])
            seeded = initial_guess(problem, index, 3, 0.3, mode)
            assert np.array_equal(first_configuration(problem, index, 3, 0.3, mode), seeded.Q[0])
    assert not np.array_equal(first_configuration(problem, 1, 3, 0.3), first_configuration(problem, 2, 3, 0.3))


def test_starts_walked_together_reach_what_each_walk_alone_does():
    """`first_configurations_of` walks a leader's starts to the first waypoint in lockstep: each row equals that
    start's own walk to the bit (independent truth: `Rebranched.first_configuration`, one start at a time), moved
    designs and starts that converge at different iterations among them, in every init."""
    problem = coarse_problem(problem_from_config(parse_config({})), 6)
    leader = SimpleNamespace(raw=SimpleNamespace(q_d=problem.chain.design_values + 0.05))
    for mode in ("ik", "home", "constant"):
        starts = [Rebranched(leader, 3, index, mode, 0.1 if index % 3 == 2 else 0.0) for index in range(12)]
        together = first_configurations_of(problem, starts)
        alone = np.array([start.first_configuration(problem) for start in starts])
        assert together.shape == (12, problem.chain.n_moving)
        assert np.array_equal(together, alone)
    assert first_configurations_of(problem, []).shape == (0, problem.chain.n_moving)


def test_branches_spread_by_farthest_points_one_from_each_cluster():
    """`spread_branches`: the first row, then the row farthest from all taken, revolute differences wrapped (a
    configuration at pi - 0.01 rad is next to one at -pi + 0.01), prismatic ones in m; never a row twice."""
    rng = np.random.default_rng(0)
    centres = np.array([[0.0, 0.0, 0.3], [2.0, -2.0, 0.3], [-2.0, 2.0, 0.8]])
    rows = np.vstack([c + 0.05 * rng.standard_normal((5, 3)) for c in centres])  # clusters of 5, in order
    angle = np.array([True, True, False])
    taken = spread_branches(rows, 3, angle)
    assert taken[0] == 0 and sorted(k // 5 for k in taken) == [0, 1, 2]
    wrapped = np.array([[np.pi - 0.01, 0.0], [-np.pi + 0.01, 0.0], [0.0, 0.0]])
    assert spread_branches(wrapped, 2, np.array([True, True])) == [0, 2]
    assert spread_branches(wrapped, 2, np.array([False, False])) == [0, 1]  # unwrapped, the two are 2 pi apart
    assert spread_branches(np.zeros((4, 2)), 4, np.array([True, True])) == [0, 1, 2, 3]
    assert spread_branches(rows, 40, angle) == [0, *spread_branches(rows, 15, angle)[1:]] and len(
        set(spread_branches(rows, 40, angle))) == 15
    assert spread_branches(rows, 0, angle) == []


def _two_leaders():
    """The main job, its 6-waypoint coarse problem, two coarse optima of two forms on it and an exploration task."""
    problem = problem_from_config(parse_config({}))
    coarse = coarse_problem(problem, 6)
    a, b = (0, 0, 1, 0, 1), (0, 0, 1, 0, 0)
    sols = [_optimum(coarse, 1.0, a, 0.0), _optimum(coarse, 2.0, b, 0.0)]
    return problem, coarse, sols, Task("", "explore", coarse, Collocation(), SolverProfile(), Seeded(0, 0))


def test_a_leaders_starts_taken_from_a_larger_pool_spread_over_branches():
    """``rebranch_pool``: each leader's starts drawn that many times over, in a block of start numbers of its own
    (`Search.leader_start`: `leader_width` counts the pool), the ones taken spread over the branches their walks
    reach first (`spread_branches` of the first configurations), the first drawn always among them; 1: the starts as
    before.
    The reflect step numbers its starts after all of them."""
    problem, coarse, sols, task = _two_leaders()
    plain = Search(starts=6, rebranch=2, seed=4, init="home")
    pooled = replace(plain, rebranch_pool=3)
    before = rebranched_tasks([[(task, s) for s in sols]], plain)
    assert [t.start.index for t in before] == list(range(6, 12))
    after = rebranched_tasks([[(task, s) for s in sols]], pooled)
    assert [pooled.leader_start(0, k) for k in range(3)] == [6, 6 + 3 * 3, 6 + 2 * 3 * 3]
    assert [t.start.solution for t in after] == [sols[0]] * 3 + [sols[1]] * 3
    first, second = [t.start.index for t in after[:3]], [t.start.index for t in after[3:]]
    assert first[0] == 6 and second[0] == 15 and first == sorted(first) and second == sorted(second)
    assert set(first) <= set(range(6, 15)) and set(second) <= set(range(15, 24))
    for leader, taken in ((sols[0], first), (sols[1], second)):
        pool = [Rebranched(leader, 4, j, "home") for j in range(taken[0], taken[0] + 9)]
        firsts = np.array([s.first_configuration(coarse) for s in pool])
        angle = np.array([j.kind == "angle" for j in coarse.chain.moving])
        assert taken == sorted(taken[0] + k for k in spread_branches(firsts, 3, angle))
    assert all(pooled.second_round(t.seed) for t in after)
    assert "3x as many drawn" in pooled.describe()
    assert reflect.first_start(replace(preset("default"), rebranch_pool=5)) == 2200  # 160 + 12 x (5 x 20 + 50 + 20)


def test_rows_kept_then_the_rest_spread_farthest_from_them():
    """`spread_branches(..., kept=k)`: the first k rows taken as they are, then each time the row farthest from every
    one taken; kept=1 is the plain farthest-point sampling."""
    rng = np.random.default_rng(1)
    centres = np.array([[0.0, 0.0], [2.0, -2.0], [-2.0, 2.0], [2.5, 2.5]])
    rows = np.vstack([c + 0.05 * rng.standard_normal((4, 2)) for c in centres])  # clusters of 4, in order
    angle = np.array([False, False])
    taken = spread_branches(rows, 7, angle, kept=4)  # the first cluster kept whole: one row of each other cluster
    assert taken[:4] == [0, 1, 2, 3] and sorted(k // 4 for k in taken[4:]) == [1, 2, 3]
    assert spread_branches(rows, 5, angle, kept=1) == spread_branches(rows, 5, angle)
    assert spread_branches(rows, 3, angle, kept=8) == [0, 1, 2]  # never more than count


def test_a_leaders_drawn_starts_kept_and_extra_ones_spread_over_the_branches_they_miss():
    """``rebranch_extra``: each leader's drawn starts stay (the first leader's the same numbers; a later leader's
    block after the earlier ones' larger blocks), and that many more join them, taken from ``rebranch_extra_pool``
    drawn in the leader's block after its drawn ones (`Search.more_start`) by `spread_branches` kept at the drawn
    ones' first configurations. The reflect step numbers its starts after all of them."""
    problem, coarse, sols, task = _two_leaders()
    plain = Search(starts=6, rebranch=2, seed=4, init="home")
    extra = replace(plain, rebranch_extra=2, rebranch_extra_pool=5)
    before = rebranched_tasks([[(task, s) for s in sols]], plain)
    after = rebranched_tasks([[(task, s) for s in sols]], extra)
    assert extra.leader_width == 3 + 5 and [extra.leader_start(0, k) for k in (0, 1)] == [6, 14]
    assert extra.more_start(0, 0, 0) == 9 and extra.more_start(0, 0, 1) == 17 and extra.last_exploration_start == 22
    assert [t.start.solution for t in after] == [sols[0]] * 5 + [sols[1]] * 5
    indices = [t.start.index for t in after]
    assert indices[:3] == [t.start.index for t in before[:3]] and indices[5:8] == [14, 15, 16]
    angle = np.array([j.kind == "angle" for j in coarse.chain.moving])
    for k, (leader, mine) in enumerate(((sols[0], indices[:5]), (sols[1], indices[5:]))):
        drawn = [Rebranched(leader, 4, j, "home") for j in mine[:3]]
        begin = extra.more_start(0, 0, k)
        pool = [Rebranched(leader, 4, j, "home") for j in range(begin, begin + 5)]
        firsts = np.array([s.first_configuration(coarse) for s in drawn + pool])
        chosen = spread_branches(firsts, 5, angle, kept=3)[3:]
        assert mine[3:] == sorted(extra.more_start(0, 0, k) + j - 3 for j in chosen)
    assert all(extra.second_round(t.seed) for t in after)
    assert "and 2 more spread over the branches those miss (of 5 drawn)" in extra.describe()
    assert "more spread" not in plain.describe()
    unmoved = replace(preset("default"), rebranch_moved=0)
    assert unmoved.last_exploration_start == 1000 and reflect.first_start(unmoved) == 1000  # 160 + 12 x (20 + 50)
    assert reflect.first_start(replace(unmoved, rebranch_extra_pool=60)) == 1200  # 160 + 12 x (20 + 60) = 1120


def test_moved_starts_join_a_leaders_other_starts_on_the_branches_those_miss():
    """``rebranch_moved``: each leader's drawn and extra starts stay as they are (the leader's design; the first
    leader's the same numbers, a later leader's block after the earlier ones' larger blocks), and that many more
    join them, drawn in the leader's block after the extras' pool (`Search.more_start`), their designs moved around
    the leader's by ``rebranch_moved_perturbation`` (within x 0.5 m / x pi rad of it), taken by `spread_branches`
    with every start before them kept. The reflect step's numbers follow theirs."""
    problem, coarse, sols, task = _two_leaders()
    extra = Search(starts=6, rebranch=2, seed=4, init="home", rebranch_extra=2, rebranch_extra_pool=5)
    moved = replace(extra, rebranch_moved=2, rebranch_moved_pool=4, rebranch_moved_perturbation=0.05)
    before = rebranched_tasks([[(task, s) for s in sols]], extra)
    after = rebranched_tasks([[(task, s) for s in sols]], moved)
    assert [moved.more_start(1, 0, k) for k in (0, 1)] == [14, 26] and moved.last_exploration_start == 30
    assert [t.start.solution for t in after] == [sols[0]] * 7 + [sols[1]] * 7
    joints = coarse.chain.design
    step = np.array([0.5 if j.kind == "length" else np.pi for j in joints]) * 0.05
    angle = np.array([j.kind == "angle" for j in coarse.chain.moving])
    assert [t.start.index for t in after[:5]] == [t.start.index for t in before[:5]]
    assert [t.start.index for t in after[7:10]] == [18, 19, 20]  # the second leader's block: 6 + (3 + 5 + 4)
    for k, leader in enumerate(sols):
        mine, kept = after[7 * k:7 * k + 7], after[7 * k:7 * k + 5]
        for t in kept:
            assert np.array_equal(t.start.design(coarse), np.asarray(leader.raw.q_d, float))
        block = [Rebranched(leader, 4, j, "home", 0.05) for j in range(moved.more_start(1, 0, k),
                                                                        moved.more_start(1, 0, k) + 4)]
        firsts = np.array([t.start.first_configuration(coarse) for t in kept] +
                          [s.first_configuration(coarse) for s in block])
        chosen = spread_branches(firsts, 7, angle, kept=5)[5:]
        assert [t.start.index for t in mine[5:]] == sorted(moved.more_start(1, 0, k) + j - 5 for j in chosen)
        q_d = np.asarray(leader.raw.q_d, float)
        for t in mine[5:]:
            d = t.start.design(coarse)
            assert np.all(np.abs(d - q_d) <= step + 1e-12) and not np.allclose(d, q_d)
    assert all(moved.second_round(t.seed) for t in after)
    assert reflect.first_start(moved) == 900
    assert reflect.first_start(preset("default")) == 1300  # 160 + 12 x (20 + 50 + 20) = 1240
    assert "and 2 more with the design moved by 0.05" in moved.describe()
    assert "moved by" not in extra.describe()


def test_extra_starts_moved_around_their_leaders_design():
    """``rebranch_extra_perturbation``: a leader's extra starts start from its design plus uniform noise of that
    scale (x 0.5 m for lengths, x pi rad for angles, within the bounds), each start its own draw (not the branch's:
    `initial_guess` draws the first configuration from (seed, index)), the same for the same (seed, index); the drawn
    starts keep the design exactly; their walks still reach the first waypoint as
    `first_configuration` says, to the bit. 0: the extras keep the design too."""
    problem, coarse, sols, task = _two_leaders()
    extra = Search(starts=6, rebranch=2, seed=4, init="home", rebranch_extra=2, rebranch_extra_pool=5)
    moved = replace(extra, rebranch_extra_perturbation=0.05)
    kept = rebranched_tasks([[(task, s) for s in sols]], extra)
    after = rebranched_tasks([[(task, s) for s in sols]], moved)
    joints = coarse.chain.design
    step = np.array([0.5 if j.kind == "length" else np.pi for j in joints]) * 0.05
    lower, upper = np.array([j.lower for j in joints]), np.array([j.upper for j in joints])
    for k, leader in enumerate(sols):
        mine = after[5 * k:5 * k + 5]
        q_d = np.asarray(leader.raw.q_d, float)
        for t in mine[:3]:
            assert np.array_equal(t.start.guess(coarse).q_d, q_d)
        designs = [t.start.guess(coarse).q_d for t in mine[3:]]
        for d, t in zip(designs, mine[3:], strict=True):
            assert np.all(np.abs(d - q_d) <= step + 1e-12) and np.all((lower <= d) & (d <= upper))
            assert not np.allclose(d, q_d)
            inside = (lower < d) & (d < upper)  # noise not clipped: its draw is not the branch's own draw
            branch = np.random.default_rng([4, t.start.index]).uniform(-1.0, 1.0, len(joints))
            assert not np.allclose(((d - q_d) / step)[inside], branch[inside])
            assert np.array_equal(t.start.first_configuration(coarse), t.start.guess(coarse).Q[0])
            again = Rebranched(leader, 4, t.start.index, "home", 0.05)
            assert np.array_equal(again.design(coarse), d)
        assert not np.allclose(designs[0], designs[1])
    for t in kept:
        assert np.array_equal(t.start.design(coarse), np.asarray(t.start.solution.raw.q_d, float))
    assert "with the design perturbed by 0.05" in moved.describe() and "perturbed by" not in extra.describe()


def test_a_snapped_design_has_its_arms_angles_on_the_lattice_and_nothing_else_moved():
    """`snapped_design`: every design angle of the arm (the DH twists here) at its nearest multiple of pi/2; the
    lengths and the placement's angles exactly as given; within bounds; snapping twice changes nothing."""
    problem = problem_from_config(parse_config({}))
    chain = problem.chain
    placement = {j.name for j in chain.placement_joints}
    arm_angle = np.array([j.kind == "angle" and j.name not in placement for j in chain.design])
    assert arm_angle.sum() == 6 and not arm_angle[[j.name for j in chain.design].index("placement.yaw")]
    rng = np.random.default_rng(3)
    lower, upper = np.array([j.lower for j in chain.design]), np.array([j.upper for j in chain.design])
    for _ in range(20):
        q = np.clip(chain.design_values + rng.uniform(-0.7, 0.7, chain.n_design), lower, upper)
        snapped = snapped_design(chain, q)
        assert np.array_equal(snapped[~arm_angle], q[~arm_angle])
        quarter = snapped[arm_angle] / (np.pi / 2)
        assert np.allclose(quarter, np.rint(quarter), atol=1e-12)
        assert np.all(np.abs(snapped[arm_angle] - q[arm_angle]) <= np.pi / 4 + 1e-12)
        assert np.all((lower <= snapped) & (snapped <= upper))
        assert np.array_equal(snapped_design(chain, snapped), snapped)


def test_extra_starts_from_their_leaders_design_snapped():
    """``rebranch_extra_snap``: a leader's extra starts start from its design with the arm's angles snapped
    (`snapped_design`), its drawn starts from its design as it is; the extras are spread over the branches with
    the snapped design's walks (`first_configuration` is each one's walk's first row, to the bit). Off: as before."""
    problem, coarse, sols, task = _two_leaders()
    joints = [j.name for j in coarse.chain.design]
    for sol in sols:  # twists a few tenths off the lattice, the placement turned: what snapping must tell apart
        sol.raw.q_d = sol.raw.q_d.copy()
        sol.raw.q_d[joints.index("link4.alpha")] += 0.2
        sol.raw.q_d[joints.index("link2.alpha")] -= 0.15
        sol.raw.q_d[joints.index("placement.yaw")] += 0.3
    extra = Search(starts=6, rebranch=2, seed=4, init="home", rebranch_extra=2, rebranch_extra_pool=5)
    snap = replace(extra, rebranch_extra_snap=True)
    assert snap.more_blocks[0] == (2, 5, 0.0, True) and extra.more_blocks[0] == (2, 5, 0.0, False)
    kept = rebranched_tasks([[(task, s) for s in sols]], extra)
    after = rebranched_tasks([[(task, s) for s in sols]], snap)
    angle = np.array([j.kind == "angle" for j in coarse.chain.moving])
    for k, leader in enumerate(sols):
        mine = after[5 * k:5 * k + 5]
        q_d = np.asarray(leader.raw.q_d, float)
        assert [t.start.index for t in mine[:3]] == [t.start.index for t in kept[5 * k:5 * k + 3]]
        for t in mine[:3]:
            assert np.array_equal(t.start.guess(coarse).q_d, q_d)
        for t in mine[3:]:
            guess = t.start.guess(coarse)
            assert np.array_equal(guess.q_d, snapped_design(coarse.chain, q_d)) and not np.allclose(guess.q_d, q_d)
            assert guess.q_d[joints.index("placement.yaw")] == q_d[joints.index("placement.yaw")]
            assert np.array_equal(t.start.first_configuration(coarse), guess.Q[0])
        begin = snap.more_start(0, 0, k)
        pool = [Rebranched(leader, 4, j, "home", 0.0, True) for j in range(begin, begin + 5)]
        firsts = np.array([t.start.first_configuration(coarse) for t in mine[:3]] +
                          [s.first_configuration(coarse) for s in pool])
        chosen = spread_branches(firsts, 5, angle, kept=3)[3:]
        assert [t.start.index for t in mine[3:]] == sorted(begin + j - 3 for j in chosen)
    for t in kept:
        assert np.array_equal(t.start.design(coarse), np.asarray(t.start.solution.raw.q_d, float))
    assert "arm's angles at the nearest multiple of pi/2" in snap.describe()
    assert "nearest multiple" not in extra.describe()


def test_a_later_round_on_new_joint_branches_starts_from_the_best_of_every_round_before_it():
    """``rebranch_rounds``: the rounds on new joint branches share the first round's count (``starts // (rebranch x
    rounds)`` per leader), each from the best distinct optima of every round before it, numbered in blocks from
    ``most_starts``, a leader's rounds side by side (`Search.leader_start`), every one of them told apart from the
    first round. Driven through the plan: the explored solves in, each round's tasks out."""
    problem = problem_from_config(parse_config({}))
    a = (0, 0, 1, 0, 1)
    search = Search(starts=4, rebranch=2, rebranch_rounds=2, seed=5)
    assert search.rebranch_starts == 1 and search.leader_width == 1  # leader k's round r: 4 + 2 k + r
    assert [search.leader_start(r, k) for k in range(2) for r in range(2)] == [4, 5, 6, 7]
    assert replace(search, rebranch_rounds=1).rebranch_starts == 2
    plan = coarse_to_fine.plan([Job("", problem)], search)
    explore = next(plan)
    first = [_optimum(problem, cost, a, shift) for cost, shift in ((3.0, 0.0), (1.0, 0.1), (2.0, 0.2), (4.0, 0.3))]
    round1 = plan.send(list(zip(explore, first, strict=True)))
    assert [t.start.solution for t in round1] == [first[1], first[2]]
    assert [t.start.index for t in round1] == [4, 6]
    found = [_optimum(problem, 0.5, a, 0.4), _optimum(problem, 5.0, a, 0.5)]  # the first leader's start did better
    round2 = plan.send(list(zip(round1, found, strict=True)))
    assert [t.start.solution for t in round2] == [found[0], first[1]]
    assert [t.start.index for t in round2] == [5, 7]
    assert all(search.second_round(t.seed) for t in round1 + round2)
    assert not any(search.second_round(t.seed) for t in explore)
    assert "in 2 rounds, each from the best of every round before it" in search.describe()
    assert "rounds" not in replace(search, rebranch_rounds=1).describe()


def test_draws_are_independent_searches_made_side_by_side():
    """``draws``: the whole search made once per draw seed (`Search.draw_seeds`: the search's own first, the others
    `DRAW_STRIDE` apart), every draw's stage given to the executor in one call and each draw's results back to it;
    a job's solves are every draw's, in start order, and its answer the best of all. Each draw solves the starts
    that search made alone solves. `thorough` is the default made three times."""
    problem = problem_from_config(parse_config({}))
    search = Search(strategy="multistart", starts=3, seed=7, draws=3, structure_neighbours=False)
    assert search.draw_seeds == [7, 7 + DRAW_STRIDE, 7 + 2 * DRAW_STRIDE]
    assert search.drawn() == [replace(search, seed=s, draws=1) for s in search.draw_seeds]

    def cost(task):  # a stand-in solve's design cost: a function of its start alone
        return 1.0 + (task.seed * 7919 % 1009) / 1009

    calls = []

    def execute(tasks):  # answers in reverse order: each draw must get its own back by key
        calls.append(tasks)
        return [(t, _optimum(problem, cost(t), (0, 0, 1, 0, 1), 0.0)) for t in reversed(tasks)]

    (searched,) = run_search([Job("", problem)], search, execute)
    numbers = sorted(start_number(s, i) for s in search.draw_seeds for i in range(3))
    assert [sorted(t.seed for t in tasks) for tasks in calls] == [numbers]
    assert [t.seed for t, _ in searched.final] == numbers
    assert searched.best[1].metrics.design_cost == min(cost(t) for t in calls[0])
    assert [search.draw_of(t.seed) for t, _ in searched.final] == [0, 0, 0, 1, 1, 1, 2, 2, 2]
    assert draw_bests(searched, search) == [min(cost(t) for t, _ in searched.final[3 * k: 3 * k + 3])
                                            for k in range(3)]
    for one in search.drawn():
        (alone,) = run_search([Job("", problem)], one, execute)
        assert [t.seed for t, _ in alone.final] == [start_number(one.seed, i) for i in range(3)]
    assert search.describe().startswith("3 independent draws (seeds 7, 1000007, 2000007), the best of them, each "
                                        "multistart: 3 seeded starts")
    assert not replace(search, draws=1).describe().startswith("3 independent")
    assert PRESETS["thorough"] == replace(PRESETS["default"], draws=3)
    rounds = Search(starts=4, rebranch=2, seed=7, draws=2)  # a start's round and leader within its own draw
    for seed in rounds.draw_seeds:
        numbers = [start_number(seed, i) for i in (0, 3, 4, 5, 6)]
        assert [rounds.index_in_draw(n) for n in numbers] == [0, 3, 4, 5, 6]
        assert [bool(rounds.second_round(n)) for n in numbers] == [False, False, True, True, True]
        assert [rounds.leader_of(n) for n in numbers] == [None, None, 0, 0, 1]
    with pytest.raises(ValueError, match="draws"):
        Search(draws=0)


def test_a_search_written_and_read_back_is_the_same_search():
    """search.json (`search_to_dict`, as JSON) read back (`search_from_dict`) is the search it was written from,
    every preset and a search with every kind of field set (tuples of numbers, of names, of option pairs, None);
    a field of another version is refused."""
    import json

    from designopt.solve.search import search_from_dict, search_to_dict

    odd = Search(rebranch_shares=(3, 2), screen_mu_init=(None, 1e-6), screen_linear_solver=("ldl", "mumps"),
                 same_arm_cost=None, draws=2, profile=SolverProfile(observers=("above_bound",), options=(
                     ("ipopt.mu_init", 1e-6), ("ipopt.alpha_for_y", "min-dual-infeas"))))
    for search in [*PRESETS.values(), odd]:
        back = search_from_dict(json.loads(json.dumps(search_to_dict(search))))
        assert back == search and back.describe() == search.describe()
    with pytest.raises(ValueError, match="Search has no field starts_per_leader"):
        search_from_dict({**search_to_dict(odd), "starts_per_leader": 3})
    with pytest.raises(ValueError, match="SolverProfile has no field tol"):
        search_from_dict({**search_to_dict(odd), "profile": {"tol": 1e-8}})


def test_plans_of_different_lengths_are_driven_stage_by_stage_together():
    """`strategies._drive`: each round, the current stage of every plan not yet done goes to one executor call
    (none when no plan has a task); each plan gets back its own tasks' results, whatever order they come in, and
    returns its answer; two plans with a solve of the same key are refused."""
    def task(key):
        return SimpleNamespace(key=key)

    def plan(stages, answer):
        got = []
        for tasks in stages:
            got.append(sorted(key for t, key in (yield tasks)))
        return answer, got

    a1, a2, b1, c2 = task("a1"), task("a2"), task("b1"), task("c2")
    calls = []

    def execute(tasks):
        calls.append([t.key for t in tasks])
        return [(t, t.key) for t in reversed(tasks)]

    answers = _drive([plan([[a1], [a2]], "A"), plan([[b1]], "B"), plan([[], [c2]], "C"), plan([], "D")], execute)
    assert calls == [["a1", "b1"], ["a2", "c2"]]
    assert answers == [("A", [["a1"], ["a2"]]), ("B", [["b1"]]), ("C", [[], ["c2"]]), ("D", [])]
    calls.clear()
    assert _drive([plan([[]], "E")], execute) == [("E", [[]])] and calls == []
    with pytest.raises(ValueError, match="share a solve"):
        _drive([plan([[a1]], "A"), plan([[task("a1")]], "A again")], execute)


def test_a_smaller_problem_of_a_batch_gets_more_exploration_starts():
    """`Search.small_problem_starts`: in a batch, a problem with fewer unknowns n (moving joints x the exploration's
    waypoints + design joints) gets starts x (n_max / n)^2, at most that factor x starts; 1 (the default), one
    problem alone, or problems of one size: ``starts`` each. The plan explores each problem with its own count, and
    the second round's starts (numbered after the most any problem gets) stay told apart from the first's."""
    sweep = load_config(Path(__file__).parent.parent / "configs" / "structures.yaml")
    rrr, six = (problem_from_config(structure_config(sweep, s)) for s in ("RRR", "RRRRRR"))
    # every link's d or theta, a, alpha and the six placement joints designed: n = 10 N + 3 N + 6
    assert (rrr.chain.n_moving, rrr.chain.n_design, six.chain.n_design) == (3, 15, 24)
    n_rrr, n_six = 10 * 3 + 15, 10 * 6 + 24
    more = Search(starts=40, small_problem_starts=4)
    assert exploration_starts([six, rrr, six], more) == [40, round(40 * (n_six / n_rrr) ** 2), 40] == [40, 139, 40]
    assert exploration_starts([rrr, six], replace(more, small_problem_starts=2)) == [80, 40]
    assert exploration_starts([rrr, six], Search(starts=40)) == [40, 40]
    assert exploration_starts([rrr], more) == exploration_starts([rrr, rrr], more)[:1] == [40]
    assert "up to 4x as many" in more.describe() and "as many" not in Search(starts=40).describe()

    jobs = [Job("", rrr), Job("", six)]
    more = replace(more, seed=3)
    explore = next(coarse_to_fine.plan(jobs, more))
    counts = {s: sum(t.problem.chain.structure == s for t in explore) for s in ("RRR", "RRRRRR")}
    assert counts == {"RRR": 139, "RRRRRR": 40}
    assert all(t.problem.toolpath.n == more.explore_waypoints for t in explore)
    assert more.most_starts == 160 and not any(more.second_round(t.seed) for t in explore)
    sol = _optimum(rrr, 1.0, (0, 0), 0.0)
    rebranched = rebranched_tasks([[(explore[0], sol)]], replace(more, rebranch=1))
    assert [t.start.index for t in rebranched] == list(range(160, 200))
    assert all(more.second_round(t.seed) for t in rebranched)


def test_a_small_arm_gets_more_exploration_starts_but_the_screen_of_its_share():
    """`Search.small_arm_starts`: an arm of fewer than `SMALL_ARM` moving joints explores with that many times its
    share of the batch's starts (`coarse_to_fine.shares`), a larger arm with its share; the screen stays the share's
    (candidates and waypoints), the second round is numbered after the most any problem gets, and the plan explores
    each problem with its count. Alone, a small arm gets that many times ``starts``."""
    sweep = load_config(Path(__file__).parent.parent / "configs" / "structures.yaml")
    rrr, rrrr, rrrrr, six = (problem_from_config(structure_config(sweep, s))
                             for s in ("RRR", "RRRR", "RRRRR", "RRRRRR"))
    base = Search(starts=40, rebranch=0, screen=12, screen_waypoints=20, small_problem_starts=4)
    more = replace(base, small_arm_starts=2)
    arms = [rrr, rrrr, rrrrr, six]
    assert shares(arms, more) == exploration_starts(arms, base) == [139, 84, 56, 40]
    assert exploration_starts(arms, more) == [278, 168, 56, 40]
    assert screening(arms, more) == screening(arms, base)
    assert exploration_starts([rrrr], replace(more, small_problem_starts=1)) == [80]
    assert exploration_starts([six], more) == [40]
    assert more.most_starts == 320 and base.most_starts == 160
    assert "2x as many for an arm of fewer than 5 joints" in more.describe()
    assert "as many for an arm" not in base.describe()
    jobs = [Job("", rrrr), Job("", six)]
    more = replace(more, seed=5)
    explore = next(coarse_to_fine.plan(jobs, more))
    counts = {s: sum(t.problem.chain.structure == s for t in explore) for s in ("RRRR", "RRRRRR")}
    assert counts == {"RRRR": 168, "RRRRRR": 40}
    assert len({t.seed for t in explore if t.problem.chain.structure == "RRRR"}) == 168
    assert not any(more.second_round(t.seed) for t in explore)


def test_the_second_round_is_told_apart_past_a_thousand_starts():
    """A start's number is seed x 1000 + index (`initial_guess.start_number`), and a config may ask for up to
    100,000 starts: `Search.second_round` reads the index back for any count, so start 1,100 of seed 3 is of the
    first round of a 1,200-start search and start 1,200 (the first rebranched) of the second, as
    `rebranched_tasks` numbers them."""
    big = Search(starts=1200, rebranch=4, seed=3)
    assert start_index(start_number(3, 1100), 3) == 1100
    assert not big.second_round(start_number(3, 1100)) and not big.second_round(start_number(3, 0))
    problem = problem_from_config(parse_config({}))
    task = Task("", "explore", problem, Collocation(), SolverProfile(), Seeded(3, 0))
    sol = _optimum(problem, 1.0, (0, 0, 1, 0, 1), 0.0)
    rebranched = rebranched_tasks([[(task, sol)]], big)
    assert [t.start.index for t in rebranched] == list(range(1200, 1500))
    assert all(big.second_round(t.seed) for t in rebranched)
    assert list(big.second_round(np.array([start_number(3, 999), start_number(3, 1199), start_number(3, 1200)]))) == [
        False, False, True]


def test_a_smaller_problem_of_a_batch_is_screened_on_more_candidates_and_waypoints():
    """`Search.small_problem_starts` and the screen (`coarse_to_fine.screening`): a problem explored with k times the
    starts screens k times the candidates, on the waypoints w that make its screen problem as large as the largest
    one's (m w + d = n_max), the full path once w reaches its count; without the factor, or alone, the search's own.
    Driven through the plan too: the explored solves in, each job's screen tasks out."""
    sweep = load_config(Path(__file__).parent.parent / "configs" / "structures.yaml")
    rrr, rrrr, six = (problem_from_config(structure_config(sweep, s)) for s in ("RRR", "RRRR", "RRRRRR"))
    assert {p.toolpath.n for p in (rrr, rrrr, six)} == {40}
    more = Search(starts=40, rebranch=0, screen=12, screen_waypoints=20, small_problem_starts=4)
    assert exploration_starts([rrr, rrrr, six], more) == [139, 84, 40]
    # on 20 waypoints six joints are 6 x 20 + 24 = 144 unknowns: RRRR (d = 18) w = 126 / 4 = 31.5 -> 32, RRR
    # (d = 15) w = 129 / 3 = 43 >= 40 waypoints: the full path; candidates 12 x 139 / 40 = 41.7 and 12 x 84 / 40 = 25.2
    assert screening([rrr, rrrr, six], more) == [(42, None), (25, 32), (12, 20)]
    assert screening([rrr, six], replace(more, small_problem_starts=1)) == [(12, 20)] * 2
    assert screening([rrrr], more) == [(12, 20)]
    assert "more, on more waypoints" in more.describe() and "more waypoints" not in Search().describe()

    plan = coarse_to_fine.plan([Job("a", rrr), Job("b", six)], more)
    explore = next(plan)
    sols = [_optimum(t.problem, float(k), (0,) * int(form_joints(t.problem.chain).sum()), 0.05 * k)
            for k, t in enumerate(explore)]
    screen = plan.send(list(zip(explore, sols, strict=True)))
    assert [sum(t.case == case for t in screen) for case in "ab"] == [42, 12]
    assert {t.problem.toolpath.n for t in screen if t.case == "a"} == {40}
    assert {t.problem.toolpath.n for t in screen if t.case == "b"} == {20}
    assert [t.start.solution for t in screen if t.case == "a"] == sols[:42]  # the cheapest distinct, in order


def test_the_screens_later_passes_are_for_arms_of_five_joints_or_more():
    """`Search.small_arm_screens_once`: the screen's passes after the first (here the second linear solver) only
    for a problem whose arm has at least `SMALL_ARM` (5) moving joints; a smaller arm is screened once, by the first
    pass's solver, on the same candidates. False (the default): every problem every pass. Driven through the plan:
    the explored solves in, each job's screen tasks out."""
    sweep = load_config(Path(__file__).parent.parent / "configs" / "structures.yaml")
    rrrr, six = (problem_from_config(structure_config(sweep, s)) for s in ("RRRR", "RRRRRR"))
    both = Search(starts=6, rebranch=0, screen=3, screen_waypoints=20, screen_linear_solver=("ldl", "mumps"))

    def screened(search):
        plan = coarse_to_fine.plan([Job("a", rrrr), Job("b", six)], search)
        explore = next(plan)
        sols = [_optimum(t.problem, float(k), (0,) * int(form_joints(t.problem.chain).sum()), 0.05 * k)
                for k, t in enumerate(explore)]
        return {(t.case, t.stage, t.profile.linear_solver, t.start.solution.metrics.design_cost)
                for t in plan.send(list(zip(explore, sols, strict=True)))}

    every = screened(both)
    assert {(case, stage, solver) for case, stage, solver, _ in every} == {
        (case, stage, solver) for case in "ab" for stage, solver in (("screen", "ldl"), ("screen2", "mumps"))}
    assert len(every) == 4 * 3
    once = replace(both, small_arm_screens_once=True)
    # RRRR: the first pass only, on the same candidates
    assert screened(once) == {t for t in every if t[0] == "b" or t[1] == "screen"}
    assert both.passes_for(1) == both.screen_passes == [(None, "ldl"), (None, "mumps")]
    assert (once.passes_for(4), once.passes_for(5)) == ([(None, "ldl")], both.screen_passes)
    assert "fewer than 5 joints the first pass only" in once.describe()
    assert "first pass only" not in both.describe()
    assert "first pass only" not in replace(once, screen_linear_solver=("ldl",)).describe()


def test_an_arm_of_fewer_than_five_joints_explores_from_wider_starts():
    """`Search.small_arm_perturbation`: the exploration's seeded starts of an arm with fewer than `SMALL_ARM` (5)
    moving joints are perturbed by it, a larger arm's by ``perturbation``; None (the default): every arm by
    ``perturbation``. A wider start is a different design: start 1 of RRRR moves from the configured design twice
    as far, the same draw, wherever neither start is clipped to a bound."""
    sweep = load_config(Path(__file__).parent.parent / "configs" / "structures.yaml")
    rrrr, rrrrr = (problem_from_config(structure_config(sweep, s)) for s in ("RRRR", "RRRRR"))
    wide = Search(starts=3, rebranch=0, small_arm_perturbation=0.6)
    explore = next(coarse_to_fine.plan([Job("a", rrrr), Job("b", rrrrr)], wide))
    assert {(t.case, t.start.scale) for t in explore} == {("a", 0.6), ("b", 0.3)}
    plain = next(coarse_to_fine.plan([Job("a", rrrr), Job("b", rrrrr)], Search(starts=3, rebranch=0)))
    assert {t.start.scale for t in plain} == {0.3}
    assert (wide.perturbation_for(4), wide.perturbation_for(5), Search().perturbation_for(1)) == (0.6, 0.3, 0.3)
    # the same draw, twice as far from the configured design wherever neither start is clipped to a bound
    home = rrrr.chain.design_values
    lo, hi = np.array([(j.lower, j.upper) for j in rrrr.chain.design]).T
    far, near = (t.start.guess(t.problem).q_d for t in (explore[1], plain[1]))
    inside = (lo < far) & (far < hi) & (lo < near) & (near < hi)
    assert inside.sum() >= len(home) // 2
    assert np.allclose((far - home)[inside], 2 * (near - home)[inside], rtol=1e-9, atol=1e-12)
    assert "fewer than 5 joints perturbed by 0.6" in wide.describe()
    assert "perturbed by" not in Search().describe()


def test_the_screen_takes_at_most_screen_per_form_of_one_form():
    """`Search.screen_per_form`: the screen lifts the distinct coarse optima in order of cost, at most that many of
    one form before those of other forms (`optima.distinct_best`'s ``per_form``); None: the cheapest by cost alone.
    Driven through the search's plan: the explored solves in, the screen's starts out."""
    problem = problem_from_config(parse_config({}))
    a, b, c = (0, 0, 1, 0, 1), (0, 0, 1, 0, 0), (1, 0, 1, 0, 1)
    sols = [_optimum(problem, cost, form, shift) for cost, form, shift in
            ((1.0, a, 0.0), (2.0, a, 0.1), (3.0, a, 0.2), (4.0, b, 0.0), (5.0, a, 0.3), (6.0, c, 0.0))]
    job = Job("", problem)

    def screened(search):
        plan = coarse_to_fine.plan([job], search)
        explore = next(plan)
        assert len(explore) == len(sols)
        return [t.start.solution for t in plan.send(list(zip(explore, sols, strict=True)))]

    base = Search(starts=6, rebranch=0, screen=3, screen_waypoints=20)
    assert problem.toolpath.n > base.screen_waypoints
    assert screened(base) == sols[:3]
    assert screened(replace(base, screen_per_form=1)) == [sols[0], sols[3], sols[5]]
    assert screened(replace(base, screen_per_form=2)) == [sols[0], sols[1], sols[3]]
    assert "at most 2 of one form" in replace(base, screen_per_form=2).describe()


def test_the_prescreen_adds_the_best_of_the_next_coarse_optima_on_more_waypoints():
    """`Search.prescreen`: the ``prescreen`` best distinct coarse optima after the screen's are lifted to
    ``prescreen_waypoints`` (stage ``prescreen``, solved as the screen's first pass: its cap and barrier), and the
    ``prescreen_keep`` of them whose prescreened optima track cheapest join the screen's candidates, each lifted
    from its coarse optimum (`best_prescreened`), from its prescreened optimum with ``screen_prescreened``
    "prescreened", both ways with "both" (the prescreened optima in passes of their own, screen3 and screen4);
    without it, or when the screen's waypoints are no more than the
    prescreen's, the screen lifts the best coarse optima alone. Driven through the plan."""
    problem = problem_from_config(parse_config({}))
    a = (0, 0, 1, 0, 1)
    job = Job("", problem)

    def optima(costs, seeds):
        return _numbered_optima(problem, costs, a, seeds)

    def explored(search):
        plan = coarse_to_fine.plan([job], search)
        explore = next(plan)
        sols = optima([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0], [t.seed for t in explore])
        return plan, sols, plan.send(list(zip(explore, sols, strict=True)))

    search = Search(starts=8, rebranch=0, screen=2, screen_waypoints=20, prescreen=4, prescreen_keep=2,
                    prescreen_waypoints=15, screen_mu_init=(1e-6, None), screen_max_iter=77)
    assert problem.toolpath.n > search.screen_waypoints
    plan, sols, pre = explored(search)
    assert {t.stage for t in pre} == {"prescreen"}
    assert [t.start.solution for t in pre] == sols[2:6]  # the 4 best distinct after the screen's 2
    assert {t.problem.toolpath.n for t in pre} == {15}
    assert {t.profile.max_iter for t in pre} == {77}
    assert {dict(t.profile.options)["ipopt.mu_init"] for t in pre} == {1e-6}  # the screen's first pass
    # on 15 waypoints the coarse 5th and 6th are the cheapest that track (the 4th does not track)
    lifted = optima([4.0, 0.5, 1.0, 3.0], [t.seed for t in pre])
    lifted[1].metrics.tracks = False
    screen = plan.send(list(zip(pre, lifted, strict=True))[::-1])  # the order solves come back in does not matter
    assert {t.stage for t in screen} == {"screen", "screen2"}
    for stage in ("screen", "screen2"):  # each lifted from its coarse optimum
        assert [t.start.solution for t in screen if t.stage == stage] == [sols[0], sols[1], sols[4], sols[5]]
    assert {t.problem.toolpath.n for t in screen} == {20}
    assert "the best 2 of the next 4 re-ranked on 15 waypoints" in search.describe()
    pairs = [(SimpleNamespace(seed=t.seed), sol) for t, sol in zip(pre, lifted, strict=True)]
    coarse = [(SimpleNamespace(seed=t.seed), sol) for t, sol in zip(pre, sols[2:6], strict=True)]
    assert [c[1] for c in coarse_to_fine.best_prescreened(coarse, pairs, 5)] == [sols[4], sols[5], sols[2]]
    # "prescreened": the screen lifts the prescreened optima themselves (10, 20, then 40 waypoints)
    assert [c[1] for c in coarse_to_fine.best_prescreened(coarse, pairs, 5, own=True)] == [lifted[2], lifted[3],
                                                                                           lifted[0]]
    for how, passes in (("prescreened", {"screen": "own", "screen2": "own"}),
                        ("both", {"screen": "coarse", "screen2": "coarse", "screen3": "own", "screen4": "own"})):
        laddered = replace(search, screen_prescreened=how)
        plan, sols, pre = explored(laddered)
        again = optima([4.0, 0.5, 1.0, 3.0], [t.seed for t in pre])
        again[1].metrics.tracks = False
        screen = plan.send(list(zip(pre, again, strict=True)))
        assert {t.stage for t in screen} == set(passes)
        for stage, starts in passes.items():
            expected = {"coarse": [sols[0], sols[1], sols[4], sols[5]], "own": [sols[0], sols[1], again[2], again[3]]}
            if how == "both" and starts == "own":
                expected["own"] = [again[2], again[3]]  # the passes of their own hold the prescreened optima alone
            assert [t.start.solution for t in screen if t.stage == stage] == expected[starts], (how, stage)
        assert {t.problem.toolpath.n for t in screen} == {20}
        # both ways of a candidate share its start number, so `better_pass` keeps its best pass of the four
        assert len({t.seed for t in screen}) == 4
    prescreened = replace(search, screen_prescreened="prescreened")
    assert "(as the screen's first pass, screened from there)" in prescreened.describe()
    assert "screened from there and from 10" in replace(search, screen_prescreened="both").describe()
    assert "screened from there" not in search.describe()
    with pytest.raises(ValueError, match="screen_prescreened must be one of coarse, prescreened, both"):
        replace(search, screen_prescreened="twice")

    for without in (replace(search, prescreen=0), replace(search, prescreen_waypoints=20)):
        _, sols, screen = explored(without)
        assert [t.start.solution for t in screen if t.stage == "screen"] == sols[:2]
    assert "re-ranked on 15" not in replace(search, prescreen=0).describe()


def test_refine_from_coarse_refines_each_refined_candidate_again_from_its_coarse_optimum():
    """`Search.refine_from_coarse`: besides a pass per barrier of ``refine_mu_init`` from the screened solutions,
    each of the ``refine`` candidates is refined once more from the coarse optimum its screen was lifted from (the
    same start number), on the full path, from the warm start's barrier, in the stage after the barriers' passes;
    the candidates the refine does not take get no such pass. Driven through the plan."""
    problem = problem_from_config(parse_config({}))
    a = (0, 0, 1, 0, 1)
    job = Job("", problem)

    def optima(costs, seeds):
        return _numbered_optima(problem, costs, a, seeds)

    def refines(search):
        plan = coarse_to_fine.plan([job], search)
        explore = next(plan)
        sols = optima([1.0, 2.0, 3.0, 4.0, 5.0, 6.0], [t.seed for t in explore])
        screen = plan.send(list(zip(explore, sols, strict=True)))
        assert [t.start.solution for t in screen] == sols[:3]
        # on the screen's waypoints the coarse 3rd screens cheapest, then the 1st; the 2nd is not refined
        screened = optima([2.5, 9.0, 0.5], [t.seed for t in screen])
        return sols, screened, plan.send(list(zip(screen, screened, strict=True))[::-1])

    search = Search(starts=6, rebranch=0, screen=3, screen_waypoints=20, refine=2, refine_mu_init=(None, 1e-6),
                    refine_from_coarse=True)
    sols, screened, refine = refines(search)
    assert [t.stage for t in refine] == ["refine", "refine", "refine2", "refine2", "refine3", "refine3"]
    assert [t.start.solution for t in refine if t.stage != "refine3"] == [screened[2], screened[0]] * 2
    assert [t.start.solution for t in refine if t.stage == "refine3"] == [sols[0], sols[2]]  # their coarse optima
    assert {t.problem.toolpath.n for t in refine} == {problem.toolpath.n}  # the full path
    third = [t for t in refine if t.stage == "refine3"]
    assert {dict(t.profile.options).get("ipopt.mu_init") for t in third} == {dict(refine[0].profile.options)
                                                                             .get("ipopt.mu_init")}
    assert "and once from its coarse optimum" in search.describe()

    _, screened, refine = refines(replace(search, refine_from_coarse=False))
    assert [t.stage for t in refine] == ["refine", "refine", "refine2", "refine2"]
    assert "from its coarse optimum" not in replace(search, refine_from_coarse=False).describe()

def test_refine_relaxed_refines_a_candidate_whose_lift_steps_too_far_through_relaxed_velocity_limits(monkeypatch):
    """`Search.refine_relaxed`: each of that many best refined candidates whose lifted start steps beyond the
    velocity limits (r > 1, `step_ratio`) is solved warm with the limits x 1.05 r (stage ``relax``), from that
    solution with x sqrt(1.05 r) and barrier 1e-6 (``relax2``), then at the problem's own limits from 1e-6 in the
    stage after the refine's passes; a candidate whose lift fits the limits gets no such pass; the relaxed solves
    are not in the answers. Driven through the plan, the step ratios given."""
    problem = problem_from_config(parse_config({}))
    a = (0, 0, 1, 0, 1)
    job = Job("", problem)
    search = Search(starts=6, rebranch=0, screen=3, screen_waypoints=20, refine=2, refine_mu_init=(None, 1e-6),
                    refine_relaxed=2)
    plan = coarse_to_fine.plan([job], search)
    explore = next(plan)
    sols = _numbered_optima(problem, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0], a, [t.seed for t in explore])
    screen = plan.send(list(zip(explore, sols, strict=True)))
    screened = _numbered_optima(problem, [2.5, 9.0, 0.5], a, [t.seed for t in screen])
    ratios = {id(screened[2]): 4.0, id(screened[0]): 0.7}  # the refine takes the 3rd (cheapest), then the 1st
    monkeypatch.setattr(coarse_to_fine, "step_ratio", lambda _, sol: ratios[id(sol)])
    relax = plan.send(list(zip(screen, screened, strict=True)))
    assert [(t.stage, t.start.solution) for t in relax] == [("relax", screened[2])]
    limits = problem.velocity_limits
    assert np.allclose(relax[0].problem.velocity_limits, 4.2 * limits)
    assert relax[0].problem.toolpath is problem.toolpath  # the full path, the same task
    assert dict(relax[0].profile.options).get("ipopt.mu_init") == dict(
        coarse_to_fine.lifted(job, screened[:1], "refine", None, search)[0].profile.options).get("ipopt.mu_init")
    first = _numbered_optima(problem, [0.4], a, [relax[0].seed])
    relax2 = plan.send(list(zip(relax, first, strict=True)))
    assert [(t.stage, t.start.solution) for t in relax2] == [("relax2", first[0])]
    assert np.allclose(relax2[0].problem.velocity_limits, np.sqrt(4.2) * limits)
    assert dict(relax2[0].profile.options)["ipopt.mu_init"] == 1e-6
    second = _numbered_optima(problem, [0.3], a, [relax[0].seed])
    refine = plan.send(list(zip(relax2, second, strict=True)))
    assert [t.stage for t in refine] == ["refine", "refine", "refine2", "refine2", "refine3"]
    assert [t.start.solution for t in refine] == [screened[2], screened[0]] * 2 + [second[0]]
    assert np.array_equal(refine[-1].problem.velocity_limits, limits)
    assert dict(refine[-1].profile.options)["ipopt.mu_init"] == 1e-6
    answers = _numbered_optima(problem, [0.6, 0.8, 0.7, 0.9, 0.5], a, [t.seed for t in refine])
    with pytest.raises(StopIteration) as done:
        plan.send(list(zip(refine, answers, strict=True)))
    assert {t.stage for t, _ in done.value.value[0].final} == {"refine", "refine2", "refine3"}
    assert "relaxed to fit its lifted start" in search.describe()
    assert "relaxed" not in replace(search, refine_relaxed=0).describe()
    assert "the best 1 once through velocity limits relaxed" in replace(search, refine_relaxed=1).describe()

    plan = coarse_to_fine.plan([job], replace(search, refine_relaxed=1))  # the best candidate's lift fits: none
    screen = plan.send(list(zip(next(plan), sols, strict=True)))
    ratios = {id(screened[2]): 0.9, id(screened[0]): 4.0}
    assert [t.stage for t in plan.send(list(zip(screen, screened, strict=True)))] == ["refine", "refine", "refine2",
                                                                                     "refine2"]


def test_refine_distinct_arms_refines_the_next_arm_in_place_of_the_same_arm_written_another_way():
    """`Search.refine_distinct_arms`: of the screened candidates, one whose arm is a cheaper one's with two twists
    turned by pi (`optima.arm_invariants`) at a screen cost within ``same_arm_cost`` is that one, so the refine
    takes the next distinct arm instead; without it (or without ``same_arm_cost``) the refine takes both
    writings. Driven through the plan."""
    problem = problem_from_config(parse_config({}))
    names = [j.name for j in problem.chain.design]
    a = (0, 0, 1, 0, 1)

    def refined(search):
        plan = coarse_to_fine.plan([Job("", problem)], search)
        explore = next(plan)
        screen = plan.send(list(zip(explore, _numbered_optima(problem, [1.0, 2.0, 3.0, 4.0], a,
                                                              [t.seed for t in explore]), strict=True)))
        screened = _numbered_optima(problem, [0.5, 0.5005, 0.9], a, [t.seed for t in screen])
        turned = screened[0].raw.q_d.copy()
        for name in ("link1.alpha", "link2.alpha"):
            turned[names.index(name)] += np.pi
        turned[names.index("link2.d")] *= -1
        screened[1].raw.q_d = turned
        refine = plan.send(list(zip(screen, screened, strict=True)))
        return [screened.index(t.start.solution) for t in refine]

    search = Search(starts=4, rebranch=0, screen=3, screen_waypoints=20, refine=2, same_arm_cost=0.002)
    assert refined(search) == [0, 1]
    assert refined(replace(search, refine_distinct_arms=True)) == [0, 2]
    assert refined(replace(search, refine_distinct_arms=True, same_arm_cost=None)) == [0, 1]
    assert "(the refine's whichever way its joint axes point)" in replace(search, refine_distinct_arms=True).describe()
    assert "whichever way" not in search.describe()


def test_step_ratio_is_the_lifted_starts_largest_step_over_what_the_velocity_limits_allow(monkeypatch):
    """`step_ratio` against a lifted start that moves one joint at k times its velocity limit between two
    waypoints and slower elsewhere: k; `relaxed_problem` scales every limit and so every step allowed, and leaves
    the problem it relaxes as it was."""
    problem = problem_from_config(parse_config({}))
    t, v = problem.toolpath.t, problem.velocity_limits
    Q = np.zeros((len(t), problem.chain.n_moving))
    Q[:, 1] = 0.5 * v[1] * t
    Q[7:, 2] = 3.0 * v[2] * (t[7] - t[6])  # one step of 3 v_max h
    monkeypatch.setattr(coarse_to_fine, "lifted_guess", lambda p, sol: InitialGuess(q_d=sol, Q=Q))
    assert coarse_to_fine.step_ratio(problem, problem.chain.design_values) == pytest.approx(3.0)
    relaxed = coarse_to_fine.relaxed_problem(problem, 2.5)
    assert np.allclose(relaxed.max_steps, 2.5 * problem.max_steps)
    assert np.array_equal(problem.velocity_limits, v)
    assert relaxed.chain is problem.chain


@pytest.fixture(scope="module")
def yaw_placed(milling_12):
    """(problem, known, single): the PUMA-560 placed by its yaw alone, the optimum over yaw by an exhaustive grid (24
    yaws, the workpiece fixed, 2 starts each), and start 0's solution (from the configured yaw)."""
    def config(design, **placement):
        c = copy.deepcopy(milling_12)
        c["design"] = design
        c["placement"].update(placement)
        return parse_config(c)

    grid = []
    for yaw in np.linspace(-np.pi, np.pi, 25)[:-1]:
        p = problem_from_config(config([], ypr=[float(yaw), 0.0, 0.0]))
        grid += [x.metrics.design_cost for x in (solve(p, index=i, max_iter=300) for i in range(2)) if x.metrics.tracks]
    problem = problem_from_config(config(["yaw"]))
    return problem, min(grid), solve(problem, max_iter=300)


def test_the_search_finds_the_optimum_a_single_start_misses(yaw_placed):
    """The PUMA-560 placed by its yaw alone: start 0 (the configured yaw) ends in a local optimum 28 % above the
    grid's optimum, the search (8 coarse starts, the best 2 refined) reaches it."""
    problem, known, single = yaw_placed
    assert single.metrics.design_cost > 1.2 * known  # one start misses it

    search = Search(starts=8, explore_waypoints=6, refine=2, profile=SolverProfile(max_iter=300))
    (searched,) = run_search([Job("", problem)], search, lambda tasks: [(t, run_task(t)) for t in tasks])
    best = searched.best[1]
    assert best is not None and best.metrics.tracks
    assert best.metrics.design_cost <= known * 1.001  # at least as good as the grid's best
    # 8 seeded starts, then each of the (up to 8) best distinct optima once more on a new joint branch
    assert 8 < len(searched.explore) <= 16 and 1 <= len(searched.final) <= 2


def test_the_hop_step_restarts_around_the_answer_and_reaches_the_optimum_it_missed(yaw_placed):
    """``hop``: when every stage before it ends in start 0's local optimum (28 % above the grid's), the hop step
    restarts around it ``hop`` times with the yaw moved by up to ``hop_perturbation`` x pi (numbered from
    `Search.hop_start`), on the screen's waypoints, refines the best ``hop_refine`` distinct on the full path, and
    the answer is the grid's optimum. The reflect step's numbers follow the hops'."""
    problem, known, single = yaw_placed
    assert single.metrics.design_cost > 1.2 * known

    def execute(tasks):  # the strategy's stages end where start 0 did; the hop step solves
        return [(task, run_task(task) if task.stage.startswith("hop") else single) for task in tasks]

    stages = []
    search = Search(starts=2, explore_waypoints=6, rebranch=0, screen_waypoints=8, refine=1, hop=4,
                    hop_incumbents=1, hop_perturbation=0.5, hop_refine=2, profile=SolverProfile(max_iter=300))
    (searched,) = run_search([Job("", problem)], search, lambda tasks: stages.append(tasks) or execute(tasks))
    assert [{task.stage for task in tasks} for tasks in stages] == [{"explore"}, {"screen"}, {"refine"}, {"hop"},
                                                                    {"hop_full"}]
    hops, refines = stages[3], stages[4]
    assert [task.start.index for task in hops] == [2, 3, 4, 5] and search.hop_start(0) == 2
    assert all(task.problem.toolpath.n == 8 and task.start.solution is single for task in hops)
    yaws = np.array([task.start.design(task.problem)[0] for task in hops])
    assert np.all(np.abs(yaws - single.raw.q_d[0]) <= 0.5 * np.pi) and len(set(yaws)) == 4
    assert len(refines) == 2 and all(task.problem is problem for task in refines)
    best_task, best = searched.best
    assert best_task.stage == "hop_full" and best.metrics.design_cost <= known * 1.001
    assert [task.stage for task, _ in searched.final] == ["refine", "hop_full", "hop_full"]
    assert "then 4 restarts around each of the best 1 distinct optima" in search.describe()
    stages.clear()  # a path of no more waypoints than the screen's: no screen, the hops on the full path, final
    (searched,) = run_search([Job("", problem)], replace(search, screen_waypoints=12),
                             lambda tasks: stages.append(tasks) or execute(tasks))
    assert [{task.stage for task in tasks} for tasks in stages] == [{"explore"}, {"refine"}, {"hop_full"}]
    assert all(task.problem is problem for task in stages[2]) and searched.best[0].stage == "hop_full"
    assert [task.stage for task, _ in searched.final] == ["refine"] + ["hop_full"] * 4
    assert "restarts around" not in replace(search, hop=0).describe()
    default = replace(preset("default"), hop=40)  # the exploration's numbers end at 1240; 1240 + 2 x 40 = 1320
    assert default.hop_start(1) == 1280 and default.last_start == 1320 and reflect.first_start(default) == 1400
    assert reflect.first_start(replace(default, hop=0)) == 1300


def test_the_hops_start_around_the_best_distinct_tracking_optima_by_rank():
    """`hop.hop_tasks`: the ``hop_incumbents`` best distinct full-path optima that track (a cheaper one that does not
    track, and a second solve of the best's optimum, are not incumbents), ``hop`` starts around each, the best's
    numbered first (`Search.hop_start`), each a `Rebranched` of its incumbent with ``hop_perturbation``."""
    problem, _, _, _ = _two_leaders()
    best, again = _optimum(problem, 1.0, (0, 0, 1, 0, 1), 0.0), _optimum(problem, 1.001, (0, 0, 1, 0, 1), 0.001)
    second, third = _optimum(problem, 2.0, (0, 0, 1, 0, 0), 0.0), _optimum(problem, 3.0, (0, 1, 1, 0, 0), 0.0)
    lost = _optimum(problem, 0.5, (1, 0, 1, 0, 0), 0.0)
    lost.metrics.tracks = False
    task = Task("", "refine", problem, Collocation(), SolverProfile(), Seeded(0, 0))
    searched = Searched(Job("", problem), [], [(task, sol) for sol in (third, lost, second, again, best)])
    search = Search(starts=6, rebranch=0, seed=4, hop=3, hop_incumbents=2, hop_perturbation=0.05)
    tasks = hop.hop_tasks(searched, 5, search)
    assert [t.start.solution for t in tasks] == [best] * 3 + [second] * 3
    assert [t.start.index for t in tasks] == [6, 7, 8, 9, 10, 11] and search.last_start == 12
    assert all(t.stage == "hop" and t.problem.toolpath.n == 5 and t.start.perturbation == 0.05 for t in tasks)
    assert all(t.start.seed == 4 for t in tasks)
    assert hop.hop_tasks(searched, None, search)[0].problem is problem  # screened on the full path: hops there


def test_a_rebranched_start_keeps_the_design_on_a_new_branch(milling_12):
    """A coarse optimum started again: the same design joints, first joints drawn over the whole circle and walked
    by IK -- most walks reach the first waypoint (a drawn configuration by itself would not, within 1 mm), on
    other branches than the optimum's own (joints radians away); the same (seed, index), the same start. (On a
    coarse path the walk's later waypoints are far apart and a branch the design was not made for often loses
    the path: the solve restores it.)"""
    problem = coarse_problem(problem_from_config(parse_config(milling_12)), 6)
    sol = solve(problem, max_iter=300)
    assert sol.metrics.tracks
    guesses = [Rebranched(sol, 3, i).guess(problem) for i in range(8)]
    first = problem.toolpath.points_W[0]
    reached = 0
    for g in guesses:
        assert np.array_equal(g.q_d, sol.raw.q_d)
        r = np.array(residual_function(problem)(g.Q[0], g.q_d, first)[0]).ravel()
        reached += np.linalg.norm(r[:3]) < problem.position_tol and np.linalg.norm(r[3:]) < problem.axis_tol
    assert reached >= 4
    assert min(np.abs(g.Q[0] - sol.raw.Q[0]).max() for g in guesses) > 1.0
    assert np.array_equal(Rebranched(sol, 3, 5).guess(problem).Q, guesses[5].Q)
    assert Rebranched(sol, 3, 5).number == 3005


def test_the_second_round_restarts_the_best_optima_on_new_branches(milling_12):
    """``rebranch``: after the seeded starts, the ``rebranch`` best distinct coarse optima, ``starts // rebranch``
    starts each, numbered after the seeded ones, on the same coarse problem and cap; all pooled for the screen.
    ``rebranch`` 0: no second round."""
    problem = problem_from_config(parse_config(milling_12))
    stages = []

    def execute(tasks):
        done = [(t, run_task(t)) for t in tasks]
        stages.append(done)
        return done

    search = Search(starts=4, explore_waypoints=6, explore_max_iter=100, rebranch=2, screen_waypoints=0, refine=1,
                    profile=SolverProfile(max_iter=200))
    (searched,) = run_search([Job("", problem)], search, execute)
    first, second = stages[0], stages[1]
    assert [t.start.number for t, _ in first] == [0, 1, 2, 3]
    leaders = [first[i][1] for i in distinct_best([s for _, s in first], 2, search.distinct)]
    assert len(second) == 2 * len(leaders) and search.rebranch_starts == 2
    assert [t.start.number for t, _ in second] == list(range(4, 4 + len(second)))
    for k, (task, _) in enumerate(second):
        assert isinstance(task.start, Rebranched) and task.start.solution is leaders[k // 2]
        assert task.stage == "explore" and task.problem is first[0][0].problem and task.profile is first[0][0].profile
        assert task.problem.toolpath.n == 6 and task.profile.max_iter == 100
    assert len(searched.explore) == 4 + len(second)

    stages.clear()
    (searched,) = run_search([Job("", problem)], replace(search, rebranch=0), execute)
    assert [t.stage for t, _ in stages[1]] == ["refine"] and len(searched.explore) == 4


def test_each_stage_keeps_its_own_iteration_cap(milling_12):
    """Exploration within explore_max_iter (and with explore_linear_solver), screening within screen_max_iter (once
    by each of screen_linear_solver and from each barrier of screen_mu_init), refinement within the profile's
    max_iter (once from each barrier of refine_mu_init): a screening solve only ranks, so a stalling one must not
    take the full budget (design only stalls there). The caps are read off the tasks each stage was given, so the
    test does not depend on which solve reaches its cap; the screen's cap is loose enough that its optima track and
    a refine follows."""
    problem = problem_from_config(parse_config(milling_12))
    search = Search(starts=4, explore_waypoints=6, explore_max_iter=100, rebranch=0, screen_waypoints=9, screen=3,
                    screen_max_iter=150, refine=1, profile=SolverProfile(max_iter=300),  # rebranch: its own test
                    explore_linear_solver="ldl", screen_linear_solver=("ldl", "mumps"), screen_mu_init=(None, 1e-7),
                    refine_mu_init=(None, 1e-6))
    done = []

    def execute(tasks):
        done.extend((t, run_task(t)) for t in tasks)
        return done[-len(tasks):]

    run_search([Job("", problem)], search, execute)
    screens = ("screen", "screen2", "screen3", "screen4")
    caps = {"explore": 100, **dict.fromkeys(screens, 150), "refine": 300, "refine2": 300}
    assert {t.stage for t, _ in done} == set(caps)
    for stage, cap in caps.items():
        assert all(t.profile.max_iter == cap for t, _ in done if t.stage == stage)
        assert max(s.raw.iterations for t, s in done if t.stage == stage) <= cap
    waypoints = {t.stage: t.problem.toolpath.n for t, _ in done}
    assert waypoints == {"explore": 6, **dict.fromkeys(screens, 9), "refine": 12, "refine2": 12}
    # the exploration and the screen their own linear solvers; each candidate screened once per screen barrier (the
    # warm start's own, then 1e-7) by each screen solver, and refined once per refine barrier (the warm start's
    # own, then 1e-6)
    solvers = {t.stage: t.profile.linear_solver for t, _ in done}
    assert solvers == {"explore": "ldl", "screen": "ldl", "screen2": "mumps", "screen3": "ldl", "screen4": "mumps",
                       "refine": "mumps", "refine2": "mumps"}
    barriers = {t.stage: dict(t.profile.options).get("ipopt.mu_init") for t, _ in done}
    assert barriers == {"explore": None, "screen": None, "screen2": None, "screen3": 1e-7, "screen4": 1e-7,
                        "refine": None, "refine2": 1e-6}
    starts = {stage: sorted(t.seed for t, _ in done if t.stage == stage) for stage in (*screens, "refine", "refine2")}
    # as many candidates as the exploration found distinct tracking optima, up to 3 (its 4 starts end in 2 or 3
    # distinct optima, depending on the machine's libm: the solves are chaotic in their last bits)
    explored = [(t, s) for t, s in done if t.stage == "explore"]
    candidates = distinct_best([s for _, s in explored], search.screen, search.distinct)
    assert all(starts[stage] == sorted(explored[i][0].seed for i in candidates) for stage in screens)
    assert len(candidates) >= 2
    assert starts["refine"] == starts["refine2"] and len(starts["refine"]) == 1
    # the refines start from the cheapest of every screened solve, from any pass
    screened = [s for t, s in done if t.stage in screens and s.metrics.tracks]
    cheapest = min(screened, key=lambda s: s.metrics.design_cost)
    assert all(t.start.solution is cheapest for t, _ in done if t.stage in ("refine", "refine2"))
    assert all(t.profile.warm for t, _ in done if t.stage != "explore")


def test_the_refine_ranks_every_screen_pass_together(milling_12):
    """With two screen barriers, each candidate is ranked by its better pass: here the second pass's solves are made
    to look cheaper (their design cost halved), so the refine must start from the cheapest of them; from the first
    pass's if the second is made dearer. Two refines start from two candidates, never from both passes of one (a
    solve's files are named by stage and start)."""
    problem = problem_from_config(parse_config(milling_12))
    search = Search(starts=4, explore_waypoints=6, explore_max_iter=100, rebranch=0, screen_waypoints=9, screen=2,
                    screen_max_iter=150, refine=1, profile=SolverProfile(max_iter=300),
                    screen_mu_init=(None, 1e-6))
    for factor, favoured, refine in ((0.5, "screen2", 1), (2.0, "screen", 1), (1.0, None, 2)):
        done = []

        def execute(tasks, factor=factor, done=done):
            out = []
            for t in tasks:
                sol = run_task(t)
                if t.stage == "screen2":
                    sol = replace(sol, metrics=replace(sol.metrics, design_cost=factor * sol.metrics.design_cost))
                out.append((t, sol))
            done.extend(out)
            return out

        run_search([Job("", problem)], replace(search, refine=refine), execute)
        by_stage = {}
        for t, sol in done:
            by_stage.setdefault(t.stage, []).append(sol)
        assert len(by_stage["screen"]) == len(by_stage["screen2"]) >= 1
        refined = [t.start.solution for t, _ in done if t.stage == "refine"]
        seeds = [s.raw.seed for s in refined]
        assert len(refined) == refine and len(set(seeds)) == len(seeds)
        if favoured:
            cheapest = min((s for s in by_stage[favoured] if s.metrics.tracks), key=lambda s: s.metrics.design_cost)
            assert refined[0] is cheapest


@settings(max_examples=60, deadline=None)
@given(starts=st.lists(st.integers(1, 12), min_size=1, max_size=12), workers=st.integers(1, 4))
@example(starts=[12], workers=1)  # one problem whose starts a piecewise split would cut (12 // 4 = 3 a unit)
def test_a_problems_starts_go_to_few_workers(starts, workers):
    """`units`: every task dispatched exactly once, in its order; a unit holds one problem's starts only; with
    several problems, starts are grouped in pieces of at most a quarter of a worker's share, cut only where that
    cap forces it (so a worker builds few problems' NLPs); one problem goes out a start per unit."""
    problems = [object() for _ in starts]
    profile, transcription = SolverProfile(), Collocation()
    tasks = [Task("c", "explore", p, transcription, profile, Seeded(0, i))
             for p, n in zip(problems, starts, strict=True) for i in range(n)]
    dispatched = units(tasks, workers)
    flat = [t for u in dispatched for t in u]
    assert sorted(map(id, flat)) == sorted(map(id, tasks))
    for u in dispatched:
        assert len({id(t.problem) for t in u}) == 1
        assert [t.start.index for t in u] == sorted(t.start.index for t in u)
    if len(problems) == 1:
        assert all(len(u) == 1 for u in dispatched)
    else:
        most = max(1, len(tasks) // (4 * workers))
        assert all(len(u) <= most for u in dispatched)
        assert len(dispatched) == sum(-(-n // most) for n in starts)


def test_a_bound_stops_a_feasible_solve_still_above_it_and_nothing_else():
    from designopt.solve.observers import AboveBound, Bound, Iterate

    watch = AboveBound(None)
    q_d = np.zeros(3)
    for bound, iterate, expected in [
        (None, Iterate(q_d, 9.0, 0.0), False),  # no bound: never
        (Bound(1.0, 300), Iterate(q_d, 1.5, 0.0), True),  # feasible and above it
        (Bound(1.0, 300), Iterate(q_d, 0.5, 0.0), False),  # below it: on its way to beat it
        (Bound(1.0, 300), Iterate(q_d, 9.0, 0.1), False),  # not yet feasible: its objective says nothing
        (Bound(1.0, 100), Iterate(q_d, 1.5, 0.0), True),  # the bound says when it applies
    ]:
        watch.reset(bound)
        after = bound.after if bound else 300
        steps = [watch.observe(iterate, 5) for _ in range(after // 5)]
        assert steps[:-1] == [False] * (len(steps) - 1)  # never before `after` iterations
        assert steps[-1] is expected and watch.stopped is expected


def test_a_stalled_violation_stops_a_solve_and_a_falling_or_feasible_one_never():
    from designopt.solve.observers import Iterate, StalledViolation

    def stops_at(violations, patience=50):
        """The iteration (observed every 5th) at which the watch stops a solve with these violations, or None."""
        watch = StalledViolation(None, patience=patience)
        for k, v in enumerate(violations, start=1):
            if watch.observe(Iterate(np.zeros(2), 1.0, v), 5):
                return 5 * k
        return None

    assert stops_at([0.3] * 40) == 5 + 50  # flat above 1 mm: the first look sets where it stands, 50 more stop it
    assert stops_at([0.3 * 0.9**k for k in range(400)]) is None  # halves every 7 looks (35 iterations): never
    assert stops_at([0.3] * 9 + [0.14] * 9 + [0.06] * 9 + [0.02] * 9) is None  # each pause shorter than patience
    assert stops_at([5e-4] * 400) is None  # tracks (violation <= 1e-3): never, however long
    assert stops_at([5e-4] * 20 + [0.3] * 40) == 5 * 20 + 50  # off the path again after 100, and stuck there
    assert stops_at([0.3] * 9 + [0.2] * 40) == 5 + 50  # falling by less than half is not falling
    assert stops_at([0.3] * 40, patience=100) == 5 + 100
    # nearly back on the path (2 mm, the lowest yet), a step away, then on its way back (20 % a look, so halved
    # within the patience however it is counted), never below half the lowest before its patience is up: not stopped
    assert stops_at([0.3] * 2 + [2e-3] + [0.2] * 2 + [0.2 * 0.8**k for k in range(60)]) is None
    assert stops_at([0.3] * 2 + [2e-3] + [0.2] * 30) == 5 * 3 + 50  # ... and when it stays away: stopped
    assert stops_at([0.3, 0.2, 0.3, 0.25] * 10) == 5 + 50  # spikes that never halve it: stopped


def test_a_cold_start_that_stalls_off_the_path_stops_with_its_status(milling_12, monkeypatch):
    """The placement alone is designed, from 2 m away: IPOPT gets within centimetres of the path, stays there and
    declares the problem infeasible after ~300 iterations; the watch stops it once it has stalled for its patience
    (here after ~90), having lost nothing (neither tracks). From 1.5 m the approach is slower and, on some
    machines' libm, still falling by half every 80 iterations when IPOPT gives up (173 iterations): no stall."""
    from designopt.solve.observers import StalledViolation

    cfg = copy.deepcopy(milling_12)
    cfg["design"], cfg["placement"]["xyz"] = ["placement"], [2.0, 0.0, -0.2]
    problem = problem_from_config(parse_config(cfg))
    guess = initial_guess(problem, 0, 0, 0.3)
    free = solve_guess(problem, Collocation(), SolverProfile(max_iter=1500), guess)
    assert not free.metrics.tracks and free.raw.iterations > 150
    monkeypatch.setattr(StalledViolation, "PATIENCE", 50)
    watched = solve_guess(problem, Collocation(), SolverProfile(max_iter=1499, observers=("stalled_violation",)),
                          guess)
    assert watched.raw.status == "Stopped_On_Stalled_Violation" and not watched.metrics.tracks
    assert 50 <= watched.raw.iterations < free.raw.iterations


def test_multistart_watches_exact_tracking_starts_for_a_stalled_violation_and_nothing_else(milling_12):
    from designopt.solve.strategies import multistart
    from designopt.transcriptions.forward_kinematics import ForwardKinematics

    problem = problem_from_config(parse_config(milling_12))
    search = preset("paper", starts=2)
    jobs = [Job("", problem), Job("", problem, ForwardKinematics())]
    tasks = next(multistart.plan(jobs, search))
    assert len(tasks) == 4
    assert ["stalled_violation" in t.profile.observers for t in tasks] == [True, True, False, False]
    assert all(t.profile.max_iter == 1500 and t.profile.options == search.profile.options for t in tasks)


def test_a_solve_given_a_bound_stops_at_it_with_its_status(milling_12):
    from designopt.solve.observers import Bound

    problem = coarse_problem(problem_from_config(parse_config(milling_12)), 6)
    profile = SolverProfile(max_iter=500, observers=("above_bound",))
    guess = initial_guess(problem, 1, 0, 0.3)
    free = solve_guess(problem, Collocation(), profile, guess)
    assert free.raw.status == "Solve_Succeeded" and free.raw.iterations > 30
    held = solve_guess(problem, Collocation(), profile, guess, bound=Bound(0.5 * free.raw.objective, 20))
    assert held.raw.status == "Stopped_Above_Bound" and 20 <= held.raw.iterations < free.raw.iterations
    assert held.raw.objective > 0.5 * free.raw.objective
    again = solve_guess(problem, Collocation(), profile, guess, bound=Bound(100.0 * free.raw.objective, 20))
    assert again.raw.status == "Solve_Succeeded" and again.raw.iterations == free.raw.iterations


def _placed_elsewhere(solution, cost: float, **moves):
    """``solution``'s stand-in with the same arm, its placement joints moved by ``moves`` (name: amount, metres or
    radians), at design cost ``cost``."""
    chain = solution.problem.chain
    q = solution.raw.q_d.copy()
    for name, amount in moves.items():
        q[[j.name for j in chain.design].index(f"placement.{name}")] += amount
    return SimpleNamespace(problem=solution.problem, metrics=SimpleNamespace(tracks=True, design_cost=cost),
                           raw=SimpleNamespace(q_d=q))


def test_the_same_arm_placed_elsewhere_at_the_same_cost_is_one_optimum():
    """``same_arm_cost``: an optimum whose arm (every design joint but the placement's, `arm_joints`) lies within
    ``tol`` of a cheaper one's and whose cost is within that fraction of it joins it, however far its placement
    (a copy turned about a circle's axis); a cost further off, an arm moved by more than ``tol``, or an arm
    without design joints (a fixed robot's placements: a tie in cost alone) keeps them apart; None: as before."""
    problem = problem_from_config(parse_config({}))
    chain = problem.chain
    arm = arm_joints(chain)
    names = [j.name for j in chain.design]
    assert [n for n, a in zip(names, arm, strict=True) if not a] == [n for n in names if n.startswith("placement.")]
    assert arm.sum() == len(names) - 6
    best = _optimum(problem, 1.0, (0, 0, 1, 0, 1), 0.0)
    sols = [best,
            _placed_elsewhere(best, 1.0015, yaw=2.1, x=-0.3),  # a copy: the same arm, 0.15 % dearer
            _placed_elsewhere(best, 1.01, yaw=2.1),  # the same arm 1 % dearer: another optimum
            _optimum(problem, 1.0005, (0, 0, 1, 0, 1), 0.1),  # another arm at the same cost
            _placed_elsewhere(_optimum(problem, 1.0, (0, 0, 1, 0, 1), 0.015), 1.001, y=0.4)]  # arm 15 mm off
    assert distinct_best(sols, 10) == [0, 3, 4, 1, 2]
    assert distinct_best(sols, 10, same_arm_cost=0.002) == [0, 3, 2]
    assert distinct_best(sols, 2, same_arm_cost=0.002) == [0, 3]
    assert distinct_best(sols, 10, same_arm_cost=0.02) == [0, 3]
    costs = np.array([s.metrics.design_cost for s in sols])
    designs = np.array([s.raw.q_d for s in sols])
    angle = np.array([j.kind == "angle" for j in chain.design])
    assert list(cluster_designs(designs, costs, angle, 0.02, arm, 0.002)) == [0, 0, 2, 1, 0]

    placed = problem_from_config(parse_config({"design": ["placement"]}))
    assert not arm_joints(placed.chain).any()
    fixed = [SimpleNamespace(problem=placed, metrics=SimpleNamespace(tracks=True, design_cost=1.0 + 1e-4 * k),
                             raw=SimpleNamespace(q_d=placed.chain.design_values + 0.3 * k)) for k in range(3)]
    assert distinct_best(fixed, 3, same_arm_cost=0.002) == [0, 1, 2]

    task = Task("", "explore", problem, Collocation(), SolverProfile(), Seeded(0, 0))
    search = Search(starts=6, rebranch=3, same_arm_cost=0.002)
    tasks = rebranched_tasks([[(task, s) for s in sols]], search)
    assert [t.start.solution for t in tasks[:: search.rebranch_starts]] == [sols[0], sols[3], sols[2]]
    screened = coarse_to_fine.lifted_tasks([Job("", problem)], [[(task, s) for s in sols]], 3, "screen", None, search)
    assert [t.start.solution for t in screened] == [sols[0], sols[3], sols[2]]
    assert reflect.leading(sols, best, 1.005, search) == [sols[0], sols[3]]
    assert reflect.leading(sols, best, 1.005, Search()) == [sols[0], sols[3], sols[4], sols[1]]
    assert "the same arm within 0.2% of a cheaper one's cost one optimum" in search.describe()
    assert "the same arm" not in Search().describe()
