"""Where a search loses the best design's family: never reached, not screened, or lost after the screen.

A coarse optimum is of the *best family* when every link length of its arm (|a| of each link, and the offsets d
summed along each run of parallel joint axes, where they are interchangeable: `lengths`; not the placement) is
within ``--within`` metres of the best design known's (``--reference``): the family the screen and
the refine can carry to the best design, even where its coarse cost on 10 waypoints is 1.5-2x the best's. For
each RUN (a directory `search_seeds.py --out DIR` keeps, DIR/<name>/s<seed>) this reads every tracking coarse
optimum's design (its solution file) and prints:

- per kind of exploration start (first round; a second-round leader's drawn starts, its extra starts
  `Search.rebranch_extra`, its moved starts `Search.rebranch_moved`): starts, family coarse optima, and starts per
  family optimum;
- per run: its family coarse optima (how many, the best one's coarse rank and coarse cost over the best known),
  the best screen of a family candidate, the answer, and where the family was lost: ``never reached`` (no family
  coarse optimum), ``not screened``, ``screened, not landed`` (no family screen within 1.10x), ``lost in the
  refine`` (a family screen within 1.10x, the answer above it) or ``reached`` (the answer within 1.10x).

Nothing is solved. A run's search is its search.json (`designopt.experiments.runs.search_of_run`); a run written
before runs had one is read from its config.yaml with this checkout's presets, so one made by a checkout whose
preset numbered its starts otherwise (another leader width) gets wrong start kinds (its verdict does not depend on
them). The length test suits a task whose near-best designs are one arm (the circle with a keep-out
zone); on the main job designs within 1.10x of the best known have other lengths too (20 of 20 runs reach 1.10x
with 7 family optima among 17,600), and under a physical stiffness model many designs share the lengths.

    .venv/bin/python benchmarks/family_reach.py DIR/circle_standoff/s* \\
        --reference benchmarks/reference/circle_standoff_best_known.json
"""

from __future__ import annotations

import argparse
import json
import re
import signal
from pathlib import Path

import numpy as np
import pandas as pd
from replay_stages import answer

from designopt.config import load_config
from designopt.experiments.runs import search_of_run
from designopt.initial_guess import start_index
from designopt.problem import problem_from_config
from designopt.tables import stage_kind

ROOT = Path(__file__).resolve().parent.parent
WITHIN = 1.10  # an answer or screen "within" the best known: at most this factor above it


def start_kind(search, number: int) -> str:
    """Which kind of exploration start ``number`` is: first round, or a second-round leader's drawn, extra or
    moved start (`Search.leader_start`, `Search.more_blocks`), in its own draw (`Search.draws`)."""
    search = search.drawn()[search.draw_of(number)]
    rank = search.leader_of(number)
    if rank is None:
        return "first round"
    index = start_index(number, search.seed)
    r = next(r for r in range(search.rebranch_rounds)
             if 0 <= index - search.leader_start(r, rank) < search.leader_width)
    offset = index - search.leader_start(r, rank)
    if offset < search.leader_drawn:
        return "drawn"
    for block, (count, size, perturbation, snapped) in enumerate(search.more_blocks):
        begin = search.more_start(block, r, rank) - search.leader_start(r, rank)
        if count > 0 and begin <= offset < begin + size:
            kind = "extra" if not perturbation else f"moved by {perturbation:g}"
            return f"{kind}, snapped" if snapped else kind
    return "other"


PARALLEL = 0.2  # consecutive joint axes are parallel where |sin(alpha)| is below this


def lengths(design_joints: dict, names: list[str], grouped_by: dict | None = None) -> np.ndarray:
    """An arm's link lengths as the kinematics sees them [m]: |a| of each link, and for each run of consecutive
    parallel joint axes (twist near 0 or pi) the |signed sum| of the offsets d along it, since an offset moves
    along a parallel axis to the next without changing the arm (d_i + d_(i+1) at twist 0, d_i - d_(i+1) at pi).
    ``names``: the design's length joints (`linkK.a`, `linkK.d`); a length joint of another name is taken as
    it is. ``grouped_by``: the design whose twists decide which axes are parallel (None: this one), so that two
    designs' lengths compare entry by entry; the signs are this design's own."""
    grouped_by = design_joints if grouped_by is None else grouped_by
    links = sorted({int(m.group(1)) for n in names if (m := re.fullmatch(r"link(\d+)\.[ad]", n))})
    out = [abs(design_joints[n]) for n in names if not re.fullmatch(r"link\d+\.[ad]", n)]
    out += [abs(design_joints[f"link{k}.a"]) for k in links if f"link{k}.a" in names]
    offsets = [k for k in links if f"link{k}.d" in names]
    run, sign = 0.0, 1.0
    for i, k in enumerate(offsets):
        run += sign * design_joints[f"link{k}.d"]
        joined = (i + 1 < len(offsets) and offsets[i + 1] == k + 1
                  and abs(np.sin(grouped_by.get(f"link{k}.alpha", np.pi / 2))) < PARALLEL)
        if joined:
            sign *= np.sign(np.cos(design_joints.get(f"link{k}.alpha", 0.0))) or 1.0
        else:
            out.append(abs(run))
            run, sign = 0.0, 1.0
    return np.array(out)


def run_rows(run: Path, reference: dict, within: float) -> tuple[pd.DataFrame, dict]:
    """(one row per exploration solve: its start kind and whether it is a tracking family optimum; the run's
    verdict row)."""
    search, chain = search_of_run(run), problem_from_config(load_config(run / "config.yaml")).chain
    placement = {j.name for j in chain.placement_joints}
    names = [j.name for j in chain.design if j.kind == "length" and j.name not in placement]
    best = lengths(reference["design_joints"], names)
    known = reference["metrics"]["design_cost"]
    summary = pd.read_csv(run / "summary.csv")
    kind = summary["stage"].astype(str).map(stage_kind)
    tracks = summary["tracks"].astype(bool)
    explored = summary[kind == "explore"]
    ok = tracks[kind == "explore"]
    family = [bool(o) and np.abs(lengths(json.loads((run / f).read_text())["design_joints"], names,
                                                    reference["design_joints"]) - best).max()
              <= within for f, o in zip(explored["solution_file"], ok, strict=True)]
    rows = pd.DataFrame({"run": run.name, "kind": [start_kind(search, int(s)) for s in explored["seed"]],
                         "family": family, "seed": explored["seed"].to_numpy(),
                         "cost": explored["design_cost"].to_numpy() / known, "tracks": ok.to_numpy()})
    ranked = rows[rows["tracks"]].sort_values("cost", kind="stable").reset_index(drop=True)
    fam = ranked[ranked["family"]]
    screens = summary[(kind == "screen") & tracks & summary["seed"].isin(fam["seed"])]
    screened = screens["design_cost"].min() / known if len(screens) else np.nan
    best_cost = answer(run, known)
    if best_cost <= WITHIN:
        verdict = "reached"
    elif fam.empty:
        verdict = "never reached"
    elif screens.empty:
        verdict = "not screened"
    elif screened > WITHIN:
        verdict = "screened, not landed"
    else:
        verdict = "lost in the refine"
    return rows, {"run": run.name, "family optima": len(fam),
                  "best family rank": int(fam.index[0]) if len(fam) else None,
                  "its coarse cost": round(float(fam["cost"].iloc[0]), 3) if len(fam) else None,
                  "best family screen": round(float(screened), 3), "answer": round(float(best_cost), 3),
                  "where": verdict}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--reference", required=True, help="the best design known (a solution file)")
    parser.add_argument("--within", type=float, default=0.06, help="family: every link length within this [m]")
    args = parser.parse_args()
    reference = json.loads((ROOT / args.reference).read_text())
    done = [run_rows(run, reference, args.within) for run in args.runs]
    starts = pd.concat([rows for rows, _ in done], ignore_index=True)
    per_kind = starts.groupby("kind").agg(starts=("family", "size"), family=("family", "sum"))
    per_kind["starts per family optimum"] = (per_kind["starts"] / per_kind["family"].replace(0, np.nan)).round()
    print(f"{len(starts)} exploration solves of {len(args.runs)} runs; family: every link length within "
          f"{args.within} m of the best known's\n")
    print(per_kind.to_string())
    runs = pd.DataFrame([verdict for _, verdict in done])
    print("\n" + runs.to_string(index=False))
    print("\n" + ", ".join(f"{n} {where}" for where, n in runs["where"].value_counts().items()))


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
