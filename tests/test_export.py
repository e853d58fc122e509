"""The exported URDF against an independent kinematics library (pinocchio): tool pose and Jacobian, 1e-9.

This is the project's external proof that its forward kinematics and Jacobian are right: pinocchio knows
nothing of DH parameters, only the URDF joints designopt wrote.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from designopt.config import parse_config
from designopt.export import export, urdf_model
from designopt.initial_guess import initial_guesses
from designopt.kinematics.chain import geometric_jacobian, placement_pose, tool_pose
from designopt.problem import problem_from_config
from designopt.solution import chain_from_file, to_dict
from designopt.solve import SolverProfile, solve_guess
from designopt.transcriptions import Collocation

pin = pytest.importorskip("pinocchio")


@pytest.fixture(scope="module")
def solved():
    """A small solved design with both joint types, a twisted placement and a tool offset."""
    cfg = parse_config({"toolpath": {"kind": "circle", "radius": 0.08, "waypoints": 10},
                        "robot": {"structure": "RRPRRR", "dh": "generic"},
                        "placement": {"xyz": [0.35, 0.1, -0.1], "ypr": [0.3, 0.0, 0.0]}})
    problem = problem_from_config(cfg)
    return to_dict(solve_guess(problem, Collocation(), SolverProfile(max_iter=300),
                               initial_guesses(problem, 1, 0, 0.3, "ik")[0]))


def _pin_model(path):
    model = pin.buildModelFromUrdf(str(path))
    return model, model.createData()


def test_urdf_matches_designopt_kinematics(solved, tmp_path, rng):
    urdf, *_ = export(solved, tmp_path)
    model, data = _pin_model(urdf)
    assert model.nq == len(solved["dh"])
    tool_id, wp_id = model.getFrameId("tool"), model.getFrameId("workpiece")
    chain = chain_from_file(solved)
    q_d = np.zeros(0)
    qs = [np.array(q) for q in solved["q"]] + [rng.uniform(-2, 2, model.nq) for _ in range(20)]
    for q in qs:
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(data.oMf[tool_id].homogeneous, tool_pose(chain, q, q_d), atol=1e-9)
        np.testing.assert_allclose(data.oMf[wp_id].homogeneous, placement_pose(chain, q, q_d), atol=1e-9)
        J = pin.computeFrameJacobian(model, data, q, tool_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(J, geometric_jacobian(chain, q, q_d), atol=1e-9)


def test_urdf_loads_in_yourdfpy_and_round_trips(solved, tmp_path):
    import yourdfpy

    urdf, csv_path, yaml_path = export(solved, tmp_path)
    loaded = yourdfpy.URDF.load(str(urdf), load_meshes=False)
    assert loaded.validate()
    assert loaded.num_actuated_joints == len(solved["dh"])
    q = np.array(solved["q"][3])
    loaded.update_cfg(q)
    chain = chain_from_file(solved)
    np.testing.assert_allclose(loaded.get_transform("tool", "base"), tool_pose(chain, q, np.zeros(0)), atol=1e-9)
    lines = csv_path.read_text().splitlines()
    assert len(lines) == len(solved["q"]) + 1
    assert len(loaded.link_map["workpiece"].visuals) == len(solved["toolpath"]["points_W"])
    assert urdf_model(solved).robot.name == "designopt_cell"


def test_exported_joint_limits_come_from_the_solution(solved, tmp_path):
    import yourdfpy

    urdf, *_ = export(solved, tmp_path)
    loaded = yourdfpy.URDF.load(str(urdf), load_meshes=False)
    lim = loaded.joint_map["joint3"].limit
    assert loaded.joint_map["joint3"].type == "prismatic"
    assert (lim.lower, lim.upper) == (solved["joint_limits"][2]["lower"], solved["joint_limits"][2]["upper"])
    json.dumps(solved)  # the dict is plain JSON


def test_export_and_render_commands(solved, tmp_path):
    from typer.testing import CliRunner

    from cli.main import app

    path = tmp_path / "sol.json"
    path.write_text(json.dumps(solved))
    runner = CliRunner()
    result = runner.invoke(app, ["export", str(path), "--out", str(tmp_path / "x")])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "x" / "sol.urdf").is_file() and (tmp_path / "x" / "sol_trajectory.csv").is_file()
    result = runner.invoke(app, ["render", str(path), "--out", str(tmp_path / "r"), "--frames", "3", "--animate"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "r" / "sol_render.png").stat().st_size > 1000
    assert (tmp_path / "r" / "sol_render.gif").stat().st_size > 1000
    bad = tmp_path / "bad.json"
    bad.write_text('{"schema": "other"}')
    result = runner.invoke(app, ["export", str(bad)])
    assert result.exit_code == 2 and "schema" in result.output


def _offaxis_solution(tmp_path):
    """A solved design of tests/data/offaxis.urdf (copied beside a mesh in a relative and a package:// path) whose
    fixed_mid.origin.z is a design joint, moved in the file (with its elementary transform) to 0.31 m."""
    from pathlib import Path

    source = (Path(__file__).parent / "data" / "offaxis.urdf").read_text()
    mesh = ('<visual><geometry><mesh filename="meshes/l1.stl"/></geometry></visual>'
            '<visual><geometry><mesh filename="package://arm/meshes/l2.stl"/></geometry></visual>')
    source = source.replace('<link name="l1"/>', f'<link name="l1">{mesh}</link>')
    arm = tmp_path / "robot" / "arm.urdf"
    arm.parent.mkdir()
    arm.write_text(source)
    cfg = parse_config({"robot": {"urdf": "arm.urdf", "tool_link": "tip"},
                        "design": ["placement", "fixed_mid.origin.z"],
                        "toolpath": {"kind": "circle", "radius": 0.05, "waypoints": 8},
                        "placement": {"xyz": [0.5, 0.0, 0.0]}}, "cfg.yaml", arm.parent)
    problem = problem_from_config(cfg)
    data = to_dict(solve_guess(problem, Collocation(), SolverProfile(max_iter=15),
                               initial_guesses(problem, 1, 0, 0.3, "ik")[0]))
    index = next(i for i, et in enumerate(problem.chain.robot)
                 if problem.chain.joints[et.joint].name == "fixed_mid.origin.z")
    data["ets"][index]["value"] = data["design_joints"]["fixed_mid.origin.z"] = 0.31
    return arm, data


def test_a_urdf_robot_is_exported_as_itself(tmp_path, rng):
    """Its own joint names (pinocchio's model and the trajectory's header), its limits, the freed origin at its
    solved value, a relative mesh made absolute and a package:// mesh kept; pinocchio's tool pose on the exported
    file equals designopt's kinematics of the solution file to 1e-9. With the source gone, the elementary-transform
    export keeps the joint names and the kinematics."""
    import xml.etree.ElementTree as ET

    arm, data = _offaxis_solution(tmp_path)
    assert data["urdf"] == {"file": str(arm.resolve()), "tool_link": "tip"}
    urdf, csv_path, _ = export(data, tmp_path / "x")
    model, pdata = _pin_model(urdf)
    assert list(model.names)[1:] == ["j1", "j2", "j3", "j4"]
    assert csv_path.read_text().splitlines()[0] == "t_task,j1,j2,j3,j4"
    np.testing.assert_allclose(model.lowerPositionLimit, [-3, -0.5, -2, -2])
    root = ET.parse(urdf).getroot()
    assert float(root.find("joint[@name='fixed_mid']/origin").get("xyz").split()[2]) == pytest.approx(0.31)
    meshes = [m.get("filename") for m in root.iter("mesh")]
    assert meshes == [str((arm.parent / "meshes" / "l1.stl").resolve()), "package://arm/meshes/l2.stl"]
    chain = chain_from_file(data)
    tool, workpiece = model.getFrameId("designopt_tool"), model.getFrameId("designopt_workpiece")
    for q in [np.array(q) for q in data["q"]] + [rng.uniform(-0.5, 0.5, 4) for _ in range(10)]:
        pin.framesForwardKinematics(model, pdata, q)
        np.testing.assert_allclose(pdata.oMf[tool].homogeneous, tool_pose(chain, q, np.zeros(0)), atol=1e-9)
        np.testing.assert_allclose(pdata.oMf[workpiece].homogeneous, placement_pose(chain, q, np.zeros(0)), atol=1e-9)
    arm.unlink()  # the solution outlived its robot file: the chain is written from the file's transforms
    fallback, *_ = export(data, tmp_path / "y")
    model, pdata = _pin_model(fallback)
    assert list(model.names)[1:] == ["j1", "j2", "j3", "j4"]
    q = np.array(data["q"][2])
    pin.framesForwardKinematics(model, pdata, q)
    np.testing.assert_allclose(pdata.oMf[model.getFrameId("tool")].homogeneous, tool_pose(chain, q, np.zeros(0)),
                               atol=1e-9)


def test_trajectory_of_a_timed_program_is_in_seconds(solved, tmp_path):
    """A toolpath timed by a program's feeds: the CSV's first column is time_s and holds the file's times."""
    timed = json.loads(json.dumps(solved))
    timed["toolpath"]["time_unit"] = "s"
    timed["toolpath"]["t"] = [3.0 * t for t in timed["toolpath"]["t"]]
    _, csv_path, yaml_path = export(timed, tmp_path)
    lines = csv_path.read_text().splitlines()
    assert lines[0].split(",")[0] == "time_s"
    assert [float(row.split(",")[0]) for row in lines[1:]] == timed["toolpath"]["t"]
    assert "time_unit: s" in yaml_path.read_text()
