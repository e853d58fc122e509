"""Tables computed from solves: distinct optima by design distance, best cost so far."""

from __future__ import annotations

import numpy as np
import pandas as pd

from designopt.solve import cluster_designs, design_distance
from designopt.tables import best_so_far


def test_design_distance_wraps_angles():
    angle = np.array([False, True])
    assert abs(design_distance([0.1, np.pi - 0.01], [0.1, -np.pi + 0.01], angle) - 0.02) < 1e-12
    assert abs(design_distance([0.3, 0.0], [0.1, 0.0], angle) - 0.2) < 1e-12


def test_cluster_designs_finds_the_distinct_optima():
    angle = np.array([False, True])
    designs = np.array([[0.10, 3.135], [0.50, 0.0], [0.105, -3.135], [0.51, 0.005], [0.9, 1.0]])
    costs = np.array([1.0, 2.0, 1.1, 2.5, 0.5])
    labels = cluster_designs(designs, costs, angle, tol=0.02)
    # cheapest first: [0.9, 1.0] is optimum 0, the wrapped pair 1, the 0.5 m pair 2
    assert list(labels) == [1, 2, 1, 2, 0]


def test_best_so_far_ignores_solves_that_do_not_track():
    summary = pd.DataFrame({"design_cost": [3.0, 1.0, 2.0, 0.5], "tracks": [True, False, True, True],
                            "solve_time_s": [1.0, 2.0, 0.5, 1.5]})
    table = best_so_far(summary)
    assert list(table["best_cost"]) == [3.0, 3.0, 2.0, 0.5]
    assert list(table["solver_seconds"]) == [1.0, 3.0, 3.5, 5.0]
