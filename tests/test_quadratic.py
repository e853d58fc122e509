"""The objective's quadratic terms (`designopt.transcriptions.quadratic`): their value against closed forms, their
constant Hessian and their gradient against CasADi's derivatives of the whole sum, on intervals and weights that
differ point by point (a non-uniform path)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from designopt.config import parse_config
from designopt.problem import problem_from_config
from designopt.transcriptions import quadratic
from designopt.transcriptions.jacobian import assemble_gradient

N = 7  # waypoints; x = (q_d, z_0, ..., z_{N-1}), z_k = (q_k, v_k), as the collocation lays it out


@pytest.fixture(scope="module")
def problem():
    return problem_from_config(parse_config({"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": N}}))


def _terms(problem, rng):
    """The three terms on random intervals and weights, and (q_index, h, weights, n_x)."""
    n_m, n_d = problem.chain.n_moving, problem.chain.n_design
    q_index = n_d + np.arange(N)[:, None] * 2 * n_m + np.arange(n_m)[None, :]
    h, weights = rng.uniform(0.05, 0.3, N - 1), rng.uniform(0.05, 0.3, N)
    terms = (quadratic.smoothness(problem, q_index, q_index + n_m, h),
             quadratic.joint_regularization(problem, q_index, weights),
             *quadratic.design_costs(problem, np.arange(n_d)))
    assert len(terms) == 3  # the default problem has a quadratic design cost (L_r)
    return terms, q_index, h, weights, n_d + N * 2 * n_m


def test_values_are_the_closed_forms(problem, rng):
    """The joint regularisation is weight * sum_k w_k |q_k|^2; the smoothness term the integral of the squared
    acceleration of each cubic Hermite segment, by 4-point Gauss-Legendre (exact for it)."""
    terms, q_index, h, weights, n_x = _terms(problem, rng)
    x = rng.normal(size=n_x)
    Q, V = x[q_index], x[q_index + problem.chain.n_moving]
    regularization = problem.joint_regularization * np.sum(weights[:, None] * Q**2)
    assert float(terms[1].value(ca.DM(x))) == pytest.approx(regularization, rel=1e-12)
    nodes, node_weights = np.polynomial.legendre.leggauss(4)
    integral = 0.0
    for k in range(N - 1):
        s = (nodes + 1) / 2  # [0, 1]
        # q(s) = h00 q0 + h10 h v0 + h01 q1 + h11 h v1; q'' = its second derivative in t = s h
        d2 = [12 * s - 6, (6 * s - 4) * h[k], -12 * s + 6, (6 * s - 2) * h[k]]
        acc = (d2[0][:, None] * Q[k] + d2[1][:, None] * V[k] + d2[2][:, None] * Q[k + 1]
               + d2[3][:, None] * V[k + 1]) / h[k] ** 2
        integral += h[k] / 2 * np.sum(node_weights[:, None] * acc**2)
    assert float(terms[0].value(ca.DM(x))) == pytest.approx(problem.smoothness * integral, rel=1e-9)


def test_hessian_and_gradient_equal_casadis_of_the_sum(problem, rng):
    terms, *_, n_x = _terms(problem, rng)
    x = ca.SX.sym("x", n_x)
    total = quadratic.total(terms, x)
    rows, cols, values = quadratic.constant_hessian(terms)
    ours = np.zeros((n_x, n_x))
    np.add.at(ours, (rows, cols), values)
    assert np.all(rows <= cols)
    reference = np.triu(np.array(ca.evalf(ca.hessian(total, x)[0])))
    np.testing.assert_allclose(ours, reference, rtol=1e-12, atol=1e-14 * np.abs(reference).max())
    grad = assemble_gradient(n_x, ca.Function("f", [x], [total]), quadratic.gradient_groups(terms))
    reference_grad = ca.Function("g", [x], [total, ca.gradient(total, x)])
    for _ in range(3):
        at = rng.normal(size=n_x)
        for a, b in zip(grad(at, []), reference_grad(at), strict=True):
            np.testing.assert_allclose(np.array(a), np.array(b), rtol=1e-10, atol=1e-14)


def test_a_term_that_is_not_quadratic_is_refused():
    y = ca.SX.sym("y", 2)
    cubic = quadratic.QuadraticTerm(ca.Function("cubic", [y], [y[0] ** 3 + y[1] ** 2]), np.array([[0, 1]]))
    with pytest.raises(ValueError, match="not quadratic"):
        quadratic.constant_hessian((cubic,))
