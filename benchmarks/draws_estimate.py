"""What k independent draws of a search reach (`Search.draws`), from runs of one draw: nothing is solved.

A search of k draws answers the best of k independent searches, each with its own seed, so its distribution over
seeds is that of the best of k runs of one draw. Given RUNS (run directories of one search and task on as many
seeds, e.g. `search_seeds.py --out DIR`'s DIR/<name>/s*; a run of several draws, e.g. `thorough`, gives each of its
draws' answers, in seed order), this prints for each k:

- ``every k of n``: the best of k runs drawn without replacement from the n, over all n-choose-k of them (its
  quantiles exact by order statistics: the i-th cheapest of n is the best of a k-subset in C(n - i, k - 1) of them);
- ``disjoint k-tuples``: the best of each k consecutive answers (n // k of them, none sharing a draw: with runs of
  k draws, the answers those runs gave).

Each as best / median / p90 / worst of (answer / best design known), and the share within 1.10x; for the first, the
chance that 20 seeds are all within (the share to the 20th power). Quantiles are the distribution's (the smallest
value whose cumulative share reaches q), so one draw's median can differ from `search_seeds.py`'s (which
interpolates) where n is even. The cost of k draws
is k times a run's (the draws' stages are solved side by side, so their workers stay as busy as one draw's).

    .venv/bin/python benchmarks/draws_estimate.py DIR/circle_standoff/s* --draws 2 3 \\
        --reference benchmarks/reference/circle_standoff_best_known.json
"""

from __future__ import annotations

import argparse
import json
import signal
from math import comb
from pathlib import Path

import numpy as np
import pandas as pd

from designopt.experiments.runs import search_of_run
from designopt.tables import full_path

WITHIN = 1.10
SEEDS = 20  # an evaluation set's size (issue 25: at least 20 seeds never tuned on)


def draw_answers(run: Path, known: float) -> list[float]:
    """A run's answer per draw over ``known`` (one for a run of one draw): the cheapest tracking full-path solve of
    each draw (`Search.draw_of` of its start number), what best.json holds for a run of one draw; inf for a draw
    that tracks nothing."""
    search = search_of_run(run)
    summary = pd.read_csv(run / "summary.csv")
    final = full_path(summary)  # a solve with relaxed velocity limits is never an answer
    final = final[final["tracks"].astype(str).eq("True")]
    best = final.groupby(search.draw_of(final["seed"]))["design_cost"].min()
    return [float(best.get(k, np.inf)) / known for k in range(search.draws)]


def best_of_every_k(answers: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """The distribution of the best of ``k`` of ``answers`` drawn without replacement: the sorted answers and the
    probability that each is the best (the i-th cheapest, 0-based, in C(n - 1 - i, k - 1) of the C(n, k) subsets)."""
    a = np.sort(np.asarray(answers, float))
    n = len(a)
    p = np.array([comb(n - 1 - i, k - 1) for i in range(n)], float) / comb(n, k)
    return a, p


def quantile(values: np.ndarray, weights: np.ndarray, q: float) -> float:
    """The ``q`` quantile of a discrete distribution (sorted ``values`` with these probabilities): the smallest
    value whose cumulative probability reaches q."""
    return float(values[np.searchsorted(np.cumsum(weights), q - 1e-12)])


def describe(values: np.ndarray, weights: np.ndarray, seeds: int | None = None) -> str:
    """Best / median / p90 / worst of a discrete distribution, its share within `WITHIN`, and (``seeds``) the chance
    that that many seeds drawn from it are all within."""
    support = values[weights > 0]
    within = weights[values <= WITHIN].sum()
    every = f"; {seeds} seeds all within: {within ** seeds:.0%}" if seeds else ""
    return (f"{support[0]:.3f} / {quantile(values, weights, 0.5):.3f} / {quantile(values, weights, 0.9):.3f} / "
            f"{support[-1]:.3f}, within {WITHIN:.2f}x {within:.1%}{every}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--reference", required=True, type=Path, help="the best design known (a solution file)")
    parser.add_argument("--draws", nargs="+", type=int, default=[2, 3])
    args = parser.parse_args()
    known = json.loads(args.reference.read_text())["metrics"]["design_cost"]
    runs = sorted(args.runs, key=lambda run: int(run.name.lstrip("s")))
    a = np.array([x for run in runs for x in draw_answers(run, known)])
    n = len(a)
    print(f"{n} draws of {len(runs)} runs, seeds {runs[0].name}-{runs[-1].name}; best / median / p90 / worst of "
          "answer / best known")
    print(f"  1 draw: {describe(*best_of_every_k(a, 1), SEEDS)}")
    for k in args.draws:
        if not 1 < k <= n:
            raise SystemExit(f"error: --draws {k}: needs 2 to {n} (the number of draws given)")
        tuples = a[: n // k * k].reshape(-1, k).min(axis=1)
        print(f"  {k} draws, every {k} of {n}: {describe(*best_of_every_k(a, k), SEEDS)}")
        uniform = np.full(len(tuples), 1 / len(tuples))
        print(f"  {k} draws, {len(tuples)} disjoint {k}-tuples: {describe(np.sort(tuples), uniform)}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
