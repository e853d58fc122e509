"""Robots from URDF: the chain built from the file against pinocchio on the same file, design joints by name,
and the UR10 example end to end."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from cli.main import app
from designopt.config import parse_config
from designopt.costs import design_length_indices
from designopt.errors import InputError
from designopt.kinematics.chain import geometric_jacobian, tool_pose
from designopt.problem import problem_from_config
from designopt.solution import chain_from_file
from designopt.verify import verify_file

pin = pytest.importorskip("pinocchio")
ROOT = Path(__file__).resolve().parent.parent
UR10 = ROOT / "configs" / "robots" / "ur10.urdf"
OFFAXIS = ROOT / "tests" / "data" / "offaxis.urdf"


def urdf_problem(path: Path, tool: str, design=("placement",)):
    cfg = parse_config({"robot": {"urdf": path.name, "tool_link": tool}, "design": list(design),
                        "placement": {"xyz": [0.5, 0.0, 0.0]}}, "cfg.yaml", path.parent)
    return problem_from_config(cfg)


@pytest.mark.parametrize("path,base,tool,structure", [(UR10, "world", "tool0", "RRRRRR"),
                                                      (OFFAXIS, "root", "tip", "RPRR")], ids=["ur10", "offaxis"])
def test_urdf_chain_matches_pinocchio(path, base, tool, structure, rng):
    problem = urdf_problem(path, tool)  # the chain starts at the URDF's root link (``base``)
    chain = problem.chain
    assert chain.structure == structure
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    frame = model.getFrameId(tool)
    # pinocchio orders joints as the tree does; here the tree is the chain
    assert [model.names[i] for i in range(1, model.njoints)] == [j.name for j in chain.moving]
    lo, hi = np.array([j.lower for j in chain.moving]), np.array([j.upper for j in chain.moving])
    np.testing.assert_allclose(lo, model.lowerPositionLimit)
    np.testing.assert_allclose(hi, model.upperPositionLimit)
    for _ in range(20):
        q = rng.uniform(lo, hi)
        pin.framesForwardKinematics(model, data, q)
        T_base = data.oMf[model.getFrameId(base)].homogeneous
        T_tool = np.linalg.inv(T_base) @ data.oMf[frame].homogeneous
        np.testing.assert_allclose(tool_pose(chain, q, chain.design_values), T_tool, atol=1e-9)
        J = pin.computeFrameJacobian(model, data, q, frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(geometric_jacobian(chain, q, chain.design_values), J, atol=1e-9)


def test_any_origin_component_is_a_design_joint_by_name():
    problem = urdf_problem(UR10, "tool0", design=["placement", "elbow_joint.origin.z", "wrist_1_joint.origin.z"])
    design = {j.name: j for j in problem.chain.design}
    assert {"elbow_joint.origin.z", "wrist_1_joint.origin.z"} <= set(design)
    assert design["elbow_joint.origin.z"].value == pytest.approx(0.612)  # the UR10's upper-arm length
    assert design_length_indices(problem.chain)  # design lengths are regularised like DH lengths
    # changing that design joint moves the tool by the change along the upper arm
    chain = problem.chain
    q = np.zeros(6)
    moved = chain.with_roles({}, {"elbow_joint.origin.z": 0.712})
    delta = tool_pose(moved, q, moved.design_values)[:3, 3] - tool_pose(chain, q, chain.design_values)[:3, 3]
    assert np.linalg.norm(delta) == pytest.approx(0.1, abs=1e-12)


@pytest.mark.parametrize("robot,key,reason", [
    ({"robot": {"urdf": "ur10.urdf", "tool_link": "nowhere"}}, "robot.tool_link", "no link"),
    ({"robot": {"urdf": "ur10.urdf", "tool_link": "world"}}, "robot.tool_link", "root link"),
    ({"robot": {"urdf": "ur10.urdf", "tool_link": "tool0"}, "design": ["elbow.origin.q"]}, "design",
     "'elbow.origin.q' names no joint"),
    ({"robot": {"urdf": "ur10.urdf", "tool_link": "tool0"}, "design": ["a"]}, "design", "not a DH table"),
    ({"robot": {"urdf": "ur10.urdf", "tool_link": "tool0", "structure": "RRR"}}, "robot.structure",
     "takes its joints from robot.urdf"),
    ({"robot": {"urdf": "ur10.urdf"}}, "robot.tool_link", "needed"),
    ({"robot": {"urdf": "ur10.urdf", "tool_link": "tool0", "base_link": "base_link"}}, "robot.base_link",
     "root link"),
    ({"robot": {"urdf": "missing.urdf", "tool_link": "b"}}, "robot.urdf", "no such file"),
])
def test_bad_urdf_robot_is_one_line(tmp_path, robot, key, reason):
    (tmp_path / "ur10.urdf").write_text(UR10.read_text())
    config = tmp_path / "c.yaml"
    config.write_text(yaml.safe_dump(robot))
    result = CliRunner().invoke(app, ["check", str(config)])
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and f"{config}: {key}: " in lines[0] and reason in lines[0], result.output


def test_not_a_urdf_is_one_line(tmp_path):
    (tmp_path / "r.urdf").write_text("<robot name='x'><joint name='j' type='revolute'>")
    config = tmp_path / "c.yaml"
    config.write_text(yaml.safe_dump({"robot": {"urdf": "r.urdf", "tool_link": "b"}}))
    result = CliRunner().invoke(app, ["check", str(config)])
    assert result.exit_code == 2 and f"{tmp_path / 'r.urdf'}: (file): not a readable URDF" in result.output


def test_ur10_placement_runs_tracks_and_reverifies(tmp_path):
    cfg = yaml.safe_load((ROOT / "configs" / "ur10_placement.yaml").read_text())
    cfg["robot"]["urdf"] = str(UR10)
    cfg["toolpath"]["waypoints"] = 30
    cfg["search"] = {"preset": "quick", "starts": 4}
    config = tmp_path / "ur10.yaml"
    config.write_text(yaml.safe_dump(cfg))
    result = CliRunner().invoke(app, ["run", str(config), "--out", str(tmp_path / "r"), "--name", "t", "--urdf",
                                      "--jobs", "1"])
    assert result.exit_code == 0, result.output
    run = tmp_path / "r" / "ur10_placement" / "t"
    best = json.loads((run / "best.json").read_text())
    assert best["metrics"]["tracks"] and "ets" in best and "dh" not in best
    for f in [run / "best.json", *(run / "solutions").glob("*.json")]:
        assert verify_file(f) == [], f
    # the exported cell is the UR10's own URDF (its joint names) and loads in pinocchio with designopt's tool pose
    # (1e-9) and the solved tool position at every waypoint
    model = pin.buildModelFromUrdf(str(run / "export" / "best.urdf"))
    assert list(model.names)[1:] == list(pin.buildModelFromUrdf(str(UR10)).names)[1:] == [
        "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
    data = model.createData()
    frame = model.getFrameId("designopt_tool")
    chain = chain_from_file(best)
    placement = best["placement"]
    yaw, pitch, roll = placement["ypr"]
    c, s = math.cos, math.sin
    R_BW = (np.array([[c(yaw), -s(yaw), 0], [s(yaw), c(yaw), 0], [0, 0, 1]])
            @ np.array([[c(pitch), 0, s(pitch)], [0, 1, 0], [-s(pitch), 0, c(pitch)]])
            @ np.array([[1, 0, 0], [0, c(roll), -s(roll)], [0, s(roll), c(roll)]]))
    for q, p_W in zip(best["q"], best["toolpath"]["points_W"], strict=True):
        pin.framesForwardKinematics(model, data, np.array(q))
        np.testing.assert_allclose(data.oMf[frame].homogeneous, tool_pose(chain, np.array(q), np.zeros(0)), atol=1e-9)
        target = R_BW @ np.array(p_W) + np.array(placement["xyz"])
        np.testing.assert_allclose(data.oMf[frame].translation, target, atol=1.1e-3)


@pytest.mark.parametrize("command", ["continuous", "waypoints", "modular"])
def test_dh_experiments_refuse_a_urdf_robot_with_one_line(command, tmp_path):
    config = ROOT / "configs" / "ur10_placement.yaml"
    result = CliRunner().invoke(app, [command, str(config), "--out", str(tmp_path)])
    assert result.exit_code == 2 and f"{config}: robot.urdf: " in result.output, result.output
    assert not any(tmp_path.iterdir()), "a run directory was left behind"


def test_joints_without_limits_take_the_default_travel(tmp_path):
    """A continuous joint and joints whose <limit> gives no travel (no lower/upper: URDF reads 0 and 0): the chain
    moves them within +-2 pi rad and +-2 m (designopt's defaults for joints a file does not limit); a limited joint
    keeps the file's limits. Pinocchio, reading the same file, agrees on the kinematics."""
    text = (OFFAXIS.read_text()
            .replace('<joint name="j1" type="revolute">', '<joint name="j1" type="continuous">')
            .replace('<limit lower="-0.5" upper="0.5" effort="1" velocity="1"/>', '<limit effort="1" velocity="1"/>')
            .replace('<limit lower="-2" upper="2" effort="1" velocity="1"/>\n  </joint>\n  <joint name="j4"',
                     '<limit effort="1" velocity="1"/>\n  </joint>\n  <joint name="j4"'))
    path = tmp_path / "unlimited.urdf"
    path.write_text(text)
    chain = urdf_problem(path, "tip").chain
    limits = {j.name: (j.lower, j.upper) for j in chain.moving}
    assert limits == {"j1": (-2 * math.pi, 2 * math.pi), "j2": (-2.0, 2.0), "j3": (-2 * math.pi, 2 * math.pi),
                      "j4": (-2.0, 2.0)}
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    rng = np.random.default_rng(5)
    for _ in range(5):
        q_ours = rng.uniform(-1, 1, 4)
        # pinocchio represents a continuous joint by (cos, sin)
        q_pin = np.r_[np.cos(q_ours[0]), np.sin(q_ours[0]), q_ours[1:]]
        pin.framesForwardKinematics(model, data, q_pin)
        np.testing.assert_allclose(tool_pose(chain, q_ours, chain.design_values),
                                   data.oMf[model.getFrameId("tip")].homogeneous, atol=1e-9)


def _urdf_on_pocket(robot: dict):
    """configs/gcode_pocket.yaml (a program timed in seconds by its feeds) with the UR10 from its URDF."""
    data = yaml.safe_load((ROOT / "configs" / "gcode_pocket.yaml").read_text())
    data["robot"] = {"urdf": "robots/ur10.urdf", "tool_link": "tool0", **robot}
    return parse_config(data, "pocket.yaml", ROOT / "configs")


def test_velocity_limits_come_from_the_urdf_on_a_timed_program():
    """On a toolpath timed in seconds, the moving joints' |dq/dt| bounds are the URDF's <limit velocity>, read here
    with ElementTree; robot.joint_velocity (one value or one per joint) overrides them; on a task-time path
    (normalised t, where rad/s mean nothing) the default stays."""
    import xml.etree.ElementTree as ET

    tree = ET.parse(UR10)
    moving = [j for j in tree.getroot().iter("joint") if j.get("type") in ("revolute", "continuous", "prismatic")]
    expected = [float(j.find("limit").get("velocity")) for j in moving]
    cfg = _urdf_on_pocket({})
    assert cfg._toolpath.time_unit == "s"
    problem = problem_from_config(cfg)
    np.testing.assert_array_equal(problem.velocity_limits, expected)
    assert len(set(expected)) > 1  # the file's joints differ: a single value could not pass
    np.testing.assert_array_equal(problem_from_config(_urdf_on_pocket({"joint_velocity": 1.5})).velocity_limits,
                                  [1.5] * 6)
    per_joint = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
    assert problem_from_config(_urdf_on_pocket({"joint_velocity": per_joint})).velocity_limits.tolist() == per_joint
    with pytest.raises(InputError, match=r"robot\.joint_velocity.*3 values for 6 moving joints"):
        _urdf_on_pocket({"joint_velocity": [1.0, 2.0, 3.0]})
    task_time = urdf_problem(UR10, "tool0")
    assert task_time.toolpath.time_unit == "task"
    np.testing.assert_array_equal(task_time.velocity_limits, [10.0] * 6)


def test_a_mimic_joint_on_the_chain_is_refused(tmp_path):
    """A coupled joint (a finger that mimics another) cannot be an independent joint of the chain: one line that
    names it and says to choose a tool link above it."""
    text = OFFAXIS.read_text().replace('<joint name="j3" type="revolute">\n    <parent link="l3"/><child link="l4"/>',
                                       '<joint name="j3" type="revolute">\n    <parent link="l3"/><child link="l4"/>\n'
                                       '    <mimic joint="j1" multiplier="-1"/>')
    assert "<mimic" in text
    path = tmp_path / "mimic.urdf"
    path.write_text(text)
    with pytest.raises(InputError, match=r"robot\.tool_link: .*'j3'.*mimics 'j1'.*above it") as info:
        urdf_problem(path, "tip")
    assert "\n" not in str(info.value)
    assert urdf_problem(path, "l3").chain.n_moving == 2  # a tool link above the finger is fine
