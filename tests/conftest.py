"""Shared fixtures: tiny problems whose answers are known independently of designopt, and the shortest way to
solve one of them."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from designopt.config import parse_config
from designopt.problem import problem_from_config
from designopt.solve import Seeded, SolverProfile, solve_guess, solve_one

# No background builds while the suite runs (and in the CLI processes it starts): a new block is compiled at
# `FIRST_TIER` where it is first needed, large ones too, and never tiered up. Which blocks would cross the tier-up
# threshold, and which solves would run interpreted before their library lands, depends on the machine's speed, and
# the builds would take the cores the tests time nothing on. tests/test_tiered_compile.py turns them on where it
# tests them.
os.environ["DESIGNOPT_TIER_UP_AFTER"] = "never"

@pytest.fixture(scope="module")
def module_compile_cache(tmp_path_factory):
    """One compile cache (`DESIGNOPT_CACHE`) for a module's processes (the CLI's workers, killed subprocesses), given
    back after the module: the modules a pytest worker runs next keep the blocks the suite has compiled."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("DESIGNOPT_CACHE", str(tmp_path_factory.mktemp("cache")))
        yield


# The configs the project ships (not benchmarks/search_seeds.py's per-seed copies beside them, `.bench-*.yaml`)
SHIPPED_CONFIGS = sorted(p for p in (Path(__file__).resolve().parent.parent / "configs").glob("*.yaml")
                         if not p.name.startswith("."))

# A Cartesian gantry in standard DH: link 1 moves along z0, link 2 along z1 = y0, link 3 along z2 = x0.
GANTRY_DH = [
    {"theta": 0.0, "d": 0.0, "a": 0.0, "alpha": -math.pi / 2},
    {"theta": -math.pi / 2, "d": 0.0, "a": 0.0, "alpha": -math.pi / 2},
    {"theta": 0.0, "d": 0.0, "a": 0.0, "alpha": 0.0},
]


def gantry_config(**overrides) -> dict:
    """PPP gantry milling a short line, workpiece rotated so its -z axis is reachable by the tool; the offsets a
    of every link are the design joints, the placement is fixed."""
    cfg = {
        "name": "gantry",
        "design": ["a"],
        "toolpath": {"kind": "line", "length": 0.2, "waypoints": 12, "force": 2.0},
        "robot": {"structure": "PPP", "dh": GANTRY_DH},
        "placement": {"xyz": [0.3, 0.2, 0.5], "ypr": [0.0, -math.pi / 2, 0.0]},
        "search": {"preset": "paper", "starts": 1},
    }
    for key, value in overrides.items():
        cfg[key] = {**cfg.get(key, {}), **value} if isinstance(value, dict) else value
    return cfg


def solve(problem, transcription=None, index: int = 0, seed: int = 0, init: str = "ik", max_iter: int = 1000,
          hold_degenerate: bool = True, **profile):
    """Start ``index`` of seed ``seed`` of ``problem`` solved (TO unless ``transcription``), as a Solution."""
    return solve_one(problem, Seeded(seed, index, init=init), transcription,
                     SolverProfile(max_iter=max_iter, **profile), hold_degenerate)


def solve_from(problem, guess, transcription=None, max_iter: int = 1000, **profile):
    """``problem`` solved from an explicit InitialGuess (no continuation)."""
    from designopt.transcriptions import Collocation

    return solve_guess(problem, transcription or Collocation(), SolverProfile(max_iter=max_iter, **profile), guess)


def config(data: dict, base_dir=None):
    """A parsed config (relative files against ``base_dir``)."""
    return parse_config(data, "<test>", base_dir)


@pytest.fixture
def temp_keeping_compiler(tmp_path, monkeypatch):
    """(compile cache, this process's own TMPDIR), both made under ``tmp_path`` and set, with $CC a gcc that first
    leaves a file (``cckept*``) in its temporary directory, as a killed gcc would: for the tests that gcc's
    temporary files stay in the build's own directory."""
    cache, own_tmp = tmp_path / "cache", tmp_path / "tmp"
    cache.mkdir()
    own_tmp.mkdir()
    monkeypatch.setenv("DESIGNOPT_CACHE", str(cache))
    monkeypatch.setenv("TMPDIR", str(own_tmp))
    cc = tmp_path / "cc.sh"
    cc.write_text('#!/bin/sh\necho partial > "${TMPDIR:-/tmp}/cckept$$.s"\nexec gcc "$@"\n')
    cc.chmod(0o755)
    monkeypatch.setenv("CC", str(cc))
    return cache, own_tmp


@pytest.fixture
def gantry_problem():
    return problem_from_config(parse_config(gantry_config()))


@pytest.fixture
def rng():
    return np.random.default_rng(1234)
