"""Figures of experiments (the paper's results figures), PNG + PDF."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from designopt import style
from designopt.plots import draw_poses, plt, save
from designopt.style import METHOD_COLORS, fit_3d, label_3d
from designopt.tables import full_path

METHOD_LABELS = {"to": "TO (collocation)", "fk": "FK (Whitman et al.)", "fk_continuous": "FK, bounded steps"}
CASE_LABELS = {"placement_only": "placement only", "design_only": "design only", "combined": "design + placement"}
OPTIMA_SHOWN = 15  # distinct optima drawn in the search-progress figure, best first


def design_cost_figure(table: pd.DataFrame, summary: pd.DataFrame, directory: Path) -> list[Path]:
    """Best design cost per case and method (bars), every tracking full-path solve (dots), max joint step (labels)."""
    summary = full_path(summary)
    cases = [c for c in CASE_LABELS if c in set(table["case"])]
    methods = [m for m in METHOD_LABELS if m in set(table["method"])]
    fig, ax = plt.subplots(figsize=(7, 3.8))
    width = 0.8 / len(methods)
    top = 0.0
    for j, method in enumerate(methods):
        for i, case in enumerate(cases):
            row = table[(table["case"] == case) & (table["method"] == method)]
            x = i + (j - (len(methods) - 1) / 2) * width
            if row.empty or not np.isfinite(row["design_cost"].iloc[0]):
                ax.text(x, 1, "no start\ntracks", ha="center", fontsize=6)
                continue
            cost = row["design_cost"].iloc[0]
            ax.bar(x, cost, width * 0.9, color=METHOD_COLORS.get(method, f"C{j}"),
                   label=METHOD_LABELS[method] if i == 0 else None)
            starts = summary[(summary["case"] == case) & (summary["method"] == method) & summary["tracks"]]
            ax.scatter(np.full(len(starts), x), starts["design_cost"], s=8, color="k", zorder=3,
                       label="every tracking full-path solve" if (i == 0 and j == 0) else None)
            # above the bar and its dots, so that a short bar never cuts its label
            high = max([cost, *starts["design_cost"]])
            top = max(top, high)
            ax.annotate(f"{row['max_joint_step'].iloc[0]:.2g} rad", (x, high), xytext=(0, 4),
                        textcoords="offset points", ha="center", va="bottom", fontsize=6, rotation=90)
    n_design = table.drop_duplicates("case").set_index("case")["n_design_joints"]
    ax.set_xticks(range(len(cases)), [f"{CASE_LABELS[c]}\n({n_design[c]} design joints)" for c in cases])
    ax.set_yscale("log")
    if top > 0:
        ax.set_ylim(top=top * 30)  # room for the labels above the highest dot
    ax.set_ylabel("design cost  Σ Δt L_d  (best tracking start)")
    ax.set_title("Continuous design problem: label = largest joint step between waypoints")
    ax.legend(fontsize=7)
    return save(fig, directory, "design_cost")


def optimal_robots_figure(solutions: dict, directory: Path) -> list[Path]:
    """The best TO robot of each case at five poses along its path with the placed toolpath, side by side; each
    view has equal axes fitted to its own cell."""
    fig = plt.figure(figsize=(style.DOUBLE, style.DOUBLE / max(len(solutions), 1) * 1.05))
    ax = None
    for k, (case, sol) in enumerate(solutions.items()):
        ax = fig.add_subplot(1, len(solutions), k + 1, projection="3d")
        fit_3d(ax, draw_poses(ax, sol))
        label_3d(ax)
        ax.set_title(f"{CASE_LABELS.get(case, case)}\ndesign cost {sol.metrics.design_cost:.3g}")
    if ax is not None:
        style.legend_below(fig, ax, ncol=4)
    fig.subplots_adjust(wspace=0.35)
    return save(fig, directory, "optimal_robots")


def waypoint_figure(table: pd.DataFrame, directory: Path) -> list[Path]:
    fig, axes = plt.subplots(1, 3, figsize=(10, 3))
    axes[0].semilogx(table["waypoints"], table["design_cost"], "o-")
    axes[0].set_ylabel("best design cost")
    axes[1].loglog(table["waypoints"], table["max_midpoint_error"] * 1e3, "o-", color="C1")
    axes[1].axhline(1.0, ls="--", color="grey", lw=0.8)
    axes[1].set_ylabel("max position error between\nwaypoints [mm]")
    axes[2].loglog(table["waypoints"], table["median_solve_time_s"], "o-", color="C2")
    axes[2].set_ylabel("median solve time [s]")
    from matplotlib.ticker import NullFormatter

    for ax in axes:
        ax.set_xlabel("waypoints N")
        ax.set_xticks(table["waypoints"], [str(n) for n in table["waypoints"]])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_minor_formatter(NullFormatter())
    axes[0].set_title("(best of the multistart)", fontsize=8)
    fig.suptitle("Waypoint study (TO, design + placement)", fontsize=9)
    fig.tight_layout()
    return save(fig, directory, "waypoints")


def _ranked_bars(ax, rows: pd.DataFrame, title: str, starts: pd.DataFrame | None = None) -> None:
    """Structures ranked by their best design cost (bars) with every tracking start as a dot: the spread
    over starts shows how much of a ranking is the search's luck."""
    rows = rows.sort_values("design_cost")
    colors = [style.COLORS["best"] if np.isfinite(c) else "lightgrey" for c in rows["design_cost"]]
    ax.bar(range(len(rows)), rows["design_cost"].fillna(0), color=colors, label="best tracking start")
    if starts is not None and len(starts):
        for i, structure in enumerate(rows["structure"]):
            costs = starts.loc[(starts["structure"] == structure) & starts["tracks"], "design_cost"]
            ax.scatter(np.full(len(costs), i), costs, s=6, color=style.COLORS["start"], zorder=3,
                       label="every tracking full-path solve" if i == 0 else None)
        ax.legend(fontsize=6)
    ax.set_xticks(range(len(rows)), rows["structure"], rotation=90, fontsize=7, family="monospace")
    ax.set_yscale("log")
    ax.set_ylabel("design cost")
    ax.set_title(title, fontsize=9)


def structure_figures(table: pd.DataFrame, directory: Path, summary: pd.DataFrame | None = None) -> list[Path]:
    """The paper's structure figures plus best cost per number of joints; with the sweep's summary, every
    full-path solve is shown beside each structure's best (coarse solves' costs are of another sampling)."""
    summary = full_path(summary) if summary is not None else None
    paths = []
    six = table[table["dof"] == 6]
    if len(six):
        fig, ax = plt.subplots(figsize=(6, 3.5))
        if summary is not None:
            every = summary[(summary["dof"] == 6) & summary["tracks"]]
            ax.scatter(every["n_prismatic"] + 0.12, every["design_cost"], s=4, color=style.COLORS["other"],
                       label="every tracking full-path solve")
        ax.scatter(six["n_prismatic"], six["design_cost"], s=14, alpha=0.6, label="each 6-DOF structure (best)")
        best = six.groupby("n_prismatic")["design_cost"].min()
        ax.plot(best.index, best.values, "o-", color="C3", label="best per number of P joints")
        ax.set_yscale("log")
        ax.set_xlabel("number of prismatic joints")
        ax.set_ylabel("design cost (best tracking start)")
        ax.set_title("6-DOF structures: design cost against prismatic joints", fontsize=9)
        ax.legend(fontsize=7)
        paths += save(fig, directory, "structures_6dof_by_prismatic")
    for dof, stem in ((6, "structures_3R3P"), (5, "structures_5dof_3P")):
        rows = table[(table["dof"] == dof) & (table["n_prismatic"] == 3)]
        if len(rows):
            fig, ax = plt.subplots(figsize=(max(4, 0.3 * len(rows) + 1.5), 3.5))
            _ranked_bars(ax, rows, f"{dof}-DOF structures with three prismatic joints, ranked", summary)
            paths += save(fig, directory, stem)
    if len(table):
        from designopt.tables import best_per_dof

        best = best_per_dof(table)
        best = best[np.isfinite(best["design_cost"].astype(float))]
        fig, ax = plt.subplots(figsize=(5, 3.2))
        if best.empty:  # no structure tracks: say so rather than draw empty log axes
            ax.text(0.5, 0.5, "no structure tracks the path", ha="center", va="center", transform=ax.transAxes)
            ax.set_axis_off()
            paths += save(fig, directory, "structures_best_per_dof")
            return paths
        if summary is not None:
            every = summary[summary["tracks"]]
            ax.scatter(every["dof"] + 0.08, every["design_cost"], s=3, color=style.COLORS["other"],
                       label="every tracking full-path solve")
        ax.semilogy(best["dof"], best["design_cost"], "o-", color=style.COLORS["robot"], label="best structure")
        for _, r in best.iterrows():
            ax.annotate(r["structure"], (r["dof"], r["design_cost"]), textcoords="offset points", xytext=(-6, 6),
                        ha="right", fontsize=7, family="monospace")
        from matplotlib.ticker import LogLocator, NullFormatter

        ax.set_xticks(sorted(best["dof"].unique()))
        ax.set_xlim(best["dof"].min() - 0.5, best["dof"].max() + 0.5)
        ax.yaxis.set_major_locator(LogLocator(numticks=6))
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("number of joints")
        ax.set_ylabel("design cost")
        ax.set_title("Best structure per number of joints", fontsize=9)
        ax.legend(fontsize=7)
        paths += save(fig, directory, "structures_best_per_dof")
    return paths


def _features(vectors: np.ndarray) -> np.ndarray:
    """(offset, a, alpha) -> (offset, a, cos alpha, sin alpha): alpha and alpha + 2 pi coincide."""
    return np.column_stack([vectors[:, 0], vectors[:, 1], np.cos(vectors[:, 2]), np.sin(vectors[:, 2])])


def module_pca_figure(links: np.ndarray, modules: np.ndarray, assignment: list[int], directory: Path) -> list[Path]:
    """Links of the continuous stage and the catalogue's modules in their first two principal components."""
    X = np.vstack([_features(links), _features(modules)])
    centred = X - X.mean(axis=0)
    _, s, Vt = np.linalg.svd(centred, full_matrices=False)
    P = centred @ Vt[:2].T
    explained = s[:2] ** 2 / np.sum(s**2)
    L, M = P[: len(links)], P[len(links):]
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.scatter(M[:, 0], M[:, 1], marker="s", s=80, facecolors="none", edgecolors="k", label="modules")
    for k, (x, y) in enumerate(M):
        ax.annotate(f"m{k + 1}", (x, y), textcoords="offset points", xytext=(6, -10), fontsize=8)
    ax.scatter(L[:, 0], L[:, 1], color="C3", s=25, label="links (continuous TO with L_mod)")
    for i, (x, y) in enumerate(L):
        ax.annotate(f"L{i + 1}→m{assignment[i] + 1}", (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7,
                    color="C3")
    ax.set_xlabel(f"PC 1 ({explained[0]:.0%} of variance)")
    ax.set_ylabel(f"PC 2 ({explained[1]:.0%} of variance)")
    ax.set_title("Link design vectors and modules (d, a, cos α, sin α)", fontsize=9)
    ax.legend(fontsize=7)
    return save(fig, directory, "module_pca")


def search_progress_figure(progress: pd.DataFrame, solution_set: pd.DataFrame, directory: Path,
                           shown: int = OPTIMA_SHOWN) -> list[Path]:
    """Best tracking cost so far against solves and solver seconds (would more budget help?), and the ``shown``
    best distinct optima the search reached: each one's cost relative to the best, and how many solves reached it."""
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(11, 3.4))
    from matplotlib.ticker import FuncFormatter, MaxNLocator

    for ax, x, label in ((a1, "solves", "solves finished"), (a2, "solver_seconds", "solver time [s]")):
        ax.scatter(progress[x], progress["cost"], s=12, color="0.6", label="each tracking solve")
        ax.step(progress[x], progress["best_cost"], where="post", color="C0", label="best so far")
        ax.set_xlabel(label)
        ax.set_ylabel("design cost")
        ax.set_yscale("log")
    a1.xaxis.set_major_locator(MaxNLocator(integer=True))
    a1.legend(fontsize=7)
    best = solution_set.head(shown)
    if len(best):
        ratio = best["ratio_to_best"]
        a3.bar(np.arange(1, len(best) + 1), ratio, color="C2")
        for x, (r, n) in enumerate(zip(ratio, best["reached_by"], strict=True), start=1):
            a3.annotate(f"{n}", (x, r), ha="center", va="bottom", fontsize=6, xytext=(0, 1), textcoords="offset points")
        a3.set_yscale("log")
        a3.set_ylim(top=float(ratio.max()) * 1.5)
        plain = FuncFormatter(lambda v, _: f"{v:g}")
        a3.yaxis.set_major_formatter(plain)
        a3.yaxis.set_minor_formatter(plain)
    a3.xaxis.set_major_locator(MaxNLocator(integer=True))
    a3.set_xlabel(f"distinct optimum, best first ({len(best)} of {len(solution_set)})")
    a3.set_ylabel("design cost / best (solves reaching it)")
    fig.tight_layout()
    return save(fig, directory, "search_progress")
