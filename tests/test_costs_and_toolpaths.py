"""Costs by hand and toolpaths against their definitions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designopt import costs, toolpaths
from designopt.evaluation import max_joint_step


@settings(max_examples=30, deadline=None)
@given(L=st.floats(0.05, 2.0), k=st.floats(0.1, 100.0), alpha=st.floats(0.1, 10.0))
def test_one_joint_compliance_by_hand(L, k, alpha):
    # One revolute joint about z with link length L along x at theta = 0: J = (0, L, 0, 0, 0, 1)^T.
    J = np.array([[0.0], [L], [0.0], [0.0], [0.0], [1.0]])
    C = costs.compliance(J, np.array([1.0 / k]))
    np.testing.assert_allclose(C, J @ J.T / k)
    F = np.array([0.0, alpha, 0.0])
    # C w = J (J_v^T F) / k = (0, L^2, 0, 0, 0, L) alpha / k
    expected = np.array([0, L * L, 0, 0, 0, L]) * alpha / k
    np.testing.assert_allclose(costs.deflection(J, np.array([1 / k]), F), expected)
    # abs=0: these costs go down to ~1e-12, where approx's default absolute tolerance (1e-12) would accept anything
    full, translational = (L**4 + L**2) * alpha**2 / k**2, L**4 * alpha**2 / k**2
    assert costs.deformation(J, np.array([1 / k]), F, "full") == pytest.approx(full, rel=1e-10, abs=0)
    assert costs.deformation(J, np.array([1 / k]), F, "translational") == pytest.approx(translational, rel=1e-10, abs=0)


def test_compliance_is_symmetric_psd(rng):
    J = rng.normal(size=(6, 4))
    C = costs.compliance(J, rng.uniform(0.1, 2, 4))
    np.testing.assert_allclose(C, C.T)
    assert np.linalg.eigvalsh(C).min() > -1e-12
    assert np.linalg.matrix_rank(C) == 4


def test_deflection_equals_compliance_times_wrench(rng):
    J, k_inv = rng.normal(size=(6, 5)), rng.uniform(0.1, 2, 5)
    F = rng.normal(size=3)
    np.testing.assert_allclose(costs.deflection(J, k_inv, F), costs.compliance(J, k_inv) @ np.r_[F, 0, 0, 0])


def test_stiffness_model_and_design_cost():
    assert list(costs.Stiffness(2.0, 5.0).diagonal("RPR")) == [2.0, 5.0, 2.0]
    assert costs.Stiffness().is_paper_model
    assert costs.design_cost(np.ones(11), 0.1) == pytest.approx(1.1)
    with pytest.raises(ValueError):
        costs.deformation(np.eye(6), np.ones(6), np.ones(3), "sideways")


def test_figure_eight_definition():
    tp = toolpaths.figure_eight(0.6, 0.3, 81, force=2.5)
    t = tp.t
    np.testing.assert_allclose(tp.points_W[:, 0], 0.3 * np.sin(2 * np.pi * t))
    np.testing.assert_allclose(tp.points_W[:, 1], 0.15 * np.sin(4 * np.pi * t))
    np.testing.assert_allclose(np.linalg.norm(tp.force_W, axis=1), 2.5)
    fd = np.gradient(tp.points_W, t, axis=0, edge_order=2)
    cos = np.sum(fd * tp.tangents_W, axis=1) / np.linalg.norm(fd, axis=1)
    assert cos[1:-1].min() > 0.99  # tangent along the finite-difference velocity
    assert tp.dt == pytest.approx(1 / 80)


@pytest.mark.parametrize("tp", [toolpaths.circle(0.15, 40), toolpaths.line(0.5, 40)])
def test_circle_and_line(tp):
    np.testing.assert_allclose(np.linalg.norm(tp.tangents_W, axis=1), 1.0)
    assert tp.points_W[:, 2].max() == 0.0


def test_points_are_resampled_by_arc_length():
    tp = toolpaths.from_points(np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]]), n=5)
    np.testing.assert_allclose(tp.points_W, [[0, 0, 0], [0.5, 0, 0], [1, 0, 0], [1, 0.5, 0], [1, 1, 0]])
    with pytest.raises(ValueError, match="identical"):
        toolpaths.from_points(np.array([[0, 0, 0], [0, 0, 0], [1, 0, 0]]))


def test_max_joint_step():
    Q = np.array([[0.0, 0.0], [0.1, -0.3], [0.2, 0.2]])
    assert max_joint_step(Q) == pytest.approx(0.5)
    assert max_joint_step(Q[:1]) == 0.0
