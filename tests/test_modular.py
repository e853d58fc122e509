"""Modules: L_mod, the angular distance, rounding, the fixed re-solve, a brute-force check, the CLI."""

from __future__ import annotations

import functools
import itertools
import math
from pathlib import Path

import casadi as ca
import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designopt.config import parse_config
from designopt.design_space import build_chain
from designopt.experiments.modular import (
    catalogue_from_config,
    fix_modules,
    module_values,
    with_modular_cost,
)
from designopt.kinematics.chain import tool_pose
from designopt.kinematics.joints import Role
from designopt.modular import (
    Catalogue,
    check_catalogue,
    distance,
    distinct_optima,
    lift,
    lifted_assignment,
    lifted_range,
    lifts,
    lifts_absorbed,
    modular_cost,
    nearest_modules,
    neighbourhood_search,
    neighbours,
    same_robot,
    screened_candidates,
    spread_assignments,
    swapped,
    within_box,
)
from designopt.problem import problem_from_config

CAT = Catalogue("R", ((0.0, 0.5, 0.0), (0.0, 0.5, math.pi / 2), (1.0, 0.0, 0.0), (1.0, 0.5, 0.0),
                      (0.5, 0.5, -math.pi / 2)), w_lin=1.0, w_ang=0.25)


def chain_with_links(rows):
    dh = [{"theta": 0.0, "d": d, "a": a, "alpha": al} for d, a, al in rows]
    return build_chain("R" * len(rows), dh, ["d", "a", "alpha"], (0, 0, 0), (0, 0, 0), ())


def test_lmod_is_zero_exactly_at_modules():
    for combo in itertools.product(range(5), repeat=2):
        chain = chain_with_links([CAT.modules[k] for k in combo])
        assert modular_cost(chain, chain.design_values, CAT) == pytest.approx(0.0, abs=1e-15)
        assert nearest_modules(chain, chain.design_values, CAT) == list(combo)


@settings(max_examples=50, deadline=None)
@given(d=st.floats(0, 2), a=st.floats(0, 2), alpha=st.floats(-3.1, 3.1))
def test_lmod_is_positive_elsewhere(d, a, alpha):
    chain = chain_with_links([(d, a, alpha)])
    gaps = [distance((d, a, alpha), m, CAT) for m in CAT.modules]
    value = modular_cost(chain, chain.design_values, CAT)
    assert value == pytest.approx(np.prod(gaps), rel=1e-12, abs=1e-300)
    if min(gaps) > 1e-9:
        assert value > 0


@settings(max_examples=50, deadline=None)
@given(alpha=st.floats(-10, 10), k=st.integers(-3, 3))
def test_angular_distance_treats_alpha_and_alpha_plus_2pi_alike(alpha, k):
    module = (0.0, 0.5, 0.3)
    assert distance((0.0, 0.5, alpha), module, CAT) == pytest.approx(
        distance((0.0, 0.5, alpha + 2 * math.pi * k), module, CAT), abs=1e-9)
    assert distance((0.0, 0.5, math.pi), (0.0, 0.5, -math.pi), CAT) == pytest.approx(0.0, abs=1e-12)


def test_rounding_picks_the_nearest_module_and_matches_brute_force(rng):
    for _ in range(50):
        link = (rng.uniform(0, 1.2), rng.uniform(0, 0.7), rng.uniform(-math.pi, math.pi))
        chain = chain_with_links([link])
        brute = min(range(5), key=lambda k: CAT.w_lin * ((link[0] - CAT.modules[k][0]) ** 2 +
                                                           (link[1] - CAT.modules[k][1]) ** 2)
                    + CAT.w_ang * 2 * (1 - math.cos(link[2] - CAT.modules[k][2])))
        assert nearest_modules(chain, chain.design_values, CAT) == [brute]


def test_lmod_symbolic_equals_numeric(rng):
    chain = chain_with_links([(0.2, 0.3, 0.4), (0.9, 0.1, -1.0)])
    q = ca.SX.sym("q", chain.n_design)
    f = ca.Function("f", [q], [modular_cost(chain, q, CAT)])
    x = rng.uniform(-1, 1, chain.n_design)
    assert float(f(x)) == pytest.approx(modular_cost(chain, x, CAT), rel=1e-12)


def test_the_resolve_keeps_modules_fixed():
    cfg = parse_config({"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 6}})
    problem = problem_from_config(cfg)
    assignment = [0, 1, 2, 3, 4, 0]
    fixed = fix_modules(problem, assignment, catalogue_from_config(cfg), {"placement.x": 0.7})
    assert all(j.name.startswith("placement.") for j in fixed.chain.design)
    values = module_values(problem, assignment, catalogue_from_config(cfg))
    for name, v in values.items():
        j = fixed.chain.joint(name)
        assert j.role is Role.FIXED and j.value == v
    assert fixed.chain.joint("placement.x").value == 0.7
    assert [c.name for c in fixed.design_costs] == ["regularization"]
    assert [c.name for c in with_modular_cost(problem, CAT, 1e-3).design_costs] == ["regularization", "modular"]


def test_catalogue_assumptions():
    check_catalogue("RRRRRR", CAT)
    with pytest.raises(ValueError, match="one joint type"):
        check_catalogue("RRPRRR", CAT)


def test_modular_command_writes_every_stage(tmp_path):
    import json

    import pandas as pd
    import yaml
    from typer.testing import CliRunner

    from cli.main import app
    from designopt.verify import verify_file

    config = tmp_path / "m.yaml"
    config.write_text(yaml.safe_dump({"name": "modular", "toolpath": {"kind": "figure_eight", "waypoints": 12},
                                      "placement": {"xyz": [0.45, 0.0, -0.2]},
                                      "search": {"preset": "paper", "starts": 1}}))
    # 40 coarse starts per refined optimum (the command's default, REFINE_STARTS, quadruples this test's time)
    result = CliRunner().invoke(app, ["modular", str(config), "--out", str(tmp_path / "r"), "--name", "t",
                                      "--budget", "30", "--refine", "3", "--refine-starts", "40"])
    assert result.exit_code == 0, result.output
    run = tmp_path / "r" / "modular" / "t"
    summary = pd.read_csv(run / "summary.csv")
    stages = set(summary["case"])
    assert {"continuous", "continuous_modular", "rounded", "modular", "fk"} <= stages
    screened = {c for c in stages if c.startswith("sc-")}  # the neighbourhood search's screened candidates
    assert len(screened) == 30  # the budget, all spent: a sample of 5 and local searches from the best of it
    robots = {same_robot(tuple(int(c) - 1 for c in case[3:]), CAT) for case in screened}
    assert len(robots) == 30  # one assignment per robot: no two screened differ by a lift alone
    warm = summary[summary["stage"] == "warm"]  # neighbours of an incumbent: one more start, from its optimum
    assert len(warm) and warm["case"].str.startswith("sc-").all() and warm["case"].is_unique
    size = summary.groupby([summary["case"].str[:3], "stage"])["n_variables"].agg(set)
    assert len(size["sc-", "start"]) == 1  # screened on 10 of the 12 waypoints, searched (default) on all 12
    assert max(size["sc-", "start"]) < min(size["nb-", "refine"])
    refined = {c for c in stages if c.startswith("nb-")}  # the best screened, searched on the full path
    assert 1 <= len(refined) <= 3
    nb = summary[summary["case"].isin(refined)]
    assert {"explore", "refine"} <= set(nb["stage"])  # coarse to fine (no screen on 12 waypoints), not the paper's
    assert (nb[nb["stage"] == "explore"].groupby("case").size() == 40).all()  # --refine-starts reaches the search
    rows = summary[summary["case"].isin(screened) & (summary["tracks"].astype(str) == "True")]
    costs = rows.groupby("case")["design_cost"].min()
    table = pd.read_csv(run / "table.csv").set_index("stage")
    rounded = table.loc["modular", "modules"].replace("m", "").replace(" ", "")  # solved already: not again
    # the best screened optima, one assignment each: no two refined share a screening cost (to 1e-6), and every
    # screened assignment cheaper than the dearest refined one shares its cost with a refined one (or the rounded)
    kept = [costs["sc-" + c[3:]] for c in refined] + ([costs[f"sc-{rounded}"]] if f"sc-{rounded}" in costs else [])
    assert all(abs(a - b) > 1e-6 * a for a, b in itertools.combinations(kept[: len(refined)], 2))
    dearest = max(costs["sc-" + c[3:]] for c in refined)
    assert all(any(abs(c - k) <= 1e-6 * k for k in kept) for c in costs[costs < dearest])
    assert len(refined | {f"nb-{rounded}"}) >= min(3, len(set(np.round(costs.values, 6))))
    table = pd.read_csv(run / "table.csv").set_index("stage")
    # the search starts from the rounded assignment and never ends worse than its re-solve
    assert table.loc["neighbourhood", "design_cost"] <= table.loc["modular", "design_cost"] * (1 + 1e-9)
    built = json.loads((run / "best-neighbourhood.json").read_text())  # the robot as built: its placement in the box
    assert " ".join(f"m{[tuple(m) for m in CAT.modules].index((r['d'], r['a'], r['alpha'])) + 1}"
                    for r in built["dh"]) == table.loc["neighbourhood", "modules"]
    assert -1.0 <= built["design_joints"]["placement.z"] <= 2.0
    assert (run / "figures" / "module_pca.png").stat().st_size > 1000
    # the rounded assignment is the nearest modules of the continuous solution with L_mod (its file's links)
    continuous = json.loads((run / "best-continuous_modular.json").read_text())
    links = [(row["d"], row["a"], row["alpha"]) for row in continuous["dh"]]
    nearest = [int(np.argmin([distance(np.array(link), m, CAT) for m in CAT.modules])) for link in links]
    assert table.loc["rounded", "modules"] == " ".join(f"m{k + 1}" for k in nearest)
    assert table.loc["modular", "modules"] == table.loc["rounded", "modules"]
    modular_file = summary.loc[summary["case"] == "modular", "solution_file"].iloc[0]
    final = json.loads((run / modular_file).read_text())
    modules = set(catalogue_from_config(parse_config({})).modules)
    for row in final["dh"]:  # every link is exactly a catalogue module
        assert (row["d"], row["a"], row["alpha"]) in modules
    assert set(final["design_joints"]) == {f"placement.{p}" for p in ("x", "y", "z", "yaw", "pitch", "roll")}
    for f in (run / "solutions").glob("*.json"):
        assert verify_file(f) == [], f


def test_a_rounded_assignment_that_does_not_track_still_gets_the_neighbourhood_search(tmp_path, monkeypatch):
    """Seed 1101 of the shipped config: none of the rounded assignment's 4 re-solves tracked (IPOPT: infeasible),
    and the run ended with no modular robot. The neighbourhood search does not need that re-solve: it screens the
    rounded assignment with its own starts and a sample spread over the catalogue. Here the re-solve is made to
    find no tracking start; the search still ends at a tracking robot built from catalogue modules."""
    import json

    from designopt.experiments import modular as experiment
    from designopt.verify import verify_file

    stage = experiment._stage

    def no_tracking_resolve(setup, problem, case, transcription=None):
        return None if case == "modular" else stage(setup, problem, case, transcription)

    monkeypatch.setattr(experiment, "_stage", no_tracking_resolve)
    cfg = parse_config({"name": "modular", "toolpath": {"kind": "figure_eight", "waypoints": 12},
                        "placement": {"xyz": [0.45, 0.0, -0.2]}, "search": {"preset": "paper", "starts": 1}})
    result = experiment.run_modular(cfg, tmp_path, "t", figures=False, jobs=1, neighbourhood_budget=8,
                                    neighbourhood_refine=1, neighbourhood_refine_starts=40)
    table = result.table.set_index("stage")
    assert not table.loc["modular", "tracks"] and np.isnan(table.loc["modular", "design_cost"])
    assert table.loc["neighbourhood", "tracks"] and np.isfinite(table.loc["neighbourhood", "design_cost"])
    summary = pd.read_csv(result.directory.path / "summary.csv")
    assert summary["case"].str.startswith("sc-").sum() >= 8  # the budget's robots screened
    modules = {tuple(m) for m in catalogue_from_config(cfg).modules}
    built = result.directory.path / "best-neighbourhood.json"
    assert verify_file(built) == []
    assert all((r["d"], r["a"], r["alpha"]) in modules for r in json.loads(built.read_text())["dh"])


@pytest.mark.parametrize(("flag", "swaps"), [([], True), (["--swaps"], True), (["--no-swaps"], False)])
def test_the_swaps_flag_reaches_the_search(tmp_path, monkeypatch, flag, swaps):
    """`designopt modular` hands the neighbourhood search its exchanges of neighbouring links unless `--no-swaps`;
    the CLI's default is the library's."""
    from types import SimpleNamespace

    from typer.testing import CliRunner

    from cli.main import app
    from designopt.experiments import modular as experiment

    seen = {}

    def fake_run(cfg, out, name, bar, **kwargs):
        seen.update(kwargs)
        return SimpleNamespace(table=pd.DataFrame({"stage": ["modular"]}), directory=SimpleNamespace(path=tmp_path))

    monkeypatch.setattr(experiment, "run_modular", fake_run)
    config = Path(__file__).resolve().parent.parent / "configs" / "modular.yaml"
    result = CliRunner().invoke(app, ["modular", str(config), "--out", str(tmp_path), *flag])
    assert result.exit_code == 0, result.output
    assert seen["neighbourhood_swaps"] is swaps
    if not flag:
        assert swaps is experiment.NEIGHBOURHOOD_SWAPS
        # every default of the command is the library's
        assert seen["neighbourhood_refine_starts"] == experiment.REFINE_STARTS
        assert seen["neighbourhood_budget"] == experiment.NEIGHBOURHOOD_BUDGET
        assert seen["neighbourhood_refine"] == experiment.NEIGHBOURHOOD_REFINE


def test_mixed_structure_is_a_one_line_error(tmp_path):
    import yaml
    from typer.testing import CliRunner

    from cli.main import app

    config = tmp_path / "m.yaml"
    config.write_text(yaml.safe_dump({"robot": {"structure": "RRPRRR", "dh": "generic"}}))
    result = CliRunner().invoke(app, ["modular", str(config), "--out", str(tmp_path)])
    assert result.exit_code == 2
    assert "robot.structure" in result.output and "one joint type" in result.output


def test_tiny_enumeration_agrees_with_a_brute_force_loop(rng):
    """Every assignment of 3 modules to 2 links, scored by L_mod of a perturbed design: the enumeration the
    study uses (itertools.product over assignments) finds the same best as two nested loops."""
    small = Catalogue("R", CAT.modules[:3], CAT.w_lin, CAT.w_ang)
    design = [(0.1, 0.45, 0.2), (0.9, 0.1, -0.1)]
    chain = chain_with_links(design)

    def score(assignment):
        return sum(distance(design[i], small.modules[k], small) for i, k in enumerate(assignment))

    enumerated = min(itertools.product(range(3), repeat=2), key=score)
    loops = None
    for a in range(3):
        for b in range(3):
            if loops is None or score((a, b)) < score(loops):
                loops = (a, b)
    assert enumerated == loops
    assert list(enumerated) == nearest_modules(chain, chain.design_values, small)


def test_modular_study_end_to_end(tmp_path):
    """The study on a 2-link robot and a 2-module sub-catalogue: every one of the 2^2
    assignments is solved and ranked, rounding's pick is marked once, the weight study has its row."""
    from designopt.experiments.modular import run_modular_study
    from designopt.solve import SolverProfile, preset

    cfg = parse_config({"name": "modular", "toolpath": {"kind": "figure_eight", "waypoints": 8},
                        "robot": {"structure": "RR", "dh": "generic"}, "placement": {"xyz": [0.3, 0.0, -0.2]}})
    search = preset("paper", starts=1, profile=SolverProfile(max_iter=100))
    result = run_modular_study(cfg, tmp_path / "r", "a", jobs=1, weights=(1.0e-3,), enumeration_modules=(1, 2),
                               enumeration_waypoints=6, search=search)
    run = result.directory.path
    enum = pd.read_csv(run / "enumeration.csv")
    assert sorted(enum["assignment"]) == ["m1 m1", "m1 m2", "m2 m1", "m2 m2"]
    assert enum["rounding_picked"].sum() == 1 and list(enum["rank"]) == [1, 2, 3, 4]
    # the neighbourhood search ends at a local optimum of one-link changes, no worse than rounding's pick
    cost = dict(zip(enum["assignment"], enum["design_cost"].fillna(np.inf), strict=True))  # NaN: does not track
    picked = enum.loc[enum["neighbourhood_picked"], "assignment"].item()
    a, b = picked.split()
    flip = {"m1": "m2", "m2": "m1"}
    assert cost[picked] <= min(cost[f"{flip[a]} {b}"], cost[f"{a} {flip[b]}"])
    assert cost[picked] <= cost[enum.loc[enum["rounding_picked"], "assignment"].item()]
    assert len(pd.read_csv(run / "weight_study.csv")) == 1


def test_neighbourhood_search_finds_the_optimum_of_a_separable_cost():
    """A cost that is a sum over links has no local optimum but the global one under one-link changes: the
    search finds the brute-force optimum from any start, evaluating each assignment once."""
    rng = np.random.default_rng(7)
    table = rng.uniform(0, 1, (4, 3))  # 4 links, 3 modules

    def cost(a):
        return float(sum(table[i, k] for i, k in enumerate(a)))

    calls = []

    def evaluate(batch, incumbent):
        calls.extend(batch)
        # a step's batch is its incumbent's neighbours (one link changed) and exchanges of two neighbouring
        # links' modules, which warm-start from it
        assert incumbent is None or all(a in neighbours(incumbent, 3) or a in swapped(incumbent) for a in batch)
        return [cost(a) for a in batch]

    truth = min(itertools.product(range(3), repeat=4), key=cost)
    for start in [(0, 0, 0, 0), (2, 1, 0, 2)]:
        calls.clear()
        best, value, seen = neighbourhood_search([start], 3, evaluate, budget=81, swaps=True)
        assert tuple(best) == truth and value == pytest.approx(cost(truth))
        assert len(calls) == len(set(calls)) == len(seen)  # each assignment solved once


@given(st.lists(st.integers(0, 4), min_size=1, max_size=7).map(tuple))
def test_swapped_exchanges_two_neighbouring_links_that_differ(assignment):
    """Each swapped assignment holds the same modules, differs in exactly two neighbouring links, and has their
    modules exchanged; there is one per pair of unequal neighbouring links, none twice."""
    out = swapped(assignment)
    assert len(out) == len(set(out)) == sum(x != y for x, y in itertools.pairwise(assignment))
    for a in out:
        assert sorted(a) == sorted(assignment)
        changed = [i for i, (x, y) in enumerate(zip(a, assignment, strict=True)) if x != y]
        i = changed[0]
        assert changed == [i, i + 1] and (a[i], a[i + 1]) == (assignment[i + 1], assignment[i])


def test_a_swap_escapes_where_one_link_changes_cannot():
    """Closed-form truth: a cost that charges any change of the set of modules more than it can ever gain, and
    otherwise counts the pairs of links out of order. Every one-link change of a start costs more, so a search by
    one-link changes stays there; with ``swaps`` exchanges of neighbouring links sort the assignment (bubble sort)
    to the optimum, the modules in ascending order."""
    start = (3, 1, 2, 0, 2)

    def cost(a):
        if sorted(a) != sorted(start):
            return 100.0
        return float(sum(a[i] > a[j] for i, j in itertools.combinations(range(len(a)), 2)))

    assert all(cost(a) > cost(start) for a in neighbours(start, 4))
    evaluate = lambda batch, _: [cost(a) for a in batch]  # noqa: E731
    best, value, _ = neighbourhood_search([start], 4, evaluate, budget=500)
    assert tuple(best) == start and value == cost(start)
    best, value, _ = neighbourhood_search([start], 4, evaluate, budget=500, swaps=True)
    assert tuple(best) == (0, 1, 2, 2, 3) and value == 0.0


def test_neighbourhood_search_keeps_its_budget_and_escapes_a_rounding_trap():
    """A deceptive cost: the rounded start (0, 0) is a local optimum, (1, 1) the global one; with a second
    start the search finds it; the budget caps the evaluations."""
    costs = {(0, 0): 1.0, (0, 1): 2.0, (1, 0): 2.0, (1, 1): 0.5}
    best, value, seen = neighbourhood_search([(0, 0)], 2, lambda b, _: [costs[a] for a in b], budget=10)
    assert tuple(best) == (0, 0) and len(seen) == 3  # stuck: both neighbours are worse
    best, value, seen = neighbourhood_search([(0, 0), (1, 0)], 2, lambda b, _: [costs[a] for a in b], budget=10)
    assert tuple(best) == (1, 1) and value == 0.5
    _, _, seen = neighbourhood_search([(0, 0, 0)], 5, lambda b, _: [float(sum(a)) + 1 for a in b], budget=5)
    assert len(seen) == 5
    nan = neighbourhood_search([(0,)], 3, lambda b, _: [np.nan if a == (0,) else 1.0 for a in b], budget=5)
    assert nan[0] in ([1], [2]) and nan[1] == 1.0  # a start that does not track is left for one that does


def test_refined_candidates_are_distinct_optima():
    """Link 1's module does not change the cost (as a module's offset along the first joint's axis, which the free
    placement absorbs), so every cost comes in 3 equal copies, two of them 1e-9 apart as IPOPT ends one optimum
    from two starts. The candidates sent to the full path are the cheapest *distinct* costs of all screened
    (brute force over what the search screened), one assignment each; without the rule they would be copies."""
    rng = np.random.default_rng(3)
    table = rng.uniform(0, 1, (3, 3))

    def cost(a):
        return float(1.0 + sum(table[i, k] for i, k in enumerate(a[1:]))) * (1 + 1e-9 * (a[0] == 2))

    ranked, evaluated = screened_candidates((0, 0, 0, 0), 3, lambda b, _: [cost(a) for a in b], budget=81,
                                            sample=2, refine=4, seed=0)
    values = sorted({round(c, 6) for _, c in evaluated})[:4]
    assert [round(cost(a), 6) for a in ranked] == values
    assert len({a[1:] for a in ranked}) == 4  # four different robots, not one robot under four link-1 modules
    copies = [(a, c) for a, c in evaluated if a[1:] == ranked[0][1:]]
    assert len(copies) > 1 and distinct_optima(copies, 4) == [min(copies, key=lambda p: p[1])[0]]
    assert distinct_optima([((0,), 1.0), ((1,), 1.0 + 2e-6)], 2) == [(0,), (1,)]  # 2e-6 apart: two optima


def test_spread_assignments_use_every_module_equally_often_on_every_link():
    sample = spread_assignments(12, 6, 5, seed=7)
    assert len(set(sample)) > 1 and sample == spread_assignments(12, 6, 5, seed=7) != spread_assignments(12, 6, 5, 8)
    for link in range(6):
        counts = np.bincount([a[link] for a in sample], minlength=5)
        assert counts.max() - counts.min() <= 1 and counts.sum() == 12


def test_the_local_searches_start_from_the_cheapest_screened_start():
    """A deceptive 4-link cost: a wide shallow basin around all-zeros and a narrow deep one around (2, 2, 2, 2).
    From the starts in the given order the budget runs out in the shallow basin; cheapest first, the search
    starts next to the deep one and reaches it."""
    deep = (2, 2, 2, 2)

    def cost(a):
        far = sum(x != y for x, y in zip(a, deep, strict=True))
        return 0.1 * far if far <= 1 else 1.0 + sum(a)

    starts = [(0, 0, 0, 0), (1, 1, 1, 1), (2, 2, 2, 0), (0, 1, 2, 3)]
    evaluate = lambda batch, _: [cost(a) for a in batch]  # noqa: E731
    best, value, _ = neighbourhood_search(starts, 4, evaluate, budget=20)
    assert value >= 1.0  # in order: the shallow basin takes the budget
    best, value, seen = neighbourhood_search(starts, 4, evaluate, budget=20, cheapest_first=True)
    assert tuple(best) == deep and value == 0.0
    assert [a for a, _ in seen[:4]] == starts  # the starts are screened first, as one batch


@functools.lru_cache(maxsize=1)
def robots_of_the_paper_catalogue() -> dict:
    """Every assignment of the five paper modules on six links, grouped by `same_robot` (brute force)."""
    groups: dict = {}
    for a in itertools.product(range(5), repeat=6):
        groups.setdefault(same_robot(a, CAT), []).append(a)
    return groups


def tool_poses(assignment, qs, catalogue=CAT):
    chain = chain_with_links([catalogue.modules[k] for k in assignment])
    return [np.array(tool_pose(chain, q, chain.design_values), float) for q in qs]


REVERSING = Catalogue("R", ((0.3, 0.5, math.pi), (0.2, 0.4, math.pi / 2), (0.7, 0.5, math.pi), (0.6, 0.4, math.pi / 2),
                            (0.4, 0.5, 0.0)))


def test_a_reversing_twist_lowers_what_follows():
    """Closed-form truth on a catalogue with twists of pi (z reversed): every assignment of 4 links against every
    other one of the same robot, tool poses equal up to their difference of lifts along base z."""
    qs = np.random.default_rng(2).uniform(-np.pi, np.pi, (3, 4))
    poses = functools.partial(tool_poses, qs=qs, catalogue=REVERSING)

    groups: dict = {}
    for a in itertools.product(range(5), repeat=4):
        groups.setdefault(same_robot(a, REVERSING), []).append(a)
    assert max(len(g) for g in groups.values()) > 4 and len(groups) < 5 ** 4
    for group in groups.values():
        first = poses(group[0])
        for other in group[1:]:
            shift = np.eye(4)
            shift[2, 3] = lift(other, REVERSING) - lift(group[0], REVERSING)
            assert all(np.allclose(p, shift @ o, atol=1e-12) for p, o in zip(poses(other), first, strict=True))
    assert lift((0, 4, 1, 1), REVERSING) == pytest.approx(0.3 - 0.4 - 0.2)  # after a pi, d lowers


@settings(max_examples=25, deadline=None)
@given(st.tuples(*[st.integers(0, 4)] * 6))
def test_one_robot_is_one_tool_pose_up_to_its_lift(assignment):
    """Closed-form truth: assignments `same_robot` calls one robot put the tool at the same pose up to a
    translation along base z by their difference of lifts, at every joint angle; an assignment of another robot
    does not (its tool poses differ by more than a translation along base z at some angles)."""
    rng = np.random.default_rng(sum(assignment))
    qs = rng.uniform(-np.pi, np.pi, (4, 6))
    own = tool_poses(assignment, qs)
    group = robots_of_the_paper_catalogue()[same_robot(assignment, CAT)]
    assert assignment in group
    for other in group:
        shift = np.eye(4)
        shift[2, 3] = lift(other, CAT) - lift(assignment, CAT)
        assert all(np.allclose(p, shift @ o, atol=1e-12) for p, o in zip(tool_poses(other, qs), own, strict=True))
    stranger = next(a for a in neighbours(assignment, 5) if same_robot(a, CAT) != same_robot(assignment, CAT))
    gaps = [p[:3, 3] - o[:3, 3] for p, o in zip(tool_poses(stranger, qs), own, strict=True)]
    rotations_equal = all(np.allclose(p[:3, :3], o[:3, :3]) for p, o in zip(tool_poses(stranger, qs), own, strict=True))
    assert not (rotations_equal and np.allclose(gaps, gaps[0]) and np.allclose(np.array(gaps)[:, :2], 0))


def test_lifts_ranges_and_the_member_inside_the_box_agree_with_brute_force():
    box = (-1.0, 2.0)
    assert lifts_absorbed(CAT, box) and not lifts_absorbed(CAT, (0.0, 0.5))
    groups = robots_of_the_paper_catalogue()
    assert len(groups[same_robot((0,) * 6, CAT)]) == 64  # a planar robot of m1/m4 links: 2^6 lifts of one robot
    for a in [(0, 4, 0, 0, 0, 1), (3, 3, 1, 0, 3, 4), (2, 0, 3, 4, 3, 3), (1, 3, 3, 3, 3, 3)]:
        group = groups[same_robot(a, CAT)]
        truth = sorted({round(lift(b, CAT), 12) for b in group})
        assert lifts(a, CAT) == truth
        for r in truth:
            b = lifted_assignment(a, CAT, r)
            assert b in group and lift(b, CAT) == pytest.approx(r)
        assert lifted_assignment(a, CAT, lift(a, CAT)) == a and lifted_assignment(a, CAT, truth[-1] + 0.25) is None
        # the range of a's placement z is the union of every member's box, moved by the difference of lifts
        lo, hi = lifted_range(a, CAT, box)
        intervals = sorted((box[0] - (r - lift(a, CAT)), box[1] - (r - lift(a, CAT))) for r in truth)
        assert (lo, hi) == pytest.approx((intervals[0][0], intervals[-1][1]))
        assert all(nxt[0] <= cur[1] for cur, nxt in itertools.pairwise(intervals))  # one interval
        for z in np.linspace(lo, hi, 13):
            member, z_member = within_box(a, CAT, z, box)
            assert member in group and box[0] - 1e-9 <= z_member <= box[1] + 1e-9
            assert z_member - z == pytest.approx(lift(member, CAT) - lift(a, CAT))
            if box[0] <= z <= box[1]:
                assert member == a and z_member == z
        with pytest.raises(ValueError, match="outside"):
            within_box(a, CAT, hi + 0.1, box)


def test_the_search_evaluates_one_assignment_per_robot():
    """Link 1's module does not change the robot (``same`` drops it): one assignment of each robot is evaluated,
    the budget counts robots, every step's incumbent is an evaluated assignment, and the optimum over robots is
    found, as on the cost of the robots alone."""
    rng = np.random.default_rng(11)
    table = rng.uniform(0, 1, (4, 3))

    def cost(a):
        return float(sum(table[i, k] for i, k in enumerate(a) if i))

    calls, incumbents = [], []

    def evaluate(batch, incumbent):
        calls.extend(batch)
        incumbents.append(incumbent)
        return [cost(a) for a in batch]

    best, value, seen = neighbourhood_search([(0, 0, 0, 0)], 3, evaluate, budget=27, same=lambda a: a[1:])
    truth = min(itertools.product(range(3), repeat=4), key=cost)
    assert value == pytest.approx(cost(truth)) and tuple(best)[1:] == truth[1:]
    assert len({a[1:] for a in calls}) == len(calls) == len(seen) <= 27  # one per robot
    assert all(i is None or i in calls for i in incumbents)
    calls.clear()
    _, _, seen = neighbourhood_search([(0, 0, 0, 0)], 3, evaluate, budget=5, same=lambda a: a[1:])
    assert len(calls) == len(seen) == 5


def test_a_solution_as_built_keeps_its_metrics_with_its_placement_in_the_box():
    """Invariant: a solution whose placement z lies outside the box, moved to the assignment of the same robot
    whose z lies inside (`as_built`), tracks and costs the same (metrics evaluated afresh on the other robot),
    for any joint trajectory; inside the box it is returned as it is."""
    from designopt.evaluation import evaluate
    from designopt.experiments.modular import as_built, lifted_modules
    from designopt.solution import Solution
    from designopt.transcriptions.base import RawResult
    from designopt.transcriptions.trajectory import HermiteCubic

    cfg = parse_config({"toolpath": {"kind": "circle", "radius": 0.1, "waypoints": 6}})
    base, catalogue = problem_from_config(cfg), catalogue_from_config(cfg)
    a = (0, 4, 0, 0, 0, 1)  # m1 m5 m1 m1 m1 m2: lift 0.5; m4 in place of m1 on link 1 lifts it 1 m more
    problem = lifted_modules(base, list(a), catalogue, {})
    z = problem.chain.joint("placement.z")
    assert (z.lower, z.upper) == pytest.approx((-1.0 - 1.0, 2.0))
    rng = np.random.default_rng(5)
    n, m = problem.toolpath.n, problem.chain.n_moving
    trajectory = HermiteCubic(problem.toolpath.t, rng.normal(size=(n, m)), rng.normal(size=(n, m)))
    names = [j.name for j in problem.chain.design]
    for z_value, expected in [(-1.6, (3, 4, 0, 0, 0, 1)), (0.3, a)]:
        q_d = problem.chain.design_values.copy()
        q_d[names.index("placement.z")] = z_value
        raw = RawResult(q_d, trajectory, "x", True, 0, 0.0, 0.0, 0.0, 0, 0)
        sol = Solution(problem, "to", raw, evaluate(problem, q_d, trajectory))
        member, built = as_built(sol, a, base, catalogue, {})
        assert member == expected
        assert built.problem.chain.joint("link1.d").value == catalogue.modules[expected[0]][0]
        placed = dict(zip([j.name for j in built.problem.chain.design], built.raw.q_d, strict=True))
        assert placed["placement.z"] == pytest.approx(z_value + lift(expected, CAT) - lift(a, CAT))
        assert -1.0 <= placed["placement.z"] <= 2.0
        assert built.metrics.design_cost == pytest.approx(sol.metrics.design_cost, rel=1e-9)
        assert built.metrics.max_position_error == pytest.approx(sol.metrics.max_position_error, rel=1e-9)
