"""Run directories (SPEC §7): results/<experiment>/<run-name>/ with config, summary, solutions, figures, log.

Every row of summary.csv is appended and flushed as soon as its solve finishes, and every solution file is
written atomically, so a run that dies keeps everything it finished.
"""

from __future__ import annotations

import csv
import datetime as dt
import io
import os
from pathlib import Path

import pandas as pd

SUMMARY_COLUMNS = [
    "experiment", "case", "method", "structure", "dof", "n_prismatic", "n_design_joints",
    "design_cost", "max_position_error", "max_axis_error", "max_joint_step", "tracks", "best",
    "status", "success", "iterations", "solve_time_s", "build_time_s", "n_variables", "n_constraints",
    "objective", "regularization", "min_standoff", "kinematic_drift", "seed",
    "stiffness_revolute", "stiffness_prismatic", "deflection", "cost_modular", "solution_file",
]


def default_run_name() -> str:
    return dt.datetime.now().strftime("%Y%m%d-%H%M%S")


class RunDirectory:
    """One run's directory and the files in it."""

    def __init__(self, path: Path):
        self.path = Path(path)
        self.solutions = self.path / "solutions"
        self.figures = self.path / "figures"
        for d in (self.path, self.solutions, self.figures):
            d.mkdir(parents=True, exist_ok=True)

    @classmethod
    def create(cls, root: Path, experiment: str, name: str | None = None) -> RunDirectory:
        return cls(Path(root) / experiment / (name or default_run_name()))

    @property
    def summary(self) -> Path:
        return self.path / "summary.csv"

    def write_config(self, text: str) -> None:
        (self.path / "config.yaml").write_text(text)

    def append_row(self, row: dict) -> None:
        """Append one row to summary.csv (header with the first row) in one O_APPEND write, then fsync,
        so a process killed at any moment leaves whole rows only."""
        buffer = io.StringIO()
        writer = csv.DictWriter(buffer, fieldnames=SUMMARY_COLUMNS, extrasaction="ignore", lineterminator="\n")
        if not self.summary.exists() or self.summary.stat().st_size == 0:
            writer.writeheader()
        writer.writerow({k: _fmt(row.get(k, "")) for k in SUMMARY_COLUMNS})
        fd = os.open(self.summary, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, buffer.getvalue().encode())
            os.fsync(fd)
        finally:
            os.close(fd)

    def mark_best(self, best_files: set[str]) -> pd.DataFrame:
        """Add the ``best`` column to summary.csv, rewritten atomically (temporary file + rename) so that a
        crash during the rewrite cannot cost a finished row."""
        summary = pd.read_csv(self.summary)
        summary["best"] = summary["solution_file"].isin(best_files)
        tmp = self.summary.with_suffix(".csv.tmp")
        summary.to_csv(tmp, index=False)
        os.replace(tmp, self.summary)
        return summary

    def finished(self) -> set[tuple[str, str, str, int]]:
        """(case, method, structure, seed) of every recorded row whose solution file exists."""
        if not self.summary.exists():
            return set()
        with self.summary.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
        return {(r["case"], r["method"], r["structure"], int(r["seed"])) for r in rows
                if r.get("solution_file") and (self.path / r["solution_file"]).exists()}

    def log(self, message: str) -> None:
        stamp = dt.datetime.now().isoformat(timespec="seconds")
        with (self.path / "run.log").open("a") as fh:
            fh.write(f"{stamp} {message}\n")


def _fmt(value):
    if isinstance(value, float):
        return repr(value)
    return value
