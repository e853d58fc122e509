"""A sparse LDLᵀ for IPOPT's KKT systems: an AMD ordering and QDLDL's factorisation behind MA27's calling
convention, built once per machine into the compile cache and loaded by IPOPT as its ``ma27`` (option
``hsllib``).

Why: on this project's KKT systems (a band of per-waypoint blocks bordered by the design joints' dense columns)
MUMPS's fixed costs per factorisation dominate: 50-60 % of an iteration of the 10-waypoint exploration problem
(docs/decisions.md, 2026-11-26). This factorisation has no numerical pivoting: a zero pivot is reported as a
singular matrix, which IPOPT answers by regularising the constraint block, and the inertia IPOPT checks is the
signs of D. Sources (C, in this directory): ``ma27.c`` (this project's), ``qdldl.c`` (QDLDL 0.1.8, osqp/qdldl,
Apache-2.0, ``LICENSE.qdldl``), ``amd/`` (SuiteSparse AMD as vendored by osqp/osqp, BSD-3-Clause,
``amd/LICENSE.amd``; ``glob_opts.h`` and ``osqp.h`` are stand-ins for OSQP's headers).
"""

from __future__ import annotations

import functools
import hashlib
import os
import subprocess
import tempfile
from pathlib import Path

from designopt.transcriptions.compiled import BUILD_DIR_PREFIX, cache_dir

HERE = Path(__file__).resolve().parent
SOURCES = (HERE / "ma27.c", HERE / "qdldl.c", *sorted((HERE / "amd").glob("*.c")))
HEADERS = (*sorted(HERE.glob("*.h")), *sorted((HERE / "amd").glob("*.h")))
FLAGS = ("-O2", "-fPIC", "-shared")


def _key() -> str:
    digest = hashlib.sha256(" ".join(FLAGS).encode())
    for path in (*SOURCES, *HEADERS):
        digest.update(path.name.encode() + path.read_bytes())
    return digest.hexdigest()[:20]


@functools.lru_cache(maxsize=1)
def library() -> Path | None:
    """The shared library in the compile cache (``ldl_<key>.so``, keyed by its sources), built here if missing
    (gcc, about 2 s, once per machine); None when it cannot be built (no compiler): IPOPT then keeps MUMPS."""
    target = cache_dir() / f"ldl_{_key()}.so"
    if target.exists():
        return target
    try:
        # gcc's temporary files in the build's own directory, which goes with it (`compiled.BUILD_DIR_PREFIX`)
        with tempfile.TemporaryDirectory(dir=target.parent, prefix=BUILD_DIR_PREFIX) as tmp:
            out = Path(tmp) / target.name
            command = [os.environ.get("CC", "gcc"), *FLAGS, f"-I{HERE}", f"-I{HERE / 'amd'}",
                       *map(str, SOURCES), "-o", str(out), "-lm"]
            subprocess.run(command, check=True, capture_output=True, env={**os.environ, "TMPDIR": tmp})
            os.replace(out, target)
    except (OSError, subprocess.CalledProcessError):
        return None
    return target
