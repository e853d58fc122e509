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

from designopt.errors import InputError

SUMMARY_COLUMNS = [
    "experiment", "case", "stage", "method", "structure", "dof", "n_prismatic", "n_design_joints", "waypoints",
    "design_cost", "max_position_error", "max_axis_error", "max_joint_step", "tracks", "best",
    "status", "success", "iterations", "solve_time_s", "build_time_s", "n_variables", "n_constraints",
    "objective", "regularization", "min_standoff", "kinematic_drift", "held", "seed",
    "stiffness_revolute", "stiffness_prismatic", "deflection", "min_clearance", "clearance_link",
    "clearance_obstacle", "solution_file",
]
# ...plus one cost_<name> column per named term of the objective (before solution_file), as rows bring them.


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
    def create(cls, root: Path, experiment: str, name: str | None = None, resume: bool = False) -> RunDirectory:
        """results/<experiment>/<name>. A named run that already holds results is finished with ``resume``
        and refused without it (nothing is overwritten); an unnamed run gets a fresh timestamped name."""
        base = Path(root) / experiment
        if name is None:
            if resume:
                raise InputError(base, "--name", "--resume needs the name of the run to finish")
            name, k = default_run_name(), 2
            while (base / name).exists():
                name, k = f"{default_run_name()}-{k}", k + 1
        run = cls(base / name)
        if not resume and run.summary.exists():
            raise InputError(run.path, "--name", "already holds a run: pass --resume to finish it, or another --name")
        return run

    @property
    def summary(self) -> Path:
        return self.path / "summary.csv"

    def write_config(self, text: str) -> None:
        (self.path / "config.yaml").write_text(text)

    def write_search(self, text: str) -> None:
        """The search the run makes, every setting resolved (`designopt.solve.search.search_to_dict`, as JSON)."""
        (self.path / "search.json").write_text(text)

    def append_row(self, row: dict) -> None:
        """Append one row to summary.csv (header with the first row) in one O_APPEND write, then fsync,
        so a process killed at any moment leaves whole rows only. A row with a column the file does not have
        yet (a new cost_<name>) first widens the file's header, atomically; no value is ever dropped."""
        unknown = sorted(set(row) - set(SUMMARY_COLUMNS) - {k for k in row if k.startswith("cost_")})
        if unknown:
            raise ValueError(f"summary.csv has no column for {unknown}")
        fieldnames = self._header()  # one line: appending stays cheap however long the file is
        new = not fieldnames
        if new:
            fieldnames = _columns(row)
        elif set(row) - set(fieldnames):
            fieldnames = _columns({**dict.fromkeys(fieldnames), **row})
            self._rewrite(fieldnames, self._read_rows()[1])
        buffer = io.StringIO()
        writer = csv.DictWriter(buffer, fieldnames=fieldnames, lineterminator="\n")
        if new:
            writer.writeheader()
        writer.writerow({k: _fmt(row.get(k, "")) for k in fieldnames})
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

    def _header(self) -> list[str]:
        if not self.summary.exists() or self.summary.stat().st_size == 0:
            return []
        with self.summary.open(newline="") as fh:
            return next(csv.reader(fh), [])

    def _read_rows(self) -> tuple[list[str], list[dict]]:
        if not self.summary.exists() or self.summary.stat().st_size == 0:
            return [], []
        with self.summary.open(newline="") as fh:
            reader = csv.DictReader(fh)
            return list(reader.fieldnames or []), list(reader)

    def _rewrite(self, fieldnames: list[str], rows: list[dict]) -> None:
        """Replace summary.csv atomically with these rows, cell for cell as read."""
        tmp = self.summary.with_suffix(".csv.tmp")
        with tmp.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=fieldnames, lineterminator="\n")
            writer.writeheader()
            writer.writerows(rows)
        os.replace(tmp, self.summary)

    def resume(self) -> dict[tuple[str, str, str, str, int], dict]:
        """The finished solves, by (case, stage, method, structure, seed), ready to be resumed.

        A row whose solution file is gone (or a second row for the same solve) is dropped from summary.csv,
        so the solve it stood for is done again and counted once."""
        fieldnames, rows = self._read_rows()
        kept: dict = {}
        for r in rows:
            key = _key(r)
            if key not in kept and r.get("solution_file") and (self.path / r["solution_file"]).is_file():
                kept[key] = r
        if len(kept) < len(rows):
            self._rewrite(fieldnames, list(kept.values()))
            self.log(f"resume: dropped {len(rows) - len(kept)} row(s) without a solution file")
        return kept

    def drop_rows(self, keys: set) -> None:
        """Remove the rows of these (case, stage, method, structure, seed) keys from summary.csv."""
        fieldnames, rows = self._read_rows()
        keep = [r for r in rows if _key(r) not in keys]
        self._rewrite(fieldnames, keep)

    def log(self, message: str) -> None:
        stamp = dt.datetime.now().isoformat(timespec="seconds")
        with (self.path / "run.log").open("a") as fh:
            fh.write(f"{stamp} {message}\n")


def _key(row: dict) -> tuple[str, str, str, str, int]:
    """(case, stage, method, structure, seed) of a summary row: what identifies a solve."""
    return row["case"], row.get("stage") or "", row["method"], row["structure"], int(row["seed"])


def _columns(row: dict) -> list[str]:
    """SUMMARY_COLUMNS with the row's cost_<name> columns before solution_file."""
    base = [c for c in SUMMARY_COLUMNS if c != "solution_file"]
    return [*base, *sorted(k for k in row if k.startswith("cost_")), "solution_file"]


def _fmt(value):
    if isinstance(value, float):
        return repr(value)
    return value
