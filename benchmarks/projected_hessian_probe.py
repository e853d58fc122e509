"""Probe for issue 24: does a positive semidefinite Hessian, block by block, remove the inertia corrections and
keep the solves?

The Lagrangian's Hessian is a sum of per-waypoint blocks (`designopt.transcriptions.hessian`) plus a constant
positive semidefinite part. Replacing each block B_k = V diag(l) V^T by V diag(max(l, 0)) V^T (``clamp``) or
V diag(|l|) V^T (``abs``: "projected Newton") makes the whole Hessian positive semidefinite, so that IPOPT never
needs an inertia correction -- at the price of the exact curvature. This script swaps the assembled Hessian for
a Python callback that does so (``none``: the same blocks unprojected, to show the callback changes nothing) and
solves the same seeded starts, printing iterations, the share of inertia-corrected iterations, how many converge
and the costs reached. Per-iteration times are the callback's (numpy), not a lever's. A probe: nothing in
designopt uses it.

    .venv/bin/python benchmarks/projected_hessian_probe.py configs/milling.yaml --waypoints 10 --explore --starts 8
    .venv/bin/python benchmarks/projected_hessian_probe.py configs/milling.yaml --starts 8 --mode abs
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import tempfile
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import casadi as ca  # noqa: E402
import numpy as np  # noqa: E402
from iteration_split import logged_solve  # noqa: E402
from speed_table import setup  # noqa: E402

import designopt.transcriptions.nlp as nlp_module  # noqa: E402
from designopt.solve import local  # noqa: E402
from designopt.transcriptions.hessian import ccs_sparsity, per_point  # noqa: E402

MODES = ("none", "clamp", "abs")


class ProjectedHessian(ca.Callback):
    """hess_lag(x, p, lam_f, lam_g) as `assemble_hessian` builds it, each block projected per ``mode``."""

    def __init__(self, mode: str, n_x: int, n_g: int, groups, constant):
        ca.Callback.__init__(self)
        self.mode, self.n_x, self.n_g = mode, n_x, n_g
        rows, cols, self.shapes = [], [], []
        for _, y_index, _, _ in groups:
            a, b = np.triu_indices(y_index.shape[1])
            i, j = y_index[:, a], y_index[:, b]
            rows.append(np.minimum(i, j).ravel())
            cols.append(np.maximum(i, j).ravel())
            self.shapes.append((y_index.shape[0], y_index.shape[1], a, b))
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        c_rows, c_cols, c_values = (np.asarray(v) for v in constant)
        block_keys, const_keys = cols * n_x + rows, c_cols.astype(int) * n_x + c_rows.astype(int)
        keys = np.unique(np.concatenate([block_keys, const_keys]))
        self.sp = ccs_sparsity(n_x, n_x, keys % n_x, keys // n_x)
        self.block_nz = np.searchsorted(keys, block_keys)
        self.const_values = np.zeros(self.sp.nnz())
        np.add.at(self.const_values, np.searchsorted(keys, const_keys), c_values)
        x, lam_f, lam_g = ca.MX.sym("x", n_x), ca.MX.sym("lam_f"), ca.MX.sym("lam_g", n_g)
        values = [ca.vec(block.map(y.shape[0])(per_point(x, y), lam_f, per_point(lam_g, mu), *inputs))
                  for block, y, inputs, mu in groups]
        self.values = ca.Function("block_values", [x, lam_f, lam_g], [ca.vertcat(*values)])
        self.construct("hess_lag", {})

    def get_n_in(self):
        return 4

    def get_n_out(self):
        return 1

    def get_name_in(self, i):
        return ("x", "p", "lam_f", "lam_g")[i]

    def get_name_out(self, i):
        return "hess"

    def get_sparsity_in(self, i):
        return (ca.Sparsity.dense(self.n_x, 1), ca.Sparsity(0, 1), ca.Sparsity.dense(1, 1),
                ca.Sparsity.dense(self.n_g, 1))[i]

    def get_sparsity_out(self, i):
        return self.sp

    def eval(self, arg):
        v = np.asarray(self.values(arg[0], arg[2], arg[3])).ravel()
        out, offset = [], 0
        for N, n, a, b in self.shapes:
            upper = v[offset:offset + N * len(a)].reshape(N, len(a))  # map stacks each point's entries
            offset += N * len(a)
            H = np.zeros((N, n, n))
            H[:, a, b] = upper
            H[:, b, a] = upper
            if self.mode != "none":
                lam, V = np.linalg.eigh(H)
                lam = np.maximum(lam, 0.0) if self.mode == "clamp" else np.abs(lam)
                H = np.einsum("kij,kj,klj->kil", V, lam, V)
            out.append(H[:, a, b].ravel())
        nz = np.zeros(self.sp.nnz())
        np.add.at(nz, self.block_nz, np.concatenate(out))
        return [ca.DM(self.sp, nz + float(arg[2]) * self.const_values)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config")
    parser.add_argument("--waypoints", type=int, default=0, help="the path's N as the search's coarse stages take it")
    parser.add_argument("--explore", action="store_true", help="capped and watched, as the search's exploration")
    parser.add_argument("--starts", type=int, default=8)
    parser.add_argument("--mode", choices=MODES, nargs="+", default=list(MODES))
    args = parser.parse_args()
    for mode in args.mode:
        kept = []

        def projected(n_x, n_g, groups, constant, mode=mode, kept=kept):
            kept.append(ProjectedHessian(mode, n_x, n_g, groups, constant))  # a Callback must outlive its use
            return kept[-1]

        nlp_module.assemble_hessian = projected
        local._built.cache_clear()  # a new NLP (and solver) per mode
        local._prepared.cache_clear()
        problem, search = setup(args.config, args.waypoints, "explore" if args.explore else "full")
        rows = []
        with tempfile.TemporaryDirectory() as tmp:
            for start in range(args.starts):
                _, _, outcome, _, corrected, _ = logged_solve(problem, search, start, Path(tmp) / f"{start}.log")
                rows.append((outcome.status, outcome.iterations, corrected, outcome.objective))
        med = statistics.median
        print(f"{mode:5s}: iterations median {med(r[1] for r in rows):.0f} (max {max(r[1] for r in rows)}), "
              f"inertia-corrected {100 * med(r[2] for r in rows):.0f}%, "
              f"converged {sum(r[0] == 'Solve_Succeeded' for r in rows)} of {len(rows)}, "
              f"objective best {min(r[3] for r in rows):.4g} median {med(r[3] for r in rows):.4g}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
