"""Kinematics against independent truth: closed forms, finite differences, published reference values."""

from __future__ import annotations

import casadi as ca
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from designopt.design_space import build_chain
from designopt.kinematics import geometric_jacobian, placement_pose, tool_in_workpiece, tool_pose
from designopt.kinematics.presets import preset
from designopt.kinematics.transforms import inverse, placement_transform

angles = st.floats(-np.pi, np.pi)
lengths = st.floats(0.0, 1.0)


def chain_for(structure, rows, placement=(0, 0, 0, 0, 0, 0), free_placement=()):
    return build_chain(structure, rows, [], placement[:3], placement[3:], free_placement)


def test_puma560_at_zero_matches_robotics_toolbox():
    # Corke, Robotics Toolbox: Puma560().fkine(qz) in standard DH -> t = (0.4521, -0.15005, 0.4318) m.
    chain = chain_for("RRRRRR", preset("puma560", 6))
    T = tool_pose(chain, np.zeros(6), np.zeros(0))
    np.testing.assert_allclose(T[:3, 3], [0.4521, -0.15005, 0.4318], atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(a1=lengths, a2=lengths, q1=angles, q2=angles)
def test_planar_2r_closed_form(a1, a2, q1, q2):
    rows = [{"theta": 0.0, "d": 0.0, "a": a1, "alpha": 0.0}, {"theta": 0.0, "d": 0.0, "a": a2, "alpha": 0.0}]
    T = tool_pose(chain_for("RR", rows), np.array([q1, q2]), np.zeros(0))
    expected = [a1 * np.cos(q1) + a2 * np.cos(q1 + q2), a1 * np.sin(q1) + a2 * np.sin(q1 + q2), 0.0]
    np.testing.assert_allclose(T[:3, 3], expected, atol=1e-12)
    np.testing.assert_allclose(T[:3, 2], [0, 0, 1], atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(d=st.lists(st.floats(-1, 1), min_size=3, max_size=3))
def test_ppp_gantry_closed_form(d):
    import conftest

    T = tool_pose(chain_for("PPP", conftest.GANTRY_DH), np.array(d), np.zeros(0))
    np.testing.assert_allclose(T[:3, 3], [d[2], d[1], d[0]], atol=1e-12)


def random_chain(rng, structure):
    rows = [{"theta": rng.uniform(-3, 3), "d": rng.uniform(0, 0.5), "a": rng.uniform(0, 0.5),
             "alpha": rng.uniform(-3, 3)} for _ in structure]
    chain = build_chain(structure, rows, ["d", "a", "alpha"], rng.uniform(-1, 1, 3), rng.uniform(-3, 3, 3),
                        ("x", "y", "z", "yaw", "pitch", "roll"))
    return chain, rng.uniform(-2, 2, chain.n_moving)


@settings(max_examples=30, deadline=None)
@given(structure=st.text(alphabet="RP", min_size=1, max_size=7), seed=st.integers(0, 2**31))
def test_jacobian_matches_finite_differences(structure, seed):
    rng = np.random.default_rng(seed)
    chain, q = random_chain(rng, structure)
    q_d = chain.design_values
    J = geometric_jacobian(chain, q, q_d)
    assert J.shape == (6, len(structure))
    eps = 1e-6
    for i in range(len(q)):
        dq = np.zeros_like(q)
        dq[i] = eps
        Tp, Tm = tool_pose(chain, q + dq, q_d), tool_pose(chain, q - dq, q_d)
        np.testing.assert_allclose(J[:3, i], (Tp[:3, 3] - Tm[:3, 3]) / (2 * eps), atol=1e-7)
        W = (Tp[:3, :3] - Tm[:3, :3]) / (2 * eps) @ tool_pose(chain, q, q_d)[:3, :3].T  # skew(omega)
        np.testing.assert_allclose(J[3:, i], [W[2, 1], W[0, 2], W[1, 0]], atol=1e-7)


def test_symbolic_and_numeric_kinematics_agree(rng):
    chain, q = random_chain(rng, "RPRRPR")
    qs, qds = ca.SX.sym("q", chain.n_moving), ca.SX.sym("qd", chain.n_design)
    f = ca.Function("f", [qs, qds], [tool_in_workpiece(chain, qs, qds), geometric_jacobian(chain, qs, qds)])
    T_sym, J_sym = f(q, chain.design_values)
    np.testing.assert_allclose(np.array(T_sym), tool_in_workpiece(chain, q, chain.design_values), atol=1e-12)
    np.testing.assert_allclose(np.array(J_sym), geometric_jacobian(chain, q, chain.design_values), atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(xyz=st.lists(st.floats(-2, 2), min_size=3, max_size=3), ypr=st.lists(angles, min_size=3, max_size=3))
def test_placement_transform_applied_and_undone(xyz, ypr):
    T = placement_transform(*xyz, *ypr)
    np.testing.assert_allclose(T @ inverse(T), np.eye(4), atol=1e-12)
    np.testing.assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-12)
    assert np.isclose(np.linalg.det(T[:3, :3]), 1.0)


def test_placing_the_workpiece_equals_moving_the_base(rng):
    """Tool pose in W with placement T_BW equals the tool pose seen from W after moving the base by T_BW^-1."""
    chain, q = random_chain(rng, "RRPRRR")
    q_d = chain.design_values
    T_BW = placement_pose(chain, q, q_d)
    np.testing.assert_allclose(tool_in_workpiece(chain, q, q_d), inverse(T_BW) @ tool_pose(chain, q, q_d),
                               atol=1e-12)
    # Placement joints do not change the robot: FK in B is independent of them.
    moved = chain.with_roles({}, {"placement.x": 5.0, "placement.yaw": 1.0})
    q_d2 = moved.design_values
    np.testing.assert_allclose(tool_pose(moved, q, q_d2), tool_pose(chain, q, q_d), atol=1e-12)
    assert not np.allclose(placement_pose(moved, q, q_d2), T_BW)


def test_design_joint_on_prismatic_link_is_theta():
    chain = build_chain("RP", preset("generic", 2), ["d", "a", "alpha"], (0, 0, 0), (0, 0, 0), ())
    names = [j.name for j in chain.design]
    assert names == ["link1.d", "link1.a", "link1.alpha", "link2.theta", "link2.a", "link2.alpha"]
    assert [j.name for j in chain.moving] == ["link1.theta", "link2.d"]
