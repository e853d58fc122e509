"""``designopt check``: validate a config and build its problem and NLP, without solving.

What a user wants to know before a long run: is the input valid, which joints are design joints, how big
the NLP is, and which stiffness model the answer will be stated in.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from designopt.config import Config
from designopt.costs import Stiffness
from designopt.experiments.adapters import search_from_config
from designopt.kinematics.joints import Joint
from designopt.problem import problem_from_config
from designopt.transcriptions import Collocation


@dataclass(frozen=True)
class ProblemSummary:
    """What a solve of the config would be. Lengths in metres, force in newtons."""

    name: str
    structure: str
    moving: tuple[Joint, ...]
    design: tuple[Joint, ...]
    n_fixed: int
    toolpath_kind: str
    waypoints: int
    path_length_m: float
    force_n: float
    force_model: str  # paper (alpha * tangent) or milling
    tracked: int  # waypoints on cutting moves (the rest are rapids)
    duration: float  # task time at the last waypoint (s when time_unit is s)
    time_unit: str
    cell: str  # the cell in words, or "" when there is none
    stiffness: Stiffness
    deflection: str
    tracking: str
    kinematics: str
    n_variables: int
    n_constraints: int
    build_time_s: float
    search: str  # how `designopt run` would search it, in words


def _describe_cell(cell) -> str:
    if cell is None:
        return ""
    sx, sy, sz = cell.block_size
    return (f"block {sx:g} x {sy:g} x {sz:g} m under the path, floor at z = {cell.floor:g} m, clearance "
            f"{cell.clearance:g} m, link radii {', '.join(f'{r:g}' for r in sorted(set(cell.link_radius)))} m, "
            f"tool {cell.tool_length:g} m")


def check_config(cfg: Config) -> ProblemSummary:
    """Build the problem and its TO NLP (no solve) and describe them.

    Raises ConfigError / InputError on bad input, like every command that would solve it.
    """
    problem = problem_from_config(cfg)
    t0 = time.perf_counter()
    nlp = Collocation().build(problem).nlp
    build = time.perf_counter() - t0
    chain, tp = problem.chain, problem.toolpath
    return ProblemSummary(
        name=cfg.name, structure=chain.structure, moving=chain.moving, design=chain.design,
        n_fixed=len(chain.joints) - chain.n_moving - chain.n_design, toolpath_kind=tp.kind, waypoints=tp.n,
        path_length_m=float(np.linalg.norm(np.diff(tp.points_W, axis=0), axis=1).sum()),
        force_n=float(np.linalg.norm(tp.force_W, axis=1).max()), force_model=tp.force_model,
        tracked=int(tp.is_tracked.sum()), duration=float(tp.t[-1] - tp.t[0]), time_unit=tp.time_unit,
        cell=_describe_cell(problem.cell), stiffness=problem.stiffness,
        deflection=problem.deflection, tracking="hard", kinematics="forward",
        n_variables=nlp.n_variables, n_constraints=nlp.n_constraints, build_time_s=build,
        search=search_from_config(cfg).describe(),
    )
