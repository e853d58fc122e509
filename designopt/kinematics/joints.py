"""Design joints: one mechanism for robot parameters and workpiece placement.

Every scalar of the kinematic model -- each DH parameter of each link and each of the six placement
coordinates -- is a `Joint` with a role:

* ``moving``: follows a trajectory q_m(t) (theta of an R link, d of a P link);
* ``design``: a decision variable constant over the whole task (a link length, a twist, the workpiece x);
* ``fixed``: a constant the optimizer may not change.

Robot design and workpiece placement differ only in *where* their joints sit in the chain: the placement
joints come first (they move the workpiece frame W relative to the robot base frame B), the DH joints
follow. Nothing downstream special-cases either.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from enum import Enum

import numpy as np

DH_PARAMS = ("theta", "d", "a", "alpha")
PLACEMENT_PARAMS = ("x", "y", "z", "yaw", "pitch", "roll")


class Role(str, Enum):
    MOVING = "moving"
    DESIGN = "design"
    FIXED = "fixed"


@dataclass(frozen=True)
class Joint:
    """One scalar of the model.

    ``kind`` is ``"length"`` (metres) or ``"angle"`` (radians); ``value`` is the fixed value or the
    initial guess; ``lower``/``upper`` bound moving and design joints.
    """

    name: str
    kind: str
    role: Role
    value: float
    lower: float = -np.inf
    upper: float = np.inf

    @property
    def is_free(self) -> bool:
        return self.role is not Role.FIXED


@dataclass(frozen=True)
class Chain:
    """A serial chain: six placement joints, then four DH joints (theta, d, a, alpha) per link.

    ``structure`` is a string over {R, P}, base to tool. ``tool`` is a fixed 4x4 transform appended after
    the last DH frame (identity by default).
    """

    structure: str
    joints: tuple[Joint, ...]
    tool: tuple[tuple[float, ...], ...] = field(default=tuple(tuple(r) for r in np.eye(4)))

    def __post_init__(self):
        expected = len(PLACEMENT_PARAMS) + len(DH_PARAMS) * len(self.structure)
        if len(self.joints) != expected:
            raise ValueError(f"chain {self.structure} needs {expected} joints, got {len(self.joints)}")

    @property
    def n_links(self) -> int:
        return len(self.structure)

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
        return self.values(q_m, q_d)[: len(PLACEMENT_PARAMS)]

    def link_values(self, q_m, q_d) -> list[list]:
        vals = self.values(q_m, q_d)[len(PLACEMENT_PARAMS) :]
        return [vals[4 * i : 4 * i + 4] for i in range(self.n_links)]

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
