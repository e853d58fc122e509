"""Shared fixtures: tiny problems whose answers are known independently of designopt."""

from __future__ import annotations

import math

import numpy as np
import pytest

from designopt.config import parse_config
from designopt.problem import problem_from_config

# A Cartesian gantry in standard DH: link 1 moves along z0, link 2 along z1 = y0, link 3 along z2 = x0.
GANTRY_DH = [
    {"theta": 0.0, "d": 0.0, "a": 0.0, "alpha": -math.pi / 2},
    {"theta": -math.pi / 2, "d": 0.0, "a": 0.0, "alpha": -math.pi / 2},
    {"theta": 0.0, "d": 0.0, "a": 0.0, "alpha": 0.0},
]


def gantry_config(**overrides) -> dict:
    """PPP gantry milling a short line, workpiece rotated so its -z axis is reachable by the tool."""
    cfg = {
        "name": "gantry",
        "toolpath": {"kind": "line", "length": 0.2, "waypoints": 12, "force": 2.0},
        "robot": {"structure": "PPP", "design": ["a"], "dh": GANTRY_DH, "bounds": {"prismatic": [-2, 2]}},
        "placement": {"optimize": False, "xyz": [0.3, 0.2, 0.5], "ypr": [0.0, -math.pi / 2, 0.0]},
        "solver": {"multistart": 1, "max_iter": 200},
    }
    for key, value in overrides.items():
        cfg[key] = {**cfg.get(key, {}), **value} if isinstance(value, dict) else value
    return cfg


@pytest.fixture
def gantry_problem():
    return problem_from_config(parse_config(gantry_config()))


@pytest.fixture
def rng():
    return np.random.default_rng(1234)
