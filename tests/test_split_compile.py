"""A long block's body compiled in parts (`designopt.transcriptions.compiled.split_statements`): gcc -O1 allocates
registers in time that grows faster than a function's length, so an -O1 build that a solve waits for cuts the
straight-line body CasADi generates into parts that share the values crossing them through one array. The parts run
the same IEEE operations in the same order, so the library must give the same bits as CasADi's own virtual machine
(the independent truth here), and it must really be the split C that gcc built (a library that fails to build falls
back to the interpreted function silently, which would make a bit test pass for nothing)."""

from __future__ import annotations

import re
import subprocess
import time
from types import SimpleNamespace

import casadi as ca
import numpy as np

from designopt.transcriptions import compiled as compiled_module
from designopt.transcriptions.compiled import built_together, compiled, split_statements


def _long_function(operations: int, name: str = "longblock") -> ca.Function:
    """(x[4], s) -> (y[3], z): a straight line of about ``operations`` SX operations mixing every kind CasADi writes
    as one C statement (arithmetic, sin/cos/exp/sqrt, fmin/fmax, fabs, sign), with two outputs written at different
    points of the body."""
    x, s = ca.SX.sym("x", 4), ca.SX.sym("s")
    values = [x[0], x[1], x[2], x[3], s]
    while len(values) < operations // 3:  # values reach 40 back: dozens live at once, CasADi's names padded (a08)
        a, b, c = values[-1], values[-3], values[-min(len(values), 40)]
        values.append(ca.sin(a) * b + ca.fmax(c, -0.5) / (1 + ca.fabs(a)))
        values.append(ca.sqrt(1 + b * b) - ca.exp(-ca.fmin(c * c, 4)) * ca.sign(a))
    first = ca.vertcat(values[40], values[len(values) // 2], values[-7])
    return ca.Function(name, [x, s], [first, values[-1] * values[-2]])


def _random_args(fn: ca.Function, rng) -> list[np.ndarray]:
    return [rng.normal(size=fn.sparsity_in(i).shape) for i in range(fn.n_in())]


def test_a_long_body_compiled_in_parts_gives_the_interpreted_bits(tmp_path, monkeypatch):
    """At -O1 a body above `SPLIT_FROM` statements is built in parts (the library's symbols show them), at -O0
    whole, and both libraries compute exactly what the interpreted function does at 300 random points."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    fn = _long_function(3 * compiled_module.SPLIT_FROM)
    source = compiled_module._source(fn)
    split = split_statements(source)
    parts = len(re.findall(r"static __attribute__\(\(noinline\)\) void casadi_f0_part\d+\(", split))
    statements = len(re.findall(r"^  (a\d+=|if \(res)", source, re.M))
    assert statements > compiled_module.SPLIT_FROM
    assert parts == -(-statements // compiled_module.SPLIT_EVERY)
    o1, o0 = compiled(fn, "O1"), compiled(fn, "O0")
    assert {p.name.split(".")[1] for p in tmp_path.glob("longblock_*.so")} == {"O0", "O1"}  # both really built
    assert o1.class_name() == o0.class_name() == "External"  # not the interpreted stand-in
    symbols = {level: subprocess.run(["nm", str(next(tmp_path.glob(f"longblock_*.{level}.so")))], check=True,
                                     capture_output=True, text=True).stdout for level in ("O0", "O1")}
    assert symbols["O1"].count("casadi_f0_part") == parts and "casadi_f0_part" not in symbols["O0"]
    rng = np.random.default_rng(11)
    for _ in range(300):
        args = _random_args(fn, rng)
        truth = [np.array(v) for v in fn(*args)]
        for level in (o1, o0):
            got = [np.array(v) for v in level(*args)]
            assert all(np.array_equal(t, g, equal_nan=True) for t, g in zip(truth, got, strict=True))


def test_split_parts_cover_every_statement_once_in_order():
    """The parts hold the body's statements in their order, each scalar a0012 written a[12] (not an octal literal)
    or as the part's local l12; a value read by a later part goes through the array, one read only within its part
    stays local; the function keeps its signature and its return."""
    fn = _long_function(900)
    source = compiled_module._source(fn)
    split = split_statements(source, every=7, least=10)
    body = re.findall(r"^  (?:a\d+=|if \(res).*;$", source, re.M)
    moved = re.findall(r"^  (?:a\[\d+\]=|l\d+=|if \(res).*;$", split, re.M)
    plain = [re.sub(r"\ba\[(\d+)\]|\bl(\d+)\b", lambda m: f"a{int(m.group(1) or m.group(2))}", line)
             for line in moved]
    assert plain == [re.sub(r"\ba(\d+)\b", lambda m: f"a{int(m.group(1))}", line) for line in body]
    assert not re.search(r"a\[0\d", split)
    parts = re.findall(r"void casadi_f0_part\d+\([^)]*\) \{\n(.*?)\n\}\n", split, re.S)
    assert len(parts) == -(-len(body) // 7)
    for k, part in enumerate(parts):
        defined = set()
        for line in part.split("\n")[1:]:  # after the part's declaration
            target, _, expression = line.partition("=") if not line.startswith("  if") else ("", "", line)
            assert set(re.findall(r"\bl\d+\b", expression)) <= defined  # a local is read only after its part set it
            defined |= set(re.findall(r"\bl\d+\b", target))
        later = "\n".join(parts[k + 1:])
        for stored in set(re.findall(r"\ba\[(\d+)\]=", part)):
            assert f"a[{stored}]" in later  # an array entry written for a later part
    assert any(re.search(r"\bl\d+=", part) for part in parts) and any("a[" in part for part in parts)
    assert "static int casadi_f0(const casadi_real** arg, casadi_real** res" in split
    assert split.count("  return 0;") == source.count("  return 0;")


def test_sources_of_other_shapes_are_left_whole():
    """A short body, a body with a branch, one that reads the work vector, a source of two functions and C that is
    not CasADi's come back as they were."""
    fn = _long_function(300)
    source = compiled_module._source(fn)
    assert len(re.findall(r"^  a\d+=", source, re.M)) < compiled_module.SPLIT_FROM
    assert split_statements(source) == source
    branched = source.replace("  return 0;", "  if (arg[0]) { a0001=1.0; }\n  return 0;", 1)
    assert split_statements(branched, every=7, least=10) == branched
    worked = source.replace("  return 0;", "  a0001=w[0];\n  return 0;", 1)
    assert split_statements(worked, every=7, least=10) == worked
    two = source + source.replace("casadi_f0", "casadi_f1")
    assert split_statements(two, every=7, least=10) == two
    assert split_statements("int main(void) { return 0; }\n", every=7, least=1) == "int main(void) { return 0; }\n"


def test_the_background_tier_up_compiles_the_body_whole(tmp_path, monkeypatch):
    """A tier-up, which no solve waits for, builds its -O1 library from the whole body (the faster library), and it
    gives the same bits as the interpreted function. (An -O0 library tiers up: a large block's, or here one built
    with `FIRST_TIER` -O0.)"""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setattr(compiled_module, "FIRST_TIER", "O0")
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    fn = _long_function(3 * compiled_module.SPLIT_FROM)
    used = []
    compiled(fn, "tiered", used)
    stem = used[0].with_name(used[0].name.split(".", 1)[0])
    assert compiled_module.tier_up(stem, background=False)
    library = compiled_module.library_at(stem, "O1")
    assert library.exists()
    assert "casadi_f0_part" not in subprocess.run(["nm", str(library)], check=True, capture_output=True,
                                                  text=True).stdout
    loaded = compiled(fn, "tiered")
    assert loaded.class_name() == "External"
    rng = np.random.default_rng(5)
    for _ in range(50):
        args = _random_args(fn, rng)
        assert all(np.array_equal(np.array(t), np.array(g), equal_nan=True)
                   for t, g in zip(fn(*args), loaded(*args), strict=True))


def test_a_problems_blocks_built_together_compile_in_parts(tmp_path, monkeypatch):
    """The blocks an NLP's build notes and compiles together on leaving `built_together` (gcc in parallel) are
    split like one built alone, and load as the same bits."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    fn = _long_function(3 * compiled_module.SPLIT_FROM)
    with built_together() as batch:
        stand_in = compiled(fn, "O1")
    assert batch.here and stand_in.class_name() != "External"
    library = next(tmp_path.glob("longblock_*.O1.so"))
    assert "casadi_f0_part" in subprocess.run(["nm", str(library)], check=True, capture_output=True, text=True).stdout
    loaded = compiled(fn, "O1")
    assert loaded.class_name() == "External"
    args = _random_args(fn, np.random.default_rng(2))
    assert all(np.array_equal(np.array(t), np.array(g)) for t, g in zip(fn(*args), loaded(*args), strict=True))


def test_a_long_body_built_from_several_files_gives_the_interpreted_bits(tmp_path, monkeypatch):
    """With a unit of 1,500 statements a body of about 6,000 is built from a file of the entry point and several
    files of parts (`translation_units`), each part defined once, all linked into one library: its symbols show the
    parts (local to the library), and it computes exactly what the interpreted function does at 300 random points."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setattr(compiled_module, "UNIT_STATEMENTS", 1500)
    fn = _long_function(3 * compiled_module.SPLIT_FROM)
    source = compiled_module._source(fn)
    units = compiled_module.translation_units(source)
    parts = len(re.findall(r"void casadi_f0_part\d+\(", split_statements(source)))
    group = 1500 // compiled_module.SPLIT_EVERY
    assert len(units) == 1 + -(-parts // group) >= 4
    defined = [re.findall(r"^__attribute__\(\(noinline, visibility\(\"hidden\"\)\)\) void (casadi_f0_part\d+)\(.*\{$",
                          unit, re.M) for unit in units]
    assert defined[0] == [] and sorted(sum(defined, []), key=lambda n: int(n[14:])) == [
        f"casadi_f0_part{k}" for k in range(parts)]
    assert all(len(names) <= group for names in defined)
    assert units[0].count(");\n") >= parts  # the entry point's file declares every part
    assert all("casadi_version" not in unit and "static casadi_real casadi_sq(" in unit for unit in units[1:])
    library = compiled(fn, "O1")
    assert library.class_name() == "External"  # built, not the interpreted stand-in
    symbols = subprocess.run(["nm", str(next(tmp_path.glob("longblock_*.O1.so")))], check=True, capture_output=True,
                             text=True).stdout
    local = re.findall(r" t casadi_f0_part\d+$", symbols, re.M)
    assert len(local) == parts and " T casadi_f0_part" not in symbols
    rng = np.random.default_rng(12)
    for _ in range(300):
        args = _random_args(fn, rng)
        truth = [np.array(v) for v in fn(*args)]
        got = [np.array(v) for v in library(*args)]
        assert all(np.array_equal(t, g, equal_nan=True) for t, g in zip(truth, got, strict=True))


def _logging_compiler(tmp_path, fail: str = "") -> str:
    """A C compiler that runs gcc, logging each run's start and end (to count how many ran at once) and failing
    when a file name ends with ``fail``."""
    script = tmp_path / "cc.sh"
    log = tmp_path / "cc.log"
    script.write_text("#!/bin/sh\n"
                      f'echo "start $$" >> {log}\n'
                      + (f'for a in "$@"; do case "$a" in *{fail}) echo "end $$" >> {log}; exit 1;; esac; done\n'
                         if fail else "")
                      + f'sleep 0.2; gcc "$@"; rc=$?\necho "end $$" >> {log}\nexit $rc\n')
    script.chmod(0o755)
    return str(script)


def test_a_batch_runs_as_many_compilers_at_once_as_it_has_cores(tmp_path, monkeypatch):
    """Two long blocks built together on two cores: their files are compiled two at a time, never more, and both
    libraries land with the right bits."""
    cache = tmp_path / "cache"
    monkeypatch.setenv("DESIGNOPT_CACHE", str(cache))
    monkeypatch.setattr(compiled_module, "UNIT_STATEMENTS", 1500)
    monkeypatch.setattr(compiled_module.os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    monkeypatch.setenv("CC", _logging_compiler(tmp_path))
    fns = [_long_function(3 * compiled_module.SPLIT_FROM + 60 * k, f"long{k}") for k in range(2)]
    with built_together():
        for fn in fns:
            compiled(fn, "O1")
    running, most = 0, 0
    for line in (tmp_path / "cc.log").read_text().split("\n"):
        running += {"start": 1, "end": -1}.get(line.split(" ")[0], 0)
        most = max(most, running)
    assert most == 2 and running == 0
    rng = np.random.default_rng(13)
    for fn in fns:
        library = compiled(fn, "O1")
        assert library.class_name() == "External"
        args = _random_args(fn, rng)
        assert all(np.array_equal(np.array(t), np.array(g)) for t, g in zip(fn(*args), library(*args), strict=True))


def test_a_file_that_fails_to_compile_leaves_the_block_interpreted(tmp_path, monkeypatch):
    """When one of a library's files fails to compile, no library lands and no lock is left: the block is the
    interpreted function, with the same values."""
    cache = tmp_path / "cache"
    monkeypatch.setenv("DESIGNOPT_CACHE", str(cache))
    monkeypatch.setattr(compiled_module, "UNIT_STATEMENTS", 1500)
    monkeypatch.setenv("CC", _logging_compiler(tmp_path, fail="_2.c"))
    fn = _long_function(3 * compiled_module.SPLIT_FROM)
    for inside in (False, True):
        if inside:
            with built_together():
                compiled(fn, "O1")
        block = compiled(fn, "O1") if not inside else None
        assert not list(cache.glob("*.so")) and not list(cache.glob("*.lock"))
        if block is not None:
            assert block.class_name() != "External"
            args = _random_args(fn, np.random.default_rng(14))
            assert all(np.array_equal(np.array(t), np.array(g)) for t, g in zip(fn(*args), block(*args), strict=True))
    assert "_1.c" in " ".join(compiled_module._build_steps(compiled_module._source(fn), "O1", tmp_path / "fn",
                                                           tmp_path / "x.so")[0][1])


def test_a_problem_built_cold_by_default_loads_final_o1_libraries(tmp_path, monkeypatch):
    """The default compile mode on a short path (``auto``: tiered) builds every block of a problem the cache lacks
    at -O1 where it is first needed (`FIRST_TIER`): the cache then holds -O1 libraries only, none is reported for a
    tier-up, and the Hessian of the Lagrangian equals the interpreted one's to the bit."""
    from designopt.config import parse_config
    from designopt.problem import problem_from_config
    from designopt.transcriptions import Collocation

    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 5}, "robot": {"structure": "RRR",
                                                                                    "dh": "generic"}}
    nlp = Collocation().build(problem_from_config(parse_config(cfg))).nlp
    assert compiled_module.level("auto", 5) == "tiered"
    _, pieces = nlp.derivatives("auto")
    assert nlp.tiered_libraries("auto") == ()
    libraries = [p for p in tmp_path.glob("*.so") if not p.name.startswith("ldl_")]
    assert libraries and {p.name.split(".")[1] for p in libraries} == {"O1"}
    assert not list(tmp_path.glob("*.c.gz"))
    _, interpreted = nlp.derivatives("none")
    rng = np.random.default_rng(15)
    args = [rng.normal(size=nlp.n_variables), ca.DM(0, 1), 1.0, rng.normal(size=nlp.n_constraints)]
    compiled_h, interpreted_h = pieces["hess_lag"](*args), interpreted["hess_lag"](*args)
    assert np.array_equal(np.array(ca.DM(compiled_h)), np.array(ca.DM(interpreted_h)))


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, ended but not yet reaped by its parent, does not)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def test_an_interrupted_build_leaves_no_compiler_or_temporary_file_behind(tmp_path, monkeypatch):
    """Interrupted while its compilers run (Ctrl-C), a build stops each compiler and the program it started (as gcc
    starts cc1), even one that ignores SIGTERM, and nothing they wrote to their temporary directory is left, in the
    cache or in the process's own ``TMPDIR``."""
    cache, own_tmp = tmp_path / "cache", tmp_path / "tmp"
    own_tmp.mkdir()
    monkeypatch.setenv("DESIGNOPT_CACHE", str(cache))
    monkeypatch.setenv("TMPDIR", str(own_tmp))
    monkeypatch.setattr(compiled_module, "UNIT_STATEMENTS", 1500)
    monkeypatch.setattr(compiled_module.os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    log = tmp_path / "pids.log"
    # writes a temporary file as gcc does, then waits on a child as gcc on cc1, one that ignores SIGTERM
    script = tmp_path / "slowcc.sh"
    script.write_text("#!/bin/sh\n"
                      'echo partial > "${TMPDIR:-/tmp}/ccslow$$.s"\n'
                      f'(trap "" TERM; sleep 60) & echo "$$ $!" >> {log}\nwait\n')
    script.chmod(0o755)
    monkeypatch.setenv("CC", str(script))
    real_sleep, interrupted = time.sleep, []

    def interrupt_once_started(seconds):
        if not interrupted and log.exists() and len(log.read_text().split("\n")) > 2:  # both compilers and
            interrupted.append(True)                                                  # their children are up
            raise KeyboardInterrupt
        real_sleep(seconds)

    monkeypatch.setattr(compiled_module, "time", SimpleNamespace(time=time.time, sleep=interrupt_once_started))
    fn = _long_function(3 * compiled_module.SPLIT_FROM)
    try:
        with built_together():
            compiled(fn, "O1")
        raised = False
    except KeyboardInterrupt:
        raised = True
    pids = [int(p) for p in log.read_text().split()]
    assert raised and len(pids) == 4
    deadline = time.time() + 5.0  # a signal is delivered, not obeyed at once: on a loaded machine give it seconds
    while any(_alive(pid) for pid in pids) and time.time() < deadline:
        time.sleep(0.05)
    assert not any(_alive(pid) for pid in pids)
    assert not list(own_tmp.iterdir()) and not list(cache.rglob("ccslow*")) and not list(cache.glob("*.lock"))
