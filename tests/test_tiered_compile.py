"""Tiered compilation of the per-waypoint blocks (`designopt.transcriptions.compiled`): a new block built at
`FIRST_TIER` (-O1) where first needed and final, or, when large, interpreted while gcc builds its -O0 library in the
background, then -O1 once the solves that used the -O0 library add up to the tier-up threshold. Most tests here set
`FIRST_TIER` to "O0" (the tiers as they were, which large blocks and libraries already in a cache still go through),
so that small blocks exercise the -O0 -> -O1 path; the last ones test the default (and
tests/test_split_compile.py a problem built cold by it). The levels must compute the same
numbers to the last bit (a solve may switch levels between runs and must not change), which is checked here against
the interpreted function as the independent truth."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import casadi as ca
import numpy as np
import pytest

from designopt.config import parse_config
from designopt.problem import problem_from_config
from designopt.solve import Seeded, SolverProfile, solve_guess
from designopt.transcriptions import Collocation
from designopt.transcriptions import compiled as compiled_module
from designopt.transcriptions.compiled import (
    built_together,
    compiled,
    interpreted_at,
    library_at,
    record_work,
    source_of,
    tier_up_after,
    tiered_up,
)
from designopt.transcriptions.hessian import block_hessian_function


@pytest.fixture(autouse=True)
def o0_first(monkeypatch):
    """-O0 first for small blocks too (see the module's doc); the tests of the default set it back."""
    monkeypatch.setattr(compiled_module, "FIRST_TIER", "O0")


def _stem(library):
    return library.with_name(library.name.split(".", 1)[0])


def _block_terms():
    """A 3R-like block: (y, s) -> (phi, c) with products of sines and cosines, the shape of a chain's terms."""
    y, s = ca.SX.sym("y", 6), ca.SX.sym("s", 2)
    pos = ca.vertcat(y[3] * ca.cos(y[0]) + y[4] * ca.cos(y[0] + y[1]) + y[5] * ca.cos(y[0] + y[1] + y[2]),
                     y[3] * ca.sin(y[0]) + y[4] * ca.sin(y[0] + y[1]) + y[5] * ca.sin(y[0] + y[1] + y[2]))
    phi = ca.sumsqr(y[3:] * ca.vertcat(ca.sin(y[1]), ca.cos(y[2]), s[0])) / (1 + ca.sumsqr(pos))
    return ca.Function("terms", [y, s], [phi, pos - s])


def _circle_problem(structure: str, waypoints: int):
    """A small task: a 0.1 m circle of ``waypoints`` waypoints for a generic ``structure`` arm."""
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": waypoints},
           "robot": {"structure": structure, "dh": "generic"}}
    return problem_from_config(parse_config(cfg))


def test_o0_and_o1_compute_the_same_bits(tmp_path, monkeypatch):
    """A Hessian block at -O0 and at -O1 gives identical doubles at 200 random points, and so does the interpreted
    function (CasADi's virtual machine runs the same IEEE operations in the same order as the generated C)."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    terms = _block_terms()
    levels = {mode: block_hessian_function(terms, 6, 2, mode) for mode in ("none", "O0", "O1")}
    rng = np.random.default_rng(7)
    for _ in range(200):
        args = [rng.normal(size=6), rng.normal(), rng.normal(size=2), rng.normal(size=2)]
        out = {mode: np.array(fn(*args)).ravel() for mode, fn in levels.items()}
        assert np.array_equal(out["O0"], out["O1"]) and np.array_equal(out["O0"], out["none"])


def _landed(libraries, level="O0", seconds=120.0) -> bool:
    """Whether every library's ``level`` build lands in the cache within ``seconds``."""
    deadline = time.time() + seconds
    while time.time() < deadline and not all(library_at(_stem(lib), level).exists() for lib in libraries):
        time.sleep(0.1)
    return all(library_at(_stem(lib), level).exists() for lib in libraries)


def test_a_small_block_waits_for_gcc_even_with_background_builds_on(tmp_path, monkeypatch):
    """A block whose C source is below `BACKGROUND_FROM_BYTES` is compiled at -O0 where it is first needed, as
    without background builds: its library is loaded at once and reported, nothing is interpreted."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    x = ca.SX.sym("x", 3)
    fn = ca.Function("blk8", [x], [ca.cos(x[0]) * ca.sumsqr(x) - x[1] / (2 + x[2] ** 2)])
    assert len(compiled_module._source(fn)) < compiled_module.BACKGROUND_FROM_BYTES
    used = []
    compiled(fn, "tiered", used)
    assert len(used) == 1 and used[0].name.endswith(".O0.so") and used[0].exists()
    assert not list(tmp_path.glob("*.lock"))


def test_a_new_large_block_is_interpreted_while_its_o0_library_builds(tmp_path, monkeypatch):
    """With background builds on, a block at or above `BACKGROUND_FROM_BYTES` (here: every block) the cache has no
    library of is the interpreted function at once, its C source kept and its -O0 build started; its marker is
    reported, `tiered_up` turns true once the library lands, and the next load is that library, computing the same
    bits."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    monkeypatch.setattr(compiled_module, "BACKGROUND_FROM_BYTES", 0)
    x = ca.SX.sym("x", 3)
    fn = ca.Function("blk6", [x], [ca.cos(x[0]) * ca.sumsqr(x) - x[1] / (2 + x[2] ** 2)])
    used = []
    first = compiled(fn, "tiered", used)
    stem = _stem(used[0])
    assert used == [interpreted_at(stem)] and source_of(stem).exists()
    assert _landed(used)
    assert tiered_up(used)
    again = []
    loaded = compiled(fn, "tiered", again)
    assert again == [library_at(stem, "O0")] and not tiered_up(again)
    rng = np.random.default_rng(3)
    for _ in range(50):
        x0 = rng.normal(size=3)
        assert np.array_equal(np.array(loaded(x0)), np.array(first(x0)))
    deadline = time.time() + 10  # the background shell removes its lock and directory just after the library lands
    while time.time() < deadline and (list(tmp_path.glob("*.lock")) or list(tmp_path.glob("build-*"))):
        time.sleep(0.05)
    assert not list(tmp_path.glob("*.lock")) and not list(tmp_path.glob("build-*"))


def test_tiered_up_waits_for_every_interpreted_block(tmp_path, monkeypatch):
    """An NLP whose blocks are interpreted is built again once all of them have a library, not once per block;
    one of its -O0 libraries gaining an -O1 one is enough, as before."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    a, b, c = (tmp_path / f"blk{k}_0123456789abcdef012{k}" for k in range(3))
    waiting = [interpreted_at(a), interpreted_at(b)]
    assert not tiered_up(waiting)
    library_at(a, "O0").write_bytes(b"")
    assert not tiered_up(waiting)
    library_at(b, "O1").write_bytes(b"")  # tiered up past -O0 (another process)
    assert tiered_up(waiting)
    assert not tiered_up([library_at(c, "O0")])
    library_at(c, "O1").write_bytes(b"")
    assert tiered_up([library_at(c, "O0"), interpreted_at(tmp_path / "blk9_0123456789abcdef0129")])


def test_a_failed_background_build_leaves_the_block_interpreted(tmp_path, monkeypatch):
    """A compiler that fails leaves a large block interpreted with its build's lock kept: the NLP is not built
    again and later loads start no build until the lock is stale."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    monkeypatch.setattr(compiled_module, "BACKGROUND_FROM_BYTES", 0)
    monkeypatch.setenv("CC", "false")
    x = ca.SX.sym("x", 2)
    fn = ca.Function("blk7", [x], [ca.sinh(x[0]) * x[1]])
    used = []
    compiled(fn, "tiered", used)
    stem = _stem(used[0])
    lock = library_at(stem, "O0").with_name(library_at(stem, "O0").name + ".lock")
    deadline = time.time() + 30
    while time.time() < deadline and list(tmp_path.glob("build-*")):
        time.sleep(0.1)
    assert lock.exists() and not library_at(stem, "O0").exists() and not tiered_up(used)
    mtime = lock.stat().st_mtime
    assert compiled(fn, "tiered", []) is not None and lock.stat().st_mtime == mtime


def _counting_compiler(tmp_path):
    """A compiler that notes how many of its copies run at once (in ``tmp_path/overlap``) and takes half a second
    before calling gcc."""
    cc = tmp_path / "counting-cc"
    cc.write_text(f'#!/bin/sh\nd={tmp_path}/running\nmkdir -p $d\ntouch $d/$$\nls $d | wc -l >> {tmp_path}/overlap\n'
                  'sleep 0.5\nrm -f $d/$$\nexec gcc "$@"\n')
    cc.chmod(0o755)
    return cc


def test_blocks_met_together_are_compiled_together_on_leaving(tmp_path, monkeypatch):
    """Inside `built_together` a missing block is its interpreted function and nothing is compiled; on leaving, every
    noted block is compiled, as many at once as the process has cores and never more, its source kept; a block met
    again then loads its library, computing the same bits."""
    cache = tmp_path / "cache"
    monkeypatch.setenv("DESIGNOPT_CACHE", str(cache))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    monkeypatch.setenv("CC", str(_counting_compiler(tmp_path)))
    x = ca.SX.sym("x", 3)
    fns = [ca.Function(f"blk1{k}", [x], [ca.cos(k * x[0]) * ca.sumsqr(x) - x[1] / (2 + x[2] ** 2)]) for k in range(3)]
    inside = []
    with built_together() as batch:
        for fn in fns:
            inside.append(compiled(fn, "tiered", []))
            inside.append(compiled(fn, "tiered", []))  # met twice (two blocks of one shape): built once
        assert not list(cache.glob("*.so"))
    assert all(f.class_name() == "SXFunction" for f in inside) and len(batch.here) == 6
    cores = len(os.sched_getaffinity(0))
    overlap = [int(v) for v in (tmp_path / "overlap").read_text().split()]
    assert len(overlap) == 3 and max(overlap) == min(cores, 3)
    rng = np.random.default_rng(5)
    for fn, first in zip(fns, inside[::2], strict=True):
        used = []
        loaded = compiled(fn, "tiered", used)
        assert loaded.class_name() == "External" and used[0].name.endswith(".O0.so")
        assert source_of(_stem(used[0])).exists()
        x0 = rng.normal(size=3)
        assert np.array_equal(np.array(loaded(x0)), np.array(first(x0)))
    assert len((tmp_path / "overlap").read_text().split()) == 3  # nothing compiled again
    assert not [d for d in cache.iterdir() if d.is_dir()]


def test_a_block_another_process_is_building_is_waited_for_not_built_twice(tmp_path, monkeypatch):
    """Two workers starting on one shape: a library whose lock another process holds is not compiled again on
    leaving `built_together` but waited for, and loaded once it lands; a lock whose holder never delivers is waited
    for only so long, and left alone."""
    import shutil
    import threading

    cache, elsewhere = tmp_path / "cache", tmp_path / "elsewhere"
    x = ca.SX.sym("x", 3)
    fn = ca.Function("blk31", [x], [ca.sin(x[0]) * ca.sumsqr(x)])
    mine = ca.Function("blk32", [x], [ca.cos(x[1]) * ca.sumsqr(x)])
    monkeypatch.setenv("DESIGNOPT_CACHE", str(elsewhere))
    theirs = []
    compiled(fn, "tiered", theirs)  # the other process's build, made beforehand
    monkeypatch.setenv("DESIGNOPT_CACHE", str(cache))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    monkeypatch.setenv("CC", str(_counting_compiler(tmp_path)))
    target = cache / theirs[0].name
    lock = target.with_name(target.name + ".lock")
    cache.mkdir()
    lock.write_bytes(b"")

    def deliver():
        time.sleep(1.0)
        shutil.copy(theirs[0], target.with_name(target.name + ".part"))
        os.replace(target.with_name(target.name + ".part"), target)
        lock.unlink()

    other = threading.Thread(target=deliver)
    other.start()
    with built_together() as batch:
        compiled(fn, "tiered", [])
        compiled(mine, "tiered", [])
    other.join()
    assert len(batch.here) == 2 and target.exists()
    assert len((tmp_path / "overlap").read_text().split()) == 1  # only its own block was compiled
    assert compiled(fn, "tiered", []).class_name() == "External"
    assert not list(cache.glob("*.lock"))
    gone = ca.Function("blk33", [x], [ca.tan(x[2]) * x[0]])
    with built_together() as batch:
        compiled(gone, "tiered", [])
    (source, library), = batch.here
    library.unlink()
    stuck = library.with_name(library.name + ".lock")
    stuck.write_bytes(b"")
    compiled_module._build_all(batch.here, wait_s=0.3)
    assert not library.exists() and stuck.exists()


def test_an_interrupted_batch_leaves_no_lock_behind(tmp_path, monkeypatch):
    """A batch interrupted while gcc runs (Ctrl-C) passes the interrupt on and releases the locks of every block it
    had taken, finished or not: a run started again at once builds them instead of waiting on a dead build."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    x = ca.SX.sym("x", 3)
    fns = [ca.Function(f"blk4{k}", [x], [ca.cosh(k * x[2]) * ca.sumsqr(x)]) for k in range(3)]
    with built_together() as batch:
        monkeypatch.setattr(compiled_module, "_build_all", lambda builds: None)  # noted, not built, on leaving
        for fn in fns:
            compiled(fn, "tiered", [])
    monkeypatch.undo()
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    finished = compiled_module._finish

    def interrupted(build, locked):
        finished(build, locked)
        raise KeyboardInterrupt

    monkeypatch.setattr(compiled_module, "_finish", interrupted)
    try:
        compiled_module._build_all(batch.here)
        raised = False
    except KeyboardInterrupt:
        raised = True
    assert raised and len(batch.here) == 3 and not list(tmp_path.glob("*.lock"))


def test_a_large_block_in_a_batch_goes_to_the_background_after_the_batch(tmp_path, monkeypatch):
    """A large block met inside `built_together` is interpreted and reported as before, but its background build
    starts only on leaving, after the batch's own builds; a compiler that fails leaves the batch's blocks
    interpreted where they are next met, nothing raised."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    monkeypatch.setattr(compiled_module, "BACKGROUND_FROM_BYTES", 0)
    x = ca.SX.sym("x", 2)
    fn = ca.Function("blk21", [x], [ca.tanh(x[0]) * x[1]])
    used = []
    with built_together() as batch:
        compiled(fn, "tiered", used)
        stem = _stem(used[0])
        assert used == [interpreted_at(stem)] and source_of(stem).exists()
        assert not list(tmp_path.glob("*.lock")) and not library_at(stem, "O0").exists()
    assert batch.later == [stem] and not batch.here
    assert _landed(used)
    monkeypatch.setattr(compiled_module, "BACKGROUND_FROM_BYTES", 10**9)
    monkeypatch.setenv("CC", "false")
    other = ca.Function("blk22", [x], [ca.tanh(x[1]) * x[0]])
    with built_together() as batch:
        compiled(other, "tiered", [])
    assert len(batch.here) == 1 and not list(tmp_path.glob("blk22*.so"))
    assert compiled(other, "tiered", []).class_name() == "SXFunction"


def test_a_problem_built_cold_loads_a_library_for_every_block(tmp_path, monkeypatch):
    """An NLP built with an empty cache compiles its blocks together and is then made with their libraries: every
    tiered block it reports is an -O0 library in the cache, every library compiled is one it loads, and its
    Hessian of the Lagrangian equals the interpreted one's to the bit."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    nlp = Collocation().build(_circle_problem("RRR", 5)).nlp
    _, pieces = nlp.derivatives("auto")
    reported = nlp.tiered_libraries("auto")
    assert reported and all(lib.name.endswith(".O0.so") and lib.exists() for lib in reported)
    assert set(reported) == set(tmp_path.glob("*.O0.so"))
    _, interpreted = nlp.derivatives("none")
    rng = np.random.default_rng(11)
    args = [rng.normal(size=nlp.n_variables), ca.DM(0, 1), 1.0, rng.normal(size=nlp.n_constraints)]
    compiled_h, interpreted_h = pieces["hess_lag"](*args), interpreted["hess_lag"](*args)
    assert np.array_equal(np.array(ca.DM(compiled_h)), np.array(ca.DM(interpreted_h)))


def test_a_cached_solver_is_built_again_once_its_blocks_have_libraries(tmp_path, monkeypatch):
    """A worker's solver prepared while its (large) blocks were interpreted is reused until their -O0 libraries
    land, then prepared anew at its next solve with them; a start solves the same to the bit either way."""
    from designopt.solve import local

    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    monkeypatch.setattr(compiled_module, "BACKGROUND_FROM_BYTES", 0)
    slow = tmp_path / "slow-cc"  # a compiler that takes its time: the first solve is surely interpreted
    slow.write_text('#!/bin/sh\nsleep 3\nexec gcc "$@"\n')
    slow.chmod(0o755)
    monkeypatch.setenv("CC", str(slow))
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 5}, "robot": {"structure": "RRR",
                                                                                    "dh": "generic"}}
    problem, profile = problem_from_config(parse_config(cfg)), SolverProfile(max_iter=40)
    built, solver, _ = local.prepared(problem, Collocation(), profile)
    waiting = built.nlp.tiered_libraries(profile.compile)
    assert waiting and all(lib.name.endswith(".none.so") for lib in waiting)
    guess = Seeded(0, 1).guess(problem)
    before = solve_guess(problem, Collocation(), profile, guess)
    assert local.prepared(problem, Collocation(), profile)[1] is solver  # still interpreted, reused
    assert _landed(waiting)
    again, fresh, spent = local.prepared(problem, Collocation(), profile)
    assert fresh is not solver and spent > 0
    assert all(lib.name.endswith(".O0.so") for lib in again.nlp.tiered_libraries(profile.compile))
    after = solve_guess(problem, Collocation(), profile, guess)
    assert after.raw.iterations == before.raw.iterations and np.array_equal(after.raw.q_d, before.raw.q_d)
    assert np.array_equal(after.raw.trajectory.Q, before.raw.trajectory.Q)
    assert np.array_equal(after.raw.trajectory.V, before.raw.trajectory.V)


def test_a_block_tiers_up_once_its_solves_reach_the_threshold(tmp_path, monkeypatch):
    """Below the threshold the -O0 library is loaded and reported as used; the solve that reaches it builds -O1
    (here in the foreground), after which the block loads at -O1, is no longer reported, and computes the same."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "1.0")
    x = ca.SX.sym("x", 3)
    fn = ca.Function("blk", [x], [ca.sin(x[0]) * ca.sumsqr(x) + x[1] * x[2]])
    used = []
    slow = compiled(fn, "tiered", used)
    assert len(used) == 1 and used[0].name.endswith(".O0.so") and source_of(_stem(used[0])).exists()
    assert record_work(used, 0.4, background=False) == []
    assert not library_at(_stem(used[0]), "O1").exists()
    assert record_work(used, 0.7, background=False) == used  # 1.1 s in all
    fast_library = library_at(_stem(used[0]), "O1")
    assert fast_library.exists()
    assert not list(tmp_path.glob("*.lock")) and not list(tmp_path.glob("build-*"))
    again = []
    fast = compiled(fn, "tiered", again)
    assert again == []  # loaded at -O1: nothing left to count
    x0 = np.array([0.3, -1.2, 0.7])
    assert np.array_equal(np.array(fast(x0)), np.array(slow(x0)))
    assert record_work(used, 5.0, background=False) == []  # already tiered up: nothing built twice


def test_tiering_never_and_a_lock_held_elsewhere(tmp_path, monkeypatch):
    """``never`` records and builds nothing; a build whose lock another process holds is left to it, and a lock
    older than the stale limit is taken over."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    x = ca.SX.sym("x", 2)
    used = []
    compiled(ca.Function("blk2", [x], [ca.cos(x[0]) * x[1]]), "tiered", used)
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "never")
    assert tier_up_after() is None
    assert record_work(used, 100.0, background=False) == [] and not list(tmp_path.glob("*.work"))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "0")
    target = library_at(_stem(used[0]), "O1")
    lock = target.with_name(target.name + ".lock")
    lock.touch()
    assert record_work(used, 1.0, background=False) == [] and not target.exists()
    old = time.time() - 3600
    os.utime(lock, (old, old))
    assert record_work(used, 1.0, background=False) == used and target.exists() and not lock.exists()


def test_a_solve_counts_towards_the_tier_up_and_the_background_build_lands(tmp_path, monkeypatch):
    """Solving with the default compile mode records the solve's seconds against each of the NLP's tiered
    libraries; at threshold 0 the first solve starts the detached -O1 builds, which land in the cache, and the
    next build of the same NLP loads them (nothing left to count)."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "0")
    problem = _circle_problem("RR", 6)
    nlp = Collocation().build(problem).nlp
    nlp.derivatives("auto")
    libraries = nlp.tiered_libraries("auto")
    assert len(libraries) >= 4 and all(lib.name.endswith(".O0.so") for lib in libraries)
    t0 = time.perf_counter()
    solve_guess(problem, Collocation(), SolverProfile(max_iter=50), Seeded(0, 0).guess(problem))
    wall = time.perf_counter() - t0
    records = list(tmp_path.glob("*.work"))
    assert len(records) == len(libraries)
    assert all(0 < float(r.read_text()) <= wall for r in records)  # the solve's own seconds, one line each
    deadline = time.time() + 120
    while time.time() < deadline and not all(library_at(_stem(lib), "O1").exists() for lib in libraries):
        time.sleep(0.2)
    assert all(library_at(_stem(lib), "O1").exists() for lib in libraries)
    fresh = Collocation().build(problem).nlp
    fresh.derivatives("auto")
    assert fresh.tiered_libraries("auto") == ()


def test_a_failed_build_is_not_retried_after_every_solve(tmp_path, monkeypatch):
    """A compiler that fails leaves no library and keeps the build's lock: the next solves do not start it again
    (until the lock is stale), and the -O0 library stays in use."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    x = ca.SX.sym("x", 2)
    used = []
    compiled(ca.Function("blk3", [x], [ca.exp(x[0]) * x[1]]), "tiered", used)
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "0")
    monkeypatch.setenv("CC", "false")
    target = library_at(_stem(used[0]), "O1")
    assert record_work(used, 1.0, background=False) == used  # started, and failed
    assert not target.exists() and target.with_name(target.name + ".lock").exists()
    assert not list(tmp_path.glob("build-*"))
    assert record_work(used, 1.0, background=False) == []


def test_a_tier_up_build_writes_its_temporary_files_in_its_own_directory(temp_keeping_compiler, monkeypatch):
    """gcc's temporary files of a tier-up build go into the build's working directory in the cache, which goes when
    the build ends, landed or failed: none reach the process's own ``TMPDIR``."""
    cache, own_tmp = temp_keeping_compiler
    x = ca.SX.sym("x", 2)
    used = []
    compiled(ca.Function("blk9", [x], [ca.exp(x[1]) * x[0]]), "tiered", used)
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "0")
    assert record_work(used, 1.0, background=False) == used
    assert library_at(_stem(used[0]), "O1").exists()
    assert not list(own_tmp.iterdir()) and not list(cache.glob("build-*")) and not list(cache.rglob("cckept*"))


def test_a_cache_that_cannot_be_written_leaves_the_solve_alone(tmp_path, monkeypatch):
    """Counting a solve never fails it: a record that cannot be written (here a directory in its place) is
    skipped and the block stays at -O0."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "0")
    x = ca.SX.sym("x", 2)
    used = []
    compiled(ca.Function("blk4", [x], [ca.tanh(x[0]) + x[1]]), "tiered", used)
    stem = _stem(used[0])
    stem.with_name(stem.name + ".work").mkdir()
    assert record_work(used, 1.0, background=False) == []
    assert not library_at(stem, "O1").exists()


def test_a_cached_solver_is_built_again_once_its_blocks_tier_up(tmp_path, monkeypatch):
    """A worker's cached solver whose blocks gained -O1 libraries (here built by hand, as another process would)
    is prepared anew at its next solve and loads them; until then the same solver is reused."""
    from designopt.solve import local

    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    cfg = {"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 5}, "robot": {"structure": "RR",
                                                                                    "dh": "generic"}}
    problem, profile = problem_from_config(parse_config(cfg)), SolverProfile(max_iter=20)
    built, solver, _ = local.prepared(problem, Collocation(), profile)
    libraries = built.nlp.tiered_libraries(profile.compile)
    assert libraries and local.prepared(problem, Collocation(), profile)[1] is solver
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "0")
    assert record_work(libraries, 1.0, background=False) == list(libraries)
    again, fresh, spent = local.prepared(problem, Collocation(), profile)
    assert fresh is not solver and spent > 0 and again.nlp.tiered_libraries(profile.compile) == ()
    assert local.prepared(problem, Collocation(), profile)[1] is fresh


def test_the_cache_command_counts_levels_and_records_and_clears(tmp_path, monkeypatch):
    """`designopt cache` reports a tiered block at -O0 counting its solves, then tiered up at -O1, and a file of
    no current kind (an older designopt's library); --clear-other removes only that one (not the KKT solver's
    library), --clear the rest."""
    from typer.testing import CliRunner

    from cli.main import app
    from designopt.transcriptions.compiled import cache_report

    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "2.5")
    x = ca.SX.sym("x", 2)
    used = []
    compiled(ca.Function("blk5", [x], [ca.sin(x[0]) * x[1]]), "tiered", used)
    (tmp_path / "waypoint_hessian_0123456789abcdef0123.so").write_bytes(b"old")
    (tmp_path / "ldl_0123456789abcdef0123.so").write_bytes(b"kkt")  # the KKT solver's library: a current kind
    record_work(used, 1.5, background=False)
    report = cache_report()
    assert report.libraries == {"O0": 1, "O1": 0, "O2": 0} and report.other == 1
    assert [s for _, s in report.counting] == [1.5] and report.tiered_up == 0
    record_work(used, 1.5, background=False)
    report = cache_report()
    assert report.libraries["O1"] == 1 and report.tiered_up == 1 and report.counting == ()
    runner = CliRunner()
    shown = runner.invoke(app, ["cache"])
    assert shown.exit_code == 0 and "at 2.5 s of solving" in shown.output and str(tmp_path) in shown.output
    assert runner.invoke(app, ["cache", "--clear-other"]).exit_code == 0
    assert cache_report().other == 0 and cache_report().libraries["O1"] == 1
    assert (tmp_path / "ldl_0123456789abcdef0123.so").exists()
    cleared = runner.invoke(app, ["cache", "--clear"])
    assert cleared.exit_code == 0 and "removed" in cleared.output and not list(tmp_path.iterdir())


def test_a_killed_builds_directory_is_cleared_once_stale(tmp_path, monkeypatch):
    """A build's working directory left by a process killed mid-build is a file of no current kind once untouched
    for `STALE_LOCK_S` (--clear-other removes it, with what is in it); a build's directory under way is not, and
    --clear removes it too."""
    from designopt.transcriptions.compiled import BUILD_DIR_PREFIX, cache_report, clear_cache

    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    dead, alive = tmp_path / f"{BUILD_DIR_PREFIX}dead", tmp_path / f"{BUILD_DIR_PREFIX}alive"
    for d in (dead, alive):
        d.mkdir()
        (d / "fn0_0.c").write_text("int f;")
        (d / "ccX.s").write_text("partial")
    old = time.time() - compiled_module.STALE_LOCK_S - 60
    os.utime(dead, (old, old))
    report = cache_report()
    assert report.other == 1 and report.bytes == 13
    assert clear_cache(only_other=True) == (2, 13)
    assert not dead.exists() and alive.exists() and cache_report().other == 0
    assert clear_cache() == (2, 13) and not list(tmp_path.iterdir())


def test_a_build_lock_of_a_process_that_died_is_taken_over(tmp_path, monkeypatch):
    """A foreground build's lock names its process: one left by a process that died mid-build (a sweep killed during
    gcc) is taken over and the library built, not waited for; a live process's lock, and a background build's lock
    (no process named) younger than `STALE_LOCK_S`, are waited for and left alone."""
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    x = ca.SX.sym("x", 2)
    source = compiled_module._source(ca.Function("blk9", [x], [ca.sin(x[0]) * x[1]]))
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    cases = {"dead": str(dead.pid), "alive": str(os.getpid()), "background": ""}
    for name, text in cases.items():
        library = tmp_path / f"blk9_{name}.O0.so"
        library.with_name(f"{library.name}.lock").write_text(text)
        compiled_module._build_all([(source, library)], wait_s=0.5)
        assert library.exists() == (name == "dead"), name
        assert library.with_name(f"{library.name}.lock").exists() == (name != "dead"), name


def test_a_new_block_is_built_at_the_first_tier_and_stays_there(tmp_path, monkeypatch):
    """With `FIRST_TIER` -O1 (the default) a new small tiered block gets an -O1 library where it is first needed,
    inside a batch or not: final, so it is not reported for the tier-up, no source is kept and no solve is counted;
    it computes what the interpreted function does. A large block is still interpreted while its -O0 library builds
    in the background, and without background builds it is built here at -O1 too."""
    monkeypatch.setattr(compiled_module, "FIRST_TIER", "O1")
    monkeypatch.setenv("DESIGNOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "60")
    x = ca.SX.sym("x", 3)
    alone = ca.Function("blk51", [x], [ca.cos(x[0]) * ca.sumsqr(x) - x[1] / (2 + x[2] ** 2)])
    batched = ca.Function("blk52", [x], [ca.sin(x[1]) * ca.sumsqr(x)])
    used = []
    first = compiled(alone, "tiered", used)
    with built_together() as batch:
        compiled(batched, "tiered", used)
    assert [library.name.split(".")[1] for _, library in batch.here] == ["O1"]
    second = compiled(batched, "tiered", used)
    assert used == [] and first.class_name() == second.class_name() == "External"
    assert sorted(p.name.split(".")[1] for p in tmp_path.glob("*.so")) == ["O1", "O1"]
    assert not list(tmp_path.glob("*.c.gz")) and not list(tmp_path.glob("*.work"))
    rng = np.random.default_rng(9)
    for _ in range(50):
        x0 = rng.normal(size=3)
        assert np.array_equal(np.array(first(x0)), np.array(alone(x0)))
        assert np.array_equal(np.array(second(x0)), np.array(batched(x0)))
    monkeypatch.setattr(compiled_module, "BACKGROUND_FROM_BYTES", 0)
    large = ca.Function("blk53", [x], [ca.tanh(x[2]) * ca.sumsqr(x)])
    reported = []
    compiled(large, "tiered", reported)
    assert reported == [interpreted_at(_stem(reported[0]))] and _landed(reported, "O0")
    monkeypatch.setenv("DESIGNOPT_TIER_UP_AFTER", "never")
    never = ca.Function("blk54", [x], [ca.exp(x[2]) * ca.sumsqr(x)])
    kept = []
    assert compiled(never, "tiered", kept).class_name() == "External" and kept == []
    assert [p.name.split(".")[1] for p in tmp_path.glob("blk54*.so")] == ["O1"]
