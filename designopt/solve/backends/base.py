"""What every backend returns and provides (`designopt.solve.backends`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from designopt.solve.observers import Bound
from designopt.transcriptions.nlp import NLP


@dataclass(frozen=True)
class Outcome:
    """What a backend returned: the final decision vector, objective, status and effort (wall seconds)."""

    x: np.ndarray
    objective: float
    status: str
    success: bool
    iterations: int
    solve_time_s: float


class Prepared(Protocol):
    """One NLP made ready under one profile; solves from any starting point."""

    prepare_time_s: float

    def solve(self, x0: np.ndarray, bound: Bound | None = None) -> Outcome: ...

    def bounded(self, lower: np.ndarray, upper: np.ndarray) -> Prepared:
        """The same solver with the design joints (x[:n_design]) bounded by ``lower`` and ``upper``. Optional: without
        it, each problem with held design joints is built on its own (`designopt.solve.local.prepared`)."""


class Backend(Protocol):
    name: str

    def prepare(self, nlp: NLP, profile) -> Prepared: ...
