"""Cost terms of the design problem (SPEC §3), as pure functions over numpy or CasADi values.

* ``tracking``      L_t = |p - s_B|^2 + |z - z*|^2
* ``compliance``    C(q) = J K^-1 J^T, 6 x 6, in the base frame
* ``deformation``   L_d = |C w|^2 (full) or |(C w)_{1:3}|^2 (translational), w = (F, 0, 0, 0)
* ``regularization`` L_r = lambda_r * sum of squared design lengths (Whitman et al.)
* ``design_cost``   sum_k dt L_d(t_k): the number every method is compared on
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from designopt.kinematics.transforms import is_symbolic

DEFLECTION_MODES = ("full", "translational")


@dataclass(frozen=True)
class Stiffness:
    """Joint stiffness model: revolute in N*m/rad, prismatic in N/m. The paper's model is both = 1."""

    revolute: float = 1.0
    prismatic: float = 1.0

    def diagonal(self, structure: str) -> np.ndarray:
        """Diagonal of K for the moving joints of a structure, base to tool."""
        return np.array([self.revolute if c == "R" else self.prismatic for c in structure], dtype=float)

    @property
    def is_paper_model(self) -> bool:
        return self.revolute == 1.0 and self.prismatic == 1.0

    def describe(self) -> str:
        """The model in words, with units: every result states the one it used."""
        if self.is_paper_model:
            return "K = I (the paper's: 1 N*m/rad = 1 N/m)"
        return f"revolute {self.revolute:g} N*m/rad, prismatic {self.prismatic:g} N/m"


def tracking(p, z, s_B, z_target):
    """Tracking cost L_t: squared position error plus squared tool-axis error (m^2 + dimensionless)."""
    dp, dz = p - s_B, z - z_target
    if is_symbolic(dp, dz):
        return ca.sumsqr(dp) + ca.sumsqr(dz)
    return float(dp @ dp + dz @ dz)


def compliance(J, k_inv):
    """Cartesian compliance C = J K^-1 J^T (6 x 6) for a 6 x n Jacobian and the n inverse stiffnesses."""
    if is_symbolic(J):
        return J @ ca.diag(k_inv) @ J.T
    return J @ np.diag(k_inv) @ J.T


def deflection(J, k_inv, force_B):
    """C w for the wrench w = (F, 0, 0, 0): only the linear rows of J^T act on a pure force."""
    if is_symbolic(J, force_B):
        return J @ (ca.diag(k_inv) @ (J[:3, :].T @ force_B))
    return J @ (k_inv * (J[:3, :].T @ force_B))


def deformation(J, k_inv, force_B, mode: str = "full"):
    """L_d = |C w|^2 over all six rows (``full``, the paper) or the first three (``translational``)."""
    if mode not in DEFLECTION_MODES:
        raise ValueError(f"deflection must be one of {DEFLECTION_MODES}, got {mode!r}")
    delta = deflection(J, k_inv, force_B)
    if mode == "translational":
        delta = delta[:3]
    if is_symbolic(delta):
        return ca.sumsqr(delta)
    return float(np.dot(delta, delta))


def regularization(lengths, weight: float):
    """L_r = weight * sum of squared design lengths (m^2)."""
    if is_symbolic(lengths):
        return weight * ca.sumsqr(lengths)
    lengths = np.asarray(lengths, dtype=float)
    return float(weight * lengths @ lengths)


def design_cost(deformations, dt: float) -> float:
    """The reported design cost: sum_k dt * L_d(t_k) over all N waypoints."""
    return float(dt * np.sum(deformations))
