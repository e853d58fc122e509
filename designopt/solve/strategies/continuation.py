"""Continuation: finish a solve that stopped on a degenerate design, on the problem that holds that design.

When every joint axis of a design is parallel to the workpiece normal (a DH arm with every twist at 0 or pi), the
tool axis, and over a planar path the tool's height, no longer depend on the joints: N copies of one equality of
the design, on which IPOPT creeps until its cap (docs/decisions.md, "Degenerate designs"). The solve's
`DegenerateWatch` stops it there; `HoldDegenerate` then builds the regular problem of that set -- the angles that
put it there held, each degenerate row imposed once (`held_at_multiples_of_pi`) -- and solves it warm from where
the first solve stopped. The answer is a solution of the problem as posed (a held joint stays a design joint).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from designopt.solution import Solution, solve_and_evaluate
from designopt.solve.local import solve_guess
from designopt.transcriptions.base import InitialGuess
from designopt.transcriptions.degeneracy import held_at_multiples_of_pi


@dataclass(frozen=True)
class HoldDegenerate:
    """Finish a solve its `DegenerateWatch` stopped (or that ended unconverged on a degenerate design) warm on the
    held problem. The continuation is the result when it tracks at a lower cost (or the first solve did not
    track); its iterations and times add to the first solve's, and ``held`` names the held joints."""

    observer = "degenerate"  # the observer that stops such solves (`designopt.solve.observers.OBSERVERS`)

    def finish(self, task, solution: Solution) -> Solution:
        raw = solution.raw
        if raw.success:
            return solution
        held = held_at_multiples_of_pi(task.problem, raw.q_d)
        if held is None:
            return solution
        problem, q_d = held
        more = solve_guess(problem, task.transcription, task.profile.warmed(),
                           InitialGuess(q_d=q_d, Q=raw.Q, V=raw.V, seed=raw.seed)).raw
        names = " ".join(j.name for j, k in zip(problem.chain.design, task.problem.chain.design, strict=True)
                         if j.lower == j.upper and k.lower != k.upper)
        more = replace(more, iterations=raw.iterations + more.iterations,
                       solve_time_s=raw.solve_time_s + more.solve_time_s,
                       build_time_s=raw.build_time_s + more.build_time_s, held=names)
        continued = solve_and_evaluate(problem, solution.method, more)
        if continued.metrics.tracks and (not solution.metrics.tracks
                                         or continued.metrics.design_cost < solution.metrics.design_cost):
            return continued
        return solution
