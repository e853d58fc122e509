"""The CLI end to end through Typer's CliRunner, and every solution file re-checked independently."""

from __future__ import annotations

import json
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import gantry_config
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from cli.main import app
from designopt.solution import json_text
from designopt.verify import verify_file

runner = CliRunner()


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory):
    root = tmp_path_factory.mktemp("run")
    config = root / "gantry.yaml"
    cfg = gantry_config(design=["a", "x", "z"], search={"preset": "quick", "starts": 3})
    config.write_text(yaml.safe_dump(cfg))
    # two workers: the search's solves and the figures side by side (`runs.draw`)
    result = runner.invoke(app, ["run", str(config), "--out", str(root / "results"), "--name", "t", "--jobs", "2"])
    return result, root / "results" / "gantry" / "t"


def test_run_writes_the_run_directory(finished_run):
    result, run = finished_run
    assert result.exit_code == 0, result.output
    assert "design cost" in result.output
    for name in ("config.yaml", "summary.csv", "run.log", "best.json"):
        assert (run / name).is_file(), name
    for stem in ("robot", "joints", "deformation"):
        assert (run / "figures" / f"{stem}.png").stat().st_size > 1000
        assert (run / "figures" / f"{stem}.pdf").is_file()
    view = (run / "view.html").read_text()
    assert "Plotly.newPlot" in view and "Plotly.addFrames" in view  # animated, plotly.js inside
    assert not re.search(r"<script[^>]+src=[\"']https?://", view)  # nothing to fetch: opens offline
    summary = pd.read_csv(run / "summary.csv")
    stages = summary["stage"].value_counts()
    # 3 starts, twice that for an arm of 3 joints (quick's `small_arm_starts`), the best (up to 4) refined
    assert stages["explore"] == 6 and 1 <= stages["refine"] <= 4
    required = ["experiment", "case", "stage", "method", "structure", "dof", "n_prismatic", "design_cost",
                "max_position_error", "max_axis_error", "max_joint_step", "tracks", "status", "iterations",
                "solve_time_s", "seed", "solution_file"]
    assert set(required) <= set(summary.columns)
    assert summary["best"].sum() == 1 and summary.loc[summary["best"], "stage"].item() == "refine"
    assert (summary["stiffness_revolute"] == 1.0).all()
    # the path each solve tracked: the config's 12 waypoints in the refine, the search's 10 in the exploration
    waypoints = summary.groupby("stage")["waypoints"].unique()
    assert list(waypoints["refine"]) == [12] and list(waypoints["explore"]) == [10]


def test_progress_is_plain_lines_when_not_on_a_terminal(tmp_path, monkeypatch):
    """In a log file or CI (the test runner's output is not a terminal) rich draws no bar: a line now and then
    says how far the work is (here after every solve). With each candidate refined from two barriers, the table
    of refined solves says which refine each row is."""
    import cli.main
    from designopt.solve.search import PRESETS

    monkeypatch.setattr(cli.main, "PLAIN_PROGRESS_EVERY_S", 0.0)
    monkeypatch.setitem(PRESETS, "quick", replace(PRESETS["quick"], refine_mu_init=(None, 1e-6)))
    config = tmp_path / "gantry.yaml"
    config.write_text(yaml.safe_dump(gantry_config(design=["a", "x", "z"], search={"preset": "quick", "starts": 3})))
    result = runner.invoke(app, ["run", str(config), "--out", str(tmp_path / "r"), "--jobs", "1", "--no-figures"])
    assert result.exit_code == 0, result.output
    lines = re.findall(r": (\d+) of (\d+) solves planned so far, (\d+) not tracking", result.output)
    assert len(lines) >= 4 and [int(done) for done, _, _ in lines] == list(range(1, len(lines) + 1))
    assert all(int(done) <= int(total) for done, total, _ in lines)
    header = next(line for line in result.output.splitlines() if "design cost" in line)
    assert re.search(r"seed\s*┃\s*stage\s*┃\s*status", header), header
    table = result.output.split(header, 1)[1].split("└", 1)[0]  # the refined solves' rows
    staged = re.findall(r"^│\s*\d+\s*│\s*(\S+)\s*│", table, flags=re.M)
    assert sorted(set(staged)) == ["refine", "refine2"] and staged.count("refine") == staged.count("refine2")


def test_view_command_writes_one_offline_file(finished_run, tmp_path):
    _, run = finished_run
    result = runner.invoke(app, ["view", str(run / "best.json"), "--out", str(tmp_path / "v.html"), "--frames", "5"])
    assert result.exit_code == 0, result.output
    html = (tmp_path / "v.html").read_text()
    assert html.count('"name":"') >= 5 and "sliders" in html
    bad = runner.invoke(app, ["view", str(tmp_path / "missing.json")])
    assert bad.exit_code == 2 and len(bad.output.strip().splitlines()) == 1


def test_piped_output_is_not_cut(finished_run):
    """CliRunner's stdout is not a terminal, as in CI logs and `make run | tee`: the table prints in full."""
    result, run = finished_run
    assert "…" not in result.output and "..." not in result.output, result.output
    assert "Solve_Succeeded" in result.output
    best = pd.read_csv(run / "summary.csv").query("best")
    # the design cost keeps six significant digits: enough to compare runs
    assert f"{best['design_cost'].iloc[0]:.6g}" in result.output


def test_every_solution_file_reverifies(finished_run):
    _, run = finished_run
    files = sorted((run / "solutions").glob("*.json")) + [run / "best.json"]
    summary = pd.read_csv(run / "summary.csv")
    assert len(files) == len(summary) + 1
    waypoints = dict(zip(summary["solution_file"], summary["waypoints"], strict=True))
    for f in files:
        text = f.read_text()
        data = json.loads(text)
        assert data["schema"] == "designopt.solution/1"
        assert [row["d"] for row in data["dh"]] == [None, None, None]  # P links: d moves
        assert len(data["q"]) == len(data["toolpath"]["t"])
        if f.name != "best.json":
            assert len(data["q"]) == waypoints[f"solutions/{f.name}"]
        # one line per waypoint: the first row of q on its own line, as the text of its numbers
        assert "\n  " + json.dumps(data["q"][0]) + ",\n" in text
        assert verify_file(f) == [], f


def test_verifier_catches_a_wrong_cost(finished_run, tmp_path):
    _, run = finished_run
    data = json.loads((run / "best.json").read_text())
    data["metrics"]["design_cost"] *= 1.001
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    assert any("design_cost" in p for p in verify_file(bad))
    data["metrics"]["design_cost"] /= 1.001
    data["q"][3][0] += 0.01  # the tool leaves the path by 1 cm at one waypoint
    bad.write_text(json.dumps(data))
    assert any("max_position_error" in p for p in verify_file(bad))


@pytest.mark.parametrize("text", ["solver: {max_iter: -3}\n", "robot: {colour: red}\n", "toolpath: [1, 2\n"])
def test_bad_config_exits_2_with_one_line(tmp_path, text):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    result = runner.invoke(app, ["run", str(path), "--out", str(tmp_path)])
    assert result.exit_code == 2
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and str(path) in lines[0] and "Traceback" not in result.output


def test_missing_config_exits_2(tmp_path):
    result = runner.invoke(app, ["run", str(tmp_path / "nope.yaml")])
    assert result.exit_code == 2
    assert "no such file" in result.output


def test_the_solution_set_is_an_output(finished_run):
    _, run = finished_run
    optima = pd.read_csv(run / "solution_set.csv", dtype={"seeds": str})  # "3 17", or "3": not a number
    summary = pd.read_csv(run / "summary.csv")
    explored = summary[summary["stage"] == "explore"]
    assert optima["reached_by"].sum() == explored["tracks"].sum()  # the exploration's optima, each solve once
    assert optima["design_cost"].is_monotonic_increasing and optima["ratio_to_best"].iloc[0] == 1.0
    # every refined optimum carries its full-path cost, the one of the refine solve of its seed
    refined = summary[summary["stage"] == "refine"].set_index("seed")["design_cost"]
    with_cost = optima.dropna(subset=["full_path_cost"])
    assert len(with_cost) == len(refined)
    for _, row in with_cost.iterrows():
        seeds = [int(x) for x in str(row["seeds"]).split()]
        assert row["full_path_cost"] == pytest.approx(min(refined[s] for s in seeds if s in refined.index), rel=1e-9)
    assert (run / "figures" / "search_progress.png").stat().st_size > 1000


def test_verify_prints_reported_and_recomputed_and_exits_by_verdict(tmp_path):
    """`python -m designopt.verify` on a good and a tampered file: a row each with reported / recomputed numbers,
    the tampered one named on stderr, exit 2; the good one alone exits 0; --help exits 0 and names the exit codes."""
    import subprocess
    import sys

    good = Path(__file__).parent.parent / "benchmarks" / "reference" / "milling_best_known.json"
    data = json.loads(good.read_text())
    data["metrics"]["design_cost"] *= 2
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    run = lambda *a: subprocess.run([sys.executable, "-m", "designopt.verify", *map(str, a)],  # noqa: E731
                                    capture_output=True, text=True)
    both = run(good, bad)
    assert both.returncode == 2, both.stderr
    rows = both.stdout.strip().splitlines()
    assert len(rows) == 3 and rows[1].startswith(str(good)) and rows[1].endswith("| ok")
    assert rows[2].startswith(str(bad)) and rows[2].endswith("DOES NOT CHECK OUT")
    reported, recomputed = (float(x) for x in rows[2].split(" | ")[1].split(" / "))
    assert reported == pytest.approx(2 * recomputed, rel=1e-5)
    errors = both.stderr.strip().splitlines()
    assert len(errors) == 1 and errors[0].startswith(f"{bad}: ") and "design_cost" in errors[0]
    assert run(good).returncode == 0
    helped = run("--help")
    assert helped.returncode == 0 and "exit codes" in helped.stdout


def test_every_best_design_known_checks_out():
    """The best designs known per task (benchmarks/reference, what the search is judged against) are re-verified
    from their files by the independent verifier, the modular one is a robot of the catalogue's modules, and every
    structure sweep reference (sweep_structures_<model>.csv) is the cost of a design kept there."""
    from designopt.config import load_config
    from designopt.experiments.modular import catalogue_from_config
    from designopt.verify import verify_file

    root = Path(__file__).parent.parent
    kept = sorted((root / "benchmarks" / "reference").glob("*_best_known.json"))
    assert {p.name for p in kept} >= {"milling_best_known.json", "modular_best_known.json",
                                      "circle_standoff_best_known.json", "milling_physical_best_known.json",
                                      "structures_physical_best_known.json", "structures_k_i_best_known.json"}
    for path in kept:
        assert verify_file(path) == [], path
    modules = set(catalogue_from_config(load_config(root / "configs" / "modular.yaml")).modules)
    modular = json.loads(kept[[p.name for p in kept].index("modular_best_known.json")].read_text())
    assert all((row["d"], row["a"], row["alpha"]) in modules for row in modular["dh"])
    # a sweep reference kept with its design (structures_<model>_<STRUCTURE>_best_known.json) is that design's cost
    reference = root / "benchmarks" / "reference"
    for model in ("k_i", "physical"):
        costs = pd.read_csv(reference / f"sweep_structures_{model}.csv").set_index("structure").reference_cost
        backed = sorted(reference.glob(f"structures_{model}_[PR]*_best_known.json"))  # verified above, as in `kept`
        assert backed, model
        # every reference has its design: its own file, or the sweep's lowest design's when it is that structure's
        designs = [reference / f"structures_{model}_best_known.json", *backed]
        structures = set()
        for path in designs:
            data = json.loads(path.read_text())
            structures.add(data["structure"])
            if path in backed or data["structure"] in costs.index:
                assert costs[data["structure"]] == pytest.approx(data["metrics"]["design_cost"], rel=1e-12, abs=0), path
        assert set(costs.index) <= structures, (model, sorted(set(costs.index) - structures))


def test_the_reference_readme_lists_every_best_design_known_with_its_cost():
    """benchmarks/reference/README.md says how each best design known was found: it names every file kept there (and
    no other), each in a row that states the file's design cost to the six digits it prints."""
    import re

    reference = Path(__file__).parent.parent / "benchmarks" / "reference"
    rows = [line for line in (reference / "README.md").read_text().splitlines() if line.startswith("| `")]
    named = {}
    for row in rows:
        files = re.findall(r"`([^`]+_best_known\.json)`", row.split("|")[1])
        costs = [float(c) for c in row.split("|")[3].split(",")]
        assert len(files) == len(costs), row
        named.update(zip(files, costs, strict=True))
    kept = {p.name for p in reference.glob("*_best_known.json")}
    assert set(named) == kept, sorted(set(named) ^ kept)
    for name, cost in named.items():
        actual = json.loads((reference / name).read_text())["metrics"]["design_cost"]
        assert float(f"{actual:.5e}") == cost, name


# each best design known's task: the config it was found on (a sweep structure's: the sweep's, with its structure)
REFERENCE_TASKS = {"milling_physical": "physical_stiffness.yaml", "milling": "milling.yaml",
                   "circle_standoff": "circle_standoff.yaml", "structures_k_i": "structures.yaml",
                   "structures_physical": "structures_physical.yaml"}


def test_every_best_design_known_is_a_feasible_point_of_its_task_as_built_now():
    """What the search is judged against must be a point the NLP of its task, as this code builds it, accepts: its
    design and its knots' joints and velocities within their bounds, and every constraint row (tracking,
    midpoint joints and velocities) within the tracking tolerance, the most a solution that tracks may miss its
    path by. A change to the formulation that a best design known no longer satisfies fails here, not silently in
    the search's figures. (The modular design is a robot of catalogue modules, another problem: not read here.)"""
    from designopt.config import load_config
    from designopt.experiments.adapters import structure_config
    from designopt.problem import problem_from_config
    from designopt.solution import read_solution_for
    from designopt.transcriptions import Collocation, InitialGuess

    root = Path(__file__).parent.parent
    checked = 0
    for path in sorted((root / "benchmarks" / "reference").glob("*_best_known.json")):
        task = next((t for t in sorted(REFERENCE_TASKS, key=len, reverse=True) if path.name.startswith(t)), None)
        if task is None:
            assert path.name == "modular_best_known.json"
            continue
        data = json.loads(path.read_text())
        cfg = load_config(root / "configs" / REFERENCE_TASKS[task])
        problem = problem_from_config(structure_config(cfg, data["structure"]) if task.startswith("structures")
                                      else cfg)
        solution = read_solution_for(problem, Collocation(), path)  # raises for a file of another problem
        built = Collocation().build(problem)
        velocities = np.abs(np.array(data["v"], float))  # (pack clips them to their limits: checked here)
        assert np.all(velocities <= problem.velocity_limits * (1 + 1e-6)), path.name
        x = built.pack(InitialGuess(q_d=solution.raw.q_d, Q=data["q"], V=data["v"]))
        assert built.nlp.violation(x) <= problem.position_tol, path.name
        checked += 1
    assert checked >= 20


def test_a_run_draws_every_standard_figure_of_its_best_solution():
    """The run plans its figures by name (so that it needs no matplotlib itself): the names it plans are the ones
    `designopt.plots` draws."""
    from designopt import plots
    from designopt.experiments import run

    assert run.SOLUTION_FIGURES == tuple(plots.SOLUTION_FIGURES)


_scalars = st.none() | st.booleans() | st.integers() | st.floats() | st.text(alphabet="[], {}\":ab\n")
_json = st.recursive(_scalars, lambda inner: st.lists(inner, max_size=4)
                     | st.dictionaries(st.text(alphabet="[], {}\":ab", max_size=4), inner, max_size=4), max_leaves=30)


@settings(max_examples=300, deadline=None)
@given(_json)
def test_solution_text_is_the_same_json_as_the_standard_encoders(data):
    # json_text lays out rows of numbers by editing the encoder's text: strings holding "], [" and NaN must survive
    assert json.dumps(json.loads(json_text(data))) == json.dumps(data)


def test_solution_text_puts_each_row_of_a_table_on_its_own_line():
    text = json_text({"q": [[1.0, -2.5], [3.0, None]], "dh": [{"d": None}], "m": {"k": "], ["}})
    assert text.splitlines() == ['{', ' "q": [', '  [1.0, -2.5],', '  [3.0, null]', ' ],', ' "dh": [',
                                 '  {"d": null}', ' ],', ' "m": {', '  "k": "], ["', ' }', '}']
