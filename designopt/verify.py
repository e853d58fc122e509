"""Re-check a solution file with nothing but numpy and the file itself.

This module deliberately shares no code with designopt's kinematics: it is the independent check that
a reported design cost and tracking error follow from the DH table, placement and joint values in the
file (SPEC §7). Usable as ``python -m designopt.verify FILE...``.
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np


def _dh(theta, d, a, alpha):
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]])


def _rot(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    R = np.eye(4)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


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
    x, y, z = data["placement"]["xyz"]
    yaw, pitch, roll = data["placement"]["ypr"]
    T_BW = np.eye(4)
    T_BW[:3, 3] = (x, y, z)
    T_BW = T_BW @ _rot("z", yaw) @ _rot("y", pitch) @ _rot("x", roll)
    tool = np.array(data["tool"])
    k_inv = 1.0 / np.array(data["stiffness"])
    pts, forces, Q = np.array(data["toolpath"]["points_W"]), np.array(data["toolpath"]["force_W"]), np.array(data["q"])
    dt = 1.0 / (len(pts) - 1)
    cost, pos_err, axis_err = 0.0, 0.0, 0.0
    for k in range(len(pts)):
        T = np.eye(4)
        origins, axes = [], []
        for row, q in zip(data["dh"], Q[k], strict=True):
            origins.append(T[:3, 3].copy())
            axes.append(T[:3, 2].copy())
            theta = q if row["type"] == "R" else row["theta"]
            d = q if row["type"] == "P" else row["d"]
            T = T @ _dh(theta, d, row["a"], row["alpha"])
        T = T @ tool
        p = T[:3, 3]
        cols = []
        for row, o, zi in zip(data["dh"], origins, axes, strict=True):
            cols.append(np.r_[np.cross(zi, p - o), zi] if row["type"] == "R" else np.r_[zi, 0, 0, 0])
        J = np.array(cols).T
        w = np.r_[T_BW[:3, :3] @ forces[k], 0, 0, 0]
        delta = J @ np.diag(k_inv) @ J.T @ w
        if deflection == "translational":
            delta = delta[:3]
        cost += dt * float(delta @ delta)
        s_B = T_BW[:3, :3] @ pts[k] + T_BW[:3, 3]
        pos_err = max(pos_err, float(np.linalg.norm(p - s_B)))
        axis_err = max(axis_err, float(np.linalg.norm(T[:3, 2] - T_BW[:3, :3] @ np.array([0, 0, -1.0]))))
    return Check(cost, pos_err, axis_err, pos_err <= position_tol and axis_err <= axis_tol)


def verify_file(path: Path, rtol: float = 1e-6) -> list[str]:
    """Problems found in one solution file (an empty list means it checks out)."""
    data = json.loads(Path(path).read_text())
    if data.get("schema") != "designopt.solution/1":
        return [f"schema is {data.get('schema')!r}"]
    check, m = recompute(data), data["metrics"]
    problems = []
    if not np.isclose(check.design_cost, m["design_cost"], rtol=rtol, atol=0.0):
        problems.append(f"design_cost {m['design_cost']} != recomputed {check.design_cost}")
    if not np.isclose(check.max_position_error, m["max_position_error"], rtol=1e-6, atol=1e-12):
        problems.append(f"max_position_error {m['max_position_error']} != {check.max_position_error}")
    if not np.isclose(check.max_axis_error, m["max_axis_error"], rtol=1e-6, atol=1e-12):
        problems.append(f"max_axis_error {m['max_axis_error']} != {check.max_axis_error}")
    if check.tracks != m["tracks"]:
        problems.append(f"tracks {m['tracks']} != recomputed {check.tracks}")
    return problems


if __name__ == "__main__":
    bad = 0
    for arg in sys.argv[1:]:
        issues = verify_file(Path(arg))
        bad += bool(issues)
        print(f"{arg}: {'ok' if not issues else '; '.join(issues)}")
    sys.exit(1 if bad else 0)
