"""Toolpaths s(t) in the workpiece frame W, sampled at N waypoints t_k = k / (N - 1).

Units: metres; t is normalised task time in [0, 1]. The process force of SPEC §3 points along the unit
tangent: F = alpha * s'(t) / |s'(t)|.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class Toolpath:
    """Waypoints of a path in W with their unit tangents and process forces (N x 3 arrays)."""

    kind: str
    t: np.ndarray
    points_W: np.ndarray
    tangents_W: np.ndarray
    force_W: np.ndarray

    @property
    def n(self) -> int:
        return len(self.t)

    @property
    def dt(self) -> float:
        """Task-time step between waypoints, 1 / (N - 1)."""
        return 1.0 / (self.n - 1)


def _from_samples(kind: str, t: np.ndarray, points: np.ndarray, velocity: np.ndarray, force: float) -> Toolpath:
    speed = np.linalg.norm(velocity, axis=1, keepdims=True)
    if np.any(speed < 1e-12):
        raise ValueError(f"{kind} toolpath has a waypoint with zero speed: its force direction is undefined")
    tangents = velocity / speed
    return Toolpath(kind, t, points, tangents, force * tangents)


def figure_eight(width: float, height: float, n: int, force: float = 1.0) -> Toolpath:
    """s(t) = (W/2 sin 2 pi t, H/2 sin 4 pi t, 0) on W's z = 0 plane."""
    t = np.linspace(0.0, 1.0, n)
    w = 2 * np.pi * t
    pts = np.column_stack([width / 2 * np.sin(w), height / 2 * np.sin(2 * w), np.zeros(n)])
    vel = np.column_stack([width * np.pi * np.cos(w), height * 2 * np.pi * np.cos(2 * w), np.zeros(n)])
    return _from_samples("figure_eight", t, pts, vel, force)


def circle(radius: float, n: int, force: float = 1.0) -> Toolpath:
    """s(t) = (r cos 2 pi t, r sin 2 pi t, 0)."""
    t = np.linspace(0.0, 1.0, n)
    w = 2 * np.pi * t
    pts = np.column_stack([radius * np.cos(w), radius * np.sin(w), np.zeros(n)])
    vel = np.column_stack([-radius * 2 * np.pi * np.sin(w), radius * 2 * np.pi * np.cos(w), np.zeros(n)])
    return _from_samples("circle", t, pts, vel, force)


def line(length: float, n: int, force: float = 1.0) -> Toolpath:
    """s(t) = (L (t - 1/2), 0, 0): a straight cut centred on W's origin."""
    t = np.linspace(0.0, 1.0, n)
    pts = np.column_stack([length * (t - 0.5), np.zeros(n), np.zeros(n)])
    vel = np.tile([length, 0.0, 0.0], (n, 1))
    return _from_samples("line", t, pts, vel, force)


def from_points(points: np.ndarray, n: int | None = None, force: float = 1.0, kind: str = "csv") -> Toolpath:
    """A user's polyline in W, resampled by arc length to n waypoints (all of them if n is None).

    Tangents are central differences of the resampled points (one-sided at the ends).
    """
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 2:
        raise ValueError("a point toolpath needs at least 2 rows of x, y, z")
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    if np.any(seg < 1e-12):
        raise ValueError("a point toolpath has two identical consecutive points")
    arc = np.concatenate([[0.0], np.cumsum(seg)]) / seg.sum()
    n = len(points) if n is None else n
    t = np.linspace(0.0, 1.0, n)
    pts = np.column_stack([np.interp(t, arc, points[:, k]) for k in range(3)])
    vel = np.gradient(pts, t, axis=0)
    return _from_samples(kind, t, pts, vel, force)


def read_csv(path: Path) -> np.ndarray:
    """Read x, y, z columns (metres, in W) from a CSV with a header row naming them."""
    import pandas as pd

    frame = pd.read_csv(path)
    missing = {"x", "y", "z"} - set(frame.columns)
    if missing:
        raise ValueError(f"missing column(s) {', '.join(sorted(missing))}")
    return frame[["x", "y", "z"]].to_numpy(dtype=float)
