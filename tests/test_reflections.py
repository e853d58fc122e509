"""Reflections of a DH arm (`designopt.kinematics.reflections`) and the search's reflect stage.

Independent truth: forward kinematics and the geometric Jacobian of the chain itself (the same arm must put the tool
in the same place, with the same axis and compliance), a reflection applied twice is the identity, and on a problem
whose optimum is known a design held at a length bound is carried back to it.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from designopt.config import parse_config
from designopt.initial_guess import projected
from designopt.kinematics.chain import geometric_jacobian, tool_pose
from designopt.kinematics.reflections import Reflection, at_bound, reflections, wrap
from designopt.problem import problem_from_config
from designopt.solve.local import solve_guess
from designopt.solve.optima import arm_invariants, distinct_best
from designopt.solve.profile import SolverProfile
from designopt.solve.search import PRESETS, Job, Search
from designopt.solve.strategies import reflect, run_search
from designopt.solve.tasks import run_task
from designopt.transcriptions import Collocation
from designopt.transcriptions.base import InitialGuess

ROOT = Path(__file__).resolve().parent.parent
CHAIN = problem_from_config(parse_config({})).chain  # 6R, every d, a, alpha and the placement designed


def test_every_reflection_of_a_designed_dh_arm_is_listed():
    """d-reflections of links 2-6 (link 1's would turn the placement), a-reflections of links 1-6; none when the
    twists are not design joints or the chain has no DH table."""
    assert [r.name for r in reflections(CHAIN)] == [f"link{j}.d" for j in range(2, 7)] + [
        f"link{i}.a" for i in range(1, 7)]
    lengths_only = problem_from_config(parse_config({"design": ["d", "a"]})).chain
    assert reflections(lengths_only) == []
    assert reflections(replace(CHAIN, dh=None)) == []


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_a_reflected_arm_is_the_same_arm(seed):
    """For a random design and configuration, each reflection leaves the tool pose as it was (the last link's
    a-reflection turns the tool frame by pi about its own z axis: the tool point and axis stay), and the
    compliance J J^T too; applied twice, it gives the design back, and the joints up to whole turns."""
    rng = np.random.default_rng(seed)
    design = CHAIN.design
    q_d = np.array([rng.uniform(max(j.lower, -1.0), min(j.upper, 1.0)) for j in design])
    q_m = rng.uniform(-np.pi, np.pi, CHAIN.n_moving)
    T, J = tool_pose(CHAIN, q_m, q_d), geometric_jacobian(CHAIN, q_m, q_d)
    for r in reflections(CHAIN):
        q_d2 = r.design(CHAIN, q_d)
        q_m2 = r.joints(CHAIN, q_m[None, :])[0]
        T2, J2 = tool_pose(CHAIN, q_m2, q_d2), geometric_jacobian(CHAIN, q_m2, q_d2)
        np.testing.assert_allclose(T2[:3, 3], T[:3, 3], atol=1e-12, err_msg=r.name)
        np.testing.assert_allclose(T2[:3, 2], T[:3, 2], atol=1e-12, err_msg=r.name)
        turned = r.name == "link6.a"
        np.testing.assert_allclose(T2[:3, :2], -T[:3, :2] if turned else T[:3, :2], atol=1e-12, err_msg=r.name)
        np.testing.assert_allclose(J2 @ J2.T, J @ J.T, atol=1e-12, err_msg=r.name)
        assert q_d2[r.length(CHAIN)] == -q_d[r.length(CHAIN)]
        angles = np.array([j.kind == "angle" for j in design])
        assert np.all(np.abs(q_d2[angles]) <= np.pi)
        back = r.design(CHAIN, q_d2)
        np.testing.assert_allclose(wrap(back - q_d), 0.0, atol=1e-12)
        np.testing.assert_allclose(wrap(r.joints(CHAIN, q_m2[None, :])[0] - q_m), 0.0, atol=1e-12)
        V = rng.standard_normal((3, CHAIN.n_moving))
        np.testing.assert_allclose(np.abs(r.velocities(CHAIN, V)), np.abs(V))


def _twists_turned(q_d, q_m, first: int, last: int):
    """The same arm written another way: link ``first``'s twist and link ``last``'s turned by pi, every offset d
    and joint angle theta of the links between (``first`` + 1 .. ``last``) negated: Rx(pi) commutes with Tx and
    turns Rz(theta) Tz(d) into Rz(-theta) Tz(-d), and two half turns about x cancel."""
    names = [j.name for j in CHAIN.design]
    q_d, q_m = np.array(q_d, float), np.array(q_m, float)
    for link in (first, last):
        k = names.index(f"link{link}.alpha")
        q_d[k] = wrap(q_d[k] + np.pi)
    for link in range(first + 1, last + 1):
        q_d[names.index(f"link{link}.d")] *= -1
        q_m[link - 1] *= -1
    return q_d, q_m


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_one_arm_written_several_ways_has_one_row_of_invariants(seed):
    """`optima.arm_invariants`: every reflection of a design, and its twists turned by pi on two links with the
    offsets between them negated (the tool pose the same: forward kinematics), give the design's row; the
    placement is not in it, and changing a length or the angle between two joint axes changes it."""
    rng = np.random.default_rng(seed)
    q_d = np.array([rng.uniform(max(j.lower, -1.0), min(j.upper, 1.0)) for j in CHAIN.design])
    q_m = rng.uniform(-np.pi, np.pi, CHAIN.n_moving)
    row = arm_invariants(CHAIN, q_d)
    names = [j.name for j in CHAIN.design]
    assert row.shape == (1, len(names) - 6)
    for r in reflections(CHAIN):
        np.testing.assert_allclose(arm_invariants(CHAIN, r.design(CHAIN, q_d)), row, atol=1e-12, err_msg=r.name)
    first, last = sorted(rng.choice(np.arange(1, 7), 2, replace=False))
    q_d2, q_m2 = _twists_turned(q_d, q_m, first, last)
    T, T2 = tool_pose(CHAIN, q_m, q_d), tool_pose(CHAIN, q_m2, q_d2)
    np.testing.assert_allclose(T2, T, atol=1e-12)
    np.testing.assert_allclose(arm_invariants(CHAIN, q_d2), row, atol=1e-12)
    placed = q_d.copy()
    placed[names.index("placement.x")] += 0.5
    np.testing.assert_allclose(arm_invariants(CHAIN, placed), row)
    longer = q_d.copy()
    longer[names.index("link3.a")] += 0.05  # a >= 0
    turned = q_d.copy()
    between = np.mod(q_d[names.index("link2.alpha")], np.pi)
    between = min(between, np.pi - between)  # the angle between link 2's and link 3's axis lines
    turned[names.index("link2.alpha")] = between + (0.3 if between <= np.pi / 4 else -0.3)
    for other in (longer, turned):
        assert np.max(np.abs(arm_invariants(CHAIN, other) - row)) > 0.02


# the main job's 1.031x family as the search finds it (seed 1887's answer, rounded): offsets of about 1 mm, where the
# arm's own symmetry puts them
RUNNER_UP_DH = [(0.0007, 0.1733, -0.0003), (0.0007, 0.1972, 0.0), (0.0007, 0.0246, -1.5710), (0.0012, 0.1947, 3.1415),
                (0.0004, 0.2038, 3.13), (0.0012, 0.0009, -1.56)]


def test_the_same_arm_written_another_way_at_the_same_cost_is_one_optimum_when_axes_may_point_either_way():
    """`optima.distinct_best` with ``any_axis_direction``: the main job's 1.031x arm and the same arm with its first
    and fifth twists turned by pi (the offsets between written at +1 mm, as the bound d >= 0 keeps them: the same
    arm within 2.4 mm), 0.1 % dearer, are one optimum, so the next distinct arm takes the second place; joint by
    joint they are two, and a cost 1 % off keeps them two either way."""
    full = problem_from_config(parse_config({}))
    names = [j.name for j in full.chain.design]
    q_d = full.chain.design_values.copy()
    for i, (d, a, alpha) in enumerate(RUNNER_UP_DH, start=1):
        q_d[[names.index(f"link{i}.{p}") for p in ("d", "a", "alpha")]] = d, a, alpha
    turned, _ = _twists_turned(q_d, np.zeros(6), 1, 5)
    turned[[names.index(f"link{i}.d") for i in range(2, 6)]] *= -1  # back within d >= 0
    other = q_d.copy()
    other[names.index("link3.a")] += 0.05

    def stand_in(q, cost):
        return SimpleNamespace(problem=full, metrics=SimpleNamespace(tracks=True, design_cost=cost),
                               raw=SimpleNamespace(q_d=q))

    sols = [stand_in(q_d, 1.0), stand_in(turned, 1.001), stand_in(other, 1.004)]
    assert distinct_best(sols, 2, same_arm_cost=0.002) == [0, 1]
    assert distinct_best(sols, 2, same_arm_cost=0.002, any_axis_direction=True) == [0, 2]
    assert distinct_best(sols, 2, any_axis_direction=True) == [0, 1]  # without same_arm_cost: joint by joint
    dearer = [sols[0], stand_in(turned, 1.01), sols[2]]
    assert distinct_best(dearer, 3, same_arm_cost=0.002, any_axis_direction=True) == [0, 2, 1]


def test_a_reflection_that_would_turn_a_joint_out_of_its_bounds_does_not_apply():
    """An a-reflection turns theta by pi whichever way stays within the joint's bounds (+-2 pi), none if neither."""
    r = Reflection("a", 2)
    Q = np.zeros((3, 6))
    Q[:, 1] = [-1.9 * np.pi, 0.0, 1.9 * np.pi]  # a half turn either way leaves +-2 pi somewhere
    assert r.joints(CHAIN, Q) is None
    Q[:, 1] = [-1.5, 0.0, 1.5]
    Q[:, 2] = [1.5 * np.pi, 1.6 * np.pi, 1.7 * np.pi]
    turned = r.joints(CHAIN, Q)
    np.testing.assert_allclose(turned[:, 1], Q[:, 1] + np.pi)
    np.testing.assert_allclose(turned[:, 2], Q[:, 2] - np.pi)


def test_only_lengths_near_their_bound_of_zero_are_reflected():
    q_d = CHAIN.design_values.copy()
    names = [j.name for j in CHAIN.design]
    q_d[[names.index(n) for n in ("link2.d", "link3.d", "link4.d", "link5.d", "link6.d")]] = [0.0, 0.005, 0.02, 0.3,
                                                                                                0.01]
    q_d[[names.index(f"link{i}.a") for i in range(1, 7)]] = [0.2, 0.2, 1e-9, 0.2, 0.2, 0.2]
    assert [r.name for r in at_bound(CHAIN, q_d, 0.01)] == ["link2.d", "link3.d", "link6.d", "link3.a"]


# the main job's best design known (rounded): its link 4 offset d4 = 0.149 m; the same arm with link 4 d-reflected
# needs d4 = -0.149 m, which the bound d >= 0 forbids
BEST_DH = [(0.0007, 0.1800, -0.0038), (0.0007, 0.1901, 0.0016), (0.0007, 0.1007, -1.5735), (0.1489, 0.1884, -0.0044),
           (0.1489, 0.0697, 1.5715), (0.0021, 0.0958, -1.5725)]
BEST_Q0 = [0.05, 2.99, 2.89, 3.14, -3.14, -1.28]  # its first configuration


def _held_problem():
    """The main job on 12 waypoints with the best design known's DH table, only link 3's twist, link 4's d and twist
    and the placement designed."""
    cfg = yaml.safe_load((ROOT / "configs" / "milling.yaml").read_text())
    cfg["toolpath"]["waypoints"] = 12
    cfg["robot"]["dh"] = [{"theta": 0.0, "d": d, "a": a, "alpha": al} for d, a, al in BEST_DH]
    cfg["placement"]["xyz"], cfg["placement"]["ypr"] = [0.0707, 0.2189, 0.0023], [1.5016, 0.0040, -1.5723]
    cfg["design"] = ["link3.alpha", "link4.d", "link4.alpha", "placement"]
    return problem_from_config(parse_config(cfg))


@pytest.fixture(scope="module")
def held_problem():
    """(problem, optimum, held): the held problem (`_held_problem`), its optimum from the best design known's own
    basin, and the worse optimum from that optimum's link-4 d-reflection with d4 clipped to the bound."""
    problem = _held_problem()
    chain, t = problem.chain, problem.toolpath.t
    profile = SolverProfile(max_iter=500).warmed()
    walk = projected(problem, chain.design_values, np.tile(BEST_Q0, (len(t), 1)))
    optimum = solve_guess(problem, Collocation(), profile, InitialGuess(q_d=chain.design_values, Q=walk))
    d4 = Reflection("d", 4)
    q_d = d4.design(chain, optimum.raw.q_d)
    q_d[d4.length(chain)] = 0.0
    Q = d4.joints(chain, optimum.sample(t))
    held = solve_guess(problem, Collocation(), profile, InitialGuess(q_d=q_d, Q=projected(problem, q_d, Q)))
    return problem, optimum, held


@pytest.mark.parametrize("strategy", ["coarse_to_fine", "multistart"])
def test_a_design_held_at_a_length_bound_is_reflected_back_to_its_optimum(strategy, held_problem):
    """From the best design known's own basin, the optimum of the held problem; from its link-4 d-reflection with d4
    clipped to the bound, a worse optimum with d4 at the bound. The reflect step (`Search.reflect`), after either
    strategy, reflects that solution's d4 and solves warm: it reaches the optimum (the same design cost and design),
    and a second round from the new best has nothing at a bound to reflect, so the step ends there."""
    problem, optimum, held = held_problem
    assert optimum.metrics.tracks and held.metrics.tracks
    assert held.metrics.design_cost > 1.2 * optimum.metrics.design_cost
    assert [r.name for r in at_bound(problem.chain, held.raw.q_d, 0.01)] == ["link4.d"]

    def execute(tasks):  # the explore and refine stages end where the held solve did; the reflect stage solves
        return [(task, run_task(task) if task.stage.startswith("reflect") else held) for task in tasks]

    stages = []
    search = Search(strategy=strategy, starts=2, explore_waypoints=6, rebranch=0, screen_waypoints=0, refine=1,
                    reflect=3, profile=SolverProfile(max_iter=500))
    (searched,) = run_search([Job("", problem)], search, lambda tasks: stages.append(tasks) or execute(tasks))
    before = [{"explore"}, {"refine"}] if strategy == "coarse_to_fine" else [{"start"}]
    assert [{task.stage for task in tasks} for tasks in stages] == [*before, {"reflect"}]
    assert [task.start.reflection.name for task in stages[-1]] == ["link4.d"]
    best = searched.best[1]
    assert best is not held
    np.testing.assert_allclose(best.metrics.design_cost, optimum.metrics.design_cost, rtol=1e-5)
    np.testing.assert_allclose(best.raw.q_d, optimum.raw.q_d, atol=1e-4)
    assert "reflected across its length bounds (up to 3 rounds)" in search.describe()
    assert "reflected" not in replace(search, reflect=0).describe()


def _second_optimum_search(problem, optimum, held, within):
    """The stages a multistart of 3 starts with ``reflect_within`` = ``within`` runs when its starts end at
    ``optimum``, ``held`` and ``held`` again (the same optimum twice), the reflect stage solving."""
    answers = {0: optimum, 1: held, 2: held}

    def execute(tasks):
        return [(t, run_task(t) if t.stage.startswith("reflect") else answers[t.start.index]) for t in tasks]

    stages = []
    search = Search(strategy="multistart", starts=3, reflect=3, reflect_within=within,
                    profile=SolverProfile(max_iter=500))
    (searched,) = run_search([Job("", problem)], search, lambda tasks: stages.append(tasks) or execute(tasks))
    return stages, searched


def test_a_second_optimum_at_a_length_bound_is_reflected_when_near_the_best(held_problem):
    """The best optimum has no length at a bound and the second (d4 held at 0, 1.2-2x its cost) has: the reflect
    step that reflects the best alone solves nothing; with ``reflect_within`` above the second's ratio the first round
    reflects it too (once, though two starts ended there: one optimum), numbered after the best's reflections, and
    the answer is the optimum; with ``reflect_within`` below the ratio, nothing again."""
    problem, optimum, held = held_problem
    ratio = held.metrics.design_cost / optimum.metrics.design_cost
    assert 1.2 < ratio < 2.0 and not at_bound(problem.chain, optimum.raw.q_d, 1e-4)
    stages, searched = _second_optimum_search(problem, optimum, held, None)
    assert [{t.stage for t in tasks} for tasks in stages] == [{"start"}]
    assert searched.best[1] is optimum
    stages, _ = _second_optimum_search(problem, optimum, held, 0.99 * ratio)
    assert [{t.stage for t in tasks} for tasks in stages] == [{"start"}]
    stages, searched = _second_optimum_search(problem, optimum, held, 2.0)
    assert [{t.stage for t in tasks} for tasks in stages] == [{"start"}, {"reflect"}]
    (task,) = stages[1]
    assert task.start.solution is held and task.start.reflection.name == "link4.d"
    assert task.start.index == reflect.FIRST_START + reflect.LEADER_STRIDE
    (solved,) = [sol for t, sol in searched.final if t is task]
    np.testing.assert_allclose(solved.metrics.design_cost, optimum.metrics.design_cost, rtol=1e-5)
    assert "every distinct optimum within 2x of the best" in replace(PRESETS["default"], reflect_within=2.0).describe()
