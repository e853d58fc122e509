"""DH presets (standard DH, metres and radians).

``puma560`` is the standard-DH model of Corke's Robotics Toolbox (``Puma560()``; Corke & Armstrong-Helouvry
1995 parameters). At q = 0 its last frame is at (0.4521, -0.15005, 0.4318) m.
"""

from __future__ import annotations

import math

PRESETS: dict[str, list[dict[str, float]]] = {
    "puma560": [
        {"theta": 0.0, "d": 0.0, "a": 0.0, "alpha": math.pi / 2},
        {"theta": 0.0, "d": 0.0, "a": 0.4318, "alpha": 0.0},
        {"theta": 0.0, "d": 0.15005, "a": 0.0203, "alpha": -math.pi / 2},
        {"theta": 0.0, "d": 0.4318, "a": 0.0, "alpha": math.pi / 2},
        {"theta": 0.0, "d": 0.0, "a": 0.0, "alpha": -math.pi / 2},
        {"theta": 0.0, "d": 0.0, "a": 0.0, "alpha": 0.0},
    ],
}


def generic_dh(n_links: int) -> list[dict[str, float]]:
    """A neutral starting design for any number of links: 0.1 m offsets, 0.3 m links, alternating twists."""
    return [
        {"theta": 0.0, "d": 0.1, "a": 0.3, "alpha": (math.pi / 2 if i % 2 == 0 else 0.0)} for i in range(n_links)
    ]


def preset(name: str, n_links: int) -> list[dict[str, float]]:
    """DH rows of a named preset; ``generic`` adapts to any number of links."""
    if name == "generic":
        return generic_dh(n_links)
    if name not in PRESETS:
        raise KeyError(f"unknown DH preset '{name}' (known: generic, {', '.join(sorted(PRESETS))})")
    rows = PRESETS[name]
    if len(rows) != n_links:
        raise ValueError(f"preset '{name}' has {len(rows)} links, the structure has {n_links}")
    return [dict(r) for r in rows]
