"""The production models against independent truth, each guarded by a mutation in `make mutate`: the clearance
aggregate is a lower bound of the true minimum, the floor is a plane of the base frame, a milling force never
loads a rapid, a hand-computed program's tracked flags and force directions, and the offline view's geometry
against the solution file's own numpy recomputation (designopt.verify)."""

from __future__ import annotations

import math
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
import yaml

from designopt.clearance import constraint_terms, softmin
from designopt.config import parse_config
from designopt.gcode import parse_program, sample_program
from designopt.initial_guess import initial_guesses
from designopt.problem import problem_from_config
from designopt.solution import Solution, to_dict
from designopt.solve import SolverProfile, solve_guess
from designopt.transcriptions import Collocation
from designopt.verify import _placement, _robot_walk, _skeleton

ROOT = Path(__file__).resolve().parent.parent
MM = 1e-3


@pytest.fixture(scope="module")
def pocket():
    """configs/gcode_pocket.yaml with a tilted, turned placement (so that B and W differ in every axis), coarse
    waypoints and a short solve: a solution with a cell, a milling force and rapids (converged or not)."""
    data = yaml.safe_load((ROOT / "configs" / "gcode_pocket.yaml").read_text())
    data["toolpath"]["spacing"] = 0.02
    data["placement"]["ypr"] = [0.4, 0.3, -0.2]
    cfg = parse_config(data, "gcode_pocket.yaml", ROOT / "configs")
    problem = problem_from_config(cfg)
    solved = solve_guess(problem, Collocation(), SolverProfile(max_iter=20), initial_guesses(problem, 1, 0, 0.3)[0])
    return problem, to_dict(solved)


def test_the_clearance_aggregate_is_a_lower_bound_of_the_true_minimum(rng):
    """softmin(v) <= min(v) (so aggregate >= 0 implies every distance >= 0) and lies within log(n)/k of it."""
    for n in (2, 7, 60, 400):
        for _ in range(20):
            values = rng.normal(0.0, rng.choice([1e-3, 1e-2, 1.0]), n)
            value = float(ca.evalf(softmin([ca.DM(v) for v in values])))
            assert value <= values.min() + 1e-15
            assert value >= values.min() - math.log(n) / 2000.0 - 1e-15


def test_floor_clearance_is_height_above_the_floor_in_the_base_frame(pocket):
    """Each skeleton point's floor term is its z in B (recomputed by verify's numpy walk) minus the floor, the
    link radius and the clearance: with W tilted, a term taken in W would differ."""
    problem, data = pocket
    cell, chain = problem.cell, problem.chain
    q = np.array(data["q"][1])
    points, links = _skeleton(data, q, cell.tool_length)
    terms = constraint_terms(chain, cell, ca.DM(q), ca.DM(chain.design_values), aggregate=False)
    for i, p in enumerate(points):
        adjacent = [links[j] for j in (i - 1, i) if 0 <= j < len(links)] or [0]
        expected = p[2] - cell.floor - max(cell.radius(link) for link in adjacent) - cell.clearance
        assert float(ca.evalf(terms[i])) == pytest.approx(expected, abs=1e-12)
    R = _placement(data)[:3, :3]
    assert not np.allclose(R, np.eye(3), atol=0.1)  # the frames differ, so the check can tell them apart


def test_a_milling_force_never_loads_a_rapid(pocket):
    problem, _ = pocket
    tp = problem.toolpath
    assert tp.force_model == "milling" and (~tp.is_tracked).sum() >= 3
    np.testing.assert_array_equal(tp.force_W[~tp.is_tracked], 0.0)
    assert np.all(np.linalg.norm(tp.force_W[tp.is_tracked], axis=1) > 1.0)


def test_tracked_flags_and_force_directions_of_a_hand_computed_program():
    """G0 to (0,0,5); plunge G1 to z=0; cut +x to 10; rapid up and over to x=30; plunge; cut +y to 10 (mm), one
    waypoint per move (spacing 50 mm). By hand: the waypoint where a plunge starts (the end of a rapid) is tracked
    and points down; the last waypoint of a cut that a rapid leaves keeps the cut's direction."""
    text = "G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F300\nG1 X10 F600\nG0 Z5\nG0 X30\nG1 Z0 F300\nG1 Y10 F600\n"
    s = sample_program(parse_program(text), spacing=50 * MM, rapid_speed=0.1)
    expected_points = np.array([[0, 0, 5], [0, 0, 0], [10, 0, 0], [10, 0, 5], [30, 0, 5], [30, 0, 0], [30, 10, 0]])
    np.testing.assert_allclose(s.points, expected_points * MM, atol=1e-12)
    assert s.tracked.tolist() == [True, True, True, False, True, True, True]
    expected_tangents = np.array([[0, 0, -1], [1, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, -1], [0, 1, 0], [0, 1, 0]])
    np.testing.assert_allclose(s.tangents, expected_tangents, atol=1e-12)


def test_the_view_draws_the_solution_where_verify_puts_it(pocket):
    """The offline view's vertex data against verify's numpy recomputation from the file: the block's corners
    through the file's placement, the path in B, and every joint of the robot at the centre of a sphere of its
    link radius in every frame."""
    from designopt.view import cell_figure

    _, data = pocket
    sol = Solution.from_dict(data)
    fig = cell_figure(sol, frames=3)
    T = _placement(data)
    cell = data["cell"]
    (sx, sy, sz), (cx, cy) = cell["block"]["size"], cell["block"]["center"]
    corners = np.array([[cx + a * sx / 2, cy + b * sy / 2, c] for a in (-1, 1) for b in (-1, 1) for c in (-sz, 0)])
    block = next(t for t in fig.data if t.name == "workpiece block")
    drawn = np.column_stack([block.x, block.y, block.z])
    expected = corners @ T[:3, :3].T + T[:3, 3]
    assert sorted(map(tuple, drawn.round(12))) == sorted(map(tuple, expected.round(12)))
    path = next(t for t in fig.data if t.name.startswith("toolpath"))
    np.testing.assert_allclose(np.column_stack([path.x, path.y, path.z]),
                               np.array(data["toolpath"]["points_W"]) @ T[:3, :3].T + T[:3, 3], atol=1e-12)
    picks = np.unique(np.linspace(0, len(data["q"]) - 1, 3).round().astype(int))
    assert len(fig.frames) == len(picks)
    for frame, k in zip(fig.frames, picks, strict=True):
        marker = frame.data[1]  # the tool centre point: the robot's, by verify's own forward kinematics
        tcp = _tool_position(data, np.array(data["q"][k]))
        np.testing.assert_allclose([marker.x[0], marker.y[0], marker.z[0]], tcp, atol=1e-12)
        mesh = frame.data[0]
        vertices = np.column_stack([mesh.x, mesh.y, mesh.z])
        points, links = _skeleton(data, np.array(data["q"][k]), cell["tool"]["length"])
        radii = cell["link_radius"]
        for i, p in enumerate(points):
            r = radii[min(links[i - 1] if i else 0, len(radii) - 1)]
            on_sphere = np.abs(np.linalg.norm(vertices - np.asarray(p, dtype=float), axis=1) - r) < 1e-9
            assert on_sphere.sum() >= 40, (k, i)  # a whole sphere (8 x 5 vertices) of radius r around the joint


def _tool_position(data: dict, q: np.ndarray) -> np.ndarray:
    """The tool centre point in B by verify's numpy walk of the file: last link frame times the tool."""
    T, *_ = _robot_walk(data, q)
    return (T @ np.array(data["tool"], dtype=float))[:3, 3]
