"""Solutions: one solved design, its metrics, and its JSON file (schema ``designopt.solution/1``).

The file holds everything needed to check a result without designopt: the DH table with the moving
parameter of each link set to null, the tool transform, the placement, the stiffness, the force scale,
the toolpath in W with its forces, the joint values at every waypoint, and the metrics.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from designopt.clearance import Cell
from designopt.costs import Stiffness
from designopt.evaluation import Metrics, evaluate
from designopt.kinematics.joints import DH_PARAMS, Chain, Role
from designopt.kinematics.urdf import RobotFile
from designopt.problem import DesignProblem
from designopt.transcriptions.base import RawResult
from designopt.transcriptions.trajectory import trajectory as make_trajectory

SCHEMA = "designopt.solution/1"


@dataclass(frozen=True)
class Solution:
    """A solved design: the problem it answers, where the solver ended, and the metrics there."""

    problem: DesignProblem
    method: str
    raw: RawResult
    metrics: Metrics

    @property
    def chain(self) -> Chain:
        """The problem's chain with every design joint fixed at its solved value (only q moves)."""
        values = dict(zip([j.name for j in self.problem.chain.design], self.raw.q_d, strict=True))
        return self.problem.chain.with_roles(dict.fromkeys(values, Role.FIXED), values)

    @classmethod
    def from_file(cls, path) -> Solution:
        """Read a solution file that is well formed and checks out (`designopt.verify.load_verified`)."""
        from designopt.verify import load_verified

        return cls.from_dict(load_verified(path), path, checked=True)

    @classmethod
    def from_dict(cls, data: dict, file="<solution>", checked: bool = False) -> Solution:
        """A solution file's content as a Solution: the solved chain (design joints fixed), its toolpath,
        stiffness, tolerances, the weights of its named cost terms and its trajectory; metrics recomputed. The
        file's shape is checked by the one schema check (`designopt.verify.check_schema`; skipped if
        ``checked``); SolutionFileError if it fails."""
        from designopt.toolpaths import Toolpath
        from designopt.verify import check_schema

        if not checked:
            check_schema(data, file)
        chain = chain_from_file(data)
        # the design joints the file names are design joints again (at their solved values), so that the design
        # terms (the regularisation) are recomputed as they were; a name the chain does not have (an origin
        # component of a URDF robot, whose file carries elementary transforms) stays fixed
        design = {n: float(v) for n, v in (data.get("design_joints") or {}).items()
                  if n in {j.name for j in chain.joints}}
        chain = chain.with_roles(dict.fromkeys(design, Role.DESIGN), design)
        tp = data["toolpath"]
        force = np.array(tp["force_W"], dtype=float)
        norms = np.linalg.norm(force, axis=1, keepdims=True)
        points = np.array(tp["points_W"], dtype=float)
        t = np.array(tp.get("t", np.linspace(0, 1, len(points))), dtype=float)
        tracked = np.array(tp["tracked"], dtype=bool) if "tracked" in tp else None
        toolpath = Toolpath(tp.get("kind", "file"), t, points, np.divide(force, norms, where=norms > 0,
                                                                       out=np.zeros_like(force)), force, tracked,
                            tp.get("time_unit", "task"), tp.get("force_model", "paper"))
        m = data["metrics"]
        tol = m.get("tolerances", {})
        limits = data.get("joint_limits") or [{}]
        problem = DesignProblem(name=data.get("method", "file"), chain=chain, toolpath=toolpath,
                                stiffness=_stiffness_from_file(data),
                                deflection=m["deflection"],
                                position_tol=tol.get("position", 1e-3), axis_tol=tol.get("axis", 1e-2),
                                joint_velocity=tuple(float(lim.get("velocity_per_task_time", 10.0)) for lim in limits)
                                if data.get("joint_limits") else 10.0,
                                cell=cell_from_dict(data["cell"]) if "cell" in data else None,
                                robot_file=RobotFile(str(data["urdf"]["file"]), str(data["urdf"]["tool_link"]))
                                if isinstance(data.get("urdf"), dict) else None)
        problem = _with_file_weights(problem, m.get("cost_weights") or {})
        raw = _raw_from_file(data, chain.design_values, t)
        return cls(problem, data.get("method", "file"), raw, evaluate(problem, raw.q_d, raw.trajectory))

    def sample(self, t) -> np.ndarray:
        """Joint values q(t) (len(t) x n_m) at times t of the path: the solution's trajectory decides what lies
        between the waypoints (`designopt.transcriptions.trajectory`)."""
        return self.raw.trajectory.sample(t)

    def sample_velocity(self, t) -> np.ndarray:
        """Joint velocities dq/dt (len(t) x n_m, per unit of the path's time) of `sample`'s trajectory."""
        return self.raw.trajectory.velocity(t)

    def row(self) -> dict:
        """One summary.csv row (without experiment/case columns, which the caller adds)."""
        structure = self.problem.chain.structure
        r = self.raw
        return {
            "method": self.method,
            "structure": structure,
            "dof": len(structure),
            "n_prismatic": structure.count("P"),
            "n_design_joints": self.problem.chain.n_design,
            # the path this solve tracked: a search's explore and screen stages solve shorter ones than the
            # refine, so design costs compare within one count only
            "waypoints": len(self.problem.toolpath.t),
            **self.metrics.row(),
            "status": r.status,
            "success": r.success,
            "iterations": r.iterations,
            "solve_time_s": r.solve_time_s,
            "build_time_s": r.build_time_s,
            "n_variables": r.n_variables,
            "n_constraints": r.n_constraints,
            "objective": r.objective,
            "kinematic_drift": r.kinematic_drift,
            "held": r.held,
            "seed": r.seed,
            "stiffness_revolute": self.problem.stiffness.by_type()[0],
            "stiffness_prismatic": self.problem.stiffness.by_type()[1],
            "deflection": self.problem.deflection,
        }


def solve_and_evaluate(problem: DesignProblem, method: str, raw: RawResult) -> Solution:
    return Solution(problem, method, raw, evaluate(problem, raw.q_d, raw.trajectory))


def _with_file_weights(problem: DesignProblem, weights: dict) -> DesignProblem:
    """The problem with the weights a file states for its named terms (a term the file does not name keeps
    the default; a term the problem does not have cannot be rebuilt from a file and stays out)."""
    waypoint = tuple(replace(c, weight=float(weights.get(c.name, c.weight))) for c in problem.waypoint_costs)
    design = tuple(replace(c, weight=float(weights.get(c.name, c.weight))) for c in problem.design_costs)
    return replace(problem, waypoint_costs=waypoint, design_costs=design)


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def robot_description(chain: Chain) -> dict:
    """The solved robot as the file carries it: a DH table (``dh``, the moving parameter null) when the robot
    is one, else its elementary-transform chain (``ets``: motion, unit axis, value; null for a moving joint)."""
    values = chain.values(np.zeros(chain.n_moving), np.zeros(0))
    if chain.dh is not None:
        dh = []
        for link_type, link in zip(chain.structure, chain.dh, strict=True):
            row = {"type": link_type}
            for name, index in zip(DH_PARAMS, link, strict=True):
                row[name] = None if chain.joints[index].role is Role.MOVING else float(values[index])
            dh.append(row)
        return {"dh": dh}
    return {"ets": [{"motion": et.motion, "axis": list(et.axis),
                     "value": None if chain.joints[et.joint].role is Role.MOVING else float(values[et.joint])}
                    for et in chain.robot]}


def _stiffness_from_file(data: dict) -> Stiffness:
    """The stiffness model a file states: the two-value model when it names one, else one value per joint."""
    model = data["metrics"].get("stiffness_model") or {}
    revolute, prismatic = model.get("revolute_Nm_per_rad"), model.get("prismatic_N_per_m")
    per_joint = tuple(float(v) for v in data["stiffness"])
    if revolute is not None and prismatic is not None:
        two = Stiffness(float(revolute), float(prismatic))
        if np.allclose(two.diagonal(data["structure"]), per_joint, rtol=0, atol=0):
            return two
    return Stiffness(per_joint=per_joint)


def cell_to_dict(cell: Cell) -> dict:
    """The cell as a solution file carries it (metres; block in W, floor in B, one radius per link)."""
    return {"block": {"size": list(cell.block_size), "center": list(cell.block_center)}, "floor": cell.floor,
            "clearance": cell.clearance, "link_radius": list(cell.link_radius),
            "tool": {"length": cell.tool_length, "radius": cell.tool_radius}, "samples": cell.samples}


def cell_from_dict(data: dict) -> Cell:
    return Cell(tuple(data["block"]["size"]), tuple(data["block"]["center"]), float(data["floor"]),
                float(data["clearance"]), tuple(float(r) for r in data["link_radius"]), float(data["tool"]["length"]),
                float(data["tool"]["radius"]), int(data.get("samples", 9)))


def to_dict(sol: Solution) -> dict:
    """The solution as a JSON-ready dict in schema designopt.solution/1."""
    chain, p = sol.chain, sol.problem
    placement = chain.placement_values(np.zeros(chain.n_moving), np.zeros(0))
    m, r = sol.metrics, sol.raw
    return {
        "schema": SCHEMA,
        "method": sol.method,
        "structure": chain.structure,
        **robot_description(chain),
        "tool": [list(map(float, row)) for row in chain.tool],
        "placement": {"xyz": [float(v) for v in placement[:3]], "ypr": [float(v) for v in placement[3:]]},
        "stiffness": [float(k) for k in p.stiffness.diagonal(chain.structure)],
        "force_alpha": float(np.linalg.norm(p.toolpath.force_W[0])),
        "toolpath": {
            "kind": p.toolpath.kind,
            "t": p.toolpath.t.tolist(),
            "points_W": p.toolpath.points_W.tolist(),
            "force_W": p.toolpath.force_W.tolist(),
            "time_unit": p.toolpath.time_unit,
            "force_model": p.toolpath.force_model,
            **({"tracked": p.toolpath.is_tracked.tolist()} if p.toolpath.tracked is not None else {}),
        },
        **({"cell": cell_to_dict(p.cell)} if p.cell is not None else {}),
        **({"urdf": {"file": p.robot_file.path, "tool_link": p.robot_file.tool_link}} if p.robot_file else {}),
        "q": np.asarray(r.Q).tolist(),
        # joint velocities dq/dt at the waypoints (TO's Hermite knots; absent for FK): with q and the trajectory's
        # kind they define the trajectory between waypoints
        **({"v": np.asarray(r.V).tolist()} if r.V is not None else {}),
        "trajectory": r.trajectory.kind,
        # velocity_per_task_time: |dq/dt| per unit of the toolpath's time (per second when time_unit is s)
        "joint_limits": [{"name": j.name, "lower": j.lower, "upper": j.upper, "velocity_per_task_time": float(v)}
                         for j, v in zip(p.chain.moving, p.velocity_limits, strict=True)],
        "design_joints": {j.name: float(v) for j, v in zip(p.chain.design, r.q_d, strict=True)},
        "metrics": {
            "design_cost": m.design_cost,
            "max_position_error": m.max_position_error,
            "max_axis_error": m.max_axis_error,
            "tracks": m.tracks,
            "max_joint_step": m.max_joint_step,
            "deflection": p.deflection,
            "status": r.status,
            "iterations": r.iterations,
            "solve_time_s": r.solve_time_s,
            "regularization": m.regularization,
            "costs": {name: value for name, value in m.costs},
            "cost_weights": {c.name: c.weight for c in (*p.waypoint_costs, *p.design_costs)},
            "min_standoff": m.min_standoff,
            **({"clearance": {"min": m.clearance.value, "link": m.clearance.link, "obstacle": m.clearance.obstacle,
                              "time_index": m.clearance.time_index}} if m.clearance is not None else {}),
            "kinematic_drift": r.kinematic_drift,
            **({"held": r.held} if r.held else {}),
            "objective": _finite(r.objective),
            "success": r.success,
            "build_time_s": r.build_time_s,
            "n_variables": r.n_variables,
            "n_constraints": r.n_constraints,
            "seed": r.seed,
            "tolerances": {"position": p.position_tol, "axis": p.axis_tol},
            "stiffness_model": {"revolute_Nm_per_rad": _finite(p.stiffness.by_type()[0]),
                                "prismatic_N_per_m": _finite(p.stiffness.by_type()[1]),
                                "described": p.stiffness.describe()},
        },
    }


def json_text(data) -> str:
    """JSON text that reads like the data: an object one key per line (nested objects indented by one space), a
    list of rows or objects one element per line, every other value (a row, a scalar, an object inside a list) on
    one line. Lists go through json's C encoder, a table of numbers in one call; ``json.dump`` with an indent runs
    json's Python encoder over every number instead. ``json.loads`` of the text equals ``json.loads`` of
    ``json.dumps(data)``."""
    return _json_lines(data, "")


def _json_lines(value, indent: str) -> str:
    kind = type(value)
    if kind is dict and value and all(type(k) is str for k in value):
        inner = indent + " "
        items = (f"{inner}{_json_string(k)}: {_json_lines(v, inner)}" for k, v in value.items())
        return "{\n" + ",\n".join(items) + "\n" + indent + "}"
    if kind is float:
        return repr(value) if math.isfinite(value) else json.dumps(value)
    if kind is str:
        return _json_string(value)
    if kind is list and value and all(type(v) in (list, dict) for v in value):
        inner = indent + " "
        if all(type(v) is list and all(type(x) in _NUMBERS for x in v) for v in value):
            # rows of numbers: one call of the encoder, a line break between rows ("], [" is nowhere else)
            return "[\n" + inner + json.dumps(value)[1:-1].replace("], [", "],\n" + inner + "[") + "\n" + indent + "]"
        return "[\n" + ",\n".join(inner + json.dumps(v) for v in value) + "\n" + indent + "]"
    return json.dumps(value)


_NUMBERS = (float, int, bool, type(None))
_json_string = json.encoder.encode_basestring_ascii  # what json.dumps writes a string as (ensure_ascii)


def write_json(data: dict, path: Path) -> None:
    """Write `json_text` atomically (temporary file + rename), so a killed run never leaves half a file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile("w", dir=path.parent, suffix=".tmp", delete=False) as fh:
        fh.write(json_text(data) + "\n")
        tmp = fh.name
    os.replace(tmp, path)


def write_solution(sol: Solution, path: Path) -> None:
    write_json(to_dict(sol), path)



class SolutionLoadError(ValueError):
    """A solution file that cannot stand for a solve of the given problem (missing, malformed, other problem)."""


def read_solution_for(problem: DesignProblem, transcription, path: Path) -> Solution:
    """Load a solution this problem's solve wrote earlier (to resume a run): the design joints and the joint
    trajectory from the file, the metrics recomputed on the problem.

    Raises SolutionLoadError if the file is unreadable or does not fit the problem (other design joints,
    waypoints or joints), so the caller solves again instead of trusting it.
    """
    try:
        data = json.loads(Path(path).read_text())
        names = [j.name for j in problem.chain.design]
        raw = _raw_from_file(data, np.array([data["design_joints"][n] for n in names], dtype=float), problem.toolpath.t)
        if set(data["design_joints"]) != set(names) or raw.Q.shape != (problem.toolpath.n, problem.chain.n_moving):
            raise SolutionLoadError(f"{path}: written for another problem")
        if raw.trajectory.kind != transcription.trajectory_kind:
            raise SolutionLoadError(f"{path}: a {raw.trajectory.kind} trajectory where {transcription.name} makes a "
                                    f"{transcription.trajectory_kind} one")
    except (OSError, ValueError, KeyError, TypeError) as exc:
        if isinstance(exc, SolutionLoadError):
            raise
        raise SolutionLoadError(f"{path}: {exc}") from None
    return Solution(problem, transcription.name, raw, evaluate(problem, raw.q_d, raw.trajectory))


def _raw_from_file(data: dict, q_d: np.ndarray, t: np.ndarray) -> RawResult:
    """The solver's answer as a solution file records it (its metrics block), with these design joints; ``t`` are
    the waypoint times of the trajectory's knots."""
    m = data["metrics"]
    objective = m.get("objective")
    trajectory = make_trajectory(t, np.array(data["q"], dtype=float),
                                 np.array(data["v"], dtype=float) if "v" in data else None, data.get("trajectory"))
    return RawResult(q_d=q_d, trajectory=trajectory,
                     status=str(m.get("status", "unknown")), success=bool(m.get("success", False)),
                     iterations=int(m.get("iterations", 0)), solve_time_s=float(m.get("solve_time_s", 0.0)),
                     build_time_s=float(m.get("build_time_s", 0.0)),
                     objective=float("nan") if objective is None else float(objective),
                     n_variables=int(m.get("n_variables", 0)), n_constraints=int(m.get("n_constraints", 0)),
                     seed=int(m.get("seed", 0)), kinematic_drift=float(m.get("kinematic_drift", 0.0)),
                     held=str(m.get("held", "")))


def chain_from_file(data: dict) -> Chain:
    """Rebuild the solved chain (every design joint fixed) from a designopt.solution/1 dict."""
    from designopt.design_space import build_chain, placement_ets, placement_joints
    from designopt.kinematics.joints import ET, Joint

    xyz, ypr = data["placement"]["xyz"], data["placement"]["ypr"]
    if "dh" in data:
        rows = [{k: (0.0 if row[k] is None else row[k]) for k in DH_PARAMS} for row in data["dh"]]
        chain = build_chain(data["structure"], rows, [], xyz, ypr, ())
    else:
        joints, robot, frames = placement_joints(xyz, ypr, ()), [], []
        for k, et in enumerate(data["ets"]):
            moving = et["value"] is None
            kind = "angle" if et["motion"] == "rotate" else "length"
            robot.append(ET(et["motion"], tuple(float(v) for v in et["axis"]), len(joints)))
            joints.append(Joint(f"et{k}", kind, Role.MOVING if moving else Role.FIXED, 0.0 if moving else et["value"]))
            if moving:
                frames.append(len(robot))
        chain = Chain(tuple(joints), placement_ets(0), tuple(robot), tuple(frames))
    limits = iter(data.get("joint_limits") or [])
    joints = tuple(replace(j, lower=float(lim["lower"]), upper=float(lim["upper"]))
                   if j.role is Role.MOVING and (lim := next(limits, None)) is not None else j for j in chain.joints)
    return replace(chain, joints=joints, tool=tuple(tuple(float(v) for v in r) for r in data["tool"]))
