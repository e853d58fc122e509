"""Kinematics of design-joint chains: transforms, joints, forward kinematics and Jacobians."""

from designopt.kinematics.chain import (
    geometric_jacobian,
    link_frames,
    placement_pose,
    tool_in_workpiece,
    tool_pose,
)
from designopt.kinematics.joints import DH_PARAMS, PLACEMENT_PARAMS, Chain, Joint, Role

__all__ = [
    "DH_PARAMS",
    "PLACEMENT_PARAMS",
    "Chain",
    "Joint",
    "Role",
    "geometric_jacobian",
    "link_frames",
    "placement_pose",
    "tool_in_workpiece",
    "tool_pose",
]
