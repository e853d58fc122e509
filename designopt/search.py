"""The search: which starts a problem gets, and which of them are worth solving on the full path.

Local optima are everywhere in design problems: the same task solved from 48 seeded starts ends anywhere
between the best design known and 2,000 times its cost, and a start's objective after a few hundred IPOPT
iterations barely predicts where it ends (docs/benchmarks.md, "Racing starts"). What does predict it is the
same problem solved on fewer waypoints: a design optimal for a coarse sampling of the path lies, more often
than not, in the basin of a design optimal for the full path. So the default search has three stages:

1. **explore**: ``explore_starts`` cold, seeded starts (`designopt.initial_guess`) of the *coarse problem* --
   the same robot, placement, costs and cell on ``explore_waypoints`` of the path's waypoints
   (`toolpaths.subsample`) -- each capped at ``explore_max_iter`` IPOPT iterations. A coarse solve costs about
   a tenth of a full one, so the same budget visits ten times as many basins.
2. **screen** (when ``screen_waypoints`` is between 0 and the path's waypoints): the ``screen`` best distinct
   coarse optima are lifted to a finer sampling (``screen_waypoints``) and solved warm, and ranked again there:
   the 10-waypoint ranking alone often puts a design that lifts badly ahead of one that lifts well. Each is
   capped at ``screen_max_iter`` iterations: it only has to rank.
3. **refine**: the ``refine`` best *distinct* screened (or coarse) optima (designs further apart than
   ``distinct`` in some design joint: `cluster_designs`) are lifted to the full path -- design as is,
   trajectory sampled from the coarser cubic (`lifted_guess`) -- and solved warm: IPOPT's barrier starts
   small (`WARM_IPOPT`) so that the solve stays in the basin it was given instead of being pushed off its
   active bounds.

``strategy: multistart`` is the plain alternative: ``solver.multistart`` cold starts on the full path.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from designopt.problem import DesignProblem
from designopt.toolpaths import subsample
from designopt.transcriptions.base import InitialGuess

STRATEGIES = ("coarse_to_fine", "multistart")

# A warm start's barrier: mu_init 1e-4 instead of 0.1 and bound push/frac 1e-6 instead of 1e-2. With IPOPT's
# defaults a solve started at the best design known for the main job leaves it (3.80e-4 -> 7.66e-4): many of
# its lengths sit a millimetre above their bound 0, and a push of 1 cm changes the problem.
WARM_IPOPT = {"ipopt.mu_init": 1e-4, "ipopt.bound_push": 1e-6, "ipopt.bound_frac": 1e-6}


@dataclass(frozen=True)
class Search:
    """How a problem is searched (module docstring). Waypoint and start counts are per problem."""

    strategy: str = "coarse_to_fine"
    explore_waypoints: int = 10
    explore_starts: int = 80
    explore_max_iter: int = 250
    refine: int = 4
    distinct: float = 0.02  # m or rad: optima closer than this in every design joint are one optimum
    screen_waypoints: int = 40  # re-rank the best ``screen`` coarse optima on this many waypoints first (0: don't)
    screen: int = 12
    screen_max_iter: int = 300  # a screening solve ranks; it need not converge (design-only stalls there)

    def __post_init__(self):
        if self.strategy not in STRATEGIES:
            raise ValueError(f"strategy must be one of {STRATEGIES}, got {self.strategy!r}")


def coarse_problem(problem: DesignProblem, waypoints: int) -> DesignProblem:
    """The same problem on ``waypoints`` of its path's waypoints (first and last kept)."""
    return replace(problem, toolpath=subsample(problem.toolpath, waypoints))


def lifted_guess(problem: DesignProblem, solution) -> InitialGuess:
    """A start for ``problem`` from a solution of another sampling of the same task: its design joints, and its
    trajectory (and joint velocities) evaluated at ``problem``'s waypoint times."""
    t = problem.toolpath.t
    return InitialGuess(q_d=np.asarray(solution.raw.q_d, float), Q=solution.sample(t), V=solution.sample_velocity(t),
                        seed=solution.raw.seed)


def design_distance(a: np.ndarray, b: np.ndarray, angle: np.ndarray) -> float:
    """Largest difference between two designs: metres for lengths, radians (wrapped to [-pi, pi]) for angles."""
    d = np.asarray(a, float) - np.asarray(b, float)
    d = np.where(angle, np.arctan2(np.sin(d), np.cos(d)), d)
    return float(np.max(np.abs(d))) if d.size else 0.0


def cluster_designs(designs: np.ndarray, costs: np.ndarray, angle: np.ndarray, tol: float = 0.02) -> np.ndarray:
    """Label each design with its local optimum: in order of cost, a design joins the first (cheaper) cluster
    whose representative lies within ``tol`` (m or rad) in every design joint, else starts a new one."""
    order = np.argsort(costs, kind="stable")
    labels, leaders = np.empty(len(costs), dtype=int), []
    for i in order:
        for k, j in enumerate(leaders):
            if design_distance(designs[i], designs[j], angle) <= tol:
                labels[i] = k
                break
        else:
            labels[i] = len(leaders)
            leaders.append(i)
    return labels


def distinct_best(solutions: list, count: int, tol: float = 0.02) -> list[int]:
    """Indices into ``solutions`` of the best tracking solution of each of the ``count`` cheapest distinct
    optima (`cluster_designs`), cheapest first."""
    tracking = [i for i, s in enumerate(solutions) if s.metrics.tracks]
    if not tracking or count <= 0:
        return []
    angle = np.array([j.kind == "angle" for j in solutions[tracking[0]].problem.chain.design], dtype=bool)
    costs = np.array([solutions[i].metrics.design_cost for i in tracking])
    labels = cluster_designs(np.array([solutions[i].raw.q_d for i in tracking]).reshape(len(tracking), -1), costs,
                             angle, tol)
    leaders = {}
    for k in np.argsort(costs, kind="stable"):
        leaders.setdefault(labels[k], tracking[k])
    return list(leaders.values())[:count]
