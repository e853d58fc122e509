"""Where a solve starts: a seeded start (`Seeded`), a solution of another sampling of the same task (`Lifted`), or a
coarse optimum's design on a new joint branch (`Rebranched`).

Every start has a ``number`` that identifies it in a run's files (the seed column of summary.csv): seed * 1000 +
index for a seeded or rebranched start, the lifted solution's number for a lifted one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designopt.initial_guess import initial_guess
from designopt.problem import DesignProblem
from designopt.transcriptions.base import InitialGuess


@dataclass(frozen=True, eq=False)
class Seeded:
    """Start ``index`` of a seeded multistart (`designopt.initial_guess`): index 0 keeps the configured design, the
    others perturb it by ``scale`` (x 0.5 m for lengths, x pi for angles) or draw it from the task's box (``spread``
    box), or ``design`` is the start design;
    joints by IK along the path (``init``). Depends only on (seed, index): starts can be made in any order."""

    seed: int
    index: int
    scale: float = 0.3
    init: str = "ik"
    design: np.ndarray | None = None
    spread: str = "perturb"

    @property
    def number(self) -> int:
        return self.seed * 1000 + self.index

    def guess(self, problem: DesignProblem) -> InitialGuess:
        return initial_guess(problem, self.index, self.seed, self.scale, self.init, self.design, self.spread)


@dataclass(frozen=True, eq=False)
class Lifted:
    """A solution of another sampling of the same task, lifted: its design joints, and its trajectory (and joint
    velocities) evaluated at this problem's waypoint times (`lifted_guess`)."""

    solution: object  # designopt.solution.Solution

    @property
    def number(self) -> int:
        return self.solution.raw.seed

    def guess(self, problem: DesignProblem) -> InitialGuess:
        return lifted_guess(problem, self.solution)


@dataclass(frozen=True, eq=False)
class Rebranched:
    """A coarse optimum started again on a new joint branch: its design joints, and start ``index`` of ``seed``'s
    first configuration drawn over the whole circle (revolute joints in [-pi, pi] rad), walked along the path by
    IK (``init``). A design's best basin is often on a branch its own start never visits (a folded posture, the
    tool near every joint axis): the design and its branch have to be found together."""

    solution: object  # designopt.solution.Solution
    seed: int
    index: int
    init: str = "ik"

    @property
    def number(self) -> int:
        return self.seed * 1000 + self.index

    def guess(self, problem: DesignProblem) -> InitialGuess:
        # with a design given, spread "box" only sets the first joints' range: the whole circle
        return initial_guess(problem, self.index, self.seed, 0.0, self.init, np.asarray(self.solution.raw.q_d, float),
                             "box")


def lifted_guess(problem: DesignProblem, solution) -> InitialGuess:
    """A start for ``problem`` from a solution of another sampling of the same task: its design joints, and its
    trajectory sampled at ``problem``'s waypoint times (the solution's own trajectory decides what lies between
    its knots)."""
    t = problem.toolpath.t
    return InitialGuess(q_d=np.asarray(solution.raw.q_d, float), Q=solution.sample(t), V=solution.sample_velocity(t),
                        seed=solution.raw.seed)
