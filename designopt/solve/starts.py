"""Where a solve starts: a seeded start (`Seeded`), a solution of another sampling of the same task (`Lifted`), a
coarse optimum's design on a new joint branch (`Rebranched`), a solution of a structure with one joint fewer
(`Grown`) or with one still joint more (`Pruned`), or a solution written with one length's sign flipped and pushed
across its bound (`Reflected`).

Every start has a ``number`` that identifies it in a run's files (the seed column of summary.csv):
`initial_guess.start_number` (seed * 1000 + index) for a seeded, rebranched, reflected, grown or pruned start
(`Numbered`), the lifted solution's number for a lifted one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designopt.initial_guess import (
    design_named,
    first_configuration,
    first_configurations,
    initial_guess,
    perturbed_design,
    projected,
    start_number,
)
from designopt.kinematics.chain import placement_pose
from designopt.kinematics.joints import Role
from designopt.kinematics.reflections import Reflection
from designopt.kinematics.transforms import dh_transform, inverse
from designopt.kinematics.urdf import rpy_of
from designopt.problem import DesignProblem
from designopt.solve.optima import snapped_design
from designopt.transcriptions.base import InitialGuess


class Numbered:
    """A start numbered by its ``seed`` and ``index`` fields: ``number`` is `initial_guess.start_number` of them."""

    @property
    def number(self) -> int:
        return start_number(self.seed, self.index)


@dataclass(frozen=True, eq=False)
class Seeded(Numbered):
    """Start ``index`` of a seeded multistart (`designopt.initial_guess`): index 0 keeps the configured design, the
    others perturb it by ``scale`` (x 0.5 m for lengths, x pi for angles) or draw it from the task's box (``spread``
    box; mixed: odd starts from the box, even ones perturbed), or ``design`` is the start design;
    joints by IK along the path (``init``). Depends only on (seed, index): starts can be made in any order."""

    seed: int
    index: int
    scale: float = 0.3
    init: str = "ik"
    design: np.ndarray | None = None
    spread: str = "perturb"

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
class Rebranched(Numbered):
    """A coarse optimum started again on a new joint branch: its design joints, and start ``index`` of ``seed``'s
    first configuration drawn over the whole circle (revolute joints in [-pi, pi] rad), walked along the path by
    IK (``init``). A design's best basin is often on a branch its own start never visits (a folded posture, the
    tool near every joint axis): the design and its branch have to be found together. With ``perturbation`` > 0
    the design is moved around the optimum's too (`design`): a restart near it, for the better optima of its form
    that lie a few centimetres or a fraction of a radian away. With ``snapped`` the optimum's arm angles are first
    set to their nearest multiple of pi/2 (`optima.snapped_design`): the idealised arm of its form, whose
    best basin a coarse optimum with twists a few tenths of a radian off the lattice may not be in."""

    solution: object  # designopt.solution.Solution
    seed: int
    index: int
    init: str = "ik"
    perturbation: float = 0.0
    snapped: bool = False

    def design(self, problem: DesignProblem) -> np.ndarray:
        """The start's design joints: the optimum's (``snapped``: with its arm angles at their nearest multiple of
        pi/2), plus uniform noise of ``perturbation`` x 0.5 m for lengths and x pi rad for angles
        (`initial_guess.perturbed_design`, drawn from (seed, index) apart from the first configuration's draw),
        clipped to their bounds; without noise when ``perturbation`` is 0."""
        q_d = np.asarray(self.solution.raw.q_d, float)
        if self.snapped:
            q_d = snapped_design(problem.chain, q_d)
        if not self.perturbation:
            return q_d
        return perturbed_design(problem, np.random.default_rng([self.seed, self.index, 1]), self.perturbation, q_d)

    def guess(self, problem: DesignProblem) -> InitialGuess:
        # with a design given, spread "box" only sets the first joints' range: the whole circle
        return initial_guess(problem, self.index, self.seed, 0.0, self.init, self.design(problem), "box")

    def first_configuration(self, problem: DesignProblem) -> np.ndarray:
        """Where this start's walk reaches the path's first waypoint (`guess`'s first row, for a fraction of its cost:
        `initial_guess.first_configuration`; a seventh on the main job's 10 waypoints)."""
        return first_configuration(problem, self.index, self.seed, 0.0, self.init, self.design(problem), "box")


def first_configurations_of(problem: DesignProblem, starts: list[Rebranched]) -> np.ndarray:
    """Each start's `Rebranched.first_configuration` (one row each), to the bit, the walks of one init made
    together (`initial_guess.first_configurations`)."""
    if len({start.init for start in starts}) > 1:
        return np.array([start.first_configuration(problem) for start in starts])
    drawn = [(start.index, start.seed, 0.0, start.design(problem), "box") for start in starts]
    return first_configurations(problem, drawn, starts[0].init if starts else "ik")


def spread_branches(configurations: np.ndarray, count: int, angle: np.ndarray, kept: int = 1) -> list[int]:
    """Indices of ``count`` of ``configurations`` (one per row) spread over the joint space by farthest-point
    sampling: the first ``kept`` rows (at least one), then each time the row farthest from every one taken
    (Euclidean over the joints, revolute differences wrapped to [-pi, pi] rad, prismatic ones in m; ``angle`` marks
    the revolute columns), ties to the lower index. Rebranched walks funnel into a few branches (on the circle two
    sign patterns of the first configuration held 79 of 256 walks and none of the best basin's), so starts taken
    this way from a larger pool cover more branches than as many drawn at random (`Search.rebranch_pool`); with
    ``kept`` the starts already drawn, those added cover the branches they miss (`Search.rebranch_extra`)."""
    X = np.asarray(configurations, float)
    count = min(count, len(X))
    if count <= 0:
        return []
    kept = min(max(kept, 1), count)

    def distance(i):
        d = X - X[i]
        d = np.where(angle, np.arctan2(np.sin(d), np.cos(d)), d)
        return np.sqrt((d * d).sum(axis=1))

    taken, nearest = [0], distance(0)
    for i in range(1, kept):
        taken.append(i)
        nearest = np.minimum(nearest, distance(i))
    nearest[taken] = -np.inf  # never taken twice, even where every row left is a copy of one taken
    for _ in range(count - kept):
        i = int(np.argmax(nearest))
        taken.append(i)
        nearest = np.minimum(nearest, distance(i))
        nearest[taken] = -np.inf
    return taken


@dataclass(frozen=True, eq=False)
class Reflected(Numbered):
    """A full-path solution reflected across a length bound (`designopt.kinematics.reflections`): the same arm and
    motion written with that length's sign flipped, then the length pushed ``step`` (m) past its bound of 0 -- the
    side the bound had closed -- and each waypoint moved onto the path with that design (`projected`). ``seed`` and
    ``index`` number it."""

    solution: object  # designopt.solution.Solution
    reflection: Reflection
    step: float
    seed: int
    index: int

    def guess(self, problem: DesignProblem) -> InitialGuess:
        chain, t = problem.chain, problem.toolpath.t
        q_d, k = self.reflection.design(chain, self.solution.raw.q_d), self.reflection.length(chain)
        q_d[k] = chain.design[k].lower + self.step
        Q = self.reflection.joints(chain, self.solution.sample(t))
        V = self.reflection.velocities(chain, self.solution.sample_velocity(t))
        return InitialGuess(q_d=q_d, Q=projected(problem, q_d, Q), V=V, seed=self.number)


@dataclass(frozen=True, eq=False)
class Grown(Numbered):
    """A solution of a structure with one joint fewer (``source``, its problem) as a start of this structure, which
    is that one with a link inserted at ``where`` (0-based): the link an identity transform (its DH parameters 0)
    whose joint stays at 0 along the path, every other design joint and joint trajectory the solution's
    (`grown_guess`). The start tracks the path exactly as the solution did; only the inserted joint's compliance
    is new. ``seed`` and ``index`` number it."""

    solution: object  # designopt.solution.Solution
    source: DesignProblem
    where: int
    seed: int
    index: int

    def guess(self, problem: DesignProblem) -> InitialGuess:
        return grown_guess(problem, self.source, self.solution, self.where, self.number)


def grown_guess(problem: DesignProblem, source: DesignProblem, solution, where: int, seed: int = 0) -> InitialGuess:
    """`Grown`'s start: ``problem``'s chain is ``source``'s with a DH link inserted at ``where`` (0-based, so link
    ``where + 1`` is new and source link i > where becomes link i + 1; both chains DH tables); each design joint
    of ``source`` carried to the joint of the same link (so shifted) and parameter, the placement's as they are, the
    new link's parameters 0 (an identity transform at joint value 0), the joints and velocities of ``solution``
    at ``problem``'s waypoint times with the new joint's column 0. Parameters that are not design joints keep
    ``problem``'s own values (in a sweep every DH parameter but the joint's is one)."""
    grown, short = problem.chain.structure, source.chain.structure
    dh_tables = problem.chain.dh is not None and source.chain.dh is not None
    if not dh_tables or not 0 <= where < len(grown) or grown[:where] + grown[where + 1:] != short:
        raise ValueError(f"{problem.chain.structure} is not {source.chain.structure} with a joint inserted at {where}")

    # source joint name -> this chain's joint of the same link (shifted past the inserted one) and parameter
    named = {j.name: j.name for j in source.chain.placement_joints}
    for i, link in enumerate(source.chain.dh):
        moved = problem.chain.dh[i + (i >= where)]
        named |= {source.chain.joints[a].name: problem.chain.joints[b].name for a, b in zip(link, moved, strict=True)}
    given = {named[j.name]: float(v) for j, v in zip(source.chain.design, solution.raw.q_d, strict=True)}
    given |= {problem.chain.joints[b].name: 0.0 for b in problem.chain.dh[where]}
    t = problem.toolpath.t
    Q = np.insert(solution.sample(t), where, 0.0, axis=1)
    V = np.insert(solution.sample_velocity(t), where, 0.0, axis=1)
    return InitialGuess(q_d=design_named(problem, given), Q=Q, V=V, seed=seed)


@dataclass(frozen=True, eq=False)
class Pruned(Numbered):
    """A solution of a structure with one joint more whose first joint stays still along the path, as a start of
    this structure, which is that one without its first link: ``design`` (`pruned_design`: the same arm, the still
    link's transform carried into the placement) and the solution's motion without the first joint. The start
    tracks the path as the solution did. ``seed`` and ``index`` number it."""

    solution: object  # designopt.solution.Solution
    design: np.ndarray
    seed: int
    index: int

    def guess(self, problem: DesignProblem) -> InitialGuess:
        t = problem.toolpath.t
        Q = np.delete(self.solution.sample(t), 0, axis=1)
        V = np.delete(self.solution.sample_velocity(t), 0, axis=1)
        return InitialGuess(q_d=self.design, Q=projected(problem, self.design, Q), V=V, seed=self.number)


def pruned_design(problem: DesignProblem, source: DesignProblem, solution) -> np.ndarray | None:
    """`Pruned`'s design: ``source``'s chain is ``problem``'s with a DH link inserted first (both DH tables), and
    its first joint is held at its mean over ``solution``'s knots. Link i + 1 of ``source`` becomes link i, its
    design joints carried by parameter; the placement T_BW (workpiece in base, m and rad) becomes inv(T_1) T_BW,
    T_1 the held first link's transform, written as x, y, z and yaw, pitch, roll (Rz Ry Rx). None when that
    placement leaves its bounds, or when ``problem``'s placement is not those six design joints."""
    short, long_ = problem.chain, source.chain
    if short.dh is None or long_.dh is None or long_.structure[1:] != short.structure:
        raise ValueError(f"{short.structure} is not {long_.structure} without its first joint")
    names = [j.name for j in short.placement_joints]
    if names != [f"placement.{k}" for k in ("x", "y", "z", "yaw", "pitch", "roll")] or not all(
            j.role is Role.DESIGN for j in short.placement_joints):
        return None
    q_long, q_m = np.asarray(solution.raw.q_d, float), np.mean(np.asarray(solution.raw.Q, float), axis=0)
    values = long_.values(q_m, q_long)
    first = dh_transform(*(float(values[k]) for k in long_.dh[0]))
    place = inverse(first) @ np.asarray(placement_pose(long_, q_m, q_long), float)
    roll, pitch, yaw = rpy_of(place[:3, :3])
    pose = {"x": place[0, 3], "y": place[1, 3], "z": place[2, 3], "yaw": yaw, "pitch": pitch, "roll": roll}
    given = {f"placement.{k}": float(v) for k, v in pose.items()}
    if any(not j.lower <= given[j.name] <= j.upper for j in short.placement_joints):
        return None
    for i, link in enumerate(short.dh):
        moved = long_.dh[i + 1]
        given |= {short.joints[b].name: float(values[a]) for a, b in zip(moved, link, strict=True)}
    return design_named(problem, given)


def lifted_guess(problem: DesignProblem, solution) -> InitialGuess:
    """A start for ``problem`` from a solution of another sampling of the same task: its design joints, and its
    trajectory sampled at ``problem``'s waypoint times, each sample moved onto the path (`projected`: between
    the solution's knots its trajectory may leave the path by decimetres and turn the tool over)."""
    t = problem.toolpath.t
    q_d = np.asarray(solution.raw.q_d, float)
    return InitialGuess(q_d=q_d, Q=projected(problem, q_d, solution.sample(t)), V=solution.sample_velocity(t),
                        seed=solution.raw.seed)
