"""`benchmarks/sweep_judge.py`: a sweep replay's solves priced at the base's rates, hand-computed on tiny tables."""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
from sweep_judge import moved, priced, reached  # noqa: E402


def _rows(*rows):
    return pd.DataFrame(rows, columns=["structure", "stage", "iterations", "solve_time_s"])


BASE = _rows(("RR", "explore", 100, 1.0), ("RR", "explore", 100, 3.0), ("RR", "refine", 50, 1.0),
             ("PR", "explore", 200, 2.0))


def test_kept_stages_price_to_the_base_seconds_and_new_work_at_the_nearest_rate():
    variant = pd.concat([BASE[BASE["stage"] == "explore"],
                         _rows(("RR", "refine", 100, 9.0),     # the base's RR refine rate: 1 s / 50 -> 2 s
                               ("RR", "reflect", 25, 9.0),     # no RR reflect in the base: its refine's rate -> 0.5 s
                               ("PR", "neighbour2", 60, 9.0))])  # no PR refine either: the whole base's 7 s / 450
    table = priced(BASE, variant)
    assert table.loc["explore", "variant seconds (priced)"] == pytest.approx(6.0)  # kept: the base's own seconds
    assert table.loc["refine", "variant seconds (priced)"] == pytest.approx(2.0)
    assert table.loc["reflect", "variant seconds (priced)"] == pytest.approx(0.5)
    assert table.loc["neighbour", "variant seconds (priced)"] == pytest.approx(60 * 7.0 / 450)
    assert table.loc["neighbour", "seconds"] == 0 and table.loc["refine", "iterations"] == 50
    assert table["variant solves"].sum() == 6 and table["solves"].sum() == 4


def test_references_reached_and_bests_moved_beyond_the_margin():
    references = pd.Series({"RR": 1.0, "PR": 2.0, "PP": 1.0})
    assert reached(pd.Series({"RR": 1.10, "PR": 2.3}), references, 1.10) == ["RR"]
    base, variant = pd.Series({"A": 1.0, "B": 1.0, "C": 1.0, "D": 1.0}), pd.Series({"A": 0.95, "B": 1.005,
                                                                                 "C": 1.2, "D": float("nan")})
    lower, higher = moved(base, variant, 0.01)
    assert list(lower.index) == ["A"] and list(higher.index) == ["C"]
