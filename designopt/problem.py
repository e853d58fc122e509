"""The design problem: a chain with design joints, a toolpath, and the costs -- independent of any solver.

Transcriptions (TO collocation, the FK baseline) take a `DesignProblem` and never look at the config.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from designopt import toolpaths
from designopt.clearance import Cell
from designopt.config import Config, MillingForce, dh_rows
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
from designopt.design_space import JointBounds, build_chain, placement_ets, placement_joints
from designopt.errors import InputError
from designopt.forces import MATERIALS, MillingProcess
from designopt.kinematics.chain import placement_pose
from designopt.kinematics.joints import DH_PARAMS, Chain, Role


@dataclass(frozen=True)
class DesignProblem:
    """Everything that defines the optimum, nothing about how it is found.

    Units: metres, radians, newtons; task time t in [0, 1]. The objective is the sum of the named, weighted
    terms in ``waypoint_costs`` and ``design_costs`` (see `designopt.costs`), plus the trajectory
    regularisers ``smoothness`` (weight of the integral of |q''|^2) and ``joint_regularization`` (weight of
    sum_k dt |q_k|^2), plus ``tracking_weight`` * L_t when tracking is soft. ``joint_velocity`` bounds
    |dq/dt| per unit task time; ``position_tol`` (m) and ``axis_tol`` (norm of z - z*) define when a
    solution tracks.
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
    joint_velocity: float = 10.0
    keep_out_radius: float = 0.0
    position_tol: float = 1.0e-3
    axis_tol: float = 1.0e-2
    cell: Cell | None = None  # block, floor and capsules: clearance constraints (designopt.clearance)

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


def milling_process(force: MillingForce) -> MillingProcess:
    """The config's milling force model as a process of `designopt.forces`."""
    base = MATERIALS[force.material]
    overrides = {k: getattr(force, k) for k in ("kc11", "mc", "radial_ratio", "axial_ratio")
                 if getattr(force, k) is not None}
    material = replace(base, **overrides, source=base.source + (" (overridden: " + ", ".join(overrides) + ")"
                                                                 if overrides else ""))
    return MillingProcess(material, force.tool_diameter, force.teeth, force.feed_per_tooth, force.axial_depth,
                          force.radial_width, force.direction)


def toolpath_from_config(cfg: Config, base_dir: Path) -> toolpaths.Toolpath:
    """The config's toolpath with its force model; a path that cannot define a task is a ConfigError (or an
    InputError naming the line of a CSV or G-code file)."""
    force = cfg.toolpath.force
    path = _path_only(cfg, base_dir)
    if isinstance(force, MillingForce):
        if force.radial_width is not None and force.radial_width > force.tool_diameter:
            raise cfg.error("toolpath.force.radial_width", f"{force.radial_width:g} m is wider than the tool "
                                                           f"({force.tool_diameter:g} m)")
        return toolpaths.with_force(path, milling_process(force))
    return path


def _path_only(cfg: Config, base_dir: Path) -> toolpaths.Toolpath:
    tp = cfg.toolpath
    alpha = tp.force if isinstance(tp.force, float | int) else 1.0  # replaced by the milling model's force
    if tp.kind == "gcode":
        from designopt import gcode

        program = gcode.read_program(base_dir / tp.file, tp.chord_tolerance)
        sampled = gcode.sample_program(program, tp.spacing, tp.rapid_speed)
        if len(sampled.t) > 5000:
            raise cfg.error("toolpath.spacing", f"{tp.spacing:g} m gives {len(sampled.t)} waypoints (at most 5000): "
                                                "choose a larger spacing")
        return toolpaths.from_program(sampled, alpha)
    try:
        if tp.kind == "figure_eight":
            return toolpaths.figure_eight(tp.width, tp.height, tp.waypoints, alpha)
        if tp.kind == "circle":
            return toolpaths.circle(tp.radius, tp.waypoints, alpha)
        if tp.kind == "line":
            return toolpaths.line(tp.length, tp.waypoints, alpha)
        path = base_dir / tp.file
        points = toolpaths.read_csv(path)
        if tp.waypoints is None and len(points) < 3:
            raise InputError(path, "(file)", f"{len(points)} points make {len(points)} waypoints, a path needs at "
                                             "least 3: add points, or set toolpath.waypoints to resample")
        return toolpaths.from_points(points, tp.waypoints, alpha)
    except toolpaths.ToolpathError as exc:
        raise cfg.error("toolpath", str(exc)) from None


def _config_keys(chain: Chain) -> dict[int, str]:
    """The config key a user edits to change each joint's start value (index into chain.joints -> key)."""
    keys = {et.joint: "placement.xyz" if k < 3 else "placement.ypr" for k, et in enumerate(chain.placement)}
    for i, link in enumerate(chain.dh or ()):
        keys.update({j: f"robot.dh[{i}].{param}" for j, param in zip(link, DH_PARAMS, strict=True)})
    return keys


def check_start_values(cfg: Config, chain: Chain) -> None:
    """Every design joint starts inside its bounds: start 0 of a multistart is the configured design, and
    silently clipping it would make it another one."""
    keys = _config_keys(chain)
    for i, j in enumerate(chain.joints):
        if j.role is Role.DESIGN and not j.lower <= j.value <= j.upper:
            raise cfg.error(keys.get(i, "robot"), f"start value {j.value:g} of design joint {j.name} lies outside "
                                                  f"its bounds [{j.lower:g}, {j.upper:g}]")


def check_standoff(cfg: Config, chain: Chain, toolpath: toolpaths.Toolpath) -> None:
    """A keep-out radius the cell cannot satisfy is a config error, not a solve that fails.

    With the placement fixed the distance of every waypoint from the base z-axis is known. With free
    coordinates it is at most the farthest (x, y) the box allows plus the path's radius about W's origin.
    """
    r = cfg.placement.keep_out_radius
    if r <= 0:
        return
    free = set(cfg.placement.free)
    if not free:
        T_BW = placement_pose(chain, np.zeros(chain.n_moving), chain.design_values)
        s_B = toolpath.points_W @ T_BW[:3, :3].T + T_BW[:3, 3]
        k = int(np.argmin(np.hypot(s_B[:, 0], s_B[:, 1])))
        nearest = float(np.hypot(*s_B[k, :2]))
        if nearest < r:
            raise cfg.error("placement.keep_out_radius", f"the fixed placement puts waypoint {k} {nearest:.4g} m from "
                                                         f"the base axis, inside the stand-off of {r:g} m")
        return
    xs = cfg.placement.box[0] if "x" in free else (cfg.placement.xyz[0],) * 2
    ys = cfg.placement.box[1] if "y" in free else (cfg.placement.xyz[1],) * 2
    farthest = max(np.hypot(x, y) for x in xs for y in ys) + float(np.linalg.norm(toolpath.points_W, axis=1).max())
    if farthest < r:
        raise cfg.error("placement.keep_out_radius", f"{r:g} m cannot be met: no waypoint can get farther than "
                                                     f"{farthest:.4g} m from the base axis inside placement.box")


def stiffness_from_config(cfg: Config, n_moving: int) -> Stiffness:
    """The config's stiffness model; a per-joint list (or preset) must give one value per moving joint."""
    k = cfg.robot.stiffness
    if isinstance(k, float | int):
        return Stiffness(float(k), float(k))
    if isinstance(k, str | list):
        values = STIFFNESS_PRESETS[k] if isinstance(k, str) else tuple(float(v) for v in k)
        if len(values) != n_moving:
            what = f"preset {k} has" if isinstance(k, str) else "the list has"
            raise cfg.error("robot.stiffness", f"{what} {len(values)} values but the robot has {n_moving} moving "
                                               "joints (one per joint, base to tool)")
        return Stiffness(per_joint=values, name=k if isinstance(k, str) else "")
    return Stiffness(k.revolute, k.prismatic)


def robot_chain(cfg: Config, base_dir: Path, bounds: JointBounds) -> Chain:
    """The config's robot and placement as one chain: a DH table or a URDF serial chain."""
    r, p = cfg.robot, cfg.placement
    if not r.is_urdf:
        return build_chain(r.structure, dh_rows(cfg), r.design, p.xyz, p.ypr, p.free, bounds)
    from designopt.kinematics.urdf import chain_from_urdf

    return chain_from_urdf(base_dir / r.urdf, r.base_link, r.tool_link, r.design_origins,
                           placement_joints(p.xyz, p.ypr, p.free, bounds), placement_ets(0), bounds.design_length,
                           bounds.design_angle, bounds.revolute, bounds.prismatic, cfg.error)


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
    chain = robot_chain(cfg, base_dir, bounds)
    cell = cell_from_config(cfg, chain)
    if cell is not None:
        chain = with_tool_length(chain, cell.tool_length)
    check_start_values(cfg, chain)
    toolpath = toolpath_from_config(cfg, base_dir)
    check_standoff(cfg, chain, toolpath)
    check_on_block(cfg, cell, toolpath)
    return DesignProblem(
        name=cfg.name,
        chain=chain,
        toolpath=toolpath,
        stiffness=stiffness_from_config(cfg, chain.n_moving),
        deflection=cfg.costs.deflection,
        # deformation_weight only rescales the objective (a unit choice for physical stiffness models, whose
        # L_d is ~1e-8 m^2 and would otherwise be drowned by the regularisation); the reported cost is unscaled.
        waypoint_costs=(WaypointCost("deformation", cfg.costs.deformation_weight, deformation_term),),
        design_costs=(DesignCost("regularization", cfg.costs.regularization, regularization_term, quadratic=True),),
        tracking_weight=cfg.costs.tracking_weight,
        smoothness=cfg.costs.smoothness,
        joint_regularization=cfg.costs.joint_regularization,
        joint_velocity=cfg.robot.joint_velocity,
        keep_out_radius=cfg.placement.keep_out_radius,
        position_tol=cfg.tolerance.position,
        axis_tol=cfg.tolerance.axis,
        cell=cell,
    )


def check_on_block(cfg: Config, cell: Cell | None, toolpath: toolpaths.Toolpath) -> None:
    """Every cutting waypoint lies over the block's top face (the tool cuts the block, not the air beside it)."""
    if cell is None:
        return
    (sx, sy, _), (cx, cy) = cell.block_size, cell.block_center
    xy = toolpath.points_W[toolpath.is_tracked, :2]
    outside = np.flatnonzero((np.abs(xy[:, 0] - cx) > sx / 2 + 1e-9) | (np.abs(xy[:, 1] - cy) > sy / 2 + 1e-9))
    if len(outside):
        x, y = xy[outside[0]]
        span = f"x {cx - sx / 2:.4g}..{cx + sx / 2:.4g}, y {cy - sy / 2:.4g}..{cy + sy / 2:.4g}"
        raise cfg.error("cell.block", f"{len(outside)} cutting waypoints lie beside the block's top face (the first at "
                                      f"x = {x:.4g}, y = {y:.4g} m in W; the face spans {span}): move or grow it")


def with_tool_length(chain: Chain, length: float) -> Chain:
    """The chain with its tool centre point moved ``length`` along the tool z axis (the cell's tool)."""
    tool = np.array(chain.tool, dtype=float) @ np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, length],
                                                         [0, 0, 0, 1.0]])
    return replace(chain, tool=tuple(tuple(float(v) for v in row) for row in tool))


def cell_from_config(cfg: Config, chain: Chain) -> Cell | None:
    """The config's cell, checked against the robot: one radius per link, the base above the floor, a tool
    long enough for the last link to clear the block."""
    c = cfg.cell
    if c is None:
        return None
    radii = (c.link_radius,) * (chain.n_moving + 1) if isinstance(c.link_radius, float | int) \
        else tuple(c.link_radius)
    if len(radii) != chain.n_moving + 1:
        raise cfg.error("cell.link_radius", f"{len(radii)} radii for {chain.n_moving + 1} links (the base link and "
                                            f"one per moving joint)")
    if c.floor > -(radii[0] + c.clearance):
        raise cfg.error("cell.floor", f"{c.floor:g} m: the base link (radius {radii[0]:g} m) stands at z = 0 and "
                                      f"must clear the floor by {c.clearance:g} m")
    if c.tool.length <= radii[-1] + c.clearance:
        raise cfg.error("cell.tool.length", f"{c.tool.length:g} m: the last link (radius {radii[-1]:g} m) ends "
                                            "where the tool begins, so the tool must be longer than that radius plus "
                                            f"the clearance ({radii[-1] + c.clearance:g} m)")
    return Cell(tuple(c.block.size), tuple(c.block.center), c.floor, c.clearance, radii, c.tool.length,
                c.tool.radius, c.samples)
