"""Every shipped config loads; every kind of bad input is one line naming the file, key and reason."""

from __future__ import annotations

import pytest
from conftest import SHIPPED_CONFIGS

from designopt.config import ConfigError, dump_config, load_config, parse_config
from designopt.problem import problem_from_config

CONFIGS = SHIPPED_CONFIGS


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.name)
def test_every_config_loads_and_builds(path):
    cfg = load_config(path)
    problem = problem_from_config(cfg)
    assert problem.toolpath.n >= 3
    assert load_config(path) == parse_config(__import__("yaml").safe_load(dump_config(cfg)), path, path.parent)


BAD = [
    ("search: {starts: 0}\n", "search.starts", "greater than or equal to 1"),
    ("search: {starts_: 10}\n", "search.starts_", "unknown key"),
    ("solver: {max_iter: 10}\n", "solver", "replaced by search"),
    ("robot: {stiffness: {revolute: -1}}\n", "robot.stiffness.revolute", "greater than 0"),
    ("robot: {structure: RRX}\n", "robot.structure", "pattern"),
    ("robot: {structure: RRR, dh: puma560}\n", "robot.dh", "6 links"),
    ("robot: {dh: kuka}\n", "robot.dh", "unknown preset"),
    ("toolpath: {kind: spiral}\n", "toolpath", "unknown kind"),
    ("toolpath: {kind: circle, radius: big}\n", "toolpath.radius", "valid number"),
    ("toolpath: {kind: csv, file: nowhere.csv}\n", "toolpath.file", "no such file"),
    ("placement: {xyz: [5, 0, 0]}\n", "placement.xyz", "outside the box"),
    ("design: [x, w]\n", "design", "'w' names no joint"),
    ("placement: {optimize: [x, w]}\n", "placement.optimize", "moved to design"),
    ("costs: {deflection: sideways}\n", "costs.deflection", "'full'"),
    ("- just\n- a list\n", "(top level)", "mapping"),
    ("name: [unclosed\n", "line 2", "malformed YAML"),
]


@pytest.mark.parametrize("text,key,reason", BAD)
def test_bad_config_is_one_line_naming_key(tmp_path, text, key, reason):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        load_config(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: {key}: "), message
    assert reason in message


def test_missing_file(tmp_path):
    with pytest.raises(ConfigError, match="no such file"):
        load_config(tmp_path / "absent.yaml")
