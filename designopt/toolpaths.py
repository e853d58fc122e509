"""Toolpaths s(t) in the workpiece frame W, sampled at N waypoints t_k.

Units: metres. For the paper's paths (figure-eight, circle, line, CSV) t is normalised task time,
t_k = k / (N - 1), and the process force of SPEC §3 points along the unit tangent: F = alpha * s'(t) / |s'(t)|.
A G-code program (`designopt.gcode`) gives t in seconds from its feeds, a force per waypoint from a cutting
model (`designopt.forces`), and waypoints that are not tracked (the rapids between cuts).
"""

from __future__ import annotations

import csv
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from designopt.errors import InputError, InputWarning, read_text


class ToolpathError(ValueError):
    """A toolpath that cannot define a task (its message says why)."""


@dataclass(frozen=True)
class Toolpath:
    """Waypoints of a path in W with their unit tangents and process forces (N x 3 arrays).

    ``tracked`` (N booleans, default all): where the tool must follow the path. An untracked waypoint (a
    rapid) carries no force and no tracking constraint; joint limits still hold there. ``time_unit`` is
    ``task`` (normalised, t in [0, 1]) or ``s`` (seconds, from a program's feeds).
    """

    kind: str
    t: np.ndarray
    points_W: np.ndarray
    tangents_W: np.ndarray
    force_W: np.ndarray
    tracked: np.ndarray | None = None
    time_unit: str = "task"
    force_model: str = "paper"  # "paper": alpha * tangent (SPEC §3); "milling": designopt.forces
    # the force split into named parts (e.g. feed, feed-normal, axial), each (N, 3) in W, summing to force_W
    force_parts: tuple[tuple[str, np.ndarray], ...] = ()

    @property
    def n(self) -> int:
        return len(self.t)

    @property
    def h(self) -> np.ndarray:
        """Time steps t_{k+1} - t_k (N - 1)."""
        return np.diff(self.t)

    @property
    def uniform(self) -> bool:
        h = self.h
        return bool(np.allclose(h, h[0], rtol=1e-9, atol=0.0))

    @property
    def dt(self) -> float:
        """The one time step of a uniformly sampled path (1 / (N - 1) for task time)."""
        if not self.uniform:
            raise ValueError("this toolpath's time steps differ; use Toolpath.h or Toolpath.weights")
        return float(self.t[-1] - self.t[0]) / (self.n - 1)

    @property
    def weights(self) -> np.ndarray:
        """Quadrature weight of each waypoint for integrals sum_k w_k f(t_k): w_k = t_{k+1} - t_k, the last
        waypoint repeating the last step. On a uniform path every weight is dt, which is the paper's dt * sum."""
        if self.uniform:
            return np.full(self.n, self.dt)
        h = self.h
        return np.concatenate([h, h[-1:]])

    @property
    def is_tracked(self) -> np.ndarray:
        return np.ones(self.n, dtype=bool) if self.tracked is None else np.asarray(self.tracked, dtype=bool)


def _from_samples(kind: str, t: np.ndarray, points: np.ndarray, velocity: np.ndarray, force: float) -> Toolpath:
    speed = np.linalg.norm(velocity, axis=1, keepdims=True)
    if not np.all(np.isfinite(points)) or not np.all(np.isfinite(velocity)):
        raise ToolpathError(f"{kind} toolpath has a point that is not a finite number")
    if np.any(speed < 1e-12):
        raise ToolpathError(f"{kind} toolpath has a waypoint with zero speed: its force direction is undefined")
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

    Tangents are central differences of the resampled points (one-sided at the ends). Where the path
    doubles back (a zig-zag pass) the central difference vanishes; there the tangent is the direction of the
    segment that leaves the waypoint, so the force follows the new direction of travel.
    """
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 2:
        raise ToolpathError("a point toolpath needs at least 2 rows of x, y, z")
    if not np.all(np.isfinite(points)):
        raise ToolpathError("a point toolpath has a coordinate that is not a finite number")
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    if np.any(seg < 1e-12):
        raise ToolpathError("a point toolpath has two identical consecutive points")
    n = len(points) if n is None else n
    if n < 3:
        raise ToolpathError(f"{n} waypoints; a toolpath needs at least 3")
    arc = np.concatenate([[0.0], np.cumsum(seg)]) / seg.sum()
    t = np.linspace(0.0, 1.0, n)
    pts = np.column_stack([np.interp(t, arc, points[:, k]) for k in range(3)])
    vel = np.gradient(pts, t, axis=0)
    steps = np.diff(pts, axis=0) / np.diff(t)[:, None]
    typical = np.median(np.linalg.norm(steps, axis=1))
    for k in np.flatnonzero(np.linalg.norm(vel, axis=1) < 1e-6 * typical):
        # a reversal: leave along the outgoing segment (the last waypoint keeps its incoming one)
        candidates = [steps[j] for j in (k, k - 1) if 0 <= j < len(steps) and np.linalg.norm(steps[j]) > 1e-12]
        if candidates:
            vel[k] = candidates[0]
    return _from_samples(kind, t, pts, vel, force)


def with_force(tp: Toolpath, process) -> Toolpath:
    """The toolpath with the milling model's force (`designopt.forces.MillingProcess`) at its tracked waypoints
    instead of the paper's alpha * tangent; untracked waypoints carry no force."""
    from designopt.forces import COMPONENTS, milling_force_components

    parts = milling_force_components(process, tp.tangents_W) * tp.is_tracked[None, :, None]
    return Toolpath(tp.kind, tp.t, tp.points_W, tp.tangents_W, parts.sum(axis=0), tp.tracked, tp.time_unit, "milling",
                    tuple(zip(COMPONENTS, parts, strict=True)))


def from_program(sampled, alpha: float = 1.0) -> Toolpath:
    """A G-code program's waypoints (`designopt.gcode.SampledProgram`) with the paper's force alpha * tangent
    on cutting moves and none on rapids."""
    force = alpha * sampled.tangents * sampled.tracked[:, None]
    return Toolpath("gcode", sampled.t, sampled.points, sampled.tangents, force, sampled.tracked,
                    sampled.time_unit)


def read_csv(path: Path) -> np.ndarray:
    """Read x, y, z columns (metres, in W) from a CSV whose first non-empty row names them.

    Bad content raises `InputError` naming the file and line. Consecutive repeated points are dropped with
    an `InputWarning` (a CAM export often repeats the point where a segment ends and the next begins).
    """
    path = Path(path)
    reader = csv.reader(read_text(path).splitlines())
    header, columns, points, lines = None, None, [], []
    try:
        for row in reader:
            cells = [c.strip() for c in row]
            if not any(cells):
                continue
            line = f"line {reader.line_num}"
            if header is None:
                header = [c.lower() for c in cells]
                missing = [c for c in "xyz" if c not in header]
                if missing:
                    raise InputError(path, line, f"the header must name columns x, y, z (missing: "
                                                 f"{', '.join(missing)}; found: {', '.join(cells)})")
                columns = [header.index(c) for c in "xyz"]
                continue
            if len(cells) <= max(columns):
                raise InputError(path, line, f"{len(cells)} cells, but column {header[max(columns)]} is "
                                             f"number {max(columns) + 1} of the header")
            values = []
            for name, i in zip("xyz", columns, strict=True):
                try:
                    value = float(cells[i])
                except ValueError:
                    raise InputError(path, line, f"{name} = {cells[i]!r} is not a number") from None
                if not math.isfinite(value):
                    raise InputError(path, line, f"{name} = {cells[i]} is not a finite number")
                values.append(value)
            points.append(values)
            lines.append(reader.line_num)
    except csv.Error as exc:
        raise InputError(path, f"line {reader.line_num}", f"malformed CSV: {exc}") from None
    if header is None:
        raise InputError(path, "(file)", "empty: expected a header x,y,z and the points below it")
    if not points:
        raise InputError(path, "(file)", "no points below the header")
    points = np.array(points)
    repeated = np.flatnonzero(np.all(np.abs(np.diff(points, axis=0)) < 1e-12, axis=1)) + 1
    if len(points) - len(repeated) < 2:
        raise InputError(path, "(file)", "a path needs at least 2 distinct points")
    if len(repeated):
        where = ", ".join(str(lines[i]) for i in repeated[:5]) + (" ..." if len(repeated) > 5 else "")
        warnings.warn(f"{path}: line{'s' if len(repeated) > 1 else ''} {where}: repeated point dropped",
                      InputWarning, stacklevel=2)
        points = np.delete(points, repeated, axis=0)
    return points


def subsample(tp: Toolpath, n: int) -> Toolpath:
    """The same task on ``n`` of its waypoints, evenly spread by index, first and last kept (n >= N: the path
    itself). Times, points, tangents, forces and the tracked flags of the kept waypoints are unchanged, so the
    coarse path's integrals are quadratures of the same task with longer steps (`Toolpath.weights`)."""
    if n >= tp.n:
        return tp
    if n < 3:
        raise ValueError(f"a coarse path needs at least 3 waypoints, got {n}")
    keep = np.unique(np.linspace(0, tp.n - 1, n).round().astype(int))
    tracked = None if tp.tracked is None else np.asarray(tp.tracked)[keep]
    return Toolpath(tp.kind, tp.t[keep], tp.points_W[keep], tp.tangents_W[keep], tp.force_W[keep], tracked,
                    tp.time_unit, tp.force_model, tuple((name, part[keep]) for name, part in tp.force_parts))
