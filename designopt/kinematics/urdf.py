"""Robots from URDF: the serial chain from the file's root link to a tool link, built into the same
elementary-transform chain as a DH robot.

Every URDF joint on the way from the root to ``tool_link`` contributes its origin -- six ETs x, y, z, yaw, pitch,
roll (URDF's rpy is Rz(yaw) Ry(pitch) Rx(roll)), each a fixed joint named ``<joint>.origin.<component>`` that a
design space may make a design joint (`designopt.design_space.design_joint_names`) -- followed, for a revolute,
continuous or prismatic joint, by its motion about or along its axis (a moving joint named after the URDF joint,
with the URDF's limits). The tool frame is ``tool_link``'s frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from designopt.errors import InputError
from designopt.kinematics.joints import ET, REGULARISED, Chain, Joint, Role, X, Y, Z

ORIGIN = (("x", "translate", X), ("y", "translate", Y), ("z", "translate", Z),
          ("yaw", "rotate", Z), ("pitch", "rotate", Y), ("roll", "rotate", X))
MOVING_TYPES = {"revolute": "rotate", "continuous": "rotate", "prismatic": "translate"}


@dataclass(frozen=True)
class RobotFile:
    """Where a robot came from: its URDF (an absolute path) and the link that carries the tool."""

    path: str
    tool_link: str


def rpy_of(R: np.ndarray) -> tuple[float, float, float]:
    """(roll, pitch, yaw) with R = Rz(yaw) Ry(pitch) Rx(roll) (URDF's convention)."""
    pitch = math.asin(max(-1.0, min(1.0, -R[2, 0])))
    if abs(R[2, 0]) < 1 - 1e-12:
        return math.atan2(R[2, 1], R[2, 2]), pitch, math.atan2(R[1, 0], R[0, 0])
    return 0.0, pitch, math.atan2(-R[0, 1], R[1, 1])  # gimbal lock: put it all in yaw


def root_link(urdf) -> str:
    """The link that is no joint's child."""
    children = {j.child for j in urdf.robot.joints}
    roots = [link.name for link in urdf.robot.links if link.name not in children]
    return roots[0]


def serial_joints(urdf, tool_link: str, config_error) -> list:
    """The URDF joints from the root link down to tool_link, in order."""
    links = {link.name for link in urdf.robot.links}
    if tool_link not in links:
        raise config_error("robot.tool_link", f"no link {tool_link!r} in the URDF (links: {', '.join(sorted(links))})")
    by_child = {j.child: j for j in urdf.robot.joints}
    path, link = [], tool_link
    while link in by_child:
        path.append(by_child[link])
        link = by_child[link].parent
    if link == tool_link:
        raise config_error("robot.tool_link", f"{tool_link!r} is the URDF's root link: the tool must be below it")
    return path[::-1]


def load_urdf(path: Path):
    import yourdfpy

    try:
        return yourdfpy.URDF.load(str(path), build_scene_graph=False, load_meshes=False,
                                  filename_handler=yourdfpy.filename_handler_null)  # meshes: never opened
    except Exception as exc:  # yourdfpy raises what lxml or its own parser raise: all mean "not a URDF"
        reason = str(exc).splitlines()[0] if str(exc) else repr(exc)
        raise InputError(path, "(file)", f"not a readable URDF: {reason}") from None


def chain_from_urdf(path: Path, tool_link: str, placement: list[Joint], placement_ets: tuple[ET, ...], bounds,
                    config_error=None) -> Chain:
    """The chain of a URDF robot after the given placement joints, every origin component fixed.

    Joint limits come from the URDF (continuous joints, and joints without limits, take ``bounds.revolute`` /
    ``bounds.prismatic``, a `designopt.design_space.JointBounds`); origin components, should a design space free
    them, are bounded by ``bounds.design_length`` / ``bounds.design_angle``. ``config_error(key, reason)`` makes
    the exception for a mistake in the config (not in the URDF).
    """
    if config_error is None:
        def config_error(key, reason):
            return InputError("<config>", key, reason)
    urdf = load_urdf(path)
    joints, robot, frames = list(placement), [], []
    for uj in serial_joints(urdf, tool_link, config_error):
        origin = np.asarray(uj.origin if uj.origin is not None else np.eye(4), dtype=float)
        roll, pitch, yaw = rpy_of(origin[:3, :3])
        values = dict(zip(("x", "y", "z"), origin[:3, 3], strict=True)) | {"yaw": yaw, "pitch": pitch, "roll": roll}
        for component, motion, axis in ORIGIN:
            name = f"{uj.name}.origin.{component}"
            length = motion == "translate"
            lo, hi = bounds.design_length if length else bounds.design_angle
            tags = frozenset({REGULARISED}) if length else frozenset()
            robot.append(ET(motion, axis, len(joints)))
            joints.append(Joint(name, "length" if length else "angle", Role.FIXED, float(values[component]), lo, hi,
                                tags))
        if uj.type in MOVING_TYPES and uj.mimic is not None:
            raise config_error("robot.tool_link", f"the chain to {tool_link!r} passes joint {uj.name!r}, which mimics "
                                                  f"{uj.mimic.joint!r} (a finger or coupled joint): choose a tool_link "
                                                  "above it, e.g. the hand or flange link")
        if uj.type in MOVING_TYPES:
            motion = MOVING_TYPES[uj.type]
            axis = np.asarray(uj.axis if uj.axis is not None else (1.0, 0.0, 0.0), dtype=float)
            axis = tuple(float(v) for v in axis / np.linalg.norm(axis))
            lo, hi = bounds.revolute if motion == "rotate" else bounds.prismatic
            if uj.type != "continuous" and uj.limit is not None and uj.limit.lower is not None \
                    and uj.limit.upper is not None and uj.limit.lower < uj.limit.upper:
                lo, hi = float(uj.limit.lower), float(uj.limit.upper)
            robot.append(ET(motion, axis, len(joints)))
            joints.append(Joint(uj.name, "angle" if motion == "rotate" else "length", Role.MOVING, 0.0, lo, hi))
        elif uj.type != "fixed":
            raise InputError(path, "robot.urdf", f"joint {uj.name!r} is {uj.type}: only revolute, continuous, "
                                                 "prismatic and fixed joints make a serial chain")
        frames.append(len(robot))
    return Chain(joints=tuple(joints), placement=placement_ets, robot=tuple(robot), frames=tuple(frames))


def joint_velocities(path: Path, tool_link: str) -> tuple[float | None, ...]:
    """The URDF's velocity limit of each moving joint on the chain to ``tool_link`` (rad/s or m/s; None where
    the file gives none or 0)."""
    urdf = load_urdf(path)

    def config_error(key, reason):
        return InputError(path, key, reason)

    return tuple(float(uj.limit.velocity) if uj.limit is not None and uj.limit.velocity else None
                 for uj in serial_joints(urdf, tool_link, config_error) if uj.type in MOVING_TYPES)
