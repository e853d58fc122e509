"""How long `designopt check` takes on real programs (issue 23's target: under 5 s on a 600-waypoint program).

For some programs of the G-code corpus (`make corpus`) placed on the PUMA cell of
benchmarks/configs/aluminum_button.yaml (a 0.6 m block, waypoints at most 20 mm apart), times the whole check
(config validation, reading and sampling the program, the milling force, the cell checks and the NLP count) in
one process, median of --repeats runs, and prints waypoints, NLP size and seconds per program.

    .venv/bin/python benchmarks/check_speed.py --repeats 5
"""

from __future__ import annotations

import argparse
import signal
import statistics
import time
from pathlib import Path

import yaml

from designopt.config import parse_config
from designopt.experiments.check import check_config

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / ".venv" / "gcode-corpus" / "carveracontroller" / "gcodes" / "Examples"
PROGRAMS = ["LED/ALUMINUM-Button.nc", "LED/ABS-Base.nc", "LED/ACRYLIC-SpiderMan.nc", "LED/ACRYLIC-Face.nc",
            "Relief/PirateShip.nc"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    base = yaml.safe_load((ROOT / "benchmarks" / "configs" / "aluminum_button.yaml").read_text())
    print("program | lines | waypoints | NLP variables | check median [s] | min [s]")
    for name in PROGRAMS:
        path = CORPUS / name
        # a block large enough for every program (the XY check is not what is timed), waypoints at most 20 mm apart
        data = {**base, "toolpath": {**base["toolpath"], "file": str(path), "spacing": 0.02},
                "cell": {**base["cell"], "block": [0.6, 0.6, 0.05]}}
        times, summary = [], None
        for _ in range(args.repeats):
            start = time.perf_counter()
            try:
                summary = check_config(parse_config(data, "bench.yaml", ROOT / "benchmarks" / "configs"))
            except Exception as exc:  # a program this cell cannot hold is reported, not timed
                summary = exc
                break
            times.append(time.perf_counter() - start)
        lines = sum(1 for _ in path.open(errors="replace"))
        if isinstance(summary, Exception):
            print(f"{name} | {lines} | - | - | refused: {str(summary)[:90]}")
            continue
        print(f"{name} | {lines} | {summary.waypoints} | {summary.n_variables} | {statistics.median(times):.3f} | "
              f"{min(times):.3f}", flush=True)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
