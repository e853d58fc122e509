"""Design spaces: which scalars of a chain are design joints, and their bounds.

A design space is nothing but a choice of roles for the joints of one `Chain`. ``robot_design`` picks
DH parameters, ``placement`` picks workpiece coordinates; both end up as design joints of the same chain.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from designopt.kinematics.joints import DH_PARAMS, PLACEMENT_PARAMS, Chain, Joint, Role, moving_param

ANGLE_PARAMS = {"theta", "alpha", "yaw", "pitch", "roll"}


@dataclass(frozen=True)
class JointBounds:
    """Bounds of every joint kind, in metres and radians."""

    design_length: tuple[float, float] = (0.0, 2.0)
    design_angle: tuple[float, float] = (-math.pi, math.pi)
    revolute: tuple[float, float] = (-2 * math.pi, 2 * math.pi)
    prismatic: tuple[float, float] = (-2.0, 2.0)
    placement_box: tuple[tuple[float, float], ...] = ((-2.0, 2.0), (-2.0, 2.0), (-1.0, 2.0))
    placement_angle: tuple[float, float] = (-math.pi, math.pi)


def resolve_design_params(link_type: str, design: Sequence[str]) -> set[str]:
    """Which DH parameters of one link are design joints.

    The config names them as for an R link (``d, a, alpha``); on a P link d moves, so a requested ``d``
    becomes its ``theta`` (the SPEC's convention). The moving parameter is never a design joint.
    """
    chosen = set(design)
    if link_type == "P" and "d" in chosen:
        chosen = (chosen - {"d"}) | {"theta"}
    return chosen - {moving_param(link_type)}


def build_chain(
    structure: str,
    dh: Sequence[dict[str, float]],
    design: Sequence[str],
    placement_xyz: Sequence[float],
    placement_ypr: Sequence[float],
    placement_free: Sequence[str],
    bounds: JointBounds = JointBounds(),
) -> Chain:
    """Assemble the chain: placement joints first, then (theta, d, a, alpha) of every link.

    ``dh`` gives the initial (or fixed) value of every DH parameter; ``design`` names the DH parameters
    that are design joints; ``placement_free`` names the placement coordinates that are design joints.
    """
    joints: list[Joint] = []
    for k, (name, value) in enumerate(zip(PLACEMENT_PARAMS, [*placement_xyz, *placement_ypr], strict=True)):
        lo, hi = bounds.placement_box[k] if k < 3 else bounds.placement_angle
        role = Role.DESIGN if name in placement_free else Role.FIXED
        kind = "angle" if name in ANGLE_PARAMS else "length"
        joints.append(Joint(f"placement.{name}", kind, role, float(value), lo, hi))
    for i, (link_type, row) in enumerate(zip(structure, dh, strict=True)):
        chosen = resolve_design_params(link_type, design)
        for param in DH_PARAMS:
            kind = "angle" if param in ANGLE_PARAMS else "length"
            if param == moving_param(link_type):
                role = Role.MOVING
                lo, hi = bounds.revolute if link_type == "R" else bounds.prismatic
            else:
                role = Role.DESIGN if param in chosen else Role.FIXED
                lo, hi = bounds.design_length if kind == "length" else bounds.design_angle
            joints.append(Joint(f"link{i + 1}.{param}", kind, role, float(row[param]), lo, hi))
    return Chain(structure=structure, joints=tuple(joints))


def design_lengths(chain: Chain) -> list[int]:
    """Indices into q_d of the design joints that are link lengths (d, a): the regularised ones."""
    return [i for i, j in enumerate(chain.design) if j.name.startswith("link") and j.kind == "length"]
