"""Seeded multistart: one start of one problem, solved; the best of several.

Local optima are everywhere in design problems, so several starts are part of the method. Each start is
one task of the experiment machinery (`designopt.experiments.tasks`), which fans them out and writes each
as it finishes. A worker process builds a problem's NLP once and reuses it for every start it is given (the
cache below lives in the worker and holds at most two built NLPs).
"""

from __future__ import annotations

import functools
import hashlib
import os
import pickle
from dataclasses import dataclass, replace

from designopt.initial_guess import initial_guess
from designopt.problem import DesignProblem
from designopt.solution import Solution, solve_and_evaluate
from designopt.transcriptions.base import InitialGuess

# IPOPT's linear algebra gains nothing from threads at this size; parallelism is across starts.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")


@dataclass(frozen=True)
class Multistart:
    """How many starts, from which seed, how far to perturb the design, and how to initialise q."""

    count: int = 4
    seed: int = 0
    scale: float = 0.3
    init: str = "ik"
    jobs: int = -1


@functools.lru_cache(maxsize=2)
def _built(key: str, payload: bytes):
    problem, transcription = pickle.loads(payload)
    return transcription.build(problem)


def solve_guess(problem: DesignProblem, transcription, guess: InitialGuess, label: str = "") -> Solution:
    """Build (or reuse) the NLP and solve it from ``guess``. The result's ``build_time_s`` is the time this call
    spent building: 0 when the worker reused an NLP it had built for an earlier start."""
    payload = pickle.dumps((problem, transcription))
    misses = _built.cache_info().misses
    nlp = _built(hashlib.sha256(payload).hexdigest(), payload)
    raw = nlp.solve(guess)
    if _built.cache_info().misses == misses:
        raw = replace(raw, build_time_s=0.0)
    return solve_and_evaluate(problem, transcription.name, raw, label)


def solve_start(problem: DesignProblem, transcription, settings: Multistart, index: int, label: str = "",
                design=None) -> Solution:
    """Build (or reuse) the NLP and solve start ``index`` of the multistart (from ``design`` if given)."""
    guess = initial_guess(problem, index, settings.seed, settings.scale, settings.init, design)
    return solve_guess(problem, transcription, guess, label)


def best_solution(solutions) -> Solution | None:
    """The tracking solution with the lowest design cost (None if no start tracks)."""
    tracking = [s for s in solutions if s.metrics.tracks]
    return min(tracking, key=lambda s: s.metrics.design_cost) if tracking else None
