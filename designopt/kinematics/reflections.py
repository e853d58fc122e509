"""Reflections of a DH arm: two parameter sets that describe the same arm, one length's sign apart.

A standard DH link is ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``. Reversing a frame's z or x axis commutes with the next
transforms up to signs -- ``Rx(pi) Rz(theta) Tz(d) = Rz(-theta) Tz(-d) Rx(pi)`` and ``Rz(pi) Tx(a) Rx(alpha) =
Tx(-a) Rx(-alpha) Rz(pi)`` -- so, passing the reversal on to where it cancels:

* the *d-reflection* of link j (j >= 2): alpha_{j-1} + pi, theta_j -> -theta_j, d_j -> -d_j, alpha_j - pi;
* the *a-reflection* of link i: theta_i + pi, a_i -> -a_i, alpha_i -> -alpha_i, theta_{i+1} + pi (for the last
  link the tool frame turns by pi about its own z axis instead, which moves neither the tool point nor the tool
  axis when the tool transform is along z).

Every frame from link j (or i) on is the same, so is the tool's path and (the joint axes only change sign) the
arm's compliance: the two are one design. With design lengths bounded below by 0 (SPEC), a design whose cost
falls as a length goes below 0 stops at the bound, a local optimum of the bounded problem that is not one of the
arm's; its reflection is the same arm with the length free to grow on the other side. Twists stay within
(-pi, pi] (the design angles' bounds), so a reflection also carries a twist across +-pi.

Frames: the DH link frames of `designopt.kinematics.chain`; lengths in metres, angles in radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designopt.kinematics.joints import Chain, Role

LINK_PARAMS = {"theta": 0, "d": 1, "a": 2, "alpha": 3}  # positions in Chain.dh's rows


def wrap(angle):
    """An angle (rad) within (-pi, pi]."""
    return np.pi - np.mod(np.pi - np.asarray(angle, float), 2 * np.pi)


@dataclass(frozen=True)
class Reflection:
    """The ``kind`` ("d" or "a") reflection of DH link ``link`` (1-based, as the config's link names)."""

    kind: str
    link: int

    @property
    def name(self) -> str:
        """The reflected length's joint name, e.g. ``link4.d``."""
        return f"link{self.link}.{self.kind}"

    def _joint(self, chain: Chain, link: int, param: str) -> int:
        return chain.dh[link - 1][LINK_PARAMS[param]]

    def length(self, chain: Chain) -> int:
        """The reflected length's position in the design vector."""
        return _design_position(chain, self._joint(chain, self.link, self.kind))

    def design(self, chain: Chain, q_d: np.ndarray) -> np.ndarray:
        """The design vector (design joints in `Chain.design` order) of the same arm written with the length's sign
        flipped: it is negated, the twists turned (d: alpha_{j-1} + pi and alpha_j - pi; a: alpha_i negated) and
        wrapped to (-pi, pi]."""
        q = np.array(q_d, dtype=float)
        q[self.length(chain)] *= -1
        if self.kind == "d":
            for link, turn in ((self.link - 1, np.pi), (self.link, -np.pi)):
                k = _design_position(chain, self._joint(chain, link, "alpha"))
                q[k] = wrap(q[k] + turn)
        else:
            k = _design_position(chain, self._joint(chain, self.link, "alpha"))
            q[k] = wrap(-q[k])
        return q

    def joints(self, chain: Chain, Q: np.ndarray) -> np.ndarray | None:
        """Joint values (one row per waypoint, `Chain.moving` order) of the same motion on the reflected design: d:
        theta_j negated; a: theta_i and theta_{i+1} turned by pi, whichever way keeps each within its bounds. None
        when a turned joint would leave its bounds either way."""
        Q = np.array(Q, dtype=float)
        if self.kind == "d":
            k, joint = self._moving(chain, self.link)
            Q[:, k] *= -1
            return Q if _within(joint, Q[:, k]) else None
        for link in (self.link, self.link + 1):
            if link > len(chain.dh):
                continue
            k, joint = self._moving(chain, link)
            for turn in (np.pi, -np.pi):
                if _within(joint, Q[:, k] + turn):
                    Q[:, k] += turn
                    break
            else:
                return None
        return Q

    def velocities(self, chain: Chain, V: np.ndarray) -> np.ndarray:
        """Joint velocities of the same motion on the reflected design (d: theta_j's negated)."""
        V = np.array(V, dtype=float)
        if self.kind == "d":
            V[:, self._moving(chain, self.link)[0]] *= -1
        return V

    def _moving(self, chain: Chain, link: int):
        index = self._joint(chain, link, "theta")
        return [i for i, j in enumerate(chain.joints) if j.role is Role.MOVING].index(index), chain.joints[index]


def _design_position(chain: Chain, joint: int) -> int:
    return [i for i, j in enumerate(chain.joints) if j.role is Role.DESIGN].index(joint)


def _within(joint, values) -> bool:
    return bool(np.all(values >= joint.lower) and np.all(values <= joint.upper))


def reflections(chain: Chain) -> list[Reflection]:
    """Every reflection of the chain's DH arm whose parameters are free to move as it needs: the length and its
    twists design joints, the thetas it turns moving joints (revolute links); for the last link's a-reflection, a
    tool transform that a half turn about z leaves where it is. Link 1's d-reflection would turn the placement
    instead and is not among them. None without a DH table."""
    if chain.dh is None:
        return []
    role = [j.role for j in chain.joints]
    n = len(chain.dh)

    def is_(link, param, r):
        return role[chain.dh[link - 1][LINK_PARAMS[param]]] is r

    tool = np.asarray(chain.tool, float)
    half_turn = np.diag([-1.0, -1.0, 1.0, 1.0])
    tool_along_z = np.allclose(half_turn @ tool, tool @ half_turn)
    out = []
    for j in range(2, n + 1):
        if (is_(j, "d", Role.DESIGN) and is_(j - 1, "alpha", Role.DESIGN) and is_(j, "alpha", Role.DESIGN)
                and is_(j, "theta", Role.MOVING)):
            out.append(Reflection("d", j))
    for i in range(1, n + 1):
        turned = is_(i + 1, "theta", Role.MOVING) if i < n else tool_along_z
        if is_(i, "a", Role.DESIGN) and is_(i, "alpha", Role.DESIGN) and is_(i, "theta", Role.MOVING) and turned:
            out.append(Reflection("a", i))
    return out


def at_bound(chain: Chain, q_d: np.ndarray, within: float) -> list[Reflection]:
    """The reflections (`reflections`) of the lengths of design ``q_d`` that lie within ``within`` (m) of a lower
    bound of 0: where the bound, not the arm, may be what holds the design."""
    design = chain.design
    out = []
    for r in reflections(chain):
        k = r.length(chain)
        if design[k].lower == 0.0 and q_d[k] - design[k].lower <= within:
            out.append(r)
    return out
