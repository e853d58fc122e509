"""What writing a solution file's text costs: `designopt.solution.json_text` (one line per key, one per row of a
table, each line by json's C encoder; since 2026-12-05) against ``json.dump(data, fh, indent=1)`` (json's Python
encoder over every number; what `write_json` did before), on the solution files of finished runs.

    .venv/bin/python benchmarks/solution_write.py RUN [RUN ...] [--files 300] [--rounds 5]

A run's main process writes one file per solve while its workers solve (a default run of the main job about
1,000). Prints per run the files timed, their waypoint counts, the milliseconds per file of each writer (median of
the rounds, the two alternating within each round), their ratio, and the sizes of the texts.
"""

from __future__ import annotations

import argparse
import io
import json
import signal
import statistics
import time
from pathlib import Path

from designopt.solution import json_text


def indented(data: dict) -> str:
    fh = io.StringIO()
    json.dump(data, fh, indent=1)
    return fh.getvalue()


def seconds(writer, documents: list[dict]) -> float:
    t0 = time.perf_counter()
    for data in documents:
        writer(data)
    return time.perf_counter() - t0


def main() -> None:
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("runs", nargs="+", type=Path, help="run directories (results/<experiment>/<name>)")
    parser.add_argument("--files", type=int, default=300, help="solution files per run, the first by name")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    print("run | files | waypoints | indent=1 ms/file | json_text ms/file | ratio | size indent=1 / json_text")
    for run in args.runs:
        paths = sorted((run / "solutions").glob("*.json"))[: args.files]
        documents = [json.loads(p.read_text()) for p in paths]
        if not documents:
            print(f"{run} | 0 files")
            continue
        for data in documents:
            assert json.loads(json_text(data)) == json.loads(indented(data))
        old, new = [], []
        for _ in range(args.rounds):
            old.append(seconds(indented, documents))
            new.append(seconds(json_text, documents))
        counts = sorted({len(d["q"]) for d in documents})
        ms_old, ms_new = (1e3 * statistics.median(s) / len(documents) for s in (old, new))
        size_old = sum(len(indented(d)) for d in documents)
        size_new = sum(len(json_text(d)) for d in documents)
        print(f"{run} | {len(documents)} | {counts} | {ms_old:.2f} | {ms_new:.2f} | {ms_new / ms_old:.2f} | "
              f"{size_old / 1e6:.1f} / {size_new / 1e6:.1f} MB")


if __name__ == "__main__":
    main()
