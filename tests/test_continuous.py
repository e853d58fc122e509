"""The continuous experiment end to end on a small problem: 9 rows, both figures, files re-verify."""

from __future__ import annotations

import pandas as pd
import yaml
from typer.testing import CliRunner

from cli.main import app
from designopt.config import parse_config
from designopt.experiments.continuous import case_config
from designopt.verify import verify_file


def test_cases_differ_only_in_roles():
    from designopt.problem import problem_from_config

    cfg = parse_config({})
    placement, design, combined = (problem_from_config(case_config(cfg, c)).chain
                                   for c in ("placement_only", "design_only", "combined"))
    assert {j.name.split(".")[0] for j in placement.design} == {"placement"} and placement.n_design == 6
    assert {j.name.split(".")[1] for j in design.design} == {"d", "a", "alpha"} and design.n_design == 18
    assert {j.name for j in combined.design} == {j.name for j in placement.design} | {j.name for j in design.design}
    # the same joints with the same values: only the roles differ
    assert [(j.name, j.value) for j in placement.joints] == [(j.name, j.value) for j in combined.joints]
    assert case_config(cfg, "combined").toolpath == case_config(cfg, "design_only").toolpath == cfg.toolpath


def test_continuous_experiment_small(tmp_path):
    config = tmp_path / "c.yaml"
    config.write_text(yaml.safe_dump({
        "name": "continuous",
        "toolpath": {"kind": "figure_eight", "width": 0.6, "height": 0.3, "waypoints": 10},
        "placement": {"xyz": [0.45, 0.0, -0.2]},
        "search": {"preset": "paper", "starts": 1},
    }))
    result = CliRunner().invoke(app, ["continuous", str(config), "--out", str(tmp_path / "r"), "--name", "t",
                                      "--jobs", "2"])
    assert result.exit_code == 0, result.output
    run = tmp_path / "r" / "continuous" / "t"
    summary = pd.read_csv(run / "summary.csv")
    assert len(summary) == 9
    assert set(zip(summary["case"], summary["method"], strict=True)) == {
        (c, m) for c in ("placement_only", "design_only", "combined") for m in ("to", "fk", "fk_continuous")}
    assert set(summary.groupby("case")["n_design_joints"].first()) == {6, 18, 24}
    for stem in ("design_cost", "optimal_robots"):
        assert (run / "figures" / f"{stem}.png").stat().st_size > 1000
    table = pd.read_csv(run / "table.csv")
    assert len(table) == 9
    for f in (run / "solutions").glob("*.json"):
        assert verify_file(f) == [], f
    # max_joint_step of fk_continuous never exceeds its bound vmax * dt
    bound = 10.0 / 9
    assert (summary.loc[summary["method"] == "fk_continuous", "max_joint_step"] <= bound * (1 + 1e-6)).all()
