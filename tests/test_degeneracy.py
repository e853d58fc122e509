"""Degenerate designs (issue 12, cause 3): the tracking rows that stop depending on the joints when every joint
axis is parallel to the workpiece normal, holding a design there, the watch that stops a creeping solve, and
the design-only stall this fixes."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import gantry_config, solve

from designopt.config import parse_config
from designopt.evaluation import evaluate
from designopt.initial_guess import initial_guess
from designopt.kinematics.chain import tool_pose
from designopt.problem import problem_from_config
from designopt.solve import Search
from designopt.solve.observers import DegenerateWatch, Iterate
from designopt.transcriptions.degeneracy import held_at_multiples_of_pi, q_independent_rows

ROOT = Path(__file__).resolve().parent.parent


def design_only(waypoints: int = 12):
    raw = yaml.safe_load((ROOT / "configs" / "design_only.yaml").read_text())
    raw["toolpath"]["waypoints"] = waypoints
    cfg = parse_config(raw)
    return cfg, problem_from_config(cfg)


def twists(problem) -> np.ndarray:
    return np.array([j.name.endswith(".alpha") for j in problem.chain.design])


def planar_design(problem, offset: float = 2e-4) -> np.ndarray:
    """The configured design with every twist within ``offset`` of 0 or -pi (all joint axes parallel)."""
    q_d = np.array([j.value for j in problem.chain.design])
    q_d[twists(problem)] = [offset, -np.pi + offset, offset, offset, -np.pi + offset, offset]
    return q_d


def test_a_planar_arm_tracks_its_height_and_axis_without_its_joints():
    _, problem = design_only()
    assert len(q_independent_rows(problem)) == 0  # twists free: every row depends on the joints somewhere
    held, q_d = held_at_multiples_of_pi(problem, planar_design(problem))
    assert list(q_independent_rows(held)) == [2, 3, 4, 5]  # height p_z and the tool axis, not x and y
    # closed form: with every twist 0 or pi all z axes are parallel, so the tool axis is +-z and the tool's
    # height is the signed sum of the d offsets, whatever the joints
    rng = np.random.default_rng(1)
    poses = [tool_pose(held.chain, rng.uniform(-np.pi, np.pi, 6), q_d) for _ in range(3)]
    assert all(np.allclose(abs(T[2, 2]), 1.0) for T in poses)
    assert np.ptp([T[2, 3] for T in poses]) < 1e-12
    assert np.ptp([T[0, 3] for T in poses]) > 1e-3  # x still moves: it is tracked at every waypoint
    # a path whose height changes cannot be followed by a planar arm: its height row is not held once
    tp = held.toolpath
    points = tp.points_W.copy()
    points[:, 2] += np.linspace(0.0, 0.05, tp.n)
    climbing = replace(held, toolpath=replace(tp, points_W=points))
    assert list(q_independent_rows(climbing)) == [3, 4, 5]


def test_holding_snaps_the_angles_near_a_multiple_of_pi_and_nothing_else():
    _, problem = design_only()
    q_d = planar_design(problem)
    held, snapped = held_at_multiples_of_pi(problem, q_d)
    mask = twists(problem)
    assert np.array_equal(snapped[mask], [0.0, -np.pi, 0.0, 0.0, -np.pi, 0.0])
    assert np.array_equal(snapped[~mask], q_d[~mask])  # lengths are not touched
    for joint, value, twist in zip(held.chain.design, snapped, mask, strict=True):
        assert (joint.lower == joint.upper == value) if twist else joint.lower < joint.upper
    assert held_at_multiples_of_pi(held, snapped) is None  # held joints are not held again
    assert held_at_multiples_of_pi(problem, q_d + 0.01 * mask) is None  # 1e-2 rad off: not degenerate
    # the PUMA-560 has twists of 0 (links 2 and 6), but its other axes are perpendicular: nothing degenerates
    assert held_at_multiples_of_pi(problem, np.array([j.value for j in problem.chain.design])) is None
    # a PPP gantry's axis rows never depended on its joints (they are held once already): holding the angles of
    # its configured design that are multiples of pi frees no further row (its three axes stay orthogonal)
    gantry = problem_from_config(parse_config(gantry_config(design=["theta", "a", "alpha", "placement"])))
    assert list(q_independent_rows(gantry)) == [3, 4, 5]
    configured = np.array([j.value for j in gantry.chain.design])
    at_pi = np.array([j.kind == "angle" and abs(np.sin(j.value)) < 1e-12 for j in gantry.chain.design])
    assert at_pi.sum() >= 4
    assert held_at_multiples_of_pi(gantry, configured + 1e-4 * at_pi) is None


def test_the_watch_stops_only_a_solve_that_stays_on_a_degenerate_design():
    _, problem = design_only()
    watch = DegenerateWatch(problem, patience=3)

    def step(q_d):
        return int(watch.observe(Iterate(q_d)))

    planar, puma = planar_design(problem), np.array([j.value for j in problem.chain.design])
    assert [step(planar), step(planar), step(puma), step(planar), step(planar)] == [0, 0, 0, 0, 0]
    assert step(planar) == 1 and watch.stopped  # the third in a row
    watch.reset()
    assert not watch.stopped and step(planar) == 0


@pytest.mark.parametrize("hold", [False, True])
def test_a_solve_stalled_on_a_planar_design_is_finished_with_its_twists_held(hold):
    # start 3 of the design-only problem on 12 waypoints walks into a planar arm (twists 0 and -pi) and, as is,
    # creeps there until the iteration cap (measured: 400 iterations, cost 0.29-0.42 as the start's last bits
    # vary). Held, it converges: the held problem is slow from where the watch stops it (measured: 475 more
    # iterations, 160 with other rounding of the start), so the held solve gets a cap of 1000.
    cfg, problem = design_only()
    stalled = solve(problem, index=3, max_iter=400, hold_degenerate=False)
    assert stalled.raw.status == "Maximum_Iterations_Exceeded"
    assert held_at_multiples_of_pi(problem, stalled.raw.q_d) is not None  # it stalled on a degenerate design
    if not hold:
        return
    sol = solve(problem, index=3, max_iter=1000, hold_degenerate=True)
    assert sol.raw.success, sol.raw.status
    assert sol.raw.held.split() == [j.name for j in problem.chain.design if j.name.endswith(".alpha")]
    assert sol.raw.iterations < 1000  # the watch stopped the creep: unwatched, it alone would take the cap
    assert sol.metrics.tracks
    assert sol.metrics.design_cost < 0.5 * stalled.metrics.design_cost
    again = evaluate(problem, sol.raw.q_d, sol.raw.trajectory)  # a solution of the problem as posed
    assert again.tracks and np.isclose(again.design_cost, sol.metrics.design_cost, rtol=1e-12)
    assert all(j.lower <= v <= j.upper for j, v in zip(problem.chain.design, sol.raw.q_d, strict=True))


def test_the_search_says_whether_stalled_solves_are_held():
    assert "finished held" in Search(hold_degenerate=True).describe()
    assert "held" not in Search(hold_degenerate=False).describe()


def test_held_problems_share_one_nlp_and_solve_as_if_built_alone():
    """The planar arm held with its twists at 0 / -pi and at 0 / +pi: one NLP built (as `shared_shape`, held at 0),
    each solved with its own bounds, and each solve is the one an NLP built from that held problem alone gives, to
    the bit. A problem whose rows imposed once change when held at 0 is its own shape."""
    from designopt.solve import local
    from designopt.solve.backends import backend_named
    from designopt.solve.profile import SolverProfile
    from designopt.transcriptions.collocation import Collocation
    from designopt.transcriptions.degeneracy import shared_shape

    _, problem = design_only(waypoints=8)
    q_d = planar_design(problem)
    minus, at_minus = held_at_multiples_of_pi(problem, q_d)
    flipped = np.where(np.isclose(at_minus, -np.pi), np.pi, at_minus)
    plus, at_plus = held_at_multiples_of_pi(problem, flipped)
    assert not np.array_equal(at_minus, at_plus)
    shape = shared_shape(minus)
    assert shape is not minus and shared_shape(plus) == shape and shared_shape(shape) is shape
    assert all(j.lower == j.upper == 0.0 for j in shape.chain.design if j.name.endswith(".alpha"))
    assert shared_shape(problem) is problem  # nothing held
    # the first twist held at pi/2: fewer rows imposed once than the four of every twist at 0 or pi
    first = next(i for i, j in enumerate(minus.chain.joints) if j.name.endswith(".alpha"))
    tilted = list(minus.chain.joints)
    tilted[first] = replace(tilted[first], value=np.pi / 2, lower=np.pi / 2, upper=np.pi / 2)
    tilted = replace(minus, chain=replace(minus.chain, joints=tuple(tilted)))
    assert list(q_independent_rows(minus)) == [2, 3, 4, 5] != list(q_independent_rows(tilted))
    assert shared_shape(tilted) is tilted

    profile = SolverProfile(max_iter=40, compile="none")
    transcription = Collocation()
    local._built.cache_clear()
    local._prepared.cache_clear()
    builds = []
    for held, at in ((minus, at_minus), (plus, at_plus)):
        built, solver, spent = local.prepared(held, transcription, profile)
        builds.append(spent)
        guess = built.pack(initial_guess(held, 0, 0, 0.3, "ik"))
        outcome = solver.solve(guess)
        alone = transcription.build(held)  # the NLP of this held problem, built from it
        own = backend_named(profile.backend).prepare(alone.nlp, profile).solve(alone.pack(initial_guess(held, 0, 0,
                                                                                                       0.3, "ik")))
        assert outcome.iterations == own.iterations > 0 and outcome.status == own.status
        np.testing.assert_array_equal(outcome.x, own.x)
        np.testing.assert_array_equal(outcome.x[: len(at)][twists(held)], at[twists(held)])  # held where it was
    assert builds[0] > 0 and builds[1] == 0.0  # the second held problem built nothing

    # a bounded solver keeps the NLP's fixed joints: it cannot fix one more
    _, solver, _ = local.prepared(minus, transcription, profile)
    design = minus.chain.design
    lower = np.array([j.lower for j in design])
    with pytest.raises(ValueError, match="fix the design joints"):
        solver.bounded(lower, lower)


def test_a_backend_that_cannot_move_bounds_builds_each_held_problem(monkeypatch):
    """A backend whose prepared solver has no `bounded`: a held problem is built and solved as itself."""
    from types import SimpleNamespace

    from designopt.solve import local
    from designopt.solve.backends import BACKENDS
    from designopt.solve.backends.ipopt import Ipopt
    from designopt.solve.profile import SolverProfile
    from designopt.transcriptions.collocation import Collocation

    class Plain:
        name = "plain"

        def prepare(self, nlp, profile):
            inner = Ipopt().prepare(nlp, profile)
            return SimpleNamespace(solve=inner.solve, prepare_time_s=inner.prepare_time_s)

    monkeypatch.setitem(BACKENDS, "plain", Plain)
    _, problem = design_only(waypoints=8)
    held, at = held_at_multiples_of_pi(problem, planar_design(problem))
    built, solver, spent = local.prepared(held, Collocation(), SolverProfile(backend="plain", max_iter=40))
    assert built.problem.chain == held.chain and spent > 0
    outcome = solver.solve(built.pack(initial_guess(held, 0, 0, 0.3, "ik")))
    np.testing.assert_array_equal(outcome.x[: len(at)][twists(held)], at[twists(held)])
