"""Two real arms from example-robot-data (tests/data/robots, with their licences): the Franka Panda and the
Kinova Jaco2 (continuous joints, fingers below the tool link) each place the plate of configs/pocket.nc in a cell
with clearance, the result re-verifies, and the export is the arm's own URDF: pinocchio, reading it, gives
designopt's tool pose to 1e-9 at every waypoint, and the trajectory is headed by the arm's joint names in
seconds."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from cli.main import app
from designopt.kinematics.chain import tool_pose
from designopt.solution import chain_from_file
from designopt.verify import verify_file

pin = pytest.importorskip("pinocchio")
ROOT = Path(__file__).resolve().parent.parent
ROBOTS = ROOT / "tests" / "data" / "robots"


def _pin_q(model, names: list[str], q: np.ndarray) -> np.ndarray:
    """designopt's joint values as pinocchio's configuration: a continuous joint is (cos, sin); joints off the
    chain (the Panda's fingers) stay neutral."""
    config = pin.neutral(model)
    for name, value in zip(names, q, strict=True):
        joint = model.joints[model.getJointId(name)]
        config[joint.idx_q: joint.idx_q + joint.nq] = [np.cos(value), np.sin(value)] if joint.nq == 2 else [value]
    return config


@pytest.mark.parametrize("arm,tool_link", [("panda", "panda_hand"), ("kinova", "j2s6s200_end_effector")])
def test_a_real_arm_places_a_workpiece_and_exports_as_itself(arm, tool_link, tmp_path):
    urdf = ROBOTS / f"{arm}.urdf"
    config = {
        "name": f"{arm}_pocket", "design": ["placement"],
        "toolpath": {"kind": "gcode", "file": str(ROOT / "configs" / "pocket.nc"), "spacing": 0.01,
                     "origin": [0.006, 0.0, 0.0],
                     "force": {"material": "aluminium", "teeth": 3, "feed_per_tooth": 5.0e-5, "axial_depth": 1.0e-3}},
        "robot": {"urdf": str(urdf), "tool_link": tool_link, "stiffness": 1000.0},
        "placement": {"xyz": [0.5, 0.0, 0.0], "ypr": [0.0, 3.14159, 0.0], "box": [[-1, 1], [-1, 1], [-0.5, 1]]},
        "cell": {"block": [0.09, 0.05, 0.04], "floor": -0.3, "clearance": 0.005, "link_radius": 0.05,
                 "tool_length": 0.1},
        "costs": {"deflection": "translational", "deformation_weight": 1.0e6, "regularization": 1.0e-4},
        "tolerance": {"position": 1.0e-4, "axis": 1.0e-2},
        "search": {"preset": "quick", "starts": 2},
    }
    path = tmp_path / f"{arm}.yaml"
    path.write_text(yaml.safe_dump(config))
    result = CliRunner().invoke(app, ["run", str(path), "--out", str(tmp_path / "r"), "--name", "t", "--urdf",
                                      "--jobs", "1"])
    assert result.exit_code == 0, result.output
    assert "explored: explore 2 solves (" in result.output  # each coarse stage with how many of its solves track
    run = tmp_path / "r" / f"{arm}_pocket" / "t"
    best = json.loads((run / "best.json").read_text())
    assert best["metrics"]["tracks"] and best["metrics"]["clearance"]["min"] >= 0.005 - 1e-6
    assert verify_file(run / "best.json") == []
    source = pin.buildModelFromUrdf(str(urdf))
    model = pin.buildModelFromUrdf(str(run / "export" / "best.urdf"))
    names = [lim["name"] for lim in best["joint_limits"]]
    assert list(model.names) == list(source.names)  # the whole arm, fingers too, under its own names
    assert names == list(source.names)[1: 1 + len(names)]
    header = (run / "export" / "best_trajectory.csv").read_text().splitlines()[0].split(",")
    assert header == ["time_s", *names]
    data, frame, chain = model.createData(), model.getFrameId("designopt_tool"), chain_from_file(best)
    for q in best["q"]:
        q = np.array(q)
        pin.framesForwardKinematics(model, data, _pin_q(model, names, q))
        np.testing.assert_allclose(data.oMf[frame].homogeneous, tool_pose(chain, q, np.zeros(0)), atol=1e-9)
