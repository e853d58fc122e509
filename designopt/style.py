"""One look for every figure: colours, fonts, sizes, and 3D views with equal axes fitted to what they show.

Every figure module calls `apply()` once and takes its colours from here, so a method or a case has the same
colour in every figure of every experiment.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

# Widths in inches: one column and the full text width of a two-column paper.
SINGLE, DOUBLE = 3.5, 7.2

COLORS = {
    "robot": "#1f5fa8",
    "path": "#c0392b",
    "workpiece": "0.55",
    "floor": "#d9c9a3",
    "base": "k",
    "best": "#2e8b57",
    "other": "0.65",
    "start": "k",
}
METHOD_COLORS = {"to": "#1f5fa8", "fk": "#e67e22", "fk_continuous": "#8e44ad", "rounded": "#16a085"}
CASE_COLORS = {"placement_only": "#16a085", "design_only": "#d35400", "combined": "#2c3e50"}
AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4")  # frame triads: x red, y green, z blue

RC = {
    "font.size": 8,
    "axes.titlesize": 9,
    "axes.labelsize": 8,
    "legend.fontsize": 7,
    "xtick.labelsize": 7,
    "ytick.labelsize": 7,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "savefig.dpi": 200,
    "savefig.bbox": "tight",
    "savefig.pad_inches": 0.05,
    "figure.constrained_layout.use": False,
    "pdf.fonttype": 42,  # editable text in the PDFs
}


def apply() -> None:
    """Set the shared matplotlib style (idempotent)."""
    plt.rcParams.update(RC)


def fit_3d(ax, points: np.ndarray, margin: float = 0.06, minimum: float = 0.05) -> None:
    """Equal axes (one metre is one metre in every direction) fitted to ``points``: the limits are the
    points' bounding box grown by ``margin`` of its largest side (each side at least ``minimum`` m), and the
    box aspect follows the limits so that no direction is stretched."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    lo, hi = points.min(axis=0), points.max(axis=0)
    pad = margin * max(float((hi - lo).max()), minimum)
    centre = (lo + hi) / 2
    half = np.maximum((hi - lo) / 2 + pad, minimum / 2)
    for setter, c, h in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, half, strict=True):
        setter(c - h, c + h)
    ax.set_box_aspect(tuple(2 * half), zoom=0.85)


def label_3d(ax) -> None:
    """Axis labels with units and few enough ticks that a short (foreshortened) axis never overlaps its labels."""
    from matplotlib.ticker import MaxNLocator

    for axis, name in ((ax.xaxis, "x"), (ax.yaxis, "y"), (ax.zaxis, "z")):
        axis.set_major_locator(MaxNLocator(3))
        axis.set_label_text(f"{name} [m]")
        axis.labelpad = 2
    ax.tick_params(pad=0)


def legend_below(fig, ax, ncol: int = 3) -> None:
    """The legend of ``ax`` under the figure: it never covers the data and is never cut off."""
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="lower center", ncol=ncol, frameon=False, bbox_to_anchor=(0.5, 0.0))
        fig.subplots_adjust(bottom=0.1)


apply()
