"""An interactive view of a designed cell: one self-contained HTML file (plotly.js embedded, no network needed
at view time) with the robot's links as capsules, the placed workpiece and toolpath, the deformation along the
path as colour, and a slider and a play button that move the robot along its trajectory.

plotly (PyPI, maintained) is used because its figures export to a single offline HTML file with animation
frames and sliders built in, and a 3D scene with ``aspectmode="data"`` keeps one metre one metre in every
direction. Frames: B (the robot base); lengths in metres.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import plotly.graph_objects as go

from designopt.clearance import BLOCK_FACES, block_corners_W, skeleton
from designopt.kinematics.chain import placement_pose, tool_pose
from designopt.solution import Solution
from designopt.style import COLORS


def _cylinder(a: np.ndarray, b: np.ndarray, r: float, sides: int = 12):
    """Vertices and triangles of an open cylinder from a to b (radius r)."""
    axis = b - a
    length = np.linalg.norm(axis)
    z = axis / length if length > 1e-12 else np.array([0.0, 0.0, 1.0])
    x = np.cross(z, [1.0, 0, 0]) if abs(z[0]) < 0.9 else np.cross(z, [0, 1.0, 0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    angles = np.linspace(0, 2 * np.pi, sides, endpoint=False)
    ring = r * (np.cos(angles)[:, None] * x + np.sin(angles)[:, None] * y)
    vertices = np.vstack([a + ring, b + ring])
    i = np.arange(sides)
    j = (i + 1) % sides
    triangles = np.vstack([np.c_[i, j, i + sides], np.c_[j, j + sides, i + sides]])
    return vertices, triangles


def _sphere(c: np.ndarray, r: float, n: int = 8):
    """Vertices and triangles of a UV sphere."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n, endpoint=False), np.linspace(0, np.pi, n // 2 + 1))
    vertices = c + r * np.c_[(np.cos(u) * np.sin(v)).ravel(), (np.sin(u) * np.sin(v)).ravel(), np.cos(v).ravel()]
    rows, cols = v.shape
    triangles = []
    for a in range(rows - 1):
        for b in range(cols):
            p, q = a * cols + b, a * cols + (b + 1) % cols
            triangles += [(p, q, p + cols), (q, q + cols, p + cols)]
    return vertices, np.array(triangles)


def _merge(parts):
    vertices, triangles, offset = [], [], 0
    for v, t in parts:
        vertices.append(v)
        triangles.append(t + offset)
        offset += len(v)
    return np.vstack(vertices), np.vstack(triangles)


def robot_mesh(sol: Solution, q: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """The robot at joint values q as capsules (cylinders with spheres at their ends) and the tool as a thin
    cylinder: vertices (V x 3) and triangles (T x 3) in B."""
    chain, cell = sol.chain, sol.problem.cell
    tool_length = cell.tool_length if cell is not None else 0.0
    points, links = skeleton(chain, q, np.zeros(0), tool_length)
    points = [np.asarray(p, dtype=float).ravel() for p in points]
    parts = []
    for a, b, link in zip(points[:-1], points[1:], links, strict=True):
        r = cell.radius(link) if cell is not None else radius
        if np.linalg.norm(b - a) > 1e-9:
            parts.append(_cylinder(a, b, r))
        parts.append(_sphere(b, r))
    parts.append(_sphere(points[0], cell.radius(0) if cell is not None else radius))
    tcp = tool_pose(chain, q, np.zeros(0))[:3, 3]
    tool_r = cell.tool_radius if cell is not None else radius / 3
    parts.append(_cylinder(points[-1], tcp, tool_r, sides=8))
    return _merge(parts)


def _box_mesh(corners: np.ndarray):
    """Triangles of a box given its 8 corners in the order of `block_corners_W`."""
    triangles = [t for a, b, c, d in BLOCK_FACES for t in ((a, b, c), (a, c, d))]
    return corners, np.array(triangles)


def _mesh_trace(vertices, triangles, color: str, name: str, opacity: float = 1.0) -> go.Mesh3d:
    return go.Mesh3d(x=vertices[:, 0], y=vertices[:, 1], z=vertices[:, 2], i=triangles[:, 0], j=triangles[:, 1],
                     k=triangles[:, 2], color=color, opacity=opacity, name=name, showlegend=True, flatshading=True,
                     lighting={"ambient": 0.55, "diffuse": 0.8, "specular": 0.2}, hoverinfo="name")


def cell_figure(sol: Solution, frames: int = 60) -> go.Figure:
    """The interactive figure: robot (capsules), workpiece, path coloured by deformation, slider and play."""
    chain, tp, Q = sol.chain, sol.problem.toolpath, sol.raw.Q
    T_BW = placement_pose(chain, Q[0], np.zeros(0))
    s_B = tp.points_W @ T_BW[:3, :3].T + T_BW[:3, 3]
    reach = max(float(np.linalg.norm(s_B, axis=1).max()), 0.1)
    radius = 0.025 * reach
    traces = []
    cell = sol.problem.cell
    if cell is not None:
        corners = block_corners_W(cell)
        traces.append(_mesh_trace(*_box_mesh(corners @ T_BW[:3, :3].T + T_BW[:3, 3]), "#9aa0a6", "workpiece block",
                                  0.6))
        span = 1.2 * max(reach, float(np.abs(s_B[:, :2]).max()))
        floor = np.array([[x, y, cell.floor] for y in (-span, span) for x in (-span, span)])
        traces.append(_mesh_trace(floor, np.array([[0, 1, 3], [0, 3, 2]]), COLORS["floor"], "floor", 0.35))
    else:
        lo = tp.points_W[:, :2].min(axis=0) - 0.05
        hi = tp.points_W[:, :2].max(axis=0) + 0.05
        plate = np.array([[lo[0], lo[1], 0], [hi[0], lo[1], 0], [lo[0], hi[1], 0], [hi[0], hi[1], 0]])
        traces.append(_mesh_trace(plate @ T_BW[:3, :3].T + T_BW[:3, 3], np.array([[0, 1, 3], [0, 3, 2]]),
                                  "#9aa0a6", "workpiece top face", 0.5))
    deformation = sol.metrics.deformation
    traces.append(go.Scatter3d(
        x=s_B[:, 0], y=s_B[:, 1], z=s_B[:, 2], mode="lines+markers", name="toolpath (deformation)",
        line={"color": "#555", "width": 2},
        marker={"size": 3, "color": deformation, "colorscale": "Viridis", "showscale": True,
                "colorbar": {"title": {"text": "L_d"}, "x": 1.0, "len": 0.6}},
        text=[f"t = {t:.3g}{' (rapid)' if not tr else ''}<br>L_d = {d:.3g}"
              for t, d, tr in zip(tp.t, deformation, tp.is_tracked, strict=True)], hoverinfo="text"))
    picks = np.unique(np.linspace(0, len(Q) - 1, min(frames, len(Q))).round().astype(int))
    meshes = [robot_mesh(sol, Q[k], radius) for k in picks]
    robot_index = len(traces)
    traces.append(_mesh_trace(*meshes[0], COLORS["robot"], f"{chain.structure} robot"))
    # the robot's own tool centre point (on the path when the solution tracks; off it, visibly, when not)
    tcp = np.array([tool_pose(chain, Q[k], np.zeros(0))[:3, 3] for k in picks], dtype=float)
    traces.append(go.Scatter3d(x=tcp[:1, 0], y=tcp[:1, 1], z=tcp[:1, 2], mode="markers",
                               marker={"size": 6, "color": COLORS["path"]}, name="tool centre point"))
    animation = []
    for n, ((v, t), p) in enumerate(zip(meshes, tcp, strict=True)):
        animation.append(go.Frame(name=str(n), traces=[robot_index, robot_index + 1], data=[
            go.Mesh3d(x=v[:, 0], y=v[:, 1], z=v[:, 2], i=t[:, 0], j=t[:, 1], k=t[:, 2]),
            go.Scatter3d(x=[p[0]], y=[p[1]], z=[p[2]])]))
    unit = "s" if tp.time_unit == "s" else ""
    steps = [{"method": "animate", "label": f"{tp.t[k]:.3g}{unit}",
              "args": [[str(n)], {"mode": "immediate", "frame": {"duration": 0, "redraw": True},
                                  "transition": {"duration": 0}}]} for n, k in enumerate(picks)]
    clearance = sol.metrics.clearance
    subtitle = f"design cost {sol.metrics.design_cost:.4g} · {sol.problem.stiffness.describe()}"
    if clearance is not None:
        subtitle += f" · min clearance {clearance.value * 1e3:.1f} mm (link {clearance.link}, {clearance.obstacle})"
    fig = go.Figure(data=traces, frames=animation)
    fig.update_layout(
        title={"text": f"{chain.structure} cell ({sol.method})<br><sub>{subtitle}</sub>", "x": 0.02},
        scene={"aspectmode": "data", "xaxis_title": "x [m]", "yaxis_title": "y [m]", "zaxis_title": "z [m]"},
        legend={"x": 0.0, "y": 0.98, "bgcolor": "rgba(255,255,255,0.7)"},
        margin={"l": 0, "r": 0, "t": 60, "b": 0},
        updatemenus=[{"type": "buttons", "showactive": False, "x": 0.02, "y": 0.02, "xanchor": "left",
                      "buttons": [
                          {"label": "▶ play", "method": "animate",
                           "args": [None, {"frame": {"duration": 80, "redraw": True}, "fromcurrent": True,
                                           "transition": {"duration": 0}}]},
                          {"label": "❚❚ pause", "method": "animate",
                           "args": [[None], {"mode": "immediate", "frame": {"duration": 0, "redraw": False}}]}]}],
        sliders=[{"active": 0, "x": 0.2, "len": 0.78, "y": 0.02, "currentvalue": {"prefix": "t = "},
                  "steps": steps}],
    )
    return fig


# Opening the file as view.html#frame=N shows frame N at once (a link to one moment of the task; also how
# benchmarks/view_screenshot.py checks in a real browser that the frames move the robot).
_JUMP_TO_FRAME = """
var m = window.location.hash.match(/frame=(\\d+)/);
if (m) { Plotly.animate('{plot_id}', [m[1]], {mode: 'immediate', frame: {duration: 0, redraw: true},
                                            transition: {duration: 0}}); }
"""


def write_view(sol: Solution, path: Path, frames: int = 60) -> Path:
    """Write the view as one HTML file with plotly.js inside it (opens offline in any browser)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    cell_figure(sol, frames).write_html(path, include_plotlyjs=True, full_html=True, auto_play=False,
                                        post_script=_JUMP_TO_FRAME)
    return path
