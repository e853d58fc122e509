"""Every config key does something: changing it changes the problem, the search or the catalogue a run would use
(a key that is read but ignored fails here), and the schema stays small (issue 22: at most half of the 95 keys
the configuration had before; 99 by the count below).

A key is a leaf of the schema: a section's field whose value is not itself a section (a list of rows counts its
row fields; a field that takes a value or a section counts as its section's keys). `config_keys` walks the
pydantic models; the table below must name every key it finds.
"""

from __future__ import annotations

import copy
import shutil
import typing
from pathlib import Path

import numpy as np
import pytest
from pydantic import BaseModel

from designopt.config import Config, parse_config
from designopt.experiments.adapters import search_from_config
from designopt.experiments.modular import catalogue_from_config
from designopt.problem import problem_from_config

ROOT = Path(__file__).resolve().parent.parent
MAX_KEYS = 47  # half of the 95 keys of the configuration before issue 22, rounded down


def _models(annotation) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for a in typing.get_args(annotation) for m in _models(a)]


def config_keys(model: type[BaseModel] = Config, prefix: str = "") -> list[str]:
    """Every leaf key of the schema, dotted (a union of sections contributes the union of their keys)."""
    keys: list[str] = []
    for name, field in model.model_fields.items():
        subs = _models(field.annotation)
        if not subs:
            keys.append(prefix + name)
            continue
        found: list[str] = []
        for sub in subs:
            found += [k for k in config_keys(sub, f"{prefix}{name}.") if k not in found]
        keys += found
    return keys


def test_the_schema_has_at_most_half_the_keys_it_had():
    keys = config_keys()
    assert len(keys) == len(set(keys))
    assert len(keys) <= MAX_KEYS, f"{len(keys)} keys: {keys}"


# ---------------------------------------------------------------------------------------------------------
# Bases: small valid configs of each kind of robot and path; a change is applied to a copy.

FIGURE8 = {"toolpath": {"kind": "figure_eight", "waypoints": 20}}
CIRCLE = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 12}}
LINE = {"toolpath": {"kind": "line", "length": 0.04, "waypoints": 8}}
CSV = {"toolpath": {"kind": "csv", "file": "path.csv"}}
GCODE = {"toolpath": {"kind": "gcode", "file": "p.nc", "spacing": 0.004}}
MILLING = {"toolpath": {"kind": "line", "length": 0.04, "waypoints": 8,
                        "force": {"material": "aluminium", "teeth": 3, "feed_per_tooth": 5e-5, "axial_depth": 1e-3}}}
ROWS = {"robot": {"structure": "RRP", "dh": [{"theta": 0.1, "d": 0.2, "a": 0.3, "alpha": 0.4},
                                             {"a": 0.3}, {"alpha": 0.2}]}}
PRISMATIC = {"robot": {"structure": "RRP", "dh": "generic"}}
URDF = {"robot": {"urdf": "ur10.urdf", "tool_link": "tool0"}, "placement": {"xyz": [0.8, 0.0, 0.0]}}
CELL = {**LINE, "design": ["placement"], "cell": {"block": [0.1, 0.1, 0.05], "floor": -1.0, "clearance": 0.01,
                                                 "link_radius": 0.05, "tool_length": 0.1}}

# key: (base, a change of that key alone); a change is a partial config merged into the base
CHANGES = {
    "name": ({}, {"name": "other"}),
    "design": ({}, {"design": ["d", "a", "placement"]}),
    "toolpath.kind": (FIGURE8, {"toolpath": {"kind": "circle"}}),
    "toolpath.width": (FIGURE8, {"toolpath": {"width": 0.5}}),
    "toolpath.height": (FIGURE8, {"toolpath": {"height": 0.2}}),
    "toolpath.waypoints": (FIGURE8, {"toolpath": {"waypoints": 21}}),
    "toolpath.radius": (CIRCLE, {"toolpath": {"radius": 0.12}}),
    "toolpath.length": (LINE, {"toolpath": {"length": 0.05}}),
    "toolpath.file": (CSV, {"toolpath": {"file": "other.csv"}}),
    "toolpath.spacing": (GCODE, {"toolpath": {"spacing": 0.003}}),
    "toolpath.origin": (GCODE, {"toolpath": {"origin": [0.001, 0.0, 0.0]}}),
    "toolpath.force": (LINE, {"toolpath": {"force": 2.0}}),
    "toolpath.force.material": (MILLING, {"toolpath": {"force": {"material": "steel_c45"}}}),
    "toolpath.force.teeth": (MILLING, {"toolpath": {"force": {"teeth": 4}}}),
    "toolpath.force.feed_per_tooth": (MILLING, {"toolpath": {"force": {"feed_per_tooth": 6e-5}}}),
    "toolpath.force.axial_depth": (MILLING, {"toolpath": {"force": {"axial_depth": 2e-3}}}),
    "robot.structure": (PRISMATIC, {"robot": {"structure": "RPP"}}),
    "robot.dh": ({}, {"robot": {"dh": "generic"}}),
    "robot.dh.theta": (ROWS, {"robot": {"dh": [{"theta": 0.2, "d": 0.2, "a": 0.3, "alpha": 0.4}, {"a": 0.3},
                                                {"alpha": 0.2}]}}),
    "robot.dh.d": (ROWS, {"robot": {"dh": [{"theta": 0.1, "d": 0.3, "a": 0.3, "alpha": 0.4}, {"a": 0.3},
                                            {"alpha": 0.2}]}}),
    "robot.dh.a": (ROWS, {"robot": {"dh": [{"theta": 0.1, "d": 0.2, "a": 0.4, "alpha": 0.4}, {"a": 0.3},
                                            {"alpha": 0.2}]}}),
    "robot.dh.alpha": (ROWS, {"robot": {"dh": [{"theta": 0.1, "d": 0.2, "a": 0.3, "alpha": 0.5}, {"a": 0.3},
                                                {"alpha": 0.2}]}}),
    "robot.urdf": (URDF, {"robot": {"urdf": "longer_ur10.urdf"}}),
    "robot.tool_link": (URDF, {"robot": {"tool_link": "wrist_3_link"}}),
    "robot.bounds.length": ({}, {"robot": {"bounds": {"length": [0.0, 1.5]}}}),
    "robot.stiffness": (PRISMATIC, {"robot": {"stiffness": 2.0}}),
    "robot.stiffness.revolute": (PRISMATIC, {"robot": {"stiffness": {"revolute": 2.0}}}),
    "robot.stiffness.prismatic": (PRISMATIC, {"robot": {"stiffness": {"prismatic": 3.0}}}),
    "robot.joint_velocity": ({}, {"robot": {"joint_velocity": 5.0}}),
    "placement.xyz": ({}, {"placement": {"xyz": [0.4, 0.0, -0.2]}}),
    "placement.ypr": ({}, {"placement": {"ypr": [0.1, 0.0, 0.0]}}),
    "placement.box": ({}, {"placement": {"box": [[-1.5, 2], [-2, 2], [-1, 2]]}}),
    "placement.keep_out_radius": ({}, {"placement": {"keep_out_radius": 0.05}}),
    "costs.deflection": ({}, {"costs": {"deflection": "translational"}}),
    "costs.regularization": ({}, {"costs": {"regularization": 0.05}}),
    "costs.deformation_weight": ({}, {"costs": {"deformation_weight": 10.0}}),
    "tolerance.position": ({}, {"tolerance": {"position": 2e-3}}),
    "tolerance.axis": ({}, {"tolerance": {"axis": 0.02}}),
    "search.preset": ({}, {"search": {"preset": "thorough"}}),
    "search.seed": ({}, {"search": {"seed": 3}}),
    "search.starts": ({}, {"search": {"starts": 7}}),
    "search.spread": ({}, {"search": {"spread": "box"}}),
    "cell.block": (CELL, {"cell": {"block": [0.12, 0.1, 0.05]}}),
    "cell.floor": (CELL, {"cell": {"floor": -1.2}}),
    "cell.clearance": (CELL, {"cell": {"clearance": 0.02}}),
    "cell.link_radius": (CELL, {"cell": {"link_radius": 0.06}}),
    "cell.tool_length": (CELL, {"cell": {"tool_length": 0.12}}),
    "modules.d": ({}, {"modules": [{"d": 0.1, "a": 0.5}]}),
    "modules.a": ({}, {"modules": [{"a": 0.4}]}),
    "modules.alpha": ({}, {"modules": [{"a": 0.5, "alpha": 0.3}]}),
}


def _merge(base: dict, change: dict) -> dict:
    out = copy.deepcopy(base)
    for key, value in change.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> Path:
    """The files the bases name: two CSV paths, a G-code program, the UR10 and a UR10 with a longer upper arm."""
    d = tmp_path_factory.mktemp("files")
    (d / "path.csv").write_text("x,y,z\n0,0,0\n0.01,0.005,0\n0.02,0,0\n0.03,-0.005,0\n")
    (d / "other.csv").write_text("x,y,z\n0,0,0\n0.01,0.006,0\n0.02,0,0\n0.03,-0.005,0\n")
    (d / "p.nc").write_text("G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F300\nG1 X20 F600\nG1 Y10\n")
    ur10 = ROOT / "configs" / "robots" / "ur10.urdf"
    shutil.copy(ur10, d / "ur10.urdf")
    (d / "longer_ur10.urdf").write_text(ur10.read_text().replace('xyz="0.0 -0.1719 0.612"', 'xyz="0.0 -0.1719 0.7"'))
    assert (d / "longer_ur10.urdf").read_text() != ur10.read_text()
    return d


def fingerprint(cfg: Config) -> tuple:
    """What a run of this config would use: the problem (chain, toolpath, stiffness, costs, limits, tolerances,
    cell), the search, and the module catalogue."""
    p = problem_from_config(cfg)
    joints = tuple((j.name, j.role.value, j.value, j.lower, j.upper) for j in p.chain.joints)
    tp = p.toolpath
    path = tuple(np.round(np.concatenate([tp.t, tp.points_W.ravel(), tp.force_W.ravel(),
                                          tp.is_tracked.astype(float)]), 12))
    costs = tuple((c.name, c.weight) for c in (*p.waypoint_costs, *p.design_costs))
    return (p.name, joints, np.round(np.array(p.chain.tool), 12).tobytes(), path,
            tuple(p.stiffness.diagonal(p.chain.structure)), p.deflection, costs, p.joint_velocity,
            p.keep_out_radius, p.position_tol, p.axis_tol, p.cell, search_from_config(cfg),
            catalogue_from_config(cfg).modules)


def test_the_table_names_every_key():
    # and the three fields that take a value or a section (robot.dh: a preset name; robot.stiffness and
    # toolpath.force: a number) as keys of their own
    assert set(CHANGES) == set(config_keys()) | {"robot.dh", "robot.stiffness", "toolpath.force"}


@pytest.mark.parametrize("key", sorted(CHANGES))
def test_every_key_changes_what_a_run_uses(key, files):
    base, change = CHANGES[key]
    before = parse_config(copy.deepcopy(base), files / "c.yaml", files)
    after = parse_config(_merge(base, change), files / "c.yaml", files)
    assert fingerprint(before) != fingerprint(after), f"{key} is read but changes nothing"
