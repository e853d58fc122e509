"""Clearance against an independent distance library (coal) and a problem whose unconstrained optimum passes
through the workpiece block."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import casadi as ca
import coal
import numpy as np
import pytest
from typer.testing import CliRunner

from cli.main import app
from designopt.clearance import Cell, box_signed_distance, segment_box_distance, skeleton
from designopt.config import parse_config
from designopt.initial_guess import initial_guess
from designopt.kinematics.chain import link_frames
from designopt.problem import problem_from_config
from designopt.solution import to_dict
from designopt.solve import SolverProfile, solve_guess
from designopt.transcriptions.collocation import Collocation
from designopt.verify import clearance as coal_clearance
from designopt.verify import problems

CELL = Cell((0.4, 0.3, 0.2), (0.05, -0.02), -1.0, 0.01, (0.05,) * 7, 0.1, 0.005)


def _coal_segment_box(a, b, cell):
    length = np.linalg.norm(b - a)
    z = (b - a) / length
    x = np.cross(z, [1.0, 0, 0]) if abs(z[0]) < 0.9 else np.cross(z, [0, 1.0, 0])
    x /= np.linalg.norm(x)
    pose = coal.Transform3s(np.column_stack([x, np.cross(z, x), z]), (a + b) / 2)
    box_pose = coal.Transform3s(np.eye(3), np.array([*cell.block_center, -cell.block_size[2] / 2]))
    return coal.distance(coal.Capsule(1e-9, length), pose, coal.Box(*cell.block_size), box_pose,
                         coal.DistanceRequest(), coal.DistanceResult())


def test_box_distance_of_points_by_hand():
    assert box_signed_distance(np.array([0.05, -0.02, 0.3]), CELL) == pytest.approx(0.3)  # above the top face
    assert box_signed_distance(np.array([0.05 + 0.2 + 0.03, -0.02 + 0.15 + 0.04, 0.0]), CELL) == pytest.approx(0.05)
    assert box_signed_distance(np.array([0.05, -0.02, -0.05]), CELL) == pytest.approx(-0.05)  # inside: depth


def test_segment_distance_matches_coal():
    rng = np.random.default_rng(3)
    for _ in range(40):
        a, b = rng.uniform(-0.6, 0.6, 3), rng.uniform(-0.6, 0.6, 3)
        ours = segment_box_distance(a, b, CELL)
        if ours > 1e-6:  # coal's distance of intersecting shapes is a penetration estimate, not our depth
            assert ours == pytest.approx(_coal_segment_box(a, b, CELL), abs=1e-7)


def test_skeleton_follows_the_dh_links():
    cfg = parse_config({"robot": {"structure": "RRRRRR", "dh": "puma560"}, "design": ["d", "a"]})
    chain = problem_from_config(cfg).chain
    q = np.random.default_rng(0).uniform(-1, 1, 6)
    points, links = skeleton(chain, q, chain.design_values)
    frames = link_frames(chain, q, chain.design_values)
    expected = []
    for i in range(1, 7):  # o_{i-1} + d_i z_{i-1}, then o_i
        d = chain.design_values[[j.name for j in chain.design].index(f"link{i}.d")]
        expected += [frames[i - 1][:3, 3] + d * frames[i - 1][:3, 2], frames[i][:3, 3]]
    np.testing.assert_allclose(np.array(points[1:]), np.array(expected), atol=1e-12)
    assert links == [i for i in range(1, 7) for _ in range(2)]


def _placement_problem(cell: bool):
    """A fixed PUMA-560; the workpiece's x and z are free. Without the cell, the least deflection puts the
    path where the forearm passes through the block under it."""
    cfg = parse_config({"toolpath": {"kind": "line", "length": 0.1, "waypoints": 8},
                        "robot": {"structure": "RRRRRR", "dh": "puma560"}, "design": ["x", "z"],
                        "placement": {"xyz": [0.5, 0.0, -0.2]},
                        "cell": {"block": [0.6, 0.6, 0.3], "floor": -1.5, "clearance": 0.01,
                                 "link_radius": 0.05, "tool_length": 0.1}})
    problem = problem_from_config(cfg)
    return problem if cell else replace(problem, cell=None)


def _solve(problem):
    return solve_guess(problem, Collocation(), SolverProfile(max_iter=500), initial_guess(problem, 0, 0, 0.3, "ik"))


def test_clearance_keeps_the_robot_out_of_the_block_and_costs_more():
    free = _solve(_placement_problem(cell=False))
    with_cell = _placement_problem(cell=True)
    assert free.metrics.tracks
    # the unconstrained optimum passes through the block (coal says so, from the solution file alone)
    free_file = to_dict(replace(free, problem=replace(free.problem, cell=with_cell.cell)))
    assert coal_clearance(free_file)[0] < -0.05
    constrained = _solve(with_cell)
    assert constrained.raw.success and constrained.metrics.tracks
    data = to_dict(constrained)
    value, _, _ = coal_clearance(data)
    assert value >= with_cell.cell.clearance - 1e-6
    assert data["metrics"]["clearance"]["min"] == pytest.approx(value, abs=1e-6)
    assert problems(data) == []
    data["metrics"]["clearance"]["min"] += 1e-4  # a reported clearance is checked against coal's, not itself
    assert [key for key, _ in problems(data)] == ["metrics.clearance.min"]
    assert constrained.metrics.design_cost > free.metrics.design_cost


@pytest.mark.parametrize(("cell", "key"), [
    ({"floor": -0.02}, "cell.floor"),
    ({"tool_length": 0.03}, "cell.tool_length"),
    ({"tool": {"length": 0.1}}, "cell.tool"),
    ({"link_radius": [0.05, 0.05]}, "cell.link_radius"),
    ({"clearance": -0.01}, "cell.clearance"),
])
def test_bad_cells_are_one_line_and_exit_2(tmp_path, cell, key):
    import yaml

    (tmp_path / "c.yaml").write_text(yaml.safe_dump({"cell": cell}))
    result = CliRunner().invoke(app, ["check", str(tmp_path / "c.yaml")])
    assert result.exit_code == 2, result.output
    assert len(result.output.strip().splitlines()) == 1 and key in result.output


def test_per_joint_stiffness_reaches_the_deflection(tmp_path):
    """A per-joint list is the diagonal of K, checked by the standalone numpy recomputation of verify."""
    k = [2.0, 5.0, 0.5, 3.0, 1.5, 0.8]
    cfg = parse_config({"robot": {"structure": "RRRRRR", "dh": "puma560", "stiffness": k}, "design": [],
                        "placement": {"xyz": [0.45, 0.0, -0.2]},
                        "toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 12}})
    problem = problem_from_config(cfg)
    np.testing.assert_array_equal(problem.stiffness.diagonal("RRRRRR"), k)
    sol = _solve(problem)
    data = to_dict(sol)
    assert data["stiffness"] == k and problems(data) == []
    with pytest.raises(Exception, match="robot.stiffness: the list has 2 values but the robot has 6 moving joints"):
        parse_config({"robot": {"stiffness": [1.0, 2.0]}}, tmp_path / "c.yaml")


def test_the_production_job_end_to_end(tmp_path):
    """configs/gcode_pocket.yaml, coarser (one start, 6 mm spacing): G-code in, a placement that tracks every
    cutting move and keeps the clearance (coal), re-verified from the file, the cell exported as URDF."""
    import json
    import shutil

    import yaml
    import yourdfpy

    root = Path(__file__).resolve().parents[1] / "configs"
    shutil.copy(root / "pocket.nc", tmp_path / "pocket.nc")
    cfg = yaml.safe_load((root / "gcode_pocket.yaml").read_text())
    cfg["toolpath"]["spacing"] = 0.006
    cfg["search"]["starts"] = 1
    (tmp_path / "pocket.yaml").write_text(yaml.safe_dump(cfg))
    result = CliRunner().invoke(app, ["run", str(tmp_path / "pocket.yaml"), "--out", str(tmp_path / "r"),
                                      "--name", "t", "--urdf", "--jobs", "1"])
    assert result.exit_code == 0, result.output
    run = tmp_path / "r" / "gcode_pocket" / "t"
    data = json.loads((run / "best.json").read_text())
    assert data["metrics"]["tracks"] and problems(data) == []
    tracked = np.array(data["toolpath"]["tracked"])
    assert tracked.any() and not tracked.all()  # cuts and rapids
    value, _, _ = coal_clearance(data)
    assert value >= cfg["cell"]["clearance"] - 1e-6
    assert (run / "figures" / "force_deflection.png").exists()
    urdf = yourdfpy.URDF.load(str(run / "export" / "best.urdf"), load_meshes=False)
    assert {"floor", "workpiece", "tool"} <= set(urdf.link_map)


def test_a_path_beside_the_block_is_a_config_error(tmp_path):
    import yaml

    cfg = {"toolpath": {"kind": "line", "length": 0.5}, "cell": {"block": [0.2, 0.1, 0.05]}}
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(cfg))
    result = CliRunner().invoke(app, ["check", str(tmp_path / "c.yaml")])
    assert result.exit_code == 2 and len(result.output.strip().splitlines()) == 1
    assert "cell.block" in result.output and "beside the block" in result.output


def test_the_cells_assembled_jacobian_equals_casadis(rng):
    """The clearance and floor rows' Jacobian assembled from their blocks (and the linear rows' own) equals the
    Jacobian CasADi derives from the whole constraint graph, at random points; so does the objective's gradient
    assembled from the waypoint blocks (the clearance blocks add no objective term) and the quadratic terms."""
    nlp = Collocation().build(_placement_problem(cell=True)).nlp
    ours, ours_grad = nlp.jacobian("none"), nlp.gradient("none")
    ref = ca.Function("ref", [nlp.x], [nlp.g, ca.jacobian(nlp.g, nlp.x)])
    ref_grad = ca.Function("ref_grad", [nlp.x], [nlp.f, ca.gradient(nlp.f, nlp.x)])
    for _ in range(3):
        x = rng.normal(size=nlp.n_variables)
        for a, b in [*zip(ours(x, []), ref(x), strict=True), *zip(ours_grad(x, []), ref_grad(x), strict=True)]:
            np.testing.assert_allclose(np.array(ca.DM(a)), np.array(ca.DM(b)), rtol=1e-9, atol=1e-9)
