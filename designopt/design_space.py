"""Design spaces: which scalars of a chain are design joints, and their bounds.

A design space is nothing but a choice of roles for the joints of one `Chain`. ``robot_design`` picks
DH parameters, ``placement`` picks workpiece coordinates; both end up as design joints of the same chain.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

from designopt.kinematics.joints import (
    DH_PARAMS,
    ET,
    PLACEMENT_PARAMS,
    REGULARISED,
    Chain,
    Joint,
    Role,
    X,
    Y,
    Z,
    moving_param,
)

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


def placement_ets(first_joint: int) -> tuple[ET, ...]:
    """T_BW = Trans(x, y, z) Rz(yaw) Ry(pitch) Rx(roll), for the six placement joints from ``first_joint``."""
    return tuple(ET(motion, axis, first_joint + k) for k, (motion, axis) in enumerate(
        [("translate", X), ("translate", Y), ("translate", Z), ("rotate", Z), ("rotate", Y), ("rotate", X)]))


def placement_joints(xyz: Sequence[float], ypr: Sequence[float], free: Sequence[str],
                     bounds: JointBounds = JointBounds()) -> list[Joint]:
    """The six placement joints; those named in ``free`` are design joints."""
    joints = []
    for k, (name, value) in enumerate(zip(PLACEMENT_PARAMS, [*xyz, *ypr], strict=True)):
        lo, hi = bounds.placement_box[k] if k < 3 else bounds.placement_angle
        role = Role.DESIGN if name in free else Role.FIXED
        kind = "angle" if name in ANGLE_PARAMS else "length"
        joints.append(Joint(f"placement.{name}", kind, role, float(value), lo, hi))
    return joints


# A standard DH link: T = Rz(theta) Tz(d) Tx(a) Rx(alpha).
DH_ETS = (("rotate", Z), ("translate", Z), ("translate", X), ("rotate", X))


def build_chain(
    structure: str,
    dh: Sequence[dict[str, float]],
    design: Sequence[str],
    placement_xyz: Sequence[float],
    placement_ypr: Sequence[float],
    placement_free: Sequence[str],
    bounds: JointBounds = JointBounds(),
) -> Chain:
    """Assemble a DH robot and its placement into one chain: six placement joints, then (theta, d, a, alpha)
    of every link, each an elementary transform.

    ``dh`` gives the initial (or fixed) value of every DH parameter; ``design`` names the DH parameters
    that are design joints; ``placement_free`` names the placement coordinates that are design joints.
    """
    joints = placement_joints(placement_xyz, placement_ypr, placement_free, bounds)
    robot, frames, links = [], [], []
    for i, (link_type, row) in enumerate(zip(structure, dh, strict=True)):
        chosen = resolve_design_params(link_type, design)
        indices = []
        for param, (motion, axis) in zip(DH_PARAMS, DH_ETS, strict=True):
            kind = "angle" if param in ANGLE_PARAMS else "length"
            if param == moving_param(link_type):
                role = Role.MOVING
                lo, hi = bounds.revolute if link_type == "R" else bounds.prismatic
            else:
                role = Role.DESIGN if param in chosen else Role.FIXED
                lo, hi = bounds.design_length if kind == "length" else bounds.design_angle
            tags = frozenset({REGULARISED}) if kind == "length" else frozenset()
            indices.append(len(joints))
            robot.append(ET(motion, axis, len(joints)))
            joints.append(Joint(f"link{i + 1}.{param}", kind, role, float(row[param]), lo, hi, tags))
        links.append(tuple(indices))
        frames.append(len(robot))
    return Chain(joints=tuple(joints), placement=placement_ets(0), robot=tuple(robot), frames=tuple(frames),
                 dh=tuple(links))


def design_joint_names(chain: Chain, design: Sequence[str]) -> set[str]:
    """The joints of ``chain`` that ``design`` makes design joints -- robot and placement alike.

    Each item is a DH parameter name (``theta``, ``d``, ``a``, ``alpha``: that parameter of every link; on a P link
    a requested ``d`` is its ``theta``, SPEC §4), ``placement`` (all six placement coordinates) or one of them
    (``x`` ... ``roll``), or the name of any joint of the chain (``link2.a``, ``placement.yaw``,
    ``elbow_joint.origin.z``). A moving joint is never a design joint. KeyError (with the reason) for an item that
    names nothing."""
    by_name = {j.name: j for j in chain.joints}
    out: set[str] = set()
    for item in design:
        if item in DH_PARAMS:
            if chain.dh is None:
                raise KeyError(f"{item!r} names a DH parameter, and this robot is not a DH table: name joints of the "
                               "chain (e.g. <urdf joint>.origin.z) or the placement")
            for i, link_type in enumerate(chain.structure):
                out |= {f"link{i + 1}.{p}" for p in resolve_design_params(link_type, [item])}
        elif item == "placement":
            out |= {j.name for j in chain.placement_joints}
        elif item in PLACEMENT_PARAMS:
            out.add(f"placement.{item}")
        elif item in by_name:
            if by_name[item].role is Role.MOVING:
                raise KeyError(f"{item!r} is a moving joint: it follows a trajectory, it cannot be a design joint")
            out.add(item)
        else:
            raise KeyError(f"{item!r} names no joint (a DH parameter theta/d/a/alpha, placement or one of "
                           f"{', '.join(PLACEMENT_PARAMS)}, or a joint of the chain such as "
                           f"{next((n for n in by_name if not n.startswith('placement')), 'link1.a')})")
    return out


def enumerate_structures(min_dof: int = 1, max_dof: int = 6) -> list[str]:
    """All strings over {R, P} with min_dof..max_dof letters: by length, then R before P at each place.
    1..6 gives 2 + 4 + ... + 64 = 126."""
    return ["".join(s) for n in range(min_dof, max_dof + 1) for s in itertools.product("RP", repeat=n)]
