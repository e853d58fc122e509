"""Mutation check: does the test suite notice a wrong objective?

Each mutation below is a plausible bug (a wrong force direction, a dropped time step, K in place of K^-1,
...). For each, the project is copied to a temporary directory, the one line is changed there, and the
fast tests run against the copy. A mutation is *caught* when a test fails. Run with ``make mutate``;
exit code 1 if any mutation survives. The working tree is never modified.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# The tests that guard the objective; each mutation runs them with -x (stop at the first failure).
TESTS = ["tests/test_objective_truth.py", "tests/test_costs_and_toolpaths.py", "tests/test_kinematics.py",
         "tests/test_collocation.py", "tests/test_fk.py", "tests/test_cli_and_files.py", "tests/test_urdf.py",
         "tests/test_gcode.py", "tests/test_forces.py", "tests/test_clearance.py", "tests/test_search.py",
         "tests/test_degeneracy.py"]
PRODUCTION = ("tests/test_production_models.py",)


@dataclass(frozen=True)
class Mutation:
    """A one-line bug; ``tests`` (default: `TESTS`) are the tests that must notice it."""

    name: str
    file: str
    old: str
    new: str
    tests: tuple[str, ...] | None = None


MUTATIONS = [
    Mutation("force along the in-plane normal instead of the tangent", "designopt/toolpaths.py",
             "return Toolpath(kind, t, points, tangents, force * tangents)",
             "return Toolpath(kind, t, points, tangents, force * np.column_stack("
             "[-tangents[:, 1], tangents[:, 0], tangents[:, 2]]))"),
    Mutation("force against the direction of travel", "designopt/toolpaths.py",
             "return Toolpath(kind, t, points, tangents, force * tangents)",
             "return Toolpath(kind, t, points, tangents, -force * tangents)"),
    Mutation("dt dropped from the objective's deformation term", "designopt/transcriptions/nlp.py",
             "phi += h * cost.weight * cost.fn(w)", "phi += cost.weight * cost.fn(w)"),
    Mutation("a waypoint term's weight ignored", "designopt/transcriptions/nlp.py",
             "phi += h * cost.weight * cost.fn(w)", "phi += h * cost.fn(w)"),
    Mutation("K instead of K^-1 (problem)", "designopt/problem.py",
             "return 1.0 / self.stiffness.diagonal(self.chain.structure)",
             "return self.stiffness.diagonal(self.chain.structure)"),
    Mutation("K instead of K^-1 (symbolic branch only)", "designopt/costs.py",
             "return J @ (ca.diag(k_inv) @ (J[:3, :].T @ force_B))",
             "return J @ (ca.diag(1.0 / k_inv) @ (J[:3, :].T @ force_B))"),
    Mutation("revolute and prismatic stiffness swapped", "designopt/costs.py",
             "[self.revolute if c == \"R\" else self.prismatic for c in structure]",
             "[self.prismatic if c == \"R\" else self.revolute for c in structure]"),
    Mutation("placement rotation order reversed", "designopt/kinematics/transforms.py",
             "return trans(x, y, z) @ rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)",
             "return trans(x, y, z) @ rot_x(roll) @ rot_y(pitch) @ rot_z(yaw)"),
    Mutation("tracking tolerance comparison flipped", "designopt/evaluation.py",
             "tracks=bool(max_pos <= problem.position_tol and max_axis <= problem.axis_tol)",
             "tracks=bool(max_pos >= problem.position_tol and max_axis >= problem.axis_tol)"),
    Mutation("translational deflection takes the rotational rows", "designopt/costs.py",
             "delta = delta[:3]", "delta = delta[3:]"),
    Mutation("prismatic Jacobian column as if revolute-like", "designopt/kinematics/chain.py",
             "else (a, 0 * a)", "else (0 * a, a)"),
    Mutation("regularisation dropped from the objective", "designopt/transcriptions/quadratic.py",
             "[sum(cost(problem.chain, q_d) for cost in quadratic)]",
             "[0 * sum(cost(problem.chain, q_d) for cost in quadratic)]"),
    Mutation("rotation about a general axis turned the wrong way", "designopt/kinematics/transforms.py",
             "[c + x * x * v, x * y * v - z * s, x * z * v + y * s, 0],",
             "[c + x * x * v, x * y * v + z * s, x * z * v + y * s, 0],"),
    Mutation("smoothness integral off by the interval length", "designopt/transcriptions/trajectory.py",
             "return h / 3.0 * (a0 * a0 + a0 * a1 + a1 * a1)", "return 1 / 3.0 * (a0 * a0 + a0 * a1 + a1 * a1)"),
    Mutation("G2 and G3 swapped", "designopt/gcode.py",
             "period = -2 * math.pi if clockwise else 2 * math.pi",
             "period = 2 * math.pi if clockwise else -2 * math.pi"),
    Mutation("G20 read as millimetres", "designopt/gcode.py",
             "UNITS = {20: 0.0254, 21: 0.001}", "UNITS = {20: 0.001, 21: 0.001}"),
    Mutation("rapids count in the tracking error", "designopt/evaluation.py",
             "max_pos, max_axis = float(pos_err[tracked].max()), float(axis_err[tracked].max())",
             "max_pos, max_axis = float(pos_err.max()), float(axis_err.max())"),
    Mutation("uneven time steps averaged in the integrals", "designopt/toolpaths.py",
             "return np.concatenate([h, h[-1:]])", "return np.full(self.n, h.mean())"),
    Mutation("feed-normal milling force mirrored", "designopt/forces.py",
             "F_y = F_t * np.sin(phi) - F_r * np.cos(phi)", "F_y = -F_t * np.sin(phi) - F_r * np.cos(phi)"),
    Mutation("Kienzle exponent dropped", "designopt/forces.py",
             "h_mm ** (1.0 - m.mc)", "h_mm"),
    Mutation("capsule radius left out of the block clearance", "designopt/clearance.py",
             "need = cell.radius(link) + cell.clearance + length / (2 * (n - 1))",
             "need = cell.clearance + length / (2 * (n - 1))"),
    Mutation("per-joint stiffness read in reverse", "designopt/costs.py",
             "return np.array(self.per_joint, dtype=float)", "return np.array(self.per_joint[::-1], dtype=float)"),
    # the search (issue 11)
    Mutation("search refines the most expensive coarse optima", "designopt/solve/optima.py",
             "for k in np.argsort(costs, kind=\"stable\"):", "for k in np.argsort(-costs, kind=\"stable\"):"),
    Mutation("distinct optima: a design joins the last cluster near it, not the first", "designopt/solve/optima.py",
             "labels[i] = near[0]", "labels[i] = near[-1]", ("tests/test_tables.py",)),
    Mutation("a form keeps one leader more than rebranch_per_form allows", "designopt/solve/optima.py",
             "if taken.get(f, 0) < per_form:", "if taken.get(f, 0) <= per_form:", ("tests/test_search.py",)),
    Mutation("the second round's leaders by cost alone (rebranch_per_form ignored)",
             "designopt/solve/strategies/coarse_to_fine.py", "search.distinct, search.rebranch_per_form,",
             "search.distinct, None,", ("tests/test_search.py",)),
    Mutation("the second round adds no optimum of a new form (rebranch_new_forms ignored)",
             "designopt/solve/strategies/coarse_to_fine.py", "search.rebranch_new_forms)", "0)",
             ("tests/test_search.py",)),
    Mutation("a d-reflection turns only the twist before the link (reflect)", "designopt/kinematics/reflections.py",
             "for link, turn in ((self.link - 1, np.pi), (self.link, -np.pi)):",
             "for link, turn in ((self.link - 1, np.pi),):", ("tests/test_reflections.py",)),
    Mutation("an a-reflection keeps the link's twist (reflect)", "designopt/kinematics/reflections.py",
             "q[k] = wrap(-q[k])", "q[k] = wrap(q[k])", ("tests/test_reflections.py",)),
    Mutation("a reflected twist not wrapped into its bounds (reflect)", "designopt/kinematics/reflections.py",
             "q[k] = wrap(q[k] + turn)", "q[k] = q[k] + turn", ("tests/test_reflections.py",)),
    Mutation("every length reflected, near its bound or not (reflect)", "designopt/kinematics/reflections.py",
             "q_d[k] - design[k].lower <= within", "True", ("tests/test_reflections.py",)),
    Mutation("the reflect stage never runs (Search.reflect ignored)", "designopt/solve/strategies/reflect.py",
             "for i in range(search.reflect):", "for i in range(0):", ("tests/test_reflections.py",)),
    Mutation("the screen's candidates by cost alone (screen_per_form ignored)",
             "designopt/solve/strategies/coarse_to_fine.py", "per_form=search.screen_per_form,", "per_form=None,",
             ("tests/test_search.py",)),
    Mutation("an optimum added to the second round whatever its form", "designopt/solve/optima.py",
             "            if f not in seen:", "            if True:", ("tests/test_search.py",)),
    Mutation("the last link's twist counted in the arm's form", "designopt/solve/optima.py",
             "chain.robot[moving[0] + 1:moving[-1]]", "chain.robot[moving[0] + 1:]", ("tests/test_search.py",)),
    Mutation("the evaluation reads the path's forces as its points", "designopt/evaluation.py",
             "q_d, np.asarray(tp.points_W, float).T,", "q_d, np.asarray(tp.force_W, float).T,"),
    Mutation("every refine from the warm start's barrier (refine_mu_init ignored)",
             "designopt/solve/strategies/coarse_to_fine.py", "mu_init=refine_mu)]", "mu_init=None)]",
             ("tests/test_search.py",)),
    Mutation("every screen from the warm start's barrier (screen_mu_init ignored)",
             "designopt/solve/strategies/coarse_to_fine.py", "mu_init=screen_mu,", "mu_init=None,",
             ("tests/test_search.py",)),
    Mutation("the refine's candidates from the first screen pass only", "designopt/solve/strategies/coarse_to_fine.py",
             "[better_pass(d) for d in by_job(sub, (yield tasks))]",
             "[[x for x in d if x[0].stage == 'screen'] for d in by_job(sub, (yield tasks))]",
             ("tests/test_search.py",)),
    Mutation("a candidate screened twice keeps its dearer pass", "designopt/solve/strategies/coarse_to_fine.py",
             "kept = best_solution([sol for _, sol in passes[seed]])",
             "kept = max((s for _, s in passes[seed] if s.metrics.tracks), key=lambda s: s.metrics.design_cost, "
             "default=None)", ("tests/test_search.py",)),
    Mutation("lifted start drops the coarse design", "designopt/solve/starts.py",
             "q_d = np.asarray(solution.raw.q_d, float)", "q_d = problem.chain.design_values"),
    Mutation("a lifted start's waypoints left where the coarse trajectory puts them", "designopt/solve/starts.py",
             "Q=projected(problem, q_d, solution.sample(t))", "Q=solution.sample(t)", ("tests/test_search.py",)),
    Mutation("a lifted start keeps the IK's changes of branch between neighbouring waypoints",
             "designopt/initial_guess.py", "if np.linalg.norm(r[k]) > tol or jumped:",
             "if np.linalg.norm(r[k]) > tol:", ("tests/test_search.py",)),
    Mutation("a joint's step between waypoints allowed twice what its velocity limit allows", "designopt/problem.py",
             "return self.toolpath.h[:, None] * self.velocity_limits[None, :]",
             "return 2 * self.toolpath.h[:, None] * self.velocity_limits[None, :]",
             ("tests/test_search.py", "tests/test_fk.py")),
    Mutation("a profile's IPOPT options never reach IPOPT (the production and quick presets' regularisation lost)",
             "designopt/solve/backends/ipopt.py",
             "return {**opts, **(WARM_OPTIONS if profile.warm else {}), **dict(profile.options)}",
             "return {**opts, **(WARM_OPTIONS if profile.warm else {})}", ("tests/test_search.py",)),
    Mutation("a smaller problem's exploration starts scale with its size, not its size squared",
             "designopt/solve/strategies/coarse_to_fine.py", "(largest / n) ** 2", "(largest / n)",
             ("tests/test_search.py",)),
    Mutation("the second round numbered after the configured starts, over a smaller problem's extra ones",
             "designopt/solve/search.py", "return start_index(number, self.seed) >= self.most_starts",
             "return start_index(number, self.seed) >= self.starts", ("tests/test_search.py",)),
    Mutation("a smaller problem screened on the configured waypoints", "designopt/solve/strategies/coarse_to_fine.py",
             "None if full else waypoints", "None if full else search.screen_waypoints", ("tests/test_search.py",)),
    Mutation("a smaller problem screens the configured count of candidates",
             "designopt/solve/strategies/coarse_to_fine.py", "round(search.screen * starts / search.starts)",
             "search.screen", ("tests/test_search.py",)),
    Mutation("screening ignores its iteration cap", "designopt/solve/strategies/coarse_to_fine.py",
             "search.screen_max_iter, mu_init=screen_mu,", "None, mu_init=screen_mu,"),
    Mutation("a rebranched start draws its first joints within +-pi/2 (the seeded starts' range)",
             "designopt/solve/starts.py", '"box")', '"perturb")'),
    Mutation("the second round left out of the screen's pool", "designopt/solve/strategies/coarse_to_fine.py",
             "explored = [first + more for first, more in", "explored = [first for first, more in"),
    Mutation("rebranched starts numbered over the seeded ones", "designopt/solve/strategies/coarse_to_fine.py",
             "search.seed, search.most_starts + k * m + j,", "search.seed, k * m + j,"),
    # degenerate designs (issue 12, cause 3)
    Mutation("a moving target's row held once", "designopt/transcriptions/degeneracy.py",
             "if i in POSITION_ROWS and tracked.any() and np.ptp(tp.points_W[tracked, i]) > 1e-12:",
             "if i in POSITION_ROWS and tracked.any() and np.ptp(tp.points_W[tracked, i]) > 1e12:"),
    Mutation("a gantry's own once-only rows count as degenerate", "designopt/transcriptions/degeneracy.py",
             "if len(q_independent_rows(candidate, jacobian=jacobian)) <= before:",
             "if len(q_independent_rows(candidate, jacobian=jacobian)) == 0:"),
    Mutation("a stalled solve is continued without holding its angles", "designopt/solve/strategies/continuation.py",
             "more = solve_guess(problem, task.transcription,", "more = solve_guess(task.problem, task.transcription,"),
    Mutation("the degenerate-design watch is not attached", "designopt/solve/strategies/steps.py",
             "return profile.observing(HoldDegenerate.observer), HoldDegenerate()",
             "return profile, HoldDegenerate()"),
    # issue 22: classes of bugs the suite used to miss
    Mutation("verify compares a reported error with itself", "designopt/verify.py",
             "if not np.isclose(check.max_axis_error, m[\"max_axis_error\"], rtol=1e-6, atol=1e-12):",
             "if not np.isclose(m[\"max_axis_error\"], m[\"max_axis_error\"], rtol=1e-6, atol=1e-12):",
             ("tests/test_bad_inputs.py",)),
    Mutation("verify compares the reported clearance with itself", "designopt/verify.py",
             "if reported is None or not np.isclose(value, reported, rtol=0.0, atol=1e-6):",
             "if reported is None or not np.isclose(reported, reported, rtol=0.0, atol=1e-6):",
             ("tests/test_clearance.py",)),
    Mutation("a config key read and ignored (the stand-off)", "designopt/problem.py",
             "keep_out_radius=cfg.placement.keep_out_radius,", "keep_out_radius=0.0,", ("tests/test_config_keys.py",)),
    Mutation("a search option of the config ignored (the seed)", "designopt/experiments/adapters.py",
             "return preset(s.preset, seed=s.seed,", "return preset(s.preset, seed=0,", ("tests/test_config_keys.py",)),
    Mutation("a search option of the config ignored (the starts)", "designopt/experiments/adapters.py",
             '(("starts", s.starts), ("spread", s.spread))', '(("spread", s.spread),)',
             ("tests/test_config_keys.py",)),
    Mutation("modular rounding reads the configured design, not the solved one", "designopt/experiments/modular.py",
             "assignment = nearest_modules(continuous.problem.chain, continuous.raw.q_d, catalogue)",
             "assignment = nearest_modules(continuous.problem.chain, continuous.problem.chain.design_values, "
             "catalogue)",
             ("tests/test_modular.py",)),
    Mutation("resume keeps a row whose solution file is gone", "designopt/results_io.py",
             "if key not in kept and r.get(\"solution_file\") and (self.path / r[\"solution_file\"]).is_file():",
             "if key not in kept and r.get(\"solution_file\"):",
             ("tests/test_resume.py::test_a_row_without_its_solution_file_is_dropped_on_resume",)),
    Mutation("URDF joints without limits take the other joint type's travel", "designopt/kinematics/urdf.py",
             "lo, hi = bounds.revolute if motion == \"rotate\" else bounds.prismatic",
             "lo, hi = bounds.prismatic if motion == \"rotate\" else bounds.revolute", ("tests/test_urdf.py",)),
    Mutation("a solution file reads back with default cost weights", "designopt/solution.py",
             "problem = _with_file_weights(problem, m.get(\"cost_weights\") or {})",
             "problem = _with_file_weights(problem, {})", ("tests/test_transcriptions.py",)),
    # issue 23: the production models
    Mutation("the clearance aggregate is an upper bound of the minimum", "designopt/clearance.py",
             "return m - ca.log(ca.sum1(ca.exp(-sharpness * (v - m)))) / sharpness",
             "return m + ca.log(ca.sum1(ca.exp(-sharpness * (v - m)))) / sharpness", PRODUCTION),
    Mutation("the floor taken in the workpiece frame", "designopt/clearance.py",
             "out.append(p[2] - cell.floor - r - cell.clearance)",
             "out.append((R.T @ (p - t))[2] - cell.floor - r - cell.clearance)", PRODUCTION),
    Mutation("the milling force loads the rapids", "designopt/toolpaths.py",
             "parts = milling_force_components(process, tp.tangents_W) * tp.is_tracked[None, :, None]",
             "parts = milling_force_components(process, tp.tangents_W)", PRODUCTION),
    Mutation("a plunge after a rapid starts untracked", "designopt/gcode.py",
             "tracked[-len(pts) - 1] = True", "tracked[-len(pts) - 1] = tracked[-len(pts) - 1]", PRODUCTION),
    Mutation("the last waypoint of a cut takes the rapid's direction", "designopt/gcode.py",
             "tangents[ends] = tangents[ends - 1]", "tangents[ends] = tangents[ends]", PRODUCTION),
    Mutation("a continuous joint takes the limits its file gives", "designopt/kinematics/urdf.py",
             "if uj.type != \"continuous\" and uj.limit is not None and uj.limit.lower is not None \\",
             "if uj.limit is not None and uj.limit.lower is not None \\", ("tests/test_urdf.py",)),
    Mutation("the view draws the block unrotated", "designopt/view.py",
             "traces.append(_mesh_trace(*_box_mesh(corners @ T_BW[:3, :3].T + T_BW[:3, 3]), \"#9aa0a6\", ",
             "traces.append(_mesh_trace(*_box_mesh(corners + T_BW[:3, 3]), \"#9aa0a6\", ", PRODUCTION),
    Mutation("the view's robot one joint short", "designopt/view.py",
             "for a, b, link in zip(points[:-1], points[1:], links, strict=True):",
             "for a, b, link in zip(points[:-2], points[1:-1], links[:-1], strict=True):", PRODUCTION),
    Mutation("a URDF robot exported under generic joint names", "designopt/export.py",
             "return [lim[\"name\"] for lim in data[\"joint_limits\"]]",
             "return [f\"joint{i + 1}\" for i in range(len(data[\"structure\"]))]",
             ("tests/test_export.py",)),
    Mutation("a URDF's velocity limits ignored on a timed program", "designopt/config.py",
             "if r.is_urdf and self._toolpath.time_unit == \"s\":", "if False:", ("tests/test_urdf.py",)),
    Mutation("a mimic joint on the chain taken as an independent joint", "designopt/kinematics/urdf.py",
             "if uj.type in MOVING_TYPES and uj.mimic is not None:", "if False:", ("tests/test_urdf.py",)),
    Mutation("a solution file's trajectory kind ignored", "designopt/solution.py",
             "np.array(data[\"v\"], dtype=float) if \"v\" in data else None, data.get(\"trajectory\"))",
             "np.array(data[\"v\"], dtype=float) if \"v\" in data else None, None)",
             ("tests/test_transcriptions.py",)),
    Mutation("the block Jacobian's rows scattered one waypoint late", "designopt/transcriptions/jacobian.py",
             "triplets = [(mu_index[:, rows].ravel(), y_index[:, cols].ravel())",
             "triplets = [(np.roll(mu_index, 1, axis=0)[:, rows].ravel(), y_index[:, cols].ravel())",
             ("tests/test_transcriptions.py", "tests/test_clearance.py")),
    Mutation("the rows outside the blocks left out of the Jacobian", "designopt/transcriptions/jacobian.py",
             "    values.append(rest_fn(X))\n", "    values.append(0 * rest_fn(X))\n",
             ("tests/test_transcriptions.py", "tests/test_clearance.py")),
    Mutation("the objective's block gradient scattered one waypoint late", "designopt/transcriptions/jacobian.py",
             "            rows.append(y_index.ravel())", "            rows.append(np.roll(y_index, 1, axis=0).ravel())",
             ("tests/test_transcriptions.py", "tests/test_clearance.py")),
    Mutation("the quadratic terms left out of the gradient", "designopt/transcriptions/nlp.py",
             "groups + gradient_groups(self.quadratic))", "groups)",
             ("tests/test_transcriptions.py", "tests/test_clearance.py")),
    Mutation("the constraints from blocks put in the wrong rows", "designopt/transcriptions/nlp.py",
             "np.zeros(0, int)])] = np.arange(n_g)", "np.zeros(0, int)])] = np.roll(np.arange(n_g), 1)",
             ("tests/test_collocation.py", "tests/test_transcriptions.py")),
    Mutation("the quadratic terms left out of the objective's value", "designopt/transcriptions/nlp.py",
             "    f, values, rows = total(quadratic, X), [], []", "    f, values, rows = ca.MX(0), [], []",
             ("tests/test_collocation.py", "tests/test_transcriptions.py")),
    Mutation("every solver builds the whole path's graph (the deferred entries built with the bounds)",
             "designopt/transcriptions/nlp.py", "        self.lbg, self.ubg = constraints.bounds()",
             "        _, self.lbg, self.ubg = constraints.stacked()", ("tests/test_transcriptions.py",)),
    Mutation("the rows outside the blocks taken in ascending order, not in the order asked for",
             "designopt/transcriptions/nlp.py", "[ca.DM([where[int(row)] for row in index])]",
             "[ca.DM(sorted(where[int(row)] for row in index))]", ("tests/test_transcriptions.py",)),
    Mutation("the walks' in-place residual returns its buffers, which the next call overwrites",
             "designopt/initial_guess.py", 'return [r.reshape(shape, order="F").copy() for r, shape in',
             'return [r.reshape(shape, order="F") for r, shape in', ("tests/test_collocation.py",)),
    Mutation("a tiered block loads at -O0 even when its -O1 library is in the cache",
             "designopt/transcriptions/compiled.py", 'if tiered and library_at(stem, "O1").exists():',
             'if False and library_at(stem, "O1").exists():', ("tests/test_tiered_compile.py",)),
    Mutation("a failed -O1 build releases its lock, so every later solve starts it again",
             "designopt/transcriptions/compiled.py", 'f"rm -f {q(str(lock))}; rm -f {out} {c}")',
             'f"true; rm -f {q(str(lock))} {out} {c}")', ("tests/test_tiered_compile.py",)),
    Mutation("the KKT solver reports no negative eigenvalues", "designopt/solve/backends/ldl/ma27.c",
             "INFO[14] = pos == STOPPED ? limit + 1 : n - pos;", "INFO[14] = pos == STOPPED ? limit + 1 : 0;",
             ("tests/test_ldl.py",)),
    Mutation("the KKT solver reports a stopped factorisation with the inertia IPOPT accepted",
             "designopt/solve/backends/ldl/ma27.c",
             "INFO[14] = pos == STOPPED ? limit + 1 : n - pos;", "INFO[14] = pos == STOPPED ? limit : n - pos;",
             ("tests/test_ldl.py",)),
    Mutation("the KKT solver solves with a stopped factorisation as it is", "designopt/solve/backends/ldl/ma27.c",
             "if (IW[LAST] == STOPPED) {", "if (0) {", ("tests/test_ldl.py",)),
    Mutation("the KKT solver stops before a vanished row's zero pivot", "designopt/solve/backends/ldl/ma27.c",
             "if (!bwork[j]) limit = -1;", "if (!bwork[j]) limit = limit;", ("tests/test_ldl.py",)),
    Mutation("the KKT solver never stops early", "designopt/solve/backends/ldl/ma27.c",
             "int limit = IW[ACCEPTED], j, p;", "int limit = -1, j, p;", ("tests/test_ldl.py",)),
    Mutation("the observers read the iterate's x as its constraint values", "designopt/solve/backends/ipopt.py",
             "g = np.frombuffer(arg[2], float) if arg[2] is not None else np.zeros(0)",
             "g = np.frombuffer(arg[0], float)[: len(self.lbg)]", ("tests/test_search.py",)),
    Mutation("the KKT solver eliminates a zero-diagonal row where AMD put it", "designopt/solve/backends/ldl/ma27.c",
             "if (partner < 0) { waiting[u] = 1; continue; }", "if (0) { waiting[u] = 1; continue; }",
             ("tests/test_ldl.py",)),
    Mutation("the KKT solver lets a constraint row follow any eliminated neighbour, not its own (as before 2026-11-28)",
             "designopt/solve/backends/ldl/ma27.c", "if (n >= MATCHED_FROM) {", "if (0) {", ("tests/test_ldl.py",)),
    Mutation("the KKT solver orders a regularised constraint row (-1e-8) as a pivot",
             "designopt/solve/backends/ldl/ma27.c",
             "zero[j] = fabs(diag[j]) <= WEAK;", "zero[j] = diag[j] == 0.0;", ("tests/test_ldl.py",)),
    Mutation("the KKT solver keeps the last of duplicate triplets instead of their sum",
             "designopt/solve/backends/ldl/ma27.c", "for (k = 0; k < nz; k++) Ax[map[k]] += A[k];",
             "for (k = 0; k < nz; k++) Ax[map[k]] = A[k];", ("tests/test_ldl.py",)),
    Mutation("the KKT solver trusts a workspace whose header is this size's (as before 2026-11-27)",
             "designopt/solve/backends/ldl/ma27.c", "if (!(record && built_in(record, IW, *LIW))) {",
             "if (!(record && (IW[0] == nnzA || built_in(record, IW, *LIW)))) {", ("tests/test_ldl.py",)),
    Mutation("the exploration factorised by the profile's linear solver, not the search's",
             "designopt/solve/strategies/coarse_to_fine.py", ".solved_by(search.explore_linear_solver)", "",
             ("tests/test_search.py",)),
    Mutation("the screen factorised by the profile's linear solver, not the search's",
             "designopt/solve/strategies/coarse_to_fine.py", "per_form=search.screen_per_form, linear_solver=solver)]",
             "per_form=search.screen_per_form)]",
             ("tests/test_search.py",)),
    Mutation("the screen by its first linear solver only (a candidate's other passes dropped)",
             "designopt/solve/search.py", "for solver in self.screen_linear_solver]",
             "for solver in self.screen_linear_solver[:1]]", ("tests/test_search.py",)),
    Mutation("the screen's later passes for every arm (small_arm_screens_once ignored)", "designopt/solve/search.py",
             "return passes[:1] if self.small_arm_screens_once and small_arm(moving_joints) else passes",
             "return passes", ("tests/test_search.py",)),
    Mutation("the screen's later passes withheld from a 5-joint arm too", "designopt/solve/search.py",
             "self.small_arm_screens_once and small_arm(moving_joints)",
             "self.small_arm_screens_once and moving_joints <= SMALL_ARM", ("tests/test_search.py",)),
    Mutation("the plan screens every problem by every pass (passes_for not asked)",
             "designopt/solve/strategies/coarse_to_fine.py",
             "                 if i < len(search.passes_for(jobs[k].problem.chain.n_moving))\n", "",
             ("tests/test_search.py",)),
    Mutation("every arm's starts perturbed by `perturbation` (small_arm_perturbation ignored)",
             "designopt/solve/strategies/steps.py", "search.perturbation_for(job.problem.chain.n_moving)",
             "search.perturbation", ("tests/test_search.py",)),
    Mutation("a 5-joint arm's starts perturbed as a small arm's", "designopt/solve/search.py",
             "small_arm_perturbation is not None and small_arm(moving_joints):",
             "small_arm_perturbation is not None and moving_joints <= SMALL_ARM:", ("tests/test_search.py",)),
    Mutation("a 5-joint arm small", "designopt/solve/search.py", "    return moving_joints < SMALL_ARM",
             "    return moving_joints <= SMALL_ARM", ("tests/test_search.py",)),
    Mutation("a lifted stage's own linear solver ignored", "designopt/solve/strategies/coarse_to_fine.py",
             ".capped(max_iter).solved_by(linear_solver)", ".capped(max_iter)", ("tests/test_search.py",)),
    Mutation("a long program's Hessian perturbation left unbounded under MUMPS", "designopt/solve/backends/ipopt.py",
             'opts["ipopt.max_hessian_perturbation"] = 1e8', "pass", ("tests/test_ldl.py",)),
    Mutation("a profile's linear solver ignored (every solve by MUMPS)", "designopt/solve/backends/ipopt.py",
             "or profile.linear_solver", 'or "mumps"', ("tests/test_ldl.py",)),
    Mutation("compile auto never compiles a long path's blocks at O1", "designopt/transcriptions/compiled.py",
             '    return "O1" if points >= AUTO_O1_FROM else "tiered"', '    return "tiered"',
             ("tests/test_collocation.py",)),
    Mutation("the quadratic terms' Hessian values scattered entry by entry, not point by point",
             "designopt/transcriptions/quadratic.py", "v.reshape(len(a), n_points).T.ravel()",
             "v.reshape(n_points, len(a)).ravel()", ("tests/test_quadratic.py", "tests/test_transcriptions.py")),
    Mutation("the reported design cost weights the first waypoint twice", "designopt/costs.py",
             "    return float(np.sum(np.asarray(weights) * np.asarray(deformations)))",
             "    return float(np.sum(np.asarray(weights) * np.asarray(deformations)) + weights[0] * deformations[0])",
             ("tests/test_regression.py",)),
    Mutation("the starts' IK Jacobian scaled (the walk still converges, slower and elsewhere)",
             "designopt/initial_guess.py", "[r, ca.jacobian(r, q), ca.jacobian(r, q_d)]",
             "[r, 2 * ca.jacobian(r, q), ca.jacobian(r, q_d)]", ("tests/test_collocation.py",)),
    Mutation("the box start sized by the path's whole extent, not half of it",
             "designopt/initial_guess.py", "b = 0.5 * float(np.ptp(", "b = 1.0 * float(np.ptp(",
             ("tests/test_collocation.py",)),
    Mutation("the home walk resolves the arm's self-motion by minimum-norm steps, as ik does (not repeatable)",
             "designopt/initial_guess.py", "HOME_PULL = 0.5 ", "HOME_PULL = 0.0 ", ("tests/test_search.py",)),
    Mutation("the walk's waypoints left where the pull towards home stopped, off the path",
             "designopt/initial_guess.py", "POLISH = 10 ", "POLISH = 0 ", ("tests/test_search.py",)),
    Mutation("a rounded assignment whose re-solve does not track ends the modular run without a search",
             "designopt/experiments/modular.py", "    if continuous is not None and neighbourhood_budget:",
             "    if modular is not None and neighbourhood_budget:", ("tests/test_modular.py",)),
    Mutation("a mixed spread draws every start from the box",
             "designopt/initial_guess.py", 'spread = "box" if index % 2 else "perturb"', 'spread = "box"',
             ("tests/test_collocation.py",)),
    Mutation("a stage's starts grouped across problems (a unit mixes problems: one NLP built for another's starts)",
             "designopt/solve/tasks.py", "groups.setdefault((id(t.problem), t.transcription, t.profile), [])",
             "groups.setdefault((t.transcription, t.profile), [])", ("tests/test_search.py",)),
    Mutation("one problem's starts dispatched in pieces (a worker idles while another runs a piece's tail)",
             "designopt/solve/tasks.py", "    if len(groups) == 1:\n", "    if False:\n", ("tests/test_search.py",)),
    Mutation("the modular refinement searches each assignment with half its starts",
             "designopt/experiments/modular.py",
             'init="reach", starts=REFINE_STARTS, rebranch=0,', 'init="reach", starts=REFINE_STARTS // 2, rebranch=0,',
             ("tests/test_modular.py",)),
    Mutation("the modular neighbourhood search refines its worst screened assignments",
             "designopt/modular.py", "for a, c in sorted(screened, key=lambda pair: pair[1]):",
             "for a, c in sorted(screened, key=lambda pair: -pair[1]):", ("tests/test_modular.py",)),
    Mutation("the modular refinement solves copies of one screening optimum",
             "designopt/modular.py", "if not any(abs(c - kept) <= rel_tol * abs(kept) for _, kept in picked):",
             "if True:", ("tests/test_modular.py",)),
    Mutation("the modular local searches run from their starts in the given order, not cheapest first",
             "designopt/modular.py",
             "starts = [starts[i] for i in sorted(range(len(starts)), key=lambda i: (values[i], i))]",
             "starts = starts", ("tests/test_modular.py",)),
    Mutation("the modular search's sample drawn at random per link, not spread over the catalogue",
             "designopt/modular.py",
             "columns = [rng.permutation(np.resize(np.arange(n_modules), count)) for _ in range(n_links)]",
             "columns = [rng.integers(0, n_modules, count) for _ in range(n_links)]", ("tests/test_modular.py",)),
    Mutation("a twist of pi left out of the lift's sign (d after a reversed z lifts instead of lowering)",
             "designopt/modular.py", "sign = sign if math.cos(alpha) > 0 else -sign", "sign = sign",
             ("tests/test_modular.py",)),
    Mutation("every link's d taken for a lift, past the first twisted link too",
             "designopt/modular.py", "lifting = abs(math.sin(alpha)) <= TWIST_TOL", "lifting = True",
             ("tests/test_modular.py",)),
    Mutation("modules of another twist counted as the same robot",
             "designopt/modular.py", "if aj == a and math.cos(alj - alpha) > 1 - TWIST_TOL])", "if aj == a])",
             ("tests/test_modular.py",)),
    Mutation("the modular search screens every assignment of one robot",
             "designopt/experiments/modular.py",
             "absorbed = z.role is Role.DESIGN and lifts_absorbed(catalogue, (z.lower, z.upper))", "absorbed = False",
             ("tests/test_modular.py",)),
    Mutation("a solution moved to another robot's lift keeps its own placement z",
             "designopt/experiments/modular.py", "q_d[index] = z_member", "q_d[index] = q_d[index]",
             ("tests/test_modular.py",)),
    Mutation("a solve with held joints lets CasADi's false 'overconstrained' warning through to the terminal",
             "designopt/solve/backends/ipopt.py",
             "self._casadi_warns = nlp.n_equalities + int(np.sum(nlp.lbx == nlp.ubx)) > nlp.n_variables",
             "self._casadi_warns = False", ("tests/test_sweep.py",)),
    Mutation("the compile cache keyed by a function's name, not its graph (another function's library reused)",
             "designopt/transcriptions/compiled.py", "compiled_as(fn.name(), fn.serialize(), lambda: fn, mode, used)",
             "compiled_as(fn.name(), fn.name(), lambda: fn, mode, used)", ("tests/test_collocation.py",)),
    Mutation("a Hessian block cached by its derivation only, not the terms it is derived from",
             "designopt/transcriptions/hessian.py", 'return f"{terms.serialize()}|{inspect.getsource(derivation)}|',
             'return f"{terms.name()}|{inspect.getsource(derivation)}|', ("tests/test_collocation.py",)),
    Mutation("a block found in the compile cache derived (and compiled) again",
             "designopt/transcriptions/compiled.py", "    if not library.exists():\n        fn = derive()",
             "    if True:\n        fn = derive()", ("tests/test_collocation.py",)),
    Mutation("nlpsol builds the reverse derivative of the whole NLP at set-up (most of a cell's build)",
             "designopt/solve/backends/ipopt.py", '"ipopt.acceptable_iter": 10, "no_nlp_grad": True}',
             '"ipopt.acceptable_iter": 10}', ("tests/test_transcriptions.py",)),
    Mutation("a grown start's inserted link keeps its configured twist (not an identity transform)",
             "designopt/solve/starts.py", "for b in problem.chain.dh[where]}", "for b in problem.chain.dh[where][:3]}",
             ("tests/test_sweep.py",)),
    Mutation("a grown start's links after the inserted one keep their numbers",
             "designopt/solve/starts.py", "moved = problem.chain.dh[i + (i >= where)]", "moved = problem.chain.dh[i]",
             ("tests/test_sweep.py",)),
    Mutation("a pruned start keeps the longer structure's placement (the still link not carried into it)",
             "designopt/solve/starts.py", "place = inverse(first) @ np.asarray(", "place = np.asarray(",
             ("tests/test_sweep.py",)),
    Mutation("a pruned start's links keep their numbers (the still link's parameters taken for link 1)",
             "designopt/solve/starts.py", "moved = long_.dh[i + 1]", "moved = long_.dh[i]", ("tests/test_sweep.py",)),
    Mutation("a structure is pruned from a longer one whose first joint moves",
             "designopt/solve/strategies/neighbours.py", "return bool(np.ptp(first) < STILL)", "return True",
             ("tests/test_sweep.py",)),
    Mutation("the neighbour step's second pass starts from every neighbour, lowered by the first or not",
             "designopt/solve/strategies/neighbours.py", "if lowered is not None and (case, other) not in lowered:",
             "if False:", ("tests/test_sweep.py",)),
    Mutation("the neighbour step makes one pass", "designopt/solve/strategies/neighbours.py", "PASSES = 2",
             "PASSES = 1", ("tests/test_sweep.py",)),
    Mutation("the neighbour step's cold same-length starts run to the preset's cap",
             "designopt/solve/strategies/neighbours.py",
             "cold = solve_setup(job, search, search.profile.capped(SAME_LENGTH_CAP))",
             "cold = solve_setup(job, search)", ("tests/test_sweep.py",)),
    Mutation("every neighbour start capped as the same-length ones",
             "designopt/solve/strategies/neighbours.py",
             "warm = solve_setup(job, search, search.profile.warmed())",
             "warm = solve_setup(job, search, search.profile.warmed().capped(SAME_LENGTH_CAP))",
             ("tests/test_sweep.py",)),
    Mutation("a structure takes a start from every neighbour, cheaper or not",
             "designopt/solve/strategies/neighbours.py",
             "if theirs is None or (own is not None and theirs.metrics.design_cost >= own.metrics.design_cost):",
             "if theirs is None:", ("tests/test_sweep.py",)),
    Mutation("a neighbour start is not held to its structure's best",
             "designopt/solve/strategies/neighbours.py",
             "bound = Bound(BOUND_FACTOR * own.raw.objective, BOUND_AFTER) if own is not None else None",
             "bound = None",
             ("tests/test_sweep.py",)),
    Mutation("a bound stops a solve before its iterations are up",
             "designopt/solve/observers.py", "self.bound is not None and self.iterations >= self.bound.after",
             "self.bound is not None", ("tests/test_search.py",)),
    Mutation("a bound stops a solve at an infeasible iterate",
             "designopt/solve/observers.py",
             "and iterate.violation <= self.tol and iterate.objective > self.bound.objective",
             "and iterate.objective > self.bound.objective", ("tests/test_search.py",)),
    Mutation("a stalled violation never stops a solve",
             "designopt/solve/observers.py", "            self.run += iterations",
             "            self.run = 0", ("tests/test_search.py",)),
    Mutation("an iterate on the path counts toward a stall",
             "designopt/solve/observers.py",
             "if v <= self.tol or v < self.factor * self.anchor:", "if v < self.factor * self.anchor:",
             ("tests/test_search.py",)),
    Mutation("a solve on its way back to the path after a step away counts as stalled",
             "designopt/solve/observers.py",
             " and v >= self.factor * max(w for _, w in self.window)", "", ("tests/test_search.py",)),
    Mutation("multistart's cold starts are not watched for a stalled violation",
             "designopt/solve/strategies/multistart.py",
             "watched = search.profile.observing(STALLED) if", "watched = None if", ("tests/test_search.py",)),
    Mutation("the backend does not hand a solve's bound to its observers",
             "designopt/solve/backends/ipopt.py", "o.reset(bound)", "o.reset()", ("tests/test_search.py",)),
]


def project_files() -> list[str]:
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    return [f for f in out.splitlines() if (ROOT / f).is_file()]


def copy_project(target: Path) -> None:
    for rel in project_files():
        dest = target / rel
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / rel, dest)


def run_tests(tree: Path, cache: Path, tests: list[str]) -> tuple[bool, str]:
    env = {**os.environ, "PYTHONPATH": str(tree), "DESIGNOPT_CACHE": str(cache), "MPLBACKEND": "Agg"}
    # Make sure the copy, not the installed working tree, is what the tests import.
    probe = subprocess.run([sys.executable, "-c", "import designopt, sys; print(designopt.__file__)"], cwd=tree,
                           env=env, capture_output=True, text=True)
    if not probe.stdout.strip().startswith(str(tree)):
        raise RuntimeError(f"the copy is not imported: {probe.stdout.strip() or probe.stderr.strip()}")
    proc = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *tests], cwd=tree,
                          env=env, capture_output=True, text=True)
    lines = [line for line in proc.stdout.splitlines() if line.startswith("FAILED") or " passed" in line
             or " failed" in line or line.startswith("ERROR")]
    return proc.returncode == 0, "; ".join(lines[-2:])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="run only mutations whose name contains this text")
    parser.add_argument("--tests", nargs="+", default=TESTS, help="test files to run (default: the fast ones "
                                                                  "that guard the objective)")
    args = parser.parse_args()
    chosen = [m for m in MUTATIONS if not args.only or args.only in m.name]
    with tempfile.TemporaryDirectory(prefix="designopt-mutate-") as tmp:
        tmp = Path(tmp)
        cache, clean = tmp / "cache", tmp / "clean"
        copy_project(clean)
        start = time.perf_counter()
        targeted = [t for m in chosen if m.tests and args.tests == TESTS for t in m.tests]
        ok, summary = run_tests(clean, cache, list(dict.fromkeys([*args.tests, *targeted])))
        print(f"baseline (no mutation): {'green' if ok else 'RED'} in {time.perf_counter() - start:.0f} s: {summary}")
        if not ok:
            print("the unmutated suite fails: fix it before judging mutations")
            return 2
        survived = 0
        for i, m in enumerate(chosen, 1):
            tree = tmp / f"m{i}"
            shutil.copytree(clean, tree)
            path = tree / m.file
            text = path.read_text()
            if text.count(m.old) != 1:
                print(f"[{i:2d}] NOT APPLIED  {m.name}: the line to mutate is not in {m.file} exactly once")
                survived += 1
                continue
            path.write_text(text.replace(m.old, m.new))
            start = time.perf_counter()
            passed, summary = run_tests(tree, cache, list(m.tests) if m.tests and args.tests == TESTS else args.tests)
            survived += passed
            verdict = "SURVIVED" if passed else "caught  "
            print(f"[{i:2d}] {verdict} {m.name} ({time.perf_counter() - start:.0f} s): {summary}", flush=True)
            shutil.rmtree(tree)
        print(f"{len(chosen) - survived} of {len(chosen)} mutations caught, {survived} survived")
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
