"""Tables computed from solves: distinct optima by design distance, best cost so far."""

from __future__ import annotations

import numpy as np
import pandas as pd
from hypothesis import given, settings
from hypothesis import strategies as st

from designopt.solve import cluster_designs, design_distance
from designopt.solve.optima import design_distances
from designopt.tables import best_so_far, full_path, is_coarse, is_relaxed, structure_table


def test_design_distance_wraps_angles():
    angle = np.array([False, True])
    assert abs(design_distance([0.1, np.pi - 0.01], [0.1, -np.pi + 0.01], angle) - 0.02) < 1e-12
    assert abs(design_distance([0.3, 0.0], [0.1, 0.0], angle) - 0.2) < 1e-12


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 6), st.integers(0, 2**32 - 1))
def test_design_distances_are_the_angle_between_unit_vectors(n_design, seed):
    """An angle's difference is the angle between the two directions (atan2 of the cross and dot products of their
    unit vectors: in [0, pi]) whatever turns either carries; a length's, the absolute difference."""
    rng = np.random.default_rng(seed)
    angle = rng.random(n_design) < 0.5
    a = rng.uniform(-3, 3, n_design) + 2 * np.pi * rng.integers(-3, 4, n_design) * angle
    b = rng.uniform(-3, 3, (5, n_design)) + 2 * np.pi * rng.integers(-3, 4, (5, n_design)) * angle
    between = np.abs(np.arctan2(np.sin(a) * np.cos(b) - np.cos(a) * np.sin(b), np.cos(a) * np.cos(b)
                                + np.sin(a) * np.sin(b)))
    expected = np.max(np.where(angle, between, np.abs(a - b)), axis=-1)
    assert np.allclose(design_distances(a, b, angle), expected, rtol=0, atol=1e-12)


def test_cluster_designs_finds_the_distinct_optima():
    angle = np.array([False, True])
    designs = np.array([[0.10, 3.135], [0.50, 0.0], [0.105, -3.135], [0.51, 0.005], [0.9, 1.0]])
    costs = np.array([1.0, 2.0, 1.1, 2.5, 0.5])
    labels = cluster_designs(designs, costs, angle, tol=0.02)
    # cheapest first: [0.9, 1.0] is optimum 0, the wrapped pair 1, the 0.5 m pair 2
    assert list(labels) == [1, 2, 1, 2, 0]


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 4), st.integers(1, 40), st.floats(0.01, 2.0), st.integers(0, 2**32 - 1))
def test_cluster_designs_is_the_pairwise_rule(n_design, n, tol, seed):
    """Each design, cheapest first, joins the first cluster whose representative is within tol by `design_distance`
    (angles wrapped), else starts one: the rule written out pair by pair, on designs that fall near one another."""
    rng = np.random.default_rng(seed)
    angle = rng.random(n_design) < 0.5
    centres = rng.uniform(-4, 4, (3, n_design))
    designs = centres[rng.integers(0, 3, n)] + rng.normal(scale=tol, size=(n, n_design))
    costs = rng.choice([1.0, 2.0, 3.0], n) if seed % 2 else rng.random(n)  # ties: the stable order decides
    expected, leaders = np.empty(n, dtype=int), []
    for i in np.argsort(costs, kind="stable"):
        k = next((k for k, j in enumerate(leaders) if design_distance(designs[i], designs[j], angle) <= tol), None)
        if k is None:
            k = len(leaders)
            leaders.append(i)
        expected[i] = k
    assert list(cluster_designs(designs, costs, angle, tol)) == list(expected)


def test_best_so_far_ignores_solves_that_do_not_track():
    summary = pd.DataFrame({"design_cost": [3.0, 1.0, 2.0, 0.5], "tracks": [True, False, True, True],
                            "solve_time_s": [1.0, 2.0, 0.5, 1.5]})
    table = best_so_far(summary)
    assert list(table["best_cost"]) == [3.0, 3.0, 2.0, 0.5]
    assert list(table["solver_seconds"]) == [1.0, 3.0, 3.5, 5.0]


def test_numbered_coarse_stages_are_coarse_and_never_a_structures_answer():
    """A second screen pass (screen2) is a coarse stage like the first; a second refine (refine2) is full-path: a
    structure's best is read from full-path rows only, however cheap a coarse one looks."""
    assert [is_coarse(s) for s in ("explore", "screen", "screen2", "refine", "refine2", "neighbour", "final")] == \
        [True, True, True, False, False, False, False]
    summary = pd.DataFrame({"structure": ["RR"] * 4, "stage": ["explore", "screen2", "refine", "refine2"],
                            "design_cost": [0.1, 0.2, 3.0, 2.0], "tracks": [True, True, True, True],
                            "status": ["Solve_Succeeded"] * 4, "solution_file": ["e", "s", "r", "r2"],
                            "solve_time_s": [1.0] * 4})
    row = structure_table(summary).iloc[0]
    assert row["design_cost"] == 2.0 and row["best_solution"] == "r2" and row["starts"] == 2


def test_relaxed_solves_are_full_path_but_never_an_answer():
    """A solve with relaxed velocity limits (`Search.refine_relaxed`: relax, relax2) is on the full path but not of
    the task: a structure's best and the figures' full-path rows leave it out, however cheap it is."""
    assert [is_relaxed(s) for s in ("relax", "relax2", "refine", "refine3", "screen")] == [True, True, False, False,
                                                                                           False]
    summary = pd.DataFrame({"structure": ["RR"] * 4, "stage": ["relax", "relax2", "refine", "refine3"],
                            "design_cost": [0.1, 0.2, 3.0, 2.0], "tracks": [True, True, True, True],
                            "status": ["Solve_Succeeded"] * 4, "solution_file": ["x", "x2", "r", "r3"],
                            "solve_time_s": [1.0] * 4})
    row = structure_table(summary).iloc[0]
    assert row["design_cost"] == 2.0 and row["best_solution"] == "r3" and row["starts"] == 2
    assert list(full_path(summary)["stage"]) == ["refine", "refine3"]


def test_search_progress_figure_draws_the_best_optima_relative_to_the_best(tmp_path, monkeypatch):
    """A search that reached 40 distinct optima: the third panel shows the 15 best, each one's cost over the best's
    and how many solves reached it, and says how many it leaves out."""
    from designopt import plots_experiments

    drawn = {}
    monkeypatch.setattr(plots_experiments, "save", lambda fig, directory, stem: drawn.setdefault(stem, fig) and [])
    costs = 2e-4 * 1.1 ** np.arange(40)
    optima = pd.DataFrame({"optimum": np.arange(1, 41), "design_cost": costs, "reached_by": [3] + [1] * 39,
                           "ratio_to_best": costs / costs[0]})
    progress = best_so_far(pd.DataFrame({"tracks": ["True"] * 5, "design_cost": [5e-4, 3e-4, 4e-4, 2e-4, 6e-4],
                                         "solve_time_s": [0.1] * 5}))
    plots_experiments.search_progress_figure(progress, optima, tmp_path)
    panel = drawn["search_progress"].axes[2]
    heights = [bar.get_height() for bar in panel.patches]
    assert np.allclose(heights, 1.1 ** np.arange(15))
    assert [t.get_text() for t in panel.texts] == ["3"] + ["1"] * 14
    assert "15 of 40" in panel.get_xlabel()
