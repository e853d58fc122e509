"""Every transcription in the registry, on the same problems: the known optimum of a tiny problem, a failed
solve returned as a result, and the exact structured Hessian equal to CasADi's own. And solutions: a file
round-trips through Solution.from_dict, and Solution.sample is the trajectory between waypoints."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from conftest import gantry_config, solve_from

from designopt.config import parse_config
from designopt.initial_guess import initial_guesses
from designopt.problem import problem_from_config
from designopt.solution import Solution, to_dict
from designopt.solve import SolverProfile
from designopt.solve.local import prepared
from designopt.transcriptions import TRANSCRIPTIONS, transcription_named
from designopt.transcriptions.nlp import Deferred

METHODS = sorted(TRANSCRIPTIONS)


@pytest.mark.parametrize("method", METHODS)
def test_known_optimum(method):
    """A Cartesian gantry with K = I: C w = (F, 0) at every pose, so L_d = alpha^2 and the design cost is
    alpha^2 N / (N - 1) whatever the design (alpha = 2 here)."""
    problem = problem_from_config(parse_config(gantry_config()))
    guess = initial_guesses(problem, 1, 0, 0.3, "constant")[0]
    sol = solve_from(problem, guess, transcription_named(method), max_iter=300)
    N = problem.toolpath.n
    assert sol.raw.success, sol.raw.status
    assert sol.metrics.tracks
    assert sol.metrics.design_cost == pytest.approx(4.0 * N / (N - 1), rel=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_a_failed_solve_is_a_result(method, gantry_problem):
    sol = solve_from(gantry_problem, initial_guesses(gantry_problem, 1, 0, 0.3, "constant")[0],
                     transcription_named(method), max_iter=1)
    raw = sol.raw
    assert not raw.success and raw.status == "Maximum_Iterations_Exceeded"
    assert sol.row()["status"] == "Maximum_Iterations_Exceeded" and sol.row()["iterations"] == 1


@pytest.mark.parametrize("method", METHODS)
def test_structured_derivatives_equal_casadi(method, rng):
    """The Hessian, constraint Jacobian and gradient assembled from per-waypoint blocks equal the ones CasADi
    derives from the whole graph (the ``auto`` transcription). The Jacobian and gradient IPOPT is given carry no
    values (g and f NaN: IPOPT reads only the derivatives); the NLP's own carry them, equal to CasADi's."""
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 6},
           "robot": {"structure": "RPRR", "dh": "generic", "stiffness": {"revolute": 2.0, "prismatic": 0.5}},
           "placement": {"xyz": [0.4, 0.1, 0.0], "keep_out_radius": 0.1}}
    problem = problem_from_config(parse_config(cfg))
    _, ours, _ = prepared(problem, transcription_named(method, hessian="structured"), SolverProfile(compile="none"))
    _, ref, _ = prepared(problem, transcription_named(method, hessian="auto"), SolverProfile())
    ours_solver, ref_solver = ours.solver, ref.solver
    ours, ref, H_ours, H_ref = (ours.nlp, ref.nlp, ours.solver.get_function("nlp_hess_l"),
                                ref.solver.get_function("nlp_hess_l"))
    assert (ours.n_variables, ours.n_constraints) == (ref.n_variables, ref.n_constraints)
    for _ in range(3):
        x, lam_g = rng.normal(size=ours.n_variables), rng.normal(size=ours.n_constraints)
        np.testing.assert_allclose(np.triu(np.array(ca.DM(H_ours(x, [], 0.7, lam_g)))),
                                   np.triu(np.array(ca.DM(H_ref(x, [], 0.7, lam_g)))), rtol=1e-9, atol=1e-9)
        for name, full in (("nlp_jac_g", ours.jacobian("none")), ("nlp_grad_f", ours.gradient("none"))):
            (value, derivative), (ref_value, ref_derivative) = (ours_solver.get_function(name)(x, []),
                                                                ref_solver.get_function(name)(x, []))
            assert np.isnan(np.array(ca.DM(value))).all()
            np.testing.assert_allclose(np.array(ca.DM(derivative)), np.array(ca.DM(ref_derivative)), rtol=1e-9,
                                       atol=1e-9)
            for a, b in zip(full(x, []), (ref_value, ref_derivative), strict=True):
                np.testing.assert_allclose(np.array(ca.DM(a)), np.array(ca.DM(b)), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_the_solver_derives_nothing_of_the_whole_nlp(method, gantry_problem):
    """nlpsol is given every derivative IPOPT asks for, and asked for no reverse derivative of the whole NLP
    ("nlp_grad", which it would build at set-up only to compute lam_p of an NLP without parameters): on a
    production cell that derivative was most of the build. The solve still returns IPOPT's own multipliers."""
    _, solver, _ = prepared(gantry_problem, transcription_named(method), SolverProfile(compile="none"))
    assert not solver.solver.has_function("nlp_grad")
    nlp = solver.nlp
    x0 = np.clip(np.zeros(nlp.n_variables), nlp.lbx, nlp.ubx)
    out = solver.solver(x0=x0, lbx=nlp.lbx, ubx=nlp.ubx, lbg=nlp.lbg, ubg=nlp.ubg)
    assert np.all(np.isfinite(np.array(out["lam_g"]))) and np.any(np.array(out["lam_g"]) != 0)


@pytest.mark.parametrize("method", METHODS)
def test_ipopt_never_reads_the_values_of_its_gradient_and_jacobian(method, gantry_problem):
    """IPOPT is given grad_f and jac_g whose f and g outputs are NaN (computing them again in every call was about
    5 % of an exploration iteration): the solve is the same to the bit as with the NLP's own gradient and Jacobian,
    which compute them. Were a value read, the NaN would stop the solve."""
    _, solver, _ = prepared(gantry_problem, transcription_named(method), SolverProfile(compile="none"))
    nlp = solver.nlp
    problem, derivatives = nlp.derivatives("none")
    with_values = {**derivatives, "jac_g": nlp.jacobian("none"), "grad_f": nlp.gradient("none")}
    x0 = np.clip(np.full(nlp.n_variables, 0.1), nlp.lbx, nlp.ubx)
    runs = []
    for given in (derivatives, with_values):
        ipopt = ca.nlpsol("ipopt", "ipopt", problem, {"ipopt.print_level": 0, "print_time": False, **given})
        out = ipopt(x0=x0, lbx=nlp.lbx, ubx=nlp.ubx, lbg=nlp.lbg, ubg=nlp.ubg)
        runs.append((np.array(out["x"]).ravel(), ipopt.stats()["iter_count"], ipopt.stats()["success"]))
    (x, iterations, success), (x_ref, iterations_ref, _) = runs
    assert success and iterations == iterations_ref
    np.testing.assert_array_equal(x, x_ref)


@pytest.mark.parametrize("method", METHODS)
def test_a_solver_builds_no_graph_of_the_whole_path(method, rng):
    """Preparing a solver with blocks does not build the per-point terms' graph inlined over every waypoint (a
    `Deferred` entry: it was 70 % of a 1,208-waypoint program's build); built when asked for (`NLP.g`), its rows
    are the ones `ConstraintList.rows` gives, in any order of rows."""
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 6},
           "robot": {"structure": "RPRR", "dh": "generic"},
           "placement": {"xyz": [0.4, 0.1, 0.0], "keep_out_radius": 0.1}}
    _, solver, _ = prepared(problem_from_config(parse_config(cfg)), transcription_named(method),
                            SolverProfile(compile="none"))
    nlp = solver.nlp
    deferred = [e for e in nlp.constraints.g if isinstance(e, Deferred)]
    assert deferred and not any("value" in vars(e) for e in deferred)
    assert "f" not in vars(nlp) and "g" not in vars(nlp)
    index = rng.permutation(nlp.n_constraints)[: nlp.n_constraints // 2 + 1]
    whole = ca.Function("whole", [nlp.x], [nlp.g[ca.DM(index.tolist())]])
    rows = ca.Function("rows", [nlp.x], [nlp.constraints.rows(index)])
    x = rng.normal(size=nlp.n_variables)
    np.testing.assert_array_equal(np.array(whole(x)), np.array(rows(x)))


@pytest.fixture(scope="module")
def solved():
    cfg = parse_config({"toolpath": {"kind": "circle", "radius": 0.08, "waypoints": 10},
                        "robot": {"structure": "RRPRRR", "dh": "generic", "stiffness": {"revolute": 3.0,
                                                                                       "prismatic": 0.5}},
                        "placement": {"xyz": [0.35, 0.1, -0.1], "ypr": [0.3, 0.0, 0.0]}})
    problem = problem_from_config(cfg)
    return solve_from(problem, initial_guesses(problem, 1, 0, 0.3)[0], max_iter=300)


def test_solution_round_trips_through_its_file(solved):
    data = to_dict(solved)
    back = Solution.from_dict(data)
    assert back.metrics.design_cost == pytest.approx(solved.metrics.design_cost, rel=1e-12)
    assert back.metrics.max_position_error == pytest.approx(solved.metrics.max_position_error, abs=1e-15)
    again = to_dict(back)
    for key in ("structure", "dh", "tool", "placement", "stiffness", "q", "v", "trajectory", "joint_limits"):
        assert again[key] == data[key], key
    np.testing.assert_allclose(again["toolpath"]["force_W"], data["toolpath"]["force_W"], atol=1e-15)


def test_a_file_reads_back_with_its_own_cost_weights(solved):
    """A solution of a problem with other weights than the defaults reads back with those weights (its metrics,
    e.g. the weighted regularisation, are recomputed with them)."""
    from dataclasses import replace

    from designopt.solution import solve_and_evaluate

    weighted = replace(solved.problem,
                       waypoint_costs=tuple(replace(c, weight=7.0) for c in solved.problem.waypoint_costs),
                       design_costs=tuple(replace(c, weight=0.05) for c in solved.problem.design_costs))
    sol = solve_and_evaluate(weighted, "to", solved.raw)
    back = Solution.from_dict(to_dict(sol))
    weights = {c.name: c.weight for c in (*back.problem.waypoint_costs, *back.problem.design_costs)}
    assert weights == {"deformation": 7.0, "regularization": 0.05}
    assert back.metrics.regularization == pytest.approx(sol.metrics.regularization, rel=1e-12)
    assert back.metrics.regularization == pytest.approx(0.05 / 1e-3 * solved.metrics.regularization, rel=1e-12)


def test_a_file_reads_back_with_its_own_trajectory(solved):
    """TO's file says its trajectory is the Hermite cubic through (q, v); the FK baseline's, straight lines."""
    from designopt.transcriptions.trajectory import HermiteCubic, PiecewiseLinear

    back = Solution.from_dict(to_dict(solved))
    assert isinstance(back.raw.trajectory, HermiteCubic)
    t = np.linspace(0, 1, 17)
    np.testing.assert_allclose(back.sample(t), solved.sample(t), atol=1e-12)
    data = to_dict(solved)
    data["trajectory"] = "linear"
    linear = Solution.from_dict(data)
    assert isinstance(linear.raw.trajectory, PiecewiseLinear)
    tp = solved.problem.toolpath
    mid = 0.5 * (tp.t[3] + tp.t[4])
    np.testing.assert_allclose(linear.sample(mid)[0], 0.5 * (solved.raw.Q[3] + solved.raw.Q[4]), atol=1e-12)


def test_sample_is_the_hermite_trajectory(solved):
    tp, Q, V = solved.problem.toolpath, solved.raw.Q, solved.raw.V
    np.testing.assert_allclose(solved.sample(tp.t), Q, atol=1e-12)
    # Between waypoints k and k+1: the cubic through (q_k, v_k) and (q_k+1, v_k+1), solved directly.
    k, frac = 3, 0.3
    h = tp.t[k + 1] - tp.t[k]
    A = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [1, h, h**2, h**3], [0, 1, 2 * h, 3 * h**2]])
    for j in range(Q.shape[1]):
        c = np.linalg.solve(A, [Q[k, j], V[k, j], Q[k + 1, j], V[k + 1, j]])
        assert solved.sample(tp.t[k] + frac * h)[0, j] == pytest.approx(np.polyval(c[::-1], frac * h), abs=1e-12)


@pytest.mark.parametrize("config", ["milling.yaml", "gcode_pocket.yaml", "circle_standoff.yaml", "ur10_placement.yaml"])
def test_the_counted_nlp_size_is_the_built_one(config):
    """`designopt check` counts the NLP instead of building it: the count must be what a build makes, for every
    variant of the transcription (soft tracking, differential kinematics, a stand-off, a cell)."""
    from pathlib import Path

    from designopt.config import load_config
    from designopt.transcriptions import Collocation

    problem = problem_from_config(load_config(Path(__file__).resolve().parent.parent / "configs" / config))
    for t in (Collocation(), Collocation(tracking="soft"), Collocation(kinematics="differential", hessian="auto")):
        if problem.cell is not None and t.kinematics == "differential":
            continue
        nlp = t.build(problem).nlp
        assert t.size(problem) == (nlp.n_variables, nlp.n_constraints), (config, t)
