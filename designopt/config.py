"""Experiment configuration (SPEC §8): YAML validated by pydantic, in one place.

`load_config` returns a validated `Config` or raises `ConfigError` whose message is one line
``<file>: <key>: <reason>``. Unknown keys, wrong types, out-of-range values, keys of an older shape (`MOVED`),
and everything that needs the built model to check -- a design joint that starts outside its bounds, a stand-off
the cell cannot satisfy, a cutting move beside the block -- are all errors found here, by the validators of this
module; `designopt.problem` only assembles. What validation builds (the chain, the toolpath, the cell) is kept
on the config, so that a G-code program is read once.

A toolpath kind is declared once: a model below with its keys and a ``path(base_dir)`` that builds it, listed in
`TOOLPATH_KINDS`.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Annotated, Literal, Union

import numpy as np
import yaml
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from designopt import toolpaths
from designopt.clearance import Cell
from designopt.costs import STIFFNESS_PRESETS
from designopt.design_space import JointBounds, build_chain, design_joint_names, placement_ets, placement_joints
from designopt.errors import InputError, InputWarning, read_text
from designopt.forces import MATERIALS, MillingProcess
from designopt.gcode import WORK_OFFSETS
from designopt.kinematics.chain import placement_pose
from designopt.kinematics.joints import DH_PARAMS, Chain, Role
from designopt.kinematics.presets import PRESETS as DH_PRESETS
from designopt.kinematics.presets import preset as dh_preset

DEFAULT_JOINT_VELOCITY = 10.0  # |dq/dt| bound per unit of the toolpath's time when nothing else gives one

class ConfigError(InputError):
    """A config problem, worded as one line naming the file, the key and the reason."""


class _Strict(BaseModel):
    # NaN and inf are never meaningful here (a tolerance of .inf would make every start "track").
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


Pair = tuple[float, float]
Positive = Annotated[float, Field(gt=0)]
Waypoints = Annotated[int, Field(ge=3, le=5000)]

# Constants that were config keys once (README "Config"): fixed here so that every result states the same ones.
CHORD_TOLERANCE = 1.0e-4  # m: arcs of a G-code program are sampled so that no chord leaves the arc by more
RAPID_SPEED = 0.1  # m/s: the speed of G0 moves when the program gives feeds
CLEARANCE_SAMPLES = 17  # points per link segment checked against the block (conservative by <= length / 32)
TOOL_RADIUS = 0.005  # m: the tool as drawn (only the tool may touch the block, so its radius constrains nothing)
ORIGINS = ("top_center", "top_corner", "bottom_center", "bottom_corner")


class MillingForce(_Strict):
    """The milling force model (`designopt.forces`): Kienzle per tooth in a full slot, averaged over a revolution
    (so the tool's diameter does not enter). Lengths in m."""

    material: Literal[tuple(MATERIALS)] = "aluminium"
    teeth: Annotated[int, Field(ge=1, le=50)] = 3
    feed_per_tooth: Positive = 5.0e-5
    axial_depth: Positive = 1.0e-3

    def process(self) -> MillingProcess:
        return MillingProcess(MATERIALS[self.material], TOOL_RADIUS * 2, self.teeth, self.feed_per_tooth,
                              self.axial_depth)


Force = Positive | MillingForce  # a number: the paper's alpha (N), F = alpha * tangent


class _Path(_Strict):
    force: Force = 1.0

    @property
    def alpha(self) -> float:
        """The paper's force scale (N); 1 under a milling model, whose force replaces it."""
        return float(self.force) if isinstance(self.force, float | int) else 1.0

    def path(self, base_dir: Path, cell: Cell | None) -> toolpaths.Toolpath:
        raise NotImplementedError


class FigureEight(_Path):
    kind: Literal["figure_eight"]
    width: Positive = 0.6
    height: Positive = 0.3
    waypoints: Waypoints = 80

    def path(self, base_dir, cell):
        return toolpaths.figure_eight(self.width, self.height, self.waypoints, self.alpha)


class Circle(_Path):
    kind: Literal["circle"]
    radius: Positive = 0.15
    waypoints: Waypoints = 80

    def path(self, base_dir, cell):
        return toolpaths.circle(self.radius, self.waypoints, self.alpha)


class Line(_Path):
    kind: Literal["line"]
    length: Positive = 0.5
    waypoints: Waypoints = 80

    def path(self, base_dir, cell):
        return toolpaths.line(self.length, self.waypoints, self.alpha)


class CsvPath(_Path):
    """Points x, y, z (m, in W) from a CSV file relative to the config; ``waypoints`` resamples them."""

    kind: Literal["csv"]
    file: str
    waypoints: Waypoints | None = None

    def path(self, base_dir, cell):
        path = base_dir / self.file
        points = toolpaths.read_csv(path)
        if self.waypoints is None and len(points) < 3:
            raise InputError(path, "(file)", f"{len(points)} points make {len(points)} waypoints, a path needs at "
                                             "least 3: add points, or set toolpath.waypoints to resample")
        return toolpaths.from_points(points, self.waypoints, self.alpha)


OriginPoint = tuple[float, float, float] | Literal[ORIGINS]


class GcodePath(_Path):
    """A G-code program (`designopt.gcode`): cutting moves tracked and loaded, rapids free. ``spacing``: largest
    distance between waypoints along the path (m). ``origin``: where the program's zero lies in W (m), or a named
    point of the cell's block (W is the block's top-face centre); for a program that uses several work offsets, one
    per offset: ``{G54: ..., G55: ...}``."""

    kind: Literal["gcode"]
    file: str
    spacing: Positive = 2.0e-3
    origin: OriginPoint | dict[Literal[WORK_OFFSETS], OriginPoint] = (0.0, 0.0, 0.0)

    def offsets(self, cell: Cell | None) -> dict[str, np.ndarray]:
        """Where the zero of each work offset lies in W (m)."""
        given = self.origin if isinstance(self.origin, dict) else {"G54": self.origin}
        return {name: program_zero(point, cell) for name, point in given.items()}

    def path(self, base_dir, cell):
        from designopt import gcode

        program = gcode.read_program(base_dir / self.file, CHORD_TOLERANCE, self.offsets(cell))
        sampled = gcode.sample_program(program, self.spacing, RAPID_SPEED)
        if len(sampled.t) > 5000:
            raise _KeyError("toolpath.spacing", f"{self.spacing:g} m gives {len(sampled.t)} waypoints (at most 5000): "
                                                "choose a larger spacing")
        return toolpaths.from_program(sampled, self.alpha)


TOOLPATH_KINDS = (FigureEight, Circle, Line, CsvPath, GcodePath)
KIND_NAMES = tuple(k.model_fields["kind"].annotation.__args__[0] for k in TOOLPATH_KINDS)
ToolpathConfig = Annotated[Union[TOOLPATH_KINDS], Field(discriminator="kind")]  # noqa: UP007 (a tuple of kinds)


def program_zero(origin, cell: Cell | None) -> np.ndarray:
    """Where a program's zero lies in W (m): the given point, or a named point of the cell's block."""
    if not isinstance(origin, str):
        return np.asarray(origin, dtype=float)
    if cell is None:
        raise _KeyError("toolpath.origin", f"{origin!r} names a point of the block: it needs a cell (cell.block)")
    sx, sy, sz = cell.block_size
    x, y = (-sx / 2, -sy / 2) if origin.endswith("corner") else (0.0, 0.0)
    return np.array([x, y, -sz if origin.startswith("bottom") else 0.0])


class StiffnessConfig(_Strict):
    revolute: Positive = Field(1.0, description="N*m/rad")
    prismatic: Positive = Field(1.0, description="N/m")


class BoundsConfig(_Strict):
    length: Pair = (0.0, 2.0)  # m: every design length (DH d and a, URDF origin components)

    @field_validator("length")
    @classmethod
    def _ordered(cls, v):
        if not 0 <= v[0] <= v[1]:
            raise ValueError(f"expected 0 <= lower <= upper (design lengths are >= 0, SPEC §3), got {list(v)}")
        return v


class DHRow(_Strict):
    theta: float = 0.0
    d: float = 0.0
    a: float = 0.0
    alpha: float = 0.0


class RobotConfig(_Strict):
    """A DH robot (structure, dh) or a URDF robot (urdf, tool_link; the chain starts at the URDF's root link)."""

    structure: Annotated[str, Field(pattern=r"^[RP]{1,12}$")] = "RRRRRR"
    dh: str | list[DHRow] = "puma560"
    urdf: str | None = None  # path relative to the config
    tool_link: str | None = None
    bounds: BoundsConfig = BoundsConfig()
    # one value (both types), {revolute, prismatic}, one value per moving joint, or a preset name
    stiffness: Positive | StiffnessConfig | list[Positive] | str = 1.0
    # |dq/dt| bound per unit of the toolpath's time: one value or one per moving joint; unset: a URDF robot on a
    # toolpath timed in seconds takes its URDF's velocity limits, everything else 10
    joint_velocity: Positive | list[Positive] | None = None

    @property
    def is_urdf(self) -> bool:
        return self.urdf is not None

    @field_validator("stiffness")
    @classmethod
    def _known_stiffness(cls, v):
        if isinstance(v, str) and v not in STIFFNESS_PRESETS:
            raise ValueError(f"unknown stiffness preset '{v}' (known: {', '.join(sorted(STIFFNESS_PRESETS))})")
        if isinstance(v, list) and not v:
            raise ValueError("an empty list: give one stiffness per moving joint")
        return v

    @field_validator("dh")
    @classmethod
    def _known_preset(cls, v):
        if isinstance(v, str) and v not in {"generic", *DH_PRESETS}:
            raise ValueError(f"unknown preset '{v}' (known: generic, {', '.join(sorted(DH_PRESETS))})")
        return v

    @model_validator(mode="after")
    def _one_kind_of_robot(self):
        n = len(self.structure)
        if self.is_urdf:
            for key in ("structure", "dh"):
                if key in self.model_fields_set:
                    raise _KeyError(f"robot.{key}", "a URDF robot takes its joints from robot.urdf")
            if self.tool_link is None:
                raise _KeyError("robot.tool_link", "needed with robot.urdf: the chain runs from the URDF's root link "
                                                   "to tool_link")
        elif self.tool_link is not None:
            raise _KeyError("robot.tool_link", "only for a URDF robot (robot.urdf)")
        elif isinstance(self.dh, str) and self.dh in DH_PRESETS and len(DH_PRESETS[self.dh]) != n:
            raise _KeyError("robot.dh", f"preset '{self.dh}' has {len(DH_PRESETS[self.dh])} links, structure "
                                        f"{self.structure} has {n}")
        elif isinstance(self.dh, list) and len(self.dh) != n:
            raise _KeyError("robot.dh", f"{len(self.dh)} rows for structure {self.structure} of {n} links")
        return self

    def dh_rows(self) -> list[dict[str, float]]:
        """The initial/fixed DH table as plain dicts."""
        if isinstance(self.dh, str):
            return dh_preset(self.dh, len(self.structure))
        return [{p: getattr(row, p) for p in DH_PARAMS} for row in self.dh]


class PlacementConfig(_Strict):
    """The pose of W in B, T_BW = Trans(xyz) Rz(yaw) Ry(pitch) Rx(roll): its start (or fixed) value, the cell's
    bounds on x, y, z (m) and a stand-off of every waypoint from the base axis (m, 0 = off)."""

    xyz: tuple[float, float, float] = (0.45, 0.0, -0.2)
    ypr: tuple[float, float, float] = (0.0, 0.0, 0.0)
    box: tuple[Pair, Pair, Pair] = ((-2.0, 2.0), (-2.0, 2.0), (-1.0, 2.0))
    keep_out_radius: Annotated[float, Field(ge=0)] = 0.0

    @model_validator(mode="after")
    def _inside_the_box(self):
        for k, ((lo, hi), v) in enumerate(zip(self.box, self.xyz, strict=True)):
            axis = "xyz"[k]
            if not lo <= hi:
                raise _KeyError(f"placement.box.{axis}", f"lower bound {lo} is above upper bound {hi}")
            if not lo <= v <= hi:
                raise _KeyError("placement.xyz", f"{axis} = {v} lies outside the box [{lo}, {hi}]")
        return self


class CostsConfig(_Strict):
    """``deflection``: full (the paper's 6-D |C w|^2) or translational (the tool tip's displacement).
    ``regularization``: weight of the sum of squared design lengths. ``deformation_weight``: multiplies L_d in the
    objective only -- a unit choice for physical stiffness models, whose L_d (~1e-8 m^2) would otherwise be drowned
    by the regularisation; the reported cost is unweighted."""

    deflection: Literal["full", "translational"] = "full"
    regularization: Annotated[float, Field(ge=0)] = 1.0e-3
    deformation_weight: Positive = 1.0


class ToleranceConfig(_Strict):
    position: Positive = 1.0e-3  # m
    axis: Positive = 1.0e-2  # norm of z - z*


class SearchConfig(_Strict):
    """How the problem is searched (`designopt.solve.search`): a named preset, its seed, and optionally another
    number of starts or another spread of their designs (perturb, box, mixed)."""

    preset: Literal["quick", "default", "thorough", "paper", "production"] = "default"
    seed: Annotated[int, Field(ge=0)] = 0
    starts: Annotated[int, Field(ge=1, le=100_000)] | None = None
    spread: Literal["perturb", "box", "mixed"] | None = None


class ModuleRow(_Strict):
    """One module of a catalogue of revolute links: the DH values it fixes (theta moves)."""

    d: float = 0.0
    a: float = 0.0
    alpha: float = 0.0


_PAPER_MODULES = [ModuleRow(d=0.0, a=0.5, alpha=0.0), ModuleRow(d=0.0, a=0.5, alpha=math.pi / 2),
                  ModuleRow(d=1.0, a=0.0, alpha=0.0), ModuleRow(d=1.0, a=0.5, alpha=0.0),
                  ModuleRow(d=0.5, a=0.5, alpha=-math.pi / 2)]


class CellConfig(_Strict):
    """The production cell (`designopt.clearance`): a block whose top-face centre is W's origin (x, y extents and
    height, m), a floor (z in B, m), link capsules (radius per link, base link first, or one for all) and the
    tool's length beyond the robot's tool frame (m); every link keeps ``clearance`` from block and floor."""

    block: tuple[Positive, Positive, Positive] = (0.1, 0.1, 0.05)
    floor: float = -1.0
    clearance: Annotated[float, Field(ge=0)] = 0.01
    link_radius: Positive | list[Positive] = 0.05
    tool_length: Positive = 0.1


# Keys of an older shape: each names what replaced it (README "Config").
MOVED = {
    "solver": "replaced by search: {preset: quick | default | thorough | paper | production, seed, starts}",
    "robot.design": "moved to design: the design joints of robot and placement in one list, e.g. "
                    "design: [d, a, alpha, placement]",
    "robot.design_origins": "moved to design: name the origin components there, e.g. [elbow_joint.origin.z]",
    "robot.base_link": "not needed: a URDF chain starts at the file's root link",
    "robot.bounds.angle": "no longer a key: design angles are bounded by [-pi, pi]",
    "robot.bounds.revolute": "no longer a key: DH joints move within [-2 pi, 2 pi] rad (URDF: the file's limits)",
    "robot.bounds.prismatic": "no longer a key: DH joints move within [-2, 2] m (URDF: the file's limits)",
    "placement.optimize": "moved to design: list placement (or some of x, y, z, yaw, pitch, roll) there",
    "costs.tracking_weight": "no longer a key: tracking is hard; the paper's soft penalty is a library option "
                             "(Collocation(tracking='soft'))",
    "costs.smoothness": "no longer a key (1e-9, DesignProblem.smoothness)",
    "costs.joint_regularization": "no longer a key (1e-7, DesignProblem.joint_regularization)",
    "toolpath.chord_tolerance": f"no longer a key: arcs are sampled to {CHORD_TOLERANCE:g} m",
    "toolpath.rapid_speed": f"no longer a key: rapids run at {RAPID_SPEED:g} m/s",
    "toolpath.force.model": "not needed: a force block is the milling model",
    "cell.block.size": "moved to cell.block: [x, y, height]",
    "cell.block.center": "not needed: W's origin is the block's top-face centre; place the program with "
                         "toolpath.origin",
    "cell.tool": "moved to cell.tool_length (the tool's radius constrains nothing: only the tool may touch the block)",
    "cell.samples": f"no longer a key ({CLEARANCE_SAMPLES} points per link segment)",
    "continuous": "moved to the command line: designopt continuous --cases ... --methods ...",
    "modular": "the catalogue moved to modules: [{d, a, alpha}, ...]; the L_mod weight to designopt modular --weight",
}
for _key in ("kc11", "mc", "radial_ratio", "axial_ratio", "radial_width", "direction", "tool_diameter"):
    MOVED[f"toolpath.force.{_key}"] = ("no longer a key: the mean force of a full slot with the material's Kienzle "
                                       "values, whatever the tool's diameter (add a material to "
                                       "designopt.forces.MATERIALS)")


class _KeyError(ValueError):
    """A validator's complaint about a key other than the one being validated (reported under ``key``)."""

    def __init__(self, key: str, reason: str):
        self.key, self.reason = key, reason
        super().__init__(reason)


class Config(_Strict):
    name: Annotated[str, Field(pattern=r"^[A-Za-z0-9_.-]+$")] = "run"
    # which scalars are design joints: DH parameter names (every link's), `placement` or some of its coordinates,
    # or joint names of the chain (link2.a, placement.yaw, <urdf joint>.origin.z). Default: d, a, alpha and the
    # placement for a DH robot, the placement for a URDF robot (it exists).
    design: list[str] | None = None
    toolpath: ToolpathConfig = FigureEight(kind="figure_eight")
    robot: RobotConfig = RobotConfig()
    placement: PlacementConfig = PlacementConfig()
    costs: CostsConfig = CostsConfig()
    tolerance: ToleranceConfig = ToleranceConfig()
    search: SearchConfig = SearchConfig()
    cell: CellConfig | None = None  # no cell: nothing keeps the robot out of the workpiece or the floor
    modules: Annotated[list[ModuleRow], Field(min_length=1)] = _PAPER_MODULES
    # Where the config came from (errors found later name this file; relative paths resolve against its
    # directory), and what validating it built.
    _file: str = PrivateAttr("<config>")
    _base_dir: Path = PrivateAttr(Path("."))
    _chain: Chain | None = PrivateAttr(None)
    _toolpath: toolpaths.Toolpath | None = PrivateAttr(None)
    _cell: Cell | None = PrivateAttr(None)
    _joint_velocity: float | tuple[float, ...] = PrivateAttr(DEFAULT_JOINT_VELOCITY)

    def __eq__(self, other) -> bool:
        """Two configs are equal when their keys are (what validation built from them follows from the keys)."""
        return isinstance(other, Config) and self.model_dump() == other.model_dump()

    __hash__ = BaseModel.__hash__

    @property
    def file(self) -> str:
        return self._file

    @property
    def base_dir(self) -> Path:
        return self._base_dir

    def error(self, key: str, reason: str) -> ConfigError:
        """A ConfigError about this config's ``key``."""
        return ConfigError(self._file, key, reason)

    @model_validator(mode="after")
    def _build_and_check(self, info: ValidationInfo):
        """Build the chain, the cell and the toolpath, and check what needs them."""
        context = info.context or {}
        self._file, self._base_dir = str(context.get("file", "<config>")), Path(context.get("base_dir", "."))
        if not context.get("build", True):
            return self
        self._chain = self._robot_chain()
        self._cell = _cell_of(self, self._chain)
        self._toolpath = self._toolpath_built()
        self._joint_velocity = self._velocity_limits()
        _check_start_values(self, self._chain)
        _check_standoff(self, self._chain, self._toolpath)
        _check_on_block(self, self._cell, self._toolpath)
        return self

    def _velocity_limits(self) -> float | tuple[float, ...]:
        """robot.joint_velocity as given; unset, the URDF's limits when the toolpath's time is in seconds (a
        joint without one takes the default), else DEFAULT_JOINT_VELOCITY."""
        r, n = self.robot, self._chain.n_moving
        if isinstance(r.joint_velocity, list):
            if len(r.joint_velocity) != n:
                raise self.error("robot.joint_velocity", f"{len(r.joint_velocity)} values for {n} moving joints: give "
                                                         "one value, or one per moving joint")
            return tuple(float(v) for v in r.joint_velocity)
        if r.joint_velocity is not None:
            return float(r.joint_velocity)
        if r.is_urdf and self._toolpath.time_unit == "s":
            from designopt.kinematics.urdf import joint_velocities

            return tuple(DEFAULT_JOINT_VELOCITY if v is None else v
                         for v in joint_velocities(self._base_dir / r.urdf, r.tool_link))
        return DEFAULT_JOINT_VELOCITY

    def _robot_chain(self) -> Chain:
        r, p = self.robot, self.placement
        bounds = JointBounds(design_length=r.bounds.length, placement_box=p.box)
        if not r.is_urdf:
            chain = build_chain(r.structure, r.dh_rows(), (), p.xyz, p.ypr, (), bounds)
        else:
            from designopt.kinematics.urdf import chain_from_urdf

            path = self._base_dir / r.urdf
            if not path.is_file():
                raise self.error("robot.urdf", f"no such file: {path.resolve()}")
            chain = chain_from_urdf(path, r.tool_link, placement_joints(p.xyz, p.ypr, (), bounds), placement_ets(0),
                                    bounds, self.error)
        try:
            names = design_joint_names(chain, self.design_joints)
        except KeyError as exc:
            raise self.error("design", exc.args[0]) from None
        chain = chain.with_roles(dict.fromkeys(names, Role.DESIGN))
        k = r.stiffness
        if isinstance(k, str | list):
            count = len(STIFFNESS_PRESETS[k]) if isinstance(k, str) else len(k)
            if count != chain.n_moving:
                what = f"preset {k} has" if isinstance(k, str) else "the list has"
                raise self.error("robot.stiffness", f"{what} {count} values but the robot has {chain.n_moving} moving "
                                                    "joints (one per joint, base to tool)")
        return chain

    @property
    def design_joints(self) -> list[str]:
        """``design``, or its default for the robot's kind."""
        if self.design is not None:
            return self.design
        return ["placement"] if self.robot.is_urdf else ["d", "a", "alpha", "placement"]

    def _toolpath_built(self) -> toolpaths.Toolpath:
        tp = self.toolpath
        if getattr(tp, "file", None) is not None and not (self._base_dir / tp.file).is_file():
            raise self.error("toolpath.file", f"no such file: {(self._base_dir / tp.file).resolve()}")
        try:
            path = tp.path(self._base_dir, self._cell)
        except _KeyError as exc:
            raise self.error(exc.key, exc.reason) from None
        except toolpaths.ToolpathError as exc:
            raise self.error("toolpath", str(exc)) from None
        if isinstance(tp.force, MillingForce):
            return toolpaths.with_force(path, tp.force.process())
        return path


def _cell_of(cfg: Config, chain: Chain) -> Cell | None:
    """The config's cell, checked against the robot: one radius per link, the base above the floor, a tool long
    enough for the last link to clear the block."""
    c = cfg.cell
    if c is None:
        return None
    radii = (c.link_radius,) * (chain.n_moving + 1) if isinstance(c.link_radius, float | int) else tuple(c.link_radius)
    if len(radii) != chain.n_moving + 1:
        raise cfg.error("cell.link_radius", f"{len(radii)} radii for {chain.n_moving + 1} links (the base link and "
                                            f"one per moving joint)")
    if c.floor > -(radii[0] + c.clearance):
        raise cfg.error("cell.floor", f"{c.floor:g} m: the base link (radius {radii[0]:g} m) stands at z = 0 and "
                                      f"must clear the floor by {c.clearance:g} m")
    if c.tool_length <= radii[-1] + c.clearance:
        raise cfg.error("cell.tool_length", f"{c.tool_length:g} m: the last link (radius {radii[-1]:g} m) ends where "
                                            "the tool begins, so the tool must be longer than that radius plus the "
                                            f"clearance ({radii[-1] + c.clearance:g} m)")
    return Cell(tuple(c.block), (0.0, 0.0), c.floor, c.clearance, radii, c.tool_length, TOOL_RADIUS,
                CLEARANCE_SAMPLES)


def _config_keys(chain: Chain) -> dict[int, str]:
    """The config key a user edits to change each joint's start value (index into chain.joints -> key)."""
    keys = {et.joint: "placement.xyz" if k < 3 else "placement.ypr" for k, et in enumerate(chain.placement)}
    for i, link in enumerate(chain.dh or ()):
        keys.update({j: f"robot.dh[{i}].{param}" for j, param in zip(link, DH_PARAMS, strict=True)})
    return keys


def _check_start_values(cfg: Config, chain: Chain) -> None:
    """Every design joint starts inside its bounds: start 0 of a search is the configured design, and silently
    clipping it would make it another one."""
    keys = _config_keys(chain)
    for i, j in enumerate(chain.joints):
        if j.role is Role.DESIGN and not j.lower <= j.value <= j.upper:
            raise cfg.error(keys.get(i, "design"), f"start value {j.value:g} of design joint {j.name} lies outside "
                                                   f"its bounds [{j.lower:g}, {j.upper:g}]")


def _check_standoff(cfg: Config, chain: Chain, toolpath: toolpaths.Toolpath) -> None:
    """A keep-out radius the cell cannot satisfy is a config error, not a solve that fails. With the placement
    fixed the distance of every waypoint from the base z-axis is known; with free coordinates it is at most the
    farthest (x, y) the box allows plus the path's radius about W's origin."""
    r = cfg.placement.keep_out_radius
    if r <= 0:
        return
    free = {j.name.split(".", 1)[1] for j in chain.placement_joints if j.role is Role.DESIGN}
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


def _check_on_block(cfg: Config, cell: Cell | None, toolpath: toolpaths.Toolpath) -> None:
    """Every cutting waypoint lies over the block's top face (the tool cuts the block, not the air beside it)."""
    if cell is None:
        return
    (sx, sy, sz), (cx, cy) = cell.block_size, cell.block_center
    xy = toolpath.points_W[toolpath.is_tracked, :2]
    outside = np.flatnonzero((np.abs(xy[:, 0] - cx) > sx / 2 + 1e-9) | (np.abs(xy[:, 1] - cy) > sy / 2 + 1e-9))
    if len(outside):
        x, y = xy[outside[0]]
        span = f"x {cx - sx / 2:.4g}..{cx + sx / 2:.4g}, y {cy - sy / 2:.4g}..{cy + sy / 2:.4g}"
        raise cfg.error("cell.block", f"{len(outside)} cutting waypoints lie beside the block's top face (the first at "
                                      f"x = {x:.4g}, y = {y:.4g} m in W; the face spans {span}): move the program "
                                      "(toolpath.origin) or grow the block")
    z = toolpath.points_W[toolpath.is_tracked, 2]
    hint = "is the program's zero where toolpath.origin says?"
    if z.min() > 1e-9:
        warnings.warn(f"{cfg.file}: toolpath: no cutting move reaches into the block: the deepest cut is "
                      f"{z.min() * 1e3:.4g} mm above the block's top face (z = 0 in W); {hint}", InputWarning,
                      stacklevel=2)
    if z.min() < -sz - 1e-9:
        warnings.warn(f"{cfg.file}: toolpath: cutting moves go {(-sz - z.min()) * 1e3:.4g} mm below the block's "
                      f"bottom (z = {-sz:g} m in W); {hint}", InputWarning, stacklevel=2)


def _key(loc: tuple) -> str:
    """Dotted key from a pydantic error location, without union branch tags ('figure_eight', 'float')."""
    key = ""
    for part in loc:
        if isinstance(part, int):
            key += f"[{part}]"
            continue
        part = str(part)
        if part in KIND_NAMES or part[:1].isupper() or not part.isidentifier():
            continue
        if part in {"float", "str", "bool", "int", "tuple", "list"}:
            continue
        key += f".{part}" if key else part
    return key or "(top level)"


def _moved(data: dict, file) -> None:
    """A key of an older shape: one line naming what replaced it."""
    for path, reason in MOVED.items():
        node = data
        for part in path.split("."):
            node = node.get(part) if isinstance(node, dict) else None
            if node is None:
                break
        else:
            raise ConfigError(file, path, reason)


def parse_config(data: object, file: str | Path = "<config>", base_dir: Path | None = None) -> Config:
    """Validate an already-parsed mapping; raise ConfigError on the first problem."""
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ConfigError(file, "(top level)", f"expected a mapping of keys, got {type(data).__name__}")
    _moved(data, file)
    context = {"file": str(file), "base_dir": base_dir if base_dir is not None else Path(".")}
    try:
        return Config.model_validate(data, context=context)
    except ValidationError as exc:
        # In a union, the branch that got deepest into the input is the one the user meant.
        err = max(exc.errors(), key=lambda e: len(e["loc"]))
        original = (err.get("ctx") or {}).get("error")
        if isinstance(original, _KeyError):
            raise ConfigError(file, original.key, original.reason) from None
        msg = err["msg"].removeprefix("Value error, ")
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
        elif err["type"] == "union_tag_invalid":
            msg = f"unknown kind {err.get('ctx', {}).get('tag')!r} ({', '.join(KIND_NAMES)})"
        raise ConfigError(file, _key(err["loc"]), msg) from None


def load_config(path: str | Path) -> Config:
    """Read, parse and validate a YAML config file."""
    path = Path(path)
    text = read_text(path, ConfigError)
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}" if mark is not None else "(yaml)"
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(path, where, f"malformed YAML: {problem}") from None
    return parse_config(data, path, path.parent)


def revised(cfg: Config, **changes) -> Config:
    """The config with some sections (or their keys) replaced, validated again like a user's config: e.g.
    ``revised(cfg, design=["placement"])`` or ``revised(cfg, toolpath={"waypoints": 20})``."""
    data = cfg.model_dump(mode="json", exclude_unset=False)
    for key, value in changes.items():
        data[key] = {**data[key], **value} if isinstance(value, dict) and isinstance(data.get(key), dict) else value
    if cfg.robot.is_urdf:
        data["robot"] = {k: v for k, v in data["robot"].items() if k not in ("structure", "dh")}
    else:
        data["robot"].pop("urdf", None), data["robot"].pop("tool_link", None)
    return parse_config(data, cfg.file, cfg.base_dir)


def dump_config(cfg: Config) -> str:
    """The resolved config as YAML (every default filled in; a robot's keys of the other kind left out)."""
    unused = {"structure", "dh"} if cfg.robot.is_urdf else {"urdf", "tool_link"}
    return yaml.safe_dump(cfg.model_dump(mode="json", exclude={"robot": unused}), sort_keys=False)

