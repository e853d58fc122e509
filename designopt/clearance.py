"""Clearance between the robot and the cell: a workpiece block and a floor.

The cell (all lengths in metres):
* the block is an axis-aligned box in the workpiece frame W whose top face is W's z = 0 plane (the toolpath
  lies on it): x, y extents centred on ``block_center``, from z = -height to 0;
* the floor is the plane z = ``floor`` of the base frame B (the robot stands on it);
* the robot is a chain of capsules: its skeleton runs from the base origin through the point after every
  translation of the chain's walk (for a DH link, o_{i-1} + d z_{i-1} and then o_i; for a URDF joint origin,
  its x, y, z offsets in turn) to the chain's tool frame; each segment is a capsule of its link's radius;
* the tool is a cylinder of ``tool_length`` along the tool z axis ending at the tool centre point; it alone may
  touch the block.

Constraints (`constraint_terms`): every skeleton point at least r + c above the floor (exact for a capsule:
its lowest point is an end) and every capsule at least c from the block. The block distance is imposed at
``samples`` points per segment; since the distance to a convex set is convex and 1-Lipschitz along a segment,
requiring r + c + delta / 2 at points delta apart guarantees r + c everywhere on the segment (delta = segment
length / (samples - 1)). All margins of one configuration enter the NLP as one row, their soft minimum (a
lower bound of the minimum, at most ~2 mm low): one row per configuration instead of ~100 keeps IPOPT's KKT
small (measured on configs/gcode_pocket.yaml: 0.49 s per iteration with one row per margin, 0.14 s with
one). Both approximations err on the safe side; `min_clearance` reports the exact minimum (a convex line
search per segment) and `designopt.verify` recomputes it with coal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from designopt.kinematics.chain import Walk, placement_pose
from designopt.kinematics.joints import Chain, Role
from designopt.kinematics.transforms import is_symbolic

_SMOOTH = 1e-9  # m^2: keeps the square root of the outside distance differentiable at the surface


@dataclass(frozen=True)
class Cell:
    """A block in W, a floor in B, link capsules and the tool. Lengths in metres."""

    block_size: tuple[float, float, float]
    block_center: tuple[float, float]
    floor: float
    clearance: float
    link_radius: tuple[float, ...]  # per link, base link first (n_moving + 1 values)
    tool_length: float
    tool_radius: float
    samples: int = 9

    def radius(self, link: int) -> float:
        return self.link_radius[min(link, len(self.link_radius) - 1)]


def skeleton(chain: Chain, q_m, q_d, tool_length: float = 0.0) -> tuple[list, list[int]]:
    """([p_0, p_1, ...], [link of segment 0, ...]): the skeleton's points in B (p_0 the base origin, the last the
    robot's own tool frame, ``tool_length`` short of the tool centre point: the cell's tool is not a link) and,
    for each segment p_i -> p_{i+1}, the link it belongs to (0: the base link, i: the link moved by the i-th
    moving joint). A translation fixed at zero adds no point."""
    values = chain.values(q_m, q_d)
    walk = Walk(chain.robot, values)
    points, links, moved = [walk.frame(0)[:3, 3]], [], 0
    for k, et in enumerate(chain.robot):
        joint = chain.joints[et.joint]
        if joint.role is Role.MOVING:
            moved += 1
        if et.motion != "translate" or (joint.role is Role.FIXED and joint.value == 0.0):
            continue
        points.append(walk.frame(k + 1)[:3, 3])
        links.append(moved)
    tool = np.array(chain.tool, dtype=float)
    tool[:3, 3] -= tool_length * tool[:3, 2]
    if not np.allclose(tool[:3, 3], 0.0):
        end = walk.end
        tcp_robot = end @ (ca.DM(tool) if is_symbolic(end) else tool)
        points.append(tcp_robot[:3, 3])
        links.append(moved)
    return points, links


# The block's faces as corner indices of `block_corners_W`, each face's corners in order around it.
BLOCK_FACES = ((0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5))


def block_corners_W(cell: Cell) -> np.ndarray:
    """The block's 8 corners in W (8 x 3), x varying fastest, then y, then z (bottom face first)."""
    (sx, sy, sz), (cx, cy) = cell.block_size, cell.block_center
    return np.array([[x, y, z] for z in (-sz, 0.0) for y in (cy - sy / 2, cy + sy / 2)
                     for x in (cx - sx / 2, cx + sx / 2)])


def _box_frame(cell: Cell):
    """Centre (3) and half extents (3) of the block in W."""
    sx, sy, sz = cell.block_size
    return np.array([cell.block_center[0], cell.block_center[1], -sz / 2]), np.array([sx, sy, sz]) / 2


def box_signed_distance(p_W, cell: Cell):
    """Signed distance (m) of a point in W from the block: positive outside, negative inside. Numbers or CasADi."""
    centre, half = _box_frame(cell)
    if is_symbolic(p_W):
        d = ca.fabs(p_W - centre) - half
        outside = ca.sqrt(ca.sumsqr(ca.fmax(d, 0)) + _SMOOTH) - math.sqrt(_SMOOTH)
        return outside + ca.fmin(ca.mmax(d), 0)
    d = np.abs(np.asarray(p_W, dtype=float) - centre) - half
    return float(np.linalg.norm(np.maximum(d, 0.0)) + min(d.max(), 0.0))


def constraint_terms(chain: Chain, cell: Cell, q_m, q_d, aggregate: bool = True) -> list:
    """Expressions that must be >= 0 at one configuration (CasADi): floor clearance of every skeleton point and
    block clearance of every capsule at ``cell.samples`` points per segment (see the module docstring)."""
    points, links = skeleton(chain, q_m, q_d, cell.tool_length)
    T_BW = placement_pose(chain, q_m, q_d)
    R, t = T_BW[:3, :3], T_BW[:3, 3]
    out = []
    for i, p in enumerate(points):
        adjacent = [links[j] for j in (i - 1, i) if 0 <= j < len(links)] or [0]
        r = max(cell.radius(link) for link in adjacent)
        out.append(p[2] - cell.floor - r - cell.clearance)
    n = max(cell.samples, 2)
    for i, link in enumerate(links):
        a, b = points[i], points[i + 1]
        length = ca.sqrt(ca.sumsqr(b - a) + _SMOOTH)
        need = cell.radius(link) + cell.clearance + length / (2 * (n - 1))
        for s in np.linspace(0.0, 1.0, n):
            p_B = a + s * (b - a)
            out.append(box_signed_distance(R.T @ (p_B - t), cell) - need)
    return [softmin(out)] if aggregate else out


def softmin(values: list, sharpness: float = 2000.0):
    """A smooth lower bound of min(values) (Kreisselmeier-Steinhauser): m - log(sum exp(-k (v - m))) / k, with m
    the minimum (the shift changes neither value nor gradient; it keeps exp in range). It lies below the minimum
    by at most log(len(values)) / k (k = 2000 / m: ~2 mm for 60 values), so softmin >= 0 implies every value >= 0."""
    v = ca.vertcat(*values)
    m = ca.mmin(v)
    return m - ca.log(ca.sum1(ca.exp(-sharpness * (v - m)))) / sharpness


def block_above_floor(chain: Chain, cell: Cell, q_d) -> list:
    """Expressions >= 0 when the block's four bottom corners are at or above the floor (a function of the design
    joints only: the placement)."""
    T_BW = placement_pose(chain, np.zeros(chain.n_moving), q_d)
    bottom = block_corners_W(cell)[[0, 2, 1, 3]]
    return [(T_BW[:3, :3] @ corner + T_BW[:3, 3])[2] - cell.floor for corner in bottom]


def segment_box_distance(a_W: np.ndarray, b_W: np.ndarray, cell: Cell, iterations: int = 80) -> float:
    """Exact distance (m; negative: depth inside) from the segment a-b (in W) to the block: the signed distance
    is convex along the segment, so a golden-section search finds its minimum."""
    f = lambda s: box_signed_distance(a_W + s * (b_W - a_W), cell)  # noqa: E731
    lo, hi = 0.0, 1.0
    g = (math.sqrt(5) - 1) / 2
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = f(x1), f(x2)
    for _ in range(iterations):
        if f1 <= f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - g * (hi - lo)
            f1 = f(x1)
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + g * (hi - lo)
            f2 = f(x2)
    return min(f(0.0), f(1.0), f1, f2)


@dataclass(frozen=True)
class Clearance:
    """The smallest clearance of a trajectory (m; negative: the capsule penetrates), where and against what."""

    value: float
    link: int
    obstacle: str  # "block" or "floor"
    time_index: float  # waypoint index; a .5 is the collocation point between two waypoints


def min_clearance(chain: Chain, cell: Cell, q_d, configurations: np.ndarray, indices=None) -> Clearance:
    """The exact minimum clearance over joint configurations (rows of q_m), as a `Clearance`."""
    best = Clearance(math.inf, -1, "", -1.0)
    indices = np.arange(len(configurations), dtype=float) if indices is None else indices
    for q, index in zip(configurations, indices, strict=True):
        points, links = skeleton(chain, q, q_d, cell.tool_length)
        T_BW = placement_pose(chain, q, q_d)
        R, t = T_BW[:3, :3], T_BW[:3, 3]
        pts = np.array([np.asarray(p, dtype=float).ravel() for p in points])
        pts_W = (pts - t) @ R
        for i, link in enumerate(links):
            if np.linalg.norm(pts[i + 1] - pts[i]) <= 1e-12:
                continue  # a design length at zero: its neighbours' capsules cover the point
            r = cell.radius(link)
            floor = min(pts[i, 2], pts[i + 1, 2]) - cell.floor - r
            block = segment_box_distance(pts_W[i], pts_W[i + 1], cell) - r
            for value, what in ((floor, "floor"), (block, "block")):
                if value < best.value:
                    best = Clearance(float(value), link, what, float(index))
    return best
