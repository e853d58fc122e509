"""IPOPT through CasADi's ``nlpsol``: exact Hessian, constraint Jacobian and gradient (from the transcription's
per-waypoint blocks when it has them: `NLP.derivatives`), the KKT systems factorised by the profile's linear solver
(MUMPS, METIS ordering from ``METIS_FROM`` variables; or the LDLᵀ of `designopt.solve.backends.ldl`), quiet.

A profile's cap and time limit become ``max_iter`` and ``max_wall_time``; a warm profile starts the barrier at
1e-4 with bound push and fraction 1e-6 instead of 0.1 and 1e-2: with IPOPT's defaults a solve started at the best
design known for the main job leaves it (3.80e-4 -> 7.66e-4), because many of its lengths sit a millimetre above
their bound 0 and a push of 1 cm changes the problem. Observers (`designopt.solve.observers`) see every
``OBSERVE_EVERY``-th iteration through one CasADi callback.
"""

from __future__ import annotations

import contextlib
import copy
import io
import os
import sys
import time

import casadi as ca
import numpy as np

import designopt.solve.backends.ldl as ldl
from designopt.solve.backends.base import Outcome
from designopt.solve.observers import Bound, Iterate, make_observers
from designopt.solve.profile import LINEAR_SOLVERS
from designopt.transcriptions.nlp import NLP

# no_nlp_grad: nlpsol otherwise builds, at set-up, the reverse derivative of the whole NLP ("nlp_grad"), which it
# needs only to compute lam_p (our NLPs have no parameters) or multipliers IPOPT returns itself: 1.8 s of the pocket
# cell's warm build, 0.16 s of the main job's (benchmarks/speed_table.py --build).
BASE_OPTIONS = {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False, "ipopt.tol": 1e-8,
                "ipopt.acceptable_tol": 1e-6, "ipopt.acceptable_iter": 10, "no_nlp_grad": True}
WARM_OPTIONS = {"ipopt.mu_init": 1e-4, "ipopt.bound_push": 1e-6, "ipopt.bound_frac": 1e-6}
# IPOPT stops these before its first iteration, and the iteration count it reports is then stale.
PRE_ITERATION_STATUSES = {"Not_Enough_Degrees_Of_Freedom", "Invalid_Problem_Definition", "Invalid_Option"}
# Iterations between two calls of the observers: each call is a Python callback (until 2026-11-28 one that copied
# every output of the solver); calling it every iteration cost 10 % of an exploration solve (1.70 -> 1.54 ms/iter,
# 24 starts, benchmarks/speed_table.py --only "exploration (10 wp)"), and a watch with a patience of 30 iterations
# loses nothing by looking every 5th.
OBSERVE_EVERY = 5


# MUMPS orders the KKT matrix with METIS from this many variables on (its automatic choice otherwise).
# benchmarks/speed_table.py, 12 starts, ms/iter METIS / automatic: 0.54 on a sweep structure (40 waypoints, ~500
# variables), 0.90 on the main job (80, 984), 1.02 on the pocket cell, but 1.15 on the exploration problem
# (10, ~150 variables; 24 starts).
METIS_FROM = 400
# From this many variables on, IPOPT's Hessian perturbation is held below 1e8 (its own limit is 1e20). On a long
# program (benchmarks/configs/aluminum_button.yaml, 21,744 variables, start 3) an iteration that had lost its way
# asked for 1e10, and MUMPS then sat in one factorisation for over 6 minutes at 6 GB -- past the start's time
# limit, which IPOPT checks between iterations only; with the bound that start converges in 133 iterations, 34 s.
# Smaller problems are left as they were: on the paper's continuous comparison (984 variables) the bound changed 10
# of 72 solves (docs/decisions.md, 2026-11-28).
BOUNDED_PERTURBATION_FROM = 5000


def linear_solver(profile) -> str:
    """The linear solver of a profile's solves: the profile's ``linear_solver``, unless the environment's
    ``DESIGNOPT_LINEAR_SOLVER`` names one for every solve of the process (to compare the two; docs/benchmarks.md);
    "ldl" only when its library can be built, else "mumps"."""
    name = os.environ.get("DESIGNOPT_LINEAR_SOLVER", "").strip().lower() or profile.linear_solver
    if name not in LINEAR_SOLVERS:
        raise ValueError(f"DESIGNOPT_LINEAR_SOLVER must be one of {LINEAR_SOLVERS}, got {name!r}")
    return "ldl" if name == "ldl" and ldl.library() is not None else "mumps"


def options(profile, n_variables: int = 0) -> dict:
    """nlpsol options of a profile for an NLP of ``n_variables`` (without the derivatives and the observers)."""
    opts = {**BASE_OPTIONS, "ipopt.max_iter": int(profile.max_iter), "ipopt.max_wall_time": float(profile.time_limit)}
    if linear_solver(profile) == "ldl":
        opts |= {"ipopt.linear_solver": "ma27", "ipopt.hsllib": str(ldl.library())}
    else:  # MUMPS
        if n_variables >= METIS_FROM:
            opts["ipopt.mumps_pivot_order"] = 5
        if n_variables >= BOUNDED_PERTURBATION_FROM:
            opts["ipopt.max_hessian_perturbation"] = 1e8
    if profile.objective_scale != 1.0:
        opts["ipopt.obj_scaling_factor"] = float(profile.objective_scale)
    return {**opts, **(WARM_OPTIONS if profile.warm else {}), **dict(profile.options)}


class Ipopt:
    name = "ipopt"

    def prepare(self, nlp: NLP, profile) -> PreparedIpopt:
        return PreparedIpopt(nlp, profile)


class _Observe(ca.Callback):
    """IPOPT's iteration callback: hands every observer the iterate (design joints x[:n_design], objective, largest
    constraint violation); stops when one says so."""

    def __init__(self, observers, n_x: int, n_g: int, n_design: int, lbg: np.ndarray, ubg: np.ndarray):
        ca.Callback.__init__(self)
        self.observers, self.n_x, self.n_g, self.n_design = observers, n_x, n_g, n_design
        self.lbg, self.ubg = lbg, ubg
        self.construct("observe", {})

    def get_n_in(self):
        return ca.nlpsol_n_out()

    def get_n_out(self):
        return 1

    def get_name_in(self, i):
        return ca.nlpsol_out(i)

    def get_name_out(self, i):
        return "ret"

    def get_sparsity_in(self, i):
        n = {"x": self.n_x, "lam_x": self.n_x, "g": self.n_g, "lam_g": self.n_g, "f": 1}.get(ca.nlpsol_out(i), 0)
        return ca.Sparsity.dense(n, 1)

    def has_eval_buffer(self):
        return True

    def eval_buffer(self, arg, res):
        """The outputs as views of the solver's memory (a Callback's ``eval`` gets each copied into a DM first):
        0.104 -> 0.059 ms a call on the exploration problem (CasADi's timer of the callback, 32 starts)."""
        g = np.frombuffer(arg[2], float) if arg[2] is not None else np.zeros(0)
        violation = float(np.max(np.maximum(self.lbg - g, g - self.ubg), initial=0.0))
        x = np.frombuffer(arg[0], float)
        iterate = Iterate(x[: self.n_design].copy(), float(np.frombuffer(arg[1], float)[0]), violation)
        stop = [o.observe(iterate, OBSERVE_EVERY) for o in self.observers]
        np.frombuffer(res[0], float)[0] = 1.0 if any(stop) else 0.0
        return 0


class PreparedIpopt:
    """One NLP under one profile: the nlpsol, ready to solve from any x0."""

    def __init__(self, nlp: NLP, profile):
        t0 = time.perf_counter()
        self.nlp = nlp
        self.observers = make_observers(profile.observers, nlp.problem)
        self._callback = None  # CasADi keeps no Python reference: the callback must live as long as the solver
        self.lbx, self.ubx = nlp.lbx, nlp.ubx
        self._casadi_warns = False
        self.solver = None
        if nlp.n_equalities > nlp.n_variables:  # never solved (`solve`): nothing to compile or build
            self.prepare_time_s = time.perf_counter() - t0
            return
        opts = options(profile, nlp.n_variables)
        problem, derivatives = nlp.derivatives(profile.compile)
        opts.update(derivatives)
        if self.observers:
            self._callback = _Observe(self.observers, nlp.n_variables, nlp.n_constraints, nlp.n_design,
                                      np.asarray(nlp.lbg, float), np.asarray(nlp.ubg, float))
            opts["iteration_callback"] = self._callback
            opts["iteration_callback_step"] = OBSERVE_EVERY
        self.solver = ca.nlpsol(nlp.name, "ipopt", problem, opts)
        # CasADi counts fixed variables (held design joints, lbx == ubx) as equalities and warns on the terminal at
        # every solve when that count exceeds the variables, although IPOPT removes them and solves (a held planar
        # arm's tracking rows are redundant, not too many: the sweep's held RR, RP, PR on 10 waypoints converge).
        self._casadi_warns = nlp.n_equalities + int(np.sum(nlp.lbx == nlp.ubx)) > nlp.n_variables
        self.prepare_time_s = time.perf_counter() - t0

    def bounded(self, lower: np.ndarray, upper: np.ndarray) -> PreparedIpopt:
        """This solver with the design joints (x[:n_design]) between ``lower`` and ``upper`` instead of the NLP's
        own bounds: the same nlpsol and observers, so that problems which differ only there share one build
        (`designopt.transcriptions.degeneracy.shared_shape`). Which joints are fixed (lower == upper) must be
        the NLP's own."""
        lower, upper = np.asarray(lower, float), np.asarray(upper, float)
        n = self.nlp.n_design
        if not np.array_equal(lower == upper, self.lbx[:n] == self.ubx[:n]):
            raise ValueError("a bounded solver must fix the design joints its NLP fixes, and only those")
        view = copy.copy(self)
        view.lbx, view.ubx = np.r_[lower, self.lbx[n:]], np.r_[upper, self.ubx[n:]]
        return view

    def solve(self, x0: np.ndarray, bound: Bound | None = None) -> Outcome:
        """Solve from x0 (clipped into the bounds); ``bound``: what the observers may hold the solve to
        (`designopt.solve.observers.AboveBound`). A solve that fails is an outcome with its status."""
        nlp = self.nlp
        x0 = np.clip(np.asarray(x0, float), self.lbx, self.ubx)
        for o in self.observers:
            o.reset(bound)
        if nlp.n_equalities > nlp.n_variables:
            # IPOPT would stop here before its first iteration, but only after CasADi printed a warning on the
            # terminal, once per solve (a sweep's one-joint structures: hundreds of lines).
            return Outcome(x0, float("nan"), "Not_Enough_Degrees_Of_Freedom", False, 0, 0.0)
        t0 = time.perf_counter()
        # CasADi writes its warnings through Python's stderr: caught only where it would warn, the rest passed on
        quiet = contextlib.redirect_stderr(io.StringIO()) if self._casadi_warns else contextlib.nullcontext()
        with quiet as said:
            sol = self.solver(x0=x0, lbx=self.lbx, ubx=self.ubx, lbg=nlp.lbg, ubg=nlp.ubg)
        if said is not None:
            sys.stderr.write("".join(line for line in said.getvalue().splitlines(keepends=True)
                                     if "NLP is overconstrained" not in line))
        wall = time.perf_counter() - t0
        stats = self.solver.stats()
        status = str(stats.get("return_status", "unknown"))
        status = next((o.status for o in self.observers if o.stopped), status)
        iterations = 0 if status in PRE_ITERATION_STATUSES else int(stats.get("iter_count", -1))
        return Outcome(np.asarray(sol["x"]).ravel(), float(sol["f"]), status, bool(stats.get("success", False)),
                       iterations, wall)
