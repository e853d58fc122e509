"""Fuzz: random mutations of every shipped config and random CSV toolpaths through `designopt check`.

Whatever the input, `check` ends with exit 0 (valid) or exit 2 with one error line -- never a traceback. A
few dozen cases run in the default suite; `make test-slow` runs the same properties on >= 500 cases each.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pytest
import yaml
from conftest import SHIPPED_CONFIGS
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from cli.main import app

ROOT = Path(__file__).resolve().parent.parent
CONFIGS = SHIPPED_CONFIGS
runner = CliRunner()

# Values a user (or a typo) might put anywhere: wrong types, non-finite and extreme numbers, small integers
# (kept small so that a valid mutated config still builds quickly).
VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-3, 60), st.sampled_from([0, -1, 10**9, 2**63]),
    st.floats(allow_nan=True, allow_infinity=True), st.floats(-3.0, 3.0),
    st.text(alphabet="RPxyz01.-_ abc", max_size=6), st.sampled_from(["csv", "circle", "line", "figure_eight",
                                                                   "nowhere.csv", "user_path.csv", "generic",
                                                                   "robots/ur10.urdf", "tool0", "base_link",
                                                                   "elbow_joint.origin.z", "user_path.csv"]),
    st.lists(st.floats(-3, 3), max_size=4), st.lists(st.lists(st.floats(-3, 3), max_size=3), max_size=3),
    st.dictionaries(st.sampled_from(["kind", "d", "a", "revolute", "x", "bogus"]), st.floats(-2, 2), max_size=2),
)


def _paths(node, prefix=()):
    """Every path to a key or list item in a parsed YAML document."""
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        yield (*prefix, key)
        yield from _paths(value, (*prefix, key))


@st.composite
def mutated_config(draw):
    source = draw(st.sampled_from(CONFIGS))
    data = yaml.safe_load(source.read_text())
    for _ in range(draw(st.integers(1, 3))):
        paths = list(_paths(data))
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = data
        for key in path[:-1]:
            parent = parent[key]
        action = draw(st.sampled_from(["replace", "replace", "delete", "add"]))
        if action == "replace":
            parent[path[-1]] = draw(VALUES)
        elif action == "delete" and isinstance(parent, dict):
            del parent[path[-1]]
        elif isinstance(parent, dict):
            parent[draw(st.sampled_from(["bogus", "waypoints", "file", "box", "design"]))] = draw(VALUES)
    return source.name, data


CELLS = st.one_of(st.floats(-1, 1).map(repr), st.sampled_from(["", "nan", "inf", "-inf", "abc", "1e400", "0", " 0.1 ",
                                                               '"1"', "1,2"]))


@st.composite
def csv_text(draw):
    header = draw(st.sampled_from(["x,y,z", "x,y,z", "z,y,x", "X, Y, Z", "x,y,z,extra", "x,y", "", "a,b,c"]))
    good_row = st.lists(st.floats(-0.3, 0.3).map(repr), min_size=3, max_size=4)
    any_row = st.lists(CELLS, min_size=0, max_size=4)
    rows = draw(st.lists(st.one_of(good_row, good_row, good_row, any_row), max_size=10))
    return "\n".join([header, *(",".join(r) for r in rows)]) + draw(st.sampled_from(["", "\n", "\n\n"]))


def _check(config_text: str, csv: str | None = None) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        shutil.copy(ROOT / "configs" / "user_path.csv", tmp / "user_path.csv")
        shutil.copytree(ROOT / "configs" / "robots", tmp / "robots")  # the URDF robots configs refer to
        if csv is not None:
            (tmp / "fuzz.csv").write_text(csv)
        config = tmp / "fuzz.yaml"
        config.write_text(config_text)
        result = runner.invoke(app, ["check", str(config)])
    event(f"exit {result.exit_code}")  # shown by --hypothesis-show-statistics: how many inputs were valid
    assert result.exit_code in (0, 2), f"exit {result.exit_code}: {result.exception!r}\n{result.output}"
    assert "Traceback" not in result.output
    if result.exit_code == 2:
        errors = [line for line in result.output.splitlines() if line.startswith("error:")]
        assert len(errors) == 1, result.output
        assert errors[0].count(": ") >= 3, errors[0]  # error: <file>: <key or line>: <reason>


def _configs(case):
    _, data = case
    _check(yaml.safe_dump(data))


def _csvs(text, waypoints):
    toolpath = {"kind": "csv", "file": "fuzz.csv", **({"waypoints": waypoints} if waypoints is not None else {})}
    _check(yaml.safe_dump({"toolpath": toolpath, "placement": {"xyz": [0.45, 0.0, -0.2]}}), text)


FAST = settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SLOW = settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
WAYPOINTS = st.one_of(st.none(), st.integers(-2, 40))


@FAST
@given(case=mutated_config())
def test_fuzz_configs(case):
    _configs(case)


@FAST
@given(text=csv_text(), waypoints=WAYPOINTS)
def test_fuzz_csv_toolpaths(text, waypoints):
    _csvs(text, waypoints)


@pytest.mark.slow
@SLOW
@given(case=mutated_config())
def test_fuzz_configs_slow(case):
    _configs(case)


@pytest.mark.slow
@SLOW
@given(text=csv_text(), waypoints=WAYPOINTS)
def test_fuzz_csv_toolpaths_slow(text, waypoints):
    _csvs(text, waypoints)
