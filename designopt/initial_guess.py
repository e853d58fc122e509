"""Seeded initial guesses for multistart.

A start perturbs the design joints around their configured values and picks a joint configuration;
``ik`` mode then walks the path waypoint by waypoint with a damped least-squares inverse kinematics,
each waypoint warm-started from the previous one, so the start trajectory is continuous (one IK branch)
and tracks as well as the start design allows. ``home`` walks alike with the arm's self-motion pulled
towards the first configuration (`ik_trajectory`), so that around a closed path the walk returns to where
it began. ``reach`` does what ``ik`` does, but when the start design cannot follow the path it first
moves the design joints (placement and robot alike) the least it takes to reach it -- IK over the design
joints too (`reach`) -- because a start that is far from feasible costs IPOPT hundreds of iterations of
restoration. ``constant`` holds the configuration at every waypoint and leaves tracking to the solver.
"""

from __future__ import annotations

import functools
import pickle

import numpy as np

from designopt.costs import tracking_residual, waypoint
from designopt.problem import DesignProblem
from designopt.transcriptions.base import InitialGuess

INIT_MODES = ("reach", "ik", "home", "constant")
SPREADS = ("perturb", "box", "mixed")  # how seeded starts spread their designs (`initial_guess`)


def perturbed_design(problem: DesignProblem, rng: np.random.Generator, scale: float,
                     around: np.ndarray | None = None) -> np.ndarray:
    """Design joints: ``around`` (None: the configured values) plus uniform noise (scale x 0.5 m for lengths,
    scale x pi for angles), clipped to their bounds."""
    joints = problem.chain.design
    noise = rng.uniform(-1.0, 1.0, len(joints))
    step = np.array([0.5 if j.kind == "length" else np.pi for j in joints]) * scale
    centre = np.array([j.value for j in joints]) if around is None else np.asarray(around, float)
    return within_bounds(problem, centre + noise * step)


def within_bounds(problem: DesignProblem, q_d: np.ndarray) -> np.ndarray:
    """Design joint values clipped to their bounds."""
    joints = problem.chain.design
    return np.clip(np.asarray(q_d, float), [j.lower for j in joints], [j.upper for j in joints])


def box_design(problem: DesignProblem, rng: np.random.Generator) -> np.ndarray:
    """Design joints drawn from a box the size of the task, not around the configured design: angles uniform over
    the circle, the placement's position within +- b of its configured value, other lengths uniform in [0, b] m,
    with b half the path's largest extent (the optimum shrinks the arm toward the path's size); within bounds."""
    b = 0.5 * float(np.ptp(problem.toolpath.points_W, axis=0).max())
    placement = {j.name for j in problem.chain.placement_joints}
    out = []
    for j in problem.chain.design:
        if j.kind == "angle":
            out.append(rng.uniform(-np.pi, np.pi))
        elif j.name in placement:
            out.append(j.value + rng.uniform(-b, b))
        else:
            out.append(rng.uniform(0.0, b))
    return within_bounds(problem, np.array(out))


def random_configuration(problem: DesignProblem, rng: np.random.Generator, half_range: float = np.pi / 2) -> np.ndarray:
    """A joint configuration: revolute joints uniform in [-half_range, half_range] (rad), prismatic at mid-stroke
    +- 0.2 m."""
    out = []
    for j in problem.chain.moving:
        if j.kind == "angle":
            out.append(rng.uniform(-half_range, half_range))
        else:
            mid = 0.5 * (max(j.lower, -1.0) + min(j.upper, 1.0))
            out.append(mid + rng.uniform(-0.2, 0.2))
    return np.array(out)


def moving_bounds(problem: DesignProblem) -> tuple[np.ndarray, np.ndarray]:
    """The moving joints' lower and upper bounds (rad for revolute joints, m for prismatic ones), where an IK walk
    clips its steps."""
    return np.array([j.lower for j in problem.chain.moving]), np.array([j.upper for j in problem.chain.moving])


HOME_PULL = 0.5  # share of the self-motion step towards the home posture an IK iteration of ``init: home`` takes
HOME_STEP = 0.5  # largest self-motion step of one IK iteration [rad or m, the joints' own units]
POLISH = 10  # damped least-squares iterations without the pull that finish a waypoint's IK
IK_ITERATIONS = 30  # `ik_trajectory`'s damped least-squares iterations at its first waypoint (a third at the others)


def ik_trajectory(problem: DesignProblem, q_d: np.ndarray, q0: np.ndarray, iterations: int = IK_ITERATIONS,
                  home_pull: float = 0.0, waypoints: int | None = None) -> np.ndarray:
    """Damped least-squares IK along the path from ``q0``, each waypoint starting from the previous solution; with
    ``home_pull`` > 0 (`HOME_PULL` for ``init: home``), the redundancy resolved towards the first waypoint's
    configuration (the *home* posture).

    The first waypoint is walked to from ``q0`` as without the pull. At every later one each iteration takes the
    damped Gauss-Newton step on the tracking residual r(q) (tool position in W [m], tool axis) plus ``home_pull``
    times the step towards the home posture within the null space of dr/dq (the arm's self-motion, e.g. its turn
    about the tool axis; at most `HOME_STEP` long), and keeps it if the residual does not grow above what it was
    or above 1e-6; a rejected step halves the pull. Up to `POLISH` iterations without the pull then finish the
    waypoint on the path. So a waypoint's configuration lies towards the one nearest the home posture on its
    branch, which depends on the path point, not on the way there, and a walk around a closed path comes back to
    its first configuration. Minimum-norm steps alone (``home_pull`` 0) are not repeatable: around a closed path
    they drift along the self-motion, and the solver then spends the start undoing the drift (on 40 perturbed
    starts of a 12-waypoint circle, `tests/test_search.py`, 2 of the 25 walks on the path ended within 1e-3 of
    where they began; pulled, 27 of 27). Where dr/dq has no null space, or only joints the walk never moves (a
    last joint turning about the tool axis), the walk is the minimum-norm walk to the bit wherever that reaches the
    path (residual below 1e-7) within its iterations; at a waypoint it does not reach (an arm with too few joints
    for the path, a point out of reach) the `POLISH` iterations walk on, so the start differs there too.
    ``waypoints``: walk only the first that many (None: all); each row is the full walk's to the bit."""
    fn = point_residual(problem)
    points = problem.toolpath.points_W

    def residual(q, k):
        r, J_q = fn(q, q_d, points[k])
        return r.ravel(), J_q

    def towards_home(q, J):  # the self-motion step towards the home posture, at most HOME_STEP long
        _, s, Vt = np.linalg.svd(J)
        rank = int((s > 1e-6 * max(s[0], 1e-12)).sum()) if len(s) else 0
        N = Vt[rank:].T
        step = N @ (N.T @ (home - q))
        size = np.linalg.norm(step)
        return step * min(1.0, HOME_STEP / size) if size > 0 else step

    lo, hi = moving_bounds(problem)
    Q = np.empty((problem.toolpath.n if waypoints is None else min(waypoints, problem.toolpath.n), len(q0)))
    q = np.array(q0, dtype=float)
    home = None  # the first waypoint's own configuration, once walked to (the first waypoint is walked unpulled)
    eye = np.eye(len(q))
    for k in range(len(Q)):
        damping, pull = 1e-2, home_pull if k else 0.0
        r, J = residual(q, k)
        pulled = iterations if k == 0 else max(8, iterations // 3)
        for i in range(pulled + (POLISH if home_pull else 0)):
            if i == pulled:  # the pull may have stopped short of the path: back onto it without the pull
                pull = 0.0
                if r @ r < 1e-14:
                    break
            step = np.linalg.solve(J.T @ J + damping * eye, -J.T @ r)
            home_step = pull * towards_home(q, J) if pull else 0.0
            trial = np.clip(q + step + home_step, lo, hi)
            r_new, J_new = residual(trial, k)
            if r_new @ r_new < (max(r @ r, 1e-12) if np.any(home_step) else r @ r):
                q, r, J, damping = trial, r_new, J_new, max(damping / 3, 1e-6)
            else:
                damping, pull = damping * 5, pull / 2
            if r @ r < 1e-14 and np.linalg.norm(home_step) < 1e-6:
                break
        Q[k] = q
        if k == 0:
            home = q.copy()
    return Q


def projected(problem: DesignProblem, q_d: np.ndarray, Q: np.ndarray, iterations: int = 30,
              tol: float = 1e-3) -> np.ndarray:
    """``Q`` (N x n_moving) moved onto the path with the design ``q_d`` held: at every waypoint a damped
    least-squares IK on the tracking residual (tool position in W [m], tool axis), within the joints' bounds,
    from that waypoint's row of ``Q`` (so that it keeps its branch). Then, from the first waypoint on, a
    waypoint still further than ``tol`` from its target, or one that no trajectory within the velocity limits
    reaches from the waypoint before it (`beyond_reach`: the IK or ``Q`` changed branch there), starts again
    from the waypoint before it, as a walk along the path does. The walk is kept if it is nearer the target, or
    if it is on it (within ``tol``) and within reach where the step was not (where the path itself asks for more
    than the limits allow, the IK's own answer stays). A waypoint's residual never grows above its row's, or
    above ``tol`` where the step was beyond reach."""
    Q = np.array(Q, dtype=float)
    everywhere = np.arange(len(Q))
    chain = pickle.dumps(problem.chain)
    Q, r = _moved_onto_path(problem, q_d, Q, everywhere, iterations, chain)
    for k in range(1, len(Q)):
        jumped = bool(beyond_reach(problem, Q[k - 1 : k + 1], k - 1)[0])
        if np.linalg.norm(r[k]) > tol or jumped:
            walked, r_walked = _moved_onto_path(problem, q_d, Q[k - 1 : k], everywhere[k : k + 1], iterations,
                                                chain)
            nearer = r_walked[0] @ r_walked[0] < r[k] @ r[k]
            reached = np.linalg.norm(r_walked[0]) <= tol and not beyond_reach(problem, np.vstack([Q[k - 1], walked]),
                                                                             k - 1)[0]
            if nearer or (jumped and reached):
                Q[k], r[k] = walked[0], r_walked[0]
    return Q


def beyond_reach(problem: DesignProblem, Q: np.ndarray, first: int = 0) -> np.ndarray:
    """For each step between rows of ``Q`` (waypoints ``first``, ``first + 1``, ...): is some joint's step
    longer than it can move in the time between them (`DesignProblem.max_steps`)? No trajectory the collocation
    accepts makes such a step. (len(Q) - 1 booleans.)"""
    return np.any(np.abs(np.diff(Q, axis=0)) > problem.max_steps[first : first + len(Q) - 1], axis=1)


def _moved_onto_path(problem: DesignProblem, q_d: np.ndarray, Q: np.ndarray, ks: np.ndarray, iterations: int,
                     chain: bytes | None = None):
    """(Q, residuals): damped least squares at waypoints ``ks`` from the rows of ``Q`` (len(ks) x n_moving), each
    waypoint with its own damping; a step that does not lower a waypoint's residual is not taken. ``chain``: the
    problem's chain pickled, the key of its residual functions (None: pickled here)."""
    n, n_m = Q.shape
    # r and dr/dq only: the design is held
    fn = _mapped_point_residual(pickle.dumps(problem.chain) if chain is None else chain, n)
    S = problem.toolpath.points_W[ks].T
    D = np.tile(np.asarray(q_d, float)[:, None], (1, n))
    lo, hi = moving_bounds(problem)

    def evaluate(Q):  # residuals (n x 6) and Jacobians (n x 6 x n_m)
        r, J_q = fn(Q.T, D, S)
        return r.T, J_q.reshape(6, n, n_m).transpose(1, 0, 2)

    Q = np.array(Q, dtype=float)
    r, J = evaluate(Q)
    damping = np.full(n, 1e-2)
    eye = np.eye(n_m)
    for _ in range(iterations):
        JT = J.transpose(0, 2, 1)
        step = np.linalg.solve(JT @ J + damping[:, None, None] * eye, -(JT @ r[:, :, None]))[:, :, 0]
        trial = np.clip(Q + step, lo, hi)
        r_new, J_new = evaluate(trial)
        off = np.sum(r**2, axis=1) >= 1e-14  # a waypoint on its target stays where it is
        better = off & (np.sum(r_new**2, axis=1) < np.sum(r**2, axis=1))
        Q[better], r[better], J[better] = trial[better], r_new[better], J_new[better]
        damping = np.where(better, np.maximum(damping / 3, 1e-6), damping * 5)
        if not off.any():
            break
    return Q, r


def reach(problem: DesignProblem, q_d: np.ndarray, Q: np.ndarray, iterations: int = 60, samples=None):
    """A design near ``q_d`` and a trajectory near ``Q`` that follow the path: IK over the design joints too.

    Design joints are joints: a damped least-squares IK on the tracking residuals at every waypoint, with the
    design joints shared by all waypoints and kept within their bounds, starting from the IK walk ``Q`` (so
    the trajectory stays on its branch). The damping keeps the design near the start (so starts stay
    diverse). Returns (q_d, Q).
    """
    chain = problem.chain
    ks = np.arange(problem.toolpath.n) if samples is None else np.asarray(samples)
    N, n_m, n_d = len(ks), chain.n_moving, chain.n_design
    lo = np.concatenate([[j.lower for j in chain.design], np.tile([j.lower for j in chain.moving], N)])
    hi = np.concatenate([[j.upper for j in chain.design], np.tile([j.upper for j in chain.moving], N)])
    fn = residual_function(problem).map(N)
    S = problem.toolpath.points_W[ks].T
    rows = np.arange(6 * N).reshape(N, 6)

    def evaluate(z):
        r, J_q, J_d = fn(z[n_d:].reshape(N, n_m).T, np.tile(z[:n_d, None], (1, N)), S)
        J_q, J_d = np.array(J_q), np.array(J_d)
        J = np.zeros((6 * N, n_d + n_m * N))
        for k in range(N):
            J[rows[k], :n_d] = J_d[:, n_d * k : n_d * (k + 1)]
            J[rows[k], n_d + n_m * k : n_d + n_m * (k + 1)] = J_q[:, n_m * k : n_m * (k + 1)]
        return np.array(r).T.ravel(), J

    z = np.concatenate([q_d, np.asarray(Q, dtype=float)[ks].ravel()])
    r, J = evaluate(z)
    damping = 1e-2
    for _ in range(iterations):
        if r @ r < 1e-14:
            break
        trial = np.clip(z + np.linalg.solve(J.T @ J + damping * np.eye(len(z)), -J.T @ r), lo, hi)
        r_new, J_new = evaluate(trial)
        if r_new @ r_new < r @ r:
            z, r, J, damping = trial, r_new, J_new, max(damping / 3, 1e-6)
        else:
            damping *= 5
    return z[:n_d], z[n_d:].reshape(N, n_m)


def residual_function(problem: DesignProblem):
    """(q, q_d, s_W) -> tracking residual r = (p_W - s_W [m], z_W - (0, 0, -1)), in the workpiece frame W, and its
    Jacobians dr/dq and dr/dq_d (6 x n_moving, 6 x n_design): a CasADi function of the problem's chain, built once
    per chain in a process (a numpy walk of the chain costs ~20x more per call, and starts call it ~100 times per
    waypoint). s_W: a path point in W [m]."""
    return _residual_function(pickle.dumps(problem.chain))


@functools.lru_cache(maxsize=16)
def _residual_function(payload: bytes):
    import casadi as ca

    chain = pickle.loads(payload)
    q, q_d, s_W = ca.SX.sym("q", chain.n_moving), ca.SX.sym("q_d", chain.n_design), ca.SX.sym("s_W", 3)
    w = waypoint(chain, q, q_d, s_W, ca.SX.zeros(3), None, "full")
    r = ca.vertcat(*tracking_residual(w))
    return ca.Function("tracking_residual", [q, q_d, s_W], [r, ca.jacobian(r, q), ca.jacobian(r, q_d)])


def point_residual(problem: DesignProblem):
    """(q, q_d, s_W) -> (r, dr/dq) of `residual_function` at one point as new numpy arrays (6 x 1, 6 x n_moving),
    evaluated in place on buffers (CasADi's FunctionBuffer) by a function without dr/dq_d: the same numbers as
    calling `residual_function`, at 21 instead of 75 us a call (a DM per argument and result, and the design
    Jacobian an IK walk does not use; the seeded starts' walks make ~100 calls per waypoint). Built once per chain
    in a process."""
    return _point_residual(pickle.dumps(problem.chain))


class _InPlace:
    """A CasADi function of dense inputs and outputs evaluated on numpy arrays it owns (its FunctionBuffer); each
    call returns copies."""

    def __init__(self, fn):
        self.fn = fn
        self._args = [np.zeros(fn.nnz_in(i)) for i in range(fn.n_in())]
        self._res = [np.zeros(fn.nnz_out(i)) for i in range(fn.n_out())]
        self._shapes = [fn.size_out(i) for i in range(fn.n_out())]
        self._buffer, self._eval = fn.buffer()
        for i, a in enumerate(self._args):
            self._buffer.set_arg(i, memoryview(a))
        for i, a in enumerate(self._res):
            self._buffer.set_res(i, memoryview(a))

    def __call__(self, *args) -> list[np.ndarray]:
        for buffer, value in zip(self._args, args, strict=True):
            buffer[:] = np.ravel(value, order="F")
        self._eval()
        return [r.reshape(shape, order="F").copy() for r, shape in zip(self._res, self._shapes, strict=True)]


@functools.lru_cache(maxsize=16)
def _point_residual(payload: bytes):
    import casadi as ca

    full = _residual_function(payload)
    args = [ca.SX.sym(full.name_in(i), full.sparsity_in(i)) for i in range(full.n_in())]
    r, J_q, _ = full(*args)  # its graph inlined; the design Jacobian, which nothing reads, dropped
    # dense, so that a joint no row depends on (a last joint turning about the tool axis) is a column of zeros
    return _InPlace(ca.Function("tracking_residual_q", args, [ca.densify(r), ca.densify(J_q)]))


@functools.lru_cache(maxsize=64)
def _mapped_point_residual(payload: bytes, n: int):
    """`point_residual`'s function mapped over ``n`` points, evaluated in place (`_InPlace`): (q (n_moving x n), q_d
    (n_design x n), s_W (3 x n)) -> (r (6 x n), dr/dq (6 x n n_moving)). Built once per chain and count in a
    process: a lift walks 40-80 waypoints together, then each one it walks again alone, and a mapped function
    created and called through CasADi's DMs each time cost a lift about as much as its IK."""
    return _InPlace(_point_residual(payload).fn.map(n))


STARTS_PER_SEED = 1000  # a start's number: seed * STARTS_PER_SEED + index


def start_number(seed: int, index: int) -> int:
    """The number of start ``index`` of ``seed``: what identifies it in a run's files (summary.csv's seed)."""
    return seed * STARTS_PER_SEED + index


def start_index(number, seed: int):
    """The index of the start numbered ``number`` (an int or an array of them) within ``seed``'s starts: the inverse
    of `start_number` for any index, also past ``STARTS_PER_SEED`` (a run has one seed, so numbers are unique)."""
    return number - seed * STARTS_PER_SEED


def initial_guess(problem: DesignProblem, index: int, seed: int, scale: float, mode: str = "ik",
                  design: np.ndarray | None = None, spread: str = "perturb") -> InitialGuess:
    """Start ``index`` of a seeded multistart (numbered `start_number`). Start 0 keeps the configured design; the
    others perturb it by ``scale`` (``spread`` perturb: first joints within +-pi/2) or draw it from the task's
    box (``spread`` box, `box_design`: first joints over the whole circle, so that folded postures are
    reached); ``spread`` mixed: odd starts as box, even ones as perturb. ``design`` (if given) is the start design
    instead. Each start depends only on (seed, index), so starts can be made in any order."""
    if mode not in INIT_MODES:
        raise ValueError(f"init must be one of {INIT_MODES}, got {mode!r}")
    if spread not in SPREADS:
        raise ValueError(f"spread must be one of {SPREADS}, got {spread!r}")
    q_d, q0 = _drawn(problem, index, seed, scale, design, spread)
    if mode == "constant":
        return InitialGuess(q_d=q_d, Q=np.tile(q0, (problem.toolpath.n, 1)), seed=start_number(seed, index))
    pull = HOME_PULL if mode == "home" else 0.0
    Q = ik_trajectory(problem, q_d, q0, home_pull=pull)
    if mode == "reach" and problem.chain.n_design and not tracks(problem, q_d, Q):
        # first the design, from a few waypoints spread along the path; then the walk with it; then, if some
        # waypoints still miss, design and trajectory together from that walk
        samples = np.unique(np.linspace(0, problem.toolpath.n - 1, 8).round().astype(int))
        q_d, _ = reach(problem, q_d, Q, samples=samples)
        Q = ik_trajectory(problem, q_d, q0, home_pull=pull)
        if not tracks(problem, q_d, Q):
            q_d, Q = reach(problem, q_d, Q)
    return InitialGuess(q_d=q_d, Q=Q, seed=start_number(seed, index))


def _drawn(problem: DesignProblem, index: int, seed: int, scale: float, design: np.ndarray | None,
           spread: str) -> tuple[np.ndarray, np.ndarray]:
    """Start ``index`` of ``seed``'s design and the configuration its walk starts from (`initial_guess`)."""
    rng = np.random.default_rng([seed, index])
    if spread == "mixed":
        spread = "box" if index % 2 else "perturb"
    if design is not None:
        q_d = within_bounds(problem, design)
    elif index == 0:
        q_d = problem.chain.design_values
    else:
        q_d = perturbed_design(problem, rng, scale) if spread == "perturb" else box_design(problem, rng)
    return q_d, random_configuration(problem, rng, np.pi / 2 if spread == "perturb" else np.pi)


def first_configuration(problem: DesignProblem, index: int, seed: int, scale: float, mode: str = "ik",
                        design: np.ndarray | None = None, spread: str = "perturb") -> np.ndarray:
    """Where start ``index`` of ``seed`` (`initial_guess`, the same arguments) reaches the path's first waypoint:
    the first row of its walk (``reach``: of its first walk), to the bit, for the cost of that waypoint's IK alone
    (rad for revolute joints, m for prismatic ones; the draw itself for ``constant``, which does not walk). Which
    branch a walk is on shows there first (`designopt.solve.starts.spread_branches`)."""
    q_d, q0 = _drawn(problem, index, seed, scale, design, spread)
    if mode == "constant":
        return q0
    return ik_trajectory(problem, q_d, q0, home_pull=HOME_PULL if mode == "home" else 0.0, waypoints=1)[0]


def first_configurations(problem: DesignProblem, starts: list[tuple[int, int, float, np.ndarray | None, str]],
                         mode: str = "ik") -> np.ndarray:
    """`first_configuration` of many starts of one problem, one row each, to the bit: ``starts`` holds each one's
    (index, seed, scale, design, spread). The walks to the first waypoint go in lockstep, each start with its own
    damping and stopping where it alone would (the first waypoint is walked unpulled in every ``mode``), their
    residuals evaluated by one mapped function; numpy's batched solves and products give each start the numbers its
    own walk gets. A second round's leader has 60-90 such starts, walked between two stages while the workers wait."""
    drawn = [_drawn(problem, index, seed, scale, design, spread) for index, seed, scale, design, spread in starts]
    if mode == "constant" or not drawn:
        return np.array([q0 for _, q0 in drawn], dtype=float).reshape(len(drawn), problem.chain.n_moving)
    m, n = len(drawn), problem.chain.n_moving
    fn = _mapped_point_residual(pickle.dumps(problem.chain), m)
    D = np.array([q_d for q_d, _ in drawn], dtype=float).T.reshape(problem.chain.n_design, m)
    S = np.tile(np.asarray(problem.toolpath.points_W[0], float)[:, None], (1, m))
    lo, hi = moving_bounds(problem)

    def evaluate(Q):  # each start's residual (6,) and Jacobian (6 x n), contiguous as its own walk's are
        r, J_q = fn(Q.T, D, S)
        return np.ascontiguousarray(r.T), np.ascontiguousarray(J_q.reshape(6, m, n).transpose(1, 0, 2))

    Q = np.array([q0 for _, q0 in drawn], dtype=float)
    r, J = evaluate(Q)
    damping = np.full(m, 1e-2)
    walking = np.ones(m, dtype=bool)
    eye = np.eye(n)
    for _ in range(IK_ITERATIONS + (POLISH if mode == "home" else 0)):  # as `ik_trajectory` at its first waypoint
        JT = J.transpose(0, 2, 1)
        step = np.linalg.solve(JT @ J + damping[:, None, None] * eye, -(JT @ r[:, :, None]))[:, :, 0]
        trial = np.clip(Q + step + 0.0, lo, hi)
        r_new, J_new = evaluate(trial)
        for i in np.flatnonzero(walking):
            if r_new[i] @ r_new[i] < r[i] @ r[i]:
                Q[i], r[i], J[i], damping[i] = trial[i], r_new[i], J_new[i], max(damping[i] / 3, 1e-6)
            else:
                damping[i] = damping[i] * 5
            if r[i] @ r[i] < 1e-14:
                walking[i] = False
        if not walking.any():
            break
    return Q


def design_from(problem: DesignProblem, other: DesignProblem, q_d_other: np.ndarray) -> np.ndarray:
    """``problem``'s design joints with the values another problem's design ``q_d_other`` gives the joints of the
    same name (e.g. a neighbouring structure's placement and link lengths); the others keep their configured
    values."""
    return design_named(problem, {j.name: float(v) for j, v in zip(other.chain.design, q_d_other, strict=True)})


def design_named(problem: DesignProblem, given: dict[str, float]) -> np.ndarray:
    """``problem``'s design joints: the value ``given`` names for each, else its configured value."""
    return np.array([given.get(j.name, j.value) for j in problem.chain.design])


def tracks(problem: DesignProblem, q_d: np.ndarray, Q: np.ndarray) -> bool:
    """Whether joint values Q with design q_d follow the path within the problem's tolerances."""
    tracked, points, fn = problem.toolpath.is_tracked, problem.toolpath.points_W, residual_function(problem)
    for k, q in enumerate(Q):
        if not tracked[k]:
            continue
        r = np.array(fn(q, q_d, points[k])[0]).ravel()
        if np.linalg.norm(r[:3]) > problem.position_tol or np.linalg.norm(r[3:]) > problem.axis_tol:
            return False
    return True


def initial_guesses(problem: DesignProblem, count: int, seed: int, scale: float, mode: str = "ik"):
    """The first ``count`` starts of a seeded multistart."""
    return [initial_guess(problem, i, seed, scale, mode) for i in range(count)]
