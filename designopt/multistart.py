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
from designopt.search import WARM_IPOPT
from designopt.solution import Solution, solve_and_evaluate
from designopt.transcriptions.base import InitialGuess, RawResult
from designopt.transcriptions.degeneracy import held_at_multiples_of_pi

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


def _solve_built(problem: DesignProblem, transcription, guess: InitialGuess) -> RawResult:
    payload = pickle.dumps((problem, transcription))
    misses = _built.cache_info().misses
    raw = _built(hashlib.sha256(payload).hexdigest(), payload).solve(guess)
    return raw if _built.cache_info().misses > misses else replace(raw, build_time_s=0.0)


def solve_guess(problem: DesignProblem, transcription, guess: InitialGuess, label: str = "") -> Solution:
    """Build (or reuse) the NLP and solve it from ``guess``. The result's ``build_time_s`` is the time this call
    spent building: 0 when the worker reused an NLP it had built for an earlier start.

    A solve that stops without converging on a design where the tracking constraints degenerate (every joint
    axis parallel to the workpiece normal: `designopt.transcriptions.degeneracy`; the NLP's watch stops such a
    solve early) is continued warm, with the design angles that put it there held and the degenerate rows
    imposed once (``hold_degenerate`` of the transcription). The continuation is the result when it tracks at a
    lower cost (or the first solve did not track); its iterations and times add to the first solve's, and
    ``held`` names the held joints."""
    raw = _solve_built(problem, transcription, guess)
    solution = solve_and_evaluate(problem, transcription.name, raw, label)
    if raw.success or not getattr(transcription, "hold_degenerate", False):
        return solution
    held = held_at_multiples_of_pi(problem, raw.q_d)
    if held is None:
        return solution
    held_problem, q_d = held
    warm = replace(transcription, ipopt={**transcription.ipopt, **WARM_IPOPT})
    more = _solve_built(held_problem, warm, InitialGuess(q_d=q_d, Q=raw.Q, V=raw.V, seed=raw.seed))
    names = " ".join(j.name for j, k in zip(held_problem.chain.design, problem.chain.design, strict=True)
                     if j.lower == j.upper and k.lower != k.upper)
    more = replace(more, iterations=raw.iterations + more.iterations, solve_time_s=raw.solve_time_s + more.solve_time_s,
                   build_time_s=raw.build_time_s + more.build_time_s, held=names)
    continued = solve_and_evaluate(held_problem, transcription.name, more, label)
    if continued.metrics.tracks and (not solution.metrics.tracks
                                     or continued.metrics.design_cost < solution.metrics.design_cost):
        return continued
    return solution


def solve_start(problem: DesignProblem, transcription, settings: Multistart, index: int, label: str = "",
                design=None) -> Solution:
    """Build (or reuse) the NLP and solve start ``index`` of the multistart (from ``design`` if given)."""
    guess = initial_guess(problem, index, settings.seed, settings.scale, settings.init, design)
    return solve_guess(problem, transcription, guess, label)


def best_solution(solutions) -> Solution | None:
    """The tracking solution with the lowest design cost (None if no start tracks)."""
    tracking = [s for s in solutions if s.metrics.tracks]
    return min(tracking, key=lambda s: s.metrics.design_cost) if tracking else None
