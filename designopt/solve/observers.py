"""Observers: watch a solve's iterates and may stop it; they never change the problem or the iterate.

An observer is made per prepared solver from the problem (``OBSERVERS[name](problem)``); before each solve a
backend calls ``reset(bound)`` (the solve's `Bound`, for `AboveBound`; None for most solves), then ``observe(iterate,
iterations)`` with the current `Iterate` every few iterations (``iterations`` since the last call), and stops the
solve when it returns True; the solve's status is then the observer's ``status``. What happens next (a
continuation on another problem) is a strategy's business (`designopt.solve.strategies.continuation`).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from designopt.problem import DesignProblem
from designopt.transcriptions.degeneracy import held_at_multiples_of_pi, tracking_jacobian


@dataclass(frozen=True)
class Iterate:
    """What an observer sees of an iterate: the design joints (m, rad), the NLP's objective, and the largest
    constraint violation (the constraints' own units: m and rad for tracking rows)."""

    q_d: np.ndarray
    objective: float = float("nan")
    violation: float = 0.0


@dataclass(frozen=True)
class Bound:
    """What a solve is held to (`AboveBound`): once ``after`` iterations have passed, a feasible iterate whose NLP
    objective is above ``objective`` stops it. A strategy sets both: what a start must beat, and how long it gets."""

    objective: float
    after: int


class DegenerateWatch:
    """Stops a solve once its design has sat on a degenerate design (`held_at_multiples_of_pi` would hold
    something: every joint axis parallel to the workpiece normal, docs/decisions.md) for ``patience`` iterations
    in a row: from there IPOPT only creeps. A solve that only passes through such a design is not stopped.
    Held joints (lower == upper) are not watched: a problem already held there must be allowed to finish."""

    status = "Stopped_On_Degenerate_Design"

    def __init__(self, problem: DesignProblem, patience: int = 30, tol: float = 1e-3):
        self.problem, self.patience, self.tol = problem, patience, tol
        self.angle = np.array([j.kind == "angle" and j.lower < j.upper for j in problem.chain.design], dtype=bool)
        self._verdicts: dict[tuple[bool, ...], bool] = {}
        self._jacobian = None  # the tracking Jacobian, built at the first verdict and reused by every other one
        self.reset()

    def reset(self, bound: Bound | None = None) -> None:
        self.run, self.stopped = 0, False

    def _degenerate(self, q_d: np.ndarray) -> bool:
        near = self.angle & (np.abs(q_d - np.round(q_d / np.pi) * np.pi) <= self.tol)
        if not near.any():
            return False
        key = tuple(near)
        if key not in self._verdicts:  # the analysis is exact per set of near-pi angles: once per set
            if self._jacobian is None:
                self._jacobian = tracking_jacobian(self.problem)
            self._verdicts[key] = held_at_multiples_of_pi(self.problem, q_d, self.tol, self._jacobian) is not None
        return self._verdicts[key]

    def observe(self, iterate: Iterate, iterations: int = 1) -> bool:
        self.run = self.run + iterations if self._degenerate(np.asarray(iterate.q_d, float)) else 0
        self.stopped = self.run >= self.patience
        return self.stopped


class AboveBound:
    """Stops a solve that, ``bound.after`` iterations in, still sits above its bound: a feasible iterate
    (violation <= ``tol``, 1 mm or mrad) whose objective is above ``bound.objective`` (the `Bound` the solve was
    given, ``reset(bound)``). A start meant to beat a known design that is still far above it by then rarely gets
    there; a strategy that sets bounds (`designopt.solve.strategies.neighbours`) says how its rule was measured. A
    solve without a bound is never stopped."""

    status = "Stopped_Above_Bound"

    def __init__(self, problem: DesignProblem, tol: float = 1e-3):
        self.tol = tol
        self.reset()

    def reset(self, bound: Bound | None = None) -> None:
        self.bound, self.iterations, self.stopped = bound, 0, False

    def observe(self, iterate: Iterate, iterations: int = 1) -> bool:
        self.iterations += iterations
        self.stopped = (self.bound is not None and self.iterations >= self.bound.after
                        and iterate.violation <= self.tol and iterate.objective > self.bound.objective)
        return self.stopped


class StalledViolation:
    """Stops a solve whose constraint violation has stopped falling. Both must hold, on a solve above ``tol`` (1 mm or
    mrad): for ``patience`` iterations in a row the violation has not fallen below ``factor`` times the level it last
    fell to (``anchor``: each time it falls below ``factor`` times the anchor, or to ``tol``, that is the new anchor
    and the count starts again), and it is now still at least ``factor`` times the largest violation of those
    iterations.
    IPOPT declares a problem locally infeasible only after its restoration phase fails too; a start that cannot track
    the path can spend hundreds of iterations, or its time limit, getting there. A solve that tracks is never
    stopped, nor one that is making its way back to the path after a step away from it (the second condition), nor
    one whose violation only spikes (the first).

    ``PATIENCE``: 2.5 times the longest stall of a start that went on to track, over the cold full-path starts of five
    jobs and the explorations of three (`benchmarks/violation_traces.py`, docs/benchmarks.md "Stalled starts")."""

    status = "Stopped_On_Stalled_Violation"
    PATIENCE = 150

    def __init__(self, problem: DesignProblem | None = None, patience: int | None = None, tol: float = 1e-3,
                 factor: float = 0.5):
        self.patience = self.PATIENCE if patience is None else patience
        self.tol, self.factor = tol, factor
        self.reset()

    def reset(self, bound: Bound | None = None) -> None:
        self.anchor, self.run, self.stopped = float("inf"), 0, False
        self.window: deque[tuple[int, float]] = deque()  # (run, violation) of the looks in the current run

    def observe(self, iterate: Iterate, iterations: int = 1) -> bool:
        v = iterate.violation
        if v <= self.tol or v < self.factor * self.anchor:
            self.anchor, self.run = max(v, self.tol), 0
            self.window.clear()
        else:
            self.run += iterations
        self.window.append((self.run, v))
        while self.window[0][0] < self.run - self.patience:
            self.window.popleft()
        self.stopped = self.run >= self.patience and v >= self.factor * max(w for _, w in self.window)
        return self.stopped


OBSERVERS = {"degenerate": DegenerateWatch, "above_bound": AboveBound, "stalled_violation": StalledViolation}


def make_observers(names, problem: DesignProblem) -> list:
    unknown = [n for n in names if n not in OBSERVERS]
    if unknown:
        raise ValueError(f"unknown observer {unknown[0]!r} ({', '.join(OBSERVERS)})")
    return [OBSERVERS[n](problem) for n in names]
