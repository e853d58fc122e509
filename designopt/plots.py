"""Figures of solutions (PNG + PDF, labelled axes with units). Pure functions: data in, files out."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from designopt import style
from designopt.clearance import BLOCK_FACES, block_corners_W
from designopt.kinematics.chain import link_frames, placement_pose, tool_pose
from designopt.solution import Solution
from designopt.style import COLORS, fit_3d, label_3d, plt


def save(fig, directory: Path, stem: str) -> list[Path]:
    """Write the figure as PNG and PDF (the shared style crops to the drawn content) and close it."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = [directory / f"{stem}.png", directory / f"{stem}.pdf"]
    for p in paths:
        fig.savefig(p, bbox_inches="tight")
    plt.close(fig)
    return paths


def draw_robot(ax, chain, q: np.ndarray, points_W: np.ndarray | None = None, color: str = COLORS["robot"],
               label: str | None = None, alpha: float = 1.0) -> np.ndarray:
    """Draw a solved chain at joint values q (a polyline through the DH frame origins), its base and,
    if given, the toolpath placed in B. Returns the points drawn (for axis limits)."""
    frames = link_frames(chain, q, np.zeros(0))
    tool = tool_pose(chain, q, np.zeros(0))
    origins = np.array([T[:3, 3] for T in frames] + [tool[:3, 3]])
    ax.plot(*origins.T, "-o", color=color, lw=3, ms=4, alpha=alpha, label=label or f"{chain.structure} robot")
    ax.scatter(0, 0, 0, marker="s", s=40, color=COLORS["base"], label="base B" if label is None else None)
    drawn = [origins]
    if points_W is not None:
        T_BW = placement_pose(chain, q, np.zeros(0))
        s_B = (T_BW[:3, :3] @ np.asarray(points_W).T).T + T_BW[:3, 3]
        drawn.append(draw_workpiece(ax, T_BW, np.asarray(points_W), show_label=label is None))
        ax.plot(*s_B.T, "-", color=COLORS["path"], lw=1.5, label="toolpath (placed)" if label is None else None)
        scale = 0.25 * max(float(np.ptp(s_B, axis=0).max()), 0.02)  # the W triad, sized to the path
        for axis, c in zip(range(3), style.AXIS_COLORS, strict=True):
            end = T_BW[:3, 3] + scale * T_BW[:3, axis]
            ax.plot(*np.c_[T_BW[:3, 3], end], color=c, lw=1)
        drawn.append(s_B)
    return np.vstack(drawn)


def draw_workpiece(ax, T_BW: np.ndarray, points_W: np.ndarray, margin: float = 0.05, show_label: bool = True):
    """The workpiece's top face: a plate in W's z = 0 plane around the path (margin in m), placed by T_BW.
    Returns its corners in B."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    lo, hi = points_W[:, :2].min(axis=0) - margin, points_W[:, :2].max(axis=0) + margin
    corners_W = np.array([[lo[0], lo[1], 0], [hi[0], lo[1], 0], [hi[0], hi[1], 0], [lo[0], hi[1], 0]])
    corners_B = corners_W @ T_BW[:3, :3].T + T_BW[:3, 3]
    ax.add_collection3d(Poly3DCollection([corners_B], facecolor=COLORS["workpiece"], edgecolor="0.4", alpha=0.25,
                                         label="workpiece top face" if show_label else None))
    return corners_B


def draw_cell(ax, sol: Solution, q: np.ndarray, robot_points: np.ndarray | None = None) -> np.ndarray:
    """The cell of a solution: the workpiece block placed by T_BW and a patch of the floor under the robot and
    the block. A floor far below everything else (more than the drawing's own height) would shrink the cell to
    a speck: it is then named in the legend instead of drawn. Returns the corners drawn (for axis limits)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    cell = sol.problem.cell
    T_BW = placement_pose(sol.chain, q, np.zeros(0))
    c = block_corners_W(cell) @ T_BW[:3, :3].T + T_BW[:3, 3]
    faces = [[c[i] for i in face] for face in BLOCK_FACES]
    ax.add_collection3d(Poly3DCollection(faces, facecolor=COLORS["workpiece"], edgecolor="0.3", alpha=0.35,
                                         label="workpiece block"))
    drawn = c if robot_points is None else np.vstack([c, robot_points, np.zeros((1, 3))])
    height = np.ptp(drawn[:, 2])
    if drawn[:, 2].min() - cell.floor > max(height, 0.05):
        ax.plot([], [], " ", label=f"floor at z = {cell.floor:g} m (below the view)")
        return c
    reach = np.abs(drawn[:, :2]).max() * 1.15
    floor = np.array([[-reach, -reach], [reach, -reach], [reach, reach], [-reach, reach]])
    floor = np.column_stack([floor, np.full(4, cell.floor)])
    ax.add_collection3d(Poly3DCollection([floor], facecolor=COLORS["floor"], edgecolor="0.5", alpha=0.25,
                                         label="floor"))
    return np.vstack([c, floor])


def draw_poses(ax, sol: Solution, poses: int = 5) -> np.ndarray:
    """The solved robot at ``poses`` waypoints spread along its path (lighter = earlier), the placed path and
    workpiece (the cell's block and floor when it has one). Returns every point drawn, for `fit_3d`."""
    Q, pts = sol.raw.Q, sol.problem.toolpath.points_W
    picks = np.unique(np.linspace(0, len(Q) - 1, poses).round().astype(int))
    drawn = []
    for n, k in enumerate(picks):
        last = n == len(picks) - 1
        alpha = 0.25 + 0.75 * n / max(len(picks) - 1, 1)
        drawn.append(draw_robot(ax, sol.chain, Q[k], pts if last else None, color=COLORS["robot"],
                                label=None if last else "_earlier pose", alpha=alpha))
    if sol.problem.cell is not None:
        drawn.append(draw_cell(ax, sol, Q[0], np.vstack(drawn)))
    return np.vstack([*drawn, np.zeros((1, 3))])


def robot_figure(sol: Solution, title: str | None = None):
    """The designed cell in 3D: the robot at five poses along its path, the placed path and workpiece, equal
    axes fitted to all of it, the legend under the axes."""
    fig = plt.figure(figsize=(style.SINGLE * 1.5, style.SINGLE * 1.6))
    ax = fig.add_subplot(projection="3d")
    fit_3d(ax, draw_poses(ax, sol))
    label_3d(ax)
    ax.set_title(title or f"{sol.problem.chain.structure} robot at 5 poses along the path\n"
                          f"design cost {sol.metrics.design_cost:.3g}")
    style.legend_below(fig, ax)
    return fig


def joint_figure(sol: Solution):
    structure, t, Q = sol.problem.chain.structure, sol.problem.toolpath.t, sol.raw.Q
    fig, axes = plt.subplots(2, 1, figsize=(6, 4.5), sharex=True)
    for i, c in enumerate(structure):
        ax = axes[0] if c == "R" else axes[1]
        ax.plot(t, Q[:, i], label=f"q{i + 1} ({c})")
    axes[0].set_ylabel("revolute joints [rad]")
    axes[1].set_ylabel("prismatic joints [m]")
    axes[1].set_xlabel(f"task time t [{'s' if sol.problem.toolpath.time_unit == 's' else '-'}]")
    for ax in axes:
        if ax.lines:
            ax.legend(fontsize=7, ncol=3)
    axes[0].set_title(f"Joint trajectories (max step {sol.metrics.max_joint_step:.3g} between waypoints)")
    return fig


def deformation_figure(sol: Solution):
    tp, m = sol.problem.toolpath, sol.metrics
    fig, (a0, a1) = plt.subplots(1, 2, figsize=(8, 3.2))
    sc = a0.scatter(tp.points_W[:, 0], tp.points_W[:, 1], c=m.deformation, cmap="viridis", s=14)
    a0.set_aspect("equal")
    a0.set_xlabel("x_W [m]")
    a0.set_ylabel("y_W [m]")
    a0.set_title("Deformation cost along the path")
    fig.colorbar(sc, ax=a0, label="L_d")
    a1.plot(tp.t, m.deformation, color="C2")
    a1.set_xlabel(f"task time t [{'s' if tp.time_unit == 's' else '-'}]")
    a1.set_ylabel(f"L_d ({sol.problem.deflection})")
    a1.set_title(f"design cost = sum dt L_d = {m.design_cost:.4g}")
    fig.tight_layout()
    return fig


def deflection_by_component(sol: Solution) -> list[tuple[str, np.ndarray]]:
    """|delta_i| (m per the stiffness units) at every waypoint caused by each named part of the force alone:
    delta = J K^-1 J^T [f; 0] is linear in f, so the parts' deflections sum to the total (as vectors)."""
    from designopt.costs import deflection
    from designopt.kinematics.chain import geometric_jacobian

    p, Q = sol.problem, sol.raw.Q
    R_BW = placement_pose(sol.chain, Q[0], np.zeros(0))[:3, :3]
    jacobians = [geometric_jacobian(sol.chain, q, np.zeros(0)) for q in Q]
    return [(name, np.array([np.linalg.norm(deflection(J, p.k_inv, R_BW @ f)[:3])
                             for J, f in zip(jacobians, part, strict=True)]))
            for name, part in (*p.toolpath.force_parts, ("total", p.toolpath.force_W))]


def force_deflection_figure(sol: Solution):
    """Which force component causes what: the force parts along the path and the tool deflection each causes."""
    tp = sol.problem.toolpath
    unit = "s" if tp.time_unit == "s" else "-"
    fig, (a0, a1) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    for name, part in (*tp.force_parts, ("total", tp.force_W)):
        a0.plot(tp.t, np.linalg.norm(part, axis=1), lw=2 if name == "total" else 1.2, label=name)
    for name, delta in deflection_by_component(sol):
        a1.plot(tp.t, delta * 1e6, lw=2 if name == "total" else 1.2, label=name)
    a0.set_ylabel("|force| on the tool [N]")
    a1.set_ylabel("tool deflection [um]")
    a1.set_xlabel(f"task time t [{unit}]")
    stiffness = sol.problem.stiffness
    model = stiffness.name or ("K = I" if stiffness.is_paper_model else "stated stiffness")
    a0.set_title(f"Force components and the tool deflection each causes (stiffness: {model})", fontsize=9)
    for ax in (a0, a1):
        ax.legend(fontsize=7, ncol=4)
    fig.tight_layout()
    return fig


SOLUTION_FIGURES = {"robot": robot_figure, "joints": joint_figure, "deformation": deformation_figure,
                    "force_deflection": force_deflection_figure}


def solution_figure(sol: Solution, directory: Path, name: str) -> list[Path]:
    """One of the standard figures of a solution (`SOLUTION_FIGURES`), as ``name``.png and .pdf; none where it
    does not apply (the force breakdown of a force without parts)."""
    if name == "force_deflection" and not sol.problem.toolpath.force_parts:
        return []
    return save(SOLUTION_FIGURES[name](sol), directory, name)


def solution_figures(sol: Solution, directory: Path) -> list[Path]:
    """The standard figures of one solution, one after the other."""
    return [path for name in SOLUTION_FIGURES for path in solution_figure(sol, directory, name)]


def render_figure(sol: Solution, frames: int = 6):
    """The robot of a solution drawn at ``frames`` waypoints along its path (lighter = earlier)."""
    chain, Q, pts, t = sol.chain, sol.raw.Q, sol.problem.toolpath.points_W, sol.problem.toolpath.t
    picks = np.linspace(0, len(Q) - 1, frames).round().astype(int)
    fig = plt.figure(figsize=(6, 5.5))
    ax = fig.add_subplot(projection="3d")
    cmap = plt.get_cmap("Blues")
    drawn = []
    for n, k in enumerate(picks):
        drawn.append(draw_robot(ax, chain, Q[k], pts if n == 0 else None,
                                color=cmap(0.35 + 0.65 * n / max(frames - 1, 1)),
                                label=f"t = {t[k]:.2f}"))
    if sol.problem.cell is not None:
        drawn.append(draw_cell(ax, sol, Q[0], np.vstack(drawn)))
    fit_3d(ax, np.vstack(drawn + [np.zeros((1, 3))]))
    label_3d(ax)
    ax.set_title(f"{chain.structure} ({sol.method}): design cost {sol.metrics.design_cost:.3g}")
    ax.legend(loc="upper left", fontsize=6)
    return fig


def render_animation(sol: Solution, path: Path, fps: int = 15) -> Path:
    """An animation of the robot following its path (GIF through Pillow, or MP4 if ffmpeg is present)."""
    from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter

    chain, Q, pts, t = sol.chain, sol.raw.Q, sol.problem.toolpath.points_W, sol.problem.toolpath.t
    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")
    limits = np.vstack([draw_robot(ax, chain, q, pts) for q in Q[:: max(1, len(Q) // 8)]] + [np.zeros((1, 3))])
    T_BW = placement_pose(chain, Q[0], np.zeros(0))
    s_B = (T_BW[:3, :3] @ pts.T).T + T_BW[:3, 3]

    def frame(k):
        ax.cla()
        draw_robot(ax, chain, Q[k], pts)
        ax.scatter(*s_B[k], color="C3", s=25)
        fit_3d(ax, limits)
        label_3d(ax)
        ax.set_title(f"t = {t[k]:.2f}")

    anim = FuncAnimation(fig, frame, frames=len(Q))
    if path.suffix == ".mp4" and FFMpegWriter.isAvailable():
        anim.save(path, writer=FFMpegWriter(fps=fps))
    else:
        path = path.with_suffix(".gif")
        anim.save(path, writer=PillowWriter(fps=fps))
    plt.close(fig)
    return path
