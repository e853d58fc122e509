"""TO on problems with known answers, and its Hessian against CasADi's own differentiation."""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import replace

import casadi as ca
import numpy as np
import pytest
from conftest import gantry_config, solve, solve_from

from designopt.config import parse_config
from designopt.initial_guess import initial_guesses
from designopt.problem import problem_from_config
from designopt.solve import SolverProfile
from designopt.solve.local import prepared
from designopt.transcriptions import Collocation, InitialGuess
from designopt.transcriptions.compiled import AUTO_O1_FROM, compiled, level
from designopt.transcriptions.forward_kinematics import ForwardKinematics
from designopt.transcriptions.nlp import split_terms
from designopt.transcriptions.trajectory import hermite_acceleration_integral, hermite_midpoint


def hessian_function(problem, transcription, compile="O0"):
    """The nlp_hess_l of the prepared IPOPT solver of a problem."""
    _, solver, _ = prepared(problem, transcription, SolverProfile(compile=compile))
    return solver.solver.get_function("nlp_hess_l"), solver.nlp


def test_hermite_formulas_match_the_cubic(rng):
    q0, v0, q1, v1, h = rng.normal(size=5)
    h = abs(h) + 0.1
    # Cubic through (0, q0, v0) and (h, q1, v1), solved directly.
    A = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [1, h, h**2, h**3], [0, 1, 2 * h, 3 * h**2]])
    c = np.linalg.solve(A, [q0, v0, q1, v1])
    q_mid, v_mid = hermite_midpoint(q0, v0, q1, v1, h)
    assert q_mid == pytest.approx(np.polyval(c[::-1], h / 2))
    assert v_mid == pytest.approx(np.polyval(np.polyder(c[::-1]), h / 2))
    ts = np.linspace(0, h, 20001)
    acc = np.polyval(np.polyder(c[::-1], 2), ts)
    assert hermite_acceleration_integral(q0, v0, q1, v1, h) == pytest.approx(np.trapezoid(acc**2, ts), rel=1e-6)


def test_gantry_known_optimum():
    """A Cartesian gantry with K = I has J_v J_v^T = I, so C w = (F, 0) at every pose: L_d = alpha^2 and
    the design cost is alpha^2 N / (N - 1) for any design. The offsets a_i only pay regularisation, so the
    optimum has a = 0 (exactly so without the tiny joint regularisation, which trades against it)."""
    problem = replace(problem_from_config(parse_config(gantry_config())), smoothness=0.0, joint_regularization=0.0)
    guess = initial_guesses(problem, 1, seed=0, scale=0.3, mode="constant")[0]
    sol = solve_from(problem, guess)
    N, alpha = problem.toolpath.n, 2.0
    assert sol.raw.success, sol.raw.status
    assert sol.metrics.tracks
    assert sol.metrics.design_cost == pytest.approx(alpha**2 * N / (N - 1), rel=1e-9)
    # a = 0 lies on the bound a >= 0 where the gradient also vanishes; an interior-point method stops at
    # a ~ sqrt(mu / (2 lambda)) with mu ~ 1e-9, lambda = 1e-3, i.e. ~1e-3 m.
    assert np.all(sol.raw.q_d >= 0) and np.all(sol.raw.q_d < 3e-3)
    # Line along x_W maps to base z under pitch -pi/2: only d1 moves, by the line's length.
    assert np.ptp(sol.raw.Q[:, 0]) == pytest.approx(0.2, abs=1e-6)


def test_violation_is_zero_at_a_solution_and_a_bound_overstepped_by_what_it_oversteps():
    """`NLP.violation` at the gantry's optimum (what IPOPT calls feasible: within its tolerances), then with one
    knot velocity of the decision vector 0.3 beyond its limit: the velocity's own bound is the worst (its
    neighbouring midpoint velocities move by a quarter of the change, the tracking rows not at all), so the
    violation is that 0.3."""
    problem = replace(problem_from_config(parse_config(gantry_config())), smoothness=0.0, joint_regularization=0.0)
    sol = solve_from(problem, initial_guesses(problem, 1, seed=0, scale=0.3, mode="constant")[0])
    built = Collocation().build(problem)
    Q, V = np.array(sol.raw.Q), np.array(sol.raw.V)
    assert built.nlp.violation(built.pack(InitialGuess(q_d=sol.raw.q_d, Q=Q, V=V))) < 1e-8
    v_max = problem.velocity_limits[0]
    assert np.abs(V[:, 0]).max() < 0.5 * v_max  # the premise: the midpoints stay within their limits
    x = built.pack(InitialGuess(q_d=sol.raw.q_d, Q=Q, V=V))
    at = built.nlp.n_design + 5 * built.n_state + problem.chain.n_moving  # knot 5's first velocity
    assert x[at] == V[5, 0]
    x[at] = v_max + 0.3  # (pack itself clips velocities to their limits)
    assert built.nlp.violation(x) == pytest.approx(0.3, abs=1e-8)


@pytest.mark.parametrize("tracking", ["hard", "soft"])
def test_soft_and_differential_variants_solve_the_gantry(tracking):
    problem = problem_from_config(parse_config(gantry_config()))
    for kinematics in ("forward", "differential"):
        transcription = Collocation(tracking=tracking, kinematics=kinematics, hessian="auto" if kinematics ==
                                    "differential" else "structured")
        guess = initial_guesses(problem, 1, 0, 0.3, "constant")[0]
        sol = solve_from(problem, guess, transcription, max_iter=3000)
        raw = sol.raw
        assert raw.success, (tracking, kinematics, raw.status)
        # soft tracking leaves a residual of order 1/w; hard tracks exactly
        assert sol.metrics.max_position_error < (1e-6 if tracking == "hard" else 1e-3)
        assert raw.kinematic_drift < 1e-6  # straight line, constant J: Simpson is exact



@pytest.mark.parametrize("tracking,keep_out", [("hard", 0.0), ("soft", 0.0), ("hard", 0.2)])
def test_structured_hessian_equals_casadi_hessian(tracking, keep_out, rng):
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 7},
           "robot": {"structure": "RPRR", "dh": "generic"},
           "placement": {"xyz": [0.4, 0.1, 0.0], "keep_out_radius": keep_out}}
    problem = problem_from_config(parse_config(cfg))
    H_ours, ours = hessian_function(problem, Collocation(tracking=tracking, hessian="structured"), "none")
    H_ref, ref = hessian_function(problem, Collocation(tracking=tracking, hessian="auto"))
    n_x, n_g = ours.n_variables, ours.n_constraints
    assert (n_x, n_g) == (ref.n_variables, ref.n_constraints)
    for _ in range(3):
        x, lam_f, lam_g = rng.normal(size=n_x), rng.uniform(0.5, 2), rng.normal(size=n_g)
        a = np.triu(np.array(ca.DM(H_ours(x, [], lam_f, lam_g))))
        b = np.triu(np.array(ca.DM(H_ref(x, [], lam_f, lam_g))))
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("transcription,keep_out", [(Collocation(), 0.2), (ForwardKinematics(), 0.0)])
def test_objective_and_constraints_from_blocks_equal_the_whole_graphs(transcription, keep_out, rng):
    """The NLP a backend solves takes f and g from its blocks' own terms (each split into phi and c, mapped over
    their points) plus the quadratic terms and the rows in no block; they equal the transcription's whole SX f
    and g, interpreted and compiled."""
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 7},
           "robot": {"structure": "RPRR", "dh": "generic"},
           "placement": {"xyz": [0.4, 0.1, 0.0], "keep_out_radius": keep_out}}
    nlp = transcription.build(problem_from_config(parse_config(cfg))).nlp
    ref = ca.Function("ref", [nlp.x], [nlp.f, nlp.g])
    for mode in ("none", "O0"):
        f_of, g_of = nlp.functions(mode)
        for _ in range(3):
            x = rng.normal(size=nlp.n_variables)
            f, g = ref(x)
            np.testing.assert_allclose(float(f_of(x)), float(f), rtol=1e-12)
            np.testing.assert_allclose(np.array(g_of(x)), np.array(g), rtol=1e-12, atol=1e-14)


def test_a_block_without_an_objective_term_is_not_evaluated_for_f():
    """A clearance block's phi is structurally zero: `split_terms` gives no phi function for it, so that f does
    not evaluate the cell's clearance, and a waypoint block gives both."""
    y = ca.SX.sym("y", 3)
    only_c = ca.Function("clear", [y], [ca.SX(0), ca.sumsqr(y)])
    both = ca.Function("terms", [y], [ca.sin(y[0]), y[1:] * 2])
    phi, c = split_terms(only_c)
    assert phi is None and float(c([1, 2, 3])) == 14
    phi, c = split_terms(both)
    assert float(phi([0.5, 1, 1])) == pytest.approx(np.sin(0.5)) and list(np.array(c([0, 1, 2])).ravel()) == [2, 4]


def test_compiled_block_gives_the_same_hessian(rng, tmp_path, monkeypatch):
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 5}, "robot": {"structure": "RR", "dh": "generic"}}
    problem = problem_from_config(parse_config(cfg))
    fa, a = hessian_function(problem, Collocation(), "O1")  # a level no other test asks for: compiled here
    fb, _ = hessian_function(problem, Collocation(), "none")
    assert list(tmp_path.glob("*.so")), "the block function was not compiled"
    x, lam_g = rng.normal(size=a.n_variables), rng.normal(size=a.n_constraints)
    Ha = np.array(ca.DM(fa(x, [], 1.0, lam_g)))
    Hb = np.array(ca.DM(fb(x, [], 1.0, lam_g)))
    np.testing.assert_allclose(Ha, Hb, rtol=1e-12, atol=1e-12)


def test_auto_compiles_blocks_of_long_paths_at_o1(monkeypatch):
    """``auto`` (the profile's default) compiles a block evaluated at AUTO_O1_FROM points or more at O1 and one
    at fewer points tiered (`FIRST_TIER` where first needed, or a large one -O0, then O1 once solved with long
    enough); any other mode is itself, and a block is
    never compiled at "auto"."""
    import designopt.transcriptions.hessian as hessian_module

    assert level("auto", AUTO_O1_FROM) == "O1" and level("auto", AUTO_O1_FROM - 1) == "tiered"
    assert level("none", 10**6) == "none" and level("O2", 1) == "O2" and SolverProfile().compile == "auto"
    x = ca.SX.sym("x")
    with pytest.raises(ValueError, match="auto"):
        compiled(ca.Function("f", [x], [x**2]), "auto")
    asked = []
    monkeypatch.setattr(hessian_module, "compiled_as",
                        lambda name, identity, derive, mode, used: asked.append(mode) or derive())
    for n, expected in ((AUTO_O1_FROM, "O1"), (12, "tiered")):
        cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": n}, "robot": {"structure": "RR",
                                                                                         "dh": "generic"}}
        Collocation().build(problem_from_config(parse_config(cfg))).nlp.hessian("auto")
        assert asked.pop() == expected


BLOCK = """
import casadi as ca
x = ca.SX.sym("x", 3)
def block(expr):
    return ca.Function("blk", [x], [expr(x) * ca.sumsqr(x)])
"""


def test_compile_cache_is_keyed_by_the_function_in_any_process(tmp_path, monkeypatch):
    """Two functions of one name get two libraries, each computing its own function; the same function built
    anew (here, and in another process) finds its library instead of compiling again."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    scope = {}
    exec(BLOCK, scope)
    x0 = np.array([0.3, -1.2, 0.7])
    for expr in (ca.sin, ca.cos):
        fn = scope["block"](expr)
        np.testing.assert_allclose(np.array(compiled(fn, "O0")(x0)), np.array(fn(x0)), rtol=1e-14)
    libraries = sorted(tmp_path.glob("*.so"))
    assert len(libraries) == 2
    compiled(scope["block"](ca.sin), "O0")
    script = BLOCK + "from designopt.transcriptions.compiled import compiled\ncompiled(block(ca.sin), 'O0')\n"
    subprocess.run([sys.executable, "-c", script], check=True, env={**os.environ, "DESIGNOPT_CACHE": str(tmp_path)})
    assert sorted(tmp_path.glob("*.so")) == libraries


def test_a_hessian_block_found_in_the_cache_is_not_derived_again(tmp_path, monkeypatch):
    """The compiled Hessian block equals the interpreted one; it is cached under the terms it is derived from,
    so that another terms function gets another library and a build that finds its library derives nothing
    (no symbolic Hessian: most of a warm build)."""
    from designopt.transcriptions.hessian import block_hessian_function

    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    y, s_W = ca.SX.sym("y", 3), ca.SX.sym("s_W", 2)
    rng = np.random.default_rng(3)
    args = [rng.normal(size=3), 0.7, rng.normal(size=2), rng.normal(size=2)]
    for k, scale in enumerate((1.0, 2.0)):
        terms = ca.Function("terms", [y, s_W], [scale * ca.sin(y[0]) * ca.sumsqr(y),
                                                ca.vertcat(y[1] * y[2] - s_W[0], ca.cos(y[0]) * s_W[1])])
        ours, ref = block_hessian_function(terms, 3, 2, "O0"), block_hessian_function(terms, 3, 2, "none")
        np.testing.assert_allclose(np.array(ours(*args)), np.array(ref(*args)), rtol=1e-13)
        assert len(list(tmp_path.glob("waypoint_hessian_*.so"))) == k + 1
    monkeypatch.setattr(ca, "hessian", lambda *a: pytest.fail("derived although cached"))
    again = block_hessian_function(terms, 3, 2, "O0")
    np.testing.assert_allclose(np.array(again(*args)), np.array(ref(*args)), rtol=1e-13)
    assert len(list(tmp_path.glob("waypoint_hessian_*.so"))) == 2


def test_jacobian_gradient_and_split_blocks_found_in_the_cache_are_not_derived_again(tmp_path, monkeypatch):
    """A block's Jacobian, gradient and split terms are cached under the terms they come from, as its Hessian is:
    compiled, they equal the interpreted ones, and a build that finds their libraries derives and serialises
    nothing of them (the Jacobian's rows and columns come from the terms' own sparsity)."""
    from designopt.transcriptions import hessian as hessian_module
    from designopt.transcriptions.jacobian import block_gradient_function, block_jacobian_function
    from designopt.transcriptions.nlp import compiled_split_terms

    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    y, s_W = ca.SX.sym("y", 3), ca.SX.sym("s_W", 2)
    terms = ca.Function("terms", [y, s_W], [ca.sin(y[0]) * ca.sumsqr(y[1:]),
                                            ca.vertcat(y[1] * y[2] - s_W[0], ca.cos(y[0]) * s_W[1], y[2])])
    args = [np.array([0.3, -1.2, 0.8]), np.array([0.5, 2.0])]

    def built():
        jac, rows, cols = block_jacobian_function(terms, "O0")
        return jac, rows, cols, block_gradient_function(terms, "O0"), compiled_split_terms(terms, "O0")

    jac, rows, cols, grad, (phi, c) = built()
    J = np.zeros((3, 3))
    J[rows, cols] = np.array(jac(*args)).ravel()
    x0, x1, x2 = args[0]
    np.testing.assert_allclose(J, [[0, x2, x1], [-np.sin(x0) * 2.0, 0, 0], [0, 0, 1]], rtol=1e-13)
    np.testing.assert_allclose(np.array(grad(*args)).ravel(),
                               [np.cos(x0) * (x1**2 + x2**2), 2 * x1 * np.sin(x0), 2 * x2 * np.sin(x0)], rtol=1e-13)
    assert float(phi(*args)) == pytest.approx(np.sin(x0) * (x1**2 + x2**2), rel=1e-13)
    np.testing.assert_allclose(np.array(c(*args)).ravel(), [x1 * x2 - 0.5, np.cos(x0) * 2.0, x2], rtol=1e-13)
    libraries = sorted(tmp_path.glob("*.so"))
    assert len(libraries) == 4
    for name in ("jacobian", "gradient"):
        monkeypatch.setattr(ca, name, lambda *a, name=name: pytest.fail(f"{name} derived although cached"))
    monkeypatch.setattr(hessian_module, "_serialised", lambda f: f.serialize())  # no memo: count each serialisation
    serialised, serialize = [], ca.Function.serialize
    monkeypatch.setattr(ca.Function, "serialize", lambda f, *a: serialised.append(f.name()) or serialize(f, *a))
    assert built()[0].class_name() == "External"
    assert serialised == ["terms"] * 4 and sorted(tmp_path.glob("*.so")) == libraries


def test_a_derivations_source_in_the_cache_key_is_what_inspect_gives():
    """The compile cache keys a derived block by its derivation's source: read from the lines its code comes from
    (not by tokenising the module), it is `inspect.getsource`'s text for every derivation the blocks use, so keys
    did not move; a derivation with a nested function and a statement over several lines included."""
    import inspect

    from designopt.transcriptions.hessian import _source, block_hessian_function
    from designopt.transcriptions.jacobian import block_gradient_function, block_jacobian_function

    def ends_in_a_nested_function(scale):
        def derive():
            return scale * 2

    for derivation in (block_hessian_function, block_jacobian_function, block_gradient_function, split_terms,
                       ends_in_a_nested_function):
        assert _source(derivation) == inspect.getsource(derivation)
    assert "def derive()" in _source(block_jacobian_function)
    assert _source(block_gradient_function).rstrip().endswith("compile_mode,\n                       used)")


def test_a_gradient_with_entries_no_term_touches_is_dense_and_ipopt_reads_it_right():
    """nlpsol hands IPOPT the nonzeros of the grad_f it is given as the whole gradient: a gradient output without
    stored entries for the variables no objective term touches (the points only a clearance block covers) would
    move every later entry. The assembled gradient is dense, and IPOPT finds the known optimum of
    min (x0 - 1)^2 + (x2 - 2)^2 subject to x1 = x0 + x2: (1, 3, 2)."""
    from designopt.transcriptions.jacobian import assemble_gradient

    y, target = ca.SX.sym("y"), ca.SX.sym("t")
    block = ca.Function("block_gradient", [y, target], [2 * (y - target)])
    grad_f = assemble_gradient(3, None, [(block, np.array([[0], [2]]), [ca.DM([[1.0, 2.0]])])])
    assert grad_f.sparsity_out(1).is_dense()
    x = ca.MX.sym("x", 3)
    problem = {"x": x, "f": (x[0] - 1) ** 2 + (x[2] - 2) ** 2, "g": x[1] - x[0] - x[2]}
    ipopt = ca.nlpsol("ipopt", "ipopt", problem, {"grad_f": grad_f, "ipopt.print_level": 0, "print_time": False})
    out = ipopt(x0=[5.0, 5.0, 5.0], lbg=0, ubg=0)
    assert ipopt.stats()["success"]
    np.testing.assert_allclose(np.array(out["x"]).ravel(), [1.0, 3.0, 2.0], atol=1e-8)


def test_ik_start_tracks_a_reachable_path():
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 20},
           "placement": {"xyz": [0.45, 0.0, -0.2]}}
    problem = problem_from_config(parse_config(cfg))
    from designopt.evaluation import evaluate
    from designopt.transcriptions.trajectory import PiecewiseLinear

    guess = initial_guesses(problem, 1, 0, 0.3, "ik")[0]
    m = evaluate(problem, guess.q_d, PiecewiseLinear(problem.toolpath.t, guess.Q))
    assert m.max_position_error < 1e-6 and m.max_axis_error < 1e-6
    assert m.max_joint_step < 0.5  # one branch, no jumps


@pytest.mark.parametrize("structure", ["RRRRRR", "RPRRPR"])
def test_the_ik_residual_is_the_numpy_kinematics_and_its_jacobian_their_derivative(structure):
    """Starts walk the path with a CasADi function of the tracking residual: at random joints, designs and
    points it equals the residual of the numpy kinematics the verifier uses, and its Jacobians in q and q_d equal
    central differences of that numpy residual."""
    from designopt.costs import tracking_residual
    from designopt.initial_guess import residual_function

    problem = problem_from_config(parse_config({"robot": {"structure": structure},
                                                "design": ["d", "a", "alpha", "placement"]}))
    fn, rng = residual_function(problem), np.random.default_rng(3)

    def numpy_residual(q, q_d, s):
        return np.concatenate(tracking_residual(problem.waypoint(q, q_d, s, np.zeros(3))))

    for _ in range(3):
        q = rng.uniform(-1, 1, problem.chain.n_moving)
        q_d = problem.chain.design_values + rng.uniform(-0.2, 0.2, problem.chain.n_design)
        s = rng.uniform(-0.3, 0.3, 3)
        r, J_q, J_d = (np.array(x) for x in fn(q, q_d, s))
        np.testing.assert_allclose(r.ravel(), numpy_residual(q, q_d, s), atol=1e-12)
        h = 1e-6
        fd_q = np.column_stack([(numpy_residual(q + h * e, q_d, s) - numpy_residual(q - h * e, q_d, s)) / (2 * h)
                                for e in np.eye(len(q))])
        fd_d = np.column_stack([(numpy_residual(q, q_d + h * e, s) - numpy_residual(q, q_d - h * e, s)) / (2 * h)
                                for e in np.eye(len(q_d))])
        np.testing.assert_allclose(J_q, fd_q, atol=1e-7)
        np.testing.assert_allclose(J_d, fd_d, atol=1e-7)


@pytest.mark.parametrize("structure,dh", [("RRRRRR", "puma560"), ("RRRRRR", "generic"), ("P", "generic")])
def test_the_walks_in_place_residual_gives_the_same_bits(structure, dh):
    """The IK walks' in-place residual (`point_residual`: a FunctionBuffer, no design Jacobian, dense) returns
    exactly `residual_function`'s r and dr/dq (as 6 x 1 and 6 x n matrices, one joint too), also where a joint
    moves no row (a column of zeros), and copies that later calls do not overwrite."""
    from designopt.initial_guess import point_residual, residual_function

    problem = problem_from_config(parse_config({"robot": {"structure": structure, "dh": dh},
                                                "design": ["d", "a", "alpha", "placement"]}))
    fn, fast, rng = residual_function(problem), point_residual(problem), np.random.default_rng(5)
    kept = []
    for _ in range(50):
        q = rng.uniform(-2, 2, problem.chain.n_moving)
        q_d = problem.chain.design_values + rng.uniform(-0.2, 0.2, problem.chain.n_design)
        s = rng.uniform(-0.3, 0.3, 3)
        r, J_q, _ = fn(q, q_d, s)
        ours = fast(q, q_d, s)
        assert np.array_equal(ours[0], np.array(r)) and np.array_equal(ours[1], np.array(J_q))
        kept.append((ours, np.array(r)))
    assert all(np.array_equal(ours[0], r) for ours, r in kept)


def test_a_failed_solve_is_a_result_not_an_exception(gantry_problem):
    raw = solve_from(gantry_problem, initial_guesses(gantry_problem, 1, 0, 0.3, "constant")[0], max_iter=2).raw
    assert not raw.success
    assert raw.status == "Maximum_Iterations_Exceeded"


def test_axis_held_once_when_no_joint_turns_the_tool():
    """A PPP chain cannot turn its tool: the axis equalities are the same at every waypoint. Held once, the
    problem is regular and IPOPT converges (it stalled at max_iter when they were repeated N times)."""
    from designopt.transcriptions.nlp import once_only_rows

    problem = problem_from_config(parse_config(gantry_config(design=["theta", "a", "alpha", "placement"])))
    assert list(once_only_rows(problem, "hard")) == [3, 4, 5]
    assert len(once_only_rows(problem_from_config(parse_config({})), "hard")) == 0
    sol = solve_from(problem, initial_guesses(problem, 1, 0, 0.1, "constant")[0], max_iter=300)
    raw = sol.raw
    assert raw.success, raw.status
    assert sol.metrics.tracks


def test_each_start_depends_only_on_seed_and_index(gantry_problem):
    from designopt.initial_guess import initial_guess

    many = initial_guesses(gantry_problem, 3, seed=7, scale=0.3, mode="constant")
    one = initial_guess(gantry_problem, 2, seed=7, scale=0.3, mode="constant")
    np.testing.assert_array_equal(many[2].Q, one.Q)
    np.testing.assert_array_equal(many[2].q_d, one.q_d)
    assert one.seed == 7002


def test_reach_moves_the_design_joints_until_the_start_reaches_the_path():
    """Design only, workpiece fixed: the perturbed design of start 1 cannot follow the path (its IK walk misses
    by centimetres); `reach` (IK over the design joints too) finds a design near it that tracks, inside bounds."""
    from designopt.initial_guess import initial_guess, tracks

    cfg = parse_config({"toolpath": {"kind": "figure_eight", "waypoints": 30}, "design": ["d", "a", "alpha"],
                        "placement": {"xyz": [0.45, 0.0, -0.2]}})
    problem = problem_from_config(cfg)
    plain, reached = initial_guess(problem, 1, 0, 0.3, "ik"), initial_guess(problem, 1, 0, 0.3, "reach")
    assert not tracks(problem, plain.q_d, plain.Q)
    assert tracks(problem, reached.q_d, reached.Q)
    lo, hi = np.array([j.lower for j in problem.chain.design]), np.array([j.upper for j in problem.chain.design])
    assert np.all(reached.q_d >= lo) and np.all(reached.q_d <= hi)
    assert np.linalg.norm(reached.q_d - plain.q_d) < 1.0  # moved, but stays a start of its own
    # start 0 already tracks: reach leaves it exactly as it was
    a, b = initial_guess(problem, 0, 0, 0.3, "ik"), initial_guess(problem, 0, 0, 0.3, "reach")
    np.testing.assert_array_equal(a.Q, b.Q)


def test_build_time_is_counted_once_per_built_nlp():
    """A worker builds a problem's NLP for its first start and reuses it: only that start reports a build time
    (summing build_time_s over a sweep must give the time spent building)."""
    # a force no other test uses, so that this problem is not in the worker's cache yet
    problem = problem_from_config(parse_config(gantry_config(toolpath={"force": 2.718281828})))
    first, second = (solve(problem, index=i, init="constant", max_iter=50) for i in range(2))
    assert first.raw.build_time_s > 0
    assert second.raw.build_time_s == 0


def test_a_box_start_draws_the_design_from_the_tasks_size_and_the_joints_from_the_whole_circle():
    """``spread`` box (`box_design`): lengths in [0, b] with b half the path's largest extent (0.3 m for the
    main job's 0.6 m figure-eight), the placement's position within +-b of the configured one, angles over the
    circle; the first joints of revolute joints over [-pi, pi] (perturb: [-pi/2, pi/2]); start 0 keeps the
    configured design either way; ``spread`` mixed makes each odd start the box's and each even one the
    perturbation's."""
    from designopt.initial_guess import box_design, initial_guess, random_configuration

    problem = problem_from_config(parse_config({"toolpath": {"kind": "figure_eight", "waypoints": 10}}))
    chain = problem.chain
    b = 0.5 * np.ptp(problem.toolpath.points_W, axis=0).max()
    assert b == pytest.approx(0.3, abs=0.01)  # 10 samples of the 0.6 m figure-eight
    placement = {j.name for j in chain.placement_joints}
    configured = chain.design_values
    draws = np.array([box_design(problem, np.random.default_rng(k)) for k in range(400)])
    for i, j in enumerate(chain.design):
        column = draws[:, i]
        assert np.all((column >= j.lower) & (column <= j.upper))
        if j.kind == "angle":
            assert column.min() < -2.5 and column.max() > 2.5  # the whole circle
        elif j.name in placement:
            assert np.all(np.abs(column - configured[i]) <= b + 1e-12)
            assert np.ptp(column) > 1.5 * b
        else:
            assert column.min() >= 0.0 and column.max() <= b and np.ptp(column) > 0.8 * b
    wide = np.array([random_configuration(problem, np.random.default_rng(k), np.pi) for k in range(400)])
    narrow = np.array([random_configuration(problem, np.random.default_rng(k)) for k in range(400)])
    assert np.abs(narrow).max() <= np.pi / 2 and np.abs(wide).max() > 3.0
    for spread in ("perturb", "box"):
        np.testing.assert_array_equal(initial_guess(problem, 0, 3, 0.3, "constant", spread=spread).q_d, configured)
    box = initial_guess(problem, 5, 3, 0.3, "constant", spread="box")
    np.testing.assert_array_equal(box.q_d, initial_guess(problem, 5, 3, 0.3, "constant", spread="box").q_d)
    assert not np.allclose(box.q_d, initial_guess(problem, 5, 3, 0.3, "constant").q_d)
    for index in range(1, 7):  # mixed: odd starts are the box's own, even ones the perturbation's, design and joints
        mixed = initial_guess(problem, index, 3, 0.3, "constant", spread="mixed")
        alike = initial_guess(problem, index, 3, 0.3, "constant", spread="box" if index % 2 else "perturb")
        np.testing.assert_array_equal(mixed.q_d, alike.q_d)
        np.testing.assert_array_equal(mixed.Q, alike.Q)
    with pytest.raises(ValueError, match="spread"):
        initial_guess(problem, 1, 0, 0.3, spread="sphere")
