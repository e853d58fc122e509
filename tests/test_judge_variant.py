"""The rule `benchmarks/judge_variant.py` judges a search variant by: each clause on seeds made to pass or fail it."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
from judge_variant import Rule, verdict  # noqa: E402

BASE = np.array([1.00, 1.03, 1.20, 1.50, 2.00])


def test_a_variant_equal_to_the_base_passes_unless_it_must_be_strictly_better():
    assert verdict(BASE, BASE.copy(), 1.0, Rule()) == (True, [])
    passed, failed = verdict(BASE, BASE.copy(), 1.0, Rule(strictly_better=True))
    assert not passed and failed == ["seeds better / worse 0 / 0"]


def test_seeds_are_better_or_worse_only_beyond_the_margin():
    variant = BASE * np.array([0.995, 1.005, 1, 1, 1])  # within 1 % both ways: neither better nor worse
    assert verdict(BASE, variant, 1.0, Rule(strictly_better=True))[1] == ["seeds better / worse 0 / 0"]
    variant = BASE * np.array([0.9, 1, 1, 1, 1])
    assert verdict(BASE, variant, 1.0, Rule(strictly_better=True)) == (True, [])


def test_more_seeds_worse_than_better_fails():
    variant = BASE * np.array([0.9, 1.05, 1.05, 1, 1])
    passed, failed = verdict(BASE, variant, 1.0, Rule())
    assert not passed and failed[0] == "seeds better / worse 1 / 2"


@pytest.mark.parametrize(("which", "clause"), [(2, "median 1.200 -> 1.210x"), (4, "worst 2.000 -> 2.017x")])
def test_median_and_worst_may_not_get_worse_beyond_the_hold(which, clause):
    factors = np.ones(5)
    factors[0] = 0.5  # one seed better, so the count of seeds passes
    factors[which] = 1.0 + 1.0 / 120  # 0.83 %: worse than the hold (0.5 %), not beyond the margin (1 %)
    passed, failed = verdict(BASE, BASE * factors, 1.0, Rule())
    assert not passed and failed == [clause]
    assert verdict(BASE, BASE * factors, 1.0, Rule(hold=0.01)) == (True, [])


def test_solve_time_beyond_its_allowance_fails_alone():
    assert verdict(BASE, BASE.copy(), 1.15, Rule(time=1.20)) == (True, [])
    assert verdict(BASE, BASE.copy(), 1.25, Rule(time=1.20)) == (False, ["solve time 1.250x > 1.20x"])


def test_a_seed_without_an_answer_counts_as_worst():
    variant = BASE.copy()
    variant[0] = np.inf
    passed, failed = verdict(BASE, variant, 1.0, Rule())
    assert not passed and "seeds better / worse 0 / 1" in failed and "worst 2.000 -> infx" in failed
