"""The modular neighbourhood search replayed on the enumeration's screening: how often it ends at the best assignment.

Reads a finished `modular_enumeration.py` run (every assignment's screening cost on the coarse path, and the full-path
cost of the best screened and of a random sample) and replays the neighbourhood stage of `designopt modular`
(`designopt.experiments.modular`: a local search over one-link changes, with `--swaps` also exchanges of neighbouring
links, on screening costs from a start assignment and seeded random ones, then the best screened re-solved on the full
path) for many seeds, with the enumeration's costs in place of the solves. Prints, per budget, the distribution over
seeds of (the search's full-path answer / the best full-path cost of the enumeration) and how many assignments it
screened.

The replay uses the enumeration's screening (search seed 0) for every seed: what it measures is the local
search and its starts, not the screening's own seed-to-seed noise (real runs: docs/results.md). Like the search,
it evaluates one assignment per robot (`designopt.modular.same_robot`); the enumeration screened every assignment
with its placement z in the box, so a robot costs what its first assignment met cost there, where the search
solves it with the placement z of any assignment of the robot.

    .venv/bin/python benchmarks/modular_search_eval.py RUN_DIR [--first-seed 1000] [--seeds 20]
        [--budget 100 200 300] [--sample-share 0.1667] [--refine 8] [--start 213151] [--swaps]
"""

from __future__ import annotations

import argparse
import signal
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd

from designopt.config import load_config
from designopt.experiments.modular import NEIGHBOURHOOD_SAMPLE, catalogue_from_config
from designopt.modular import same_robot, screened_candidates
from designopt.tables import full_path

ROOT = Path(__file__).resolve().parent.parent


def costs(run: Path) -> tuple[dict, dict]:
    """(screening cost, full-path cost) per assignment (tuples of 0-based module indices); inf: does not track."""
    summary = pd.read_csv(run / "summary.csv")
    tracks = summary["tracks"].astype(str) == "True"
    out = []
    for prefix, rows in (("s", summary[tracks]), ("f", full_path(summary[tracks]))):
        rows = rows[rows["case"].astype(str).str.startswith(prefix)]
        best = rows.groupby("case")["design_cost"].min()
        out.append({tuple(int(c) - 1 for c in case[1:]): float(v) for case, v in best.items()})
    return out[0], out[1]


def replay(screen: dict, full: dict, start, seed: int, budget: int, share: float, refine: int, catalogue,
           swaps: bool = False):
    """(the best screening cost it found, the answer's full-path cost, assignments screened, refined candidates
    without a full-path cost). The answer is the best full-path cost among the refined candidates that the
    enumeration solved on the full path: an upper bound when some were not (they ranked below its refinement), NaN
    when none was. An assignment the screening did not track costs inf."""
    screened = lambda batch, _: [screen.get(a, np.inf) for a in batch]  # noqa: E731
    ranked, evaluated = screened_candidates(start, len(catalogue.modules), screened, budget, round(budget * share),
                                            refine, seed, partial(same_robot, catalogue=catalogue), swaps)
    known = [full[a] for a in ranked if a in full]
    found = min(c for _, c in evaluated)
    return found, (min(known) if known else np.nan), len(evaluated), len(ranked) - len(known)


def _quantiles(r) -> str:
    r = np.asarray(r, float)
    return (f"best {np.nanmin(r):.3f} median {np.nanmedian(r):.3f} p90 {np.nanpercentile(r, 90):.3f} worst "
            f"{np.nanmax(r):.3f}; within 1.10x {int(np.sum(r <= 1.10))}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("--config", default=str(ROOT / "configs" / "modular.yaml"), help="the enumeration's catalogue")
    parser.add_argument("--first-seed", type=int, default=1000)
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--budget", type=int, nargs="+", default=[100, 200, 300])
    parser.add_argument("--sample-share", type=float, default=NEIGHBOURHOOD_SAMPLE,
                        help="the share of the budget screened as a spread sample before the local searches")
    parser.add_argument("--refine", type=int, default=8)
    parser.add_argument("--swaps", action="store_true", help="a step also exchanges two neighbouring links' modules")
    parser.add_argument("--start", default="213151",
                        help="the first start's modules (the rounded assignment; default: seed 0's in docs/results.md)")
    args = parser.parse_args()

    screen, full = costs(Path(args.run))
    best_screen = min(screen.values())
    best = min(full.values()) if full else np.nan
    catalogue = catalogue_from_config(load_config(args.config))
    start = tuple(int(c) - 1 for c in args.start)
    print(f"{len(screen)} assignments track on the screening (best {best_screen:.6g}), {len(full)} solved on the full "
          f"path (best {best:.6g}); seeds {args.first_seed}-{args.first_seed + args.seeds - 1}")
    for budget in args.budget:
        found, answer, spent, unknown = zip(*[replay(screen, full, start, seed, budget, args.sample_share, args.refine,
                                                     catalogue, args.swaps)
                                              for seed in range(args.first_seed, args.first_seed + args.seeds)],
                                            strict=True)
        print(f"budget {budget} (screened {int(np.median(spent))} median): best screened found / best screening "
              f"cost: {_quantiles(np.array(found) / best_screen)}")
        if full:
            print(f"    answer on the full path / best full-path cost: {_quantiles(np.array(answer) / best)}; refined "
                  f"candidates without a full-path cost {sum(unknown)}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
