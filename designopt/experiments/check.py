"""``designopt check``: validate a config and describe its problem and NLP, without solving.

What a user wants to know before a long run: is the input valid, where the path lies, which joints are design
joints, how big the NLP is, and which stiffness model the answer will be stated in. The NLP is counted, not built
(building a program of a few hundred waypoints takes minutes); ``build`` builds it.
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
    build_time_s: float | None  # None: counted, not built
    search: str  # how `designopt run` would search it, in words
    extent_m: tuple[float, float, float] = (0.0, 0.0, 0.0)  # x, y, z extent of the path in W
    z_range_m: tuple[float, float] = (0.0, 0.0)  # lowest and highest cutting waypoint in W
    cut_length_m: float = 0.0
    rapid_length_m: float = 0.0
    force_range_n: tuple[float, float] = (0.0, 0.0)  # least and most force on a cutting waypoint


def _describe_cell(cell) -> str:
    if cell is None:
        return ""
    sx, sy, sz = cell.block_size
    return (f"block {sx:g} x {sy:g} x {sz:g} m under the path, floor at z = {cell.floor:g} m, clearance "
            f"{cell.clearance:g} m, link radii {', '.join(f'{r:g}' for r in sorted(set(cell.link_radius)))} m, "
            f"tool {cell.tool_length:g} m")


def check_config(cfg: Config, build: bool = False) -> ProblemSummary:
    """Describe the problem and the size of its TO NLP, counted (``build``: built, and timed); nothing is solved.

    Raises ConfigError / InputError on bad input, like every command that would solve it.
    """
    problem = problem_from_config(cfg)
    transcription = Collocation()
    n_variables, n_constraints = transcription.size(problem)
    seconds = None
    if build:
        t0 = time.perf_counter()
        nlp = transcription.build(problem).nlp
        seconds, n_variables, n_constraints = time.perf_counter() - t0, nlp.n_variables, nlp.n_constraints
    chain, tp = problem.chain, problem.toolpath
    steps = np.linalg.norm(np.diff(tp.points_W, axis=0), axis=1)
    cutting = tp.is_tracked[1:] & tp.is_tracked[:-1]
    force = np.linalg.norm(tp.force_W, axis=1)[tp.is_tracked]
    z = tp.points_W[tp.is_tracked, 2]
    return ProblemSummary(
        name=cfg.name, structure=chain.structure, moving=chain.moving, design=chain.design,
        n_fixed=len(chain.joints) - chain.n_moving - chain.n_design, toolpath_kind=tp.kind, waypoints=tp.n,
        path_length_m=float(np.linalg.norm(np.diff(tp.points_W, axis=0), axis=1).sum()),
        force_n=float(np.linalg.norm(tp.force_W, axis=1).max()), force_model=tp.force_model,
        tracked=int(tp.is_tracked.sum()), duration=float(tp.t[-1] - tp.t[0]), time_unit=tp.time_unit,
        cell=_describe_cell(problem.cell), stiffness=problem.stiffness,
        deflection=problem.deflection, tracking="hard", kinematics="forward",
        n_variables=n_variables, n_constraints=n_constraints, build_time_s=seconds,
        search=search_from_config(cfg).describe(), extent_m=tuple(float(v) for v in np.ptp(tp.points_W, axis=0)),
        z_range_m=(float(z.min()), float(z.max())), cut_length_m=float(steps[cutting].sum()),
        rapid_length_m=float(steps[~cutting].sum()), force_range_n=(float(force.min()), float(force.max())),
    )
