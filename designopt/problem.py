"""The design problem: a chain with design joints, a toolpath, and the costs -- independent of any solver.

`problem_from_config` is the one place a problem is built from a config (`designopt.config` has validated it and
built its chain, toolpath and cell); transcriptions (TO collocation, the FK baseline) take a `DesignProblem` and
never look at the config.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from designopt import toolpaths
from designopt.clearance import Cell
from designopt.config import Config
from designopt.costs import (
    STIFFNESS_PRESETS,
    DesignCost,
    Stiffness,
    Waypoint,
    WaypointCost,
    deformation_term,
    regularization_term,
    waypoint,
)
from designopt.kinematics.joints import Chain
from designopt.kinematics.urdf import RobotFile


@dataclass(frozen=True)
class DesignProblem:
    """Everything that defines the optimum, nothing about how it is found.

    Units: metres, radians, newtons; task time t in [0, 1]. The objective is the sum of the named, weighted
    terms in ``waypoint_costs`` and ``design_costs`` (see `designopt.costs`), plus the trajectory
    regularisers ``smoothness`` (weight of the integral of |q''|^2) and ``joint_regularization`` (weight of
    sum_k dt |q_k|^2), plus ``tracking_weight`` * L_t when tracking is soft. ``joint_velocity`` bounds
    |dq/dt| per unit of the toolpath's time (one value, or one per moving joint; rad or m per second when the
    toolpath's time is in seconds, see `velocity_limits`); ``position_tol`` (m) and ``axis_tol`` (norm of
    z - z*) define when a solution tracks.
    """

    name: str
    chain: Chain
    toolpath: toolpaths.Toolpath
    stiffness: Stiffness
    deflection: str = "full"
    waypoint_costs: tuple[WaypointCost, ...] = (WaypointCost("deformation", 1.0, deformation_term),)
    design_costs: tuple[DesignCost, ...] = (DesignCost("regularization", 1.0e-3, regularization_term, True),)
    tracking_weight: float = 1.0e4
    smoothness: float = 1.0e-9
    joint_regularization: float = 1.0e-7
    joint_velocity: float | tuple[float, ...] = 10.0
    keep_out_radius: float = 0.0
    position_tol: float = 1.0e-3
    axis_tol: float = 1.0e-2
    cell: Cell | None = None  # block, floor and capsules: clearance constraints (designopt.clearance)
    robot_file: RobotFile | None = None  # the URDF the chain was read from (export keeps its names and meshes)

    @property
    def velocity_limits(self) -> np.ndarray:
        """|dq/dt| bound of each moving joint, base to tool (per unit of the toolpath's time)."""
        return np.broadcast_to(np.asarray(self.joint_velocity, dtype=float), (self.chain.n_moving,)).copy()

    @property
    def max_steps(self) -> np.ndarray:
        """The most each moving joint can move between neighbouring waypoints, v_max h ((N - 1) x n_moving; rad or
        m). No trajectory the collocation accepts moves further: its cubic's velocities at both knots and at the
        midpoint are bounded, and the midpoint's is 3/2 dq/h - (v_0 + v_1)/4."""
        return self.toolpath.h[:, None] * self.velocity_limits[None, :]

    @property
    def k_inv(self) -> np.ndarray:
        """Inverse stiffness of each moving joint, base to tool (rad/(N*m) or m/N)."""
        return 1.0 / self.stiffness.diagonal(self.chain.structure)

    def with_cost(self, cost: WaypointCost | DesignCost) -> DesignProblem:
        """A copy with one more named term in the objective (a name already there is replaced)."""
        if isinstance(cost, WaypointCost):
            kept = tuple(c for c in self.waypoint_costs if c.name != cost.name)
            return replace(self, waypoint_costs=(*kept, cost))
        kept = tuple(c for c in self.design_costs if c.name != cost.name)
        return replace(self, design_costs=(*kept, cost))

    def without_cost(self, name: str) -> DesignProblem:
        return replace(self, waypoint_costs=tuple(c for c in self.waypoint_costs if c.name != name),
                       design_costs=tuple(c for c in self.design_costs if c.name != name))

    def waypoint(self, q, q_d, s_W, f_W) -> Waypoint:
        """The state a per-waypoint cost sees (numbers or CasADi symbols)."""
        return waypoint(self.chain, q, q_d, s_W, f_W, self.k_inv, self.deflection)


def stiffness_from_config(cfg: Config) -> Stiffness:
    """The config's stiffness model (its length against the robot was checked on validation)."""
    k = cfg.robot.stiffness
    if isinstance(k, float | int):
        return Stiffness(float(k), float(k))
    if isinstance(k, str):
        return Stiffness(per_joint=STIFFNESS_PRESETS[k], name=k)
    if isinstance(k, list):
        return Stiffness(per_joint=tuple(float(v) for v in k))
    return Stiffness(k.revolute, k.prismatic)


def with_tool_length(chain: Chain, length: float) -> Chain:
    """The chain with its tool centre point moved ``length`` along the tool z axis (the cell's tool)."""
    tool = np.array(chain.tool, dtype=float) @ np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, length],
                                                         [0, 0, 0, 1.0]])
    return replace(chain, tool=tuple(tuple(float(v) for v in row) for row in tool))


def problem_from_config(cfg: Config) -> DesignProblem:
    """The validated config as a DesignProblem: its chain, toolpath and cell, the stiffness model, and the named
    cost terms (deformation, weighted by ``costs.deformation_weight`` -- a unit choice, the reported cost is
    unweighted -- and the regularisation)."""
    chain, cell = cfg._chain, cfg._cell
    if cell is not None:
        chain = with_tool_length(chain, cell.tool_length)
    return DesignProblem(
        name=cfg.name,
        chain=chain,
        toolpath=cfg._toolpath,
        stiffness=stiffness_from_config(cfg),
        deflection=cfg.costs.deflection,
        waypoint_costs=(WaypointCost("deformation", cfg.costs.deformation_weight, deformation_term),),
        design_costs=(DesignCost("regularization", cfg.costs.regularization, regularization_term, quadratic=True),),
        joint_velocity=cfg._joint_velocity,
        keep_out_radius=cfg.placement.keep_out_radius,
        position_tol=cfg.tolerance.position,
        axis_tol=cfg.tolerance.axis,
        cell=cell,
        robot_file=RobotFile(str((cfg.base_dir / cfg.robot.urdf).resolve()), cfg.robot.tool_link)
        if cfg.robot.is_urdf else None,
    )
