"""Local optima: when two designs are the same optimum, the distinct ones among many solutions, the best one.

Designs are compared joint by joint: metres for lengths, radians (wrapped) for angles.
"""

from __future__ import annotations

import numpy as np

from designopt.kinematics.joints import Role

TWO_PI = 2.0 * np.pi


def design_distances(a: np.ndarray, b: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Largest difference between design ``a`` and each design in the last axis of ``b`` (one design, or one per
    row): metres for lengths, radians for angles (the shorter way round the circle, in [0, pi]); 0 without design
    joints."""
    return np.max(joint_differences(a, b, angle), axis=-1, initial=0.0)


def joint_differences(a: np.ndarray, b: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """|a - b| joint by joint (``b`` one design, or one per row): metres for lengths, radians for the angles marked in
    ``angle``, the shorter way round the circle (|a - b| modulo 2 pi, or 2 pi less that: in [0, pi])."""
    d = np.abs(np.asarray(a, float) - np.asarray(b, float))
    angle = np.flatnonzero(angle)
    if angle.size:
        turn = np.mod(d[..., angle], TWO_PI)
        d[..., angle] = np.minimum(turn, TWO_PI - turn)
    return d


def design_distance(a: np.ndarray, b: np.ndarray, angle: np.ndarray) -> float:
    """Largest difference between two designs (`design_distances`)."""
    return float(design_distances(a, b, angle))


def cluster_designs(designs: np.ndarray, costs: np.ndarray, angle: np.ndarray, tol: float = 0.02,
                    arm: np.ndarray | None = None, same_arm_cost: float | None = None,
                    arms: np.ndarray | None = None) -> np.ndarray:
    """Label each design with its local optimum: in order of cost, a design joins the first (cheaper) cluster
    whose representative lies within ``tol`` (m or rad) in every design joint (`design_distance`), else starts a
    new one. With ``same_arm_cost`` (a fraction) it also joins a cluster whose representative's arm -- the design
    joints marked in ``arm`` (`arm_joints`) -- lies within ``tol`` and whose cost it exceeds by at most that
    fraction: the same arm at the same cost, placed elsewhere (without design joints in the arm, a fixed robot's
    placements, a tie in cost alone is no such evidence: not merged). ``arms`` (one row per design, e.g.
    `arm_invariants`): compare these rows instead of the arm joints for that rule (within ``tol`` in every
    column). Each design is compared with every representative at once, its joint differences taken once for both
    rules: a default run's 880 coarse optima, most of them distinct, are clustered several times between its
    stages, while the workers wait."""
    designs = np.asarray(designs, float).reshape(len(costs), -1)
    costs = np.asarray(costs, float)
    order = np.argsort(costs, kind="stable")
    labels, leaders, n = np.empty(len(costs), dtype=int), np.empty_like(designs), 0
    leader_costs = np.empty(len(costs))
    merge = same_arm_cost is not None and arm is not None and arm.any()
    if merge and arms is not None:
        arms = np.asarray(arms, float).reshape(len(costs), -1)
        leader_arms = np.empty_like(arms)
    for i in order:
        if n:
            differences = joint_differences(designs[i], leaders[:n], angle)
            close = np.max(differences, axis=-1, initial=0.0) <= tol
            if merge:
                arm_close = (np.max(differences[:, arm], axis=-1) if arms is None
                             else np.max(np.abs(leader_arms[:n] - arms[i]), axis=-1, initial=0.0)) <= tol
                close |= arm_close & (costs[i] <= (1 + same_arm_cost) * leader_costs[:n])
            near = np.flatnonzero(close)
            if near.size:
                labels[i] = near[0]
                continue
        labels[i], leaders[n], leader_costs[n] = n, designs[i], costs[i]
        if merge and arms is not None:
            leader_arms[n] = arms[i]
        n += 1
    return labels


def arm_invariants(chain, designs: np.ndarray) -> np.ndarray:
    """Each design's arm whichever way its joint axes point (one row per design, `arm_joints`' columns): its
    lengths by their size (m), its angles as the angle between two lines, folded into [0, pi/2] (rad). A DH
    arm's reflections (`kinematics.reflections`: a length's sign flipped, the twists beside it turned by pi or
    negated), a twist turned by pi on two links with the offsets between them negated, and a mirror image
    all give one row; so the same arm written several ways, at the same cost, is one optimum
    (`cluster_designs`' ``arms``). Joint by joint: lengths along their axes, other angles (a URDF origin's)
    folded alike."""
    arm = arm_joints(chain)
    designs = np.asarray(designs, float).reshape(-1, len(arm))[:, arm]
    angle = np.array([j.kind == "angle" for j in chain.design], dtype=bool)[arm]
    out = np.abs(designs)
    turn = np.mod(designs[:, angle], np.pi)
    out[:, angle] = np.minimum(turn, np.pi - turn)
    return out


def form_joints(chain) -> np.ndarray:
    """Which design joints make an arm's form (`design_forms`): its design angles between its first and its last
    moving joint, which turn one joint axis against the next (a DH link's twist, a URDF joint origin's angles);
    not the placement's, nor those after the last moving joint (the tool's)."""
    moving = [k for k, et in enumerate(chain.robot) if chain.joints[et.joint].role is Role.MOVING]
    inner = {et.joint for et in chain.robot[moving[0] + 1:moving[-1]]} if moving else set()
    design = [i for i, j in enumerate(chain.joints) if j.role is Role.DESIGN]
    return np.array([chain.joints[i].kind == "angle" and i in inner for i in design], dtype=bool)


def arm_joints(chain) -> np.ndarray:
    """Which design joints make the arm: every design joint but the placement's (the walk from the robot base to
    the workpiece, ``chain.placement``). The same arm placed elsewhere differs from itself only outside this mask."""
    placement = {et.joint for et in chain.placement}
    design = [i for i, j in enumerate(chain.joints) if j.role is Role.DESIGN]
    return np.array([i not in placement for i in design], dtype=bool)


def snapped_design(chain, q_d: np.ndarray) -> np.ndarray:
    """Design joints with the arm's angles (`arm_joints` of kind angle: DH twists, a URDF joint origin's angles) at
    their nearest multiple of pi/2 (rad), within bounds; lengths and placement as given. The idealised arm of a
    design's form (`design_forms`): consecutive joint axes exactly parallel or perpendicular where the design has
    them nearly so."""
    lattice = arm_joints(chain) & np.array([j.kind == "angle" for j in chain.design], dtype=bool)
    q = np.array(q_d, dtype=float)
    q[lattice] = np.round(q[lattice] / (np.pi / 2)) * (np.pi / 2)
    return np.clip(q, [j.lower for j in chain.design], [j.upper for j in chain.design])


def design_forms(designs: np.ndarray, form: np.ndarray) -> list[tuple[int, ...]]:
    """Each design's form: its design angles marked in ``form`` (`form_joints`), each 0 near a multiple of pi
    (consecutive joint axes parallel, for a twist) or 1 near an odd multiple of pi/2 (perpendicular) -- the
    pattern of the arm's joint axes, which its lengths do not change. ``designs``: one design per row."""
    angles = np.asarray(designs, float).reshape(len(designs), -1)[:, np.asarray(form, bool)]
    return [tuple(int(v) for v in row) for row in np.rint(angles / (np.pi / 2)).astype(int) % 2]


def distinct_best(solutions: list, count: int, tol: float = 0.02, per_form: int | None = None,
                  new_forms: int = 0, same_arm_cost: float | None = None, lineages: list | None = None,
                  new_lineages: int = 0, any_axis_direction: bool = False) -> list[int]:
    """Indices into ``solutions`` of the best tracking solution of each of the ``count`` cheapest distinct
    optima (`cluster_designs`), cheapest first. ``per_form``: at most this many optima of one form
    (`design_forms`) before the optima of other forms, cheapest first; then, if fewer than ``count`` are taken,
    the cheapest of the rest (None: by cost alone; a design space without form joints has one form, and is
    taken by cost alone too). ``new_forms``: then, beyond the ``count``, the cheapest optimum of each of up to
    this many forms not among them, cheapest first. ``same_arm_cost``: the same arm within that fraction of a
    cheaper optimum's cost is that optimum (`cluster_designs`; None: designs compared joint by joint only).
    ``new_lineages``: then the cheapest optimum of each of up to this many lineages not among them, cheapest first,
    where ``lineages`` gives each solution's (e.g. the second-round leader whose starts found it; None: of none).
    ``any_axis_direction``: the same arm at the same cost recognised whichever way its joint axes point
    (`arm_invariants`), not joint by joint."""
    tracking = [i for i, s in enumerate(solutions) if s.metrics.tracks]
    if not tracking or count <= 0:
        return []
    chain = solutions[tracking[0]].problem.chain
    angle = np.array([j.kind == "angle" for j in chain.design], dtype=bool)
    costs = np.array([solutions[i].metrics.design_cost for i in tracking])
    designs = np.array([solutions[i].raw.q_d for i in tracking]).reshape(len(tracking), -1)
    labels = cluster_designs(designs, costs, angle, tol, arm_joints(chain), same_arm_cost,
                             arm_invariants(chain, designs) if any_axis_direction else None)
    leaders = {}
    for k in np.argsort(costs, kind="stable"):
        leaders.setdefault(labels[k], k)
    ranked = list(leaders.values())  # positions in ``tracking``, cheapest optimum first
    form = form_joints(chain) if per_form is not None or new_forms else None
    if per_form is not None and form.any():
        forms = design_forms(designs[ranked], form)
        taken: dict[tuple[int, ...], int] = {}
        first = []
        for k, f in zip(ranked, forms, strict=True):
            if taken.get(f, 0) < per_form:
                taken[f] = taken.get(f, 0) + 1
                first.append(k)
        kept = set(first)
        ranked = first + [k for k in ranked if k not in kept]
    picked, rest = ranked[:count], ranked[count:]
    if new_forms and rest and form.any():
        seen = set(design_forms(designs[picked], form))
        for k, f in zip(rest, design_forms(designs[rest], form), strict=True):
            if len(picked) == count + new_forms:
                break
            if f not in seen:
                seen.add(f)
                picked.append(k)
    if new_lineages and lineages is not None:
        seen, wanted = {lineages[tracking[k]] for k in picked}, len(picked) + new_lineages
        for k in ranked:
            if len(picked) == wanted:
                break
            if lineages[tracking[k]] is not None and lineages[tracking[k]] not in seen:
                seen.add(lineages[tracking[k]])
                picked.append(k)
    return [tracking[k] for k in picked]


def best_solution(solutions):
    """The tracking solution with the lowest design cost (None if none tracks)."""
    tracking = [s for s in solutions if s.metrics.tracks]
    return min(tracking, key=lambda s: s.metrics.design_cost) if tracking else None
