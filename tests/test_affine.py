"""Affine constraint rows (`designopt.transcriptions.affine`): their stated Jacobian and their mapped values are
CasADi's own derivative and evaluation of the rows' expression, to the bit."""

import casadi as ca
import numpy as np
import pytest

from designopt.transcriptions.affine import Affine
from designopt.transcriptions.collocation import _mid_q, _mid_tie, _mid_v
from designopt.transcriptions.forward_kinematics import _step
from designopt.transcriptions.jacobian import assemble_jacobian
from designopt.transcriptions.nlp import ConstraintList

M, N = 3, 40


def _layout(rng, uniform: bool):
    """x = (Q, V, Mid) as M x N, M x N and M x (N - 1) blocks in a shuffled order, and the interval steps."""
    x = ca.SX.sym("x", 3 * M * N)
    where = rng.permutation(3 * M * N)
    Q, V, Mid = (where[k * M * N : (k + 1) * M * N].reshape(M, N) for k in range(3))
    h = 0.37 if uniform else np.tile(rng.uniform(1e-3, 0.3, N - 1), (M, 1))
    knots = (Q[:, :-1], V[:, :-1], Q[:, 1:], V[:, 1:])
    return x, knots, Mid[:, :-1], h


def _entries(x, knots, mid, h):
    return [Affine(_mid_q, x, knots, (h,)), Affine(_mid_v, x, knots, (h,)), Affine(_mid_tie, x, (mid, *knots), (h,)),
            Affine(_step, x, (knots[0], knots[2]))]


@pytest.mark.parametrize("uniform", [True, False])
def test_the_stated_jacobian_is_casadis_derivative_of_the_expression_to_the_bit(rng, uniform):
    x, knots, mid, h = _layout(rng, uniform)
    for entry in _entries(x, knots, mid, h):
        rows, cols, values = entry.jacobian
        stated = np.zeros((entry.size, x.shape[0]))
        stated[rows, cols] = values
        derived = ca.jacobian(entry.expression, x)
        assert derived.nnz() == len(values)  # the same structure: no entry dropped, none added
        reference = np.array(ca.evalf(ca.densify(derived)))
        np.testing.assert_array_equal(stated, reference)


@pytest.mark.parametrize("uniform", [True, False])
def test_the_expression_is_fn_entry_by_entry_in_casadis_column_order(rng, uniform):
    x, knots, mid, h = _layout(rng, uniform)
    point = rng.normal(size=x.shape[0])
    for entry in _entries(x, knots, mid, h):
        whole = np.array(ca.Function("whole", [x], [entry.expression])(point)).ravel()
        numeric = entry.fn(*(point[i] for i in entry.index), *entry.constants)
        np.testing.assert_array_equal(whole, np.ravel(numeric, order="F"))


def test_the_assembled_jacobian_of_affine_rows_is_the_derived_one(rng):
    """`assemble_jacobian` given the constant rows of a `ConstraintList` equals CasADi's Jacobian of the same rows
    (nothing else in the list derived), with a non-affine row beside them derived as before."""
    x, knots, mid, h = _layout(rng, uniform=False)
    cons = ConstraintList()
    for entry in _entries(x, knots, mid, h):
        cons.add(entry, -1.0, 1.0)
    cons.add(ca.sin(x[0]) * x[1], 0.0, 0.0)
    stacked = cons.stacked()[0]
    ours = assemble_jacobian(x, cons.size, cons.rows, None, [], cons.constant_jacobian)
    reference = ca.Function("reference", [x], [ca.jacobian(stacked, x)])
    point = rng.normal(size=x.shape[0])
    a, b = ours(point, [])[1], reference(point)
    assert a.sparsity() == b.sparsity()
    np.testing.assert_array_equal(np.array(a.nonzeros()), np.array(b.nonzeros()))


def test_every_affine_operation_gives_casadis_derivative_to_the_bit(rng):
    """Sums and differences with numbers on either side, negation, products and quotients by constants and by
    arrays of them."""
    x, knots, mid, h = _layout(rng, uniform=False)

    def fn(a, b, c, step):
        return 2.0 - a / step + 3.0 * b - (b + 1.0) + (-c) * 0.7 + 1.0 + step * (c - 0.1) / 3.0

    entry = Affine(fn, x, knots[:3], (h,))
    rows, cols, values = entry.jacobian
    derived = ca.jacobian(entry.expression, x)
    stated = np.zeros((entry.size, x.shape[0]))
    stated[rows, cols] = values
    assert derived.nnz() == len(values)
    np.testing.assert_array_equal(stated, np.array(ca.evalf(ca.densify(derived))))


def test_rows_that_are_not_affine_or_not_elementwise_are_refused(rng):
    x, knots, mid, h = _layout(rng, uniform=True)
    with pytest.raises(TypeError, match="not affine"):
        _ = Affine(lambda a, b: a * b, x, knots[:2]).jacobian
    with pytest.raises(TypeError, match="does not depend"):
        _ = Affine(lambda a, b: 2.0, x, knots[:2]).jacobian
    with pytest.raises(ValueError, match="two arguments of the same row"):
        _ = Affine(lambda a, b: a - b, x, (knots[0], knots[0])).jacobian
    with pytest.raises(ValueError, match="differ in shape"):
        Affine(_step, x, (knots[0], mid[:, :-1]))
