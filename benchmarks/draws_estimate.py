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

``--confirm K`` applies a search drawn until K draws reach its answer (a draw's best within ``--within`` of the
lowest of its seed's draws; at most ``--max-draws``; judged and not adopted, docs/decisions.md, Search,
2026-12-06) to the runs, seed by seed: RUNS are then
draws of several seeds (a run of seed s + j x 1,000,000 is draw j of seed s, `Search.draw_seeds`; a run of
several draws gives them all), and each seed's answer is the lowest of its draws once K reach it (or all
``--max-draws`` are made). A seed whose next draw is not among RUNS is listed as open, with the seed to run next.
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
from designopt.solve.search import DRAW_STRIDE
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


def reaching(answers: list[float], within: float) -> int:
    """How many of a seed's draws reach its answer: those within ``within`` times the lowest (inf: a draw that
    tracks nothing, never one)."""
    finite = [a for a in answers if np.isfinite(a)]
    return sum(a <= within * min(finite) for a in finite) if finite else 0


def confirmed_answer(answers: list[float], confirm: int, within: float, most: int) -> tuple[float, int] | None:
    """What a search drawn until ``confirm`` draws reach its answer answers, given its draws' answers in draw order:
    (the lowest of the draws made, how many were made), or None when the draws given end before it stops. The
    first ``confirm`` draws are always made; then one more until ``confirm`` reach the lowest (`reaching`) or
    ``most`` are made."""
    for made in range(confirm, most + 1):
        if len(answers) < made:
            return None
        if reaching(answers[:made], within) >= confirm or made == most:
            return min(answers[:made]), made
    return None


def confirm_table(runs: list[Path], known: float, confirm: int, within: float, most: int) -> None:
    """Prints each seed's draws and the confirmed answer, the distribution over the seeds settled, and the open
    seeds' next draw to run."""
    draws: dict[int, dict[int, float]] = {}
    for run in runs:
        if not (run / "solution_set.csv").exists():  # written when the search has ended
            print(f"  {run}: not finished; left out")
            continue
        for seed, answer in zip(search_of_run(run).draw_seeds, draw_answers(run, known), strict=True):
            draws.setdefault(seed % DRAW_STRIDE, {})[seed // DRAW_STRIDE] = answer
    answers, made, missing = [], [], []
    for seed in sorted(draws):
        given = []  # draws 0, 1, ... as far as none is missing: the rule makes them in that order
        while len(given) in draws[seed]:
            given.append(draws[seed][len(given)])
        found = confirmed_answer(given, confirm, within, most)
        shown = ", ".join(f"{a:.3f}" for a in given)
        if found is None:
            missing.append(seed + len(given) * DRAW_STRIDE)
            print(f"  seed {seed}: draws {shown}x; open")
        else:
            answers.append(found[0])
            made.append(found[1])
            # more draws given than the rule made (e.g. a `thorough` run's three): what the rule answers over theirs
            beyond = (f"; the best of all {len(given)} given {min(given):.3f}x, the answer "
                      f"{found[0] / min(given):.4f}x it") if len(given) > found[1] else ""
            print(f"  seed {seed}: draws {shown}x; answer {found[0]:.3f}x after {found[1]} draws{beyond}")
    if answers:
        a = np.sort(answers)
        print(f"{len(a)} seeds settled: {describe(a, np.full(len(a), 1 / len(a)))}; within 1.03x "
              f"{int((a <= 1.03).sum())}; draws made {np.mean(made):.2f} on average, at most {max(made)}")
    if missing:
        print(f"open: run seed{'s' if len(missing) > 1 else ''} {' '.join(str(s) for s in missing)} next")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--reference", required=True, type=Path, help="the best design known (a solution file)")
    parser.add_argument("--draws", nargs="+", type=int, default=[2, 3])
    parser.add_argument("--confirm", type=int, help="draws until this many reach the answer (RUNS: draws per seed)")
    parser.add_argument("--within", type=float, default=1.02, help="with --confirm: a draw's best within this of the "
                                                                     "lowest reaches it")
    parser.add_argument("--max-draws", type=int, default=5, help="with --confirm: at most this many draws")
    args = parser.parse_args()
    known = json.loads(args.reference.read_text())["metrics"]["design_cost"]
    for run in args.runs:  # a glob that matched nothing reaches here as itself
        if not (run.is_dir() and run.name.startswith("s") and run.name[1:].isdigit()):
            parser.error(f"{run}: not a run directory of search_seeds.py (DIR/<config name>/s<seed>)")
    runs = sorted(args.runs, key=lambda run: int(run.name[1:]))
    if args.confirm:
        print(f"draws until {args.confirm} reach the answer (within {args.within:g}x), at most {args.max_draws}; "
              "answers / best known")
        confirm_table(runs, known, args.confirm, args.within, args.max_draws)
        return
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
