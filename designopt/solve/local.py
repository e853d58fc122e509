"""One local solve: a problem, its transcription, a solver profile and one initial guess -> a `Solution`.

A worker process builds a problem's NLP once (per transcription) and prepares it once per profile, and reuses both
for every start it is given: the caches below live in the worker. Keys are the content of the problem and the
transcription, so two starts of the same problem share one build whatever objects they came in.
"""

from __future__ import annotations

import functools
import hashlib
import os
import pickle
import time

from designopt.problem import DesignProblem
from designopt.solution import Solution, solve_and_evaluate
from designopt.solve.backends import backend_named
from designopt.solve.observers import Bound
from designopt.solve.profile import SolverProfile
from designopt.transcriptions.base import InitialGuess, RawResult
from designopt.transcriptions.compiled import record_work, tiered_up
from designopt.transcriptions.degeneracy import shared_shape

# IPOPT's linear algebra gains nothing from threads at this size; parallelism is across starts.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")


@functools.lru_cache(maxsize=4)
def _built(key: str, payload: bytes):
    problem, transcription = pickle.loads(payload)
    return transcription.build(problem)


@functools.lru_cache(maxsize=8)
def _prepared(key: str, payload: bytes, profile: SolverProfile):
    built = _built(key, payload)
    return built, backend_named(profile.backend).prepare(built.nlp, profile)


def prepared(problem: DesignProblem, transcription, profile: SolverProfile):
    """(built NLP, prepared solver, seconds this call spent building and preparing: 0 when both were cached).
    A problem with held design joints is built as its `shared_shape` (held at 0) and solved with its own bounds
    (`Prepared.bounded`, when the backend has it), so that the held problems of a search share one build per set
    of held joints.
    A cached solver whose blocks have since tiered up (`designopt.transcriptions.compiled.tiered_up`: -O0
    libraries for blocks it interprets, or -O1 ones; another process may have built them) is built again, so that
    a run gains from each tier at once."""
    t0 = time.perf_counter()
    shape = shared_shape(problem)
    built, solver, fresh = _cached(shape, transcription, profile)
    if shape is not problem:
        if hasattr(solver, "bounded"):
            design = problem.chain.design
            solver = solver.bounded([j.lower for j in design], [j.upper for j in design])
        else:  # a backend that cannot move the design joints' bounds: this problem's own build
            built, solver, again = _cached(problem, transcription, profile)
            fresh = fresh or again
    return built, solver, (time.perf_counter() - t0) if fresh else 0.0


def _cached(problem: DesignProblem, transcription, profile: SolverProfile):
    """(built NLP, prepared solver, whether this call built or prepared it) of the problem, from the caches."""
    payload = pickle.dumps((problem, transcription))
    key = hashlib.sha256(payload).hexdigest()
    misses = _prepared.cache_info().misses
    built, solver = _prepared(key, payload, profile)
    fresh = _prepared.cache_info().misses > misses
    if tiered_up(built.nlp.tiered_libraries(profile.compile)):
        _built.cache_clear()  # once per tier-up: the other cached problems are built again when next asked for
        _prepared.cache_clear()
        built, solver = _prepared(key, payload, profile)
        fresh = True
    return built, solver, fresh


def solve_guess(problem: DesignProblem, transcription, profile: SolverProfile, guess: InitialGuess,
                bound: Bound | None = None) -> Solution:
    """Solve the problem from ``guess`` (held to ``bound`` if the profile observes "above_bound").
    A solve that fails is a solution with its status, not an exception. Its seconds count towards the tier-up of
    the NLP's compiled blocks (`designopt.transcriptions.compiled`)."""
    built, solver, spent = prepared(problem, transcription, profile)
    outcome = solver.solve(built.pack(guess), bound)
    record_work(built.nlp.tiered_libraries(profile.compile), outcome.solve_time_s)  # -O1 once paid for
    q_d, trajectory, drift = built.unpack(outcome.x)
    raw = RawResult(q_d=q_d, trajectory=trajectory, status=outcome.status, success=outcome.success,
                    iterations=outcome.iterations, solve_time_s=outcome.solve_time_s, build_time_s=spent,
                    objective=outcome.objective, n_variables=built.nlp.n_variables,
                    n_constraints=built.nlp.n_constraints, seed=guess.seed, kinematic_drift=drift)
    return solve_and_evaluate(problem, transcription.name, raw)
