"""Kill and resume, one test per command family: `run`, `continuous`, `waypoints`, `modular` (the sweep's is in
test_sweep.py). A run SIGKILLed part-way keeps every finished solve; `--resume` with the same `--name` solves
only the missing ones; a row whose solution file is gone is solved again and counted once."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from cli.main import app
from designopt.verify import verify_file

ROOT = Path(__file__).resolve().parent.parent
KEY = ["case", "stage", "method", "structure", "seed"]
runner = CliRunner()

SMALL = {
    "toolpath": {"kind": "figure_eight", "width": 0.6, "height": 0.3, "waypoints": 12},
    "placement": {"xyz": [0.45, 0.0, -0.2]},
    "search": {"preset": "paper", "starts": 3},
}


pytestmark = pytest.mark.usefixtures("module_compile_cache")


def read_summary(path: Path) -> pd.DataFrame:
    return pd.read_csv(path, dtype={"case": str, "stage": str}, keep_default_na=False,
                       na_values={"case": [], "stage": []})


def kill_part_way(args: list[str], summary: Path, timeout: float = 240) -> pd.DataFrame:
    """Start `designopt ARGS` in a subprocess, SIGKILL it once its first solve is written, return the rows."""
    proc = subprocess.Popen([sys.executable, "-m", "cli.main", *args, "--jobs", "1"], cwd=ROOT, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + timeout
    while time.time() < deadline and proc.poll() is None:
        if summary.exists() and len(summary.read_text().splitlines()) >= 2:  # header + one row
            break
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    return read_summary(summary)


def check_resumed(run: Path, before: pd.DataFrame, expected: set, result) -> pd.DataFrame:
    assert result.exit_code == 0, result.output
    after = read_summary(run / "summary.csv")
    keys = list(after[KEY].itertuples(index=False, name=None))
    assert len(keys) == len(set(keys)), "a solve is counted twice"
    assert set(keys) == expected, "a solve is missing"
    # The first finished solve lost its file before the resume: it was solved again (one row, file back).
    lost = tuple(before[KEY].iloc[0])
    assert (run / before["solution_file"].iloc[0]).is_file()
    # Every other finished solve was kept as it was, not solved again.
    merged = before.iloc[1:].merge(after, on=KEY, suffixes=("_before", "_after"))
    assert len(merged) == len(before) - 1
    assert (merged["design_cost_before"] == merged["design_cost_after"]).all()
    assert (merged["solve_time_s_before"] == merged["solve_time_s_after"]).all()
    assert lost in set(keys)
    for f in after["solution_file"]:
        assert verify_file(run / f) == [], f
    return after


def _setup(tmp_path, extra=None):
    cfg = {**SMALL, **(extra or {})}
    config = tmp_path / "c.yaml"
    config.write_text(yaml.safe_dump(cfg))
    return config


def _lose_first_file(run: Path, before: pd.DataFrame) -> None:
    assert 1 <= len(before), "nothing was written before the kill"
    (run / before["solution_file"].iloc[0]).unlink()


def test_run_resumes(tmp_path):
    config = _setup(tmp_path, {"name": "job", "search": {"preset": "quick", "starts": 5}})
    out, run = tmp_path / "r", tmp_path / "r" / "job" / "k"
    before = kill_part_way(["run", str(config), "--out", str(out), "--name", "k", "--no-figures"], run / "summary.csv")
    assert len(before) < 5, "the run was not killed part-way"
    _lose_first_file(run, before)
    again = runner.invoke(app, ["run", str(config), "--out", str(out), "--name", "k"])
    assert again.exit_code == 2 and "--resume" in again.output  # never overwrites a run silently
    result = runner.invoke(app, ["run", str(config), "--out", str(out), "--name", "k", "--resume", "--no-figures"])
    keys = set(read_summary(run / "summary.csv")[KEY].itertuples(index=False, name=None))
    refined = {k for k in keys if k[1] == "refine"}
    assert 1 <= len(refined) <= 4  # the best four distinct coarse optima, refined on the full path
    reflected = {k for k in keys if k[1].startswith("reflect")}  # optima reflected across their length bounds, if any
    after = check_resumed(run, before, {("", "explore", "to", "RRRRRR", s) for s in range(5)} | refined | reflected,
                          result)
    assert after["best"].sum() == 1 and (run / "best.json").is_file()


def test_continuous_resumes(tmp_path):
    config = _setup(tmp_path)
    out, run = tmp_path / "r", tmp_path / "r" / "continuous" / "k"
    subset = ["--cases", "placement_only,combined", "--methods", "to,fk"]
    before = kill_part_way(["continuous", str(config), "--out", str(out), "--name", "k", *subset], run / "summary.csv")
    assert len(before) < 12, "the run was not killed part-way"
    _lose_first_file(run, before)
    result = runner.invoke(app, ["continuous", str(config), "--out", str(out), "--name", "k", "--resume", *subset])
    expected = {(c, "start", m, "RRRRRR", s) for c in ("placement_only", "combined") for m in ("to", "fk")
                for s in range(3)}
    check_resumed(run, before, expected, result)
    assert len(pd.read_csv(run / "table.csv")) == 4


def test_waypoints_resumes(tmp_path):
    config = _setup(tmp_path)
    out, run = tmp_path / "r", tmp_path / "r" / "waypoints" / "k"
    counts = ["--waypoints", "8,10,12"]
    before = kill_part_way(["waypoints", str(config), "--out", str(out), "--name", "k", *counts], run / "summary.csv")
    assert len(before) < 9, "the run was not killed part-way"
    _lose_first_file(run, before)
    result = runner.invoke(app, ["waypoints", str(config), "--out", str(out), "--name", "k", "--resume", *counts])
    check_resumed(run, before, {(f"N{n}", "start", "to", "RRRRRR", s) for n in (8, 10, 12) for s in range(3)},
                  result)
    table = pd.read_csv(run / "table.csv")
    assert list(table["waypoints"]) == [8, 10, 12] and table["max_midpoint_error"].notna().all()


def test_modular_resumes(tmp_path):
    config = _setup(tmp_path, {"search": {"preset": "paper", "starts": 2}})
    out, run = tmp_path / "r", tmp_path / "r" / "modular" / "k"
    args = ["modular", str(config), "--out", str(out), "--name", "k", "--budget", "12", "--refine", "2",
            "--refine-starts", "40"]
    before = kill_part_way(args, run / "summary.csv")
    assert len(before) < 9, "the run was not killed part-way"
    _lose_first_file(run, before)
    result = runner.invoke(app, [*args, "--resume"])
    after = read_summary(run / "summary.csv")
    solves = {(c, "start", m, "RRRRRR", s) for c, m in (("continuous", "to"), ("fk", "fk"),
                                                         ("continuous_modular", "to"), ("modular", "to"))
              for s in range(2)}
    rounded = {k for k in after[KEY].itertuples(index=False, name=None) if k[0] == "rounded"}
    assert len(rounded) == 1
    keys = set(after[KEY].itertuples(index=False, name=None))
    screened = {k for k in keys if k[0].startswith("sc-")}
    assert len({k for k in screened if k[1] == "start"}) == 3 * 12  # the budget's 12 assignments, 3 starts each
    warm = {k for k in screened if k[1] != "start"}  # a neighbour's one start from its incumbent
    assert {k[1] for k in warm} == {"warm"} and len({k[0] for k in warm}) == len(warm) <= 11
    searched = {k for k in keys if k[0].startswith("nb-")}
    refined = {k for k in searched if k[1] == "refine"}  # the best screened, searched on the full path
    assert 1 <= len({k[0] for k in refined}) <= 2  # --refine 2
    assert {k[1] for k in searched} == {"explore", "refine"}  # the default search (no screen on 12 waypoints)
    check_resumed(run, before, solves | rounded | screened | searched, result)
    assert len(pd.read_csv(run / "table.csv")) == 6


def test_a_row_without_its_solution_file_is_dropped_on_resume(tmp_path):
    """RunDirectory.resume keeps a row only with its file: the row of a lost file leaves summary.csv (so the solve
    is done again and counted once), and a second row for the same solve is dropped too."""
    from designopt.results_io import RunDirectory

    run = RunDirectory(tmp_path / "run")
    rows = [{"experiment": "e", "case": "c", "stage": "start", "method": "to", "structure": "RR", "seed": s,
             "design_cost": float(s), "solution_file": f"solutions/s{s}.json"} for s in range(3)]
    for row in [*rows, {**rows[2], "design_cost": 9.0}]:
        run.append_row(row)
    for s in (0, 2):
        (run.path / f"solutions/s{s}.json").write_text("{}")
    kept = run.resume()
    assert set(kept) == {("c", "start", "to", "RR", 0), ("c", "start", "to", "RR", 2)}
    assert float(kept["c", "start", "to", "RR", 2]["design_cost"]) == 2.0  # the first row of a solve counts
    after = read_summary(run.summary)
    assert sorted(after["seed"]) == [0, 2]


def test_a_search_of_several_draws_is_one_run_written_and_resumed(tmp_path, monkeypatch):
    """A search of 2 draws (`Search.draws`; here the `paper` preset's 2 starts made twice): one run directory whose
    summary holds both draws' solves (start numbers of seeds 0 and `DRAW_STRIDE`), the answer the cheaper of the
    draws' bests, each draw's best in the log and on the terminal, the search's every setting in search.json;
    resumed, nothing is solved again; resumed with another search (the preset changed), refused."""
    from dataclasses import replace

    from designopt.config import load_config
    from designopt.experiments.adapters import search_from_config
    from designopt.experiments.runs import search_of_run
    from designopt.solve.search import DRAW_STRIDE, PRESETS, search_from_dict

    monkeypatch.setitem(PRESETS, "paper", replace(PRESETS["paper"], draws=2))
    config = _setup(tmp_path, {"name": "job", "search": {"preset": "paper", "starts": 2}})
    run = tmp_path / "r" / "job" / "d"
    args = ["run", str(config), "--out", str(tmp_path / "r"), "--name", "d", "--no-figures", "--jobs", "1"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    rows = read_summary(run / "summary.csv")
    assert sorted(rows["seed"]) == [0, 1, DRAW_STRIDE * 1000, DRAW_STRIDE * 1000 + 1]
    tracking = rows[rows["tracks"].astype(str) == "True"]
    bests = [tracking[(tracking["seed"] >= DRAW_STRIDE * 1000) == (k == 1)]["design_cost"].min() for k in (0, 1)]
    assert rows.loc[rows["best"].astype(bool), "design_cost"].item() == min(bests)
    assert f"each draw's best (seeds 0, {DRAW_STRIDE}): {bests[0]:.6g}, {bests[1]:.6g}" in (run / "run.log").read_text()
    assert "2 draws, each one's best / the answer:" in result.output
    again = runner.invoke(app, [*args[:-2], "--resume", "--jobs", "1"])
    assert again.exit_code == 0, again.output
    assert "resume: 4 solves already done, 0 to do" in (run / "run.log").read_text()
    assert read_summary(run / "summary.csv")[KEY].equals(rows[KEY])
    written = search_from_dict(json.loads((run / "search.json").read_text()))  # the run's search, every setting
    assert written == search_from_config(load_config(config)) and written.draws == 2 and written.starts == 2
    assert search_of_run(run) == written
    monkeypatch.setitem(PRESETS, "paper", replace(PRESETS["paper"], draws=3))  # the preset changed since
    changed = runner.invoke(app, [*args[:-2], "--resume", "--jobs", "1"])
    assert changed.exit_code == 2 and "search.json: --resume: the run was started with another search" in changed.output
    assert read_summary(run / "summary.csv")[KEY].equals(rows[KEY]) and search_of_run(run) == written
    (run / "search.json").unlink()  # a run of before search.json: its config's search, with today's presets
    assert search_of_run(run).draws == 3
