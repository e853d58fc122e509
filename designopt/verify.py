"""Re-check a solution file with nothing but numpy and the file itself.

This module deliberately shares no code with designopt's kinematics: it is the independent check that
a reported design cost and tracking error follow from the DH table, placement and joint values in the
file (SPEC §7). Usable as ``python -m designopt.verify FILE...`` (``--help``: what it recomputes, the exit codes).
"""

from __future__ import annotations

import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

SCHEMA = "designopt.solution/1"


class SolutionFileError(ValueError):
    """A solution file that is malformed or does not check out: one line naming the file, key and reason."""

    def __init__(self, file, key: str, reason: str):
        self.file, self.key, self.reason = str(file), key, reason
        super().__init__(f"{file}: {key}: {reason}")


def _array(data: dict, key: str, shape: tuple, file) -> np.ndarray:
    """data[key] (a dotted path) as a finite float array of the given shape (None: any length)."""
    value = data
    for part in key.split("."):
        if not isinstance(value, dict) or part not in value:
            raise SolutionFileError(file, key, "missing")
        value = value[part]
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise SolutionFileError(file, key, "expected numbers") from None
    if arr.ndim != len(shape) or any(s is not None and s != a for s, a in zip(shape, arr.shape, strict=True)):
        want = " x ".join("N" if s is None else str(s) for s in shape) or "a number"
        raise SolutionFileError(file, key, f"expected {want}, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise SolutionFileError(file, key, "contains a value that is not a finite number")
    return arr


def _check_ets(ets: object, structure: str, file) -> None:
    """An elementary-transform chain: motion, unit axis, finite value (null for the moving joints, whose
    types spell the structure)."""
    if not isinstance(ets, list) or not ets:
        raise SolutionFileError(file, "ets", "expected a list of elementary transforms")
    kinds = ""
    for i, et in enumerate(ets):
        if not isinstance(et, dict) or et.get("motion") not in ("translate", "rotate"):
            raise SolutionFileError(file, f"ets[{i}].motion", "expected translate or rotate")
        axis = et.get("axis")
        try:
            axis = np.array(axis, dtype=float)
        except (TypeError, ValueError):
            raise SolutionFileError(file, f"ets[{i}].axis", "expected 3 numbers") from None
        if axis.shape != (3,) or not np.all(np.isfinite(axis)) or abs(np.linalg.norm(axis) - 1) > 1e-9:
            raise SolutionFileError(file, f"ets[{i}].axis", "expected a unit vector of 3 numbers")
        value = et.get("value", "missing")
        if value is None:
            kinds += "R" if et["motion"] == "rotate" else "P"
        elif isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
            raise SolutionFileError(file, f"ets[{i}].value", f"expected a finite number or null, got {value!r}")
    if kinds != structure:
        raise SolutionFileError(file, "ets", f"its moving joints are {kinds or 'none'}, the structure is {structure}")


def check_schema(data: object, file="<solution>") -> None:
    """Raise SolutionFileError unless ``data`` has every field of designopt.solution/1 with the right shape."""
    if not isinstance(data, dict):
        raise SolutionFileError(file, "(top level)", "expected a JSON object")
    if data.get("schema") != SCHEMA:
        raise SolutionFileError(file, "schema", f"expected {SCHEMA!r}, got {data.get('schema')!r}")
    structure = data.get("structure")
    if not isinstance(structure, str) or not structure or set(structure) - {"R", "P"}:
        raise SolutionFileError(file, "structure", f"expected a string over R and P, got {structure!r}")
    n = len(structure)
    if "ets" in data and "dh" not in data:
        _check_ets(data["ets"], structure, file)
    else:
        _check_dh(data.get("dh"), structure, file)
    _check_rest(data, n, file)


def _check_dh(dh: object, structure: str, file) -> None:
    """A DH table: one row per link, the moving parameter null, the others finite."""
    if not isinstance(dh, list) or len(dh) != len(structure):
        raise SolutionFileError(file, "dh", f"expected {len(structure)} rows for structure {structure}")
    for i, (row, link_type) in enumerate(zip(dh, structure, strict=True)):
        if not isinstance(row, dict) or row.get("type") != link_type:
            raise SolutionFileError(file, f"dh[{i}].type", f"expected {link_type!r} (structure {structure})")
        moving = "theta" if link_type == "R" else "d"
        for param in ("theta", "d", "a", "alpha"):
            value = row.get(param, "missing")
            if param == moving:
                if value is not None:
                    raise SolutionFileError(file, f"dh[{i}].{param}", "the moving parameter must be null")
            elif isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                raise SolutionFileError(file, f"dh[{i}].{param}", f"expected a finite number, got {value!r}")


def _check_rest(data: dict, n: int, file) -> None:
    """Tool, placement, stiffness, force, toolpath, joint values and metrics of an n-joint robot."""
    _array(data, "tool", (4, 4), file)
    _array(data, "placement.xyz", (3,), file)
    _array(data, "placement.ypr", (3,), file)
    if np.any(_array(data, "stiffness", (n,), file) <= 0):
        raise SolutionFileError(file, "stiffness", "every joint stiffness must be > 0")
    if _array(data, "force_alpha", (), file) < 0:
        raise SolutionFileError(file, "force_alpha", "must be >= 0")
    points = _array(data, "toolpath.points_W", (None, 3), file)
    if len(points) < 2:
        raise SolutionFileError(file, "toolpath.points_W", "a path needs at least 2 waypoints")
    _array(data, "toolpath.force_W", (len(points), 3), file)
    if "t" in data["toolpath"] and np.any(np.diff(_array(data, "toolpath.t", (len(points),), file)) <= 0):
        raise SolutionFileError(file, "toolpath.t", "times must increase")
    tracked = data["toolpath"].get("tracked")
    if tracked is not None and (not isinstance(tracked, list) or len(tracked) != len(points)
                                or not all(isinstance(v, bool) for v in tracked) or not any(tracked)):
        raise SolutionFileError(file, "toolpath.tracked", f"expected {len(points)} true/false values, at least one "
                                                          "true")
    _array(data, "q", (len(points), n), file)
    if "cell" in data:
        _check_cell(data, n, file)
    metrics = data.get("metrics")
    if not isinstance(metrics, dict):
        raise SolutionFileError(file, "metrics", "missing")
    for key in ("design_cost", "max_position_error", "max_axis_error"):
        if _array(data, f"metrics.{key}", (), file) < 0:
            raise SolutionFileError(file, f"metrics.{key}", "must be >= 0")
    if not isinstance(metrics.get("tracks"), bool):
        raise SolutionFileError(file, "metrics.tracks", f"expected true or false, got {metrics.get('tracks')!r}")
    if metrics.get("deflection") not in ("full", "translational"):
        raise SolutionFileError(file, "metrics.deflection", f"expected full or translational, got "
                                                            f"{metrics.get('deflection')!r}")
    if "tolerances" in metrics:
        for key in ("position", "axis"):
            if _array(data, f"metrics.tolerances.{key}", (), file) <= 0:
                raise SolutionFileError(file, f"metrics.tolerances.{key}", "must be > 0")


def read_solution(path) -> dict:
    """Read a solution file and check its schema; SolutionFileError (one line) if it is not one."""
    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        raise SolutionFileError(path, "(file)", "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SolutionFileError(path, "(file)", f"cannot read: {getattr(exc, 'strerror', None) or exc}") from None
    except json.JSONDecodeError as exc:
        raise SolutionFileError(path, f"line {exc.lineno}", f"not JSON: {exc.msg}") from None
    check_schema(data, path)
    return data


def _dh(theta, d, a, alpha):
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]])


def _rot(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    R = np.eye(4)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def translation(axis, value):
    T = np.eye(4)
    T[:3, 3] = np.asarray(axis, dtype=float) * value
    return T


def rotation(axis, angle):
    """Rodrigues: rotation by angle about the unit axis."""
    k = np.asarray(axis, dtype=float)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    T = np.eye(4)
    T[:3, :3] = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    return T


def _robot_walk(data: dict, q) -> tuple:
    """Last link frame in B, and the origin, axis (in B) and type of every moving joint, from the file's DH
    table or its elementary-transform chain."""
    T, origins, axes, kinds = np.eye(4), [], [], []
    q = iter(q)
    if "dh" in data:
        for row in data["dh"]:
            origins.append(T[:3, 3].copy())
            axes.append(T[:3, 2].copy())
            kinds.append(row["type"])
            value = next(q)
            theta = value if row["type"] == "R" else row["theta"]
            d = value if row["type"] == "P" else row["d"]
            T = T @ _dh(theta, d, row["a"], row["alpha"])
        return T, origins, axes, kinds
    for et in data["ets"]:
        value = et["value"]
        if value is None:
            value = next(q)
            origins.append(T[:3, 3].copy())
            axes.append(T[:3, :3] @ np.asarray(et["axis"], dtype=float))
            kinds.append("R" if et["motion"] == "rotate" else "P")
        T = T @ (rotation(et["axis"], value) if et["motion"] == "rotate" else translation(et["axis"], value))
    return T, origins, axes, kinds


def _skeleton(data: dict, q, tool_length: float) -> tuple[list, list]:
    """The robot's capsule skeleton in B: the base origin, the point after every translation of nonzero length,
    the robot's own tool frame (``tool_length`` short of the tool centre point); and each segment's link."""
    T, points, links, moved = np.eye(4), [np.zeros(3)], [], 0
    q = iter(q)

    def add(point):
        if np.linalg.norm(point - points[-1]) > 1e-12:
            points.append(point)
            links.append(moved)

    if "dh" in data:
        for row in data["dh"]:
            moved += 1
            value = next(q)
            theta = value if row["type"] == "R" else row["theta"]
            d = value if row["type"] == "P" else row["d"]
            add(T[:3, 3] + d * T[:3, 2])
            T = T @ _dh(theta, d, row["a"], row["alpha"])
            add(T[:3, 3].copy())
    else:
        for et in data["ets"]:
            value = et["value"]
            if value is None:
                value = next(q)
                moved += 1
            T = T @ (rotation(et["axis"], value) if et["motion"] == "rotate" else translation(et["axis"], value))
            if et["motion"] == "translate":
                add(T[:3, 3].copy())
    tool = np.array(data["tool"], dtype=float)
    add((T @ tool @ translation([0, 0, 1], -tool_length))[:3, 3])
    return points, links


def _configurations(data: dict) -> tuple[np.ndarray, np.ndarray]:
    """Joint values at the waypoints and, with velocities in the file, at the collocation points (the midpoints
    of the cubic Hermite segments); and their waypoint indices (k + 0.5 for a midpoint)."""
    Q = np.array(data["q"], dtype=float)
    index = np.arange(len(Q), dtype=float)
    if "v" not in data:
        return Q, index
    V = np.array(data["v"], dtype=float)
    t = np.array(data["toolpath"].get("t", np.linspace(0, 1, len(Q))), dtype=float)
    h = np.diff(t)[:, None]
    mid = 0.5 * (Q[:-1] + Q[1:]) + h * (V[:-1] - V[1:]) / 8.0
    return np.vstack([Q, mid]), np.concatenate([index, np.arange(len(Q) - 1) + 0.5])


def clearance(data: dict) -> tuple[float, int, str]:
    """The smallest distance (m) of any link capsule from the block or the floor, recomputed with coal (the FCL
    extension) from the file's robot, placement, cell and trajectory: (distance, link, "block" or "floor")."""
    import coal

    cell = data["cell"]
    radii, L = cell["link_radius"], float(cell["tool"]["length"])
    T_BW = _placement(data)
    sx, sy, sz = cell["block"]["size"]
    cx, cy = cell["block"]["center"]
    box = coal.Box(float(sx), float(sy), float(sz))
    box_pose = coal.Transform3s(T_BW[:3, :3], T_BW[:3, :3] @ np.array([cx, cy, -sz / 2]) + T_BW[:3, 3])
    floor = coal.Halfspace(np.array([0.0, 0.0, 1.0]), float(cell["floor"]))
    identity = coal.Transform3s()
    best = (np.inf, -1, "")
    for q in _configurations(data)[0]:
        points, links = _skeleton(data, q, L)
        for a, b, link in zip(points[:-1], points[1:], links, strict=True):
            axis = b - a
            length = float(np.linalg.norm(axis))
            z = axis / length
            x = np.cross(z, [1.0, 0, 0]) if abs(z[0]) < 0.9 else np.cross(z, [0, 1.0, 0])
            x /= np.linalg.norm(x)
            pose = coal.Transform3s(np.column_stack([x, np.cross(z, x), z]), (a + b) / 2)
            capsule = coal.Capsule(float(radii[min(link, len(radii) - 1)]), length)
            for shape, shape_pose, what in ((box, box_pose, "block"), (floor, identity, "floor")):
                d = coal.distance(capsule, pose, shape, shape_pose, coal.DistanceRequest(), coal.DistanceResult())
                if d < best[0]:
                    best = (float(d), link, what)
    return best


def _placement(data: dict) -> np.ndarray:
    x, y, z = data["placement"]["xyz"]
    yaw, pitch, roll = data["placement"]["ypr"]
    T_BW = np.eye(4)
    T_BW[:3, 3] = (x, y, z)
    return T_BW @ _rot("z", yaw) @ _rot("y", pitch) @ _rot("x", roll)


@dataclass(frozen=True)
class Check:
    design_cost: float
    max_position_error: float
    max_axis_error: float
    tracks: bool


def recompute(data: dict, position_tol: float = 1e-3, axis_tol: float = 1e-2, deflection: str | None = None) -> Check:
    """Recompute the design cost and tracking errors of a designopt.solution/1 dict."""
    tol = data["metrics"].get("tolerances", {})
    position_tol, axis_tol = tol.get("position", position_tol), tol.get("axis", axis_tol)
    deflection = deflection or data["metrics"]["deflection"]
    T_BW = _placement(data)
    tool = np.array(data["tool"])
    k_inv = 1.0 / np.array(data["stiffness"])
    pts, forces, Q = np.array(data["toolpath"]["points_W"]), np.array(data["toolpath"]["force_W"]), np.array(data["q"])
    t = np.array(data["toolpath"].get("t", np.linspace(0.0, 1.0, len(pts))), dtype=float)
    h = np.diff(t)
    # quadrature weights: the interval that starts at each waypoint, the last one repeated (dt on a uniform path)
    weights = np.full(len(pts), (t[-1] - t[0]) / (len(pts) - 1)) if np.allclose(h, h[0], rtol=1e-9, atol=0) \
        else np.r_[h, h[-1]]
    tracked = np.array(data["toolpath"].get("tracked", [True] * len(pts)), dtype=bool)
    cost, pos_err, axis_err = 0.0, 0.0, 0.0
    for k in range(len(pts)):
        T, origins, axes, kinds = _robot_walk(data, Q[k])
        T = T @ tool
        p = T[:3, 3]
        cols = [np.r_[np.cross(a, p - o), a] if kind == "R" else np.r_[a, 0, 0, 0]
                for kind, o, a in zip(kinds, origins, axes, strict=True)]
        J = np.array(cols).T
        w = np.r_[T_BW[:3, :3] @ forces[k], 0, 0, 0]
        delta = J @ np.diag(k_inv) @ J.T @ w
        if deflection == "translational":
            delta = delta[:3]
        cost += weights[k] * float(delta @ delta)
        if not tracked[k]:
            continue  # a rapid: the tool may leave the path
        s_B = T_BW[:3, :3] @ pts[k] + T_BW[:3, 3]
        pos_err = max(pos_err, float(np.linalg.norm(p - s_B)))
        axis_err = max(axis_err, float(np.linalg.norm(T[:3, 2] - T_BW[:3, :3] @ np.array([0, 0, -1.0]))))
    return Check(cost, pos_err, axis_err, pos_err <= position_tol and axis_err <= axis_tol)


def _check_cell(data: dict, n: int, file) -> None:
    if not isinstance(data["cell"], dict):
        raise SolutionFileError(file, "cell", "expected a mapping")
    if np.any(_array(data, "cell.block.size", (3,), file) <= 0):
        raise SolutionFileError(file, "cell.block.size", "every extent must be > 0")
    _array(data, "cell.block.center", (2,), file)
    _array(data, "cell.floor", (), file)
    if _array(data, "cell.clearance", (), file) < 0:
        raise SolutionFileError(file, "cell.clearance", "must be >= 0")
    if np.any(_array(data, "cell.link_radius", (n + 1,), file) <= 0):
        raise SolutionFileError(file, "cell.link_radius", "every radius must be > 0")
    if _array(data, "cell.tool.length", (), file) <= 0:
        raise SolutionFileError(file, "cell.tool.length", "must be > 0")
    _array(data, "metrics.clearance.min", (), file)


def problems(data: dict, rtol: float = 1e-6) -> list[tuple[str, str]]:
    """(key, reason) for every reported number that does not follow from the file's own data."""
    return audit(data, rtol)[2]


def audit(data: dict, rtol: float = 1e-6) -> tuple[Check, tuple[float, int, str] | None, list[tuple[str, str]]]:
    """The recomputation of a file (`recompute`, and `clearance` when it has a cell, else None) and its
    `problems`."""
    found, swept = [], None
    m = data["metrics"]
    alpha = float(data["force_alpha"])
    norms = np.linalg.norm(np.array(data["toolpath"]["force_W"], dtype=float), axis=1)
    # the paper's force has one magnitude alpha everywhere; a cutting model's varies (and is 0 on rapids)
    if data["toolpath"].get("force_model", "paper") == "paper" and not np.allclose(norms, alpha, rtol=1e-9,
                                                                                    atol=1e-12):
        found.append(("toolpath.force_W", f"force magnitudes {norms.min():.6g}..{norms.max():.6g} differ from "
                                          f"force_alpha {alpha:.6g}"))
    check = recompute(data)
    if not np.isclose(check.design_cost, m["design_cost"], rtol=rtol, atol=0.0):
        found.append(("metrics.design_cost", f"{m['design_cost']} != recomputed {check.design_cost}"))
    if not np.isclose(check.max_position_error, m["max_position_error"], rtol=1e-6, atol=1e-12):
        found.append(("metrics.max_position_error", f"{m['max_position_error']} != recomputed "
                                                    f"{check.max_position_error}"))
    if not np.isclose(check.max_axis_error, m["max_axis_error"], rtol=1e-6, atol=1e-12):
        found.append(("metrics.max_axis_error", f"{m['max_axis_error']} != recomputed {check.max_axis_error}"))
    if check.tracks != m["tracks"]:
        found.append(("metrics.tracks", f"{m['tracks']} != recomputed {check.tracks}"))
    if "cell" in data:
        reported = m.get("clearance", {}).get("min")
        swept = value, link, what = clearance(data)
        if reported is None or not np.isclose(value, reported, rtol=0.0, atol=1e-6):
            found.append(("metrics.clearance.min", f"{reported} != {value:.9g} recomputed with coal ({what}, link "
                                                   f"{link})"))
    return check, swept, found


def verify_file(path: Path, rtol: float = 1e-6) -> list[str]:
    """Problems found in one solution file (an empty list means it checks out). A malformed file raises
    SolutionFileError."""
    return [f"{key}: {reason}" for key, reason in problems(read_solution(path), rtol)]


def load_verified(path) -> dict:
    """A solution file that is well formed *and* checks out, or SolutionFileError naming the first problem:
    export and render never draw a tampered cell."""
    data = read_solution(path)
    found = problems(data)
    if found:
        raise SolutionFileError(path, *found[0])
    return data


USAGE = """usage: python -m designopt.verify SOLUTION.json [SOLUTION.json ...]

Recompute what each solution file (schema designopt.solution/1) reports from the file alone -- its robot, placement,
stiffness, force, toolpath and joint values -- with numpy (and, for a file with a cell, the clearance with coal):
the design cost, the largest tracking errors, whether it tracks, and the minimum clearance. Prints one row per file
with the reported and the recomputed numbers, then the first problem of each file that does not check out.

exit codes: 0 every file checks out; 2 a file is malformed, unreadable, or reports a number that does not follow
from its data (the problem is named on stderr, one line per file)."""


def _row(path, data: dict, check: Check, swept: tuple[float, int, str] | None) -> str:
    m = data["metrics"]
    cells = [str(path), f"{m['design_cost']:.6g} / {check.design_cost:.6g}",
             f"{m['max_position_error']:.3g} / {check.max_position_error:.3g}",
             f"{m['max_axis_error']:.3g} / {check.max_axis_error:.3g}", f"{m['tracks']} / {check.tracks}"]
    if swept is not None:
        value, link, what = swept
        cells.append(f"{m.get('clearance', {}).get('min', float('nan')):.4g} / {value:.4g} ({what}, link {link})")
    else:
        cells.append("-")
    return " | ".join(cells)


def main(argv: list[str]) -> int:
    """Check each file: a row of reported / recomputed numbers per readable file, one line per file that fails;
    exit 2 if any file fails."""
    if not argv or argv[0] in ("-h", "--help"):
        print(USAGE, file=sys.stdout if argv else sys.stderr)
        return 0 if argv else 2
    print("file | design cost (reported / recomputed) | max position error [m] | max axis error | tracks | "
          "min clearance [m] | verdict")
    bad = 0
    for arg in argv:
        try:
            data = read_solution(arg)
            check, swept, found = audit(data)
            try:
                row = _row(arg, data, check, swept)
            except (ArithmeticError, LookupError, TypeError, ValueError):  # a tampered file: its problem says why
                row = f"{arg} | ? | ? | ? | ? | ?"
            print(f"{row} | {'ok' if not found else 'DOES NOT CHECK OUT'}", flush=True)
            if found:
                raise SolutionFileError(arg, *found[0])
        except SolutionFileError as exc:
            bad += 1
            print(exc, file=sys.stderr)
    return 2 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
