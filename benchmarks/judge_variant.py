"""Judge a search variant against the default on the same seeds, by a rule written down before either ran.

BASE and VARIANT are directories of runs of one task (DIR/<name> of `search_seeds.py --out DIR`, or of
`replay_stages.py --out R`), one run per seed (s<seed>); the seeds both hold are compared. Each run's answer is its
best design cost (best.json; a run without one counts as infinitely bad) over the best design known (``--reference``).
This prints both distributions (best / median / p90 / worst, within 1.10x), the seeds better and worse by more
than ``--margin``, the variant's solve time against the base's (`stage_cost.py`: each stage's iterations at the
base's own time per iteration there, so a shared machine does not decide), and the verdict of the rule:

- seeds better >= seeds worse (``--strictly-better``: more better than worse, as the circle's clause asks);
- median and worst not worse than the base's by more than ``--hold``;
- solve time at most ``--time`` x the base's.

    .venv/bin/python benchmarks/judge_variant.py DIR/circle_standoff R/circle_standoff \
        --reference benchmarks/reference/circle_standoff_best_known.json --strictly-better --time 1.10

Exit code 0 when the variant passes, 1 when it does not. The rule is this project's (docs/decisions.md, "Search");
what it cannot do is keep a variant from being tuned on the seeds that judge it: use seeds never run before.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from replay_stages import answer, quartiles
from stage_cost import common_runs, compared

ROOT = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class Rule:
    """What a variant must show on one task: ``margin`` what counts as better or worse per seed (a fraction),
    ``hold`` how much worse median and worst may get, ``time`` the solve time allowed (x the base's),
    ``strictly_better``: more seeds better than worse (else at least as many)."""

    margin: float = 0.01
    hold: float = 0.005
    time: float = 1.10
    strictly_better: bool = False


def verdict(base: np.ndarray, variant: np.ndarray, time_ratio: float, rule: Rule) -> tuple[bool, list[str]]:
    """Whether ``variant`` (each seed's answer over the best known) passes ``rule`` against ``base`` (the same
    seeds, in the same order), and why not."""
    better = int((variant < base / (1 + rule.margin)).sum())
    worse = int((variant > base * (1 + rule.margin)).sum())
    failed = []
    if better < worse or (rule.strictly_better and better <= worse):
        failed.append(f"seeds better / worse {better} / {worse}")
    if np.median(variant) > np.median(base) * (1 + rule.hold):
        failed.append(f"median {np.median(base):.3f} -> {np.median(variant):.3f}x")
    if variant.max() > base.max() * (1 + rule.hold):
        failed.append(f"worst {base.max():.3f} -> {variant.max():.3f}x")
    if time_ratio > rule.time:
        failed.append(f"solve time {time_ratio:.3f}x > {rule.time:.2f}x")
    return not failed, failed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base", type=Path)
    parser.add_argument("variant", type=Path)
    parser.add_argument("--reference", required=True, help="the best design known (a solution file)")
    parser.add_argument("--margin", type=float, default=Rule.margin, help="a seed better or worse by more than this")
    parser.add_argument("--hold", type=float, default=Rule.hold, help="median and worst may get this much worse")
    parser.add_argument("--time", type=float, default=Rule.time, help="solve time allowed, x the base's")
    parser.add_argument("--strictly-better", action="store_true", help="more seeds better than worse")
    args = parser.parse_args()
    rule = Rule(args.margin, args.hold, args.time, args.strictly_better)
    known = json.loads((ROOT / args.reference).read_text())["metrics"]["design_cost"]
    runs = common_runs(args.base, args.variant)
    if not runs:
        sys.exit(f"{args.base}, {args.variant}: no run in both")
    base = np.array([answer(args.base / r, known) for r in runs])
    variant = np.array([answer(args.variant / r, known) for r in runs])
    _, time_ratio = compared(args.base, args.variant, runs)
    moved = [f"{r} {b:.3f} -> {v:.3f}" for r, b, v in zip(runs, base, variant, strict=True)
             if abs(np.log(v / b)) > np.log1p(rule.margin)]
    print(f"{len(runs)} seeds ({runs[0]}-{runs[-1]}), against the best known {known:.4g}")
    print(f"base:    {quartiles(base)}")
    print(f"variant: {quartiles(variant)}")
    print(f"seeds moved by more than {rule.margin:.1%}: {', '.join(moved) or 'none'}")
    print(f"solve time: {time_ratio:.3f}x the base's (its iterations at the base's time per iteration per stage)")
    passed, failed = verdict(base, variant, time_ratio, rule)
    print("PASS" if passed else f"FAIL: {'; '.join(failed)}")
    sys.exit(0 if passed else 1)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
