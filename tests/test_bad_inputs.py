"""Bad input never ends in a traceback: one line `<file>: <key or line>: <reason>` and exit code 2, from `check`,
`run` and every experiment; solution files that are malformed or tampered with likewise for verify, export and
render."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest
import yaml
from conftest import gantry_config
from typer.testing import CliRunner

from cli.main import app

runner = CliRunner()

GOOD_CSV = "x,y,z\n0,0,0\n0.1,0.02,0\n0.2,0,0\n0.25,-0.05,0\n"

# (name, config overrides, CSV text or None, expected key, expected words in the reason)
BAD_INPUTS = [
    ("empty csv", {}, "", "(file)", "empty"),
    ("header only", {}, "x,y,z\n", "(file)", "no points"),
    ("one point", {}, "x,y,z\n0,0,0\n", "(file)", "at least 2 distinct points"),
    ("two points, no resampling", {}, "x,y,z\n0,0,0\n1,0,0\n", "(file)", "at least 3"),
    ("non-numeric cell", {}, "x,y,z\n0,0,0\n0.1,abc,0\n0.2,0,0\n", "line 3", "'abc' is not a number"),
    ("NaN in csv", {}, "x,y,z\n0,0,0\n0.1,nan,0\n0.2,0,0\n", "line 3", "not a finite number"),
    ("inf in csv", {}, "x,y,z\n0,0,0\n0.1,0,inf\n0.2,0,0\n", "line 3", "not a finite number"),
    ("missing column", {}, "x,y\n0,0\n1,1\n", "line 1", "missing: z"),
    ("short row", {}, "x,y,z\n0,0,0\n1,1\n2,2,2\n", "line 3", "2 cells"),
    ("all points equal", {}, "x,y,z\n1,1,1\n1,1,1\n1,1,1\n", "(file)", "at least 2 distinct points"),
    ("binary file", {}, b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe", "(file)", "not a text file"),
    ("NaN ypr", {"placement": {"ypr": [".nan", 0, 0]}}, None, "placement.ypr[0]", "finite"),
    ("inf DH row", {"robot": {"dh": [{"d": ".inf"}, {}, {}]}}, None, "robot.dh[0].d", "finite"),
    ("NaN force", {"toolpath": {"force": ".nan"}}, None, "toolpath.force", "finite"),
    ("inf joint velocity", {"robot": {"joint_velocity": ".inf"}}, None, "robot.joint_velocity", "finite"),
    ("NaN weight", {"costs": {"regularization": ".nan"}}, None, "costs.regularization", "finite"),
    ("inf tolerance", {"tolerance": {"position": ".inf"}}, None, "tolerance.position", "finite"),
    ("zero tolerance", {"tolerance": {"axis": 0}}, None, "tolerance.axis", "greater than 0"),
    ("bounds reversed", {"robot": {"bounds": {"length": [2, 0.5]}}}, None, "robot.bounds.length", "lower <= upper"),
    ("box reversed", {"placement": {"box": [[1, -1], [-2, 2], [-1, 2]]}}, None, "placement.box.x", "above"),
    ("design start out of bounds", {"robot": {"bounds": {"length": [0.1, 2]}}}, None, "robot.dh[0].a",
     "outside its bounds"),
    ("free angle out of range", {"design": ["a", "placement"], "placement": {"ypr": [4.0, 0, 0]}}, None,
     "placement.ypr", "outside its bounds [-3.14159, 3.14159]"),
    ("unreachable stand-off", {"design": ["x"], "placement": {"keep_out_radius": 10.0}}, None,
     "placement.keep_out_radius", "cannot be met"),
    ("fixed placement inside stand-off", {"design": ["d"], "placement": {"keep_out_radius": 5.0}}, None,
     "placement.keep_out_radius", "inside the stand-off"),
    ("unknown design joint", {"design": ["d", "link9.a"]}, None, "design", "'link9.a' names no joint"),
    ("a moving joint as a design joint", {"design": ["link1.d"]}, None, "design", "moving joint"),
    ("search starts of zero", {"search": {"starts": 0}}, None, "search.starts", "greater than or equal to 1"),
    ("unknown search preset", {"search": {"preset": "fast"}}, None, "search.preset", "'quick'"),
    # a key of the old shape names what replaced it
    ("old solver block", {"solver": {"multistart": 4}}, None, "solver", "search: {preset"),
    ("old placement.optimize", {"placement": {"optimize": True}}, None, "placement.optimize", "moved to design"),
    ("too few waypoints", {"toolpath": {"kind": "line", "waypoints": 2}}, None, "toolpath.waypoints", "3"),
    ("zero-size path", {"toolpath": {"length": 1e-300}}, None, "toolpath", "zero speed"),
    ("empty module catalogue", {"modules": []}, None, "modules", "at least 1"),
]


def write_case(tmp_path, overrides, csv_text):
    cfg = gantry_config()
    if csv_text is not None:
        csv = tmp_path / "path.csv"
        csv.write_bytes(csv_text if isinstance(csv_text, bytes) else csv_text.encode())
        cfg["toolpath"] = {"kind": "csv", "file": "path.csv"}
    for key, value in overrides.items():
        cfg[key] = {**cfg.get(key, {}), **value} if isinstance(value, dict) else value
    path = tmp_path / "bad.yaml"
    # YAML's .nan/.inf must stay unquoted to be numbers
    path.write_text(yaml.safe_dump(cfg).replace("'.nan'", ".nan").replace("'.inf'", ".inf"))
    return path, (tmp_path / "path.csv" if csv_text is not None else path)


def one_line(result) -> str:
    assert "Traceback" not in result.output, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1, result.output
    return lines[0]


@pytest.mark.parametrize("command", ["check", "run"])
@pytest.mark.parametrize("name,overrides,csv_text,key,reason", BAD_INPUTS, ids=[b[0] for b in BAD_INPUTS])
def test_bad_input_is_one_line_and_exit_2(tmp_path, command, name, overrides, csv_text, key, reason):
    config, culprit = write_case(tmp_path, overrides, csv_text)
    result = runner.invoke(app, [command, str(config), "--out", str(tmp_path / "r")] if command == "run"
                           else [command, str(config)])
    assert result.exit_code == 2, result.output
    line = one_line(result)
    assert f"{culprit}: {key}: " in line, line
    assert reason in line, line


@pytest.mark.parametrize("command", ["continuous", "waypoints", "modular", "modular-study"])
def test_every_experiment_rejects_bad_input_with_one_line(tmp_path, command):
    # the config is read (and its CSV with it) before anything else about the experiment is checked
    config, culprit = write_case(tmp_path, {}, "x,y,z\n0,0,0\n0.1,abc,0\n0.2,0,0\n")
    result = runner.invoke(app, [command, str(config), "--out", str(tmp_path / "r")])
    assert result.exit_code == 2, result.output
    assert f"{culprit}: line 3: " in one_line(result)


def test_sweep_rejects_bad_input_with_one_line(tmp_path):
    config, culprit = write_case(tmp_path, {"tolerance": {"position": ".inf"}}, None)
    result = runner.invoke(app, ["sweep-structures", "--config", str(config), "--out", str(tmp_path / "r")])
    assert result.exit_code == 2, result.output
    assert f"{culprit}: tolerance.position: " in one_line(result)


def test_repeated_csv_points_are_dropped_with_a_warning(tmp_path):
    config, culprit = write_case(tmp_path, {}, "x,y,z\n0,0,0\n0.1,0,0\n0.1,0,0\n0.2,0,0\n0.3,0,0\n")
    result = runner.invoke(app, ["check", str(config)])
    assert result.exit_code == 0, result.output
    assert f"warning: {culprit}: line 4: repeated point dropped" in result.output
    assert "4 waypoints" in result.output


def test_a_path_that_doubles_back_is_a_valid_task(tmp_path):
    """A zig-zag pass: out along +x and back. The force follows the direction of travel on each leg."""
    from designopt.toolpaths import from_points

    tp = from_points([[0, 0, 0], [0.2, 0, 0], [0, 0, 0.0]], n=9, force=2.0)
    assert tp.force_W[0] == pytest.approx([2.0, 0, 0]) and tp.force_W[-1] == pytest.approx([-2.0, 0, 0])
    assert tp.force_W[4] == pytest.approx([-2.0, 0, 0])  # the turning point leaves along the way back
    config, _ = write_case(tmp_path, {}, "x,y,z\n0,0,0\n0.2,0,0\n0,0,0\n")
    result = runner.invoke(app, ["check", str(config)])
    assert result.exit_code == 0, result.output


# ---------------------------------------------------------------------------------------------------------
# Solution files: malformed or tampered


@pytest.fixture(scope="module")
def solution_file(tmp_path_factory):
    root = tmp_path_factory.mktemp("sol")
    config = root / "g.yaml"
    cfg = gantry_config(design=["a", "x", "z"])
    config.write_text(yaml.safe_dump(cfg))
    result = runner.invoke(app, ["run", str(config), "--out", str(root / "r"), "--name", "t", "--no-figures",
                                 "--jobs", "1"])
    assert result.exit_code == 0, result.output
    return root / "r" / "gantry" / "t" / "best.json"


def _tamper(data, path, value):
    target = data
    for part in path[:-1]:
        target = target[part]
    target[path[-1]] = value(target[path[-1]]) if callable(value) else value


TAMPERED = [
    ("placement moved", ("placement", "xyz", 0), lambda v: v + 0.01, "max_position_error"),
    ("placement turned", ("placement", "ypr", 1), lambda v: v + 0.01, "max_"),
    ("DH table edited", ("dh", 2, "a"), lambda v: v + 0.01, "max_position_error"),
    ("force scaled", ("toolpath", "force_W", 3, 0), lambda v: 2 * v + 1, "force"),
    ("force_alpha edited", ("force_alpha",), lambda v: 2 * v, "force_alpha"),
    ("tracks flipped", ("metrics", "tracks"), lambda v: not v, "metrics.tracks"),
    # each reported number is compared with its recomputation (not with itself)
    ("position error edited", ("metrics", "max_position_error"), lambda v: v + 1e-4, "metrics.max_position_error"),
    ("axis error edited", ("metrics", "max_axis_error"), lambda v: v + 1e-4, "metrics.max_axis_error"),
    ("cost edited", ("metrics", "design_cost"), lambda v: v * 1.001, "metrics.design_cost"),
    ("tolerance made infinite", ("metrics", "tolerances", "position"), 1e309, "metrics.tolerances.position"),
]

MALFORMED = [
    ("not JSON", "{not json", "line 1"),
    ("a list", "[1, 2]", "(top level)"),
    ("wrong schema", json.dumps({"schema": "other/9"}), "schema"),
]


@pytest.mark.parametrize("name,path,value,key", TAMPERED, ids=[t[0] for t in TAMPERED])
@pytest.mark.parametrize("command", ["verify", "export", "render"])
def test_tampered_solution_is_refused(tmp_path, solution_file, command, name, path, value, key):
    data = json.loads(solution_file.read_text())
    _tamper(data, path, value)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    if command == "verify":
        proc = subprocess.run([sys.executable, "-m", "designopt.verify", str(bad)], capture_output=True, text=True)
        assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"{bad}: ") and key in lines[0], proc.stderr
        return
    result = runner.invoke(app, [command, str(bad), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    line = one_line(result)
    assert str(bad) in line and key in line, line
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())


@pytest.mark.parametrize("name,text,key", MALFORMED, ids=[m[0] for m in MALFORMED])
@pytest.mark.parametrize("command", ["verify", "export", "render"])
def test_malformed_solution_is_one_line(tmp_path, command, name, text, key):
    bad = tmp_path / "bad.json"
    bad.write_text(text)
    if command == "verify":
        proc = subprocess.run([sys.executable, "-m", "designopt.verify", str(bad)], capture_output=True, text=True)
        assert proc.returncode == 2 and proc.stderr.strip() .startswith(f"{bad}: {key}"), proc.stderr
        return
    result = runner.invoke(app, [command, str(bad)])
    assert result.exit_code == 2 and f"{bad}: {key}" in one_line(result)


def test_every_missing_field_is_named(solution_file):
    """Delete each top-level field in turn: the schema check names it (never a KeyError)."""
    from designopt.verify import SolutionFileError, check_schema

    data = json.loads(solution_file.read_text())
    for key in ("structure", "dh", "tool", "placement", "stiffness", "force_alpha", "toolpath", "q", "metrics"):
        broken = {k: v for k, v in data.items() if k != key}
        with pytest.raises(SolutionFileError) as info:
            check_schema(broken, "f.json")
        assert "\n" not in str(info.value) and str(info.value).startswith("f.json: ")
    assert not math.isnan(data["metrics"]["design_cost"])
