"""Backends: what turns a transcribed `NLP` and a `SolverProfile` into a solver.

A backend is a class with a ``name`` and ``prepare(nlp, profile) -> Prepared``; ``Prepared.solve(x0)`` returns an
`Outcome` (`designopt.solve.backends.base`). Adding one is a module here and a line in `BACKENDS`.
"""

from __future__ import annotations

from designopt.solve.backends.base import Backend, Outcome, Prepared
from designopt.solve.backends.ipopt import Ipopt

BACKENDS: dict[str, type] = {Ipopt.name: Ipopt}

__all__ = ["BACKENDS", "Backend", "Outcome", "Prepared", "backend_named"]


def backend_named(name: str) -> Backend:
    if name not in BACKENDS:
        raise ValueError(f"unknown backend {name!r} ({', '.join(BACKENDS)})")
    return BACKENDS[name]()
