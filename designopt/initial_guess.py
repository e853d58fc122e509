"""Seeded initial guesses for multistart.

A start perturbs the design joints around their configured values and picks a joint configuration;
``ik`` mode then walks the path waypoint by waypoint with a damped least-squares inverse kinematics,
each waypoint warm-started from the previous one, so the start trajectory is continuous (one IK branch)
and tracks as well as the start design allows. ``constant`` mode holds that configuration at every
waypoint and leaves tracking to the solver.
"""

from __future__ import annotations

import numpy as np

from designopt.kinematics.chain import geometric_jacobian, placement_pose, tool_pose
from designopt.problem import DesignProblem
from designopt.transcriptions.base import InitialGuess

INIT_MODES = ("ik", "constant")


def perturbed_design(problem: DesignProblem, rng: np.random.Generator, scale: float) -> np.ndarray:
    """Design joints: configured values plus uniform noise (scale x 0.5 m for lengths, scale x pi for
    angles), clipped to their bounds."""
    joints = problem.chain.design
    noise = rng.uniform(-1.0, 1.0, len(joints))
    step = np.array([0.5 if j.kind == "length" else np.pi for j in joints]) * scale
    values = np.array([j.value for j in joints]) + noise * step
    return np.clip(values, [j.lower for j in joints], [j.upper for j in joints])


def random_configuration(problem: DesignProblem, rng: np.random.Generator) -> np.ndarray:
    """A joint configuration: revolute joints uniform in [-pi/2, pi/2], prismatic at mid-stroke +- 0.2."""
    out = []
    for j in problem.chain.moving:
        if j.kind == "angle":
            out.append(rng.uniform(-np.pi / 2, np.pi / 2))
        else:
            mid = 0.5 * (max(j.lower, -1.0) + min(j.upper, 1.0))
            out.append(mid + rng.uniform(-0.2, 0.2))
    return np.array(out)


def ik_residual(problem: DesignProblem, q: np.ndarray, q_d: np.ndarray, k: int):
    """Tracking residual at waypoint k in W (position; tool axis minus (0, 0, -1)) and its Jacobian."""
    chain, tp = problem.chain, problem.toolpath
    T_BW = placement_pose(chain, q, q_d)
    R_WB = T_BW[:3, :3].T
    T = tool_pose(chain, q, q_d)
    J = geometric_jacobian(chain, q, q_d)
    z = T[:3, 2]
    r = np.concatenate([R_WB @ (T[:3, 3] - T_BW[:3, 3]) - tp.points_W[k], R_WB @ z - np.array([0.0, 0.0, -1.0])])
    Jz = np.cross(J[3:, :].T, z).T  # dz/dq_i = omega_i x z
    return r, np.vstack([R_WB @ J[:3, :], R_WB @ Jz])


def ik_trajectory(problem: DesignProblem, q_d: np.ndarray, q0: np.ndarray, iterations: int = 30) -> np.ndarray:
    """Damped least-squares IK along the path, each waypoint starting from the previous solution."""
    lo = np.array([j.lower for j in problem.chain.moving])
    hi = np.array([j.upper for j in problem.chain.moving])
    Q = np.empty((problem.toolpath.n, len(q0)))
    q = np.array(q0, dtype=float)
    for k in range(problem.toolpath.n):
        damping = 1e-2
        r, J = ik_residual(problem, q, q_d, k)
        for _ in range(iterations if k == 0 else max(8, iterations // 3)):
            step = np.linalg.solve(J.T @ J + damping * np.eye(len(q)), -J.T @ r)
            trial = np.clip(q + step, lo, hi)
            r_new, J_new = ik_residual(problem, trial, q_d, k)
            if r_new @ r_new < r @ r:
                q, r, J, damping = trial, r_new, J_new, max(damping / 3, 1e-6)
            else:
                damping *= 5
            if r @ r < 1e-14:
                break
        Q[k] = q
    return Q


def initial_guess(problem: DesignProblem, index: int, seed: int, scale: float, mode: str = "ik") -> InitialGuess:
    """Start ``index`` of a seeded multistart (seed * 1000 + index). Start 0 keeps the configured design;
    the others perturb it. Each start depends only on (seed, index), so starts can be made in any order."""
    if mode not in INIT_MODES:
        raise ValueError(f"init must be one of {INIT_MODES}, got {mode!r}")
    rng = np.random.default_rng([seed, index])
    q_d = problem.chain.design_values if index == 0 else perturbed_design(problem, rng, scale)
    q0 = random_configuration(problem, rng)
    Q = ik_trajectory(problem, q_d, q0) if mode == "ik" else np.tile(q0, (problem.toolpath.n, 1))
    return InitialGuess(q_d=q_d, Q=Q, seed=seed * 1000 + index)


def initial_guesses(problem: DesignProblem, count: int, seed: int, scale: float, mode: str = "ik"):
    """The first ``count`` starts of a seeded multistart."""
    return [initial_guess(problem, i, seed, scale, mode) for i in range(count)]
