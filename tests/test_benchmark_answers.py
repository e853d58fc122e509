"""What the benchmark tools count as an answer (`benchmarks/draws_estimate.py`, `benchmarks/modular_enumeration.py`),
on summaries written by hand: never a coarse stage's solve or one with relaxed velocity limits."""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
from draws_estimate import confirmed_answer, draw_answers  # noqa: E402
from modular_enumeration import best_per_case  # noqa: E402

from designopt.solve import preset  # noqa: E402
from designopt.solve.search import search_to_dict  # noqa: E402


def test_a_draws_answer_is_its_cheapest_tracking_full_path_solve_never_a_relaxed_or_coarse_one(tmp_path):
    """Two draws (start numbers seed * 1000 + index, draw j from seed + j * 1,000,000): the coarse stages and the
    solves with relaxed velocity limits (`Search.refine_relaxed`: relax, relax2) are cheaper but are not answers;
    a non-tracking solve is none either, and a draw with no tracking full-path solve answers inf."""
    search = replace(preset("default"), seed=7, draws=2)
    (tmp_path / "search.json").write_text(json.dumps(search_to_dict(search)))
    first, second = 7000, 1_000_007 * 1000
    rows = [("explore", first + 1, 0.5, True), ("screen", first + 1, 0.8, True), ("relax", first + 1, 0.6, True),
            ("relax2", first + 1, 0.7, True), ("refine", first + 1, 3.0, True), ("refine2", first + 2, 2.0, True),
            ("reflect", first + 3, 1.5, False),
            ("explore", second + 1, 0.4, True), ("relax", second + 1, 0.9, True), ("refine", second + 1, 4.0, False)]
    pd.DataFrame(rows, columns=["stage", "seed", "design_cost", "tracks"]).to_csv(tmp_path / "summary.csv",
                                                                                 index=False)
    assert draw_answers(tmp_path, 2.0) == pytest.approx([1.0, float("inf")])


def test_a_confirmed_answer_is_the_lowest_draw_once_enough_draws_reach_it():
    """``--confirm``'s rule (a search drawn until K draws reach its answer): the first K draws always, then until K
    are within the factor of the lowest or the most are made; None while the draws given end first."""
    assert confirmed_answer([1.0, 1.015], 2, 1.02, 5) == (1.0, 2)
    assert confirmed_answer([1.5, 1.2, 1.0, 1.01, 0.1], 2, 1.02, 5) == (1.0, 4)  # the fifth never drawn
    assert confirmed_answer([1.5, 1.2, 1.0], 2, 1.02, 5) is None
    assert confirmed_answer([5.0, 4.0, 3.0, 2.0, 1.0], 2, 1.02, 5) == (1.0, 5)
    assert confirmed_answer([2.0, float("inf"), 2.01], 2, 1.02, 3) == (2.0, 3)
    assert confirmed_answer([1.0], 2, 1.02, 5) is None
    assert confirmed_answer([1.0, 1.02], 2, 1.02, 5) == (1.0, 2)  # within the factor, its bound included
    assert confirmed_answer([float("inf"), float("inf")], 2, 1.02, 3) is None  # draws tracking nothing reach nothing


def test_an_assignments_full_path_best_leaves_out_its_coarse_and_relaxed_solves():
    """The modular refine's search relaxes its best candidate's velocity limits once (the default's
    `refine_relaxed`); that solve is cheaper than the assignment's answer and is not one."""
    summary = pd.DataFrame({"case": ["f12", "f12", "f12", "f12", "f34", "s12"],
                            "stage": ["screen", "relax", "refine", "refine2", "refine", "explore"],
                            "design_cost": [0.1, 0.2, 3.0, 2.0, 5.0, 0.05], "tracks": [True] * 6})
    assert best_per_case(summary, "f", full_path=True).to_dict() == {"f12": 2.0, "f34": 5.0}
    assert best_per_case(summary, "f").to_dict() == {"f12": 0.1, "f34": 5.0}


def test_the_confirm_table_says_what_the_rule_answers_over_every_draw_given(tmp_path, capsys):
    """``--confirm`` over runs of one draw each (draw j of seed s the run of seed s + j x 1,000,000): a seed whose
    first two draws agree stops there, and where a third draw was run anyway (a `thorough` run's) the table says
    the best of all three and the rule's answer over it; a seed whose draws disagree takes the third."""
    from draws_estimate import confirm_table

    def run(seed: int, cost: float) -> Path:
        path = tmp_path / f"s{seed}"
        path.mkdir()
        (path / "search.json").write_text(json.dumps(search_to_dict(replace(preset("default"), seed=seed))))
        (path / "solution_set.csv").write_text("")
        pd.DataFrame([("refine", seed * 1000, cost, True)], columns=["stage", "seed", "design_cost", "tracks"]).to_csv(
            path / "summary.csv", index=False)
        return path

    runs = [run(5 + j * 1_000_000, c) for j, c in enumerate((1.035, 1.035, 1.022))]
    runs += [run(6 + j * 1_000_000, c) for j, c in enumerate((1.068, 1.094, 1.072))]
    confirm_table(runs, 1.0, 2, 1.02, 3)
    out = capsys.readouterr().out
    assert "seed 5: draws 1.035, 1.035, 1.022x; answer 1.035x after 2 draws; the best of all 3 given 1.022x, " \
           "the answer 1.0127x it" in out
    assert "seed 6: draws 1.068, 1.094, 1.072x; answer 1.068x after 3 draws\n" in out
    assert "2 seeds settled" in out and "draws made 2.50 on average, at most 3" in out


def test_runs_that_are_not_run_directories_are_one_line_errors(tmp_path):
    """A glob that matched nothing (`DIR/<name>/s*` with the wrong name) or a file given as a run is refused in one
    line with exit code 2, not a traceback."""
    import subprocess

    script = Path(__file__).resolve().parent.parent / "benchmarks" / "draws_estimate.py"
    reference = Path(__file__).resolve().parent.parent / "benchmarks" / "reference" / "milling_best_known.json"
    (tmp_path / "s12").write_text("not a run")
    for run in (tmp_path / "wrong" / "s*", tmp_path / "s12"):
        proc = subprocess.run([sys.executable, str(script), str(run), "--reference", str(reference)],
                              capture_output=True, text=True)
        assert proc.returncode == 2 and "Traceback" not in proc.stderr
        assert f"{run}: not a run directory" in proc.stderr.strip().splitlines()[-1]
