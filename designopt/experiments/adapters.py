"""Config adapters: from a validated config to the objects experiments hand to the Solve layer -- the search it
names, and the variants of a config that the experiments solve (cases, structures, path samplings).

Variants are made by `designopt.config.revised`, so each is validated like a user's config.
"""

from __future__ import annotations

from designopt.config import Config, revised
from designopt.design_space import enumerate_structures
from designopt.solve.search import Search, preset

__all__ = ["CASES", "case_config", "enumerate_structures", "search_from_config", "structure_config", "with_waypoints"]

# The cases of the continuous problem (SPEC §5): which joints are design joints -- one mechanism.
CASES = {"placement_only": ["placement"], "design_only": ["d", "a", "alpha"],
         "combined": ["d", "a", "alpha", "placement"]}


def search_from_config(cfg: Config) -> Search:
    """The config's search: its preset with the config's seed (and number of starts and spread, when given)."""
    s = cfg.search
    given = {k: v for k, v in (("starts", s.starts), ("spread", s.spread)) if v is not None}
    return preset(s.preset, seed=s.seed, **given)


def _dh_only(cfg: Config, what: str) -> None:
    if cfg.robot.is_urdf:
        raise cfg.error("robot.urdf", f"{what} varies DH parameters and needs a DH robot (robot.structure, "
                                      "robot.dh); `designopt run` takes URDF robots")


def case_config(cfg: Config, case: str) -> Config:
    """The config of one case of the continuous problem: the same robot and cell with other joints marked as
    design joints (placement_only, design_only, combined)."""
    _dh_only(cfg, "this experiment")
    if case not in CASES:
        raise ValueError(f"unknown case {case!r} ({', '.join(CASES)})")
    return revised(cfg, design=CASES[case])


def with_waypoints(cfg: Config, n: int) -> Config:
    return revised(cfg, toolpath={"waypoints": n})


def structure_config(cfg: Config, structure: str) -> Config:
    """The sweep's config for one structure: generic start design, every link's d/theta, a, alpha and the
    placement free."""
    _dh_only(cfg, "the structure sweep")
    return revised(cfg, robot={"structure": structure, "dh": "generic"}, design=CASES["combined"])
