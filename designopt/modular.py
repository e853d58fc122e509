"""Modules (SPEC §3, §5): a catalogue of DH links, the similarity cost L_mod, and rounding.

A module fixes every DH parameter of a link except the moving one (theta of an R link, d of a P link).
The distance between a link's design vector and a module is
    dist = w_lin (Delta d^2 + Delta a^2) + w_ang * 2 (1 - cos Delta alpha)   (R links)
and the same with theta in place of d for P links, where the cosine form makes alpha and alpha + 2 pi the
same angle. L_mod = sum_i prod_k dist(link i, module k) is zero exactly when every link is a module.
Functions work on numpy and CasADi values alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from designopt.kinematics.joints import Chain
from designopt.kinematics.transforms import is_symbolic

PAPER_MODULES = (  # Table II of the paper: (theta free, d, a, alpha)
    {"d": 0.0, "a": 0.5, "alpha": 0.0},
    {"d": 0.0, "a": 0.5, "alpha": math.pi / 2},
    {"d": 1.0, "a": 0.0, "alpha": 0.0},
    {"d": 1.0, "a": 0.5, "alpha": 0.0},
    {"d": 0.5, "a": 0.5, "alpha": -math.pi / 2},
)
# Two screening costs this close (relative) are one optimum: IPOPT ends the same robot's optimum within ~4e-7 from
# different starts, where the nearest distinct optima of the paper's catalogue seen in screens lay 9e-4 apart.
SAME_OPTIMUM = 1.0e-6
TWIST_TOL = 1.0e-9  # a twist within this (rad, through sin and cos) of 0 or pi keeps z parallel to the base's


@dataclass(frozen=True)
class Catalogue:
    """Modules of one joint type. Each module: (offset, a, alpha) with offset = d (R) or theta (P)."""

    joint_type: str
    modules: tuple[tuple[float, float, float], ...]
    w_lin: float = 1.0
    w_ang: float = 1.0

    def params(self) -> tuple[str, str, str]:
        """Which DH parameters a module fixes, in the order of its tuple."""
        return ("d", "a", "alpha") if self.joint_type == "R" else ("theta", "a", "alpha")


def _cos(x):
    return ca.cos(x) if is_symbolic(x) else np.cos(x)


def distance(link, module, catalogue: Catalogue):
    """Weighted distance between a link's (offset, a, alpha) and a module; angles through 1 - cos."""
    offset, a, alpha = link
    m_offset, m_a, m_alpha = module
    if catalogue.joint_type == "R":
        linear = (offset - m_offset) ** 2 + (a - m_a) ** 2
        angular = 2 * (1 - _cos(alpha - m_alpha))
    else:  # theta is an angle too on a P link
        linear = (a - m_a) ** 2
        angular = 2 * (1 - _cos(alpha - m_alpha)) + 2 * (1 - _cos(offset - m_offset))
    return catalogue.w_lin * linear + catalogue.w_ang * angular


def link_vectors(chain: Chain, q_d, catalogue: Catalogue) -> list[list]:
    """Each link's (offset, a, alpha), taken from q_d where they are design joints, else fixed values."""
    values = chain.link_values([0.0] * chain.n_moving, q_d)  # moving values are never read here
    index = {"theta": 0, "d": 1, "a": 2, "alpha": 3}
    return [[row[index[p]] for p in catalogue.params()] for row in values]


def modular_cost(chain: Chain, q_d, catalogue: Catalogue):
    """L_mod = sum over links of the product over modules of dist(link, module)."""
    total = 0
    for link in link_vectors(chain, q_d, catalogue):
        prod = 1
        for module in catalogue.modules:
            prod = prod * distance(link, module, catalogue)
        total = total + prod
    return total


def nearest_modules(chain: Chain, q_d, catalogue: Catalogue) -> list[int]:
    """Index of the nearest module for every link (by the same weighted distance)."""
    return [int(np.argmin([distance(np.asarray(link, float), m, catalogue) for m in catalogue.modules]))
            for link in link_vectors(chain, np.asarray(q_d, float), catalogue)]


def check_catalogue(structure: str, catalogue: Catalogue) -> None:
    """The paper's assumption: every link has the catalogue's joint type."""
    if set(structure) != {catalogue.joint_type}:
        raise ValueError(f"structure {structure} mixes joint types; all modules are {catalogue.joint_type} "
                         f"joints (the three-step method assumes one joint type and a fixed number of joints)")


def neighbours(assignment: tuple[int, ...], n_modules: int) -> list[tuple[int, ...]]:
    """Every assignment that differs from ``assignment`` in one link's module."""
    return [assignment[:i] + (k,) + assignment[i + 1:] for i in range(len(assignment)) for k in range(n_modules)
            if k != assignment[i]]


def swapped(assignment: tuple[int, ...]) -> list[tuple[int, ...]]:
    """Every assignment with the modules of two neighbouring links exchanged, where they differ: the same
    modules in another order, which one-link changes reach only through two steps (the first of which may cost
    more)."""
    return [assignment[:i] + (assignment[i + 1], assignment[i]) + assignment[i + 2:]
            for i in range(len(assignment) - 1) if assignment[i] != assignment[i + 1]]


def lift_choices(assignment: tuple[int, ...], catalogue: Catalogue) -> list[list[tuple[int, float]]]:
    """For every link, the modules that build the same robot in its place, each with the lift it adds (m).

    A DH link is Rz(theta) Tz(d) Tx(a) Rx(alpha). While every twist before a link is 0 or pi, the link's z axis
    is parallel to the base's (reversed by each pi), so its d translates the rest of the robot along base z by
    the same vector at every joint angle: it lifts the robot, and a free placement z (W in B) absorbs the lift
    exactly. This holds for every link up to and including the first twisted one (alpha not 0 or pi); there any
    module with the same (a, alpha) builds the same robot, lifted by its signed d; past it only the module
    itself. A P link's d moves, so a P catalogue has no lifts: each link's choice is its own module, lift 0.
    """
    if catalogue.joint_type != "R":
        return [[(k, 0.0)] for k in assignment]
    choices, sign, lifting = [], 1.0, True
    for k in assignment:
        _, a, alpha = catalogue.modules[k]
        if lifting:
            choices.append([(j, sign * d) for j, (d, aj, alj) in enumerate(catalogue.modules)
                            if aj == a and math.cos(alj - alpha) > 1 - TWIST_TOL])
            lifting = abs(math.sin(alpha)) <= TWIST_TOL
            sign = sign if math.cos(alpha) > 0 else -sign
        else:
            choices.append([(k, 0.0)])
    return choices


def lift(assignment: tuple[int, ...], catalogue: Catalogue) -> float:
    """How far (m, along base z) an assignment lifts the robot it builds (`lift_choices`)."""
    return sum(dict(options)[k] for k, options in zip(assignment, lift_choices(assignment, catalogue), strict=True))


def same_robot(assignment: tuple[int, ...], catalogue: Catalogue) -> tuple:
    """A key equal for exactly the assignments that build one robot up to a lift along base z (`lift_choices`)."""
    return tuple(tuple(sorted(j for j, _ in options)) if len(options) > 1 else options[0][0]
                 for options in lift_choices(assignment, catalogue))


def _reachable(choices: list[list[tuple[int, float]]]) -> list[set[float]]:
    """For every link i (and one past the last), the lifts (m, to 1e-12) the links from i on can add."""
    reachable = [{0.0}]
    for options in reversed(choices):
        reachable.insert(0, {round(r + d, 12) for r in reachable[0] for _, d in options})
    return reachable


def lifts(assignment: tuple[int, ...], catalogue: Catalogue) -> list[float]:
    """Every lift (m) an assignment of the same robot can have, ascending."""
    return sorted(_reachable(lift_choices(assignment, catalogue))[0])


def lifted_assignment(assignment: tuple[int, ...], catalogue: Catalogue, target: float) -> tuple[int, ...] | None:
    """An assignment of the same robot whose lift is ``target`` (m, to 1e-9), keeping each link's module, from the
    base on, wherever the links after it can still make up the rest (the given one when its own lift is
    ``target``); None when no assignment of the robot has that lift."""
    choices = lift_choices(assignment, catalogue)
    reachable = _reachable(choices)
    if not any(abs(r - target) <= 1e-9 for r in reachable[0]):
        return None
    picked, rest = [], target
    for i, options in enumerate(choices):
        own = [o for o in options if o[0] == assignment[i]]  # keep this link's module where the rest can follow
        for k, d in own + [o for o in options if o[0] != assignment[i]]:
            if any(abs(r - (rest - d)) <= 1e-9 for r in reachable[i + 1]):
                picked.append(k)
                rest -= d
                break
    return tuple(picked)


def lifted_range(assignment: tuple[int, ...], catalogue: Catalogue, box: tuple[float, float]) -> tuple[float, float]:
    """The placement z (m, W in B) over which the robot ``assignment`` builds fits the task as some assignment of
    the same robot with its placement z inside ``box``: that assignment's z is this z plus its lift minus this
    one's. One interval when no two neighbouring lifts lie further apart than the box is tall (`lifts_absorbed`)."""
    own, reached = lift(assignment, catalogue), lifts(assignment, catalogue)
    return box[0] - (reached[-1] - own), box[1] - (reached[0] - own)


def within_box(assignment: tuple[int, ...], catalogue: Catalogue, z: float, box: tuple[float, float],
               tol: float = 1e-6) -> tuple[tuple[int, ...], float]:
    """The assignment of the same robot whose placement z lies in ``box`` (to ``tol``, m) when ``assignment``'s is
    ``z``, and that z: ``assignment`` itself if its z is inside, else the one with the lift nearest its own."""
    if box[0] - tol <= z <= box[1] + tol:
        return tuple(assignment), z
    own = lift(assignment, catalogue)
    inside = [r for r in lifts(assignment, catalogue) if box[0] - tol <= z + r - own <= box[1] + tol]
    if not inside:
        raise ValueError(f"placement z {z} lies outside {box} for every assignment of this robot")
    target = min(inside, key=lambda r: (abs(r - own), r))
    return lifted_assignment(assignment, catalogue, target), z + target - own


def lifts_absorbed(catalogue: Catalogue, box: tuple[float, float]) -> bool:
    """Whether a placement z free in ``box`` absorbs every lift: a revolute catalogue whose d span no more than the
    box is tall, so the lifts of one robot lie no further apart than that and `lifted_range` is one interval."""
    offsets = [m[0] for m in catalogue.modules]
    return catalogue.joint_type == "R" and max(offsets) - min(offsets) <= box[1] - box[0]


def neighbourhood_search(starts: list[tuple[int, ...]], n_modules: int, evaluate, budget: int,
                         cheapest_first: bool = False, same=None, swaps: bool = False):
    """Best-improvement local search over module assignments, from each of ``starts`` in turn.

    ``evaluate(assignments, incumbent) -> costs`` solves a batch (NaN or inf: does not track), the neighbours of
    ``incumbent`` (None for a start). ``same(assignment)`` (default: the assignment itself) is a key shared by
    assignments that build one robot (`same_robot`): one of them is evaluated, the first met, and the others
    take its cost for nothing; ``budget`` counts robots evaluated. A step evaluates every neighbour of the
    incumbent (one link's module changed; with ``swaps`` also every exchange of two neighbouring links' modules,
    `swapped`) and moves to the cheapest if it beats the incumbent; a start ends at a local optimum of this
    neighbourhood or when the budget is spent. ``cheapest_first``: every start is evaluated first, in one batch,
    and the local searches run from the cheapest start on (a start inside a basin searched already costs nothing
    more). Returns (best assignment, its cost, every (assignment evaluated, cost) in order: one per robot).
    """
    same = same or (lambda a: a)
    seen: dict = {}  # robot -> (the assignment evaluated for it, its cost)

    def costs(batch, incumbent=None):
        first: dict = {}  # each robot of the batch not evaluated yet, by its first assignment in the batch
        for a in batch:
            if same(a) not in seen:
                first.setdefault(same(a), a)
        new = list(first.items())[: max(budget - len(seen), 0)]
        if new:
            warm = None if incumbent is None else seen[same(incumbent)][0]
            values = evaluate([a for _, a in new], warm)
            seen.update({key: (a, float(c) if np.isfinite(c) else np.inf)
                         for (key, a), c in zip(new, values, strict=True)})
        return [seen[same(a)][1] if same(a) in seen else np.inf for a in batch]

    starts = [tuple(a) for a in starts]
    if cheapest_first:
        values = costs(starts)
        starts = [starts[i] for i in sorted(range(len(starts)), key=lambda i: (values[i], i))]
    for start in starts:
        current = start
        (cost,) = costs([current])
        while len(seen) < budget:
            around = neighbours(current, n_modules) + (swapped(current) if swaps else [])
            values = costs(around, current)
            k = int(np.argmin(values))
            if values[k] >= cost:
                break
            current, cost = around[k], values[k]
    evaluated = list(seen.values())
    best, value = min(evaluated, key=lambda pair: pair[1])
    return list(best), value, evaluated


def spread_assignments(count: int, n_links: int, n_modules: int, seed: int) -> list[tuple[int, ...]]:
    """``count`` module assignments spread over the catalogue, from ``seed`` alone: on every link each module
    appears equally often (to one; a Latin hypercube over the links), in a seeded random order per link."""
    rng = np.random.default_rng([seed, 25])
    columns = [rng.permutation(np.resize(np.arange(n_modules), count)) for _ in range(n_links)]
    return [tuple(int(column[i]) for column in columns) for i in range(count)]


def screened_candidates(start: tuple[int, ...], n_modules: int, screen, budget: int, sample: int, refine: int,
                        seed: int, same=None, swaps: bool = False):
    """The coarse half of the modular search: ``start`` (the rounded assignment) and ``sample`` seeded
    `spread_assignments` screened in one batch (``screen(assignments, incumbent)``), then `neighbourhood_search`
    from them cheapest first, within ``budget`` robots screened in all (``same``: which assignments are one
    robot, and ``swaps``: see `neighbourhood_search`). Returns (the ``refine`` best screened assignments that
    track and are `distinct_optima`, best first; every (assignment, screening cost) in the order screened)."""
    starts = [tuple(start), *spread_assignments(sample, len(start), n_modules, seed)]
    _, _, evaluated = neighbourhood_search(starts, n_modules, screen, budget, cheapest_first=True, same=same,
                                           swaps=swaps)
    return distinct_optima([(a, c) for a, c in evaluated if np.isfinite(c)], refine), evaluated


def distinct_optima(screened: list[tuple[tuple[int, ...], float]], count: int,
                    rel_tol: float = SAME_OPTIMUM) -> list[tuple[int, ...]]:
    """The ``count`` cheapest of ``(assignment, cost)`` pairs, best first, one per optimum: an assignment whose cost
    equals (to ``rel_tol``) one already picked is skipped. Assignments that differ only where the free placement
    and joint angles absorb the difference (a module's offset d along the first joint's axis, say) are the same
    robot; screened from the same warm start they end at the same optimum to the last digits, and refining both
    would solve one robot twice."""
    picked: list[tuple[tuple[int, ...], float]] = []
    for a, c in sorted(screened, key=lambda pair: pair[1]):
        if len(picked) == count:
            break
        if not any(abs(c - kept) <= rel_tol * abs(kept) for _, kept in picked):
            picked.append((a, c))
    return [a for a, _ in picked]
