"""Replay finished runs from one stage on with this checkout's search: what would another screen or refine answer?

A run's exploration is most of its cost, and a change to a later stage (the screen, the refine) leaves it as it
is; a change to the second round of the exploration (its starts on new joint branches) leaves the first round as
it is. For each RUN (a directory `search_seeds.py --out DIR` keeps, DIR/<name>/s<seed>), this copies it to
``--out``, drops the rows and solution files of ``--from`` and every stage after it (summary.csv, solutions/;
``rebranch``: the exploration's starts from number ``search.starts`` on, the config's search), and finishes the
copy with `designopt run CONFIG --resume` in this checkout (its config.yaml; a subprocess, so the checkout's own
`designopt` is the one imported): the kept stages are read back, the dropped ones solved again.
Prints each run's answer before and after against the best design known, and both distributions.

    .venv/bin/python benchmarks/replay_stages.py DIR/milling/s* --from screen --out REPLAY \
        --reference benchmarks/reference/milling_best_known.json

Run it from a `git worktree` that holds the variant (e.g. another screen barrier in `PRESETS["default"]`). A
replay from ``rebranch`` is the same as a run only when the variant's first round is the run's (the same starts).
"""

from __future__ import annotations

import argparse
import json
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from designopt.experiments.runs import search_of_run
from designopt.tables import stage_kind

ROOT = Path(__file__).resolve().parent.parent
# a stage's rows are dropped with every later one (refine2, ... follow); "rebranch" is the exploration's second round;
# "relax" (`Search.refine_relaxed`) goes with the refine: a solve is resumed by its stage and start number alone, so a
# kept relax row would stand in for a relaxed solve whose screened start the variant changed
ORDER = ("explore", "rebranch", "prescreen", "screen", "refine", "relax", "hop", "reflect")


def later(stage: str, number: int, start: str, search) -> bool:
    """Whether a solve of ``stage`` with start ``number`` is of ``start`` or after it (screen2 after screen, refine2
    after refine, hop_full after hop; an exploration start of the search's second round, `Search.second_round`,
    is ``rebranch``'s)."""
    kind = stage_kind(stage).removesuffix("_full")  # hop_full is the hop step's
    if kind == "explore" and search.second_round(number):
        kind = "rebranch"
    return kind in ORDER and ORDER.index(kind) >= ORDER.index(start)


def strip(run: Path, start: str) -> int:
    """Drop the rows and solution files of ``start`` and later stages; the number of rows dropped."""
    summary = pd.read_csv(run / "summary.csv")
    drop = dropped(summary, start, search_of_run(run))
    for name in summary.loc[drop, "solution_file"].dropna():
        (run / str(name)).unlink(missing_ok=True)
    summary.loc[~drop].to_csv(run / "summary.csv", index=False)
    # search.json too: the copy is finished by this checkout's search (a variant's), and `designopt run --resume`
    # refuses a run whose recorded search is another; the kept stages' solves stay the run's own
    for name in ("best.json", "solution_set.csv", "search.json"):
        (run / name).unlink(missing_ok=True)
    return int(drop.sum())


def dropped(summary: pd.DataFrame, start: str, search) -> pd.Series:
    """The rows of ``summary`` of stage ``start`` and later (`later`)."""
    return pd.Series([later(str(st), int(n), start, search) for st, n in
                      zip(summary["stage"], summary["seed"], strict=True)], index=summary.index, dtype=bool)


def answer(run: Path, known: float) -> float:
    """A run's best design cost over ``known`` (inf when the run has no answer)."""
    best = run / "best.json"
    return json.loads(best.read_text())["metrics"]["design_cost"] / known if best.exists() else np.inf


def quartiles(a: np.ndarray) -> str:
    return (f"{a.min():.3f} / {np.median(a):.3f} / {np.percentile(a, 90):.3f} / {a.max():.3f}, "
            f"{int((a <= 1.10).sum())} of {len(a)} within 1.10x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--from", dest="start", choices=ORDER[1:], default="screen")
    parser.add_argument("--out", type=Path, required=True, help="where the copies go (one per run)")
    parser.add_argument("--reference", required=True, help="the best design known (a solution file)")
    args = parser.parse_args()
    known = json.loads((ROOT / args.reference).read_text())["metrics"]["design_cost"]
    before, after = [], []
    for run in args.runs:
        experiment = run.parent.name
        copy = args.out / experiment / run.name
        if copy.exists():
            sys.exit(f"{copy}: exists already (say another --out)")
        shutil.copytree(run, copy)
        n_dropped = strip(copy, args.start)
        t0 = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "cli.main", "run", str(copy / "config.yaml"), "--out",
                               str(args.out), "--name", run.name, "--resume", "--no-figures"], cwd=ROOT,
                              capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if done.returncode not in (0, 3):
            sys.exit(f"{run}: designopt run --resume exited {done.returncode}: {done.stderr.strip()}")
        was, now = answer(run, known), answer(copy, known)
        before.append(was)
        after.append(now)
        search = search_of_run(copy)
        solved = int(dropped(pd.read_csv(copy / "summary.csv"), args.start, search).sum())
        print(f"{run}: {was:.3f} -> {now:.3f}x the best known ({n_dropped} solves dropped, {solved} solved, "
              f"{wall:.1f} s wall)", flush=True)
    b, a = np.array(before), np.array(after)
    print(f"as run: {quartiles(b)}")
    print(f"replayed from {args.start}: {quartiles(a)}")
    print(f"runs better / worse (by more than 0.5 %): {int((a < 0.995 * b).sum())} / {int((a > 1.005 * b).sum())}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
