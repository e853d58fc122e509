"""Does the answer depend on the seed? `designopt run CONFIG --no-figures` for several search seeds.

Each seed is one run of the CLI in a subprocess (wall time includes start-up, the NLP builds and the search);
its best design cost is compared with the best design known for the problem (a solution file).

    .venv/bin/python benchmarks/search_seeds.py [--config configs/milling.yaml] [--seeds 5]
        [--reference benchmarks/reference/milling_best_known.json] [--set search.preset=paper]

Prints one line per seed, then the spread between seeds and the best, median, 90th percentile and worst ratio to
the best known. Judge a search on seeds it was never tuned on (e.g. --first-seed 1000 --seeds 20).
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parent.parent


def _set(cfg: dict, dotted: str, value) -> None:
    *path, last = dotted.split(".")
    for key in path:
        cfg = cfg.setdefault(key, {})
    cfg[last] = value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="configs/milling.yaml")
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--reference", default="benchmarks/reference/milling_best_known.json")
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--out", help="keep the runs here (default: a temporary directory)")
    parser.add_argument("--set", action="append", default=[], help="KEY=VALUE (YAML value), e.g. "
                                                                     "search.starts=120")
    args = parser.parse_args()
    config = ROOT / args.config
    base = yaml.safe_load(config.read_text())
    for item in args.set:
        key, value = item.split("=", 1)
        _set(base, key, yaml.safe_load(value))
    known = json.loads((ROOT / args.reference).read_text())["metrics"]["design_cost"] if args.reference else None
    ratios, walls = [], []
    with tempfile.TemporaryDirectory() as scratch:
        tmp = args.out or scratch
        for seed in range(args.first_seed, args.first_seed + args.seeds):
            cfg = json.loads(json.dumps(base))
            _set(cfg, "search.seed", seed)
            # beside the original (relative files resolve), named so that concurrent runs do not collide
            path = config.parent / f".bench-{config.stem}-{os.getpid()}-seed{seed}.yaml"
            path.write_text(yaml.safe_dump(cfg))
            try:
                t0 = time.perf_counter()
                done = subprocess.run([sys.executable, "-m", "cli.main", "run", str(path), "--out", tmp, "--name",
                                       f"s{seed}", "--no-figures"], cwd=ROOT, capture_output=True, text=True)
                wall = time.perf_counter() - t0
            finally:
                path.unlink()
            if done.returncode != 0:  # e.g. 2: the run exists in --out already (say --out elsewhere)
                sys.exit(f"seed {seed}: designopt run exited {done.returncode}: {done.stderr.strip()}")
            best = json.loads((Path(tmp) / cfg["name"] / f"s{seed}" / "best.json").read_text())["metrics"]
            cost = best["design_cost"]
            ratios.append(cost / known if known else cost)
            walls.append(wall)
            extra = f" ({cost / known:.3f}x best known)" if known else ""
            print(f"seed {seed}: best {cost:.6g}{extra}, {wall:.1f} s wall", flush=True)
    if known:
        print(f"spread between seeds {max(ratios) / min(ratios):.3f}x; worst {max(ratios):.3f}x, best "
              f"{min(ratios):.3f}x the best known ({known:.6g})")
        q = np.quantile(ratios, [0.0, 0.5, 0.9, 1.0])
        print(f"{len(ratios)} seeds, best / median / p90 / worst: {q[0]:.3f} / {q[1]:.3f} / {q[2]:.3f} / {q[3]:.3f}x "
              f"the best known; {sum(walls):.0f} s wall in all")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
