"""The FK baseline (Whitman et al.) and its continuous variant on problems with known answers."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import gantry_config, solve_from

from designopt.config import parse_config
from designopt.initial_guess import initial_guesses
from designopt.problem import problem_from_config
from designopt.transcriptions import ForwardKinematics, transcription_named


@pytest.mark.parametrize("continuous", [False, True])
def test_fk_gantry_known_optimum(continuous):
    """Gantry with K = I: L_d = alpha^2 at every pose, so the design cost is alpha^2 N/(N-1) whatever FK picks."""
    problem = problem_from_config(parse_config(gantry_config()))
    guess = initial_guesses(problem, 1, 0, 0.3, "constant")[0]
    sol = solve_from(problem, guess, ForwardKinematics(continuous=continuous))
    N = problem.toolpath.n
    assert sol.raw.success
    assert sol.metrics.design_cost == pytest.approx(4.0 * N / (N - 1), rel=1e-9)
    assert sol.metrics.tracks
    assert sol.metrics.max_position_error <= 0.95e-3 * (1 + 1e-6)  # epsilon = (0.95 tol)^2


def test_fk_continuous_respects_the_velocity_bound():
    cfg = parse_config({"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 16},
                        "robot": {"joint_velocity": 4.0}, "placement": {"xyz": [0.45, 0.0, -0.2]}})
    problem = problem_from_config(cfg)
    guess = initial_guesses(problem, 1, 0, 0.3, "ik")[0]
    sol = solve_from(problem, guess, ForwardKinematics(continuous=True), max_iter=500)
    raw = sol.raw
    bound = 4.0 / (problem.toolpath.n - 1)
    assert sol.metrics.max_joint_step <= bound * (1 + 1e-6)
    step = np.abs(np.diff(raw.Q, axis=0)).max()
    assert step == pytest.approx(sol.metrics.max_joint_step)


def test_transcription_names():
    assert transcription_named("fk").name == "fk"
    assert transcription_named("fk_continuous", hessian="auto").name == "fk_continuous"
    assert transcription_named("to").name == "to"
    with pytest.raises(ValueError):
        transcription_named("pso")


def test_a_to_solution_is_feasible_for_fk_continuous():
    """fk_continuous is a relaxation of TO (docs/results.md, C1): a TO solution's knots meet FK's tracking within
    epsilon and its step bound, since TO's velocity bounds at both knots and the midpoint bound the step
    h (v_0 + 4 v_mid + v_1) / 6. Checked where the velocity limit binds: some TO step is near v_max h."""
    import casadi as ca

    from designopt.transcriptions import Collocation
    from designopt.transcriptions.base import InitialGuess

    cfg = parse_config({"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 16},
                        "robot": {"joint_velocity": 4.0}, "placement": {"xyz": [0.45, 0.0, -0.2]}})
    problem = problem_from_config(cfg)
    to = solve_from(problem, initial_guesses(problem, 1, 0, 0.3, "ik")[0], Collocation(), max_iter=500)
    assert to.raw.success and to.metrics.tracks
    bound = 4.0 / (problem.toolpath.n - 1)
    assert to.metrics.max_joint_step >= 0.9 * bound  # the velocity limit shapes the TO trajectory

    fk = ForwardKinematics(continuous=True).build(problem)
    x = fk.pack(InitialGuess(q_d=to.raw.q_d, Q=to.raw.Q, V=to.raw.V, seed=0))
    nlp = fk.nlp
    g = np.asarray(ca.Function("g", [nlp.x], [nlp.g])(x)).ravel()
    slack = 1e-9
    assert np.all(g >= nlp.lbg - slack) and np.all(g <= nlp.ubg + slack)
    assert np.all(x >= nlp.lbx - slack) and np.all(x <= nlp.ubx + slack)
