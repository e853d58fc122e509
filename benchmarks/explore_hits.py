"""How often does one exploration start land in the best basin known? The search's hit rate, measured cheaply.

A search finds the best design only if some exploration start ends in its basin; with a hit rate p per start, S
starts miss it with probability (1 - p)^S. This measures p directly: ``--starts`` seeded starts per seed of the
search's exploration problem (the task on ``--waypoints`` of its waypoints, capped at ``--max-iter``, the default
search's settings unless given), each compared with the best design known lifted to the same coarse path and
solved warm there. A start *hits* when it ends within 1.02x / 1.10x of that cost. Hundreds of starts take about
a minute, where the seed distribution of `search_seeds.py` takes 20 full runs: use this to compare ways of
starting (``--spread box``: designs from the task's box and first joints over the whole circle,
`designopt.initial_guess.box_design`, instead of perturbing the configured design by ``--scale``; ``--init home``:
IK walks pulled towards their first waypoint's configuration), then judge the search that uses the better one on
the seed distribution. ``--at-reference``: every start at the best design known itself, on a new joint branch
(`designopt.solve.starts.Rebranched` of its coarse solution: first joints over the whole circle): does the walk
find that design's basin when the design is right?

    .venv/bin/python benchmarks/explore_hits.py [--config configs/milling.yaml]
        [--reference benchmarks/reference/milling_best_known.json] [--first-seed 100] [--seeds 5] [--starts 80]
        [--scale 0.3 | --spread box] [--init ik|home|reach] [--at-reference] [--waypoints 10] [--max-iter 250]
        [--jobs 2] [--option ipopt.KEY=VALUE ...]
"""

from __future__ import annotations

import argparse
import signal
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from solver_options import parse_options

from designopt.config import load_config
from designopt.initial_guess import INIT_MODES, SPREADS
from designopt.problem import problem_from_config
from designopt.solution import read_solution_for
from designopt.solve import Job, Lifted, Seeded, Task, fan_out, preset
from designopt.solve.starts import Rebranched
from designopt.solve.strategies.coarse_to_fine import coarse_problem
from designopt.solve.strategies.steps import solve_setup
from designopt.transcriptions import Collocation

ROOT = Path(__file__).resolve().parent.parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="configs/milling.yaml")
    parser.add_argument("--reference", default="benchmarks/reference/milling_best_known.json")
    parser.add_argument("--first-seed", type=int, default=100)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--starts", type=int, default=80, help="starts per seed")
    parser.add_argument("--spread", choices=SPREADS, default="perturb")
    parser.add_argument("--init", choices=INIT_MODES, default=None, help="how starts walk (default: the search's)")
    parser.add_argument("--at-reference", action="store_true",
                        help="start at the best design known, on new joint branches (its coarse solution rebranched)")
    parser.add_argument("--scale", type=float, default=None, help="perturbation (default: the search's)")
    parser.add_argument("--waypoints", type=int, default=None, help="default: the search's explore_waypoints")
    parser.add_argument("--max-iter", type=int, default=None, help="default: the search's explore_max_iter")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                        help="an nlpsol option for the exploration's solves, e.g. ipopt.max_soc=0 (repeatable)")
    args = parser.parse_args()

    search = preset("default")
    waypoints = args.waypoints or search.explore_waypoints
    scale = search.perturbation if args.scale is None else args.scale
    problem = problem_from_config(load_config(ROOT / args.config))
    job = Job("hits", problem)
    coarse = coarse_problem(problem, waypoints)
    best = read_solution_for(problem, job.transcription, ROOT / args.reference)
    warm, hold = solve_setup(job, search, search.profile.warmed().capped(300))
    ((_, ref),) = list(fan_out([Task("hits", "reference", coarse, Collocation(), warm, Lifted(best), hold)], 1))
    if not ref.metrics.tracks:
        raise SystemExit(f"{args.reference}: the best design known does not track on {waypoints} waypoints")
    known = ref.metrics.design_cost

    profile, hold = solve_setup(job, search, search.profile.capped(args.max_iter or search.explore_max_iter))
    profile = replace(profile, options=(*profile.options, *parse_options(args.option)))
    seeds = range(args.first_seed, args.first_seed + args.seeds)

    init = args.init or search.init
    tasks = [Task("hits", "explore", coarse, Collocation(), profile,
                  Rebranched(ref, s, i, init) if args.at_reference else Seeded(s, i, scale, init, spread=args.spread),
                  hold)
             for s in seeds for i in range(args.starts)]
    t0 = time.perf_counter()
    done = list(fan_out(tasks, args.jobs))
    wall = time.perf_counter() - t0
    ratio = np.array([sol.metrics.design_cost / known if sol.metrics.tracks else np.inf for _, sol in done])
    cpu = sum(sol.raw.solve_time_s for _, sol in done)
    n = len(ratio)
    how = "the task's box" if args.spread == "box" else f"perturbation {scale}"
    how = "at the best design known, new joint branches" if args.at_reference else how
    how += f", init {init}"
    how += "".join(f", {k} {v}" for k, v in parse_options(args.option))
    print(f"{args.config}: {n} starts ({len(seeds)} seeds x {args.starts}; {how}) on {waypoints} waypoints, "
          f"<= {args.max_iter or search.explore_max_iter} iterations; best known there {known:.4g}")
    for level in (1.02, 1.10, 1.30):
        hits = int((ratio <= level).sum())
        p = hits / n
        print(f"  within {level:.2f}x: {hits} ({100 * p:.2f} % of starts; P(no hit in {search.starts} starts) "
              f"{(1 - p) ** search.starts:.2f})")
    finite = ratio[np.isfinite(ratio)]
    print(f"  tracking {len(finite)} of {n}; best {finite.min():.3f}x, quartiles "
          f"{' / '.join(f'{v:.2f}' for v in np.quantile(finite, [0.25, 0.5, 0.75]))}x; "
          f"solver CPU {cpu:.1f} s ({1000 * cpu / n:.0f} ms per start), wall {wall:.1f} s")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
