"""The design problem: a chain with design joints, a toolpath, and the costs -- independent of any solver.

Transcriptions (TO collocation, the FK baseline) take a `DesignProblem` and never look at the config.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from designopt import toolpaths
from designopt.config import Config, dh_rows
from designopt.costs import Stiffness
from designopt.design_space import JointBounds, build_chain, design_lengths
from designopt.kinematics.joints import Chain


@dataclass(frozen=True)
class DesignCost:
    """A named, weighted cost on the design joints only: weight * fn(chain, q_d) (numpy or CasADi)."""

    name: str
    weight: float
    fn: Callable

    def __call__(self, chain: Chain, q_d):
        return self.weight * self.fn(chain, q_d)


@dataclass(frozen=True)
class DesignProblem:
    """Everything that defines the optimum, nothing about how it is found.

    Units: metres, radians, newtons; task time t in [0, 1]. ``joint_velocity`` bounds |dq/dt| per unit
    task time; ``position_tol`` (m) and ``axis_tol`` (norm of z - z*) define when a solution tracks.
    """

    name: str
    chain: Chain
    toolpath: toolpaths.Toolpath
    stiffness: Stiffness
    deflection: str = "full"
    deformation_weight: float = 1.0
    tracking_weight: float = 1.0e4
    regularization: float = 1.0e-3
    smoothness: float = 1.0e-9
    joint_regularization: float = 1.0e-7
    joint_velocity: float = 10.0
    keep_out_radius: float = 0.0
    position_tol: float = 1.0e-3
    axis_tol: float = 1.0e-2
    design_costs: tuple[DesignCost, ...] = ()

    @property
    def k_inv(self) -> np.ndarray:
        """Inverse stiffness of each moving joint, base to tool (rad/(N*m) or m/N)."""
        return 1.0 / self.stiffness.diagonal(self.chain.structure)

    @property
    def regularized(self) -> list[int]:
        """Indices into q_d of the design lengths that the regularisation penalises."""
        return design_lengths(self.chain)


def toolpath_from_config(cfg: Config, base_dir: Path) -> toolpaths.Toolpath:
    tp = cfg.toolpath
    if tp.kind == "figure_eight":
        return toolpaths.figure_eight(tp.width, tp.height, tp.waypoints, tp.force)
    if tp.kind == "circle":
        return toolpaths.circle(tp.radius, tp.waypoints, tp.force)
    if tp.kind == "line":
        return toolpaths.line(tp.length, tp.waypoints, tp.force)
    points = toolpaths.read_csv(base_dir / tp.file)
    return toolpaths.from_points(points, tp.waypoints, tp.force)


def stiffness_from_config(cfg: Config) -> Stiffness:
    k = cfg.robot.stiffness
    if isinstance(k, float | int):
        return Stiffness(float(k), float(k))
    return Stiffness(k.revolute, k.prismatic)


def problem_from_config(cfg: Config, base_dir: Path = Path(".")) -> DesignProblem:
    """Turn a validated config into a DesignProblem."""
    b = cfg.robot.bounds
    bounds = JointBounds(
        design_length=b.length,
        design_angle=b.angle,
        revolute=b.revolute,
        prismatic=b.prismatic,
        placement_box=cfg.placement.box,
    )
    chain = build_chain(
        cfg.robot.structure,
        dh_rows(cfg),
        cfg.robot.design,
        cfg.placement.xyz,
        cfg.placement.ypr,
        cfg.placement.free,
        bounds,
    )
    return DesignProblem(
        name=cfg.name,
        chain=chain,
        toolpath=toolpath_from_config(cfg, base_dir),
        stiffness=stiffness_from_config(cfg),
        deflection=cfg.costs.deflection,
        deformation_weight=cfg.costs.deformation_weight,
        tracking_weight=cfg.costs.tracking_weight,
        regularization=cfg.costs.regularization,
        smoothness=cfg.costs.smoothness,
        joint_regularization=cfg.costs.joint_regularization,
        joint_velocity=cfg.robot.joint_velocity,
        keep_out_radius=cfg.placement.keep_out_radius,
        position_tol=cfg.tolerance.position,
        axis_tol=cfg.tolerance.axis,
    )
