"""Real CNC programs (tests/data/gcode/SOURCES.md): every one is read unedited, with the cut and rapid lengths of a
second, independent reader (tests/gcode_reference.py), or refused with one line naming the line, the code and what
to do. No traceback, nothing dropped silently."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from gcode_reference import lengths
from typer.testing import CliRunner

from cli.main import app
from designopt.gcode import read_program

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / ".venv" / "gcode-corpus" / "carveracontroller" / "gcodes" / "Examples"
MM = 1e-3

ACCEPTED = ["LED/ABS-Base.nc", "LED/ALUMINUM-Button.nc", "LED/ACRYLIC-Carvera.nc", "LED/ACRYLIC-Face.nc",
            "LED/ACRYLIC-R2D2.nc", "LED/ACRYLIC-SpiderMan.nc", "LED/PCB-NO-UV-MASK.nc", "LED/PCB-UV-MASK(PART1).nc",
            "LED/PCB-UV-MASK(PART2).nc", "Laser/AudreyHepburnSmall.nc", "Relief/PirateShip.nc"]
LARGE = ["Laser/AudreyHepburn.nc"]  # 269,285 lines: `make test-slow`
REFUSED = {  # program -> (line, words in the reason)
    "LED/ACRYLIC-Balloon.nc": ("line 1878", "cannot read"),  # a corrupted line: G1Z-58145e87f0c3f3ee...
    "Rotation/NefertitiRough.nc": ("line 8", "A360: rotary and auxiliary axes are not read: post-process for three"),
    "Rotation/NefertitiFinish.nc": ("line 8", "A360: rotary"),
    "Tests/atc-test.nc": ("line 1", "cannot read 'ECHO"),
    "Tests/atc-fatigue-test.nc": ("line 1", "cannot read 'ECHO"),
    "Tests/board-test.nc": ("line 1", "cannot read 'ECHO"),
    "Tests/fatigue-test.nc": ("line 11", "G10: the program changes its coordinate system"),
    "Tests/spindle-test.nc": ("(file)", "no cutting move"),
}

pytestmark = pytest.mark.skipif(not CORPUS.is_dir(), reason="the corpus is installed by `make corpus`")


def test_the_corpus_is_the_one_described():
    found = {str(p.relative_to(CORPUS)) for p in CORPUS.rglob("*.nc")}
    assert found == set(ACCEPTED) | set(LARGE) | set(REFUSED)


def _compare(name: str) -> None:
    path = CORPUS / name
    moves = read_program(path, chord_tolerance=1e-8)
    cut = sum(m.length for m in moves if not m.rapid) / MM
    rapid = sum(m.length for m in moves if m.rapid) / MM
    ref_cut, ref_rapid = lengths(path.read_text())
    # CAM posts round arc centres to 1 um: an arc's end is then up to ~1 um off its start's circle, which designopt
    # follows as a spiral and the reference measures on the start's circle (1e-5 of the cut length here)
    assert cut == pytest.approx(ref_cut, rel=1e-4), name
    assert rapid == pytest.approx(ref_rapid, rel=1e-6, abs=1e-6), name
    assert cut > 100  # a real program: metres of cutting


@pytest.mark.parametrize("name", ACCEPTED)
def test_a_real_program_is_read_with_the_lengths_of_a_second_reader(name):
    _compare(name)


@pytest.mark.slow
@pytest.mark.parametrize("name", LARGE)
def test_a_large_real_program_is_read_with_the_lengths_of_a_second_reader(name):
    _compare(name)


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_a_program_a_cell_cannot_follow_is_one_line_naming_line_code_and_what_to_do(name, tmp_path):
    (tmp_path / "c.yaml").write_text(f"toolpath: {{kind: gcode, file: '{CORPUS / name}'}}\ndesign: [placement]\n")
    result = CliRunner().invoke(app, ["check", str(tmp_path / "c.yaml")])
    line, reason = REFUSED[name]
    assert result.exit_code == 2 and "Traceback" not in result.output, result.output
    out = [x for x in result.output.splitlines() if x.strip()]
    assert len(out) == 1 and f"{name.split('/')[-1]}: {line}: " in out[0] and reason in out[0], out[0]


def test_arcs_of_a_real_program_are_on_their_circles():
    """The Fusion program's arcs in the XY plane: every sample within 1 um of the circle through three of them (the
    posted centres are rounded to 1 um)."""
    moves = read_program(CORPUS / "LED/ALUMINUM-Button.nc", chord_tolerance=1e-5)
    arcs = [m for m in moves if len(m.points) > 4 and np.ptp(m.points[:, 2]) < 1e-12]
    assert len(arcs) > 10
    for m in arcs[:50]:
        p = m.points[:, :2]
        # the circle through three of its points; every sample on it
        a, b, c = p[0], p[len(p) // 2], p[-1]
        d = 2 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]))
        ux = ((a @ a) * (b[1] - c[1]) + (b @ b) * (c[1] - a[1]) + (c @ c) * (a[1] - b[1])) / d
        uy = ((a @ a) * (c[0] - b[0]) + (b @ b) * (a[0] - c[0]) + (c @ c) * (b[0] - a[0])) / d
        r = np.linalg.norm(p - [ux, uy], axis=1)
        assert np.ptp(r) < 1e-6
