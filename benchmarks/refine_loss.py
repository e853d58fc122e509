"""Where a finished run's refines end against what their screen found: does the lift to the full path keep a
screened optimum's cost?

    .venv/bin/python benchmarks/refine_loss.py RUN [RUN ...] --config configs/physical_stiffness.yaml \
        --reference 1.7428669603586052e-12

RUN: a run directory of the default search (its summary.csv and solutions/), e.g. the per-seed directories
`search_seeds.py --out DIR` keeps (DIR/<name>/s<seed>). For every refine: its screened start's cost (40 waypoints),
the lifted start on the full path (`designopt.solve.starts.lifted_guess`: design as screened, waypoints moved onto
the path by IK) -- its cost, whether it tracks, and its largest joint step over what the velocity limits allow
(v_max h) -- and where the refine ended, all over ``--reference`` (the best design known). Then per run: the best
screened cost against the run's answer.

``--mu-init V`` (repeatable) also solves every refine again from its screened start with IPOPT's barrier starting
at V instead of the warm start's 1e-4 (`Search.refine_mu_init`; the explore and screen stages are the run's, so this
is what a search with that refine would have answered), and prints per variant -- the run's own refines, each V, and
each candidate's better refine of all of them -- the answers' best / median / p90 / worst and how many are within
1.10x (two worker processes):

    .venv/bin/python benchmarks/refine_loss.py DIR/milling_physical/s* --config configs/physical_stiffness.yaml \
        --reference 1.7428669603586052e-12 --mu-init 1e-6
"""

from __future__ import annotations

import argparse
import os
import signal
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from joblib import Parallel, delayed  # noqa: E402

from designopt.config import load_config  # noqa: E402
from designopt.evaluation import evaluate  # noqa: E402
from designopt.experiments.adapters import search_from_config  # noqa: E402
from designopt.problem import problem_from_config  # noqa: E402
from designopt.solution import read_solution_for  # noqa: E402
from designopt.solve.search import Job  # noqa: E402
from designopt.solve.starts import lifted_guess  # noqa: E402
from designopt.solve.strategies.coarse_to_fine import coarse_problem, lifted_tasks  # noqa: E402
from designopt.solve.tasks import run_task  # noqa: E402
from designopt.tables import stage_kind  # noqa: E402
from designopt.transcriptions import Collocation  # noqa: E402
from designopt.transcriptions.trajectory import trajectory  # noqa: E402


def screened_start(run: Path, summary: pd.DataFrame, seed: int) -> tuple[Path, float] | None:
    """The screened solve a refine of ``seed`` started from (``summary``: the run's summary.csv), and its design
    cost: with several screen passes (screen, screen2, ...) the better one, as the search picks it
    (`coarse_to_fine.better_pass`); None when the run refined a coarse optimum (its path had no more waypoints than
    the screen's)."""
    d = summary
    rows = d[(d.seed == seed) & d.stage.map(lambda s: stage_kind(s) == "screen")]
    if rows.empty:
        return None
    tracking = rows[rows.tracks.astype(str) == "True"]
    best = tracking.loc[tracking.design_cost.idxmin()] if len(tracking) else rows.iloc[0]
    return run / str(best.solution_file), float(best.design_cost)


def refines(run: Path, full, screen_waypoints: int, ref: float) -> list[dict]:
    d = pd.read_csv(run / "summary.csv")
    rows = []
    for _, r in d[d.stage == "refine"].iterrows():
        found = screened_start(run, d, int(r.seed))
        if found is None:
            continue
        path, screened_cost = found
        sol = read_solution_for(coarse_problem(full, screen_waypoints), Collocation(), path)
        guess = lifted_guess(full, sol)
        start = evaluate(full, guess.q_d, trajectory(full.toolpath.t, guess.Q, guess.V))
        rows.append({"run": run.name, "seed": int(r.seed), "screen": screened_cost / ref,
                     "lifted_start": start.design_cost / ref, "start_tracks": start.tracks,
                     "step_over_limit": float((np.abs(np.diff(guess.Q, axis=0)) / full.max_steps).max()),
                     "refine": r.design_cost / ref, "refine_tracks": bool(r.tracks)})
    return rows


def replayed(config: str, run: str, seed: int, screen_waypoints: int, mu_init: float) -> tuple[float, bool]:
    """One refine solved again from its screened start with the refine's barrier from ``mu_init``: (cost, tracks)."""
    cfg = load_config(config)
    search, full = search_from_config(cfg), problem_from_config(cfg)
    path, _ = screened_start(Path(run), pd.read_csv(Path(run) / "summary.csv"), seed)
    sol = read_solution_for(coarse_problem(full, screen_waypoints), Collocation(), path)
    task = lifted_tasks([Job("", full)], [[(None, sol)]], 1, "refine", None, search, mu_init=mu_init)[0]
    done = run_task(task)
    return done.metrics.design_cost, done.metrics.tracks


def quartiles(answers: pd.Series) -> str:
    a = answers.to_numpy()
    return (f"{a.min():.3f} / {np.median(a):.3f} / {np.percentile(a, 90):.3f} / {a.max():.3f}, "
            f"{int((a <= 1.10).sum())} within 1.10x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--config", default="configs/milling.yaml")
    parser.add_argument("--reference", type=float, required=True, help="the best design cost known (full path)")
    parser.add_argument("--screen-waypoints", type=int, default=40)
    parser.add_argument("--mu-init", type=float, action="append", default=[],
                        help="also refine again from the screened starts with this barrier (repeatable)")
    args = parser.parse_args()
    full = problem_from_config(load_config(args.config))
    table = pd.DataFrame([row for run in args.runs for row in refines(run, full, args.screen_waypoints,
                                                                      args.reference)])
    table["loss"] = table.refine / table.screen
    print(table.drop(columns="tracked", errors="ignore").to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    lost, over = table.loss > 1.2, table.step_over_limit > 1.001
    print(f"\n{len(table)} refines: {int(lost.sum())} end above 1.2x their screened cost; lifted starts that track "
          f"{int(table.start_tracks.sum())}, with a step over the velocity limits {int(over.sum())}")
    table["tracked"] = table.refine.where(table.refine_tracks, np.inf)
    per_run = table.groupby("run").agg(screened=("screen", "min"), answer=("tracked", "min"))
    above = int((per_run.answer > 1.1 * per_run.screened).sum())
    print(f"runs whose answer is above 1.1x their best screened cost: {above} of {len(per_run)}")
    if not args.mu_init:
        return
    runs = {run.name: str(run) for run in args.runs}
    columns = ["tracked"]
    for mu in args.mu_init:
        done = Parallel(n_jobs=2)(delayed(replayed)(args.config, runs[r], seed, args.screen_waypoints, mu)
                                  for r, seed in zip(table.run, table.seed, strict=True))
        name = f"mu_init {mu:g}"
        table[name] = [cost / args.reference if tracks else np.inf for cost, tracks in done]
        columns.append(name)
    table["better of all"] = table[columns].min(axis=1)
    answers = table.groupby("run")[[*columns, "better of all"]].min().rename(columns={"tracked": "as run"})
    print("\n" + answers.to_string(float_format=lambda v: f"{v:.3f}"))
    for name in columns[1:]:
        better = int((answers[name] < 0.995 * answers["as run"]).sum())
        worse = int((answers[name] > 1.005 * answers["as run"]).sum())
        print(f"{name}: runs better / worse than as run (by more than 0.5 %): {better} / {worse}")
    print("\nthe answers (each run's best tracking refine) / best known: best / median / p90 / worst")
    for name in ("tracked", *columns[1:], "better of all"):
        label = "as run" if name == "tracked" else name
        print(f"  {label}: {quartiles(table.groupby('run')[name].min())}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
