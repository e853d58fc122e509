"""Constraint rows affine in the decision vector, with their constant Jacobian stated rather than derived.

The rows of a transcription that sit in no per-point block (the collocation's midpoint rows, the FK baseline's
joint steps) are affine in x: their Jacobian A is a constant matrix. CasADi can derive it from their SX
expressions, but that symbolic Jacobian of tens of thousands of rows was the largest single part of a
1,208-waypoint program's warm build (0.17-0.25 s of 0.66-0.83 s; benchmarks/speed_table.py). An `Affine` entry
carries A as triplets next to the expression, read off the same function the expression is built from.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np


class _Tangent:
    """A derivative carried through an affine function evaluated on numbers (forward mode), each operation as
    CasADi's derivative of an SX expression with numeric constants computes it: a sum's derivatives added, a
    product's scaled by the constant, a quotient's scaled by the constant's reciprocal (1/c, then the product: what
    CasADi folds the partial derivative of x/c to). Anything else is not affine: TypeError."""

    __array_ufunc__ = None  # a numpy array on the left defers to the reflected operations below

    def __init__(self, d):
        self.d = d

    def __add__(self, other):
        return _Tangent(self.d + other.d) if isinstance(other, _Tangent) else self

    __radd__ = __add__

    def __sub__(self, other):
        return _Tangent(self.d - other.d) if isinstance(other, _Tangent) else self

    def __rsub__(self, other):
        return -self

    def __neg__(self):
        return _Tangent(-self.d)

    def __mul__(self, other):
        if isinstance(other, _Tangent):
            raise TypeError("Affine: a product of two arguments is not affine")
        return _Tangent(other * self.d)

    __rmul__ = __mul__

    def __truediv__(self, other):
        if isinstance(other, _Tangent):
            raise TypeError("Affine: a quotient of two arguments is not affine")
        return _Tangent((1.0 / np.asarray(other, float)) * self.d)


@dataclass(frozen=True, eq=False)
class Affine:
    """Constraint rows fn(x[index_1], ..., x[index_k], *constants), taken elementwise and stacked column by column
    (CasADi's vec), with fn affine in its first k arguments (e.g. `trajectory.hermite_midpoint`, its step a
    constant), each index array (m x n, positions in the decision vector ``x``) of one shape and each constant a
    number or an m x n array.

    A solve evaluates the rows as their SX ``expression`` and takes their Jacobian as constants (`jacobian`).
    (Evaluated instead as fn mapped over the entries or over chunks of columns, g cost 1.1-1.4x as much an
    evaluation: docs/decisions.md, 2026-12-07.)"""

    fn: Callable
    x: ca.SX
    index: tuple[np.ndarray, ...]
    constants: tuple = ()

    def __post_init__(self):
        if any(np.shape(i) != np.shape(self.index[0]) for i in self.index):
            raise ValueError("Affine: the index arrays differ in shape")

    @property
    def size(self) -> int:
        return int(np.size(self.index[0]))

    @functools.cached_property
    def expression(self) -> ca.SX:
        """The rows as one SX column of ``x`` (built on first use: the rows' values in a solve)."""
        shape = np.shape(self.index[0])
        args = [ca.reshape(self.x[ca.DM(np.ravel(i, order="F").tolist())], *shape) for i in self.index]
        return ca.vec(self.fn(*args, *(ca.DM(c) if np.ndim(c) else c for c in self.constants)))

    @functools.cached_property
    def jacobian(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """dg/dx as triplets (rows within this entry, columns in x, values), each row's entries distinct: fn's
        derivative in each argument evaluated on numpy arrays (`_Tangent`), the same products and quotients
        CasADi's derivative of the expression computes, so the two agree to the bit (tests/test_affine.py).
        Coefficients that come out exactly 0 are left out (an argument the entry does not use)."""
        shape = np.shape(self.index[0])
        numeric = [np.asarray(c, float) if np.ndim(c) else float(c) for c in self.constants]
        rows, cols, values = [], [], []
        for j, index in enumerate(self.index):
            seeds = [_Tangent(np.full(shape, 1.0 if k == j else 0.0)) for k in range(len(self.index))]
            out = self.fn(*seeds, *numeric)
            if not isinstance(out, _Tangent):
                raise TypeError("Affine: fn does not depend on its arguments")
            coefficient = np.broadcast_to(out.d, shape).ravel(order="F")
            used = coefficient != 0.0
            rows.append(np.flatnonzero(used))
            cols.append(np.ravel(index, order="F")[used])
            values.append(coefficient[used])
        rows, cols, values = (np.concatenate(v) for v in (rows, cols, values))
        keys = np.sort(rows * self.x.shape[0] + cols)
        if np.any(keys[1:] == keys[:-1]):
            raise ValueError("Affine: one entry of x appears in two arguments of the same row")
        return rows, cols, values
