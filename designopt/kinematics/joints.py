"""Design joints and the one chain they live in.

Every scalar of the kinematic model -- each DH parameter of each link, each origin component of a URDF joint
and each of the six placement coordinates -- is a `Joint` with a role:

* ``moving``: follows a trajectory q_m(t) (theta of an R link, d of a P link, a URDF joint's motion);
* ``design``: a decision variable constant over the whole task (a link length, a twist, the workpiece x);
* ``fixed``: a constant the optimizer may not change.

The kinematic model is one sequence of elementary transforms (`ET`: a translation along, or a rotation
about, a fixed axis) whose values are joints -- the robotics-toolbox ETS idea. A DH link is four ETs, the
placement six, a URDF joint its origin's six plus its motion: all are *built into* the same sequence, and
robot design and workpiece placement differ only in *where* their joints sit in it. Nothing downstream
special-cases either.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from enum import Enum

import numpy as np

DH_PARAMS = ("theta", "d", "a", "alpha")
PLACEMENT_PARAMS = ("x", "y", "z", "yaw", "pitch", "roll")
REGULARISED = "regularised"  # tag of the design lengths the regularisation L_r penalises


class Role(str, Enum):
    MOVING = "moving"
    DESIGN = "design"
    FIXED = "fixed"


@dataclass(frozen=True)
class Joint:
    """One scalar of the model.

    ``kind`` is ``"length"`` (metres) or ``"angle"`` (radians); ``value`` is the fixed value or the
    initial guess; ``lower``/``upper`` bound moving and design joints; ``tags`` carry meaning the costs
    need (e.g. `REGULARISED`).
    """

    name: str
    kind: str
    role: Role
    value: float
    lower: float = -np.inf
    upper: float = np.inf
    tags: frozenset[str] = frozenset()

    @property
    def is_free(self) -> bool:
        return self.role is not Role.FIXED


@dataclass(frozen=True)
class ET:
    """An elementary transform: translate along, or rotate about, the unit ``axis`` (in the current frame)
    by the value of ``Chain.joints[joint]`` (metres or radians)."""

    motion: str  # "translate" or "rotate"
    axis: tuple[float, float, float]
    joint: int

    def __post_init__(self):
        if self.motion not in ("translate", "rotate"):
            raise ValueError(f"an ET translates or rotates, not {self.motion!r}")
        if abs(float(np.linalg.norm(self.axis)) - 1.0) > 1e-9:
            raise ValueError(f"ET axis {self.axis} is not a unit vector")

    @property
    def basis(self) -> int | None:
        """0, 1 or 2 when the axis is x, y or z (closed-form matrices), else None."""
        for i in range(3):
            if self.axis[i] == 1.0 and self.axis[(i + 1) % 3] == 0.0 and self.axis[(i + 2) % 3] == 0.0:
                return i
        return None


X, Y, Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Chain:
    """The kinematic model: joints, and the ETs that use them.

    ``placement`` walks from the robot base B to the workpiece frame W (T_BW); ``robot`` walks from B to the
    last link frame, and ``tool`` (a fixed 4x4) follows it. ``frames`` are the ET counts of ``robot`` after
    which a link frame ends (for drawing and export). ``dh`` gives, when the robot is a DH table, the joint
    indices (theta, d, a, alpha) of every link. Moving joints appear in ``joints`` in the order the robot
    walk meets them, so q_m lines up with the Jacobian's columns.
    """

    joints: tuple[Joint, ...]
    placement: tuple[ET, ...]
    robot: tuple[ET, ...]
    frames: tuple[int, ...] = ()
    dh: tuple[tuple[int, int, int, int], ...] | None = None
    tool: tuple[tuple[float, ...], ...] = field(default=tuple(tuple(r) for r in np.eye(4)))

    def __post_init__(self):
        n = len(self.joints)
        if any(not 0 <= et.joint < n for et in (*self.placement, *self.robot)):
            raise ValueError("an ET refers to a joint the chain does not have")
        walk_order = [et.joint for et in self.robot if self.joints[et.joint].role is Role.MOVING]
        if walk_order != list(self._indices(Role.MOVING)) or len(set(walk_order)) != len(walk_order):
            raise ValueError("moving joints must be robot ETs, each used once, in the order the walk meets them")

    @property
    def structure(self) -> str:
        """R or P for every moving joint, base to tool."""
        return "".join("R" if et.motion == "rotate" else "P" for et in self.robot
                       if self.joints[et.joint].role is Role.MOVING)

    @property
    def n_links(self) -> int:
        return len(self.frames)

    def _indices(self, role: Role) -> tuple[int, ...]:
        return tuple(i for i, j in enumerate(self.joints) if j.role is role)

    @property
    def moving(self) -> tuple[Joint, ...]:
        return tuple(self.joints[i] for i in self._indices(Role.MOVING))

    @property
    def design(self) -> tuple[Joint, ...]:
        return tuple(self.joints[i] for i in self._indices(Role.DESIGN))

    @property
    def n_moving(self) -> int:
        return len(self._indices(Role.MOVING))

    @property
    def n_design(self) -> int:
        return len(self._indices(Role.DESIGN))

    @property
    def placement_joints(self) -> tuple[Joint, ...]:
        return tuple(self.joints[et.joint] for et in self.placement)

    def values(self, q_m, q_d) -> list:
        """All scalars of the chain in order, taking moving values from q_m and design values from q_d.

        Fixed values are lifted to the type of q_m/q_d when those are symbolic so that numpy and CasADi
        never mix inside one product.
        """
        lift = _lifter(q_m, q_d)
        it_m, it_d = iter(range(self.n_moving)), iter(range(self.n_design))
        out = []
        for j in self.joints:
            if j.role is Role.MOVING:
                out.append(q_m[next(it_m)])
            elif j.role is Role.DESIGN:
                out.append(q_d[next(it_d)])
            else:
                out.append(lift(j.value))
        return out

    def placement_values(self, q_m, q_d) -> list:
        """(x, y, z, yaw, pitch, roll) of W in B."""
        values = self.values(q_m, q_d)
        return [values[et.joint] for et in self.placement]

    def link_values(self, q_m, q_d) -> list[list]:
        """(theta, d, a, alpha) of every link of a DH robot."""
        if self.dh is None:
            raise ValueError("this robot is not a DH table")
        values = self.values(q_m, q_d)
        return [[values[i] for i in link] for link in self.dh]

    def joint(self, name: str) -> Joint:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(name)

    def with_roles(self, roles: dict[str, Role], values: dict[str, float] | None = None) -> Chain:
        """A copy in which the named joints take new roles (and optionally new values)."""
        values = values or {}
        joints = tuple(
            replace(j, role=roles.get(j.name, j.role), value=values.get(j.name, j.value)) for j in self.joints
        )
        return replace(self, joints=joints)

    @property
    def design_values(self) -> np.ndarray:
        return np.array([j.value for j in self.design])


def _lifter(q_m, q_d):
    import casadi as ca

    for q in (q_m, q_d):
        if isinstance(q, ca.SX):
            return ca.SX
        if isinstance(q, ca.MX):
            return ca.MX
    return float


def moving_param(link_type: str) -> str:
    """The DH parameter that moves: theta for a revolute link, d for a prismatic one."""
    return {"R": "theta", "P": "d"}[link_type]
