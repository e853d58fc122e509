"""Tables of results (pandas): the best tracking solve per case and method, per structure, per number of
joints. Computed from solutions or from summary.csv; plots draw them, the CLI prints them."""

from __future__ import annotations

import numpy as np
import pandas as pd

from designopt.design_space import enumerate_structures
from designopt.solve.optima import best_solution, cluster_designs

CASE_LABELS = {"placement_only": "placement only", "design_only": "design only", "combined": "design + placement"}


def best_table(solutions: dict) -> pd.DataFrame:
    """One row per (case, method): the best tracking start and how many starts tracked."""
    rows = []
    for (case, method), sols in solutions.items():
        best = best_solution(sols)
        tracking = [s for s in sols if s.metrics.tracks]
        rows.append({
            "case": case, "method": method, "n_design_joints": sols[0].problem.chain.n_design,
            "design_cost": best.metrics.design_cost if best else float("nan"),
            "max_joint_step": best.metrics.max_joint_step if best else float("nan"),
            "max_position_error": best.metrics.max_position_error if best else float("nan"),
            "starts": len(sols), "tracking_starts": len(tracking),
            "median_cost_tracking": pd.Series([s.metrics.design_cost for s in tracking]).median(),
            "median_solve_time_s": pd.Series([s.raw.solve_time_s for s in sols]).median(),
            "median_iterations": pd.Series([s.raw.iterations for s in sols]).median(),
            "best_seed": best.raw.seed if best else None,
        })
    order = {c: i for i, c in enumerate(CASE_LABELS)}
    return pd.DataFrame(rows).sort_values(["case", "method"], key=lambda c: c.map(order) if c.name == "case" else c)


def best_per_dof(table: pd.DataFrame) -> pd.DataFrame:
    """The lowest-cost tracking structure for each number of joints."""
    tracking = table.dropna(subset=["design_cost"]).sort_values("design_cost")
    return tracking.groupby("dof").head(1).sort_values("dof")


# solves on a coarser sampling of the path; every other stage is full-path
COARSE_STAGES = ("explore", "prescreen", "screen", "hop")
# full-path solves with the velocity limits relaxed (`Search.refine_relaxed`): steps of a refine, never answers
RELAXED_STAGES = ("relax",)


def stage_kind(stage) -> str:
    """A stage's name without its number: a search that screens or refines from several barriers names the second
    pass ``screen2``, ``refine2`` (`designopt.solve.strategies.coarse_to_fine.numbered_stage`)."""
    return str(stage).rstrip("0123456789")


def is_coarse(stage) -> bool:
    """Whether a stage solves on a coarser sampling of the path (`COARSE_STAGES`, numbered or not)."""
    return stage_kind(stage) in COARSE_STAGES


def is_relaxed(stage) -> bool:
    """Whether a stage solves the task with its velocity limits relaxed (`RELAXED_STAGES`, numbered or not)."""
    return stage_kind(stage) in RELAXED_STAGES


def _stage_of(stage) -> str:
    """explore, screen, relax, or final (any full-path stage of the task itself: refine, a multistart start, a
    neighbour start)."""
    return stage_kind(stage) if is_coarse(stage) or is_relaxed(stage) else "final"


def full_path(summary: pd.DataFrame) -> pd.DataFrame:
    """The rows of full-path solves of the task (`_stage_of` "final"): not the coarse stages of a search, nor its
    solves with relaxed velocity limits; a summary without stages (a plain multistart) as it is."""
    if "stage" not in summary:
        return summary
    return summary[summary["stage"].map(_stage_of) == "final"]


def structure_table(summary: pd.DataFrame) -> pd.DataFrame:
    """One row per structure: best tracking full-path solve (cost NaN if none tracks), how many full-path solves
    reached within 5 % of it (``near_best``) and, for a coarse-to-fine search, how many exploration solves came
    within 5 % of the exploration's best (``explore_near_best`` of ``explore_starts``); statuses."""
    rows = []
    stage = summary["stage"].map(_stage_of) if "stage" in summary else pd.Series("final", index=summary.index)
    tracks = summary["tracks"].astype(str) == "True"
    for structure, group in summary.groupby("structure", sort=False):
        final = group[stage[group.index] == "final"]
        explore = group[(stage[group.index] == "explore") & tracks[group.index]]
        tracking = final[tracks[final.index]]
        best = tracking.loc[tracking["design_cost"].idxmin()] if len(tracking) else None
        cost = best["design_cost"] if best is not None else float("nan")
        rows.append({
            "structure": structure, "dof": len(structure), "n_prismatic": structure.count("P"),
            "design_cost": cost,
            "tracking_starts": len(tracking), "starts": len(final),
            "near_best": int((tracking["design_cost"] <= 1.05 * cost).sum()),
            "explore_near_best": int((explore["design_cost"] <= 1.05 * explore["design_cost"].min()).sum()),
            "explore_starts": int((stage[group.index] == "explore").sum()),
            "statuses": ";".join(sorted(set(final["status"]))),
            "best_solution": best["solution_file"] if best is not None else "",
            "median_solve_time_s": group["solve_time_s"].median(),
            "solver_time_s": group["solve_time_s"].sum(),
        })
    table = pd.DataFrame(rows)
    order = {s: i for i, s in enumerate(enumerate_structures(1, 12))}
    return table.sort_values("structure", key=lambda c: c.map(order)).reset_index(drop=True)


def solution_set(solutions: list, tol: float = 0.02) -> pd.DataFrame:
    """The distinct local optima the tracking solutions reached, best first: cost, how many solves reached each
    (and which seeds), and the spread of their costs. Designs are compared joint by joint (`cluster_designs`)."""
    tracking = [s for s in solutions if s.metrics.tracks]
    if not tracking:
        return pd.DataFrame(columns=["optimum", "design_cost", "reached_by", "share", "seeds", "worst_cost_in_cluster",
                                     "ratio_to_best"])
    angle = np.array([j.kind == "angle" for j in tracking[0].problem.chain.design], dtype=bool)
    costs = np.array([s.metrics.design_cost for s in tracking])
    labels = cluster_designs(np.array([s.raw.q_d for s in tracking]), costs, angle, tol)
    rows = []
    for k in range(labels.max() + 1):
        members = np.flatnonzero(labels == k)
        rows.append({"optimum": k + 1, "design_cost": float(costs[members].min()), "reached_by": len(members),
                     "share": len(members) / len(solutions),
                     "seeds": " ".join(str(tracking[i].raw.seed) for i in members),
                     "worst_cost_in_cluster": float(costs[members].max())})
    table = pd.DataFrame(rows)
    table["ratio_to_best"] = table["design_cost"] / table["design_cost"].min()
    return table


def best_so_far(summary: pd.DataFrame) -> pd.DataFrame:
    """Best tracking design cost after each solve, in the order the solves finished (summary.csv's row order),
    against the number of solves and the solver seconds spent; ``cost`` is each solve's own (NaN if it does not
    track)."""
    tracks = summary["tracks"].astype(str) == "True"
    cost = summary["design_cost"].where(tracks)
    return pd.DataFrame({"solves": np.arange(1, len(summary) + 1),
                         "solver_seconds": summary["solve_time_s"].cumsum().to_numpy(),
                         "cost": cost.to_numpy(), "best_cost": cost.cummin().ffill().to_numpy()})
