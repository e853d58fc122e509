"""The objective against independent truth.

Everything here is computed a second way that shares no code with designopt's kinematics or NLP: closed-form
SCARA inverse kinematics over a grid of designs, a plain-numpy DH chain, numerically integrated splines.
A wrong force direction, a dropped time step, K in place of K^-1 or a reversed placement rotation makes one
of these fail (`make mutate` checks that it does).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from designopt import toolpaths
from designopt.config import parse_config
from designopt.costs import DesignCost
from designopt.evaluation import evaluate
from designopt.initial_guess import initial_guess
from designopt.kinematics.joints import Role
from designopt.kinematics.transforms import placement_transform
from designopt.problem import problem_from_config
from designopt.solve import SolverProfile, solve_guess
from designopt.transcriptions import Collocation
from designopt.transcriptions.nlp import model_inputs, waypoint_terms
from designopt.transcriptions.trajectory import PiecewiseLinear

PROFILE = SolverProfile(max_iter=500, compile="none")

# ---------------------------------------------------------------------------------------------------------
# Independent reference implementations (plain numpy, written from the SPEC's formulas)


def ref_dh(theta, d, a, alpha):
    ct, st, ca_, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st * ca_, st * sa, a * ct], [st, ct * ca_, -ct * sa, a * st], [0, sa, ca_, d],
                     [0, 0, 0, 1.0]])


def ref_placement(x, y, z, yaw, pitch, roll):
    """T_BW = Trans(x, y, z) Rz(yaw) Ry(pitch) Rx(roll), the ZYX Euler matrix written out."""
    cy, sy, cp, sp, cr, sr = (math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch), math.cos(roll),
                              math.sin(roll))
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr, x],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr, y],
        [-sp, cp * sr, cp * cr, z],
        [0, 0, 0, 1.0],
    ])


def ref_waypoint(structure, rows, placement, q, s_W, f_W, k, deflection="full"):
    """Tool position and axis in W and L_d = |C w|^2 at one waypoint, from the SPEC's definitions."""
    T, origins, axes = np.eye(4), [], []
    for link_type, row, qi in zip(structure, rows, q, strict=True):
        origins.append(T[:3, 3].copy())
        axes.append(T[:3, 2].copy())
        theta = qi if link_type == "R" else row["theta"]
        d = qi if link_type == "P" else row["d"]
        T = T @ ref_dh(theta, d, row["a"], row["alpha"])
    p = T[:3, 3]
    J = np.column_stack([np.r_[np.cross(z, p - o), z] if t == "R" else np.r_[z, 0, 0, 0]
                         for t, o, z in zip(structure, origins, axes, strict=True)])
    T_BW = ref_placement(*placement)
    R = T_BW[:3, :3]
    w = np.r_[R @ f_W, 0, 0, 0]
    delta = J @ np.diag(1.0 / np.asarray(k)) @ J.T @ w
    if deflection == "translational":
        delta = delta[:3]
    return R.T @ (p - T_BW[:3, 3]), R.T @ T[:3, 2], float(delta @ delta)


# ---------------------------------------------------------------------------------------------------------
# 1. A SCARA whose optimum is known from closed-form IK over a grid of designs

SCARA_A1 = 0.4  # fixed first link (m)
SCARA_LIMITS = (0.2, 2.9)  # revolute limits (rad): one elbow branch, never straight or folded
SCARA_K = (0.5, 5.0)  # revolute N*m/rad, prismatic N/m: not 1, and not equal
SCARA_LAMBDA = 1.0e-3


def scara_problem(tmp_path: Path, deformation_weight: float = 1.0, **weights):
    """RRP SCARA (all twists 0, tool axis vertical) milling a tilted ellipse: a curved path whose tangent has
    a vertical component, so both the revolute and the prismatic stiffness matter. Design joints: the second
    link length a2 and the workpiece position x, y (W is flipped, roll = pi, so its -z is the tool's +z)."""
    phi = np.linspace(0, 2 * np.pi, 41)
    pts = np.c_[0.12 * np.cos(phi), 0.08 * np.sin(phi), 0.05 * np.sin(phi)]
    (tmp_path / "ellipse.csv").write_text("x,y,z\n" + "".join(f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c in pts))
    cfg = parse_config({
        "toolpath": {"kind": "csv", "file": "ellipse.csv", "waypoints": 20, "force": 1.5},
        # Only a2 is designed: a1 stays fixed, and a3 (which would only add to a2) too.
        "design": ["link2.a", "x", "y"],
        "robot": {"structure": "RRP", "dh": [{"a": SCARA_A1}, {"a": 0.3}, {}],
                  "stiffness": {"revolute": SCARA_K[0], "prismatic": SCARA_K[1]}, "joint_velocity": 50.0},
        "placement": {"xyz": [0.3, 0.3, 0.0], "ypr": [0.0, 0.0, math.pi]},
        "costs": {"regularization": SCARA_LAMBDA, "deformation_weight": deformation_weight},
    }, "scara", tmp_path)
    problem = problem_from_config(cfg)
    # the revolute joints' limits of the closed form (the prismatic joint keeps its default stroke)
    joints = tuple(replace(j, lower=SCARA_LIMITS[0], upper=SCARA_LIMITS[1]) if j.role is Role.MOVING
                   and j.kind == "angle" else j for j in problem.chain.joints)
    return replace(problem, chain=replace(problem.chain, joints=joints), **weights)


def scara_objective(points_W, force_W, a2, x, y):
    """Closed-form objective sum_k dt L_d + lambda a2^2 of the SCARA, vectorised over designs (a2, x, y);
    inf where the path leaves the workspace or a joint leaves its limits (checked at the waypoints)."""
    a2, x, y = (np.asarray(v, float)[..., None] for v in (a2, x, y))
    a1, (lo, hi), (kR, kP) = SCARA_A1, SCARA_LIMITS, SCARA_K
    # W = Trans(x, y, 0) Rx(pi): (u, v, w) in W is (x + u, y - v, -w) in B.
    px, py = x + points_W[:, 0], y - points_W[:, 1]
    Fx, Fy, Fz = force_W[:, 0], -force_W[:, 1], -force_W[:, 2]
    c2 = (px**2 + py**2 - a1**2 - a2**2) / (2 * a1 * a2)
    feasible = np.all(np.abs(c2) <= 1, axis=-1)
    c2 = np.clip(c2, -1, 1)
    s2 = np.sqrt(1 - c2**2)  # the elbow branch with q2 in (0, pi)
    q2 = np.arctan2(s2, c2)
    q1 = np.arctan2(py, px) - np.arctan2(a2 * s2, a1 + a2 * c2)
    q1 = (q1 + np.pi) % (2 * np.pi) - np.pi
    tol = 1e-6  # IPOPT relaxes bounds by ~1e-8
    feasible &= np.all((q1 >= lo - tol) & (q1 <= hi + tol) & (q2 >= lo - tol) & (q2 <= hi + tol), axis=-1)
    ox, oy = a1 * np.cos(q1), a1 * np.sin(q1)
    # Joint torques tau_i = J_i^T w over stiffness; C w = sum_i J_i tau_i / k_i.
    m1 = (px * Fy - py * Fx) / kR
    m2 = ((px - ox) * Fy - (py - oy) * Fx) / kR
    dx, dy, dz, wz = -py * m1 - (py - oy) * m2, px * m1 + (px - ox) * m2, Fz / kP, m1 + m2
    L_d = dx**2 + dy**2 + dz**2 + wz**2
    value = L_d.sum(axis=-1) / (len(points_W) - 1) + SCARA_LAMBDA * a2[..., 0] ** 2
    return np.where(feasible, value, np.inf)


def grid_optimum(points_W, force_W):
    """Global grid over (a2, x, y), then zoom in around the best point."""
    grids = [np.linspace(0.02, 1.0, 50), np.linspace(-0.8, 0.8, 60), np.linspace(-0.8, 0.8, 60)]
    steps = np.array([g[1] - g[0] for g in grids])
    for _ in range(14):
        mesh = np.meshgrid(*grids, indexing="ij")
        values = scara_objective(points_W, force_W, *mesh)
        i = np.unravel_index(np.argmin(values), values.shape)
        best, value = np.array([m[i] for m in mesh]), values[i]
        steps /= 3
        grids = [np.linspace(c - 3 * s, c + 3 * s, 19) for c, s in zip(best, steps, strict=True)]
    return best, value


def test_scara_optimum_matches_closed_form_grid(tmp_path):
    problem = scara_problem(tmp_path, smoothness=0.0, joint_regularization=0.0)
    assert [j.name for j in problem.chain.design] == ["placement.x", "placement.y", "link2.a"]
    tp = problem.toolpath
    sols = [solve_guess(problem, Collocation(), PROFILE, initial_guess(problem, i, 0, 0.3)) for i in range(3)]
    best = min((s for s in sols if s.metrics.tracks), key=lambda s: s.raw.objective)
    x, y, a2 = best.raw.q_d

    # The objective at TO's answer, recomputed in closed form, is the NLP's objective and the reported cost.
    closed = float(scara_objective(tp.points_W, tp.force_W, a2, x, y))
    assert np.isfinite(closed), "TO's design violates the closed-form workspace or joint limits"
    assert best.raw.objective == pytest.approx(closed, rel=1e-7)
    assert best.metrics.design_cost + best.metrics.regularization == pytest.approx(closed, rel=1e-7)

    # No design on the grid is better, and the zoomed grid lands on TO's design.
    grid_design, grid_value = grid_optimum(tp.points_W, tp.force_W)
    assert best.raw.objective <= grid_value * (1 + 1e-7)
    assert grid_value <= best.raw.objective * (1 + 1e-4)
    np.testing.assert_allclose([a2, x, y], grid_design, atol=5e-3)
    # And it is not a flat landscape: a design 5 cm away costs measurably more.
    assert float(scara_objective(tp.points_W, tp.force_W, a2, x + 0.05, y)) > 1.001 * closed


# ---------------------------------------------------------------------------------------------------------
# 2. The NLP's objective is the sum of its terms, each computed separately


def hermite_acceleration_numeric(q0, v0, q1, v1, h):
    """Integral of the squared acceleration of the cubic through (0, q0, v0), (h, q1, v1), by quadrature."""
    A = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [1, h, h**2, h**3], [0, 1, 2 * h, 3 * h**2]])
    c = np.linalg.solve(A, [q0, v0, q1, v1])
    nodes, weights = np.polynomial.legendre.leggauss(4)  # exact for the quadratic acceleration squared
    t = 0.5 * h * (nodes + 1)
    acc = 2 * c[2] + 6 * c[3] * t
    return 0.5 * h * float(weights @ acc**2)


@pytest.mark.parametrize("tracking", ["hard", "soft"])
def test_objective_equals_design_cost_plus_every_other_term(tmp_path, tracking):
    smooth, joint_reg, w_d, w_t = 1e-5, 1e-4, 3.0, 50.0
    problem = scara_problem(tmp_path, smoothness=smooth, joint_regularization=joint_reg, deformation_weight=w_d,
                            tracking_weight=w_t)
    sol = solve_guess(problem, Collocation(tracking=tracking), PROFILE, initial_guess(problem, 1, 0, 0.3))
    assert sol.raw.success, sol.raw.status
    Q, V, q_d, h = sol.raw.Q, sol.raw.V, sol.raw.q_d, problem.toolpath.dt
    m = sol.metrics
    smoothness = sum(hermite_acceleration_numeric(Q[k, j], V[k, j], Q[k + 1, j], V[k + 1, j], h)
                     for k in range(len(Q) - 1) for j in range(Q.shape[1]))
    tracking_term = 0.0
    if tracking == "soft":
        tracking_term = w_t * h * float(np.sum(m.position_error**2 + m.axis_error**2))
    expected = (w_d * m.design_cost + SCARA_LAMBDA * q_d[2] ** 2 + smooth * smoothness
                + joint_reg * h * float(np.sum(Q**2)) + tracking_term)
    assert sol.raw.objective == pytest.approx(expected, rel=1e-9)
    # The design cost itself is sum_k dt L_d in the reference implementation.
    tp, rows = problem.toolpath, [{"theta": 0.0, "d": 0.0, "a": SCARA_A1, "alpha": 0.0},
                                  {"theta": 0.0, "d": 0.0, "a": q_d[2], "alpha": 0.0},
                                  {"theta": 0.0, "d": 0.0, "a": 0.0, "alpha": 0.0}]
    placement = (q_d[0], q_d[1], 0.0, 0.0, 0.0, math.pi)
    k = (SCARA_K[0], SCARA_K[0], SCARA_K[1])
    L_d = [ref_waypoint("RRP", rows, placement, Q[i], tp.points_W[i], tp.force_W[i], k)[2] for i in range(tp.n)]
    assert m.design_cost == pytest.approx(h * sum(L_d), rel=1e-12)


# ---------------------------------------------------------------------------------------------------------
# 3. Optimizer and evaluation agree with the reference at random points


@pytest.mark.parametrize("deflection", ["full", "translational"])
def test_optimizer_and_evaluation_agree_with_reference_at_random_points(deflection, rng):
    structure = "RPRRPR"
    rows = [{"theta": rng.uniform(-3, 3), "d": rng.uniform(0, 0.5), "a": rng.uniform(0, 0.5),
             "alpha": rng.uniform(-3, 3)} for _ in structure]
    cfg = parse_config({"robot": {"structure": structure, "dh": rows, "stiffness": {"revolute": 3.0, "prismatic": 0.2}},
                        "placement": {"xyz": [0.4, -0.3, 0.2], "ypr": [0.7, -0.4, 1.1]},
                        "costs": {"deflection": deflection}, "toolpath": {"kind": "circle", "waypoints": 9}})
    problem = problem_from_config(cfg)
    chain, h = problem.chain, problem.toolpath.dt
    # the optimizer's per-waypoint function: phi = dt * L_d (+ nothing else here), c = (p_W - s_W, z_W)
    terms, _, _ = waypoint_terms(problem, "hard")
    for _ in range(5):
        q, q_d, s_W, f_W, dh, placement = _random_point(rng, chain, rows)
        p_ref, z_ref, L_ref = ref_waypoint(structure, dh, placement, q, s_W, f_W, [3.0, 0.2, 3, 3, 0.2, 3],
                                           deflection)
        phi, c = terms(np.r_[q, q_d], s_W, f_W, [h, 1.0], *model_inputs(problem))
        c = np.array(c).ravel()
        np.testing.assert_allclose(c[:3], p_ref - s_W, atol=1e-12)
        np.testing.assert_allclose(c[3:6], z_ref, atol=1e-12)
        assert float(phi) / h == pytest.approx(L_ref, rel=1e-10)
        # The evaluation (the reported numbers) on a path through this point and three others, each with its own
        # joints and force: every waypoint's numbers where they belong, the sums weighted by the path's dt.
        S, F = np.vstack([s_W, rng.normal(size=(3, 3))]), np.vstack([f_W, rng.normal(size=(3, 3))])
        Q = np.vstack([q, rng.uniform(-2, 2, (3, chain.n_moving))])
        tp = toolpaths.Toolpath("points", np.linspace(0.0, 1.0, 4), S, np.zeros((4, 3)), F)
        m = evaluate(replace(problem, toolpath=tp), q_d, PiecewiseLinear(tp.t, Q))
        refs = [ref_waypoint(structure, dh, placement, Q[k], S[k], F[k], [3.0, 0.2, 3, 3, 0.2, 3], deflection)
                for k in range(4)]
        assert refs[0][2] == L_ref
        np.testing.assert_allclose(m.deformation, [r[2] for r in refs], rtol=1e-10)
        np.testing.assert_allclose(m.position_error, [np.linalg.norm(r[0] - S[k]) for k, r in enumerate(refs)],
                                   rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(m.axis_error, [np.linalg.norm(r[1] - [0, 0, -1]) for r in refs], rtol=1e-9,
                                   atol=1e-12)
        assert m.design_cost == pytest.approx(sum(w * r[2] for w, r in zip(tp.weights, refs, strict=True)),
                                              rel=1e-10)
        T_BW = ref_placement(*placement)  # the path's points in B: the stand-off is their least distance from z_B
        assert m.min_standoff == pytest.approx(min(np.hypot(*(T_BW[:3, :3] @ s + T_BW[:3, 3])[:2]) for s in S),
                                               rel=1e-10)


def test_one_block_serves_every_stiffness_deflection_and_weight(rng):
    """The per-waypoint terms take K^-1, the deflection's rows and the terms' weights as inputs: two models of one
    robot and path have the same terms (the compile cache's key), and each model's inputs give its own cost."""
    structure = "RRPR"
    rows = [{"theta": rng.uniform(-3, 3), "d": rng.uniform(0, 0.5), "a": rng.uniform(0, 0.5),
             "alpha": rng.uniform(-3, 3)} for _ in structure]
    models = {"paper": ({}, "full", 1.0, [1.0] * 4),
              "physical": ({"revolute": 3.0, "prismatic": 0.2}, "translational", 250.0, [3.0, 3.0, 0.2, 3.0])}
    problems, terms = {}, {}
    for name, (stiffness, deflection, weight, _) in models.items():
        robot = {"structure": structure, "dh": rows, **({"stiffness": stiffness} if stiffness else {})}
        cfg = parse_config({"robot": robot, "placement": {"xyz": [0.4, -0.3, 0.2], "ypr": [0.7, -0.4, 1.1]},
                            "costs": {"deflection": deflection, "deformation_weight": weight},
                            "toolpath": {"kind": "circle", "waypoints": 9}})
        # a design term the per-waypoint terms carry (not quadratic), weighted differently per model
        problems[name] = problem_from_config(cfg).with_cost(DesignCost("spread", weight / 50.0, _quartic))
        terms[name] = waypoint_terms(problems[name], "hard")[0]
    assert terms["paper"].serialize() == terms["physical"].serialize()
    chain, h = problems["paper"].chain, problems["paper"].toolpath.dt
    q, q_d, s_W, f_W, dh, placement = _random_point(rng, chain, rows)
    for name, (_, deflection, weight, k) in models.items():
        L_ref = ref_waypoint(structure, dh, placement, q, s_W, f_W, k, deflection)[2]
        phi, _ = terms["paper"](np.r_[q, q_d], s_W, f_W, [h, 1.0], *model_inputs(problems[name]))
        spread = weight / 50.0 * (q_d[0] - 0.1) ** 4 / problems[name].toolpath.n
        assert float(phi) == pytest.approx(h * weight * L_ref + spread, rel=1e-10)


def _random_point(rng, chain, rows):
    """Random joints, design joints (within their bounds, |v| <= 1), waypoint and force, and the DH rows and
    placement of that design for the numpy reference (``rows``: the configured DH rows, a design joint replaces its
    entry)."""
    q = rng.uniform(-2, 2, chain.n_moving)
    q_d = np.array([rng.uniform(max(j.lower, -1), min(j.upper, 1)) for j in chain.design])
    s_W, f_W = rng.normal(size=3), rng.normal(size=3)
    values = dict(zip([j.name for j in chain.design], q_d, strict=True))
    dh = [{p: values.get(f"link{i + 1}.{p}", row[p]) for p in ("theta", "d", "a", "alpha")}
          for i, row in enumerate(rows)]
    placement = [values[f"placement.{p}"] for p in ("x", "y", "z", "yaw", "pitch", "roll")]
    return q, q_d, s_W, f_W, dh, placement


def _quartic(chain, q_d):
    """A design term that is not quadratic: the per-waypoint terms carry it, spread over the waypoints."""
    return (q_d[0] - 0.1) ** 4


def test_symbolic_deformation_uses_inverse_stiffness():
    """One revolute joint, link L along x: L_d = |J J^T w / k|^2 = (L^4 + L^2) F^2 / k^2 (numeric and CasADi)."""
    from designopt import costs

    L, k, F = 0.7, 4.0, 3.0
    J = np.array([[0.0], [L], [0.0], [0.0], [0.0], [1.0]])
    expected = (L**4 + L**2) * F**2 / k**2
    force = np.array([0.0, F, 0.0])
    assert costs.deformation(J, np.array([1 / k]), force) == pytest.approx(expected)
    assert float(costs.deformation(ca.SX(ca.DM(J)), np.array([1 / k]), ca.SX(ca.DM(force)))) == pytest.approx(expected)


# ---------------------------------------------------------------------------------------------------------
# 4. Placement and force direction against their closed forms


def test_placement_transform_is_zyx_euler(rng):
    for _ in range(20):
        args = (*rng.uniform(-2, 2, 3), *rng.uniform(-3, 3, 3))
        np.testing.assert_allclose(placement_transform(*args), ref_placement(*args), atol=1e-12)


@pytest.mark.parametrize("kind", ["figure_eight", "circle", "line", "csv"])
def test_force_points_along_the_closed_form_tangent(kind):
    alpha, n = 2.5, 41
    t = np.linspace(0, 1, n)
    w = 2 * np.pi * t
    if kind == "figure_eight":
        tp = toolpaths.figure_eight(0.6, 0.3, n, alpha)
        velocity = np.c_[0.6 * np.pi * np.cos(w), 0.3 * 2 * np.pi * np.cos(2 * w), 0 * t]
    elif kind == "circle":
        tp = toolpaths.circle(0.15, n, alpha)
        velocity = np.c_[-np.sin(w), np.cos(w), 0 * t]
    elif kind == "line":
        tp = toolpaths.line(0.5, n, alpha)
        velocity = np.tile([1.0, 0.0, 0.0], (n, 1))
    else:
        # An L-shaped polyline: along +x, then along +y. Away from the corner the tangent is exact.
        tp = toolpaths.from_points(np.array([[0, 0, 0], [1.0, 0, 0], [1.0, 1.0, 0]]), n, alpha)
        velocity = np.where((tp.points_W[:, 0] < 1 - 1e-9)[:, None], [1.0, 0, 0], [0, 1.0, 0])
        corner = np.abs(tp.points_W[:, 0] - 1) + np.abs(tp.points_W[:, 1]) < 0.06
        velocity, tp = velocity[~corner], replace(tp, force_W=tp.force_W[~corner])
    expected = alpha * velocity / np.linalg.norm(velocity, axis=1, keepdims=True)
    np.testing.assert_allclose(tp.force_W, expected, atol=1e-12)
