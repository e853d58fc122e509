"""Every command in the README and docs/ is one a user can type today: a `designopt` command line parses with
today's options (and `designopt check` runs), a script exists and answers --help, a make target exists, a file it
names exists. A command that cannot be checked here (a cluster, a browser) says so with `(not checked)`.

Commands are the lines of ```bash blocks (a trailing `# comment` is not part of the command).
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from cli.main import app

ROOT = Path(__file__).resolve().parent.parent
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
PLACEHOLDER = re.compile(r"^(results/|RUN\d|ADDRESS|SOLUTION|CONFIG|FILE)")


def commands() -> list[tuple[str, str]]:
    """(doc, command line) of every line of every ```bash block."""
    out = []
    for doc in DOCS:
        block, pending = False, ""
        for line in doc.read_text().splitlines():
            if line.startswith("```"):
                block = line.strip() == "```bash"
                continue
            if not block or not line.strip() or line.lstrip().startswith("#"):
                continue
            pending += " " + line.strip()
            if pending.endswith("\\"):  # a command continued on the next line
                pending = pending[:-1]
                continue
            out.append((doc.name, pending.strip()))
            pending = ""
    return out


COMMANDS = commands()


def _split(line: str) -> list[str]:
    """The command's words: without a trailing comment, continuation backslashes, env assignments and timing."""
    words = shlex.split(line.split("  #")[0].replace("\\\n", " ").rstrip("\\"), posix=True)
    while words and (re.match(r"^[A-Z_]+=", words[0]) or words[0] in ("/usr/bin/time", "-v", "nice")):
        words = words[1:]
    return words


def _files_exist(words: list[str]) -> None:
    for w in words:
        if (w.startswith(("configs/", "benchmarks/", "tests/")) and not PLACEHOLDER.match(w)
                and re.search(r"\.(yaml|py|json|nc|csv|urdf)$", w)):
            assert (ROOT / w).exists(), f"{w} does not exist"


def test_the_docs_have_commands():
    assert len(COMMANDS) > 20


@pytest.mark.parametrize("doc,line", COMMANDS, ids=[f"{d}:{c[:60]}" for d, c in COMMANDS])
def test_every_documented_command_is_valid_today(doc, line):
    if "(not checked)" in line:
        return
    words = _split(line)
    assert words, line
    program, args = words[0], words[1:]
    _files_exist(words)
    if program == "designopt":
        group = typer.main.get_command(app)
        assert args and args[0] in group.commands, f"no command {args[:1]}"
        command = group.commands[args[0]]
        command.make_context(args[0], [a for a in args[1:] if not a.startswith("<")])  # parses every option
        if args[0] == "check":
            result = CliRunner().invoke(app, args)
            assert result.exit_code == 0, result.output
        return
    if program == "make":
        targets = re.findall(r"^([a-z-]+):", (ROOT / "Makefile").read_text(), re.MULTILINE)
        assert args and args[0] in targets, f"no make target {args[:1]}"
        return
    if program in ("python", ".venv/bin/python") and args[:2] == ["-m", "designopt.verify"]:
        import designopt.verify  # noqa: F401  (the module a user runs)

        return
    if program in ("python", ".venv/bin/python"):
        script = args[0]
        assert (ROOT / script).is_file(), f"no script {script}"
        proc = subprocess.run([sys.executable, str(ROOT / script), "--help"], cwd=ROOT, capture_output=True,
                              text=True, timeout=120)
        assert proc.returncode == 0, proc.stderr
        return
    if program in ("bash", "CI=true") and args and args[0] == ".ci/run":
        assert (ROOT / ".ci" / "run").is_file()
        return
    pytest.fail(f"{doc}: cannot check {line!r}: mark it '(not checked)' if it cannot be")
