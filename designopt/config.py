"""Experiment configuration (SPEC §8): YAML validated by pydantic.

`load_config` returns a validated `Config` or raises `ConfigError` whose message is one line:
``<file>: <key>: <reason>``. Unknown keys, wrong types and out-of-range values are all errors.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, PrivateAttr, ValidationError, field_validator

from designopt.errors import InputError, read_text
from designopt.kinematics.joints import DH_PARAMS, PLACEMENT_PARAMS
from designopt.kinematics.presets import PRESETS


class ConfigError(InputError):
    """A config problem, worded as one line naming the file, the key and the reason."""


class _Strict(BaseModel):
    # NaN and inf are never meaningful here (a tolerance of .inf would make every start "track").
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


Pair = tuple[float, float]
Positive = Annotated[float, Field(gt=0)]


class MillingForce(_Strict):
    """A milling force model (designopt.forces): Kienzle per tooth, averaged over a revolution. Lengths in m."""

    model: Literal["milling"]
    material: Literal["aluminium", "steel_c45"] = "aluminium"
    kc11: Positive | None = Field(None, description="N/mm^2; overrides the material's")
    mc: Annotated[float, Field(ge=0, lt=1)] | None = None
    radial_ratio: Annotated[float, Field(ge=0)] | None = None
    axial_ratio: Annotated[float, Field(ge=0)] | None = None
    tool_diameter: Positive = 0.010
    teeth: Annotated[int, Field(ge=1, le=50)] = 3
    feed_per_tooth: Positive = 5.0e-5
    axial_depth: Positive = 1.0e-3
    radial_width: Positive | None = None  # None: a full slot
    direction: Literal["down", "up"] = "down"


Force = Positive | MillingForce  # a number: the paper's alpha (N), F = alpha * tangent


class FigureEight(_Strict):
    kind: Literal["figure_eight"]
    width: Positive = 0.6
    height: Positive = 0.3
    waypoints: Annotated[int, Field(ge=3, le=5000)] = 80
    force: Force = 1.0


class Circle(_Strict):
    kind: Literal["circle"]
    radius: Positive = 0.15
    waypoints: Annotated[int, Field(ge=3, le=5000)] = 80
    force: Force = 1.0


class Line(_Strict):
    kind: Literal["line"]
    length: Positive = 0.5
    waypoints: Annotated[int, Field(ge=3, le=5000)] = 80
    force: Force = 1.0


class CsvPath(_Strict):
    kind: Literal["csv"]
    file: str
    waypoints: Annotated[int, Field(ge=3, le=5000)] | None = None
    force: Force = 1.0


class GcodePath(_Strict):
    """A G-code program (designopt.gcode): cutting moves tracked and loaded, rapids free. Lengths in m."""

    kind: Literal["gcode"]
    file: str
    spacing: Positive = 2.0e-3  # largest distance between waypoints along the path
    chord_tolerance: Positive = 1.0e-4  # arcs are sampled so no chord leaves the arc by more
    rapid_speed: Positive = 0.25  # m/s, the speed of G0 moves when the program gives feeds
    force: Force = 1.0


ToolpathConfig = Annotated[FigureEight | Circle | Line | CsvPath | GcodePath, Field(discriminator="kind")]


class StiffnessConfig(_Strict):
    revolute: Positive = Field(1.0, description="N*m/rad")
    prismatic: Positive = Field(1.0, description="N/m")


class BoundsConfig(_Strict):
    length: Pair = (0.0, 2.0)
    angle: Pair = (-math.pi, math.pi)
    revolute: Pair = (-2 * math.pi, 2 * math.pi)
    prismatic: Pair = (-2.0, 2.0)


class DHRow(_Strict):
    theta: float = 0.0
    d: float = 0.0
    a: float = 0.0
    alpha: float = 0.0


class RobotConfig(_Strict):
    """A DH robot (structure, dh, design) or a URDF robot (urdf, base_link, tool_link, design_origins)."""

    structure: Annotated[str, Field(pattern=r"^[RP]{1,12}$")] = "RRRRRR"
    design: list[Literal["theta", "d", "a", "alpha"]] = ["d", "a", "alpha"]
    dh: str | list[DHRow] = "puma560"
    urdf: str | None = None  # path relative to the config
    base_link: str | None = None
    tool_link: str | None = None
    design_origins: list[str] = []  # URDF origin components that are design joints, e.g. elbow_joint.origin.z
    bounds: BoundsConfig = BoundsConfig()
    # one value (both types), {revolute, prismatic}, one value per moving joint, or a preset name
    stiffness: Positive | StiffnessConfig | list[Positive] | str = 1.0
    joint_velocity: Positive = 10.0

    @property
    def is_urdf(self) -> bool:
        return self.urdf is not None

    @field_validator("stiffness")
    @classmethod
    def _known_stiffness_preset(cls, v):
        from designopt.costs import STIFFNESS_PRESETS

        if isinstance(v, str) and v not in STIFFNESS_PRESETS:
            raise ValueError(f"unknown stiffness preset '{v}' (known: {', '.join(sorted(STIFFNESS_PRESETS))})")
        if isinstance(v, list) and not v:
            raise ValueError("an empty list: give one stiffness per moving joint")
        return v

    @field_validator("dh")
    @classmethod
    def _known_preset(cls, v):
        if isinstance(v, str) and v not in {"generic", *PRESETS}:
            raise ValueError(f"unknown preset '{v}' (known: generic, {', '.join(sorted(PRESETS))})")
        return v


Axis = Literal["x", "y", "z", "yaw", "pitch", "roll"]


class PlacementConfig(_Strict):
    optimize: bool | list[Axis] = True
    xyz: tuple[float, float, float] = (1.0, 0.0, 0.0)
    ypr: tuple[float, float, float] = (0.0, 0.0, 0.0)
    box: tuple[Pair, Pair, Pair] = ((-2.0, 2.0), (-2.0, 2.0), (-1.0, 2.0))
    keep_out_radius: Annotated[float, Field(ge=0)] = 0.0

    @property
    def free(self) -> tuple[str, ...]:
        if self.optimize is True:
            return PLACEMENT_PARAMS
        return tuple(self.optimize) if self.optimize else ()


class CostsConfig(_Strict):
    tracking_weight: Positive = 1.0e4
    regularization: Annotated[float, Field(ge=0)] = 1.0e-3
    deflection: Literal["full", "translational"] = "full"
    deformation_weight: Positive = 1.0
    smoothness: Annotated[float, Field(ge=0)] = 1.0e-9
    joint_regularization: Annotated[float, Field(ge=0)] = 1.0e-7


class ToleranceConfig(_Strict):
    position: Positive = 1.0e-3
    axis: Positive = 1.0e-2


class SearchConfig(_Strict):
    """How `designopt run` searches a problem (`designopt.search`): ``coarse_to_fine`` explores with many cheap
    starts on a coarse sampling of the path and refines the best distinct optima on the full path;
    ``multistart`` solves ``solver.multistart`` cold starts on the full path."""

    strategy: Literal["coarse_to_fine", "multistart"] = "coarse_to_fine"
    explore_waypoints: Annotated[int, Field(ge=3, le=5000)] = 10
    explore_starts: Annotated[int, Field(ge=1, le=1000)] = 80
    explore_max_iter: Annotated[int, Field(ge=1, le=1_000_000)] = 250
    refine: Annotated[int, Field(ge=1, le=1000)] = 4
    distinct: Annotated[float, Field(gt=0)] = 0.02  # m or rad
    screen_waypoints: Annotated[int, Field(ge=0, le=5000)] = 40  # 0 (or >= the path's waypoints): no screening
    screen: Annotated[int, Field(ge=1, le=1000)] = 12
    screen_max_iter: Annotated[int, Field(ge=1, le=1_000_000)] = 300
    # sweep only: one more start per structure from each neighbouring structure's (one joint type changed) better
    # design
    structure_neighbours: bool = True


class SolverConfig(_Strict):
    method: Literal["to"] = "to"
    kinematics: Literal["forward", "differential"] = "forward"
    tracking: Literal["hard", "soft"] = "hard"
    degree: Literal[3] = 3
    multistart: Annotated[int, Field(ge=1, le=1000)] = 4
    seed: Annotated[int, Field(ge=0)] = 0
    max_iter: Annotated[int, Field(ge=1, le=1_000_000)] = 3000  # IPOPT takes a 32-bit int
    jobs: Annotated[int, Field(ge=-1, le=1024)] = -1  # -1: every core; 0 is rejected in _semantic_errors
    perturbation: Annotated[float, Field(ge=0)] = 0.3
    init: Literal["reach", "ik", "constant"] = "ik"
    compile: Literal["none", "O0", "O1", "O2"] = "O0"
    time_limit: Positive = 300.0
    # a TO solve that stalls on a design whose joint axes are all parallel to the workpiece normal is finished
    # with those design angles held (designopt.transcriptions.degeneracy; README "Degenerate designs")
    hold_degenerate: bool = True
    search: SearchConfig = SearchConfig()


Method = Literal["to", "fk", "fk_continuous"]
Case = Literal["placement_only", "design_only", "combined"]


class ContinuousConfig(_Strict):
    """The continuous-design comparison (SPEC §5): which cases and methods, and the waypoint study."""

    cases: list[Case] = ["placement_only", "design_only", "combined"]
    methods: list[Method] = ["to", "fk", "fk_continuous"]
    waypoint_study: list[Annotated[int, Field(ge=3, le=2000)]] = [20, 40, 80, 160, 320]


class ModuleRow(_Strict):
    """One module: the DH values it fixes (theta is ignored for R modules, d for P modules)."""

    theta: float = 0.0
    d: float = 0.0
    a: float = 0.0
    alpha: float = 0.0


_PAPER_MODULES = [ModuleRow(d=0.0, a=0.5, alpha=0.0), ModuleRow(d=0.0, a=0.5, alpha=math.pi / 2),
                  ModuleRow(d=1.0, a=0.0, alpha=0.0), ModuleRow(d=1.0, a=0.5, alpha=0.0),
                  ModuleRow(d=0.5, a=0.5, alpha=-math.pi / 2)]


class ModularConfig(_Strict):
    """The modular design problem (SPEC §5): catalogue, similarity weights, L_mod weight and its study."""

    joint_type: Literal["R", "P"] = "R"
    modules: Annotated[list[ModuleRow], Field(min_length=1)] = _PAPER_MODULES
    weight: Positive = 1.0e-3
    linear_weight: Positive = 1.0
    angular_weight: Positive = 0.25
    weight_study: list[Positive] = [1.0e-4, 1.0e-3, 1.0e-2]
    enumeration_modules: Annotated[list[Annotated[int, Field(ge=1)]], Field(min_length=1, max_length=3)] = [2, 5]
    enumeration_waypoints: Annotated[int, Field(ge=3)] = 40
    # after rounding: a local search over module assignments, at most this many assignments evaluated (0: off)
    neighbourhood_budget: Annotated[int, Field(ge=0, le=100_000)] = 48


class BlockConfig(_Strict):
    size: tuple[Positive, Positive, Positive] = (0.1, 0.1, 0.05)  # x, y extents and height (m)
    center: tuple[float, float] = (0.0, 0.0)  # x, y of the top face's centre in W (m)


class ToolConfig(_Strict):
    length: Positive = 0.1  # m, from the robot's tool frame along its z axis to the tool centre point
    radius: Positive = 0.005


class CellConfig(_Strict):
    """The production cell (designopt.clearance): a block under the path, a floor, link capsules and a tool."""

    block: BlockConfig = BlockConfig()
    floor: float = -1.0  # z of the floor in the base frame (m)
    clearance: Annotated[float, Field(ge=0)] = 0.01  # m, between any link capsule and block or floor
    link_radius: Positive | list[Positive] = 0.05  # m; a list: one per link, base link first (n_moving + 1)
    tool: ToolConfig = ToolConfig()
    samples: Annotated[int, Field(ge=2, le=50)] = 9  # points per skeleton segment for the block constraint


class Config(_Strict):
    name: Annotated[str, Field(pattern=r"^[A-Za-z0-9_.-]+$")] = "run"
    toolpath: ToolpathConfig = FigureEight(kind="figure_eight")
    robot: RobotConfig = RobotConfig()
    placement: PlacementConfig = PlacementConfig()
    costs: CostsConfig = CostsConfig()
    tolerance: ToleranceConfig = ToleranceConfig()
    solver: SolverConfig = SolverConfig()
    continuous: ContinuousConfig = ContinuousConfig()
    modular: ModularConfig = ModularConfig()
    cell: CellConfig | None = None  # no cell: nothing keeps the robot out of the workpiece or the floor
    # Where the config came from: errors found later (building the problem) name this file, and relative
    # paths in it (a CSV toolpath) resolve against its directory.
    _file: str = PrivateAttr("<config>")
    _base_dir: Path = PrivateAttr(Path("."))

    @property
    def file(self) -> str:
        return self._file

    def error(self, key: str, reason: str) -> ConfigError:
        """A ConfigError about this config's ``key``."""
        return ConfigError(self._file, key, reason)


def _key(loc: tuple) -> str:
    """Dotted key from a pydantic error location, without union branch tags ('figure_eight', 'float')."""
    key = ""
    for part in loc:
        if isinstance(part, int):
            key += f"[{part}]"
            continue
        part = str(part)
        if part in {"figure_eight", "circle", "line", "csv"} or part[:1].isupper() or not part.isidentifier():
            continue
        if part in {"float", "str", "bool", "int"}:
            continue
        key += f".{part}" if key else part
    return key or "(top level)"


def _semantic_errors(cfg: Config, base_dir: Path) -> list[tuple[str, str]]:
    """Checks that span several keys; each names the key a user must change."""
    errors = []
    n = len(cfg.robot.structure)
    if cfg.robot.is_urdf:
        for key in ("structure", "dh", "design"):
            if key in cfg.robot.model_fields_set:
                errors.append((f"robot.{key}", "a URDF robot takes its joints from robot.urdf (design joints: "
                                               "robot.design_origins)"))
        for key in ("base_link", "tool_link"):
            if getattr(cfg.robot, key) is None:
                errors.append((f"robot.{key}", "needed with robot.urdf: the chain runs from base_link to tool_link"))
        if not (base_dir / cfg.robot.urdf).is_file():
            errors.append(("robot.urdf", f"no such file: {(base_dir / cfg.robot.urdf).resolve()}"))
    elif cfg.robot.design_origins or cfg.robot.base_link or cfg.robot.tool_link:
        errors.append(("robot.design_origins" if cfg.robot.design_origins else "robot.base_link",
                       "only for a URDF robot (robot.urdf)"))
    elif isinstance(cfg.robot.dh, str):
        if cfg.robot.dh in PRESETS and len(PRESETS[cfg.robot.dh]) != n:
            errors.append(("robot.dh", f"preset '{cfg.robot.dh}' has {len(PRESETS[cfg.robot.dh])} links, "
                                       f"structure {cfg.robot.structure} has {n}"))
    elif len(cfg.robot.dh) != n:
        errors.append(("robot.dh", f"{len(cfg.robot.dh)} rows for structure {cfg.robot.structure} of {n} links"))
    for name in ("length", "angle", "revolute", "prismatic"):
        lo, hi = getattr(cfg.robot.bounds, name)
        if not lo <= hi:
            errors.append((f"robot.bounds.{name}", f"lower bound {lo} is above upper bound {hi}"))
    if cfg.robot.bounds.length[0] < 0:
        errors.append(("robot.bounds.length", "design lengths are >= 0 (SPEC §3); lower bound must be >= 0"))
    for k, ((lo, hi), v) in enumerate(zip(cfg.placement.box, cfg.placement.xyz, strict=True)):
        axis = "xyz"[k]
        if not lo <= hi:
            errors.append((f"placement.box.{axis}", f"lower bound {lo} is above upper bound {hi}"))
        elif not lo <= v <= hi:
            errors.append(("placement.xyz", f"{axis} = {v} lies outside the box [{lo}, {hi}]"))
    for name, v in zip(("yaw", "pitch", "roll"), cfg.placement.ypr, strict=True):
        if name in cfg.placement.free and not -math.pi <= v <= math.pi:
            errors.append(("placement.ypr", f"{name} = {v} is a free placement angle and must lie in [-pi, pi]"))
    if cfg.solver.jobs == 0:
        errors.append(("solver.jobs", "0 workers cannot solve anything (-1: every core, or >= 1)"))
    n_modules = len(cfg.modular.modules)
    for k in cfg.modular.enumeration_modules:
        if k > n_modules:
            errors.append(("modular.enumeration_modules", f"module {k} does not exist (the catalogue has "
                                                          f"{n_modules})"))
    if cfg.toolpath.kind in ("csv", "gcode"):
        path = (base_dir / cfg.toolpath.file).resolve()
        if not path.is_file():
            errors.append(("toolpath.file", f"no such file: {path}"))
    return errors


def parse_config(data: object, file: str | Path = "<config>", base_dir: Path | None = None) -> Config:
    """Validate an already-parsed mapping; raise ConfigError on the first problem."""
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ConfigError(file, "(top level)", f"expected a mapping of keys, got {type(data).__name__}")
    try:
        cfg = Config.model_validate(data)
    except ValidationError as exc:
        # In a union, the branch that got deepest into the input is the one the user meant.
        err = max(exc.errors(), key=lambda e: len(e["loc"]))
        msg = err["msg"]
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
        elif err["type"] == "union_tag_invalid":
            msg = f"unknown kind {err.get('ctx', {}).get('tag')!r} (figure_eight, circle, line, csv)"
        raise ConfigError(file, _key(err["loc"]), msg) from None
    base = base_dir if base_dir is not None else Path(".")
    errors = _semantic_errors(cfg, base)
    if errors:
        raise ConfigError(file, *errors[0])
    cfg._file, cfg._base_dir = str(file), base
    return cfg


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


def dump_config(cfg: Config) -> str:
    """The resolved config as YAML (every default filled in; a robot's keys of the other kind left out)."""
    unused = {"structure", "dh", "design"} if cfg.robot.is_urdf else {"urdf", "base_link", "tool_link",
                                                                      "design_origins"}
    return yaml.safe_dump(cfg.model_dump(mode="json", exclude={"robot": unused}), sort_keys=False)


def dh_rows(cfg: Config) -> list[dict[str, float]]:
    """The initial/fixed DH table of the robot as plain dicts."""
    from designopt.kinematics.presets import preset

    if isinstance(cfg.robot.dh, str):
        return preset(cfg.robot.dh, len(cfg.robot.structure))
    return [{p: getattr(row, p) for p in DH_PARAMS} for row in cfg.robot.dh]
