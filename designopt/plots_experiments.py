"""Figures of experiments (the paper's results figures), PNG + PDF."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from designopt.plots import _equal_3d, _label_axes, draw_robot, plt, save

METHOD_LABELS = {"to": "TO (collocation)", "fk": "FK (Whitman et al.)", "fk_continuous": "FK, bounded steps"}
CASE_LABELS = {"placement_only": "placement only", "design_only": "design only", "combined": "design + placement"}


def design_cost_figure(table: pd.DataFrame, summary: pd.DataFrame, directory: Path) -> list[Path]:
    """Best design cost per case and method (bars), every tracking start (dots), max joint step (labels)."""
    cases = [c for c in CASE_LABELS if c in set(table["case"])]
    methods = [m for m in METHOD_LABELS if m in set(table["method"])]
    fig, ax = plt.subplots(figsize=(7, 3.8))
    width = 0.8 / len(methods)
    for j, method in enumerate(methods):
        for i, case in enumerate(cases):
            row = table[(table["case"] == case) & (table["method"] == method)]
            x = i + (j - (len(methods) - 1) / 2) * width
            if row.empty or not np.isfinite(row["design_cost"].iloc[0]):
                ax.text(x, 1, "no start\ntracks", ha="center", fontsize=6)
                continue
            cost = row["design_cost"].iloc[0]
            ax.bar(x, cost, width * 0.9, color=f"C{j}", label=METHOD_LABELS[method] if i == 0 else None)
            starts = summary[(summary["case"] == case) & (summary["method"] == method) & summary["tracks"]]
            ax.scatter(np.full(len(starts), x), starts["design_cost"], s=8, color="k", zorder=3,
                       label="every tracking start" if (i == 0 and j == 0) else None)
            ax.text(x, cost * 0.55, f"{row['max_joint_step'].iloc[0]:.2g} rad", ha="center", va="top",
                    fontsize=6, rotation=90, color="white")
    n_design = table.drop_duplicates("case").set_index("case")["n_design_joints"]
    ax.set_xticks(range(len(cases)), [f"{CASE_LABELS[c]}\n({n_design[c]} design joints)" for c in cases])
    ax.set_yscale("log")
    ax.set_ylabel("design cost  Σ Δt L_d  (best tracking start)")
    ax.set_title("Continuous design problem: label in bar = largest joint step between waypoints")
    ax.legend(fontsize=7)
    return save(fig, directory, "design_cost")


def optimal_robots_figure(solutions: dict, directory: Path) -> list[Path]:
    """The best TO robots at theta = 0 (d = 0 for P joints) with the placed toolpath, side by side."""
    fig = plt.figure(figsize=(4.5 * len(solutions), 4.5))
    for k, (case, sol) in enumerate(solutions.items()):
        ax = fig.add_subplot(1, len(solutions), k + 1, projection="3d")
        pts = draw_robot(ax, sol.chain, np.zeros(sol.problem.chain.n_moving), sol.problem.toolpath.points_W)
        _equal_3d(ax, np.vstack([pts, np.zeros((1, 3))]))
        _label_axes(ax)
        ax.set_title(f"{CASE_LABELS.get(case, case)}\ndesign cost {sol.metrics.design_cost:.3g}", fontsize=9)
        if k == 0:
            ax.legend(loc="upper left", fontsize=6)
    return save(fig, directory, "optimal_robots")


def waypoint_figure(table: pd.DataFrame, directory: Path) -> list[Path]:
    fig, axes = plt.subplots(1, 3, figsize=(10, 3))
    axes[0].plot(table["waypoints"], table["design_cost"], "o-")
    axes[0].set_ylabel("best design cost")
    axes[1].semilogy(table["waypoints"], table["max_midpoint_error"] * 1e3, "o-", color="C1")
    axes[1].axhline(1.0, ls="--", color="grey", lw=0.8)
    axes[1].set_ylabel("max position error between\nwaypoints [mm]")
    axes[2].loglog(table["waypoints"], table["median_solve_time_s"], "o-", color="C2")
    axes[2].set_ylabel("median solve time [s]")
    for ax in axes:
        ax.set_xlabel("waypoints N")
    fig.suptitle("Waypoint study (TO, design + placement)", fontsize=9)
    fig.tight_layout()
    return save(fig, directory, "waypoints")
