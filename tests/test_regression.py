"""No behaviour change on the default job, in two parts.

The model: the stored solution file (tests/data/milling_seed0_reference.json, start 0 of `designopt run
configs/milling.yaml`, seed 0) read back recomputes its own design cost to 1e-9 -- kinematics, deformation and the
cost terms as they were when it was written. Exact on any machine.

The solve: start 0 solved today converges and reaches the stored cost to 1e-4, near the stored design. It ends in a
flat valley (its reduced Hessian has eigenvalues from -9e-4 to 1e-9 there, docs/decisions.md "Speed (issue 24)"),
where the last bits of a derivative, or of the machine's BLAS kernels, move the end point by centimetres at the same
cost: the constraint Jacobian from compiled blocks moved it 2.8 cm in placement and 0.04 rad in the joints (design
cost 2.3281354e-3 -> 2.3280938e-3), MUMPS with METIS back (2.3281372e-3), the objective's gradient from blocks by
4.2e-6 rad (2.3281367e-3, the file); the same code on another 2-core machine ends at 2.3280938e-3 again (2.8 cm,
0.04 rad from the file, 2026-11-23). Hence 1e-4 in cost and 0.1 in placement and joints: a solve that leaves the
valley (another basin, another branch) fails it; one that moves within it does not."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import solve

from designopt.config import load_config
from designopt.problem import problem_from_config
from designopt.solution import Solution, to_dict

ROOT = Path(__file__).resolve().parent.parent


REFERENCE = ROOT / "tests" / "data" / "milling_seed0_reference.json"


def test_the_stored_solution_recomputes_its_own_cost():
    before = json.loads(REFERENCE.read_text())
    again = Solution.from_dict(before)
    assert again.metrics.design_cost == pytest.approx(before["metrics"]["design_cost"], rel=1e-9)
    assert again.metrics.tracks


def test_default_job_reaches_the_stored_solution():
    before = json.loads(REFERENCE.read_text())
    cfg = load_config(ROOT / "configs" / "milling.yaml")
    problem = problem_from_config(cfg)
    sol = solve(problem)
    now = to_dict(sol)
    assert now["metrics"]["status"] == before["metrics"]["status"] == "Solve_Succeeded"
    assert now["metrics"]["design_cost"] == pytest.approx(before["metrics"]["design_cost"], rel=1e-4)
    np.testing.assert_allclose(now["placement"]["xyz"], before["placement"]["xyz"], atol=0.1)
    np.testing.assert_allclose(now["placement"]["ypr"], before["placement"]["ypr"], atol=0.1)
    np.testing.assert_allclose(now["q"], before["q"], atol=0.1)
    for row_now, row_before in zip(now["dh"], before["dh"], strict=True):
        for key in ("theta", "d", "a", "alpha"):
            assert (row_now[key] is None) == (row_before[key] is None)
            if row_now[key] is not None:
                assert row_now[key] == pytest.approx(row_before[key], abs=0.1)
