"""Compile small CasADi functions to C, with an on-disk cache keyed by their serialised graphs.

Only per-waypoint functions are compiled (a few thousand lines of C, seconds); compiling a whole NLP
takes minutes. The cache lives in ``$DESIGNOPT_CACHE`` or ``~/.cache/designopt`` and is safe to share
between processes: each library is written under a temporary name and renamed into place.

A problem's blocks the cache lacks are compiled together (`built_together`, what an NLP's build does): gcc runs
on as many of them at once as there are cores, and a library another process is already building (two workers
starting on one shape) is waited for, not built twice.

Tiered compilation (level ``tiered``, what ``auto`` gives a block evaluated at few points): a block the cache has no
library of yet is compiled at `FIRST_TIER` (-O1) where it is first needed, and that library is final; or, when its
C source is large (`BACKGROUND_FROM_BYTES`: a cell's Hessian block), it is interpreted at once while gcc builds its
-O0 library in a detached background process; later builds, in any process, load that library (a worker's cached
solver is built again once all of its blocks have theirs: `tiered_up`). Every solve that used an -O0 library adds
its seconds to the block's record in the cache, and once those reach `tier_up_after` seconds the same C source is
compiled again at -O1 in the background (its body whole), which later builds load instead (`designopt cache` shows
where each block stands). Every library is compiled with ``-ffp-contract=off`` (and never with -ffast-math), so
CasADi's virtual machine, -O0 and -O1 compute the same IEEE operations in the same order: a solve is the same to the
last bit at any level, only faster compiled (an exploration iteration of the main job 0.70x at -O1), and a first
build need not wait for a long compile. With `tier_up_after` ``never`` nothing is built in the background: a tiered
block is compiled at `FIRST_TIER` where it is first needed. A build that a
solve waits for (a block at -O1 from `AUTO_O1_FROM` points, or a profile's ``compile="O1"``) compiles a long
block's body in parts (`split_statements`), a quarter to a seventh of gcc's time for the same bits, the parts
grouped into several files that gcc compiles at once on the cores and links into one library (`translation_units`).
"""

from __future__ import annotations

import gzip
import hashlib
import os
import re
import shlex
import shutil
import signal
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager, suppress
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path

import casadi as ca

COMPILE_MODES = ("none", "O0", "O1", "O2", "auto")
GENERATOR = {"with_header": False}  # CasADi's code generator options (part of the cache key)
# gcc's flags besides the level (part of the cache key): no fused multiply-adds, so that every level rounds alike
FLAGS = ("-fPIC", "-shared", "-ffp-contract=off")
# Mode ``auto``: a block evaluated at this many points or more per call is compiled at O1, any other at O0. At -O0
# a cell's clearance Hessian block takes 3x as long per point as at -O1 (82 against 26 us, the pocket cell's PUMA)
# and is most of an iteration on a long program, but gcc -O1 takes about 8 s for it (its body in parts; 35-60 s
# whole) against 3 s: once per block and machine (the cache), paid back within one solve from some 500 points (a
# program of 250 waypoints with a cell).
# Below it, ``tiered``: `FIRST_TIER` where first needed, or for a large block -O0 first and O1 once it has been
# solved with long enough to pay for it (module doc).
AUTO_O1_FROM = 500
# The level a tiered block the cache has no library of is built at where it is first needed, unless its C source is
# large (`BACKGROUND_FROM_BYTES`): -O1, a long body in parts on the cores (`translation_units`), and then final. On
# two cores the main job's blocks build in 2.4-2.5 s instead of 1.5 s at -O0, and a cold default run
# (`designopt run configs/milling.yaml`) takes 0.78x the wall of one that starts at -O0 and tiers up
# (docs/decisions.md, Speed, 2026-12-07). "O0": the tiers as they were (-O0 first, -O1 after `TIER_UP_AFTER`).
FIRST_TIER = "O1"
# Seconds of solves with an -O0 library after which its -O1 build starts (a large block's, `BACKGROUND_FROM_BYTES`, or
# one built with `FIRST_TIER` "O0"): the solving whose -O0 penalty (about a fifth of it on the main job) adds up to
# what gcc -O1 takes for the main job's blocks whole (about 10 s) -- the ski-rental rule, which never costs more than
# twice what knowing the future would.
# `DESIGNOPT_TIER_UP_AFTER` (seconds, or ``never``) overrides it.
TIER_UP_AFTER = 60.0
# A tiered block whose C source has this many bytes or more, and no library yet, is interpreted while gcc builds its
# -O0 library in the background; a smaller one waits for gcc here. gcc -O0 takes about 2 us per byte (0.35 s at
# 0.23 MB, 1.1 s at 0.54 MB, 9.5 s at 4.7 MB): the main job's Hessian block (0.96 MB, about 2 s) and every sweep
# structure's and modular assignment's wait; a cell's (the pocket cell's 1.95 MB, about 4 s) does not. Interpreted
# solves cost 2-4x a compiled Hessian call and the background gcc runs beside busy workers, so the wait is worth
# skipping only where it is long: measured, the pocket cell's cold build 5.2-6.1 -> 1.5 s, while the modular
# experiment's many small shapes lost 1.26-1.47x with every block backgrounded (docs/decisions.md).
BACKGROUND_FROM_BYTES = 1_500_000
# A build at -O1 or -O2 that a solve waits for compiles a block's straight-line body in parts of this many
# statements (`split_statements`): gcc's register allocation takes time that grows faster than the length of the
# function it allocates, and a block is one function of up to 83,000 statements (a cell's Hessian block). In
# parts, gcc -O1 takes 2.7 s of CPU instead of 10 s for the main job's Hessian block and 5.9 s instead of 39 s for
# a cell's; a call of the main job's block costs 1.04x (the exploration's iteration 1.03x), the cell's 0.96x
# (docs/decisions.md, Speed, 2026-12-07). A background build (the tier-up, `build_later`), which no solve waits
# for, compiles the body whole, and so does -O0 (in parts slower to build and to run).
SPLIT_EVERY = 150
SPLIT_FROM = 2000  # statements: a shorter body compiles in a second or two whole
# A split body's parts are compiled as files of about this many statements each, as many at once as there are cores,
# and linked into one library (`translation_units`): on two cores the pocket cell's Hessian block (1.95 MB of C)
# builds at -O1 in 3.5 s instead of 6.6 s, the same code (a call 24.4-24.6 against 25.6-26.2 us a point).
UNIT_STATEMENTS = 6000
STALE_LOCK_S = 1800.0  # a tier-up lock older than this is taken to be from a build that died
BUILD_DIR_PREFIX = "build-"  # a build's working directory in the cache (`_run_builds`): its C, objects, gcc temporaries


@dataclass
class BuildBatch:
    """The library builds that `compiled_as` noted instead of running them, inside `built_together`: (C source,
    library) pairs to compile here, and the stems of large blocks whose -O0 build goes to the background after
    them."""

    here: list[tuple[str, Path]] = field(default_factory=list)
    later: list[Path] = field(default_factory=list)


# The batch of the innermost `built_together` of this thread or task, if any (a context variable, so that each
# thread's builds are its own).
_BATCH: ContextVar[BuildBatch | None] = ContextVar("designopt_build_batch", default=None)


@contextmanager
def built_together() -> Iterator[BuildBatch]:
    """Within it, a library `compiled_as` would build where it is met is only noted (its C source generated) and the
    interpreted function stands in for it; on leaving, every noted build runs at once, gcc processes in parallel
    on the machine's cores, longest first, and only then do the noted background builds start. A problem's
    small blocks thus cost the longest of their compiles, not their sum, and the background build of a large one
    does not take a core from them. The batch yielded is non-empty when functions made inside hold interpreted
    stand-ins: made again, they load the libraries (`designopt.transcriptions.nlp.NLP.derivatives`)."""
    batch = BuildBatch()
    token = _BATCH.set(batch)
    try:
        yield batch
    finally:
        _BATCH.reset(token)
        try:
            _build_all(batch.here)
        except OSError:  # a cache that cannot be written: the blocks are built, or interpreted, where next met
            pass
        for stem in batch.later:
            build_later(stem, "O0")


def level(mode: str, points: int) -> str:
    """The compile level of one block function evaluated at ``points`` points per call under ``mode``: ``auto`` is
    O1 from `AUTO_O1_FROM` points and ``tiered`` below; any other mode is itself."""
    if mode != "auto":
        return mode
    return "O1" if points >= AUTO_O1_FROM else "tiered"


def tier_up_after() -> float | None:
    """Seconds of solves after which a tiered library is built at -O1 (`TIER_UP_AFTER`, or the environment's
    ``DESIGNOPT_TIER_UP_AFTER``); None: never."""
    text = os.environ.get("DESIGNOPT_TIER_UP_AFTER", "").strip().lower()
    if not text:
        return TIER_UP_AFTER
    if text == "never":
        return None
    try:
        return max(float(text), 0.0)
    except ValueError:
        return TIER_UP_AFTER


def cache_dir() -> Path:
    path = Path(os.environ.get("DESIGNOPT_CACHE", Path.home() / ".cache" / "designopt"))
    path.mkdir(parents=True, exist_ok=True)
    return path


def compiled(fn: ca.Function, mode: str = "O0", used: list[Path] | None = None) -> ca.Function:
    """Return ``fn`` evaluated as compiled C (level O0/O1/O2/tiered; ``auto`` is resolved by `level` first), or
    unchanged for mode ``none``. ``used``: see `compiled_as`.

    Falls back to the interpreted function if no C compiler works, so a machine without gcc is slower,
    not broken.
    """
    return compiled_as(fn.name(), fn.serialize(), lambda: fn, mode, used)


def compiled_as(name: str, identity: str, derive: Callable[[], ca.Function], mode: str = "O0",
                used: list[Path] | None = None) -> ca.Function:
    """The function ``derive()`` (named ``name``) as compiled C, found in the cache by ``identity`` -- any text
    that determines the function, e.g. its serialised graph, or the small graph it is derived from and how --
    so that a function found there is never derived (its symbolic derivation and serialisation are most of a
    warm build). Mode ``none``: ``derive()`` itself. Level ``tiered``: the -O1 library if the cache has it, else
    the -O0 one (its C source kept beside it for the tier-up), whose path is appended to ``used`` so that the
    solves that use it can be counted (`record_work`); with neither in the cache, the `FIRST_TIER` library built
    here (final: not appended), or, for C source of `BACKGROUND_FROM_BYTES` or more, ``derive()`` itself while its
    -O0 library is built in the background (`build_later`), with its `interpreted_at` marker appended to ``used``
    (`tiered_up` tells when the library has landed). Without background builds (`tier_up_after` None) every
    library is built here."""
    if mode == "none":
        return derive()
    if mode not in ("O0", "O1", "O2", "tiered"):
        raise ValueError(f"a block compiles at none, O0, O1, O2 or tiered (auto is resolved by level), got {mode!r}")
    # Serialised graphs are deterministic across processes; hashing one is 4-6x cheaper than generating its C,
    # which is only needed when the library is missing (0.58 s of the pocket cell's warm build).
    key = hashlib.sha256(f"{identity}|{ca.__version__}|{GENERATOR}|{FLAGS}".encode()).hexdigest()[:20]
    stem = cache_dir() / f"{name}_{key}"
    tiered = mode == "tiered"
    if tiered and library_at(stem, "O1").exists():
        return ca.external(name, str(library_at(stem, "O1")))
    mode = "O0" if tiered else mode
    library = library_at(stem, mode)
    if not library.exists():
        fn = derive()
        background = tiered and tier_up_after() is not None
        batch = _BATCH.get()
        try:
            if background and source_of(stem).exists():  # a large block whose -O0 build is under way (or died)
                return _interpreted_meanwhile(stem, fn, used)
            source = _source(fn)
            if background and len(source) >= BACKGROUND_FROM_BYTES:
                _keep_source(stem, source)
                return _interpreted_meanwhile(stem, fn, used)
            if tiered:  # its first library: final at -O1, or an -O0 one that tiers up
                mode, library = FIRST_TIER, library_at(stem, FIRST_TIER)
            if batch is not None:  # built on leaving `built_together`, with the batch's other blocks
                batch.here.append((source, library))
                return fn
            _build(source, library, mode)
        except (OSError, subprocess.CalledProcessError):
            return fn
        if mode == "O0":  # kept for a tier-up
            _keep_source(stem, source)
    if tiered and used is not None and source_of(stem).exists():
        used.append(library)
    return ca.external(name, str(library))


def _interpreted_meanwhile(stem: Path, fn: ca.Function, used: list[Path] | None) -> ca.Function:
    """``fn``, interpreted while the block's -O0 library is built from its kept C source in the background (a build
    under way in this or another process is left to it: `build_later`'s lock; inside `built_together`, started on
    leaving it), its `interpreted_at` marker appended to ``used``."""
    batch = _BATCH.get()
    if batch is None:
        build_later(stem, "O0")
    elif stem not in batch.later:
        batch.later.append(stem)
    if used is not None:
        used.append(interpreted_at(stem))
    return fn


def library_at(stem: Path, mode: str) -> Path:
    """The cache's library of ``stem`` (``<cache>/<name>_<key>``) compiled at level ``mode``."""
    return stem.with_name(f"{stem.name}.{mode}.so")


def interpreted_at(stem: Path) -> Path:
    """The marker that stands for ``stem``'s block interpreted while its -O0 library is built (no such file)."""
    return stem.with_name(f"{stem.name}.none.so")


def source_of(stem: Path) -> Path:
    """The gzipped C source kept beside a tiered library, for its -O1 build."""
    return stem.with_name(f"{stem.name}.c.gz")


def _stem(library: Path) -> Path:
    return library.with_name(library.name.split(".", 1)[0])


def record_work(libraries: Iterable[Path], seconds: float, background: bool = True) -> list[Path]:
    """Count ``seconds`` of solving towards the tier-up of each tiered block in ``libraries`` (paths that
    `compiled_as` appended to its ``used``: -O0 libraries and interpreted markers), and start the -O1 build of
    each whose count has reached `tier_up_after` (in a detached background process unless ``background`` is false;
    one process builds it, others find its lock). Returns the libraries whose -O1 build this call started."""
    after = tier_up_after()
    started = []
    for library in dict.fromkeys(libraries):  # once each, in order
        stem = _stem(library)
        if after is None or library_at(stem, "O1").exists():
            continue
        record = stem.with_name(f"{stem.name}.work")
        try:
            with open(record, "a") as fh:  # one short line per solve: appends from several processes do not mix
                fh.write(f"{seconds:.3f}\n")
            total = sum(float(v) for v in record.read_text().split() if _is_number(v))
        except OSError:  # a cache that cannot be written (read-only, full): the block stays at -O0
            continue
        if total >= after and tier_up(stem, background):
            started.append(library)
    return started


def tiered_up(libraries: Iterable[Path]) -> bool:
    """Whether these tiered blocks (`compiled_as`'s ``used``) load faster by now: any -O0 library has an -O1 one
    in the cache, or every interpreted block (`interpreted_at`) has a library (a stat or two each). One rebuild
    per NLP once its blocks have all landed, not one per block."""
    libraries = list(libraries)
    waiting = [lib for lib in libraries if lib.name.endswith(".none.so")]
    if waiting and all(library_at(_stem(lib), "O0").exists() or library_at(_stem(lib), "O1").exists()
                       for lib in waiting):
        return True
    return any(library_at(_stem(lib), "O1").exists() for lib in libraries if lib not in waiting)


def tier_up(stem: Path, background: bool = True) -> bool:
    """Build ``stem``'s kept C source at -O1 (`build_later`)."""
    return build_later(stem, "O1", background)


def build_later(stem: Path, level: str, background: bool = True) -> bool:
    """Build ``stem``'s kept C source at ``level`` into its library (atomically: in a working directory of its own
    in the cache, where gcc also writes its temporary files, then renamed into place), in a detached background
    process, or here when ``background`` is false. False when there is no source, or another process holds the
    build's lock. A build that fails keeps its lock, so that it is tried again only once the lock is stale
    (`STALE_LOCK_S`), not after every solve; one that is killed leaves its directory (`_dead_build`)."""
    source, target = source_of(stem), library_at(stem, level)
    lock = _lock_of(target)
    if not source.exists() or not _take(lock):
        return False
    work = None
    q = shlex.quote
    try:
        work = Path(tempfile.mkdtemp(dir=target.parent, prefix=BUILD_DIR_PREFIX))
        tmp, c_file = work / target.name, work / f"{stem.name}.c"
        c_file.write_bytes(gzip.decompress(source.read_bytes()))
        out = q(str(tmp))
        build = (f"TMPDIR={q(str(work))} {shlex.join(_compile_command([c_file], tmp, level))} && "
                 f"mv -f {out} {q(str(target))} && rm -f {q(str(lock))}; rm -rf {q(str(work))}")
        # in the background the shell returns at once and the build, orphaned, outlives this process
        command = f"({build}) >/dev/null 2>&1" + (" &" if background else "")
        subprocess.run(["sh", "-c", command], check=False, stdin=subprocess.DEVNULL)
    except (OSError, EOFError, gzip.BadGzipFile):
        if work is not None:
            shutil.rmtree(work, ignore_errors=True)
        lock.unlink(missing_ok=True)
        return False
    return True


def _take(lock: Path, holder: bool = False) -> bool:
    """Create ``lock`` if no other process holds it. With ``holder``, this process's id is written into it: the
    process itself builds and releases it (`_build_all`), so a lock whose process is gone (a sweep killed during a
    build) is taken over at once; a lock without a process id (a background build, whose shell outlives the process
    that took it) only once it is older than `STALE_LOCK_S`."""
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            if holder:
                os.write(fd, str(os.getpid()).encode())
            os.close(fd)
            return True
        except FileExistsError:
            try:
                if _held(lock):
                    return False
                lock.unlink()
            except FileNotFoundError:
                pass
    return False


def _held(lock: Path) -> bool:
    """Whether ``lock`` exists and its build may still be under way: its process (when it names one) is alive, or
    (when it names none) it is younger than `STALE_LOCK_S`."""
    try:
        text = lock.read_text().strip()
        if text.isdigit():
            os.kill(int(text), 0)  # raises if no such process
            return True
        return time.time() - lock.stat().st_mtime < STALE_LOCK_S
    except ProcessLookupError:
        return False
    except PermissionError:  # a process of another user holds it
        return True
    except FileNotFoundError:
        return False


def _is_number(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


def _write_atomically(path: Path, data: bytes) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name)
    with os.fdopen(fd, "wb") as fh:
        fh.write(data)
    os.replace(tmp, path)


def _source(fn: ca.Function) -> str:
    """The C source of ``fn`` (CasADi's code generator with ``GENERATOR`` options)."""
    with tempfile.TemporaryDirectory() as tmp:
        gen = ca.CodeGenerator(f"{fn.name()}.c", GENERATOR)
        gen.add(fn)
        return Path(gen.generate(tmp + os.sep)).read_text()


_DECLARATION = re.compile(r"  casadi_real a\d+(, a\d+)*;")
_ASSIGNMENT = re.compile(r"  a(\d+)=([^{};]*);")
_OUTPUT = re.compile(r"  if \(res\[\d+\]!=0\) res\[\d+\]\[\d+\]=[^{};]*;")
_SCALAR = re.compile(r"\ba(\d+)\b")
_WORK = re.compile(r"\b(i?w|mem)\b")  # casadi_f0's other arguments: a body that uses them stays whole


def split_statements(source: str, every: int = SPLIT_EVERY, least: int = SPLIT_FROM) -> str:
    """CasADi's C of one SX function whose body is straight-line code (scalars ``a0000, a0001, ...`` declared,
    then one assignment or output write per line), with that body split into ``static`` parts of ``every``
    statements called in order. A value used only within its part stays a local of the part (a register, as
    before); one used by a later part is written to an array on the stack that the parts share, and read from it
    there. The same operations in the same order: the same bits (`FLAGS` has no contraction), only compiled
    faster at -O1 (`SPLIT_EVERY`). A body of fewer than ``least`` statements, or C of any other shape (more than
    one function, a work vector, a branch), is returned as it is."""
    split = _split_parts(source, every, least)
    return source if split is None else _one_file(*split)


def translation_units(source: str, every: int = SPLIT_EVERY, least: int = SPLIT_FROM,
                      per_unit: int | None = None) -> list[str]:
    """`split_statements`'s C as several files that gcc compiles at once on several cores and links into one
    library: the first keeps everything CasADi wrote but the parts' bodies (it declares them); each further file
    defines consecutive parts of about ``per_unit`` statements in all, after CasADi's preamble up to its exported
    functions with its helpers (``casadi_sq``, ...) made ``static``, so that each file inlines them as one file
    would. The parts are ``hidden``: a library's parts are its own. The same functions compiled with the same
    flags: the same bits as the one file (`tests/test_split_compile.py`). One file, as `split_statements`
    returns it, when the body is not split, fits one unit, or the preamble is not of the shape expected.
    ``per_unit``: `UNIT_STATEMENTS` unless given."""
    split = _split_parts(source, every, least)
    if split is None:
        return [source]
    head, signature, tail, count, parts = split
    preamble, marker, _ = source.partition(_EXPORTED)
    group = max((UNIT_STATEMENTS if per_unit is None else per_unit) // every, 1)
    if not marker or len(preamble) >= len(head) or len(parts) <= group:
        return [_one_file(*split)]
    declared = "".join(f"{_SHARED_PART}void casadi_f0_part{k}{_PART_SIGNATURE};\n" for k in range(len(parts)))
    main = head + declared + _entry(signature, count, len(parts)) + tail
    shared = _HELPER.sub(r"static \1", preamble)
    units = ["".join(_part_definition(k, parts[k], "") for k in range(first, min(first + group, len(parts))))
             for first in range(0, len(parts), group)]
    return [main, *(shared + unit for unit in units)]


_EXPORTED = "/* Configuration this file was compiled with */"  # CasADi's preamble ends here; exported functions follow
_HELPER = re.compile(r"^((?:casadi_real|casadi_int|int|void) casadi_\w+\()", re.M)
_PART_SIGNATURE = "(const casadi_real** arg, casadi_real** res, casadi_real* restrict a)"
_SHARED_PART = '__attribute__((noinline, visibility("hidden"))) '  # a part another file calls


def _one_file(head: str, signature: str, tail: str, count: int, parts: list[str]) -> str:
    """`_split_parts`'s analysis as one file of ``static`` parts (`split_statements`)."""
    defined = "".join(_part_definition(k, part, "static ") for k, part in enumerate(parts))
    return head + defined + _entry(signature, count, len(parts)) + tail


def _part_definition(k: int, part: str, storage: str) -> str:
    """Part ``k``'s definition: ``static`` (one file) or shared between the library's files (``storage`` "")."""
    attributes = "__attribute__((noinline)) " if storage else _SHARED_PART
    return f"{storage}{attributes}void casadi_f0_part{k}{_PART_SIGNATURE} {{\n{part}\n}}\n"


def _entry(signature: str, count: int, parts: int) -> str:
    calls = "".join(f"  casadi_f0_part{k}(arg, res, a);\n" for k in range(parts))
    return f"static int casadi_f0({signature}{{\n  casadi_real a[{count}];\n{calls}  return 0;\n}}\n"


def _split_parts(source: str, every: int, least: int) -> tuple[str, str, str, int, list[str]] | None:
    """`split_statements`'s analysis: (the C before ``casadi_f0``, its signature, the C after its body, the length of
    the shared array, each part's body), or None when the source is left whole."""
    head, marker, rest = source.partition("static int casadi_f0(")
    if not marker or "casadi_f1(" in rest:
        return None
    signature, brace, rest = rest.partition("{\n")
    body, end, tail = rest.partition("\n}\n")
    if not brace or not end:
        return None
    lines = body.split("\n")
    declarations = [line for line in lines if _DECLARATION.fullmatch(line)]
    statements = lines[len(declarations):]
    if not declarations or statements[-1:] != ["  return 0;"] or len(statements) - 1 < least:
        return None
    statements = statements[:-1]
    # each statement as (the scalar it assigns or None for an output write, the text after "=" or the line)
    parsed = []
    for line in statements:
        assignment = _ASSIGNMENT.fullmatch(line)
        if _WORK.search(line):  # the parts get arg, res and the shared array only
            return None
        if assignment:
            parsed.append((int(assignment.group(1)), assignment.group(2)))
        elif _OUTPUT.fullmatch(line):
            parsed.append((None, line))
        else:
            return None
    count = 1 + max(int(i) for line in declarations for i in _SCALAR.findall(line))
    if count > 65536:  # more than 512 kB of stack: leave it whole
        return None
    last_use, current = {}, {}  # the statement that last reads each assignment's value; each scalar's assignment
    for i, (scalar, text) in enumerate(parsed):
        for used in _SCALAR.findall(text):
            if int(used) not in current:
                return None  # read before it is written: not the straight-line code expected
            last_use[current[int(used)]] = i
        if scalar is not None:
            current[scalar] = i
    parts = []
    for begin in range(0, len(parsed), every):
        stop = min(begin + every, len(parsed))
        name, local, text = {}, set(), []  # within the part: the name of each scalar's value
        for i in range(begin, stop):
            scalar, expression = parsed[i]
            expression = _SCALAR.sub(lambda m, name=name: name.get(int(m.group(1)), f"a[{int(m.group(1))}]"),
                                     expression)
            if scalar is None:
                text.append(expression)
                continue
            if last_use.get(i, -1) >= stop:  # read by a later part
                name[scalar] = f"a[{scalar}]"
            else:
                name[scalar] = f"l{scalar}"
                local.add(scalar)
            text.append(f"  {name[scalar]}={expression};")
        declared = f"  casadi_real {', '.join(f'l{v}' for v in sorted(local))};\n" if local else ""
        parts.append(declared + "\n".join(text))
    return head, signature, tail, count, parts


def _keep_source(stem: Path, source: str) -> None:
    """Keep a tiered block's C source beside its library, gzipped (a tenth of the library's size), for its
    background builds."""
    _write_atomically(source_of(stem), gzip.compress(source.encode(), compresslevel=1))


def _build_all(builds: list[tuple[str, Path]], wait_s: float = 120.0) -> None:
    """Compile each (C source, library) at the level its library's name gives, as many gcc processes at a time as
    this process may use cores, longest source first (a long body above -O0 as several files: `translation_units`);
    a tiered block's (-O0) source is kept for its tier-up. A library another process is building (its lock: two
    sweep workers starting on one shape) is waited for, up to ``wait_s`` seconds, not built twice. A build that
    fails, or is not seen to land, leaves its library missing (the block is then built, or interpreted, where it is
    next met)."""
    missing = {library: source for source, library in builds if not library.exists()}  # each library once
    pending = sorted(missing.items(), key=lambda b: -len(b[1]))
    mine = [(library, source) for library, source in pending if _take(_lock_of(library), holder=True)]
    theirs = [library for library in missing if library not in dict(mine)]
    try:
        _run_builds(mine, locked=True)
    except BaseException:  # interrupted (Ctrl-C): no lock left for others to wait on (`_run_builds` kills its gcc)
        for library, _ in mine:
            _lock_of(library).unlink(missing_ok=True)
        raise
    deadline = time.time() + wait_s
    while theirs and time.time() < deadline:
        theirs = [lib for lib in theirs if not lib.exists() and _held(_lock_of(lib))]
        if theirs:
            time.sleep(0.01)


@dataclass
class _Build:
    """One library's build in `_run_builds`: its steps (lists of compiler commands; a step's commands run at once,
    each step after the one before it has succeeded), where gcc writes it, and how far it has got."""

    library: Path
    source: str
    output: Path
    steps: list[list[list[str]]]
    step: int = 0
    waiting: list[list[str]] = field(default_factory=list)  # the current step's commands not started yet
    running: list[subprocess.Popen] = field(default_factory=list)
    failed: bool = False

    def __post_init__(self) -> None:
        self.waiting = list(self.steps[0]) if self.steps else []
        self.failed = self.failed or not self.steps


def _run_builds(mine: list[tuple[Path, str]], locked: bool) -> None:
    """Build each (library, source) (`_build_steps`), up to the process's cores gcc processes at a time, the first
    builds' commands first, each library moved into place as it lands (its lock released if ``locked``). gcc
    writes its own temporary files (``TMPDIR``) into the build's directory, which goes with them; on an exception
    every gcc still running is stopped with the programs it started (`_stop`)."""
    if not mine:
        return
    cores = max(len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1, 1)
    with tempfile.TemporaryDirectory(dir=mine[0][0].parent, prefix=BUILD_DIR_PREFIX) as tmp:
        builds = []
        for k, (library, source) in enumerate(mine):
            output = Path(tmp) / f"{k}_{library.name}"
            try:
                steps = _build_steps(source, library.name.split(".")[-2], Path(tmp) / f"fn{k}", output)
            except OSError:
                steps = []
            builds.append(_Build(library, source, output, steps))
        try:
            _schedule(builds, cores, locked, {**os.environ, "TMPDIR": tmp})
        finally:
            _stop([process for build in builds for process in build.running])


def _schedule(builds: list[_Build], cores: int, locked: bool, env: dict[str, str]) -> None:
    """`_run_builds`'s loop: start commands (in environment ``env``, each its own process group) while fewer than
    ``cores`` run, collect those that end, and finish each build whose last step has ended (or that failed)."""
    active = list(builds)
    while active:
        free = cores - sum(len(b.running) for b in active)
        for build in active:
            while free > 0 and build.waiting and not build.failed:
                try:
                    build.running.append(subprocess.Popen(build.waiting.pop(0), stdin=subprocess.DEVNULL,
                                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                                          env=env, start_new_session=True))
                    free -= 1
                except OSError:
                    build.failed = True
        ended = False
        for build in list(active):
            for process in [p for p in build.running if p.poll() is not None]:
                build.running.remove(process)
                build.failed |= process.returncode != 0
                ended = True
            if build.running or (build.waiting and not build.failed):
                continue
            if not build.failed and build.step + 1 < len(build.steps):
                build.step += 1
                build.waiting = list(build.steps[build.step])
                continue
            active.remove(build)
            _finish(build, locked)
        if active and not ended:
            time.sleep(0.005)


def _stop(processes: list[subprocess.Popen], grace_s: float = 1.0) -> None:
    """Stop compilers that are still running (an interrupt, an error): SIGTERM to each one's process group -- gcc
    and the cc1, as and ld it started, which SIGKILL to gcc alone would leave running -- so that gcc removes its
    temporary files; SIGKILL to the groups that still have a process ``grace_s`` seconds later."""
    for process in processes:
        with suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGTERM)
    deadline, waiting = time.time() + grace_s, list(processes)
    while waiting and time.time() < deadline:  # gcc (reaped here), then the programs it started
        waiting = [p for p in waiting if p.poll() is None or _group_alive(p.pid)]
        if waiting:
            time.sleep(0.01)
    for process in waiting:
        with suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
    for process in processes:
        process.wait()


def _group_alive(group: int) -> bool:
    """Whether process group ``group`` still has a process (one that has ended but not been reaped counts)."""
    try:
        os.killpg(group, 0)
    except ProcessLookupError:
        return False
    return True


def _finish(build: _Build, locked: bool) -> None:
    """Move a build's library into place if every step succeeded (a -O0 library's source kept for its tier-up), and
    release the library's lock if this process holds it."""
    try:
        if not build.failed and build.output.exists():
            os.replace(build.output, build.library)
            if build.library.name.endswith(".O0.so"):
                _keep_source(_stem(build.library), build.source)
    finally:
        if locked:
            _lock_of(build.library).unlink(missing_ok=True)


def _build_steps(source: str, level: str, base: Path, library: Path) -> list[list[list[str]]]:
    """Write the C that gcc compiles at ``level`` into files named after ``base`` and return the commands that build
    ``library`` from them: one, or (a long body above -O0, `translation_units`) one per file, run at once, then the
    link. The same code either way: a build a solve waits for compiles a long body in parts (`SPLIT_EVERY`),
    spread over the cores (`UNIT_STATEMENTS`); -O0 compiles it whole."""
    units = [source] if level == "O0" else translation_units(source)
    files = [base.with_name(f"{base.name}_{k}.c") for k in range(len(units))]
    for file, text in zip(files, units, strict=True):
        file.write_text(text)
    if len(files) == 1:
        return [[_compile_command(files, library, level)]]
    objects = [file.with_suffix(".o") for file in files]
    compiles = [_compile_command([file], obj, level, link=False) for file, obj in zip(files, objects, strict=True)]
    return [compiles, [_compile_command(objects, library, level)]]


def _lock_of(library: Path) -> Path:
    """The lock a process holds while it builds ``library`` (`_take`)."""
    return library.with_name(f"{library.name}.lock")


def _build(source: str, library: Path, mode: str) -> None:
    """Build one library here (a block met outside `built_together`), its files compiled at once on the cores;
    raises CalledProcessError when it does not land."""
    _run_builds([(library, source)], locked=False)
    if not library.exists():
        raise subprocess.CalledProcessError(1, f"gcc -{mode} {library.name}")


def _compile_command(inputs: list[Path], output: Path, mode: str, link: bool = True) -> list[str]:
    """The compiler's command line ($CC, or gcc) at level ``mode`` that builds ``inputs`` (C files or objects) into
    the shared library ``output``, or, without ``link``, one C file into the object ``output``."""
    flags = FLAGS if link else [*(flag for flag in FLAGS if flag != "-shared"), "-c"]
    return [os.environ.get("CC", "gcc"), f"-{mode}", *flags, *map(str, inputs), "-o", str(output),
            *(["-lm"] if link else [])]


@dataclass(frozen=True)
class CacheReport:
    """What the compile cache holds: libraries by level (``tiered_up``: -O1 libraries built from a tiered block's
    kept source), blocks still counting towards their tier-up and the seconds of solving each has, tier-up builds
    under way (locks), files of no current kind (an older designopt's libraries, the working directory of a build
    whose process was killed: `_dead_build`), and the bytes of it all."""

    path: Path
    libraries: dict[str, int]
    tiered_up: int
    counting: tuple[tuple[str, float], ...]
    building: int
    other: int
    bytes: int


def _kind(name: str) -> str:
    """A cache file's kind from its name: ``O0``/``O1``/``O2`` (a library), ``source``, ``work``, ``lock``, ``ldl``
    (the KKT solver's library, `designopt.solve.backends.ldl`) or ``other``."""
    parts = name.split(".")
    if name.startswith("ldl_") and len(parts) == 2 and parts[1] == "so":
        return "ldl"
    if len(parts) == 3 and parts[2] == "so" and parts[1] in ("O0", "O1", "O2"):
        return parts[1]
    if name.endswith(".c.gz") and len(parts) == 3:
        return "source"
    if len(parts) == 2 and parts[1] == "work":
        return "work"
    if name.endswith(".so.lock") and len(parts) == 4:
        return "lock"
    return "other"


def _dead_build(directory: Path) -> bool:
    """Whether ``directory`` in the cache is a build's working directory (`_run_builds`) untouched for
    `STALE_LOCK_S`: left by a process that was killed (SIGKILL) before it could remove it."""
    try:
        return directory.name.startswith(BUILD_DIR_PREFIX) and time.time() - directory.stat().st_mtime > STALE_LOCK_S
    except FileNotFoundError:  # its build has just ended
        return False


def _size(directory: Path) -> tuple[int, int]:
    """(files, bytes) below ``directory`` (a file that goes meanwhile, a build's that ends, counts nothing)."""
    files = sizes = 0
    for f in directory.rglob("*"):
        with suppress(OSError):
            if f.is_file():
                sizes += f.stat().st_size
                files += 1
    return files, sizes


def cache_report(path: Path | None = None) -> CacheReport:
    """What the compile cache (`cache_dir`, or ``path``) holds; a dead build's directory counts as one file of no
    current kind."""
    path = cache_dir() if path is None else path
    files = [f for f in path.iterdir() if f.is_file()] if path.is_dir() else []
    dead = [d for d in path.iterdir() if d.is_dir() and _dead_build(d)] if path.is_dir() else []
    kinds = {f: _kind(f.name) for f in files}
    names = {f.name for f in files}
    libraries = {level: sum(k == level for k in kinds.values()) for level in ("O0", "O1", "O2")}
    stems = {_stem(f).name for f, k in kinds.items() if k == "source"}
    tiered_up = sum(1 for s in stems if f"{s}.O1.so" in names)
    counting = []
    for f, k in kinds.items():
        stem = _stem(f).name
        if k == "work" and f"{stem}.O1.so" not in names:
            try:
                seconds = sum(float(v) for v in f.read_text().split() if _is_number(v))
            except OSError:
                continue
            counting.append((stem, seconds))
    return CacheReport(path=path, libraries=libraries, tiered_up=tiered_up,
                       counting=tuple(sorted(counting, key=lambda c: -c[1])),
                       building=sum(k == "lock" for k in kinds.values()),
                       other=sum(k == "other" for k in kinds.values()) + len(dead),
                       bytes=sum(f.stat().st_size for f in files) + sum(_size(d)[1] for d in dead))


def clear_cache(path: Path | None = None, only_other: bool = False) -> tuple[int, int]:
    """Delete the compile cache's files and directories (only those of no current kind and dead builds'
    directories, `_dead_build`, with ``only_other``): (files, bytes) removed. Libraries are compiled again when next
    needed."""
    path = cache_dir() if path is None else path
    removed = freed = 0
    for entry in list(path.iterdir()) if path.is_dir() else ():
        if entry.is_dir():
            if only_other and not _dead_build(entry):
                continue
            files, size = _size(entry)
            shutil.rmtree(entry, ignore_errors=True)
        else:
            if only_other and _kind(entry.name) != "other":
                continue
            files, size = 1, entry.stat().st_size
            entry.unlink(missing_ok=True)
        removed, freed = removed + files, freed + size
    return removed, freed
