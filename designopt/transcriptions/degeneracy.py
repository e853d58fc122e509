"""Designs on which the tracking constraints degenerate, and the problem that holds them (issue 12, cause 3).

When every joint axis of the robot is parallel to the workpiece normal (a DH arm with every twist at 0 or pi,
a PPP gantry), the tool axis no longer depends on the moving joints, and neither does the tool's height over a
planar path: the N copies of those tracking rows become copies of one function of the design. The equality
constraints lose rank there (LICQ fails), and an IPOPT iterate that reaches such a design creeps until its
iteration cap or fails in restoration (docs/benchmarks.md, "The design-only stall, cause 3").

The set is a piece of the feasible set on its own: with the design angles that put the arm there held, and each
row that no longer depends on the joints imposed once (`q_independent_rows`), the problem is regular again.
`held_at_multiples_of_pi` builds that problem from a design; `designopt.solve.observers.DegenerateWatch` stops a
solve that sits there, and `designopt.solve.strategies.continuation` finishes it on the held problem.
"""

from __future__ import annotations

import functools
import pickle
from dataclasses import replace

import casadi as ca
import numpy as np

from designopt.costs import waypoint
from designopt.kinematics.joints import Role
from designopt.problem import DesignProblem

POSITION_ROWS, AXIS_ROWS = (0, 1, 2), (3, 4, 5)  # the hard tracking rows: p_W - s_W, then z_W


def _sample(joints, rng) -> np.ndarray:
    """Uniform within each joint's bounds; an unbounded side is replaced by value -+ pi (angles) or 1 m (lengths)."""
    value = np.array([j.value for j in joints])
    half = np.where(np.array([j.kind for j in joints]) == "angle", np.pi, 1.0)
    lower, upper = np.array([j.lower for j in joints]), np.array([j.upper for j in joints])
    lo = np.where(np.isfinite(lower), lower, value - half)
    hi = np.where(np.isfinite(upper), upper, value + half)
    return rng.uniform(lo, hi)


def tracking_jacobian(problem: DesignProblem) -> ca.Function:
    """(q, q_d) -> the 6 x n_moving Jacobian d(p_W, z_W)/dq of the hard tracking rows (tool position in W [m],
    tool axis in W) with respect to the moving joints. Neither depends on the waypoint, only their targets do.
    Built once per chain in a process (every unconverged solve of a search asks, `held_at_multiples_of_pi`)."""
    return _tracking_jacobian(pickle.dumps(problem.chain))


@functools.lru_cache(maxsize=16)
def _tracking_jacobian(chain_key: bytes) -> ca.Function:
    chain = pickle.loads(chain_key)
    q, q_d = ca.SX.sym("q", chain.n_moving), ca.SX.sym("q_d", chain.n_design)
    w = waypoint(chain, q, q_d, ca.SX.zeros(3), ca.SX.zeros(3), None, "full")  # p_W, z_W: the chain's alone
    return ca.Function("drows_dq", [q, q_d], [ca.jacobian(ca.vertcat(w.p_W, w.z_W), q)])


def q_independent_rows(problem: DesignProblem, samples: int = 4, seed: int = 0, tol: float = 1e-9,
                       jacobian: ca.Function | None = None) -> np.ndarray:
    """The hard tracking rows (0-2 tool position in W, 3-5 tool axis z_W) that do not depend on the moving
    joints for any design within the design joints' bounds and whose target is the same at every tracked
    waypoint: holding such a row at one waypoint holds it at all of them.

    Independence is exact when the expression does not contain the joints (a PPP gantry's axis); otherwise it is
    judged on ``samples`` random (q, q_d) within bounds (a held twist of pi leaves sin(pi) = 1e-16 in the
    expression): every |d row / dq| below ``tol``. ``jacobian``: `tracking_jacobian` of this problem or of one
    that differs from it only in its joints' bounds (a held problem's is its unheld problem's), to build it once."""
    chain, tp = problem.chain, problem.toolpath
    jacobian = tracking_jacobian(problem) if jacobian is None else jacobian
    depends = set(jacobian.sparsity_out(0).get_triplet()[0])  # rows whose expression contains q at all
    rng = np.random.default_rng(seed)
    draws = [(_sample(chain.moving, rng), _sample(chain.design, rng)) for _ in range(samples)]
    tracked = tp.is_tracked
    out = []
    for i in (*POSITION_ROWS, *AXIS_ROWS):
        if i in depends and any(np.abs(np.asarray(jacobian(a, b))[i]).max() > tol for a, b in draws):
            continue
        if i in POSITION_ROWS and tracked.any() and np.ptp(tp.points_W[tracked, i]) > 1e-12:
            continue  # a target that moves: a planar arm cannot follow it, and holding the row once would hide that
        out.append(i)
    return np.array(out, dtype=int)


def held_at_multiples_of_pi(problem: DesignProblem, q_d, tol: float = 1e-3,
                            jacobian: ca.Function | None = None) -> tuple[DesignProblem, np.ndarray] | None:
    """``problem`` with every angle design joint within ``tol`` (rad) of a multiple of pi held there (its bounds
    set to that value), and the design with those joints snapped; None when no joint not yet held is that close,
    or when holding them frees no tracking row from the joints that the problem did not already hold once.
    A held joint stays a design joint: the solution's layout does not change, IPOPT treats it as fixed.
    ``jacobian``: the problem's `tracking_jacobian`, for a caller that asks many times (built here otherwise)."""
    q_d = np.array(q_d, dtype=float)
    joints = list(problem.chain.joints)
    design_index = [i for i, j in enumerate(joints) if j.role is Role.DESIGN]
    held = 0
    for k, i in enumerate(design_index):
        joint = joints[i]
        snapped = float(np.round(q_d[k] / np.pi) * np.pi)
        if (joint.kind != "angle" or joint.lower == joint.upper or abs(snapped - q_d[k]) > tol
                or not joint.lower <= snapped <= joint.upper):
            continue
        joints[i] = replace(joint, value=snapped, lower=snapped, upper=snapped)
        q_d[k] = snapped
        held += 1
    if not held:
        return None
    candidate = replace(problem, chain=replace(problem.chain, joints=tuple(joints)))
    jacobian = tracking_jacobian(problem) if jacobian is None else jacobian  # held joints stay inputs: one function
    before = len(q_independent_rows(problem, jacobian=jacobian))
    if len(q_independent_rows(candidate, jacobian=jacobian)) <= before:
        return None  # e.g. a PPP gantry, whose axis rows never depended on its joints: nothing degenerates here
    return candidate, q_d


def shared_shape(problem: DesignProblem) -> DesignProblem:
    """The problem whose NLP a solve of ``problem`` can use: ``problem`` with each held design joint (lower ==
    upper) held at 0 instead. A held joint stays a variable of the NLP, so where it is held changes only its bounds,
    which a solve passes (`designopt.solve.backends.base.Prepared.bounded`), and the tracking rows imposed once
    (`q_independent_rows`, judged at the held values). The held problems of a search's continuations (twists held at
    0 or +-pi) then share one NLP per set of held joints instead of one each. ``problem`` itself when no design joint
    is held, when every held one is at 0 already, or when the rows imposed once at 0 are not those at its values."""
    joints = problem.chain.joints
    held = [i for i, j in enumerate(joints) if j.role is Role.DESIGN and j.lower == j.upper]
    if all(_plus_zero(joints[i].value) and _plus_zero(joints[i].lower) for i in held):
        return problem
    at_zero = list(joints)
    for i in held:
        at_zero[i] = replace(joints[i], value=0.0, lower=0.0, upper=0.0)
    shape = replace(problem, chain=replace(problem.chain, joints=tuple(at_zero)))
    jacobian = tracking_jacobian(shape)  # the held values are inputs of it: one function for both
    if not np.array_equal(q_independent_rows(problem, jacobian=jacobian), q_independent_rows(shape, jacobian=jacobian)):
        return problem
    return shape


def _plus_zero(x: float) -> bool:
    """x is +0.0 (a joint held at -0.0 pickles differently, so it is moved to +0.0 too)."""
    return x == 0.0 and not np.signbit(x)
