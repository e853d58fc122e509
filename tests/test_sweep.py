"""The structure sweep: enumeration, end to end, killed and resumed, Dask against loky, failures as rows."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from cli.main import app
from designopt.config import load_config
from designopt.experiments.sweep import enumerate_structures, run_sweep
from designopt.solve import Search, SolverProfile
from designopt.solve.observers import Bound
from designopt.solve.strategies.neighbours import neighbours, shorter
from designopt.verify import verify_file

runner = CliRunner()
ROOT = Path(__file__).resolve().parent.parent


def test_enumeration_count_and_order():
    all6 = enumerate_structures(1, 6)
    assert len(all6) == 126 == sum(2**n for n in range(1, 7))
    assert len(set(all6)) == 126
    assert all6[:6] == ["R", "P", "RR", "RP", "PR", "PP"]
    assert enumerate_structures(6, 6)[0] == "RRRRRR" and enumerate_structures(6, 6)[-1] == "PPPPPP"
    assert sum(s.count("P") == 3 for s in enumerate_structures(6, 6)) == 20


def test_neighbours_differ_in_one_joint_type():
    structures = enumerate_structures(1, 3)
    assert sorted(neighbours("RRP", structures)) == ["PRP", "RPP", "RRR"]
    assert neighbours("R", structures) == ["P"]
    assert all(len(neighbours(s, structures)) == len(s) for s in structures)


def test_shorter_neighbours_are_the_structure_without_one_joint():
    structures = enumerate_structures(1, 4)
    assert shorter("RRPR", structures) == [("RPR", 0), ("RPR", 1), ("RRR", 2), ("RRP", 3)]
    assert shorter("R", structures) == [] and shorter("RRPR", ["RRPR", "PRR"]) == []
    for s in structures:  # inserting the joint back gives the structure
        assert all(other[:k] + s[k] + other[k:] == s for other, k in shorter(s, structures))


@pytest.mark.parametrize("small, where, big", [("RRP", 0, "RRRP"), ("RRP", 1, "RPRP"), ("RRP", 3, "RRPR"),
                                               ("PRR", 2, "PRPR"), ("RRRRR", 2, "RRRRRR")])
def test_a_grown_start_keeps_the_shorter_structures_tool_path(small, where, big):
    """The invariant behind `Grown`: a structure with a link inserted as an identity transform, its joint at 0,
    puts the tool (and the workpiece) exactly where the shorter structure did, at every waypoint."""
    from types import SimpleNamespace

    from designopt.config import parse_config
    from designopt.initial_guess import initial_guess
    from designopt.kinematics.chain import placement_pose, tool_pose
    from designopt.problem import problem_from_config
    from designopt.solve.starts import grown_guess

    def problem(structure):
        return problem_from_config(parse_config({
            "toolpath": {"kind": "line", "length": 0.2, "waypoints": 6}, "placement": {"xyz": [0.3, 0.0, -0.2]},
            "robot": {"dh": "generic", "structure": structure}}))

    source, target = problem(small), problem(big)
    guess = initial_guess(source, 3, 7, 0.3)  # a perturbed design and some joint values (tracking or not)
    rng = np.random.default_rng(0)
    V = rng.normal(size=guess.Q.shape)
    solution = SimpleNamespace(raw=SimpleNamespace(q_d=guess.q_d), sample=lambda t: guess.Q,
                               sample_velocity=lambda t: V)
    grown = grown_guess(target, source, solution, where, seed=5)
    assert grown.Q.shape == (6, len(big)) and np.all(grown.Q[:, where] == 0) and np.all(grown.V[:, where] == 0)
    assert np.array_equal(np.delete(grown.V, where, axis=1), V)
    for q_small, q_big in zip(guess.Q, grown.Q, strict=True):
        assert np.allclose(tool_pose(target.chain, q_big, grown.q_d), tool_pose(source.chain, q_small, guess.q_d),
                           atol=1e-12)
        assert np.allclose(placement_pose(target.chain, q_big, grown.q_d),
                           placement_pose(source.chain, q_small, guess.q_d), atol=1e-12)
    for wrong, at in (("RR", 0), ("P" * (len(small) + 1), where), (big, len(big))):
        with pytest.raises(ValueError, match=f"not {small} with a joint inserted"):
            grown_guess(problem(wrong), source, solution, at)


def _found(q_d, cost, Q):
    """A structure's best solution as the neighbour step reads it: tracking at ``cost``, its design ``q_d``, its
    objective 1.5 x the cost and its joint values ``Q`` (one row per knot)."""
    from types import SimpleNamespace

    return SimpleNamespace(metrics=SimpleNamespace(tracks=True, design_cost=cost),
                           raw=SimpleNamespace(q_d=q_d, objective=1.5 * cost, Q=Q))


@pytest.mark.parametrize("shorter_cost, grown", [(1.0, [0, 1, 2]), (3.0, [])])
def test_a_structure_grows_from_a_shorter_one_only_when_that_found_a_cheaper_design(shorter_cost, grown):
    from types import SimpleNamespace

    from designopt.config import parse_config
    from designopt.problem import problem_from_config
    from designopt.solve import Job, Searched, preset
    from designopt.solve.starts import Grown
    from designopt.solve.strategies import neighbours as neighbour_stage

    def searched(structure, cost):
        job = Job("sweep", problem_from_config(parse_config({"robot": {"dh": "generic", "structure": structure}})))
        moving = np.linspace(0.0, 1.0, 6)[:, None] * np.ones(len(structure))  # every joint moves
        return Searched(job, [], [(SimpleNamespace(), _found(job.problem.chain.design_values, cost, moving))])

    plan = neighbour_stage.plan([searched("RRP", shorter_cost), searched("RRRP", 2.0)], preset("quick"))
    tasks = next(plan, [])
    # RRRP is RRP with a joint inserted at 0, 1 or 2 (and RRR, absent, at 3); RRP has no shorter neighbour here
    assert [t.start.where for t in tasks] == grown
    assert all(isinstance(t.start, Grown) and t.problem.chain.structure == "RRRP" and t.profile.warm for t in tasks)
    # a grown start keeps the preset's cap: only the cold same-length starts are capped sooner
    assert all(t.profile.max_iter == preset("quick").profile.max_iter > neighbour_stage.SAME_LENGTH_CAP for t in tasks)
    assert len({t.start.number for t in tasks}) == len(tasks)
    # each is held to its structure's best: stopped if still above 3x its objective (1.5 * 2.0) after 300 iterations
    assert all(t.bound == Bound(pytest.approx(3 * 1.5 * 2.0), 300) and "above_bound" in t.profile.observers
               for t in tasks)


def _structure_problem(structure):
    """A structure of the sweep's config: every link parameter but the joint's and the placement designed."""
    from designopt.experiments.adapters import structure_config
    from designopt.problem import problem_from_config

    return problem_from_config(structure_config(load_config(Path(__file__).parent.parent / "configs" /
                                                            "structures.yaml"), structure))


@pytest.mark.parametrize("big", ["RRRP", "PRRR", "PRRRRR", "RPPRRP"])
def test_a_pruned_start_keeps_the_longer_structures_tool_path(big):
    """The invariant behind `Pruned`: a structure whose first joint stays still is the structure without it, placed
    by the still link's transform: with that link carried into the placement, the tool is where it was in the
    workpiece frame at every waypoint (the shorter structure's own kinematics, no shared code path)."""
    from types import SimpleNamespace

    from designopt.initial_guess import initial_guess
    from designopt.kinematics.chain import tool_in_workpiece
    from designopt.solve.starts import pruned_design

    source, target = _structure_problem(big), _structure_problem(big[1:])
    checked = 0
    for seed in range(6):
        guess = initial_guess(source, seed, 7, 0.3)  # a perturbed design and some joint values (tracking or not)
        Q = guess.Q.copy()
        Q[:, 0] = Q[0, 0]  # the first joint held
        solution = SimpleNamespace(raw=SimpleNamespace(q_d=guess.q_d, Q=Q))
        q_d = pruned_design(target, source, solution)
        if q_d is None:  # the carried placement leaves its bounds
            continue
        checked += 1
        for q in Q:
            assert np.allclose(np.asarray(tool_in_workpiece(target.chain, q[1:], q_d), float),
                               np.asarray(tool_in_workpiece(source.chain, q, guess.q_d), float), atol=1e-10)
    assert checked >= 3
    with pytest.raises(ValueError, match="without its first joint"):
        pruned_design(_structure_problem("RR"), source, solution)


def test_a_pruned_start_whose_placement_leaves_its_bounds_is_not_given():
    """The placement that carries the still link can fall outside the placement's box: no start then."""
    from types import SimpleNamespace

    from designopt.solve.starts import pruned_design

    source, target = _structure_problem("PRR"), _structure_problem("RR")
    q_d = source.chain.design_values.copy()
    names = [j.name for j in source.chain.design]
    q_d[names.index("link1.theta")], q_d[names.index("placement.x")] = 0.0, 1.9
    Q = np.zeros((4, 3))
    Q[:, 0] = 0.5  # the prismatic first joint held 0.5 m out, along the base z axis
    assert pruned_design(target, source, SimpleNamespace(raw=SimpleNamespace(q_d=q_d, Q=Q))) is not None
    Q[:, 0] = -2.5  # the workpiece 2.5 m above the shorter arm's base: beyond placement.z's upper bound of 2 m
    assert pruned_design(target, source, SimpleNamespace(raw=SimpleNamespace(q_d=q_d, Q=Q))) is None


@pytest.mark.parametrize("still", [True, False])
def test_a_structure_is_pruned_from_a_longer_one_only_when_its_first_joint_stays_still(still):
    from types import SimpleNamespace

    from designopt.solve import Job, Searched, preset
    from designopt.solve.starts import Pruned
    from designopt.solve.strategies import neighbours as neighbour_stage

    def searched(structure, cost):
        job = Job("sweep", _structure_problem(structure))
        Q = np.linspace(0.0, 1.0, 6)[:, None] * np.ones(len(structure))
        if still:
            Q[:, 0] = 0.1
        return Searched(job, [], [(SimpleNamespace(), _found(job.problem.chain.design_values, cost, Q))])

    tasks = next(neighbour_stage.plan([searched("RRP", 3.0), searched("RRRP", 2.0)], preset("quick")), [])
    pruned = [t for t in tasks if isinstance(t.start, Pruned)]
    assert len(pruned) == still and all(t.problem.chain.structure == "RRP" and t.profile.warm for t in pruned)
    assert len({t.start.number for t in tasks}) == len(tasks)


def test_a_second_pass_starts_only_from_the_structures_the_first_pass_lowered():
    """RRP (3.0) is cheaper than its neighbours RRR (4.0) and RPP (5.0): the first pass gives each of them a start from
    it. RRR's start lands at 1.0, RPP's at 6.0: the second pass (``neighbour2``) gives RRP a start from RRR, the one
    structure the first pass lowered, and nothing else (RPP is not RRR's neighbour); then the step ends."""
    from types import SimpleNamespace

    from designopt.solve import Job, Searched, Seeded, preset
    from designopt.solve.strategies import neighbours as neighbour_stage

    def solution(structure, cost):
        Q = np.linspace(0.0, 1.0, 6)[:, None] * np.ones(len(structure))
        return _found(_structure_problem(structure).chain.design_values, cost, Q)

    searched = [Searched(Job("sweep", _structure_problem(s)), [], [(SimpleNamespace(), solution(s, c))])
                for s, c in (("RRP", 3.0), ("RRR", 4.0), ("RPP", 5.0))]
    plan = neighbour_stage.plan(searched, preset("quick"))
    first = next(plan)
    assert sorted((t.problem.chain.structure, t.stage) for t in first) == [("RPP", "neighbour"), ("RRR", "neighbour")]
    # same-length starts: cold, from the neighbour's design, at most SAME_LENGTH_CAP iterations (the preset: 600)
    cap = neighbour_stage.SAME_LENGTH_CAP
    assert all(isinstance(t.start, Seeded) and not t.profile.warm and t.profile.max_iter == cap for t in first)
    # each held from iteration 100 to 10x its own structure's best objective (1.5 x its cost: RRR 4.0, RPP 5.0),
    # sooner than the grown and pruned starts (3x from 300)
    assert {t.problem.chain.structure: t.bound for t in first} == {"RRR": Bound(pytest.approx(10 * 1.5 * 4.0), 100),
                                                                   "RPP": Bound(pytest.approx(10 * 1.5 * 5.0), 100)}
    assert all("above_bound" in t.profile.observers for t in first)
    landed = {"RRR": 1.0, "RPP": 6.0}
    second = plan.send([(t, solution(t.problem.chain.structure, landed[t.problem.chain.structure])) for t in first])
    assert [(t.problem.chain.structure, t.stage) for t in second] == [("RRP", "neighbour2")]
    with pytest.raises(StopIteration) as done:
        plan.send([(second[0], solution("RRP", 0.5))])
    bests = {s.job.problem.chain.structure: s.best[1].metrics.design_cost for s in done.value.value}
    assert bests == {"RRP": 0.5, "RRR": 1.0, "RPP": 5.0}


def test_a_neighbours_design_starts_the_joints_of_the_same_name():
    from designopt.config import parse_config
    from designopt.initial_guess import design_from
    from designopt.problem import problem_from_config

    rr = problem_from_config(parse_config({"robot": {"dh": "generic", "structure": "RRRRRR"}}))
    pr = problem_from_config(parse_config({"robot": {"dh": "generic", "structure": "PRRRRR"}}))
    q = np.linspace(0.1, 0.9, rr.chain.n_design)
    mapped = design_from(pr, rr, q)
    given = dict(zip([j.name for j in rr.chain.design], q, strict=True))
    for j, v in zip(pr.chain.design, mapped, strict=True):
        assert v == (given[j.name] if j.name in given else j.value), j.name
    assert "link1.theta" in {j.name for j in pr.chain.design} and "link1.d" not in {j.name for j in pr.chain.design}


def small_config(tmp_path) -> Path:
    """A short line; the quick search with 3 starts (on a path this short the exploration uses every waypoint)."""
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump({
        "name": "structures",
        "toolpath": {"kind": "line", "length": 0.2, "waypoints": 8},
        "placement": {"xyz": [0.3, 0.0, -0.2]},
        "search": {"preset": "quick", "starts": 3},
    }))
    return path


pytestmark = pytest.mark.usefixtures("module_compile_cache")


def sweep(config, out, *extra):
    return runner.invoke(app, ["sweep-structures", "--config", str(config), "--out", str(out), *extra])


def test_sweep_1_to_2_dof_end_to_end(tmp_path):
    result = sweep(small_config(tmp_path), tmp_path / "r", "--max-dof", "2", "--jobs", "2", "--name", "a")
    assert result.exit_code == 0, result.output
    run = tmp_path / "r" / "structures" / "a"
    summary = pd.read_csv(run / "summary.csv")
    assert set(summary["structure"]) == {"R", "P", "RR", "RP", "PR", "PP"}
    assert (summary["case"] == "sweep").all()
    stages = summary.groupby(["structure", "stage"]).size()
    for s in ("RR", "RP", "PR", "PP"):  # every two-joint structure, a small arm: 2 x 3 starts, the best 4 refined
        assert stages[s, "explore"] == 6 and stages.get((s, "refine"), 0) <= 4
    # a structure gets a neighbour's start exactly when a neighbour (one joint type changed, or one joint fewer)
    # searched its way to a cheaper design than its own, one start per such neighbour (and insertion)
    refined = summary[summary["stage"] == "refine"]
    best = refined[refined["tracks"]].groupby("structure")["design_cost"].min()
    seeded = summary.loc[summary["stage"] == "neighbour", "structure"].value_counts()
    for s in best.index:
        better = [n for n in neighbours(s, list(best.index)) if best[n] < best[s]]
        better += [n for n, _ in shorter(s, list(best.index)) if best[n] < best[s]]
        assert seeded.get(s, 0) == len(better), s
    assert "6 structures solved" in result.output
    table = pd.read_csv(run / "table.csv")
    assert list(table["structure"]) == ["R", "P", "RR", "RP", "PR", "PP"]
    # a share of 3 coarse starts for two joints; one joint, whose starts cost less, a share of 3 x (28 / 17)^2 = 8.1
    # (quick's `small_problem_starts`; n = joints x 8 waypoints + d or theta, a, alpha per link + 6 placement joints);
    # every arm here small, so twice its share (quick's `small_arm_starts`)
    assert dict(zip(table["structure"], table["explore_starts"], strict=True)) == {
        "R": 16, "P": 16, "RR": 6, "RP": 6, "PR": 6, "PP": 6}
    refined = table[table["starts"] == 1]
    assert (refined["near_best"] == refined["tracking_starts"]).all()  # one full-path solve: it is its own best
    assert (table["near_best"] <= table["tracking_starts"]).all()
    for f in (run / "solutions").glob("*.json"):
        assert verify_file(f) == [], f
    assert (run / "figures" / "structures_best_per_dof.png").is_file()
    again = sweep(small_config(tmp_path), tmp_path / "r", "--max-dof", "2", "--name", "a")
    assert again.exit_code == 2 and "--resume" in again.output


def test_failed_solves_are_rows(tmp_path, capfd):
    # 1 revolute joint cannot meet 5 tracking equalities per waypoint (IPOPT: Not_Enough_Degrees_Of_Freedom);
    # 2 joints stopped after 2 iterations do not converge (Maximum_Iterations_Exceeded, or a failed
    # restoration). All are rows.
    cfg = load_config(small_config(tmp_path))
    search = Search(starts=3, explore_waypoints=5, explore_max_iter=2, profile=SolverProfile(max_iter=2))
    result = run_sweep(cfg, tmp_path / "r", "sweep", 1, 2, jobs=1, search=search)
    summary = pd.read_csv(tmp_path / "r" / "structures" / "sweep" / "summary.csv")
    assert len(summary) == 6 * 3 and (summary["stage"] == "explore").all()  # nothing tracks: nothing refined
    assert not summary["success"].any() and not summary["tracks"].any()
    statuses = summary.groupby("structure")["status"].agg(set)
    assert statuses["R"] == {"Not_Enough_Degrees_Of_Freedom"}
    assert "Maximum_Iterations_Exceeded" in statuses["RR"]
    assert result.table["design_cost"].isna().all()
    # decided without calling IPOPT: CasADi would print a warning per over-constrained solve on the terminal
    captured = capfd.readouterr()
    assert "overconstrained" not in captured.out + captured.err


def test_a_problem_with_too_few_degrees_of_freedom_compiles_nothing(tmp_path, monkeypatch):
    """One revolute joint against five tracking equalities per waypoint: IPOPT would stop before its first
    iteration, so the solver is prepared without building the NLP's derivatives -- no block reaches the compile
    cache -- and the solve is its status at once."""
    from designopt.experiments.sweep import structure_config
    from designopt.problem import problem_from_config
    from designopt.solve import local
    from designopt.transcriptions.collocation import Collocation

    cache = tmp_path / "cache"
    monkeypatch.setenv("DESIGNOPT_CACHE", str(cache))
    problem = problem_from_config(structure_config(load_config(small_config(tmp_path)), "R"))
    built, solver, _ = local.prepared(problem, Collocation(), SolverProfile(max_iter=3, compile="O1"))
    assert built.nlp.n_equalities > built.nlp.n_variables
    outcome = solver.solve(np.zeros(built.nlp.n_variables))
    assert outcome.status == "Not_Enough_Degrees_Of_Freedom" and outcome.iterations == 0
    assert not list(cache.glob("*.so"))
    rr = problem_from_config(structure_config(load_config(small_config(tmp_path)), "RR"))
    local.prepared(rr, Collocation(), SolverProfile(max_iter=3, compile="O1"))  # one that can move is built
    assert list(cache.glob("*.so"))


def test_held_joints_solve_without_casadis_warning(tmp_path, capfd):
    """A 2-joint arm on a few waypoints has a few more variables than equalities; with more design joints than
    that held (lbx == ubx, as the hold of a degenerate design does) CasADi counts the held joints as equalities
    and warns that the NLP is overconstrained, but IPOPT removes them and solves: the solve runs (no
    Not_Enough_Degrees_Of_Freedom), and the warning does not reach the terminal."""
    from dataclasses import replace

    from designopt.experiments.sweep import structure_config
    from designopt.initial_guess import initial_guess
    from designopt.problem import problem_from_config
    from designopt.solve import local
    from designopt.transcriptions.collocation import Collocation

    problem = problem_from_config(structure_config(load_config(small_config(tmp_path)), "RR"))
    built, _, _ = local.prepared(problem, Collocation(), SolverProfile(max_iter=3))
    spare = built.nlp.n_variables - built.nlp.n_equalities
    design = [i for i, j in enumerate(problem.chain.joints) if j.role.name == "DESIGN"][: spare + 2]
    joints = [replace(j, lower=j.value, upper=j.value) if i in design else j
              for i, j in enumerate(problem.chain.joints)]
    held = replace(problem, chain=replace(problem.chain, joints=tuple(joints)))
    built, solver, _ = local.prepared(held, Collocation(), SolverProfile(max_iter=3))
    assert built.nlp.n_equalities <= built.nlp.n_variables < built.nlp.n_equalities + len(design)
    outcome = solver.solve(built.pack(initial_guess(held, 0, 0, 0.3, "ik")))
    assert outcome.iterations > 0 and not outcome.status.startswith("Not_Enough"), outcome.status
    assert "overconstrained" not in "".join(capfd.readouterr())


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_killed_sweep_resumes_without_losing_or_repeating(tmp_path):
    config = small_config(tmp_path)
    out = tmp_path / "r"
    cmd = [sys.executable, "-m", "cli.main", "sweep-structures", "--config", str(config), "--out", str(out),
           "--min-dof", "1", "--max-dof", "3", "--jobs", "1", "--name", "k"]
    proc = subprocess.Popen(cmd, cwd=ROOT, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    summary = out / "structures" / "k" / "summary.csv"
    deadline = time.time() + 240
    while time.time() < deadline:
        if summary.exists() and len(summary.read_text().splitlines()) >= 4:  # header + 3 rows
            break
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    before = pd.read_csv(summary)
    assert 3 <= len(before) < 8 * 6 + 4 * 12 + 2 * 24, "the sweep was not killed part-way"
    kept = {f: _digest(out / "structures" / "k" / f) for f in before["solution_file"]}
    prefix = summary.read_bytes()

    result = sweep(config, out, "--min-dof", "1", "--max-dof", "3", "--jobs", "2", "--name", "k", "--resume")
    assert result.exit_code == 0, result.output
    after = pd.read_csv(summary)
    assert set(after["structure"]) == set(enumerate_structures(1, 3))
    assert not after.duplicated(["case", "stage", "structure", "seed"]).any()  # each solve exactly once
    explored = after[after["stage"] == "explore"].groupby("structure").size()
    # quick's shares by size (`small_problem_starts`): n = joints x 8 waypoints + 3 per link + 6 (39, 28, 17), so
    # 3 x (39 / 28)^2 = 5.8 starts for two joints and 3 x 4 (the cap) for one; every arm here small, so twice its
    # share (`small_arm_starts`)
    assert explored.to_dict() == {s: {1: 24, 2: 12, 3: 6}[len(s)] for s in enumerate_structures(1, 3)}
    assert summary.read_bytes().startswith(prefix)  # finished rows untouched, byte for byte
    for f, digest in kept.items():
        assert _digest(out / "structures" / "k" / f) == digest


def test_dask_local_cluster_gives_the_same_rows_as_loky(tmp_path):
    pytest.importorskip("dask.distributed")
    config = small_config(tmp_path)
    a = sweep(config, tmp_path / "r", "--max-dof", "1", "--name", "loky", "--jobs", "2")
    b = sweep(config, tmp_path / "r", "--max-dof", "1", "--name", "dask", "--backend", "dask", "--jobs", "2")
    assert a.exit_code == 0 and b.exit_code == 0, (a.output, b.output)
    cols = ["structure", "stage", "seed", "status", "iterations", "design_cost", "tracks"]
    order = ["structure", "stage", "seed"]
    loky = pd.read_csv(tmp_path / "r" / "structures" / "loky" / "summary.csv")[cols].sort_values(order)
    dask = pd.read_csv(tmp_path / "r" / "structures" / "dask" / "summary.csv")[cols].sort_values(order)
    pd.testing.assert_frame_equal(loky.reset_index(drop=True), dask.reset_index(drop=True), rtol=1e-9)


def test_two_sweep_configs_do_not_share_a_directory(tmp_path):
    a = small_config(tmp_path)
    b = tmp_path / "other.yaml"
    b.write_text(a.read_text().replace("name: structures", "name: structures_other"))
    assert sweep(a, tmp_path / "r", "--max-dof", "1", "--name", "x", "--jobs", "1").exit_code == 0
    result = sweep(b, tmp_path / "r", "--max-dof", "1", "--name", "x", "--jobs", "1")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "r" / "structures_other" / "x" / "summary.csv").is_file()
