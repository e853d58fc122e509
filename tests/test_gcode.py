"""G-code toolpaths against closed forms: arcs in every plane and direction, units, incremental mode, feeds as
time, rapids untracked and unloaded; bad programs through the CLI are one line and exit 2."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli.main import app
from designopt.config import parse_config
from designopt.errors import InputError
from designopt.evaluation import evaluate
from designopt.gcode import parse_program, sample_program
from designopt.initial_guess import initial_guess
from designopt.problem import problem_from_config
from designopt.transcriptions.trajectory import PiecewiseLinear

MM = 1e-3
# plane -> (first, second, normal) axis indices and the offset words along the first two
PLANES = {17: ((0, 1, 2), "IJ"), 18: ((2, 0, 1), "KI"), 19: ((1, 2, 0), "JK")}


def _xyz(v) -> str:
    return " ".join(f"{a}{c:g}" for a, c in zip("XYZ", v, strict=True))


@pytest.mark.parametrize("plane", [17, 18, 19])
@pytest.mark.parametrize("g", [2, 3])
def test_arc_matches_its_closed_form(plane, g):
    (a, b, n), (oa, ob) = PLANES[plane]
    start = np.array([1.0, 2.0, 3.0])
    centre = start.copy()
    centre[a] += 5.0  # radius 5 mm, the start at angle pi in the plane's (a, b) coordinates
    end = centre.copy()
    end[b] += 5.0  # at angle pi/2
    end[n] += 2.0  # a helix: the normal axis moves linearly
    text = f"G21 G90 G{plane}\nG0 {_xyz(start)}\nG{g} {_xyz(end)} {oa}5 {ob}0 F600\n"
    arc = parse_program(text, chord_tolerance=1e-3 * MM)[-1]
    assert not arc.rapid
    pts = arc.points / MM
    u = pts[:, [a, b]] - centre[[a, b]]
    np.testing.assert_allclose(np.linalg.norm(u, axis=1), 5.0, atol=1e-9)  # every vertex on the circle
    np.testing.assert_allclose(pts[0], start, atol=1e-12)
    np.testing.assert_allclose(pts[-1], end, atol=1e-12)
    theta = np.unwrap(np.arctan2(u[:, 1], u[:, 0]))
    sweep = theta[-1] - theta[0]
    # from angle pi to pi/2: clockwise (G2) is the short quarter, counter-clockwise (G3) the long way round
    assert sweep == pytest.approx(-math.pi / 2 if g == 2 else 3 * math.pi / 2, abs=1e-9)
    assert np.all(np.diff(theta) < 0) if g == 2 else np.all(np.diff(theta) > 0)
    # the normal coordinate is linear in the angle (helix), and no chord leaves the arc by more than the tolerance
    np.testing.assert_allclose(pts[:, n], start[n] + 2.0 * (theta - theta[0]) / sweep, atol=1e-9)
    sagitta = 5.0 * (1 - np.cos(np.abs(np.diff(theta)) / 2))
    assert sagitta.max() <= 1e-3 + 1e-12


@pytest.mark.parametrize(("r", "expected"), [(5.0, -math.pi / 2), (-5.0, -3 * math.pi / 2)])
def test_radius_arcs_take_the_short_or_long_way(r, expected):
    # G2 from (0, 0) to (5, 5) with |R| = 5: the short arc has its centre at (5, 0), the long one at (0, 5)
    arc = parse_program(f"G21 G17\nG0 X0 Y0\nG2 X5 Y5 R{r:g} F100\n")[-1]
    pts = arc.points[:, :2] / MM
    centre = np.array([5.0, 0.0]) if r > 0 else np.array([0.0, 5.0])
    np.testing.assert_allclose(np.linalg.norm(pts - centre, axis=1), 5.0, atol=1e-9)
    theta = np.unwrap(np.arctan2(*(pts - centre).T[::-1]))
    assert theta[-1] - theta[0] == pytest.approx(expected, abs=1e-9)


def test_full_circle_and_units_and_incremental_mode():
    circle = parse_program("G21\nG0 X10 Y0\nG3 X10 Y0 I-10 J0 F60\n")[-1]
    theta = np.unwrap(np.arctan2(circle.points[:, 1], circle.points[:, 0]))
    assert theta[-1] - theta[0] == pytest.approx(2 * math.pi)
    inch = parse_program("G20 G90\nG1 X1 Y2 F10\n")[-1]
    np.testing.assert_allclose(inch.points[-1], [0.0254, 0.0508, 0.0])
    assert inch.feed == pytest.approx(10 * 0.0254 / 60)
    incremental = parse_program("G21 G91\nG1 X10 F600\nX10 Y-5\nG90 X0\n")
    np.testing.assert_allclose([m.points[-1] / MM for m in incremental], [[10, 0, 0], [20, -5, 0], [0, -5, 0]])


def test_feeds_give_time_in_seconds_and_rapids_are_free():
    text = "G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F300\nG1 X10 F600\nG0 Z5\nG0 X30\nG1 Z0 F300\nG1 X40 F600\n"
    s = sample_program(parse_program(text), spacing=1 * MM, rapid_speed=0.1)
    assert s.time_unit == "s"
    # 5 mm at 5 mm/s, 10 mm at 10 mm/s, 5 + 20 mm of rapids at 100 mm/s, 5 mm at 5 mm/s, 10 mm at 10 mm/s
    assert s.t[-1] == pytest.approx(1 + 1 + 0.25 + 1 + 1)
    np.testing.assert_allclose(np.diff(s.t)[: 5], 0.2)  # 1 mm steps at 5 mm/s
    assert np.all(np.linalg.norm(np.diff(s.points, axis=0), axis=1) <= 1 * MM + 1e-12)
    rapid = (s.points[:, 2] > 0.5 * MM) & (s.points[:, 0] > 10.5 * MM) & (s.points[:, 0] < 29.5 * MM)
    assert rapid.any() and not s.tracked[rapid].any()
    cutting = np.isclose(s.points[:, 2], 0.0) & ((s.points[:, 0] <= 10 * MM) | (s.points[:, 0] >= 30 * MM))
    assert s.tracked[cutting].all()


def _pocket_problem(tmp_path: Path, force=1.0):
    (tmp_path / "p.nc").write_text("G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F300\nG1 X20 F600\nG0 Z5\nG0 X40\nG1 Z0 F300\n"
                                   "G1 Y20 F600\n")
    cfg = parse_config({"toolpath": {"kind": "gcode", "file": "p.nc", "spacing": 0.004, "force": force},
                        "robot": {"structure": "RRRRRR", "dh": "puma560"}, "design": [],
                        "placement": {"xyz": [0.45, 0.0, -0.2]}}, tmp_path / "c.yaml", tmp_path)
    return problem_from_config(cfg)


def test_a_design_that_leaves_the_path_on_a_rapid_still_tracks(tmp_path):
    problem = _pocket_problem(tmp_path)
    tp = problem.toolpath
    assert (~tp.is_tracked).any()
    np.testing.assert_array_equal(np.linalg.norm(tp.force_W, axis=1)[~tp.is_tracked], 0.0)  # unloaded
    np.testing.assert_allclose(np.linalg.norm(tp.force_W, axis=1)[tp.is_tracked], 1.0)
    guess = initial_guess(problem, 0, 0, 0.0, "ik")

    def tracks(Q):
        return evaluate(problem, guess.q_d, PiecewiseLinear(tp.t, Q)).tracks

    assert tracks(guess.Q)
    away = guess.Q.copy()
    away[~tp.is_tracked] += 0.3  # leave the path (by ~0.1 m) wherever the tool is in a rapid
    assert tracks(away)
    cut = np.flatnonzero(tp.is_tracked)[3]
    away[cut] += 0.3
    assert not tracks(away)


BAD_PROGRAMS = [
    ("G21\nG1 X1 Q5 F100\n", "line 2", "Q5: unknown word"),
    ("G21\nG1 X1 A30 F100\n", "line 2", "rotary"),
    ("G21\nG0 X0 Y0\nG2 X10 Y0 I4 J0 F100\n", "line 3", "inconsistent"),
    ("G21\nG0 X0 Y0\nG2 X30 Y0 R5 F100\n", "line 3", "no such arc"),
    ("G21\nG0 X0 Y0\nG0 X5\n", "(file)", "no cutting move"),
    ("G21\nG81 X1 Y1 Z-2 R1\n", "line 2", "G81: canned cycles are not read: post-process with cycles expanded"),
    ("G21\nG1 X1\nG1 X2 F100\n", "line 2", "before any F"),
    ("G21\nG1 X1 F0\n", "line 2", "must be > 0"),
    ("G21\nG1 X1 F100 Y#3\n", "line 2", "plain numbers"),
]


@pytest.mark.parametrize(("program", "where", "reason"), BAD_PROGRAMS)
def test_bad_programs_are_one_line_and_exit_2(tmp_path, program, where, reason):
    (tmp_path / "bad.nc").write_text(program)
    (tmp_path / "c.yaml").write_text("toolpath: {kind: gcode, file: bad.nc}\n")
    result = CliRunner().invoke(app, ["check", str(tmp_path / "c.yaml")])
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.output
    assert "bad.nc" in lines[0] and where in lines[0] and reason in lines[0], lines[0]


def test_missing_program_file_is_a_config_error(tmp_path):
    (tmp_path / "c.yaml").write_text("toolpath: {kind: gcode, file: nowhere.nc}\n")
    result = CliRunner().invoke(app, ["check", str(tmp_path / "c.yaml")])
    assert result.exit_code == 2 and "toolpath.file" in result.output and "no such file" in result.output


def test_parse_errors_name_the_source():
    with pytest.raises(InputError, match="prog.nc: line 1"):
        parse_program("G1 X1 E5", "prog.nc")


# ---------------------------------------------------------------------------------------------------------
# What CAM posts and shops write: one test per dialect feature, against hand-written coordinates


def _points(text: str, **kw) -> np.ndarray:
    """Every move's end point, in mm."""
    return np.array([m.points[-1] for m in parse_program(text, **kw)]) / MM


def test_numbers_with_dots_and_spaces_read_as_the_controller_reads_them():
    # trailing dots (Fanuc, Fusion, Haas posts), leading dots, a space before a negative number (LinuxCNC), spaces
    # inside a word, lower case: the same moves as the plain form
    plain = _points("G21 G90\nG0 X0 Y0 Z15\nG1 Z-1 F100\nG1 X10 Y0.5\nG1 X-300 Y2.5\n")
    dialect = _points("g21 g90\nG0 X0. Y0. Z15.\nG1 Z -1 F100.\nG 1 X 10. Y.5\nG1X-300Y 2.5\n")
    np.testing.assert_allclose(dialect, plain, atol=1e-12)
    np.testing.assert_allclose(plain[1], [0, 0, -1])  # not +15: the -1 was read


def test_comments_numbers_percent_block_delete_and_crlf_are_read_or_ignored():
    text = ("%\r\nO1000 (program number)\r\nN10 G21 G90 ; a comment\r\n(MSG, whole-line comment)\r\n"
            "N20 G0 X1 Y2 Z3 (inline) M3 S12000 T1\r\n/N30 G1 X4 F200\r\nN40 M30\r\nG1 X99\r\n%\r\n")
    np.testing.assert_allclose(_points(text), [[1, 2, 3], [4, 2, 3]])  # block delete runs; nothing after M30


def test_setup_codes_are_accepted_and_change_no_coordinate():
    setup = ("G21 G90 G40 G49 G80 G94 G64 G61 G17\nG0 X0 Y0\nG43 Z50. H1\nM6 T2\nM8\nG4 P0.5\n"
             "G1 X10 Y5 Z-1 F300\nM5 M9\n")
    np.testing.assert_allclose(_points(setup), [[0, 0, 50], [10, 5, -1]])


@pytest.mark.parametrize(("line", "reason"), [
    ("G28 X0 Y0", "machine coordinates"), ("G53 G0 Z0", "machine coordinates"), ("G30", "machine coordinates"),
    ("G81 X1 Y1 Z-2 R1", "cycles expanded"), ("G83 X1 Y1 Z-2 R1 Q1", "cycles expanded"),
    ("G41 D1 X1", "compensation off (G40)"), ("G42 X1", "compensation off (G40)"),
    ("G92 X0 Y0", "toolpath.origin"), ("G10 L2 P1 X0", "toolpath.origin"), ("G16 X10 Y45", "Cartesian"),
    ("G1 @10 ^45 F100", "Cartesian"), ("G93 G1 X1 F2", "feed per minute (G94)"), ("G95 G1 X1 F0.1", "(G94)"),
    ("O100 sub", "flat program"), ("O100 call", "flat program"), ("M98 P100", "flat program"),
    ("G1 X#1 F100", "plain numbers"), ("G1 X[1+2] F100", "plain numbers"), ("G1 X1 E0.5 F100", "extruder"),
    ("G1 X1 A30 F100", "three linear axes"), ("echo hello", "cannot read"),
])
def test_codes_a_cell_cannot_follow_are_refused_with_what_to_do(line, reason):
    with pytest.raises(InputError) as info:
        parse_program(f"G21\n{line}\n", "p.nc")
    message = str(info.value)
    assert message.startswith("p.nc: line 2: ") and reason in message and "\n" not in message, message


def test_a_full_circle_without_axis_words_and_turns():
    # LinuxCNC's documented full circle: G2 with only I (the end is the start); P2: two turns, a helix down 2 mm
    (circle,) = [m for m in parse_program("G21\nG0 X45 Y0 Z0\nG2 I-45 F100\n", chord_tolerance=1e-9) if not m.rapid]
    r = np.linalg.norm(circle.points[:, :2] / MM, axis=1)
    np.testing.assert_allclose(r, 45.0, atol=1e-6)
    assert circle.length / MM == pytest.approx(2 * math.pi * 45, rel=1e-4)
    (helix,) = [m for m in parse_program("G21\nG0 X10 Y0 Z0\nG3 X10 Y0 Z-2 I-10 J0 P2 F100\n", chord_tolerance=1e-9)
                if not m.rapid]
    assert helix.length / MM == pytest.approx(math.hypot(2 * 2 * math.pi * 10, 2), rel=1e-4)
    np.testing.assert_allclose(helix.points[-1] / MM, [10, 0, -2], atol=1e-9)
    z = helix.points[:, 2] / MM  # the depth falls linearly with the angle over both turns
    assert np.all(np.diff(z) <= 1e-12) and z[len(z) // 2] == pytest.approx(-1.0, abs=0.01)


@pytest.mark.parametrize("plane", [17, 18, 19])
def test_arc_centres_absolute_and_incremental_give_the_same_arc(plane):
    (a, b, n), (oa, ob) = PLANES[plane]
    start, centre = np.array([3.0, 4.0, 5.0]), np.array([3.0, 4.0, 5.0])
    centre[a] += 6.0
    end = centre.copy()
    end[b] -= 6.0
    incremental = {oa: centre[a] - start[a], ob: centre[b] - start[b]}
    absolute = {oa: centre[a], ob: centre[b]}
    head = f"G21 G{plane}\nG0 {_xyz(start)}\n"
    arcs = [parse_program(head + mode + f"G3 {_xyz(end)} " + " ".join(f"{k}{v:g}" for k, v in given.items())
                          + " F100\n")[-1].points / MM
            for mode, given in (("G91.1\n", incremental), ("G90.1\n", absolute))]
    np.testing.assert_allclose(arcs[0], arcs[1], atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(arcs[0][:, [a, b]] - centre[[a, b]], axis=1), 6.0, atol=1e-6)


def test_work_offsets_place_the_program_where_the_config_says():
    offsets = {"G54": np.array([0.01, 0.0, 0.0]), "G55": np.array([0.0, 0.02, -0.005])}
    # switching the offset moves nothing: an axis the next move does not name stays where the tool is
    text = "G21 G90\nG0 X1 Y1 Z0\nG1 X2 F100\nG55\nG1 X3\nG1 X3 Y1 Z0\n"
    np.testing.assert_allclose(_points(text, offsets=offsets), [[11, 1, 0], [12, 1, 0], [3, 1, 0], [3, 21, -5]],
                               atol=1e-9)
    with pytest.raises(InputError, match="G56 selects a work offset whose place in W is not given"):
        parse_program("G21\nG56\nG1 X1 F100\n", offsets=offsets)


def test_named_origins_put_the_program_zero_on_the_block(tmp_path):
    (tmp_path / "p.nc").write_text("G21 G90\nG0 X0 Y0 Z2\nG1 Z-1 F100\nG1 X20 Y10\n")
    cell = {"block": [0.1, 0.06, 0.03], "floor": -1.0, "clearance": 0.01, "link_radius": 0.05, "tool_length": 0.1}
    expected = {"top_center": [0, 0, 0], "top_corner": [-0.05, -0.03, 0], "bottom_corner": [-0.05, -0.03, -0.03],
                (0.01, 0.02, 0.0): [0.01, 0.02, 0.0]}
    for origin, zero in expected.items():
        cfg = parse_config({"toolpath": {"kind": "gcode", "file": "p.nc", "origin": list(origin) if isinstance(
            origin, tuple) else origin}, "cell": cell, "design": ["placement"]}, tmp_path / "c.yaml", tmp_path)
        tp = problem_from_config(cfg).toolpath
        np.testing.assert_allclose(tp.points_W[0], np.array(zero) + [0, 0, 0.002], atol=1e-12)  # the plunge's start


def test_check_warns_when_the_cuts_are_not_in_the_block(tmp_path):
    # a program whose zero is the stock's bottom (NIST's circle-diamond-square sets it 2 inches below the top):
    # read with its zero on the top face, every cut lies above the block
    (tmp_path / "p.nc").write_text("G20 G90\nG0 X0 Y0 Z2.1\nG1 Z1.9 F10\nG1 X1 Y0.5\n")
    (tmp_path / "c.yaml").write_text(
        "toolpath: {kind: gcode, file: p.nc, origin: top_corner}\ndesign: [placement]\n"
        "cell: {block: [0.1, 0.06, 0.06], floor: -1.0, clearance: 0.01, link_radius: 0.05, tool_length: 0.1}\n")
    result = CliRunner().invoke(app, ["check", str(tmp_path / "c.yaml")])
    assert result.exit_code == 0, result.output
    assert "warning:" in result.output and "above the block's top face" in result.output
    assert "toolpath.origin" in result.output
    (tmp_path / "c.yaml").write_text((tmp_path / "c.yaml").read_text().replace("top_corner", "bottom_corner"))
    result = CliRunner().invoke(app, ["check", str(tmp_path / "c.yaml")])
    assert result.exit_code == 0 and "warning:" not in result.output, result.output


@pytest.mark.parametrize("depth,warning", [
    ("Z-1", None),
    ("Z2", r"no cutting move reaches into the block: the deepest cut is 2 mm above the block's top face"),
    ("Z-25", r"cutting moves go 5 mm below the block's bottom \(z = -0.02 m in W\)"),
])
def test_a_program_above_or_below_the_block_is_warned_about(tmp_path, depth, warning):
    """The block is 20 mm high with W on its top face: a program that never cuts into it, or cuts through its
    bottom, is accepted with a warning that names by how much (an ordinary pocket is not warned about)."""
    import warnings as w

    from designopt.errors import InputWarning

    (tmp_path / "p.nc").write_text(f"G21 G90\nG0 X0 Y0 Z5\nG1 {depth} F300\nG1 X10 F600\n")
    data = {"toolpath": {"kind": "gcode", "file": "p.nc", "spacing": 0.004}, "design": ["placement"],
            "placement": {"xyz": [0.45, 0.0, -0.2]},
            "cell": {"block": [0.04, 0.04, 0.02], "floor": -0.9, "clearance": 0.005, "link_radius": 0.05,
                     "tool_length": 0.1}}
    with w.catch_warnings(record=True) as caught:
        w.simplefilter("always")
        parse_config(data, tmp_path / "c.yaml", tmp_path)
    messages = [str(c.message) for c in caught if issubclass(c.category, InputWarning)]
    if warning is None:
        assert messages == []
    else:
        assert len(messages) == 1 and re.search(warning, messages[0]) and "toolpath.origin" in messages[0], messages
