"""Cost terms of the design problem (SPEC §3), as pure functions over numpy or CasADi values, and the named,
weighted terms a `DesignProblem` holds.

* ``tracking``      L_t = |p - s_B|^2 + |z - z*|^2
* ``compliance``    C(q) = J K^-1 J^T, 6 x 6, in the base frame
* ``deformation``   L_d = |C w|^2 (full) or |(C w)_{1:3}|^2 (translational), w = (F, 0, 0, 0)
* ``regularization`` L_r = lambda_r * sum of squared design lengths (Whitman et al.)
* ``design_cost``   sum_k dt L_d(t_k): the number every method is compared on

A problem's objective is a sum of named terms (crocoddyl's ``costs.addCost(name, cost, weight)``):
`WaypointCost` ``sum_k dt * weight * fn(waypoint_k)`` integrated along the path, and `DesignCost`
``weight * fn(chain, q_d)`` on the design joints alone. Each term's value before its weight is reported as
``cost_<name>`` (in Metrics, summary.csv and the solution file). Adding a per-waypoint term is its function of
a `Waypoint` and one `DesignProblem.with_cost` call; both transcriptions and the exact structured Hessian
pick it up.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np

from designopt.kinematics.chain import geometric_jacobian, placement_pose, tool_pose
from designopt.kinematics.joints import REGULARISED, Chain, Role
from designopt.kinematics.transforms import is_symbolic


@dataclass(frozen=True)
class Waypoint:
    """What a per-waypoint cost sees at one waypoint, numbers or CasADi symbols alike.

    Frames: B (robot base) unless a name ends in _W (workpiece). ``q`` moving joints, ``q_d`` design joints,
    ``T_BW`` the placement, ``p``/``z`` tool position (m) and tool axis, ``J`` the 6 x n_m geometric
    Jacobian, ``s_W``/``f_W`` the waypoint (m) and its process force (N) in W, ``force`` that force in B,
    ``k_inv`` the inverse joint stiffnesses, ``deflection`` full or translational (or, in a symbolic waypoint,
    the weights of the deflection's six rows: see `deflection_rows`).
    """

    q: object
    q_d: object
    T_BW: object
    p: object
    z: object
    J: object
    s_W: object
    f_W: object
    force: object
    k_inv: object
    deflection: object

    @property
    def p_W(self):
        """Tool position in W."""
        R, t = self.T_BW[:3, :3], self.T_BW[:3, 3]
        return R.T @ (self.p - t)

    @property
    def z_W(self):
        """Tool axis in W."""
        return self.T_BW[:3, :3].T @ self.z


Z_DOWN = np.array([0.0, 0.0, -1.0])  # the target tool axis in W: into the surface


def waypoint(chain: Chain, q, q_d, s_W, f_W, k_inv, deflection) -> Waypoint:
    """The state at one waypoint from the chain's kinematics. The pose and the Jacobian walk the chain separately:
    sharing one walk changes the CasADi graph, and with it the default job's trajectory by ~2e-6 (measured)."""
    T_BW = placement_pose(chain, q, q_d)
    T_BT, J = tool_pose(chain, q, q_d), geometric_jacobian(chain, q, q_d)
    return Waypoint(q=q, q_d=q_d, T_BW=T_BW, p=T_BT[:3, 3], z=T_BT[:3, 2], J=J,
                    s_W=s_W, f_W=f_W, force=T_BW[:3, :3] @ f_W, k_inv=k_inv, deflection=deflection)


def tracking_residual(w: Waypoint):
    """(p_W - s_W, z_W - z*): the position and tool-axis errors in W that L_t squares (z* = (0, 0, -1))."""
    return w.p_W - w.s_W, w.z_W - Z_DOWN


@dataclass(frozen=True)
class WaypointCost:
    """``sum_k dt * weight * fn(waypoint_k)``: a term integrated along the path (fn: Waypoint -> scalar)."""

    name: str
    weight: float
    fn: Callable[[Waypoint], object]


@dataclass(frozen=True)
class DesignCost:
    """``weight * fn(chain, q_d)``: a term on the design joints alone (numpy or CasADi).

    ``quadratic`` terms (constant Hessian, like L_r) go into the NLP's constant Hessian part; the others are
    spread evenly over the waypoints so that the per-waypoint Hessian blocks carry them.
    """

    name: str
    weight: float
    fn: Callable
    quadratic: bool = False

    def __call__(self, chain: Chain, q_d):
        return self.weight * self.fn(chain, q_d)


def sumsqr(x):
    """Sum of squares of a vector, numpy or CasADi (for writing cost terms once for both)."""
    if is_symbolic(x):
        return ca.sumsqr(x)
    x = np.asarray(x, dtype=float).ravel()
    return float(x @ x)


def deformation_term(w: Waypoint):
    """L_d at a waypoint: the deformation cost of SPEC §3 (``design_cost`` is its integral)."""
    return deformation(w.J, w.k_inv, w.force, w.deflection)


def design_length_indices(chain: Chain) -> list[int]:
    """Indices into q_d of the design joints tagged as regularised lengths (DH d and a, URDF origin xyz)."""
    return [i for i, j in enumerate(j for j in chain.joints if j.role is Role.DESIGN) if REGULARISED in j.tags]


def regularization_term(chain: Chain, q_d):
    """sum of squared design lengths (m^2): Whitman et al.'s L_r before its weight lambda_r."""
    index = design_length_indices(chain)
    if not index:
        return 0.0
    return sumsqr(q_d[index] if is_symbolic(q_d) else np.asarray(q_d, dtype=float)[index])

DEFLECTION_MODES = ("full", "translational")


@dataclass(frozen=True)
class Stiffness:
    """Joint stiffness model: revolute in N*m/rad, prismatic in N/m. The paper's model is both = 1.

    Either two values (one per joint type) or ``per_joint`` (one per moving joint, base to tool), which
    overrides them; ``name`` names a preset (see `STIFFNESS_PRESETS`) so that results can state it.
    """

    revolute: float = 1.0
    prismatic: float = 1.0
    per_joint: tuple[float, ...] | None = None
    name: str = ""

    def diagonal(self, structure: str) -> np.ndarray:
        """Diagonal of K for the moving joints of a structure, base to tool."""
        if self.per_joint is not None:
            if len(self.per_joint) != len(structure):
                raise ValueError(f"{len(self.per_joint)} joint stiffnesses for {len(structure)} moving joints")
            return np.array(self.per_joint, dtype=float)
        return np.array([self.revolute if c == "R" else self.prismatic for c in structure], dtype=float)

    @property
    def is_paper_model(self) -> bool:
        if self.per_joint is not None:
            return all(k == 1.0 for k in self.per_joint)
        return self.revolute == 1.0 and self.prismatic == 1.0

    def by_type(self) -> tuple[float, float]:
        """(revolute, prismatic) of the two-value model; NaN for a per-joint model (it has no such pair)."""
        return (math.nan, math.nan) if self.per_joint is not None else (self.revolute, self.prismatic)

    def describe(self) -> str:
        """The model in words, with units: every result states the one it used."""
        if self.is_paper_model:
            return "K = I (the paper's: 1 N*m/rad = 1 N/m)"
        if self.per_joint is not None:
            label = f"{self.name}: " if self.name else ""
            return f"per joint, {label}" + ", ".join(f"{k:g}" for k in self.per_joint) + \
                " (N*m/rad revolute, N/m prismatic; base to tool)"
        return f"revolute {self.revolute:g} N*m/rad, prismatic {self.prismatic:g} N/m"


# Joint stiffness presets (N*m/rad, base to tool). Industrial robots' joint stiffnesses are rarely published by
# their makers; identification studies of heavy-payload 6R robots (Dumas, Caro, Garnier, Furet, "Joint stiffness
# identification of six-revolute industrial serial robots", Robotics and Computer-Integrated Manufacturing 27(4),
# 2011, on a KUKA KR240-2) report the main axes at the order of 1e6 N*m/rad and the wrist axes about an order of
# magnitude lower. `industrial_6r` encodes that profile; it is a representative profile, not one robot's
# identified values: use your robot's own identified values for a real cell (docs/production.md).
STIFFNESS_PRESETS: dict[str, tuple[float, ...]] = {
    "industrial_6r": (3.0e6, 2.5e6, 1.5e6, 3.0e5, 2.5e5, 1.5e5),
}


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


def deflection_rows(mode: str) -> np.ndarray:
    """The weights (0 or 1) of the deflection's six rows (translation m, rotation rad) that L_d squares."""
    return np.array([1.0, 1.0, 1.0, *([1.0] * 3 if _known(mode) == "full" else [0.0] * 3)])


def _known(mode: str) -> str:
    """``mode`` if it is a deflection mode (`DEFLECTION_MODES`), else a ValueError naming the modes."""
    if mode not in DEFLECTION_MODES:
        raise ValueError(f"deflection must be one of {DEFLECTION_MODES}, got {mode!r}")
    return mode


def deformation(J, k_inv, force_B, mode="full"):
    """L_d = |C w|^2 over all six rows (``full``, the paper) or the first three (``translational``).

    ``mode`` may also be the six rows' weights as a CasADi symbol (`deflection_rows`' values given at run time), so
    that one compiled block serves every stiffness and deflection model: L_d = |diag(rows) C w|^2.
    """
    delta = deflection(J, k_inv, force_B)
    if is_symbolic(mode):
        return ca.sumsqr(mode * delta)
    if _known(mode) == "translational":
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


def design_cost(deformations, weights) -> float:
    """The reported design cost: sum_k w_k L_d(t_k) over all N waypoints (w_k = dt on a uniform path)."""
    return float(np.sum(np.asarray(weights) * np.asarray(deformations)))
