"""Solver profiles: which backend solves an NLP, and how (caps, warm or cold, observers).

A profile is a small frozen value: the search derives the profile of every stage from one base profile
(``capped`` for a coarse exploration, ``warmed`` for a solve that starts at a solution of another sampling), and
a worker caches one prepared solver per (NLP, profile). Nothing in a profile changes the problem being solved,
only how the backend goes about it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from designopt.transcriptions.compiled import COMPILE_MODES

LINEAR_SOLVERS = ("ldl", "mumps")


@dataclass(frozen=True)
class SolverProfile:
    """How one NLP is solved.

    ``backend``: a name in `designopt.solve.backends.BACKENDS`. ``max_iter``: iteration cap. ``time_limit``:
    wall seconds per solve. ``warm``: the guess is a solution of a neighbouring problem (another sampling of
    the path, the same design held): start the barrier small and do not push the guess off its active bounds.
    ``compile``: how the per-waypoint blocks are evaluated (``none``: interpreted; ``O0``-``O2``: C compiled at
    that level, cached on disk; ``auto``: O1 for a block evaluated at 500 points or more, a long program's, and O0
    below: `designopt.transcriptions.compiled.level`). ``observers``: names in `designopt.solve.observers.OBSERVERS`,
    watching every iteration; an observer may stop a solve, never change it. ``linear_solver``: what factorises
    the backend's KKT systems, a name in `LINEAR_SOLVERS` (``mumps``: MUMPS with pivoting; ``ldl``: an AMD-ordered
    LDLᵀ without pivoting, faster and less robust, `designopt.solve.backends.ldl`). ``objective_scale``: the factor
    the backend multiplies the objective by while it iterates (IPOPT's ``obj_scaling_factor``, on top of its own
    gradient-based scaling, which caps the objective's largest gradient entry at the start at 100); the objective
    reported, the observers' and the solution's costs are the NLP's own. A design cost of 1e-4 to 1 weighs little
    against IPOPT's barrier (0.1 at first) and Hessian perturbation (1e-4 at first): scaled up, a solve takes fewer
    and cheaper iterations but settles sooner, often in a worse basin (judged on the exploration, not adopted:
    `designopt.solve.search.Search`'s ``explore_objective_scale``, docs/decisions.md).
    """

    backend: str = "ipopt"
    max_iter: int = 1000
    time_limit: float = 300.0
    warm: bool = False
    compile: str = "auto"
    observers: tuple[str, ...] = ()
    options: tuple[tuple[str, float | int | str], ...] = ()
    linear_solver: str = "mumps"
    objective_scale: float = 1.0

    def __post_init__(self):
        if self.compile not in COMPILE_MODES:
            raise ValueError(f"compile must be one of {COMPILE_MODES}, got {self.compile!r}")
        if self.linear_solver not in LINEAR_SOLVERS:
            raise ValueError(f"linear_solver must be one of {LINEAR_SOLVERS}, got {self.linear_solver!r}")
        if self.max_iter < 1 or self.time_limit <= 0:
            raise ValueError("max_iter must be >= 1 and time_limit > 0")
        if not self.objective_scale > 0:
            raise ValueError(f"objective_scale must be > 0, got {self.objective_scale!r}")

    def capped(self, max_iter: int | None) -> SolverProfile:
        """The same profile with at most ``max_iter`` iterations (None: unchanged)."""
        return self if max_iter is None else replace(self, max_iter=min(self.max_iter, max_iter))

    def warmed(self) -> SolverProfile:
        return replace(self, warm=True)

    def solved_by(self, linear_solver: str | None) -> SolverProfile:
        """The same profile with another linear solver (None: unchanged)."""
        return self if linear_solver is None else replace(self, linear_solver=linear_solver)

    def scaled(self, objective_scale: float) -> SolverProfile:
        """The same profile with the objective scaled by ``objective_scale`` while the backend iterates."""
        return replace(self, objective_scale=float(objective_scale))

    def observing(self, *names: str) -> SolverProfile:
        return replace(self, observers=tuple(dict.fromkeys((*self.observers, *names))))

    def with_options(self, **options: float | int | str) -> SolverProfile:
        """The same profile with these backend options set (a name already set is replaced), e.g.
        ``with_options(**{"ipopt.mu_init": 1e-6})``."""
        return replace(self, options=tuple({**dict(self.options), **options}.items()))
