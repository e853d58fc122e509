"""Config adapters: from a validated config to the objects experiments run -- the transcription of a method,
the multistart settings, and the variants of a config that the experiments solve (cases, structures).

The only module that turns solver keys of the config into library objects.
"""

from __future__ import annotations

from designopt.config import Config
from designopt.design_space import enumerate_structures
from designopt.multistart import Multistart
from designopt.search import Search
from designopt.transcriptions import transcription_named

__all__ = ["case_config", "describe_search", "enumerate_structures", "multistart_from_config", "search_from_config",
           "structure_config", "transcription_for", "with_waypoints"]


def transcription_for(cfg: Config, method: str = "to"):
    """The transcription of ``method`` (to, fk, fk_continuous) with the config's solver settings."""
    s = cfg.solver
    options = {"max_iter": s.max_iter, "compile": s.compile, "ipopt": {"ipopt.max_wall_time": float(s.time_limit)}}
    if method == "to":
        options.update(kinematics=s.kinematics, tracking=s.tracking, degree=s.degree, hold_degenerate=s.hold_degenerate)
    return transcription_named(method, **options)


def multistart_from_config(cfg: Config) -> Multistart:
    s = cfg.solver
    return Multistart(count=s.multistart, seed=s.seed, scale=s.perturbation, init=s.init, jobs=s.jobs)


def search_from_config(cfg: Config) -> Search:
    """The library's `Search` from ``solver.search`` (every key but the sweep's ``structure_neighbours``)."""
    return Search(**cfg.solver.search.model_dump(exclude={"structure_neighbours"}))


def describe_search(cfg: Config) -> str:
    """The config's search in words."""
    s = cfg.solver.search
    held = "; a solve stalled on a degenerate design is finished held" if cfg.solver.hold_degenerate else ""
    if s.strategy == "multistart":
        return f"multistart, {cfg.solver.multistart} starts{held}"
    screen = (f", the best {s.screen} distinct re-ranked on {s.screen_waypoints} waypoints (<= {s.screen_max_iter} "
              f"iterations, if the path has more)"
              if s.screen_waypoints else "")
    return (f"coarse to fine: {s.explore_starts} starts on {s.explore_waypoints} waypoints (<= {s.explore_max_iter} "
            f"iterations){screen}, the best {s.refine} distinct optima refined on the full path{held}")


def case_config(cfg: Config, case: str) -> Config:
    """The config of one case of the continuous problem: the same robot and cell with other joints marked as
    design joints (placement_only, design_only, combined)."""
    robot, placement = cfg.robot, cfg.placement
    if robot.is_urdf:
        raise cfg.error("robot.urdf", "this experiment varies DH parameters and needs a DH robot (robot.structure, "
                                      "robot.dh); `designopt run` takes URDF robots")
    design = robot.design or ["d", "a", "alpha"]
    if case == "placement_only":
        robot, placement = robot.model_copy(update={"design": []}), placement.model_copy(update={"optimize": True})
    elif case == "design_only":
        robot, placement = robot.model_copy(update={"design": design}), placement.model_copy(update={"optimize": False})
    elif case == "combined":
        robot, placement = robot.model_copy(update={"design": design}), placement.model_copy(update={"optimize": True})
    else:
        raise ValueError(f"unknown case {case!r}")
    return cfg.model_copy(update={"robot": robot, "placement": placement})


def with_waypoints(cfg: Config, n: int) -> Config:
    return cfg.model_copy(update={"toolpath": cfg.toolpath.model_copy(update={"waypoints": n})})


def structure_config(cfg: Config, structure: str) -> Config:
    """The sweep's config for one structure: generic start design, every link's d/theta, a, alpha free."""
    if cfg.robot.is_urdf:
        raise cfg.error("robot.urdf", "the structure sweep builds DH robots; a URDF robot has one structure")
    robot = cfg.robot.model_copy(update={"structure": structure, "dh": "generic", "design": ["d", "a", "alpha"]})
    return cfg.model_copy(update={"robot": robot})
