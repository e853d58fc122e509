"""Compile small CasADi functions to C, with an on-disk cache keyed by their serialised graphs.

Only per-waypoint functions are compiled (a few thousand lines of C, seconds); compiling a whole NLP
takes minutes. The cache lives in ``$DESIGNOPT_CACHE`` or ``~/.cache/designopt`` and is safe to share
between processes: each library is written under a temporary name and renamed into place.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import tempfile
from collections.abc import Callable
from pathlib import Path

import casadi as ca

COMPILE_MODES = ("none", "O0", "O1", "O2", "auto")
GENERATOR = {"with_header": False}  # CasADi's code generator options (part of the cache key)
# Mode ``auto``: a block evaluated at this many points or more per call is compiled at O1, any other at O0. At -O0
# a cell's clearance Hessian block takes 3x as long per point as at -O1 (82 against 26 us, the pocket cell's PUMA)
# and is most of an iteration on a long program, but gcc -O1 takes 35-60 s for it against 3 s: once per block and
# machine (the cache), paid back within one solve from some 500 points (a program of 250 waypoints with a cell).
AUTO_O1_FROM = 500


def level(mode: str, points: int) -> str:
    """The compile mode of one block function evaluated at ``points`` points per call under ``mode``: ``auto`` is
    O1 from `AUTO_O1_FROM` points and O0 below; any other mode is itself."""
    if mode != "auto":
        return mode
    return "O1" if points >= AUTO_O1_FROM else "O0"


def cache_dir() -> Path:
    path = Path(os.environ.get("DESIGNOPT_CACHE", Path.home() / ".cache" / "designopt"))
    path.mkdir(parents=True, exist_ok=True)
    return path


def compiled(fn: ca.Function, mode: str = "O0") -> ca.Function:
    """Return ``fn`` evaluated as compiled C (mode O0/O1/O2; ``auto`` is resolved by `level` first), or unchanged
    for mode ``none``.

    Falls back to the interpreted function if no C compiler works, so a machine without gcc is slower,
    not broken.
    """
    return compiled_as(fn.name(), fn.serialize(), lambda: fn, mode)


def compiled_as(name: str, identity: str, derive: Callable[[], ca.Function], mode: str = "O0") -> ca.Function:
    """The function ``derive()`` (named ``name``) as compiled C, found in the cache by ``identity`` -- any text
    that determines the function, e.g. its serialised graph, or the small graph it is derived from and how --
    so that a function found there is never derived (its symbolic derivation and serialisation are most of a
    warm build). Mode ``none``: ``derive()`` itself."""
    if mode == "none":
        return derive()
    if mode not in COMPILE_MODES or mode == "auto":
        raise ValueError(f"a block compiles at none, O0, O1 or O2 (auto is resolved by level), got {mode!r}")
    # Serialised graphs are deterministic across processes; hashing one is 4-6x cheaper than generating its C,
    # which is only needed when the library is missing (0.58 s of the pocket cell's warm build).
    key = hashlib.sha256(f"{identity}|{mode}|{ca.__version__}|{GENERATOR}".encode()).hexdigest()[:20]
    library = cache_dir() / f"{name}_{key}.so"
    if not library.exists():
        fn = derive()
        try:
            _build(_source(fn), library, mode)
        except (OSError, subprocess.CalledProcessError):
            return fn
    return ca.external(name, str(library))


def _source(fn: ca.Function) -> str:
    """The C source of ``fn`` (CasADi's code generator with ``GENERATOR`` options)."""
    with tempfile.TemporaryDirectory() as tmp:
        gen = ca.CodeGenerator(f"{fn.name()}.c", GENERATOR)
        gen.add(fn)
        return Path(gen.generate(tmp + os.sep)).read_text()


def _build(source: str, library: Path, mode: str) -> None:
    with tempfile.TemporaryDirectory(dir=library.parent) as tmp:
        c_file = Path(tmp) / "fn.c"
        c_file.write_text(source)
        tmp_lib = Path(tmp) / library.name
        compiler = os.environ.get("CC", "gcc")
        subprocess.run(
            [compiler, f"-{mode}", "-fPIC", "-shared", str(c_file), "-o", str(tmp_lib), "-lm"],
            check=True,
            capture_output=True,
        )
        os.replace(tmp_lib, library)
